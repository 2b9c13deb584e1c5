"""Every command's --out problem is named by the option (a MATLAB user's review: 'run'
said 'error: --out: ...', static, modes, steady and sweep-speed did not)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from torquesplit.cli import app


@pytest.mark.parametrize("args", [
    ["run", "ji_li_mill_drive", "--cycles", "2"],
    ["static", "mo2017_star_reducer", "--revolutions", "0.01"],
    ["modes", "ji_li_mill_drive"],
    ["modes", "ji_li_mill_drive", "--campbell", "--from", "600 rpm", "--to", "700 rpm"],
    ["steady", "ji_li_mill_drive", "--no-stability"],
    ["sweep-speed", "ji_li_mill_drive", "--from", "700 rpm", "--to", "710 rpm"],
])
def test_a_bad_out_path_is_named_by_the_option_before_any_computation(args, tmp_path):
    res = CliRunner().invoke(app, args + ["--out", str(tmp_path / "x.txt")])
    assert res.exit_code == 2, res.output
    assert "error: --out: cannot save results as 'x.txt'" in " ".join(res.output.split())
