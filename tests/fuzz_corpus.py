"""A deterministic corpus of malformed model files, and how to judge what the CLI does.

Mutant ``i`` of seed ``s`` is always the same bytes (``random.Random(f"{s}-{i}")``), so a
failure found by the CI fuzz test or by ``scripts/fuzz_models.py`` is reproduced by its
number alone.  A mutant starts from a valid model (a spur pair, a helical pair with
most of the schema, a two-path split) and gets one to three mutations:

* on the data: a key deleted or renamed, a leaf or a whole section replaced by junk
  (another type, a boolean, an edge number, a unit alone, a wrong dimension, an absurd
  magnitude), a section duplicated; then written as TOML or JSON;
* on the text: truncated, a line deleted or repeated, random or invalid UTF-8 bytes,
  a BOM, UTF-16, brackets or inline tables nested up to 100,000 deep, dotted keys
  thousands deep, quantity strings up to 100,000 characters, integers of 20,000
  digits, an empty file.

:func:`judge` classifies an outcome: ``ok`` (exit 0), ``error`` (exit 2 and every line
on stderr an ``error:`` or ``warning:`` line of bounded length), anything else a bug.
"""

from __future__ import annotations

import copy
import json
import random
import tomllib

import tomli_w

from model_fixtures import PAIR_TOML, RICH_TOML
from model_texts import split_model

#: the valid models mutants start from
BASES = {"pair": PAIR_TOML, "rich": RICH_TOML, "split": split_model()}

#: longest stderr line judged clean (errors.LINE_LIMIT plus the file name and location)
MAX_LINE = 1400

WRONG_UNITS = ["50 kg", "3 s", "2 N/m", "100 rpm", "20 deg", "5 mm", "7 GPa", "1 kW", "3 N m",
               "1 kg m^2", "2 Hz", "1 N s/m", "4 N m/rad", "7850 kg/m^3", "0.01 Pa s",
               "20 degC", "1 m/s", "3 mm^2", "mm", "rpm", "N m", "", "20", "-5 mm", "0 mm"]
ABSURD = ["560 parsec", "1e-30 m", "1e30 N/m", "1e16 N/m", "1e-15 kg m^2", "1e9 rpm",
          "1e12 N m", "1e6 kg", "3e8 km", "1 fm", "1e-12 N/m", "1e300 mm"]
EDGE_NUMBERS = [0, 0.0, -1, -1.5, -1e-9, 1e200, 1e300, -1e300, 10**30, 2**64, 1e-300, 5e-324,
                2**63 - 1, 1e6, 0.5, 3]
WORDS = ["pinion", "wheel", "motor", "balanced", "theta", "x", "right", "table", "loa",
         "constant", "fourier", "rk4", "out", "a", "b"]
FIELD_NAMES = ["modul", "teeth", "module", "position", "place", "speed", "torque", "power",
               "body", "gears", "stiffness", "damping", "damping_ratio", "backlash", "axis",
               "dofs", "support", "mass", "polar_inertia", "from_gear", "angle", "hand",
               "helix_angle", "kind", "connects", "drives", "loads", "meshes", "shafts",
               "bodies", "model", "name", "pinion", "wheel", "method", "values", "phase"]


def _junk(rng: random.Random):
    kind = rng.randrange(12)
    if kind == 0:
        return None
    if kind == 1:
        return rng.choice([True, False])
    if kind == 2:
        return rng.randint(-10**6, 10**6)
    if kind == 3:
        return rng.choice([float("nan"), float("inf"), -float("inf"), rng.uniform(-1e6, 1e6)])
    if kind == 4:
        return rng.choice(EDGE_NUMBERS)
    if kind == 5:
        return "".join(chr(rng.randrange(32, 0x2FF)) for _ in range(rng.randrange(13)))
    if kind == 6:
        return rng.choice(WRONG_UNITS)
    if kind == 7:
        return rng.choice(ABSURD)
    if kind == 8:
        return rng.choice(WORDS)
    if kind == 9:
        return [rng.choice([rng.randint(-5, 50), rng.choice(WRONG_UNITS)])
                for _ in range(rng.randrange(5))]
    if kind == 10:
        return {rng.choice(FIELD_NAMES): rng.randint(-3, 3) for _ in range(rng.randrange(4))}
    return [True, False, True][: rng.randrange(4)]


def _paths(obj, prefix=()):
    out = []
    items = obj.items() if isinstance(obj, dict) else (
        enumerate(obj) if isinstance(obj, list) else ())
    for key, value in items:
        out.append(prefix + (key,))
        out.extend(_paths(value, prefix + (key,)))
    return out


