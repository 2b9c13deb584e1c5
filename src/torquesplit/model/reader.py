"""The one guarded reader of model files: limits first, then the TOML or JSON parser.

A model file is a few kilobytes of text nested a few levels deep.  Whatever a file
holds instead -- a folder, an endless device such as ``/dev/zero``, gigabytes, bytes that
are not UTF-8, a BOM, arrays nested ten thousand deep, a 20,000-digit integer -- ends in
one :class:`~torquesplit.errors.ModelError` that says what is wrong and what to do,
quickly and without a traceback:

==========================  ============================================================
limit                       why
==========================  ============================================================
:data:`MAX_FILE_BYTES`      at most this much is read, so an endless input stops at once
UTF-8, BOM accepted         a UTF-8 byte-order mark (Windows editors) is skipped;
                            UTF-16/32 and invalid bytes are named with line and column
:data:`MAX_DEPTH`           brackets nested deeper are refused *before* the parser,
                            whose recursion would otherwise end in ``RecursionError``;
                            the parsed data (dotted keys) is measured again after it
==========================  ============================================================

String-length limits of quantity fields (before pint sees them) live in
:func:`torquesplit.model.units.parse_quantity`, next to the parsing they protect.
"""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path
from typing import Any

from ..errors import ModelError, clip_text

#: largest model file read [bytes]; the largest shipped example is about 20 KB
MAX_FILE_BYTES = 4 * 1024 * 1024

#: deepest nesting of arrays, inline tables and sections; the schema needs about 5
MAX_DEPTH = 32

_BOMS = {
    b"\xef\xbb\xbf": None,  # UTF-8: accepted
    b"\xff\xfe\x00\x00": "UTF-32", b"\x00\x00\xfe\xff": "UTF-32",
    b"\xff\xfe": "UTF-16", b"\xfe\xff": "UTF-16",
}

#: tokens that matter for nesting: brackets, string delimiters, comments, line ends
_TOML_TOKENS = re.compile(r'"""|\'\'\'|["\'#\[\]{}\n\\.=,]')
_QUOTES = ('"', "'", '"""', "'''")
_JSON_TOKENS = re.compile(r'["\[\]{}\n\\]')


def read_model_file(path) -> dict[str, Any]:
    """Read and parse a model file (``.json`` as JSON, anything else as TOML).

    Parameters
    ----------
    path : str or Path
        The file.  Folders, unreadable files, files over :data:`MAX_FILE_BYTES`
        (including endless devices), text that is not UTF-8 and nesting deeper than
        :data:`MAX_DEPTH` are refused.

    Returns
    -------
    dict
        The parsed data (not yet validated against the schema).

    Raises
    ------
    ModelError
        Naming the file, what is wrong and what to do.

    Examples
    --------
    >>> import torquesplit
    >>> from torquesplit.model.reader import read_model_file
    >>> data = read_model_file(torquesplit.example_path("ji_li_mill_drive"))
    >>> sorted(data)[:3]
    ['analysis', 'bodies', 'drives']
    """
    path = Path(path)
    source = str(path)
    if path.suffix.lower() in (".nc", ".netcdf", ".h5", ".mat", ".csv"):
        raise ModelError([("", (
            f"is a results file ({path.suffix}), not a model file; read results with "
            f"torquesplit.results.load_results (.nc) or open them in MATLAB or a "
            f"spreadsheet, and give the model file (.toml or .json) here"))], source)
    raw = _read_bytes(path, source)
    text = decode_model_bytes(raw, source)
    data = parse_model_text(text, "json" if path.suffix.lower() == ".json" else "toml", source)
    _warn_bare_speeds(data, source)
    return data


