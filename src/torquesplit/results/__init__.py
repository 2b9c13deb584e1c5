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

import dataclasses

import json
import math
import numbers
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple
from pathlib import Path

import numpy as np

from .. import _args
from ..assembly.structure import element_units
from ..errors import OptionError
from ..metrics import load_sharing as ls
from ..model.kinematics import bearing_frame

#: the load-sharing definition of a new model: the mean-force ratio, the mesh load factor
#: K_gamma of the design standards (see docs/load-sharing.md)
STANDARD_DEFINITION = ls.STANDARD_DEFINITION


class CycleStatistics(NamedTuple):
    """Per-cycle statistics of every mesh, (n_cycles, n_meshes) each
    (:meth:`Results.complete_cycle_statistics`; a reviewer guessed the meaning of a bare
    5-tuple by position)."""

    max: np.ndarray  #: largest force of the cycle [N]
    min: np.ndarray  #: smallest force of the cycle [N]
    mean: np.ndarray  #: mean force of the cycle [N]
    count: np.ndarray  #: samples in the cycle (0: a cycle cut by the start or end)
    ratio_max: np.ndarray  #: largest instantaneous load-sharing ratio in the cycle

@dataclass(frozen=True)
class MeshRow:
    """One line of the summary table of a run (forces in N, the rest dimensionless)."""

    mesh: str
    group: str
    nominal_force: float
    """Equal-split nominal tooth force."""
    static_force: float
    """Force at the static equilibrium under the mean excitation (static load sharing
    included): mean mesh stiffness, constant errors, an eccentricity or runout turning
    with its gear averaged out; not the t = 0 equilibrium the run starts from."""
    mean_force: float
    peak_force: float
    min_force: float
    dynamic_factor: float
    """Settled peak / static force (K_v sense; NaN for an unloaded mesh)."""
    dynamic_factor_engineering: float
    """Mean of the settled per-cycle peaks / static force."""
    peak_to_nominal: float
    """Settled peak / nominal force (Ji & Li eq. 19 per mesh)."""
    load_sharing: float
    """Coefficient of the metrics' definition."""
    contact_loss: float
    """Fraction of the run with the mesh inside its backlash (drive flank separated)."""
    back_contact: float
    """Fraction of the run in back-flank contact (tensile force for a mesh without
    backlash: double-flank contact)."""
    back_flank_force: float = 0.0
    """Largest back-flank force over the settled cycles (like the peak force) [N], >= 0:
    minus the smallest settled force when that is negative and the back flank was
    reached (``back_contact`` > 0, or no backlash).  A mesh with backlash that never
    reaches its back flank reports 0: a negative force there is the damping force of
    the drive flank as it separates (Kelvin-Voigt contact, Ji & Li eq. 11), not a
    back-flank load.  The start-up transient's, if any, is left out; the plausibility
    warnings name it."""
    double_flank: bool = False
    """The mesh has no backlash: its back flank is always in reach (double-flank
    contact), so it can carry tension."""


@dataclass(frozen=True)
class Metrics:
    """Metrics of a run for one load-sharing definition."""

    definition: str
    settling: ls.Settling
    load_sharing: ls.LoadSharing
    dynamic_factors: ls.DynamicFactors
    rows: list[MeshRow]

    def __repr__(self) -> str:
        """One line: the system and group coefficients, the dynamic factor, the settle
        time (the dataclass's own repr printed every field: 3 kB)."""
        d = self.dynamic_factors
        # ('#': trailing zeros kept, 1.0000286 read 'stage2 1')
        groups = ", ".join(f"{g} {v:#.5g}" for g, v in
                           list(self.load_sharing.per_group.items())[:3])
        more = len(self.load_sharing.per_group) - 3
        groups += f" and {more} more" if more > 0 else ""
        kv = ls._nanmax(list(d.per_group_dynamic_factor.values()))
        st = self.settling
        why = ("too short to tell" if st.short or st.shrunk else
               "transient did not die out")
        # (a periodic state's 'settled from 0.04189 s' lay beyond the period its
        # dataset holds: a Python API reviewer)
        settled = ("a periodic state (no transient)" if st.periodic else
                   f"settled from {st.start_time:.4g} s" if st.settled else
                   f"not settled ({why}), from {st.start_time:.4g} s")
        return (f"Metrics({self.definition!r}: load sharing {self.load_sharing.system:#.5g} "
                f"({groups}), dynamic factor {kv:#.4g}, {settled})")

    def to_dict(self) -> dict:
        d = self.dynamic_factors
        return {
            "definition": self.definition,
            "definition_text": ls.DEFINITION_TEXT[self.definition],
            "settle_time_s": self.settling.start_time,
            "settle_time_note": "the latest group's; each group's metrics start at its own "
                                "(groups.<name>.settle_time_s)",
            "settled": self.settling.settled,
            "system_load_sharing": self.load_sharing.system,
            "groups": {g: {"meshes": self.load_sharing.groups[g],
                           "settle_time_s": self.settling.group_time.get(g, math.nan),
                           "load_sharing": self.load_sharing.per_group[g],
                           "dynamic_factor": d.per_group_dynamic_factor[g],
                           "peak_to_nominal": d.per_group_peak_to_nominal[g],
                           "peak_to_nominal_engineering":
                               d.per_group_peak_to_nominal_engineering[g]}
                       for g in self.load_sharing.groups},
            "meshes": {r.mesh: {k: v for k, v in r.__dict__.items() if k != "mesh"}
                       for r in self.rows},
        }

    def settle_times_text(self) -> str:
        """The transient the metrics leave out: '0.04 s', or per group where the groups'
        differ ('split 0.02 s, combine 0.04 s': each group's metrics start at its own)."""
        times = self.settling.group_time

        def said(t):  # (a group without a whole cycle has no settle time: it read -inf s)
            return f"{t:.4g} s" if math.isfinite(t) else "none (no whole cycle)"

        if len(set(times.values())) <= 1:
            return said(self.settling.start_time)
        return ", ".join(f"{g} {said(t)}" for g, t in times.items())

    def values(self) -> dict[str, float]:
        """Every number of these metrics by a flat name (what studies ask for):
        ``load_sharing.<definition>`` (system) and ``.<group>`` / ``.<mesh>``;
        ``dynamic_factor``, ``peak_to_nominal`` (system, ``.<group>``, ``.<mesh>``);
        ``dynamic_factor_engineering.<mesh>``, ``peak_to_nominal_engineering.<group>``;
        ``peak_force``, ``min_force``, ``mean_force``, ``static_force``,
        ``nominal_force``, ``contact_loss``, ``back_contact``, ``back_flank_force``
        ``.<mesh>``;
        ``settle_time``."""
        lsc, d = self.load_sharing, self.dynamic_factors
        key = f"load_sharing.{self.definition}"
        out = {key: lsc.system, "settle_time": self.settling.start_time}
        out.update({f"{key}.{g}": v for g, v in lsc.per_group.items()})
        out.update({f"{key}.{m}": v for m, v in lsc.per_mesh.items()})
        out["dynamic_factor"] = ls._nanmax(list(d.per_group_dynamic_factor.values()))
        out["peak_to_nominal"] = ls._nanmax(list(d.per_group_peak_to_nominal.values()))
        for g in lsc.groups:
            out[f"dynamic_factor.{g}"] = d.per_group_dynamic_factor[g]
            out[f"peak_to_nominal.{g}"] = d.per_group_peak_to_nominal[g]
            out[f"peak_to_nominal_engineering.{g}"] = d.per_group_peak_to_nominal_engineering[g]
        for r in self.rows:
            for name in ("dynamic_factor", "dynamic_factor_engineering", "peak_to_nominal",
                         "peak_force", "min_force", "mean_force", "static_force",
                         "nominal_force", "contact_loss", "back_contact",
                         "back_flank_force"):
                out[f"{name}.{r.mesh}"] = getattr(r, name)
        return out


