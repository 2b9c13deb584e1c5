"""Multi-objective optimisation of model parameters with pymoo (NSGA-II by default).

    torquesplit optimize OPT.toml [--workers 2] [--out DIR]
    from torquesplit.optimize import optimize; optimize("OPT.toml")

The evaluations of a generation run in a local process pool kept for the whole
optimisation (the studies' pool starts its workers per batch, a second each, too slow
for 50 generations of LTCA evaluations of a tenth of a second), or through the studies'
runners on a Dask cluster (``--scheduler``, ``client=``); they are stored in a
JSON-lines file as they finish (``OPT.evaluations.jsonl`` in the current folder, or
``store = "..."`` relative to the optimisation file), keyed by the variable values and
a fingerprint of the model, its [set] and the outputs, so that an interrupted
optimisation run again with the same file and seed recomputes nothing it has already
evaluated (pymoo with a fixed seed proposes the same designs again).

The optimisation file (TOML)::

    [optimization]
    model = "liu2021_split_torque_helicopter"   # example name, or a model file (relative)
    algorithm = "nsga2"              # any pymoo algorithm by name (see ALGORITHMS)
    population = 40
    generations = 50
    seed = 1
    workers = 2                      # processes; 1 = in this process
    choose = "min_sum"               # design written back: least sum of the objectives
    # store = "runs/evals.jsonl"     # where evaluations are kept (default: current folder)

    [set]                            # fixed overrides of the model (as --set PATH=VALUE)
    "meshes.L68.stiffness" = {method = "ltca"}

    [[variables]]                    # any model path; tables on the way are created
    path = "gears.L6.modifications.topological.y1"
    lower = "0 mm"                   # as in the model file: units, or SI numbers
    upper = "0.06 mm"
    also = ["gears.L7.modifications.topological.y1"]   # set to the same value

    [[objectives]]
    output = "ltca.L68.te_peak_to_peak_arcsec"   # or dynamic.GROUP.dynamic_factor ...
    relative_to = "baseline"         # divide by the value of the model without variables
    sense = "min"                    # or "max"

    [[constraints]]
    output = "ltca.L68.max_hertz_pressure_Pa"
    upper = "1500 MPa"

Outputs: ``ltca.MESH.KEY`` -- any key of the LTCA summary of a mesh with
``stiffness.method = "ltca"`` at its operating load (``te_peak_to_peak_arcsec``,
``te_peak_to_peak_m``, ``impact_peak_force_N`` (needs ``impact = true``),
``stiffness_secant_mean_N_per_m``, ``max_hertz_pressure_Pa``, ``actual_contact_ratio``...);
``dynamic.GROUP.dynamic_factor``, ``dynamic.GROUP.load_sharing``,
``dynamic.MESH.dynamic_factor``, ``dynamic.MESH.load_sharing``,
``dynamic.system_load_sharing`` -- from a dynamic run
(:func:`torquesplit.simulate`, per-cycle peak definitions; slow).

Results: the Pareto front (table ``pareto.csv``, and figure ``pareto.png`` with two
objectives or more) and the chosen design written back as a model file
(``chosen.toml``).  Variables are shown (tables,
``pareto.csv``) and written (``chosen.toml``: '0.023 mm') in the unit of their bounds;
objectives with ``relative_to`` are ratios, headed ``(/ baseline)``.
"""

from __future__ import annotations

import csv
import functools
import hashlib
import json
import re
import tomllib
import warnings
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .errors import ModelError, ModelWarning, OptionError, TorquesplitError, warn_user

__all__ = ["ALGORITHMS", "OptimizationSpec", "OptimizationResult", "read_spec", "optimize",
           "evaluate_design", "output_unit"]

#: pymoo algorithms by name (module, class); any of them takes ``pop_size``
ALGORITHMS = {
    "nsga2": ("pymoo.algorithms.moo.nsga2", "NSGA2"),
    "rnsga2": ("pymoo.algorithms.moo.rnsga2", "RNSGA2"),
    "nsga3": ("pymoo.algorithms.moo.nsga3", "NSGA3"),
    "unsga3": ("pymoo.algorithms.moo.unsga3", "UNSGA3"),
    "agemoea": ("pymoo.algorithms.moo.age", "AGEMOEA"),
    "smsemoa": ("pymoo.algorithms.moo.sms", "SMSEMOA"),
    "ga": ("pymoo.algorithms.soo.nonconvex.ga", "GA"),
    "de": ("pymoo.algorithms.soo.nonconvex.de", "DE"),
    "pso": ("pymoo.algorithms.soo.nonconvex.pso", "PSO"),
}

PENALTY = 1e12  # objective value of a design that could not be evaluated


# =============================================================================== spec
@dataclass(frozen=True)
class Variable:
    path: str
    lower: float
    upper: float
    also: tuple[str, ...] = ()
    unit: str = ""
    """The unit the bounds are written in ("mm"; "" for SI numbers): tables, pareto.csv
    and chosen.toml show the values in it."""
    scale: float = 1.0
    """SI value of one ``unit``."""

    def shown(self, value: float) -> float:
        """``value`` (SI) in :attr:`unit`."""
        return float(value) / self.scale

    def label(self, name: str | None = None) -> str:
        """A column header: the name (default the path) and the unit in brackets."""
        name = name or self.path
        return f"{name} [{self.unit}]" if self.unit else name

    def written(self, value: float):
        """``value`` (SI) as a model file writes it: '0.023 mm', or a number in SI."""
        return f"{self.shown(value):.6g} {self.unit}" if self.unit else float(value)


