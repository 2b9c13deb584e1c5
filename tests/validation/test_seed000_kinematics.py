"""Seed 000 example (two-input split-torque helicopter reducer): nominal kinematics
against the numbers printed in the paper.

Liu, Fang, Jia, Zhao, Shen, Guo, Zhang, "Investigation of Load Sharing and Dynamic
Load Characteristics of a Split Torque Transmission System with Double-Helical Gear
Modification", Shock and Vibration 2021.  Acceptance values: issue 2.
"""

from __future__ import annotations

import math

import pytest

import torquesplit

RPM = 2 * math.pi / 60  # rad/s per rpm


@pytest.fixture(scope="module")
def model():
    return torquesplit.load_model(torquesplit.example_path("liu2021_split_torque_helicopter"))


@pytest.fixture(scope="module")
def kin(model):
    return torquesplit.solve_kinematics(model)


def test_ten_meshes_labelled(model):
    # Sec. 2.1: per side one bevel (12), two spur split (34, 35) and two DH meshes (68, 78)
    assert len(model.meshes) == 10
    stages = {"12": "bevel", "34": "spur_split", "35": "spur_split",
              "68": "dh_combine", "78": "dh_combine"}
    for side, path in (("L", "left"), ("R", "right")):
        for pair, stage in stages.items():
            mesh = model.meshes[f"{side}{pair}"]
            assert mesh.stage == stage
            assert mesh.path == path


def test_dof_count_matches_eq_11(model):
    # eq. 11: 49 DOF -- bevel gears x, y, z, theta; the other 14 + 1 gears x, y, theta.
    # No rigid shafts, so every gear keeps its own rotation.  Exact count.
    assert not any(s.rigid for s in model.shafts.values())
    assert sum(len(g.dofs) for g in model.gears.values()) + sum(
        len(b.dofs) for b in model.bodies.values()) == 49


@pytest.mark.parametrize("side", ["L", "R"])
def test_stage_speeds(kin, side):
    # Table 1 "Input speed (r/min)": 20900 (bevel pinion), 7626 (spur pinion), 2423 (DH
    # pinion).  The last two are printed rounded to 1 rpm (exact: 7625.68, 2423.11), hence
    # +/- 1 rpm (issue 2).
    b = kin.bodies
    assert abs(b[f"{side}1"].speed) / RPM == pytest.approx(20900, abs=1e-6)
    assert abs(b[f"{side}3"].speed) / RPM == pytest.approx(7626, abs=1)
    assert abs(b[f"{side}2"].speed) / RPM == pytest.approx(7626, abs=1)
    for g in "4567":
        assert abs(b[f"{side}{g}"].speed) / RPM == pytest.approx(2423, abs=1)


def test_both_spur_pinions_turn_the_same_way(kin):
    # Not printed, but forced by the topology (both sides drive the one gear z_8): z_L3
    # and z_R3 turn like z_8 (3 -> 4 reverses, 6 -> 8 reverses again).
    b = kin.bodies
    assert b["L3"].speed * b["R3"].speed > 0
    assert b["L3"].speed * b["G8"].speed > 0


@pytest.mark.parametrize("mesh", ["L68", "L78", "R68", "R78"])
def test_double_helical_contact_ratio(kin, mesh):
    # Sec. 5.2: "the theoretical contact ratio of DH gear pair is 3.42" (printed to 2
    # decimals; we get 1.4145 + 2.0070 = 3.4215), tolerance +/- 0.01 (issue 2).
    assert kin.meshes[mesh].total_contact_ratio == pytest.approx(3.42, abs=0.01)


@pytest.mark.parametrize("mesh", ["L68", "L78", "R68", "R78"])
def test_design_load_on_output_gear(kin, mesh):
    # Sec. 5.2: "the design load of DH gear pair is equal to 17500 Nm" -- the torque one
    # DH pinion puts on z_8 (475 kW at 259.22 rpm = 17498.6 N m).  The paper rounds to
    # 3 significant figures, hence +/- 0.1 % (issue 2).
    mk = kin.meshes[mesh]
    assert mk.driven == "G8"
    assert mk.torque_driven == pytest.approx(17500, rel=1e-3)


@pytest.mark.parametrize("side", ["L", "R"])
def test_stage_powers(kin, side):
    # Table 1 "Input power (KW)": 950 (bevel pinion), 950 (spur pinion), 475 (each DH
    # pinion): an equal split, lossless; exact to rounding.
    b = kin.bodies
    assert b[f"{side}1"].power == pytest.approx(950e3, rel=1e-9)
    assert b[f"{side}3"].power == pytest.approx(950e3, rel=1e-9)
    for g in "67":
        assert b[f"{side}{g}"].power == pytest.approx(475e3, rel=1e-9)
    assert kin.meshes[f"{side}68"].power == pytest.approx(475e3, rel=1e-9)
