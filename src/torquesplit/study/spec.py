"""The study file: schema (pydantic) and reading, with one-line errors naming the field.

A study file is TOML::

    [study]
    name = "diameter"
    model = "ji_li_mill_drive"        # a model file (relative to this file) or an example
    outputs = ["load_sharing.engineering.*"]

    [set]                                # optional: fixed changes to the model, as --set
    "analysis.steps_per_period" = 400

    [analysis]                           # optional: type = "run" (default) or "static"
    duration = "30 s"

    [grid]                               # exactly one design: grid, monte_carlo, sensitivity
    [[grid.parameters]]
    name = "d"
    paths = ["shafts.drive1.diameter", "shafts.drive2.diameter"]
    start = "130 mm"
    stop = "400 mm"
    num = 28

Values are checked here for form (types, required fields, exclusive options); units and
model paths are checked against the model in :mod:`torquesplit.study.design`.  Both
stages raise :class:`~torquesplit.study.errors.StudyError` with one line
``file: field: problem; fix``.  ``docs/studies.md`` describes every field.
"""

from __future__ import annotations

import difflib
import json
import math
import os
import tomllib
import typing
from pathlib import Path
from typing import Any, Literal, Union

import pydantic
from pydantic import (BaseModel, ConfigDict, Field, StrictFloat, StrictInt, field_validator,
                      model_validator)

from ..errors import FieldError, TorquesplitError
from .errors import StudyError

Value = Union[StrictInt, StrictFloat, str]
"""A number (read in the field's SI unit, or in ``unit``) or a string with units."""


# raised by a validator for one field of its section (the location gets ``field``)
_Problem = FieldError


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _one_of(obj, names: tuple[str, ...], what: str) -> str:
    given = [n for n in names if getattr(obj, n) is not None]
    if len(given) != 1:
        listed = ", ".join(repr(n) for n in names)
        if not given:
            raise _Problem(names[0], f"{what}: give one of {listed}")
        raise _Problem(given[1], f"{what}: give only one of {listed}, not "
                                 f"{' and '.join(repr(g) for g in given)}")
    return given[0]


def _forbid(obj, names, why: str) -> None:
    for n in names:
        if getattr(obj, n) is not None:
            raise _Problem(n, f"does not apply {why}; remove it")


# ============================================================================ sections
class StudyInfo(_Strict):
    """What the study is and what it reports."""

    name: str = Field(description="Short name (used for output files).")
    description: str = Field("", description="One line on what the study shows.")
    reference: str = Field("", description="The figure or section of the paper it follows.")
    model: str | dict[str, Any] = Field(description=(
        "Model file (relative to the study file) or example name; from Python also a "
        "model as a dict or a torquesplit Model."))
    outputs: list[str] = Field(min_length=1, description=(
        "Output names or patterns (`load_sharing.engineering.*`); see docs/studies.md."))


class SettleRule(_Strict):
    """Opt-in: run each case only until its metrics stop changing."""

    tolerance: float = Field(0.002, gt=0, lt=1, description=(
        "Largest relative change of every requested output between two successive run "
        "lengths."))
    start: Value | None = Field(None, description=(
        "First run length (time); default 50 cycles of the slowest mesh."))
    growth: float = Field(2.0, gt=1, le=10, description="Factor between run lengths.")


class AnalysisSpec(_Strict):
    """The analysis run for each case."""

    type: Literal["run", "static"] = Field("run", description=(
        "'run': static equilibrium then dynamic response (torquesplit run); 'static': "
        "quasi-static load sharing (torquesplit static)."))
    duration: Value | None = Field(None, description="Simulated time (run); default: model.")
    cycles: int | None = Field(None, gt=0, description="Cycles of the slowest mesh (run).")
    method: Literal["rk4", "dopri"] | None = Field(None, description="Integrator (run).")
    steps_per_period: int | None = Field(None, ge=10, description="RK4 steps per period (run).")
    rtol: float | None = Field(None, gt=0, lt=1, description="Relative tolerance (dopri).")
    settle: SettleRule | None = Field(None, description="Stop-when-settled rule (run).")
    revolutions: float | None = Field(None, gt=0, description=(
        "Revolutions of the slowest gear (static); default: whole periods of the errors "
        "and tables, at least one revolution."))
    points_per_cycle: int | None = Field(None, ge=1, description=(
        "Positions per cycle of the fastest excitation (static), default 32."))
    max_steps: int | None = Field(None, ge=1, description=(
        "Refuse a case's RK4 run needing more steps (run), default 2e8: what --max-steps "
        "is to torquesplit run."))
    max_points: int | None = Field(None, ge=16, description=(
        "Most positions of a case's sweep (static), default 20000: what --max-points is "
        "to torquesplit static."))

    @model_validator(mode="after")
    def _fits_type(self):
        if self.type == "run":
            _forbid(self, ("revolutions", "points_per_cycle", "max_points"),
                    "to type = 'run'")
            if self.duration is not None and self.cycles is not None:
                raise _Problem("cycles", "give either 'duration' or 'cycles', not both")
        else:
            _forbid(self, ("duration", "cycles", "method", "steps_per_period", "rtol",
                           "settle", "max_steps"), "to type = 'static'")
        return self


