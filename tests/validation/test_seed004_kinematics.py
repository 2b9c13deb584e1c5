"""Seed 004 (two-stage external-mesh star reducer, 3 paths): kinematics of the example.

Paper: S. Mo et al., "Research on Multiple-Split Load Sharing Characteristics of 2-Stage
External Meshing Star Gear System in Consideration of Displacement Compatibility",
Math. Probl. Eng. 2017, 1037479.  Table 1: 15/54/15/54 teeth, module 1.5 mm, 100 kW at
40000 r/min.  Issue 2 acceptance: input torque 23.873 N m, 7.958 N m per path at the first
stage, 28.648 N m on each star shaft, output torque 309.4 N m.  These are the ideal
(error-free, equal-split) torques: the denominators of the paper's load-sharing
coefficients (eq. 14) and the values its Figs. 6-7 curves scatter about.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import torquesplit
from torquesplit.model.io import model_from_dict

NAME = "mo2017_star_reducer"
RPM = math.pi / 30
PATHS = (1, 2, 3)


@pytest.fixture(scope="module")
def model():
    return torquesplit.load_model(torquesplit.example_path(NAME))


@pytest.fixture(scope="module")
def kin(model):
    return torquesplit.solve_kinematics(model)


# --------------------------------------------------------------------------- acceptance
def test_input_torque(kin):
    # Issue 2: 23.873 N m = 100 kW / (40000 r/min) (Table 1); tolerance = half a unit of
    # the last printed digit.
    assert kin.drive_torques["turbine"] == pytest.approx(23.873, abs=5e-4)
    assert kin.bodies["s1"].torque == pytest.approx(23.873, abs=5e-4)


def test_first_stage_torque_per_path(kin):
    # Issue 2: 7.958 N m = T_s1 / 3 per path (the ideal |T_s1p1i|, denominator of
    # Omega_p1i in eq. 14); half a unit of the last digit.
    for i in PATHS:
        assert kin.meshes[f"s1p1{i}"].torque_driver == pytest.approx(7.958, abs=5e-4)


def test_star_shaft_torque(kin):
    # Issue 2: 28.648 N m on each star shaft = 3.6 x 7.958 (eq. 5: T_p2is2 = (r_bp1/r_bs1)
    # T_s1p1i; denominator of Omega_p2i in eq. 14); half a unit of the last digit.  The
    # same torque enters the star from s1 and leaves it into the p2i-s2 mesh.
    for i in PATHS:
        assert kin.bodies[f"p1{i}"].torque == pytest.approx(28.648, abs=5e-4)
        assert kin.bodies[f"p2{i}"].torque == pytest.approx(28.648, abs=5e-4)
        assert kin.meshes[f"s1p1{i}"].torque_driven == pytest.approx(28.648, abs=5e-4)
        assert kin.meshes[f"p2{i}s2"].torque_driver == pytest.approx(28.648, abs=5e-4)


def test_output_torque(kin):
    # Issue 2: 309.4 N m = 23.873 x 12.96; printed to one decimal, so +/- 0.05 N m.
    assert kin.load_torques["output"] == pytest.approx(309.4, abs=0.05)
    assert kin.bodies["s2"].torque == pytest.approx(309.4, abs=0.05)
    total = sum(kin.meshes[f"p2{i}s2"].torque_driven for i in PATHS)
    assert total == pytest.approx(309.4, abs=0.05)


# --------------------------------------------------------------------------- paper data
def test_table1_and_section6_data(model):
    # Table 1: teeth and module; section 6: K_s1p = K_ps2 = 1e7, K_s1 = K_p1 = 4e7,
    # K_s2 = K_p2 = 8e7 N/m; every error 6 um, phase 0.25 deg (exact, as printed).
    teeth = {"s1": 15, "s2": 54}
    teeth.update({f"p1{i}": 54 for i in PATHS})
    teeth.update({f"p2{i}": 15 for i in PATHS})
    support = {"s1": 4e7, "s2": 8e7}
    support.update({f"p1{i}": 4e7 for i in PATHS})
    support.update({f"p2{i}": 8e7 for i in PATHS})
    for g, z in teeth.items():
        gear = model.gears[g]
        assert gear.teeth == z
        assert gear.module == pytest.approx(1.5e-3, rel=1e-12)
        assert gear.support.stiffness == pytest.approx(support[g], rel=1e-12)
        assert set(gear.dofs) == {"x", "y", "theta"}
        e = gear.errors
        for v in (e.eccentricity, e.installation, e.tooth_thickness, e.pitch, e.bearing_runout):
            assert v == pytest.approx(6e-6, rel=1e-12)
        for ph in (e.eccentricity_phase, e.installation_phase, e.bearing_runout_phase):
            assert ph == pytest.approx(math.radians(0.25), rel=1e-12)
    for name, mesh in model.meshes.items():
        assert mesh.stiffness.method == "constant"
        assert mesh.stiffness.value == pytest.approx(1e7, rel=1e-12)
    for i in PATHS:
        assert model.shafts[f"star{i}"].rigid


# --------------------------------------------------------------------------- consistency
def test_speeds_and_mesh_frequencies(kin):
    # Derived from Table 1 (not printed): stars 11111.1 r/min (opposite sense), output
    # 3086.42 r/min; mesh frequencies 10000 Hz and 2777.78 Hz.
    w = 40000 * RPM
    assert kin.bodies["s1"].speed == pytest.approx(w, rel=1e-12)
    for i in PATHS:
        assert kin.bodies[f"p1{i}"].speed == pytest.approx(-w * 15 / 54, rel=1e-12)
        assert kin.bodies[f"p2{i}"].speed == pytest.approx(-w * 15 / 54, rel=1e-12)
        assert kin.meshes[f"s1p1{i}"].frequency == pytest.approx(10000.0, rel=1e-12)
        assert kin.meshes[f"p2{i}s2"].frequency == pytest.approx(2777.7778, rel=1e-7)
    assert kin.bodies["s2"].speed == pytest.approx(w / 12.96, rel=1e-12)
    assert kin.output_power == pytest.approx(100e3, rel=1e-12)


def test_star_layout(kin):
    # Section 4.1: star i at phi_i = 2 pi (i - 1) / n, star 1 on the x axis; p1i and p2i on
    # one fixed axis; s1 and s2 coaxial.  Centre distance 51.75 mm (both stages).
    for i in PATHS:
        phi = 2 * math.pi * (i - 1) / 3
        for g in (f"p1{i}", f"p2{i}"):
            p = kin.bodies[g].position
            np.testing.assert_allclose(p[:2], 0.05175 * np.array([math.cos(phi), math.sin(phi)]),
                                       atol=1e-12)
    np.testing.assert_allclose(kin.bodies["s1"].position[:2], kin.bodies["s2"].position[:2])
    for name, mk in kin.meshes.items():
        assert mk.center_distance == pytest.approx(0.05175, rel=1e-9)


def test_floating_suns_balanced(kin):
    # Section 3: with equal loads "the principal vector of F_s1p1i is 0" (and of F_p2is2):
    # the three mesh forces on each floating sun sum to zero.  Nominal normal forces (alpha =
    # 20 deg assumed): 752.75 N (stage 1) and 2709.9 N (stage 2).
    for stage, fn in (("s1p1{}", 752.75), ("p2{}s2", 2709.9)):
        forces = [kin.meshes[stage.format(i)].force * kin.meshes[stage.format(i)].line_of_action
                  for i in PATHS]
        np.testing.assert_allclose(np.sum(forces, axis=0), 0.0, atol=1e-9)
        for i in PATHS:
            assert kin.meshes[stage.format(i)].force == pytest.approx(fn, rel=1e-4)


def test_line_of_action_directions(kin):
    # Reconstruction of the paper's A_i / B_i (eq. 13): with s1 turning counter-clockwise
    # the force on star p1i points at phi_i + 90 - alpha_w1 deg, the force on s2 from p2i at
    # phi_i + 90 + alpha_w2 deg (alpha_w = 20 deg).
    for i in PATHS:
        phi = 120.0 * (i - 1)
        for mesh, ang in ((f"s1p1{i}", phi + 70.0), (f"p2{i}s2", phi + 110.0)):
            n = kin.meshes[mesh].line_of_action
            a = math.radians(ang)
            np.testing.assert_allclose(n, [math.cos(a), math.sin(a), 0.0], atol=1e-12)


def test_error_free_variant_same_kinematics(kin):
    # The nominal (error-free) model: remove every [gears.X.errors]; speeds, torques and
    # forces must not change (errors enter only the excitation).
    data = tomllib.loads(torquesplit.example_path(NAME).read_text(encoding="utf-8"))
    for g in data["gears"].values():
        g.pop("errors", None)
    nominal = torquesplit.solve_kinematics(torquesplit.load_model(model_from_dict(data)))
    for name, mk in kin.meshes.items():
        assert nominal.meshes[name].torque_driver == pytest.approx(mk.torque_driver, rel=1e-12)
        assert nominal.meshes[name].force == pytest.approx(mk.force, rel=1e-12)
