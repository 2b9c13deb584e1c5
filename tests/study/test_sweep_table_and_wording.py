"""sweep's table shows the unit of the varied parameter; runner messages name both the
argument of the Python API and the flag of the command line."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from study_helpers import CYCLES
from torquesplit.cli import app
from torquesplit.study.runners import make_runner

runner = CliRunner()


def test_sweep_table_header_carries_the_unit(tmp_path, split_file):
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.transmission_error.constant,"
                              "meshes.a2.transmission_error.constant=0:10:2um",
                              "--output", "load_sharing.cycle_peak", "--cycles", str(CYCLES),
                              "--workers", "1", "--out", str(tmp_path / "sw"), "--quiet",
                              "--no-figures"])
    assert res.exit_code == 0, res.output
    assert "constant [µm]" in res.stdout


def test_sweep_refuses_cycles_with_duration_by_flag(split_file):
    res = runner.invoke(app, ["sweep", str(split_file), "--vary", "meshes.a1.stiffness=1:2:2",
                              "--cycles", "10", "--duration", "5ms"])
    assert res.exit_code == 2
    assert "--cycles" in res.output and "--duration" in res.output


def test_make_runner_names_the_argument_and_the_flag():
    with pytest.raises(ValueError) as info:
        make_runner(-1)
    assert "workers=2" in str(info.value) and "--workers 2" in str(info.value)


def test_a_grid_with_many_outputs_prints_grid_tables_not_statistics(tmp_path, split_file):
    import tomli_w

    from study_helpers import grid_study

    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um", "4 um"]}],
                      outputs=["load_sharing.cycle_peak*", "peak_force.*"])
    path = tmp_path / "g.toml"
    path.write_text(tomli_w.dumps(data))
    res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / "o"), "--workers",
                              "1", "--quiet", "--no-figures"], terminal_width=200)
    assert res.exit_code == 0, res.output
    text = res.stdout
    assert "p95" not in text and "mean " not in text
    # a table per family, the family in the title, the members as column headers
    assert "test grid: load_sharing.cycle_peak" in text and "test grid: peak_force" in text
    for member in ("system", "split", "a1", "a2", "b1", "b2"):
        assert f" {member} " in text
    assert "cycle_peak.a1" not in text and "peak_force.a1" not in text
    # what each family measures, as run's legend says it (a reviewer: the tables named
    # their columns only)
    from torquesplit.metrics.load_sharing import DEFINITION_TEXT

    flat = " ".join(text.split())
    assert f"load_sharing.cycle_peak: {DEFINITION_TEXT['cycle_peak']}" in flat, text
    assert "peak_force: peak mesh force" in flat
    res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / "o"), "--resume",
                              "--json", "--no-figures"])
    import json

    data = json.loads(res.stdout)
    assert data["output_dimensions"] == ["meshes.a1.transmission_error.constant"]
    assert data["output_units"]["peak_force.a1"] == "N"
    assert data["definitions"][0].startswith("load_sharing.cycle_peak: ")


def test_a_large_grid_is_not_summarised_as_a_sample(tmp_path, split_file, monkeypatch):
    from torquesplit.study import cli as study_cli

    monkeypatch.setattr(study_cli, "MAX_TABLE_CASES", 1)
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.transmission_error.constant=0:10:2um",
                              "--output", "load_sharing.cycle_peak", "--cycles", str(CYCLES),
                              "--workers", "1", "--out", str(tmp_path / "sw"), "--quiet",
                              "--no-figures"])
    assert res.exit_code == 0, res.output
    assert "a grid of 2 cases (2), too many to print" in res.stdout
    assert "p95" not in res.stdout


@pytest.mark.parametrize("args, said", [
    # the first --vary was dropped silently
    (["--vary", "meshes.a1.damping_ratio=0.01:0.1:2", "--vary",
      "meshes.b1.damping_ratio=0.01:0.1:2"], "--vary is given twice"),
    # --set on the varied path was accepted silently
    (["--vary", "meshes.a1.damping_ratio=0.01:0.1:2", "--set", "meshes.a1.damping_ratio=0.05"],
     "sets a path that --vary varies"),
    # rich printed ':100:' as an emoji
    (["--vary", "meshes.a1.backlash=10:100:2"], "'meshes.a1.backlash=10:100:2'"),
])
def test_sweep_refuses_what_it_would_drop_and_prints_the_text_as_given(split_file, args, said):
    res = runner.invoke(app, ["sweep", str(split_file), *args])
    assert res.exit_code == 2 and said in res.stderr, res.stderr
    assert "\U0001f4af" not in res.stderr


def test_sweep_reports_every_bad_option_at_once(split_file):
    """A reviewer's bad --output hid --workers 0, and a range without its unit hid the bad
    --output: each needed another attempt."""
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.transmission_error.constant=0:10:3",
                              "--output", "load_sharing.peak", "--workers", "0"])
    assert res.exit_code == 2, res.output
    errors = [ln for ln in res.output.splitlines() if ln.startswith("error: ")]
    assert [e.split(":")[1].split()[0] for e in errors] == ["--workers", "--vary", "--output"], \
        res.output
    assert "range has no unit" in errors[1] and "matches no output" in errors[2]
    assert "'0:10:3mm' or '0:10:3um'" in errors[1]  # (a length: a diameter's or a gap's)


def test_a_wrong_unit_of_vary_is_told_in_the_sweeps_words(split_file):
    """It said 'write e.g. unit = "um"': the study file's syntax, not --vary's."""
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.transmission_error.constant=0:10:3Nm"])
    assert res.exit_code == 2, res.output
    assert "write the unit after the count, e.g. START:STOP:NUMum" in res.stderr, res.stderr
    assert 'unit = "' not in res.stderr


def test_a_unit_on_a_plain_number_field_is_said_in_the_sweeps_words(tmp_path):
    """It said "remove 'unit'", a study file's key, to a command line."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                                   "meshes.m11.damping_ratio=0.05:0.1:2mm", "--out",
                                   str(tmp_path / "s")])
    assert res.exit_code == 2
    assert "write no unit after the count" in res.stderr and "'unit'" not in res.stderr


def test_a_range_without_its_unit_is_said_once(tmp_path):
    """After 'write the unit after the count' it also said that case 0, at 0.5 m, was an
    invalid model: the consequence of the same slip, read in SI."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    vary = ["sweep", "ji_li_mill_drive", "--vary", "meshes.m11.backlash=0.5:1.5:3",
            "--out", str(tmp_path / "s")]
    res = CliRunner().invoke(app, vary)
    assert res.exit_code == 2
    err = " ".join(res.stderr.split())
    assert "write the unit after the count" in err
    assert "case 0" not in err and "deeper than the whole tooth" not in err
    res = CliRunner().invoke(app, vary + ["--output", "load_sharing.bogus"])
    err = " ".join(res.stderr.split())  # (the other options' problems are still said)
    assert "write the unit after the count" in err
    assert "--output: 'load_sharing.bogus' matches no output" in err
