"""The element laws (solve/laws.py): a hand case per law, derivatives against finite
differences, and every consumer (compiled kernel, numpy twin, static Newton, modal
linearisation) giving the law's own numbers on a one-element structure."""

from __future__ import annotations

import math

import numpy as np
import pytest

from torquesplit.assembly.structure import MESH, SPLINE, build_structure
from torquesplit.solve import element_forces, element_forces_numpy, laws, modal_analysis
from torquesplit.solve.static import _StaticProblem

K, C, G = 2.0e8, 300.0, 1.0e-6  # N/m, N s/m, m
PAR = (5.0e7, 20.0, 1.0e-6, 3.0e-6, 30.0, 1.0e-3)  # spline: k, c, S1, S2, F_m, v


def _fd(fun, x, h):
    return (fun(x + h) - fun(x - h)) / (2 * h)


# ------------------------------------------------------------------ hand cases
@pytest.mark.parametrize("d, g, h, dh", [
    (5e-6, 1e-6, 4e-6, 1.0),  # beyond the dead zone: d - g
    (-3e-6, 1e-6, -2e-6, 1.0),  # back side: d + g
    (0.4e-6, 1e-6, 0.0, 0.0),  # inside: nothing carried
    (-2e-6, 0.0, -2e-6, 1.0),  # no dead zone
])
def test_dead_zone_hand_cases(d, g, h, dh):
    hh, dd, u = laws.dead_zone(d, g)
    assert (hh, dd) == pytest.approx((h, dh), rel=1e-12, abs=1e-22)
    assert u == pytest.approx(0.5 * h * h, rel=1e-12, abs=1e-30)


def test_spring_force_hand_case():
    # f = k (d - g) + c r = 2e8 * 4e-6 + 300 * 0.01 = 803 N; inside: 0 and no damping
    assert laws.spring_force(K, C, 5e-6, 0.01, G) == pytest.approx((803.0, K, C), rel=1e-12)
    assert laws.spring_force(K, C, 0.5e-6, 0.01, G) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("radius, rate, force, region", [
    # stick: k R + c Rdot = 5e7 * 0.5e-6 + 20 * 0.01 = 25.2 N
    (0.5e-6, 0.01, 25.2, laws.STICK),
    # floating: F_m tanh(Rdot / v) = 30 tanh(0.5)
    (2.0e-6, 0.5e-3, 30.0 * math.tanh(0.5), laws.FLOAT),
    # contact: k (R - S2) + c Rdot + F_m tanh(Rdot / v) = 50 + 0.2 + 30 tanh(10)
    (4.0e-6, 0.01, 50.0 + 0.2 + 30.0 * math.tanh(10.0), laws.CONTACT),
])
def test_spline_radial_hand_cases(radius, rate, force, region):
    f, _, _, _, reg = laws.spline_radial(radius, rate, *PAR)
    assert f == pytest.approx(force, rel=1e-12)
    assert reg == region


def test_table_phase_and_cycle_hand_case():
    # phase 3 + 13/32 in a 16-sample table: 6.5 samples in, weight 0.5, cycle 3
    i0, i1, w, fl = laws.table_phase(3.40625, 16)
    assert (i0, i1, w, fl) == (6, 7, 0.5, 3.0)
    assert laws.lerp(1.0, 2.0, w) == 1.5
    assert laws.table_phase(0.96875, 16)[:2] == (15, 0)  # wraps around the period
    assert laws.stat_cycle(4.0 - 1e-12, 3.0) == 4  # a boundary sample starts its cycle
    assert laws.positive_part(-2.0) == (0.0, 0.0) and laws.positive_part(2.0) == (2.0, 1.0)


# ------------------------------------------------------ derivatives, finite diffs
@pytest.mark.parametrize("d", [5e-6, -3e-6, 0.4e-6])
def test_spring_force_derivatives_match_finite_differences(d):
    r = 0.01
    f, f_d, f_r = laws.spring_force(K, C, d, r, G)
    assert f_d == pytest.approx(_fd(lambda x: laws.spring_force(K, C, x, r, G)[0], d, 1e-10),
                                rel=1e-6, abs=1e-3)
    assert f_r == pytest.approx(_fd(lambda x: laws.spring_force(K, C, d, x, G)[0], r, 1e-6),
                                rel=1e-6, abs=1e-6)
    # the energy of the dead zone is the integral of h
    assert laws.dead_zone(d, G)[0] == pytest.approx(
        _fd(lambda x: laws.dead_zone(x, G)[2], d, 1e-10), rel=1e-6, abs=1e-18)


