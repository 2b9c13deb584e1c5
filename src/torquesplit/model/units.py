"""Units at the edge: parse quantities written in model files and on the command line.

Inside torquesplit every number is SI float64.  This module is the only place that
knows about pint.  A field declares its *kind* (``"length"``, ``"stiffness"``...);
a value may be written as a string with units (``"0.85e6 N/mm"``), or as a bare
number, which is read in the kind's SI unit (given in :data:`KINDS`).

What reaches pint is guarded: a string longer than :data:`MAX_QUANTITY_CHARS` is
refused before pint's preprocessing (its time grows with the square of the length), a
unit without a number (``"mm"``, which pint reads as 1 mm) is refused, booleans are
not numbers, and messages quote at most ~80 characters of a value.

Speeds and frequencies: pint reads Hz as 1/s and the radian as dimensionless, so both
have the dimension 1/[time] and a plain conversion would read "50 Hz" as 50 rad/s.  Here
a rate without an angle (Hz, 1/s, kHz, 1/min) counts revolutions: a speed given as
"50 Hz" is 3000 rpm (2 pi x 50 rad/s), and a frequency given as "12000 rpm" or in rad/s
is 200 Hz (see :func:`_rotation`).
"""

from __future__ import annotations

import math
import numbers
import re
from functools import lru_cache

import pint

from ..errors import QUOTE_LIMIT

#: longest quantity string handed to pint; "0.85e6 N/mm" is 11 characters
MAX_QUANTITY_CHARS = 100

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
    "diametral_pitch": ("1/m", "4 1/in"),
}


