"""Cost control before and during a run (the reliability issue, item 4): a step shortened
by a stiff element is warned about with the element named, the history is sampled in time
(its size does not depend on the step), and a run beyond the step budget is refused
before it starts."""

from __future__ import annotations

import warnings

import pytest

import torquesplit
from model_texts import SPUR_PAIR, write_model
from torquesplit.errors import ModelWarning, SolverError
from torquesplit.simulation import AUTO_HISTORY_RECORDS
from torquesplit.model.io import model_from_dict
from torquesplit.model.overrides import apply_overrides, read_raw


def _pair(tmp_path, **overrides):
    path = write_model(tmp_path, SPUR_PAIR)
    data = apply_overrides(read_raw(path), overrides) if overrides else read_raw(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)  # the ISO plausibility warning
        return torquesplit.load_model(model_from_dict(data, source=str(path)))


def test_stiff_mesh_history_size_equals_a_normal_models(tmp_path):
    normal = _pair(tmp_path)
    stiff = _pair(tmp_path, **{"meshes.m.stiffness": "4e13 N/m"})
    a = torquesplit.simulate(normal, cycles=30, samples_per_period=20)
    with pytest.warns(ModelWarning, match=r"shorter than 100 steps.*element 'm'"):
        b = torquesplit.simulate(stiff, cycles=30, samples_per_period=20)
    assert b.solution.n_steps > 50 * a.solution.n_steps  # the step was cut hard
    assert "mostly element 'm'" in b.solution.step_limited_by
    # the same sampling interval, rounded to whole steps: the same count, to one record
    assert abs(len(b.solution.history_t) - len(a.solution.history_t)) <= 1
    # the default history: every step of the normal run, the budget of the stiff one
    with pytest.warns(ModelWarning, match=r"shorter than 100 steps"):
        b = torquesplit.simulate(stiff, cycles=30)
    assert len(b.solution.history_t) <= AUTO_HISTORY_RECORDS + 1 < b.solution.n_steps
    a = torquesplit.simulate(normal, cycles=30)
    assert len(a.solution.history_t) == a.solution.n_steps + 1


def test_run_beyond_the_step_budget_is_refused_before_it_starts(tmp_path):
    stiff = _pair(tmp_path, **{"meshes.m.stiffness": "4e13 N/m"})
    with pytest.raises(SolverError, match=r"needs [\d,]+ RK4 steps.*element 'm'.*max_steps"):
        torquesplit.simulate(stiff, cycles=30, max_steps=10_000)
