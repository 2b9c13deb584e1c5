"""Tests of torquesplit.gears.backlash (seed 001 eq. 14)."""

import numpy as np
import pytest

from torquesplit.errors import ModelError
from torquesplit.gears.backlash import (
    BacklashSequence,
    backlash_from_tooth_thickness,
    constant_backlash,
    contact_loss,
    hunting_period_cycles,
    random_backlash,
)

# seed 001: first stage 19/168 teeth, band 0.522-0.851 mm, mesh frequency 235.91667 Hz
LOWER, UPPER, Z1, Z2 = 0.522e-3, 0.851e-3, 19, 168
T_MESH = 1 / 235.91667


def test_hunting_period_of_seed001_stages():
    assert hunting_period_cycles(Z1, Z2) == 3192  # as in seed 001 eq. 14
    assert hunting_period_cycles(17, 91) == 1547  # seed 001 prints 1530 for the second stage
    assert hunting_period_cycles(20, 30) == 60


def test_same_seed_same_sequence():
    a = random_backlash(LOWER, UPPER, Z1, Z2, T_MESH, 1234)
    b = random_backlash(LOWER, UPPER, Z1, Z2, T_MESH, np.random.default_rng(1234))
    c = random_backlash(LOWER, UPPER, Z1, Z2, T_MESH, 1235)
    np.testing.assert_array_equal(a.values, b.values)
    assert not np.array_equal(a.values, c.values)


def test_values_in_band_and_period():
    seq = random_backlash(LOWER, UPPER, Z1, Z2, T_MESH, 5)
    assert seq.values.min() >= LOWER and seq.values.max() <= UPPER
    assert seq.n_engagements == 3192
    assert seq.period == pytest.approx(3192 * T_MESH)
    t = np.linspace(0.0, 3 * seq.period, 5000)
    np.testing.assert_array_equal(seq.at(t), seq.at(t + seq.period))
    # piecewise constant per engagement
    k = 17
    inside = np.linspace(k * T_MESH + 1e-9, (k + 1) * T_MESH - 1e-9, 7)
    assert np.all(seq.at(inside) == seq.values[k])


def test_mean_and_std_as_requested():
    seq = random_backlash(0.0, 1e-3, 101, 199, 1e-3, 99, mean=0.5e-3, std=0.1e-3)  # 20099 draws
    assert seq.values.mean() == pytest.approx(0.5e-3, abs=3e-6)
    assert seq.values.std() == pytest.approx(0.1e-3, rel=0.03)
    default = random_backlash(LOWER, UPPER, 101, 199, 1e-3, 3)
    assert default.values.mean() == pytest.approx((LOWER + UPPER) / 2, abs=2e-6)
    assert default.values.std() == pytest.approx((UPPER - LOWER) / 6, rel=0.05)  # slightly below, truncated


def test_seed001_literal_sequence_opens_the_mesh():
    """Jumps of ~0.1 mm against a static deflection F/k of 44 um (2e5 N on
    4.5e9 N/m) open the mesh at a large fraction of the engagement changes."""
    seq = random_backlash(LOWER, UPPER, Z1, Z2, T_MESH, 0)
    report = contact_loss(seq, 2.0e5, 4.5e9)
    assert report.any and report.count > 0.2 * seq.n_engagements
    assert report.worst_margin < -0.1e-3
    # constant backlash never opens the mesh under a positive load
    assert not contact_loss(constant_backlash(0.6e-3, Z1, Z2, T_MESH), 2.0e5, 4.5e9).any


def test_contact_loss_by_hand():
    seq = BacklashSequence([0.60e-3, 0.70e-3, 0.65e-3, 0.64e-3], 1e-3)
    # jumps: +0.10, -0.05, -0.01, -0.04 mm; deflection 2e5/4.5e9 = 44.4 um
    report = contact_loss(seq, 2.0e5, 4.5e9)
    np.testing.assert_array_equal(report.lost, [True, False, False, False])
    assert report.margin[0] == pytest.approx(2e5 / 4.5e9 - 0.1e-3)


def test_backlash_from_tooth_thickness_repeats_over_hunting_period():
    rng = np.random.default_rng(1)
    s1, s2 = rng.normal(0, 5e-6, 4), rng.normal(0, 5e-6, 6)
    seq = backlash_from_tooth_thickness(0.1e-3, s1, s2, 1e-3, np.radians(20))
    assert seq.n_engagements == 12
    assert seq.values[0] == pytest.approx(0.1e-3 - 0.5 * (s1[0] + s2[0]) * np.cos(np.radians(20)))
    assert seq.values[5] == pytest.approx(0.1e-3 - 0.5 * (s1[1] + s2[5]) * np.cos(np.radians(20)))


def test_bad_input_is_named():
    with pytest.raises(ModelError, match="upper must exceed lower"):
        random_backlash(UPPER, LOWER, Z1, Z2, T_MESH, 0)
    with pytest.raises(ValueError, match="mesh_period"):
        BacklashSequence([1e-4], 0.0)
