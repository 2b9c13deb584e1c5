"""Study parameters addressed by their path in the model file (the ``--set`` paths).

A parameter names one field (``meshes.m11.backlash``), several (``paths = [...]``), or a
pattern (``gears.*.support.stiffness``: ``*``, ``?`` and ``[..]`` match within one
segment, over the fields present in the model file).  Each field's *kind* (length,
stiffness...) comes from the model schema, so values in a study file take the same
units as the model file; they are converted to SI here, once, and written into the raw
model data with :func:`torquesplit.model.overrides.set_parameter` (the model is then
validated as if the file said so).
"""

from __future__ import annotations

import difflib
import fnmatch
import math
import types
import typing
from dataclasses import dataclass

import pydantic

from ..model.schema import Model, Unit, list_item
from ..model.units import KINDS, parse_quantity
from .errors import StudyError

_GLOB = set("*?[")


@dataclass(frozen=True)
class Field:
    """A model field a study can change."""

    path: str
    kind: str | None
    """Quantity kind (``"length"``...) or None for a plain number."""
    integer: bool
    """The schema wants a whole number."""
    nonnegative: bool = False
    """The schema refuses negative values (an amplitude, a clearance)."""


def is_pattern(path: str) -> bool:
    return any(c in _GLOB for c in path)


# ============================================================================ schema
def schema_field(path: str, where: str) -> Field:
    """The schema's description of the field at ``path`` (no model data needed).

    Raises StudyError naming ``where`` when the path does not lead to a number field.
    """
    node, meta = Model, []
    parts = path.split(".")
    for i, part in enumerate(parts):
        node, meta = _unwrap(node, meta)
        here = ".".join(parts[: i + 1])
        if isinstance(node, type) and issubclass(node, pydantic.BaseModel):
            field = node.model_fields.get(part)
            if field is None:
                guess = difflib.get_close_matches(part, list(node.model_fields), n=1)
                hint = f"did you mean {guess[0]!r}? " if guess else ""
                known = ", ".join(node.model_fields)
                raise StudyError(where, f"{path!r}: {here!r} is not a model field; {hint}"
                                        f"fields here: {known} (see docs/model-file.md)")
            node, meta = field.annotation, list(field.metadata)
        elif typing.get_origin(node) is dict:
            node, meta = typing.get_args(node)[1], []
        elif typing.get_origin(node) in (list, tuple):
            if not part.isdigit():
                raise StudyError(where, f"{path!r}: {here!r} must be a list index (0, 1, ...); "
                                        f"correct the path")
            args = typing.get_args(node)
            fixed = typing.get_origin(node) is tuple and list_item(node) is None
            node, meta = (args[int(part)] if fixed and int(part) < len(args)
                          else args[0]), []
        else:
            raise StudyError(where, f"{path!r}: {'.'.join(parts[:i])!r} is a value, not a "
                                    f"table; shorten the path")
    node, meta = _unwrap(node, meta)
    unit = next((m for m in meta if isinstance(m, Unit)), None)
    if isinstance(node, type) and issubclass(node, pydantic.BaseModel):
        if unit is not None:  # a table with a one-number shorthand (backlash = "20 um")
            return Field(path, unit.kind, False, True)
        fields = ", ".join(node.model_fields)
        raise StudyError(where, f"{path!r} is a table, not a number; address one of its "
                                f"fields ({fields})")
    if node is bool or (typing.get_origin(node) is typing.Literal):
        raise StudyError(where, f"{path!r} is not a number; a study varies numeric fields "
                                f"(put fixed choices in the [set] table)")
    if node not in (int, float) and unit is None:
        raise StudyError(where, f"{path!r} is not a number field; address a numeric field "
                                f"(see docs/model-file.md)")
    lower = [getattr(m, "ge", None) for m in meta] + [getattr(m, "gt", None) for m in meta]
    nonneg = any(b is not None and b >= 0 for b in lower)
    return Field(path, unit.kind if unit else None, node is int, nonneg)


