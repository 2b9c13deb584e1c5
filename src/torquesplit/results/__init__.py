"""Results of a dynamic run: metrics on demand, xarray Dataset, NetCDF / CSV / MAT export.

============  ==============================================================
module        content
============  ==============================================================
``results``   :class:`Results` (this module): holds the pipeline's stages
``dataset``   conversion to an :class:`xarray.Dataset` with units and long names
``files``     checked, claimed, atomic writing of results files with provenance
============  ==============================================================
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from ..metrics import load_sharing as ls


@dataclass(frozen=True)
class MeshRow:
    """One line of the summary table of a run."""

    mesh: str
    group: str
    nominal_force: float
    static_force: float
    mean_force: float
    peak_force: float
    dynamic_factor: float
    dynamic_factor_engineering: float
    load_sharing: float
    contact_loss: float


@dataclass(frozen=True)
class Metrics:
    """Metrics of a run for one load-sharing definition."""

    definition: str
    settling: ls.Settling
    load_sharing: ls.LoadSharing
    dynamic_factors: ls.DynamicFactors
    rows: list[MeshRow]

    def to_dict(self) -> dict:
        return {
            "definition": self.definition,
            "settle_time_s": self.settling.start_time,
            "settled": self.settling.settled,
            "system_load_sharing": self.load_sharing.system,
            "groups": {g: {"meshes": self.load_sharing.groups[g],
                           "load_sharing": self.load_sharing.per_group[g],
                           "dynamic_factor": self.dynamic_factors.per_group_peak[g],
                           "dynamic_factor_engineering":
                               self.dynamic_factors.per_group_engineering[g]}
                       for g in self.load_sharing.groups},
            "meshes": {r.mesh: {k: v for k, v in r.__dict__.items() if k != "mesh"}
                       for r in self.rows},
        }


class Results:
    """A finished (or stopped) dynamic run and everything needed to interpret it."""

    def __init__(self, *, model, kinematics, structure, static, solution):
        self.model = model
        self.kinematics = kinematics
        self.structure = structure
        self.static = static
        self.solution = solution

    # ------------------------------------------------------------------ status
    @property
    def success(self) -> bool:
        return self.solution.success

    @property
    def message(self) -> str:
        return self.solution.message

    @property
    def mesh_names(self) -> list[str]:
        return list(self.model.meshes)

    def statistics(self) -> dict:
        """Integration statistics: steps, rhs evaluations, step size, times."""
        s = self.solution
        return {
            "method": s.method, "status": s.status, "message": s.message,
            "steps": s.n_steps, "rejected_steps": s.n_rejected, "rhs_evaluations": s.n_rhs,
            "step_s": s.step, "step_min_s": s.step_min, "step_max_s": s.step_max,
            "simulated_time_s": s.t_final - s.t_span[0],
            "compile_time_s": s.compile_time, "wall_time_s": s.wall_time,
            "microseconds_per_step": 1e6 * s.wall_time / max(s.n_steps, 1),
            "rhs": s.rhs, "rhs_compile_time_s": s.rhs_compile_time,
        }

    # ------------------------------------------------------------------ metrics
    @cached_property
    def _mesh_meta(self) -> dict:
        return self.structure.metadata["meshes"]

    @cached_property
    def groups(self) -> dict[str, list[str]]:
        return ls.group_meshes(self._mesh_meta)

    def nominal_forces(self) -> dict[str, float]:
        """Equal-split static tooth force of each mesh [N]."""
        return {m: self.kinematics.meshes[m].force for m in self.mesh_names}

    def static_forces(self) -> dict[str, float]:
        """Mesh forces of the static equilibrium (the static load sharing) [N]."""
        names = self.structure.element_names
        return {m: float(self.static.element_forces[names.index(m)]) for m in self.mesh_names}

    def metrics(self, definition: str | None = None, *, window: int = 20,
                tolerance: float = 0.01) -> Metrics:
        """Load sharing (by ``definition``, see :mod:`torquesplit.metrics.load_sharing`)
        and dynamic load factors over the settled part of the run."""
        definition = definition or self.model.analysis.load_sharing
        if definition not in ls.DEFINITIONS:
            raise ValueError(f"unknown load-sharing definition {definition!r}; choose one of "
                             f"{', '.join(ls.DEFINITIONS)}")
        s = self.solution
        names = self.mesh_names
        st = ls.settle(s.cycle_max, s.cycle_start, names, self.settle_windows(window),
                       tolerance)
        groups = self.groups
        if definition == "cycle_peak":
            lsc = ls.cycle_peak(s.cycle_max, names, groups, st.first_cycle)
        elif definition == "mean_force":
            lsc = ls.mean_force(s.cycle_mean, s.cycle_count, names, groups, st.first_cycle)
        elif definition in ("instantaneous", "engineering"):
            t, f = self.mesh_force_history()
            freq = {g: self._mesh_meta[m[0]]["frequency"] for g, m in groups.items()}
            lsc = ls.instantaneous(t, f, names, groups, st.start_time, freq, definition)
        else:  # static_torque on a dynamic run: instantaneous on the history
            t, f = self.mesh_force_history()
            lsc = ls.instantaneous(t, f, names, groups, st.start_time, None, "instantaneous")
            lsc = ls.LoadSharing("static_torque", lsc.per_mesh, lsc.per_group, lsc.system,
                                 lsc.groups)
        nominal = self.nominal_forces()
        dyn = ls.dynamic_factors(s.cycle_max, names, groups, st.first_cycle, nominal)
        static = self.static_forces()
        group_of = {m: g for g, ms in groups.items() for m in ms}
        el = self.structure.element_names
        rows = []
        for j, m in enumerate(names):
            k0 = st.first_cycle[m]
            c = s.cycle_count[k0:, j]
            mean = float((np.nan_to_num(s.cycle_mean[k0:, j]) * c).sum() / max(c.sum(), 1))
            peak = s.cycle_max[k0:, j]
            peak = float(np.nanmax(peak)) if np.isfinite(peak).any() else math.nan
            rows.append(MeshRow(
                mesh=m, group=group_of[m], nominal_force=nominal[m], static_force=static[m],
                mean_force=mean, peak_force=peak, dynamic_factor=dyn.peak[m],
                dynamic_factor_engineering=dyn.engineering[m],
                load_sharing=lsc.per_mesh[m],
                contact_loss=float(s.separation_fraction[el.index(m)]),
            ))
        return Metrics(definition, st, lsc, dyn, rows)

    def settle_windows(self, minimum: int = 20) -> list[int]:
        """Cycles per settle window of each mesh: at least ``minimum`` and the longest
        excitation period (slowest error sinusoid or backlash sequence) in its cycles."""
        st = self.structure
        slow = [w / (2 * math.pi) for w in np.abs(st.error_omega) if w > 0]
        for e in range(st.n_elements):
            n_gaps = st.gap_ptr[e + 1] - st.gap_ptr[e]
            if n_gaps > 1 and st.frequency[e] > 0:
                slow.append(st.frequency[e] / n_gaps)
        f_slow = min(slow) if slow else None
        out = []
        for m in self.mesh_names:
            f = self._mesh_meta[m]["frequency"]
            out.append(max(minimum, int(math.ceil(f / f_slow))) if f_slow else minimum)
        return out

    def mesh_force_history(self) -> tuple[np.ndarray, np.ndarray]:
        """Decimated time and mesh forces (n_samples, n_meshes) [s, N]."""
        s = self.solution
        el = self.structure.element_names
        cols = [list(s.history_elements).index(el.index(m)) for m in self.mesh_names]
        return s.history_t, s.history_forces[:, cols]

    # ------------------------------------------------------------------ export
    def to_dataset(self):
        """The run as an :class:`xarray.Dataset` (units and long names on every variable)."""
        from .dataset import results_to_dataset

        return results_to_dataset(self)

    def to_netcdf(self, path, *, overwrite: bool = False) -> Path:
        """Save as NetCDF (h5netcdf); the model is embedded so the file can be re-run.

        The file is written atomically (:mod:`torquesplit.results.files`): complete or
        absent, never replacing an existing file unless ``overwrite``; its attributes
        ``run_id``, ``created_utc``, ``software`` and ``command`` say which run wrote it.

        Raises
        ------
        OutputError
            The path's folder is missing, the file exists (without ``overwrite``) or
            another run is writing it.
        """
        from . import files

        plan = files.check_output(path, formats=files.NETCDF_FORMATS, overwrite=overwrite)
        with files.claim_output(plan) as claim:
            ds = self.to_dataset()
            ds.attrs.update(files.provenance(claim.run_id))
            claim.write({plan.path: files.netcdf_bytes(ds)})
        return plan.path

    def save(self, path, *, overwrite: bool = False) -> Path:
        """Save by suffix: ``.nc`` NetCDF, ``.mat`` MATLAB, ``.csv`` spreadsheet tables.

        Every file is written atomically and an existing one is kept unless
        ``overwrite`` (see :meth:`to_netcdf`).
        """
        from . import files

        plan = files.check_output(path, overwrite=overwrite)
        writer = {"netcdf": self.to_netcdf, "mat": self.to_mat, "csv": self.to_csv}[plan.format]
        return writer(plan.path, overwrite=overwrite)

    def to_mat(self, path, *, overwrite: bool = False) -> Path:
        """Save for MATLAB (scipy.io.savemat): every variable of the Dataset, SI units,
        and a ``provenance`` struct naming the run; written atomically."""
        from . import files

        plan = files.check_output(path, formats={".mat": "mat"}, overwrite=overwrite)
        with files.claim_output(plan) as claim:
            ds = self.to_dataset()
            data = {name: np.asarray(ds[name].values) for name in ds.data_vars}
            for name in ds.coords:
                values = ds[name].values
                data[name] = (np.asarray(values, dtype=object) if values.dtype.kind in "UO"
                              else np.asarray(values))
            data["units"] = {name: ds[name].attrs.get("units", "") for name in ds.data_vars}
            data["model_json"] = ds.attrs["model_json"]
            data["metrics_json"] = ds.attrs.get("metrics_json", "")
            data["provenance"] = files.provenance(claim.run_id)
            claim.write({plan.path: files.mat_bytes(data)})
        return plan.path

    def to_csv(self, path, *, overwrite: bool = False) -> Path:
        """Save spreadsheet tables: ``NAME.csv`` (per-mesh summary) and beside it
        ``NAME_history.csv`` (decimated forces) and ``NAME_cycles.csv`` (cycle peaks).

        All three are written atomically, and none replaces an existing file unless
        ``overwrite``.  A run that did not finish has no metrics: its summary lists the
        meshes with empty metric columns and its status.
        """
        from . import files

        plan = files.check_output(path, formats={".csv": "csv"}, overwrite=overwrite)
        path = plan.path
        header = ["mesh", "group", "nominal_force_N", "static_force_N", "mean_force_N",
                  "peak_force_N", "dynamic_factor", "dynamic_factor_engineering",
                  "load_sharing", "contact_loss_fraction"]
        try:
            met = self.metrics() if self.success else None
        except (ValueError, ArithmeticError):
            met = None
        if met is not None:
            header[8] = f"load_sharing_{met.definition}"
            rows = [[r.mesh, r.group, r.nominal_force, r.static_force, r.mean_force,
                     r.peak_force, r.dynamic_factor, r.dynamic_factor_engineering,
                     r.load_sharing, r.contact_loss] for r in met.rows]
        else:
            header.append("status")
            group_of = {m: g for g, ms in self.groups.items() for m in ms}
            nominal, static = self.nominal_forces(), self.static_forces()
            rows = [[m, group_of.get(m, ""), nominal[m], static[m], "", "", "", "", "", "",
                     self.message] for m in self.mesh_names]
        s = self.solution
        el = self.structure.element_names
        names = [el[i] for i in s.history_elements]
        cols = [list(s.tracked_elements).index(el.index(m)) for m in self.mesh_names]
        history, cycles, summary = plan.files[1], plan.files[2], plan.files[0]
        contents = {
            history: files.csv_bytes(["time_s"] + [f"{n}_N" for n in names],
                                     np.column_stack([s.history_t, s.history_forces]).tolist()),
            cycles: files.csv_bytes(["cycle"] + [f"{m}_start_s" for m in self.mesh_names]
                                    + [f"{m}_peak_N" for m in self.mesh_names],
                                    np.column_stack([np.arange(s.cycle_max.shape[0]),
                                                     s.cycle_start[:, cols],
                                                     s.cycle_max[:, cols]]).tolist()),
            summary: files.csv_bytes(header, rows),  # last: its presence marks the set
        }
        with files.claim_output(plan) as claim:
            claim.write(contents)
        return path

    def write_figures(self, directory, formats=("png", "svg"), **kwargs):
        """Write the report figures (see :func:`torquesplit.plot.write_figures`)."""
        from ..plot import write_figures

        return write_figures(self, directory, formats, **kwargs)

    def model_json(self) -> str:
        from ..model.io import model_to_json

        return model_to_json(self.model)


def open_results(path):
    """Open a results file written by :meth:`Results.to_netcdf` as an xarray Dataset."""
    import xarray as xr

    return xr.open_dataset(path, engine="h5netcdf")


def model_from_results(dataset):
    """Re-create the model embedded in a results Dataset."""
    from ..model.io import load_model

    return load_model(json.loads(dataset.attrs["model_json"]))
