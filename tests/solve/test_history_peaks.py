"""Streamed force-vector magnitudes (``integrate(history_peaks=...)``: the bearing
table's peaks) against their readable twin, and independent of the history's sampling."""

from __future__ import annotations

import numpy as np
import pytest
from solve_models import random_structure, spur_pair

from torquesplit.errors import OptionError
from torquesplit.solve import integrate
from torquesplit.solve.reference import (
    contact_regime_numpy,
    element_forces_numpy,
    excitation_numpy,
    history_peaks_numpy,
)

VECTORS = {"a": [("spring1", (1.0, 0.0, 0.0)), ("mesh1", (0.0, 1.0, 0.0))],
           "b": [("mesh0", (0.6, 0.8, 0.0)), ("mesh2", (-1.0, 0.0, 0.5)),
                 ("spring0", (0.0, 0.0, 1.0))],
           "c": [("ground", (-1.0, 0.0, 0.0))],
           # a support's: orthogonal unit directions, no gap (the kernel's own loops)
           "d": [("spring0", (1.0, 0.0, 0.0)), ("ground", (0.0, -1.0, 0.0))],
           "e": [("spring2", (0.0, 0.0, 1.0)), ("spring0", (0.0, 1.0, 0.0)),
                 ("ground", (1.0, 0.0, 0.0))]}


def _twin(s, t, ys, vectors, rows, kinks=None):
    """The twin's peaks from the states ``ys`` at the instants ``t``."""
    names = list(s.element_names)
    mags, codes = [], []
    for ti, yi in zip(t, ys):
        f, d = element_forces_numpy(s, ti, yi)
        reg = contact_regime_numpy(d, excitation_numpy(s, ti).half_gap)
        mags.append([np.linalg.norm(sum(f[names.index(e)] * np.asarray(c) for e, c in terms))
                     for terms in vectors.values()])
        code = []
        for terms in vectors.values():
            k = 0
            for e, _ in terms:
                k = 3 * k + int(reg[names.index(e)]) + 1
            code.append(k)
        codes.append(code)
    return history_peaks_numpy(t, np.array(mags), np.array(codes), rows, kinks), np.array(mags)


def test_streamed_peaks_equal_the_twin_over_every_step():
    """A 5-DOF structure whose meshes and springs open and close their gaps: each row's
    peak equals the twin's from every step's state, the parabola's vertex between steps
    included, and it does reach above the steps' own magnitudes."""
    s = random_structure(4)
    rng = np.random.default_rng(11)
    y0 = np.concatenate([rng.normal(scale=3e-6, size=s.n_dof), np.zeros(s.n_dof)])
    sol = integrate(s, y0, (0.0, 0.004), step=2e-6, full_history=True, record_every=7,
                    history_peaks=VECTORS, corners=False)
    assert sol.success and sol.history_peak_names == ("a", "b", "c", "d", "e")
    rows = np.flatnonzero(np.isin(sol.full_t, sol.history_t))
    assert rows.size == sol.history_t.size > 200
    twin, mags = _twin(s, sol.full_t, sol.full_y, VECTORS, rows)
    np.testing.assert_allclose(sol.history_peaks, twin, rtol=1e-10)
    # the vertex between the steps counts: some rows lie above every step's magnitude
    plain = np.array([mags[: r + 1][np.searchsorted(rows, np.arange(r + 1)) == k].max(axis=0)
                      for k, r in enumerate(rows)])
    assert np.any(twin > plain * (1 + 1e-6))


def test_streamed_peaks_include_the_table_corners():
    """A rectangular stiffness wave: the mesh force jumps at its table's corners, which
    RK4 steps onto; the streamed peak over a span is the largest of the forces at the
    steps and at the corners (the readable RK4 on that grid), never a parabola across a
    jump."""
    from torquesplit.solve.reference import corner_times_numpy, rk4_numpy

    s = spur_pair(damping=100.0, frequency=1000.0, phase=0.37,
                  stiffness=2e8 * (1 + 0.3 * np.sign(np.sin(2 * np.pi * (np.arange(64)
                                                                         + 0.5) / 64))),
                  errors=[(2e-6, 2 * np.pi * 60, 0.0)])
    y0 = np.array([1e-4, -5e-5, 0.0, 0.0])
    h = 1.0 / (97 * 1000.0)
    n_steps = 747
    vectors = {"mesh": [("mesh", (0.0, 1.0, 0.0))]}
    sol = integrate(s, y0, (0.0, n_steps * h), step=h, record_every=10,
                    history_peaks=vectors)
    steps = h * np.arange(n_steps + 1)
    corners = corner_times_numpy(s, 0.0, n_steps * h)
    t, ys = rk4_numpy(s, y0, 0.0, h, n_steps, times=np.union1d(steps, corners))
    rows = np.flatnonzero(np.isin(t, sol.history_t))
    near = np.min(np.abs(t[:, None] - corners[None, :]), axis=1) <= 1e-6 * h
    twin, mags = _twin(s, t, ys, vectors, rows, kinks=near)
    np.testing.assert_allclose(sol.history_peaks, twin, rtol=1e-10)
    # the steps alone miss the corners' forces
    on = np.isin(t, steps)
    assert twin.max() > mags[on].max() * (1 + 1e-9)