def _parent(data, path):
    node = data
    for key in path[:-1]:
        node = node[key]
    return node


def _scalable(value) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    if isinstance(value, str):
        head = value.split(" ", 1)[0]
        try:
            float(head)
            return True
        except ValueError:
            return False
    return False


def _scaled(value, factor: float):
    if isinstance(value, int):
        return max(int(value * factor), 0) if factor >= 1 else value
    if isinstance(value, float):
        return value * factor
    head, _, unit = value.partition(" ")
    return f"{float(head) * factor:g} {unit}".strip()


def mutate_data(data: dict, rng: random.Random) -> str:
    """One mutation of the data, in place; a description of it."""
    paths = _paths(data)
    if not paths:
        return "nothing to mutate"
    kind = rng.choice(["delete", "replace_leaf", "replace_leaf", "replace_any", "rename",
                       "duplicate", "absurd", "rescale", "rescale"])
    if kind == "rescale":  # a quantity 10^-15..10^15 times its value: valid, maybe absurd
        numeric = [p for p in paths if _scalable(_parent(data, p)[p[-1]])]
        if not numeric:
            return "rescale: nothing"
        path = rng.choice(numeric)
        _parent(data, path)[path[-1]] = _scaled(_parent(data, path)[path[-1]],
                                                10.0 ** rng.randint(-15, 15))
    elif kind == "delete":
        path = rng.choice(paths)
        del _parent(data, path)[path[-1]]
    elif kind in ("replace_leaf", "replace_any", "absurd"):
        leaves = [p for p in paths if not isinstance(_parent(data, p)[p[-1]], (dict, list))]
        path = rng.choice(leaves if kind != "replace_any" and leaves else paths)
        value = rng.choice(ABSURD) if kind == "absurd" else _junk(rng)
        _parent(data, path)[path[-1]] = value
    elif kind == "rename":
        keyed = [p for p in paths if isinstance(p[-1], str)] or paths
        path = rng.choice(keyed)
        parent = _parent(data, path)
        if isinstance(parent, dict):
            new = rng.choice(FIELD_NAMES + ["".join(rng.choice("abcxyz_.") for _ in range(5))])
            parent[new] = parent.pop(path[-1])
    else:
        tables = [p for p in paths if isinstance(_parent(data, p)[p[-1]], dict)]
        if not tables:
            return "duplicate: nothing"
        path = rng.choice(tables)
        value = copy.deepcopy(_parent(data, path)[path[-1]])
        target = rng.choice(["sibling", "gears", "bodies", "meshes", "drives", "loads"])
        if target == "sibling":
            _parent(data, path)[f"{path[-1]}_copy"] = value
        elif isinstance(data.get(target, {}), dict):
            data.setdefault(target, {})[str(path[-1])] = value
    return f"{kind} {'.'.join(map(str, path))}"


def _serialise(data: dict, rng: random.Random) -> tuple[bytes, str]:
    if rng.random() < 0.8:
        try:
            return tomli_w.dumps(data).encode("utf-8"), ".toml"
        except (TypeError, ValueError):
            pass  # None or NaN cannot be TOML: write JSON
    return json.dumps(data, allow_nan=True).encode("utf-8"), ".json"


def _quantity_spans(text: str) -> list[tuple[int, int]]:
    """Positions of quoted strings that start with a digit (quantities such as "20 mm")."""
    spans, i = [], 0
    while True:
        i = text.find('"', i)
        if i < 0:
            return spans
        j = text.find('"', i + 1)
        if j < 0:
            return spans
        if i + 1 < j and (text[i + 1].isdigit() or text[i + 1] == "-"):
            spans.append((i + 1, j))
        i = j + 1


