"""Tables on an 80-column terminal keep every number whole (no ellipsis)."""

from __future__ import annotations

import io

from rich.console import Console

from torquesplit._table import Table


def _table():
    t = Table(title="meshes")
    for head in ("mesh", "group", "nominal F [kN]", "static F [kN]", "mean F [kN]",
                 "peak F [kN]", "dynamic factor", "peak/ nominal", "LSC (engineering)",
                 "contact loss", "back flank (time, force)"):
        t.add_column(head, justify="right")
    for i in range(4):
        t.add_row(f"m{i}1", "stage1", "112.17", "112.17", "112.17", "120.74",
                  f"1.076{i}", "1.0764", "1.0656", "0.00 %", "0.00 %")
    return t


def _render(width: int) -> str:
    out = io.StringIO()
    Console(file=out, width=width, color_system=None).print(_table())
    return out.getvalue()


def test_a_wide_table_on_80_columns_shows_every_number_whole():
    text = _render(80)
    assert "…" not in text
    assert all(len(line) <= 80 for line in text.splitlines())
    for i in range(4):
        assert f"1.076{i}" in text
    assert text.count("120.74") == 4 and text.count("0.00 %") == 8


def test_a_table_that_fits_keeps_its_rules():
    assert "┃" in _render(200) and "┃" not in _render(80)
