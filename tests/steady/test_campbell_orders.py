"""The Campbell map's mesh orders and range: strong orders above the default cap are
named (a rectangular stiffness wave keeps 8 % of its fundamental up to order 16-21),
``--orders`` draws them, and a map may start at standstill."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
from typer.testing import CliRunner

import torquesplit as ts
from torquesplit.cli import app
from torquesplit.errors import OptionError
from torquesplit.steady.maps import (HARMONIC_SHARE, MAX_ORDERS, campbell,
                                     strong_orders_beyond)
from tests.model_texts import SPUR_PAIR

RECTANGULAR = SPUR_PAIR.replace(
    'stiffness = "4e8 N/m"',
    'stiffness = {method = "constant", value = "4e8 N/m", peak_to_peak = 0.3}')


def test_strong_orders_beyond_the_cap_are_found_by_their_share():
    phase = np.arange(1024) / 1024
    step = np.where(phase < 0.6, 1.1, 1.0)  # a steep single/double contact wave
    top, share = strong_orders_beyond(step)
    amp = np.abs(np.fft.rfft(step))
    assert top > MAX_ORDERS and amp[top] >= HARMONIC_SHARE * amp[1]
    assert not (amp[top + 1:] >= HARMONIC_SHARE * amp[1]).any()
    assert share == pytest.approx(amp[MAX_ORDERS + 1:].max() / amp[1])
    assert strong_orders_beyond(1.0 + 0.1 * np.cos(2 * np.pi * phase)) is None
    assert strong_orders_beyond(np.ones(64)) is None


def test_the_map_names_strong_orders_it_leaves_out_and_draws_them_when_asked():
    m = ts.load_model(tomllib.loads(RECTANGULAR))
    top, _ = strong_orders_beyond(ts.assemble(m).stiffness_table[0])
    ds, _ = campbell(m, 1000.0, 3000.0, points=3)
    (note,) = ds.attrs["orders_left_out"]
    assert f"up to order {top}" in note and f"--orders {top}" in note
    assert sum(lab.endswith("mesh m") for lab in ds["line"].values) == MAX_ORDERS
    ds, _ = campbell(m, 1000.0, 3000.0, points=3, orders=top)
    assert "orders_left_out" not in ds.attrs
    assert sum(lab.endswith("mesh m") for lab in ds["line"].values) == top
    with pytest.raises(OptionError, match="orders must be a whole number"):
        campbell(m, 1000.0, 3000.0, orders=0)


def test_the_cli_prints_the_note_and_takes_orders(tmp_path):
    path = tmp_path / "rect.toml"
    path.write_text(RECTANGULAR, encoding="utf-8")
    r = CliRunner().invoke(app, ["modes", str(path), "--campbell", "--from", "0 rpm",
                                 "--to", "30000 rpm"])
    assert r.exit_code == 0, r.output
    assert "note: mesh m: stiffness harmonics up to order" in " ".join(r.output.split())
    r = CliRunner().invoke(app, ["modes", str(path), "--campbell", "--from", "0 rpm",
                                 "--to", "30000 rpm", "--orders", "30", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert "orders_left_out" not in out
    assert max(c["order"] for c in out["critical_speeds"]) > MAX_ORDERS
    r = CliRunner().invoke(app, ["modes", str(path), "--orders", "12"])
    assert r.exit_code != 0 and "add --campbell" in r.output
    r = CliRunner().invoke(app, ["modes", str(path), "--campbell", "--from", "0 rpm",
                                 "--to", "1 rpm", "--orders", "0"])
    assert r.exit_code == 2 and "--orders must be a whole number of at least 1" in r.output


def test_a_map_starts_at_standstill_also_with_a_turning_carrier():
    from tests.steady.test_campbell_review import LP3

    m = ts.load_model(tomllib.loads(LP3))
    ds, _ = campbell(m, 0.0, 300.0, points=4)
    assert ds["speed"].values[0] == 0.0 and np.isfinite(ds["natural_frequency"]).all()
    near, _ = campbell(m, 1e-3, 300.0, points=4)  # standstill is the limit of slow speeds
    np.testing.assert_allclose(ds["natural_frequency"].values[0],
                               near["natural_frequency"].values[0], rtol=1e-6)
    assert (ds["excitation_frequency"].values[0] == 0.0).all()
    with pytest.raises(OptionError, match="the lower one 0 or more"):
        campbell(m, -10.0, 300.0)


def test_a_degenerate_pairs_crossings_give_the_pairs_strain_energy_not_the_solvers_basis():
    """The translational modes of a star stage (Lin & Parker's, carrier held) come in
    degenerate pairs: each crossing of one of them gave that mode's own strain-energy
    shares, which depend on the basis the eigensolver returned (727 Hz: the carrier's x
    support 0.382 in one mode and 0.080 in its partner).  Both now give the pair's
    (0.231 each), as ``modes`` does, and the layout's symmetry shows: x and y supports
    take equal shares."""
    from torquesplit.modes import model_modes

    model = ts.load_model("lin_parker1999_star")
    _, crossings = campbell(model, "0 rpm", "3000 rpm", points=5)
    groups = {}
    for row in model_modes(model).rows:
        groups.setdefault(row.group, []).append(row)
    pairs = {r.mode: g for g in groups.values() if len(g) == 2 for r in g}
    seen = 0
    for c in crossings:
        if c["mode"] not in pairs:
            continue
        seen += 1
        want = pairs[c["mode"]][0].strain_energy
        for name, share in c["energy"]:
            assert share == pytest.approx(want[name], rel=1e-9, abs=1e-12), (c["mode"], name)
        top = dict(c["energy"])
        for name, share in top.items():
            other = name[:-1] + ("y" if name.endswith(".x") else "x")
            if name.endswith((".x", ".y")) and other in top:
                assert share == pytest.approx(top[other], rel=1e-6)
    assert seen >= 6
