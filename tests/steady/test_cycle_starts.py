"""The steady state's per-cycle extremes at cycle starts equal the integrator's rule (its
numpy twins): the force, and the load-sharing ratio of the forces, interpolated at each
cycle start between two instants enter both cycles."""

import numpy as np

from torquesplit.solve.reference import (
    cycle_index_numpy,
    cycle_ratio_numpy,
    cycle_statistics_numpy,
)
from torquesplit.steady.api import boundary_extremes, boundary_ratios, cycle_extremes

F, PHASE, T0 = 1000.0, 0.37, 0.0


def _series():
    """Two members' forces at 23 instants per 1 kHz cycle (not on the cycle starts), one
    rising and one falling monotonically (40 Hz waves short of their extremes), so that
    every cycle's extremes sit at its ends."""
    t = np.linspace(0.0, 0.006, 139)[:-1] + 1.3e-6
    f = np.stack([1000.0 + 300.0 * np.sin(2 * np.pi * 40 * t),
                  1000.0 - 200.0 * np.sin(2 * np.pi * 40 * t - 0.5)], axis=1)
    return t, f


def _cycles(t):
    base = cycle_index_numpy(F * T0 + PHASE)
    return (cycle_index_numpy(F * t + PHASE) - base).astype(np.int64), base


def test_boundary_extremes_equal_the_twin():
    t, f = _series()
    idx, base = _cycles(t)
    n = int(idx.max()) + 1
    mx, mn = cycle_extremes(f[:, 0], idx, n)
    boundary_extremes(t, f[:, 0], (base - PHASE) / F, 1.0 / F, mx, mn)
    cmax, cmin, _, _ = cycle_statistics_numpy(t, f[:, 0], F, PHASE, T0, n,
                                              continuous_start=True)
    plain = cycle_statistics_numpy(t, f[:, 0], F, PHASE, T0, n)[0]
    np.testing.assert_allclose(mx, cmax, rtol=1e-14)
    np.testing.assert_allclose(mn, cmin, rtol=1e-14)
    assert np.sum(mx > plain + 1e-9) > 3


def test_boundary_ratios_equal_the_twin():
    t, f = _series()
    idx, base = _cycles(t)
    n = int(idx.max()) + 1
    freq, ph = np.full(2, F), np.full(2, PHASE)
    want_max, want_min = cycle_ratio_numpy(t, f, freq, ph, T0, n, group_min=10.0,
                                           continuous_start=[True, True])
    plain = cycle_ratio_numpy(t, f, freq, ph, T0, n, group_min=10.0)[0]
    for j in range(2):
        ratio = 2 * f[:, j] / f.sum(axis=1)
        mx, mn = cycle_extremes(ratio, idx, n)
        boundary_ratios(t, f, j, (base - PHASE) / F, 1.0 / F, 10.0, mx, mn)
        np.testing.assert_allclose(mx, want_max[:, j], rtol=1e-14)
        np.testing.assert_allclose(mn, want_min[:, j], rtol=1e-14)
        assert np.sum(mx > plain[:, j] + 1e-9) > 3
