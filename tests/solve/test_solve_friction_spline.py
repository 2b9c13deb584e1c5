"""Tooth friction and spline radial elements: kernels against their numpy twins, the
radial law, friction-free runs bit for bit, robust per-cycle statistics."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest
from solve_models import J1, J2, R1, R2, random_structure_extras, spur_pair

from torquesplit.assembly.structure import MESH, SPLINE, SPRING, build_structure
from torquesplit.solve import element_forces, integrate, rhs, static_equilibrium
from torquesplit.solve.reference import (
    cycle_index_numpy,
    dopri_numpy,
    element_forces_numpy,
    excitation_numpy,
    rhs_numpy,
    rk4_numpy,
    spline_law_numpy,
)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kernel_rhs_equals_twin_with_friction_and_splines(seed):
    s = random_structure_extras(seed)
    rng = np.random.default_rng(200 + seed)
    n = s.n_dof
    regimes, signs = set(), set()
    for t in [0.0, 1.234e-3, 0.0371, 2.5, 17.3]:
        for _ in range(30):
            y = np.concatenate([rng.normal(scale=3e-6, size=n), rng.normal(scale=1e-3, size=n)])
            dy_k = rhs(s, t, y)
            dy_n = rhs_numpy(s, t, y)
            np.testing.assert_array_equal(dy_k[:n], dy_n[:n])
            scale = np.max(np.abs(dy_n[n:]))
            assert np.max(np.abs(dy_k[n:] - dy_n[n:])) <= 1e-12 * scale
            f_k, d_k = element_forces(s, t, y)
            f_n, d_n = element_forces_numpy(s, t, y)
            np.testing.assert_allclose(d_k, d_n, rtol=0, atol=1e-12 * np.max(np.abs(d_n)))
            np.testing.assert_allclose(f_k, f_n, rtol=0, atol=1e-12 * np.max(np.abs(f_n)))
            ex, ey = s.sp_el[0]
            rad = math.hypot(d_n[ex], d_n[ey])
            regimes.add(0 if rad < 1e-6 else (1 if rad <= 3e-6 else 2))
            signs.update(np.sign(f_n[s.fr_el]).tolist())
    assert regimes == {0, 1, 2}  # stick, float and contact of spline A all seen
    assert {-1.0, 1.0} <= signs  # friction applied (f > 0) and skipped (f < 0)


def test_friction_and_spline_terms_of_the_twin_by_hand():
    s = random_structure_extras(3)
    rng = np.random.default_rng(5)
    n = s.n_dof
    t = 0.0123
    y = np.concatenate([rng.normal(scale=3e-6, size=n), rng.normal(scale=1e-3, size=n)])
    force, delta = element_forces_numpy(s, t, y)
    # (delta is V q - e; the rate less the errors' rate: spB's components carry errors)
    rate = s.projection_matrix() @ y[n:] - excitation_numpy(s, t).error_rate
    for (ex, ey), par in zip(s.sp_el, s.sp_par, strict=True):
        fx, fy = spline_law_numpy(par, delta[ex], delta[ey], rate[ex], rate[ey])
        assert (force[ex], force[ey]) == (fx, fy)
    # the friction part of the acceleration: -M^-1 sum_e W_e(s(t)) max(f_e, 0)
    vals = excitation_numpy(s, t).friction
    expected = np.zeros(n)
    for j, e in enumerate(s.fr_el):
        for i in range(s.fr_ptr[j], s.fr_ptr[j + 1]):
            expected[s.fr_dof[i]] -= s.fr_coef[i] * vals[s.fr_row[i]] * max(force[e], 0.0)
    no_friction = build_structure(s.dof_names, s.inv_mass, [], n_table=4)  # for shapes only
    assert no_friction.n_friction == 0
    gen = s.external_force - s.ground_damping * y[n:] - s.projection_matrix().T @ force
    np.testing.assert_allclose(rhs_numpy(s, t, y)[n:], s.inv_mass * (gen + expected),
                               rtol=1e-13, atol=0)


def test_spline_law_regimes():
    k, c, s1, s2, fm, v = 1e8, 50.0, 2e-6, 1e-5, 40.0, 1e-3
    par = np.array([k, c, s1, s2, fm, v])
    # stick: linear spring-damper along d
    fx, fy = spline_law_numpy(par, 1e-6, 0.0, 2e-3, 0.0)
    assert fx == pytest.approx(k * 1e-6 + c * 2e-3) and fy == 0.0
    # floating: friction only, opposing the radial rate (F > 0 along d for Rdot > 0)
    fx, fy = spline_law_numpy(par, 0.0, 5e-6, 0.0, 1.0)
    assert fx == 0.0 and fy == pytest.approx(fm * math.tanh(1.0 / v))
    fx, fy = spline_law_numpy(par, 0.0, 5e-6, 0.0, -1e-4)
    assert fy == pytest.approx(fm * math.tanh(-0.1))
    # tangential sliding in the clearance is free
    assert spline_law_numpy(par, 0.0, 5e-6, 3.0, 0.0) == (0.0, 0.0)
    # contact: elastic beyond the clearance plus damping and friction
    d = np.array([3e-6, 1.2e-5])
    rad = np.linalg.norm(d)
    fx, fy = spline_law_numpy(par, d[0], d[1], 0.0, 0.0)
    assert np.hypot(fx, fy) == pytest.approx(k * (rad - s2))
    assert fx / fy == pytest.approx(d[0] / d[1])
    assert spline_law_numpy(par, 0.0, 0.0, 1.0, 1.0) == (0.0, 0.0)


def _floating_mass(clearance, friction, stick=0.0, with_spline=True):
    """A 2-D mass on soft ground springs, optionally held by a spline to ground."""
    els = [dict(name="kx", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=1e6, damping=5.0),
           dict(name="ky", kind=SPRING, dofs=[1], coefs=[1.0], stiffness=2e6, damping=5.0)]
    if with_spline:
        els.append(dict(name="sp", kind=SPLINE, x=([0], [-1.0]), y=([1], [-1.0]),
                        stiffness=1e9, damping=100.0, stick_limit=stick,
                        clearance=clearance, friction_force=friction,
                        velocity_scale=1e-3))
    return build_structure(["m.x", "m.y"], [1 / 2.0, 1 / 2.0], els)


def test_spline_clearance_larger_than_the_motion_exerts_no_force():
    y0 = np.array([4e-6, -3e-6, 0.0, 0.0])  # orbit radius <= 5 um, clearance 20 um
    free = integrate(_floating_mass(0.0, 0.0, with_spline=False), y0, (0.0, 0.05),
                     step=2e-5, full_history=True)
    held = integrate(_floating_mass(20e-6, 0.0), y0, (0.0, 0.05), step=2e-5,
                     full_history=True)
    assert held.success and np.max(np.hypot(*held.full_y[:, :2].T)) < 20e-6
    np.testing.assert_array_equal(held.history_forces[:, 2:], 0.0)
    np.testing.assert_array_equal(held.full_y, free.full_y)  # bit for bit
    # with friction the spline only ever exerts friction (never the elastic force)
    fric = integrate(_floating_mass(20e-6, 3.0), y0, (0.0, 0.05), step=2e-5)
    radial = np.hypot(*fric.history_forces[:, 2:].T)
    assert np.max(radial) <= 3.0 + 1e-12 and np.max(radial) > 1.0


def test_spline_contact_restores_and_friction_opposes_radial_motion():
    s = _floating_mass(10e-6, 5.0, with_spline=True)
    s = build_structure(s.dof_names, s.inv_mass, [
        dict(name="sp", kind=SPLINE, x=([0], [-1.0]), y=([1], [-1.0]), stiffness=1e9,
             clearance=10e-6, friction_force=5.0, velocity_scale=1e-3)])
    u = np.array([9e-6, 12e-6])  # R = 15 um: 5 um into contact
    acc = rhs(s, 0.0, np.concatenate([u, [0.0, 0.0]]))[2:]
    assert acc @ u < 0  # restoring
    np.testing.assert_allclose(np.linalg.norm(acc) * 2.0, 1e9 * 5e-6, rtol=1e-12)
    u = np.array([3e-6, 4e-6])  # floating, moving outwards
    acc = rhs(s, 0.0, np.concatenate([u, 0.01 * u / 5e-6]))[2:]
    assert acc @ u < 0
    np.testing.assert_allclose(np.linalg.norm(acc) * 2.0, 5.0 * math.tanh(10.0), rtol=1e-12)


def test_rk4_kernel_matches_readable_rk4_with_friction_and_splines():
    s = random_structure_extras(4)
    rng = np.random.default_rng(9)
    y0 = np.concatenate([rng.normal(scale=2e-6, size=s.n_dof), np.zeros(s.n_dof)])
    h, n_steps = 2e-6, 300
    _, ys = rk4_numpy(s, y0, 0.0, h, n_steps)
    sol = integrate(s, y0, (0.0, n_steps * h), step=h, full_history=True, corners=False)
    assert sol.n_steps == n_steps
    scale = np.max(np.abs(ys), axis=0)
    assert np.all(np.abs(sol.full_y - ys) <= 1e-10 * scale + 1e-300)


def _smooth_friction_pair(mu=0.05):
    """Spur pair with constant friction moments on both rotations (a tabulated one would
    have kinks at the table nodes, where accept / reject decisions of the adaptive
    method hinge on round-off) and a preloaded mesh: comparable with the twin."""
    m1, m2 = -0.3 * mu * R1, -0.3 * mu * R2  # both oppose the rotation
    mesh = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[R1, -R2], stiffness=2e8,
                damping=200.0, frequency=900.0,
                errors=[(1e-6, 2 * np.pi * 900, 0.3), (3e-7, 2 * np.pi * 1700, 1.0)],
                friction=dict(table=[[0.0], [m1], [m2]], dofs=[0, 1], coefs=[-1.0, -1.0],
                              rows=[1, 2]))
    f = 100.0 / (R1 - m1)  # lossy balance: the load takes what friction leaves
    return build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh],
                           external_force=[100.0, -(R2 + m2) * f], n_table=64)


def test_dopri_kernel_matches_readable_dopri_with_friction():
    s = _smooth_friction_pair()
    st = static_equilibrium(s)
    assert abs(st.rigid_acceleration[0]) < 1e-9 * np.max(np.abs(s.external_force))
    y0 = st.y0 + np.array([0.0, 0.0, 1e-3, -2e-3])
    atol = np.array([1e-12, 1e-12, 1e-8, 1e-8])
    sol = integrate(s, y0, (0.0, 0.005), method="dopri", rtol=1e-7, atol=atol,
                    max_step=1e-4, full_history=True, history_elements=(), history_dofs=())
    mod = importlib.import_module("torquesplit.solve.integrate")
    h0 = min(mod._initial_step(s, y0, 0.0, 0.005, 1e-7, atol, None), 1e-4)
    _, y_ref, n_rej = dopri_numpy(s, y0, (0.0, 0.005), rtol=1e-7, atol=atol, h0=h0,
                                  h_max=1e-4)
    assert sol.n_steps == len(y_ref) - 1 and sol.n_rejected == n_rej
    np.testing.assert_allclose(sol.y_final, y_ref[-1], rtol=1e-9,
                               atol=1e-9 * np.abs(y_ref).max(axis=0).max())


@pytest.mark.parametrize("method", ["rk4", "dopri"])
def test_zero_friction_runs_bit_for_bit_like_no_friction(method):
    table = 2e8 * (1 + 0.3 * np.sign(np.sin(2 * np.pi * np.arange(64) / 64)))
    plain = spur_pair(damping=150.0, frequency=1000.0, stiffness=table, gaps=3e-6,
                      errors=[(2e-6, 2 * np.pi * 60, 0.0)])
    mesh = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[R1, -R2], stiffness=table,
                damping=150.0, gaps=3e-6, frequency=1000.0,
                errors=[(2e-6, 2 * np.pi * 60, 0.0)],
                friction=dict(table=np.zeros((3, 64)), dofs=[0, 1], coefs=[-1.0, 1.0],
                              rows=[1, 2]))
    zero = build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh],
                           external_force=plain.external_force, n_table=64)
    y0 = static_equilibrium(plain).y0
    kw = dict(method=method, full_history=True)
    a = integrate(plain, y0, (0.0, 0.01), **kw)
    b = integrate(zero, y0, (0.0, 0.01), **kw)
    assert a.n_steps == b.n_steps
    np.testing.assert_array_equal(a.full_y, b.full_y)
    np.testing.assert_array_equal(a.history_forces, b.history_forces)
    np.testing.assert_array_equal(a.cycle_max, b.cycle_max)


def test_cycle_index_counts_boundary_samples_in_the_cycle_they_start():
    assert cycle_index_numpy(31.999999999999996) == 32
    assert cycle_index_numpy(31.9999) == 31
    assert cycle_index_numpy(-1e-17) == 0
    # 100 steps per mesh period: every full cycle must hold exactly 100 samples; with
    # floor(f t + phase) samples at the boundaries that round below the integer fell
    # into the previous cycle (99 / 101 samples)
    f = 4243.67  # seed 002 stage I: 9 of the 40 boundaries round below the integer
    s = spur_pair(damping=100.0, frequency=f, phase=0.0,
                  stiffness=2e8 * (1 + 0.3 * (np.arange(64) < 20)))
    sol = integrate(s, static_equilibrium(s).y0, (0.0, 40 / f), steps_per_period=100)
    assert sol.success and sol.n_steps == 4000
    boundary = f * (np.arange(0, 4001, 100) * sol.step)
    assert np.sum(np.floor(boundary) < np.arange(41)) >= 5  # what floor(s) got wrong
    np.testing.assert_array_equal(sol.cycle_count[:-1, 0], 100)
    # the stepped stiffness is high from phase 0: the boundary sample carries the
    # cycle's new (higher-stiffness) state and is counted in the cycle it starts
    starts = sol.cycle_start[:, 0]
    np.testing.assert_allclose(f * starts, np.arange(len(starts)), atol=1e-9)


def _friction_jump_pair():
    """A loaded mesh (constant stiffness, stays in contact) whose friction table jumps at
    0.3 of the cycle and at its end, as the sliding direction reverses at a pitch point."""
    n = 256
    ph = np.arange(n) / n
    row = np.where(ph < 0.3, 0.05, -0.05) * (1.0 + ph)
    return build_structure(
        ["a.theta", "b.theta", "b.x"], [1e3, 5e2, 1.0],
        [dict(name="m", kind=MESH, dofs=[0, 1, 2], coefs=[0.05, 0.08, 1.0],
              stiffness=[2e8, 2e8], frequency=1000.0, damping=200.0,
              friction=dict(table=[row, 0.02 * row, -0.01 * row], dofs=[0, 1, 2],
                            coefs=[1.0, 1.0, 0.5], rows=[1, 2, 0])),
         dict(name="ka", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=1e6, damping=10.0),
         dict(name="kb", kind=SPRING, dofs=[1], coefs=[1.0], stiffness=1e6, damping=10.0),
         dict(name="kx", kind=SPRING, dofs=[2], coefs=[1.0], stiffness=1e8, damping=100.0)],
        external_force=[0.0, 0.0, 1000.0], n_table=n)


def test_rk4_keeps_its_order_through_the_jumps_of_a_friction_table():
    """The jumps of a friction table are corners (kernel_data._corners): RK4 steps end on
    them, so halving the step divides the error by about 16.  Stepped over (as before,
    and as with corners=False here), the differences fall by 7x and then 1.4x."""
    from torquesplit.solve.kernel_data import kernel_model

    s = _friction_jump_pair()
    m = kernel_model(s)
    assert {76, 77} <= set(m.corner_node[m.corner_ptr[0]:m.corner_ptr[1]].tolist())
    y0 = static_equilibrium(s).y0
    finals = []
    for spc in (40, 80, 160, 320):
        sol = integrate(s, y0, (0.0, 0.01), method="rk4", step=1e-3 / spc)
        assert sol.success and sol.cycle_min.min() > 300.0  # in contact: no force kink
        finals.append(sol.y_final)
    diffs = [float(np.max(np.abs(a - b))) for a, b in zip(finals, finals[1:])]
    assert diffs[0] / diffs[1] > 8.0 and diffs[1] / diffs[2] > 8.0, diffs
