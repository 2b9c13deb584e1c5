"""One reference case per element kind, and every consumer of its law against it.

Each case is a one-element structure built with ``build_structure`` at a state where the
element has a given deformation and rate: a mesh with a stiffness table and per-cycle
half-gaps (its stiffness and gap at the time of the case), a support with a radial
clearance, a shaft (two rotations), a bearing between two bodies (two translations), a
mesh with tooth friction and a gyroscopic pair.  The reference is the law itself
(:func:`torquesplit.solve.laws.spring_force` on the element's k(t), c, deformation, rate
and half-gap g(t)); its consumers: the compiled general kernel, the generated code, the
numpy twin, the steady-state solvers' linearisation (force and both slopes), the static
Newton problem (force and tangent, the tangent also against a
central difference of the force) and the modal linearisation (the law's slope at the
mean stiffness and half-gap: modes are those of the time-averaged system).  The
right-hand side dy/dt of the three dynamic consumers is also compared with the
generalized forces written by hand: -V^T f, the friction moment -W(s) max(f, 0), the
gyroscopic force -G v (Ji & Li eq. 9 written for one element)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from torquesplit.assembly.structure import MESH, SPRING, build_structure
from torquesplit.solve import codegen, laws, modal_analysis
from torquesplit.solve.integrate import _evaluate
from torquesplit.solve.kernel_data import kernel_model, make_work
from torquesplit.solve.reference import (
    element_forces_numpy,
    excitation_numpy,
    rhs_numpy,
)
from torquesplit.solve.static import _StaticProblem
from torquesplit.steady import _kernels as sk

K, C = 3.0e8, 250.0  # N/m, N s/m
TABLE = K * (1.0 + 0.2 * np.cos(2 * np.pi * np.arange(256) / 256))
F_MESH, T_CASE = 800.0, 3.3e-4  # mesh frequency [Hz]; the case's time: phase 0.264


def _mesh_with_table():
    el = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[0.04, -0.06], stiffness=TABLE,
              frequency=F_MESH, phase=0.0, damping=C, gaps=[2e-6, 5e-6, 3e-6])
    return build_structure(["a.theta", "b.theta"], [1 / 2e-3, 1 / 5e-3], [el]), \
        np.array([2.5e-4, 1.0e-4]), np.array([0.3, -0.1])


def _support_with_clearance():
    el = dict(name="a.support.x", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=K,
              damping=C, gaps=4e-6)
    return build_structure(["a.x"], [1 / 2.0], [el]), np.array([9e-6]), np.array([0.02])


def _support_inside_its_clearance():
    s, q, v = _support_with_clearance()
    return s, np.array([2.5e-6]), v  # within the 4 um half-gap: no force, no slope


def _shaft():
    el = dict(name="shaft", kind=SPRING, dofs=[0, 1], coefs=[1.0, -1.0], stiffness=2e5,
              damping=3.0)
    return build_structure(["a.theta", "b.theta"], [1 / 1e-3, 1 / 4e-3], [el]), \
        np.array([1e-3, -2e-4]), np.array([0.5, 0.2])


def _two_body_bearing():
    el = dict(name="wheel.support.x", kind=SPRING, dofs=[0, 1], coefs=[1.0, -1.0],
              stiffness=K, damping=C)
    return build_structure(["wheel.x", "carrier.x"], [1 / 2.0, 1 / 5.0], [el]), \
        np.array([3e-6, -1e-6]), np.array([0.01, -0.02])


CASES = {"mesh with table and dead zone": (_mesh_with_table, True),
         "support with clearance": (_support_with_clearance, True),
         "support inside its clearance": (_support_inside_its_clearance, False),
         "shaft": (_shaft, True), "two-body bearing": (_two_body_bearing, True)}


def _law(s, t, q, v):
    """The reference: the law on the element's k(t), c, deformation, rate, g(t)."""
    ex = excitation_numpy(s, t)
    V = s.projection_matrix()
    d, r = float(V[0] @ q), float(V[0] @ v)
    f, df, _ = laws.spring_force(ex.stiffness[0], s.damping[0], d, r, ex.half_gap[0])
    return f, df, d, ex


