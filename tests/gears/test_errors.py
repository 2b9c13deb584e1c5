"""Tests of torquesplit.gears.errors (line-of-action error signals)."""

import math

import numpy as np
import pytest

from torquesplit.errors import ModelError
from torquesplit.gears.errors import (
    CentreDeviation,
    LineOfActionDeviation,
    bearing_runout_error,
    centre_errors_on_line,
    cumulative_pitch_error,
    pitch_error_from_deviations,
    rotating_offset_on_line,
    eccentricity_installation_error_sum_form,
    eccentricity_installation_error_difference_form,
    tooth_thickness_error,
)

T = np.linspace(0.0, 0.05, 301)


def test_signal_normalisation_and_rate():
    e = LineOfActionDeviation(1e-6, [-2e-6, 3e-6, 4e-6], [-50.0, 80.0, 0.0], [0.3, -1.0, 0.5])
    assert np.all(e.omegas >= 0) and np.all(e.amplitudes >= 0)
    assert e.omegas.size == 2  # the zero-frequency term became part of the constant
    direct = 1e-6 - 2e-6 * np.sin(-50.0 * T + 0.3) + 3e-6 * np.sin(80.0 * T - 1.0) + 4e-6 * math.sin(0.5)
    np.testing.assert_allclose(e.evaluate(T), direct, atol=1e-18)
    h = 1e-7
    fd = (e.evaluate(T + h) - e.evaluate(T - h)) / (2 * h)
    np.testing.assert_allclose(e.rate(T), fd, rtol=1e-6, atol=1e-12)
    merged = (e + e).combined()
    assert merged.omegas.size == 2
    np.testing.assert_allclose(merged.evaluate(T), 2 * e.evaluate(T), atol=1e-18)
    np.testing.assert_allclose(e.angular(0.05).evaluate(T), e.evaluate(T) / 0.05)


def test_eccentricity_rotates_with_its_gear():
    """Signal at the gear's rotation frequency, phase from the offset direction
    relative to the line of action: -E cos(Omega t + phi - zeta) for gear 1."""
    ecc, phi, omega, zeta = 8e-6, 0.7, 798.6, math.radians(22.5) + 1.2
    gear = CentreDeviation(eccentricity=ecc, eccentricity_phase=phi, omega=omega)
    e = centre_errors_on_line(zeta, gear, CentreDeviation())
    assert e.omegas.tolist() == [pytest.approx(omega)]
    assert e.amplitudes[0] == pytest.approx(ecc)
    # direct vector projection of the rotating offset
    eps = ecc * np.stack([np.cos(omega * T + phi), np.sin(omega * T + phi)], axis=-1)
    n = np.array([math.cos(zeta), math.sin(zeta)])
    np.testing.assert_allclose(e.evaluate(T), -(eps @ n), atol=1e-18)
    # the maximum opening occurs when the offset points against n
    t_max = (math.pi + zeta - phi) / omega % (2 * math.pi / omega)
    assert e.evaluate(t_max) == pytest.approx(ecc)
    # a clockwise gear: frequency |Omega|, direction reversed
    e_cw = rotating_offset_on_line(ecc, phi, -omega, zeta)
    assert e_cw.omegas[0] == pytest.approx(omega)
    np.testing.assert_allclose(e_cw.evaluate(T), ecc * np.cos(-omega * T + phi - zeta), atol=1e-18)


def test_common_offset_cancels_and_installation_is_constant():
    g = CentreDeviation(installation=12e-6, installation_direction=0.4, omega=100.0)
    mate = CentreDeviation(installation=12e-6, installation_direction=0.4, omega=-30.0)
    e = centre_errors_on_line(1.1, g, mate)
    assert e.omegas.size == 0 and e.constant == pytest.approx(0.0, abs=1e-20)
    only = centre_errors_on_line(1.1, g, CentreDeviation(omega=-30.0))
    assert only.omegas.size == 0
    assert only.constant == pytest.approx(-12e-6 * math.cos(0.4 - 1.1))