def _steady_summary(attrs) -> dict:
    """A periodic steady state's own numbers from its attributes (``steady_*``: method,
    period, residual, stability, largest Floquet multiplier, and what the record is),
    without the prefix; {} for a run."""
    if attrs.get("analysis") != "periodic steady state":
        return {}
    out = {k[len("steady_"):]: v for k, v in attrs.items()
           if k.startswith("steady_") and k != "steady_json"}
    out["record"] = attrs.get("record", "")
    out["dropped_excitations"] = attrs.get("dropped_excitations", "none")
    return out


def _copied(obj):
    """A dataclass of metrics with its own copies of its dict fields (their values are
    numbers, strings or tuples): a caller's change does not reach the kept one."""
    return dataclasses.replace(obj, **{f.name: dict(v) for f in dataclasses.fields(obj)
                                       if isinstance(v := getattr(obj, f.name), dict)})


class Results:
    """A finished (or stopped) dynamic run and everything needed to interpret it."""

    def __init__(self, *, model, kinematics, structure, static, solution,
                 run_warnings=(), model_warnings=None, periodic: bool = False,
                 period: float | None = None):
        self.model = model
        self.steady = None
        """The :class:`~torquesplit.steady.SteadyState` this record repeats (a steady
        state's :meth:`~torquesplit.steady.SteadyState.to_results`), else None: its
        summary goes into the saved file."""
        self.periodic = periodic
        """The record is a periodic state repeated over whole periods (a steady state):
        no transient to detect, every complete cycle counts."""
        self.period = period
        """The period of a periodic record [s] (None for a run)."""
        self.saved_definition: str | None = None
        """A run read back from its file: the load-sharing definition it was saved with
        (its ``load_sharing_definition`` attribute), which :meth:`metrics` then reports
        by default."""
        self.saved_steady: dict = {}
        """A steady state read back from its file: its ``steady_*`` (and record)
        attributes and RMS transmission errors, which a save writes again."""
        self.kinematics = kinematics
        self.structure = structure
        self.static = static
        self.solution = solution
        self.run_warnings: list[str] = list(run_warnings)
        """Warnings of the run itself (cost, step, static equilibrium), as text."""
        self.model_warnings: list[str] | None = (None if model_warnings is None
                                                 else list(model_warnings))
        """Warnings of the model's checks, as text; None: computed on demand from the
        model (:func:`torquesplit.model.checks.plausibility_warnings`)."""

    def warnings(self, definition: str | None = None) -> list[str]:
        """Every warning of this run, each ``"location: message"``: the model's
        plausibility checks, the run's own (cost, step, static equilibrium) and the
        plausibility of its results (:mod:`torquesplit.results.plausibility`: back-flank
        and double-flank contact, contact loss, negative static force, a dynamic factor
        near a resonance, a transient that did not settle).

        The command line prints them, lists them in ``--json`` and the results files
        carry them (attribute ``warnings``).
        """
        from .plausibility import result_warnings

        if definition is not None:
            self.check_definition(definition)
        out = list(self.model_warnings) if self.model_warnings is not None else [
            f"{loc}: {msg}" for loc, msg in self._model_plausibility()]
        out += self.run_warnings
        if not self.success:  # (its metrics are NaN: say why beside them)
            out.append(f"run: {self.message}")
        if self.success:
            try:
                met = self.metrics(definition)
            except (ValueError, ArithmeticError):  # pragma: no cover - reported elsewhere
                met = None
            if met is not None:
                out += [f"{loc}: {msg}" for loc, msg in result_warnings(self, met)]
        seen: set[str] = set()
        return [w for w in out if not (w in seen or seen.add(w))]

    def _steady_attributes(self, info: dict | None = None) -> dict:
        """The attributes that say what this steady state is ({} for a run); ``info``:
        its summary where the caller has it already."""
        if self.steady is not None:
            from .dataset import steady_attrs

            return steady_attrs(self, info if info is not None
                                else self.steady.summary(results=self))
        return dict(self.saved_steady.get("attrs", {}))

    def _model_plausibility(self) -> list[tuple[str, str]]:
        """The model's plausibility warnings, less those its file accepts with a reason
        (``[model] accepted_warnings``: not shown by a run, so not in its files either)."""
        from ..model.checks import accepted, as_written, plausibility_warnings

        try:
            found = as_written(self.model, plausibility_warnings(self.model, self.kinematics))
        except (ValueError, ArithmeticError, KeyError):  # pragma: no cover - checked before
            return []
        return [(loc, msg) for loc, msg in found if accepted(self.model, loc) is None]

    # ------------------------------------------------------------------ status
    def __repr__(self) -> str:
        s = self.solution
        if s is None:
            return f"<Results of {self.model.model.name!r}: no solution>"
        kind = "periodic steady state" if self.periodic else "dynamic run"
        return (f"<Results of {self.model.model.name!r}: {kind}, {s.t_final - s.t_span[0]:.4g} "
                f"s simulated, {len(self.mesh_names)} meshes, "
                f"{'ok' if self.success else 'stopped: ' + self.message}; "
                f".metrics(), .metric_values(), .warnings(), .save(path), "
                f".write_figures(dir)>")

    @property
    def success(self) -> bool:
        return self.solution.success

    @property
    def message(self) -> str:
        return self.solution.message

    @property
    def mesh_names(self) -> list[str]:
        """The meshes in the model file's order: the columns of
        :meth:`mesh_force_history` and the ``mesh`` coordinate of the datasets."""
        return list(self.model.meshes)

    def statistics(self) -> dict:
        """Integration statistics: steps, rhs evaluations, step size, times, and the
        history's size (samples, and samples per shortest mesh period)."""
        s = self.solution
        return {
            "method": s.method, "status": s.status, "message": s.message,
            "steps": s.n_steps, "rejected_steps": s.n_rejected, "rhs_evaluations": s.n_rhs,
            "step_s": s.step, "step_min_s": s.step_min, "step_max_s": s.step_max,
            "step_limited_by": s.step_limited_by,
            "simulated_time_s": s.t_final - s.t_span[0],
            "compile_time_s": s.compile_time, "wall_time_s": s.wall_time,
            "microseconds_per_step": 1e6 * s.wall_time / max(s.n_steps, 1),
            "rhs": s.rhs, "rhs_compile_time_s": s.rhs_compile_time,
            "history_samples": int(s.history_t.size),
            "history_samples_per_period": self.history_samples_per_period(),
        }

    # ------------------------------------------------------------------ metrics
    @cached_property
    def _mesh_meta(self) -> dict:
        return self.structure.metadata["meshes"]

    @cached_property
    def groups(self) -> dict[str, list[str]]:
        """Load-sharing group -> its meshes: the meshes of one ``stage`` (keyed
        ``"path/stage"`` where the meshes name a ``path``), whose loads the coefficients
        compare."""
        return ls.group_meshes(self._mesh_meta)

    def nominal_forces(self) -> dict[str, float]:
        """Equal-split static tooth force of each mesh [N]."""
        return {m: self.kinematics.meshes[m].force for m in self.mesh_names}

    def static_forces(self) -> dict[str, float]:
        """Mesh forces of the static equilibrium under the mean excitation (the static
        load sharing) [N]: mean mesh stiffness and constant errors; errors that turn with
        the gears (eccentricity, runout) average out.  The run starts from the equilibrium
        at t = 0 instead (``prepare_run``)."""
        names = self.structure.element_names
        return {m: float(self.static.element_forces[names.index(m)]) for m in self.mesh_names}

    def metrics(self, definition: str | None = None, *, window: int = 20,
                tolerance: float = 0.01) -> Metrics:
        """Load sharing (by ``definition``, see :mod:`torquesplit.metrics.load_sharing`)
        and dynamic factors over the settled part of the run.

        Every number comes from the per-cycle statistics streamed by the integrator at
        every step; the settle criterion (``window`` cycles at least, ``tolerance``) gives
        one settle time per load-sharing group, used by all of its metrics: ``window`` a
        whole number >= 2, ``tolerance`` a positive fraction (0.01: 1 %)."""
        definition = self.check_definition(definition)
        if (isinstance(window, bool) or not isinstance(window, numbers.Real)
                or not float(window).is_integer() or window < 2):
            raise OptionError(f"window must be a whole number of cycles >= 2, got "
                              f"{window!r}; give e.g. window=20")
        if isinstance(tolerance, bool) or not (isinstance(tolerance, numbers.Real)
                                               and 0 < tolerance < 1):
            raise OptionError(f"tolerance must be a fraction between 0 and 1, got "
                              f"{tolerance!r}; give e.g. tolerance=0.01 (1 %)")
        st, dyn, rows = self._metric_base(int(window), float(tolerance))
        names = self.mesh_names
        c_max, _, c_mean, c_cnt, c_ratio = self.complete_cycle_statistics()
        c_start = self.solution.cycle_start[:, self._mesh_columns]
        groups = self.groups
        if definition == "cycle_peak":
            lsc = ls.cycle_peak(c_max, c_start, names, groups, st.first_cycle)
        elif definition == "mean_force":  # (every group over the same span)
            lsc = ls.mean_force(c_mean, c_cnt, c_start, names, groups, st.mean_first)
        else:
            lsc = ls.instantaneous(c_ratio, c_start, names, groups, st.first_cycle,
                                   definition)
        rows = [dataclasses.replace(r, load_sharing=lsc.per_mesh[r.mesh]) for r in rows]
        return Metrics(definition, st, lsc, dyn, rows)

    def _metric_base(self, window: int, tolerance: float):
        """What :meth:`metrics` gives whatever the definition: the settling, the dynamic
        factors and the mesh rows (load sharing NaN), computed once per ``window`` and
        ``tolerance`` (a study case asks for two definitions, the report for four); each
        call gets its own copy of the mutable parts."""
        cache = self.__dict__.setdefault("_metric_bases", {})
        if (window, tolerance) not in cache:
            cache[window, tolerance] = self._compute_metric_base(window, tolerance)
        st, dyn, rows = cache[window, tolerance]
        return _copied(st), _copied(dyn), rows

    def _compute_metric_base(self, window: int, tolerance: float):
        s = self.solution
        names = self.mesh_names
        c_max, c_min, c_mean, c_cnt, c_ratio = self.complete_cycle_statistics()
        c_start = s.cycle_start[:, self._mesh_columns]
        groups = self.groups
        st = (ls.periodic(c_max, c_start, names, groups) if self.periodic else
              ls.settle(c_max, c_start, names, self.settle_windows(window), tolerance,
                        groups))
        if not self.periodic:  # the mean forces of every group over one span (a periodic
            # state's groups are over whole periods already)
            st = dataclasses.replace(st, mean_first_cycle=ls.common_first_cycle(
                st, c_start, names))
        nominal = self.nominal_forces()
        static = self.static_forces()
        dyn = ls.dynamic_factors(c_max, names, groups, st.first_cycle, static, nominal)
        group_of = {m: g for g, ms in groups.items() for m in ms}
        el = self.structure.element_names
        rows = []
        for j, m in enumerate(names):
            k0 = st.first_cycle[m]
            km = st.mean_first[m]  # (the mean force over the span of the coefficients)
            mean = ls.span_mean(c_mean[km:, j], c_cnt[km:, j])
            back = float(s.back_contact_fraction[el.index(m)])
            double = not (self.model.meshes[m].backlash.nominal > 0)
            rows.append(MeshRow(
                mesh=m, group=group_of[m], nominal_force=nominal[m], static_force=static[m],
                mean_force=mean, peak_force=ls._nanmax(c_max[k0:, j]),
                min_force=-ls._nanmax(-c_min[k0:, j]),
                dynamic_factor=dyn.dynamic_factor[m],
                dynamic_factor_engineering=dyn.dynamic_factor_engineering[m],
                peak_to_nominal=dyn.peak_to_nominal[m], load_sharing=math.nan,
                contact_loss=float(s.separation_fraction[el.index(m)]),
                back_contact=back,
                back_flank_force=back_flank_force(c_min[k0:, j]) if back > 0 or double else 0.0,
                double_flank=double,
            ))
        return st, dyn, rows

    @property
    def default_definition(self) -> str:
        """The load-sharing definition :meth:`metrics` reports when none is given: the
        model's ``[analysis] load_sharing``, or :data:`STANDARD_DEFINITION` when that is
        the quasi-static ``static_torque`` (which needs ``torquesplit static``); for a run
        read back from a file, the definition it was saved with (``--definition``), so
        that its metrics are the ones the file's tables hold."""
        if self.saved_definition in ls.DYNAMIC_DEFINITIONS:
            return self.saved_definition
        return default_definition(self.model)

    @cached_property
    def complete_cycles(self) -> np.ndarray:
        """(n_cycles, n_meshes) True where a mesh cycle lies wholly inside the simulated
        span.  The cycle cut off by the end of the run (and the one cut by its start)
        has a peak, a mean and a ratio of part of a cycle only: no metric, table or
        figure uses it."""
        s = self.solution
        start = s.cycle_start[:, self._mesh_columns]
        f = np.array([float(self._mesh_meta[m]["frequency"]) for m in self.mesh_names])
        if start.size == 0 or not np.all(f > 0):
            return np.ones(start.shape, bool)
        tol = 1e-6 / f
        return (start >= s.t_span[0] - tol) & (start + 1.0 / f <= s.t_final + tol)

    def complete_cycle_statistics(self) -> "CycleStatistics":
        """Per-cycle (max, min, mean, count, largest instantaneous ratio) of every mesh,
        (n_cycles, n_meshes) each, with the incomplete cycles (:attr:`complete_cycles`)
        emptied: NaN statistics and count 0.  Read-only arrays, computed once (every
        metric, table and figure reads them); a named tuple (``.max``, ``.min``,
        ``.mean``, ``.count``, ``.ratio_max``) that unpacks as the five arrays."""
        return self._complete_cycle_statistics

    @cached_property
    def _complete_cycle_statistics(self):
        s = self.solution
        cols = self._mesh_columns
        every = list(cols) == list(range(s.cycle_max.shape[1]))  # (a copy, not a gather)
        partial = ~self.complete_cycles
        out = []
        for a in (s.cycle_max, s.cycle_min, s.cycle_mean, s.cycle_count, s.cycle_ratio_max):
            a = np.array(a if every else a[:, cols])
            a[partial] = 0 if a.dtype.kind in "iu" else np.nan
            a.flags.writeable = False
            out.append(a)
        return CycleStatistics(*out)

    def check_definition(self, definition: str | None) -> str:
        """``definition``, or the model's default when None; an unknown one, or the
        quasi-static 'static_torque', raises (before anything is computed or written)."""
        definition = definition or self.default_definition
        if definition in ("static", "static_torque"):
            raise OptionError(
                "'static_torque' is the load sharing of quasi-static equilibria (Mo et al. "
                "2017 eqs. 14-15), not of a dynamic run; compute it with `torquesplit "
                "static MODEL` (or torquesplit.quasi_static_load_sharing), or "
                f"choose one of {', '.join(ls.DYNAMIC_DEFINITIONS)} for this run.")
        if definition not in ls.DEFINITIONS:
            raise OptionError(f"unknown load-sharing definition {definition!r}; choose one of "
                              f"{', '.join(ls.DYNAMIC_DEFINITIONS)}")
        return definition

    def metric_values(self, definitions=None, *, window: int = 20,
                      tolerance: float = 0.01) -> dict[str, float]:
        """Every metric of the run by a flat name (:meth:`Metrics.values`), for every
        dynamic load-sharing definition (or those given), with the planet load-sharing
        factor ``planet_load_sharing.<definition>[.<carrier>|.<planet>]`` of planetary
        stages."""
        from ..metrics.planetary import planet_load_sharing

        out: dict[str, float] = {}
        if isinstance(definitions, str):  # one definition (not its letters)
            definitions = [definitions]
        for d in definitions or ls.DYNAMIC_DEFINITIONS:
            met = self.metrics(d, window=window, tolerance=tolerance)
            out.update(met.values())
            # the planet load-sharing factor K_gamma of every planetary stage (if any)
            out.update(planet_load_sharing(met.load_sharing, self.kinematics).values())
        return out

    @cached_property
    def _mesh_columns(self) -> list[int]:
        """Column of each mesh in the solution's cycle arrays."""
        el = self.structure.element_names
        tracked = list(self.solution.tracked_elements)
        return [tracked.index(el.index(m)) for m in self.mesh_names]

    def settle_windows(self, minimum: int = 20) -> list[int]:
        """Cycles per settle window of each mesh: at least ``minimum`` and the longest
        excitation period (slowest error sinusoid or backlash sequence) in its cycles."""
        minimum = _args.whole(minimum, "minimum", "minimum=20", minimum=2)
        st = self.structure
        # sinusoids of zero amplitude (an excitation left out, e.g. by a steady state's
        # keep=) excite nothing and do not lengthen the window
        slow = [w / (2 * math.pi) for w, a in zip(np.abs(st.error_omega), st.error_amplitude)
                if w > 0 and a != 0]
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

    def history_samples_per_period(self) -> float:
        """Samples of the history per shortest mesh period (0 without a history)."""
        t = self.solution.history_t if self.solution is not None else np.zeros(0)
        f_max = max((float(self._mesh_meta[m]["frequency"]) for m in self.mesh_names),
                    default=0.0)
        if t.size < 2 or not f_max > 0:
            return 0.0
        return 1.0 / (f_max * float(np.median(np.diff(t))))

    def history_keeps_every_step(self) -> bool:
        """Whether the history holds every (fixed) step: a finer one needs a finer step."""
        t = self.solution.history_t if self.solution is not None else np.zeros(0)
        step = self.solution.step if self.solution is not None else None
        return bool(t.size >= 2 and step and float(np.median(np.diff(t))) < 1.5 * step)

    def support_columns(self) -> dict[str, list[tuple[str, int, float]]]:
        """Supported body -> its bearing elements' (direction, column of the history, sign
        that turns the element's force into the force the body puts on its bearing).

        A body held radially by a spline alone (Dong et al. 2021's floating pinions: no
        support of its own) has the spline's radial element as its bearing: the spline's
        force acts on the floating member with the opposite sign of a support's."""
        el = self.structure.element_names
        hist = list(self.solution.history_elements)
        out: dict[str, list[tuple[str, int, float]]] = {}
        for body, parts in _bearing_elements(el, self.model).items():
            for direction, e, sign in parts:
                if e in hist:
                    out.setdefault(body, []).append((direction, hist.index(e), sign))
        return out

    def bearing_via(self) -> dict[str, str]:
        """Body -> the spline that is its bearing, for the bodies a spline alone holds."""
        supported = {n.split(".support.", 1)[0] for n in self.structure.element_names
                     if ".support." in n}
        return {sp.connects[1]: name for name, sp in getattr(self.model, "splines", {}).items()
                if sp.connects[1] not in supported}

    def history_start(self, metrics=None, group: str | None = None) -> float:
        """Where the settled part of the history starts [s]: the settle time (the
        group's, where given), or a periodic record's first sample (a saved steady state
        holds one period, which can end before a settle time: its spectrum figure found
        no sample)."""
        s = self.solution
        if self.periodic and s is not None and s.history_t.size:
            return float(s.history_t[0])
        met = self.metrics() if metrics is None else metrics
        if group is None:
            return float(met.settling.start_time)
        times = met.settling.group_time
        if group not in times:  # (a typo gave the overall start without a word: a reviewer)
            raise OptionError(f"no load-sharing group {group!r}; the groups are "
                              f"{', '.join(times) or '(none)'}")
        return float(times[group])

    def bearing_forces(self, start_time: float | None = None, *,
                       metrics=None) -> list[dict]:
        """Per supported body, its bearing (support) force over the settled part: the mean
        of each direction [N], the magnitude of that mean and the largest magnitude of the
        force vector [N] (a body held by a spline alone: the spline's radial force, its
        name in ``via``; a body held rigidly, with no translational DOF: the sum of its
        meshes' forces along their lines of action, in the housing's x, y, z, axial thrust
        included, or a turning carrier's where its meshes turn with it, ``held`` "rigid"),
        from the history from ``start_time`` (default the latest group settle time: pass
        ``metrics().settling.start_time`` when the metrics are at hand; a periodic
        state's: its first whole period, whatever ``start_time``).  The history is
        decimated (``samples_per_period``): a peak between its samples is missed, as
        :func:`~torquesplit.results.plausibility.coarse_history` says for the meshes, and
        a mean is that of its samples (a force that jumps with a stiffness table's step,
        sampled at the same phase of every cycle, moves it by a part of the jump over the
        samples per period).  A rigid bearing's mean, at the settle time (the default) is
        the sum of its meshes' mean forces over their settled cycles (the streamed time
        integrals of the mesh table: its samples' mean was 0.4 % off a mesh's mean force in
        the tutorial's model).  Forces are in the frame of the support (a
        turning carrier's for planets), which ``frame`` names: ``"housing"`` or
        ``"turning with NAME"``.  A run without a whole cycle of some mesh has no
        settled part (its settle time is -inf): no rows.  ``metrics``: the run's
        :meth:`metrics` where the caller has them (they are not computed again)."""
        s = self.solution
        if s is None or not s.history_t.size:
            return []
        by_body = self.support_columns()
        rigid = rigid_bearings(self.model, self.kinematics)
        if not by_body and not rigid:
            return []
        if start_time is not None and not (isinstance(start_time, numbers.Real)
                                           and not isinstance(start_time, bool)):
            raise OptionError(f"start_time must be a time in seconds (a number), got "
                              f"{start_time!r}; give e.g. res.metrics().settling.start_time")
        end = float(s.history_t[-1])
        if start_time == -math.inf and not (self.periodic and self.period):
            # the settle time of a run shorter than a whole cycle of some mesh: it has no
            # settled part, so no settled bearing forces (run crashed there after its
            # tables, losing a --json output)
            return []
        if (start_time is not None and not (self.periodic and self.period)
                and not (math.isfinite(start_time) and start_time < end)):
            # (it took the whole history, start-up included, without a word; a periodic
            # state takes its first period whatever the start time)
            raise OptionError(f"start_time {start_time!r} s leaves no sample of the history, "
                              f"which ends at {end:.6g} s; give a time before that, e.g. "
                              f"res.metrics().settling.start_time")
        if self.periodic and self.period:  # one whole period: the state repeats it (a
            # settle time inside the period weighted a part of it: a mean 6x too large)
            from .dataset import period_samples

            keep = np.zeros(s.history_t.shape, bool)
            keep[:period_samples(s.history_t, self.period) or keep.size] = True
        else:
            if start_time is None and metrics is None:
                metrics = self.metrics()
            t0 = metrics.settling.start_time if start_time is None else float(start_time)
            if not math.isfinite(t0):  # the default settle time of a run without a whole
                return []  # cycle: no settled part (the start-up was given as 'settled')
            keep = s.history_t >= t0
        if not keep.any():
            keep = np.ones(s.history_t.shape, bool)
        out = []
        via = self.bearing_via()
        streamed = dict(zip(s.history_peak_names, range(len(s.history_peak_names)))) \
            if s.history_peaks is not None and not (self.periodic and self.period) else {}

        def row(body, directions, forces, **extra):
            mean = forces.mean(axis=0)
            magnitude = np.sqrt((forces ** 2).sum(axis=1))
            peak = float(magnitude.max())
            if body in streamed:  # every step's over the kept samples' intervals, the
                # one that holds the settle time whole: from the first kept sample on, a
                # peak just after the settle time counted at some samplings only (the
                # differential's pinion_a: 1742.69 N at 5 samples a period, 1745.76 at 20
                # and 100, a reviewer); the interval's part before the settle time is at
                # most one sample long
                peak = max(peak, float(np.nanmax(s.history_peaks[keep, streamed[body]],
                                                 initial=-np.inf)))
            return {"body": body, "via": via.get(body), "frame": bearing_frame(
                        self.kinematics, body), "directions": directions,
                    "mean": [float(v) for v in mean],
                    "mean_magnitude": float(np.sqrt((mean ** 2).sum())),
                    "peak_magnitude": peak, "peak_streamed": body in streamed,
                    "samples": int(keep.sum()), **extra}

        for body, parts in by_body.items():
            forces = s.history_forces[keep][:, [c for _, c, _ in parts]]
            out.append(row(body, [d for d, _, _ in parts],
                           forces * np.array([sign for _, _, sign in parts])))
        # bodies held rigidly: the sum of their meshes' forces, in the housing's x, y, z;
        # their means from the meshes' streamed means where the span is the settled one
        mesh_means = None
        if rigid and self.success:
            try:
                met = self.metrics() if metrics is None else metrics
                if start_time is None or start_time == met.settling.start_time or (
                        self.periodic and self.period):
                    mesh_means = {r.mesh: r.mean_force for r in met.rows
                                  if math.isfinite(r.mean_force)}
            except (ValueError, ArithmeticError):
                mesh_means = None
        el, hist = self.structure.element_names, list(s.history_elements)
        for body, terms in rigid.items():
            if body in by_body or any(el.index(m) not in hist for m, _ in terms):
                continue
            f = s.history_forces[keep][:, [hist.index(el.index(m)) for m, _ in terms]]
            n = np.array([sign * np.asarray(self.kinematics.meshes[m].line_of_action, float)
                          for m, sign in terms])  # (meshes, 3): force on the body per N
            axes = [k for k in range(3) if np.any(np.abs(n[:, k]) > 1e-12)]
            exact = {}
            if mesh_means is not None and all(m in mesh_means for m, _ in terms):
                mean = np.array([mesh_means[m] for m, _ in terms]) @ n[:, axes]
                exact = {"mean": [float(v) for v in mean],
                         "mean_magnitude": float(np.sqrt((mean ** 2).sum()))}
            out.append(row(body, ["xyz"[k] for k in axes], (f @ n)[:, axes], held="rigid",
                           frame=rigid_frame(self.kinematics, terms), **exact))
        return out

    def mesh_force_history(self) -> tuple[np.ndarray, np.ndarray]:
        """Decimated time and mesh forces (n_samples, n_meshes) [s, N], for plots and
        exports (no metric is computed from it)."""
        s = self.solution
        el = self.structure.element_names
        cols = [list(s.history_elements).index(el.index(m)) for m in self.mesh_names]
        return s.history_t.copy(), s.history_forces[:, cols]  # (yours to change in place)

    # ------------------------------------------------------------------ export
    def to_dataset(self, definition: str | None = None):
        """The run as an :class:`xarray.Dataset` (units and long names on every variable;
        metrics of ``definition``, default the model's; warnings in its attributes)."""
        from .dataset import results_to_dataset

        return results_to_dataset(self, definition)

    def to_netcdf(self, path, *, overwrite: bool = False,
                  definition: str | None = None) -> Path:
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
            ds = self.to_dataset(definition)
            ds.attrs.update(files.provenance(claim.run_id, ds.attrs.get("model_json")))
            claim.write({plan.path: files.netcdf_bytes(ds)})
        return plan.path

    def save(self, path, *, overwrite: bool = False, definition: str | None = None) -> Path:
        """Save by suffix: ``.nc`` NetCDF, ``.mat`` MATLAB, ``.csv`` spreadsheet tables.

        Every file is written atomically and an existing one is kept unless
        ``overwrite`` (see :meth:`to_netcdf`).
        """
        from . import files

        plan = files.check_output(path, overwrite=overwrite)
        writer = {"netcdf": self.to_netcdf, "mat": self.to_mat, "csv": self.to_csv}[plan.format]
        return writer(plan.path, overwrite=overwrite, definition=definition)

    def to_mat(self, path, *, overwrite: bool = False, definition: str | None = None) -> Path:
        """Save for MATLAB (scipy.io.savemat): every variable of the Dataset, SI units,
        in the layout every command's .mat shares (:func:`export.mat_fields`: the
        ``names``, ``units``, ``descriptions``, ``dimensions`` and ``attributes`` structs,
        a ``provenance`` struct naming the run), the model, metrics and warnings and, for
        a steady state, a ``steady`` struct (period, stability, residual); written
        atomically."""
        from . import files

        plan = files.check_output(path, formats={".mat": "mat"}, overwrite=overwrite)
        with files.claim_output(plan) as claim:
            ds = self.to_dataset(definition)
            # the layout every command's .mat shares (export.mat_fields: the names,
            # units, dimensions, descriptions and attributes structs; a Python API
            # reviewer found a run's without the attributes a study's has); the sampling
            # note of a variable joins its description, as in the NetCDF
            from .export import mat_fields

            data = mat_fields(ds, claim.run_id, attrs={  # (the model and metrics: at the top)
                k: v for k, v in ds.attrs.items() if k not in ("model_json", "metrics_json")})
            for name, ident in data["names"].items():
                note = ds[name].attrs.get("sampling", "")
                if note:
                    data["descriptions"][ident] = " ".join(filter(None, (
                        data["descriptions"][ident], note)))
            data["units"].setdefault("time", "s")
            if "first_settled_cycle" in data["names"]:
                # MATLAB counts rows from 1: a reviewer's cycle_max_force(
                # first_settled_cycle:end, k) took in one cycle before the settled span
                ident = data["names"]["first_settled_cycle"]
                data["descriptions"][ident] += (
                    "; its row in the cycle arrays is first_settled_cycle + 1, e.g. "
                    "max(cycle_max_force(first_settled_cycle(k)+1:end, k)) is peak_force(k)")
            data["model_json"] = ds.attrs["model_json"]
            data["metrics_json"] = ds.attrs.get("metrics_json", "")
            # (none: an empty cell, which isempty() sees; {''} counted one warning)
            data["warnings"] = files.cell_column(self.warnings(definition))
            steady = _steady_summary(ds.attrs)
            if steady:  # (a reviewer's MATLAB had no stability and no period of it)
                data["steady"] = {k: (float(v) if isinstance(v, (int, float, np.number))
                                      else str(v)) for k, v in steady.items()}
            claim.write({plan.path: files.mat_bytes(data)})
        return plan.path

    def to_csv(self, path, *, overwrite: bool = False, definition: str | None = None) -> Path:
        """Save spreadsheet tables: ``NAME.csv`` (a row per mesh) and beside it
        ``NAME_groups.csv`` (a row per load-sharing group, then one for the system: what
        the run's group table and system line print), ``NAME_history.csv`` (the history's
        forces and torques, each column's unit in its name: ``m1_N``, ``shaft_Nm``),
        ``NAME_cycles.csv`` (start, peak, smallest and mean force and the largest and
        smallest instantaneous load-sharing ratio of every mesh cycle, as the .nc's
        ``cycle_*``; empty for a cycle the start or the end of the run cuts,
        :attr:`complete_cycles`, whose start may precede the run's;
        ``MESH_settled`` 1 for the cycles the metrics' peaks are over; a periodic
        state's: the cycles that begin in its period),
        ``NAME_bearings.csv`` (the bearing table: :meth:`bearing_forces`),
        ``NAME_elements.csv`` (a row per recorded element: its unit, frame and the
        fractions of the run with its clearance open and in back contact) and
        ``NAME_about.json`` (the run's provenance, model, warnings and metrics, and as
        ``run --json`` the bearing table and the planets' factors:
        :func:`files.about_bytes`).  The column names do not depend on the load-sharing
        definition: a column ``load_sharing_definition`` names it.

        All seven are written atomically, and none replaces an existing file unless
        ``overwrite``.  A run that did not finish has no metrics: its summary lists the
        meshes with empty metric columns and its status, its groups file the groups.
        """
        from . import files

        if definition is not None:
            self.check_definition(definition)  # (before any file is claimed)
        plan = files.check_output(path, formats={".csv": "csv"}, overwrite=overwrite)
        path = plan.path
        header = ["mesh", "group", "nominal_force_N", "static_force_N", "mean_force_N",
                  "peak_force_N", "min_force_N", "dynamic_factor",
                  "dynamic_factor_engineering", "peak_to_nominal", "load_sharing",
                  "load_sharing_definition", "contact_loss_fraction", "back_contact_fraction",
                  # (what the .nc has of each mesh: the CSV left them out, an exports
                  # reviewer)
                  "back_flank_force_N", "mesh_frequency_Hz", "double_flank",
                  "first_settled_cycle"]
        group_header = ["group", "meshes", "load_sharing", "load_sharing_definition",
                        "dynamic_factor", "peak_to_nominal",
                        "peak_to_nominal_engineering",  # G_it (Ji & Li eq. 19)
                        "settle_time_s"]
        frequency = {m: self.kinematics.meshes[m].frequency for m in self.mesh_names}
        try:
            met = self.metrics(definition) if self.success else None
        except (ValueError, ArithmeticError):
            met = None
        bearings: list[dict] = []
        steady_summary = None  # (computed once: the table and the about file use it)
        # which cycles the metrics are over (1: in the settled span), so that the table
        # gives the summary's peaks back (a spreadsheet user could not: the settle time
        # was only in the about file)
        settled_header, settled_columns = [], []
        if met is not None:
            n_cyc = self.solution.cycle_start.shape[0]
            settled_header = [f"{m}_settled" for m in self.mesh_names]
            # (and only where the mesh has a complete cycle: a mesh of fewer cycles than
            # the table's rows was flagged settled on its empty rows, an exports review)
            complete = self.complete_cycles
            settled_columns = [(np.arange(n_cyc) >= met.settling.first_cycle[m])
                               & complete[:, j] for j, m in enumerate(self.mesh_names)]
            name = met.definition
            rows = [[r.mesh, r.group, r.nominal_force, r.static_force, r.mean_force,
                     r.peak_force, r.min_force, r.dynamic_factor,
                     r.dynamic_factor_engineering, r.peak_to_nominal, r.load_sharing, name,
                     r.contact_loss, r.back_contact, r.back_flank_force, frequency[r.mesh],
                     int(r.double_flank), met.settling.first_cycle[r.mesh]]
                    for r in met.rows]
            rows = self._planet_columns(header, rows, met)
            steady = getattr(self, "steady", None)
            if steady is not None:  # the steady table's RMS transmission error too
                steady_summary = steady.summary(results=self)
                info = steady_summary["meshes"]
                header.append("rms_transmission_error_m")
                rows = [row + [info[row[0]]["rms_transmission_error"]] for row in rows]
            # each group's and the system's coefficients and factors: what the run's
            # group table and system line print
            d, ls_ = met.dynamic_factors, met.load_sharing
            group_rows = [[g, " ".join(members), ls_.per_group[g], name,
                           d.per_group_dynamic_factor[g], d.per_group_peak_to_nominal[g],
                           d.per_group_peak_to_nominal_engineering.get(g, ""),
                           met.settling.group_time.get(g, "")]
                          for g, members in ls_.groups.items()]
            group_rows.append(["(system)", " ".join(self.mesh_names), ls_.system, name, "",
                               "", "", met.settling.start_time])
            bearings = self.bearing_forces(met.settling.start_time, metrics=met)
        else:
            header.append("status")
            group_of = {m: g for g, ms in self.groups.items() for m in ms}
            nominal, static = self.nominal_forces(), self.static_forces()
            rows = [[m, group_of.get(m, ""), nominal[m], static[m]] + [""] * 11
                    + [frequency[m], "", ""] + [self.message] for m in self.mesh_names]
            group_rows = [[g, " ".join(ms)] + [""] * 6 for g, ms in self.groups.items()]
        # the bearing table, one column per direction of any support's frame
        directions = sorted({d for b in bearings for d in b["directions"]})
        bearing_header = (["body", "via", "frame"] + [f"mean_force_{d}_N" for d in directions]
                          + ["mean_force_magnitude_N", "peak_force_magnitude_N", "samples"])
        bearing_rows = [[b["body"], b["via"] or b.get("held", ""), b["frame"]]
                        + [dict(zip(b["directions"], b["mean"])).get(d, "") for d in directions]
                        + [b["mean_magnitude"], b["peak_magnitude"], b["samples"]]
                        for b in bearings]
        s = self.solution
        el = self.structure.element_names
        names = [el[i] for i in s.history_elements]
        units = element_units(self.structure)
        cols = [list(s.tracked_elements).index(el.index(m)) for m in self.mesh_names]
        summary, history, cycles, groups, bearing_file, elements, about = plan.files
        # every recorded element's contact state (a support or spline clearance open most
        # of the run was only in the .nc and .mat: the summary is per mesh)
        from .dataset import element_frames

        contents_elements = files.csv_bytes(
            ["element", "unit", "frame", "contact_loss_fraction", "back_contact_fraction"],
            [[n, units[i], f, s.separation_fraction[i], s.back_contact_fraction[i]]
             for n, i, f in zip(names, s.history_elements, element_frames(self, names))])
        n_hist = s.history_t.size
        cycle_rows = np.arange(s.cycle_start.shape[0])
        in_table = np.ones((cycle_rows.size, len(cols)), dtype=bool)  # by cycle and mesh
        if self.periodic and self.period:  # one period, as the .nc holds
            from .dataset import period_samples

            n_hist = period_samples(s.history_t, self.period) or n_hist
            # and the cycles that begin in it (the table listed every repetition of the
            # period in the record: 89 identical rows, a planetary reviewer; the .nc keeps
            # them, its metrics are recomputed from them)
            t0, eps = float(s.t_span[0]), 1e-9 * self.period
            start = s.cycle_start[:, cols]
            in_table = (start >= t0 - eps) & (start < t0 + self.period - eps)
            inside = in_table.any(axis=1)
            cycle_rows = np.flatnonzero(inside) if inside.any() else cycle_rows
            # a mesh's cells only where its own cycle begins in the period: a row is a
            # cycle index, which the slower meshes reach later (a period's rows held the
            # faster mesh's cycles and six repetitions of the slower one's, an exports
            # reviewer)
            in_table = in_table if inside.any() else np.ones_like(in_table)
        cycle_stats = self.complete_cycle_statistics()
        cycle_table = np.column_stack(
            [s.cycle_start[:, cols], *cycle_stats[:3], cycle_stats[4],
             np.where(self.complete_cycles, s.cycle_ratio_min[:, cols], np.nan)])
        cycle_table[~np.tile(in_table, 6)] = np.nan  # (six quantities per mesh, in order)
        contents = {
            groups: files.csv_bytes(group_header, group_rows),
            bearing_file: files.csv_bytes(bearing_header, bearing_rows),
            elements: contents_elements,
            history: files.csv_bytes(["time_s"] + [f"{n}_{units[i].replace(' ', '')}"
                                                   for n, i in zip(names, s.history_elements)],
                                     np.column_stack([s.history_t[:n_hist],
                                                      s.history_forces[:n_hist]]).tolist()),
            # (the instantaneous load-sharing ratio's extremes per cycle too, as the .nc
            # has them: the CSV left them out, a reviewer)
            cycles: files.csv_bytes(
                ["cycle"] + [f"{m}_{q}" for q in ("start_s", "peak_N", "min_N", "mean_N",
                                                  "ratio_max", "ratio_min")
                             for m in self.mesh_names] + settled_header,
                [[k] + row + [int(c[k]) if in_table[k, m] else ""
                              for m, c in enumerate(settled_columns)]
                 for k, row in zip(cycle_rows.tolist(), cycle_table[cycle_rows].tolist())]),
        }
        with files.claim_output(plan) as claim:
            steady_info = _steady_summary(self._steady_attributes(steady_summary))
            contents[about] = files.about_bytes(
                claim.run_id, self.model_json(), self.warnings(definition),
                **({"steady": steady_info} if steady_info else {}),
                load_sharing_definition=met.definition if met is not None else None,
                metrics=met.to_dict() if met is not None else None,
                # (the planets' factors and the bearing table, as --json gives them)
                **self._about_extras(met, bearings),
                history_samples_per_period=self.history_samples_per_period(),
                status=self.message, files=plan.files)
            contents[summary] = files.csv_bytes(header, rows)  # last: marks the set
            claim.write(contents)
        return path

    def _about_extras(self, met, bearings) -> dict:
        """The ``planet_load_sharing`` and ``bearing_forces_N`` entries of the about file
        (those ``run --json`` gives), where the run has them."""
        out: dict = {"bearing_forces_N": bearings} if bearings else {}
        if met is not None:
            from ..cli_support import planet_sharing, planet_sharing_dict

            k = planet_sharing(met.load_sharing, self.kinematics)
            if k is not None:
                out["planet_load_sharing"] = planet_sharing_dict(k)
        return out

    def _planet_columns(self, header: list, rows: list, met) -> list:
        """The CSV summary of a planetary model gets each mesh's stage K_gamma and its
        planet's factor (empty for a mesh of no planet); other models are unchanged."""
        from ..cli_support import planet_sharing

        k = planet_sharing(met.load_sharing, self.kinematics)
        if k is None:
            return rows
        header += ["K_gamma", "planet_factor"]  # (of load_sharing_definition)
        kin = self.kinematics
        out = []
        for row in rows:
            mk = kin.meshes.get(row[0])
            carrier = getattr(mk, "carrier", None)
            planet = next((b for b in (mk.driver, mk.driven) if b in k.per_planet), None) \
                if mk is not None else None
            out.append(row + [k.per_stage.get(carrier, ""),
                              k.per_planet.get(planet, "") if planet else ""])
        return out

    def write_figures(self, directory, formats=("png", "svg"), **kwargs):
        """Write the report figures (see :func:`torquesplit.plot.write_figures`)."""
        from ..plot import write_figures

        return write_figures(self, directory, formats, **kwargs)

    def model_json(self) -> str:
        from ..model.io import model_to_json

        return model_to_json(self.model)


