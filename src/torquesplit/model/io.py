"""Read and write model files (TOML, or JSON) and turn schema errors into clear messages."""

from __future__ import annotations

import difflib
import json
import re
import types
import typing
import warnings
from pathlib import Path
from typing import Any

import pydantic

from ..errors import ModelError
from .schema import FieldError, Model, list_item
from .units import _short


def load_model(source, *, check: bool = True, changes=None) -> Model:
    """Read a model file (``.toml`` or ``.json``), a shipped example by name (as the
    command line takes it: ``"ji_li_mill_drive"``), a dict or a :class:`Model`.

    All values are converted to SI.  With ``check`` the topology and physical
    consistency checks of :mod:`torquesplit.model.checks` run too.  ``changes`` maps
    field paths to values as ``--set`` takes them (``{"meshes.m11.damping_ratio": 0.1,
    "shafts.drive1.diameter": "250 mm"}``), applied before the validation (a model is
    frozen: change one with :meth:`Model.with_changes`).  Bad input raises
    :class:`~torquesplit.errors.ModelError` naming the file, field and fix.

    Examples
    --------
    >>> import torquesplit
    >>> m = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    >>> m.gears["z1"].teeth
    19
    >>> stiffer = m.with_changes({"shafts.drive1.diameter": "300 mm"})
    """
    import os

    if not isinstance(source, (str, os.PathLike, dict, Model)):
        from ..errors import OptionTypeError

        raise OptionTypeError(f"load_model takes a model file's path, a shipped example's "
                              f"name, a dict or a Model; got {_short(source)} "
                              f"({type(source).__name__})")
    if changes:
        from .overrides import apply_overrides, read_raw

        if isinstance(source, Model):
            return source.with_changes(changes)
        raw = source if isinstance(source, dict) else read_raw(_resolve(source))
        return load_model(apply_overrides(raw, changes_mapping(changes)), check=check)
    if isinstance(source, Model):
        model, name = source, None
    elif isinstance(source, dict):
        model, name = model_from_dict(source), None
    else:
        path = _resolve(source)
        name = str(path)
        data = read_file(path)
        try:
            model = model_from_dict(data, source=name)
            if check:
                from .checks import check_model

                check_model(model, source=name)
        except ModelError as exc:
            raise _located(exc, path) from None
        return model
    if check:
        from .checks import check_model

        check_model(model, source=name)
    return model


def _located(exc: ModelError, path: Path) -> ModelError:
    """``exc`` with the line of each of its fields in the TOML file ``path``
    ('drive.toml:42: gears.pinion.module: ...', as compilers write it: an editor jumps
    there; a reviewer's 600-line file named fields without lines)."""
    if exc.source != str(path) or path.suffix.lower() == ".json":
        return exc
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, ValueError):
        return exc
    return exc.located(text)


def changes_mapping(changes) -> dict:
    """``changes`` as ``{path: value}``: a mapping of field paths (text) to values, a list
    of ``(path, value)`` pairs, or ``"PATH=VALUE"`` texts as ``--set`` takes them (one,
    or a list); anything else is refused saying what to give."""
    from collections.abc import Mapping

    from ..errors import OptionTypeError
    from .overrides import parse_assignment

    if isinstance(changes, str):
        changes = [changes]
    if isinstance(changes, Mapping):
        bad = [k for k in changes if not isinstance(k, str)]
        if not bad:
            return dict(changes)
        got = f"a key {_short(bad[0])} ({type(bad[0]).__name__})"
    elif isinstance(changes, (list, tuple)) and all(isinstance(c, str) for c in changes):
        bad = [c for c in changes if "=" not in c]
        if bad:  # (in Python: not the command line's '--set' words)
            raise OptionTypeError(f"changes: {_short(bad[0])} is not 'PATH=VALUE'; give e.g. "
                                  f"'shafts.drive1.diameter=250 mm', or a mapping "
                                  f"{{\"shafts.drive1.diameter\": \"250 mm\"}}")
        return dict(parse_assignment(c) for c in changes)
    elif isinstance(changes, (list, tuple)) and all(
            isinstance(c, (list, tuple)) and len(c) == 2 and isinstance(c[0], str)
            for c in changes):  # (path, value) pairs, as dict() takes them
        return dict(changes)
    else:
        got = f"{_short(changes)} ({type(changes).__name__})"
    raise OptionTypeError(f"changes must map field paths to values, e.g. "
                          f"{{\"meshes.m11.damping_ratio\": 0.1}}, or be 'PATH=VALUE' texts as "
                          f"--set takes them; got {got}")


