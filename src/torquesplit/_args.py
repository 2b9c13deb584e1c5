"""Checks of the Python API's plain arguments (counts, positive numbers, result kinds):
one message style for every function, naming the argument and giving an example, so a
wrong value is an :class:`~torquesplit.errors.OptionError`, never a traceback from deep
inside numpy or matplotlib."""

from __future__ import annotations

import math
import numbers

from torquesplit.errors import OptionError, OptionTypeError


def whole(value, name: str, example: str, minimum: int = 1) -> int:
    """``value`` as a whole number >= ``minimum`` (a float with a whole value is
    accepted; a bool is not)."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if isinstance(value, numbers.Real) and not isinstance(value, (bool, numbers.Integral)):
        ok = math.isfinite(value) and float(value).is_integer()
    if not ok or value < minimum:
        raise OptionError(f"{name} must be a whole number >= {minimum}, got {value!r}; give "
                          f"e.g. {example}")
    return int(value)


def positive(value, name: str, example: str) -> float:
    """``value`` as a positive finite number."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not ok or not (math.isfinite(value) and value > 0):
        raise OptionError(f"{name} must be a positive number, got {value!r}; give e.g. "
                          f"{example}")
    return float(value)


def number(value, name: str, example: str) -> float:
    """``value`` as a finite number (a string such as 'abc' was a ValueError)."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not ok or not math.isfinite(value):
        raise OptionError(f"{name} must be a finite number, got {value!r}; give e.g. "
                          f"{example}")
    return float(value)


def results_of(results, function: str, kinds: tuple[str, ...]) -> None:
    """Refuse a first argument that is not results of one of ``kinds`` ("dynamic": a
    :class:`~torquesplit.results.Results`, "static": a
    :class:`~torquesplit.quasistatic.QuasiStaticResults`)."""
    from torquesplit.quasistatic import QuasiStaticResults
    from torquesplit.results import Results

    known = {"dynamic": (Results, "the Results of a dynamic run (torquesplit.simulate)"),
             "static": (QuasiStaticResults,
                        "the results of torquesplit.quasi_static_load_sharing")}
    if any(isinstance(results, known[k][0]) for k in kinds):
        return
    wanted = " or ".join(known[k][1] for k in kinds)
    raise OptionTypeError(f"{function} takes {wanted}, got {type(results).__name__} "
                          f"{_short(results)}")


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