class _Target(_Strict):
    name: str | None = Field(None, description="Name of the parameter (a dimension or "
                                               "coordinate of the results).")
    path: str | None = Field(None, description="Model path, as for --set "
                                               "(`meshes.m11.backlash`); patterns allowed.")
    paths: list[str] | None = Field(None, min_length=1, description=(
        "Several paths set to the same value."))
    unit: str | None = Field(None, description="Unit of bare numbers in this table.")


class GridParameter(_Target):
    """One axis of a grid."""

    scale: str | None = Field(None, description=(
        "Pattern of fields to scale: the values are factors on each field's model value."))
    values: list[Value] | None = Field(None, description="Explicit values.")
    start: Value | None = Field(None, description="First value of a range.")
    stop: Value | None = Field(None, description="Last value of a range (included).")
    num: int | None = Field(None, description="Number of values of the range.")
    spacing: Literal["linear", "log"] = Field("linear", description="Range spacing.")

    @model_validator(mode="after")
    def _complete(self):
        _one_of(self, ("path", "paths", "scale"), "say what to vary")
        if self.values is not None:
            _forbid(self, ("start", "stop", "num"), "together with 'values'")
            if not self.values:
                raise _Problem("values", "is empty; give at least one value")
        else:
            for n in ("start", "stop", "num"):
                if getattr(self, n) is None:
                    raise _Problem(n, "is missing; give 'values', or 'start', 'stop' and "
                                      "'num' for a range")
            if self.num < 1:
                raise _Problem("num", f"is {self.num}: the range is empty; give num >= 1")
        if self.scale is not None and self.unit is not None:
            raise _Problem("unit", "a scale takes plain factors; remove 'unit'")
        return self


class Grid(_Strict):
    """Full factorial design over 1 to 3 parameters."""

    parameters: list[GridParameter] = Field(min_length=1, max_length=3, description=(
        "The axes, in the order of the result's dimensions."))


class MonteCarloParameter(_Target):
    """A random parameter."""

    distribution: Literal["normal", "uniform", "truncated_normal", "iso1328"] = Field(
        description="Distribution of the value.")
    mean: Value | None = Field(None, description="normal, truncated_normal: mean.")
    std: Value | None = Field(None, description="normal, truncated_normal: standard deviation.")
    low: Value | None = Field(None, description="uniform, truncated_normal: lower bound.")
    high: Value | None = Field(None, description="uniform, truncated_normal: upper bound.")
    grade: int | None = Field(None, ge=1, le=11, description=(
        "iso1328: ISO 1328-1 accuracy grade (default: the gear's errors.grade)."))
    tolerance: Literal["runout", "single_pitch", "total_cumulative_pitch", "profile_slope",
                       "helix_slope"] | None = Field(None, description=(
        "iso1328: which tolerance bounds the value (default from the field: eccentricity -> "
        "runout / 2, pitch -> total_cumulative_pitch: the model's pitch is F_p)."))
    shape: Literal["normal", "uniform"] = Field("normal", description=(
        "iso1328: normal with +/-3 sigma = tolerance (truncated), or uniform in the band."))
    gear: str | None = Field(None, description=(
        "iso1328: gear whose geometry sets the tolerance (default: from the path)."))
    shared: bool = Field(False, description=(
        "With several fields: one draw for all (true) or one independent draw each."))

    @model_validator(mode="after")
    def _complete(self):
        _one_of(self, ("path", "paths"), "say what to vary")
        need = {"normal": ("mean", "std"), "uniform": ("low", "high"),
                "truncated_normal": ("mean", "std", "low", "high"), "iso1328": ()}
        own = {"mean", "std", "low", "high", "grade", "tolerance", "gear"}
        allowed = set(need[self.distribution]) | (
            {"grade", "tolerance", "gear"} if self.distribution == "iso1328" else set())
        for n in sorted(own - allowed):
            if getattr(self, n) is not None:
                raise _Problem(n, f"does not apply to distribution = {self.distribution!r}; "
                                  f"remove it")
        for n in need[self.distribution]:
            if getattr(self, n) is None:
                raise _Problem(n, f"is missing; distribution = {self.distribution!r} needs "
                                  f"{', '.join(need[self.distribution])}")
        if self.distribution == "iso1328" and self.unit is not None:
            raise _Problem("unit", "an ISO 1328 grade gives SI tolerances; remove 'unit'")
        return self


