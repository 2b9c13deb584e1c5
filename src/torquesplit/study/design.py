"""A study's design resolved against its model: parameters in SI and the value of every case.

:func:`resolve` turns a :class:`~torquesplit.study.spec.StudySpec` into a :class:`Plan`:
the base model data (model file + ``[set]``), the validated base model and its hash, the
requested output names, the analysis settings in SI, and a :class:`Design` that knows
every case's parameter values.  Everything that can be wrong with a study file is found
here, before any case runs.

Case ``i`` depends only on the study file and ``i`` (never on the number of workers or
the order in which cases finish): grid cases are the C-order product of the axes;
Monte Carlo draws all ``n`` points of the sampler at once from the seed (a prefix of a
longer draw for random and Sobol sampling, so a stopping rule can extend it); Morris
trajectories and Sobol (Saltelli) matrices likewise.
"""

from __future__ import annotations

import hashlib
import inspect
import itertools
import json
import math
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import TorquesplitError, warn_user
from ..model.io import load_model, model_from_dict, model_to_dict
from ..model.overrides import apply_overrides, read_raw
from . import outputs as out_mod
from . import paths as P
from .errors import StudyError
from .spec import StudySpec


# ============================================================================ parameters
@dataclass(frozen=True)
class Parameter:
    """One varied quantity and the model fields it writes."""

    name: str
    fields: tuple[P.Field, ...]
    mode: str
    """"set": every field takes the value; "scale": each field's model value x the value."""
    base: tuple[float, ...] = ()
    """Model values of the fields (SI), for "scale"."""
    display_unit: str | None = None
    """Unit the study file wrote its values in (for plots and tables)."""

    @property
    def kind(self) -> str | None:
        return None if self.mode == "scale" else self.fields[0].kind

    @property
    def unit(self) -> str:
        """SI unit of the parameter's values ("1" for factors and plain numbers)."""
        return P.si_unit(self.kind)

    @property
    def paths(self) -> list[str]:
        return [f.path for f in self.fields]

    def overrides(self, value: float) -> dict:
        """``{path: value}`` for the model data (SI numbers)."""
        out = {}
        for i, f in enumerate(self.fields):
            v = value * self.base[i] if self.mode == "scale" else value
            out[f.path] = int(round(v)) if f.integer else float(v)
        return out

    def show(self, value: float) -> str:
        """A value as the study file wrote it: in its unit ("-30 um", not "-3e-05")."""
        if self.mode == "scale" or self.kind is None:
            return f"{value:g}" + (" (factor)" if self.mode == "scale" else "")
        unit = self.display_unit or self.unit
        if unit != self.unit:
            from ..model.units import convert

            try:
                return f"{convert(value, self.unit, unit):.6g} {unit}"
            except Exception:  # a unit pint cannot convert: SI
                pass
        return f"{value:.6g} {self.unit}"

    def describe(self) -> str:
        what = "scales" if self.mode == "scale" else "sets"
        paths = self.paths
        shown = ", ".join(paths[:4]) + (f" and {len(paths) - 4} more" if len(paths) > 4 else "")
        if self.mode != "scale" and list(paths) == [self.name]:
            return self.name  # (not "x sets x")
        return f"{self.name} {what} {shown}"


@dataclass
class Design:
    """Every case of a study: ``values[i]`` are the parameter values of case ``i``."""

    kind: str
    parameters: list[Parameter]
    values: np.ndarray
    """(n_cases, n_parameters) SI values (factors for scales)."""
    shape: tuple[int, ...] = ()
    """Grid: the number of values of each axis."""
    axes: list[np.ndarray] = field(default_factory=list)
    """Grid: the values of each axis."""
    extra: dict = field(default_factory=dict)
    """Sensitivity: the sampling scheme (see :mod:`torquesplit.study.sensitivity`)."""

    @property
    def n_cases(self) -> int:
        return int(self.values.shape[0])

    def overrides(self, i: int) -> dict:
        out = {}
        for p, v in zip(self.parameters, self.values[i], strict=True):
            out.update(p.overrides(float(v)))
        return out


@dataclass
class Plan:
    """A study ready to run."""

    spec: StudySpec
    source: str | None
    study_text: str
    model_source: str
    base_data: dict
    """The model file's data with ``[set]`` applied, as written (units as strings)."""
    case_data: dict
    """The same model as SI numbers (validated once here): what each case starts from,
    so that a case does not parse units again (the round trip is exact; tested)."""
    model: object
    model_hash: str
    model_dict: dict
    study_hash: str
    outputs: list[str]
    definitions: list[str]
    analysis: dict
    design: Design
    notes: list[str] = field(default_factory=list)
    """Cases found invalid before the study runs (a grid parameter at its smallest or
    largest value): they will be recorded as refused; said before any case runs."""

    @property
    def n_cases(self) -> int:
        return self.design.n_cases

    def __repr__(self) -> str:
        d = self.design
        shape = " x ".join(map(str, d.shape)) if len(d.shape) > 1 else ""
        params = ", ".join(p.name for p in d.parameters)
        count = f"{shape} = {d.n_cases} cases" if shape else f"{d.n_cases} cases"
        return (f"<Plan of {self.spec.study.name!r}: {d.kind} over {params} ({count}), "
                f"{self.analysis.get('type', 'run')} of "
                f"{self.model_source}, outputs {', '.join(self.outputs[:6])}"
                f"{' ...' if len(self.outputs) > 6 else ''}>")


