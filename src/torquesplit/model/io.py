"""Read and write model files (TOML, or JSON) and turn schema errors into clear messages."""

from __future__ import annotations

import json
import tomllib
import warnings
from pathlib import Path
from typing import Any

import pydantic

from ..errors import ModelError
from .schema import Model


def load_model(source, *, check: bool = True) -> Model:
    """Read a model file (``.toml`` or ``.json``), a dict or a :class:`Model`.

    All values are converted to SI.  With ``check`` the topology and physical
    consistency checks of :mod:`torquesplit.model.checks` run too.  Bad input raises
    :class:`~torquesplit.errors.ModelError` naming the file, field and fix.

    Examples
    --------
    >>> import torquesplit
    >>> m = torquesplit.load_model(torquesplit.example_path("seed001_mill_drive"))
    >>> m.gears["z1"].teeth
    19
    """
    if isinstance(source, Model):
        model, name = source, None
    elif isinstance(source, dict):
        model, name = model_from_dict(source), None
    else:
        path = Path(source)
        name = str(path)
        data = read_file(path)
        model = model_from_dict(data, source=name)
    if check:
        from .checks import check_model

        check_model(model, source=name)
    return model


def read_file(path: Path) -> dict[str, Any]:
    """Parse a TOML or JSON file into a dict; syntax errors become ModelError."""
    if not path.exists():
        raise ModelError(
            [("", f"no such file; check the path (current folder: {Path.cwd()})")], str(path)
        )
    text = path.read_text(encoding="utf-8")
    suffix = path.suffix.lower()
    try:
        if suffix == ".json":
            return json.loads(text)
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError([("", f"TOML syntax error: {exc}; fix the line it names")], str(path)) from None
    except json.JSONDecodeError as exc:
        raise ModelError(
            [("", f"JSON syntax error at line {exc.lineno} column {exc.colno}: {exc.msg}")], str(path)
        ) from None


def model_from_dict(data: dict[str, Any], source: str | None = None) -> Model:
    """Validate a dict against the schema; errors name every offending field."""
    if not isinstance(data, dict):
        raise ModelError([("", "a model file must contain a table of sections")], source)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", pydantic.warnings.PydanticDeprecationWarning)
            return Model.model_validate(data)
    except pydantic.ValidationError as exc:
        raise ModelError(_format_errors(exc), source) from None


def _format_errors(exc: pydantic.ValidationError) -> list[tuple[str, str]]:
    out = []
    seen = set()
    for err in exc.errors(include_url=False):
        loc = ".".join(str(p) for p in err["loc"] if not _is_internal_tag(p))
        msg = _message(err)
        key = (loc, msg)
        if key not in seen:
            seen.add(key)
            out.append(key)
    return out


def _is_internal_tag(part) -> bool:
    return isinstance(part, str) and ("[" in part or part.startswith("function-"))


def _message(err: dict) -> str:
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        return f"unknown field (value {value!r}); check the spelling against docs/model-file.md"
    if kind == "missing":
        return "required field is missing; add it"
    msg = err["msg"]
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return f"{msg}, got {value!r}; correct the value"
    if kind.endswith("_parsing") or kind.endswith("_type") or kind == "literal_error":
        return f"{msg}, got {value!r}"
    return msg


def model_to_dict(model: Model) -> dict[str, Any]:
    """The model as a plain dict of SI numbers (can be re-read by :func:`load_model`)."""
    return _drop_none(model.model_dump(mode="json"))


def model_to_json(model: Model) -> str:
    """The model as JSON text of SI numbers (embedded in results files)."""
    return json.dumps(model_to_dict(model), sort_keys=False)


def _drop_none(obj):
    if isinstance(obj, dict):
        return {k: _drop_none(v) for k, v in obj.items() if v is not None}
    if isinstance(obj, list):
        return [_drop_none(v) for v in obj]
    return obj
