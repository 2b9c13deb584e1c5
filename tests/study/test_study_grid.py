"""Grids: the same numbers as runs done one by one, any number of workers, failed cases."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import torquesplit
from study_helpers import CYCLES, grid_study
from torquesplit.model.io import load_model, model_from_dict
from torquesplit.model.overrides import read_raw, set_parameter
from torquesplit.study import Study, output_values, run_study

STIFFNESS = {"path": "meshes.a1.stiffness", "start": "2e8 N/m", "stop": "6e8 N/m", "num": 4}
ERROR = {"path": "meshes.b1.transmission_error.constant", "values": ["0 um", "8 um"]}


def test_grid_equals_runs_one_by_one(split_file):
    ds = run_study(grid_study(split_file, [STIFFNESS], outputs=["load_sharing.*",
                                                                  "peak_force.*"]),
                   workers=1)
    names = [ds[v].attrs["output"] for v in ds.data_vars if "output" in ds[v].attrs]
    k = ds["meshes.a1.stiffness"]
    assert k.attrs["units"] == "N/m" and k.values.tolist() == [2e8, 2e8 + 4e8 / 3,
                                                               2e8 + 8e8 / 3, 6e8]
    raw = read_raw(split_file)
    for i, value in enumerate(np.linspace(2e8, 6e8, 4)):
        model = load_model(model_from_dict(set_parameter(raw, "meshes.a1.stiffness", value)))
        expected = output_values(torquesplit.simulate(model, cycles=CYCLES))
        for name in names:
            got = float(ds[name].values[i])
            assert got == expected[name] or (np.isnan(got) and np.isnan(expected[name])), name
    # the grid does change the answer (a test that could fail)
    assert np.ptp(ds["peak_force.a1"].values) > 1.0


def test_one_and_two_workers_identical(split_file, tmp_path):
    from torquesplit.study.figures import write_study_figures

    study = Study(grid_study(split_file, [STIFFNESS, ERROR]))
    one = study.run(workers=1)
    two = study.run(workers=2)
    maps = write_study_figures(one, tmp_path, formats=("png",))
    assert [p.name for p in maps] == ["map_load_sharing.cycle_peak.png"]
    assert one["load_sharing.cycle_peak"].shape == (4, 2)
    xr.testing.assert_identical(one.drop_vars("case_wall_time"), two.drop_vars("case_wall_time"))
    assert np.ptp(one["load_sharing.cycle_peak"].values) > 0.01


def test_failing_cases_recorded_and_others_complete(split_file):
    # 1e10 N m deflects the train by ~6e4 rad at once: the run blows up (diverged); a
    # negative torque is refused by the model check; the other cases run
    data = grid_study(split_file, [{"path": "drives.motor.torque",
                                    "values": ["100 N m", "1e10 N m", "-5 N m", "120 N m"]}])
    ds = run_study(data, workers=1)
    status = ds["status"].values.tolist()
    assert status == ["ok", "diverged", "refused", "ok"]
    reason = ds["reason"].values
    assert "diverged" in reason[1] and "blowup" in reason[1]
    assert "drives.motor.torque" in reason[2] and "greater than 0" in reason[2]
    lsc = ds["load_sharing.cycle_peak"].values
    assert np.isfinite(lsc[[0, 3]]).all() and np.isnan(lsc[[1, 2]]).all()
    # a case that gave no outputs found no settled part (refused ones said 1)
    assert ds["settled"].values[[1, 2]].tolist() == [0, 0]
    # a stiffness variation that makes the stiffness negative is refused too
    text = split_file.read_text().replace(
        '[meshes.a1]\ngears = ["pinion", "a"]\nstiffness = "4e8 N/m"',
        '[meshes.a1]\ngears = ["pinion", "a"]\nstiffness = {method = "constant", '
        'value = "4e8 N/m", peak_to_peak = 0.1}')
    split_file.write_text(text)
    ds = run_study(grid_study(split_file, [{"path": "meshes.a1.stiffness.peak_to_peak",
                                            "values": [0.1, 2.5]}]), workers=1)
    assert ds["status"].values.tolist() == ["ok", "refused"]
    assert "peak_to_peak" in ds["reason"].values[1]


def test_linked_paths_and_scale_by_pattern(split_file):
    linked = {"name": "stage_stiffness", "paths": ["meshes.a2.stiffness", "meshes.b2.stiffness"],
              "values": [3e8, 5e8]}
    scale = {"name": "split_meshes", "scale": "meshes.*1.stiffness", "values": [0.5, 1.0]}
    ds = run_study(grid_study(split_file, [linked, scale], outputs=["static_force.*"]),
                   workers=1)
    assert ds["split_meshes"].attrs["units"] == "1"
    assert "meshes.b1.stiffness" in ds["split_meshes"].attrs["paths"]
    # equal stiffness on both paths: equal static split whatever the values
    np.testing.assert_allclose(ds["static_force.a2"].values, ds["static_force.b2"].values,
                               rtol=1e-9)
    raw = read_raw(split_file)
    for path in ("meshes.a1.stiffness", "meshes.b1.stiffness"):
        raw = set_parameter(raw, path, 0.5 * 4e8)
    for path in ("meshes.a2.stiffness", "meshes.b2.stiffness"):
        raw = set_parameter(raw, path, 5e8)
    res = torquesplit.simulate(load_model(model_from_dict(raw)), cycles=CYCLES)
    assert ds["static_force.a1"].sel(stage_stiffness=5e8, split_meshes=0.5).item() == \
        output_values(res)["static_force.a1"]


def test_log_range_and_display_units(split_file):
    ds = run_study(grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                            "start": 1, "stop": 100, "num": 3, "unit": "um",
                                            "spacing": "log"}]), workers=1)
    c = ds["meshes.a1.transmission_error.constant"]
    np.testing.assert_allclose(c.values, [1e-6, 1e-5, 1e-4], rtol=1e-12)
    assert c.attrs["display_units"] == "um" and c.attrs["units"] == "m"
    lsc = ds["load_sharing.cycle_peak"].values
    assert lsc[0] < lsc[1] < lsc[2]


@pytest.mark.parametrize("spacing", ["linear", "log"])
def test_integer_field_takes_whole_numbers(split_file, spacing):
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": [0.0]}, {"path": "analysis.table_points",
                                                       "start": 16, "stop": 64, "num": 3,
                                                       "spacing": spacing}])
    plan = Study(data).plan()
    assert all(float(v).is_integer() for v in plan.design.values[:, 1])
    assert isinstance(plan.design.overrides(1)["analysis.table_points"], int)


def test_two_parameters_writing_one_field_refused(split_file):
    from torquesplit.study import StudyError

    a = {"path": "meshes.a1.stiffness", "values": [3e8]}
    b = {"name": "all", "scale": "meshes.*.stiffness", "values": [1.0]}
    with pytest.raises(StudyError, match="grid.parameters.1: 'all' writes meshes.a1.stiffness"):
        Study(grid_study(split_file, [a, b])).plan()


@pytest.mark.parametrize("name", torquesplit.example_names())
def test_cases_start_from_an_exact_si_copy_of_the_model(name):
    """Cases start from the validated model written as SI numbers (no unit parsing per
    case): that copy must give the very same model."""
    import warnings

    from torquesplit.model.io import model_to_dict

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = load_model(torquesplit.example_path(name))
        again = load_model(model_from_dict(model_to_dict(model)))
    assert again == model
    assert model_to_dict(again) == model_to_dict(model)


def test_coordinates_are_the_decimal_values_written():
    from torquesplit.study.design import decimal_si

    # 30 um is 3e-05 m, not 30 * 1e-6 = 2.9999999999999997e-05
    assert decimal_si(30 * 1e-6, "um", "m") == 3e-05
    assert decimal_si(0.1 + 0.2, "m", "m") == 0.3
    assert decimal_si(1.2345678901234e-05, "um", "m") == 1.2345678901234e-05  # kept


def test_grid_axes_and_figures_of_log_and_3_parameter_grids(split_file):
    from torquesplit.study.figures import curves_figure, maps_figure

    plan = Study(grid_study(split_file, [{"path": "meshes.b1.transmission_error.constant",
                                          "start": 0, "stop": 40, "num": 5,
                                          "unit": "um"}])).plan()
    assert plan.design.axes[0].tolist() == [0.0, 1e-05, 2e-05, 3e-05, 4e-05]
    ds = run_study(grid_study(split_file, [
        {"path": "meshes.a1.stiffness", "start": "2e8 N/m", "stop": "8e8 N/m", "num": 2,
         "spacing": "log"},
        {"path": "meshes.b1.transmission_error.constant", "values": ["10 um", "30 um"]},
        {"path": "meshes.a2.transmission_error.constant", "values": ["0 um", "5 um"]}],
        outputs=["load_sharing.cycle_peak"]), workers=1)
    err = "meshes.b1.transmission_error.constant"
    assert ds[err].values.tolist() == [1e-05, 3e-05]
    assert ds["load_sharing.cycle_peak"].sel({err: 30e-6}).shape == (2, 2)
    assert ds["meshes.a1.stiffness"].attrs["spacing"] == "log"
    fig = maps_figure(ds, "load_sharing.cycle_peak", [("system", "load_sharing.cycle_peak")])
    panels = [a for a in fig.axes if a.collections and a.get_xscale() == "log"]
    assert len(panels) == 2  # both values of the third parameter, on a log axis
    clims = {a.collections[0].get_clim() for a in panels}
    assert len(clims) == 1  # one colour scale for the member across the third parameter
    # a small grid prints each cell's value (contours between the cells' centres crossed
    # flat cells unlabelled); the error axis in µm, as the rest of the tool writes it
    var = ds["load_sharing.cycle_peak"]
    d = var.dims
    values = var.isel({d[2]: 0}).transpose(d[1], d[0]).values.ravel()
    texts = [t.get_text() for t in panels[0].texts]
    assert texts == [f"{v:.4g}" for v in values]
    assert "[µm]" in fig.axes[0].get_ylabel() or "[µm]" in fig.axes[0].get_xlabel() or any(
        "µm" in a.get_title() for a in fig.axes)
    ds["scaled"] = 2 * ds["load_sharing.cycle_peak"]  # a second member of the family
    fig = maps_figure(ds, "load_sharing.cycle_peak", [("system", "load_sharing.cycle_peak"),
                                                      ("twice", "scaled")])
    clims = {a.collections[0].get_clim() for a in fig.axes if a.get_title()}
    assert len(clims) == 1  # one scale for the family: a colour is a value in every panel
    one = run_study(grid_study(split_file, [{**STIFFNESS, "spacing": "log"}],
                               outputs=["load_sharing.cycle_peak"]), workers=1)
    fig = curves_figure(one, "load_sharing.cycle_peak",
                        [("system", "load_sharing.cycle_peak")])
    assert fig.axes[0].get_xscale() == "log"
    # a curve equal to one drawn (the system is its worst group) was drawn under it, its
    # legend entry showing a line nowhere to be seen: its name joins that entry instead
    one["other"] = one["load_sharing.cycle_peak"] * 1.01
    one["same"] = one["load_sharing.cycle_peak"].copy()
    fig = curves_figure(one, "load_sharing.cycle_peak",
                        [("system", "load_sharing.cycle_peak"), ("a1", "other"),
                         ("stage", "same")])
    labels = [ln.get_label() for ln in fig.axes[0].get_lines()]
    assert labels == ["system = stage", "a1"], labels
    # cases that are not ok, marked by kind: contact lost keeps its values (a reviewer
    # saw 'case not ok' crosses under points drawn with their values)
    one["status"] = one["status"].astype(object)  # (room for the longer names)
    one["status"].values[:2] = ["contact_lost", "diverged"]
    fig = curves_figure(one, "load_sharing.cycle_peak", [("system", "load_sharing.cycle_peak")])
    marks = {ln.get_label(): ln.get_marker() for ln in fig.axes[0].get_lines()}
    assert marks["teeth separate (contact lost; values kept)"] == "v"
    assert marks["case failed (no values)"] == "x"
    # the model in the title and the quantity in words (a title named only the study,
    # the axis the output's key, "load_sharing.cycle_peak [-]")
    assert fig.get_suptitle().startswith(f"{one.attrs['model_name']}, study test grid: ")
    assert fig.axes[0].get_ylabel() == "load-sharing coefficient (cycle_peak) [-]"


def test_refused_cases_show_the_values_in_the_unit_written(split_file):
    from torquesplit.study import StudyError

    err = "gears.pinion.errors.eccentricity"
    ds = run_study(grid_study(split_file, [{"path": err, "values": ["10 um", "-30 um"]}]),
                   workers=1)
    assert ds["status"].values.tolist() == ["ok", "refused"]
    assert ds["reason"].values[1].endswith(f"(this case: {err} = -30 um)")
    with pytest.raises(StudyError, match=rf"case 0 \({err} = -20 um\) gives an invalid model"):
        Study(grid_study(split_file, [{"path": err, "start": -20, "stop": 0, "num": 2,
                                       "unit": "um"}])).plan()


def test_map_cells_of_a_log_parameter_are_centred_on_its_values():
    """A factor 0.1 / 1 / 10 had its cell edges at 0.55 and 5.5 (arithmetic midpoints):
    on the log axis 1 was not in the middle of its cell."""
    import xarray as xr

    from torquesplit.study.figures import _edges

    ds = xr.Dataset(coords={"k": ("k", [0.1, 1.0, 10.0], {"spacing": "log"}),
                            "e": ("e", [0.0, 4.0, 8.0])})
    np.testing.assert_allclose(_edges(ds, "k", ds["k"].values),
                               [10 ** -1.5, 10 ** -0.5, 10 ** 0.5, 10 ** 1.5], rtol=1e-12)
    np.testing.assert_allclose(_edges(ds, "e", ds["e"].values), [-2, 2, 6, 10])


def test_a_parameter_on_several_paths_names_them_on_the_axis(split_file):
    """A sweep of the backlash of two meshes drew 'backlash [µm]' without saying which."""
    from torquesplit.study.figures import curves_figure

    paths = ["meshes.a1.transmission_error.constant", "meshes.a2.transmission_error.constant"]
    ds = run_study(grid_study(split_file, [{"name": "error", "paths": paths,
                                            "values": ["0 um", "4 um"]}],
                              outputs=["load_sharing.cycle_peak"]), workers=1)
    fig = curves_figure(ds, "load_sharing.cycle_peak", [("system", "load_sharing.cycle_peak")])
    # (wrapped at spaces to the figure's width)
    assert fig.axes[0].get_xlabel().replace("\n", " ") == f"error ({', '.join(paths)}) [µm]"


def test_a_study_is_written_for_a_spreadsheet_and_for_matlab(tmp_path, split_file):
    """results.csv (a row per case) and results.mat (arrays of the grid's shape) beside
    results.nc: a studies user had only NetCDF, where `run` writes .csv and .mat."""
    import csv
    import io

    from scipy.io import loadmat

    data = grid_study(split_file, [STIFFNESS, ERROR], outputs=("load_sharing.cycle_peak",
                                                               "peak_force.a1"))
    ds = Study(data).run(workers=1, out=tmp_path / "o", figures=False)
    rows = list(csv.reader(io.StringIO((tmp_path / "o" / "results.csv").read_text())))
    header, body = rows[0], rows[1:]
    # the case index first, as a Monte Carlo's (a grid's had none: the summary's
    # 'case 2' was found by counting rows), then the grid's parameters
    assert header[:3] == ["case", "meshes.a1.stiffness [N/m]",
                          "meshes.b1.transmission_error.constant [m]"]
    assert [int(r[0]) for r in body] == list(range(8))
    assert "peak_force.a1 [N]" in header and "status" in header
    assert len(body) == 8
    col = header.index("peak_force.a1 [N]")
    got = np.array([[float(r[col]) for r in body]]).reshape(4, 2)
    np.testing.assert_array_equal(got, ds["peak_force.a1"].values)
    assert {r[header.index("status")] for r in body} == {"ok"}
    # the layout of a run's .mat: arrays, and structs naming them, with the attributes
    mat = loadmat(tmp_path / "o" / "results.mat", squeeze_me=True)
    assert mat["names"]["peak_force_a1"].item() == "peak_force.a1"
    np.testing.assert_array_equal(mat["peak_force_a1"], ds["peak_force.a1"].values)
    np.testing.assert_array_equal(mat["meshes_a1_stiffness"], ds["meshes.a1.stiffness"].values)
    assert mat["units"]["peak_force_a1"].item() == "N"
    assert mat["dimensions"]["peak_force_a1"].item() == (
        "meshes.a1.stiffness x meshes.b1.transmission_error.constant")
    # torquesplit.save of the returned Dataset writes the same files (its own save
    # wrote every column with its unit run into the name, 'peak_force.a1_N')
    import torquesplit

    for suffix in (".csv", ".mat"):
        assert torquesplit.save(ds, tmp_path / f"again{suffix}") == tmp_path / f"again{suffix}"
    assert (tmp_path / "again.csv").read_bytes() == (tmp_path / "o" / "results.csv").read_bytes()
    assert loadmat(tmp_path / "again.mat")["names"]["peak_force_a1"].item() == "peak_force.a1"
    assert str(mat["status"][0, 0]) == "ok"
    attrs = mat["attributes"]
    assert attrs["study_hash"].item() == ds.attrs["study_hash"]
    # (given as a dict: its JSON, under the name that says so)
    assert '"grid": {' in attrs["study_json"].item() and "study_toml" not in ds.attrs
    assert mat["provenance"]["model_sha256"].item()


def test_a_share_of_the_time_is_never_written_in_exponent_form():
    from torquesplit.study.case import _percent

    assert [_percent(f) for f in (1.0, 0.123, 0.0034, 1.2e-7)] == [
        "100 %", "12 %", "0.34 %", "0.000012 %"]


def test_map_cells_print_the_digits_that_tell_them_apart():
    """A reviewer's map labelled its cells '1.105' and '1.106' over a colour scale from
    1.1051 to 1.1064: the labels hid the differences the colours showed."""
    from torquesplit.study.figures import cell_digits

    z = np.array([[1.10512, 1.10571], [1.10598, 1.10641]])
    n = cell_digits(z)
    labels = {f"{v:.{n}g}" for v in z.ravel()}
    assert len(labels) == 4 and n == 5
    assert cell_digits(np.array([[1.0, 2.0], [3.0, 4.0]])) == 4
    assert cell_digits(np.array([[1.0, 1.0]])) == 4  # flat: nothing to resolve
    assert cell_digits(np.array([[1.0, 1.0 + 1e-12]])) == 8  # (at most 8)


def test_a_scale_parameter_names_what_it_scales_on_the_axis():
    from torquesplit.study.figures import _param_label, path_pattern

    paths = [f"gears.z{i}.support.shaft.bearing_stiffness" for i in range(1, 7)]
    assert path_pattern(paths) == "gears.*.support.shaft.bearing_stiffness"
    assert path_pattern(["meshes.a.backlash", "gears.b.errors.pitch"]) == \
        "meshes.a.backlash and 1 more"
    import json

    import xarray as xr

    ds = xr.Dataset(coords={"f": ("f", [0.5, 2.0], {"mode": "scale",
                                                   "paths": json.dumps(paths)})})
    assert _param_label(ds, "f") == ("f (factor on gears.*.support.shaft.bearing_stiffness, "
                                     "6 fields)")
    two = ["gears.z2.polar_inertia", "gears.z3.polar_inertia"]
    ds = xr.Dataset(coords={"J": ("J", [0.5, 2.0], {"mode": "scale",
                                                   "paths": json.dumps(two)})})
    assert _param_label(ds, "J") == "J (factor on gears.z2.polar_inertia, " \
                                    "gears.z3.polar_inertia)"