# ============================================================================ resolve
class _Problems:
    """Every problem of a study file, collected, so that the file is refused with all of
    them at once (a reviewer fixed eight mistakes in eight attempts)."""

    def __init__(self):
        self.items: list[tuple[str, str]] = []

    def attempt(self, function, *args, **kwargs):
        """``function(*args, **kwargs)``, or None with its StudyError's problems kept."""
        try:
            return function(*args, **kwargs)
        except StudyError as exc:
            self.items.extend(exc.problems)
            return None

    def raise_any(self) -> None:
        if self.items:
            raise StudyError.of(self.items)


def resolve(spec: StudySpec, folder: Path | None, text: str, source: str | None = None) -> Plan:
    """Check a study against its model and compute every case's values (no case runs)."""
    try:
        return _resolve(spec, folder, text, source)
    except StudyError as exc:
        raise exc.with_source(source) from None


def _resolve(spec, folder, text, source) -> Plan:
    model_source, raw = _model_data(spec.study.model, folder)
    try:
        base = apply_overrides(raw, spec.set)
    except TorquesplitError as exc:
        raise StudyError("set", _one_line(exc)) from None
    model = _validated(base, model_source, "set" if spec.set else "study.model")
    canon = model_to_dict(model)
    model_hash = _hash(canon)
    # the checks below do not depend on each other: every problem is said at once
    problems = _Problems()
    analysis = problems.attempt(_analysis, spec)
    if analysis is not None and analysis["type"] == "run":
        problems.attempt(_long_enough, model, analysis)
    chosen = problems.attempt(_outputs, spec, model, spec.analysis.type)
    kind = spec.design
    problems.attempt(_check_generated_paths, spec, model)
    if kind == "grid":
        design = problems.attempt(_grid, spec, base)
    elif kind == "monte_carlo":
        design = problems.attempt(_monte_carlo, spec, base, model)
    else:
        from .sensitivity import sensitivity_design

        factors = problems.attempt(_sensitivity_parameters, spec, base)
        design = (problems.attempt(sensitivity_design, spec.sensitivity, factors)
                  if factors is not None else None)
    problems.raise_any()
    outputs, definitions = chosen
    # probe: a study whose first case gives an invalid model is refused (almost always a
    # mistake in the file); an invalid later case is recorded as refused when it runs,
    # and one where a parameter takes its smallest or largest value is said now
    cases = _probe_cases(design)
    _validated(apply_overrides(base, design.overrides(0)), model_source,
               f"{kind}.parameters", case=0, design=design, deep=True)
    notes = []
    for case in cases[1:]:
        try:
            _validated(apply_overrides(base, design.overrides(case)), model_source,
                       f"{kind}.parameters", case=case, design=design)
        except StudyError as exc:
            notes.append(f"{exc}; it will be recorded as refused (the other cases run)")
    notes += _idle_phases(design, model, kind) + _mesh_count_notes(design, kind)
    canonical = spec.canonical()
    # a [[planetary]] stage's fields exist in the file's own data only (the validated copy
    # holds the elements the stage generated): cases varying one start from that data
    # (its units parsed per case), others from the SI copy
    paths = [f.path for prm in design.parameters for f in prm.fields]
    case_data = base if any(q.split(".")[0] == "planetary" for q in paths) else canon
    return Plan(spec=spec, source=source, study_text=text, model_source=model_source,
                base_data=base, case_data=case_data, model=model, model_hash=model_hash,
                model_dict=canon,
                study_hash=_hash(canonical), outputs=outputs, definitions=definitions,
                analysis=analysis, design=design, notes=notes)


def _mesh_count_notes(design, kind: str) -> list[str]:
    """A note where a parameter changes how many meshes the model has (a stage's planet
    count): the outputs are named from the base model's meshes, so a case with more
    planets has none for the others and one with fewer leaves the missing planets' empty
    (a reviewer's sweep over 2..6 planets said nothing of either)."""
    return [f"{kind}.parameters: {q} changes the number of planets, and with it the "
            f"meshes: the outputs are those of the base model's meshes, so a case with more "
            f"planets has no outputs for the others and one with fewer leaves those of the "
            f"planets it lacks empty"
            for prm in design.parameters for q in prm.paths
            if re.fullmatch(r"planetary\.\d+\.planets", q)]


