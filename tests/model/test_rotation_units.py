"""Speeds and frequencies at the edge: a rate without an angle (Hz, 1/s, rps, kHz) counts
revolutions, so that '50 Hz', '3000 rpm' and '314.159 rad/s' are one speed and
'12000 rpm' is a frequency of 200 Hz (pint alone reads Hz as rad/s: a 2 pi slip)."""

from __future__ import annotations

import json
import math
import warnings

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.cli_support import quantity
from torquesplit.errors import ModelWarning, OptionError
from torquesplit.model.io import read_file
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.model.overrides import apply_overrides
from torquesplit.model.units import convert, format_quantity, parse_quantity

W50 = 2 * math.pi * 50  # 3000 rpm in rad/s


@pytest.mark.parametrize("text", ["50 Hz", "3000 rpm", "314.159265358979 rad/s", "0.05 kHz",
                                  "50 rps", "50 1/s", "18000 deg/s", "3000 1/min",
                                  "50 revolution/second"])
def test_every_way_of_writing_3000_rpm_is_the_same_speed(text):
    assert parse_quantity(text, "speed") == pytest.approx(W50, rel=1e-12)


@pytest.mark.parametrize("text,hz", [("12000 rpm", 200.0), ("200 Hz", 200.0),
                                     ("0.2 kHz", 200.0), ("1256.6370614359173 rad/s", 200.0),
                                     ("72000 deg/s", 200.0), ("200 1/s", 200.0)])
def test_a_frequency_given_as_an_angular_speed_counts_revolutions(text, hz):
    assert parse_quantity(text, "frequency") == pytest.approx(hz, rel=1e-12)


def test_bare_numbers_stay_si():
    assert parse_quantity(314.0, "speed") == 314.0
    assert parse_quantity(200, "frequency") == 200.0
    assert quantity("314", "speed", "--speed") == 314.0


def test_options_read_speeds_and_frequencies_the_same_way():
    assert quantity("50 Hz", "speed", "--speed") == pytest.approx(W50)
    assert quantity("12000 rpm", "frequency", "--below") == pytest.approx(200.0)


@pytest.mark.parametrize("text", ["100 pi/s", "5 sr/s"])
def test_an_ambiguous_rate_is_refused_in_one_line(text):
    with pytest.raises(ValueError) as err:
        parse_quantity(text, "speed")
    msg = str(err.value)
    assert "\n" not in msg and "write" in msg and text in msg
    with pytest.raises(OptionError, match="^--speed: "):
        quantity(text, "speed", "--speed")


def test_a_unit_of_another_dimension_is_still_refused():
    with pytest.raises(ValueError, match="is not a speed"):
        parse_quantity("50 m", "speed")
    with pytest.raises(ValueError, match="add the unit"):
        parse_quantity("3000", "speed")


def test_display_conversions_agree_with_parsing():
    assert convert(W50, "rad/s", "Hz") == pytest.approx(50.0)
    assert convert(W50, "rad/s", "rpm") == pytest.approx(3000.0)
    assert convert(200.0, "Hz", "rpm") == pytest.approx(12000.0)
    assert convert(50.0, "Hz", "kHz") == pytest.approx(0.05)
    assert format_quantity(W50, "rpm") == "3000 rpm"
    assert format_quantity(50.0, "kHz") == "0.05 kHz"


def test_a_drive_speed_of_50_hz_is_3000_rpm_through_set():
    path = torquesplit.example_path("ji_li_mill_drive")
    data = apply_overrides(read_file(path), {"drives.motor.speed": "50 Hz"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        model = torquesplit.load_model(data)
    assert model.drives["motor"].speed == pytest.approx(W50)
    rpm = solve_kinematics(model).bodies["motor"].speed * 30 / math.pi
    assert rpm == pytest.approx(3000.0)


def test_check_set_50_hz_shows_3000_rpm():
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive", "--json", "--set",
                                   "drives.motor.speed='50 Hz'"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["bodies"]["motor"]["speed_rpm"] == pytest.approx(3000.0)


def test_a_speed_in_rpm_written_as_a_bare_number_is_flagged():
    path = torquesplit.example_path("ji_li_mill_drive")
    data = apply_overrides(read_file(path), {"drives.motor.speed": 3000})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        torquesplit.load_model(data)
    texts = [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]
    assert any("pitch-line speed" in t and "a bare number is read in rad/s" in t for t in texts)


def test_a_unit_of_another_kind_is_named_by_that_kind():
    """'50 N' for a length said '[mass] * [length] / [time] ** 2': it is a force."""
    from torquesplit.model.units import parse_quantity

    with pytest.raises(ValueError, match=r"is not a length \(it is a force, of dimension "):
        parse_quantity("50 N", "length")
    with pytest.raises(ValueError, match=r"it is of dimension \[length\] / \[time\]\)"):
        parse_quantity("3 m/s", "inertia")