class StopRule(_Strict):
    """Stop sampling when the confidence interval of an output statistic is narrow enough."""

    output: str = Field(description="The output whose statistic is watched (exact name).")
    statistic: Literal["mean", "p95"] = Field("mean", description="Mean or 95th percentile.")
    # (relative before half_width: pydantic validates fields in this order, and a
    # half-width with a unit means nothing as a fraction)
    relative: bool = Field(False, description="half_width relative to |statistic|.")
    half_width: float = Field(gt=0, description=(
        "Target half-width of the interval: in the output's SI unit, or with its unit "
        "('1 kN' for a force); a fraction of |statistic| with relative = true."))

    @field_validator("half_width", mode="before")
    @classmethod
    def _with_unit(cls, v, info):
        """A half-width written with a unit ('1 kN'), read in the output's SI unit (it was
        refused as 'not a valid number', and a bare number's unit was said nowhere).  A
        relative one is a plain fraction: '1 kN' there was read as 1000 times |statistic|
        and every sample met it."""
        if not isinstance(v, str):
            return v
        if info.data.get("relative"):
            try:
                return float(v)
            except ValueError:
                raise ValueError(f"with relative = true the half-width is a fraction of "
                                 f"|statistic|: write a plain number (0.01 for 1 %), got "
                                 f"{v!r}; or give it with its unit and relative = false"
                                 ) from None
        from ..model.units import KINDS, parse_quantity
        from .outputs import output_unit

        unit = output_unit(str(info.data.get("output", "")))
        kind = next((k for k, (si, _) in KINDS.items() if si == unit), None)
        if kind is None:
            raise ValueError(f"write a plain number (the output {info.data.get('output')!r} "
                             f"has no unit), got {v!r}")
        return parse_quantity(v, kind)
    confidence: float = Field(0.95, gt=0, lt=1, description="Confidence level.")
    min_samples: int = Field(32, ge=4, description="Samples before the first check.")
    batch: int = Field(16, ge=1, description="Samples between checks.")
    max_samples: int = Field(ge=1, description="Stop here in any case.")

    @model_validator(mode="after")
    def _order(self):
        if self.min_samples > self.max_samples:
            raise _Problem("min_samples", f"{self.min_samples} exceeds max_samples = "
                                          f"{self.max_samples}; lower it")
        if self.statistic == "p95":
            # the fewest samples whose largest bounds the 95th percentile with the
            # confidence: 1 - 0.95^n >= confidence (59 at 95 %)
            least = math.ceil(math.log(1 - self.confidence) / math.log(0.95))
            if self.max_samples < least:
                raise _Problem("max_samples", f"{self.max_samples} samples cannot bound a "
                                              f"95th percentile with {self.confidence:.0%} "
                                              f"confidence (it takes {least}); raise it")
        return self


class MonteCarlo(_Strict):
    """Random samples of the parameters."""

    sampling: Literal["random", "sobol", "latin_hypercube"] = Field("random", description=(
        "Independent random draws, scrambled Sobol points, or a Latin hypercube."))
    seed: int = Field(description="Seed of the sampler (results depend only on it).")
    samples: int | None = Field(None, ge=1, le=1_000_000, description="Number of samples.")
    stop: StopRule | None = Field(None, description="Or: a stopping rule.")
    parameters: list[MonteCarloParameter] = Field(min_length=1, description="Random inputs.")

    @model_validator(mode="after")
    def _count(self):
        _one_of(self, ("samples", "stop"), "say how many samples")
        if self.stop is not None and self.sampling == "latin_hypercube":
            raise _Problem("sampling", "a Latin hypercube needs a fixed sample count, so it "
                                       "cannot stop early; use 'sobol' or 'random' with [stop]")
        return self