@pytest.mark.parametrize("radius, rate", [(0.5e-6, 0.01), (2.0e-6, 0.5e-3), (4.0e-6, 0.01)])
def test_spline_radial_derivatives_match_finite_differences(radius, rate):
    f, f_r, f_rd, u, _ = laws.spline_radial(radius, rate, *PAR)
    assert f_r == pytest.approx(_fd(lambda x: laws.spline_radial(x, rate, *PAR)[0], radius,
                                    1e-11), rel=1e-6, abs=1e-3)
    assert f_rd == pytest.approx(_fd(lambda x: laws.spline_radial(radius, x, *PAR)[0], rate,
                                     1e-8), rel=1e-6)
    elastic = laws.spline_radial(radius, 0.0, *PAR)[0]
    assert elastic == pytest.approx(_fd(lambda x: laws.spline_radial(x, 0.0, *PAR)[3],
                                        radius, 1e-11), rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("d, rate", [((0.3e-6, -0.2e-6), (0.01, 0.02)),
                                     ((1.5e-6, 1.2e-6), (3e-4, -2e-4)),
                                     ((-3.0e-6, 2.5e-6), (0.01, -0.03))])
def test_spline_tangent_is_the_jacobian_of_spline_force(d, rate):
    args = (*d, *rate)
    t = laws.spline_tangent(*args, *PAR)
    jac = np.array([[t[0], t[1]], [t[2], t[3]]])
    damp = np.array([[t[4], t[5]], [t[6], t[7]]])
    for k in range(4):
        step = 1e-11 if k < 2 else 1e-8
        lo, hi = list(args), list(args)
        lo[k] -= step
        hi[k] += step
        col = (np.array(laws.spline_force(*hi, *PAR)) - np.array(laws.spline_force(*lo, *PAR))
               ) / (2 * step)
        ref = jac[:, k] if k < 2 else damp[:, k - 2]
        np.testing.assert_allclose(ref, col, rtol=1e-5, atol=1e-6 * np.abs(col).max())


# ------------------------------------------------------------- every consumer
def _one_spring(d_static):
    """A mass on a mesh-like spring with a dead zone, displaced to d_static."""
    return build_structure(["b.x"], [1.0], [dict(name="e", kind=MESH, dofs=[0], coefs=[1.0],
                                                 stiffness=K, damping=C, gaps=G)])


@pytest.mark.parametrize("d", [5e-6, -3e-6, 0.4e-6])
def test_every_consumer_uses_the_spring_law(d):
    s = _one_spring(d)
    y = np.array([d, 0.01])
    f_law, f_d, _ = laws.spring_force(K, C, d, 0.01, G)
    # compiled kernel and numpy twin
    assert element_forces(s, 0.0, y)[0][0] == f_law
    assert element_forces_numpy(s, 0.0, y)[0][0] == f_law
    # static Newton (no damping, no regularisation): force and tangent
    problem = _StaticProblem(s, 0.0, 1e-8)
    _, f, kt, energy, _, _ = problem.forces(np.array([d]), problem.loads(None), 0.0)
    assert f[0] == laws.spring_force(K, C, d, 0.0, G)[0]
    assert kt[0] == f_d
    assert energy == pytest.approx(K * laws.dead_zone(d, G)[2], rel=1e-12, abs=1e-30)
    # modal linearisation: the law's slope at the state
    modal = modal_analysis(s, np.array([d]))
    assert bool(modal.active[0]) == (f_d > 0)
    if f_d > 0:
        assert modal.frequencies[0] == pytest.approx(math.sqrt(f_d) / (2 * math.pi), rel=1e-12)
    else:
        assert modal.frequencies.size == 0


def test_every_consumer_uses_the_spline_law():
    s = build_structure(["a.x", "a.y"], [1.0, 1.0],
                        [dict(name="sp", kind=SPLINE, x=([0], [-1.0]), y=([1], [-1.0]),
                              stiffness=PAR[0], damping=PAR[1], stick_limit=PAR[2],
                              clearance=PAR[3], friction_force=PAR[4], velocity_scale=PAR[5])])
    q = np.array([-3.0e-6, 2.5e-6])  # relative displacement d = -q: in contact
    v = np.array([0.01, -0.03])
    fx, fy = laws.spline_force(*(-q), *(-v), *PAR)
    for fun in (element_forces, element_forces_numpy):
        f, _ = fun(s, 0.0, np.concatenate([q, v]))
        np.testing.assert_array_equal(f, [fx, fy])
    problem = _StaticProblem(s, 0.0, 1e-8)
    _, f, _, _, state, sp = problem.forces(q, problem.loads(None), 0.0)
    np.testing.assert_array_equal(f, laws.spline_force(*(-q), 0.0, 0.0, *PAR))
    t = laws.spline_tangent(*(-q), 0.0, 0.0, *PAR)
    np.testing.assert_array_equal(sp[0], [[t[0], t[1]], [t[2], t[3]]])
    assert state[0] == t[9] == laws.CONTACT
    modal = modal_analysis(s, q)
    lam = np.sort(np.linalg.eigvalsh(np.array([[t[0], t[1]], [t[2], t[3]]])))
    np.testing.assert_allclose(np.sort(modal.frequencies), np.sqrt(lam) / (2 * math.pi),
                               rtol=1e-12)


def test_negative_share_equals_its_twin_and_may_cross_never_misses_a_crossing():
    """The contact times' split of an interval (``laws.negative_share``, the parabola
    through three samples) against the roots in numpy, on crossings, dips between two
    positive samples and rises between two negative ones; ``may_cross`` (the kernels'
    shortcut to a whole interval) is true wherever the share is not 0 or 1."""
    from torquesplit.solve.reference import negative_share_numpy

    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(2, 4000))
    c = rng.normal(scale=3.0, size=4000)
    c[:200] = 0.0  # (the chord)
    a[200:300] = b[200:300] = 0.1  # a dip below zero between two positive samples
    c[200:300] = np.linspace(0.2, 1.0, 100)
    expect = negative_share_numpy(a, b, c)
    got = np.array([laws.negative_share(x, y, z) for x, y, z in zip(a, b, c, strict=True)])
    np.testing.assert_allclose(got, expect, rtol=1e-12, atol=1e-12)
    assert np.all((got >= 0) & (got <= 1))
    partial = (got > 1e-15) & (got < 1 - 1e-15)
    assert partial.sum() > 1000 and np.sum(partial & (np.sign(a) == np.sign(b))) > 100
    cross = np.array([laws.may_cross(x, y, z) for x, y, z in zip(a, b, c, strict=True)])
    assert not np.any(partial & ~cross)
    assert np.all(got[~cross] == (a[~cross] < 0))
    # the dips: none at a sag of 0.4 or less (the parabola's lowest point 0.1 - sag / 4)
    assert np.all(got[200:300][c[200:300] <= 0.4] == 0.0)
    assert np.all(got[200:300][c[200:300] > 0.41] > 0.0)
