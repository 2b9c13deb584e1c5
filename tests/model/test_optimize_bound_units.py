"""Optimisation bounds are read like the model file: a speed in Hz counts revolutions."""

from __future__ import annotations

import math

import pytest

from torquesplit.errors import ModelError
from torquesplit.optimize import read_spec


def _spec(lower, upper, path="drives.motor.speed"):
    return {"optimization": {"model": "ji_li_mill_drive", "population": 4, "generations": 1},
            "variables": [{"path": path, "lower": lower, "upper": upper}],
            "objectives": [{"output": "dynamic.stage1.dynamic_factor"}]}


def test_a_speed_bound_in_hz_counts_revolutions():
    var = read_spec(_spec("50 Hz", "3600 rpm")).variables[0]
    assert var.lower == pytest.approx(2 * math.pi * 50)   # 3000 rpm, not 50 rad/s
    assert var.upper == pytest.approx(2 * math.pi * 60)
    assert read_spec(_spec(50, 60)).variables[0].lower == 50.0   # bare numbers: rad/s


def test_a_bound_of_the_wrong_kind_is_refused_by_field():
    with pytest.raises(ModelError) as info:
        read_spec(_spec("5 mm", "3600 rpm"))
    (loc, msg), = info.value.issues
    assert loc == "variables[0].lower" and "speed" in msg
