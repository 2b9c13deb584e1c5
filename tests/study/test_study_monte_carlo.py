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
        assert p.display_unit == "um"  # (tolerances are microns; it showed metres)


def test_a_shared_iso1328_value_of_gears_with_other_tolerances_is_refused(split_file):
    """One value shared by gears of 20 and 40 teeth took the first gear's tolerance for
    both: the other's errors were drawn outside its own band, by path order."""
    from torquesplit.errors import StudyError

    data = mc_study(split_file, samples=16)
    par = {"paths": ["gears.pinion.errors.eccentricity", "gears.a.errors.eccentricity"],
           "distribution": "iso1328", "grade": 7, "shared": True, "name": "ecc"}
    data["monte_carlo"]["parameters"] = [par]
    with pytest.raises(StudyError, match="shared.*tolerances differ.*gear = \"pinion\""):
        Study(data).plan()
    par["gear"] = "a"  # named: that gear's band bounds the shared value
    plan = Study(data).plan()
    runout = flank_tolerances(7, 2e-3, 40 * 2e-3, 20e-3).runout
    assert plan.design.values.max() <= 0.5 * runout
    par.pop("gear")  # gears of one size share their tolerance: fine
    par["paths"] = ["gears.a.errors.eccentricity", "gears.b.errors.eccentricity"]
    assert Study(data).plan().design.values.shape == (16, 1)


@pytest.mark.parametrize("path", ["gears.a.face_width", "meshes.a1.backlash"])
def test_an_iso1328_grade_on_a_field_that_is_not_a_gear_deviation_is_refused(split_file,
                                                                            path):
    """A studies user drew a shaft's diameter from a gear's runout tolerance (3-34 um):
    every case ran, and lost contact."""
    from torquesplit.errors import StudyError

    data = mc_study(split_file, samples=4)
    data["monte_carlo"]["parameters"] = [
        {"path": path, "distribution": "iso1328", "grade": 7, "gear": "pinion",
         "tolerance": "runout"}]
    with pytest.raises(StudyError, match=r"ISO 1328-1 grade bounds a gear's manufacturing "
                                         r"deviations .*not " + path.replace(".", r"\.")):
        Study(data).plan()


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


@pytest.mark.parametrize("confidence", [0.8, 0.95])
def test_percentile_interval_covers_at_least_its_confidence_and_says_its_bounds(confidence):
    """The order-statistic ranks must cover the 95th percentile with at least the
    confidence (exactly, from the binomial law): at n = 96 they covered 0.9416 < 0.95; the
    interval is not centred on the estimate (it was reported as +/- h), and a valid one
    exists from 59 samples (below 73 it was infinite)."""
    from torquesplit.study.core import confidence_interval

    rng = np.random.default_rng(1)
    for n in list(range(59, 130)) + [200, 256, 1000]:
        x = np.sort(rng.lognormal(size=n))
        half, est, lo, hi = confidence_interval(x, "p95", confidence)
        assert np.isfinite(half) and lo <= est <= hi and half == pytest.approx((hi - lo) / 2)
        l, u = int(np.searchsorted(x, lo)), int(np.searchsorted(x, hi))
        cdf = stats.binom.cdf([l, u], n, 0.95)
        assert cdf[1] - cdf[0] >= confidence - 1e-12, n
    assert confidence_interval(rng.normal(size=58), "p95", 0.95)[0] == math.inf
    half, est, lo, hi = confidence_interval(rng.normal(size=40), "mean", 0.95)
    assert hi - est == pytest.approx(est - lo) == pytest.approx(half)


def test_latin_hypercube_cannot_stop_early(split_file):
    from torquesplit.study import StudyError

    stop = {"output": OUT, "half_width": 0.01, "max_samples": 100}
    with pytest.raises(StudyError, match="monte_carlo.sampling: a Latin hypercube"):
        Study(mc_study(split_file, stop=stop, sampling="latin_hypercube"))


@pytest.mark.parametrize("table,where", [
    ({"distribution": "normal", "mean": "2 um", "std": "3 um"},
     "monte_carlo.parameters.0.distribution"),
    ({"distribution": "uniform", "low": "-1 um", "high": "3 um"}, "monte_carlo.parameters.0.low"),
    ({"distribution": "truncated_normal", "mean": "0 um", "std": "3 um", "low": "-5 um",
      "high": "5 um"}, "monte_carlo.parameters.0.low")])
def test_a_distribution_drawing_values_the_field_refuses_is_refused(split_file, table, where):
    from torquesplit.study import StudyError

    data = mc_study(split_file, samples=8)
    data["monte_carlo"]["parameters"] = [{"path": "gears.pinion.errors.eccentricity", **table}]
    with pytest.raises(StudyError) as info:
        Study(data).plan()
    msg = str(info.value)
    assert where in msg and "gears.pinion.errors.eccentricity refuses" in msg
    if table["distribution"] == "normal":
        assert "truncated_normal" in msg
    # far from zero, or truncated at zero: accepted
    ok = {"distribution": "truncated_normal", "mean": "0 um", "std": "3 um", "low": "0 um",
          "high": "5 um"}
    for t in (ok, {"distribution": "normal", "mean": "60 um", "std": "3 um"}):
        data["monte_carlo"]["parameters"] = [{"path": "gears.pinion.errors.eccentricity", **t}]
        Study(data).plan()


