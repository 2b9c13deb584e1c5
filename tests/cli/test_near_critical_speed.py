"""`run` says when the model's speed sits next to a critical speed that the model drives
(a reviewer: a speed next to the critical speed of a stage-2 mesh order with a support
mode, the largest line of the support-force spectrum, and nothing was said), and not
where the meshes' forces cancel on the mode (a later reviewer: Ji & Li's drive at its own
745 rpm was said to be 0.24 % above a critical speed whose mode its two in-phase
branches cannot excite)."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app

runner = CliRunner()


def test_a_run_next_to_a_critical_speed_says_which(tmp_path):
    res = runner.invoke(app, ["run", "ji_li_mill_drive", "--cycles", "20", "--json",
                              "--set", "drives.motor.speed=812 rpm",
                              "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout[res.stdout.index("{"):])
    said = [w for w in data["warnings"] if "a critical speed" in w]
    assert len(said) == 1, data["warnings"]
    rpm = float(re.search(r"a critical speed \(([\d.]+) rpm\)", said[0]).group(1))
    mode = int(re.search(r"meets mode (\d+) ", said[0]).group(1))
    # the same crossing on the Campbell map, computed on its own
    _, crossings = torquesplit.campbell("ji_li_mill_drive", "800 rpm", "830 rpm", points=3)
    same = [c for c in crossings if c["mode"] == mode and c["order"] == 3]
    assert len(same) == 1 and same[0]["speed_rpm"] == pytest.approx(rpm, rel=1e-4)
    assert not same[0]["stiffness_cancelled"]
    assert "below" in said[0] and "order 3 of meshes m12, m22" in said[0]
    # kept with the results
    with torquesplit.open_results(tmp_path / "r.nc") as ds:
        assert any("a critical speed" in w for w in json.loads(ds.attrs["warnings_json"]))


def test_a_crossing_whose_mode_the_branches_cannot_excite_is_not_said():
    """Ji & Li's drive at 745 rpm sits 0.24 % above the crossing of order 3 of its stage-2
    meshes with mode 4, on which the two branches move against each other: their mesh
    forces, in phase, cancel on it (a reviewer's projection: 1e-20 against 1e-6 to 1e-4;
    the speed sweep shows no peak there).  The next mode, where they move together, is
    driven."""
    res = runner.invoke(app, ["run", "ji_li_mill_drive", "--cycles", "20", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout[res.stdout.index("{"):])
    assert not any("critical speed" in w for w in data["warnings"]), data["warnings"]
    _, crossings = torquesplit.campbell("ji_li_mill_drive", "730 rpm", "830 rpm", points=3)
    third = {c["mode"]: c for c in crossings if c["order"] == 3 and "m12" in c["source"]}
    assert third[4]["stiffness_cancelled"] and third[4]["modal_force_share"] < 1e-9
    assert not third[5]["stiffness_cancelled"] and third[5]["modal_force_share"] > 0.99
    assert third[4]["stiffness_harmonic"] == third[5]["stiffness_harmonic"] > 0.01


def test_a_run_away_from_critical_speeds_says_nothing_of_them():
    res = runner.invoke(app, ["run", "mo2017_star_reducer", "--cycles", "20", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout[res.stdout.index("{"):])
    assert not any("critical speed" in w for w in data["warnings"])


def test_a_crossing_the_planets_phasing_suppresses_is_not_said():
    """split_path_planetary_differential runs 0.08 % above the crossing of order 7 of its
    planetary meshes with mode 7, which the mesh phasing of its three planets leaves
    unexcited (Parker & Lin 2004): a false alarm."""
    from torquesplit.solve.static import static_equilibrium
    from torquesplit.steady.maps import critical_speeds, near_critical_speeds
    from torquesplit.steady.api import reference_speed

    m = torquesplit.load_model("split_path_planetary_differential")
    kin, s = torquesplit.solve_kinematics(m), torquesplit.assemble(m)
    q = static_equilibrium(s).q
    w = reference_speed(m)
    near = critical_speeds(s, q, kin, m, 0.99 * w, 1.01 * w)["crossings"]
    quiet = [c for c in near if c.get("suppressed") and c["order"] == 7 and c["mode"] == 7]
    assert quiet  # (the premise: the nearest crossing is a suppressed one)
    said = near_critical_speeds(m, s, q, kin)
    assert len(said) == 1
    assert f"({quiet[0]['speed_rpm']:.5g} rpm)" not in said[0][1]
    assert "meets mode 7 " not in said[0][1]


def _split_near_its_crossing(tmp_path, amplitude: str):
    """The two-path split (constant mesh stiffness) with a transmission error of
    ``amplitude`` at mesh frequency on mesh a1, driven 0.3 % above the speed where order 1
    of its first stage meets mode 1."""
    from model_texts import split_model, write_model
    from torquesplit.solve.static import static_equilibrium
    from torquesplit.steady.maps import critical_speeds

    text = split_model().replace('transmission_error = {constant = "0 um"}',
                                 f'transmission_error = {{amplitude = "{amplitude}"}}')
    m = torquesplit.load_model(write_model(tmp_path, text))
    kin, s = torquesplit.solve_kinematics(m), torquesplit.assemble(m)
    w = m.drives["motor"].speed
    crossing, = [c for c in critical_speeds(s, static_equilibrium(s).q, kin, m, 2 * w,
                                            8 * w)["crossings"]
                 if c["source"] == "meshes a1, b1" and c["order"] == 1 and c["mode"] == 1]
    return m.with_changes({"drives.motor.speed": f"{1.003 * crossing['speed_rpm']} rpm"})


def _said(m):
    from torquesplit.solve.static import static_equilibrium
    from torquesplit.steady.maps import near_critical_speeds

    s = torquesplit.assemble(m)
    return near_critical_speeds(m, s, static_equilibrium(s).q, torquesplit.solve_kinematics(m))


def test_a_critical_speed_driven_by_an_error_is_said(tmp_path):
    """A constant-stiffness model excited by a transmission error (or an eccentricity)
    at a critical speed got no word: only the stiffness harmonics were rated.  The error
    is rated by its force amplitude k e over the mesh's nominal force, and only on its own
    stage's lines (stage 2's order 2 has the same frequency: not it)."""
    said = _said(_split_near_its_crossing(tmp_path, "5 um"))
    assert len(said) == 1, said
    text = said[0][1]
    assert "0.3 % above" in text and "order 1 of meshes a1, b1 meets mode 1 " in text
    share = re.search(r"an error of mesh a1 \(k e = ([\d.]+) % of its nominal force\)", text)
    assert share, text
    m = _split_near_its_crossing(tmp_path, "5 um")
    kin = torquesplit.solve_kinematics(m)
    expected = 4e8 * 5e-6 / kin.meshes["a1"].force  # k e / F, by hand
    assert float(share.group(1)) == pytest.approx(100 * expected, rel=0.01)
    assert "harmonic of" not in text  # (constant stiffness: not the stiffness)
    assert _said(_split_near_its_crossing(tmp_path, "0 um")) == []
