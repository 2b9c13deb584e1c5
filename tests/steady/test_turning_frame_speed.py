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


def _sweep(file_speed: str, lo_rpm: float, hi_rpm: float):
    """A 3-point harmonic-balance sweep of the stage written at ``file_speed``."""
    from torquesplit.steady.maps import sweep_speed

    rpm = np.pi / 30
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return sweep_speed(_stage(file_speed, SMOOTH), lo_rpm * rpm, hi_rpm * rpm, points=3,
                           method="hb", stability=False)


def test_a_sweeps_critical_speeds_do_not_depend_on_the_files_speed():
    """The sweep listed the crossings of the file's-speed frequencies: none at all for the
    stage written at 10000 rpm, where the Campbell map has one (a reviewer's finding)."""
    out = [_sweep(speed, 1370, 1380).attrs["critical_speeds_rpm"]
           for speed in ("1000 rpm", "10000 rpm")]
    assert len(out[0]) >= 1
    np.testing.assert_allclose(out[1], out[0], rtol=1e-9)


def _state(model, speed=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return steady_state(model, speed=speed, method="shooting", stability=False)


def test_the_statics_metrics_and_exports_of_a_state_at_another_speed_are_that_speeds():
    """A state solved at another speed than the file's took its static equilibrium (the
    carrier's centrifugal loads, so every dynamic factor), its exported cycles and mesh
    frequencies and its near-critical-speed note from the file's speed: the --out file
    disagreed with the printed table (a reviewer's finding).  Each now equals the state
    of the file written at that speed."""
    asked = _state(_stage("10000 rpm"), "3000 rpm")
    at_file = _state(_stage("3000 rpm"))
    # the static equilibrium, and the static forces the dynamic factors divide by
    np.testing.assert_allclose(asked.static.q, at_file.static.q, rtol=1e-9, atol=1e-15)
    rows = {r.mesh: r for r in asked.mesh_table()}
    for r in at_file.mesh_table():
        for field in ("static_force", "dynamic_factor", "mean_force", "peak_force"):
            assert getattr(rows[r.mesh], field) == pytest.approx(getattr(r, field),
                                                                 rel=1e-7), field
    # and the frame terms change them here: 10000 rpm's statics are not 3000 rpm's
    own = _state(_stage("10000 rpm"))
    assert np.max(np.abs(own.static.q - at_file.static.q)) > 1e-3 * np.max(
        np.abs(at_file.static.q))
    # the record a run's exports are made of: its cycles and mesh frequencies
    ra, rf = asked.to_results(), at_file.to_results()
    assert ra.solution.cycle_count.sum(axis=0).tolist() == \
        rf.solution.cycle_count.sum(axis=0).tolist()
    da, df = ra.to_dataset(), rf.to_dataset()
    np.testing.assert_allclose(da["mesh_frequency"].values, df["mesh_frequency"].values,
                               rtol=1e-12)
    for var in ("mean_force", "static_displacement"):
        np.testing.assert_allclose(da[var].values, df[var].values, rtol=1e-7,
                                   atol=1e-9 * float(np.max(np.abs(df[var].values))))


def test_the_critical_speed_note_of_a_state_at_another_speed_uses_that_speeds_modes():
    """The note named mode 18 at 7174.9 Hz, its frequency at the file's 3000 rpm, where
    at 4500 rpm it is 7177.7 Hz (the differential example, driven by the torque of its
    50 kW at 3000 rpm: the same loads at both speeds)."""
    def model(speed):
        raw = read_raw(torquesplit.example_path("split_path_planetary_differential"))
        drive = raw["drives"]["motor"]
        drive.pop("power")
        drive.update(torque=f"{50e3 / (3000 * np.pi / 30)!r} N m", speed=speed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return torquesplit.load_model(raw)

    import re

    def notes(st):  # (which planet's mesh of a symmetric stage leads a mode: any)
        return [re.sub(r"planet\d", "planet#", n) for n in st.critical_notes()]

    asked = notes(_state(model("3000 rpm"), "4500 rpm"))
    at_file = notes(_state(model("4500 rpm")))
    assert len(at_file) == 1 and "mode 18 (7177.7 Hz" in at_file[0]
    assert asked == at_file


def test_a_sweeps_dynamic_factors_divide_by_each_speeds_static_force():
    """The sweep divided every point's peak by the static force at the file's speed
    (the carrier's centrifugal loads of that speed)."""
    out = [_sweep(speed, 2990, 3000).sel(point=0) for speed in ("3000 rpm", "10000 rpm")]
    assert float(out[0].speed_rpm) == pytest.approx(2990, rel=1e-12)
    assert float(out[1].speed_rpm) == pytest.approx(2990, rel=1e-12)
    np.testing.assert_allclose(out[1].peak_force.values, out[0].peak_force.values, rtol=1e-7)
    np.testing.assert_allclose(out[1].dynamic_factor.values, out[0].dynamic_factor.values,
                               rtol=1e-7)


def test_the_undamped_mode_warning_of_a_state_at_another_speed_is_that_speeds():
    """`steady --speed` listed the undamped modes at the file's speed (265.37 Hz at
    100 rpm where 20000 rpm has 185.73 Hz: Cooley & Parker's undamped stage, a
    reviewer)."""
    import re

    from planetary_models import cp_raw

    def undamped(raw, speed=None):
        with warnings.catch_warnings(record=True) as got:
            warnings.simplefilter("always")
            model = torquesplit.load_model(raw)
            steady_state(model, speed=speed, method="hb", harmonics=2, stability=False,
                         max_cycles=20)
        said = [str(w.message) for w in got if "without damping" in str(w.message)]
        assert said, [str(w.message) for w in got]
        return [float(x) for x in re.findall(r"([0-9.]+) Hz", said[0])]

    def raw(speed):
        r = cp_raw(4, sun_speed=speed)
        r["loads"]["out"]["fluctuation"] = [{"amplitude": "1 N m", "order": 3}]
        return r

    asked = undamped(raw("100 rpm"), "20000 rpm")
    at_file = undamped(raw("20000 rpm"))
    np.testing.assert_allclose(asked, at_file, rtol=1e-6)
    assert asked != undamped(raw("100 rpm"))
