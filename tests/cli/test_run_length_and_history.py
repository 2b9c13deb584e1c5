"""run/report refuse --cycles with --duration by flag; a saved history says it is decimated."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from model_texts import split_model, write_model
from torquesplit.cli import app

runner = CliRunner()


@pytest.mark.parametrize("command", ["run", "report"])
def test_cycles_and_duration_together_are_refused_by_flag(tmp_path, command):
    path = write_model(tmp_path, split_model())
    res = runner.invoke(app, [command, str(path), "--cycles", "10", "--duration", "5ms"])
    assert res.exit_code == 2, res.output
    assert "--cycles" in res.output and "--duration" in res.output
    assert "duration=" not in res.output and "cycles=" not in res.output


def test_saved_force_history_says_its_sample_interval(tmp_path):
    path = write_model(tmp_path, split_model())
    out = tmp_path / "r.nc"
    res = runner.invoke(app, ["run", str(path), "--cycles", "20", "--json", "--out", str(out),
                              "--samples-per-period", "10"])
    assert res.exit_code == 0, res.output
    with xr.open_dataset(out) as ds:
        force = ds["element_force"]
        dt = float(np.median(np.diff(ds["time"].values)))
        assert force.attrs["sample_interval"] == pytest.approx(dt)
        assert force.attrs["sample_interval_units"] == "s"
        note = force.attrs["sampling"]
        assert "decimated" in note and f"{dt:.4g} s" in note and "every step" in note
    # by default a run this short keeps every step, and the file says so
    res = runner.invoke(app, ["run", str(path), "--cycles", "20", "--json", "--out", str(out),
                              "--force"])
    assert res.exit_code == 0, res.output
    with xr.open_dataset(out) as ds:
        assert ds["element_force"].attrs["sampling"].startswith(
            "history of every integration step")