@dataclass(frozen=True)
class Output:
    output: str
    relative_to: str | None = None
    sense: str = "min"
    lower: float | None = None
    upper: float | None = None


@dataclass(frozen=True)
class OptimizationSpec:
    """A validated optimisation file (SI values)."""

    model_data: dict
    model_source: str
    fixed: dict
    variables: tuple[Variable, ...]
    objectives: tuple[Output, ...]
    constraints: tuple[Output, ...] = ()
    algorithm: str = "nsga2"
    population: int = 40
    generations: int = 50
    seed: int = 1
    workers: int = 1
    choose: str = "min_sum"
    store: Path | None = None
    base_dir: Path = field(default_factory=Path.cwd)
    source: str | None = None
    """The optimisation file (None for a dict): the messages of :func:`check_bounds`
    name it, as read_spec's do."""


def _kind(path) -> str | None:
    """The quantity kind of the model field at ``path`` ("speed"...), None if unknown."""
    from .errors import TorquesplitError
    from .study.paths import schema_field

    try:
        return schema_field(str(path), "path").kind
    except (TorquesplitError, ValueError, TypeError):
        return None  # not a schema field: refused by name when the model is built


def _bound(value, where: str, output: str) -> float:
    """A constraint's bound in the output's unit (:func:`output_unit`: SI, arc seconds
    for ``..._arcsec``), its unit checked against the output's (a ratio takes a plain
    number, a force a force...); a plain number is read in the output's unit."""
    si = _si(value, where)
    if not isinstance(value, str) or not _NUMBER.sub("", value).strip():
        return si
    unit = output_unit(output)
    from .model.units import registry

    ureg = registry()
    given = ureg.Quantity(value)
    if not unit:
        raise ModelError([(where, f"{output} is a ratio (no unit), but the bound {value!r} has "
                                  f"a unit; write the number alone")])
    want = ureg.Quantity(1, "arcsecond" if unit == "arc s" else unit)
    if given.dimensionality != want.dimensionality:
        raise ModelError([(where, f"{output} is in {unit}, but the bound {value!r} is not; "
                                  f"write e.g. '1 {unit}'")])
    # in the output's own unit (an LTCA output in arc seconds is compared in arc seconds)
    return float(given.to(want.units).magnitude)


def _plain_number_field(path) -> bool:
    """Whether ``path`` names a schema field that takes a plain number (no unit)."""
    from .study.paths import schema_field

    try:
        return schema_field(str(path), "path").kind is None
    except (TorquesplitError, ValueError, TypeError):
        return False


def _si(value, where: str, kind: str | None = None) -> float:
    """``value`` in SI units: read as a quantity of ``kind`` (a speed in Hz counts
    revolutions, as in the model file) when the field's kind is known."""
    if isinstance(value, bool):
        raise ModelError([(where, f"must be a number or a quantity, got {value!r}; write e.g. "
                                  "'0.05 mm'")])
    if kind is not None:
        from .model.units import parse_quantity

        try:
            return parse_quantity(value, kind)
        except ValueError as exc:
            raise ModelError([(where, str(exc))]) from None
    if isinstance(value, (int, float)):
        return float(value)
    from .model.units import registry

    try:
        q = registry().Quantity(str(value))
        return float(q.to_base_units().magnitude)
    except Exception:
        raise ModelError([(where, f"{value!r} is not a quantity; write e.g. '0.05 mm' or a "
                                  "number in SI units")]) from None


_NUMBER = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def _unit_of(values, where: str, kind: str | None) -> tuple[str, float]:
    """(unit, SI value of one unit) of the first bound written with a unit ('0.05 mm'),
    ("", 1.0) for bounds in SI numbers."""
    for value in values:
        if not isinstance(value, str):
            continue
        m = _NUMBER.match(value)
        unit = value[m.end():].strip() if m else ""
        if not unit:
            continue
        try:
            scale = _si(f"1 {unit}", where, kind)
        except ModelError:
            continue
        if scale > 0 and np.isfinite(scale):
            return unit, scale
    return "", 1.0


#: units of the outputs by the suffix of their names (the LTCA summary's keys)
_OUTPUT_UNITS = (("_arcsec", "arc s"), ("_N_per_m", "N/m"), ("_Pa", "Pa"), ("_N", "N"),
                 ("_m", "m"))


def output_unit(output: str) -> str:
    """The unit of an output by its name (``..._arcsec``: arc s, ``..._N``: N); "" for a
    ratio (dynamic factor, load sharing, contact ratio)."""
    for suffix, unit in _OUTPUT_UNITS:
        if output.endswith(suffix):
            return unit
    return ""