def parse_module(value) -> float:
    """A normal module [m], or a normal diametral pitch P (teeth per length: '4 1/in',
    '4/in') read as the module 1/P (25.4 mm / 4 = 6.35 mm), as US drawings give it."""
    try:
        return parse_quantity(value, "length")
    except ValueError as exc:
        if not isinstance(value, str) or "is not a length" not in str(exc):
            raise
        try:
            pitch = parse_quantity(value, "diametral_pitch")
        except ValueError:
            raise ValueError(f"{exc}; or give the normal diametral pitch as teeth per "
                             f"length, e.g. '4 1/in' (the module 25.4 mm / 4)") from None
        if not pitch > 0:
            raise ValueError(f"{_short(value)}: a diametral pitch must be positive, e.g. "
                             f"'4 1/in'") from None
        return 1.0 / pitch


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The one pint registry of torquesplit (created on first use), with the spellings a
    gearbox engineer in US units writes: lbm, HP and bhp (the mechanical horsepower),
    RPM and rev (and :func:`_spellings` reads the mil as a thousandth of an inch)."""
    ureg = pint.UnitRegistry()
    ureg.define("@alias pound = lbm")
    ureg.define("@alias horsepower = HP = bhp")
    ureg.define("@alias revolutions_per_minute = RPM")
    ureg.define("@alias revolution = rev")
    return ureg


#: a hyphen between two unit names is a product, as engineers write it ('8827 lb-ft',
#: 'lbf-in', 'N-m'); pint read it as a minus sign.  The chain is one factor, its own
#: powers inside it: 'lb/ft-s' is lb/(ft s), 'lb-ft^2' is lb ft^2
_UNIT = r"[A-Za-z_]+(?:(?:\^|\*\*)\d+)?"
_HYPHEN = re.compile(rf"(?<![\w.]){_UNIT}(?:-{_UNIT})+")
#: the inch mark after a number ('0.012"'), revolutions per minute as ISO writes them
_INCH_MARK = re.compile(r'(?<=[\d.\s])"')
_R_PER = re.compile(r"\br/(min|s)\b")
#: the mil of US drawings, a thousandth of an inch (pint's mil is the angular mil: a
#: backlash of '12 mil' was 'not a length')
_MIL = re.compile(r"\bmils?\b")


def _spellings(text: str) -> str:
    """``text`` with the engineering spellings pint does not read made explicit."""
    text = _HYPHEN.sub(lambda m: "(" + m.group().replace("-", "*") + ")", text)
    text = _INCH_MARK.sub(" inch", text)
    text = _MIL.sub("thou", text)
    return _R_PER.sub(r"rev/\1", text)


@lru_cache(maxsize=None)
def _reference(kind: str):
    ureg = registry()
    return ureg.Quantity(1.0, KINDS[kind][0])


def parse_quantity(value, kind: str) -> float:
    """Return ``value`` converted to the SI unit of ``kind``.

    Raises ``ValueError`` with a message that says what was expected.
    """
    si_unit, example = KINDS[kind]
    hint = f"write {_label(kind)} such as '{example}' (a bare number is read in {si_unit})"
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, str)):
        raise ValueError(f"got {_short(value)}; {hint}")
    if isinstance(value, str):
        if len(value) > MAX_QUANTITY_CHARS:
            raise ValueError(
                f"is {len(value)} characters long ({_short(value)}); a quantity is a number "
                f"and a unit of at most {MAX_QUANTITY_CHARS} characters: {hint}")
        x = _parse_string(value, kind)
    else:
        try:
            x = float(value)
        except OverflowError:
            x = math.inf
    if not math.isfinite(x):
        raise ValueError(f"got {_short(value)}, which is not a finite number; {hint}")
    return x


#: a number literal; pint evaluates integer literals exactly, so that "10**10**10 mm"
#: would not finish: they are read as floats instead (see _floats)
_NUMBER = re.compile(r"(?<![\w.])(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def _floats(text: str) -> str:
    """``text`` with every integer literal written as a float ("10**3" -> "10.0**3.0")."""
    return _NUMBER.sub(lambda m: m.group() + ".0" if m.group().isdigit() else m.group(), text)


#: a quantity string must contain a number: a digit, or inf/nan (refused later as not
#: finite); pint reads a bare unit such as "mm" as 1 mm
_HAS_NUMBER = re.compile(r"\d|\b(inf|infinity|nan|pi)\b", re.IGNORECASE)


#: 'Nm', 'kNm', 'MNm' where a torque is expected: newton metres, not nanometres
_NEWTON_METRE = re.compile(r"(?<![A-Za-z])([kM]?)Nm(?![A-Za-z])")


@lru_cache(maxsize=8192)
def _parse_string(text: str, kind: str) -> float:
    """``text`` in the SI unit of ``kind`` (ValueError saying what was expected).  Cached:
    a study's cases, a sweep's points and repeated fields ('20 mm') parse each string
    once per process (pint takes about 0.4 ms a string)."""
    ureg = registry()
    si_unit, example = KINDS[kind]
    if kind == "torque":  # 'Nm', 'kNm' (a torque's usual spelling; pint: nanometres)
        text = _NEWTON_METRE.sub(r"\1N*m", text)
    try:
        q = ureg.Quantity(_floats(_spellings(text.strip())))
        if not isinstance(q, pint.Quantity):  # pragma: no cover - older pint: a bare number
            q = ureg.Quantity(float(q))
    except Exception:
        raise ValueError(
            f"cannot read {_short(text)} as {_label(kind)}; write a number and a unit, "
            f"e.g. '{example}'"
        ) from None
    if not _HAS_NUMBER.search(text):
        raise ValueError(
            f"{_short(text)} has no number (pint would read a unit alone as 1 of it); write "
            f"the value and the unit, e.g. '{example}'")
    ref = _reference(kind)
    if q.dimensionality != ref.dimensionality:
        if _is_number(text):  # (text is at most MAX_QUANTITY_CHARS long)
            n = text.strip()
            fix = (f"add its unit: '{n} mm', '{n} um' or '{n} m'" if kind == "length"
                   else f"add the unit, e.g. '{n} {example.split(' ', 1)[1]}'")
        else:
            fix = f"write it in {si_unit} or a compatible unit, e.g. '{example}'"
            if _POUND.search(text) and _as_force(text, ref):
                fix += ("; lb is the pound-mass: a force is written lbf (e.g. '8e6 lbf/in', "
                        "'8827 lbf ft')")
        raise ValueError(
            f"{_short(text)} is not {_label(kind)} ({_dimension_text(q)}); "
            f"{fix}"
        )
    if kind == "angle" and not (q.unitless or _is_angle_unit(q)):
        raise ValueError(f"{_short(text)} is not an angle; write e.g. '{example}'")
    if kind in _TURNS:
        return _rotation(q, kind, text)
    try:
        magnitude = q.to(si_unit).magnitude
        return float(magnitude) if isinstance(magnitude, (int, float)) else math.nan
    except (ArithmeticError, TypeError, ValueError):
        return math.nan


_POUND = re.compile(r"\blbs?\b")


def _as_force(text: str, ref) -> bool:
    """Whether ``text`` with its pounds read as pounds-force has the dimension wanted
    (the hint 'write lbf' only where lbf is the fix: not for a viscosity in lb/ft-s)."""
    try:
        q = registry().Quantity(_floats(_spellings(_POUND.sub("lbf", text.strip()))))
    except Exception:  # noqa: BLE001 - pint raises many kinds: no hint then
        return False
    return q.dimensionality == ref.dimensionality

#: kinds measured per unit time whose SI unit holds a power of the radian: a speed
#: (rad/s) holds one, a frequency (Hz, revolutions or cycles per second) none
_TURNS = {"speed": 1, "frequency": 0}

_PI = re.compile(r"\bpi\b", re.IGNORECASE)


def _angle_power(q) -> float:
    """Power of the radian in ``q``'s units: 1 for rpm, rad/s, deg/s; 0 for Hz, 1/s."""
    return dict(q.to_root_units().unit_items()).get("radian", 0)


