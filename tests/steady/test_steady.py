"""Periodic steady state: harmonic balance, shooting, Floquet, period, continuation.

Reference values are independent of the code under test: closed-form frequency
responses and eigenvalues, hand-computed speeds, and time integrations by the
project's integrator (``torquesplit.solve.integrate``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from oscillators import backlash_oscillator
from torquesplit.assembly.structure import MESH, SPRING, build_structure
from torquesplit.errors import OptionError
from torquesplit.solve.integrate import integrate
from torquesplit.steady.harmonic import HarmonicBalance
from torquesplit.steady.newton import (
    floquet_hill,
    floquet_monodromy,
    solve_hb,
    solve_shooting,
)
from torquesplit.steady.period import (
    LongPeriodError,
    PeriodError,
    fundamental_period,
    keep_excitations,
)
from torquesplit.steady.problem import PeriodicProblem
from torquesplit.steady.sweep import continue_in_speed, stepped_sweep

M1, M2, K1, K2, C1, C2 = 2.0, 1.0, 1e4, 2e4, 3.0, 1.0
F0 = 7.0
A1, A2 = 1e-3, 3e-4


def _lti():
    om = 2 * math.pi * F0
    return build_structure(["a.x", "b.x"], [1 / M1, 1 / M2], [
        dict(name="k1", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=K1, damping=C1,
             errors=[(A1, om, 0.3)]),
        dict(name="k2", kind=MESH, dofs=[0, 1], coefs=[1.0, -1.0], stiffness=K2, damping=C2,
             frequency=F0, errors=[(A2, 3 * om, 0.0)])],
        external_force=[5.0, -2.0], n_table=8)


def _matrices():
    M = np.diag([M1, M2])
    V1, V2 = np.array([1.0, 0.0]), np.array([1.0, -1.0])
    K = K1 * np.outer(V1, V1) + K2 * np.outer(V2, V2)
    C = C1 * np.outer(V1, V1) + C2 * np.outer(V2, V2)
    return M, K, C, V1, V2


def test_lti_harmonic_balance_equals_the_analytic_frequency_response():
    s = _lti()
    per = fundamental_period(s)
    assert per.frequency == pytest.approx(F0, rel=1e-12) and per.orders == (1, 3)
    p = PeriodicProblem(s, per.frequency)
    hb = HarmonicBalance(p, 4)
    x, info = solve_hb(hb, np.zeros(hb.size))
    assert info.converged
    u, _ = hb.split(x)
    M, K, C, V1, V2 = _matrices()
    q0 = np.linalg.solve(K, [5.0, -2.0])
    assert np.max(np.abs(u[0] - q0)) <= 1e-9 * np.max(np.abs(q0))
    om = 2 * math.pi * F0
    for k, (A, ph, V, kk, cc) in ((1, (A1, 0.3, V1, K1, C1)), (3, (A2, 0.0, V2, K2, C2))):
        w = k * om
        # element force k (V.q - e) + c (V.q' - e'), e = A sin(w t + ph) = Re(E e^{iwt})
        E = -1j * A * np.exp(1j * ph)
        Q = np.linalg.solve(K - w * w * M + 1j * w * C, V * (kk + 1j * w * cc) * E)
        got = u[2 * k - 1] - 1j * u[2 * k]
        assert np.max(np.abs(got - Q)) <= 1e-9 * np.max(np.abs(Q))
    for k in (2, 4):  # nothing excites these harmonics
        assert np.max(np.abs(u[2 * k - 1:2 * k + 1])) <= 1e-12 * np.max(np.abs(q0))


def test_matrix_free_shooting_reaches_the_monodromy_s_state():
    """Newton-Krylov shooting (finite-difference products of the period map, GMRES) and
    Newton with the formed monodromy reach the same periodic state; on this linear case
    GMRES needs at most the 4 state dimensions per Newton step, and a second step removes
    what the differences' rounding left (the formed monodromy needs one)."""
    p = PeriodicProblem(_lti(), F0)
    y0 = np.array([1e-3, -2e-3, 0.1, 0.0])
    y_d, Phi, info_d = solve_shooting(p, y0, 800, krylov=False)
    y_k, none, info_k = solve_shooting(p, y0, 800, krylov=True, anderson=False)
    assert info_d.converged and info_k.converged and none is None and Phi is not None
    assert info_d.iterations == 1 and info_d.products == 0
    assert info_k.iterations <= 2 and 0 < info_k.products <= 4 * info_k.iterations
    assert info_k.anderson == 0
    assert np.max(np.abs(y_k - y_d)) <= 1e-8 * np.max(np.abs(y_d))


