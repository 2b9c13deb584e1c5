"""US customary spellings in model files (an industrial reviewer's 3-path mill drive in
inches, lbf and hp): what engineers write is read, exactly; the pound-mass where a force
is meant is refused with the remedy, never guessed."""

from __future__ import annotations

import math
import tomllib

import pytest

import torquesplit as ts
from torquesplit.errors import ModelError
from torquesplit.model.units import parse_module, parse_quantity
from tests.model_texts import SPUR_PAIR

INCH, LBF = 0.0254, 4.4482216152605
LBF_IN = LBF * INCH


@pytest.mark.parametrize("text, kind, si", [
    ("105924 lbf-in", "torque", 105924 * LBF_IN),
    ("8827 ft-lbf", "torque", 8827 * 12 * LBF_IN),
    ("1 N-m", "torque", 1.0),
    ("2500 lb-ft^2", "inertia", 2500 * 0.45359237 * 0.3048 ** 2),
    ("2500 lbm ft^2", "inertia", 2500 * 0.45359237 * 0.3048 ** 2),
    ("2000 HP", "power", 2000 * 550 * 12 * LBF_IN),
    ("2000 bhp", "power", 2000 * 550 * 12 * LBF_IN),
    ("1190 RPM", "speed", 1190 * math.pi / 30),
    ("1190 rev/min", "speed", 1190 * math.pi / 30),
    ("1190 r/min", "speed", 1190 * math.pi / 30),
    ("12 mil", "length", 0.012 * INCH),
    ("3 mils", "length", 0.003 * INCH),
    ('0.012"', "length", 0.012 * INCH),
    ("8e6 lbf/in", "stiffness", 8e6 * LBF / INCH),
    ("1e-6 m", "length", 1e-6),  # (a hyphen after a digit is the exponent's sign)
    ("2 mrad", "angle", 2e-3),
])
def test_us_spellings_are_read_exactly(text, kind, si):
    assert parse_quantity(text, kind) == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize("text, kind", [("8827 lb-ft", "torque"), ("8e6 lb/in", "stiffness"),
                                        ("100 lbs", "force")])
def test_the_pound_mass_where_a_force_is_meant_is_refused_with_the_remedy(text, kind):
    with pytest.raises(ValueError, match="lb is the pound-mass: a force is written lbf"):
        parse_quantity(text, kind)


def test_a_module_may_be_given_as_a_diametral_pitch():
    assert parse_module("12.7 1/in") == pytest.approx(0.002, rel=1e-12)
    assert parse_module("4/in") == pytest.approx(6.35e-3, rel=1e-12)
    assert parse_module("3 mm") == 0.003
    with pytest.raises(ValueError, match="or give the normal diametral pitch"):
        parse_module("4 kg")
    with pytest.raises(ValueError, match="must be positive"):
        parse_module("-4 1/in")
    m = ts.load_model(tomllib.loads(SPUR_PAIR.replace('module = "2 mm"', 'module = "12.7 1/in"')))
    assert m.gears["pinion"].module == pytest.approx(0.002, rel=1e-12)
    with pytest.raises(ModelError, match=r"gears\.pinion\.diametral_pitch: unknown field; "
                       r"give the normal diametral pitch as module = '4 1/in'"):
        ts.load_model(tomllib.loads(SPUR_PAIR.replace('module = "2 mm"',
                                                      'diametral_pitch = "12.7 1/in"', 1)))



def test_a_hyphen_chain_is_one_factor_and_the_lbf_hint_only_where_it_fixes():
    """'lb/ft-s' (a viscosity) read lb s/ft, and was told to write lbf (a code review)."""
    assert parse_quantity("1 lb/ft-s", "viscosity") == pytest.approx(
        0.45359237 / 0.3048, rel=1e-12)
    with pytest.raises(ValueError) as exc:
        parse_quantity("1 lb/ft-s", "pressure")
    assert "lbf" not in str(exc.value)


def test_newton_metres_written_nm_are_a_torque():
    """'200 Nm' and '0.2 kNm' (a torque's usual spelling) were refused as 'neither a force
    nor a torque': pint reads Nm as nanometres."""
    from torquesplit.model.units import parse_quantity

    assert parse_quantity("200 Nm", "torque") == pytest.approx(200.0)
    assert parse_quantity("0.2 kNm", "torque") == pytest.approx(200.0)
    assert parse_quantity("1.5 MNm", "torque") == pytest.approx(1.5e6)
    assert parse_quantity("5 nm", "length") == pytest.approx(5e-9)  # (a length stays one)