def _resolve(source) -> Path:
    """A model file's path: ``source`` itself, or the shipped example of that name."""
    if isinstance(source, str) and ("\n" in source or len(source) > 1024):
        from ..errors import OptionTypeError

        # (the text of a model taken for a path: 'File name too long' from the OS)
        raise OptionTypeError(f"load_model takes a model file's path or an example's "
                              f"name; got a text of {len(source)} characters "
                              f"({_short(source)}): for a model's TOML text, pass "
                              f"tomllib.loads(text) (a dict)")
    path = Path(source)
    if not path.exists() and path.suffix == "" and path.parent == Path("."):
        from torquesplit.examples import example_names, example_path

        if str(source) in example_names():  # a shipped example by name
            path = example_path(str(source))
        else:  # a name like an example's: a typo of it ('no such file' said nothing more)
            import difflib

            close = difflib.get_close_matches(str(source), example_names(), n=2, cutoff=0.6)
            if close:
                raise ModelError([("", f"no such file or example; did you mean "
                                       f"{' or '.join(repr(c) for c in close)}? "
                                       f"(torquesplit.example_names() lists the examples)")],
                                 str(source))
    return path


def read_file(path: Path) -> dict[str, Any]:
    """Parse a TOML or JSON file into a dict through the guarded reader
    (:func:`torquesplit.model.reader.read_model_file`); every problem is a ModelError."""
    from .reader import read_model_file

    return read_model_file(path)


MODEL_SECTIONS = ("gears", "meshes", "bodies", "planetary")
"""Top-level tables that make a file a model (a study file has [study] and none of them)."""


def model_from_dict(data: dict[str, Any], source: str | None = None, *,
                    share_source: bool = False) -> Model:
    """Validate a dict against the schema; errors name every offending field.

    The model keeps a copy of ``data`` (:meth:`Model.with_changes` applies changes to
    it); with ``share_source`` it keeps ``data`` itself, which then must never change in
    place (a study case's data, which shares its unchanged tables with the study's; the
    copy was 1.5 ms of a case)."""
    if not isinstance(data, dict):
        raise ModelError([("", "a model file must contain a table of sections")], source)
    if "study" in data and not any(k in data for k in MODEL_SECTIONS):
        raise ModelError([("", "is a study file (it has [study] and no gears or meshes), not "
                               "a model; run it with 'torquesplit study FILE' (in Python: "
                               "torquesplit.run_study)")], source)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", pydantic.warnings.PydanticDeprecationWarning)
            model = Model.model_validate(data)
    except ModelError as exc:  # (Model.model_validate formats pydantic's errors)
        raise ModelError(exc.issues, source) from None
    except pydantic.ValidationError as exc:
        raise ModelError(_format_errors(exc, data), source) from None
    import copy

    model._source = data if share_source else copy.deepcopy(data)
    return model


def _format_errors(exc: pydantic.ValidationError, data=None) -> list[tuple[str, str]]:
    """(field, message) of every problem; ``data``: the dict that was validated, whose
    values the messages quote as written (a quantity is validated in SI)."""
    out = []
    seen = set()
    for err in exc.errors(include_url=False):
        parts = [str(p) for p in err["loc"] if not _is_internal_tag(p)]
        error = (err.get("ctx") or {}).get("error")
        base = list(parts)
        if isinstance(error, FieldError) and error.field:  # ('': the section itself)
            parts.append(error.field)
        loc = ".".join(_as_written(data, parts))
        msg = _message(err, parts, _written(data, parts))
        found = [(loc, msg)]
        if isinstance(error, FieldError):  # the section's other problems
            found += [(".".join(base + [f] if f else base), m) for f, m in error.more]
        for key in found:
            if key not in seen:
                seen.add(key)
                out.append(key)
    return out


#: a location part pydantic adds for a validator or a union member, not a field or key
_INTERNAL_TAG = re.compile(r"^[a-z]+(-[a-z]+)*\[.*\]$")


def _is_internal_tag(part) -> bool:
    return isinstance(part, str) and _INTERNAL_TAG.match(part) is not None


_SEE_DOCS = "see docs/model-file.md"