def test_statistics_over_fewer_cases_say_so(split_file, tmp_path):
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary
    from torquesplit.study.figures import monte_carlo_figure

    ds = run_study(mc_study(split_file, samples=8), workers=1)
    ds[OUT].values[[2, 5]] = np.nan  # two cases without a value (refused, say)
    ds["status"].values[[2, 5]] = "refused"
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    assert "statistics over 6 of 8 cases" in cap.get()
    fig = monte_carlo_figure(ds, OUT)
    title = fig._suptitle.get_text()
    assert "statistics over 6 of 8 cases" in title
    # a case whose teeth separate keeps its values: said apart from the failed ones (a
    # reviewer's title read '4 of 4 cases not ok' over statistics of all four)
    ds["status"] = ds["status"].astype(object)  # (room for the longer name)
    ds["status"].values[0] = "contact_lost"
    title = monte_carlo_figure(ds, OUT)._suptitle.get_text()
    assert "(1 lost contact and 2 failed of 8 cases)" in title, title
    # and the summary says that the statistics hold it (a reviewer averaged four)
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    assert "1 of these 8 cases lost contact (status contact_lost): their values are in " \
           "the statistics" in " ".join(cap.get().split()), cap.get()
    # counts on whole-number ticks; no 95th percentile of fewer than 20 samples (it is
    # their largest), nor its legend entry
    ticks = fig.axes[0].get_yticks()
    assert np.all(ticks == np.round(ticks)), ticks
    labels = [t.get_text() for t in fig.axes[2].get_legend().texts]
    assert not any("95th percentile" in t for t in labels), labels
    assert fig.axes[1].get_ylabel() == "cumulative probability [-]"


def test_stopping_rule_outcome_is_reported(split_file, tmp_path):
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary, stopping_line
    from torquesplit.study.figures import monte_carlo_figure

    stop = {"output": OUT, "statistic": "mean", "half_width": 0.01, "confidence": 0.95,
            "min_samples": 16, "batch": 8, "max_samples": 400}
    ds = run_study(mc_study(split_file, stop=stop, sampling="sobol"), workers=1)
    a = ds.attrs
    assert a["stopping_target_met"] == 1 and a["stopping_cases"] == ds.sizes["sample"]
    assert a["stopping_half_width"] <= a["stopping_target"] == 0.01
    assert a["stopping_estimate"] == pytest.approx(float(ds[OUT].mean()))
    assert a["stopping_upper"] - a["stopping_lower"] == pytest.approx(2 * a["stopping_half_width"])
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    assert "stopping rule: mean of load_sharing.cycle_peak" in cap.get()
    assert "target met" in cap.get() and "95% interval)" in cap.get()
    assert ", +/- " in cap.get()  # a mean's interval is centred: said so (it gave the ends)
    # --json names the watched output and its unit (bare numbers, a reviewer)
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        _summary(ds, tmp_path, True, False)
    import json  # (imported again below, so local here)

    rule = json.loads(buffer.getvalue())["stopping_rule"]
    assert rule["output"] == OUT and rule["units"] == ds[OUT].attrs["units"]
    assert rule["estimate"] == a["stopping_estimate"]
    labels = [t.get_text() for t in monte_carlo_figure(ds, OUT).axes[2].get_legend().texts]
    assert any(t.startswith("stopping target +/-0.01 (mean, met)") for t in labels)
    assert "95% interval at the stop" in labels
    # the running mean's band at the rule's confidence (it was 95 % for any rule)
    from torquesplit.study.figures import _confidence

    ds.attrs["stopping_rule"] = ds.attrs["stopping_rule"].replace('"confidence": 0.95',
                                                                  '"confidence": 0.8')
    assert _confidence(ds) == 0.8
    # a rule that runs out of samples says so, and a count of values left out
    stop.update(half_width=1e-6, max_samples=24)
    ds = run_study(mc_study(split_file, stop=stop, sampling="sobol"), workers=1)
    assert ds.attrs["stopping_target_met"] == 0 and ds.sizes["sample"] == 24
    assert "target NOT met: max_samples = 24 reached" in stopping_line(ds)
    ds.attrs["stopping_finite_cases"] = 22
    assert "over 22 of 24 cases (2 without a finite value left out)" in stopping_line(ds)
    # a force in kN, as the table above it prints forces (it printed N, with no unit)
    import json

    rule = json.loads(ds.attrs["stopping_rule"])
    ds.attrs["stopping_rule"] = json.dumps(dict(rule, output="peak_force.a1"))
    line = stopping_line(ds)
    assert f"= {1e-3 * ds.attrs['stopping_estimate']:.6g} kN, " in line
    assert f"target half-width {1e-3 * ds.attrs['stopping_target']:.3g} kN" in line