def read_spec(source) -> OptimizationSpec:
    """Read and check an optimisation file (path or dict)."""
    from .model.overrides import read_raw

    if isinstance(source, dict):
        data, base, name = source, Path.cwd(), "<dict>"
    else:
        path = Path(source)
        if not path.exists():
            raise ModelError([("", f"no such file; check the path (current folder: {Path.cwd()})")],
                             str(path))
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except tomllib.TOMLDecodeError as exc:
            raise ModelError([("", f"TOML syntax error: {exc}; fix the line it names")],
                             str(path)) from None
        base, name = path.resolve().parent, str(path)
    known = {"optimization", "set", "variables", "objectives", "constraints"}
    from .model.io import MODEL_SECTIONS

    if "optimization" not in data and any(k in data for k in MODEL_SECTIONS):
        # (it said 'analysis: unknown section', a reliability reviewer; 'study' says this)
        raise ModelError([("", "is a model file (a gearbox, no [optimization]), not an "
                               "optimisation; run it with 'torquesplit run FILE', or write an "
                               "optimisation file whose [optimization] names it: model = "
                               "'FILE' (see docs/optimization.md; 'torquesplit example "
                               "liu2021_dh_modification' copies one)")], name)
    extra = sorted(set(data) - known)
    if extra:
        raise ModelError([(extra[0], f"unknown section; use {', '.join(sorted(known))}")], name)
    opt = dict(data.get("optimization", {}))
    issues = []
    model_ref = opt.pop("model", None)
    if not isinstance(model_ref, str):
        raise ModelError([("optimization.model",
                           "required: an example name or a model file; "
                           "add model = \"liu2021_split_torque_helicopter\"")], name)
    mpath = (base / model_ref) if not Path(model_ref).is_absolute() else Path(model_ref)
    if not mpath.exists():
        from .examples import example_names, example_path

        if model_ref in example_names():
            mpath = example_path(model_ref)
        else:
            raise ModelError([("optimization.model", f"{model_ref!r} is neither a file nor an "
                                                     "example; give a model file path")], name)
    model_data = read_raw(mpath)
    kw = {}
    for key, typ, default in (("algorithm", str, "nsga2"), ("population", int, 40),
                              ("generations", int, 50), ("seed", int, 1), ("workers", int, 1),
                              ("choose", str, "min_sum"), ("store", str, None)):
        v = opt.pop(key, default)
        if v is not None and not isinstance(v, typ):
            issues.append((f"optimization.{key}",
                           f"must be a {typ.__name__}, got {v!r}; correct it"))
        kw[key] = v
    if opt:
        issues.append((f"optimization.{sorted(opt)[0]}", "unknown field; check the spelling "
                                                          "against docs/optimization.md"))
    if kw["algorithm"] not in ALGORITHMS:
        issues.append(("optimization.algorithm", f"unknown algorithm {kw['algorithm']!r}; use one "
                                                 f"of {', '.join(ALGORITHMS)}"))
    if kw["population"] < 4 or kw["generations"] < 1 or kw["workers"] < 1:
        issues.append(("optimization.population", "population >= 4, generations >= 1 and "
                                                  "workers >= 1 are needed; correct them"))
    if kw["choose"] not in ("min_sum", "knee"):
        issues.append(("optimization.choose",
                       f"unknown choice {kw['choose']!r}; use 'min_sum' or 'knee'"))
    def attempt(function, *args):
        """``function(*args)``, its ModelError's problems added to the others (one was
        said at a time, without the file's name: a reviewer)."""
        try:
            return function(*args)
        except ModelError as exc:
            issues.extend(exc.issues)
            return None

    variables = []
    for i, v in enumerate(data.get("variables", [])):
        where = f"variables[{i}]"
        if not isinstance(v, dict) or "path" not in v or "lower" not in v or "upper" not in v:
            issues.append((where, "needs path, lower and upper; add them"))
            continue
        kind = _kind(v["path"])
        if kind is None and _plain_number_field(v["path"]):
            for end in ("lower", "upper"):
                if isinstance(v[end], str) and _NUMBER.sub("", v[end]).strip():
                    issues.append((f"{where}.{end}", (
                        f"{v['path']} is a plain number, but the bound {v[end]!r} has a "
                        f"unit; write the number alone")))
        lo = attempt(_si, v["lower"], f"{where}.lower", kind)
        hi = attempt(_si, v["upper"], f"{where}.upper", kind)
        if lo is not None and hi is not None and not lo < hi:
            issues.append((f"{where}.upper", f"must exceed lower ({lo:g}); correct the bounds"))
        unknown = sorted(set(v) - {"path", "lower", "upper", "also"})
        if unknown:
            issues.append((f"{where}.{unknown[0]}", "unknown field; use path, lower, upper, also"))
        issues += _variable_path_issues(model_data, v, where)
        shown = attempt(_unit_of, (v["lower"], v["upper"]), f"{where}.lower", kind)
        if lo is None or hi is None or shown is None:
            continue
        unit, scale = shown
        variables.append(Variable(str(v["path"]), lo, hi, tuple(v.get("also", ())), unit,
                                  scale))
    if not data.get("variables"):
        issues.append(("variables", "no variables; add [[variables]] with path, lower, upper"))

    def outputs(key):
        out = []
        for i, o in enumerate(data.get(key, [])):
            where = f"{key}[{i}]"
            if not isinstance(o, dict) or "output" not in o:
                issues.append((where, "needs an output, e.g. output = "
                                      "\"ltca.m.te_peak_to_peak_m\"; add it"))
                continue
            unknown = sorted(set(o) - {"output", "relative_to", "sense", "lower", "upper", "name"})
            if unknown:
                issues.append((f"{where}.{unknown[0]}", "unknown field; use output, relative_to, "
                                                         "sense, lower, upper"))
            parts = str(o["output"]).split(".")
            if parts[0] not in ("ltca", "dynamic") or (parts[0] == "ltca" and len(parts) != 3):
                issues.append((f"{where}.output", f"{o['output']!r} is not an output; write "
                                                  "ltca.MESH.KEY or dynamic.GROUP.KEY"))
            if o.get("relative_to") not in (None, "baseline"):
                issues.append((f"{where}.relative_to", "must be 'baseline'; write "
                                                      "relative_to = 'baseline' or remove it"))
            if o.get("sense", "min") not in ("min", "max"):
                issues.append((f"{where}.sense", "must be 'min' or 'max'; use one of them"))
            lower = None if o.get("lower") is None else attempt(
                _bound, o["lower"], f"{where}.lower", str(o["output"]))
            upper = None if o.get("upper") is None else attempt(
                _bound, o["upper"], f"{where}.upper", str(o["output"]))
            out.append(Output(str(o["output"]), o.get("relative_to"), o.get("sense", "min"),
                              lower, upper))
        return out

    objectives, constraints = outputs("objectives"), outputs("constraints")
    if not objectives:
        issues.append(("objectives", "no objectives; add [[objectives]] with an output"))
    for i, c in enumerate(data.get("constraints", [])):  # (as written: a bound refused
        if isinstance(c, dict) and c.get("lower") is None and c.get("upper") is None:  # above
            issues.append((f"constraints[{i}]", "has no bound; add lower or upper"))  # is one)
    if issues:
        raise ModelError(issues, name)
    absolute = [o.output for o in objectives if o.relative_to is None]
    if kw["choose"] == "min_sum" and len(objectives) > 1 and absolute:
        # (a reviewer's TE in arc s plus a pressure in Pa: the choice sat at the pressure's
        # extreme)
        warn_user(f"{name}: choose = 'min_sum' adds the objectives as they are, and "
                  f"{', '.join(absolute)} {'is' if len(absolute) == 1 else 'are'} not "
                  f"relative: the chosen design is ruled by the largest numbers; give each "
                  f"objective relative_to = 'baseline', or choose = 'knee' "
                  f"(docs/optimization.md)", ModelWarning)
    store = kw.pop("store")
    if store is not None:
        store_path = base / store          # relative to the optimisation file
    elif not isinstance(source, dict):     # default: in the current folder
        store_path = Path.cwd() / Path(source).with_suffix(".evaluations.jsonl").name
    else:
        store_path = None
    return OptimizationSpec(model_data=model_data, model_source=str(mpath),
                            fixed=dict(data.get("set", {})), variables=tuple(variables),
                            objectives=tuple(objectives), constraints=tuple(constraints),
                            store=store_path, base_dir=base,
                            source=None if isinstance(source, dict) else name, **kw)