_TABLE = ("must be a table of fields", f"write it as a [section] or {{key = value}} ({_SEE_DOCS})")

#: pydantic error type -> (what the value must be, what to write instead)
_TYPE_MESSAGES = {
    "int": ("must be a whole number", "write an integer such as 20"),
    "float": ("must be a number", "write a plain number such as 0.05 (or '5 %')"),
    "finite_number": ("must be a finite number", "write a plain number such as 0.05 (or '5 %')"),
    "string": ("must be text", 'write it in quotes, e.g. "pinion"'),
    "bool": ("must be true or false", "write true or false"),
    "dict": _TABLE,
    "model": _TABLE,
    "model_attributes": _TABLE,
    "list": ("must be a list", "write it as [item, item, ...]"),
    "tuple": ("must be a list", "write it as [item, item, ...]"),
}


def _as_written(data, parts: list[str]) -> list[str]:
    """``parts`` up to the one-value shorthand the file wrote for a table, if it did
    (``backlash = "-12 thou"``: its problem is at meshes.m.backlash, not at
    meshes.m.backlash.nominal, a name the file does not hold)."""
    node = data
    for i, part in enumerate(parts):
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return parts[:i] if i and isinstance(node, (str, int, float)) else parts
    return parts


def _written(data, parts: list[str]):
    """The value at ``parts`` in the file's dict as the user wrote it; a one-value
    shorthand of a table (``backlash = "-10 um"`` for ``backlash.nominal``) is that
    value; None where there is none."""
    node = data
    for part in parts:
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return node if isinstance(node, str) and node is not data else None
    return node


#: a field name from another convention -> (the field that holds it, what to write)
_SYNONYMS = {
    name: ("module", "give the normal diametral pitch as module = '4 1/in' (teeth per "
           "inch: the module 25.4 mm / 4; a helical gear's transverse P_t is P_n cos(helix))")
    for name in ("diametral_pitch", "normal_diametral_pitch", "dp", "DP")}


def _message(err: dict, parts: list[str], written=None) -> str:
    kind = err["type"]
    ctx = err.get("ctx") or {}
    value = err.get("input")
    # a converted quantity carries float noise ("-5 um" is -4.9999999999999996e-06 m)
    got = f"{value:.6g}" if isinstance(value, float) else _short(value)
    if isinstance(value, float) and isinstance(written, str):
        # a bound other than zero is in SI units, as the converted value
        zero = ctx.get("gt", ctx.get("ge", ctx.get("lt", ctx.get("le")))) == 0
        got = _short(written) if zero else f"{_short(written)} (= {got} in SI units)"
    if kind == "string_too_long":  # (a 100,000-character name took check 62 s to print)
        most = ctx.get("max_length")
        return (f"is {len(value) if isinstance(value, str) else '?'} characters long; give "
                f"at most {most}")
    if kind == "extra_forbidden":
        name, section = (parts[-1], parts[:-1]) if parts else ("", [])
        fields = _fields_at(section)
        guess = difflib.get_close_matches(name, fields, n=1, cutoff=0.6)
        hint = f"did you mean {guess[0]!r}? " if guess else ""
        if name in _SYNONYMS and _SYNONYMS[name][0] in fields:
            hint = _SYNONYMS[name][1] + "; "
        return f"unknown field; {hint}check the spelling against docs/model-file.md"
    if kind == "missing":
        if parts and parts[-1].isdigit():
            return f"an item is missing (the list is too short); give all items ({_SEE_DOCS})"
        if parts in (["drives"], ["loads"]):
            what = ("where the power enters, e.g. [drives.motor] with body = 'pinion' and "
                    "speed = '1500 rpm', power = '5 MW'" if parts == ["drives"] else
                    "where the power leaves, e.g. [loads.out] with body = 'wheel' (its "
                    "torque balances the drives' power unless given)")
            return f"the model has no {parts[0]}; add a [{parts[0]}.NAME] section {what}"
        return f"required field is missing; add it ({_SEE_DOCS})"
    if kind in ("value_error", "assertion_error"):
        msg = err["msg"]
        for prefix in ("Value error, ", "Assertion failed, "):
            if msg.startswith(prefix):
                msg = msg[len(prefix):]
        return msg
    if kind == "greater_than":
        fix = "give a positive value" if ctx.get("gt") == 0 else "correct the value"
        return f"must be greater than {ctx.get('gt')}, got {got}; {fix}"
    if kind == "greater_than_equal":
        if ctx.get("ge") == 0:
            return f"must not be negative, got {got}; give zero or a positive value"
        return f"must be at least {ctx.get('ge')}, got {got}; correct the value"
    if kind in ("less_than", "less_than_equal"):
        bound = ctx.get("lt", ctx.get("le"))
        word = "less than" if kind == "less_than" else "at most"
        return f"must be {word} {bound}, got {got}; correct the value"
    if kind == "literal_error":
        return f"must be {ctx.get('expected')}, got {got}; use one of these"
    if kind in ("too_long", "too_short"):
        n, most, least = ctx.get("actual_length"), ctx.get("max_length"), ctx.get("min_length")
        if n is not None and (most is not None or least is not None):
            bound = (f"at most {most}" if kind == "too_long" else f"at least {least}")
            return (f"has {n} item{'s' if n != 1 else ''}, {bound} allowed; give as many "
                    f"items as docs/model-file.md says")
        return f"{err['msg']}; give as many items as docs/model-file.md says"
    if kind == "string_pattern_mismatch":  # (names: the pattern of a Field)
        return (f"{got} is not a name this field takes; use letters, digits and '_', "
                f"starting with a letter (e.g. \"stage_1\")")
    if kind in ("finite_number", "float_type", "float_parsing") and _is_whole(parts):
        # (a tooth count of inf was told to write 'a plain number such as 0.05')
        return f"must be a finite whole number, got {got}; write an integer such as 20"
    # longest prefix first: 'model_attributes_type' before 'model_type'
    for base in sorted(_TYPE_MESSAGES, key=len, reverse=True):
        if kind.startswith(base):
            what, fix = _TYPE_MESSAGES[base]
            return f"{what}, got {got}; {fix}"
    msg = err["msg"]
    if msg.startswith("Input should be "):
        msg = "must be " + msg[len("Input should be "):]
    return f"{msg}, got {got}; correct the value ({_SEE_DOCS})"


