"""Render the documents whose numbers come from data, so that they cannot drift.

    python scripts/render_docs.py            # write them
    python scripts/render_docs.py --check    # exit 1 if a document differs from its data

``docs/validation.md`` is rendered from ``docs/validation.md.in`` (prose written by
hand) and ``docs/validation_results.json`` (every number, written by
``scripts/validate.py``).  A placeholder ``{{path/to/value:fmt}}`` is replaced by the
value at that path of the JSON (keys separated by ``/``; a key may hold spaces and
dots) formatted with the Python format spec ``fmt`` (``fmt~path``: and marked † where the
change under a halved step at ``path`` exceeds half its last digit, :func:`held`);
``{{=expression:fmt}}`` evaluates a
small arithmetic expression over ``$[path]`` references, with ``min`` and ``max``
(for ranges and ratios).  A
list of texts (a run's warnings) is written as one markdown bullet per item (``:nested``:
indented, inside a list item).
``benchmarks/RESULTS.md`` is rendered by ``benchmarks/run.py`` from
``benchmarks/RESULTS.json`` (``run.py --render`` re-renders it without measuring); both
renderings are checked by ``tests/test_docs_data.py``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VALIDATION = (ROOT / "docs" / "validation.md.in", ROOT / "docs" / "validation_results.json",
              ROOT / "docs" / "validation.md")

_FIELD = re.compile(r"\{\{(=?)([^{}]+?)(?::([^{}:]*))?\}\}")
_REF = re.compile(r"\$\[([^\]]+)\]")


def lookup(data, path: str):
    """The value at ``a/b/c`` of nested dicts (and lists, by index).  A key that itself
    holds ``/`` (a load-sharing group ``left/spur``) is found by joining parts."""
    node = data
    parts = path.strip().split("/")
    i = 0
    while i < len(parts):
        if isinstance(node, list):
            node = node[int(parts[i])]
            i += 1
            continue
        for j in range(len(parts), i, -1):
            key = "/".join(parts[i:j])
            if key in node:
                node = node[key]
                i = j
                break
        else:
            raise KeyError(f"{path!r}: no key {parts[i]!r} (have {sorted(node)[:12]})")
    return node


def _value(data, expression: str, is_expr: bool):
    if not is_expr:
        return lookup(data, expression)
    refs = {}

    def sub(m):
        name = f"_v{len(refs)}"
        refs[name] = float(lookup(data, m.group(1)))
        return name

    code = _REF.sub(sub, expression)
    if not re.fullmatch(r"(?:[\s_v0-9.+\-*/(),e]|min|max)*", code):
        raise ValueError(f"expression {expression!r} may only hold $[paths], numbers, "
                         "+ - * / and min( , ) / max( , )")
    return eval(code, {"__builtins__": {}, "min": min, "max": max}, refs)  # noqa: S307


def render(template: str, data) -> str:
    """The template with every placeholder replaced (see the module docstring)."""
    def field(m):
        value = _value(data, m.group(2), m.group(1) == "=")
        fmt = m.group(3)
        if isinstance(value, list):  # bullets; fmt "nested": inside a list item
            bullet = "  - " if fmt == "nested" else "- "
            return "\n".join(bullet + str(item) for item in value) if value else bullet + "none"
        if fmt and "~" in fmt:  # a number and how far it moves under h/2
            fmt, change = fmt.split("~", 1)
            # the halved run's value beside its change, where the data have it
            try:
                halved = float(lookup(data, change.replace("/halved/change/", "/halved/value/")))
            except (KeyError, TypeError, ValueError):
                halved = None
            return held(value, fmt, float(lookup(data, change)), halved)
        return format(value, fmt) if fmt else str(value)
    return _FIELD.sub(field, template)


NOT_HELD = "†"
"""The mark of a printed number that moves by more than half a unit of its last printed
digit when the step is halved (the data hold the change, not the halved value)."""


def held(value: float, fmt: str, change: float, halved: float | None = None) -> str:
    """``value`` formatted with ``fmt`` (a fixed-point ``.Nf``), marked NOT_HELD when its
    change under a halved step (``change``, absolute) is more than half a unit of the
    last printed digit, or when the halved run's value (``halved``, where known) prints
    otherwise (1.1052138 -> 1.1052504 moves by less than half a unit of the 4th decimal
    and prints 1.1052 -> 1.1053: :func:`torquesplit.convergence.agreeing_digits`'s rule,
    which ``--check-step`` applies): the digits printed do not all hold."""
    m = re.fullmatch(r"\.(\d+)f", fmt)
    if m is None:
        raise ValueError(f"a held number takes a fixed-point format (.3f), not {fmt!r}")
    unit = 10.0 ** -int(m.group(1))
    flips = halved is not None and format(halved, fmt) != format(value, fmt)
    return format(value, fmt) + (NOT_HELD if flips or not abs(change) <= 0.5 * unit else "")


def render_validation() -> str:
    template, data, _ = VALIDATION
    return render(template.read_text(encoding="utf-8"),
                  json.loads(data.read_text(encoding="utf-8")))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only compare, exit 1 on drift")
    args = ap.parse_args(argv)
    text = render_validation()
    out = VALIDATION[2]
    if args.check:
        if out.read_text(encoding="utf-8") != text:
            print(f"{out} differs from its data; run python scripts/render_docs.py")
            return 1
        return 0
    out.write_text(text, encoding="utf-8")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