def _idle_phases(design, model, kind: str) -> list[str]:
    """Notes on varied phases of errors whose amplitude is 0 in the model and varied by no
    parameter: they change nothing (a reviewer's 'gears.i*.errors.eccentricity_phase'
    also matched the input gear, which has no eccentricity, and sampled it unsaid)."""
    varied = {q for prm in design.parameters for q in prm.paths}
    notes = []
    for prm in design.parameters:  # (a pattern's paths may be parameters of their own)
        for q in prm.paths:
            head, _, last = q.rpartition(".")
            if last == "phase":
                amplitude = f"{head}.amplitude"
            elif last.endswith("_phase"):
                amplitude = f"{head}.{last[:-len('_phase')]}"
            else:
                continue
            value = _model_value(model, amplitude)
            if value == 0 and amplitude not in varied:
                notes.append(f"{kind}.parameters: {q} changes nothing: {amplitude} is "
                             f"0 in the model and no parameter varies it; leave the phase "
                             f"out, or give the error an amplitude")
    return notes


def _model_value(model, path: str):
    """The model's value at a dotted path (None where it has none)."""
    obj = model
    for part in path.split("."):
        obj = obj.get(part) if isinstance(obj, dict) else getattr(obj, part, None)
        if obj is None:
            return None
    return obj


def _probe_cases(design) -> list[int]:
    """Cases checked before any runs: the first, and for a grid each parameter at its
    smallest and largest value with the others at their first values; for a Monte Carlo
    or a sensitivity design, a case where each parameter takes its smallest and one
    where it takes its largest value (a factor's bound that makes the model invalid
    refused 14 of 20 Morris cases, said only after they ran)."""
    cases = [0]
    if design.kind != "grid" and design.values.shape[0] > 1:
        for j in range(design.values.shape[1]):
            col = design.values[:, j]
            if not np.issubdtype(col.dtype, np.number) or not np.isfinite(col).any():
                continue
            for i in (int(np.nanargmin(col)), int(np.nanargmax(col))):
                if i not in cases:
                    cases.append(i)
        return cases
    if design.kind == "grid" and design.values.shape[0] > 1:
        first = design.values[0]
        for j, axis in enumerate(design.axes):
            for v in (axis.min(), axis.max()):
                row = first.copy()
                row[j] = v
                hit = np.flatnonzero(np.all(design.values == row, axis=1))
                if hit.size and int(hit[0]) not in cases:
                    cases.append(int(hit[0]))
    return cases


def _check_generated_paths(spec: StudySpec, model) -> None:
    """A path to an element a ``[[planetary]]`` stage generated (the names results show,
    ``meshes.st_sun_planet1.backlash``) is refused with the stage's own field to vary
    instead (``planetary.0.sun_mesh.backlash``: every planet's), which the file has."""
    table = getattr(spec, spec.design)
    for i, t in enumerate(table.parameters):
        for path in ([t.path] if t.path else []) + list(t.paths or []):
            written = model.written_at(path)
            if written != path:
                # a field of the stage's per-planet lists (pin_errors: one entry per
                # planet) is that planet's alone; the others set every planet alike
                item = re.match(r"^planetary\.\d+\.(\w+)\.(\d+)\.", written)
                which = (f"planet {int(item.group(2)) + 1}'s alone: the stage's {item.group(1)} "
                         f"lists one entry per planet, which the model file must give (e.g. "
                         f"{item.group(1)} = [{{}}, {{}}, ...], one table per planet)"
                         if item else "it sets every planet's alike")
                raise StudyError(f"{spec.design}.parameters.{i}.path", (
                    f"{path!r} is generated by a [[planetary]] stage; vary the stage's own "
                    f"field instead: {written!r} ({which})"))


def _model_data(name, folder: Path | None) -> tuple[str, dict]:
    from ..examples import example_names, example_path

    if isinstance(name, dict):  # a model given as data (Python)
        import copy

        return "study.model (data)", copy.deepcopy(name)
    path = Path(name)
    if not path.is_absolute() and folder is not None:
        path = folder / path
    if path.exists():
        try:
            return str(path), read_raw(path)
        except TorquesplitError as exc:
            raise StudyError("study.model", _one_line(exc)) from None
    from ..examples import current_name

    stem, note = current_name(name)
    if stem in example_names():
        if note:
            warn_user(note, FutureWarning)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            return stem, read_raw(example_path(stem))
    raise StudyError("study.model", f"{name!r} is neither a model file (looked in "
                                    f"{path.parent}) nor a shipped example; give the path of "
                                    f"the model file, relative to the study file")


