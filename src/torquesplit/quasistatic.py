"""Quasi-static load sharing: equilibrium at each mesh position (Mo et al. 2017).

At every time of a sweep over the common period of the excitations (the errors turn with
their gears: the positions repeat only when every gear is back where it started), the
static equilibrium of the assembled system is solved with the mesh stiffness, the
errors (eccentricity, run-out... as functions of rotation) and the clearances at that
position: displacement compatibility with floating members and loss of contact.  The
result gives the static torque ratios of Mo et al. 2017 eqs. 14-15 and the floating orbits of
the members with translational DOFs.
"""

from __future__ import annotations

import json
import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import _json
from .assembly.structure import dof_units
from .errors import ModelWarning, OptionError, SolverError, warn_user
from .metrics import load_sharing as ls
from .model.io import load_model
from .model.kinematics import solve_kinematics


@dataclass
class QuasiStaticResults:
    """Equilibria over a sweep of mesh positions."""

    model: object
    kinematics: object
    structure: object
    solution: object
    kept_warnings: list = field(default_factory=list)
    """Warnings kept with the sweep as text (the command line puts the model's in too);
    empty: :meth:`warnings` derives them from the results."""

    def __repr__(self) -> str:
        sol = self.solution
        stopped = f", stopped after {sol.times.size} of {sol.planned}" if getattr(
            sol, "interrupted", False) else ""
        span = float(sol.times[-1] - sol.times[0]) if sol.times.size else 0.0
        return (f"QuasiStaticResults({self.model.model.name!r}: {sol.times.size} mesh "
                f"positions over {span:.4g} s{stopped}, "
                f"{'all' if sol.converged.all() else 'NOT all'} converged, "
                f"{len(self.mesh_names)} meshes)")

    def warnings(self) -> list[str]:
        """Every warning of the sweep, each ``"location: message"``, as
        :meth:`torquesplit.results.Results.warnings` gives a run's: those kept with it,
        else the plausibility of its results
        (:func:`torquesplit.results.plausibility.static_warnings`)."""
        if self.kept_warnings:
            return list(self.kept_warnings)
        from .results.plausibility import static_warnings

        return [f"{loc}: {msg}" for loc, msg in static_warnings(self)]

    @property
    def mesh_names(self) -> list[str]:
        return list(self.model.meshes)

    @property
    def times(self) -> np.ndarray:
        return self.solution.times

    def mesh_forces(self) -> np.ndarray:
        """(n_times, n_meshes) mesh forces [N]."""
        el = self.structure.element_names
        return self.solution.element_forces[:, [el.index(m) for m in self.mesh_names]]

    def metrics(self, definition: str | None = None) -> ls.LoadSharing:
        """Static torque ratios per mesh, group and system (Mo et al. 2017 eqs. 14-15).

        ``definition`` may be given as a dynamic run's ``metrics`` takes it: only
        ``"static_torque"`` (``"static"``), the one a quasi-static sweep has.  The
        result is the load sharing itself; its ``.load_sharing`` is the same object, so
        ``metrics().load_sharing.system`` reads a run and a sweep alike."""
        if definition not in (None, "static_torque", "static"):
            from .errors import OptionError

            raise OptionError(f"a quasi-static sweep has the 'static_torque' load sharing "
                              f"only, not {definition!r}; the dynamic definitions are a "
                              f"run's: torquesplit.simulate(model).metrics({definition!r})")
        groups = ls.group_meshes(self.structure.metadata["meshes"])
        return ls.static_torque(self.times, self.mesh_forces(), self.mesh_names, groups)

    def orbits(self) -> dict[str, np.ndarray]:
        """Floating orbit (n_times, 2) [m] of every body with x and y DOFs, relative to
        its bearing's seat: a planet's to its pin's nominal place on the (turning,
        twisted) carrier, pin error included, not the pin's own motion with the carrier's
        rotation (which depends on what else the model holds); a body on the housing's
        or held by a spline: its own displacement."""
        out = {}
        s = self.structure
        dmap = s.metadata["dof_map"]
        q = self.solution.q
        for body, tr in dmap.translation.items():
            if "x" not in tr or "y" not in tr:
                continue
            cols = []
            for d in ("x", "y"):
                name = f"{body}.support.{d}"
                if name in s.element_names:  # V q of its support: u - u_seat
                    e = s.element_names.index(name)
                    sl = slice(s.v_ptr[e], s.v_ptr[e + 1])
                    cols.append(q[:, s.v_dof[sl]] @ np.asarray(s.v_coef[sl]))
                else:
                    cols.append(q[:, tr[d]])
            out[body] = np.stack(cols, axis=-1)
        return out

    def to_dataset(self):
        """The sweep as an xarray Dataset with units and long names."""
        import xarray as xr

        from .model.io import model_to_json
        from .results.dataset import FLAG

        met = self.metrics()
        forces = self.mesh_forces()
        group_of = {m: g for g, ms in met.groups.items() for m in ms}
        ds = xr.Dataset(
            {
                # (per mesh first: a .csv set's NAME.csv is then a row per mesh, as a
                # run's is, and the positions are NAME_history.csv)
                "load_sharing": (("mesh",), [met.per_mesh[m] for m in self.mesh_names],
                                 {"units": "1",
                                  "long_name": "static torque ratio, largest over positions"}),
                # what the command's mesh table prints (the files held only load_sharing),
                # named as a run's files name them (peak_force, load_sharing_group,
                # load_sharing_system: this file said max_force, group_load_sharing and
                # had the system's coefficient as an attribute only)
                **{f"{k}_force": (("mesh",), f(forces, axis=0), {
                    "units": "N", "long_name": f"{word} quasi-static mesh force over the "
                                              f"positions"})
                   for k, word, f in (("min", "smallest", np.min), ("mean", "mean", np.mean),
                                      ("peak", "largest", np.max))},
                "mesh_force": (("time", "mesh"), forces,
                               {"units": "N", "long_name": "quasi-static mesh force"}),
                "load_sharing_group": (("group",), [met.per_group[g] for g in met.groups],
                                       {"units": "1", "long_name": "static torque ratio of "
                                        "the group: its largest member's"}),
                "load_sharing_system": ((), float(met.system),
                                        {"units": "1", "long_name": "static torque ratio of "
                                         "the system"}),
                "displacement": (("time", "dof"), self.solution.q,
                                 {"units": "m or rad", "long_name": "static displacement"}),
                "converged": (("time",), self.solution.converged.astype(np.int8),
                              {"units": "1", "long_name": "equilibrium converged (1) or not",
                               **FLAG}),
            },
            coords={"time": ("time", self.times, {"units": "s", "long_name": "time"}),
                    "mesh": ("mesh", self.mesh_names),
                    "mesh_group": ("mesh", [group_of.get(m, "") for m in self.mesh_names],
                                   {"long_name": "load-sharing group of each mesh"}),
                    "group": ("group", list(met.groups)),
                    "dof": ("dof", list(self.structure.dof_names)),
                    "dof_unit": ("dof", dof_units(self.structure),
                                 {"long_name": "unit of each DOF's displacement"})},
            attrs={"title": f"torquesplit quasi-static: {self.model.model.name}",
                   "warnings": "\n".join(self.warnings()),
                   "warnings_json": json.dumps(self.warnings()),
                   "load_sharing_definition": "static_torque",
                   # (the system's coefficient is the variable load_sharing_system; an
                   # attribute system_load_sharing beside it said it twice, an exports
                   # review)
                   "model_json": model_to_json(self.model),
                   "metrics_json": _json.dumps({"per_mesh": met.per_mesh,
                                                "per_group": met.per_group,
                                                "system": met.system})},
        )
        from .results.dataset import add_planet_load_sharing

        return add_planet_load_sharing(ds, met, self.kinematics)

    def to_netcdf(self, path, *, overwrite: bool = False):
        """Save as NetCDF, atomically, keeping an existing file unless ``overwrite``; the
        attributes say which run wrote it (see :mod:`torquesplit.results.files`)."""
        from .results import files

        files.check_output(path, formats=files.NETCDF_FORMATS, overwrite=overwrite)
        return self.save(path, overwrite=overwrite)

    def write_figures(self, directory, formats=("png", "svg"), **kwargs) -> list:
        """Write every figure of the sweep into ``directory``, as ``torquesplit static
        --plots`` does (:func:`torquesplit.plot.write_static_figures`); returns the paths."""
        from .plot import write_static_figures

        return write_static_figures(self, directory, formats, **kwargs)

    def save(self, path, *, overwrite: bool = False):
        """Save by suffix: ``.nc`` NetCDF, ``.mat`` MATLAB, ``.csv`` spreadsheet tables
        named as a run's are (``NAME.csv`` a row per mesh, ``NAME_groups.csv`` a row per
        load-sharing group and one for the system, ``NAME_history.csv`` a row per
        position; see :mod:`torquesplit.results.export`); atomically, an existing file
        kept unless ``overwrite``.  Returns the path written."""
        from .results.export import DATASET_FORMATS, save_dataset

        ds = self.to_dataset()
        if DATASET_FORMATS.get(Path(path).suffix.lower()) == "table":
            ds = system_as_group_row(ds)
        return save_dataset(ds, path, overwrite=overwrite)