def test_anderson_accelerated_shooting_is_gmres_on_a_linear_map():
    """On a linear period map Anderson acceleration with full memory is GMRES (Walker &
    Ni 2011, Theorem 2.2): after the settling map, once its secants span the 4 state
    dimensions the next map lands on the periodic state (the defect falls to rounding at
    once, from above 0.1), with no products.  Each defect map's record is the period from
    the state it started at, and the returned one is the returned state's."""
    p = PeriodicProblem(_lti(), F0)
    y0 = np.array([1e-3, -2e-3, 0.1, 0.0])
    T = 1.0 / F0
    y_d, _, _ = solve_shooting(p, y0, 800, krylov=False)
    kept = [None]

    def record(y):
        kept[0] = p.run(y, 0.0, T, 800, every=100, corners=True, track=[1], out=kept[0])
        return kept[0]

    y_a, none, info = solve_shooting(p, y0, 800, krylov=True, record=record)
    assert info.converged and none is None and info.products == 0
    assert info.anderson == info.iterations <= 1 + 1 + 4 + 1
    assert min(info.history[:-1]) > 0.1 and info.history[-1] <= 1e-12
    assert np.max(np.abs(y_a - y_d)) <= 1e-8 * np.max(np.abs(y_d))
    fresh = p.run(y_a, 0.0, T, 800, every=100, corners=True, track=[1])
    for a, b in zip(info.run, fresh):
        assert np.array_equal(a, b)
    assert np.array_equal(info.run.y[0], y_a)


def test_monodromy_columns_on_threads_are_bit_for_bit_the_serial_ones():
    """The variational equations split into column blocks on threads (each with its own
    copy of the state) give the serial monodromy exactly, and the same end state; the
    default uses one thread below PARALLEL_WORK column-steps."""
    from torquesplit.steady.problem import PARALLEL_WORK, threads_for

    p = PeriodicProblem(_lti(), F0)
    y0 = np.array([1e-3, -2e-3, 0.1, 0.0])
    cols = np.random.default_rng(3).normal(size=(4, 7))
    y1, Phi1 = p.integrate_variational(y0, 0.0, 1.0 / F0, 800, columns=cols, threads=1)
    y3, Phi3 = p.integrate_variational(y0, 0.0, 1.0 / F0, 800, columns=cols, threads=3)
    assert np.array_equal(Phi1, Phi3) and np.array_equal(y1, y3)
    assert not np.allclose(Phi1, cols)  # the map did something
    assert threads_for(PARALLEL_WORK - 1, 98) == 1 and threads_for(10**9, 20) == 1


def test_anderson_hands_over_to_newton_when_it_stalls(monkeypatch):
    """Where the Anderson iteration has not converged within its maps, Newton-Krylov goes
    on from its best state (here after 3 maps, on the linear case that needs 7)."""
    import torquesplit.steady.newton as newton

    monkeypatch.setattr(newton, "ANDERSON_MAPS", 3)
    p = PeriodicProblem(_lti(), F0)
    y0 = np.array([1e-3, -2e-3, 0.1, 0.0])
    y_d, _, _ = solve_shooting(p, y0, 800, krylov=False)
    y_a, _, info = solve_shooting(p, y0, 800, krylov=True)
    assert info.converged and info.anderson == 3 and info.products > 0
    assert info.iterations > info.anderson
    assert np.max(np.abs(y_a - y_d)) <= 1e-8 * np.max(np.abs(y_d))


