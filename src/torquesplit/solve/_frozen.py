"""Read-only arrays for the frozen result objects of :mod:`torquesplit.solve`."""

from __future__ import annotations

import dataclasses

import numpy as np


def freeze_arrays(obj) -> None:
    """Make every numpy array held by the dataclass ``obj`` read-only.

    The result dataclasses are frozen; this extends the promise to their arrays, so a
    result can be shared (e.g. between analyses of one study case) without copies.
    Copy an array (``a.copy()``) to modify it.
    """
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
