"""A study's results as an :class:`xarray.Dataset`.

=====================  ==================================================================
dimensions             grid: one per parameter, in the study's order, coordinates = the
                       values (SI, ``units`` attribute; ``display_units`` = the unit the
                       study file used); Monte Carlo and sensitivity: ``sample``, with
                       each parameter as a coordinate along it
output variables       one per requested output, named as the output
                       (``load_sharing.engineering.stage1``; a ``/`` of a group key is
                       written ``|``, as NetCDF forbids ``/``); ``units``, ``long_name``
                       and the exact ``output`` name as attributes; NaN where a case
                       failed
``status``             ok / contact_lost / diverged / refused / error (/ missing)
``reason``             why a case is not ok ("" when it is)
``settled``            1 when the metrics found a settled part and, with a settle rule,
                       the outputs (``settle_time`` excepted) agreed between the last
                       two run lengths; 0 otherwise (runs only: a quasi-static
                       study has no such variable)
``warnings``           the case's warnings, one a line ("" when none): the model checks'
                       (a unit slip), the run's (too short to tell whether it settled,
                       not settled, contact loss...); ``warning_count``: how many
``simulated_time``     simulated time of the (last) run of each case [s]
``case_wall_time``     seconds each case took on its worker (the only variable that
                       differs between two runs of the same study)
sensitivity            variables over (``output``, ``factor``): ``mu_star``, ``mu``,
                       ``sigma``, ``mu_star_conf`` (Morris) or ``S1``, ``ST``,
                       ``S1_conf``, ``ST_conf`` (Sobol; attribute
                       ``sensitivity_warnings``: JSON list of factors whose S1 exceeds
                       ST beyond the intervals)
attributes             study name, description, reference, design, the study file's
                       text, the model (JSON, SI) and both hashes, torquesplit version
=====================  ==================================================================
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from . import outputs as out_mod


def variable_name(output: str) -> str:
    """Dataset variable of an output name (NetCDF forbids ``/`` in names)."""
    return output.replace("/", "|")


def build_dataset(plan, rows, n: int, meta: dict):
    """Dataset of the first ``n`` cases of ``plan`` from the finished ``rows``."""
    import xarray as xr

    from ..results.dataset import FLAG

    names = plan.outputs
    d = plan.design
    values = np.full((n, len(names)), np.nan)
    status = np.full(n, "missing", dtype=object)
    reason = np.full(n, "not computed", dtype=object)
    settled = np.zeros(n, dtype=bool)
    sim_time = np.full(n, np.nan)
    wall = np.full(n, np.nan)
    warned = np.full(n, "", dtype=object)
    n_warned = np.zeros(n, dtype=np.int32)
    for r in rows:
        i = r["index"]
        values[i] = [math.nan if v is None else v for v in r["values"]]
        status[i] = r["status"]
        reason[i] = r["reason"]
        if r["status"] == "refused" and i < d.n_cases:  # the model speaks SI: add the
            reason[i] += " (this case: " + ", ".join(  # values as the study wrote them
                f"{p.name} = {p.show(v)}" for p, v in zip(d.parameters, d.values[i],
                                                            strict=True)) + ")"
        # a case without outputs (refused, diverged, error) found no settled part (said
        # here, where every runner's and every stored row is read)
        settled[i] = r["settled"] and r["status"] in ("ok", "contact_lost")
        sim_time[i] = np.nan if r["simulated_time"] is None else r["simulated_time"]
        wall[i] = r["wall_time"]
        notes = r.get("warnings") or []
        warned[i] = "\n".join(notes)
        n_warned[i] = len(notes)
    if d.kind == "grid":
        dims = tuple(p.name for p in d.parameters)
        shape = d.shape
        spacing = d.extra.get("spacing") or ["values"] * len(d.parameters)
        coords = {p.name: (p.name, axis, {**_param_attrs(p), "spacing": sp})
                  for p, axis, sp in zip(d.parameters, d.axes, spacing, strict=True)}
    else:
        dims = ("sample",)
        shape = (n,)
        coords = {"sample": ("sample", np.arange(n), {"long_name": "case index"})}
        for j, p in enumerate(d.parameters):
            coords[p.name] = ("sample", d.values[:n, j].copy(), _param_attrs(p))

    def var(a, attrs):
        return (dims, np.asarray(a).reshape(shape), attrs)

    data = {}
    for j, name in enumerate(names):
        data[variable_name(name)] = var(values[:, j], {
            "units": out_mod.output_unit(name), "long_name": out_mod.output_long_name(name),
            "output": name})
    data["status"] = var(status.astype(str), {
        "long_name": "case status", "flag_meanings": "ok contact_lost diverged refused error "
                                                     "missing"})
    data["reason"] = var(reason.astype(str), {"long_name": "why the case is not ok"})
    if plan.analysis["type"] != "static":  # (a quasi-static sweep has nothing to settle)
        data["settled"] = var(settled.astype(np.int8), {
            **FLAG, "units": "1", "long_name": "1: the run's metrics found a settled part and, with "
                                       "analysis.settle, the outputs (settle_time excepted) "
                                       "agreed between the last two run lengths; 0: not"})
    data["warnings"] = var(warned.astype(str), {
        "long_name": "the case's warnings (model checks, run plausibility), one a line"})
    data["warning_count"] = var(n_warned, {"units": "1", "long_name": "number of warnings "
                                                                      "of the case"})
    data["simulated_time"] = var(sim_time, {"units": "s", "long_name": "simulated time of "
                                                                       "the case's run"})
    data["case_wall_time"] = var(wall, {"units": "s", "long_name": "wall time of the case "
                                                                   "on its worker"})
    attrs = {
        "title": f"torquesplit study: {plan.spec.study.name}",
        "study_name": plan.spec.study.name,
        "model_name": plan.model.model.name,
        "description": plan.spec.study.description,
        "reference": plan.spec.study.reference,
        "design": d.kind,
        "analysis": plan.analysis["type"],
        # the analysis as run: the study file's, with the command line's --duration,
        # --cycles... (study_toml below is the file as written)
        "analysis_settings": json.dumps(plan.analysis, default=str, sort_keys=True),
        "outputs": json.dumps(names),
        "study_hash": plan.study_hash,
        "model_hash": plan.model_hash,
        "model_source": plan.model_source,
        "torquesplit_version": str(meta.get("torquesplit_version", "")),
        # the study as given: a file's TOML, or the JSON of a dict / a sweep's options
        ("study_json" if plan.study_text.lstrip().startswith("{") else "study_toml"):
            plan.study_text,
        "model_json": json.dumps(plan.model_dict),
        "cases": int(n),
    }
    if d.kind == "monte_carlo":
        mc = plan.spec.monte_carlo
        attrs.update(sampling=mc.sampling, seed=mc.seed)
        if mc.stop is not None:
            attrs["stopping_rule"] = json.dumps(mc.stop.model_dump())
            attrs["stopped_at"] = int(n)
    if "gpu_backend" in meta:  # the GPU runs' device, times and FP32 error (torquesplit.gpu)
        attrs["gpu_backend"] = json.dumps(meta["gpu_backend"])
    if meta.get("backend_fallback"):  # backend 'gpu' asked, run on the CPU runner: why
        attrs["backend_fallback"] = str(meta["backend_fallback"])
    ds = xr.Dataset(data, coords=coords, attrs=attrs)
    if d.kind == "sensitivity":
        ds = _add_indices(ds, plan, values[:n])
    return ds


def _param_attrs(p) -> dict:
    return {"units": p.unit, "long_name": p.describe(),
            "display_units": p.display_unit or p.unit, "paths": json.dumps(p.paths),
            "mode": p.mode}


def _add_indices(ds, plan, values):
    from .sensitivity import indices, ranking_key

    d = plan.design
    names = plan.outputs
    results = [indices(d, values[:, j]) for j in range(len(names))]
    keys = [k for k in results[0] if np.ndim(results[0][k]) == 1]
    factors = [p.name for p in d.parameters]
    # Morris's effects are changes of the output: its unit (Sobol's indices are shares)
    units = [ds[variable_name(n)].attrs.get("units", "1") if variable_name(n) in ds else "1"
             for n in names]
    one = units[0] if len(set(units)) == 1 else "per output: see output_unit"
    for k in keys:
        ds[k] = (("output", "factor"), np.array([r[k] for r in results]),
                 {"units": one if k in _EFFECTS else "1",
                  "long_name": _INDEX_NAMES.get(k, k)})
    used = "trajectories_used" if d.extra["method"] == "morris" else "samples_used"
    total = d.extra["trajectories"] if d.extra["method"] == "morris" else d.extra["samples"]
    ds[used] = (("output",), np.array([int(r[used]) for r in results]), {
        "units": "1", "total": int(total),
        "long_name": f"{used.split('_')[0]} whose cases all have a finite value (the "
                     f"indices are over these, of {int(total)})"})
    ds = ds.assign_coords(output=("output", [variable_name(n) for n in names]),
                          factor=("factor", factors),
                          output_unit=("output", units, {"long_name": "unit of each output "
                                                         "(and of its Morris effects)"}))
    ds.attrs.update(sensitivity_method=d.extra["method"], ranking=ranking_key(d),
                    seed=plan.spec.sensitivity.seed)
    notes = sobol_warnings(ds) if d.extra["method"] == "sobol" else []
    if notes:
        ds.attrs["sensitivity_warnings"] = json.dumps(notes)
    return ds


SOBOL_WIDE = 0.1
"""A 95 % half-width of the leading factor's total index above this (a tenth of the whole
variance) leaves the ranking unresolved: said, with the remedy."""


def sobol_warnings(ds) -> list[str]:
    """Signs that the Sobol indices are not converged (too few samples, or an output with
    failed cases), one line per output: an index outside [0, 1] (a share of the variance
    cannot be, beyond its interval; a reviewer's 8 samples gave S1 = 1.45 +/- 0.87 and
    ST = 1.25 +/- 0.55 unflagged: ST's is beyond it), a first-order index
    above the total one beyond both bootstrap half-widths (S1 <= ST holds for the true
    indices), and a wide interval on the leading factor's total index."""
    notes = []
    for o, out_name in enumerate(ds["output"].values):
        why, outside = [], []
        for f, factor in enumerate(ds["factor"].values):
            s1, st = float(ds["S1"].values[o, f]), float(ds["ST"].values[o, f])
            c1, ct = float(ds["S1_conf"].values[o, f]), float(ds["ST_conf"].values[o, f])
            outside += [f"{name} of {factor} {x:.3g} +/- {c:.2g}"
                        for name, x, c in (("S1", s1, c1), ("ST", st, ct))
                        if x - np.nan_to_num(c) > 1.0 or x + np.nan_to_num(c) < 0.0]
            if s1 - st > np.nan_to_num(c1) + np.nan_to_num(ct):
                why.append(f"S1 of {factor} ({s1:.3g} +/- {c1:.2g}) exceeds its ST "
                           f"({st:.3g} +/- {ct:.2g}) beyond the 95 % intervals")
        if outside:
            why.insert(0, f"{' and '.join(outside)} outside [0, 1], where a share of the "
                          f"variance lies")
        st_row = np.nan_to_num(ds["ST"].values[o], nan=-np.inf)
        if np.isfinite(st_row).any() and not outside:
            lead = int(np.argmax(st_row))
            ct = float(ds["ST_conf"].values[o, lead])
            if ct > SOBOL_WIDE:
                why.append(f"the leading factor's total index is {st_row[lead]:.3g} +/- "
                           f"{ct:.2g} ({ds['factor'].values[lead]}): the ranking is not "
                           f"resolved")
        if why:
            notes.append(f"{out_name}: " + "; ".join(why) + "; the indices are not "
                         "converged: raise sensitivity.samples (a power of 2)")
    return notes


#: indices in the output's unit (the others are dimensionless)
_EFFECTS = ("mu_star", "mu", "sigma", "mu_star_conf")

_INDEX_NAMES = {
    "mu_star": "Morris mu*: mean |elementary effect| (output change over the factor's range)",
    "mu": "Morris mu: mean elementary effect",
    "sigma": "Morris sigma: standard deviation of the elementary effects",
    "mu_star_conf": "half-width of the 95 % bootstrap interval of mu*",
    "S1": "first-order Sobol index", "ST": "total Sobol index",
    "S1_conf": "half-width of the 95 % bootstrap interval of S1",
    "ST_conf": "half-width of the 95 % bootstrap interval of ST",
}


def write_dataset(ds, path) -> Path:
    """Save a study Dataset as NetCDF, and beside it the same cases for a spreadsheet
    (``.csv``: :func:`case_table_bytes`, and a sensitivity's indices) and for MATLAB
    (``.mat``: :func:`case_mat_bytes`); each file whole or absent (:func:`save_study`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for suffix in (".nc", ".csv", ".mat"):
        save_study(ds, path.with_suffix(suffix), overwrite=True)
    return path


def is_study(ds) -> bool:
    """Whether a Dataset is a study's (:func:`build_dataset`): its cases' status and the
    study's hash."""
    return "status" in ds and "study_hash" in ds.attrs


def save_study(ds, path, *, overwrite: bool = False) -> Path:
    """Save a study Dataset by suffix as ``torquesplit study`` writes its results
    (``.nc`` with provenance, ``.csv`` :func:`case_table_bytes` and a sensitivity's
    ``NAME_sensitivity.csv``, ``.mat`` :func:`case_mat_bytes`); atomically, an existing
    file kept unless ``overwrite``.  Returns the path written."""
    from ..results import files
    from ..results.export import DATASET_FORMATS

    plan = files.check_output(path, formats=DATASET_FORMATS, overwrite=overwrite)
    contents = {}
    if plan.format == "netcdf":
        contents[plan.path] = files.netcdf_bytes(ds.assign_attrs(
            **files.provenance(_run_id(ds), ds.attrs.get("model_json"))))
    elif plan.format == "mat":
        contents[plan.path] = case_mat_bytes(ds)
    else:
        # a sensitivity's indices for a spreadsheet too (they were in the .nc and .mat
        # only, a studies reviewer)
        indices = plan.path.with_name(f"{plan.path.stem}_sensitivity.csv")
        if "factor" not in ds.dims and overwrite and indices.is_file():
            indices.unlink()  # (an earlier study's, in this folder)
        if "factor" in ds.dims:
            if indices.exists() and not overwrite:
                from ..errors import OutputError

                raise OutputError(f"{indices} exists; use overwrite=True to replace it, or "
                                  f"choose another file")
            plan = files.OutputPlan(path=plan.path, format="table",
                                    files=(plan.path, indices), overwrite=overwrite)
            contents[indices] = indices_table_bytes(ds)
        contents[plan.path] = case_table_bytes(ds)  # (last: marks the set)
    with files.claim_output(plan, _run_id(ds) or None) as claim:
        claim.write(contents)
    return plan.path


def indices_table_bytes(ds) -> bytes:
    """A sensitivity's indices as a spreadsheet: a row per (output, factor), the output
    by its study-file name with its unit, the factor, its rank for that output (1: the
    most important, by the study's ranking index) and every index (Morris mu, mu_star,
    sigma, mu_star_conf; Sobol S1, ST and their intervals)."""
    from ..results.files import csv_bytes

    keys = [k for k in ds.data_vars if ds[k].dims == ("output", "factor")]
    by = ds.attrs.get("ranking", keys[0] if keys else None)
    header = ["output", "output_unit", "factor", "rank"] + [
        f"{k} [{ds[k].attrs['units']}]" if ds[k].attrs.get("units", "1") not in ("", "1")
        else k for k in keys]
    rows = []
    for o, out in enumerate(ds["output"].values):
        name = str(out).replace("|", "/")
        unit = str(ds["output_unit"].values[o]) if "output_unit" in ds.coords else ""
        score = np.nan_to_num(np.asarray(ds[by].values[o], float), nan=-np.inf)
        rank = np.empty(score.size, int)
        rank[np.argsort(-score, kind="stable")] = np.arange(1, score.size + 1)
        for f, factor in enumerate(ds["factor"].values):
            rows.append([name, unit, str(factor), int(rank[f])]
                        + [float(ds[k].values[o, f]) for k in keys])
    return csv_bytes(header, rows)


def _case_variables(ds) -> list[str]:
    """The variables with one value per case (the status's dimensions): the outputs,
    status, reason, timings; a Monte Carlo's or sensitivity's parameter values are
    coordinates along ``sample``."""
    dims = ds["status"].dims
    return [v for v in ds.data_vars if ds[v].dims == dims and ds[v].dtype.kind in "fiubUSO"]


def _header(ds, name: str) -> str:
    unit = ds[name].attrs.get("units", "")
    # (an output by the name the study file and --json give it: 'left/bevel', not the
    # NetCDF-safe variable name 'left|bevel', a studies reviewer)
    name = ds[name].attrs.get("output", name)
    return name if unit in ("", "1") else f"{name} [{unit}]"


#: between a case's warnings in its results.csv cell: '; ', which the warnings' own texts
#: contain, split two warnings into five (a studies reviewer)
WARNING_JOIN = " || "


def case_table_bytes(ds) -> bytes:
    """The study as a spreadsheet: one row per case, the parameter values (SI, the unit
    in the header) then every per-case variable (outputs, status, reason, timings)."""
    from ..results.files import csv_bytes

    names = _case_variables(ds)
    frame = ds[names].reset_coords().to_dataframe().reset_index()
    if "sample" not in frame.columns:  # a grid: its rows in case order (C order of the
        frame.insert(0, "sample", np.arange(len(frame)))  # grid, as the summary counts)
    # the case's index and parameters first (a grid's dimensions, a sample's
    # coordinates), then its variables
    first = ["sample"] + [c for c in frame.columns
                          if c != "sample" and (c in ds.coords or c in ds.dims)]
    keep = first + [c for c in frame.columns if c in names and c not in first]
    header = ["case" if c == "sample" else _header(ds, c) if c in ds.variables else c
              for c in keep]
    rows = frame[keep].itertuples(index=False, name=None)
    # a case's warnings one a line in the Dataset; WARNING_JOIN in a cell (a line break
    # inside a quoted cell is CSV, but tools that count lines miscount the cases)
    at = keep.index("warnings") if "warnings" in keep else -1
    return csv_bytes(header, [[(str(v).replace("\n", WARNING_JOIN) if i == at else
                                v.item() if hasattr(v, "item") else v)
                               for i, v in enumerate(r)] for r in rows])


def case_mat_bytes(ds) -> bytes:
    """The study for MATLAB, laid out as a run's .mat
    (:func:`torquesplit.results.export.mat_fields`): every per-case variable and
    coordinate as an array of the study's shape (a grid's dimensions, or one per
    sample), a sensitivity's indices over (output, factor), strings as cell arrays; the
    structs ``names``, ``units``, ``dimensions`` and ``descriptions`` per field, and
    ``attributes`` with the study's text, hashes, seed and stopping-rule outcome (a
    reviewer's MATLAB had the cases but neither the ranking nor where they came from)."""
    from ..results.export import mat_fields
    from ..results.files import mat_bytes

    return mat_bytes(mat_fields(ds, _run_id(ds)))


def _run_id(ds) -> str:
    """The run id of a study's files: the start of its study hash."""
    return str(ds.attrs.get("study_hash", ""))[:16]


def ranking(ds, output: str) -> list[tuple[str, float]]:
    """Factors of a sensitivity Dataset ranked by importance for one output."""
    key = ds.attrs["ranking"]
    row = ds[key].sel(output=variable_name(output)).values
    order = np.argsort(-np.nan_to_num(row, nan=-np.inf))
    return [(str(ds["factor"].values[i]), float(row[i])) for i in order]


# a number standing alone (not the digits of a name such as mesh 'in1' or 'm46')
_NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?(?![\w])")


def warning_groups(ds) -> list[dict]:
    """The cases' warnings grouped by what they say (texts that differ only in their
    numbers are one group; names such as 'in1' and 'in2' are not numbers):
    ``[{"text": ..., "cases": [case indices]}]``, the group with most cases first.  The
    text is the cases' common text with each number that differs between them given as
    its range over the group ('15.1 to 18.34 kN'), so that it says nothing about one
    case that another contradicts."""
    if "warnings" not in ds:
        return []
    groups: dict[str, dict] = {}
    for i, text in enumerate(ds["warnings"].values.ravel().tolist()):
        for line in filter(None, str(text).split("\n")):
            g = groups.setdefault(_NUMBER.sub("#", line), {"lines": [], "cases": []})
            if not g["cases"] or g["cases"][-1] != i:
                g["cases"].append(i)
                g["lines"].append(line)
    out = [{"text": _merged(g["lines"]), "cases": g["cases"]} for g in groups.values()]
    return sorted(out, key=lambda g: (-len(g["cases"]), g["cases"][0]))


def _merged(lines: list[str]) -> str:
    """One text for lines that differ only in their numbers: each number as the range
    of its values over the lines where they differ."""
    numbers = [[m.group(0) for m in _NUMBER.finditer(line)] for line in lines]
    parts = iter(range(len(numbers[0])))

    def one(match) -> str:
        k = next(parts)
        seen = [n[k] for n in numbers]
        if len(set(seen)) == 1:
            return seen[0]
        by_value = sorted(seen, key=float)
        return f"{by_value[0]} to {by_value[-1]}"

    return _NUMBER.sub(one, lines[0])


def case_ranges(cases: list[int]) -> str:
    """[0, 1, 2, 5] -> "cases 0-2, 5"."""
    parts, start = [], None
    for j, c in enumerate(cases):
        if start is None:
            start = c
        if j + 1 == len(cases) or cases[j + 1] != c + 1:
            parts.append(f"{start}" if start == c else f"{start}-{c}")
            start = None
    return ("case " if len(cases) == 1 else "cases ") + ", ".join(parts)


def display_values(ds, name) -> tuple[np.ndarray, str]:
    """A parameter's values in the study's display unit (its ``display_units``, SI if
    that is unknown) and the unit as tables and figures write it ("-" for a factor)."""
    c = ds[name]
    si = c.attrs.get("units", "1")
    disp = c.attrs.get("display_units", si)
    values = np.asarray(c.values, dtype=float)
    if disp != si and si != "1":
        from ..model.units import convert

        try:
            return np.array([convert(v, si, disp) for v in values]), unit_text(disp)
        except Exception:  # an unknown display unit: show SI
            return values, unit_text(si)
    return values, ("-" if si == "1" else unit_text(si))


def unit_text(unit: str) -> str:
    """A unit as tables and figures write it: µm, not um."""
    return re.sub(r"\bu(?=[mgsNV]\b)", "µ", unit)
