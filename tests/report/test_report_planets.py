"""The HTML report's planet table (K_gamma per stage, the factor per planet) and its
"not settled" note (user review)."""

from __future__ import annotations

import html
import re

from typer.testing import CliRunner

from model_texts import split_model, write_model
from torquesplit.cli import app

runner = CliRunner()


def _report(tmp_path, source, *args) -> str:
    out = tmp_path / "r.html"
    res = runner.invoke(app, ["report", str(source), "--out", str(out), "--quiet", *args])
    assert res.exit_code == 0, res.output
    return html.unescape(out.read_text(encoding="utf-8"))


def test_report_of_a_planetary_model_has_the_planet_table(tmp_path):
    page = _report(tmp_path, "lin_parker1999_planetary", "--set",
                   "planetary.0.pin_errors=[{tangential = '10 um'}, {}, {}, {}]")
    assert "<h3>Planets</h3>" in page
    table = page[page.index("<h3>Planets</h3>"):]
    table = table[:table.index("</table>")]
    assert "factor (mean_force)" in table and "K_gamma (stage)" in table
    cells = re.findall(r"<td[^>]*>([^<]*)</td>", table)
    planets = [float(cells[i + 3]) for i in range(0, len(cells), 4) if cells[i + 1]
               .startswith("stage_planet")]
    stage = float(cells[3])
    assert len(planets) == 4 and stage == max(planets) > 1.0
    assert "K_gamma of a stage: its largest planet load over the mean" in page


def test_report_without_planets_and_of_a_short_run(tmp_path):
    """No planet table for a model without planets; a run too short to settle points to
    the warnings, not to 'the last half'."""
    model = write_model(tmp_path, split_model())
    page = _report(tmp_path, model, "--cycles", "10")
    assert "<h3>Planets</h3>" not in page
    assert "(not settled: see the warnings)" in page and "last half used" not in page
