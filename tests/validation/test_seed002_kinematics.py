"""Seed 002 example (face-gear dual-power split helicopter drive): nominal kinematics
against the numbers of the paper.

Dong, Zhang, Zhao, Duan, "Study on dynamic load-sharing characteristics of face gear
dual-power split transmission system with backlash, support and spline clearance",
Mechanical Sciences 12, 2021.  Acceptance values: issue 2 (input torque 2175.24 N m;
nominal torque on each second-stage idler 7571.1 N m +/- 0.1 %).

The paper prints the operating point (Sec. 6: 2000 kW, 8780 rpm), the tooth counts
(Table 1) and, in Sec. 6.1, mean mesh torques with their DLSC Omega = mean torque /
nominal torque; the nominal torques themselves (T_in / 2 per face mesh, 7571.1 N m per
idler) follow from those.  Speeds and mesh frequencies are not printed; they are
checked against the exact tooth-count ratios.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import torquesplit
from torquesplit.assembly.assemble import number_dofs

RPM = 2 * math.pi / 60  # rad/s per rpm
N_IN = 8780.0  # Sec. 6: input speed [rpm]
P_IN = 2000e3  # Sec. 6: input power [W]
I12 = 190 / 29  # Table 1: face-gear stage ratio
I46 = 51 / 24  # Table 1: pinion-idler ratio
IDLER_MESHES = ("m610", "m710", "m810", "m910")


@pytest.fixture(scope="module")
def model():
    return torquesplit.load_model(torquesplit.example_path("dong2021_face_gear"))


@pytest.fixture(scope="module")
def kin(model):
    return torquesplit.solve_kinematics(model)


# --------------------------------------------------------------------- acceptance (issue 2)
def test_input_torque(kin):
    # Issue 2: 2175.24 N m = P / omega with P = 2000 kW, n = 8780 rpm (Sec. 6).  The issue
    # prints it to 0.01 N m (exact 2175.2367), hence +/- 0.005 N m.
    assert kin.drive_torques["engine"] == pytest.approx(2175.24, abs=0.005)
    assert kin.bodies["O1"].torque == pytest.approx(2175.24, abs=0.005)
    assert kin.bodies["engine"].torque == pytest.approx(2175.24, abs=0.005)


@pytest.mark.parametrize("idler", ["O6", "O7", "O8", "O9"])
def test_idler_nominal_torque(kin, idler):
    # Issue 2: 7571.1 N m +/- 0.1 % on each second-stage idler, = (T_in/2) i12 / 2 * i46,
    # the nominal torque of the eq. 12 stage-II DLSC (its denominator with the idler arm).
    assert kin.bodies[idler].torque == pytest.approx(7571.1, rel=1e-3)
    mesh = kin.meshes[f"m{idler[1:]}10"]
    assert mesh.driver == idler
    assert mesh.torque_driver == pytest.approx(7571.1, rel=1e-3)
    pinion_mesh = {"O6": "m46", "O7": "m47", "O8": "m58", "O9": "m59"}[idler]
    assert kin.meshes[pinion_mesh].torque_driven == pytest.approx(7571.1, rel=1e-3)


# --------------------------------------------------------------------- Sec. 6.1 consistency
@pytest.mark.parametrize("mesh, torque, omega", [
    ("m610", 6920.5, 0.914), ("m710", 8222.9, 1.086),
    ("m810", 7178.1, 0.948), ("m910", 7965.4, 1.052),
])
def test_stage2_published_torque_over_dlsc_is_our_nominal(kin, mesh, torque, omega):
    # Sec. 6.1 prints the mean torques T_610..T_910 (N m, 0.1 N m) and Omega_610..910
    # (3 decimals).  T / Omega must be the nominal idler torque of our model: the
    # rounding of Omega to 3 decimals allows 0.5e-3 / 0.914 = 0.055 %, hence 0.1 %.
    assert torque / omega == pytest.approx(kin.meshes[mesh].torque_driver, rel=1e-3)


@pytest.mark.parametrize("mesh, torque, omega", [("m12", 1129.33, 1.0383),
                                                 ("m13", 1046.0, 0.9617)])
def test_stage1_published_torque_over_dlsc_is_our_nominal(kin, mesh, torque, omega):
    # Sec. 6.1: T_12 = 1129.33 and T_13 = 1046.0 N m with Omega_12 = 1.0383 and
    # Omega_13 = 0.9617 (4 decimals: rounding 0.5e-4 / 0.96 = 0.005 %), hence 0.01 %.
    # Our nominal T_in / 2 = 1087.62 N m on the pinion side.
    assert kin.meshes[mesh].torque_driver == pytest.approx(2175.2367 / 2, rel=1e-6)
    assert torque / omega == pytest.approx(kin.meshes[mesh].torque_driver, rel=1e-4)


def test_stage1_published_torques_sum_to_input(kin):
    # Sec. 6.1: 1129.33 + 1046.0 = 2175.33 N m against T_in = 2175.24 N m; the shares
    # are printed as 51.92 % and 48.09 % (sum 100.01 %): agreement to 0.01 %.
    assert 1129.33 + 1046.0 == pytest.approx(kin.drive_torques["engine"], rel=1e-4)
    assert 1129.33 / kin.drive_torques["engine"] == pytest.approx(0.5192, abs=5e-5)
    assert 1046.0 / kin.drive_torques["engine"] == pytest.approx(0.4809, abs=5e-5)


def test_stage1_nominal_force_is_eq12_denominator(kin):
    # Eq. 12: Omega_1j = P_1j / ((T_in / 2) / (r_1 cos alpha_n)), r_1 = 3 x 29 / 2 mm
    # (Table 1).  Our nominal tooth force of each face mesh is that denominator (26 607 N);
    # exact geometry, tolerance 1e-9.
    f_nom = (P_IN / (N_IN * RPM) / 2) / (0.0435 * math.cos(math.radians(20)))
    for name in ("m12", "m13"):
        assert kin.meshes[name].force == pytest.approx(f_nom, rel=1e-9)


# --------------------------------------------------------------------- speeds (exact ratios)
def test_speeds_and_senses(kin):
    # Not printed: exact tooth-count ratios from 8780 rpm (Sec. 6) and Table 1.
    # O2 and O3 must turn the same way about +z (O3's own axis is -z), and so must O4,
    # O5 and O10, or the locked train could not turn; idlers turn the other way.
    b = kin.bodies
    w1 = N_IN * RPM
    z = np.array([0.0, 0.0, 1.0])

    def about_z(name):
        return b[name].speed * float(b[name].axis @ z)

    assert b["O1"].speed == pytest.approx(w1, rel=1e-12)
    w2 = -w1 / I12  # O1 axis +x drives O2 above it: O2 turns clockwise seen from +z
    for g in ("O2", "O3", "O4", "O5"):
        assert about_z(g) == pytest.approx(w2, rel=1e-9)
    for g in ("O6", "O7", "O8", "O9"):
        assert about_z(g) == pytest.approx(-w2 / I46, rel=1e-9)
    assert about_z("O10") == pytest.approx(w2 * 24 / 216, rel=1e-9)
    assert abs(b["O10"].speed) / RPM == pytest.approx(148.901, abs=1e-3)
    assert abs(b["O6"].speed) / RPM == pytest.approx(630.638, abs=1e-3)
    assert abs(b["O2"].speed) / RPM == pytest.approx(1340.105, abs=1e-3)


def test_output_torque_and_power_balance(kin):
    # Lossless: output = 4 x 7571.14 x 216/51 = 128 264 N m at 148.901 rpm (derived).
    assert kin.load_torques["rotor"] == pytest.approx(4 * 7571.14 * 216 / 51, rel=1e-5)
    assert kin.output_power == pytest.approx(P_IN, rel=1e-12)


def test_mesh_frequencies(kin):
    # Not printed: f = z n / 60.  Stage I 29 x 8780 / 60 = 4243.67 Hz; stage II (both the
    # pinion-idler and the idler-output meshes) 24 x 1340.105 / 60 = 536.04 Hz.
    for name in ("m12", "m13"):
        assert kin.meshes[name].frequency == pytest.approx(29 * N_IN / 60, rel=1e-9)
    f2 = 24 * N_IN / I12 / 60
    for name in ("m46", "m47", "m58", "m59") + IDLER_MESHES:
        assert kin.meshes[name].frequency == pytest.approx(f2, rel=1e-9)
    assert f2 == pytest.approx(536.04, abs=0.005)


# --------------------------------------------------------------------- face-gear geometry
def test_face_mesh_line_of_action(kin):
    # Eq. 2: F_12x = F_13x = 0 (x = pinion axis), tangential component F cos alpha_n,
    # face-gear axial component F sin alpha_n.  O2 above / O3 below at opposite ends of
    # the pinion: n_13 = -n_12, so the two mesh forces on O1 cancel.
    n12 = kin.meshes["m12"].line_of_action
    n13 = kin.meshes["m13"].line_of_action
    c, s = math.cos(math.radians(20)), math.sin(math.radians(20))
    assert n12 == pytest.approx([0.0, -c, s], abs=1e-12)  # pushes O2 up, away from O1
    assert n13 == pytest.approx(-n12, abs=1e-12)


def test_face_mesh_arms_conserve_power(kin):
    # The face gear's arm over the pinion's must equal the speed ratio 190/29, i.e. the
    # contact at r1 z2 / z1 = 285 mm (arm r_b1 z2 / z1 = 267.81 mm); otherwise the mesh
    # torques would not match the speeds (see the cone_angle note in the model file).
    for name in ("m12", "m13"):
        mk = kin.meshes[name]
        assert abs(mk.arm_driver) == pytest.approx(0.0435 * math.cos(math.radians(20)), rel=1e-9)
        assert abs(mk.arm_driven / mk.arm_driver) == pytest.approx(I12, rel=1e-9)
    for name in ("m46", "m47", "m58", "m59"):
        mk = kin.meshes[name]
        assert abs(mk.arm_driven / mk.arm_driver) == pytest.approx(I46, rel=1e-9)


def test_stage2_layout(kin):
    # Not in the paper (Fig. 1 missing): operating centre distances 157.719 mm
    # (a46 = 4 x 75 / (2 cos 18 deg)) and 561.481 mm (a6,10), pinions coaxial with the
    # face gears at x = -/+285 mm.
    for name in ("m46", "m47", "m58", "m59"):
        assert kin.meshes[name].center_distance == pytest.approx(
            0.004 * 75 / (2 * math.cos(math.radians(18))), rel=1e-9)
    for name in IDLER_MESHES:
        mk = kin.meshes[name]
        d = np.linalg.norm((kin.bodies[mk.driver].position - kin.bodies["O10"].position)[:2])
        assert d == pytest.approx(0.004 * 267 / (2 * math.cos(math.radians(18))), rel=1e-6)
    for face, pinion in (("O2", "O4"), ("O3", "O5")):
        assert kin.bodies[face].position[:2] == pytest.approx(kin.bodies[pinion].position[:2])


# --------------------------------------------------------------------- model content
def test_dof_count(model, kin):
    # Eq. 1: 32 DOF.  Ours 34: the same 32 plus the rotations of the two spline hubs that
    # put each spline in series with its quill shaft (O1b shares O1's rotation).
    dmap, _ = number_dofs(model, kin)
    assert len(dmap.names) == 34
    assert {"hub24.theta", "hub35.theta"} <= set(dmap.names)
    assert "O1b.theta" not in dmap.names


def test_section6_clearances_and_errors(model):
    # Sec. 6: b_12 = b_13 = 10 um, b_610..b_910 = 17 um (half-widths of the eq. 7 dead
    # zone; the model file holds the total 2b), support clearance b_di = 10 um, spline
    # clearance S_2 = 50 um, A_i = E_i = 50 um; Table 2 with k_m610 = 6.5e6 N/mm (the
    # printed 0.65e6 is a factor-10 misprint, Fig. 8).
    ms = model.meshes
    for name in ("m12", "m13"):
        assert ms[name].backlash.nominal / 2 == pytest.approx(10e-6)
        assert ms[name].stiffness.value == pytest.approx(0.85e9)
    for name in IDLER_MESHES:
        assert ms[name].backlash.nominal / 2 == pytest.approx(17e-6)
        assert ms[name].stiffness.value == pytest.approx(6.5e9)
    for sp in model.splines.values():
        assert sp.radial_clearance == pytest.approx(50e-6)
        assert sp.friction_coefficient == pytest.approx(0.1)
    for name, g in model.gears.items():
        assert g.errors.eccentricity == pytest.approx(50e-6)
        assert g.errors.installation == pytest.approx(50e-6)
        if g.support is not None and name not in ("O4", "O5"):
            assert g.support.clearance == pytest.approx(10e-6)