def mutate_bytes(raw: bytes, suffix: str, rng: random.Random) -> tuple[bytes, str]:
    """One mutation of the file's bytes; the new bytes and a description."""
    text = raw.decode("utf-8", errors="replace")
    lines = text.split("\n")
    kind = rng.choice(["truncate", "line", "bytes", "bom", "utf16", "nest", "nest_open",
                       "long_quantity", "big_integer", "dotted", "bare_unit", "boolean",
                       "flip", "empty", "nul"])
    if kind == "truncate":
        return raw[: rng.randrange(len(raw) + 1)], kind
    if kind == "line" and lines:
        k = rng.randrange(len(lines))
        if rng.random() < 0.5:
            del lines[k]
        else:
            lines.insert(k, lines[k])
        return "\n".join(lines).encode(), kind
    if kind == "bytes":
        pos = rng.randrange(len(raw) + 1)
        junk = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 8)))
        return raw[:pos] + junk + raw[pos:], kind
    if kind == "bom":
        return b"\xef\xbb\xbf" + raw, kind
    if kind == "utf16":
        return text.encode(rng.choice(["utf-16", "utf-32"])), kind
    if kind in ("nest", "nest_open"):
        n = rng.choice([5, 20, 33, 40, 1000, 10_000, 100_000])
        if suffix == ".json":
            opener, closer = rng.choice([("[", "]"), ('{"a": ', "}")])
            inner = opener * n + "1" + (closer * n if kind == "nest" else "")
            return (text.rstrip().rstrip("}") + f', "x": {inner}}}').encode(), f"{kind} {n}"
        opener, closer = rng.choice([("[", "]"), ("{a = ", "}")])
        inner = opener * n + "1" + (closer * n if kind == "nest" else "")
        return (text + f"\nx = {inner}\n").encode(), f"{kind} {n}"
    if kind == "long_quantity":
        spans = _quantity_spans(text)
        if spans:
            a, b = rng.choice(spans)
            n = rng.choice([101, 1000, 20_000, 100_000])
            filler = rng.choice(["1" * n + " mm", "1 " * (n // 2) + "mm", "(" * n,
                                 "1" * n, "x" * n, "1e" + "9" * n])
            return (text[:a] + filler + text[b:]).encode(), f"{kind} {n}"
    if kind == "big_integer":
        n = rng.choice([400, 4301, 20_000])
        key = rng.choice(["teeth", "seed", "cycles", "damping_ratio", "x"])
        return (text + f"\n{key} = {'9' * n}\n").encode(), f"{kind} {n}"
    if kind == "dotted":
        n = rng.choice([10, 40, 5000])
        return (text + "\n" + "a" + ".a" * n + " = 1\n").encode(), f"{kind} {n}"
    if kind == "bare_unit":
        spans = _quantity_spans(text)
        if spans:
            a, b = rng.choice(spans)
            unit = text[a:b].split(" ", 1)[-1] if " " in text[a:b] else "mm"
            return (text[:a] + unit + text[b:]).encode(), kind
    if kind == "boolean":
        spans = _quantity_spans(text)
        if spans and suffix == ".toml":
            a, b = rng.choice(spans)
            return (text[: a - 1] + rng.choice(["true", "false"]) + text[b + 1:]).encode(), kind
    if kind == "flip" and raw:
        pos = rng.randrange(len(raw))
        return raw[:pos] + bytes([rng.randrange(32, 127)]) + raw[pos + 1:], kind
    if kind == "empty":
        return rng.choice([b"", b"   \n", b"\n\n#\n"]), kind
    if kind == "nul" and raw:
        pos = rng.randrange(len(raw))
        return raw[:pos] + b"\x00" + raw[pos:], kind
    return raw, "unchanged"


def mutant(index: int, seed: int = 0) -> tuple[str, bytes, str]:
    """Mutant ``index``: (description, file bytes, suffix)."""
    rng = random.Random(f"{seed}-{index}")
    base = rng.choice(sorted(BASES))
    data = tomllib.loads(BASES[base])
    steps = [base]
    n_data = rng.choice([0, 1, 1, 2, 3])
    for _ in range(n_data):
        steps.append(mutate_data(data, rng))
    raw, suffix = _serialise(data, rng)
    if n_data == 0 or rng.random() < 0.35:
        raw, what = mutate_bytes(raw, suffix, rng)
        steps.append(what)
    return "; ".join(steps), raw, suffix


def judge(exit_code: int, stdout: str, stderr: str, exception: BaseException | None = None) -> str:
    """Classify an outcome of ``torquesplit check``.

    ``ok`` (exit 0) and ``error`` (exit 2, every line on stderr an ``error:`` or
    ``warning:`` line of at most :data:`MAX_LINE` characters) are clean; anything else is
    a bug: ``traceback`` (an exception escaped), ``multi-line error`` (continuation lines
    without ``error:``), ``long line``, ``dirty stderr`` (other output, e.g. raw numpy
    warnings) or ``exit N``.
    """
    if exception is not None and not isinstance(exception, SystemExit):
        return "traceback"
    if "Traceback" in stdout or "Traceback" in stderr:
        return "traceback"
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    if any(len(ln) > MAX_LINE for ln in lines):
        return "long line"
    if any(not ln.startswith(("error:", "warning:")) for ln in lines):
        if exit_code == 2 and lines and lines[0].startswith("error:"):
            return "multi-line error"
        return "dirty stderr"
    if exit_code == 0:
        return "ok"
    if exit_code == 2 and any(ln.startswith("error:") for ln in lines):
        return "error"
    return f"exit {exit_code}"
