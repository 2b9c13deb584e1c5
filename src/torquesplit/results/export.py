"""Any result Dataset as a NetCDF, MATLAB or spreadsheet file, chosen by the suffix.

The quasi-static sweep, the speed sweep, the natural modes and the Campbell map are
xarray Datasets; this module writes each of them in the three formats a gearbox engineer
opens (Python, MATLAB, a spreadsheet), safely (:mod:`torquesplit.results.files`).
A dynamic run has its own richer writer (``Results.save``).

CSV: one table per *row dimension* (the first dimension of each variable, in order):
``NAME.csv`` for the first, ``NAME_<dim>.csv`` beside it for each other (named as a
run's tables are where a run has the same one: ``NAME_history.csv`` along time,
``NAME_groups.csv`` per load-sharing group, :data:`TABLE_FILES`), and
``NAME_about.json`` (provenance, model, warnings, the Dataset's attributes).  A row per
coordinate value; a 1-D variable is one column, a variable with more dimensions one
column per label of the others (``dynamic_factor_m11``); every column's unit is in its
name (``speed_rad/s``), as in a run's CSV files.  Scalar variables are columns of the
first table.  MATLAB: every variable and coordinate, with ``units``, ``descriptions`` and
``attributes`` structs and a ``provenance`` struct naming the run.
"""

from __future__ import annotations

import itertools
import json
import re
from pathlib import Path

import numpy as np

from .. import _json
from ..errors import OutputError, clip_path
from . import files

#: suffix -> format of a Dataset export
DATASET_FORMATS = {".nc": "netcdf", ".netcdf": "netcdf", ".h5": "netcdf", ".mat": "mat",
                   ".csv": "table"}

__all__ = ["DATASET_FORMATS", "row_dims", "check_dataset_output", "save_dataset",
           "dataset_files"]


#: row dimension -> the name of its table beside ``NAME.csv`` where it is not the
#: dimension's own: a run's CSV set names these so (a quasi-static sweep's were
#: NAME_time.csv and NAME_group.csv beside a run's NAME_history.csv and NAME_groups.csv,
#: an exports review)
TABLE_FILES = {"time": "history", "group": "groups"}


def table_path(path: Path, dim: str) -> Path:
    """The file of the table whose rows run along ``dim``, beside ``path`` (NAME.csv)."""
    return path.with_name(f"{path.stem}_{TABLE_FILES.get(dim, dim)}.csv")


def row_dims(ds) -> tuple[str, ...]:
    """The row dimension of each CSV table: the first dimension of each data variable, in
    the order the variables come (a Dataset of scalars only: the table '' of one row)."""
    out: list[str] = []
    for name in ds.data_vars:
        dims = ds[name].dims
        if dims and dims[0] not in out:
            out.append(dims[0])
    return tuple(out) or ("",)


def check_dataset_output(path, tables: tuple[str, ...] = (), *, overwrite: bool = False,
                         what: str = "results") -> files.OutputPlan:
    """Check ``path`` as :func:`files.check_output` does, for a Dataset export: before
    the computation with ``tables`` empty (the file named), at the save with the
    Dataset's :func:`row_dims` (a ``.csv`` also writes ``NAME_<dim>.csv`` beside
    ``NAME.csv`` for each but the first)."""
    plan = files.check_output(path, formats=DATASET_FORMATS, overwrite=overwrite, what=what)
    if plan.format != "table":
        return plan
    extra = tuple(table_path(plan.path, d) for d in tables[1:])
    extra += (files.about_path(plan.path),)
    for f in extra:
        if (f.exists() or f.is_symlink()) and not overwrite:
            raise OutputError(f"{clip_path(f)} exists; use --force (overwrite=True in "
                              f"Python) to replace it, or choose another file")
    return files.OutputPlan(path=plan.path, format="table", files=(plan.path,) + extra,
                            overwrite=overwrite)


def _unit_suffix(attrs) -> str:
    """``_unit`` for a column name ("" for none, "1", or a unit in words with commas that
    would break the header: its description says it)."""
    unit = str(attrs.get("units", "")).replace(" ", "")
    return "" if unit in ("", "1") or "," in unit or "(" in unit else f"_{unit}"


