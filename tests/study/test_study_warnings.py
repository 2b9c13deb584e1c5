"""A case's warnings (the model checks' unit slips, a run too short to tell whether it
settled) reach the Dataset and the command line's summary; none is dropped."""

from __future__ import annotations

import json

import tomli_w
from typer.testing import CliRunner

from study_helpers import grid_study
from torquesplit.cli import app
from torquesplit.study import run_study
from torquesplit.study.dataset import case_ranges, warning_groups

runner = CliRunner()


def test_a_run_too_short_warns_in_the_dataset_and_the_summary(tmp_path, split_file):
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um", "4 um", "8 um"]}],
                      outputs=["load_sharing.cycle_peak"], cycles=5)
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(data))
    res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / "o"), "--workers",
                              "1", "--quiet", "--no-figures"])
    assert res.exit_code == 0, res.output
    assert "3 of 3 cases warned" in res.stdout
    # each case with its value (a reviewer counted a sweep's cases from 1 and read the
    # warning as another value's)
    assert ("cases 0-2 (meshes.a1.transmission_error.constant = 0, 4, 8 µm): analysis: the "
            "run is too short") in " ".join(res.stdout.split()), res.stdout
    res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / "o"), "--resume",
                              "--json", "--no-figures"])
    got = json.loads(res.stdout)
    assert got["cases_warned"] == 3 and got["warnings"][0]["cases"] == [0, 1, 2]
    assert "too short" in got["warnings"][0]["text"]


def test_a_unit_slip_warns_for_its_case_only(split_file):
    data = grid_study(split_file, [{"path": "gears.pinion.errors.eccentricity",
                                    "values": ["0 um", 0.003]}],  # 0.003: read in m
                      outputs=["load_sharing.cycle_peak"])
    ds = run_study(data, workers=1)
    assert "eccentricity" not in str(ds["warnings"].values[0])
    assert "gears.pinion.errors.eccentricity: 3 mm" in str(ds["warnings"].values[1])
    assert ds["warning_count"].values[1] > ds["warning_count"].values[0]
    slips = [g for g in warning_groups(ds) if "larger than the module" in g["text"]]
    assert [g["cases"] for g in slips] == [[1]]


def test_case_ranges():
    assert case_ranges([0, 1, 2, 5, 7, 8]) == "cases 0-2, 5, 7-8"
    assert case_ranges([4]) == "case 4"


def test_a_settle_rule_that_reaches_its_cap_warns(split_file):
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["4 um"]}], outputs=["load_sharing.cycle_peak"],
                      cycles=40, settle={"tolerance": 0.002, "start": "0.02 s"})
    ds = run_study(data, workers=1)
    assert ds["settled"].values[0] == 0
    said = str(ds["warnings"].values[0])
    assert "analysis.settle: the outputs still changed" in said
    # the kept run's settling only, not that of the rule's shorter trial runs (which
    # simulate, warning in Python of a run too short to settle, gave the case too: three
    # 'too short' texts, 1, 3 and 7 cycles of the slow stage)
    ds = run_study({"study": {"name": "s", "model": "ji_li_mill_drive",
                              "outputs": ["load_sharing.cycle_peak"]},
                    "analysis": {"duration": "0.3 s",
                                 "settle": {"tolerance": 0.2, "start": "0.08 s"}},
                    "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                             "values": [0.05]}]}}, workers=1)
    said = str(ds["warnings"].values[0])
    assert said.count("too short to tell") == 1 and "completes 7 cycles" in said
    # a rule whose first run is its cap compares nothing, and says so (it said the
    # outputs 'still changed', a studies reviewer)
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["4 um"]}], outputs=["load_sharing.cycle_peak"],
                      cycles=40, settle={"tolerance": 0.002, "start": "10 s"})
    ds = run_study(data, workers=1)
    said = str(ds["warnings"].values[0])
    assert ds["settled"].values[0] == 0
    assert "the rule's first run is already the longest" in said
    assert "still changed" not in said


def test_grouped_warnings_say_nothing_one_case_contradicts():
    """Three cases of a sweep warned about different meshes and values; the summary
    printed the first case's mesh and numbers for all three ('cases 1-3: meshes.in1 ...
    15.75 kN'), while cases 2 and 3 were about in2 at 15.1 and 18.34 kN."""
    import numpy as np
    import xarray as xr

    texts = ["meshes.in1: peak 15.75 kN, dynamic factor 2.06",
             "meshes.in2: peak 15.1 kN, dynamic factor 2.029",
             "meshes.in2: peak 18.34 kN, dynamic factor 2.475\nanalysis: 1e-3 s step"]
    ds = xr.Dataset({"warnings": ("case", np.array(texts, dtype=object))})
    groups = warning_groups(ds)
    assert groups[0] == {"text": "meshes.in2: peak 15.1 to 18.34 kN, dynamic factor 2.029 "
                                 "to 2.475", "cases": [1, 2]}
    assert {"text": texts[0], "cases": [0]} in groups
    assert {"text": "analysis: 1e-3 s step", "cases": [2]} in groups


