"""Planetary review, polish: steady in kN and its period named once per frequency, K_gamma
in the .nc/.mat/.csv exports, planet.support named as written, an idler's torque, the gear
of contact's angular transmission error."""

from __future__ import annotations

import json
import tomllib
import warnings

import pytest
from typer.testing import CliRunner

from planetary_models import three_planet_toml
import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError

runner = CliRunner()

STAGE = three_planet_toml(
    "pol", mesh='{method = "iso6336"}',
    extra='pin_errors = [{tangential = "10 um"}, {}, {}]\n')


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("pol") / "pol.toml"
    path.write_text(STAGE)
    return path


@pytest.fixture(scope="module")
def run(model_file):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.simulate(torquesplit.load_model(model_file), cycles=40)


def test_planet_support_is_refused_as_written():
    raw = tomllib.loads(STAGE)
    raw["planetary"][0]["planet"]["support"] = {"stiffness": "1e8 N/m"}
    with pytest.raises(ModelError) as exc:
        torquesplit.load_model(raw)
    (loc, msg), = exc.value.issues
    assert loc == "planetary.0.planet.support" and "planet_bearing" in msg, (loc, msg)


def test_check_says_an_idler_planets_torque_is_per_mesh(model_file):
    res = runner.invoke(app, ["check", str(model_file)], terminal_width=250)
    assert res.exit_code == 0, res.output
    planet = [ln for ln in res.stdout.splitlines() if "st_planet1" in ln][0]
    assert "per mesh (idler: net 0)" in planet, planet
    sun = [ln for ln in res.stdout.splitlines() if "st_sun " in ln][0]
    assert "idler" not in sun
    res = runner.invoke(app, ["check", str(model_file), "--json"])
    bodies = json.loads(res.stdout)["bodies"]
    assert bodies["st_planet1"]["idler"] and not bodies["st_carrier"]["idler"]
    # the torques are magnitudes: each says what it is (a reviewer could not tell a star
    # stage's input from its output and its reaction)
    assert [bodies[b]["role"] for b in ("st_sun", "st_carrier", "st_ring", "st_planet1")] \
        == ["input", "output", "reaction", ""]
    res = runner.invoke(app, ["check", "lin_parker1999_star"], terminal_width=250)
    rows = {ln.split()[1]: ln for ln in res.stdout.splitlines() if ln.startswith("│ stage_")}
    assert "(input)" in rows["stage_sun"] and "(output)" in rows["stage_ring"]
    assert "(reaction)" in rows["stage_carrier"] and "(idler" in rows["stage_planet1"]
    # the power balance as what it is, its round-off as 0 ('balance -1.37e-16')
    assert "balance (input - output) / input: 0\n" in res.stdout, res.stdout[:300]


def test_contact_says_whose_angle_the_transmission_error_is(model_file):
    res = runner.invoke(app, ["contact", str(model_file), "--pair", "st_sun_planet1"],
                        terminal_width=250)
    assert res.exit_code == 0, res.output
    assert "TE p-p [arc s of st_planet1]" in res.stdout, res.stdout


def test_steady_prints_kn_and_names_one_frequency_once(model_file):
    res = runner.invoke(app, ["steady", str(model_file)], terminal_width=250)
    assert res.exit_code == 0, res.output
    assert "static F" in res.stdout and "static F [N]" not in res.stdout
    # run's columns and digits: factors to 4 decimals, forces to 5 digits (its 6 did not
    # hold: a planet's sun and ring mean forces differed in the 5th, a planetary reviewer)
    import re

    table = res.stdout[res.stdout.index("meshes (periodic steady state)"):]
    table = table[:table.index("└")]
    assert "[kN]" in table and "dynamic" in table and "nominal F" in table
    assert not re.search(r"\b\d\.\d{5}\b", table), table
    assert re.search(r"\b1\.\d{4}\b", table), table
    period = [ln for ln in res.stdout.splitlines() if "least common period" in ln][0]
    # the stage's meshes (and the pin error of a turning carrier) share no frequency,
    # or do: either way no source is named twice
    named = period.split(": ", 1)[1]
    assert named.count("st_sun_planet1") <= 1, period
    assert "1 cycles" not in period


def test_one_frequency_is_described_once():
    from torquesplit.steady.period import ExcitationSource, Period

    srcs = tuple(ExcitationSource(f"m{i}", "stiffness", 100.0, i) for i in range(3))
    text = Period(100.0, srcs, (1, 1, 1)).describe()
    assert text.endswith("1 cycle of the stiffness of m0 at 100 Hz and of 2 more "
                         "excitations at that frequency"), text
    two = (ExcitationSource("a", "stiffness", 300.0, 0), ExcitationSource("b", "error",
                                                                          100.0, 1))
    text = Period(100.0, two, (3, 1)).describe()
    assert "3 cycles of the stiffness of a" in text and "1 of the error of b" in text


def test_k_gamma_is_in_every_export(run, tmp_path):
    import xarray as xr
    from scipy.io import loadmat

    nc = run.to_netcdf(tmp_path / "r.nc")
    with xr.open_dataset(nc) as ds:
        values = dict(zip(ds["planet_entity"].values, ds["planet_load_sharing"].values))
        stored = json.loads(ds.attrs["planet_load_sharing_json"])
    assert set(values) == {"st_carrier", "st_planet1", "st_planet2", "st_planet3"}
    assert values["st_carrier"] == pytest.approx(stored["per_stage"]["st_carrier"])
    assert values["st_carrier"] > 1.001  # the pin error: unequal planet loads
    mat = loadmat(run.to_mat(tmp_path / "r.mat"))
    assert mat["planet_load_sharing"].ravel()[0] == pytest.approx(values["st_carrier"])
    run.to_csv(tmp_path / "r.csv")
    lines = (tmp_path / "r.csv").read_text().splitlines()
    head = lines[0].split(",")
    col = head.index("K_gamma")
    row = dict(zip(head, lines[1].split(",")))
    assert row["load_sharing_definition"] == stored["definition"]
    assert float(lines[1].split(",")[col]) == pytest.approx(values["st_carrier"])
    assert float(row["planet_factor"]) == pytest.approx(
        values[f"st_planet{row['mesh'][-1]}"])


def test_static_nc_has_k_gamma_and_the_peak_apart(model_file, tmp_path):
    import xarray as xr

    out = tmp_path / "s.nc"
    res = runner.invoke(app, ["static", str(model_file), "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    with xr.open_dataset(out) as ds:
        assert "planet_peak_instantaneous_ratio" in ds
        assert ds["planet_load_sharing"].sel(planet_entity="st_carrier") > 1.001
        assert "peak_instantaneous_ratio" in json.loads(ds.attrs["planet_load_sharing_json"])


def test_round_off_bearing_forces_read_zero():
    """The sun of a symmetric stage printed 'x 6.0984e-17, y 3.4230e-17' kN of round-off
    beside the planets' 1.06 kN (a reviewer)."""
    res = runner.invoke(app, ["run", "lin_parker1999_planetary", "--cycles", "41"])
    assert res.exit_code == 0, res.output
    row = next(ln for ln in res.stdout.splitlines() if ln.strip("│ ").startswith("stage_sun "))
    assert "e-1" not in row and "x 0.0000, y 0.0000" in row, row
