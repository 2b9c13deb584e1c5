"""The ``modes`` command on a planetary stage (every mode by default, multiplicity, type,
shapes in JSON and NetCDF) and one-line errors for planetary input."""

from __future__ import annotations

import json

import pytest
import xarray as xr
from typer.testing import CliRunner

from torquesplit.cli import app

runner = CliRunner()
LP = "lin_parker1999_planetary"


def _json(args):
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return json.loads(res.output)


def test_modes_lists_every_mode_with_type_and_shape():
    """All 20 elastic modes of the 21-DOF stage (none cut at 20), each with its
    multiplicity, type and mass-normalised shape over the 21 DOFs."""
    data = _json(["modes", LP, "--no-rotating-frame", "--json"])
    modes = data["modes"]
    assert data["rigid_body_modes"] == 1 and len(modes) == 20
    assert data["rotating_frame"] is False
    kinds = {m["type"] for m in modes}
    assert kinds == {"rotational", "translational", "planet"}
    first = modes[0]
    assert first["type"] == "translational" and first["multiplicity"] == 2
    assert len(first["shape"]) == 21 and "stage_planet1.x" in first["shape"]
    # the pair reports one set of strain-energy shares (basis-independent): equal rows
    assert modes[0]["strain_energy"] == modes[1]["strain_energy"]
    assert 0.5 < sum(modes[0]["strain_energy"].values()) <= 1.0 + 1e-9  # the largest six
    turning = _json(["modes", LP, "--json"])
    assert turning["rotating_frame"] is True
    assert turning["modes"][0]["multiplicity"] == 1  # the pair splits
    assert len(turning["modes"][0]["shape"]["stage_sun.x"]) == 2  # complex: [re, im]


def test_modes_below_and_count_keep_groups_whole(tmp_path):
    data = _json(["modes", LP, "--no-rotating-frame", "--json", "--below", "1.6 kHz"])
    assert [round(m["frequency_Hz"]) for m in data["modes"]] == [727, 727, 1091, 1091, 1537]
    data = _json(["modes", LP, "--no-rotating-frame", "--json", "--count", "1"])
    assert len(data["modes"]) == 2  # the degenerate pair is not cut
    out = tmp_path / "modes.nc"
    res = runner.invoke(app, ["modes", LP, "--no-rotating-frame", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "natural modes" in res.output and "translational" in res.output
    ds = xr.open_dataset(out)
    assert ds.sizes["mode"] == 20 and ds.sizes["dof"] == 21
    assert set(ds["type"].values) == {"rotational", "translational", "planet"}
    assert int(ds["multiplicity"].sel(mode=1)) == 2
    ds.close()


@pytest.mark.parametrize("args, text", [
    (["modes", LP, "--below", "fast"], "--below"),
    (["modes", LP, "--count", "0"], "--count"),
])
def test_modes_bad_options(args, text):
    res = runner.invoke(app, args)
    assert res.exit_code == 2 and text in res.output


def test_planets_that_do_not_fit_are_one_line_errors(tmp_path):
    from torquesplit.examples import example_path

    text = example_path(LP).read_text(encoding="utf-8").replace("planets = 4", "planets = 7")
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    # one line per problem, all at once: the assembly condition, and the overlap
    assert all(ln.startswith("error:") for ln in lines) and 1 <= len(lines) <= 2, lines
    assert "planetary.0.planets" in lines[0] and "assembly condition" in lines[0]
    assert len(lines) == 1 or "planets overlap" in lines[1]