def _validated(data: dict, model_source: str, where: str, case=None, design=None,
               deep: bool = False):
    """The model of ``data``, or a StudyError naming the case; ``deep``: also what every
    run does before it integrates (assembly, static equilibrium: ``torquesplit check``'s
    refusals; a study whose every case was refused by them ran to the end and exited 0,
    a reviewer)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = load_model(model_from_dict(data, source=model_source))
            if deep:
                from ..model.checks import check_model

                check_model(model, source=model_source, deep=True)
            return model
    except TorquesplitError as exc:
        what = "the model with the study's changes is invalid"
        if case is not None:
            vals = ", ".join(f"{p.name} = {p.show(v)}" for p, v in
                             zip(design.parameters, design.values[case], strict=True))
            what = f"case {case} ({vals}) gives an invalid model"
        issues = getattr(exc, "issues", None)
        why = (" | ".join(f"{loc}: {msg}" if loc else msg for loc, msg in issues) if issues
               else _one_line(exc))
        raise StudyError(where, f"{what}: {why}") from None


def _one_line(exc: BaseException) -> str:
    return " | ".join(s.strip() for s in str(exc).splitlines() if s.strip())


def _hash(data) -> str:
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _analysis(spec: StudySpec) -> dict:
    a = spec.analysis
    out = {"type": a.type}
    if a.type == "static":
        # defaults: those of torquesplit static (whole periods of the errors and tables)
        out["revolutions"] = None if a.revolutions is None else float(a.revolutions)
        out["points_per_cycle"] = 32 if a.points_per_cycle is None else int(a.points_per_cycle)
        if a.max_points is not None:  # (only when given: a stored study's plan unchanged)
            out["max_points"] = int(a.max_points)
        return out
    problems = _Problems()  # (the duration's and the settle start's both, at once)
    out["duration"] = problems.attempt(_positive_time, a.duration, "analysis.duration", "2 s")
    out.update(cycles=a.cycles, method=a.method, steps_per_period=a.steps_per_period,
               rtol=a.rtol)
    if a.max_steps is not None:  # (only when given: a stored study's plan unchanged)
        out["max_steps"] = int(a.max_steps)
    if a.settle is not None:
        start = problems.attempt(_positive_time, a.settle.start, "analysis.settle.start",
                                 "1 s")
        out["settle"] = {"tolerance": a.settle.tolerance, "start": start,
                         "growth": a.settle.growth}
    problems.raise_any()
    return out


def _positive_time(value, field: str, example: str) -> float | None:
    """A time of the study file in s (None if not given); refused unless positive."""
    if value is None:
        return None
    t = P.to_si(value, "time", None, field)
    if t <= 0:
        raise StudyError(field, f"must be positive; give e.g. '{example}'")
    return t


MIN_CYCLES = 2
"""A run analysis shorter than this many cycles of the model's fastest mesh is refused:
every output is measured over whole mesh cycles (a cycle the start or the end cuts does
not count), so its cases would all be 'ok' with no value (a reviewer's 2 ms sweep).  A
run that covers the fast meshes but not the slow ones gives the fast ones' outputs (and
says the others are short)."""


def _long_enough(model, analysis: dict) -> None:
    from ..model.kinematics import solve_kinematics
    from .case import _full_duration

    length, f_min = _full_duration(model, analysis)
    kin = solve_kinematics(model)
    name, f_max = max(((m, kin.meshes[m].frequency) for m in model.meshes),
                      key=lambda x: x[1])
    if length * f_max >= MIN_CYCLES:
        return
    field = ("analysis.duration" if analysis.get("duration") is not None
             else "analysis.cycles" if analysis.get("cycles") is not None
             else "study.model (its [analysis])")
    least = (f"{math.ceil(MIN_CYCLES * f_min / f_max)} cycle(s) of the slowest mesh"
             if field == "analysis.cycles" else f"{MIN_CYCLES / f_max:.3g} s")
    raise StudyError(field, f"the run, {length:.4g} s, holds {length * f_max:.3g} cycle(s) "
                            f"of the fastest mesh ({name}, {f_max:.6g} Hz); every output is "
                            f"measured over whole mesh cycles, so no case would have a "
                            f"value: give at least {least} (settling takes many more; "
                            f"without a run length the model's own is used)")


def _outputs(spec: StudySpec, model, analysis: str) -> tuple[list[str], list[str]]:
    from ..assembly.excitation import stage_labels
    from ..metrics.load_sharing import group_meshes
    from ..model.kinematics import solve_kinematics

    kin = solve_kinematics(model)  # (planetary stages: their K_gamma outputs; the groups)
    stages = stage_labels(model, kin)
    meta = {m: {"stage": stages[m], "path": model.meshes[m].path} for m in model.meshes}
    # (a planet's output is named after its body on the pin, as planet_load_sharing does)
    planets = {c: list(pins) for c, pins in kin.carriers.items()}
    bearings = []
    if analysis != "static" and any("bearing" in p for p in spec.study.outputs):
        from ..assembly.assemble import assemble
        from ..results import bearing_bodies

        bearings = bearing_bodies(assemble(model, kin), model, kin)
    available = out_mod.available_outputs(list(model.meshes), group_meshes(meta), analysis,
                                          planets, bearings)
    names, unmatched = out_mod.select_outputs(spec.study.outputs, available)
    if unmatched:
        import difflib

        problems = []
        for p in unmatched:
            close = difflib.get_close_matches(p, available, n=3)
            hint = f"close: {', '.join(close)}; " if close else ""
            problems.append(("study.outputs", f"{p!r} matches no output of a {analysis!r} "
                                              f"analysis of this model; {hint}see "
                                              f"docs/studies.md for the names"))
        raise StudyError.of(problems)
    stop = spec.monte_carlo.stop if spec.monte_carlo is not None else None
    if stop is not None:
        if stop.output not in available:
            raise StudyError("monte_carlo.stop.output", f"{stop.output!r} is not an output of "
                                                        f"this study; give one exact name, e.g. "
                                                        f"{names[0]!r}")
        if stop.output not in names:
            names.append(stop.output)
    return names, out_mod.definitions_needed(names)


def _check_disjoint(params, where: str) -> None:
    """Refuse two parameters that write the same field (the later would silently win)."""
    owner: dict[str, int] = {}
    for i, p in enumerate(params):
        for f in p.fields:
            if f.path in owner:
                raise StudyError(f"{where}.{i}", f"{p.name!r} writes {f.path}, which parameter "
                                                 f"{owner[f.path]} also writes; vary each field "
                                                 f"in one parameter only")
            owner[f.path] = i


# ============================================================================ grid
def _target_fields(t, raw: dict, where: str) -> list[P.Field]:
    """Fields of a parameter table's path / paths (patterns expanded)."""
    given = [t.path] if t.path is not None else list(t.paths)
    key = "path" if t.path is not None else "paths"
    fields: list[P.Field] = []
    for j, path in enumerate(given):
        w = f"{where}.{key}" + ("" if key == "path" else f".{j}")
        schema = P.schema_field(path, w) if not P.is_pattern(path) else None
        for concrete in P.expand(path, raw, w):
            f = schema or P.schema_field(concrete, w)
            f = P.Field(concrete, f.kind, f.integer, f.nonnegative)
            P.check_settable(raw, f, w)
            if all(f.path != g.path for g in fields):
                fields.append(f)
    kinds = {f.kind for f in fields}
    if len(kinds) > 1:
        shown = ", ".join(str(k or "plain number") for k in sorted(kinds, key=str))
        raise StudyError(f"{where}.{key}", f"the fields are of different kinds ({shown}); one "
                                           f"parameter sets one kind of quantity: split it")
    return fields