#: model sections whose tables are named by the user (gears.NAME...): a variable's path
#: must name one that exists (a typo created a phantom mesh: 'meshes.mm.gears: required')
NAMED_SECTIONS = ("gears", "bodies", "shafts", "meshes", "splines", "drives", "loads")


def _variable_path_issues(model_data: dict, v: dict, where: str) -> list[tuple[str, str]]:
    """Problems of a variable's path and its ``also`` paths found before any design is
    evaluated: a gear, mesh... that the model does not have, and a field that takes a
    whole number (teeth: a fuzzer's variable evaluated every design, then said 'no
    feasible design ... must be a whole number; widen the bounds')."""
    from .study.paths import schema_field

    out = []
    for key, path in [("path", v["path"])] + [("also", p) for p in v.get("also", ())]:
        parts = str(path).split(".")
        section = model_data.get(parts[0])
        if (len(parts) > 2 and parts[0] in NAMED_SECTIONS
                and not (isinstance(section, dict) and parts[1] in section)):
            known = ", ".join(sorted(section)) if isinstance(section, dict) and section \
                else "none"
            out.append((f"{where}.{key}", f"{'.'.join(parts[:2])!r} does not exist (known "
                                          f"here: {known}); check the path"))
            continue
        try:
            integer = schema_field(str(path), "path").integer
        except (TorquesplitError, ValueError, TypeError):
            continue  # (not a schema field: refused by name when the model is built)
        if integer:
            out.append((f"{where}.{key}", f"{path} takes a whole number, and an optimisation "
                                          f"varies continuous values; optimise a continuous "
                                          f"field, or compare the whole numbers in a study "
                                          f"(a grid, docs/studies.md)"))
    return out


# ========================================================================= evaluation
def _set_deep(data: dict, path: str, value) -> dict:
    """Set a dotted path, creating missing tables (a variable may add a modification)."""
    from .model.overrides import set_parameter

    parts = path.split(".")
    node = data
    for key in parts[:-1]:
        if isinstance(node, dict) and key not in node:
            node[key] = {}
        node = node[key] if isinstance(node, dict) else node
    return set_parameter(data, path, value)


def _model_data(spec: OptimizationSpec, x, units: bool = False) -> dict:
    """The model data of design ``x`` (SI); ``units``: the variables written with the
    unit of their bounds ('0.023 mm'), as in a model file."""
    import copy

    from .model.overrides import apply_overrides

    data = apply_overrides(copy.deepcopy(spec.model_data), spec.fixed)
    for var, value in zip(spec.variables, [] if x is None else x):
        for p in (var.path, *var.also):
            data = _set_deep(data, p, var.written(value) if units else float(value))
    # the optimiser's designs are not kept in the LTCA disk cache (a mesh that does not
    # use the LTCA is left as it is: evaluate_design says what it needs)
    for name in _ltca_meshes(spec):
        path = stiffness_path(data, name)
        stiffness = _get_deep(data, path)
        if isinstance(stiffness, dict) and stiffness.get("method") == "ltca":
            data = _set_deep(data, f"{path}.ltca.cache", False)
    return data


def stiffness_path(data: dict, mesh: str) -> str:
    """Where mesh ``mesh``'s stiffness is written in model data ``data``:
    ``meshes.NAME.stiffness``, or for a mesh a ``[[planetary]]`` stage generates the
    stage's field (``planetary.0.sun_mesh.stiffness``: one for every planet's)."""
    path = f"meshes.{mesh}.stiffness"
    if mesh in (data.get("meshes") or {}) or not data.get("planetary"):
        return path
    from .model.schema import Model

    try:
        return Model.model_validate(data).written_at(path)
    except Exception:  # (the data's own errors are said when it is read)
        return path