def _warn_bare_speeds(data, source: str) -> None:
    """A drive speed written as a bare number is read in rad/s (SI), which a file that
    means rpm does not show: ``speed = 3000`` ran at 28,648 rpm, a 9.5 kHz mesh, without a
    word, where ``--set drives.motor.speed=3000`` warned.  Said once, where the file is
    read (a study's cases do not repeat it); ``'3000 rad/s'`` says it was meant."""
    drives = data.get("drives") if isinstance(data, dict) else None
    if not isinstance(drives, dict):
        return
    from ..errors import ModelWarning, warn_user
    from .units import rad_s_text

    for name, drive in drives.items():
        value = drive.get("speed") if isinstance(drive, dict) else None
        if isinstance(value, (int, float)) and not isinstance(value, bool) and value != 0:
            warn_user(ModelWarning(
                f"{source}: drives.{name}.speed: a bare number is a speed in rad/s "
                f"({rad_s_text(value)}); write '{value:g} rpm' for rpm, or "
                f"'{value:g} rad/s' to say it is rad/s"))


def _read_bytes(path: Path, source: str) -> bytes:
    try:
        if path.is_dir():
            raise ModelError([("", "is a folder, not a model file; give the path of a .toml "
                                   "or .json file (or an example name)")], source)
        if path.is_fifo() or path.is_socket():  # (reading one waits for a writer: a hang)
            raise ModelError([("", "is a pipe or socket, not a model file; give the path of "
                                   "a .toml or .json file")], source)
        with open(path, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ModelError(
            [("", f"no such file; check the path (current folder: {Path.cwd()})")], source
        ) from None
    except IsADirectoryError:
        raise ModelError([("", "is a folder, not a model file; give the path of a .toml "
                               "or .json file")], source) from None
    except OSError as exc:
        reason = exc.strerror or exc.__class__.__name__
        raise ModelError([("", f"cannot be read ({reason}); check the path and the file's "
                               f"permissions")], source) from None
    if len(raw) > MAX_FILE_BYTES:
        raise ModelError([("", f"is larger than {MAX_FILE_BYTES // 2**20} MiB (a model file "
                               f"is a few KB; an endless device never ends); check that "
                               f"this is the model file")], source)
    return raw


def decode_model_bytes(raw: bytes, source: str | None = None) -> str:
    """UTF-8 text of a model file; a UTF-8 BOM is skipped, anything else named.

    Examples
    --------
    >>> decode_model_bytes(b"\\xef\\xbb\\xbfa = 1")
    'a = 1'
    """
    for bom, name in _BOMS.items():
        if raw.startswith(bom):
            if name is None:
                raw = raw[len(bom):]
                break
            raise ModelError([("", f"is encoded as {name}; save it as UTF-8 (in most editors: "
                                   f"'Save with encoding' > UTF-8)")], source)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        before = raw[: exc.start]
        line = before.count(b"\n") + 1
        column = exc.start - (before.rfind(b"\n") + 1) + 1
        bad = raw[exc.start: exc.start + 1].hex()
        raise ModelError([("", f"is not valid UTF-8 text: byte 0x{bad} at line {line}, column "
                               f"{column}; save the file as UTF-8 or remove that character")],
                         source) from None


def parse_model_text(text: str, fmt: str = "toml", source: str | None = None) -> dict[str, Any]:
    """Parse TOML or JSON text after checking its nesting depth.

    Parameters
    ----------
    text : str
    fmt : {"toml", "json"}
    source : str, optional
        Named in error messages (the file).

    Raises
    ------
    ModelError
        Syntax errors (with the line), nesting deeper than :data:`MAX_DEPTH`, numbers
        Python refuses to read (integers of more than 4300 digits).
    """
    check_nesting(text, fmt, source)
    try:
        data = json.loads(text) if fmt == "json" else tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError([("", f"TOML syntax error: {exc}; fix the line it names")],
                         source) from None
    except json.JSONDecodeError as exc:
        raise ModelError(
            [("", f"JSON syntax error at line {exc.lineno} column {exc.colno}: {exc.msg}; "
                  f"fix the file there")], source) from None
    except RecursionError:  # pragma: no cover - check_nesting stops this first
        raise ModelError([("", f"is nested too deeply; a model file needs at most "
                               f"{MAX_DEPTH} levels: check for unclosed brackets")],
                         source) from None
    except ValueError as exc:  # e.g. an integer literal of more than 4300 digits
        what = ("an integer of more than 4300 digits" if "digits" in str(exc)
                else f"a value Python cannot read ({clip_text(str(exc))})")
        raise ModelError([("", f"has {what}; write numbers of ordinary size, e.g. 1e30")],
                         source) from None
    check_data_depth(data, source)
    return data


def check_nesting(text: str, fmt: str = "toml", source: str | None = None,
                  limit: int = MAX_DEPTH) -> None:
    """Refuse brackets (arrays, inline tables) nested more than ``limit`` deep.

    A linear scan that skips strings and comments, stopping at the first level too
    deep, so it takes microseconds for a model file and cannot recurse.  TOML dotted
    keys (``a.b.c = 1``, one table per part) with more than ``limit`` parts are refused
    too: the parser takes seconds to build thousands of levels.

    Examples
    --------
    >>> check_nesting("a = [[1], {b = '[[[['}]", limit=2)
    >>> check_nesting("a = [[[1]]]", limit=2)
    Traceback (most recent call last):
    ...
    torquesplit.errors.ModelError: line 1: brackets are nested more than 2 deep; a model file needs a few levels: check for unclosed or repeated '[' and '{'
    """
    if text.count("[") + text.count("{") <= limit and text.count(".") <= limit:
        return
    tokens = _JSON_TOKENS if fmt == "json" else _TOML_TOKENS
    opened = []  # the brackets open at this point
    line = 1
    string = None  # the delimiter of the string we are in
    comment = False
    escaped_at = -1
    in_key = True  # TOML: from the start of a line (or '{', ',' in a table) to '='
    dots = 0  # dots of the current dotted key: each part is one more level of tables
    for m in tokens.finditer(text):
        tok = m.group()
        if tok == "\n":
            line += 1
            comment = False
            in_key, dots = True, 0
            if string in ('"', "'"):
                string = None  # single-line strings end at the line (the parser says more)
            continue
        if comment:
            continue
        if string is not None:
            if tok == "\\" and string in ('"', '"""'):
                if m.start() != escaped_at:
                    escaped_at = m.end()  # the next character is escaped
                continue
            if tok == string and m.start() != escaped_at:
                string = None
            continue
        if tok == "#":
            comment = True
        elif tok in _QUOTES:
            string = tok
        elif tok == "=":
            in_key, dots = False, 0
        elif tok == ",":
            in_key, dots = bool(opened) and opened[-1] == "{", 0
        elif tok == ".":
            dots += in_key
            if dots > limit:
                raise ModelError([(f"line {line}", (
                    f"a dotted key has more than {limit} parts; a model file needs a few "
                    f"levels: check the key (section.name.field)"))], source)
        elif tok in "[{":
            opened.append(tok)
            in_key = in_key or tok == "{"
            if len(opened) > limit:
                raise ModelError([(f"line {line}", (
                    f"brackets are nested more than {limit} deep; a model file needs a few "
                    f"levels: check for unclosed or repeated '[' and '{{'"))], source)
        elif tok in "]}" and opened:
            opened.pop()


def check_data_depth(data, source: str | None = None, limit: int = MAX_DEPTH) -> None:
    """Refuse parsed data nested more than ``limit`` deep (dotted keys ``a.b.c...`` make
    deep tables without brackets); iterative, so it cannot recurse."""
    stack = [(data, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > limit:
            raise ModelError([("", f"tables or lists are nested more than {limit} deep; a "
                                   f"model file needs a few levels: check long dotted keys "
                                   f"and brackets")], source)
        if isinstance(node, dict):
            stack.extend((v, depth + 1) for v in node.values() if isinstance(v, (dict, list)))
        elif isinstance(node, list):
            stack.extend((v, depth + 1) for v in node if isinstance(v, (dict, list)))
