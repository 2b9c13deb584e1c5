"""Monte Carlo: reproducible from the seed, samplers, ISO 1328 tolerances, stopping rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from study_helpers import mc_study
from torquesplit.gears.grades import flank_tolerances, sample_within
from torquesplit.study import Study, run_study
from torquesplit.study.design import iso_band, uniform_points

OUT = "load_sharing.cycle_peak"


def test_fixed_seed_reproducible_other_seed_differs(split_file):
    a = run_study(mc_study(split_file, samples=12, seed=3), workers=1)
    b = run_study(mc_study(split_file, samples=12, seed=3), workers=2)
    c = run_study(mc_study(split_file, samples=12, seed=4), workers=1)
    xr.testing.assert_identical(a.drop_vars("case_wall_time"), b.drop_vars("case_wall_time"))
    err = "meshes.a1.transmission_error.constant"
    assert a[err].attrs["units"] == "m" and a[err].dims == ("sample",)
    assert not np.array_equal(a[err].values, c[err].values)
    assert np.ptp(a[OUT].values) > 0.005  # the errors change the load sharing
    # the draws follow the distributions (uniform bounds exactly, normal roughly)
    k = a["meshes.b2.stiffness"].values
    assert k.min() >= 3e8 and k.max() <= 5e8


@pytest.mark.parametrize("sampling", ["sobol", "latin_hypercube"])
def test_quasi_random_samplers(sampling):
    u = uniform_points(sampling, 16, 2, seed=1)
    assert u.shape == (16, 2) and (u >= 0).all() and (u < 1).all()
    if sampling == "latin_hypercube":  # one point per stratum in every dimension
        for j in range(2):
            assert sorted(np.floor(u[:, j] * 16).astype(int)) == list(range(16))
    else:  # the first 8 points do not depend on how many are drawn
        np.testing.assert_array_equal(uniform_points(sampling, 8, 2, seed=1), u[:8])
    np.testing.assert_array_equal(uniform_points(sampling, 16, 2, seed=1), u)


@pytest.mark.parametrize("shape", ["normal", "uniform"])
@pytest.mark.parametrize("signed", [True, False])
def test_iso_band_follows_grades_sample_within(shape, signed):
    tol = flank_tolerances(6, 3e-3, 0.09, 0.03).runout
    rng = np.random.default_rng(11)
    expected = sample_within(tol, 500, np.random.default_rng(11), shape, signed=signed)
    got = iso_band(rng.random(500), tol, shape, signed)
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=0)


def test_iso1328_distribution_uses_the_gears_tolerance(split_file):
    data = mc_study(split_file, samples=64)
    data["monte_carlo"]["parameters"] = [
        {"path": "gears.*.errors.eccentricity", "distribution": "iso1328", "grade": 7},
    ]
    plan = Study(data).plan()
    names = [p.name for p in plan.design.parameters]
    assert names[0] == "gears.pinion.errors.eccentricity" and len(names) == 6  # one per gear
    for j, p in enumerate(plan.design.parameters):
        gear = p.name.split(".")[1]
        teeth = {"pinion": 20, "a": 40, "b": 40, "a2": 20, "b2": 20, "out": 60}[gear]
        half_runout = 0.5 * flank_tolerances(7, 2e-3, teeth * 2e-3, 20e-3).runout
        x = plan.design.values[:, j]
        assert x.min() >= 0 and x.max() <= half_runout
        assert x.max() > 0.5 * half_runout  # the band is used, not a sliver of it


def test_stopping_rule_stops_when_interval_is_narrow(split_file):
    stop = {"output": OUT, "statistic": "mean", "half_width": 0.01, "confidence": 0.95,
            "min_samples": 16, "batch": 8, "max_samples": 400}
    ds = run_study(mc_study(split_file, stop=stop, sampling="sobol"), workers=1)
    n = ds.sizes["sample"]
    assert 16 < n < 400 and (n - 16) % 8 == 0
    x = ds[OUT].values

    def half_width(v):
        return stats.t.ppf(0.975, v.size - 1) * v.std(ddof=1) / math.sqrt(v.size)

    assert half_width(x) <= 0.01 < half_width(x[: n - 8])
    assert ds.attrs["stopped_at"] == n
    # the decision depends on the samples only, not on the workers
    again = run_study(mc_study(split_file, stop=stop, sampling="sobol"), workers=2)
    xr.testing.assert_identical(ds.drop_vars("case_wall_time"),
                                again.drop_vars("case_wall_time"))


def test_percentile_interval_is_distribution_free():
    from torquesplit.study.core import confidence_half_width

    rng = np.random.default_rng(0)
    x = rng.normal(size=2000)
    half, est = confidence_half_width(x, "p95", 0.95)
    assert est == pytest.approx(1.645, abs=0.1) and 0.01 < half < 0.15
    half_small, _ = confidence_half_width(x[:20], "p95", 0.95)
    assert half_small == math.inf  # 20 samples cannot bound a 95th percentile


def test_latin_hypercube_cannot_stop_early(split_file):
    from torquesplit.study import StudyError

    stop = {"output": OUT, "half_width": 0.01, "max_samples": 100}
    with pytest.raises(StudyError, match="monte_carlo.sampling: a Latin hypercube"):
        Study(mc_study(split_file, stop=stop, sampling="latin_hypercube"))