def test_largest_streamed_peak_does_not_depend_on_the_sampling():
    """The largest magnitude over a run is the same, to round-off, whether the history
    keeps every step or every 50th (the samples themselves miss it)."""
    s = random_structure(2)
    rng = np.random.default_rng(3)
    y0 = np.concatenate([rng.normal(scale=3e-6, size=s.n_dof), np.zeros(s.n_dof)])
    peaks = []
    for every in (1, 13, 50):
        sol = integrate(s, y0, (0.0, 0.004), step=2e-6, record_every=every,
                        history_peaks=VECTORS)
        peaks.append(sol.history_peaks[1:].max(axis=0))
        if every == 50:
            forces = sol.history_forces
            names = [sol.element_names[i] for i in sol.history_elements]
            sampled = [np.linalg.norm(sum(np.outer(forces[1:, names.index(e)], c)
                                          for e, c in terms), axis=1).max()
                       for terms in VECTORS.values()]
            assert np.all(np.array(sampled) < peaks[-1] * (1 - 1e-6))
    np.testing.assert_allclose(peaks[1], peaks[0], rtol=1e-13)
    np.testing.assert_allclose(peaks[2], peaks[0], rtol=1e-13)


def test_dopri_streams_the_peaks_between_its_samples():
    s = random_structure(4)
    rng = np.random.default_rng(11)
    y0 = np.concatenate([rng.normal(scale=3e-6, size=s.n_dof), np.zeros(s.n_dof)])
    sol = integrate(s, y0, (0.0, 0.004), method="dopri", sample_interval=2e-4,
                    history_peaks=VECTORS)
    assert sol.success and sol.history_peaks.shape == (sol.history_t.size, len(VECTORS))
    # each row holds at least its own sample's magnitude
    names = [sol.element_names[i] for i in sol.history_elements]
    own = np.array([[np.linalg.norm(sum(sol.history_forces[r, names.index(e)] * np.asarray(c)
                                        for e, c in terms)) for terms in VECTORS.values()]
                    for r in range(sol.history_t.size)])
    assert np.all(sol.history_peaks >= own * (1 - 1e-12))
    assert np.any(sol.history_peaks > own * (1 + 1e-6))


@pytest.mark.parametrize("bad", [
    [("spring1", (1.0, 0.0))],  # two components
    [("spring1", (1.0, np.nan, 0.0))],
    [("spring1",)],
    [],
    "spring1",
])
def test_bad_history_peaks_are_refused_by_name(bad):
    s = random_structure(0)
    with pytest.raises(OptionError, match="history_peaks\\['v'\\]"):
        integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-4), step=1e-5,
                  history_peaks={"v": bad})


def test_unknown_element_in_history_peaks_is_named():
    s = random_structure(0)
    with pytest.raises(OptionError, match="springx"):
        integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-4), step=1e-5,
                  history_peaks={"v": [("springx", (1.0, 0.0, 0.0))]})


def test_vertex_bound_is_an_upper_bound_of_the_vertex():
    """The kernel computes a parabola's vertex only where its bound can raise the
    largest value: the bound must hold for any spacing of the three instants."""
    from torquesplit.solve._kernels import vertex, vertex_bound

    rng = np.random.default_rng(5)
    tight = 0.0
    for _ in range(20000):
        h0, h2 = 10.0 ** rng.uniform(-3, 3, 2)
        f0, f2 = rng.uniform(0.0, 1.0, 2)
        f1 = max(f0, f2) + 10.0 ** rng.uniform(-6, 0)
        top = vertex(0.0, h0, h0 + h2, f0, f1, f2)
        bound = vertex_bound(f0, f1, f2, 0.25 * (h2 / h0) ** 2, 0.25 * (h0 / h2) ** 2)
        assert top <= bound * (1 + 1e-12) + 1e-15
        tight = max(tight, (top - f1) / (bound - f1))
    assert tight > 0.5  # (and it is not loose: a parabola comes close to it)