def _get_deep(data: dict, path: str):
    """The value at a dotted path of ``data`` (list items by index), or None."""
    node = data
    for key in path.split("."):
        if isinstance(node, dict):
            node = node.get(key)
        elif isinstance(node, list) and key.isdigit() and int(key) < len(node):
            node = node[int(key)]
        else:
            return None
    return node


def _ltca_meshes(spec) -> set[str]:
    return {o.output.split(".")[1] for o in (*spec.objectives, *spec.constraints)
            if o.output.startswith("ltca.")}


def _check_dynamic_outputs(model, wanted) -> None:
    """Refuse a dynamic output the model cannot give, with the closest names, before its
    run (a mistyped group was said after a whole run of the baseline, listing a dozen
    outputs: a reviewer).  The set-up is kept for the run that follows."""
    import difflib

    from .metrics.load_sharing import group_meshes
    from .simulation import _set_up

    structure = _set_up(model)[1]
    names = list(group_meshes(structure.metadata["meshes"])) + list(model.meshes)
    known = ["dynamic.system_load_sharing"] + [
        f"dynamic.{n}.{k}" for n in names for k in ("dynamic_factor", "load_sharing")]
    for w in wanted:
        if w.startswith("dynamic.") and w not in known:
            near = difflib.get_close_matches(w, known, n=3, cutoff=0.6)
            raise ModelError([("objectives", (
                f"output {w!r} is not produced"
                + (f"; did you mean {' or '.join(repr(n) for n in near)}?" if near else
                   f"; use dynamic.GROUP.load_sharing or dynamic.GROUP.dynamic_factor with "
                   f"a group or mesh of the model ({', '.join(names[:8])}), or "
                   f"dynamic.system_load_sharing")))])


def evaluate_design(spec: OptimizationSpec, x, notes: list[str] | None = None
                    ) -> dict[str, float]:
    """Every output the objectives and constraints name, for variables ``x`` (SI), or for
    the baseline model (``x = None``).  ``notes`` gets the dynamic run's plausibility
    warnings (contact lost, not settled...: a study's case statuses), one line each."""
    from .model.io import model_from_dict

    data = _model_data(spec, x)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        import torquesplit

        model = torquesplit.load_model(model_from_dict(data, source=spec.model_source))
        out: dict[str, float] = {}
        wanted = [o.output for o in (*spec.objectives, *spec.constraints)]
        if any(w.startswith("ltca.") for w in wanted):
            from .assembly.excitation import table_points
            from .gears.contact.coupling import mesh_ltca
            from .model.kinematics import solve_kinematics

            kin = solve_kinematics(model)
            for mesh in sorted(_ltca_meshes(spec)):
                if mesh not in model.meshes:
                    raise ModelError([("objectives", f"no mesh named {mesh!r}; name a mesh of the "
                                                     "model")])
                if model.meshes[mesh].stiffness.method != "ltca":
                    where = stiffness_path(spec.model_data, mesh)
                    raise ModelError([(f"{where}.method", (
                        f"an ltca output needs the LTCA stiffness; set it in [set]: "
                        f"\"{where}\" = {{method = \"ltca\"}}"))])
                summary = mesh_ltca(model, kin, mesh, table_points(model, kin)).summary
                for k, v in summary.items():
                    if isinstance(v, (int, float)) and not isinstance(v, bool):
                        out[f"ltca.{mesh}.{k}"] = float(v)
                if model.meshes[mesh].impact and "impact_peak_force_N" not in summary:
                    out[f"ltca.{mesh}.impact_peak_force_N"] = 0.0
        if any(w.startswith("dynamic.") for w in wanted):
            from .simulation import MIN_SAMPLES_PER_PERIOD

            _check_dynamic_outputs(model, wanted)  # (before the run, not after it)
            # (metrics only: the sparse history, as a study's case)
            res = torquesplit.simulate(model, samples_per_period=MIN_SAMPLES_PER_PERIOD)
            if not res.success:  # (a diverged run's partial metrics were ranked as a design)
                raise TorquesplitError(f"the dynamic run diverged: {res.message}")
            metrics = res.metrics("cycle_peak")
            if notes is not None:
                from .results.plausibility import result_warnings

                notes += [f"{where}: {text}" for where, text
                          in result_warnings(res, metrics, history=False)]
            met = metrics.to_dict()
            out["dynamic.system_load_sharing"] = float(met["system_load_sharing"])
            for g, v in met["groups"].items():
                out[f"dynamic.{g}.dynamic_factor"] = float(v["dynamic_factor"])
                out[f"dynamic.{g}.load_sharing"] = float(v["load_sharing"])
            for mname, v in met["meshes"].items():
                out[f"dynamic.{mname}.dynamic_factor"] = float(v["dynamic_factor"])
                out[f"dynamic.{mname}.load_sharing"] = float(v["load_sharing"])
    missing = [w for w in wanted if w not in out]
    if missing:
        raise ModelError([("objectives", f"output {missing[0]!r} is not produced; use one of "
                                         f"{', '.join(sorted(out)[:12])} ...")])
    return out


def _evaluate_job(spec: OptimizationSpec, x: tuple[float, ...]) -> dict:
    try:
        notes: list[str] = []
        return {"x": list(x), "outputs": evaluate_design(spec, x, notes), "error": None,
                "notes": [n.splitlines()[0] for n in notes]}
    except (TorquesplitError, ValueError) as exc:
        return {"x": list(x), "outputs": None, "error": str(exc).splitlines()[0]}