def _scale_fields(pattern: str, raw: dict, where: str) -> tuple[list[P.Field], list[float]]:
    fields, base = [], []
    for concrete in P.expand(pattern, raw, where):
        f = P.schema_field(concrete, where)
        fields.append(f)
        base.append(P.base_value(raw, f, where))
    return fields, base


def _parameter(t, raw: dict, where: str, name_default: str | None = None) -> Parameter:
    """A parameter table (grid / sensitivity) -> Parameter."""
    if getattr(t, "scale", None) is not None:
        fields, base = _scale_fields(t.scale, raw, f"{where}.scale")
        name = t.name or name_default
        if name is None:
            raise StudyError(f"{where}.name", "a scaled parameter needs a name; add e.g. "
                                              "name = \"support_stiffness_factor\"")
        return Parameter(name, tuple(fields), "scale", tuple(base), None)
    fields = _target_fields(t, raw, where)
    if t.name is None and len(fields) > 1:  # (paths = [one path] takes its name too)
        raise StudyError(f"{where}.name", "a parameter that sets several fields needs a name; "
                                          "add e.g. name = \"diameter\"")
    name = t.name or fields[0].path
    P.check_unit(t.unit, fields[0].kind, f"{where}.unit")
    return Parameter(name, tuple(fields), "set", (), None)


_UNIT_OF = re.compile(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*(.+?)\s*$")


def _display_unit(values, unit: str | None) -> str | None:
    if unit:
        return unit
    for v in values:
        if isinstance(v, str):
            m = _UNIT_OF.match(v)
            if m:
                return m.group(1)
    return None


def _shown(v, unit: str | None) -> str:
    """A start or stop value as the study file writes it (with the table's unit)."""
    return f"{v:g} {unit}" if unit and not isinstance(v, str) else str(v)


def _value(v, p: Parameter, unit, where) -> float:
    x = P.to_si(v, p.kind, unit, where)
    if p.mode == "set" and p.fields[0].integer and x != round(x):
        raise StudyError(where, f"{v!r}: {p.fields[0].path} takes whole numbers; give integers")
    return x


MAX_CASES = 1_000_000
"""Most cases a study holds (a grid of 1e8 points grew to GB before its first case)."""


def _grid(spec: StudySpec, raw: dict) -> Design:
    params: list[Parameter] = []
    axes: list[np.ndarray] = []
    spacings: list[str] = []
    problems = _Problems()
    for i, t in enumerate(spec.grid.parameters):
        got = problems.attempt(_grid_axis, t, raw, f"grid.parameters.{i}")
        if got is not None:
            params.append(got[0])
            axes.append(got[1])
            spacings.append(t.spacing if t.values is None else "values")
    problems.raise_any()
    names = [p.name for p in params]
    _check_disjoint(params, "grid.parameters")  # (first: two names that are one path are
    # that path twice, which 'give each a different name' did not mend)
    if len(set(names)) != len(names):
        raise StudyError("grid.parameters", f"two parameters are named {names}; give each a "
                                            f"different name")
    shape = tuple(len(a) for a in axes)
    if math.prod(shape) > MAX_CASES:
        raise StudyError("grid.parameters", f"{' x '.join(map(str, shape))} = "
                                            f"{math.prod(shape):,} cases; a study holds at most "
                                            f"{MAX_CASES:,}: give fewer points")
    values = np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(axes))
    return Design("grid", params, values, shape=shape, axes=axes,
                  extra={"spacing": spacings})


