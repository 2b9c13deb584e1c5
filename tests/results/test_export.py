"""Result Datasets in the three formats users open (NetCDF, MATLAB, CSV), and the commands
that write them (static, sweep-speed, modes and its Campbell map)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import scipy.io
import xarray as xr
from typer.testing import CliRunner

from model_texts import PARAMETRIC_PAIR
from torquesplit.cli import app
from torquesplit.errors import OutputError
from torquesplit.results.export import row_dims, save_dataset

EXAMPLE = "ji_li_mill_drive"


def _dataset():
    """Two row dimensions (position, mesh), a unit per DOF, a scalar, strings."""
    t = np.array([0.0, 0.5, 1.0])
    return xr.Dataset(
        {"force": (("time", "mesh"), np.arange(6.0).reshape(3, 2), {"units": "N",
                                                                     "long_name": "force"}),
         "q": (("time", "dof"), np.array([[1.0, 2.0]] * 3), {"units": "m or rad"}),
         "share": (("mesh",), np.array([1.1, 0.9]), {"units": "1"}),
         "total": ((), 7.0, {"units": "N m"})},
        coords={"time": ("time", t, {"units": "s"}), "mesh": ["a", "b"],
                "dof": ["g.theta", "g.x"], "dof_unit": ("dof", ["rad", "m"]),
                "time_ms": ("time", 1e3 * t, {"units": "ms"})},
        attrs={"title": "test", "labels": ["x", "y"], "share": 1.25, "complete": 1,
               "speeds": [700.5, 800.0]})


def _read(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def test_csv_tables_by_row_dimension_with_units_in_the_names(tmp_path):
    ds = _dataset()
    assert row_dims(ds) == ("time", "mesh")
    path = save_dataset(ds, tmp_path / "r.csv")
    header, rows = _read(path)
    assert header == ["time_s", "time_ms", "force_a_N", "force_b_N", "q_g.theta_rad",
                      "q_g.x_m", "total_Nm"]
    assert len(rows) == 3
    assert [float(v) for v in rows[2]] == [1.0, 1000.0, 4.0, 5.0, 1.0, 2.0, 7.0]
    header, rows = _read(tmp_path / "r_mesh.csv")
    assert header == ["mesh", "share"] and rows == [["a", "1.1"], ["b", "0.9"]]


def test_mat_and_netcdf_keep_every_variable_and_unit(tmp_path):
    ds = _dataset()
    data = scipy.io.loadmat(save_dataset(ds, tmp_path / "r.mat"), simplify_cells=True)
    np.testing.assert_array_equal(data["force"], ds["force"].values)
    assert data["units"]["force"] == "N" and data["units"]["time"] == "s"
    assert data["dimensions"]["force"] == "time x mesh"  # (rows x columns, for MATLAB)
    assert data["descriptions"]["force"] == "force"
    # numbers as doubles, texts as cell arrays (a MATLAB user's review: '1.25' as text)
    attrs = data["attributes"]
    assert list(attrs["labels"]) == ["x", "y"]
    assert attrs["share"] == 1.25 and attrs["complete"] == 1.0
    np.testing.assert_array_equal(attrs["speeds"], [700.5, 800.0])
    assert list(data["mesh"]) == ["a", "b"] and "run_id" in data["provenance"]
    # a flag as a MATLAB logical (scipy reads it back as uint8), a count as a double
    flags = ds.assign(stable=("mesh", np.array([True, False])),
                      count=("mesh", np.array([3, 4], dtype=np.int64)))
    mat = scipy.io.loadmat(save_dataset(flags, tmp_path / "f.mat"))
    assert mat["stable"].dtype == np.uint8 and mat["stable"].ravel().tolist() == [1, 0]
    assert mat["count"].dtype == np.float64
    # a 0/1 variable marked with CF flag attributes (a run's double_flank and settled, a
    # study's settled, a static sweep's converged) is a logical too (a code reviewer)
    from torquesplit.results.dataset import FLAG

    marked = ds.assign(both=("mesh", np.array([1, 0], dtype=np.int8), FLAG))
    mat = scipy.io.loadmat(save_dataset(marked, tmp_path / "g.mat"))
    assert mat["both"].dtype == np.uint8 and mat["both"].ravel().tolist() == [1, 0]
    back = xr.open_dataset(save_dataset(ds, tmp_path / "r.nc"), engine="h5netcdf")
    np.testing.assert_array_equal(back["force"].values, ds["force"].values)
    assert back.attrs["run_id"] and json.loads(back.attrs["labels"]) == ["x", "y"]
    back.close()
    # no warnings: an empty cell column, which MATLAB's isempty sees ({''} did not)
    quiet = ds.assign_attrs(warnings_json="[]")
    mat = scipy.io.loadmat(save_dataset(quiet, tmp_path / "w.mat"))
    assert mat["warnings"].shape == (0, 1)
    # a coordinate has no _FillValue (CF 2.5.1; xarray gave every float one); data do
    import h5py

    with h5py.File(tmp_path / "r.nc") as f:
        assert "_FillValue" not in f["time"].attrs and "_FillValue" not in f["time_ms"].attrs
        assert "_FillValue" in f["force"].attrs


def test_a_companion_table_is_not_replaced_unless_asked(tmp_path):
    (tmp_path / "r_mesh.csv").write_text("mine")
    with pytest.raises(OutputError, match="r_mesh.csv exists"):
        save_dataset(_dataset(), tmp_path / "r.csv")
    assert (tmp_path / "r_mesh.csv").read_text() == "mine"
    assert not (tmp_path / "r.csv").exists()
    save_dataset(_dataset(), tmp_path / "r.csv", overwrite=True)
    assert _read(tmp_path / "r_mesh.csv")[0] == ["mesh", "share"]


def test_static_writes_matlab_and_spreadsheet_files(tmp_path):
    args = ["static", EXAMPLE, "--revolutions", "0.02", "--points-per-cycle", "2", "--quiet"]
    r = CliRunner().invoke(app, args + ["--out", str(tmp_path / "q.csv"), "--json"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)  # (the warnings on stderr: 0.02 revolutions is short)
    assert any("covers part of the excitations' common period" in w
               for w in data["warnings"]), data["warnings"]
    share = data["load_sharing"]["per_mesh"]
    # named as a run's tables are (an exports review: NAME_mesh.csv, NAME_group.csv and
    # a NAME.csv per position beside a run's NAME.csv per mesh and NAME_groups.csv)
    header, rows = _read(tmp_path / "q.csv")
    col = {h: i for i, h in enumerate(header)}
    assert {row[0]: float(row[col["load_sharing"]]) for row in rows} == pytest.approx(
        share, rel=1e-12)
    # the mesh table's forces and groups too (the file held only the coefficient)
    for row in rows:
        printed = data["mesh_force_N"][row[0]]
        # (named as a run's: peak_force, not max_force)
        for name, k in (("min", "min"), ("mean", "mean"), ("peak", "max")):
            assert float(row[col[f"{name}_force_N"]]) == pytest.approx(printed[k], rel=1e-12)
    header, groups = _read(tmp_path / "q_groups.csv")
    assert header == ["group", "load_sharing_group"]
    # the system as a row of its own, as a run's groups table has it (it was a column of
    # the positions' table, the same number on every row)
    assert groups[-1][0] == "(system)"
    assert float(groups[-1][1]) == pytest.approx(data["load_sharing"]["system"], rel=1e-12)
    assert {g: float(v) for g, v in groups[:-1]} == pytest.approx(
        data["load_sharing"]["per_group"], rel=1e-12)
    header, rows = _read(tmp_path / "q_history.csv")
    assert header[:2] == ["time_s", "mesh_force_m11_N"] and "displacement_z1.theta_rad" in header
    assert not any("system" in h for h in header)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "q.csv", "q_about.json", "q_groups.csv", "q_history.csv"]
    # the metrics in the about file as JSON, not a JSON text inside it
    about = json.loads((tmp_path / "q_about.json").read_text())
    assert about["attributes"]["metrics"]["per_mesh"] == pytest.approx(share, rel=1e-12)
    r = CliRunner().invoke(app, args + ["--out", str(tmp_path / "q.mat")])
    assert r.exit_code == 0, r.output
    data = scipy.io.loadmat(tmp_path / "q.mat", simplify_cells=True)
    np.testing.assert_allclose(data["mesh_force"][:, 0], [float(row[1]) for row in rows],
                               rtol=1e-12)
    # the model and the metrics at the top, where a run's .mat has them
    assert json.loads(data["model_json"])["model"]["name"] == "ji_li_mill_drive"
    assert json.loads(data["metrics_json"])["per_mesh"] == pytest.approx(share, rel=1e-12)
    assert data["load_sharing_system"] == pytest.approx(
        json.loads(data["metrics_json"])["system"], rel=1e-15)
    # a companion that exists is refused before the sweep, not after it
    for companion in ("x_history.csv", "x_groups.csv"):
        (tmp_path / companion).write_text("")
        r = CliRunner().invoke(app, args + ["--out", str(tmp_path / "x.csv")])
        assert r.exit_code == 2 and f"{companion} exists" in r.output
        assert "quasi-static" not in r.output
        (tmp_path / companion).unlink()


def test_the_campbell_map_is_written_where_asked(tmp_path):
    """'modes --campbell --out' checked the file and then wrote nothing."""
    out = tmp_path / "map.csv"
    r = CliRunner().invoke(app, ["modes", EXAMPLE, "--campbell", "--from", "300 rpm", "--to",
                                 "1200 rpm", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    # every file written is named (a CSV set: the table and what it cannot hold)
    about = tmp_path / "map_about.json"
    crossings = tmp_path / "map_crossing.csv"  # (the critical speeds, a row each)
    assert json.loads(r.output)["files"] == [str(out), str(crossings), str(about)]
    assert json.loads(about.read_text())["model"]["model"]["name"] == "ji_li_mill_drive"
    header, rows = _read(out)
    assert header[:3] == ["speed_rad/s", "speed_rpm", "natural_frequency_1_Hz"]
    assert float(rows[0][1]) == pytest.approx(300.0) and float(rows[-1][1]) == pytest.approx(1200)


def test_sweep_speed_writes_a_spreadsheet(tmp_path):
    out = tmp_path / "s.csv"
    r = CliRunner().invoke(app, ["sweep-speed", EXAMPLE, "--keep", "stage1", "--from",
                                 "700 rpm", "--to", "790 rpm", "--points", "4",
                                 "--harmonics", "8", "--no-stability", "--out", str(out),
                                 "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["results_file"] == str(out)
    header, rows = _read(out)
    assert header[:3] == ["point", "speed_rpm", "speed_rad/s"]
    assert "dynamic_factor_m11" in header and "peak_force_m11_N" in header
    assert float(rows[0][1]) == pytest.approx(700.0)


def test_set_overrides_reach_steady_and_mesh():
    """--set was missing from 'steady', 'sweep-speed' and 'mesh'."""
    base = ["steady", EXAMPLE, "--keep", "stage1", "--harmonics", "8", "--no-stability",
            "--json"]
    a = json.loads(CliRunner().invoke(app, base).stdout)  # (8 harmonics: a warning beside)
    r = CliRunner().invoke(app, base + ["--set", "loads.mill.torque=0.5*"])
    assert r.exit_code == 2 and "--set" in r.output
    r = CliRunner().invoke(app, base + ["--set", "meshes.m11.damping_ratio=0.2"])
    assert r.exit_code == 0, r.output
    b = json.loads(r.stdout)
    assert b["meshes"]["m11"]["dynamic_factor"] != a["meshes"]["m11"]["dynamic_factor"]
    r = CliRunner().invoke(app, ["mesh", EXAMPLE, "--pair", "m11", "--json", "--set",
                                 "meshes.m11.stiffness.method=iso6336"])
    assert r.exit_code == 0, r.output


DIVERGING = (PARAMETRIC_PAIR.replace("damping_ratio = 0.05", "damping_ratio = 0.0")
             .replace('backlash = "100 um"\n', "").replace('"3000 rpm"', '"16052 rpm"'))
"""Undamped, without backlash, at twice its natural frequency: it grows until stopped."""


def test_a_stopped_run_file_holds_no_coefficients_and_is_not_reported(tmp_path):
    """A stopped run's CSV left the coefficients out ('a partial run's are not results'),
    but its .nc/.mat held them, and 'report' printed them as results."""
    import torquesplit

    model = tmp_path / "diverging.toml"
    model.write_text(DIVERGING)
    res = torquesplit.simulate(model, cycles=3000)  # (mesh frequency = 2 x natural)
    assert not res.success
    ds = res.to_dataset()
    assert "load_sharing" not in ds and "dynamic_factor" not in ds
    assert "stopped" in ds.attrs["metrics_error"]
    path = res.save(tmp_path / "p.nc")
    r = CliRunner().invoke(app, ["report", str(path), "--out", str(tmp_path / "p.html")])
    assert r.exit_code == 2 and "the run stopped" in r.stderr


def test_spreadsheet_and_matlab_details(tmp_path):
    """NaN written as 'nan' (text in a spreadsheet), a unit with commas and labels with
    spaces in the header, names longer than MATLAB's 63 characters or meeting after
    cleaning ('a.b', 'a_b'), integers that MATLAB cannot mix with doubles."""
    long = "x" * 70
    ds = xr.Dataset({"a.b": (("k",), [1.0, np.nan]), "a_b": (("k",), [2.0, np.inf]),
                     long: (("k",), [3.0, 4.0]), "n": (("k",), np.array([1, 2])),
                     "shape": (("k", "line"), np.ones((2, 1)),
                               {"units": "kg^-1/2 (translations), rad (rotations)"})},
                    coords={"k": [0, 1], "line": ["1 x meshes m11, m21"]})
    header, rows = _read(save_dataset(ds, tmp_path / "d.csv"))
    assert "shape_1_x_meshes_m11_m21" in header
    assert rows[1][header.index("a.b")] == "" and rows[1][header.index("a_b")] == "inf"
    data = scipy.io.loadmat(save_dataset(ds, tmp_path / "d.mat"), simplify_cells=True)
    assert {"a_b", "a_b_2", "x" * 63} <= set(data)
    assert sorted(data["names"].values()) == sorted(["a.b", "a_b", long, "n", "shape", "k",
                                                     "line"])
    assert data["n"].dtype == float


def test_cycle_starts_end_with_the_run_and_a_capped_history_is_said():
    """A slower mesh's cycle rows past its last cycle had start times far beyond the run
    (124 s in a 12.6 s run); a history cut to 200,000 samples (4 per period for 50 asked)
    was said only in the bearing table's title.  Said where the user asked for the rate;
    the default rate is the library's choice and stays in the title and the files."""
    import warnings

    import torquesplit
    from torquesplit import simulation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate(torquesplit.example_path(EXAMPLE), cycles=200)
    s = res.solution
    assert np.nanmax(s.cycle_start) <= s.t_span[1] * (1 + 1e-12)
    np.testing.assert_array_equal(np.isnan(s.cycle_start), s.cycle_count == 0)
    cap = simulation.MAX_HISTORY_RECORDS
    try:
        simulation.MAX_HISTORY_RECORDS = 1000
        with warnings.catch_warnings():
            warnings.simplefilter("always")  # (an ignored warning is not kept either)
            res = torquesplit.simulate(torquesplit.example_path(EXAMPLE), cycles=200,
                                       samples_per_period=20)
            default = torquesplit.simulate(torquesplit.example_path(EXAMPLE), cycles=200)
    finally:
        simulation.MAX_HISTORY_RECORDS = cap
    assert any("the history holds at most 1,000 samples" in w for w in res.run_warnings)
    assert res.history_samples_per_period() < 20
    # the library's own sampling is cut to the cap silently (its rate is in the results)
    assert not any("the history holds" in w for w in default.run_warnings)
    assert default.solution.history_t.size <= 1001