def system_as_group_row(ds):
    """``ds`` with the system's coefficient as the ``(system)`` row of the groups, as a
    run's NAME_groups.csv has it: a scalar is a column of the first table, which repeated
    it on every row (an exports review)."""
    import xarray as xr

    if "load_sharing_system" not in ds or "load_sharing_group" not in ds:
        return ds
    system = ds["load_sharing_group"].isel(group=[0]).copy(
        data=[float(ds["load_sharing_system"])]).assign_coords(group=["(system)"])
    groups = xr.concat([ds["load_sharing_group"], system], dim="group")
    out = ds.drop_vars(["load_sharing_system", "load_sharing_group"]).drop_dims("group")
    out["load_sharing_group"] = groups
    return out


def slowest_gear(kin) -> tuple[str, float, str | None]:
    """``(gear, |speed| [rad/s], carrier or None)``: the slowest turning of a gear in its
    mesh's frame (a planet mesh: its carrier's; a held ring stands still in the housing
    but turns in the carrier's frame), whose revolutions a sweep counts."""
    best: tuple[str, float, str | None] | None = None
    for mk in kin.meshes.values():
        for gear, w in ((mk.driver, mk.driver_speed), (mk.driven, mk.driven_speed)):
            if w and math.isfinite(w) and (best is None or abs(w) < best[1]):
                best = (gear, abs(w), mk.carrier)
    if best is None:
        raise SolverError("no gear turns: a quasi-static sweep needs a turning mesh")
    return best


