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
    assert "constant [um]" in res.stdout


def test_sweep_refuses_cycles_with_duration_by_flag(split_file):
    res = runner.invoke(app, ["sweep", str(split_file), "--vary", "meshes.a1.stiffness=1:2:2",
                              "--cycles", "10", "--duration", "5ms"])
    assert res.exit_code == 2
    assert "--cycles" in res.output and "--duration" in res.output


def test_make_runner_names_the_argument_and_the_flag():
    with pytest.raises(ValueError) as info:
        make_runner(-1)
    assert "workers=2" in str(info.value) and "--workers 2" in str(info.value)