def _column(name: str, suffix: str) -> str:
    """A column name with its unit (not twice: ``speed_rpm`` stays as it is)."""
    return name if name.endswith(suffix) else name + suffix


def _cell(v):
    if isinstance(v, (np.floating, float)):
        return float(v)
    if isinstance(v, (np.integer, int, np.bool_, bool)):
        return int(v)
    return str(v)


def _labels(ds, dim) -> list[str]:
    """A dimension's labels as parts of column names (no commas or spaces)."""
    values = ds[dim].values if dim in ds.coords else np.arange(ds.sizes[dim])
    return [re.sub(r"[^\w.+-]+", "_", str(_cell(v))).strip("_") for v in values]


def _table(ds, dim) -> tuple[list[str], list[list]]:
    """Header and rows of the table whose rows run along ``dim`` ('' = one row)."""
    n = ds.sizes[dim] if dim else 1
    header: list[str] = []
    columns: list[np.ndarray] = []
    if dim:
        coord = ds[dim] if dim in ds.coords else None
        header.append(_column(dim, _unit_suffix(coord.attrs)) if coord is not None else dim)
        columns.append(coord.values if coord is not None else np.arange(n))
        for c in ds.coords:  # the other coordinates along the rows (speed_rpm by point)
            if c != dim and ds[c].dims == (dim,):
                header.append(_column(c, _unit_suffix(ds[c].attrs)))
                columns.append(ds[c].values)
    first = row_dims(ds)[0]
    for name in ds.data_vars:
        da = ds[name]
        if (da.dims[0] if da.dims else first) != dim:
            continue
        unit = _unit_suffix(da.attrs)
        if da.ndim <= 1:
            header.append(_column(name, unit))
            columns.append(np.broadcast_to(da.values, (n,)))
            continue
        rest = da.dims[1:]
        # a unit per column where the variable's differs along its last dimension
        # ("m or rad": a coordinate DIM_unit names each, as element_unit does)
        per = f"{rest[-1]}_unit"
        units = ([_unit_suffix({"units": u}) for u in ds[per].values]
                 if " or " in str(da.attrs.get("units", "")) and per in ds.coords else None)
        labels = [_labels(ds, d) for d in rest]
        # (a name that ends in its unit keeps it once, at the end: 'transmission_error_
        # 10kN_arcsec', not 'transmission_error_arcsec_10kN_arcsec')
        base = name[:-len(unit)] if units is None and unit and name.endswith(unit) else name
        for idx in itertools.product(*(range(ds.sizes[d]) for d in rest)):
            label = "_".join(lab[i] for lab, i in zip(labels, idx))
            header.append(f"{base}_{label}{unit if units is None else units[idx[-1]]}")
            columns.append(da.values[(slice(None),) + idx])
    rows = [[_cell(col[i]) for col in columns] for i in range(n)]
    return header, rows


def _mat_name(name: str, taken: set) -> str:
    """A MATLAB identifier for a variable name, not in ``taken``: letters, digits and
    '_', a letter first, at most 63 characters, a number added where two names meet."""
    out = re.sub(r"\W", "_", name)
    out = (out if out[:1].isalpha() else "v_" + out)[:63]
    base, k = out, 2
    while out in taken:
        tail = f"_{k}"
        out, k = base[:63 - len(tail)] + tail, k + 1
    taken.add(out)
    return out


def _mat_attribute(v):
    """A Dataset attribute as MATLAB reads it best: a number (or a vector of numbers) as
    a double, a text as a char array, anything else as JSON text (a reviewer's MATLAB
    needed str2double on 'system_load_sharing = '1.045...'')."""
    if isinstance(v, (bool, np.bool_, int, float, np.integer, np.floating)):
        return float(v)
    if isinstance(v, np.ndarray) and v.dtype.kind in "biuf":
        return v.astype(float)
    if (isinstance(v, (list, tuple)) and v and all(
            isinstance(x, (bool, int, float, np.number)) for x in v)):
        return np.asarray(v, dtype=float)
    if isinstance(v, (list, tuple)) and v and all(isinstance(x, str) for x in v):
        return np.asarray(v, dtype=object)  # (a cell array of texts)
    if isinstance(v, str):
        return v
    return _json.dumps(v.tolist() if isinstance(v, np.ndarray) else v, default=str)