class SensitivityParameter(_Target):
    """A factor of a sensitivity study: its range."""

    scale: str | None = Field(None, description="Pattern of fields scaled by the factor.")
    low: Value = Field(description="Lower end of the range.")
    high: Value = Field(description="Upper end of the range.")
    spacing: Literal["linear", "log"] = Field("linear", description="Sample the range "
                                                                   "linearly or in log.")

    @model_validator(mode="after")
    def _complete(self):
        _one_of(self, ("path", "paths", "scale"), "say what to vary")
        if self.scale is not None and self.unit is not None:
            raise _Problem("unit", "a scale takes plain factors; remove 'unit'")
        return self


class Sensitivity(_Strict):
    """Global ranking of many factors at once."""

    method: Literal["morris", "sobol"] = Field(description=(
        "Morris elementary effects (cheap screening) or Sobol indices (variance shares)."))
    seed: int = Field(description="Seed of the sampler.")
    trajectories: int | None = Field(None, ge=2, description="morris: trajectories r "
                                                             "(default 10).")
    levels: int | None = Field(None, ge=2, description="morris: grid levels p (default 4).")
    samples: int | None = Field(None, ge=2, description="sobol: base samples N (default 64; "
                                                        "a power of 2).")
    parameters: list[SensitivityParameter] = Field(min_length=2, description="The factors.")

    @model_validator(mode="after")
    def _fits_method(self):
        if self.method == "morris":
            _forbid(self, ("samples",), "to method = 'morris' (use 'trajectories')")
        else:
            _forbid(self, ("trajectories", "levels"), "to method = 'sobol' (use 'samples')")
            n = self.samples
            if n is not None and n & (n - 1):  # Saltelli's scheme on Sobol points
                lower = 1 << (n.bit_length() - 1)
                raise _Problem("samples", f"{n} is not a power of 2 (Sobol sequences balance "
                                          f"only there); give {lower} or {2 * lower}")
        return self


DESIGNS = ("grid", "monte_carlo", "sensitivity")


class StudySpec(_Strict):
    """A whole study file."""

    study: StudyInfo = Field(description="Name, model and outputs.")
    set: dict[str, Any] = Field({}, description="Fixed model changes for every case "
                                                "(path = value, as --set).")
    analysis: AnalysisSpec = Field(AnalysisSpec(), description="What each case runs.")
    grid: Grid | None = Field(None, description="Design: a grid of 1-3 parameters.")
    monte_carlo: MonteCarlo | None = Field(None, description="Design: random samples.")
    sensitivity: Sensitivity | None = Field(None, description="Design: sensitivity ranking.")

    @model_validator(mode="after")
    def _one_design(self):
        given = [d for d in DESIGNS if getattr(self, d) is not None]
        if len(given) != 1:
            if given:
                raise _Problem(given[1], f"a study has one design, here {' and '.join(given)}; "
                                         f"keep one of them (one study file per design)")
            raise _Problem("grid", "the study has no design; add a [grid], [monte_carlo] or "
                                   "[sensitivity] table")
        return self

    @property
    def design(self) -> str:
        return next(d for d in DESIGNS if getattr(self, d) is not None)

    def canonical(self) -> dict:
        """The spec as plain data (defaults filled in): what a resume compares."""
        return json.loads(self.model_dump_json())


# ============================================================================ reading
def read_study(source, analysis: dict | None = None) -> tuple[StudySpec, Path | None, str]:
    """Read and validate a study: a ``.toml`` file, a dict or a :class:`StudySpec`.

    ``analysis``: fields that replace the study's ``[analysis]`` ones (a run length
    replaces the study's: ``duration`` drops its ``cycles`` and the other way round).
    Returns ``(spec, folder the model path is relative to, text of the file)``; the
    text ends with a comment naming the replaced fields.
    Raises :class:`StudyError` (one line naming the field) on bad input.
    """
    spec, folder, text = _read(source, analysis or {})
    if analysis:
        text += ("\n# [analysis] replaced when the study was run: "
                 + ", ".join(f"{k} = {v!r}" for k, v in analysis.items()) + "\n")
    return spec, folder, text


