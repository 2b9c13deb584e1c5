"""The column-by-column sums and maxima of a group's per-cycle values equal numpy's
reductions over the members' axis bit for bit (signed zeros, NaN, infinities too)."""

from __future__ import annotations

import numpy as np
import pytest

from torquesplit.metrics import load_sharing as ls


def _values(rng, n, specials=True):
    x = rng.standard_normal((500, n)) * 10.0 ** rng.integers(-6, 6, (500, n))
    if specials:
        for v, p in ((np.nan, 0.05), (0.0, 0.03), (-0.0, 0.03), (np.inf, 0.01),
                     (-np.inf, 0.01), (1e308, 0.01)):
            x[rng.random((500, n)) < p] = v
    return x


@pytest.mark.parametrize("n", range(1, 10))
def test_row_sums_and_ratios_are_numpys(n):
    rng = np.random.default_rng(n)
    for _ in range(10):
        x = _values(rng, n)
        with np.errstate(all="ignore"):
            s = x.sum(axis=-1, keepdims=True)
            assert ls._row_sums(x).tobytes() == s.tobytes()
            expected = n * x / np.where(s != 0, s, np.nan)
            assert ls._ratio(x).tobytes() == expected.tobytes()


@pytest.mark.parametrize("n", range(1, 10))
def test_row_maxima_are_numpys(n):
    rng = np.random.default_rng(100 + n)
    for _ in range(10):
        x = _values(rng, n)
        x = x[np.all(np.isfinite(x), axis=-1)]  # (as the dynamic factors take them)
        assert ls._row_max(x).tobytes() == x.max(axis=-1).tobytes()