def test_shooting_and_floquet_of_the_lti_case():
    s = _lti()
    p = PeriodicProblem(s, F0)
    hb = HarmonicBalance(p, 4)
    x, _ = solve_hb(hb, np.zeros(hb.size))
    q, _, _ = hb.waveforms(x)
    y, Phi, info = solve_shooting(p, np.zeros(4), 800)
    assert info.converged
    amp = np.ptp(q, axis=0).max()
    assert np.max(np.abs(y[:2] - q[0])) <= 1e-6 * amp  # RK4, 800 steps per period
    M, K, C, _, _ = _matrices()
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    exact = np.exp(np.linalg.eigvals(A) / F0)
    for got in (floquet_monodromy(p, Phi), floquet_hill(hb, x)):
        assert len(got) == 4
        assert max(np.min(np.abs(got - e)) for e in exact) < 1e-6


def _mathieu(alpha, zeta=0.01):
    """x'' + 2 zeta x' + (1 + alpha cos W t) x = 0.1: the principal instability tongue of
    the Mathieu equation lies around W = 2 (width about alpha at zeta -> 0; Nayfeh &
    Mook, Nonlinear Oscillations, 1979, section 5.4)."""
    return backlash_oscillator(zeta=zeta, f_alt=0.0, alpha=alpha, half_gap=0.0)


@pytest.mark.parametrize("speed, unstable", [(2.0, True), (1.3, False), (2.6, False)])
def test_parametric_instability_tongue(speed, unstable):
    s = _mathieu(0.3)
    per = fundamental_period(s)
    p = PeriodicProblem(s, per.frequency)
    hb = HarmonicBalance(p, 12)
    x0 = np.zeros(hb.size)
    x0[0] = 0.1
    x, info = solve_hb(hb, x0, speed)
    assert info.converged
    hill = floquet_hill(hb, x, speed)
    _, Phi = p.integrate_variational(np.concatenate([hb.waveforms(x, speed)[0][0],
                                                     hb.waveforms(x, speed)[1][0]]),
                                     0.0, 1 / (per.frequency * speed), 2000, speed)
    mono = floquet_monodromy(p, Phi)
    assert (abs(mono[0]) > 1) == unstable
    assert (abs(hill[0]) > 1) == unstable
    assert abs(abs(hill[0]) - abs(mono[0])) < 1e-4
    if unstable:  # the principal tongue: a real multiplier through -1 (period doubling)
        assert mono[0].real < -1 and abs(mono[0].imag) < 1e-9


def test_period_of_tooth_counts_long_periods_and_impossible_ones():
    f1 = 235.0 + 11 / 12  # 168 and 17 cycles of f0 = f1 / 168
    f2 = f1 * 17 / 168
    el = [dict(name="a", kind=MESH, dofs=[0], coefs=[1.0], stiffness=[1.0, 2.0], frequency=f1),
          dict(name="b", kind=MESH, dofs=[0], coefs=[1.0], stiffness=[1.0, 3.0], frequency=f2)]
    s = build_structure(["x"], [1.0], el, n_table=4)
    per = fundamental_period(s)
    assert per.frequency == pytest.approx(f1 / 168, rel=1e-12)
    assert sorted(per.orders) == [17, 168]
    with pytest.raises(LongPeriodError, match="keep="):
        fundamental_period(s, max_cycles=100)
    kept, dropped = keep_excitations(s, f1)
    assert [d.element for d in dropped] == ["b"]
    assert fundamental_period(kept).frequency == pytest.approx(f1)
    assert np.ptp(kept.stiffness_table[1]) == 0 and kept.stiffness_table[1, 0] == 2.0
    el[1]["frequency"] = f1 / 1000000.5  # no ratio with a denominator up to 1e6
    with pytest.raises(PeriodError, match="no rational ratio"):
        fundamental_period(build_structure(["x"], [1.0], el, n_table=4))


def continuation_multipliers(hb, point):
    return floquet_hill(hb, point.x, point.speed, hb.H)


