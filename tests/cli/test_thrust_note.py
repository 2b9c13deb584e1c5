"""The run's notes say which bearing rows leave out a helical gear's thrust (a first-hour
review: a bull gear with DOFs x, y, theta had 231 kN of axial thrust in `check` and in
no bearing force, without a word)."""

from __future__ import annotations

import tomllib

import tomli_w
from typer.testing import CliRunner

from torquesplit.cli import app
from tests.model.model_fixtures import RICH_TOML


def _run(tmp_path, data) -> str:
    path = tmp_path / "rich.toml"
    path.write_bytes(tomli_w.dumps(data).encode())
    res = CliRunner().invoke(app, ["run", str(path), "--cycles", "20"])
    assert res.exit_code == 0, res.output
    return " ".join(res.stdout.split())


def test_a_helical_gear_without_an_axial_dof_is_named(tmp_path):
    data = tomllib.loads(RICH_TOML)
    assert data["gears"]["wheel"]["dofs"] == ["x", "y", "theta"]
    assert "Axial thrust: pinion, wheel have no axial DOF" in _run(tmp_path, data)
    data["gears"]["wheel"]["dofs"] = ["x", "y", "z", "theta"]
    data["gears"]["wheel"]["support"]["axial_stiffness"] = "1e9 N/m"
    assert "Axial thrust: pinion has no axial DOF" in _run(tmp_path, data)


def test_a_rigidly_held_gear_is_not_named_its_row_has_the_thrust(tmp_path):
    """A body held rigidly has the sum of its mesh forces as its bearing row, thrust
    included (z): the note named it all the same (an industrial reviewer's bull gear)."""
    data = tomllib.loads(RICH_TOML)
    data["gears"]["wheel"]["dofs"] = ["theta"]
    data["gears"]["wheel"].pop("support", None)
    out = _run(tmp_path, data)
    assert "Axial thrust: pinion has no axial DOF" in out
    assert "wheel (rigid bearing)" in out
