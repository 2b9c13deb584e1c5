"""A ``--set`` that cannot be applied is said together with the file's own problems (a
first-hour reviewer: with a bad --set path the file's wrong unit was said only after the
--set was mended, one run per problem)."""

from __future__ import annotations

import re

from typer.testing import CliRunner
from model_texts import SPUR_PAIR, tutorial_model

from torquesplit.cli import app



def test_a_bad_set_path_and_a_bad_unit_in_the_file_are_said_at_once(tmp_path):
    text = tutorial_model()
    text, n = re.subn(r'stiffness = "100 N/um"', 'stiffness = "100 kg"', text, count=1)
    assert n == 1
    model = tmp_path / "m.toml"
    model.write_text(text, encoding="utf-8")
    res = CliRunner().invoke(app, ["check", str(model), "--set", "gears.zz.teeth=3"])
    assert res.exit_code == 2
    err = res.stderr
    assert "--set gears.zz.teeth=3: 'gears.zz' does not exist" in err
    assert re.search(r"m\.toml:\d+: gears\.\w+\.support\.stiffness: '100 kg' is not a "
                     r"stiffness", err), err
    assert "Traceback" not in err


def test_modes_echo_a_bare_limit_with_its_unit_and_a_range_in_order(tmp_path):
    """'no mode below 5: the lowest is 877.5 Hz' dropped the unit of the bare number;
    --from 3600rpm --to 2400rpm was echoed 'between 3600rpm and 2400rpm'."""
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--below", "0.5"])
    assert res.exit_code == 0 and "no mode below 0.5 Hz" in res.stdout
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--campbell", "--from",
                                   "760rpm", "--to", "740rpm"], terminal_width=300)
    assert res.exit_code == 0, res.output
    assert "critical speeds between 740rpm and 760rpm" in res.stdout


def test_a_check_that_only_a_set_breaks_names_the_set(tmp_path):
    """--set gears.pinion.teeth=21 made meshes fail their centre distance, and the error
    pointed at the mesh's line of the file, which is right (a first-hour reviewer)."""
    placed = SPUR_PAIR.replace('place = {from_gear = "pinion", angle = "0 deg"}',
                               'position = ["60 mm", "0 mm", "0 mm"]')
    model = tmp_path / "pair.toml"
    model.write_text(placed, encoding="utf-8")
    res = CliRunner().invoke(app, ["check", str(model), "--set", "gears.pinion.teeth=21"])
    assert res.exit_code == 2, res.output
    errors = [ln for ln in res.stderr.splitlines() if ln.startswith("error:")]
    assert errors and all(ln.startswith(f"error: {model} with --set gears.pinion.teeth=21: "
                                        "meshes.") for ln in errors), res.stderr
    assert "centre distance" in errors[0]
    # the file's own problem stays the file's, at its line
    broken = placed.replace('face_width = "20 mm"', 'face_width = "20 kg"', 1)
    model.write_text(broken, encoding="utf-8")
    res = CliRunner().invoke(app, ["check", str(model), "--set", "gears.pinion.teeth=21"])
    assert re.search(rf"{re.escape(str(model))}:\d+: gears\.\w+\.face_width: ", res.stderr), \
        res.stderr


def test_the_same_field_set_twice_is_refused():
    """The last of two --set of one field won without a word (a first-hour reviewer)."""
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive",
                                   "--set", "meshes.m11.damping_ratio=0.05",
                                   "--set", "meshes.m11.damping_ratio=0.07"])
    assert res.exit_code == 2, res.output
    assert ("error: --set meshes.m11.damping_ratio=0.07: sets meshes.m11.damping_ratio again "
            "(--set meshes.m11.damping_ratio=0.05 before it): give each field once") \
        in res.stderr, res.stderr