def _contact_loss_onset(zeta, f_mean, f_alt):
    """Speed where the linear (always in contact) response first reaches the backlash:
    amplitude F_a W^2 / |1 - W^2 + 2 i zeta W| = F_m (the mean deflection beyond the gap)
    (Kahraman & Singh 1990: the single-sided impact region begins there)."""
    from scipy.optimize import brentq

    def g(w):
        return f_alt * w * w / abs(1 - w * w + 2j * zeta * w) - f_mean
    return brentq(g, 0.3, 0.999)


def test_backlash_benchmark_jump_impacts_and_time_integration():
    zeta, fm, fa = 0.05, 0.1, 0.05
    s = backlash_oscillator(zeta, fm, fa)
    per = fundamental_period(s)
    p = PeriodicProblem(s, per.frequency)
    hb, pts, folds, msg, complete, _ = continue_in_speed(p, per, np.array([1.1]), 0.5, 1.5,
                                                          points=60, harmonics=16)
    assert complete, msg
    sp = np.array([q.speed for q in pts])
    # softening: the branch turns back (jump down when sweeping up) and on again
    kinds = [k for _, k in folds]
    assert "turns back" in kinds and "turns on" in kinds
    up = max(f for f, k in folds if k == "turns back")
    down = min(f for f, k in folds if k == "turns on")
    assert 0.7 < down < up < 1.0
    # multipliers cross +1 at the turning points: stable on the outer branches,
    # unstable between; the largest multiplier next to a fold is close to +1
    stab = np.array([q.stable for q in pts])
    assert stab[0] and stab[-1] and not stab.all()
    changes = int(np.sum(stab[1:] != stab[:-1]))
    assert changes == len(folds)  # stability changes exactly at the turning points
    i = int(np.flatnonzero(~stab)[0])  # first unstable point: a real multiplier beyond +1
    mu = continuation_multipliers(hb, pts[i])
    assert mu[0].real > 1 and abs(mu[0].imag) < 1e-6
    # single-sided impacts begin where the linear response reaches the gap (hand formula)
    w_c = _contact_loss_onset(zeta, fm, fa)
    lost = []
    for q in pts[:20]:
        d = hb.residual_samples(q.x, q.speed)[3][:, 0]
        lost.append(d.min() < 1.0 - 1e-9)
    first = sp[:20][np.argmax(lost)]
    assert abs(first - w_c) < 0.03
    # run-up / run-down time integrations land on the lower / upper branch in between
    w_mid = 0.5 * (up + down)
    grid = np.array([0.6, 0.7, w_mid])
    peaks_up, _ = stepped_sweep(p, per, np.array([1.1]), grid, settle_periods=150,
                                steps_per_cycle=400, track=[0])
    peaks_dn, _ = stepped_sweep(p, per, np.array([1.1]), np.array([1.0, 0.9, w_mid]),
                                settle_periods=150, steps_per_cycle=400, track=[0])
    near = [q for q in pts if abs(q.speed - w_mid) < 0.02]
    peaks_hb = sorted(hb.residual_samples(q.x, q.speed)[2][:, 0].max() for q in near
                      if q.stable)
    assert len(peaks_hb) >= 2
    assert peaks_up[-1, 0] == pytest.approx(peaks_hb[0], rel=0.03)
    assert peaks_dn[-1, 0] == pytest.approx(peaks_hb[-1], rel=0.03)
    assert peaks_dn[-1, 0] > 1.5 * peaks_up[-1, 0]


