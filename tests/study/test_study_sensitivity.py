"""Sensitivity: the estimators on functions with known indices, and a model where one
factor dominates and one has no effect by construction."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from study_helpers import CYCLES
from torquesplit.study import run_study
from torquesplit.study.dataset import ranking
from torquesplit.study.design import Parameter
from torquesplit.study.paths import Field
from torquesplit.study.sensitivity import indices, sensitivity_design


def _design(method, k, **kw):
    spec = SimpleNamespace(method=method, seed=5, trajectories=kw.get("trajectories"),
                           levels=kw.get("levels"), samples=kw.get("samples"))
    factors = [(Parameter(f"x{i}", (Field(f"p{i}", None, False),), "set"), 0.0, 1.0, "linear")
               for i in range(k)]
    return sensitivity_design(spec, factors)


def test_morris_on_a_linear_function_gives_its_coefficients():
    d = _design("morris", 3, trajectories=12, levels=4)
    x = d.values
    y = 4.0 * x[:, 0] - 2.0 * x[:, 1] + 0.0 * x[:, 2]
    res = indices(d, y)
    np.testing.assert_allclose(res["mu_star"], [4.0, 2.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(res["mu"], [4.0, -2.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(res["sigma"], 0.0, atol=1e-12)
    assert d.n_cases == 12 * 4
    # every step changes exactly one factor by Delta = p / (2 (p - 1)) = 2/3
    steps = np.diff(x.reshape(12, 4, 3), axis=1)
    assert ((np.abs(steps) > 0).sum(axis=2) == 1).all()
    np.testing.assert_allclose(np.abs(steps).sum(axis=2), 2 / 3)


def test_sobol_indices_of_the_ishigami_function():
    d = _design("sobol", 3, samples=2048)
    x = -np.pi + 2 * np.pi * d.values  # Ishigami and Homma (1990), a = 7, b = 0.1
    y = np.sin(x[:, 0]) + 7 * np.sin(x[:, 1]) ** 2 + 0.1 * x[:, 2] ** 4 * np.sin(x[:, 0])
    res = indices(d, y)
    np.testing.assert_allclose(res["S1"], [0.3139, 0.4424, 0.0], atol=0.04)
    np.testing.assert_allclose(res["ST"], [0.5576, 0.4424, 0.2437], atol=0.04)
    assert (res["ST_conf"] > 0).all() and (res["ST_conf"] < 0.1).all()


def test_failed_cases_drop_their_trajectory():
    d = _design("morris", 2, trajectories=5)
    y = 3.0 * d.values[:, 0] + d.values[:, 1]
    y[4] = np.nan  # a failed case in trajectory 1
    res = indices(d, y)
    assert int(res["trajectories_used"]) == 4
    np.testing.assert_allclose(res["mu_star"], [3.0, 1.0], atol=1e-12)


def _study(model, method, **kw):
    factors = [
        # no effect: the pinion's density only sets a mass it does not have (theta only)
        {"path": "gears.pinion.density", "low": "7000 kg/m^3", "high": "8000 kg/m^3"},
        # small effect: a second-stage stiffness (both paths change the static split a bit)
        {"path": "meshes.b2.stiffness", "low": "3.5e8 N/m", "high": "4.5e8 N/m"},
        # dominant: an error in one path
        {"path": "meshes.a1.transmission_error.constant", "low": "0 um", "high": "10 um"},
    ]
    return {"study": {"name": "ranking", "model": str(model),
                      "outputs": ["load_sharing.cycle_peak", "static_force.a1"]},
            "analysis": {"cycles": CYCLES},
            "sensitivity": {"method": method, "seed": 2, "parameters": factors, **kw}}


@pytest.mark.parametrize("method,kw", [("morris", {"trajectories": 4}),
                                       ("sobol", {"samples": 16})])
def test_ranking_of_a_constructed_model(split_file, tmp_path, method, kw):
    from torquesplit.study.figures import write_study_figures

    ds = run_study(_study(split_file, method, **kw), workers=1)
    files = write_study_figures(ds, tmp_path, formats=("png",))
    assert {p.name for p in files} == {"tornado_load_sharing.cycle_peak.png",
                                       "tornado_static_force.a1.png"}
    for out in ("load_sharing.cycle_peak", "static_force.a1"):
        order = [name for name, _ in ranking(ds, out)]
        assert order == ["meshes.a1.transmission_error.constant", "meshes.b2.stiffness",
                         "gears.pinion.density"], (out, ranking(ds, out))
        key = ds.attrs["ranking"]
        none = ds[key].sel(output=out, factor="gears.pinion.density").item()
        assert none == 0.0
    # Morris's effects carry each output's unit (the force's in N); Sobol's are shares
    assert list(ds["output_unit"].values) == ["1", "N"]
    unit = "per output: see output_unit" if method == "morris" else "1"
    assert ds[key].attrs["units"] == unit
    assert ds.sizes["sample"] == (4 * 4 if method == "morris" else 16 * 5)
    # MATLAB gets the indices over (output, factor) and the ranking key (its .mat had
    # the cases only: a studies reviewer)
    from scipy.io import loadmat

    from torquesplit.study.dataset import case_mat_bytes

    (tmp_path / "s.mat").write_bytes(case_mat_bytes(ds))
    mat = loadmat(tmp_path / "s.mat", squeeze_me=True)
    assert mat["dimensions"][key].item() == "output x factor"
    np.testing.assert_array_equal(mat[key], ds[key].values)
    assert list(mat["factor"]) == list(ds["factor"].values)
    assert mat["attributes"]["ranking"].item() == key
    # and a spreadsheet: a row per output and factor with its rank and every index (they
    # were in the .nc and .mat only, a studies reviewer)
    import csv
    import io

    from torquesplit.study.dataset import indices_table_bytes

    rows = list(csv.DictReader(io.StringIO(indices_table_bytes(ds).decode())))
    assert len(rows) == 2 * 3
    for out in ("load_sharing.cycle_peak", "static_force.a1"):
        mine = sorted((r for r in rows if r["output"] == out), key=lambda r: int(r["rank"]))
        assert [r["factor"] for r in mine] == [name for name, _ in ranking(ds, out)]
    force = next(r for r in rows if r["output"] == "static_force.a1")
    assert force["output_unit"] == "N"
    index_columns = [k for k in rows[0] if k.split(" ")[0] in ds.data_vars]
    assert {k.split(" ")[0] for k in index_columns} >= (
        {"mu", "mu_star", "sigma", "mu_star_conf"} if method == "morris" else {"S1", "ST"})
    # the ranking table prints Morris's effect of a force in kN, with its unit (Rich read
    # an unescaped " [kN]" as markup and dropped it); Sobol's shares have none
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary

    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    text = cap.get()
    var = next(v for v in ds.data_vars if ds[v].attrs.get("output") == "static_force.a1")
    if method == "morris":
        mu = ds["mu_star"].sel(output="static_force.a1",
                               factor="meshes.a1.transmission_error.constant").item()
        assert f"{var} [kN]" in text and f"{1e-3 * mu:.3g}" in text, text
    else:
        assert f"{var} [" not in text
    # each factor with its interval (and Sobol's first-order index, Morris' mu and sigma
    # beside it): the summary gave the ranking's one number per factor only
    text = " ".join(text.split())
    dominant = dict(output="load_sharing.cycle_peak",
                    factor="meshes.a1.transmission_error.constant")
    keys = (("mu_star", "mu_star_conf"), ("mu", None), ("sigma", None)) if method == "morris" \
        else (("ST", "ST_conf"), ("S1", "S1_conf"))
    for key, conf in keys:
        x = ds[key].sel(**dominant).item()
        shown = f"{x:.3g}" + ("" if conf is None else f" +/- {ds[conf].sel(**dominant).item():.2g}")
        assert shown in text, (shown, text)


def _ishigami(d):
    x = -np.pi + 2 * np.pi * d.values
    return np.sin(x[:, 0]) + 7 * np.sin(x[:, 1]) ** 2 + 0.1 * x[:, 2] ** 4 * np.sin(x[:, 0])


@pytest.mark.parametrize("offset", [1.0, 1e3])
def test_sobol_indices_do_not_change_with_a_constant_added_to_the_output(offset):
    d = _design("sobol", 3, samples=256)
    y = _ishigami(d)
    plain = indices(d, y)
    shifted = indices(d, y + offset)  # e.g. a load-sharing coefficient, near 1
    for k in ("S1", "ST", "S1_conf", "ST_conf"):
        np.testing.assert_allclose(shifted[k], plain[k], atol=1e-9 * offset)
    np.testing.assert_allclose(shifted["S1"], [0.3139, 0.4424, 0.0], atol=0.12)
    assert (shifted["S1_conf"] < 0.3).all()


def test_sobol_of_an_additive_output_near_one():
    """y = 1 + 0.01 x0 + 0.02 x1: S1 = ST = (1/5, 4/5), whatever the constant."""
    d = _design("sobol", 2, samples=512)
    y = 1.0 + 0.01 * d.values[:, 0] + 0.02 * d.values[:, 1]
    res = indices(d, y)
    np.testing.assert_allclose(res["S1"], [0.2, 0.8], atol=0.03)
    np.testing.assert_allclose(res["ST"], [0.2, 0.8], atol=0.03)
    assert (res["S1_conf"] < 0.1).all()


def test_s1_above_st_beyond_the_intervals_is_a_warning():
    import xarray as xr

    from torquesplit.study.dataset import sobol_warnings

    ds = xr.Dataset({k: (("output", "factor"), np.array([v])) for k, v in {
        "S1": [0.9, 0.3], "ST": [0.5, 0.32], "S1_conf": [0.1, 0.1],
        "ST_conf": [0.1, 0.1]}.items()},
        coords={"output": ["y"], "factor": ["a", "b"]})
    notes = sobol_warnings(ds)
    assert len(notes) == 1 and "y: S1 of a (0.9" in notes[0] and "samples" in notes[0]


@pytest.mark.parametrize("s1, st, s1_conf, st_conf, said", [
    # a reviewer's 8 samples: S1 1.45 +/- 0.87, ST 1.25 +/- 0.55, said nothing
    ([1.447, 0.009], [1.25, 0.003], [0.87, 0.01], [0.55, 0.01],
     "the leading factor's total index is 1.25 +/- 0.55 (d1)"),
    ([0.9, 0.0], [1.3, 0.01], [0.05, 0.01], [0.1, 0.01],
     "ST of d1 1.3 +/- 0.1 outside [0, 1]"),
    ([0.95, 0.0], [1.01, 0.01], [0.05, 0.01], [0.05, 0.01], None),  # 1 within its interval
    ([-0.3, 0.5], [0.1, 0.6], [0.05, 0.05], [0.05, 0.05], "S1 of d1 -0.3 +/- 0.05 outside [0, 1]"),
    ([0.5, 0.3], [0.6, 0.35], [0.05, 0.05], [0.3, 0.05], "the leading factor's total index is "
                                                         "0.6 +/- 0.3 (d1)"),
    ([0.5, 0.3], [0.6, 0.35], [0.05, 0.05], [0.05, 0.05], None),  # converged: quiet
    ([0.5, -0.01], [0.6, 0.01], [0.05, 0.02], [0.05, 0.02], None),  # 0 within its interval
])
def test_sobol_indices_that_cannot_be_are_said(s1, st, s1_conf, st_conf, said):
    import xarray as xr

    from torquesplit.study.dataset import sobol_warnings

    ds = xr.Dataset({k: (("output", "factor"), np.array([v])) for k, v in {
        "S1": s1, "ST": st, "S1_conf": s1_conf, "ST_conf": st_conf}.items()},
        coords={"output": ["y"], "factor": ["d1", "backlash"]})
    notes = sobol_warnings(ds)
    if said is None:
        assert notes == []
    else:
        assert len(notes) == 1 and said in notes[0] and "raise sensitivity.samples" in notes[0]


def test_tornado_draws_each_interval_on_its_own_bar():
    import xarray as xr

    from torquesplit.study.figures import tornado_figure

    vals = {"S1": [0.2, 0.6], "ST": [0.3, 0.7], "S1_conf": [0.05, 0.01],
            "ST_conf": [0.02, 0.03]}
    ds = xr.Dataset({k: (("output", "factor"), np.array([v])) for k, v in vals.items()},
                    coords={"output": ["y"], "factor": ["a", "b"]},
                    attrs={"ranking": "ST", "study_name": "t"})
    ds["y"] = ("sample", np.zeros(2), {"output": "y"})
    ax = tornado_figure(ds, "y").axes[0]
    bars = {c.get_label(): c for c in ax.containers}
    for label, key in (("ST (total)", "ST"), ("S1 (first order)", "S1")):
        c = bars[label]
        assert c.errorbar is not None, label
        ends = sorted(np.ptp(seg[:, 0]) / 2 for seg in c.errorbar.lines[2][0].get_segments())
        np.testing.assert_allclose(ends, sorted(vals[f"{key}_conf"]))
        # the interval is centred on the end of its own bar
        centres = sorted(seg[:, 0].mean() for seg in c.errorbar.lines[2][0].get_segments())
        np.testing.assert_allclose(centres, sorted(vals[key]))
    assert ax.get_legend().get_title().get_text() == "whiskers: 95 % bootstrap interval"


def test_indices_over_fewer_rows_say_so(split_file, tmp_path):
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary

    ds = run_study(_study(split_file, "morris", trajectories=2), workers=1)
    assert ds["trajectories_used"].values.tolist() == [2, 2]
    assert ds["trajectories_used"].attrs["total"] == 2
    ds["trajectories_used"].values[0] = 1  # as if a case of one trajectory failed
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    assert "indices over 1 of 2 trajectories at the fewest" in cap.get()


def test_sobol_samples_must_be_a_power_of_2():
    """samples = 3 was accepted, though the docs say a power of 2 (the Sobol sequence is
    balanced only there)."""
    from torquesplit.study.spec import Sensitivity

    par = [{"path": "meshes.a1.damping_ratio", "low": 0.01, "high": 0.1},
           {"path": "meshes.b1.damping_ratio", "low": 0.01, "high": 0.1}]
    with pytest.raises(Exception, match="3 is not a power of 2.*give 2 or 4"):
        Sensitivity(method="sobol", seed=1, samples=3, parameters=par)
    assert Sensitivity(method="sobol", seed=1, samples=64, parameters=par).samples == 64


def test_tornado_of_a_force_draws_mu_star_in_the_unit_its_axis_names():
    """The axis read mu* [kN] while the bars were drawn in N: 1000 times too long."""
    import xarray as xr

    from torquesplit.study.figures import tornado_figure

    out = "peak_force.m1"
    ds = xr.Dataset({"mu_star": (("output", "factor"), [[2500.0, 400.0]]),
                     "mu_star_conf": (("output", "factor"), [[100.0, 50.0]])},
                    coords={"output": [out], "factor": ["a", "b"]},
                    attrs={"ranking": "mu_star", "study_name": "t"})
    ds[out] = ("sample", np.zeros(2), {"output": out, "units": "N"})
    ax = tornado_figure(ds, out).axes[0]
    assert ax.get_xlabel().endswith("[kN]")
    widths = sorted(p.get_width() for p in ax.patches)
    np.testing.assert_allclose(widths, [0.4, 2.5])


def test_a_long_title_is_wrapped_inside_the_figure():
    """A long model and study name ran the title off both edges of the figure."""
    import xarray as xr

    from torquesplit.study.figures import tornado_figure

    out = "peak_force.m1"
    ds = xr.Dataset({"mu_star": (("output", "factor"), [[2500.0, 400.0]]),
                     "mu_star_conf": (("output", "factor"), [[100.0, 50.0]])},
                    coords={"output": [out], "factor": ["a", "b"]},
                    attrs={"ranking": "mu_star", "study_name": "a rather long study " * 5,
                           "model_name": "ji_li_mill_drive with a long variant name " * 2})
    ds[out] = ("sample", np.zeros(2), {"output": out, "units": "N"})
    fig = tornado_figure(ds, out)
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    assert "\n" in fig._suptitle.get_text()


def test_a_factor_bound_that_makes_the_model_invalid_is_said_before_the_cases_run(
        split_file):
    """A studies user's Morris factor reached values the model refuses: 14 of 20 cases
    came back refused, said only after they ran (a grid says it before)."""
    from torquesplit.study import Study

    data = _study(split_file, "morris", trajectories=2)
    data["sensitivity"]["parameters"][1].update(low="-4e8 N/m", high="4e8 N/m")
    notes = Study(data).plan().notes
    assert any("gives an invalid model" in n and "meshes.b2.stiffness" in n
               and "recorded as refused" in n for n in notes), notes


def test_no_ranking_is_printed_where_no_index_could_be_computed(split_file, tmp_path):
    from torquesplit import cli as ui
    from torquesplit.study.cli import _summary

    ds = run_study(_study(split_file, "morris", trajectories=2), workers=1)
    ds["mu_star"].values[:] = np.nan  # as if every trajectory had lost a case
    with ui.console.capture() as cap:
        _summary(ds, tmp_path, False, False)
    text = cap.get()
    assert "none: no index could be computed" in text
    assert "gears.pinion.density nan" not in text



def test_a_sensitivity_folder_has_its_indices_for_a_spreadsheet(split_file, tmp_path):
    """results_sensitivity.csv beside results.csv; gone when a study of another design
    replaces it in the folder."""
    out = tmp_path / "o"
    run_study(_study(split_file, "morris", trajectories=2), workers=1, out=out, figures=False)
    table = out / "results_sensitivity.csv"
    assert table.is_file() and table.read_text().startswith("output,output_unit,factor,rank")
    grid = _study(split_file, "morris")
    del grid["sensitivity"]
    grid["grid"] = {"parameters": [{"path": "meshes.b2.stiffness", "values": ["4e8 N/m"]}]}
    run_study(grid, workers=1, out=out, overwrite=True, figures=False)
    assert (out / "results.csv").is_file() and not table.exists()
