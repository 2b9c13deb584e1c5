"""Where a field is in a TOML model file: the line of each key path, for error messages
that an editor can jump to (``drive.toml:42: gears.pinion.module: ...``).

tomllib gives values, not positions, so the text is scanned line by line: table headers
(``[gears.pinion]``), arrays of tables (``[[planetary]]``: ``planetary.0``,
``planetary.1``; a sub-table header ``[planetary.sun]`` belongs to the last one), keys
(``module = ...``, dotted keys ``support.stiffness = ...``) and the keys of a one-line
inline table (``support = {stiffness = "1e9 N/m"}``).  A path not in the file (a default,
a table written as its one-value shorthand) is placed at its longest prefix that is.
This is a locator for messages, not a parser: the file has already been read by tomllib,
and anything it does not follow (a key inside a multi-line array) falls back to a prefix.
"""

from __future__ import annotations

import re

_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(?:#.*)?$")
_KEY = re.compile(r"^\s*((?:[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*')"
                  r"(?:\s*\.\s*(?:[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*'))*)\s*=")
_INLINE_KEY = re.compile(r"[{,]\s*([A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*')\s*=")


def _parts(dotted: str) -> list[str]:
    """``a."b.c".d`` -> ['a', 'b.c', 'd']."""
    out = re.findall(r"\"([^\"]*)\"|'([^']*)'|([A-Za-z0-9_-]+)", dotted)
    return [a or b or c for a, b, c in out]


def key_lines(text: str) -> dict[str, int]:
    """Every key path of a TOML text -> its line (1-based), the first where it appears."""
    lines: dict[str, int] = {}
    arrays: dict[str, int] = {}  # array-of-tables path -> index of its last element
    table: list[str] = []

    def resolve(parts: list[str]) -> list[str]:
        """A header's path with the array-of-tables indices it passes through."""
        out: list[str] = []
        for p in parts:
            out.append(p)
            key = ".".join(out)
            if key in arrays:
                out.append(str(arrays[key]))
        return out

    def note(parts: list[str], line: int) -> None:
        for k in range(1, len(parts) + 1):
            lines.setdefault(".".join(parts[:k]), line)

    depth, quote = 0, None  # brackets open and the multi-line string we are in, from
    # the lines before: a line inside either is no header and no key (a lone array row
    # '  [0.5, 2e9]' read as a table header; a description's lines as keys)
    for number, raw in enumerate(text.splitlines(), start=1):
        inside = depth > 0 or quote is not None
        depth, quote = _carry(raw, depth, quote)
        if inside:
            continue
        m = _HEADER.match(raw)
        if m:
            parts = _parts(m.group(2))
            if m.group(1) == "[[":
                head = resolve(parts[:-1]) + [parts[-1]]
                key = ".".join(head)
                arrays[key] = arrays.get(key, -1) + 1
                table = head + [str(arrays[key])]
            else:
                table = resolve(parts)
            note(table, number)
            continue
        m = _KEY.match(raw)
        if m is None:
            continue
        path = table + _parts(m.group(1))
        note(path, number)
        rest = raw[m.end():]
        if rest.lstrip().startswith("{"):  # a one-line inline table: its keys too
            for inner in _INLINE_KEY.finditer(rest):
                lines.setdefault(".".join(path + _parts(inner.group(1))), number)
    return lines


def _carry(line: str, depth: int, quote: str | None) -> tuple[int, str | None]:
    """The bracket depth and the open multi-line string (its delimiter) after ``line``,
    given those before it: quotes, comments and escapes as TOML reads them."""
    i, n = 0, len(line)
    while i < n:
        if quote is not None:
            if line.startswith(quote, i):
                i, quote = i + len(quote), None
                continue
            i += 2 if line[i] == "\\" and quote[0] == '"' else 1
            continue
        c = line[i]
        if c == "#":
            break
        if line.startswith('"""', i) or line.startswith("'''", i):
            quote = line[i:i + 3]
            i += 3
            continue
        if c in "\"'":  # a one-line string: skip to its end
            j = i + 1
            while j < n and line[j] != c:
                j += 2 if c == '"' and line[j] == "\\" else 1
            i = j + 1
            continue
        if c in "[{":
            depth += 1
        elif c in "]}":
            depth = max(0, depth - 1)
        i += 1
    return depth, quote


def line_of(lines: dict[str, int], location: str) -> int | None:
    """The line of ``location`` (a dotted field path), or of its longest prefix in the
    file; None where nothing of it is."""
    parts = location.split(".")
    for k in range(len(parts), 0, -1):
        found = lines.get(".".join(parts[:k]))
        if found is not None:
            return found
    return None