def _rotation(q, kind: str, text: str) -> float:
    """``q`` (of dimension 1/[time]) as a speed [rad/s] or a frequency [Hz]: a rate
    without an angle counts revolutions (50 Hz = 3000 rpm), so that Hz, rpm and rad/s
    mean the same rotation whatever the field.  Refuses what cannot be read one way."""
    si_unit, example = KINDS[kind]
    have, want = _angle_power(q), _TURNS[kind]
    if have == 0 and want == 1 and _PI.search(text):
        raise ValueError(
            f"{_short(text)} is ambiguous: a rate with pi but no angle unit may mean rad/s or "
            f"revolutions per second; write the angle unit (e.g. '100 pi rad/s') or "
            f"revolutions (e.g. '50 Hz', '{example}')")
    if have not in (0, 1):
        raise ValueError(
            f"{_short(text)} has the angle unit to the power {have:g}; write {_label(kind)} "
            f"such as '{example}' (rpm, rad/s, deg/s; Hz counts revolutions)")
    try:
        if have == want:
            magnitude = q.to(si_unit).magnitude
        elif want == 1:  # revolutions per unit time -> rad/s
            magnitude = q.to("1/s").magnitude * (2 * math.pi)
        else:  # an angular speed -> revolutions per second
            magnitude = q.to("rad/s").magnitude / (2 * math.pi)
        return float(magnitude) if isinstance(magnitude, (int, float)) else math.nan
    except (ArithmeticError, TypeError, ValueError):
        return math.nan


def _is_number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def _is_angle_unit(q) -> bool:
    try:
        q.to("rad")
        return True
    except Exception:
        return False


def _dimension_text(q) -> str:
    """What a quantity of the wrong kind is: the kinds it could be (``a force``), and its
    dimension (``[mass] * [length] / [time] ** 2``)."""
    dim = str(q.dimensionality)
    if dim == "dimensionless":
        return "it is dimensionless"
    kinds = [k for k in KINDS if _reference(k).dimensionality == q.dimensionality]
    named = f"{' or '.join(_label(k) for k in kinds)}, of " if kinds else "of "
    return f"it is {named}dimension {dim}"


def _short(value, limit: int = QUOTE_LIMIT) -> str:
    """repr of a value for a message, shortened to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _label(kind: str) -> str:
    """'angle' -> 'an angle', 'torque' -> 'a torque' (for messages)."""
    word = kind.replace("_", " ")
    return ("an " if word[0] in "aeiou" else "a ") + word


def format_quantity(value: float, unit: str, digits: int = 6) -> str:
    """Format an SI value in ``unit`` for display, e.g. ``format_quantity(1e9, 'N/mm')``."""
    return f"{convert(value, _si_of(unit), unit):.{digits}g} {unit}"


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert a float between two units (used for display and reports).  Between a
    speed and a frequency a rate without an angle counts revolutions, as when parsing:
    ``convert(2 * pi * 50, 'rad/s', 'Hz') == 50``, ``convert(200, 'Hz', 'rpm') == 12000``."""
    ureg = registry()
    q = ureg.Quantity(value, from_unit)
    target = ureg.Quantity(1.0, to_unit)
    if q.dimensionality == target.dimensionality == ureg.Quantity(1.0, "Hz").dimensionality:
        have, want = _angle_power(q), _angle_power(target)
        if {have, want} == {0, 1}:
            q = q.to("1/s") * 2 * math.pi * ureg.rad if want == 1 else q.to("rad/s") / (
                2 * math.pi * ureg.rad)
    return float(q.to(to_unit).magnitude)


def _si_of(unit: str) -> str:
    ureg = registry()
    return str(ureg.Quantity(1.0, unit).to_base_units().units)


def rad_s_text(value: float) -> str:
    """A speed given as a bare number (rad/s) with its rpm: ``'2400 rad/s = 22918.3 rpm'``
    (what a warning about a bare speed quotes)."""
    return f"{value:g} rad/s = {value * 30.0 / math.pi:.6g} rpm"