def test_seed002_eq11_hand_computed():
    """Seed 002 eq. 11 with a_ij = pi/6, eta_i = 0, eta_j = pi/3, delta_i = pi/3,
    delta_j = -pi/6, omega_i = omega_j = 100 rad/s:
      t = 0:            e = 50*1/2 - 20*1 + 50*1 - 30*0        = 55 um
      t = pi/(2 omega): e = 50*sin(-pi/3) - 20*sin(0) + 50 - 0  = 6.6987 um
    and the opposite branch (sign -1) is the negative."""
    kw = dict(
        eccentricity_i=50e-6,
        phase_i=0.0,
        omega_i=100.0,
        installation_i=50e-6,
        installation_phase_i=math.pi / 3,
        eccentricity_j=20e-6,
        phase_j=math.pi / 3,
        omega_j=100.0,
        installation_j=30e-6,
        installation_phase_j=-math.pi / 6,
        line_angle=math.pi / 6,
    )
    e = eccentricity_installation_error_difference_form(**kw)
    assert e.evaluate(0.0) == pytest.approx(55e-6)
    assert e.evaluate(math.pi / 200) == pytest.approx(6.69873e-6, rel=1e-5)
    e13 = eccentricity_installation_error_difference_form(**kw, sign=-1.0)
    np.testing.assert_allclose(e13.evaluate(T), -e.evaluate(T), atol=1e-18)
    # installation terms are constant, eccentricity at the shaft frequency
    assert e.constant == pytest.approx(50e-6 * 1.0 - 30e-6 * 0.0)
    assert set(np.round(e.omegas, 9)) == {100.0}


def test_seed002_equals_physical_projection_with_its_conventions():
    """Seed 002 measures the offset angle psi = -w t + eta from +y towards +x and
    takes e = +(eps_i - eps_j).n; the physical (separation) convention here is
    e = -(eps_i - eps_j).n.  Both eccentricities rotate counter-clockwise as printed."""
    a = 0.9
    kw = dict(
        eccentricity_i=50e-6, phase_i=0.2, omega_i=120.0, installation_i=50e-6, installation_phase_i=0.5,
        eccentricity_j=30e-6, phase_j=-1.0, omega_j=40.0, installation_j=20e-6, installation_phase_j=2.0,
        line_angle=a,
    )
    seed = eccentricity_installation_error_difference_form(**kw)
    gi = CentreDeviation(50e-6, math.pi / 2 - 0.2, 50e-6, math.pi / 2 - 0.5, 120.0)
    gj = CentreDeviation(30e-6, math.pi / 2 + 1.0, 20e-6, math.pi / 2 - 2.0, 40.0)
    physical = centre_errors_on_line(a, gi, gj)
    np.testing.assert_allclose(seed.evaluate(T), -physical.evaluate(T), atol=1e-18)


def test_seed000_eq1_transcription_and_its_same_sign_remark():
    kw = dict(
        eccentricity_i=8e-6, phase_i=0.3, omega_i=798.6, installation_i=8e-6, installation_phase_i=1.0,
        eccentricity_j=12e-6, phase_j=-0.4, omega_j=253.8, installation_j=12e-6, installation_phase_j=0.2,
    )
    c = 0.7 + math.radians(22.5)  # gamma_34 + alpha_ts
    e = eccentricity_installation_error_sum_form(**kw, line_offset=c)
    t = T
    direct = (
        8e-6 * np.sin(-798.6 * t - 0.3 + c)
        + 8e-6 * math.sin(-1.0 + c)
        + 12e-6 * np.sin(-253.8 * t + 0.4 + c)
        + 12e-6 * math.sin(-0.2 + c)
    )
    np.testing.assert_allclose(e.evaluate(t), direct, atol=1e-18)
    # eq. 2 for the double-helical pairs: overall minus sign and gamma - alpha_th
    e68 = eccentricity_installation_error_sum_form(**kw, line_offset=0.7 - math.radians(20), sign=-1.0)
    assert e68.evaluate(0.0) == pytest.approx(
        -(8e-6 * math.sin(-0.3 + 0.7 - math.radians(20)) + 8e-6 * math.sin(-1.0 + 0.7 - math.radians(20))
          + 12e-6 * math.sin(0.4 + 0.7 - math.radians(20)) + 12e-6 * math.sin(-0.2 + 0.7 - math.radians(20)))
    )
    # both gears enter with the same sign: the same installation offset on both
    # gears does not cancel (it would in the physical form)
    same = eccentricity_installation_error_sum_form(
        eccentricity_i=0, phase_i=0, omega_i=1, installation_i=10e-6, installation_phase_i=0.3,
        eccentricity_j=0, phase_j=0, omega_j=1, installation_j=10e-6, installation_phase_j=0.3, line_offset=c,
    )
    assert same.constant == pytest.approx(2 * 10e-6 * math.sin(-0.3 + c))