def test_a_replaced_csv_set_leaves_no_stale_companion_and_files_carry_their_model(tmp_path):
    """--force left an earlier save's NAME_dof.csv beside a Campbell map's NAME.csv; the
    modes, sweep and Campbell files held neither the model nor the warnings printed."""
    out = tmp_path / "x.csv"
    r = CliRunner().invoke(app, ["modes", EXAMPLE, "--out", str(out)])
    assert r.exit_code == 0 and (tmp_path / "x_dof.csv").exists()
    r = CliRunner().invoke(app, ["modes", EXAMPLE, "--campbell", "--from", "300 rpm",
                                 "--to", "900 rpm", "--out", str(out), "--force"])
    assert r.exit_code == 0 and not (tmp_path / "x_dof.csv").exists()
    nc = tmp_path / "m.nc"
    r = CliRunner().invoke(app, ["modes", EXAMPLE, "--out", str(nc), "--set",
                                 "gears.z1.mass=154000 kg"])
    assert r.exit_code == 0, r.output
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert "gears.z1.mass" in ds.attrs["warnings"]
        assert json.loads(ds.attrs["model_json"])["model"]["name"] == "ji_li_mill_drive"


def test_load_results_of_another_kind_of_file_says_what_reads_it(tmp_path):
    """A .mat gave h5py's 'file signature not found'; a quasi-static .nc a message that
    did not point to open_results."""
    import torquesplit

    res = torquesplit.simulate(torquesplit.example_path(EXAMPLE), cycles=10)
    mat = res.to_mat(tmp_path / "r.mat")
    with pytest.raises(ValueError, match=r"not a NetCDF results file .*scipy\.io\.loadmat"):
        torquesplit.load_results(mat)
    static = torquesplit.quasi_static_load_sharing(res.model, revolutions=0.02).save(
        tmp_path / "q.nc")
    with pytest.raises(ValueError, match="open this one as a Dataset with "
                                         "torquesplit.open_results"):
        torquesplit.load_results(static)
    with torquesplit.open_results(static) as ds:
        assert len(ds.data_vars) > 0