def _unwrap(tp, meta):
    meta = list(meta)
    while True:
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            args = typing.get_args(tp)
            tp = args[0]
            meta += list(args[1:])
        elif origin in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(tp) if a is not type(None)]
            if len(args) != 1:
                # e.g. FrictionSpec | None after the shorthand: take the table
                tables = [a for a in args if isinstance(a, type)
                          and issubclass(a, pydantic.BaseModel)]
                tp = tables[0] if tables else args[0]
            else:
                tp = args[0]
        else:
            return tp, meta


# ============================================================================ data
def expand(path: str, raw: dict, where: str) -> list[str]:
    """Concrete paths of ``path``: itself, or every field matching the pattern.

    Wildcards range over the entries and fields the model file writes; a literal segment
    may also name a table the file leaves at its default (``errors``,
    ``transmission_error``: written out empty) or a field left at its default.  Parents
    must otherwise exist (as for ``--set``).
    """
    parts = path.split(".")
    if not is_pattern(path):
        _parent(raw, parts, path, where)
        return [path]
    found: list[str] = []

    def walk(node, i, prefix):
        if i == len(parts):
            found.append(".".join(prefix))
            return
        seg = parts[i]
        if isinstance(node, dict):
            if is_pattern(seg):
                keys = [k for k in node if fnmatch.fnmatchcase(str(k), seg)]
            elif seg in node or i == len(parts) - 1:
                keys = [seg]
            elif _is_section(prefix + [seg]):
                node[seg] = {}
                keys = [seg]
            elif _per_planet(node, prefix + [seg]):
                keys = [seg]
            else:
                keys = []
        elif isinstance(node, list):
            keys = [str(k) for k in range(len(node)) if fnmatch.fnmatchcase(str(k), seg)]
        else:
            return
        for k in keys:
            if i == len(parts) - 1:
                found.append(".".join(prefix + [k]))
                continue
            child = node[k] if isinstance(node, dict) else node[int(k)]
            walk(child, i + 1, prefix + [k])

    walk(raw, 0, [])
    if not found:
        raise StudyError(where, f"pattern {path!r} matches no field of the model; check it "
                                f"against the model file (wildcards match the entries and "
                                f"fields that the file writes)")
    return found


def _parent(raw, parts, path, where):
    node = raw
    for i, key in enumerate(parts[:-1]):
        here = ".".join(parts[: i + 1])
        if isinstance(node, dict) and key not in node and _is_section(parts[: i + 1]):
            node[key] = {}  # a table the file leaves out (defaults): write it out empty
        _per_planet(node, parts[: i + 1])
        if isinstance(node, dict) and key in node:
            node = node[key]
        elif isinstance(node, list) and key.isdigit() and int(key) < len(node):
            node = node[int(key)]
        else:
            if isinstance(node, list):  # (an index past the list: 'known here: none')
                raise StudyError(where, (
                    f"{path!r}: {here!r} does not exist in the model: its list has "
                    f"{len(node)} item(s), indices 0..{len(node) - 1}; check the path"
                    if node else f"{path!r}: {here!r} does not exist in the model: its list "
                    f"is empty; check the path"))
            known = ", ".join(sorted(node)) if isinstance(node, dict) else "none"
            raise StudyError(where, f"{path!r}: {here!r} does not exist in the model (known "
                                    f"here: {known}); check the path")
    return node


PER_PLANET = ("pin_errors",)
"""The lists of a ``[[planetary]]`` stage with one table per planet, all fields
defaulted: a study may vary their fields where the file leaves the list out."""


def _per_planet(node, parts: list[str]) -> bool:
    """Write out, in the raw data ``node`` of a ``[[planetary]]`` stage, its per-planet
    list ``parts[-1]`` (:data:`PER_PLANET`) that the file leaves out: one empty table per
    planet (nothing changes; the study then sets one planet's field).  True if done."""
    if not (len(parts) == 3 and parts[0] == "planetary" and parts[2] in PER_PLANET
            and isinstance(node, dict) and parts[2] not in node):
        return False
    count = node.get("planets")
    if isinstance(count, bool) or not isinstance(count, int) or not 0 < count <= 64:
        return False  # (the stage's own check names a bad count)
    node[parts[2]] = [{} for _ in range(count)]
    return True


