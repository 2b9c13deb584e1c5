"""A ``--set`` that cannot be applied is said together with the file's own problems (a
first-hour reviewer: with a bad --set path the file's wrong unit was said only after the
--set was mended, one run per problem)."""

from __future__ import annotations

import re

from typer.testing import CliRunner
from model_texts import tutorial_model

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