def test_an_overwritten_csv_set_leaves_no_file_of_the_old_set(tmp_path):
    """A reviewer: '--force' over a quasi-static set left its NAME_mesh.csv beside the new
    run's tables.  The old set's files (its NAME_about.json lists them) that the new set
    does not write are removed; other files are not touched."""
    save_dataset(_dataset(), tmp_path / "r.csv")
    assert (tmp_path / "r_mesh.csv").exists()
    (tmp_path / "r_notes.csv").write_text("mine")
    one_table = _dataset().drop_dims("mesh")
    save_dataset(one_table, tmp_path / "r.csv", overwrite=True)
    assert not (tmp_path / "r_mesh.csv").exists()
    assert (tmp_path / "r_notes.csv").read_text() == "mine"
    assert json.loads((tmp_path / "r_about.json").read_text())["files"] == [
        "r.csv", "r_about.json"]
    # names that are no file of this folder are left alone (they raised ValueError)
    (tmp_path / "r_about.json").write_text(json.dumps({"files": ["r_x/../r_notes.csv", "",
                                                                  "r_sub/y.csv", 3]}))
    save_dataset(one_table, tmp_path / "r.csv", overwrite=True)
    assert (tmp_path / "r_notes.csv").read_text() == "mine"


def test_a_runs_mat_file_has_the_layout_every_commands_has(tmp_path):
    """A Python API reviewer: a run's .mat had no 'attributes' or 'names' struct (a
    study's, a quasi-static sweep's and the modes' do), so the load-sharing definition
    was only inside a description text."""
    import scipy.io as sio

    import torquesplit

    res = torquesplit.simulate(EXAMPLE, duration=0.3)
    m = sio.loadmat(res.to_mat(tmp_path / "r.mat"), simplify_cells=True)
    assert m["attributes"]["load_sharing_definition"] == res.metrics().definition
    assert m["names"]["cycle_max_force"] == "cycle_max_force"
    assert m["units"]["time"] == "s" and m["units"]["peak_force"] == "N"
    assert "model_json" not in m["attributes"] and m["model_json"].startswith("{")
    assert m["provenance"]["run_id"]


def test_a_file_read_back_reports_the_definition_it_was_saved_with(tmp_path):
    """An exports review: a run saved with ``--definition mean_force`` read back with
    ``load_results`` reported the model's definition (its report used the file's), so the
    Python numbers differed from the file's own load_sharing variable."""
    import torquesplit

    res = torquesplit.simulate(EXAMPLE, duration=0.3)
    assert res.default_definition != "mean_force"
    back = torquesplit.load_results(res.save(tmp_path / "r.nc", definition="mean_force"))
    met = back.metrics()
    assert met.definition == back.default_definition == "mean_force"
    with xr.open_dataset(tmp_path / "r.nc") as ds:
        assert [met.load_sharing.per_mesh[m] for m in back.mesh_names] == pytest.approx(
            list(ds["load_sharing"].values), rel=1e-12)
    # another definition is still one argument away, and a run not read from a file keeps
    # the model's
    assert back.metrics(res.default_definition).definition == res.default_definition
    assert res.metrics().definition == res.default_definition
