"""Remember the last result of a function for each live frozen object.

Loading a model checks it through its kinematics, and the run set up next needs them
again; a study case that runs until settled sets the same model up for each run length;
a run's cost check and its integrator both plan the same RK4 step.
:func:`remember_last` keeps, for each object still alive (held by a weak reference, so
nothing is kept alive and an entry leaves with its object), the result of the last
arguments it was called with, and replays the warnings the first call gave, so that
every caller sees what an uncached call would have shown.  :func:`remember_content`
keeps the results of a function of arrays by their content, across objects: the cases of
a study that vary only errors or phases build new structures whose matrices are the
same.  :func:`hash_arrays` makes the keys of results computed from arrays.
"""

from __future__ import annotations

import functools
import warnings
import weakref

from .errors import collect_model_warnings, note_warning


def remember_last(fn=None, *, replay: bool = True):
    """Decorator: ``fn(obj, *args)`` computed once while ``obj`` (frozen) lives and
    ``args`` stay the same; its warnings are given again on every call.  The table
    (``id(obj) -> (weak ref, args, result, warnings)``) is ``wrapper.cache``.

    ``replay=False`` for a function that gives no warning: its calls are not recorded
    (recording changes the process's warning filters, which threads share: a Dask
    worker's thread could record another's warnings)."""
    if fn is None:
        return functools.partial(remember_last, replay=replay)
    cache: dict = {}

    @functools.wraps(fn)
    def wrapper(obj, *args):
        key = id(obj)
        ref, last_args, result, said = cache.get(key, (None, None, None, None))
        alive = ref is not None and ref() is obj
        if not alive or last_args != args:
            if replay:
                # (recorded here and given below, as on every later call: kept once)
                with warnings.catch_warnings(record=True) as said, \
                        collect_model_warnings(pause=True):
                    warnings.simplefilter("always")
                    result = fn(obj, *args)
            else:
                result, said = fn(obj, *args), []
            if not alive:
                weakref.finalize(obj, cache.pop, key, None)
            cache[key] = (weakref.ref(obj), args, result, said)
        for w in said:
            note_warning(w.message, w.category)
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return result

    wrapper.cache = cache
    return wrapper


class Kept:
    """Results by key (a digest), the oldest dropped beyond ``kept``; a lock around every
    look-up and insertion (a Dask worker's threads share a table).  ``get`` returns
    None for a key not kept."""

    def __init__(self, kept: int):
        import threading

        self.kept = kept
        self._table: dict = {}
        self._lock = threading.Lock()

    def get(self, key):
        with self._lock:
            return self._table.get(key)

    def put(self, key, value) -> None:
        with self._lock:
            while len(self._table) >= self.kept:
                self._table.pop(next(iter(self._table)))
            self._table[key] = value

    def clear(self) -> None:
        with self._lock:
            self._table.clear()

    def __len__(self) -> int:
        return len(self._table)

    def __iter__(self):
        return iter(list(self._table))


def remember_content(fn=None, *, kept: int = 8):
    """Decorator: ``fn(*arrays)`` computed once per content of its arguments (arrays or
    numbers: dtype, shape and bytes, :func:`hash_arrays`) in this process, the oldest of
    more than ``kept`` dropped.  For pure functions whose results nobody changes (make
    arrays read-only) and are never None; the table (:class:`Kept`) is
    ``wrapper.cache``."""
    if fn is None:
        return functools.partial(remember_content, kept=kept)
    import hashlib

    cache = Kept(kept)

    @functools.wraps(fn)
    def wrapper(*args):
        key = hash_arrays(hashlib.blake2b(digest_size=20), args).digest()
        result = cache.get(key)
        if result is None:
            result = fn(*args)
            cache.put(key, result)
        return result

    wrapper.cache = cache
    return wrapper


def hash_arrays(h, arrays):
    """Feed each array's dtype, shape and bytes (C order) to the hashlib object ``h``
    and return it: the key of a result computed from those arrays (equal digests, equal
    arrays)."""
    import numpy as np

    for x in arrays:
        arr = np.ascontiguousarray(x)
        h.update(str((arr.dtype, arr.shape)).encode())
        h.update(arr.tobytes())
    return h
