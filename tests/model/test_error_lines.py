"""A problem in a model file names its line, as a compiler does ('drive.toml:42:
gears.pinion.module: ...'): a reviewer's 600-line file named the field only."""

from __future__ import annotations

import json
import re
import tomllib

import pytest

import torquesplit
from torquesplit.errors import ModelError
from torquesplit.model.locate import key_lines, line_of
from tests.model_texts import SPUR_PAIR

TEXT = """\
[model]
name = "x"

[gears.pinion]
teeth = 20   # a comment
support = {stiffness = "1e9 N/m", damping_ratio = 0.02}
errors.grade = 6
"quoted.key" = 1

[[planetary]]
name = "a"
[planetary.sun]
teeth = 30

[[planetary]]
name = "b"
[planetary.sun]
teeth = 31
"""


def test_every_key_of_a_toml_text_has_its_line():
    lines = key_lines(TEXT)
    assert lines["model.name"] == 2
    assert lines["gears.pinion"] == 4 and lines["gears.pinion.teeth"] == 5
    assert lines["gears.pinion.support.stiffness"] == 6
    assert lines["gears.pinion.support.damping_ratio"] == 6
    assert lines["gears.pinion.errors.grade"] == 7 and lines["gears.pinion.errors"] == 7
    assert lines["gears.pinion.quoted.key"] == 8
    assert lines["planetary.0.name"] == 11 and lines["planetary.0.sun.teeth"] == 13
    assert lines["planetary.1.name"] == 16 and lines["planetary.1.sun.teeth"] == 18
    # a field the file does not write: its longest prefix that it does
    assert line_of(lines, "gears.pinion.module") == 4
    assert line_of(lines, "gears.pinion.support.stiffness.value") == 6
    assert line_of(lines, "meshes.m") is None
    assert tomllib.loads(TEXT)  # (the text is TOML)


def _error(tmp_path, text, name="m.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ModelError) as info:
        torquesplit.load_model(path)
    return path, str(info.value)


def test_a_schema_error_and_a_check_error_name_their_lines(tmp_path):
    text = SPUR_PAIR.replace("teeth = 40", "teeth = 0")
    path, said = _error(tmp_path, text)
    line = text.splitlines().index("teeth = 0") + 1
    assert said.startswith(f"{path}:{line}: gears.wheel.teeth: must be greater than 0")
    # a check after the schema (a mesh of a gear that does not exist)
    text = SPUR_PAIR.replace('gears = ["pinion", "wheel"]', 'gears = ["pinion", "whel"]')
    path, said = _error(tmp_path, text)
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "whel" in t)
    assert f"{path}:{line}: meshes.m.gears" in said, said
    # a field the file leaves out: at its table's header
    text = SPUR_PAIR.replace('module = "2 mm"\n', "", 1)
    path, said = _error(tmp_path, text)
    line = text.splitlines().index("[gears.pinion]") + 1
    assert f"{path}:{line}: gears.pinion.module: " in said


def test_a_json_model_and_a_set_argument_name_no_line(tmp_path):
    data = tomllib.loads(SPUR_PAIR)
    data["gears"]["wheel"]["teeth"] = 0
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ModelError) as info:
        torquesplit.load_model(path)
    assert str(info.value).startswith(f"{path}: gears.wheel.teeth: ")


def test_the_command_line_names_the_lines_of_schema_and_check_errors(tmp_path):
    """The commands read the file, then check it apart: the checks' problems had no line
    (a code review), with and without --set."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    text = SPUR_PAIR.replace('gears = ["pinion", "wheel"]', 'gears = ["pinion", "whel"]')
    path = tmp_path / "m.toml"
    path.write_text(text)
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "whel\"" in t)
    for extra in ([], ["--set", "meshes.m.damping_ratio=0.2"]):
        res = CliRunner().invoke(app, ["check", str(path), *extra])
        assert res.exit_code == 2 and f"{path}:{line}: meshes.m.gears: " in res.output, \
            res.output
    bad = SPUR_PAIR.replace("teeth = 40", "teeth = 0")
    path.write_text(bad)
    res = CliRunner().invoke(app, ["check", str(path)])
    line = bad.splitlines().index("teeth = 0") + 1
    assert f"{path}:{line}: gears.wheel.teeth: " in res.output
    # a value given with --set is the argument's, not the file's: no line
    path.write_text(SPUR_PAIR)
    res = CliRunner().invoke(app, ["check", str(path), "--set", "gears.wheel.teeth=0"])
    assert res.exit_code == 2 and "--set gears.wheel.teeth=0" in res.output
    assert re.search(r"m\.toml:\d+:", res.output) is None


def test_lines_inside_multi_line_arrays_and_strings_are_not_keys():
    """A lone array row '  [0.5, 2e9]' was read as a table header, and a description's
    lines inside a multi-line string as keys (a code review)."""
    text = '''\
[model]
name = "x"
description = """
[gears.ghost]
teeth = 3
"""

[meshes.m]
stiffness = {method = "table", phase = [0.0, 0.5], values = [
  "4e8 N/m",
  [0.5, 2e9]
]}
damping_ratio = 0.05   # "[not a header]"
note = 'a [bracket] = inside'

[gears.ghost]
teeth = 4
'''
    assert tomllib.loads(text.replace("[0.5, 2e9]", '"3e8 N/m"'))  # (TOML but the row)
    lines = key_lines(text)
    assert lines["meshes.m.damping_ratio"] == 13 and lines["meshes.m.note"] == 14
    assert lines["gears.ghost.teeth"] == 17 and lines["gears.ghost"] == 16
    assert lines["model.description"] == 3