def _grid_axis(t, raw: dict, where: str) -> tuple[Parameter, np.ndarray]:
    """One grid parameter and its values (SI)."""
    p = _parameter(t, raw, where)
    problems = _Problems()  # (every bad value at once: only the first was said)
    if t.values is not None:
        got = [problems.attempt(_value, v, p, t.unit, f"{where}.values.{j}")
               for j, v in enumerate(t.values)]
        problems.raise_any()
        vals = np.array(got, dtype=float)
        shown = t.values
    else:
        a = problems.attempt(_value, t.start, p, t.unit, f"{where}.start")
        b = problems.attempt(_value, t.stop, p, t.unit, f"{where}.stop")
        problems.raise_any()
        if t.num > MAX_CASES:
            raise StudyError(f"{where}.num", f"{t.num:,} points; a study holds at most "
                                             f"{MAX_CASES:,} cases: give fewer")
        if t.num > 1 and a == b:
            raise StudyError(f"{where}.stop", "equals 'start': the range is empty; give a "
                                              "different stop, or 'values'")
        if t.num == 1 and a != b:
            raise StudyError(f"{where}.num", f"1 point but start {_shown(t.start, t.unit)} "
                                             f"!= stop {_shown(t.stop, t.unit)}; give "
                                             "num >= 2 or start = stop")
        if t.spacing == "log":
            if a <= 0 or b <= 0:
                raise StudyError(f"{where}.start", "a log range needs positive start and "
                                                   "stop; use spacing = \"linear\"")
            vals = np.geomspace(a, b, t.num)
        else:
            vals = np.linspace(a, b, t.num)
        if p.mode == "set" and p.fields[0].integer:
            vals = np.round(vals)
        shown = [t.start, t.stop]
    if len(np.unique(vals)) != len(vals):
        raise StudyError(f"{where}.values", "repeats a value; give each value once")
    p = Parameter(p.name, p.fields, p.mode, p.base,
                  None if p.mode == "scale" else _display_unit(shown, t.unit))
    if p.display_unit and p.display_unit != p.unit:
        vals = np.array([decimal_si(x, p.display_unit, p.unit) for x in vals])
    return p, vals


def decimal_si(x: float, unit: str, si: str) -> float:
    """The SI value ``x`` of a value the study wrote in ``unit``, as the decimal product of
    that value (to 12 digits) and the unit's factor: 30 um is 3e-05 m, not the
    2.9999999999999997e-05 of 30 * 1e-6, so that ``ds.sel`` finds it.  ``x`` unchanged when
    the two differ by more than rounding."""
    from decimal import Decimal, InvalidOperation

    from ..model.units import convert

    try:
        factor = convert(1.0, unit, si)
        shown = float(f"{x / factor:.12g}")
        exact = float(Decimal(repr(shown)) * Decimal(repr(factor)))
    except (ValueError, ArithmeticError, InvalidOperation):  # a unit pint cannot convert
        return float(x)
    return exact if abs(exact - x) <= 1e-12 * abs(x) else float(x)


# ============================================================================ Monte Carlo
_ISO_DEFAULTS = {"eccentricity": ("runout", 0.5), "bearing_runout": ("runout", 1.0),
                 "pitch": ("total_cumulative_pitch", 1.0)}


@dataclass(frozen=True)
class RandomVariable:
    """How a uniform number u in (0, 1) becomes a parameter value."""

    distribution: str
    args: tuple


def _monte_carlo(spec: StudySpec, raw: dict, model) -> Design:
    mc = spec.monte_carlo
    params: list[Parameter] = []
    rvs: list[RandomVariable] = []
    problems = _Problems()
    for i, t in enumerate(mc.parameters):
        got = problems.attempt(_mc_parameter, t, raw, model, f"monte_carlo.parameters.{i}")
        for p, rv in got or ():
            params.append(p)
            rvs.append(rv)
    problems.raise_any()
    names = [p.name for p in params]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise StudyError("monte_carlo.parameters", f"{sorted(dup)[0]!r} is varied twice; vary "
                                                   f"each field in one parameter only")
    _check_disjoint(params, "monte_carlo.parameters")
    n = mc.samples if mc.samples is not None else mc.stop.max_samples
    u = uniform_points(mc.sampling, n, len(params), mc.seed)
    values = np.column_stack([transform(rv, u[:, j]) for j, rv in enumerate(rvs)])
    for j, p in enumerate(params):  # a whole-number field (teeth): the value its case runs
        # with, which the results record (they recorded the draw, 20.236 teeth)
        if p.mode == "set" and p.fields[0].integer:
            values[:, j] = np.round(values[:, j])
    return Design("monte_carlo", params, values, extra={"random_variables": rvs})


