"""A run too short for a whole cycle of some meshes past their settle time reports no
number for them, not zero (a first-hour reviewer: the tutorial's drive run for 2.5 ms
printed a mean force of 0 kN on meshes carrying 7.5 kN and a group coefficient of 3.0,
one branch carrying everything; at 1 ms 'transient discarded: combine -inf s')."""

from __future__ import annotations

import math
import warnings

import numpy as np
from model_texts import write_tutorial_model

import torquesplit
from torquesplit.metrics.load_sharing import span_mean

def _run(tmp_path, duration):
    model = write_tutorial_model(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.simulate(torquesplit.load_model(model), duration=duration)


def test_meshes_without_a_settled_sample_have_no_mean_and_their_group_no_coefficient(
        tmp_path):
    met = _run(tmp_path, 2.5e-3).metrics("mean_force")
    rows = {r.mesh: r for r in met.rows}
    empty = [m for m, r in rows.items() if not math.isfinite(r.mean_force)]
    assert empty  # the run is that short: some meshes have nothing past their settle time
    assert all(rows[m].mean_force != 0.0 for m in rows)  # a mean is a number or NaN
    for g, members in met.load_sharing.groups.items():
        if any(m in empty for m in members):
            assert math.isnan(met.load_sharing.per_group[g])
            assert all(math.isnan(met.load_sharing.per_mesh[m]) for m in members)
    assert math.isnan(met.load_sharing.system)


def test_a_group_without_a_whole_cycle_says_so_instead_of_minus_infinity(tmp_path):
    met = _run(tmp_path, 1e-3).metrics()
    text = met.settle_times_text()
    assert "inf" not in text and "none (no whole cycle)" in text


def test_span_mean_weights_cycles_by_their_samples():
    assert span_mean([1.0, 3.0], [1, 3]) == 2.5
    assert math.isnan(span_mean([1.0, np.nan], [0, 0]))
    assert math.isnan(span_mean(np.zeros(0), np.zeros(0, dtype=int)))


def test_a_run_without_a_settled_part_has_no_settled_bearing_forces(tmp_path):
    """Its default (the settle time, -inf) gave the start-up's bearing forces as settled,
    where the docstring, the CLI and the files give none."""
    res = _run(tmp_path, 1e-4)
    assert res.metrics().settling.start_time == -math.inf
    assert res.bearing_forces() == []