def bearing_round_off(bearings: list[dict]) -> float:
    """The bearing force below which a table writes 0 [N]: 1e-9 of the largest peak, the
    round-off of a force that cancels (the sun of a symmetric planetary stage: x 6e-17
    kN).  One bound for the terminal and the report (the report's 1e-6 wrote a real
    0.5 N of a 600 kN drive as 0, an exports review)."""
    return 1e-9 * max((b["peak_magnitude"] for b in bearings), default=0.0)


def default_definition(model) -> str:
    """The dynamic load-sharing definition a run of ``model`` reports by default: its
    ``[analysis] load_sharing``, or :data:`STANDARD_DEFINITION` for the quasi-static
    ``static_torque``."""
    chosen = model.analysis.load_sharing
    return STANDARD_DEFINITION if chosen in ("static", "static_torque") else chosen


def _bearing_elements(element_names, model) -> dict[str, list[tuple[str, int, float]]]:
    """Supported body -> its bearing elements' (direction, element index, sign), as
    :meth:`Results.support_columns` describes them (by element, not history column)."""
    index = {n: i for i, n in enumerate(element_names)}
    out: dict[str, list[tuple[str, int, float]]] = {}
    for i, n in enumerate(element_names):
        if ".support." in n:
            body, direction = n.split(".support.", 1)
            out.setdefault(body, []).append((direction, i, 1.0))
    for name, spline in getattr(model, "splines", {}).items():
        body = spline.connects[1]
        if body in out:
            continue
        for direction in ("x", "y"):
            e = f"{name}.radial.{direction}"
            if e in index:
                out.setdefault(body, []).append((direction, index[e], -1.0))
    return out


