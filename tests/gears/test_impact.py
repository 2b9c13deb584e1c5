"""Tests of torquesplit.gears.impact (meshing-in impact, seed 000 eqs. 6-10)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from torquesplit.errors import ModelError
from torquesplit.gears.impact import (
    equivalent_mass,
    impact_duration,
    impact_force,
    involute,
    loaded_deflection,
    meshing_in_impact,
    meshing_in_point,
    meshing_in_radius,
)

# Seed 000 Table 1, second-stage spur pair: 34/107 teeth, m = 3.5 mm, 22.5 deg,
# pinion at 7626 rpm.  Inertias and impact stiffness are not given by the seed;
# plausible values for gears of this size are used.
M, Z1, Z2, ALPHA = 3.5e-3, 34, 107, math.radians(22.5)
R1, R2 = M * Z1 / 2, M * Z2 / 2
RB1, RB2 = R1 * math.cos(ALPHA), R2 * math.cos(ALPHA)
RA1, RA2 = R1 + M, R2 + M
A = R1 + R2
PB = 2 * math.pi * RB1 / Z1
OMEGA = 7626 * math.pi / 30
GEOM = dict(base_radius_driving=RB1, base_radius_driven=RB2, tip_radius_driven=RA2, centre_distance=A)


def impact(load=10e3, omega=OMEGA, exponent=1.0, **kw):
    args = dict(
        GEOM,
        base_pitch=PB,
        omega_driving=omega,
        normal_load=load,
        loaded_stiffness=1.0e9,
        inertia_driving=0.004,
        inertia_driven=0.15,
        impact_stiffness=1.0e9 if exponent == 1.0 else 5.0e13,
        exponent=exponent,
    )
    args.update(kw)
    return meshing_in_impact(**args)


def test_zero_for_error_free_unloaded_pair():
    imp = impact(load=0.0)
    assert imp.peak_force == 0.0
    assert imp.point.offset_from_line == pytest.approx(0.0, abs=1e-12)
    assert imp.point.normal_velocity == pytest.approx(0.0, abs=1e-9)
    assert imp.point.radius_on_driving == pytest.approx(math.hypot(*imp.point.point))
    _, force = imp.table(64)
    assert np.all(force == 0.0)


def test_grows_with_load():
    peaks = [impact(load=f).peak_force for f in (2e3, 5e3, 10e3, 20e3)]
    assert all(a < b for a, b in zip(peaks, peaks[1:]))
    # a base-pitch excess of the pinion acts like extra deflection
    with_pitch = impact(load=5e3, base_pitch_difference=5e-6).peak_force
    assert with_pitch == pytest.approx(impact(load=10e3).peak_force)


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_speed_scaling_follows_eq10(exponent):
    """v_s is proportional to the speed (geometry does not depend on it), so
    eq. 10 gives F_s ~ omega^(2n/(n+1)): 2x speed -> 2^(2n/(n+1)) force."""
    f1 = impact(omega=OMEGA, exponent=exponent).peak_force
    f2 = impact(omega=2 * OMEGA, exponent=exponent).peak_force
    assert f2 / f1 == pytest.approx(2 ** (2 * exponent / (exponent + 1)), rel=1e-9)


def test_eq10_exponents():
    n = 1.5
    base = impact_force(2.0, 0.8, 3e13, n)
    assert impact_force(4.0, 0.8, 3e13, n) / base == pytest.approx(2 ** (n / (n + 1)))
    assert impact_force(2.0, 0.8, 6e13, n) / base == pytest.approx(2 ** (1 / (n + 1)))
    assert impact_force(2.0, 1.6, 3e13, n) / base == pytest.approx(2 ** (2 * n / (n + 1)))
    # linear contact: F = v sqrt(m k)
    assert impact_force(2.0, 0.8, 1e9, 1.0) == pytest.approx(0.8 * math.sqrt(2.0e9))


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_eq10_and_duration_against_impact_ode(exponent):
    """Integrate m x'' = -k x^n from x = 0, x' = v: peak force = eq. 10, contact
    time = impact_duration."""
    m, v = 1.3, 0.9
    k = 1.0e9 if exponent == 1.0 else 5.0e13

    def rhs(_, y):
        return [y[1], -k * max(y[0], 0.0) ** exponent / m]

    def leave(_, y):
        return y[0]

    leave.terminal, leave.direction = True, -1
    t_guess = 10 * impact_duration(m, v, k, exponent)
    sol = solve_ivp(
        rhs, (0, t_guess), [1e-15, v], events=leave, rtol=1e-10, atol=1e-16, max_step=t_guess / 2000
    )
    x = sol.y[0]
    assert k * x.max() ** exponent == pytest.approx(impact_force(m, v, k, exponent), rel=1e-4)
    assert sol.t_events[0][0] == pytest.approx(impact_duration(m, v, k, exponent), rel=1e-3)


def test_hertz_duration_classical_value():
    m, v, k, n = 1.0, 1.0, 1e12, 1.5
    delta_max = ((n + 1) * m * v**2 / (2 * k)) ** (1 / (n + 1))
    assert impact_duration(m, v, k, n) == pytest.approx(2.9432 * delta_max / v, rel=1e-4)


def test_meshing_in_point_geometry():
    adv = loaded_deflection(12e3, 1.2e9)
    assert adv == pytest.approx(1e-5)
    p = meshing_in_point(**GEOM, advance=adv, omega_driving=OMEGA, tip_radius_driving=RA1)
    d = np.array(p.point)
    og = np.array([A, 0.0])
    # D is on the gear tip circle, off the line of action, before E
    assert np.linalg.norm(d - og) == pytest.approx(RA2)
    assert p.offset_from_line > 0
    assert p.pinion_flank_position < p.theoretical_start
    # D lies on the pinion flank: polar angle = s_p / rbp - alpha - inv(alpha_D)
    r_d = np.linalg.norm(d)
    flank = p.pinion_flank_position / RB1 - ALPHA - involute(math.acos(RB1 / r_d))
    assert math.atan2(d[1], d[0]) == pytest.approx(float(flank), abs=1e-12)
    # seed 000 eq. 6 reproduces |O_p D| with angle = gamma_g + phi_k + dphi_kg
    assert meshing_in_radius(RA2, R1, R2, p.gamma_g + p.reverse_angle) == pytest.approx(r_d, rel=1e-12)
    # gamma_g = pi/2 - alpha_t - angle(PEO_g) (seed 000, below eq. 6)
    n_p = RB1 * np.array([math.cos(ALPHA), -math.sin(ALPHA)])
    dvec = np.array([math.sin(ALPHA), math.cos(ALPHA)])
    e_pt = n_p + p.theoretical_start * dvec
    p_pt = np.array([R1, 0.0])
    u, w = p_pt - e_pt, og - e_pt
    angle_peog = math.acos(np.dot(u, w) / np.linalg.norm(u) / np.linalg.norm(w))
    assert p.gamma_g == pytest.approx(math.pi / 2 - ALPHA - angle_peog, abs=1e-12)
    # the gear meets the pinion earlier than by its lag alone
    assert p.reverse_angle > p.lag_angle > 0


def test_relative_normal_velocity_eq9():
    """v_s = omega_p r_bp - omega_g h_g, h_g = arm of the pinion flank normal at D about O_g."""
    p = meshing_in_point(**GEOM, advance=2e-5, omega_driving=OMEGA)
    d = np.array(p.point)
    tangent_len = math.sqrt(d @ d - RB1**2)
    # tangent point T on the pinion base circle, normal n = (D - T) / |D - T|
    beta = math.atan2(d[1], d[0]) - math.atan(tangent_len / RB1)
    t_pt = RB1 * np.array([math.cos(beta), math.sin(beta)])
    n = (d - t_pt) / tangent_len
    rel = np.array([A, 0.0]) - t_pt
    h_g = abs(rel[0] * n[1] - rel[1] * n[0])
    expected = OMEGA * RB1 - OMEGA * RB1 / RB2 * h_g
    assert p.normal_velocity == pytest.approx(expected, rel=1e-9)
    assert p.normal_velocity > 0


def test_pulse_shape_and_mean():
    imp = impact()
    m_e = equivalent_mass(0.004, 0.15, RB1, RB2)
    assert imp.effective_mass == pytest.approx(m_e)
    assert imp.duration == pytest.approx(math.pi * math.sqrt(m_e / 1e9))
    assert imp.duration < imp.mesh_period
    assert imp.mesh_period == pytest.approx(2 * math.pi / (Z1 * OMEGA))
    phase, force = imp.table(4096)
    assert force.max() == pytest.approx(imp.peak_force, rel=1e-3)
    assert force.mean() == pytest.approx(imp.mean_force, rel=1e-3)
    _, zero_mean = imp.table(4096, remove_mean=True)
    assert abs(zero_mean.mean()) < 1e-3 * imp.peak_force
    # the pulse starts slightly before the theoretical start of contact (phase 0)
    assert 0.5 < imp.start_phase < 1.0
    assert imp.force(imp.start_phase + 1e-9) == pytest.approx(0.0, abs=1e-3 * imp.peak_force)


def test_bad_input_is_named():
    with pytest.raises(ModelError, match="advance"):
        meshing_in_point(**GEOM, advance=-1e-6, omega_driving=OMEGA)
    with pytest.raises(ValueError, match="centre_distance"):
        meshing_in_point(**{**GEOM, "centre_distance": 0.1}, advance=0.0, omega_driving=OMEGA)


def test_the_approach_of_a_hand_written_stiffness_is_its_mean():
    """The deflection before the new pair enters is the stiffness table's at the end of
    the cycle only where phase 0 is the entry (ISO 6336, potential energy); a Fourier
    series written by hand has its own phase: +cos and -cos gave 5768 and 7799 N."""
    import tomllib
    import warnings

    import torquesplit
    from model_texts import SPUR_PAIR
    from torquesplit.assembly.excitation import impact_force_table
    from torquesplit.model.io import model_from_dict
    from torquesplit.model.kinematics import solve_kinematics

    peaks = []
    for sign in ("", "-"):
        text = SPUR_PAIR.replace(
            'stiffness = "4e8 N/m"',
            f'stiffness = {{method = "fourier", mean = "4e8 N/m", cos = ["{sign}1e8 N/m"], '
            f'sin = []}}\nimpact = true')
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = torquesplit.load_model(model_from_dict(tomllib.loads(text)))
        peaks.append(impact_force_table(m, solve_kinematics(m), "m", 256).max())
    assert peaks[0] == pytest.approx(peaks[1], rel=1e-12) and peaks[0] > 0
