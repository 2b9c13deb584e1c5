"""A Python API reviewer: ``sweep_speed(stability=False)`` said every point was stable
(nothing was judged), and the sweep ended on two points 1.5e-4 rpm apart (759.99985 and
760 rpm: the last arclength step fell short of the end by its rounding)."""

from __future__ import annotations

import json
import warnings

import numpy as np
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app


def _sweep(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.sweep_speed("ji_li_mill_drive", "700 rpm", "760 rpm", points=4,
                                       keep="stage1", **kw)


def test_a_sweep_without_stability_judges_no_point():
    sw = _sweep(stability=False)
    assert "stable" not in sw and "max_multiplier" not in sw and "instability" not in sw
    assert "not computed" in sw.attrs["stability"]


def test_a_sweep_ends_once_on_its_end():
    rpm = _sweep(stability=False)["speed_rpm"].values
    assert abs(rpm[0] - 700.0) < 1e-9 and abs(rpm[-1] - 760.0) < 1e-9, rpm
    assert np.all(np.diff(rpm) > 1.0), rpm  # (20 rpm steps; no point next to the end)


def test_the_cli_counts_no_unstable_point_it_did_not_judge():
    res = CliRunner().invoke(app, ["sweep-speed", "ji_li_mill_drive", "--from", "700 rpm",
                                   "--to", "760 rpm", "--points", "4", "--keep", "stage1",
                                   "--no-stability", "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["unstable_points"] is None, summary
    assert summary["max_dynamic_factor"], summary  # (every point counted)


def test_a_periodic_states_metrics_say_so_not_a_settle_time():
    """'settled from 0.04189 s' on a steady state whose dataset holds 4.2 ms."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        st = torquesplit.steady_state("ji_li_mill_drive", keep="stage1", stability=False)
    met = st.to_results().metrics()
    assert met.settling.periodic and "a periodic state (no transient)" in repr(met)
    assert "settled from" not in repr(met)


def test_a_steady_states_mesh_series_defaults_to_every_mesh():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        st = torquesplit.steady_state("ji_li_mill_drive", keep="stage1", stability=False)
    t, F, D = st.mesh_series()
    t2, F2, _ = st.mesh_series(list(st.model.meshes))
    assert F.shape == (t.size, len(st.model.meshes)) and np.array_equal(F, F2)
