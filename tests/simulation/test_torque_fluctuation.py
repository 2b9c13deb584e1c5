"""Fluctuating drive and load torques (a mill's charge, a compressor, an engine): each
harmonic an element of additive force on the body's rotation."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from model_texts import SPUR_PAIR

import torquesplit
from torquesplit.errors import SolverError

J_PINION, J_WHEEL = 4e-5, 6e-4  # SPUR_PAIR's inertias [kg m^2]


def _pair(load_fluctuation: str = "", drive_extra: str = ""):
    text = SPUR_PAIR.replace('[loads.out]\nbody = "wheel"',
                             f'[loads.out]\nbody = "wheel"\n{load_fluctuation}')
    text = text.replace('torque = "100 N m"\n', f'torque = "100 N m"\n{drive_extra}\n', 1)
    return torquesplit.load_model(tomllib.loads(text))


def test_a_slow_load_fluctuation_reaches_the_mesh_as_the_rigid_train_divides_it():
    """Well below the mesh mode the train moves rigidly: a load torque T_a sin(w t) on the
    wheel changes the tooth force by T_a r_w J_p / (J_p r_w^2 + J_w r_p^2) (the pinion's
    share of the inertia carries it through the mesh)."""
    model = _pair('fluctuation = [{amplitude = "20 N m", order = 2, phase = "30 deg"}]')
    s = torquesplit.assemble(model)
    e = s.element_names.index("loads.out.fluctuation1")
    wheel = torquesplit.solve_kinematics(model).bodies["wheel"]
    assert s.frequency[e] == pytest.approx(2 * abs(wheel.speed) / (2 * np.pi), rel=1e-12)
    mesh = torquesplit.solve_kinematics(model).meshes["m"]
    r_p, r_w = mesh.base_radii
    expected = 20.0 * r_w * J_PINION / (J_PINION * r_w**2 + J_WHEEL * r_p**2)
    res = torquesplit.simulate(model, duration=0.4)
    t, f = res.mesh_force_history()
    late = f[t > 0.2, 0]
    assert (late.max() - late.min()) / 2 == pytest.approx(expected, rel=1e-3)
    assert late.mean() == pytest.approx(mesh.force, rel=1e-4)  # no change of the mean
    # the history keeps the fluctuating torque itself (N m)
    ds = res.to_dataset()
    assert dict(zip(ds["element"].values, ds["element_unit"].values))["loads.out.fluctuation1"] \
        == "N m"


def test_a_drive_fluctuation_of_a_fixed_frequency_and_its_sign():
    """More drive torque and more load torque both press the teeth harder: a drive
    harmonic reaches the mesh as T_a J_w r_p / (J_p r_w^2 + J_w r_p^2), in phase with a
    load harmonic of the same phase."""
    drive = _pair(drive_extra='fluctuation = [{amplitude = "5 N m", frequency = "40 Hz"}]')
    load = _pair('fluctuation = [{amplitude = "10 N m", frequency = "40 Hz"}]')
    mesh = torquesplit.solve_kinematics(drive).meshes["m"]
    r_p, r_w = mesh.base_radii
    out = []
    for model in (drive, load):
        t, f = torquesplit.simulate(model, duration=0.3).mesh_force_history()
        out.append(f[t > 0.15, 0] - mesh.force)
    expected = 5.0 * J_WHEEL * r_p / (J_PINION * r_w**2 + J_WHEEL * r_p**2)
    assert (out[0].max() - out[0].min()) / 2 == pytest.approx(expected, rel=2e-3)
    assert np.corrcoef(out[0], out[1])[0, 1] > 0.99


@pytest.mark.parametrize("fluct, drive, pattern", [
    ('fluctuation = [{amplitude = "20 N m"}]', "", "exactly one of 'order' and 'frequency'"),
    ('fluctuation = [{amplitude = "20 N m", order = 2, frequency = "5 Hz"}]', "",
     "exactly one of"),
    ("", 'mode = "speed"\nfluctuation = [{amplitude = "5 N m", order = 1}]',
     "'speed' drive holds its speed"),
])
def test_bad_fluctuations_are_refused(fluct, drive, pattern):
    with pytest.raises(torquesplit.ModelError, match=pattern):
        _pair(fluct, drive)


def test_a_steady_state_elsewhere_needs_an_order_not_a_fixed_frequency():
    from torquesplit.steady.api import steady_state

    fixed = _pair('fluctuation = [{amplitude = "20 N m", frequency = "50 Hz"}]')
    steady_state(fixed, method="hb")  # at the model's speed: fine
    with pytest.raises(SolverError, match="loads.out.fluctuation1.*fixed frequency"):
        steady_state(fixed, speed="2000 rpm", method="hb")
    by_order = _pair('fluctuation = [{amplitude = "20 N m", order = 2}]')
    assert steady_state(by_order, speed="2000 rpm", method="hb").success


@pytest.mark.parametrize("where", ["load", "drive"])
def test_the_quasi_static_sweep_carries_the_fluctuation_with_the_trains_inertia(where):
    """A fluctuating torque has no static equilibrium (the train accelerates): the
    quasi-static sweep balances it by the rigid train's inertial load (d'Alembert), which
    gives the rigid-train shares above exactly, with their signs (a harmonic at 90 deg is
    at its crest at t = 0: more torque, more tooth force)."""
    text = 'fluctuation = [{amplitude = "20 N m", order = 2, phase = "90 deg"}]'
    model = _pair(text) if where == "load" else _pair(drive_extra=text)
    res = torquesplit.quasi_static_load_sharing(model, revolutions=1)
    mesh = torquesplit.solve_kinematics(model).meshes["m"]
    r_p, r_w = mesh.base_radii
    den = J_PINION * r_w**2 + J_WHEEL * r_p**2
    share = r_w * J_PINION / den if where == "load" else J_WHEEL * r_p / den
    assert res.solution.converged.all()
    assert res.mesh_forces()[0, 0] - mesh.force == pytest.approx(20.0 * share, rel=1e-9)


def test_a_drives_slip_damps_the_trains_speed_swing():
    """A motor's torque-speed slope (speed_coefficient, a reviewer's request): the rigid
    train's speed swing under a slow load fluctuation is T_a/i / |i w J_eq + c|, J_eq
    the inertia referred to the pinion, i = 2 the ratio."""
    c = 0.06  # N m s/rad
    model = _pair('fluctuation = [{amplitude = "0.2 N m", order = 2}]',
                  f'speed_coefficient = "{c} N m s/rad"')
    s = torquesplit.assemble(model)
    i = list(s.dof_names).index("pinion.theta")
    assert s.ground_damping[i] == pytest.approx(c)
    res = torquesplit.simulate(model, duration=0.4, history_dofs=["pinion.theta"])
    t, v = res.solution.history_t, res.solution.history_v[:, 0]
    late = v[t > 0.2]
    w = 2 * np.pi * 50.0  # order 2 of the wheel at 1500 rpm
    j_eq = J_PINION + J_WHEEL / 4
    expected = 0.2 / 2 / abs(1j * w * j_eq + c)
    assert (late.max() - late.min()) / 2 == pytest.approx(expected, rel=5e-3)
    with pytest.raises(torquesplit.ModelError, match="speed_coefficient"):
        _pair(drive_extra='mode = "speed"\nspeed_coefficient = "0.1 N m s/rad"')


def test_a_drive_and_a_load_of_one_name_keep_their_fluctuations_apart():
    """Both were named 'x.fluctuation1' (a reviewer): the static balance found one twice."""
    text = 'fluctuation = [{amplitude = "2 N m", order = 2}]'
    model = _pair(text.replace("2 N m", "3 N m"), text)
    names = torquesplit.assemble(model).element_names
    assert {"drives.motor.fluctuation1", "loads.out.fluctuation1"} <= set(names)