def _is_section(parts: list[str]) -> bool:
    """The schema has a table with a default value (not None, not a named entry) at
    ``parts``: writing it out empty changes nothing."""
    node: object = Model
    field = None
    for part in parts:
        node, _ = _unwrap(node, [])
        if isinstance(node, type) and issubclass(node, pydantic.BaseModel):
            field = node.model_fields.get(part)
            if field is None:
                return False
            node = field.annotation
        elif typing.get_origin(node) is dict and part != parts[-1]:
            node, field = typing.get_args(node)[1], None  # a named entry: it must exist
        else:
            return False
    node, _ = _unwrap(node, [])
    return (isinstance(node, type) and issubclass(node, pydantic.BaseModel)
            and field is not None and field.default is not None
            and not field.is_required())


def current_value(raw: dict, path: str):
    """The value the model data holds at ``path`` (None if the field is not written)."""
    node = raw
    for key in path.split("."):
        if isinstance(node, dict):
            if key not in node:
                return None
            node = node[key]
        elif isinstance(node, list):
            node = node[int(key)]
        else:
            return None
    return node


def check_settable(raw: dict, field: Field, where: str) -> None:
    """Refuse to write a number over a table of the model file (it would silently drop
    the table's other entries)."""
    value = current_value(raw, field.path)
    if isinstance(value, dict):
        keys = ", ".join(value)
        numeric = [k for k, v in value.items()
                   if isinstance(v, (int, float, str)) and not isinstance(v, bool)
                   and k not in ("method", "distribution", "model")]
        inner = (numeric or list(value))[0]
        raise StudyError(where, f"{field.path!r} is a table in the model ({keys}); address "
                                f"the field to vary, e.g. {field.path}.{inner}")


def base_value(raw: dict, field: Field, where: str) -> float:
    """SI value of a field written in the model data (for scaling it)."""
    value = current_value(raw, field.path)
    if value is None:
        raise StudyError(where, f"{field.path!r} is not written in the model file, so there is "
                                f"nothing to scale; give the field in the model or use values")
    if isinstance(value, dict):
        check_settable(raw, field, where)
    try:
        return to_si(value, field.kind, None, where)
    except StudyError:
        raise StudyError(where, f"{field.path!r} holds {value!r}, which cannot be scaled; "
                                f"use values instead of a scale") from None


# ============================================================================ values
def to_si(value, kind: str | None, unit: str | None, where: str) -> float:
    """A study value (number, or string with units) in SI.  ``unit`` applies to bare
    numbers; ``kind`` None means a plain number."""
    if isinstance(value, bool):
        raise StudyError(where, f"got {value!r}; give a number")
    if kind is None:
        if isinstance(value, str) or unit:
            raise StudyError(where, f"{value!r}: this field is a plain number without units; "
                                    f"write a number such as 0.07")
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise StudyError(where, f"got {value!r}; give a number") from None
        if not math.isfinite(x):
            raise StudyError(where, f"got {value!r}; give a finite number")
        return x
    if unit is not None and not isinstance(value, str):
        value = f"{value!r} {unit}"
    try:
        return parse_quantity(value, kind)
    except ValueError as exc:
        raise StudyError(where, str(exc)) from None


def check_unit(unit: str | None, kind: str | None, where: str) -> None:
    """Refuse a ``unit`` of the wrong dimension for the field's kind."""
    if unit is None:
        return
    if kind is None:
        raise StudyError(where, f"unit {unit!r} given for a plain-number field; remove 'unit'")
    try:
        parse_quantity(f"1 {unit}", kind)
    except ValueError:
        raise StudyError(where, f"{unit!r} is not a unit of {kind.replace('_', ' ')}; write "
                                f"e.g. unit = \"{KINDS[kind][1].split(' ', 1)[1]}\"") from None


def si_unit(kind: str | None) -> str:
    return KINDS[kind][0] if kind else "1"
