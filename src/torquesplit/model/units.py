"""Units at the edge: parse quantities written in model files and on the command line.

Inside torquesplit every number is SI float64.  This module is the only place that
knows about pint.  A field declares its *kind* (``"length"``, ``"stiffness"``...);
a value may be written as a string with units (``"0.85e6 N/mm"``), or as a bare
number, which is read in the kind's SI unit (given in :data:`KINDS`).
"""

from __future__ import annotations

import math
from functools import lru_cache

import pint

#: kind -> (SI unit as written in docs, example for messages)
KINDS: dict[str, tuple[str, str]] = {
    "length": ("m", "50 um"),
    "angle": ("rad", "20 deg"),
    "mass": ("kg", "12.5 kg"),
    "inertia": ("kg m^2", "0.35 kg m^2"),
    "density": ("kg/m^3", "7850 kg/m^3"),
    "stiffness": ("N/m", "0.85e6 N/mm"),
    "torsional_stiffness": ("N m/rad", "2.5e6 N m/rad"),
    "damping": ("N s/m", "1500 N s/m"),
    "torsional_damping": ("N m s/rad", "20 N m s/rad"),
    "pressure": ("Pa", "206 GPa"),
    "speed": ("rad/s", "8780 rpm"),
    "power": ("W", "2000 kW"),
    "torque": ("N m", "17500 N m"),
    "time": ("s", "0.5 s"),
    "frequency": ("Hz", "235.9 Hz"),
    "viscosity": ("Pa s", "0.012 Pa s"),
    "force": ("N", "1200 N"),
}


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The one pint registry of torquesplit (created on first use)."""
    ureg = pint.UnitRegistry()
    return ureg


@lru_cache(maxsize=None)
def _reference(kind: str):
    ureg = registry()
    return ureg.Quantity(1.0, KINDS[kind][0])


def parse_quantity(value, kind: str) -> float:
    """Return ``value`` converted to the SI unit of ``kind``.

    Raises ``ValueError`` with a message that says what was expected.
    """
    si_unit, example = KINDS[kind]
    if isinstance(value, bool):
        raise ValueError(f"expected {_label(kind)} such as '{example}', got {value!r}")
    if isinstance(value, (int, float)):
        x = float(value)
    elif isinstance(value, str):
        x = _parse_string(value, kind)
    else:
        raise ValueError(
            f"expected {_label(kind)} such as '{example}' (a number is read in {si_unit}), "
            f"got {value!r}"
        )
    if not math.isfinite(x):
        raise ValueError(f"expected a finite {_label(kind)[2:].strip()}, got {value!r}")
    return x


def _parse_string(text: str, kind: str) -> float:
    ureg = registry()
    si_unit, example = KINDS[kind]
    try:
        q = ureg.Quantity(text.strip())
    except Exception:
        raise ValueError(
            f"cannot read {text!r} as {_label(kind)}; write a number and a unit, e.g. '{example}'"
        ) from None
    ref = _reference(kind)
    if not isinstance(q, pint.Quantity):  # a bare number in a string
        return float(q)
    if q.dimensionality != ref.dimensionality:
        raise ValueError(
            f"{text!r} is not {_label(kind)} (its dimension is {_dimension_text(q)}); "
            f"write it in {si_unit} or a compatible unit, e.g. '{example}'"
        )
    if kind == "angle" and not (q.unitless or _is_angle_unit(q)):
        raise ValueError(f"{text!r} is not an angle; write e.g. '{example}'")
    return float(q.to(si_unit).magnitude)


def _is_angle_unit(q) -> bool:
    try:
        q.to("rad")
        return True
    except Exception:
        return False


def _dimension_text(q) -> str:
    dim = str(q.dimensionality)
    return "dimensionless" if dim == "dimensionless" else dim


def _label(kind: str) -> str:
    """'angle' -> 'an angle', 'torque' -> 'a torque' (for messages)."""
    word = kind.replace("_", " ")
    return ("an " if word[0] in "aeiou" else "a ") + word


def format_quantity(value: float, unit: str, digits: int = 6) -> str:
    """Format an SI value in ``unit`` for display, e.g. ``format_quantity(1e9, 'N/mm')``."""
    ureg = registry()
    q = ureg.Quantity(value, _si_of(unit)).to(unit)
    return f"{q.magnitude:.{digits}g} {unit}"


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert a float between two units (used for display and reports)."""
    return float(registry().Quantity(value, from_unit).to(to_unit).magnitude)


def _si_of(unit: str) -> str:
    ureg = registry()
    return str(ureg.Quantity(1.0, unit).to_base_units().units)
