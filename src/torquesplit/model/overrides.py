"""Change model parameters by their path in the model file (``shafts.drive1.diameter``).

Used by ``torquesplit run --set PATH=VALUE`` and by studies: the raw model data is
edited before validation, so every override goes through the same units and checks
as the file itself.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any, Mapping

from ..errors import ModelError


def set_parameter(data: dict, path: str, value: Any) -> dict:
    """Return a copy of ``data`` with the field at dotted ``path`` set to ``value``.

    The parent table must exist; the field itself may be new (it is then checked by the
    schema like any other field).  List items are addressed by index (``axis.2``).
    """
    out = copy.deepcopy(data)
    parts = path.split(".")
    node = out
    for i, key in enumerate(parts[:-1]):
        node = _child(node, key, ".".join(parts[: i + 1]), path)
    last = parts[-1]
    if isinstance(node, list):
        idx = _index(last, node, path)
        node[idx] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise ModelError([(path, f"{'.'.join(parts[:-1])!r} is a value, not a table; "
                                 f"check the path")])
    return out


def apply_overrides(data: dict, overrides: Mapping[str, Any]) -> dict:
    """Apply several ``{path: value}`` overrides in order."""
    for path, value in overrides.items():
        data = set_parameter(data, path, value)
    return data


def parse_assignment(text: str) -> tuple[str, Any]:
    """``"meshes.m1.damping_ratio=0.07"`` -> (path, value); the value is read as TOML
    when it can be (numbers, booleans, quoted strings) and as a string otherwise
    (``250 mm``)."""
    if "=" not in text:
        raise ModelError([("--set", f"{text!r} is not PATH=VALUE; write e.g. "
                                    f"--set shafts.drive1.diameter='250 mm'")])
    path, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return path, value


def read_raw(source) -> dict:
    """The raw (unvalidated) data of a model file."""
    from .io import read_file

    return read_file(Path(source))


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
