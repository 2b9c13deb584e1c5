"""Remember the last result of a function of a frozen object.

Loading a model checks it through its kinematics, and the run set up next needs them
again; a study case that runs until settled sets the same model up for each run length.
:func:`remember_last` keeps the result for the last object (held by a weak reference, so
nothing is kept alive) and replays the warnings the first call gave, so that every
caller sees what an uncached call would have shown.
"""

from __future__ import annotations

import functools
import warnings
import weakref


def remember_last(fn):
    """Decorator: ``fn(obj, *args)`` computed once while ``obj`` (frozen) and ``args``
    stay the same; its warnings are given again on every call."""
    last: list = [None, None, None, None]  # weak ref, args, result, warnings

    @functools.wraps(fn)
    def wrapper(obj, *args):
        ref, key, result, said = last
        if ref is None or ref() is not obj or key != args:
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                result = fn(obj, *args)
            last[:] = [weakref.ref(obj), args, result, said]
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return result

    return wrapper