def test_shooting_continuation_finds_the_backlash_jumps_of_harmonic_balance():
    """The same softening branch followed by shooting continuation: turning points at the
    speeds harmonic balance finds (its 64 harmonics converged to ~1e-3 there), stable
    outer branches and an unstable middle one (a real multiplier beyond +1), and the
    peaks of the two methods equal on both stable branches between the jumps.  (Where
    contact is just lost the period map is only piecewise smooth and the multiplier
    hovers about 1 near the lower turning point: the stability flag is not required to
    change exactly there.)"""
    from torquesplit.steady.sweep import continue_in_speed_shooting, shooting_point_metrics

    s = backlash_oscillator(0.05, 0.1, 0.05)
    per = fundamental_period(s)
    p = PeriodicProblem(s, per.frequency)
    q0 = np.array([1.1])
    hb, hpts, hfolds, msg, complete, _ = continue_in_speed(p, per, q0, 0.5, 1.5, points=60,
                                                           harmonics=64)
    assert complete, msg
    cont, pts, folds, msg, complete, _ = continue_in_speed_shooting(p, per, q0, 0.5, 1.5,
                                                                    points=60)
    assert complete, msg
    assert [k for _, k in folds] == [k for _, k in hfolds]
    for (f, _), (g, _) in zip(folds, hfolds, strict=True):
        assert f == pytest.approx(g, abs=2e-3)
    # every point is a periodic state: one period integrated from it (the same steps),
    # independently of the continuation's own equations, returns to it
    for q in pts[::10]:
        y = cont.state(q.x)
        T = 1.0 / (per.frequency * q.speed)
        yT = p.integrate(y, 0.0, T, cont.steps, every=cont.steps, speed=q.speed,
                         max_rows=1)[3]
        assert np.max(np.abs(yT - y)) <= 1e-7 * np.max(np.abs(y))
    stab = np.array([q.stable for q in pts])
    assert stab[0] and stab[-1]
    worst = max(pts, key=lambda q: q.max_multiplier)
    assert not worst.stable and folds[1][0] < worst.speed < folds[0][0]
    mu = cont.multipliers(worst.x, worst.speed)
    assert mu[0].real > 1 and abs(mu[0].imag) < 1e-6
    w_mid = 0.5 * (folds[0][0] + folds[1][0])

    def both_branches(points, solve, peak):
        """Peak force at w_mid on the lower and the upper stable branch, each solved
        from the branch's stable point nearest to w_mid."""
        near = [q for q in points if q.stable and abs(q.speed - w_mid) < 0.05]
        out = sorted(peak(solve(q.x, w_mid), w_mid) for q in near)
        return out[0], out[-1]

    sh = both_branches(pts, lambda x, w: cont.solve(x, w)[0],
                       lambda x, w: shooting_point_metrics(
                           cont, x, w, [0], [], np.ones(1), np.ones(1))["peak_force"][0])
    ref = both_branches(hpts, lambda x, w: solve_hb(hb, x, w)[0],
                        lambda x, w: hb.residual_samples(x, w)[2][:, 0].max())
    assert sh[1] > 1.5 * sh[0]
    np.testing.assert_allclose(sh, ref, rtol=5e-3)


def test_hb_and_shooting_agree_with_long_time_integration_on_a_geared_model():
    """Two meshes with stepped stiffness and backlash never opened, 3 DOFs."""
    f = 50.0
    tab = np.where(np.arange(64) < 40, 1.1e6, 0.9e6)
    s = build_structure(["a", "b", "c"], [1 / 0.02, 1 / 0.05, 1 / 0.03], [
        dict(name="m1", kind=MESH, dofs=[0, 1], coefs=[1.0, -1.0], stiffness=tab,
             frequency=f, damping=15.0, gaps=1e-3),
        dict(name="m2", kind=MESH, dofs=[1, 2], coefs=[1.0, -1.0], stiffness=tab[::-1],
             frequency=f, phase=0.3, damping=15.0),
        dict(name="g", kind=SPRING, dofs=[2], coefs=[1.0], stiffness=3e5, damping=20.0)],
        external_force=[200.0, 0.0, 0.0], n_table=64)
    per = fundamental_period(s)
    p = PeriodicProblem(s, per.frequency)
    from torquesplit.steady.solution import periodic_solution
    from torquesplit.solve.static import static_equilibrium

    qs = static_equilibrium(s).q
    hb = periodic_solution(s, per, harmonics=256, q_static=qs, steps_per_cycle=2048)
    sh = periodic_solution(s, per, method="shooting", q_static=qs, steps_per_cycle=2048)
    assert hb.converged and sh.converged and hb.stable and sh.stable
    T = 1 / f
    a = integrate(s, np.concatenate([qs, 0 * qs]), (0, 60 * T), step=T / 2048,
                  history_elements=(), history_dofs=())
    b = integrate(s, a.y_final, (60 * T, 61 * T), step=T / 2048, history_elements=[0, 1],
                  history_dofs=())
    t = b.history_t - 60 * T
    for e in (0, 1):
        ref = b.history_forces[:, e]
        amp = np.ptp(ref)
        assert np.max(np.abs(np.interp(t, sh.t, sh.forces[:, e], period=T) - ref)) < 1e-3 * amp
        from torquesplit.steady.harmonic import HarmonicBalance as HB
        hb2 = HB(p, 256, 2048)
        from torquesplit.steady.solution import pad_coefficients
        F = hb2.residual_samples(pad_coefficients(hb.coefficients, hb2))[2][:, e]
        assert np.max(np.abs(F - ref[:-1])) < 1e-3 * amp


