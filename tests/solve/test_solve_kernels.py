"""Compiled kernels against their readable numpy twins (solve/reference.py)."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest
from solve_models import (
    J1,
    J2,
    K_MESH,
    R1,
    R2,
    pair_frequency,
    random_structure,
    spur_pair,
)

from torquesplit.assembly.structure import MESH, SPRING, build_structure
from torquesplit.solve import element_forces, integrate, rhs
from torquesplit.solve.reference import (
    contact_state_numpy,
    contact_times_numpy,
    cycle_statistics_numpy,
    dopri_numpy,
    element_forces_numpy,
    excitation_numpy,
    hermite_numpy,
    rhs_numpy,
    rk4_numpy,
)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kernel_rhs_equals_numpy_twin(seed):
    s = random_structure(seed)
    rng = np.random.default_rng(100 + seed)
    n = s.n_dof
    branches = set()
    for t in [0.0, 1.234e-3, 0.0371, 2.5, 17.3]:
        for _ in range(20):
            y = np.concatenate([rng.normal(scale=2e-6, size=n), rng.normal(scale=1e-3, size=n)])
            dy_k = rhs(s, t, y)
            dy_n = rhs_numpy(s, t, y)
            np.testing.assert_array_equal(dy_k[:n], dy_n[:n])
            scale = np.max(np.abs(dy_n[n:]))
            assert np.max(np.abs(dy_k[n:] - dy_n[n:])) <= 1e-12 * scale
            f_k, d_k = element_forces(s, t, y)
            f_n, d_n = element_forces_numpy(s, t, y)
            np.testing.assert_allclose(d_k, d_n, rtol=0, atol=1e-12 * np.max(np.abs(d_n)))
            np.testing.assert_allclose(f_k, f_n, rtol=0, atol=1e-12 * np.max(np.abs(f_n)))
            g = excitation_numpy(s, t).half_gap
            branches.update(np.sign(np.where(g > 0, np.where(np.abs(d_n) <= g, 0,
                                                              np.sign(d_n) * 2), 3)).tolist())
    assert {-1.0, 0.0, 1.0} <= branches  # back contact, separation, front contact seen


def test_excitation_tables_are_periodic_and_interpolated():
    s = random_structure(0)
    e = 1  # mesh1: three-entry half-gap sequence
    f = s.frequency[e]
    ex0 = excitation_numpy(s, 0.0)
    ex3 = excitation_numpy(s, 3.0 / f)  # three cycles later: same table phase, same gap
    assert ex0.stiffness[e] == pytest.approx(ex3.stiffness[e], rel=1e-12)
    assert ex0.half_gap[e] == ex3.half_gap[e]
    ex1 = excitation_numpy(s, 1.0 / f)
    assert ex1.cycle[e] == ex0.cycle[e] + 1
    assert ex1.half_gap[e] == s.gap_values[s.gap_ptr[e] + (ex1.cycle[e] % 3)]
    # exactly at a table node the value is the table entry
    n_tab = s.n_table
    t_node = ((5 / n_tab) - s.phase[e]) / f + 2 / f
    assert excitation_numpy(s, t_node).stiffness[e] == pytest.approx(
        s.stiffness_table[e, 5], rel=1e-9)


def test_rk4_kernel_matches_readable_rk4():
    s = random_structure(3)
    rng = np.random.default_rng(7)
    y0 = np.concatenate([rng.normal(scale=1e-6, size=s.n_dof), np.zeros(s.n_dof)])
    h = 2e-6
    n_steps = 300
    _, ys = rk4_numpy(s, y0, 0.0, h, n_steps)
    sol = integrate(s, y0, (0.0, n_steps * h), step=h, full_history=True, corners=False)
    assert sol.n_steps == n_steps
    scale = np.max(np.abs(ys), axis=0)
    assert np.all(np.abs(sol.full_y - ys) <= 1e-10 * scale + 1e-300)


def test_rk4_steps_through_table_corners_like_the_readable_rk4_on_that_grid():
    """With corners (default) the kernel's steps end on every table corner inside a
    step: the same as the readable RK4 on the step grid with the corner times inserted."""
    from torquesplit.solve.reference import corner_times_numpy

    s = random_structure(3)
    rng = np.random.default_rng(7)
    y0 = np.concatenate([rng.normal(scale=1e-6, size=s.n_dof), np.zeros(s.n_dof)])
    h, n_steps = 2e-6, 300
    steps = h * np.arange(n_steps + 1)
    corners = corner_times_numpy(s, 0.0, n_steps * h)
    assert corners.size > 20
    # a corner within 1e-6 h of a step time is taken as on it (as the kernel does)
    near = np.min(np.abs(corners[:, None] - steps[None, :]), axis=1) <= 1e-6 * h
    grid = np.union1d(steps, corners[~near])
    t, ys = rk4_numpy(s, y0, 0.0, h, n_steps, times=grid)
    sol = integrate(s, y0, (0.0, n_steps * h), step=h, full_history=True)
    assert sol.n_steps == n_steps and sol.n_rhs > 4 * n_steps
    on_steps = np.isin(t, steps)
    scale = np.max(np.abs(ys), axis=0)
    assert np.all(np.abs(sol.full_y - ys[on_steps]) <= 1e-10 * scale + 1e-300)
    plain = integrate(s, y0, (0.0, n_steps * h), step=h, corners=False)
    assert not np.allclose(plain.y_final, sol.y_final, rtol=1e-10, atol=0)


def test_dopri_kernel_matches_readable_dopri():
    # smooth problem: with tabulated (piecewise-linear) stiffness the accept / reject
    # decisions hinge on round-off at the table kinks and the step sequences drift apart
    s = spur_pair(damping=200.0, errors=[(1e-6, 2 * np.pi * 900, 0.3),
                                         (3e-7, 2 * np.pi * 1700, 1.0)])
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])
    atol = np.array([1e-12, 1e-12, 1e-8, 1e-8])
    sol = integrate(s, y0, (0.0, 0.01), method="dopri", rtol=1e-7, atol=atol,
                    max_step=1e-4, full_history=True, history_elements=(), history_dofs=())
    h0 = _first_step(s, y0, 1e-7, atol, 0.01)
    t_ref, y_ref, n_rej = dopri_numpy(s, y0, (0.0, 0.01), rtol=1e-7, atol=atol, h0=h0,
                                      h_max=1e-4)
    assert sol.n_steps == len(t_ref) - 1
    assert sol.n_rejected == n_rej
    np.testing.assert_allclose(sol.y_final, y_ref[-1], rtol=1e-9,
                               atol=1e-9 * np.abs(y_ref).max(axis=0).max())


def _first_step(s, y0, rtol, atol, span):
    """The starting step integrate() uses (the twin must start from the same one)."""
    mod = importlib.import_module("torquesplit.solve.integrate")  # module, not function
    return min(mod._initial_step(s, y0, 0.0, span, rtol, atol, None), 1e-4)


def test_hermite_reproduces_cubic():
    # a cubic polynomial is reproduced exactly from values and slopes at both ends
    p = np.poly1d([2.0, -1.0, 0.5, 3.0])
    dp = p.deriv()
    t0, h = 0.3, 0.7
    for theta in [0.0, 0.25, 0.5, 0.9, 1.0]:
        val = hermite_numpy(theta, h, p(t0), dp(t0), p(t0 + h), dp(t0 + h))
        assert val == pytest.approx(p(t0 + theta * h), rel=1e-13)


def test_streaming_cycle_statistics_equal_post_processed_history():
    # more steps than one chunk, so the statistics must continue across chunks; a smooth
    # stiffness (no corner events: every statistic comes from the step samples)
    from torquesplit.solve.kernel_data import corner_nodes

    s = spur_pair(damping=100.0, frequency=1000.0, phase=0.37, n_table=256,
                  stiffness=2e8 * (1 + 0.3 * np.sin(2 * np.pi * np.arange(256) / 256)),
                  errors=[(2e-6, 2 * np.pi * 60, 0.0)])
    assert corner_nodes(s.stiffness_table[0]).size == 0
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])
    sol = integrate(s, y0, (0.0, 0.0377), steps_per_period=97)
    assert sol.success and sol.n_steps > 3000
    cmax, cmin, cmean, ccnt = cycle_statistics_numpy(
        sol.history_t, sol.history_forces[:, 0], 1000.0, 0.37, 0.0, 100,
        continuous_start=True)
    n = sol.cycle_max.shape[0]
    np.testing.assert_array_equal(sol.cycle_count[:, 0], ccnt[:n])
    np.testing.assert_array_equal(sol.cycle_max[:, 0], cmax[:n])
    np.testing.assert_array_equal(sol.cycle_min[:, 0], cmin[:n])
    np.testing.assert_allclose(sol.cycle_mean[:, 0], cmean[:n], rtol=1e-13)
    assert ccnt[n:].sum() == 0
    # cycle start times: the mesh phase is an integer there
    starts = sol.cycle_start[1:, 0]
    np.testing.assert_allclose((1000.0 * starts + 0.37) % 1.0, 0.0, atol=1e-9)
    assert sol.n_samples == sol.n_steps + 1 == len(sol.history_t)


def _rectangular_pair():
    """A spur pair with a rectangular stiffness wave (ramps of one table node): its
    force has corners at the four ramp ends of every mesh cycle."""
    return spur_pair(damping=100.0, frequency=1000.0, phase=0.37,
                     stiffness=2e8 * (1 + 0.3 * np.sign(np.sin(2 * np.pi * (np.arange(64)
                                                                         + 0.5) / 64))),
                     errors=[(2e-6, 2 * np.pi * 60, 0.0)])


def test_cycle_extremes_include_the_forces_at_the_table_corners():
    """Cycle max / min = those of the forces at the step times and at every corner time,
    from the readable RK4 on the grid with the corners inserted."""
    from torquesplit.solve.reference import corner_times_numpy

    s = _rectangular_pair()
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])
    h = 1.0 / (97 * 1000.0)
    n_steps = 747
    sol = integrate(s, y0, (0.0, n_steps * h), step=h)
    steps = h * np.arange(n_steps + 1)
    corners = corner_times_numpy(s, 0.0, n_steps * h)
    near = np.min(np.abs(corners[:, None] - steps[None, :]), axis=1) <= 1e-6 * h
    t, ys = rk4_numpy(s, y0, 0.0, h, n_steps, times=np.union1d(steps, corners[~near]))
    forces = np.array([element_forces_numpy(s, ti, yi)[0][0] for ti, yi in zip(t, ys)])
    on = np.isin(t, steps)
    cmax, cmin, cmean, ccnt = cycle_statistics_numpy(t, forces, 1000.0, 0.37, 0.0, 100,
                                                     counted=on, corners=corners)
    n = sol.cycle_max.shape[0]
    np.testing.assert_allclose(sol.cycle_max[:, 0], cmax[:n], rtol=1e-10)
    np.testing.assert_allclose(sol.cycle_min[:, 0], cmin[:n], rtol=1e-10)
    # the means integrate over the corners too (trapezoid rule), the counts are the steps'
    np.testing.assert_allclose(sol.cycle_mean[:, 0], cmean[:n], rtol=1e-10)
    np.testing.assert_array_equal(sol.cycle_count[:, 0], ccnt[:n])
    # the step samples alone miss the corners
    smax, _, smean, _ = cycle_statistics_numpy(t[on], forces[on], 1000.0, 0.37, 0.0, 100)
    assert np.any(cmax[:n] > smax[:n] * (1 + 1e-9))
    assert np.nanmax(np.abs(smean[1:n - 1] / cmean[1:n - 1] - 1)) > 1e-6


def test_peak_force_with_corners_converges_with_the_step():
    """The largest force of the rectangular-stiffness pair moves by less than 1e-4 of
    itself when the step is halved from 200 steps per mesh period on (what remains is
    RK4's error across the table's corners, first order in h once a corner falls inside
    a step)."""
    s = _rectangular_pair()
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])

    def peak(spp):
        sol = integrate(s, y0, (0.0, 0.02), steps_per_period=spp)
        return np.nanmax(sol.cycle_max[5:15, 0])

    peaks = [peak(spp) for spp in (200, 400, 800)]
    assert np.max(np.abs(np.diff(peaks))) < 1e-4 * peaks[-1]


def test_contact_counters_equal_twin_over_the_full_history():
    s = random_structure(4)
    rng = np.random.default_rng(11)
    y0 = np.concatenate([rng.normal(scale=3e-6, size=s.n_dof), np.zeros(s.n_dof)])
    sol = integrate(s, y0, (0.0, 0.004), step=2e-6, full_history=True)
    assert sol.success
    sep = np.zeros(s.n_elements, dtype=int)
    back = np.zeros(s.n_elements, dtype=int)
    for t, y in zip(sol.full_t, sol.full_y, strict=True):
        a, b = contact_state_numpy(s, t, y)
        sep += a
        back += b
    np.testing.assert_array_equal(sol.separation_steps, sep)
    np.testing.assert_array_equal(sol.back_contact_steps, back)
    assert sep.sum() > 0 and back.sum() > 0
    # the times: split where delta + g or delta - g changes sign between two steps
    sep_t, back_t = contact_times_numpy(s, sol.full_t, sol.full_y)
    np.testing.assert_allclose(sol.separation_time, sep_t, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(sol.back_contact_time, back_t, rtol=1e-12, atol=1e-18)
    steps = (sep + back) * sol.step  # (whole steps: they differ)
    assert np.max(np.abs(sol.separation_time + sol.back_contact_time - steps)) > 0.1 * sol.step


@pytest.mark.parametrize("kind, gaps", [(MESH, [0.0, 10e-6]), (SPRING, [10e-6, 0.0])])
def test_contact_times_equal_twin_where_the_clearance_comes_and_goes(kind, gaps):
    """Per-cycle gaps that mix 0 and > 0 (a reviewer's case): a clearance element in a
    cycle without clearance has no contact state; the kernel kept its last gapped
    sample and split the next interval from it (0.13 % off), the twin took the gaps at
    the first instant for the whole run."""
    el = dict(name="e", kind=kind, dofs=[0, 1], coefs=[R1, -R2], stiffness=K_MESH,
              damping=50.0, gaps=gaps, frequency=1000.0,
              errors=[(40e-6, 2 * math.pi * pair_frequency(), 0.0)])
    s = build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [el],
                        external_force=[20.0, -20.0 * R2 / R1], n_table=64)
    sol = integrate(s, np.zeros(4), (0.0, 0.01), step=2e-6, full_history=True)
    sep_t, back_t = contact_times_numpy(s, sol.full_t, sol.full_y)
    assert sol.separation_time[0] > 1e-5 and sol.back_contact_time[0] > 1e-3
    np.testing.assert_allclose(sol.separation_time, sep_t, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(sol.back_contact_time, back_t, rtol=1e-12, atol=1e-18)


def test_cycle_means_converge_with_the_step_through_the_corners():
    """The rectangular-stiffness pair's force jumps within a table interval at every ramp:
    its cycle means by the trapezoid rule over the steps and the corners, split at the
    cycle starts, move by < 5e-5 of themselves from 200 to 800 steps per mesh period
    (what is left is RK4's own error across the corners; the plain mean of the step
    samples moved by 1.3e-4 and more: first order)."""
    s = _rectangular_pair()
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])

    def means(spp):
        return integrate(s, y0, (0.0, 0.02), steps_per_period=spp).cycle_mean[5:15, 0]

    coarse, fine = means(200), means(800)
    assert np.max(np.abs(coarse / fine - 1)) < 5e-5


def test_peaks_between_the_steps_are_found():
    """A smooth stiffness wave (no corners): a force peak between two RK4 steps is missed
    by the step samples by up to (omega h)^2 / 8 of the oscillation; the vertex of the
    parabola through the three samples around it finds it.  At 100 steps per mesh period
    the peak is within 3e-5 of 3200 steps' (the samples: 2e-4 low) and the trough within
    5e-4 (the samples: 8e-3)."""
    s = spur_pair(damping=100.0, frequency=1000.0, phase=0.37, n_table=256,
                  stiffness=2e8 * (1 + 0.3 * np.sin(2 * np.pi * np.arange(256) / 256)),
                  errors=[(2e-6, 2 * np.pi * 60, 0.0)])
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])
    ref = integrate(s, y0, (0.0, 0.02), steps_per_period=3200)
    sol = integrate(s, y0, (0.0, 0.02), steps_per_period=100, record_every=1)
    top, low = np.nanmax(ref.cycle_max[5:15, 0]), np.nanmin(ref.cycle_min[5:15, 0])
    assert abs(np.nanmax(sol.cycle_max[5:15, 0]) / top - 1) < 3e-5
    assert abs(np.nanmin(sol.cycle_min[5:15, 0]) / low - 1) < 5e-4
    t, f = sol.history_t, sol.history_forces[:, 0]
    inside = (t >= sol.cycle_start[5, 0]) & (t < sol.cycle_start[15, 0])
    assert f[inside].max() < top * (1 - 1e-4)  # what the samples alone give


def test_cycle_extremes_at_cycle_starts_converge_with_the_step():
    """A constant-stiffness pair under a slow 60 Hz error: the force rises or falls through
    most 1 kHz cycle starts, which fall between the steps (phase 0.37).  With the force
    interpolated at each start entered in both cycles, the per-cycle peaks move ~100x
    less from 97 to 388 steps per cycle than from the step samples alone (first order)."""
    from torquesplit.solve import static_equilibrium

    s = spur_pair(damping=2000.0, frequency=1000.0, phase=0.37, n_table=256,
                  stiffness=np.full(256, 2e8), errors=[(20e-6, 2 * np.pi * 60, 0.0)])
    y0 = static_equilibrium(s).y0  # (no free vibration: the error sets the force)

    def peaks(spp):
        sol = integrate(s, y0, (0.0, 0.03), steps_per_period=spp, record_every=1)
        plain = cycle_statistics_numpy(sol.history_t, sol.history_forces[:, 0], 1000.0,
                                       0.37, 0.0, 40)[0]
        return sol.cycle_max[5:25, 0], plain[5:25]

    (coarse, coarse_plain), (fine, fine_plain) = peaks(97), peaks(388)
    moved = np.max(np.abs(coarse - fine)) / np.max(fine)
    moved_plain = np.max(np.abs(coarse_plain - fine_plain)) / np.max(fine)
    assert moved_plain > 1e-5 and moved < moved_plain / 30, (moved, moved_plain)


@pytest.mark.parametrize("method", ["rk4", "dopri"])
def test_constant_tables_take_the_short_excitation_path_with_the_same_results(
        method, monkeypatch):
    """Time-varying elements whose stiffness and force tables are constant come last in
    the kernel model (``tv_tab[0]`` counts the others) and the excitation only updates
    their cycle index and half-gap: every output must equal the run that interpolates
    them too (a constant table, a constant non-zero force, and a per-cycle half-gap
    sequence on a constant table, beside varying tables)."""
    import dataclasses

    from torquesplit.solve import kernel_data as kd

    s = random_structure(3)
    ktab, ftab = s.stiffness_table.copy(), s.force_table.copy()
    ktab[1] = ktab[1, 0]  # mesh1: three-entry half-gap sequence
    ktab[2] = 2e8
    ftab[2] = 20.0
    s = dataclasses.replace(s, stiffness_table=ktab, force_table=ftab)
    m = kd.kernel_model(s)
    assert m.tv_tab[0] == 2 and set(m.tv_el[:2]) == {0, 3} and set(m.tv_el[2:]) == {1, 2}
    rng = np.random.default_rng(7)
    y0 = np.concatenate([rng.normal(scale=1e-6, size=s.n_dof), np.zeros(s.n_dof)])
    kw = dict(method=method, full_history=True)
    kw.update(step=2e-6) if method == "rk4" else kw.update(rtol=1e-8)
    short = integrate(s, y0, (0.0, 6e-3), **kw)
    real = kd.kernel_model
    monkeypatch.setattr(kd, "kernel_model", lambda st: real(st)._replace(
        tv_tab=np.array([len(real(st).tv_el)], dtype=np.int64)))
    full = integrate(s, y0, (0.0, 6e-3), **kw)
    assert short.n_steps == full.n_steps > 100 and np.all(short.cycle_count[:3] > 0)
    for name in ("y_final", "full_y", "cycle_max", "cycle_min", "cycle_mean", "cycle_count",
                 "separation_time", "back_contact_time", "history_forces"):
        a, b = getattr(short, name), getattr(full, name)
        assert np.array_equal(a, b, equal_nan=True), name