def with_analysis(data: dict, analysis: dict) -> dict:
    """Study data with its ``[analysis]`` fields replaced by ``analysis``."""
    if not analysis:
        return data
    a = dict(data.get("analysis") or {})
    if "duration" in analysis or "cycles" in analysis:  # one run length, the new one
        a.pop("duration", None)
        a.pop("cycles", None)
    a.update(analysis)
    return {**data, "analysis": a}


def _model_data(model) -> dict:
    """The data of a Model given to a study: what it was read from where that still gives
    it (a ``[[planetary]]`` stage's fields then exist, so the study takes the paths a
    file takes, ``planetary.0.sun.mass``), else the model itself in SI."""
    import copy

    from ..model.io import model_from_dict, model_to_dict

    data = model_to_dict(model)
    source = getattr(model, "_source", None)
    if source is not None:
        try:
            if model_to_dict(model_from_dict(source)) == data:
                return copy.deepcopy(source)
        except TorquesplitError:  # (a copy changed after reading: its own data)
            pass
    return data


def _read(source, analysis: dict) -> tuple[StudySpec, Path | None, str]:
    if isinstance(source, StudySpec):
        if not analysis:
            return source, None, json.dumps(source.canonical())
        source = source.canonical()
    if isinstance(source, dict):
        study = source.get("study")
        if isinstance(study, dict) and hasattr(study.get("model"), "meshes"):
            # a Model: its data, which the cases change and the store fingerprints
            source = {**source, "study": {**study, "model": _model_data(study["model"])}}
        return parse_study(with_analysis(source, analysis)), None, json.dumps(source,
                                                                               default=str)
    from .shipped import study_names, study_path

    if not isinstance(source, (str, os.PathLike)):
        from ..errors import OptionTypeError

        raise OptionTypeError(f"a study is a study file's path, a shipped study's name, a dict "
                              f"or a StudySpec; got {source!r:.60} ({type(source).__name__})")
    path = Path(source)
    if not path.is_file():
        if str(source) in study_names():
            path = study_path(str(source))
        elif path.is_dir():
            raise StudyError("", "is a folder, not a study file; give the .toml file (to look "
                                 "at finished results, open DIR/results.nc)", str(source))
        else:
            raise StudyError("", "no such study file (nor a shipped study of that name); "
                                 "check the path, or list shipped studies with "
                                 "'torquesplit study --list' (in Python: "
                                 "torquesplit.study.shipped.study_names())", str(source))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise StudyError("", f"cannot read the file ({exc}); check it is a TOML text file",
                         str(source)) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StudyError("", f"TOML syntax error: {exc}; fix the line it names",
                         str(path)) from None
    try:
        return parse_study(with_analysis(data, analysis)), path.parent, text
    except StudyError as exc:
        given = [(f, m) for f, m in exc.problems
                 if f.startswith("analysis.") and f.split(".")[1] in analysis]
        if given:  # (a field given beside the file, not in it: named as given)
            raise StudyError.of([(f"analysis['{f.split('.')[1]}'] (given with the study "
                                  f"{path.name})", m) for f, m in given]) from None
        raise exc.with_source(str(path)) from None


def parse_study(data: dict) -> StudySpec:
    """Validate study data; every problem becomes one line of a StudyError."""
    from ..model.io import MODEL_SECTIONS

    if (isinstance(data, dict) and "study" not in data
            and any(k in data for k in MODEL_SECTIONS)):
        raise StudyError("", "is a model file (a gearbox, no [study]), not a "
                             "study; run it with 'torquesplit run FILE', vary one of its "
                             "parameters with 'torquesplit sweep FILE --vary PATH=A:B:N', or "
                             "write a study file whose [study] names it: model = 'FILE' (see "
                             "docs/studies.md)")
    given = [d for d in DESIGNS if isinstance(data, dict) and data.get(d) is not None]
    if len(given) > 1:  # said first: an incomplete second design's missing fields hid it
        raise StudyError(given[1], f"a study has one design, here {' and '.join(given)}; "
                                   f"keep one of them (one study file per design)")
    try:
        return StudySpec.model_validate(data)
    except pydantic.ValidationError as exc:
        raise StudyError.of(_problems(exc)) from None