def _mc_parameter(t, raw: dict, model, where: str) -> list[tuple[Parameter, RandomVariable]]:
    """A Monte Carlo parameter table -> its parameters (one per field unless shared) and
    their random variables."""
    fields = _target_fields(t, raw, where)
    P.check_unit(t.unit, fields[0].kind, f"{where}.unit")
    groups = [fields] if (t.shared or len(fields) == 1) else [[f] for f in fields]
    if len(groups) == 1 and len(fields) > 1 and not t.name:
        # (it was named after its first field: gears.z2.errors.pitch for z2 and z3)
        raise StudyError(f"{where}.name", "a shared value that sets several fields needs a "
                                          "name; add e.g. name = \"pitch_error\"")
    out = []
    for g in groups:
        if t.name and len(groups) == 1:
            name = t.name
        elif t.name:
            name = f"{t.name}.{g[0].path}"
        else:
            name = g[0].path
        shown = [v for v in (t.mean, t.low, t.high) if v is not None]
        # (an ISO 1328 draw has no value written: its tolerances are microns)
        display = _display_unit(shown, t.unit) or ("um" if t.distribution == "iso1328"
                                                   else None)
        p = Parameter(name, tuple(g), "set", (), display)
        out.append((p, _random_variable(t, p, model, where)))
    return out


def _random_variable(t, p: Parameter, model, where) -> RandomVariable:
    kind = p.kind
    d = t.distribution
    if d == "iso1328":
        return _iso_variable(t, p, model, where)

    def si(name):
        return P.to_si(getattr(t, name), kind, t.unit, f"{where}.{name}")

    def each(*names):  # every bad value of the distribution at once (the first was said)
        problems = _Problems()
        got = [problems.attempt(si, n) for n in names]
        problems.raise_any()
        return got

    nonneg = [f.path for f in p.fields if f.nonnegative]
    if d == "normal":
        mean, std = each("mean", "std")
        if std <= 0:
            raise StudyError(f"{where}.std", "must be positive; give the standard deviation")
        below = 0.5 * math.erfc(mean / (std * math.sqrt(2)))  # P(x < 0)
        if nonneg and below > NEGATIVE_PROBABILITY:
            raise StudyError(f"{where}.distribution", (
                f"a normal distribution with mean {_shown(t.mean, t.unit)} and std "
                f"{_shown(t.std, t.unit)} draws negative values ({100 * below:.3g} % of the "
                f"samples), which {nonneg[0]} refuses (those cases would be left out of the "
                f"statistics); use distribution = \"truncated_normal\" with low = 0 "
                f"(and high)"))
        return RandomVariable("normal", (mean, std))
    if d == "uniform":
        low, high = each("low", "high")
        if not high > low:
            raise StudyError(f"{where}.high", "must exceed 'low'; correct the bounds")
        _refuse_negative_low(low, t, nonneg, where)
        return RandomVariable("uniform", (low, high))
    mean, std, low, high = each("mean", "std", "low", "high")
    if std <= 0:
        raise StudyError(f"{where}.std", "must be positive; give the standard deviation")
    if not high > low:
        raise StudyError(f"{where}.high", "must exceed 'low'; correct the bounds")
    _refuse_negative_low(low, t, nonneg, where)
    return RandomVariable("truncated_normal", (mean, std, low, high))


#: a normal distribution of a field that refuses negative values is refused when it draws
#: a negative value with more than this probability (one case in a billion)
NEGATIVE_PROBABILITY = 1e-9


def _refuse_negative_low(low: float, t, nonneg: list[str], where: str) -> None:
    if nonneg and low < 0:
        raise StudyError(f"{where}.low", f"is {_shown(t.low, t.unit)}, but {nonneg[0]} refuses "
                                         f"negative values (those cases would be left out of "
                                         f"the statistics); give low >= 0")


def _iso_variable(t, p: Parameter, model, where) -> RandomVariable:
    from ..gears import grades

    f0 = p.fields[0]
    if p.kind != "length":
        raise StudyError(f"{where}.distribution", f"an ISO 1328 grade gives length tolerances, "
                                                  f"but {f0.path} is not a length; use another "
                                                  f"distribution")
    parts = f0.path.split(".")
    for f in p.fields:  # (a shaft's diameter drawn at 3-34 um ran every case)
        if "errors" not in f.path.split(".") and "transmission_error" not in f.path:
            raise StudyError(f"{where}.distribution", (
                f"an ISO 1328-1 grade bounds a gear's manufacturing deviations (the fields "
                f"under gears.NAME.errors, a mesh's transmission_error), not {f.path}; use "
                f"distribution = \"normal\", \"uniform\" or \"truncated_normal\""))
    gear = t.gear or (parts[1] if parts[0] == "gears" else None)
    if gear is None or gear not in model.gears:
        raise StudyError(f"{where}.gear", "name the gear whose size sets the tolerance; add "
                                          "gear = \"NAME\"")
    g = model.gears[gear]
    grade = t.grade if t.grade is not None else g.errors.grade
    if grade is None:
        raise StudyError(f"{where}.grade", f"gear {gear!r} has no errors.grade in the model; "
                                           f"add grade = N (ISO 1328-1 grade 1-11)")
    tol_name, factor = (t.tolerance, 1.0) if t.tolerance else _ISO_DEFAULTS.get(parts[-1],
                                                                                (None, 1.0))
    if tol_name is None:
        raise StudyError(f"{where}.tolerance", f"say which ISO 1328 tolerance bounds "
                                               f"{parts[-1]!r}: tolerance = \"runout\", "
                                               f"\"single_pitch\", ...")
    def tolerance_of(g):
        d = g.teeth * g.module / math.cos(g.helix_angle)
        try:
            tol = grades.flank_tolerances(grade, g.module, d, g.face_width)
        except TorquesplitError as exc:
            raise StudyError(f"{where}.grade", _one_line(exc)) from None
        return getattr(tol, tol_name) * factor

    value = tolerance_of(g)
    if t.gear is None:  # a value shared by fields of other gears: their tolerances too
        for f in p.fields[1:]:
            other = f.path.split(".")
            if other[0] != "gears" or other[1] == gear or other[1] not in model.gears:
                continue
            v = tolerance_of(model.gears[other[1]])
            if abs(v - value) > 1e-9 * value:
                raise StudyError(f"{where}.shared", (
                    f"one shared value for gears {gear!r} and {other[1]!r}, whose grade-{grade} "
                    f"{tol_name} tolerances differ ({value * 1e6:.4g} and {v * 1e6:.4g} um); "
                    f"draw them apart (shared = false) or name the gear whose tolerance "
                    f"bounds the shared value (gear = \"{gear}\")"))
    signed = not all(f.nonnegative for f in p.fields)
    return RandomVariable("iso1328", (value, t.shape, signed))


