"""`run` says when the model's speed sits next to a critical speed (a reviewer: Ji & Li's
drive runs 0.24 % above the critical speed of its stage-2 mesh's third order with a
support mode, the largest line of its support-force spectrum, and nothing was said)."""

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
                              "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout[res.stdout.index("{"):])
    said = [w for w in data["warnings"] if "a critical speed" in w]
    assert len(said) == 1, data["warnings"]
    rpm = float(re.search(r"a critical speed \(([\d.]+) rpm\)", said[0]).group(1))
    mode = int(re.search(r"meets mode (\d+) ", said[0]).group(1))
    # the same crossing on the Campbell map, computed on its own
    _, crossings = torquesplit.campbell("ji_li_mill_drive", "730 rpm", "760 rpm", points=3)
    same = [c for c in crossings if c["mode"] == mode and c["order"] == 3]
    assert len(same) == 1 and same[0]["speed_rpm"] == pytest.approx(rpm, rel=1e-4)
    assert "0.24 % above" in said[0] and "order 3 of meshes m12, m22" in said[0]
    # kept with the results
    with torquesplit.open_results(tmp_path / "r.nc") as ds:
        assert any("a critical speed" in w for w in json.loads(ds.attrs["warnings_json"]))


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
