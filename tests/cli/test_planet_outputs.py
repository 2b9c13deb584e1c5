"""A planetary analyst's notes: the bearing table says its frame, and a planet factor
that counts pulling teeth says so."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from torquesplit.cli import app

EXAMPLE = "lin_parker1999_planetary"


def test_the_bearing_table_says_which_frame_its_directions_are_in():
    """Planet 1's 'x 0.042, y 1.034 kN' is the force on its pin in the turning carrier's
    frame (tangential 2 F cos(alpha), radial m Omega^2 R); only the results file said so."""
    res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30"])
    assert res.exit_code == 0, res.output
    table = res.stdout[res.stdout.index("bearing forces"):]
    assert "directions in" in table and "turning with stage_carrier" in table


def test_the_bearing_rows_of_the_files_say_their_frame_too(tmp_path):
    """The JSON, the CSV and the report had the forces without their frame: a sun's force,
    steady in the carrier's frame, read as a steady load on the housing."""
    import csv

    res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30", "--json", "--out",
                                   str(tmp_path / "r.csv")])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.stdout)["bearing_forces_N"]
    frames = {r["body"]: r["frame"] for r in rows}
    assert frames["stage_planet1"] == "turning with stage_carrier", frames
    path = next(tmp_path.glob("*bearings.csv"))
    table = list(csv.DictReader(path.read_text().splitlines()))
    assert {r["body"]: r["frame"] for r in table} == frames
    res = CliRunner().invoke(app, ["report", EXAMPLE, "--cycles", "30", "--out",
                                   str(tmp_path / "rep.html")])
    assert res.exit_code == 0, res.output
    html = (tmp_path / "rep.html").read_text()
    bearings = html[html.index("<h3>Bearing forces</h3>"):]
    assert "directions in" in bearings and "turning with stage_carrier" in bearings


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
        assert {r["frame"] for r in rows.values()} == {"turning with st_carrier"}
        total = np.sum([r["mean"] for r in rows.values()], axis=0)
        assert np.abs(total).max() < 1e-3 * mesh, total
        return rows["st_ring"], mesh

    ring, mesh = ring_row()
    assert ring["held"] == "rigid" and ring["mean_magnitude"] < 1e-6 * mesh
    ring, mesh = ring_row('pin_errors = [{tangential = "20 um"}, {}, {}]\n')
    assert ring["mean_magnitude"] > 0.1 * mesh  # (0.23 of it: 1.44 kN, as the sun's)


def test_check_says_which_frame_a_planet_mesh_and_speed_are_in():
    """The differential's sun meshes read 'stage_planet1->stage_sun' with 1.56 kW each,
    as an output would: that is the flank the teeth drive in the carrier's frame.  The
    table marks those meshes and says so; the JSON names each mesh's frame; a planet's
    speed on its pin (its bearing's) is beside its absolute one; an idler puts in no
    power (a planet read 5.7 kW: one mesh's torque times its speed)."""
    res = CliRunner().invoke(app, ["check", "split_path_planetary_differential"])
    assert res.exit_code == 0, res.output
    out = " ".join(res.stdout.split())
    assert "stage_planet1->stage_sun *" in out and "path_a pinion_a->sun_wheel *" not in out
    assert "* in the frame turning with stage_carrier: the driving flank" in out
    assert "-2200 (-600 on its pin)" in out
    res = CliRunner().invoke(app, ["check", "split_path_planetary_differential", "--json"])
    s = json.loads(res.stdout)
    assert s["meshes"]["stage_sun_planet1"]["frame"] == "turning with stage_carrier"
    assert s["meshes"]["path_a"]["frame"] == "housing"
    planet = s["bodies"]["stage_planet1"]
    # -2200 rpm absolute, the carrier at -1600 rpm: -600 rpm on the pin
    assert planet["speed_relative_to_carrier_rpm"] == pytest.approx(-600.0, rel=1e-12)
    assert planet["carrier"] == "stage_carrier" and planet["power_kW"] == 0.0
    assert "speed_relative_to_carrier_rpm" not in s["bodies"]["stage_sun"]


def test_the_run_says_what_a_planets_bearing_carries(tmp_path):
    """4.49 kN on a planet's bearing beside 0.59 kN tooth forces: its centrifugal force
    m Omega_c^2 r (1.7756 kg, 1600 rpm, 90 mm), said under the table; the JSON's units
    are those of the keys it has (it listed an RMS transmission error a run has not)."""
    res = CliRunner().invoke(app, ["run", "split_path_planetary_differential",
                                   "--cycles", "30"])
    assert res.exit_code == 0, res.output
    out = " ".join(res.stdout.split())
    m = 1.7756
    assert "include their centrifugal force m Ω_c² r: 4.486" in out
    assert m * (1600 * np.pi / 30) ** 2 * 0.090 == pytest.approx(4486, rel=2e-4)
    res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30", "--json"])
    d = json.loads(res.stdout)
    assert "rms_transmission_error" not in d["units"]
    assert d["units"]["planet_load_sharing"] == "1" and d["units"]["peak_force"] == "N"
    assert set(d["units"]) - {"settle_time_s", "planet_load_sharing"} <= set(
        next(iter(d["metrics"]["meshes"].values())))