MAX_REVOLUTIONS = 100.0
"""Longest default sweep in revolutions of the slowest gear: the common period of a
hunting-tooth train can be thousands (the sweep then says what it covers)."""


def quasi_static_load_sharing(model, *, revolutions: float | None = None,
                              points_per_cycle: int = 32, max_points: int = 20000,
                              progress=None) -> QuasiStaticResults:
    """Equilibria over whole common periods of the excitations (default: errors, stiffness
    and backlash tables, :func:`torquesplit.steady.period.fundamental_period`), at least
    one revolution of the slowest gear and at most :data:`MAX_REVOLUTIONS` (said when cut),
    or over ``revolutions`` of the slowest gear (in its mesh's frame: relative to the
    carrier for a planet mesh), at ``points_per_cycle`` positions per cycle of the fastest
    excitation (the fastest mesh when nothing varies; more where the meshes' phase offsets
    need it for each to sample the same phases: :func:`_positions_per_cycle`), at most
    ``max_points`` (said when that thins them).

    A shorter sweep sees only some of the error combinations: its largest ratios are too
    small and its mean forces unequal (Mo et al. 2017's example repeats every 25
    revolutions of its slowest gear).  ``progress``, if given, is called with the
    fraction of positions done."""
    from .assembly.assemble import assemble
    from .solve.static import quasi_static
    from .steady.period import excitation_sources

    # (0 positions divided by zero, -1 gave an empty sweep, 0 points a cycle 16 positions
    # silently, a string or 2.5 a TypeError)
    for name, value, example in (("points_per_cycle", points_per_cycle, 32),
                                 ("max_points", max_points, 20000)):
        if (isinstance(value, bool) or not isinstance(value, numbers.Real)
                or not float(value).is_integer() or value < 1):
            raise OptionError(f"{name} must be a whole number >= 1, got {value!r}; give "
                              f"e.g. {name}={example}")
    if revolutions is not None and (isinstance(revolutions, bool) or not isinstance(
            revolutions, numbers.Real) or not (0 < revolutions < math.inf)):
        raise OptionError(f"revolutions must be a positive number, got {revolutions!r}; "
                          f"give e.g. revolutions=1 (of the slowest gear)")
    points_per_cycle, max_points = int(points_per_cycle), int(max_points)
    if not hasattr(model, "meshes"):
        model = load_model(model)
    kin = solve_kinematics(model)
    structure = assemble(model, kin)
    turn = 2 * math.pi / slowest_gear(kin)[1]  # one revolution of the slowest gear [s]
    if revolutions is None:
        period = _excitation_period(structure, turn)
    else:
        period = revolutions * turn
        _warn_part_period(structure, turn, revolutions)
    sources = excitation_sources(structure)
    f_max = (max(x.frequency for x in sources) if sources
             else max(mk.frequency for mk in kin.meshes.values()))
    per_cycle = _positions_per_cycle(structure, f_max, points_per_cycle)
    cycles = period * f_max
    # (a whole number of cycles read as one: float noise must not add a position)
    cycles = round(cycles) if abs(cycles - round(cycles)) < 1e-9 * cycles else cycles
    wanted = max(16, math.ceil(cycles * per_cycle))
    n = int(min(max_points, wanted))
    if n < wanted:
        warn_user(
            f"the quasi-static sweep is cut to max_points = {max_points} positions, "
            f"{n / (period * f_max):.3g} per cycle of the fastest excitation ({f_max:.6g} "
            f"Hz) instead of {per_cycle}; raise max_points (--max-points; a study's "
            f"[analysis] max_points) or give fewer revolutions for the full density",
            ModelWarning)
    times = np.arange(n) * (period / n)
    sol = quasi_static(structure, times, progress=progress)
    _refuse_out_of_mesh(model, structure, sol)
    return QuasiStaticResults(model=model, kinematics=kin, structure=structure, solution=sol)