@pytest.mark.parametrize("kind", list(CASES))
def test_every_consumer_evaluates_the_law(kind):
    build, contact = CASES[kind]
    s, q, v = build()
    t = T_CASE
    y = np.concatenate([q, v])
    f, df, d, ex = _law(s, t, q, v)
    assert (f != 0.0 and df > 0.0) == contact  # (the case is where it is meant to be)
    # the steady-state solvers' linearisation (harmonic balance, shooting): force and
    # both slopes of the law at the sample
    law = laws.spring_force(ex.stiffness[0], s.damping[0], d, float(s.projection_matrix()[0]
                                                                   @ v), ex.half_gap[0])
    m = kernel_model(s)
    out = (np.empty((1, 1)), np.empty((1, 1)), np.empty((1, 1)), np.zeros((1, 1, 8)),
           np.zeros((1, 1)), np.zeros((1, 1)))
    sk.sample_linearise(np.array([t]), np.concatenate([q, v])[None, :], m, make_work(m),
                        *out)
    assert (out[0][0, 0], out[1][0, 0], out[2][0, 0]) == law
    code = codegen.generated_rhs(kernel_model(s))
    dy_gen, f_gen, d_gen = _evaluate(s, t, y, code=code)
    dy_ker, f_ker, d_ker = _evaluate(s, t, y)
    f_np, d_np = element_forces_numpy(s, t, y)
    for got in (f_gen[0], f_ker[0], f_np[0]):
        assert got == f  # (the same law, the same arithmetic: bit for bit)
    assert d_gen[0] == d_ker[0] == d_np[0] == d
    # the generalized forces: dy = [v, M^-1 (-V^T f)]
    V = s.projection_matrix()
    hand = np.concatenate([v, s.inv_mass * (-V[0] * f)])
    for dy in (dy_gen, dy_ker, rhs_numpy(s, t, y)):
        np.testing.assert_allclose(dy, hand, rtol=1e-12, atol=0.0)
    # static Newton at the case's time: the force at rest and its tangent, the tangent
    # against a central difference of the force
    problem = _StaticProblem(s, t, 1e-8)
    loads = problem.loads(t)
    _, fs, kt, _, _, _ = problem.forces(q, loads, 0.0)
    f0, df0, _ = laws.spring_force(ex.stiffness[0], 0.0, d, 0.0, ex.half_gap[0])
    assert fs[0] == f0 and kt[0] == df0
    h = 1e-6 * max(abs(d), 1e-9)
    u = V[0] / float(V[0] @ V[0])  # a move of the state that changes d by one
    fd = (problem.forces(q + h * u, loads, 0.0)[1][0]
          - problem.forces(q - h * u, loads, 0.0)[1][0]) / (2 * h)
    assert fd == pytest.approx(kt[0], rel=1e-6)
    # modal linearisation: the law's slope at the mean stiffness and half-gap (modes are
    # of the time-averaged system) times V^T V, over the masses
    modal = modal_analysis(s, q)
    g_mean = float(s.gap_values[s.gap_ptr[0]:s.gap_ptr[1]].mean())
    slope = laws.spring_force(float(s.mean_stiffness()[0]), 0.0, d, 0.0, g_mean)[1]
    assert (slope > 0.0) == contact
    Kl = slope * np.outer(V[0], V[0])
    lam = np.linalg.eigvalsh(np.sqrt(s.inv_mass)[:, None] * Kl * np.sqrt(s.inv_mass))
    want = np.sqrt(lam[lam > 1e-9 * max(lam.max(), 1e-300)]) / (2 * np.pi)
    np.testing.assert_allclose(np.sort(modal.frequencies), np.sort(want), rtol=1e-12)


@pytest.mark.parametrize("flank", [1.0, -1.0])
def test_tooth_friction_and_gyroscopic_terms_in_every_dynamic_consumer(flank):
    """The friction moment -W(s) max(f, 0) of a mesh with tooth friction (on the working
    flank only: none on the back flank, ``flank`` -1) and the gyroscopic force -G v, each
    in dy/dt of the generated code, the kernel and the numpy twin, against the hand sum."""
    n_tab = 256
    mu = np.vstack([0.05 + 0.01 * np.sin(2 * np.pi * np.arange(n_tab) / n_tab)] * 3)
    mesh = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[0.04, -0.06], stiffness=K,
                frequency=F_MESH, damping=C,
                friction=dict(table=mu, dofs=[2, 3], coefs=[1e-3, -2e-3], rows=[0, 2]))
    g = 7.0  # N s/m between the two translations
    s = build_structure(["a.theta", "b.theta", "a.x", "a.y"], [500.0, 200.0, 0.5, 0.5],
                        [mesh], gyroscopic=[(2, 3, g), (3, 2, -g)])
    q = np.array([2.5e-4 * flank, 1.0e-4 * flank, 1e-6, -2e-6])
    v = np.array([0.3, -0.1, 0.02, 0.05])
    y = np.concatenate([q, v])
    t = T_CASE
    f, _, _, ex = _law(s, t, q, v)
    assert (f > 0.0) == (flank > 0)
    V = s.projection_matrix()
    W = s.friction_matrix(ex.friction)
    G = np.zeros((4, 4))
    G[2, 3], G[3, 2] = g, -g
    acc = -V[0] * f - W.T @ np.array([max(f, 0.0)]) - G @ v
    hand = np.concatenate([v, s.inv_mass * acc])
    assert np.abs(W).max() > 0 and np.abs(G @ v).max() > 0
    code = codegen.generated_rhs(kernel_model(s))
    for dy in (_evaluate(s, t, y, code=code)[0], _evaluate(s, t, y)[0], rhs_numpy(s, t, y)):
        np.testing.assert_allclose(dy, hand, rtol=1e-12, atol=1e-12 * np.abs(hand).max())
    # and the modal linearisation takes the gyroscopic matrix: the free pair (a.x, a.y)
    # precesses at g / m (m = 2 kg), the mesh's mode is unchanged
    with_g = modal_analysis(s, q).frequencies
    without = modal_analysis(build_structure(s.dof_names, s.inv_mass, [mesh]), q).frequencies
    assert without.size == 1 and with_g.size == 2
    assert with_g[0] == pytest.approx(g * 0.5 / (2 * math.pi), rel=1e-9)
    assert with_g[1] == pytest.approx(without[0], rel=1e-12)


def test_the_cases_load_their_laws_at_the_case_time():
    """The mesh case's stiffness and half-gap are those of its phase at T_CASE (not the
    table's mean or first entry): the consumers are compared where the law varies."""
    s, q, v = _mesh_with_table()
    ex = excitation_numpy(s, T_CASE)
    phase = F_MESH * T_CASE
    assert ex.stiffness[0] != TABLE.mean() and ex.stiffness[0] != TABLE[0]
    assert ex.stiffness[0] == pytest.approx(
        np.interp(phase % 1 * 256, np.arange(257), np.append(TABLE, TABLE[0])), rel=1e-12)
    assert ex.half_gap[0] == [2e-6, 5e-6, 3e-6][math.floor(phase) % 3]
