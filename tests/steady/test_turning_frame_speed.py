"""A turning carrier's Coriolis, centripetal and centrifugal terms follow the speed of a
steady state and of a speed sweep: the speed written in the model file does not matter.

Before, ``steady --speed`` and ``sweep-speed`` scaled only the excitation frequencies and
kept the frame terms at the file's speed: the same gearbox at the same speed gave
different forces and critical speeds depending on the speed it was written for."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import torquesplit
from torquesplit.errors import SolverError
from torquesplit.model.overrides import read_raw, set_parameter
from torquesplit.steady.api import steady_state


def _stage(speed: str):
    """Lin & Parker 1999's 3-planet stage, turning carrier, stiffness with a ripple."""
    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    raw = set_parameter(raw, "planetary.0.planets", 3)
    for mesh in ("sun_mesh", "ring_mesh"):
        raw = set_parameter(raw, f"planetary.0.{mesh}.stiffness",
                            {"method": "constant", "value": "5e8 N/m", "peak_to_peak": 0.2})
        raw = set_parameter(raw, f"planetary.0.{mesh}.damping_ratio", 0.02)
    raw = set_parameter(raw, "drives.input.speed", speed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.load_model(raw)


def _peaks(model, speed, method="hb"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        st = steady_state(model, speed=speed, method=method, stability=False)
    return np.array([row.peak_force for row in st.mesh_table()])


@pytest.mark.parametrize("method", ["hb", "shooting"])
def test_the_steady_state_at_a_speed_does_not_depend_on_the_files_speed(method):
    at_file = _peaks(_stage("3000 rpm"), "3000 rpm", method)
    elsewhere = _peaks(_stage("10000 rpm"), "3000 rpm", method)  # frame terms at 3000 rpm
    np.testing.assert_allclose(elsewhere, at_file, rtol=1e-7)
    # and the frame terms matter here: at 10000 rpm the same stage answers differently
    assert np.max(np.abs(_peaks(_stage("10000 rpm"), None) / at_file - 1)) > 1e-3


def test_a_rotating_structure_at_another_speed_needs_its_model():
    from torquesplit.steady.problem import PeriodicProblem

    model = _stage("3000 rpm")
    s = torquesplit.assemble(model)
    problem = PeriodicProblem(s, 100.0)
    problem.model_at(1.0)  # the structure's own speed: fine
    with pytest.raises(SolverError, match="turning carrier"):
        problem.model_at(1.5)