def _problems(exc: pydantic.ValidationError) -> list[tuple[str, str]]:
    """(field, message) of every error, a validator's own problems before missing fields
    (more telling than a missing field elsewhere)."""
    errors = exc.errors(include_url=False)
    errors.sort(key=lambda e: e["type"] == "missing")
    out = []
    seen_union = set()
    for err in errors:
        loc = err["loc"]
        union = bool(loc) and loc[-1] in _UNION_MEMBERS
        parts = [str(p) for p in (loc[:-1] if union else loc) if not _internal(p)]
        problem = (err.get("ctx") or {}).get("error")
        if isinstance(problem, _Problem):
            parts.append(problem.field)
        if union:  # a value that none of a number, a whole number, a text is: one line
            # (a reviewer's nan listed '.int', '.float' and '.str', the validator's names)
            if tuple(parts) in seen_union:
                continue
            seen_union.add(tuple(parts))
            got = repr(err.get("input"))
            out.append((".".join(parts), (
                f"must be a finite number or a value with its unit ('5e8 N/m', '2 mm'), got "
                f"{got if len(got) <= 60 else got[:57] + '...'}; correct the value")))
            continue
        out.append((".".join(parts), _message(err, parts)))
    return out


#: the members of Value's union as pydantic names them in an error's location
_UNION_MEMBERS = ("int", "float", "str")


def _internal(part) -> bool:
    return isinstance(part, str) and ("[" in part or part.startswith("function-"))


def _message(err: dict, parts: list[str]) -> str:
    kind = err["type"]
    ctx = err.get("ctx") or {}
    got = repr(err.get("input"))
    got = got if len(got) <= 60 else got[:57] + "..."
    if kind == "extra_forbidden":
        known = _fields_at(parts[:-1])
        guess = difflib.get_close_matches(parts[-1], known, n=1, cutoff=0.6)
        hint = f"did you mean {guess[0]!r}? " if guess else ""
        return (f"unknown field; {hint}known here: {', '.join(known) or 'none'} "
                f"(see docs/studies.md)")
    if kind == "missing":
        return "required field is missing; add it (see docs/studies.md)"
    if kind in ("value_error", "assertion_error"):
        msg = err["msg"]
        return msg.split(", ", 1)[1] if msg.startswith("Value error, ") else msg
    if kind == "greater_than_equal":
        return f"must be at least {ctx.get('ge')}, got {got}; correct the value"
    if kind == "greater_than":
        return f"must be greater than {ctx.get('gt')}, got {got}; correct the value"
    if kind in ("less_than", "less_than_equal"):
        bound = ctx.get("lt", ctx.get("le"))
        return f"must be {'below' if kind == 'less_than' else 'at most'} {bound}, got {got}; " \
               f"correct the value"
    if kind == "literal_error":
        return f"must be {ctx.get('expected')}, got {got}; use one of these"
    if kind in ("too_short", "too_long"):  # (the count, not the items: tables read badly)
        given = err.get("input")
        n = len(given) if hasattr(given, "__len__") else got
        least, most = ctx.get("min_length"), ctx.get("max_length")
        if kind == "too_short":
            return f"has {n} item(s); give at least {least}"
        return f"has {n} items; give at most {most}"
    if kind.startswith(("model_type", "dict_type", "model_attributes_type")):
        return f"must be a table, got {got}; write it as a [section] or {{key = value}}"
    if kind.startswith("list_type"):
        return f"must be a list, got {got}; write it as [item, item, ...]"
    if kind == "int_from_float":  # ('..., got a number with a fractional part, got 2.5')
        return f"must be a whole number, got {got}; correct the value"
    if kind.startswith(("int_", "float_", "string_", "bool_")) or kind == "union_tag_invalid":
        return f"{err['msg'].replace('Input should be', 'must be')}, got {got}; correct the value"
    msg = err["msg"].replace("Input should be", "must be")
    return f"{msg}, got {got}; correct the value (see docs/studies.md)"


def _fields_at(parts: list[str]) -> list[str]:
    node: Any = StudySpec
    for part in parts:
        node = _strip(node)
        if isinstance(node, type) and issubclass(node, BaseModel):
            f = node.model_fields.get(part)
            if f is None:
                return []
            node = f.annotation
        elif typing.get_origin(node) is list:
            node = typing.get_args(node)[0]
        else:
            return []
    node = _strip(node)
    if isinstance(node, type) and issubclass(node, BaseModel):
        return list(node.model_fields)
    return []


def _strip(tp):
    import types

    while typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) != 1:
            return tp
        tp = args[0]
    return tp
