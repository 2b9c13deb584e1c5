"""A planetary analyst's notes: the bearing table says its frame, and a planet factor
that counts pulling teeth says so."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from torquesplit.cli import app

EXAMPLE = "lin_parker1999_planetary"


def test_the_bearing_table_says_which_frame_its_directions_are_in():
    """Planet 1's 'x 0.042, y 1.034 kN' is the force on its pin in the turning carrier's
    frame (tangential 2 F cos(alpha), radial m Omega^2 R); only the results file said so."""
    res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30"])
    assert res.exit_code == 0, res.output
    table = res.stdout[res.stdout.index("bearing forces"):]
    assert "directions in" in table and "carrier stage_carrier (turning)" in table


def test_the_bearing_rows_of_the_files_say_their_frame_too(tmp_path):
    """The JSON, the CSV and the report had the forces without their frame: a sun's force,
    steady in the carrier's frame, read as a steady load on the housing."""
    import csv

    res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30", "--json", "--out",
                                   str(tmp_path / "r.csv")])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.stdout)["bearing_forces_N"]
    frames = {r["body"]: r["frame"] for r in rows}
    assert frames["stage_planet1"] == "carrier stage_carrier (turning)", frames
    path = next(tmp_path.glob("*bearings.csv"))
    table = list(csv.DictReader(path.read_text().splitlines()))
    assert {r["body"]: r["frame"] for r in table} == frames
    res = CliRunner().invoke(app, ["report", EXAMPLE, "--cycles", "30", "--out",
                                   str(tmp_path / "rep.html")])
    assert res.exit_code == 0, res.output
    html = (tmp_path / "rep.html").read_text()
    bearings = html[html.index("<h3>Bearing forces</h3>"):]
    assert "directions in" in bearings and "carrier stage_carrier (turning)" in bearings


def test_a_planet_factor_that_counts_pulling_teeth_says_so():
    """Without backlash an unloaded planet's teeth pull, and K_gamma counts the pull
    (4.37 > N = 4 on a reviewer's stage): the warning names the cause and the fix."""
    res = CliRunner().invoke(app, [
        "static", EXAMPLE, "--quiet", "--json", "--points-per-cycle", "2",
        "--set", 'planetary.0.pin_errors=[{tangential="-60 um"},{},{},{}]',
        "--set", 'planetary.0.sun.dofs=["theta"]'])
    assert res.exit_code == 0, res.output
    said = [w for w in json.loads(res.stdout)["warnings"] if "teeth pull" in w]
    assert said and "give the backlash" in said[0]
    res = CliRunner().invoke(app, [
        "static", EXAMPLE, "--quiet", "--json", "--points-per-cycle", "2",
        "--set", 'planetary.0.pin_errors=[{tangential="-60 um"},{},{},{}]',
        "--set", 'planetary.0.sun.dofs=["theta"]',
        "--set", "planetary.0.sun_mesh.backlash=300um",
        "--set", "planetary.0.ring_mesh.backlash=300um"])
    assert not [w for w in json.loads(res.stdout)["warnings"] if "teeth pull" in w]


def test_steady_gives_the_planet_load_sharing_as_run_does():
    """'steady' printed no planet table and its JSON had no planet_load_sharing (its
    results file had the variable)."""
    fourier = '{method = "fourier", mean = "5e8 N/m", cos = ["1e8 N/m"], sin = []}'
    args = ["steady", EXAMPLE, "--no-stability",
            "--set", f"planetary.0.sun_mesh.stiffness={fourier}",
            "--set", f"planetary.0.ring_mesh.stiffness={fourier}"]
    res = CliRunner().invoke(app, args + ["--json"])
    assert res.exit_code == 0, res.output
    k = json.loads(res.stdout)["planet_load_sharing"]
    assert abs(k["per_stage"]["stage_carrier"] - 1.0) < 1e-6  # equal spacing, no errors
    res = CliRunner().invoke(app, args)
    assert "planets (load sharing" in res.stdout


def test_a_held_ring_has_its_reaction_in_the_carriers_frame(tmp_path):
    """A planetary reviewer's held ring had no bearing row (its meshes turn with the
    carrier): its load on the housing was missing from the table.  It is the sum of its
    meshes' forces in the carrier's frame, as the planets' rows: about zero for three
    equal planets at 120 degrees, and the pin error's imbalance with one."""
    import torquesplit
    from planetary_models import three_planet_toml

    def ring_row(extra=""):
        path = tmp_path / f"p{len(extra)}.toml"
        path.write_text(three_planet_toml("p", extra=extra))
        res = torquesplit.simulate(torquesplit.load_model(path), cycles=60)
        rows = {r["body"]: r for r in res.bearing_forces()}
        mesh = max(abs(r.mean_force) for r in res.metrics().rows)
        # every row in the carrier's frame here (the floating sun's too): the bearings
        # hold the whole stage, so their mean forces add up to nothing
        assert {r["frame"] for r in rows.values()} == {"carrier st_carrier (turning)"}
        total = np.sum([r["mean"] for r in rows.values()], axis=0)
        assert np.abs(total).max() < 1e-3 * mesh, total
        return rows["st_ring"], mesh

    ring, mesh = ring_row()
    assert ring["held"] == "rigid" and ring["mean_magnitude"] < 1e-6 * mesh
    ring, mesh = ring_row('pin_errors = [{tangential = "20 um"}, {}, {}]\n')
    assert ring["mean_magnitude"] > 0.1 * mesh  # (0.23 of it: 1.44 kN, as the sun's)
