"""Studies: parameter grids, tolerance Monte Carlo and sensitivity ranking of a model.

A study file (TOML) names a model, an analysis, the outputs wanted and one design;
:class:`Study` checks it against the model before anything runs, runs its cases on a
local process pool or a Dask cluster, commits each finished case to a store in the
output folder (so an interrupted study resumes without recomputing anything) and
returns an :class:`xarray.Dataset`.  ``docs/studies.md`` is the user guide.

================  ======================================================================
module            content
================  ======================================================================
``spec``          the study file's schema (pydantic) and reading, one-line errors
``paths``         model fields by path (as ``--set``), patterns, units from the schema
``design``        the study resolved against its model: parameters in SI, every case's
                  values (grid, Monte Carlo samplers, ISO 1328 tolerances)
``sensitivity``   Morris elementary effects and Sobol indices: sampling and estimators
``outputs``       :func:`~torquesplit.study.outputs.output_values`, the one reader of
                  metrics: a run's metrics as ``{name: float}``; the output names
``case``          :func:`~torquesplit.study.case.run_case`, what a worker runs per case
``runners``       serial, local process pool, Dask: ``runner(function, payloads)``
``store``         SQLite (WAL) store: one committed row per finished case, provenance
``core``          :class:`Study`, :func:`run_study`: the driver loop, resume, stopping
``dataset``       the results as an xarray Dataset, NetCDF
``figures``       curves, maps, histograms/ECDF/convergence, tornado charts (PNG, SVG)
``cli``           ``torquesplit study`` and ``torquesplit sweep``
``shipped``       the papers' studies as study files (package data)
================  ======================================================================

Conventions: values inside are SI; a study file may write units as a model file does.
Every random draw comes from the study's ``seed``; case ``i`` depends only on the study
file and ``i``, so results are bit-identical for any number of workers and any order.

Examples
--------
>>> import torquesplit
>>> ds = torquesplit.run_study({
...     "study": {"name": "damping", "model": "ji_li_mill_drive",
...               "outputs": ["load_sharing.engineering.*"]},
...     "analysis": {"cycles": 20},
...     "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
...                              "values": [0.05, 0.10]}]}}, workers=1)
>>> sorted(set(ds["status"].values.tolist()))
['ok']
"""

from __future__ import annotations

from .core import Progress, Study, load_results, run_study
from .errors import StudyError, StudyInterrupted
from .outputs import output_values

__all__ = ["Progress", "Study", "StudyError", "StudyInterrupted", "load_results",
           "output_values", "run_study"]
