"""A run's metrics are computed once per settle window and tolerance and shared by the
load-sharing definitions (a study case asks for two, the report for four); what a caller
gets is its own."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import torquesplit
from torquesplit.metrics.load_sharing import DYNAMIC_DEFINITIONS
from torquesplit.results import Results


@pytest.fixture(scope="module")
def run():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.simulate("ji_li_mill_drive", cycles=60)


def _fresh(res):
    """The same run as a new Results, nothing computed yet."""
    return Results(model=res.model, kinematics=res.kinematics, structure=res.structure,
                   static=res.static, solution=res.solution)


@pytest.mark.parametrize("definition", DYNAMIC_DEFINITIONS)
def test_shared_metrics_equal_those_computed_alone(run, definition):
    shared = _fresh(run)
    for other in DYNAMIC_DEFINITIONS:  # (every definition first: the base is kept)
        shared.metrics(other)
    alone = _fresh(run).metrics(definition)
    assert shared.metrics(definition).values() == alone.values()
    assert shared.metrics(definition).rows == alone.rows


def test_a_callers_change_does_not_reach_the_next_call(run):
    res = _fresh(run)
    met = res.metrics("cycle_peak")
    mesh = res.mesh_names[0]
    before = dict(met.dynamic_factors.dynamic_factor), dict(met.settling.first_cycle)
    met.dynamic_factors.dynamic_factor[mesh] = -1.0
    met.settling.first_cycle[mesh] = 10**6
    again = res.metrics("mean_force")
    assert (dict(again.dynamic_factors.dynamic_factor), dict(again.settling.first_cycle)) \
        == before
    stats = res.complete_cycle_statistics()
    assert all(not a.flags.writeable for a in stats)
    with pytest.raises(ValueError):
        stats[0][0, 0] = 0.0
    ds = res.to_dataset()
    ds["cycle_max_force"] /= 1e3  # (a Dataset is the user's to change in place)
    assert np.isfinite(res.complete_cycle_statistics()[0]).any()


@pytest.mark.parametrize("definition", DYNAMIC_DEFINITIONS)
def test_per_cycle_series_are_the_callers(run, definition):
    """The per-cycle coefficients a caller gets are its own arrays (the instantaneous
    ones were views of the run's read-only statistics: a reviewer)."""
    res = _fresh(run)
    mesh = res.mesh_names[0]
    series = res.metrics(definition).load_sharing.per_cycle[mesh]
    kept = series.copy()
    series[:] = -1.0
    assert np.array_equal(res.metrics(definition).load_sharing.per_cycle[mesh], kept,
                          equal_nan=True)
