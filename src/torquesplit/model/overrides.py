"""Change model parameters by their path in the model file (``shafts.drive1.diameter``).

Used by ``torquesplit run --set PATH=VALUE`` and by studies: the raw model data is
edited before validation, so every override goes through the same units and checks
as the file itself.  An error in an overridden field is reported against the ``--set``
argument, not against the model file (:func:`apply_assignments`,
:func:`attribute_errors`).
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any, Mapping

from ..errors import ModelError, clip_text, warn_user


def set_parameter(data: dict, path: str, value: Any) -> dict:
    """Return a copy of ``data`` with the field at dotted ``path`` set to ``value``.

    The field itself may be new (it is then checked by the schema like any other field),
    and so may a table on the path that the schema knows but the file does not write
    (``analysis`` of ``analysis.table_points``, ``errors`` of
    ``planetary.0.sun.errors.eccentricity``): it is created.  List items are addressed by
    index (``axis.2``).  A table set where the data has one merges into it: the fields it
    names change, the others stay (:func:`_merged`); it replaces the old one where it
    chooses another ``method`` (or distribution, kind...: :data:`SELECTORS`), where it
    is empty (``{}`` clears a table) and where it is a whole section (``drives``).  A
    mesh stiffness's ``method`` set alone drops the old method's own fields (``value``
    of 'constant' when it becomes 'iso6336': the schema refuses a field of another
    method).  A field that says what the table already says another way replaces it
    (:data:`ALTERNATIVES`: ``torque`` a drive's ``power``, ``damping_ratio`` its
    ``damping``).
    Only the tables and lists on the path are copied; the rest is shared with ``data``
    (neither is ever changed in place: a study sets a dozen parameters of a large model
    per case, and copying the whole model for each cost milliseconds).
    """
    if re.search(r"\[\s*\d+\s*\]", path):  # 'position[0]': written the way paths index
        dotted = re.sub(r"\[\s*(\d+)\s*\]", r".\1", path)
        raise ModelError([(path, f"a list item is addressed with a dot and its index, not "
                                 f"brackets; write {dotted}")])
    parts = path.split(".")
    if not all(p.strip() for p in parts):  # ('' said 'unknown field' of no field)
        raise ModelError([(path, "an empty field path, or an empty part of one ('a..b'); "
                                 "give e.g. meshes.m11.damping_ratio")])
    out = _copy_node(data)
    node = out
    for i, key in enumerate(parts[:-1]):
        if isinstance(node, dict) and key not in node and parts[i + 1].isdigit():
            # (an item of a list the file does not write: a table was made of it, and
            # 'must be a list, got {'1': '45 deg'}' said nothing of what to do)
            where = ".".join(parts[: i + 1])
            raise ModelError([(path, f"{where!r} is not in the file, so it has no item "
                                     f"{parts[i + 1]}; set the whole list: "
                                     f"{where}=[a, b, ...]")])
        if isinstance(node, dict) and key not in node and _schema_table(parts, i):
            node[key] = {}  # a table the schema knows, absent from the file: created
        child = _copy_node(_child(node, key, ".".join(parts[: i + 1]), path))
        node[_index(key, node, path) if isinstance(node, list) else key] = child
        node = child
    last = parts[-1]
    if isinstance(node, list):
        idx = _index(last, node, path)
        node[idx] = value
    elif isinstance(node, dict):
        old = node.get(last)
        if parts[-2:] == ["stiffness", "method"] and old is not None and value != old:
            # another stiffness method: the old one's own fields go with it (they would
            # be refused beside the new one), those the new one takes stay
            from .schema import STIFFNESS_FIELD_METHODS

            for key in [k for k, methods in STIFFNESS_FIELD_METHODS.items()
                        if value not in methods]:
                node.pop(key, None)
        _give_way(node, last, value)  # (the file's other way of saying it)
        node[last] = (_merged(old, value) if len(parts) > 1 and _merges(old, value)
                      else value)
    else:
        raise ModelError([(path, f"{'.'.join(parts[:-1])!r} is a value, not a table; "
                                 f"check the path")])
    return out


def _give_way(table: dict, key: str, value) -> None:
    """Remove from ``table`` (a copy) the fields that say what ``key`` set to ``value``
    says another way (:data:`ALTERNATIVES`; ``rigid = false`` replaces nothing)."""
    if key != "rigid" or value is not False:
        for other in ALTERNATIVES.get(key, ()):
            table.pop(other, None)


def alternative_clash(paths) -> tuple[str, str] | None:
    """Two of ``paths`` that set one table's field two ways (``drives.m.power`` and
    ``drives.m.torque``), which would leave the last one alone without a word; None if
    none do."""
    seen: dict[tuple[str, str], str] = {}
    for path in paths:
        table, _, key = str(path).rpartition(".")
        for other in ALTERNATIVES.get(key, ()):
            if (table, other) in seen:
                return seen[table, other], path
        seen[table, key] = path
    return None


def apply_overrides(data: dict, overrides: Mapping[str, Any]) -> dict:
    """Apply several ``{path: value}`` overrides in order (``data`` is not changed);
    two that set one field two ways (:func:`alternative_clash`) are refused."""
    clash = alternative_clash(overrides)
    if clash:
        raise ModelError([(clash[1], f"sets what {clash[0]} sets, another way; give one of "
                                     f"them")])
    for path, value in overrides.items():
        try:
            data = set_parameter(data, path, value)
        except ModelError:
            _refuse_generated(data, path)
            raise
    return data


def _refuse_generated(data, path: str) -> None:
    """A path into what a ``[[planetary]]`` stage generates (``gears.st_sun.dofs``) is
    not in the data, which holds the stage: say which field of the stage to change."""
    if not isinstance(data, dict) or not data.get("planetary"):
        return
    from .schema import Model

    try:
        written = Model.model_validate(data).written_at(path)
    except Exception:  # (the data's own errors are said when it is read)
        return
    if written != path:
        raise ModelError([(path, f"{path!r} is generated by the [[planetary]] stage: change "
                                 f"{written!r} instead")]) from None


#: a field set where the table has one of these instead: they say the same thing another
#: way (the schema refuses both), so the one set replaces them (``--set
#: drives.motor.torque=...`` on a drive the file gives a ``power``: a user cannot remove
#: the file's field from the command line, and was told to)
ALTERNATIVES = {
    "power": ("torque",), "torque": ("power",),
    "damping": ("damping_ratio",), "damping_ratio": ("damping",),
    "position": ("place",), "place": ("position",),
    "stiffness": ("rigid", "shaft"), "shaft": ("stiffness",),
    "rigid": ("stiffness", "damping", "damping_ratio"),
    "torsional_stiffness": ("diameter", "length", "rigid"),
    "diameter": ("torsional_stiffness",), "length": ("torsional_stiffness",),
}

#: keys that choose what a table is (a stiffness method, a distribution...): a table set
#: with another choice replaces the old one, whose other fields belong to the old choice
SELECTORS = ("method", "distribution", "kind", "model", "shape", "mode")


def _merges(old, new) -> bool:
    """Whether a table set on ``old`` merges into it (:func:`_merged`): both tables, the
    new one not empty (``{}`` clears) and choosing nothing else (``{method = ...}``
    with another method replaces the table)."""
    return (isinstance(old, dict) and isinstance(new, dict) and bool(new)
            and all(new[k] == old.get(k, new[k]) for k in SELECTORS if k in new))


def _merged(old: dict, new):
    """A table set on a table: the fields it names replace those of ``old``, the others
    stay (``errors = {eccentricity = ...}`` keeps the runout); tables inside merge
    alike.  Neither is changed."""
    if not isinstance(new, dict):
        return new
    out = dict(old)
    for key, value in new.items():
        if key not in old:  # (a table set whole names the field another way too)
            _give_way(out, key, value)
        out[key] = _merged(out[key], value) if _merges(out.get(key), value) else value
    return out


def _copy_node(node):
    """A shallow copy of a table or list (a value is returned as it is)."""
    if isinstance(node, dict):
        return dict(node)
    if isinstance(node, list):
        return list(node)
    return node


def parse_assignment(text: str) -> tuple[str, Any]:
    """``"meshes.m1.damping_ratio=0.07"`` -> (path, value); the value is read as TOML
    when it can be (numbers, booleans, quoted strings) and as a string otherwise
    (``250 mm``)."""
    if "=" not in text:
        raise ModelError([("--set", f"{text!r} is not PATH=VALUE; write e.g. "
                                    f"--set shafts.drive1.diameter='250 mm'")])
    from .reader import check_nesting

    path, raw = (s.strip() for s in text.split("=", 1))
    if not path:
        raise ModelError([("--set", f"{clip_text(text)!r} has no PATH before '='; write e.g. "
                                    f"--set shafts.drive1.diameter='250 mm'")])
    check_nesting(raw, "toml", f"--set {clip_text(text)}")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except ValueError:  # an integer of more than 4300 digits
        raise ModelError([("", "has an integer of more than 4300 digits; write numbers of "
                               "ordinary size, e.g. 1e30")], f"--set {clip_text(text)}") from None
    return path, value


def apply_assignments(data: dict, assignments) -> tuple[dict, dict[str, str]]:
    """Apply ``--set PATH=VALUE`` arguments to raw model data.

    Returns
    -------
    data : dict
        A copy of ``data`` with the overrides applied.
    where : dict
        ``{path: argument}``, for :func:`attribute_errors`.

    Raises
    ------
    ModelError
        An argument that is not PATH=VALUE or names no field, reported against the
        argument (``--set meshes.zz.damping=1: ...``).

    Examples
    --------
    >>> data, where = apply_assignments({"meshes": {"m": {}}}, ["meshes.m.damping_ratio=0.07"])
    >>> data, where
    ({'meshes': {'m': {'damping_ratio': 0.07}}}, {'meshes.m.damping_ratio': 'meshes.m.damping_ratio=0.07'})
    """
    where: dict[str, str] = {}
    for text in assignments:
        source = f"--set {clip_text(text)}"
        try:
            path, value = parse_assignment(text)
            if path in where:  # (the last one won without a word: a reviewer)
                raise ModelError([("", (
                    f"sets {path} again (--set {clip_text(where[path])} before it): give "
                    f"each field once"))], source)
            clash = alternative_clash([*where, path])
            if clash:  # (power then torque: the torque alone was kept, a code reviewer)
                raise ModelError([("", (
                    f"sets what --set {clip_text(where[clash[0]])} sets, another way: "
                    f"give one of them"))], source)
            data = apply_overrides(data, {path: value})
        except ModelError as exc:
            issues = [("" if loc in ("--set", path_of(text)) else loc, msg)
                      for loc, msg in exc.issues]
            raise ModelError(issues, exc.source or source) from None
        where[path] = text
        if path.rsplit(".", 1)[-1] == "speed" and _bare_number(value):
            from ..errors import ModelWarning
            from .units import rad_s_text

            warn_user(ModelWarning(
                f"--set {clip_text(text)}: a bare number is a speed in rad/s "
                f"({rad_s_text(value)}); write --set {path}='{value:g} rpm' for rpm"))
    return data, where


def _bare_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and value != 0


def path_of(text: str) -> str:
    """The PATH of a ``PATH=VALUE`` argument."""
    return text.split("=", 1)[0].strip()


def attribute_errors(exc: ModelError, where: Mapping[str, str], source: str,
                     own: set[str] | None = None) -> ModelError:
    """``exc`` with each issue reported against what caused it.

    An issue inside an overridden field (``meshes.m.stiffness.value`` for ``--set
    meshes.m.stiffness=...``) is reported against the ``--set`` argument; one in a
    section that an override changed (``meshes.m`` for ``--set meshes.m.damping=...``)
    against the file *with* that argument; any other against the file (``source``),
    unless ``own`` (the locations of the issues the file has without the overrides) shows
    that the file alone does not have it: then against the file with every ``--set``
    (a mesh that no longer fits after ``--set gears.pinion.teeth=21`` was reported at
    the file's line of the mesh, a reviewer).
    """
    causes = [_cause(loc, where, source) for loc, _ in exc.issues]
    if own is not None and where:
        every = f"{source} with " + ", ".join(f"--set {clip_text(t)}" for t in where.values())
        causes = [every if cause == source and loc not in own else cause
                  for cause, (loc, _) in zip(causes, exc.issues)]
    if len(set(causes)) == 1:
        return ModelError(exc.issues, causes[0])
    return ModelError([(f"{c}: {loc}" if loc else c, msg)
                       for c, (loc, msg) in zip(causes, exc.issues)])


def attribute_warning(text: str, where: Mapping[str, str], source: str) -> str:
    """A warning ``"SOURCE: FIELD: message"`` reported against what caused it, as
    :func:`attribute_errors` does for errors.

    Examples
    --------
    >>> attribute_warning("m.toml: gears.g.errors.installation: 15 m is large",
    ...                   {"gears.g.errors.installation": "gears.g.errors.installation=15"},
    ...                   "m.toml")
    '--set gears.g.errors.installation=15: gears.g.errors.installation: 15 m is large'
    """
    head = f"{source}: "
    if not where or not text.startswith(head):
        return text
    loc, sep, msg = text[len(head):].partition(": ")
    if not sep or not loc or " " in loc:  # a warning about the whole model
        return text
    return f"{_cause(loc, where, source)}: {loc}: {msg}"


def _cause(loc: str, where: Mapping[str, str], source: str) -> str:
    """Where an issue at field ``loc`` comes from: a ``--set`` argument that set it (or
    a field above it), the file with the argument that changed its section, else the
    file."""
    for path, text in where.items():
        if loc == path or loc.startswith(path + "."):
            return f"--set {clip_text(text)}"
    for path, text in where.items():
        if loc and path.startswith(loc + "."):
            return f"{source} with --set {clip_text(text)}"
    return source


def read_raw(source) -> dict:
    """The raw (unvalidated) data of a model file."""
    from .io import read_file

    return read_file(Path(source))


def _schema_table(parts: list[str], i: int) -> bool:
    """Whether ``parts[i]`` is a field the schema knows at ``parts[:i]`` (a path the
    schema does not know gets :func:`_child`'s message, listing what exists)."""
    from .io import _fields_at

    return parts[i] in _fields_at(parts[:i], lists=True)


def _child(node, key, where, path):
    if isinstance(node, dict):
        if key not in node:
            known = ", ".join(sorted(node)) or "none"
            raise ModelError([(path, f"{where!r} does not exist (known here: {known}); "
                                     f"check the path")])
        return node[key]
    if isinstance(node, list):
        return node[_index(key, node, path)]
    raise ModelError([(path, f"{where!r} is a value, not a table; check the path")])


def _index(key, node, path):
    try:
        idx = int(key)
        node[idx]
    except (ValueError, IndexError):
        raise ModelError([(path, f"{key!r} is not an index of a list of {len(node)}; "
                                 f"use 0..{len(node) - 1}")]) from None
    return idx
