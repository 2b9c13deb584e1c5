"""Tooth friction on mesh elements (seed 003): tables, signs, projections, energy."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from model_texts import SPUR_PAIR

import torquesplit
from torquesplit.assembly.assemble import assemble
from torquesplit.assembly.excitation import friction_direction
from torquesplit.errors import ModelError
from torquesplit.model.io import model_from_dict, model_to_dict
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.solve import element_forces, integrate, rhs, static_equilibrium
from torquesplit.solve.reference import (
    element_forces_numpy,
    excitation_numpy,
    rhs_numpy,
)

MU = 0.05


def _pair(friction=f'{{model = "constant", coefficient = {MU}}}', *, translations=False,
          wheel_drives=False, speed_coefficient=None):
    text = SPUR_PAIR
    if friction is not None:
        text = text.replace("damping_ratio = 0.05\n", f"damping_ratio = 0.05\nfriction = {friction}\n", 1)
    if translations:
        sup = '\ndofs = ["theta", "x", "y"]\nsupport = {stiffness = "5e8 N/m", damping_ratio = 0.02}\n'
        text = text.replace('position = ["0 mm", "0 mm", "0 mm"]\n',
                            'position = ["0 mm", "0 mm", "0 mm"]' + sup, 1)
        text = text.replace('place = {from_gear = "pinion", angle = "0 deg"}\n',
                            'place = {from_gear = "pinion", angle = "0 deg"}' + sup, 1)
    if wheel_drives:
        text = text.replace('body = "pinion"\nspeed = "3000 rpm"\ntorque = "100 N m"',
                            'body = "wheel"\nspeed = "1500 rpm"\ntorque = "200 N m"')
        text = text.replace('[loads.out]\nbody = "wheel"', '[loads.out]\nbody = "pinion"')
    if speed_coefficient is not None:
        text += f'speed_coefficient = "{speed_coefficient} N m s/rad"\n'
    model = torquesplit.load_model(tomllib.loads(text))
    kin = solve_kinematics(model)
    return model, kin, assemble(model, kin)


def _single_contact_check(kin, s, mu):
    """Constant mu: in the single-contact zone the friction force per unit load is -mu
    before the pitch point and +mu after it, with the arms moving with the contact."""
    mk = kin.meshes["m"]
    geo = mk.geometry
    p1, p2, _, _ = geo._tangent_lengths
    if mk.driver == "pinion":
        start, pitch = p1 + geo.path_start, p1
    else:
        start, pitch = p2 - geo.path_end, p2
    line = p1 + p2
    eps = geo.transverse_contact_ratio
    phase_p = (pitch - start) / geo.base_pitch  # the entering pair reaches the pitch point
    assert eps - 1 < phase_p < 1  # pitch point inside the single-contact zone
    n = s.n_table
    ph = np.arange(n) / n
    ff, m1, m2 = s.friction_table
    single = (ph > eps - 1 + 2 / n) & (ph < 1 - 2 / n)
    before = single & (ph < phase_p - 1.5 / n)
    after = single & (ph > phase_p + 1.5 / n)
    assert before.sum() > 5 and after.sum() > 5
    np.testing.assert_allclose(ff[before], -mu, rtol=1e-12)
    np.testing.assert_allclose(ff[after], mu, rtol=1e-12)
    pos = start + ph * geo.base_pitch  # the only pair in contact
    np.testing.assert_allclose(m1[single], -ff[single] * pos[single], rtol=1e-12)
    np.testing.assert_allclose(m2[single], ff[single] * (line - pos[single]), rtol=1e-12)
    # approach: friction aids the driver and brakes the driven gear; recess: reversed
    assert np.all(m1[before] > 0) and np.all(m2[before] < 0)
    assert np.all(m1[after] < 0) and np.all(m2[after] > 0)
    return phase_p


@pytest.mark.parametrize("wheel_drives", [False, True])
def test_friction_force_reverses_at_the_pitch_point(wheel_drives):
    _, kin, s = _pair(wheel_drives=wheel_drives)
    assert kin.meshes["m"].driver == ("wheel" if wheel_drives else "pinion")
    phase_p = _single_contact_check(kin, s, MU)
    # the EHL (Xu) coefficient reverses at the same phase and vanishes there
    _, _, sx = _pair("true", wheel_drives=wheel_drives)
    ff = sx.friction_table[0]
    n = sx.n_table
    i = int(np.floor(phase_p * n))
    assert ff[i - 2] < 0 < ff[i + 3]
    assert abs(ff[i]) < 0.3 * max(abs(ff[i - 8]), abs(ff[i + 8]))
    # the kernel's interpolated values (excitation at mesh phases) follow the table
    f = sx.frequency[0]
    t = ((np.array([phase_p - 0.05, phase_p + 0.05]) - sx.phase[0]) % 1.0) / f
    vals = [excitation_numpy(sx, ti).friction[0] for ti in t]
    assert vals[0] < 0 < vals[1]


@pytest.mark.parametrize("model", ["constant", "xu2007"])
@pytest.mark.parametrize("wheel_drives", [False, True])
def test_friction_dissipates_at_every_mesh_phase(model, wheel_drives):
    fr = f'{{model = "{model}", coefficient = {MU}}}'
    _, kin, s = _pair(fr, translations=True, wheel_drives=wheel_drives)
    mk = kin.meshes["m"]
    # nominal DOF velocities (the body axes coincide with their DOF axes here)
    v_nom = np.zeros(s.n_dof)
    for body in ("pinion", "wheel"):
        v_nom[s.dof_names.index(f"{body}.theta")] = kin.bodies[body].speed
    w_d, w_n = (abs(kin.bodies[b].speed) for b in (mk.driver, mk.driven))
    _, m1, m2 = s.friction_table
    for i in range(0, s.n_table, 7):
        W = s.friction_matrix(s.friction_table[:, i])
        power = -W[0] @ v_nom  # per unit normal load
        assert power == pytest.approx(m1[i] * w_d + m2[i] * w_n, rel=1e-12, abs=1e-15)
        assert power <= 1e-15
    assert (m1 * w_d + m2 * w_n).mean() < 0
    # the friction force lies in the transverse plane, perpendicular to the line of action,
    # along the rolling direction: driver +t, driven -t (times the friction force)
    t_dir = friction_direction(kin, "m")
    n_vec = mk.line_of_action
    assert abs(t_dir @ n_vec) < 1e-15 and abs(np.linalg.norm(t_dir) - 1) < 1e-15
    drv = kin.bodies[mk.driver]
    v_contact = drv.speed * np.cross(drv.axis, mk.contact_point - drv.position)
    assert t_dir @ v_contact > 0
    W = s.friction_matrix(np.array([1.0, 0.0, 0.0]))
    for body, sign in ((mk.driver, 1.0), (mk.driven, -1.0)):
        got = [W[0, s.dof_names.index(f"{body}.{d}")] for d in "xy"]
        np.testing.assert_allclose(got, sign * t_dir[:2], atol=1e-15)


def test_friction_kernel_rhs_equals_numpy_twin():
    _, _, s = _pair("true", translations=True)
    st = static_equilibrium(s)
    rng = np.random.default_rng(3)
    n = s.n_dof
    for t in (0.0, 1.3e-4, 7.77e-4, 0.0123):
        for scale in (0.2, 1.0, 3.0):  # also states where the mesh separates (f < 0)
            y = np.concatenate([st.q * scale + rng.normal(scale=1e-6, size=n),
                                rng.normal(scale=1e-2, size=n)])
            dy_k, dy_n = rhs(s, t, y), rhs_numpy(s, t, y)
            assert np.max(np.abs(dy_k - dy_n)) <= 1e-12 * np.max(np.abs(dy_n))
            np.testing.assert_allclose(element_forces(s, t, y)[0],
                                       element_forces_numpy(s, t, y)[0], rtol=1e-13)


def test_friction_free_run_is_bit_for_bit_the_run_without_friction():
    _, _, plain = _pair(None, translations=True)
    _, _, zero = _pair('{model = "constant", coefficient = 0.0}', translations=True)
    assert zero.n_friction == 1 and not np.any(zero.friction_table)
    y0 = static_equilibrium(plain).y0
    for method in ("rk4", "dopri"):
        a = integrate(plain, y0, (0.0, 0.005), method=method, full_history=True)
        b = integrate(zero, y0, (0.0, 0.005), method=method, full_history=True)
        np.testing.assert_array_equal(a.full_y, b.full_y)
        np.testing.assert_array_equal(a.history_forces, b.history_forces)


def _powers(s, kin, sol):
    """Mean input power of the drive, output power to the load and friction power."""
    i_p, i_w = s.dof_names.index("pinion.theta"), s.dof_names.index("wheel.theta")
    half = sol.history_t >= 0.5 * sol.history_t[-1]
    v = sol.history_v[half]
    w_p = kin.bodies["pinion"].speed + v[:, i_p]
    w_w = kin.bodies["wheel"].speed + v[:, i_w]
    p_in = s.external_force[i_p] * w_p
    p_out = -(s.external_force[i_w] - s.ground_damping[i_w] * v[:, i_w]) * w_w
    v_abs = np.zeros_like(v)
    v_abs[:, i_p], v_abs[:, i_w] = w_p, w_w
    f = sol.history_forces[half, 0]
    p_fric = np.array([-(s.friction_matrix(excitation_numpy(s, t).friction)[0] @ va)
                       * max(fi, 0.0)
                       for t, va, fi in zip(sol.history_t[half], v_abs, f, strict=True)])
    rate = v @ s.projection_matrix()[0]
    p_damp = s.damping[0] * rate**2
    return p_in.mean(), p_out.mean(), p_fric.mean(), p_damp.mean()


def test_friction_takes_power_out_input_exceeds_output():
    # the load has a speed characteristic, so the train settles at the speed where the
    # load torque takes what friction leaves (tau = J / c << the run)
    _, kin, s = _pair(speed_coefficient=2.0)
    st = static_equilibrium(s)
    assert st.converged
    sol = integrate(s, st.y0, (0.0, 0.06), steps_per_period=100)
    assert sol.success
    p_in, p_out, p_fric, p_damp = _powers(s, kin, sol)
    assert p_in - p_out > 0.002 * p_in  # about mu x sliding / rolling of the input power
    assert p_fric < 0
    # energy balance in the periodic steady state: what goes in and does not come out is
    # dissipated by friction (and a little by the mesh damping)
    assert p_in - p_out == pytest.approx(-p_fric + p_damp, rel=1e-2)  # sampled means
    # without friction input and output power are equal (up to the damping loss)
    _, kin0, s0 = _pair(None, speed_coefficient=2.0)
    sol0 = integrate(s0, static_equilibrium(s0).y0, (0.0, 0.06), steps_per_period=100)
    p_in0, p_out0, _, _ = _powers(s0, kin0, sol0)
    assert abs(p_in0 - p_out0) < 1e-3 * (p_in - p_out)


def test_friction_on_bevel_or_internal_meshes_is_refused():
    text = SPUR_PAIR.replace("damping_ratio = 0.05\n", "damping_ratio = 0.05\nfriction = true\n")
    text = text.replace("[gears.pinion]\nteeth = 20", "[gears.pinion]\nteeth = 30")
    text = text.replace("[gears.wheel]\nteeth = 40", '[gears.wheel]\nteeth = 90\nkind = "internal"')
    text = text.replace('place = {from_gear = "pinion", angle = "0 deg"}',
                        'position = ["-60 mm", "0 mm", "0 mm"]')
    model = torquesplit.load_model(tomllib.loads(text))
    with pytest.raises(ModelError, match="meshes.m.friction: .*external pairs"):
        assemble(model)
    seed000 = model_to_dict(torquesplit.load_model(torquesplit.example_path("liu2021_split_torque_helicopter")))
    seed000["meshes"]["L12"]["friction"] = True  # a spiral bevel mesh
    with pytest.raises(ModelError, match="meshes.L12.friction: .*cylindrical"):
        assemble(model_from_dict(seed000))