def uniform_points(sampling: str, n: int, d: int, seed: int) -> np.ndarray:
    """(n, d) points in [0, 1): random, scrambled Sobol or Latin hypercube, from ``seed``.
    For "random" and "sobol" the first m rows do not depend on n."""
    from scipy.stats import qmc

    if sampling == "random":
        return np.random.default_rng(seed).random((n, d))
    cls = qmc.Sobol if sampling == "sobol" else qmc.LatinHypercube
    key = "rng" if "rng" in inspect.signature(cls.__init__).parameters else "seed"
    engine = cls(d, scramble=True, **{key: np.random.default_rng(seed)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Sobol: "balance properties" for n not 2^m
        return engine.random(n)


def transform(rv: RandomVariable, u: np.ndarray) -> np.ndarray:
    """Values of a random variable at uniform points ``u`` (inverse CDF)."""
    from scipy.stats import norm, truncnorm

    if rv.distribution == "uniform":
        low, high = rv.args
        return low + u * (high - low)
    if rv.distribution == "normal":
        mean, std = rv.args
        return norm.ppf(np.clip(u, 1e-12, 1 - 1e-12), loc=mean, scale=std)
    if rv.distribution == "truncated_normal":
        mean, std, low, high = rv.args
        return truncnorm.ppf(u, (low - mean) / std, (high - mean) / std, loc=mean, scale=std)
    tol, shape, signed = rv.args
    return iso_band(u, tol, shape, signed)


def iso_band(u: np.ndarray, tolerance: float, shape: str, signed: bool) -> np.ndarray:
    """Deviation inside an ISO 1328 tolerance band from uniform ``u``: the convention of
    :func:`torquesplit.gears.grades.sample_within` (normal: +/-3 sigma = tolerance,
    truncated; magnitudes in [0, T]); a test checks that both agree."""
    from scipy.stats import truncnorm

    u = np.asarray(u, dtype=float)
    if tolerance == 0:
        return np.zeros_like(u)
    if shape == "uniform":
        return (2.0 * u - 1.0) * tolerance if signed else u * tolerance
    sigma = tolerance / 3.0
    if signed:
        return truncnorm.ppf(u, -3.0, 3.0, loc=0.0, scale=sigma)
    return truncnorm.ppf(u, 0.0, 3.0, loc=0.0, scale=sigma)


# ============================================================================ sensitivity
def _sensitivity_parameters(spec: StudySpec, raw: dict):
    out = []
    problems = _Problems()
    for i, t in enumerate(spec.sensitivity.parameters):
        got = problems.attempt(_sensitivity_factor, t, raw, f"sensitivity.parameters.{i}")
        if got is not None:
            out.append(got)
    problems.raise_any()
    names = [p.name for p, *_ in out]
    if len(set(names)) != len(names):
        raise StudyError("sensitivity.parameters", "two factors have the same name; give each "
                                                   "a different name")
    _check_disjoint([p for p, *_ in out], "sensitivity.parameters")
    return out


def _sensitivity_factor(t, raw: dict, where: str):
    """A sensitivity parameter table -> (Parameter, low, high, spacing), bounds in SI."""
    p = _parameter(t, raw, where)
    problems = _Problems()  # (both bounds' problems at once)
    low = problems.attempt(_value, t.low, p, t.unit, f"{where}.low")
    high = problems.attempt(_value, t.high, p, t.unit, f"{where}.high")
    problems.raise_any()
    if not high > low:
        raise StudyError(f"{where}.high", "must exceed 'low'; give the range low < high")
    if t.spacing == "log" and low <= 0:
        raise StudyError(f"{where}.low", "a log range needs low > 0; use spacing = "
                                         "\"linear\"")
    p = Parameter(p.name, p.fields, p.mode, p.base,
                  None if p.mode == "scale" else _display_unit([t.low, t.high], t.unit))
    return p, low, high, t.spacing