def mat_fields(ds, run_id: str, attrs=None) -> dict:
    """A Dataset as the fields of a .mat file, the layout every command's .mat shares:
    each variable and coordinate as an array (texts as cell arrays) under a MATLAB name,
    and the structs ``names`` (field -> the Dataset's name), ``units``, ``dimensions``,
    ``descriptions``, ``attributes`` (the Dataset's, or ``attrs``) and ``provenance``."""
    names = list(ds.data_vars) + list(ds.coords)
    taken = {"units", "descriptions", "attributes", "provenance", "names", "dimensions"}
    ident = {n: _mat_name(n, taken) for n in names}
    data = {}
    from .dataset import is_flag

    for name in names:
        values = ds[name].values
        # flags (bool, or 0/1 marked with CF flag_values) as MATLAB logicals (scipy writes
        # a bool array so); counts and indices as doubles, MATLAB's own type, in which
        # they take part in arithmetic as numbers (an int64 divides with rounding and
        # mixes with nothing but scalars)
        data[ident[name]] = (np.asarray(values, dtype=object) if values.dtype.kind in "UO"
                             else np.asarray(values, dtype=bool) if is_flag(ds[name].attrs)
                             else np.asarray(values, dtype=float) if values.dtype.kind in "iu"
                             else np.asarray(values))
    data["units"] = {ident[n]: str(ds[n].attrs.get("units", "")) for n in names}
    data["dimensions"] = {ident[n]: " x ".join(ds[n].dims) or "scalar" for n in names}
    # (what it is, then the definition a NetCDF keeps in 'comment': a long_name is a
    # plot label)
    data["descriptions"] = {ident[n]: " ".join(filter(None, (
        str(ds[n].attrs.get("long_name", "")), str(ds[n].attrs.get("comment", "")))))
        for n in names}
    data["names"] = {ident[n]: n for n in names}  # the Dataset's own names
    akeys: set = set()
    data["attributes"] = {_mat_name(k, akeys): _mat_attribute(v)
                          for k, v in (ds.attrs if attrs is None else attrs).items()}
    # the model, metrics and warnings at the top, where a run's .mat has them (not only
    # inside 'attributes')
    for key in ("model_json", "metrics_json"):
        if isinstance(ds.attrs.get(key), str) and key not in data:
            data[key] = ds.attrs[key]
    if isinstance(ds.attrs.get("warnings_json"), str) and "warnings" not in data:
        data["warnings"] = files.cell_column(json.loads(ds.attrs["warnings_json"]))
    data["provenance"] = files.provenance(run_id, ds.attrs.get("model_json"))
    return data


def _write(ds, plan: files.OutputPlan, claim: files.OutputClaim) -> Path:
    """Write ``ds`` to the files of ``plan`` under ``claim`` (NetCDF with the run's
    provenance in its attributes, MATLAB, or the CSV tables)."""
    ds = ds.copy()
    attrs = dict(ds.attrs)  # (their own types: MATLAB reads a list of numbers as a vector)
    for k, v in list(ds.attrs.items()):  # NetCDF attributes: strings and numbers
        if isinstance(v, (list, tuple, dict)):
            ds.attrs[k] = _json.dumps(v, default=str)
    if plan.format == "netcdf":
        ds.attrs.update(files.provenance(claim.run_id, ds.attrs.get("model_json")))
        claim.write({plan.path: files.netcdf_bytes(ds)})
    elif plan.format == "mat":
        claim.write({plan.path: files.mat_bytes(mat_fields(ds, claim.run_id, attrs))})
    else:
        dims = row_dims(ds)
        contents = {f: files.csv_bytes(*_table(ds, d)) for f, d in zip(plan.files[1:], dims[1:])}
        # what the tables cannot hold: provenance, model, warnings, the other attributes
        warnings = json.loads(ds.attrs["warnings_json"]) if "warnings_json" in ds.attrs else []
        rest = {k: v for k, v in ds.attrs.items()
                if k not in ("model_json", "warnings", "warnings_json")}
        # a JSON text attribute as the object it is (the metrics were a string inside
        # the JSON file, an exports review): metrics_json -> metrics
        for k in [k for k in rest if k.endswith("_json") and isinstance(rest[k], str)]:
            try:
                rest[k[:-len("_json")]] = json.loads(rest.pop(k))
            except ValueError:
                rest[k] = ds.attrs[k]
        contents[files.about_path(plan.path)] = files.about_bytes(
            claim.run_id, ds.attrs.get("model_json"), warnings, attributes=rest,
            files=plan.files)
        contents[plan.path] = files.csv_bytes(*_table(ds, dims[0]))  # last: marks the set
        claim.write(contents)
    return plan.path