def bearing_vectors(element_names, model, kin) -> dict[str, list[tuple[int, np.ndarray]]]:
    """Per body of the bearing table, its bearing force as a sum of element forces times
    directions (element index, (3,)): the run streams each one's magnitude
    (``integrate``'s ``history_peaks``) for the table's peaks.  A support's directions
    are the body's own axes, each element one of them (the table's magnitude is over its
    columns); a rigid bearing's are its meshes' lines of action, signed as
    :func:`rigid_bearings` says."""
    out: dict[str, list[tuple[int, np.ndarray]]] = {}
    for body, parts in _bearing_elements(element_names, model).items():
        if len(parts) <= 3:  # (x, y, z at most)
            out[body] = [(e, sign * np.eye(3)[k]) for k, (_, e, sign) in enumerate(parts)]
    index = {n: i for i, n in enumerate(element_names)}
    for body, terms in rigid_bearings(model, kin).items():
        if body not in out and all(m in index for m, _ in terms):
            out[body] = [(index[m], sign * np.asarray(kin.meshes[m].line_of_action, float))
                         for m, sign in terms]
    return out


def rigid_bearings(model, kin) -> dict[str, list[tuple[str, float]]]:
    """Bodies held rigidly (no translational DOF) that mesh -> their meshes and the sign
    that turns a mesh's force along its line of action into the force on the body (+1
    driven, -1 driver): their bearing carries the sum (a reviewer's pinions on
    torsion-only shafts carried the largest radial loads and had no bearing row).  A
    body whose meshes are analysed in one turning carrier's frame (the fixed ring of a
    planetary stage) has its sum in that frame, as the planets' bearings
    (:func:`rigid_frame`; it had no row: a planetary reviewer missed the ring's load).
    Left out: a body meshing in several turning frames, and one on a rigid shaft with a
    body that has translations (its load goes to that body's bearings)."""
    def translates(name) -> bool:
        items = model.gears if name in getattr(model, "gears", {}) else model.bodies
        return any(d != "theta" for d in getattr(items.get(name), "dofs", ("theta",)))

    # a body on a rigid shaft with one that has translations: its load goes to that one's
    # bearings (Dong et al. 2021's O1b beside O1), not to a bearing of its own
    joined = {b for sh in getattr(model, "shafts", {}).values() if sh.rigid
              for a, b in (sh.connects, sh.connects[::-1]) if translates(a)}
    out: dict[str, list[tuple[str, float]]] = {}
    for items in (getattr(model, "gears", {}), getattr(model, "bodies", {})):
        for name in items:
            if translates(name) or name in joined:
                continue
            terms = [(m, 1.0 if mk.driven == name else -1.0) for m, mk in kin.meshes.items()
                     if name in (mk.driver, mk.driven)]
            turning = {kin.meshes[m].carrier for m, _ in terms if kin.meshes[m].carrier
                       and kin.bodies[kin.meshes[m].carrier].speed}
            if terms and len(turning) <= 1:  # (directions that turn with one carrier)
                out[name] = terms
    return out


