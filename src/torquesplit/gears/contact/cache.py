"""On-disk cache of LTCA excitation tables, keyed by a hash of every input.

The folder is ``$TORQUESPLIT_CACHE_DIR/ltca`` if that variable is set, else
``$XDG_CACHE_HOME/torquesplit/ltca`` or ``~/.cache/torquesplit/ltca``.  A file is an
``.npz`` of arrays plus a JSON summary; its name is the SHA-256 of the canonical JSON of
the inputs (and :data:`CACHE_VERSION`, raised whenever the physics changes, so that
old files are never read).  A file that cannot be read is ignored and rewritten.
Writes go through a temporary file and an atomic rename (safe with parallel workers).
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["CACHE_VERSION", "cache_dir", "cache_key", "load", "store"]

#: bump when the LTCA model changes
CACHE_VERSION = 4


def cache_dir() -> Path:
    """The LTCA cache folder (not created)."""
    root = os.environ.get("TORQUESPLIT_CACHE_DIR")
    if root:
        return Path(root) / "ltca"
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "torquesplit" / "ltca"


def _canonical(obj):
    if isinstance(obj, dict):
        return {str(k): _canonical(v) for k, v in sorted(obj.items())}
    if isinstance(obj, (list, tuple)):
        return [_canonical(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj)  # json writes floats by repr: the exact binary value
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, np.ndarray):
        return [_canonical(v) for v in obj.tolist()]
    return obj


def cache_key(inputs: dict) -> str:
    """SHA-256 of the canonical JSON of ``inputs`` (floats written exactly by repr)."""
    text = json.dumps({"version": CACHE_VERSION, "inputs": _canonical(inputs)},
                      sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def load(key: str) -> tuple[dict[str, np.ndarray], dict] | None:
    """Arrays and summary stored under ``key``, or None."""
    path = cache_dir() / f"{key}.npz"
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: np.array(data[k]) for k in data.files if k != "__summary__"}
            summary = json.loads(str(data["__summary__"]))
        return arrays, summary
    except Exception:  # a damaged or foreign file: recompute
        return None


def store(key: str, arrays: dict[str, np.ndarray], summary: dict) -> Path | None:
    """Write ``arrays`` and ``summary`` under ``key``; returns the path (None if the folder
    cannot be written -- the cache is an optimisation, never a failure)."""
    folder = cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, __summary__=np.array(json.dumps(summary)), **arrays)
        target = folder / f"{key}.npz"
        os.replace(tmp, target)
        return target
    except OSError:
        return None
