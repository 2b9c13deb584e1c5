"""Seed 003 example (double-input split-torque drive, herringbone confluence stage,
tooth friction): nominal kinematics and layout against what the paper prints.

Jin, Yang, Lu, Zhu, "Effect of Friction on Dynamic Response of A Power Split
Transmission System", Trans. Nanjing Univ. Aeronautics & Astronautics 36(3), 2019.
The paper prints no numerical results (all are figures); the checks are Table 2 and
eq. 4.  Issue 2 sets no acceptance numbers for this seed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import torquesplit

RPM = 2 * math.pi / 60  # rad/s per rpm
BRANCHES = ("R", "L")


@pytest.fixture(scope="module")
def model():
    return torquesplit.load_model(torquesplit.example_path("jin2019_friction_split"))


@pytest.fixture(scope="module")
def kin(model):
    return torquesplit.solve_kinematics(model)


def _angle_deg(kin, apex, a, b):
    """Angle at body ``apex`` between the centre lines to bodies ``a`` and ``b``."""
    p = kin.bodies[apex].position
    u = kin.bodies[a].position - p
    v = kin.bodies[b].position - p
    return math.degrees(math.acos(float(u @ v) / float(np.linalg.norm(u) * np.linalg.norm(v))))


def test_friction_on_split_and_confluence_meshes_only(model):
    # eq. 5 and Sec. 3: friction f = mu F in the split (spur) and confluence
    # (herringbone) meshes; the input stage has no friction term.
    assert len(model.meshes) == 10
    for i, path in (("R", "right"), ("L", "left")):
        assert not model.meshes[f"{i}mn"].friction
        for name in (f"{i}p1s", f"{i}p2s", f"{i}B1h", f"{i}B2h"):
            assert model.meshes[name].friction, name
            assert model.meshes[name].path == path
        assert model.gears[f"{i}p"].gear_type == "spur"
        assert model.gears[f"{i}1h"].gear_type == "double_helical"


def test_input_power_and_speed(kin):
    # Table 2: "Input power 2 000 kW", "Input speed 20 900 r/min" (input pinions Z_im);
    # exact, as they are model inputs (2000 kW read as the total of the two engines).
    assert kin.input_power == pytest.approx(2000e3, rel=1e-12)
    assert kin.output_power == pytest.approx(2000e3, rel=1e-12)
    for i in BRANCHES:
        assert abs(kin.bodies[f"{i}m"].speed) / RPM == pytest.approx(20900, rel=1e-12)


@pytest.mark.parametrize("i", BRANCHES)
def test_stage_gear_ratios(kin, i):
    # Table 2: "Gear ratio of power input, split torque and power confluence stage
    # 27/74, 31/98, 23/215"; exact up to rounding.
    w = {n: abs(b.speed) for n, b in kin.bodies.items()}
    assert w[f"{i}n"] / w[f"{i}m"] == pytest.approx(27 / 74, rel=1e-12)
    assert w[f"{i}1s"] / w[f"{i}p"] == pytest.approx(31 / 98, rel=1e-12)
    assert w[f"{i}2s"] / w[f"{i}p"] == pytest.approx(31 / 98, rel=1e-12)
    assert w["B"] / w[f"{i}1h"] == pytest.approx(23 / 215, rel=1e-12)
    # the total ratio (74/27)(98/31)(215/23) = 80.992 follows
    assert w[f"{i}m"] / w["B"] == pytest.approx(1559180 / 19251, rel=1e-12)


def test_installation_angle_theta_at_output(kin):
    # Table 2: theta = 150 deg, the angle at Z_B between the lines to Z_Lp and Z_Rp.
    # Placement angles are written to 1e-5 deg, hence 1e-4 deg.
    assert _angle_deg(kin, "B", "Lp", "Rp") == pytest.approx(150, abs=1e-4)


@pytest.mark.parametrize("i", BRANCHES)
def test_installation_angle_theta_p_at_split_pinion(kin, i):
    # Table 2: theta_p = 104 deg, the angle at Z_ip between Z_i1s and Z_i2s.
    assert _angle_deg(kin, f"{i}p", f"{i}1s", f"{i}2s") == pytest.approx(104, abs=1e-4)


@pytest.mark.xfail(strict=True, reason=(
    "Table 2 prints theta_j = 108 deg, but with standard centre distances the kite "
    "Z_ip-Z_ij-Z_B is fixed by one angle: theta_p = 104 deg (kept) gives theta_j = "
    "109.116 deg; see the example's header"))
@pytest.mark.parametrize("i", BRANCHES)
def test_installation_angle_theta_j_at_duplicate_shaft(kin, i):
    # Table 2: theta_j = 108 deg at each duplicate shaft between Z_ip and Z_B.
    assert _angle_deg(kin, f"{i}1s", f"{i}p", "B") == pytest.approx(108, abs=0.01)


@pytest.mark.parametrize("i", BRANCHES)
def test_theta_j_is_the_consistent_value(kin, i):
    # The value that the kept angles and the standard centre distances give (derived,
    # not printed): 109.116 deg; both duplicate shafts alike (symmetric kite).
    assert _angle_deg(kin, f"{i}1s", f"{i}p", "B") == pytest.approx(109.1158, abs=1e-3)
    assert _angle_deg(kin, f"{i}2s", f"{i}p", "B") == pytest.approx(109.1158, abs=1e-3)


@pytest.mark.parametrize("i", BRANCHES)
def test_input_mesh_direction_cosines_eq_4(kin, i):
    # eq. 4 with the cone angle delta = 0 (parallel-axis helical input stage),
    # alpha_n = 20 deg, beta = 30 deg (Table 2): radial P_X = sin(alpha_n) = 0.34202,
    # tangential P_Y = cos(beta) cos(alpha_n) = 0.81380, axial P_Z = sin(beta)
    # cos(alpha_n) = 0.46985 (signs depend on hand and rotation, not given).
    mk = kin.meshes[f"{i}mn"]
    n = mk.line_of_action
    pm, pn = kin.bodies[f"{i}m"].position, kin.bodies[f"{i}n"].position
    axis = kin.bodies[f"{i}m"].axis
    e_r = (pn - pm) / np.linalg.norm(pn - pm)
    e_t = np.cross(axis, e_r)
    an, beta = math.radians(20), math.radians(30)
    assert abs(float(n @ e_r)) == pytest.approx(math.sin(an), abs=1e-9)
    assert abs(float(n @ e_t)) == pytest.approx(math.cos(beta) * math.cos(an), abs=1e-9)
    assert abs(float(n @ axis)) == pytest.approx(math.sin(beta) * math.cos(an), abs=1e-9)
