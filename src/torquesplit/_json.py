"""JSON that every reader accepts: NaN and infinities written as null.

Python's ``json`` writes a non-finite float as the bare token ``NaN`` or ``Infinity``,
which is not JSON: JavaScript, MATLAB's ``jsondecode`` and most other readers refuse the
whole document.  Every JSON the command line prints or a results file carries goes
through :func:`dumps`.
"""

from __future__ import annotations

import json
import math

import numpy as np


def finite(obj):
    """``obj`` with every non-finite float (also inside dicts, lists, tuples, numpy arrays
    and scalars) replaced by None."""
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def dumps(obj, **kwargs) -> str:
    """:func:`json.dumps` of :func:`finite` ``(obj)``; never writes NaN or Infinity."""
    return json.dumps(finite(obj), allow_nan=False, **kwargs)
