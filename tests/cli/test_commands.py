"""The command line: every sub-command on small models, exit codes and JSON output."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from model_texts import SPUR_PAIR, split_model, write_model
from torquesplit.cli import app

runner = CliRunner()


def _ok(args):
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return res.output


def test_examples_and_example(tmp_path):
    out = _ok(["examples"])
    for name in ("liu2021_split_torque_helicopter", "mo2017_star_reducer"):
        assert name in out
    _ok(["example", "ji_li_mill_drive", "--dir", str(tmp_path)])
    assert (tmp_path / "ji_li_mill_drive.toml").exists()
    again = runner.invoke(app, ["example", "ji_li_mill_drive", "--dir", str(tmp_path)])
    assert again.exit_code == 2 and "--force" in again.output
    bad = runner.invoke(app, ["example", "nope"])
    assert bad.exit_code == 2 and "torquesplit examples" in bad.output
    assert "ji_li_diameter" in " ".join(bad.output.split())


def test_a_shipped_study_is_listed_and_copied_as_it_is(tmp_path):
    """'torquesplit example ji_li_diameter' said 'no example named' and the docs said to
    copy from src/, which an installed package does not have (a studies reviewer)."""
    from torquesplit.study.shipped import study_names, study_path

    out = " ".join(_ok(["examples"]).split())
    assert "Shipped studies" in out and all(n in out for n in study_names())
    _ok(["example", "ji_li_diameter", "--dir", str(tmp_path)])
    copied = tmp_path / "ji_li_diameter.toml"
    assert copied.read_bytes() == study_path("ji_li_diameter").read_bytes()
    # the copy runs from where it is: its model is an example's name
    from torquesplit.study import Study

    assert Study(copied).plan().n_cases == 28


def test_run_json_out_and_set(tmp_path):
    path = write_model(tmp_path, split_model())
    out = _ok(["run", str(path), "--cycles", "20", "--json", "--out", str(tmp_path / "r.nc"),
               "--set", "meshes.a1.damping_ratio=0.07"])
    data = json.loads(out[out.index("{"):])  # (20 cycles: a too-short warning first)
    assert data["success"] is True
    assert data["metrics"]["system_load_sharing"] == pytest.approx(1.0, abs=1e-6)
    assert data["statistics"]["steps"] > 0 and data["statistics"]["rhs_evaluations"] > 0
    assert (tmp_path / "r.nc").exists()
    # every number of a mesh has its unit said (the table prints kN and %, the JSON N and
    # fractions: a script had to guess)
    for row in data["metrics"]["meshes"].values():
        numbers = {k for k, v in row.items() if isinstance(v, float) or v is None}
        assert numbers and numbers <= set(data["units"]), numbers - set(data["units"])
    assert data["units"]["peak_force"] == "N" and data["units"]["load_sharing"] == "1"
    bad = runner.invoke(app, ["run", str(path), "--set", "meshes.zz.damping_ratio=1"])
    assert bad.exit_code == 2 and "meshes.zz" in bad.output


def test_static_mesh_and_modes(tmp_path):
    path = write_model(tmp_path, split_model())
    data = json.loads(_ok(["static", str(path), "--json", "--points-per-cycle", "2"]))
    assert data["converged"] and data["load_sharing"]["system"] == pytest.approx(1.0)
    # the sweep's advice to raise max_points has its option (it had none)
    thin = runner.invoke(app, ["static", str(path), "--json", "--max-points", "16"])
    assert thin.exit_code == 0, thin.output
    assert any("cut to max_points = 16" in w and "--max-points" in w
               for w in json.loads(thin.stdout)["warnings"])
    pair = write_model(tmp_path, SPUR_PAIR, "pair.toml")
    mesh = json.loads(_ok(["mesh", str(pair), "--pair", "m", "--json",
                           "--plot", str(tmp_path / "k.png")]))
    assert {r["method"] for r in mesh["methods"]} >= {"potential_energy", "model file"}
    assert (tmp_path / "k.png").stat().st_size > 0
    modes = json.loads(_ok(["modes", str(path), "--json"]))
    assert modes["rigid_body_modes"] == 1 and modes["modes"][0]["frequency_Hz"] > 0


def test_run_says_what_set_a_finer_step(tmp_path):
    """A step finer than asked (a stiff mesh) is explained on the terminal and in the
    JSON statistics; at the asked step nothing is said."""
    pair = write_model(tmp_path, SPUR_PAIR, "pair.toml")
    stiff = _ok(["run", str(pair), "--cycles", "10", "--set", "meshes.m.stiffness='4e10 N/m'"])
    assert "set by the highest mode" in stiff and "mostly element 'm'" in stiff
    normal = _ok(["run", str(pair), "--cycles", "10"])
    assert "set by" not in normal
    out = _ok(["run", str(pair), "--cycles", "10", "--json",
               "--set", "meshes.m.stiffness='4e10 N/m'"])
    data = json.loads(out[out.index("{"):])  # after the plausibility warning (stderr)
    assert data["statistics"]["step_limited_by"].startswith("the highest mode")