def test_the_statistics_table_of_a_force_says_its_unit(split_file, tmp_path):
    """The Monte Carlo table printed a force in kN without its unit: Rich read the
    unescaped " [kN]" as markup and dropped it, while results.nc holds N."""
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary

    ds = run_study(mc_study(split_file, samples=4, outputs=("peak_force.a1",)), workers=1)
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    var = next(v for v in ds.data_vars if ds[v].attrs.get("output") == "peak_force.a1")
    row = next(ln for ln in cap.get().splitlines() if var in ln)
    assert f"{var} [kN]" in row
    assert f"{1e-3 * float(ds[var].mean()):.6g}" in row


def test_a_percentile_rule_that_cannot_stop_is_refused(split_file):
    """max_samples below 59 can never bound a 95th percentile at 95 %: the rule ran to its
    end and advised widening half_width, which cannot help."""
    from torquesplit.study import StudyError

    stop = {"output": OUT, "statistic": "p95", "half_width": 0.01, "confidence": 0.95,
            "min_samples": 16, "batch": 8, "max_samples": 48}
    with pytest.raises(StudyError, match="max_samples: 48 samples cannot bound a 95th "
                                         "percentile with 95% confidence \\(it takes 59\\)"):
        Study(mc_study(split_file, stop=stop)).plan()


def test_a_stopping_half_width_takes_the_outputs_unit():
    """half_width = "1 kN" was refused as not a number, and a bare number's unit (the
    output's SI one) was said nowhere."""
    from torquesplit.study import Study
    from torquesplit.study.errors import StudyError

    def spec(half_width, output="peak_force.m11", relative=False):
        return {"study": {"name": "t", "model": "ji_li_mill_drive", "outputs": [output]},
                "analysis": {"cycles": 20},
                "monte_carlo": {"seed": 1, "parameters": [
                    {"path": "meshes.m11.backlash", "distribution": "uniform",
                     "low": "0.5 mm", "high": "1 mm"}],
                    "stop": {"output": output, "half_width": half_width, "max_samples": 40,
                             "min_samples": 8, "batch": 8, "relative": relative}}}

    assert Study(spec("1 kN")).plan().spec.monte_carlo.stop.half_width == 1000.0
    assert Study(spec(250)).plan().spec.monte_carlo.stop.half_width == 250.0
    with pytest.raises(StudyError, match=r"monte_carlo.stop.half_width: '1 kg' is not a force"):
        Study(spec("1 kg")).plan()
    with pytest.raises(StudyError, match=r"half_width: write a plain number"):
        Study(spec("1 kN", output="load_sharing.cycle_peak")).plan()
    # a relative half-width is a fraction: '1 kN' was read as 1000 x |statistic|, which
    # every Monte Carlo met at its first check (a studies reviewer)
    with pytest.raises(StudyError, match=r"half_width: with relative = true the half-width "
                                         r"is a fraction of \|statistic\|: write a plain "
                                         r"number \(0.01 for 1 %\), got '1 kN'"):
        Study(spec("1 kN", relative=True)).plan()
    assert Study(spec("0.02", relative=True)).plan().spec.monte_carlo.stop.half_width == 0.02
    assert Study(spec(0.02, relative=True)).plan().spec.monte_carlo.stop.half_width == 0.02


def test_a_shared_value_of_several_fields_needs_a_name(split_file):
    """Its coordinate was named after its first field (gears.z2.errors.pitch for z2 and
    z3), as a grid parameter of several fields would not be (a studies reviewer)."""
    from torquesplit.errors import StudyError

    data = mc_study(split_file, samples=4)
    par = {"paths": ["gears.a.errors.eccentricity", "gears.b.errors.eccentricity"],
           "distribution": "uniform", "low": "0 um", "high": "5 um", "shared": True}
    data["monte_carlo"]["parameters"] = [par]
    with pytest.raises(StudyError, match=r"parameters\.0\.name: a shared value that sets "
                                         r"several fields needs a name"):
        Study(data).plan()
    par["name"] = "ecc_ab"
    assert [p.name for p in Study(data).plan().design.parameters] == ["ecc_ab"]
    par.pop("name")
    par["shared"] = False  # one draw each: each its field's name
    assert [p.name for p in Study(data).plan().design.parameters] == [
        "gears.a.errors.eccentricity", "gears.b.errors.eccentricity"]


def test_a_whole_number_field_is_recorded_as_the_case_ran_it(tmp_path):
    """A uniform draw of teeth ran each case with the rounded value but recorded the draw
    (20.236 teeth) in results.csv and .nc (a fuzzer)."""
    from tests.model_texts import SPUR_PAIR

    pair = tmp_path / "pair.toml"
    pair.write_text(SPUR_PAIR)
    data = mc_study(pair, samples=6)
    data["monte_carlo"]["parameters"] = [
        {"path": "gears.pinion.teeth", "distribution": "uniform", "low": 18, "high": 22}]
    plan = Study(data).plan()
    drawn = plan.design.values[:, 0]
    assert (drawn == np.round(drawn)).all() and len(set(drawn)) > 1
    assert all(plan.design.parameters[0].overrides(v)["gears.pinion.teeth"] == v
               for v in drawn)
