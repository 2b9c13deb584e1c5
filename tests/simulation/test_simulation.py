"""End-to-end dynamic runs of small models: load sharing, errors, power, files."""

from __future__ import annotations

import math

import numpy as np
import pytest

import torquesplit
from torquesplit.results import model_from_results, open_results

from model_texts import split_model, write_model


def test_spur_pair_static_force_and_quiet_start(spur_pair):
    res = torquesplit.simulate(spur_pair, cycles=50)
    assert res.success
    f_nominal = 100.0 / (0.02 * math.cos(math.radians(20)))  # T / r_b
    met = res.metrics()
    row = met.rows[0]
    assert row.static_force == pytest.approx(f_nominal, rel=1e-9)
    # started from static equilibrium: no start-up transient at all, so only the cycles
    # before the first whole settle window (never checked, never counted) are left out
    assert row.peak_force == pytest.approx(f_nominal, rel=1e-9)
    assert met.settling.settled
    assert met.settling.first_cycle["m"] < 12  # window: min(20, 50 cycles / 4)


def test_symmetric_split_shares_equally(split):
    res = torquesplit.simulate(split, cycles=100)
    for definition in ("cycle_peak", "mean_force", "instantaneous", "engineering"):
        met = res.metrics(definition)
        for m, v in met.load_sharing.per_mesh.items():
            assert v == pytest.approx(1.0, abs=1e-6), (definition, m)


def test_error_on_one_path_moves_load_as_hand_calculation(tmp_path):
    """A constant error e along mesh a1 of a rigid-shaft locked train.

    Circulating force F at a1 gives F at b1, 2F at a2 and b2 (torque balance on the
    compound gears, base radii 2:1), so the loop compliance at a1 is
    (1 + 1 + 4 + 4) / k = 10 / k and the error shifts e k / 10 from a1 to b1.
    """
    e = 5e-6
    k = 4e8
    model = torquesplit.load_model(write_model(tmp_path, split_model(error_a="5 um")))
    res = torquesplit.simulate(model, cycles=50)
    f = res.static_forces()
    f0 = 50.0 / (0.02 * math.cos(math.radians(20)))
    assert f["a1"] == pytest.approx(f0 - e * k / 10, rel=1e-6)
    assert f["b1"] == pytest.approx(f0 + e * k / 10, rel=1e-6)
    met = res.metrics("mean_force")
    assert met.load_sharing.per_mesh["b1"] > 1 > met.load_sharing.per_mesh["a1"]
    assert met.load_sharing.per_mesh["b1"] == pytest.approx(1 + e * k / 10 / f0, rel=1e-4)
    # coefficients of a group sum to the number of meshes (seed 002 normalisation)
    assert met.load_sharing.per_mesh["a1"] + met.load_sharing.per_mesh["b1"] == pytest.approx(2)


def test_power_balance_and_no_drift(tmp_path):
    text = split_model().replace('stiffness = "4e8 N/m"\ndamping_ratio = 0.05\nstage = "split"',
                                 'stiffness = {method = "constant", value = "4e8 N/m", '
                                 'peak_to_peak = 0.3}\ndamping_ratio = 0.05\nstage = "split"')
    model = torquesplit.load_model(write_model(tmp_path, text))
    res = torquesplit.simulate(model, cycles=300, history_dofs=["pinion.theta", "out.theta"])
    s = res.solution
    t, q = s.history_t, s.history_q
    k0 = len(t) // 2
    # mean speeds over the window from the angles (exact for any sampling)
    w_in = 3000 * math.pi / 30 + (q[-1, 0] - q[k0, 0]) / (t[-1] - t[k0])
    w_out = 500 * math.pi / 30 + (q[-1, 1] - q[k0, 1]) / (t[-1] - t[k0])
    p_in, p_out = 100.0 * w_in, 600.0 * w_out
    # constant torques: the mean dissipated power is the difference, bounded by 1e-3 P
    assert -1e-12 * p_in <= p_in - p_out < 1e-3 * p_in  # >= 0 to round-off
    # the rigid-body rotation does not drift: the vibratory angles stay bounded
    assert np.ptp(q[k0:, 0]) < 1e-3


