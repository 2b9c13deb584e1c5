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


RIPPLE = {"method": "constant", "value": "5e8 N/m", "peak_to_peak": 0.2}
SMOOTH = {"method": "fourier", "mean": "5e8 N/m", "cos": ["5e7 N/m"]}
"""Mesh stiffness: a rectangular single/double contact wave, or one harmonic (a cheap
sweep)."""


def _stage(speed: str, stiffness=RIPPLE):
    """Lin & Parker 1999's stage with 3 planets, turning carrier, varying stiffness."""
    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    raw = set_parameter(raw, "planetary.0.planets", 3)
    for mesh in ("sun_mesh", "ring_mesh"):
        raw = set_parameter(raw, f"planetary.0.{mesh}.stiffness", stiffness)
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


def test_a_sweeps_critical_speeds_do_not_depend_on_the_files_speed():
    """The sweep listed the crossings of the file's-speed frequencies: none at all for the
    stage written at 10000 rpm, where the Campbell map has one (a reviewer's finding)."""
    from torquesplit.steady.maps import sweep_speed

    rpm = np.pi / 30
    out = []
    for speed in ("1000 rpm", "10000 rpm"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = sweep_speed(_stage(speed, SMOOTH), 1370 * rpm, 1380 * rpm, points=3,
                             method="hb",
                             stability=False)
        out.append(ds.attrs["critical_speeds_rpm"])
    assert len(out[0]) >= 1
    np.testing.assert_allclose(out[1], out[0], rtol=1e-9)
