"""Involute geometry of gear pairs: checked against hand calculations and seed 000."""

import math

import numpy as np
import pytest

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import (
    GearGeometry,
    PairGeometry,
    involute,
    inverse_involute,
    mesh_frequency,
    mesh_period,
)

DEG = math.pi / 180.0
A20 = 20 * DEG


def spur_20_40():
    return PairGeometry(GearGeometry(20, 2e-3, A20, face_width=20e-3),
                        GearGeometry(40, 2e-3, A20, face_width=20e-3))


def test_standard_spur_pair_contact_ratio_against_hand_calculation():
    # z1 = 20, z2 = 40, m = 2 mm, alpha = 20 deg, x = 0, h_a = 1 m:
    #   r1 = 20 mm, r2 = 40 mm, r_a1 = 22 mm, r_a2 = 42 mm, a = 60 mm
    #   r_b1 = 20 cos 20 = 18.793852 mm, r_b2 = 37.587705 mm
    #   sqrt(22^2 - 18.793852^2) = sqrt(484 - 353.208872) = 11.436394 mm
    #   sqrt(42^2 - 37.587705^2) = sqrt(1764 - 1412.835489) = 18.739382 mm
    #   a sin(alpha) = 60 x 0.342020 = 20.521209 mm
    #   g_alpha = 11.436394 + 18.739382 - 20.521209 = 9.654568 mm
    #   p_b = pi m cos(alpha) = 5.904263 mm;  eps_alpha = 9.654568 / 5.904263 = 1.635186
    p = spur_20_40()
    assert p.gear1.base_radius == pytest.approx(18.793852e-3, rel=1e-6)
    assert p.base_pitch == pytest.approx(5.904263e-3, rel=1e-6)
    assert p.path_length == pytest.approx(9.654568e-3, rel=1e-6)
    assert p.transverse_contact_ratio == pytest.approx(1.635186, abs=2e-6)
    assert p.overlap_contact_ratio == 0.0
    assert p.total_contact_ratio == pytest.approx(1.635186, abs=2e-6)
    # approach and recess: pitch point at r_b1 tan(20) = 6.840403 mm from T1
    #   recess  = 11.436394 - 6.840403 = 4.595991 mm
    #   approach = 18.739382 - 37.587705 x tan(20) = 18.739382 - 13.680806 = 5.058576 mm
    assert p.path_end == pytest.approx(4.595991e-3, rel=1e-6)
    assert p.path_start == pytest.approx(-5.058576e-3, rel=1e-6)
    assert p.working_pressure_angle == pytest.approx(A20, abs=1e-12)
    assert p.operating_center_distance == pytest.approx(60e-3, rel=1e-12)
    assert p.working_pitch_radii == pytest.approx((20e-3, 40e-3), rel=1e-12)


def test_seed000_double_helical_pair_total_contact_ratio():
    # seed 000 Table 1, DH gear: z = 23/215, module 3.965 mm, tooth width 50 mm,
    # pressure angle 20 deg, helix angle 30 deg; the text (§5.2) quotes a theoretical
    # contact ratio of 3.42.  Reproduced with: 3.965 mm = NORMAL module, 20 deg = NORMAL
    # pressure angle, 50 mm = face width of ONE helix:
    #   eps_beta = 50 sin(30) / (pi 3.965) = 2.00700, eps_alpha = 1.41453 -> 3.42153
    g1 = GearGeometry(23, 3.965e-3, A20, 30 * DEG, 50e-3, double_helical=True)
    g2 = GearGeometry(215, 3.965e-3, A20, -30 * DEG, 50e-3, double_helical=True)
    p = PairGeometry(g1, g2)
    assert p.total_contact_ratio == pytest.approx(3.4215, abs=1e-3)
    assert p.overlap_contact_ratio == pytest.approx(50 * 0.5 / (math.pi * 3.965), rel=1e-12)
    assert p.total_face_width == pytest.approx(100e-3)
    # the other readings do not give 3.42 (documented in the module docstring)
    whole = PairGeometry(GearGeometry(23, 3.965e-3, A20, 30 * DEG, 25e-3, double_helical=True),
                         GearGeometry(215, 3.965e-3, A20, -30 * DEG, 25e-3, double_helical=True))
    assert abs(whole.total_contact_ratio - 3.4215) > 0.5