def rigid_frame(kin, terms) -> str:
    """The frame a rigid bearing's force (:func:`rigid_bearings`) is written in: that of
    its meshes' lines of action, a turning carrier's where they turn with it."""
    from ..model.kinematics import frame_label

    for m, _ in terms:
        c = kin.meshes[m].carrier
        if c and kin.bodies[c].speed:
            return frame_label(c)
    return frame_label(None)


def bearing_bodies(structure, model, kin=None) -> list[str]:
    """The bodies a run's bearing table lists (:meth:`Results.bearing_forces`), in its
    order, from the assembled ``structure`` and the kinematics alone (no run needed: a
    study checks its output names with it)."""
    if kin is None:
        from ..model.kinematics import solve_kinematics

        kin = solve_kinematics(model)
    held = list(_bearing_elements(structure.element_names, model))
    return held + [b for b in rigid_bearings(model, kin) if b not in held]


def back_flank_force(cycle_min: np.ndarray) -> float:
    """Largest back-flank (tensile) force [N] from the per-cycle smallest forces."""
    smallest = -ls._nanmax(-np.asarray(cycle_min, dtype=float))
    return max(0.0, -smallest) if math.isfinite(smallest) else 0.0


def open_results(path):
    """Open a results file written by :meth:`Results.to_netcdf` (or any ``.nc`` file
    torquesplit writes: quasi-static, modes, sweeps, studies) as an xarray Dataset.

    Raises
    ------
    ValueError
        The file is not a NetCDF file (a ``.mat`` or ``.csv`` of torquesplit is read with
        ``scipy.io.loadmat`` or a spreadsheet): said so, not h5py's "file signature not
        found".
    """
    import xarray as xr

    try:
        return xr.open_dataset(path, engine="h5netcdf")
    except OSError as exc:
        if not Path(path).is_file():
            from ..errors import MissingFileError, OutputError
            from ..study.store import STORE_NAME

            where = Path(path)
            if (where / STORE_NAME).is_file():
                raise OutputError(
                    f"{path}: a study's folder, not a run's results file; "
                    f"torquesplit.study.load_results({str(path)!r}) gives the study's "
                    f"Dataset (its results.nc)") from None
            what = ("a folder, not a results file" if where.is_dir() else
                    "no such file" if where.parent.is_dir() else
                    f"no such file (nor the folder {where.parent})")
            error = OutputError if where.is_dir() else MissingFileError
            raise error(f"{path}: {what}; give the .nc file a run saved "
                        f"(torquesplit run --out NAME.nc, or res.save('NAME.nc'))") from None
        raise OptionError(
            f"{path}: not a NetCDF results file ({exc}); open_results and load_results "
            f"read the .nc files torquesplit writes (a .mat opens with scipy.io.loadmat, a "
            f".csv set with a spreadsheet or pandas)") from None


def load_results(path):
    """A :class:`Results` from a results file written by :meth:`Results.to_netcdf`
    (``torquesplit run --out F.nc``): the embedded model, the run's statistics and
    histories (see :func:`torquesplit.results.dataset.results_from_dataset`)."""
    from .dataset import results_from_dataset

    with open_results(path) as ds:
        ds.load()
        try:
            return results_from_dataset(ds)
        except OptionError as exc:  # (which file: 'report s.nc' did not say)
            raise type(exc)(f"{path}: {exc}") from None


def model_from_results(dataset):
    """Re-create the model embedded in a results Dataset."""
    from ..model.io import load_model

    return load_model(json.loads(dataset.attrs["model_json"]))