def _refuse_out_of_mesh(model, structure, sol) -> None:
    """A gear translated beyond its tooth depth at any converged position: refused as
    ``check`` and ``run`` refuse it (:func:`~torquesplit.model.checks.deflection_issues`)."""
    from .model.checks import refuse_out_of_mesh

    q = np.asarray(sol.q, dtype=float)
    conv = np.asarray(sol.converged, bool)
    if conv.any():
        refuse_out_of_mesh(model, structure, np.abs(q[conv]).max(axis=0))


def _positions_per_cycle(structure, f_max: float, points_per_cycle: int,
                         most: int = 64) -> int:
    """``points_per_cycle`` made a multiple of the denominators of the meshes' phase
    offsets (sequentially phased planets, branches 120 deg apart: thirds of a cycle), so
    that every mesh of the fastest frequency samples the same phases of its cycle: its
    position-averaged load is then that of the others exactly, not up to a sampling error
    of the stiffness steps (0.24 % on K_gamma for three planets at 32).
    The least common multiple keeps every position the density gave (a factor of at most
    4), else the density is rounded up to a multiple.  Offsets with no denominator up to
    ``most`` leave the density as it is."""
    from fractions import Fraction

    f = np.asarray(structure.frequency, dtype=float)
    fast = np.flatnonzero(np.abs(f - f_max) <= 1e-9 * f_max)
    if fast.size < 2:
        return points_per_cycle
    offsets = np.mod(np.asarray(structure.phase, dtype=float)[fast] - structure.phase[fast[0]],
                     1.0)
    grid = 1
    for x in offsets:
        q = Fraction(float(x)).limit_denominator(most)
        if abs(float(q) - x) < 1e-9:
            grid = math.lcm(grid, q.denominator)
    both = math.lcm(points_per_cycle, grid)
    if both > 4 * points_per_cycle:
        both = math.ceil(points_per_cycle / grid) * grid
    return both


def _warn_part_period(structure, turn: float, revolutions: float) -> None:
    """Say that ``revolutions`` of the slowest gear cover less than one common period of
    the excitations: the sweep then sees only some of the error combinations (a studies
    reviewer's one revolution of Mo et al. 2017's errors gave 1.045 where their whole
    period gives 1.048, without a word)."""
    from .steady.period import PeriodError, fundamental_period

    try:
        per = fundamental_period(structure, max_cycles=None)
    except PeriodError:
        return
    if per.frequency <= 0:  # nothing varies: every position is the same
        return
    whole = 1.0 / (per.frequency * turn)  # the common period [revolutions]
    if revolutions < whole * (1 - 1e-9):
        warn_user(f"revolutions = {revolutions:g} covers part of the excitations' common "
                  f"period, {whole:.6g} revolutions of the slowest gear: the sweep sees "
                  f"only some combinations of the excitations (errors, stiffness and "
                  f"backlash tables), so its largest ratios may be too small and its mean "
                  f"forces unequal; leave revolutions out for whole periods", ModelWarning)


def _excitation_period(structure, turn: float) -> float:
    """Whole common periods of the excitations [s] covering at least ``turn`` (one
    revolution of the slowest gear: the orbits and figures go round once), at most
    MAX_REVOLUTIONS x ``turn`` (also when no common period exists), said when cut."""
    from .steady.period import PeriodError, fundamental_period

    cap = MAX_REVOLUTIONS * turn
    try:
        per = fundamental_period(structure, max_cycles=None)
    except PeriodError as exc:
        why = f"the excitations have no common period ({exc})"
    else:
        if per.frequency <= 0:  # nothing varies: every position is the same
            return turn
        period = 1.0 / per.frequency
        if period <= cap * (1 + 1e-9):  # whole periods, at least one revolution
            return period * max(1, math.ceil(turn / period - 1e-9))
        why = (f"the excitations repeat only every {period / turn:.6g} revolutions of the "
               f"slowest gear")
    warn_user(f"{why}; the quasi-static sweep covers {MAX_REVOLUTIONS:g} revolutions of "
                  f"the slowest gear: give revolutions to choose", ModelWarning)
    return cap