#: what an evaluation record holds: 2 since a diverged run is a failed design and each
#: record keeps its run's warnings ('notes'); records of an earlier format are not
#: reused (one had ranked a diverged run's partial metrics: a code reviewer)
STORE_FORMAT = 2


def fingerprint(spec: OptimizationSpec) -> str:
    """What an evaluation depends on besides the variables' values: the model with the
    fixed settings ([set]), the variables' paths and the outputs asked for.  A stored
    evaluation of another fingerprint is not reused (a changed [set] reused them)."""
    wanted = sorted(o.output for o in (*spec.objectives, *spec.constraints))
    text = json.dumps({"store": STORE_FORMAT, "model": _model_data(spec, None),
                       "outputs": wanted,
                       "variables": [(v.path, list(v.also)) for v in spec.variables]},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def check_bounds(spec: OptimizationSpec) -> None:
    """Build the model at every variable's lower and upper bound (the others at their
    lower bounds) before anything runs: a misspelt path or a bound the field refuses
    (a negative damping ratio) is an error naming the variable, not a run of failed
    designs."""
    from .model.io import model_from_dict

    def within(loc: str, path: str) -> bool:
        return loc == path or loc.startswith(path + ".") or path.startswith(loc + ".")

    try:  # [set] alone first: its problem is named there, not at a variable's bound
        model_from_dict(_model_data(spec, None), source=spec.model_source)
    except ModelError as exc:
        loc, msg = exc.issues[0] if exc.issues else ("", str(exc))
        key = next((k for k in spec.fixed if within(loc, k)), None)
        if key is not None:
            raise ModelError([(f'set."{key}"', f"{loc + ': ' if loc != key else ''}{msg}")],
                             spec.source) from None
    lows = [v.lower for v in spec.variables]
    for i, var in enumerate(spec.variables):
        for end in ("lower", "upper"):
            x = list(lows)
            x[i] = getattr(var, end)
            try:
                model_from_dict(_model_data(spec, x), source=spec.model_source)
            except ModelError as exc:
                loc, msg = exc.issues[0] if exc.issues else ("", str(exc))
                for at, why in exc.issues or ():
                    if any(within(at, p) for p in (var.path, *var.also)) and (
                            "unknown field" in why or "does not exist" in why):
                        # (a misspelt path, not its bound: a reviewer's 'crowing')
                        raise ModelError([(f"variables[{i}].path", f"{at}: {why}")],
                                         spec.source) from None
                raise ModelError([(f"variables[{i}].{end}", (
                    f"the model with {var.path} = {x[i]:g} (SI) is refused: "
                    f"{loc + ': ' if loc else ''}{msg}"))], spec.source) from None


class _Store:
    """Evaluations by variable values, appended to a JSON-lines file as they finish;
    only those of this ``fingerprint`` (:func:`fingerprint`) are reused."""

    def __init__(self, path: Path | None, fingerprint: str = ""):
        self.path = path
        self.fingerprint = fingerprint
        self.records: dict[tuple, dict] = {}
        self.other = 0
        """Stored evaluations of another model or outputs, not reused."""
        if path is not None and path.exists():
            text = path.read_text()
            if text and not text.endswith("\n"):  # a line cut by a kill or a full disk:
                # cut off, or the next record is appended to it and lost too (a
                # reliability reviewer)
                with path.open("r+") as fh:
                    fh.truncate(len(text[: text.rfind("\n") + 1].encode()))
            for line in text.splitlines():
                try:
                    rec = json.loads(line)
                    if rec.get("fingerprint", "") != fingerprint:
                        self.other += 1
                        continue
                    self.records[tuple(rec["x"])] = rec
                except (ValueError, KeyError):
                    continue  # a line cut by an interruption

    def __contains__(self, x) -> bool:
        return tuple(x) in self.records

    def get(self, x) -> dict:
        return self.records[tuple(x)]

    def add(self, rec: dict) -> None:
        rec = {**rec, "fingerprint": self.fingerprint}
        self.records[tuple(rec["x"])] = rec
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with self.path.open("a") as fh:
                fh.write(json.dumps(rec) + "\n")


# ============================================================================= result
@dataclass(frozen=True)
class OptimizationResult:
    """Pareto front and the chosen design."""

    spec: OptimizationSpec
    X: np.ndarray
    """(n, n_var) Pareto-optimal variable values (SI)."""
    F: np.ndarray
    """(n, n_obj) their objective values (as minimised: 'max' objectives negated)."""
    outputs: tuple[dict, ...]
    baseline: dict
    chosen: int
    evaluations: int
    computed: int
    notes: tuple[tuple[str, ...], ...] = ()
    """Per design of the front, its dynamic run's plausibility warnings (contact lost,
    not settled...), one line each."""
    baseline_notes: tuple[str, ...] = ()
    baseline_F: np.ndarray | None = None
    """(n_obj,) the baseline's objective values (as minimised, as F); None where the
    baseline failed."""
    baseline_feasible: bool = True
    """Whether the baseline meets the constraints."""

    @property
    def baseline_not_worse(self) -> bool:
        """Whether the baseline meets the constraints and is at least as good as the
        chosen design in every objective (then the variables' bounds or the objectives
        deserve a look)."""
        return (self.baseline_F is not None and self.baseline_feasible
                and bool(np.all(self.baseline_F <= self.F[self.chosen])))

    @property
    def chosen_x(self) -> np.ndarray:
        return self.X[self.chosen]

    def chosen_model_data(self, units: bool = False) -> dict:
        """The model file data of the chosen design (fixed overrides and variables set:
        SI numbers, or with ``units`` in the unit of their bounds, '0.023 mm')."""
        data = _model_data(self.spec, self.chosen_x, units)
        for name in _ltca_meshes(self.spec):  # keep the user's cache setting
            ltca = _get_deep(data, f"{stiffness_path(data, name)}.ltca")
            if isinstance(ltca, dict):
                ltca.pop("cache", None)
        return data

    def design_notes(self, i: int) -> tuple[str, ...]:
        """Design i's plausibility warnings (none where the front was built without)."""
        return self.notes[i] if i < len(self.notes) else ()

    def objective_labels(self) -> list[str]:
        """Headers of the objective columns: '(/ baseline)' for a ratio to the baseline,
        else the output's unit in brackets."""
        out = []
        for o in self.spec.objectives:
            unit = output_unit(o.output)
            out.append(f"{o.output} (/ baseline)" if o.relative_to
                       else f"{o.output} [{unit}]" if unit else o.output)
        return out

    def objective_values(self) -> np.ndarray:
        """(n, n_obj) the objectives as defined ('max' objectives not negated)."""
        sign = np.array([(-1.0 if o.sense == "max" else 1.0) for o in self.spec.objectives])
        return self.F * sign

    def write(self, directory) -> list[Path]:
        """pareto.csv (variables in the unit of their bounds, named in the header; a
        design's plausibility warnings in the last column), pareto.png and chosen.toml
        (variables with units) in ``directory``, each written atomically (whole or
        absent); a file that cannot be written (a full disk) is an
        :class:`~torquesplit.errors.OutputError` naming it (it said 'File too large;
        check the path and its permissions', no path: a reliability reviewer)."""
        import io

        import tomli_w

        from .results import files

        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        names = [v.label() for v in self.spec.variables]
        objs = self.objective_labels()
        table = io.StringIO(newline="")
        w = csv.writer(table)
        w.writerow(["chosen", *names, *objs, "warnings"])
        for i, (x, f) in enumerate(zip(self.X, self.objective_values())):
            w.writerow([int(i == self.chosen),
                        *(v.shown(a) for v, a in zip(self.spec.variables, x)),
                        *map(float, f), "; ".join(self.design_notes(i))])
        contents = {d / "pareto.csv": table.getvalue().encode("utf-8"),
                    d / "chosen.toml": ("# chosen by torquesplit optimize ("
                                        + self.spec.choose + ")\n" + tomli_w.dumps(
                                            self.chosen_model_data(units=True))).encode()}
        if self.F.shape[1] >= 2:
            from matplotlib.figure import Figure

            fig = Figure(figsize=(6.5, 5.0), layout="constrained")
            ax = fig.add_subplot()
            F = self.objective_values()
            ax.scatter(F[:, 0], F[:, 1], label="Pareto front")
            ax.scatter(F[self.chosen, 0], F[self.chosen, 1], marker="*", s=200,
                       color="tab:red", label="chosen")
            ax.set_xlabel(objs[0])
            ax.set_ylabel(objs[1])
            ax.grid(True, alpha=0.3)
            ax.legend()
            ax.set_title(f"{self.spec.algorithm}: {len(self.F)} Pareto designs, "
                         f"{self.evaluations} evaluations")
            png = io.BytesIO()
            fig.savefig(png, format="png", dpi=120)
            contents[d / "pareto.png"] = png.getvalue()
        for path, data in contents.items():
            files.write_atomically(path, data, overwrite=True,
                                   formats={path.suffix: path.suffix[1:]})
        return list(contents)


# ============================================================================= driver
def optimize(source, *, workers: int | None = None, generations: int | None = None,
             population: int | None = None, seed: int | None = None,
             progress: Callable[[int, int], None] | None = None, scheduler: str | None = None,
             client=None, runner=None) -> OptimizationResult:
    """Run the optimisation of an optimisation file (path, dict or OptimizationSpec).

    Keyword arguments override the file's settings.  ``progress(generation, total)`` is
    called after each generation.  The evaluations of a generation run in a local
    process pool kept for the whole optimisation (``workers``), or through the studies'
    runners: a Dask cluster (``scheduler`` address or ``client``, as
    :class:`torquesplit.study.Study`) or any ``runner(function, payloads)``
    (:mod:`torquesplit.study.runners`).
    """
    import importlib

    try:
        from pymoo.core.problem import Problem
        from pymoo.optimize import minimize
    except ImportError:
        raise OptionError("optimisation runs on pymoo, which this installation lacks; "
                          "install it with pip install 'torquesplit[study]' (from a "
                          "checkout: pip install '.[study]')") from None

    spec = source if isinstance(source, OptimizationSpec) else read_spec(source)
    over = {k: v for k, v in dict(workers=workers, generations=generations,
                                  population=population, seed=seed).items() if v is not None}
    least = dict(workers=1, generations=1, population=4, seed=0)
    for key, value in over.items():
        if isinstance(value, bool) or not isinstance(value, int) or value < least[key]:
            raise OptionError(f"{key} must be a whole number >= {least[key]} "
                              f"(--{key} on the command line), got {value!r}")
    if over:
        from dataclasses import replace

        spec = replace(spec, **over)
    check_bounds(spec)
    store = _Store(spec.store, fingerprint(spec))
    if store.other:
        warn_user(f"optimization.store: {store.other} stored evaluation(s) are of another "
                      f"model, [set] or outputs (or of an earlier torquesplit's store "
                      f"format) and are not reused", ModelWarning)
    baseline_notes: list[str] = []
    try:
        baseline = evaluate_design(spec, None, baseline_notes)
    except TorquesplitError as exc:  # (it read as a design's failure: a code reviewer)
        if any(o.relative_to for o in spec.objectives):
            raise ModelError([("optimization.model", (
                f"the baseline (the model without the variables), to which the objectives "
                f"are relative, failed: {str(exc).splitlines()[0]}; fix the model or its "
                f"[set], or remove relative_to"))], spec.source) from None
        warn_user(f"the baseline (the model without the variables) failed, so the chosen "
                  f"design is compared with nothing: {str(exc).splitlines()[0]}",
                  ModelWarning)
        baseline, baseline_notes = {}, []
    for o in (*spec.objectives,):
        if o.relative_to and not baseline[o.output]:
            raise ModelError([("objectives", f"the baseline value of {o.output!r} is 0; it cannot "
                                             "be a reference: remove relative_to")])
    counters = {"computed": 0, "evaluations": 0, "generation": 0}
    external = None
    if any(x is not None for x in (scheduler, client, runner)):
        from .study.runners import make_runner

        external = make_runner(client=client, scheduler=scheduler, runner=runner)
    from .study.runners import start_helpers, worker_start

    if spec.workers > 1 and external is None:
        start_helpers()
    pool = (ProcessPoolExecutor(max_workers=spec.workers, initializer=worker_start)
            if spec.workers > 1 and external is None else None)

    def objectives_of(rec):
        if rec["outputs"] is None:
            return [PENALTY] * len(spec.objectives), [1.0] * max(len(spec.constraints), 1)
        f = []
        for o in spec.objectives:
            v = rec["outputs"][o.output]
            if o.relative_to:
                v = v / baseline[o.output]   # Liu et al. 2021 eq. 23: f / f0
            f.append(-v if o.sense == "max" else v)
        g = []
        for c in spec.constraints:
            v = rec["outputs"][c.output]
            if c.upper is not None:
                g.append(v - c.upper)
            if c.lower is not None:
                g.append(c.lower - v)
        return f, g or [-1.0]

    class _Problem(Problem):
        def __init__(self):
            super().__init__(n_var=len(spec.variables), n_obj=len(spec.objectives),
                             n_ieq_constr=max(sum((c.lower is not None) + (c.upper is not None)
                                                  for c in spec.constraints), 1),
                             xl=np.array([v.lower for v in spec.variables]),
                             xu=np.array([v.upper for v in spec.variables]))

        def _evaluate(self, X, out, *args, **kwargs):
            keys = [tuple(float(v) for v in x) for x in X]
            todo = sorted({k for k in keys if k not in store})
            if external is not None:  # the studies' runner (Dask): stored as they finish
                for rec in external(functools.partial(_evaluate_job, spec), todo):
                    store.add(rec)
                    counters["computed"] += 1
            elif pool is None:
                for k in todo:
                    store.add(_evaluate_job(spec, k))
                    counters["computed"] += 1
            else:
                futures = [pool.submit(_evaluate_job, spec, k) for k in todo]
                for fut in as_completed(futures):
                    store.add(fut.result())    # stored as it finishes
                    counters["computed"] += 1
            counters["evaluations"] += len(keys)
            F, G = zip(*(objectives_of(store.get(k)) for k in keys))
            out["F"] = np.array(F)
            out["G"] = np.array(G)
            counters["generation"] += 1
            if progress is not None:
                progress(counters["generation"], spec.generations)

    mod, cls = ALGORITHMS[spec.algorithm]
    algorithm = getattr(importlib.import_module(mod), cls)(pop_size=spec.population)
    try:
        res = minimize(_Problem(), algorithm, ("n_gen", spec.generations), seed=spec.seed,
                       verbose=False)
    finally:
        if pool is not None:
            pool.shutdown()
    if res.X is None:
        errors = Counter(r["error"] for r in store.records.values() if r.get("error"))
        why = ""
        if errors:
            text, _ = errors.most_common(1)[0]
            # (every failed design: the texts differ by their values, so the most common
            # one's count said '2 of 16' where all 16 failed)
            why = (f"; {sum(errors.values())} of {len(store.records)} designs failed, "
                   f"e.g.: {text}")
        raise TorquesplitError("no feasible design found; widen the bounds or relax the "
                               "constraints" + why)
    X = np.atleast_2d(res.X)
    F = np.atleast_2d(res.F)
    order = np.lexsort(F.T[::-1])
    X, F = X[order], F[order]
    records = [store.get(tuple(float(v) for v in x)) for x in X]
    outputs = tuple(r["outputs"] for r in records)
    if spec.choose == "knee" and F.shape[1] >= 2 and len(F) > 2:
        span = np.ptp(F, axis=0)
        span[span == 0] = 1.0
        Fn = (F - F.min(axis=0)) / span
        chosen = int(np.argmin(np.linalg.norm(Fn, axis=1)))
    else:
        chosen = int(np.argmin(F.sum(axis=1)))
    return OptimizationResult(spec=spec, X=X, F=F, outputs=outputs, baseline=baseline,
                              chosen=chosen, evaluations=counters["evaluations"],
                              computed=counters["computed"],
                              notes=tuple(tuple(r.get("notes", ())) for r in records),
                              baseline_notes=tuple(n.splitlines()[0] for n in baseline_notes),
                              **({} if not baseline else dict(
                                  baseline_F=np.array(objectives_of({"outputs": baseline})[0]),
                                  baseline_feasible=bool(np.all(np.array(objectives_of(
                                      {"outputs": baseline})[1]) <= 0.0)))))