def test_a_study_case_is_not_told_that_its_unread_history_is_coarse(monkeypatch, split_file):
    """Every case of a reviewer's 120 s study warned that 'the history holds at most
    200,000 samples ... the files' waveforms are that coarse': the study chose that
    sparse history itself and writes no waveforms.  A run that asks for the sampling is
    still told."""
    import torquesplit
    import torquesplit.simulation as sim

    monkeypatch.setattr(sim, "MAX_HISTORY_RECORDS", 50)
    said = "the history holds at most 50 samples"
    res = torquesplit.simulate("ji_li_mill_drive", cycles=40, samples_per_period=20)
    assert any(said in w for w in res.warnings())
    with sim.history_unused():
        res = torquesplit.simulate("ji_li_mill_drive", cycles=40, samples_per_period=20)
    assert not any(said in w for w in res.warnings())
    res = torquesplit.simulate("ji_li_mill_drive", cycles=40, samples_per_period=20)
    assert any(said in w for w in res.warnings())  # (the block's end restores it)
    # a study's case (in this process: one worker) runs in the block
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um"]}], outputs=["load_sharing.cycle_peak"],
                      cycles=40)
    ds = run_study(data, workers=1)
    texts = " ".join(str(t) for t in ds["warnings"].values.ravel())
    assert "the history holds at most" not in texts
    # (the same sampling asked for outside a study does warn for this model too)
    assert any(said in w for w in torquesplit.simulate(
        split_file, cycles=40, samples_per_period=20).warnings())


def test_the_step_and_position_bounds_a_message_points_to_are_study_fields(split_file):
    """A reviewer: a case refused for 'more than max_steps ...; raise max_steps
    (--max-steps)' and a static sweep thinned to max_points pointed to options a study
    does not have; [analysis] max_steps and max_points are its fields now."""
    import pytest

    from torquesplit.errors import StudyError

    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um"]}], max_steps=100)
    ds = run_study(data, workers=1)
    reason = str(ds["reason"].values[0])
    assert ds["status"].values[0] == "refused"
    assert "max_steps = 100" in reason and "a study's [analysis] max_steps" in reason
    assert "settled" in ds.data_vars
    static = {"study": {"name": "s", "model": "mo2017_star_reducer",
                        "outputs": ["load_sharing.static_torque"]},
              "analysis": {"type": "static", "revolutions": 0.05, "max_points": 16},
              "grid": {"parameters": [{"path": "gears.*.errors.eccentricity", "name": "e",
                                       "values": ["0 um"]}]}}
    ds = run_study(static, workers=1)
    # (every case of a quasi-static study was 'settled = 1': it has nothing to settle)
    assert "settled" not in ds.data_vars
    said = str(ds["warnings"].values[0])
    assert ds["status"].values[0] == "ok" and "cut to max_points = 16 positions" in said
    assert "a study's [analysis] max_points" in said
    for field, other in (("max_steps", static), ("max_points", data)):
        bad = {**other, "analysis": {**other["analysis"], field: 1000}}
        with pytest.raises(StudyError, match=rf"analysis\.{field}"):
            run_study(bad, workers=1)


def test_a_cases_warnings_split_back_from_its_spreadsheet_cell(tmp_path, split_file):
    """results.csv joined a case's warnings with '; ', which their texts contain: a case
    of two warnings split into five (a studies reviewer)."""
    import csv

    from torquesplit.study.dataset import WARNING_JOIN

    data = grid_study(split_file, [{"path": "gears.pinion.errors.eccentricity",
                                    "values": [0.003]}],  # (3 mm: a unit slip)
                      outputs=["load_sharing.cycle_peak"], cycles=5)
    ds = run_study(data, workers=1, out=tmp_path / "o", figures=False)
    n = int(ds["warning_count"].values[0])
    assert n >= 2 and any("; " in w for w in str(ds["warnings"].values[0]).splitlines())
    with open(tmp_path / "o" / "results.csv", newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["warnings"].split(WARNING_JOIN) == str(ds["warnings"].values[0]).splitlines()


def test_the_spreadsheet_names_an_output_as_the_study_file_does():
    """A group 'left/bevel' is 'left|bevel' in the NetCDF (which forbids '/'); the
    spreadsheet's header said so too, where --json and the study file say 'left/bevel'
    (a studies reviewer)."""
    import csv
    import io

    import numpy as np
    import xarray as xr

    from torquesplit.study.dataset import case_table_bytes, variable_name

    name = "load_sharing.static_torque.left/bevel"
    ds = xr.Dataset({"status": ("sample", np.array(["ok"], dtype=object)),
                     variable_name(name): ("sample", [1.05], {"output": name, "units": "1"}),
                     "peak_force.m1": ("sample", [2.0e3], {"output": "peak_force.m1",
                                                           "units": "N"})},
                    coords={"sample": [0]})
    header = next(csv.reader(io.StringIO(case_table_bytes(ds).decode())))
    assert name in header and "peak_force.m1 [N]" in header
    assert not [h for h in header if "|" in h]