def test_helical_transverse_quantities_against_hand_calculation():
    # m_n = 3 mm, alpha_n = 20 deg, beta = 15 deg:
    #   m_t = 3 / cos 15 = 3.105829 mm
    #   alpha_t = atan(tan 20 / cos 15) = atan(0.376807) = 20.646896 deg
    #   beta_b = atan(tan 15 cos alpha_t) = atan(0.267949 x 0.935771) = atan(0.250739) = 14.076095 deg
    g = GearGeometry(25, 3e-3, A20, 15 * DEG, 40e-3)
    assert g.transverse_module == pytest.approx(3.105829e-3, rel=1e-6)
    assert math.degrees(g.transverse_pressure_angle) == pytest.approx(20.646896, abs=1e-5)
    assert math.degrees(g.base_helix_angle) == pytest.approx(14.076095, abs=1e-5)
    # sin(beta_b) = sin(beta) cos(alpha_n) (ISO 21771 identity)
    assert math.sin(g.base_helix_angle) == pytest.approx(math.sin(15 * DEG) * math.cos(A20), rel=1e-12)
    # r = 25 x 3.105829 / 2 = 38.822866 mm; r_a = r + 3; r_f = r - 3.75
    assert g.reference_radius == pytest.approx(38.822866e-3, rel=1e-6)
    assert g.tip_radius == pytest.approx(41.822866e-3, rel=1e-6)
    assert g.root_radius == pytest.approx(35.072866e-3, rel=1e-6)
    # eps_beta = 40 sin 15 / (3 pi) = 10.352762 / 9.424778 = 1.098462
    p = PairGeometry(g, GearGeometry(60, 3e-3, A20, -15 * DEG, 40e-3))
    assert p.overlap_contact_ratio == pytest.approx(1.098462, abs=1e-6)
    assert p.normal_base_pitch == pytest.approx(p.base_pitch * math.cos(p.base_helix_angle), rel=1e-12)


def test_profile_shifted_pair_working_pressure_angle_and_centre_distance():
    # z = 17/53, x = +0.3/-0.1, m = 2 mm:
    #   inv(alpha_wt) = inv 20 + 2 tan 20 (0.3 - 0.1) / 70
    #                 = 0.014904384 + 2 x 0.363970234 x 0.2 / 70 = 0.016984214
    #   alpha_wt = 20.858717 deg (tan a - a = 0.016984214)
    #   a = 70 mm; a_w = 70 cos 20 / cos 20.858717 = 65.778483 / 0.934452 = 70.391878 mm
    g1 = GearGeometry(17, 2e-3, A20, profile_shift=0.3, face_width=20e-3)
    g2 = GearGeometry(53, 2e-3, A20, profile_shift=-0.1, face_width=20e-3)
    p = PairGeometry(g1, g2)
    assert float(involute(p.working_pressure_angle)) == pytest.approx(0.016984214, rel=1e-7)
    assert math.degrees(p.working_pressure_angle) == pytest.approx(20.858717, abs=1e-5)
    assert p.operating_center_distance == pytest.approx(70.391878e-3, rel=1e-6)
    # giving that centre distance explicitly must give the same working pressure angle
    q = PairGeometry(g1, g2, center_distance=p.operating_center_distance)
    assert q.working_pressure_angle == pytest.approx(p.working_pressure_angle, abs=1e-10)
    # tip radii: r + m (1 + x): 17 + 2.6 = 19.6 mm and 53 + 1.8 = 54.8 mm
    assert g1.tip_radius == pytest.approx(19.6e-3) and g2.tip_radius == pytest.approx(54.8e-3)


def test_inverse_involute_round_trip():
    for a in np.linspace(0.01, 1.2, 25):
        assert inverse_involute(float(involute(a))) == pytest.approx(a, abs=1e-12)


def test_internal_pair_against_hand_calculation():
    # pinion z1 = 20, ring z2 = 80 (internal=True), m = 2 mm, x = 0:
    #   ring tip radius r_a2 = 80 - 2 = 78 mm, r_b2 = 80 cos 20 = 75.175409 mm, a = 60 mm
    #   sqrt(78^2 - 75.175409^2) = sqrt(6084 - 5651.341956) = 20.800432 mm
    #   g_alpha = sqrt(r_a1^2 - r_b1^2) - sqrt(r_a2^2 - r_b2^2) + a sin(alpha)
    #           = 11.436394 - 20.800432 + 20.521209 = 11.157171 mm
    #   eps_alpha = 11.157171 / 5.904263 = 1.889681
    ring = GearGeometry(80, 2e-3, A20, face_width=20e-3, internal=True)
    p = PairGeometry(GearGeometry(20, 2e-3, A20, face_width=20e-3), ring)
    assert ring.tip_radius == pytest.approx(78e-3) and ring.root_radius == pytest.approx(82.5e-3)
    assert p.operating_center_distance == pytest.approx(60e-3)
    assert p.path_length == pytest.approx(11.157171e-3, rel=1e-6)
    assert p.transverse_contact_ratio == pytest.approx(1.889681, abs=2e-6)
    assert ring.virtual_teeth == math.inf


def test_internal_profile_shift_sign_convention():
    # x > 0 moves the ring profile away from the axis: inv(alpha_wt) =
    # inv(alpha) + 2 tan(alpha) (x2 - x1)/(z2 - z1) > inv(alpha) for x2 > x1
    ring = GearGeometry(80, 2e-3, A20, face_width=20e-3, internal=True, profile_shift=0.5)
    p = PairGeometry(GearGeometry(20, 2e-3, A20, face_width=20e-3), ring)
    expected = float(involute(A20)) + 2 * math.tan(A20) * 0.5 / 60
    assert float(involute(p.working_pressure_angle)) == pytest.approx(expected, rel=1e-10)
    assert p.operating_center_distance > 60e-3