def test_modes_say_which_frame_their_frequencies_are_in():
    """A turning carrier's translational modes are seen at f +- its rotation frequency on
    the housing (1600 rpm: 26.67 Hz); the table did not say its f is the carrier
    frame's.  A star stage (carrier at rest) has no such note."""
    res = CliRunner().invoke(app, ["modes", "split_path_planetary_differential"])
    assert res.exit_code == 0, res.output
    out = " ".join(res.stdout.split())
    assert "measured in its turning carrier's frame" in out
    assert "(stage_carrier 26.67 Hz) in the housing's frame" in out
    res = CliRunner().invoke(app, ["modes", "lin_parker1999_star"])
    assert res.exit_code == 0, res.output
    assert "turning carrier's frame" not in " ".join(res.stdout.split())


def test_the_csv_set_holds_the_cycle_ratios_and_the_planets(tmp_path):
    """The cycle table left out the per-cycle extremes of the instantaneous load-sharing
    ratio the .nc has, and the about file the planets' factors and bearing forces that
    --json gives (a reviewer of the outputs)."""
    import csv

    import xarray as xr

    for out in ("r.csv", "r.nc"):
        res = CliRunner().invoke(app, ["run", EXAMPLE, "--cycles", "30", "--set",
                                       'planetary.0.pin_errors=[{tangential="10 um"},{},{},{}]',
                                       "--out", str(tmp_path / out)])
        assert res.exit_code == 0, res.output
    rows = list(csv.DictReader((tmp_path / "r_cycles.csv").read_text().splitlines()))
    ds = xr.open_dataset(tmp_path / "r.nc")
    m = "stage_sun_planet2"
    j = list(ds["mesh"].values).index(m)
    for q, var in (("ratio_max", "cycle_ratio_max"), ("ratio_min", "cycle_ratio_min")):
        got = np.array([float(r[f"{m}_{q}"]) if r[f"{m}_{q}"] else np.nan for r in rows])
        want = ds[var].values[:len(got), j]
        np.testing.assert_allclose(got, want, rtol=1e-12, equal_nan=True)
        assert np.nanmax(got) > 1.01  # (the pin error loads planet 2's neighbours)
    about = json.loads((tmp_path / "r_about.json").read_text())
    k = about["planet_load_sharing"]["per_stage"]["stage_carrier"]
    assert k == pytest.approx(float(ds["planet_load_sharing"].sel(
        planet_entity="stage_carrier")), rel=1e-12) and k > 1.01
    assert {b["body"] for b in about["bearing_forces_N"]} >= {"stage_planet1", "stage_sun"}


def test_a_star_stages_planets_have_no_speed_on_their_pin_beside_their_speed():
    """The carrier of a star stage is at rest: '-875 (-875 on its pin)' said nothing."""
    res = CliRunner().invoke(app, ["check", "lin_parker1999_star", "--json"])
    assert res.exit_code == 0, res.output
    planet = json.loads(res.stdout)["bodies"]["stage_planet1"]
    assert "speed_relative_to_carrier_rpm" not in planet and planet["power_kW"] == 0.0


def test_the_static_orbits_say_their_frame():
    """A planet's 11.2 um outwards is in its carrier's turning frame, the pinions' in the
    housing's; the table did not say so (a reviewer), and printed '-0.000'."""
    res = CliRunner().invoke(app, ["static", "split_path_planetary_differential", "--quiet"])
    assert res.exit_code == 0, res.output
    orbits = res.stdout[res.stdout.index("floating orbits"):]
    assert "directions in" in orbits and "-0.000" not in orbits
    rows = {line.split("│")[1].strip(): line for line in orbits.splitlines()
            if line.startswith("│")}
    assert "turning with stage_carrier" in rows["stage_planet1"]
    assert "housing" in rows["pinion_a"]


def test_every_command_with_a_progress_display_takes_quiet():
    """'steady' and 'sweep-speed' had no --quiet, unlike the other commands (a reviewer)."""
    for command in ("run", "static", "steady", "sweep-speed", "study", "modes"):
        res = CliRunner().invoke(app, [command, "--help"])
        assert "--quiet" in res.stdout, command
    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--quiet", "--no-stability",
                                   "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["converged"]
