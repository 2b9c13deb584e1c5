"""Tests of torquesplit.gears.grades (ISO 1328-1:2013)."""

import math

import numpy as np
import pytest

from torquesplit.errors import ModelError
from torquesplit.gears.grades import (
    flank_tolerances,
    grade_factor,
    round_tolerance,
    runout_tolerance,
    sample_gear_errors,
    sample_pitch_deviations,
    sample_within,
    single_pitch_tolerance,
)

UM = 1e-6
# seed 000 second-stage spur pinion: m_n = 3.5 mm, z = 34, d = 119 mm, b = 52 mm
M, D, B = 3.5e-3, 0.119, 0.052


def test_grade5_by_hand():
    """ISO 1328-1:2013 eqs. (5)-(12) at grade 5, d = 119 mm, m_n = 3.5 mm, b = 52 mm.

    f_pT  = 0.001*119 + 0.4*3.5 + 5                 = 6.519 um
    F_pT  = 0.002*119 + 0.55*sqrt(119) + 0.7*3.5 + 12 = 0.238 + 5.99979 + 2.45 + 12 = 20.68779 um
    f_HaT = 0.4*3.5 + 0.001*119 + 4                 = 5.519 um
    f_faT = 0.55*3.5 + 5                            = 6.925 um
    F_aT  = sqrt(5.519^2 + 6.925^2)                 = 8.85522 um
    f_HbT = 0.05*sqrt(119) + 0.35*sqrt(52) + 4      = 0.54544 + 2.52389 + 4 = 7.06932 um
    f_fbT = 0.07*sqrt(119) + 0.45*sqrt(52) + 4      = 0.76361 + 3.24500 + 4 = 8.00861 um
    F_bT  = sqrt(7.06932^2 + 8.00861^2)             = 10.68237 um
    F_rT  = 0.9 * 20.68779                          = 18.61901 um
    """
    t = flank_tolerances(5, M, D, B)
    assert t.single_pitch / UM == pytest.approx(6.519, abs=1e-9)
    assert t.total_cumulative_pitch / UM == pytest.approx(20.68779, abs=1e-5)
    assert t.profile_slope / UM == pytest.approx(5.519, abs=1e-9)
    assert t.profile_form / UM == pytest.approx(6.925, abs=1e-9)
    assert t.profile_total / UM == pytest.approx(8.85522, abs=1e-5)
    assert t.helix_slope / UM == pytest.approx(7.06932, abs=1e-5)
    assert t.helix_form / UM == pytest.approx(8.00861, abs=1e-5)
    assert t.helix_total / UM == pytest.approx(10.68237, abs=1e-5)
    assert t.runout / UM == pytest.approx(18.61901, abs=1e-5)
    r = t.rounded()  # 5.2.3: >10 um -> 1 um, 5-10 um -> 0.5 um
    rounded = (r.single_pitch / UM, r.total_cumulative_pitch / UM, r.profile_total / UM)
    assert rounded == pytest.approx((6.5, 21.0, 9.0))


def test_sqrt2_step_between_grades():
    t5 = flank_tolerances(5, M, D, B)
    for grade in range(1, 12):
        t = flank_tolerances(grade, M, D, B)
        ratio = math.sqrt(2) ** (grade - 5)
        assert grade_factor(grade) == pytest.approx(ratio)
        for name in ("single_pitch", "total_cumulative_pitch", "profile_total", "helix_total", "runout"):
            assert getattr(t, name) == pytest.approx(getattr(t5, name) * ratio)
    assert single_pitch_tolerance(6, M, D) / single_pitch_tolerance(5, M, D) == pytest.approx(math.sqrt(2))


def test_rounding_rules():
    assert round_tolerance(12.4e-6) == pytest.approx(12e-6)
    assert round_tolerance(12.5e-6) == pytest.approx(13e-6)
    assert round_tolerance(7.3e-6) == pytest.approx(7.5e-6)
    assert round_tolerance(7.2e-6) == pytest.approx(7.0e-6)
    assert round_tolerance(3.44e-6) == pytest.approx(3.4e-6)


def test_seed000_table2_is_about_half_the_grade5_runout():
    """Seed 000 Table 2 ('grade 5'): eccentricity = installation error = 8, 12, 8 um
    for the 34-tooth spur pinion, the 107-tooth spur gear and the 23-tooth
    double-helical pinion.  An offset e gives a runout of 2 e; F_rT / 2 at
    grade 5 is 9.3, 11.6, 9.3 um: the seed's values are within 15 %."""
    cases = [  # (m_n, d, seed value)
        (3.5e-3, 3.5e-3 * 34, 8e-6),
        (3.5e-3, 3.5e-3 * 107, 12e-6),
        (3.965e-3, 3.965e-3 * 23 / math.cos(math.radians(30)), 8e-6),
    ]
    for m, d, seed in cases:
        half_runout = runout_tolerance(5, m, d) / 2
        assert seed / half_runout == pytest.approx(1.0, abs=0.15)


def test_sampler_reproducible_and_within_tolerance():
    a = sample_gear_errors(5, M, D, B, 2000, 11)
    b = sample_gear_errors(5, M, D, B, 2000, np.random.default_rng(11))
    np.testing.assert_array_equal(a.runout, b.runout)
    np.testing.assert_array_equal(a.eccentricity_phase, b.eccentricity_phase)
    t = a.tolerances
    assert np.all((0 <= a.runout) & (a.runout <= t.runout))
    np.testing.assert_allclose(a.eccentricity, a.runout / 2)
    assert np.all(np.abs(a.single_pitch) <= t.single_pitch)
    assert np.all((0 <= a.total_cumulative_pitch) & (a.total_cumulative_pitch <= t.total_cumulative_pitch))
    assert np.all(np.abs(a.helix_slope) <= t.helix_slope)
    assert np.all((0 <= a.eccentricity_phase) & (a.eccentricity_phase < 2 * np.pi))
    # a different seed gives different draws
    assert not np.array_equal(a.runout, sample_gear_errors(5, M, D, B, 2000, 12).runout)


def test_sampler_distributions():
    tol = 10e-6
    u = sample_within(tol, 20000, 1, "uniform")
    assert u.std() == pytest.approx(2 * tol / math.sqrt(12), rel=0.03)
    n = sample_within(tol, 20000, 1, "normal")
    assert np.abs(n).max() <= tol
    assert n.std() == pytest.approx(tol / 3, rel=0.05)
    mag = sample_within(tol, 20000, 1, "uniform", signed=False)
    assert mag.min() >= 0 and mag.mean() == pytest.approx(tol / 2, rel=0.03)
    with pytest.raises(ModelError, match="distribution"):
        sample_within(tol, 10, 1, "lognormal")


def test_pitch_deviations_close_and_stay_within_tolerance():
    single, cumulative = sample_pitch_deviations(5, M, D, 34, 4)
    assert single.sum() == pytest.approx(0.0, abs=1e-18)
    assert np.all(np.abs(single) <= single_pitch_tolerance(5, M, D) + 1e-18)
    assert np.ptp(cumulative) <= flank_tolerances(5, M, D, B).total_cumulative_pitch + 1e-18


def test_scope_and_grade_checks():
    with pytest.raises(ModelError, match="grade"):
        flank_tolerances(12, M, D, B)
    with pytest.raises(ValueError, match="module"):
        flank_tolerances(5, 3.5, D, B)  # module given in mm by mistake