def test_curvature_radii_and_velocities_along_the_path():
    p = spur_20_40()
    s = p.contact_positions(11)
    r1, r2 = p.curvature_radii(s)
    # external pair: rho1 + rho2 = T1T2 = a_w sin(alpha_wt) everywhere
    assert np.allclose(r1 + r2, 60e-3 * math.sin(A20), rtol=1e-12)
    w1 = 100.0
    u, vs = p.surface_velocities(s, w1)
    # sliding = omega1 s (1 + z1/z2); entrainment at the pitch point = omega1 r_b1 tan(alpha)
    assert np.allclose(vs, w1 * s * (1 + 20 / 40), rtol=1e-10, atol=1e-12)
    u0, vs0 = p.surface_velocities(0.0, w1)
    assert float(vs0) == pytest.approx(0.0, abs=1e-12)
    assert float(u0) == pytest.approx(w1 * p.gear1.base_radius * math.tan(A20), rel=1e-12)
    # normal-plane radii of a helical pair are rho_t / cos(beta_b)
    h = PairGeometry(GearGeometry(25, 3e-3, A20, 15 * DEG, 40e-3), GearGeometry(60, 3e-3, A20, -15 * DEG, 40e-3))
    rt, _ = h.curvature_radii(0.0)
    rn, _ = h.curvature_radii(0.0, normal=True)
    assert float(rn) == pytest.approx(float(rt) / math.cos(h.base_helix_angle))


def test_internal_pair_radii_and_sliding():
    ring = GearGeometry(80, 2e-3, A20, face_width=20e-3, internal=True)
    p = PairGeometry(GearGeometry(20, 2e-3, A20, face_width=20e-3), ring)
    s = p.contact_positions(7)
    r1, r2 = p.curvature_radii(s)
    assert np.all(r2 < 0)  # concave ring flank
    assert np.allclose(-r2 - r1, 60e-3 * math.sin(A20), rtol=1e-12)
    _, vs = p.surface_velocities(s, 50.0)
    assert np.allclose(vs, 50.0 * s * (1 - 20 / 80), rtol=1e-10, atol=1e-12)


def test_mesh_period_against_hand_calculation():
    # z = 23 at 2423 rpm: f_m = 23 x 2423 / 60 = 928.816667 Hz, T_m = 1.076638e-3 s
    assert mesh_frequency(23, rpm=2423) == pytest.approx(928.816667, rel=1e-8)
    assert mesh_period(23, rpm=2423) == pytest.approx(1 / 928.816667, rel=1e-8)
    assert mesh_period(23, 2423 * 2 * math.pi / 60) == pytest.approx(mesh_period(23, rpm=2423))
    assert spur_20_40().mesh_period(100.0) == pytest.approx(2 * math.pi / (20 * 100.0))
    with pytest.raises(TypeError, match="exactly one"):
        mesh_period(20)
    with pytest.raises(TypeError):
        mesh_period(20, 1.0, rpm=3.0)


def test_bad_input_is_refused_with_a_message_naming_the_field():
    with pytest.raises(ModelError, match="internal=True"):
        GearGeometry(-80, 2e-3, A20)
    with pytest.raises(ModelError, match="metres"):
        GearGeometry(20, 2.0, A20)            # module given in mm
    with pytest.raises(ModelError, match="radians"):
        GearGeometry(20, 2e-3, 20.0)          # angle given in degrees
    with pytest.raises(ModelError, match="module"):
        PairGeometry(GearGeometry(20, 2e-3, A20), GearGeometry(40, 3e-3, A20))
    with pytest.raises(ModelError, match="pinion"):
        PairGeometry(GearGeometry(80, 2e-3, A20, internal=True), GearGeometry(20, 2e-3, A20))
    # 8-tooth unshifted pinion against a rack-like wheel: involute interference
    with pytest.raises(ModelError, match="interference"):
        PairGeometry(GearGeometry(8, 2e-3, A20), GearGeometry(100, 2e-3, A20))
    # ModelError is a ValueError
    with pytest.raises(ValueError):
        GearGeometry(2, 2e-3, A20)


def test_fast_cross_equals_numpy_bit_for_bit():
    from torquesplit.gears.vectors import cross

    rng = np.random.default_rng(3)
    for _ in range(200):
        a, b = rng.normal(size=3) * 10.0 ** rng.integers(-6, 6), rng.normal(size=3)
        assert np.array_equal(cross(a, b), np.cross(a, b))
    many = rng.normal(size=(5, 3))
    assert np.array_equal(cross(many, many[::-1]), np.cross(many, many[::-1]))