def test_two_runs_identical_and_netcdf_round_trip(split, tmp_path):
    r1 = torquesplit.simulate(split, cycles=30)
    r2 = torquesplit.simulate(split, cycles=30)
    np.testing.assert_array_equal(r1.solution.history_forces, r2.solution.history_forces)
    path = r1.to_netcdf(tmp_path / "run.nc")
    ds = open_results(path)
    np.testing.assert_array_equal(ds["element_force"].values, r1.solution.history_forces)
    assert ds["element_force"].attrs["units"] == "N"  # (rigid shafts: no torque element)
    for name in ds.data_vars:
        assert "units" in ds[name].attrs and "long_name" in ds[name].attrs, name
    again = torquesplit.simulate(model_from_results(ds), cycles=30)
    np.testing.assert_allclose(again.solution.history_forces, r1.solution.history_forces,
                               rtol=1e-12)
    ds.close()


def test_mat_and_csv_exports(split, tmp_path):
    import csv
    import json

    from scipy.io import loadmat

    res = torquesplit.simulate(split, cycles=20)
    mat = loadmat(res.save(tmp_path / "run.mat"))
    np.testing.assert_allclose(mat["element_force"], res.solution.history_forces)
    # MATLAB: time a column beside the (time x element) forces; no integer arrays (int64
    # refuses arithmetic with doubles) but the flags, logicals (scipy reads them as uint8)
    assert mat["time"].shape == (res.solution.history_t.size, 1)
    ints = [k for k, v in mat.items() if isinstance(v, np.ndarray) and not k.startswith("__")
            and v.dtype.kind in "iu"]
    assert sorted(ints) == ["double_flank", "settled"], ints
    assert all(mat[k].dtype == np.uint8 for k in ints)
    assert mat["static_force"].ravel() == pytest.approx(list(res.static_forces().values()))
    assert str(mat["dimensions"][0, 0]["element_force"][0]) == "time x element"
    # each variable's unit and what it is (the .mat had units only, time none)
    desc = mat["descriptions"][0, 0]
    assert "history of every integration step" in str(desc["element_force"][0])
    assert str(mat["units"][0, 0]["time"][0]) == "s"
    # MATLAB counts rows from 1: the first settled cycle's row is one past its index (a
    # reviewer's cycle_max_force(first_settled_cycle:end, k) took one cycle too many)
    assert "first_settled_cycle + 1" in str(desc["first_settled_cycle"][0])
    met = res.metrics()
    for k, r in enumerate(met.rows):
        row = int(mat["first_settled_cycle"].ravel()[k]) + 1  # (MATLAB's row)
        assert np.nanmax(mat["cycle_max_force"][row - 1:, k]) == r.peak_force
    # the warnings as a cell column, one per warning (none: empty, which {''} was not)
    said = res.warnings()
    assert mat["warnings"].shape == (len(said), 1)
    assert [str(w[0]) for w in mat["warnings"].ravel()] == said
    res.save(tmp_path / "run.csv")
    with open(tmp_path / "run.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    met = res.metrics()
    n = len(res.mesh_names)
    assert [r["mesh"] for r in rows] == res.mesh_names and len(rows) == n
    assert float(rows[0]["peak_force_N"]) == pytest.approx(met.rows[0].peak_force)
    # the cycles table gives the summary's peaks back over the cycles marked settled (the
    # settled span was only in the about file); so do the .nc's cycle variables
    with open(tmp_path / "run_cycles.csv", newline="") as fh:
        cyc = list(csv.DictReader(fh))
    ds = res.to_dataset()
    for j, r in enumerate(met.rows):
        settled = [float(c[f"{r.mesh}_peak_N"]) for c in cyc
                   if c[f"{r.mesh}_settled"] == "1" and c[f"{r.mesh}_peak_N"]]
        assert max(settled) == r.peak_force
        k = int(ds["first_settled_cycle"].sel(mesh=r.mesh))
        assert float(ds["cycle_max_force"].sel(mesh=r.mesh)[k:].max()) == r.peak_force
    # whether the rule found it settled, as a variable (a study's file has one)
    assert int(ds["settled"]) == int(met.settling.settled)
    # what the .nc has of each mesh and group, in the tables too (an exports reviewer)
    for r in rows:
        assert int(r["first_settled_cycle"]) == int(ds["first_settled_cycle"].sel(
            mesh=r["mesh"]))
        assert float(r["mesh_frequency_Hz"]) == float(ds["mesh_frequency"].sel(mesh=r["mesh"]))
        assert int(r["double_flank"]) == int(ds["double_flank"].sel(mesh=r["mesh"]))
    # the groups' and the system's rows, as the run's tables print them
    # the same columns whatever the definition, which a column names
    assert rows[0]["load_sharing_definition"] == met.definition
    assert float(rows[0]["load_sharing"]) == pytest.approx(met.rows[0].load_sharing)
    with open(tmp_path / "run_groups.csv", newline="") as fh:
        group_rows = list(csv.DictReader(fh))
    groups = {r["group"]: float(r["load_sharing"]) for r in group_rows}
    assert {r["load_sharing_definition"] for r in group_rows} == {met.definition}
    assert groups.pop("(system)") == pytest.approx(met.load_sharing.system)
    times = {r["group"]: float(r["settle_time_s"]) for r in group_rows}
    assert times.pop("(system)") == met.settling.start_time
    assert times == {g: float(ds["settle_time"].sel(group=g)) for g in times}
    assert groups == pytest.approx(met.load_sharing.per_group)
    # what the tables cannot hold
    about = json.loads((tmp_path / "run_about.json").read_text())
    assert about["model"] == json.loads(res.model_json())
    assert about["warnings"] == res.warnings()
    assert about["metrics"]["definition"] == met.definition
    assert about["provenance"]["model_sha256"] and about["provenance"]["run_id"]
    with open(tmp_path / "run_cycles.csv", newline="") as fh:
        cycles = list(csv.DictReader(fh))
    assert cycles[1]["cycle"] == "1"  # a whole number, not 1.0
    m = res.mesh_names[0]
    lo, mean, hi = (float(cycles[1][f"{m}_{q}_N"]) for q in ("min", "mean", "peak"))
    assert lo * (1 - 1e-12) <= mean <= hi * (1 + 1e-12)  # (a trapezoid mean's rounding)
    # a cycle cut by the start or the end of the run (its start before t = 0, or its end
    # after the run's) is listed with its start and empty statistics, in the .nc too: a
    # spreadsheet's average of a column was biased by the part-cycles
    ds = res.to_dataset()
    complete = res.complete_cycles
    seen = np.isfinite(res.solution.cycle_max[:, res._mesh_columns])  # (a slower mesh:
    assert (seen & ~complete).any()  # fewer cycles, the rest of its column empty)
    for k, row in enumerate(cycles):
        for j, m in enumerate(res.mesh_names):
            cut = not complete[k, j]
            assert (row[f"{m}_peak_N"] == "") == cut and (row[f"{m}_mean_N"] == "") == cut
            assert (row[f"{m}_start_s"] != "") == seen[k, j]
            assert np.isnan(ds["cycle_max_force"].values[k, j]) == cut
            assert np.isnan(ds["cycle_ratio_min"].values[k, j]) or not cut
    hist = np.loadtxt(tmp_path / "run_history.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(hist[:, 0], res.solution.history_t)
    with pytest.raises(ValueError, match=r"\.nc, \.mat or \.csv"):
        res.save(tmp_path / "run.xlsx")


def test_support_clearance_larger_than_the_motion_carries_no_force(tmp_path):
    """The input pinion of the split is loaded by two opposite meshes (net force zero):
    inside a 100 um radial clearance it floats, and its support never carries load."""
    text = split_model().replace(
        'polar_inertia = "4e-5 kg m^2"\nposition = ["0 mm", "0 mm", "0 mm"]',
        'polar_inertia = "4e-5 kg m^2"\nposition = ["0 mm", "0 mm", "0 mm"]\n'
        'mass = "0.2 kg"\ndofs = ["theta", "x", "y"]\n'
        'support = {stiffness = "1e8 N/m", clearance = "100 um", damping_ratio = 0.05}', 1)
    model = torquesplit.load_model(write_model(tmp_path, text))
    res = torquesplit.simulate(model, cycles=100)
    assert res.success
    names = res.structure.element_names
    hist = [list(res.solution.history_elements).index(names.index(f"pinion.support.{d}"))
            for d in "xy"]
    assert np.all(res.solution.history_forces[:, hist] == 0.0)
    # with no clearance the same support does carry the vibration
    stiff = torquesplit.load_model(write_model(tmp_path, text.replace('"100 um"', '"0 um"'),
                                               "stiff.toml"))
    res0 = torquesplit.simulate(stiff, cycles=100)
    assert res0.metrics().rows[0].static_force == pytest.approx(res.metrics().rows[0].static_force)


def test_bearing_forces_of_the_settled_part(tmp_path):
    """A report writer found no bearing loads anywhere but the thinned history: each
    supported body's settled mean and peak bearing force are in the run's table, its JSON
    and its file, computed after the settle time (the mean from the history)."""
    import re
    from pathlib import Path

    tutorial = Path(__file__).resolve().parents[2] / "docs" / "tutorial.md"
    text = re.search(r"```toml\n(.*?)```", tutorial.read_text(), re.S).group(1)
    model = torquesplit.load_model(write_model(tmp_path, text))  # supported bodies
    res = torquesplit.simulate(model, duration=0.1)
    rows = res.bearing_forces()
    s, el = res.solution, res.structure.element_names
    t0 = res.metrics().settling.start_time
    keep = s.history_t >= t0
    for r in rows:
        if r.get("held") == "rigid":  # (its meshes' forces: tests/results/test_two_path...)
            continue
        cols = [list(s.history_elements).index(el.index(f"{r['body']}.support.{d}"))
                for d in r["directions"]]
        f = s.history_forces[keep][:, cols]
        np.testing.assert_allclose(r["mean"], f.mean(axis=0), rtol=1e-12)
        # the peak, streamed at every step, holds the samples' and the corners and peaks
        # between the steps (tests/results/test_bearing_peaks.py): a little higher
        sampled = np.sqrt((f ** 2).sum(axis=1)).max()
        assert r["peak_streamed"] and sampled <= r["peak_magnitude"] <= sampled * 1.002
        assert r["peak_magnitude"] >= r["mean_magnitude"] > 0
    assert rows, "the split model has supported bodies"
    ds = res.to_dataset()
    assert list(ds["bearing"].values) == [r["body"] for r in rows]
    np.testing.assert_allclose(ds["bearing_peak_force"].values,
                               [r["peak_magnitude"] for r in rows])
    # what the table prints by direction, and each group's numbers, are variables too
    # (a MATLAB user found them only inside JSON attributes)
    comp = ds["bearing_mean_force_component"]
    for r in rows:
        for d, v in zip(r["directions"], r["mean"]):
            assert comp.sel(bearing=r["body"], bearing_direction=d).item() == v
    # and in the spreadsheet set (it had no bearing table)
    import csv

    res.to_csv(tmp_path / "r.csv")
    with open(tmp_path / "r_bearings.csv", newline="") as fh:
        table = {r["body"]: r for r in csv.DictReader(fh)}
    assert list(table) == [r["body"] for r in rows]
    for r in rows:
        assert float(table[r["body"]]["peak_force_magnitude_N"]) == r["peak_magnitude"]
        for d, v in zip(r["directions"], r["mean"]):
            assert float(table[r["body"]][f"mean_force_{d}_N"]) == v
    met = res.metrics()
    for g, members in met.load_sharing.groups.items():
        assert [str(m) for m in ds["mesh"].values[ds["mesh_group"].values == g]] == members
        assert ds["peak_to_nominal_engineering_group"].sel(group=g).item() == \
            met.dynamic_factors.per_group_peak_to_nominal_engineering[g]
    from typer.testing import CliRunner

    from torquesplit.cli import app

    out = CliRunner().invoke(app, ["run", str(tmp_path / "model.toml"), "--duration", "0.1",
                                   "--quiet"])
    assert "bearing forces (settled; peaks at every step, means from the history" in out.stdout


def test_every_element_force_is_kept_shaft_torques_in_newton_metres(tmp_path):
    """The history kept meshes and bearings only: a branch shaft's torque was nowhere in
    the files.  Now every element is, each with its unit (NetCDF coordinate
    'element_unit', CSV column suffix)."""
    res = torquesplit.simulate("ji_li_mill_drive", cycles=20)
    names = res.structure.element_names
    ds = res.to_dataset()
    units = dict(zip(ds["element"].values, ds["element_unit"].values))
    assert set(units) == set(names)
    assert [units[n] for n in ("input", "drive1", "drive2", "output")] == ["N m"] * 4
    assert all(units[n] == "N" for n in names if n not in res.model.shafts)
    assert ds["element_force"].attrs["units"] == "N or N m"
    # the shaft torque is the shaft's law on the saved state: k (theta_a - theta_b) at
    # the static equilibrium is the torque it carries (the branch's share of the input)
    col = list(ds["element"].values).index("drive1")
    static = res.static.element_forces[names.index("drive1")]
    assert ds["element_force"].values[0, col] == pytest.approx(static, rel=1e-9)
    res.to_csv(tmp_path / "r.csv")
    header = (tmp_path / "r_history.csv").read_text().splitlines()[0].split(",")
    assert "drive1_Nm" in header and "m11_N" in header and len(header) == len(names) + 1



def test_a_misspelt_definition_is_refused_by_every_export(tmp_path):
    """It was dropped: the file was written without metrics (and metric_values iterated
    the letters of one definition)."""
    res = torquesplit.simulate("ji_li_mill_drive", cycles=20)
    for call in (lambda: res.to_dataset("mean_forse"),
                 lambda: res.save(tmp_path / "r.nc", definition="foo"),
                 lambda: res.to_csv(tmp_path / "r.csv", definition="foo"),
                 lambda: res.warnings("foo")):
        with pytest.raises(ValueError, match="unknown load-sharing definition"):
            call()
    assert not list(tmp_path.iterdir())
    one = res.metric_values("mean_force")
    assert one == res.metric_values(["mean_force"]) and "load_sharing.mean_force" in one


def test_group_and_system_metrics_are_dataset_variables():
    """They were only inside the metrics_json attribute."""
    res = torquesplit.simulate("ji_li_mill_drive", cycles=20)
    met, ds = res.metrics(), res.to_dataset()
    assert list(ds["group"].values) == list(met.load_sharing.per_group)
    for g, v in met.load_sharing.per_group.items():
        assert float(ds["load_sharing_group"].sel(group=g)) == v
        assert float(ds["dynamic_factor_group"].sel(group=g)) == \
            met.dynamic_factors.per_group_dynamic_factor[g]
    assert float(ds["load_sharing_system"]) == met.load_sharing.system


def test_the_cycle_tables_give_the_peaks_back_over_the_settled_span(tmp_path):
    """A spreadsheet user could not get the summary's peak force from the cycles table:
    the settled span the metrics use was only in the about file (Ji & Li: the stage-1
    start-up peak 121,107 N against a settled 120,746 N)."""
    import csv
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate("ji_li_mill_drive", cycles=100)
    met = res.metrics()
    res.save(tmp_path / "r.csv")
    with open(tmp_path / "r_cycles.csv", newline="") as fh:
        cyc = list(csv.DictReader(fh))
    ds = res.to_dataset()
    for r in met.rows:
        col = [float(c[f"{r.mesh}_peak_N"]) if c[f"{r.mesh}_peak_N"] else -np.inf for c in cyc]
        flags = [c[f"{r.mesh}_settled"] for c in cyc]
        k = flags.index("1")  # the settled span: from one cycle on, to the mesh's last
        n = flags.count("1")  # complete cycle, and no row where it has no cycle (the
        # slow stage's rows past its last cycle were flagged 1, an exports review)
        assert set(flags[:k]) <= {"0"} and set(flags[k:k + n]) == {"1"}
        assert flags == ["1" if i >= k and c[f"{r.mesh}_peak_N"] else "0"
                         for i, c in enumerate(cyc)]
        assert k == met.settling.first_cycle[r.mesh] > 0
        assert max(col[k:]) == r.peak_force
        assert int(ds["first_settled_cycle"].sel(mesh=r.mesh)) == k
    assert max(float(c["m11_peak_N"]) for c in cyc if c["m11_peak_N"]) > met.rows[0].peak_force
    # the slow stage has a quarter of the fast one's cycles: its later rows are empty
    assert sum(c["m12_peak_N"] == "" for c in cyc) > len(cyc) / 2
    groups = list(ds["group"].values)
    assert list(ds["settle_time"].values) == [met.settling.group_time[g] for g in groups]
    # every recorded element's contact state, supports included (only in the .nc/.mat)
    with open(tmp_path / "r_elements.csv", newline="") as fh:
        els = list(csv.DictReader(fh))
    assert [e["element"] for e in els] == list(ds["element"].values)
    assert [float(e["contact_loss_fraction"]) for e in els] == list(
        ds["contact_loss_fraction"].values)
    assert [e["unit"] for e in els] == list(ds["element_unit"].values)
