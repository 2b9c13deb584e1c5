"""GPU ensembles: a study's dynamic runs integrated together, one case per GPU thread.

A tolerance Monte Carlo or a parameter sweep is thousands of independent fixed-step
integrations of one system with different numbers.  This package generates, per model
*pattern* (DOFs, sparsity, which elements have dead zones, tables, errors, friction,
splines), one straight-line kernel from the element laws of
:mod:`torquesplit.solve.laws` and the assembled kernel arrays, and runs it with numba
on a CUDA device (one case per thread, the state in thread-local scratch indexed by
constants) — or, for the tests, compiled for the CPU from the same source.  Each case
starts from its own static equilibrium (set up on the CPU exactly as
:func:`torquesplit.simulate` sets it up) and streams the same per-cycle statistics as
the CPU engine; the study outputs are then computed by the one metrics code.  FP64
results equal the CPU engine's (bit for bit where the arithmetic is the CPU's: compiled
for the CPU, in numba's simulator).

============  ==========================================================================
module        content
============  ==========================================================================
``layout``    cases grouped by pattern; each scalar a literal (equal in every case) or a
              row of the per-case parameter arrays; phase tables kept once per set
``source``    the generated Python source: excitation, right-hand side (the laws by
              name), statistics, table corners, RK4 — ``_kernels.rk4_run`` step for step
``compile``   that source compiled with ``numba.njit`` (CPU) or ``numba.cuda.jit``
              (device functions + a one-case-per-thread kernel); PTX without a device
``ensemble``  :func:`~torquesplit.gpu.ensemble.run_ensemble`: prepared runs -> Solutions
              (planning, batching under a memory bound, launch, the engine's
              ``integrate._solution``); refuses unsupported features by name
``backend``   :class:`~torquesplit.gpu.backend.GpuRunner`, the study runner behind
              ``Study.run(backend="gpu")`` and ``torquesplit study --backend gpu``;
              settle-rule rounds; FP32 error report; fallback to the CPU runner
============  ==========================================================================

Conventions: SI throughout; FP64 by default; ``precision="fp32"`` computes the
dynamics (state, stages, element forces) in single precision while times, mesh phases,
error sinusoids and statistics stay in double, and reports its error against FP64 on a
subsample.  Not supported yet, refused by name (:class:`~torquesplit.errors.
GpuUnsupportedError`): adaptive time stepping (``method = "dopri"``), quasi-static
analyses, full state histories.  Decimated histories are not produced (no study output
reads them).

Examples
--------
>>> from torquesplit.gpu.compile import cuda_available
>>> ok, why = cuda_available()
>>> isinstance(ok, bool) and isinstance(why, str)
True
"""

from .backend import GpuRunner, check_plan
from .ensemble import EnsembleResult, run_ensemble

__all__ = ["GpuRunner", "EnsembleResult", "check_plan", "run_ensemble"]
