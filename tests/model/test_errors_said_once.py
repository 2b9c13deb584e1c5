"""One cause, one line: a model error found by two checks, or at several places, is not
repeated (a reviewer counted an interference error three times; a profile shift that
broke a sun's meshes printed the same sentence nine times in each failed study case)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from model_texts import SPUR_PAIR, write_model
from torquesplit.cli import app
from torquesplit.errors import ModelError


def test_an_interfering_pair_is_one_error(tmp_path):
    text = SPUR_PAIR.replace("teeth = 20", "teeth = 12", 1)
    res = CliRunner().invoke(app, ["check", str(write_model(tmp_path, text))])
    assert res.exit_code == 2
    errors = [ln for ln in res.stderr.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1 and "involute interference" in errors[0]
    assert "PairGeometry" not in res.stderr  # (the internal class's words)


def test_one_message_at_several_places_is_one_line_naming_them():
    issues = [("meshes.a", "gears 'x' and 'y': k must be positive; give it"),
              ("meshes.a", "k must be positive; give it"),  # the same, found twice
              ("meshes.b", "k must be positive; give it"),
              ("meshes.c", "k must be positive; give it"),
              ("meshes.d", "k must be positive; give it"),
              ("gears.x.teeth", "must be at least 5")]
    err = ModelError(issues, "m.toml")
    assert len(err.issues) == 5  # every place kept for programs
    assert str(err).splitlines() == [
        "m.toml: meshes.a, meshes.b, meshes.c, meshes.d: k must be positive; give it",
        "m.toml: gears.x.teeth: must be at least 5"]
    (loc, msg), = ModelError([("meshes.a", "gears 'x' and 'y': bad")]).issues
    assert str(ModelError([(loc, msg)])) == "meshes.a: gears 'x' and 'y': bad"


@pytest.mark.parametrize("where", ["", "f.toml"])
def test_unlocated_messages_stay_apart(where):
    err = ModelError([("", "first"), ("", "second")], where or None)
    assert len(str(err).splitlines()) == 2


def test_many_places_are_listed_up_to_ten():
    err = ModelError([(f"loads.l{i}.torque", "Field required") for i in range(12)])
    assert str(err) == ", ".join(f"loads.l{i}.torque" for i in range(9)) + \
        ", 3 more: Field required"
    # a pair's prefix is a location only where the issue has none
    issues = [("", "gears 'a' and 'b': X"), ("", "gears 'c' and 'd': X")]
    assert len(ModelError(issues).issues) == 2