def test_seed004_thickness_pitch_and_bearing_errors():
    alpha = math.radians(20)
    # thinner tooth opens the mesh by (|ds|/2) cos(alpha)
    assert tooth_thickness_error(-6e-6, alpha).constant == pytest.approx(3e-6 * math.cos(alpha))
    angular = tooth_thickness_error(-6e-6, alpha).angular(0.02)
    assert angular.constant == pytest.approx(3e-6 * math.cos(alpha) / 0.02)
    cp = cumulative_pitch_error(6e-6, 0.0, 100.0, alpha)
    assert cp.amplitudes[0] == pytest.approx(3e-6 * math.cos(alpha)) and cp.omegas[0] == 100.0
    br = bearing_runout_error(6e-6, 0.0, 100.0, 0.0)
    assert br.amplitudes[0] == pytest.approx(3e-6) and br.omegas[0] == 100.0


@pytest.mark.parametrize("z", [15, 16])
def test_pitch_deviations_reproduced_at_each_tooth(z):
    rng = np.random.default_rng(3)
    cumulative = np.cumsum(rng.normal(0, 2e-6, z))
    omega, alpha = 400.0, math.radians(20)
    e = pitch_error_from_deviations(cumulative, omega, alpha)
    t_tooth = 2 * math.pi / (z * omega)
    t_mid = (np.arange(z) + 0.5) * t_tooth
    np.testing.assert_allclose(e.evaluate(t_mid), cumulative * math.cos(alpha), atol=1e-15)
    # periodic over one revolution
    np.testing.assert_allclose(e.evaluate(t_mid + 2 * math.pi / omega), e.evaluate(t_mid), atol=1e-15)
    assert e.omegas.max() <= z // 2 * omega + 1e-9


def test_bad_input_is_named():
    with pytest.raises(ModelError, match="equal"):
        LineOfActionDeviation(0.0, [1.0, 2.0], [1.0], [0.0])
    with pytest.raises(ValueError, match="one cumulative deviation per tooth"):
        pitch_error_from_deviations([1e-6] * 5, 10.0, 0.3, tooth_number=6)


def test_a_constant_deviation_is_normalised_as_a_general_one():
    """The constant-only fast path gives what the general path gives (-0.0 -> 0.0 too)."""
    from torquesplit.gears.errors import LineOfActionDeviation

    for c in (0.0, -0.0, 2.5e-6, -1e-5):
        fast = LineOfActionDeviation(c)
        general = LineOfActionDeviation(c, [0.0], [1.0], [0.3])  # a dropped zero term
        assert repr(fast.constant) == repr(general.constant)
        for name in ("amplitudes", "omegas", "phases"):
            assert getattr(fast, name).shape == (0,) == getattr(general, name).shape
            assert getattr(fast, name).dtype == np.float64


def test_normalised_terms_take_the_general_paths_values():
    """Terms already normalised (omega > 0, amplitude > 0: every sum and scaling of
    normalised deviations) skip the normalisation steps; the values, bit for bit, are
    those of the general path (here forced by a zero-amplitude term, which it drops)."""
    from torquesplit.gears.errors import LineOfActionDeviation

    rng = np.random.default_rng(3)
    for n in (1, 2, 5):
        a = rng.uniform(1e-7, 1e-5, n)
        w = rng.uniform(1.0, 5e3, n)
        p = rng.uniform(-12.0, 12.0, n)  # (some outside [-pi, pi): wrapped either way)
        for c in (0.0, -0.0, 3e-6):
            fast = LineOfActionDeviation(c, a, w, p)
            general = LineOfActionDeviation(c, np.append(a, 0.0), np.append(w, 7.0),
                                            np.append(p, 0.1))
            assert repr(fast.constant) == repr(general.constant)
            for name in ("amplitudes", "omegas", "phases"):
                assert getattr(fast, name).tobytes() == getattr(general, name).tobytes()
    src = np.array([2e-6])
    e = LineOfActionDeviation(0.0, src, [3.0], [0.2])
    src[0] = 9.0  # the deviation holds its own copy
    assert e.amplitudes[0] == 2e-6
