"""The planet load-sharing factor K_gamma in ``run``, ``static`` and their ``--json``; the
"not settled" note of a short run; ``modes --set``; ``contact`` on an internal mesh and
with ``--harris 0`` (user review)."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from model_texts import split_model, write_model
from torquesplit.cli import app

runner = CliRunner()

#: three planets, a tangential pin error on the first: unequal planet loads
PLANETARY = """
[model]
name = "pl"

[[planetary]]
name = "st"
planets = 3
module = "3 mm"
face_width = "40 mm"
sun = {teeth = 30}
planet = {teeth = 30}
ring = {teeth = 90, torsional_support = {rigid = true}}
carrier = {polar_inertia = "0.12 kg m^2"}
planet_bearing = {stiffness = "1e8 N/m"}
pin_errors = [{tangential = "10 um"}, {}, {}]
sun_mesh = {stiffness = "5e8 N/m", damping_ratio = 0.05}
ring_mesh = {stiffness = "5e8 N/m", damping_ratio = 0.05}

[drives.motor]
body = "st_sun"
speed = "1500 rpm"
torque = "300 N m"

[loads.out]
body = "st_carrier"
"""
PLANETS = ("st_planet1", "st_planet2", "st_planet3")


@pytest.fixture(scope="module")
def planetary(tmp_path_factory):
    return write_model(tmp_path_factory.mktemp("pl"), PLANETARY)


def _invoke(args, code=0):
    res = runner.invoke(app, args)
    assert res.exit_code == code, res.output
    return res.stdout


def _planet_json(data, definition):
    k = data["planet_load_sharing"]
    assert k["definition"] == definition
    assert set(k["per_planet"]) == set(PLANETS)
    assert k["per_stage"]["st_carrier"] == max(k["per_planet"].values())
    assert k["groups"]["st_carrier"] == ["st-ring", "st-sun"]
    return k


def test_run_shows_and_reports_planet_load_sharing(planetary):
    """A 'planets' table after the groups, and the same numbers in --json."""
    text = _invoke(["run", str(planetary), "--quiet"])
    assert text.index("load-sharing groups") < text.index("planets (load sharing: mean_force)")
    assert "K_gamma (stage)" in text and all(p in text for p in PLANETS)
    assert "K_gamma of a stage: its largest planet load over the mean" in text
    data = json.loads(_invoke(["run", str(planetary), "--quiet", "--json"]))
    k = _planet_json(data, "mean_force")
    assert k["per_stage"]["st_carrier"] > 1.03          # the pin error loads two planets more
    assert k["per_planet"]["st_planet1"] < 1.0
    assert f"{k['per_stage']['st_carrier']:.4f}" in text


def test_a_peak_based_definition_labels_the_stage_value_not_k_gamma(planetary):
    """K_gamma is the standards' ratio of mean loads: a peak-based definition's stage
    value is that definition's planet coefficient, and the table says so."""
    text = _invoke(["run", str(planetary), "--quiet", "--definition", "cycle_peak"])
    assert "planets (load sharing: cycle_peak)" in text
    assert "K_gamma (stage)" not in text
    assert "planet load-sharing coefficient (cycle_peak)" in " ".join(text.split())
    assert "is the stage value of --definition mean_force" in " ".join(text.split())


def test_static_shows_planet_load_sharing_equal_to_the_dynamic_mean(planetary):
    data = json.loads(_invoke(["static", str(planetary), "--quiet", "--json"]))
    # per_stage is K_gamma of the position-averaged loads; the static torque ratio (its
    # peak over the positions) is apart, under its definition's name
    k = _planet_json(data, "K_gamma")
    assert k["peak_instantaneous_ratio"]["definition"] == "static_torque"
    run = json.loads(_invoke(["run", str(planetary), "--quiet", "--json"]))
    dyn = run["planet_load_sharing"]["per_stage"]["st_carrier"]
    assert k["per_stage"]["st_carrier"] == pytest.approx(dyn, rel=1e-6)
    text = _invoke(["static", str(planetary), "--quiet"])
    assert "planets (load sharing: static_torque)" in text and "K_gamma (stage)" in text


def test_a_model_without_planets_has_no_planet_table_or_key(tmp_path):
    model = write_model(tmp_path, split_model())
    data = json.loads(_invoke(["run", str(model), "--quiet", "--json", "--cycles", "60"]))
    assert "planet_load_sharing" not in data
    assert "planets (load sharing" not in _invoke(["run", str(model), "--quiet",
                                                    "--cycles", "60"])


def test_unsettled_run_points_to_the_warnings():
    """A run too short to settle: the run line no longer claims the last half was used."""
    res = runner.invoke(app, ["run", "lin_parker1999_planetary", "--quiet", "--cycles", "10"])
    assert res.exit_code == 0, res.output
    flat = " ".join(res.stdout.split())
    assert "(not settled: see the warnings)" in flat and "last half used" not in flat


def test_modes_takes_set_overrides():
    data = json.loads(_invoke(["modes", "lin_parker1999_planetary", "--set",
                               "planetary.0.planets=3", "--no-rotating-frame", "--json"]))
    assert data["rigid_body_modes"] == 1 and len(data["modes"]) == 17  # 18 DOFs for 3 planets
    assert "stage_planet4.x" not in data["modes"][0]["shape"]
    res = runner.invoke(app, ["modes", "lin_parker1999_planetary", "--set",
                              "planetary.0.planetz=3"])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "--set planetary.0.planetz=3" in lines[0]


def test_contact_on_an_internal_mesh_says_why_there_is_no_impact():
    note = "meshing-in impact: not computed for internal gears"
    args = ["contact", "lin_parker1999_planetary", "--pair", "stage_ring_planet1",
            "--harris", "0", "--positions", "16", "--slices", "8"]
    data = json.loads(_invoke(args + ["--json"]))
    assert data["impact"] is None
    assert [w for w in data["warnings"] if w.startswith(note)]
    assert note in " ".join(_invoke(args).split())


def test_contact_harris_zero_prints_and_draws_no_harris_map(tmp_path):
    args = ["contact", "lin_parker1999_planetary", "--pair", "stage_sun_planet1",
            "--positions", "16", "--slices", "8", "--harris", "0", "--load", "500 N",
            "--load", "600 N"]
    res = runner.invoke(app, args + ["--plot", str(tmp_path / "figs")])
    assert res.exit_code == 0, res.output
    assert "Harris map" not in res.stdout
    written = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert "contact_harris.png" not in written and "contact_te.png" in written
    data = json.loads(_invoke(args + ["--json"]))
    assert data["harris"] is None
    assert "Harris map" in _invoke(args[:-6] + ["--harris", "2"])