def _fields_at(parts: list[str], lists: bool = False) -> list[str]:
    """Field names of the schema section at location ``parts`` ([] if there is none);
    with ``lists``, an index steps into a list of sections (``planetary.0.sun``)."""
    node = _schema_at(parts, lists)
    if isinstance(node, type) and issubclass(node, pydantic.BaseModel):
        return list(node.model_fields)
    return []


def _is_whole(parts: list[str]) -> bool:
    """Whether the schema field at ``parts`` takes a whole number (a count)."""
    node = _schema_at(parts, lists=True) if parts else None
    return isinstance(node, type) and issubclass(node, int) and not issubclass(node, bool)


def _schema_at(parts: list[str], lists: bool = False):
    """The schema type at location ``parts`` (``X | None`` and ``Annotated`` stripped), or
    None where the schema has nothing there; with ``lists``, an index steps into a list."""
    node = Model
    for part in parts:
        node = _strip(node)
        if isinstance(node, type) and issubclass(node, pydantic.BaseModel):
            field = node.model_fields.get(part)
            if field is None:
                return None
            node = field.annotation
        elif typing.get_origin(node) is dict:
            node = typing.get_args(node)[1]
        elif lists and list_item(node) is not None and part.isdigit():
            node = list_item(node)
        else:
            return None
    return _strip(node)


def _strip(tp):
    """``X | None`` and ``Annotated[X, ...]`` -> ``X``."""
    while True:
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            tp = typing.get_args(tp)[0]
        elif origin in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(tp) if a is not type(None)]
            if len(args) != 1:
                return tp
            tp = args[0]
        else:
            return tp


def model_to_dict(model: Model) -> dict[str, Any]:
    """The model as a plain dict of SI numbers (can be re-read by :func:`load_model`)."""
    data = _drop_none(model.model_dump(mode="json"))
    if not data.get("planetary"):  # expanded on reading: the general sections hold it
        data.pop("planetary", None)
    return data


def model_to_json(model: Model) -> str:
    """The model as JSON text of SI numbers (embedded in results files)."""
    return json.dumps(model_to_dict(model), sort_keys=False)


def _drop_none(obj):
    if isinstance(obj, dict):
        return {k: _drop_none(v) for k, v in obj.items() if v is not None}
    if isinstance(obj, list):
        return [_drop_none(v) for v in obj]
    return obj