def save(result, path, *, overwrite: bool = False) -> Path:
    """Save any torquesplit result by the suffix of ``path`` (``.nc`` NetCDF, ``.mat``
    MATLAB, ``.csv`` spreadsheet tables), as the command that computes it writes it:
    a run's :class:`~torquesplit.results.Results`, a steady state, quasi-static load
    sharing, modes, a contact analysis (their own ``save``), the Dataset of
    :func:`~torquesplit.sweep_speed` or :func:`~torquesplit.run_study`, or what
    :func:`~torquesplit.campbell` returns.  Atomically; an existing file is kept unless
    ``overwrite``.  Returns the path written.  (``Dataset.to_netcdf`` writes NetCDF
    whatever the suffix: a '.csv' that no spreadsheet opens.)"""
    import xarray as xr

    from ..errors import OptionError

    if isinstance(result, tuple) and len(result) == 2 and isinstance(result[0], xr.Dataset):
        result = result[0]  # campbell's (map, crossings): the map holds the crossings
    if isinstance(result, xr.Dataset):
        from ..study.dataset import is_study, save_study

        return (save_study if is_study(result) else save_dataset)(result, path,
                                                                  overwrite=overwrite)
    if callable(getattr(result, "save", None)):
        return result.save(path, overwrite=overwrite)
    raise OptionError(f"torquesplit.save takes a result of torquesplit (simulate, "
                      f"steady_state, quasi_static_load_sharing, model_modes, "
                      f"contact_analysis, sweep_speed, campbell, run_study), not a "
                      f"{type(result).__name__}")


def with_model(ds, model, warnings=()):
    """``ds`` with the model it came from (``model_json``, as a run's file holds it: the
    file can be re-run; its name as ``model`` where the Dataset has none) and the
    warnings its command printed."""
    from ..model.io import model_to_json

    ds = ds.copy()
    ds.attrs.setdefault("model", model.model.name)
    ds.attrs["model_json"] = model_to_json(model)
    ds.attrs["warnings"] = "\n".join(warnings)
    ds.attrs["warnings_json"] = json.dumps(list(warnings))
    return ds


#: row dimensions of the Datasets the commands write: a replaced CSV set's companions
def dataset_files(ds, path) -> list[Path]:
    """Every file a save of ``ds`` to ``path`` writes (a ``.csv``: ``NAME.csv`` and its
    other tables), to name them all where the save is reported."""
    return list(check_dataset_output(path, row_dims(ds), overwrite=True).files)


#: named so, left from an earlier save of another shape, are removed with it
KNOWN_TABLES = ("time", "mesh", "group", "planet_entity", "dof", "mode", "point", "check",
                "speed", "crossing", "position", "slice", "harris_load") + tuple(
    TABLE_FILES.values())


def save_dataset(ds, path, *, overwrite: bool = False) -> Path:
    """Save a result Dataset by suffix: ``.nc`` NetCDF, ``.mat`` MATLAB, ``.csv``
    spreadsheet tables (module docstring); atomically, an existing file kept unless
    ``overwrite``.  Returns the path written.

    Raises
    ------
    OutputError
        As :func:`files.check_output` (a companion CSV that exists included).
    """
    plan = check_dataset_output(path, row_dims(ds), overwrite=overwrite)
    with files.claim_output(plan) as claim:
        out = _write(ds, plan, claim)
    if plan.format == "table" and overwrite:  # (replacing: no stale companion beside it)
        for d in KNOWN_TABLES:  # (and by their earlier names: NAME_time.csv)
            old = plan.path.with_name(f"{plan.path.stem}_{d}.csv")
            if old not in plan.files and old.is_file():
                old.unlink()
    return out
