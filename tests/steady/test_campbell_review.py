"""Campbell diagram of a turning carrier after a modal review: shaft orders in the
carrier's frame, whirl-selective mesh phasing and a readable figure."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

import torquesplit
from torquesplit import example_path, load_model
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.steady.maps import campbell

RPM = math.pi / 30


def _lp_with_eccentricities():
    raw = copy.deepcopy(torquesplit.model.io.read_file(example_path("lin_parker1999_planetary")))
    for member in ("sun", "planet"):
        raw["planetary"][0][member]["errors"] = {"eccentricity": "10 um"}
    return load_model(raw)


def test_shaft_order_lines_are_the_speeds_relative_to_a_turning_carrier():
    """The eccentricities of sun and planets are applied at their speeds relative to the
    carrier, where the natural frequencies are computed; the lines were drawn at the
    absolute speeds (16.7 and 7.3 Hz for 12.8 and 11.2 Hz at 1000 rpm)."""
    from torquesplit.assembly import excitation

    model = _lp_with_eccentricities()
    kin = solve_kinematics(model)
    ds, _ = campbell(model, 1000 * RPM, 1100 * RPM, points=2)
    lines = {str(k): float(f) for k, f in zip(ds["line"].values,
                                                ds["excitation_frequency"].values[0])}
    sp = {b: kin.bodies[b].speed for b in ("stage_sun", "stage_planet1", "stage_carrier")}
    sun = "1 x rotation of stage_sun relative to stage_carrier"
    planet = "1 x rotation of stage_planet1 relative to stage_carrier"
    assert lines[sun] == pytest.approx(abs(sp["stage_sun"] - sp["stage_carrier"]) / 2 / math.pi)
    assert lines[planet] == pytest.approx(
        abs(sp["stage_planet1"] - sp["stage_carrier"]) / 2 / math.pi)
    _, sines = excitation.mesh_errors(model, kin, "stage_sun_planet1")
    applied = sorted({round(om / 2 / math.pi, 6) for _, om, _ in sines})
    assert applied == pytest.approx(sorted([lines[sun], lines[planet]]), rel=1e-6)
    assert not [k for k in lines if "rotation of stage_carrier" in k]  # still in its frame


def test_a_fixed_axis_train_keeps_its_absolute_shaft_orders():
    model = load_model(example_path("ji_li_mill_drive"))
    kin = solve_kinematics(model)
    ds, _ = campbell(model, 200 * RPM, 300 * RPM, points=2)
    w = ds["speed"].values[0] / torquesplit.steady.maps.reference_speed(model)
    for name, f in zip(ds["line"].values, ds["excitation_frequency"].values[0]):
        if "rotation of" in str(name):
            assert "relative" not in str(name)
            body = str(name).split("rotation of ")[1]
            assert f == pytest.approx(abs(kin.bodies[body].speed) * w / 2 / math.pi)