def test_continuation_failure_keeps_the_partial_curve(monkeypatch):
    from torquesplit.steady import sweep as sw

    s = backlash_oscillator()
    per = fundamental_period(s)
    p = PeriodicProblem(s, per.frequency)
    calls = {"n": 0}
    orig = sw.Continuation.correct

    def flaky(self, z_pred, t, max_iter=10):
        calls["n"] += 1
        if calls["n"] > 5:
            return None, max_iter
        return orig(self, z_pred, t, max_iter)

    monkeypatch.setattr(sw.Continuation, "correct", flaky)
    hb, pts, folds, msg, complete, _ = continue_in_speed(p, per, np.array([1.1]), 0.5, 1.5,
                                                          points=20, harmonics=8,
                                                          stability=False)
    assert not complete and 3 <= len(pts) <= 6
    assert "continuation failed at speed factor" in msg and "kept" in msg
    assert "--method shooting" in msg
    with pytest.raises(OptionError, match="two different positive speeds"):
        continue_in_speed(p, per, np.array([1.1]), -1.0, 1.5)
    # the same for the shooting continuation: partial curve, its own remedy
    from torquesplit.steady.sweep import continue_in_speed_shooting

    calls["n"] = 0
    orig_sh = sw.ShootingContinuation.correct

    def flaky_sh(self, z_pred, t, max_iter=12):
        calls["n"] += 1
        if calls["n"] > 5:
            return None, max_iter
        return orig_sh(self, z_pred, t, max_iter)

    monkeypatch.setattr(sw.ShootingContinuation, "correct", flaky_sh)
    _, pts, _, msg, complete, _ = continue_in_speed_shooting(
        p, per, np.array([1.1]), 0.5, 1.5, points=20, stability=False)
    assert not complete and 3 <= len(pts) <= 6
    assert "kept" in msg and "--method hb" in msg
    with pytest.raises(OptionError, match="two different positive speeds"):
        continue_in_speed_shooting(p, per, np.array([1.1]), 1.5, 1.5)


def test_cycle_extremes_equal_a_scatter_over_the_samples():
    """The per-cycle max / min of a Results record from a periodic state are reductions
    over runs of equal cycle index; against np.maximum.at / np.minimum.at over every
    sample, NaN samples (a group carrying no load) and instants between them included."""
    from torquesplit.steady.api import cycle_extremes

    rng = np.random.default_rng(5)
    cyc = np.sort(rng.integers(0, 40, 3000))
    cyc[cyc == 7] = 8  # a cycle without samples
    v = rng.normal(size=cyc.size)
    v[rng.random(cyc.size) < 0.2] = np.nan
    v[cyc == 11] = np.nan  # a cycle with only NaN samples
    ec = rng.integers(0, 42, 50)
    ev = rng.normal(scale=3.0, size=50)
    ev[:5] = np.nan
    mx, mn = cycle_extremes(v, cyc, 42, ec, ev)
    rx, rn = np.full(42, -np.inf), np.full(42, np.inf)
    for c, x in ((cyc, v), (ec, ev)):
        ok = ~np.isnan(x)
        np.maximum.at(rx, c[ok], x[ok])
        np.minimum.at(rn, c[ok], x[ok])
    np.testing.assert_array_equal(mx, rx)
    np.testing.assert_array_equal(mn, rn)
