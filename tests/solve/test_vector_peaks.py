"""Force vectors' peaks taken at every instant (``integrate``'s ``history_peaks``): the
compiled reduction against its numpy twin, chunk by chunk; the kernels' dense record
against the every-step history; bad input; a dense record that overflows."""

from __future__ import annotations

import importlib
import warnings

import numpy as np
import pytest

import torquesplit
from torquesplit.errors import OptionError, OptionTypeError
from torquesplit.solve.integrate import integrate
from torquesplit.solve.vector_peaks import VectorPeaks, enter_dense, vector_peaks_numpy


def _vectors(rng):
    """Two supports (x, y; x, y, z) and two vectors along lines of action."""
    return {"a": [(0, (1.0, 0.0, 0.0)), (1, (0.0, 1.0, 0.0))],
            "b": [(2, (1.0, 0.0, 0.0)), (3, (0.0, -1.0, 0.0)), (4, (0.0, 0.0, 1.0))],
            "c": [(1, rng.normal(size=3)), (5, rng.normal(size=3))],
            "d": [(6, rng.normal(size=3))]}


def _squared(forces, vectors):
    """The squared magnitudes the kernels write, in numpy."""
    return np.stack([(sum(forces[:, e][:, None] * np.asarray(d)[None, :]
                          for e, d in terms) ** 2).sum(axis=1)
                     for terms in vectors.values()], axis=1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_compiled_reduction_equals_its_twin_chunk_by_chunk(seed):
    rng = np.random.default_rng(seed)
    n, n_rows, dt = 400, 60, 0.07
    t = np.cumsum(rng.uniform(0.005, 0.03, n))  # uneven instants (corners between steps)
    kink = (rng.random(n) < 0.1).astype(float)
    # smooth oscillations (extrema between instants) and a plateau (equal neighbours)
    forces = np.sin(t[:, None] * rng.uniform(20, 60, 7) + rng.uniform(0, 6, 7))
    forces[100:110] = forces[100]
    base = _vectors(rng)
    peaks = VectorPeaks.build(dict(reversed(base.items())), n_rows, 0.0, dt)
    # the pair first (a support's x and y); the x, y, z support's flag: the sum of squares
    assert peaks.names == ("a", "d", "c", "b") and peaks.layout[0].tolist() == [[0, 1]]
    assert peaks.layout[2].tolist() == [0, 0, 1]
    vectors = {n: base[n] for n in peaks.names}
    expect = vector_peaks_numpy(t, kink, forces, vectors, 0.0, dt, n_rows)
    buf = np.column_stack([t, kink, _squared(forces, vectors)])
    rows = np.zeros(n, dtype=np.int64)
    for a, b in ((0, 1), (1, 2), (2, 97), (97, 250), (250, n)):  # chunks, 1-row ones too
        enter_dense(np.ascontiguousarray(buf[a:b]), b - a, peaks.row_t0, peaks.row_dt,
                    peaks.peaks, peaks.last, rows)
    np.testing.assert_allclose(peaks.peaks, expect, rtol=1e-12, atol=0)
    # the peaks between the instants raised some rows above their instants' largest
    plain = vector_peaks_numpy(t, np.ones(n), forces, vectors, 0.0, dt, n_rows)
    assert np.all(expect >= plain) and np.sum(expect > plain * (1 + 1e-9)) > 10
    # a time before row 0's goes to row 0, one after the last row's to the last row
    short = VectorPeaks.build(vectors, 5, 0.5, dt)
    assert short.names == peaks.names
    enter_dense(buf, n, short.row_t0, short.row_dt, short.peaks, short.last, rows)
    np.testing.assert_allclose(short.peaks,
                               vector_peaks_numpy(t, kink, forces, vectors, 0.5, dt, 5))
    assert np.all(short.peaks[-1] >= buf[t > 0.5 + 4 * dt, 2:].max(axis=0))


def _drive():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from torquesplit.results import bearing_vectors
        from torquesplit.simulation import prepare_run

        run = prepare_run(torquesplit.load_model(torquesplit.example_path(
            "lin_parker1999_planetary")))
    return run, bearing_vectors(run.structure.element_names, run.model, run.kinematics)


def test_the_kernels_dense_record_holds_every_step():
    """Without table corners the instants are the steps: the run's peaks equal the twin
    on its every-step history, and a history of every 7th step gives the same peaks over
    the same span."""
    run, vectors = _drive()
    kw = dict(run.integrate_kwargs, sample_interval=None, history_dofs=(),
              history_peaks=vectors)
    span = (0.0, 0.004)
    every = integrate(run.structure, run.y0, span, record_every=1, **kw)
    assert sorted(every.history_peak_names) == sorted(vectors) and len(vectors) == 7
    vectors = {n: vectors[n] for n in every.history_peak_names}  # (pairs first)
    cols = {e: list(every.history_elements).index(e) for t in vectors.values() for e, _ in t}
    forces = np.zeros((every.history_t.size, run.structure.n_elements))
    for e, c in cols.items():
        forces[:, e] = every.history_forces[:, c]
    h = every.step
    twin = vector_peaks_numpy(every.history_t, np.zeros(every.history_t.size), forces,
                              vectors, 0.0, h, every.history_t.size)
    np.testing.assert_allclose(every.history_peaks, np.sqrt(twin), rtol=1e-12)
    coarse = integrate(run.structure, run.y0, span, record_every=7, **kw)
    np.testing.assert_allclose(np.nanmax(coarse.history_peaks[1:], axis=0),
                               np.nanmax(every.history_peaks[1:], axis=0), rtol=1e-12)
    # a history of one record (t = 0) holds the whole run's in it (it held none)
    one = integrate(run.structure, run.y0, span, record_every=10**9, **kw)
    np.testing.assert_allclose(one.history_peaks[0],
                               np.nanmax(every.history_peaks, axis=0), rtol=1e-12)


def test_dormand_prince_keeps_the_peaks_of_every_accepted_step(monkeypatch):
    """Dormand-Prince enters every accepted step (it kept the history's samples): the
    peaks over the run do not depend on the sampling, equal the every-step ones of its
    twin, and a dense record emptied every few steps (the kernel returns when it is half
    full) changes neither them nor the trajectory."""
    run, vectors = _drive()
    kw = dict(method="dopri", max_step=2e-4, history_dofs=(),
              track_elements=run.integrate_kwargs["track_elements"])
    span = (0.0, 0.01)
    runs = {si: integrate(run.structure, run.y0, span, history_peaks=vectors,
                          sample_interval=si, **kw) for si in (2e-4, 3.7e-5)}
    coarse, fine = runs[2e-4], runs[3.7e-5]
    assert sorted(coarse.history_peak_names) == sorted(vectors) and coarse.n_steps > 300
    np.testing.assert_array_equal(np.nanmax(coarse.history_peaks, axis=0),
                                  np.nanmax(fine.history_peaks, axis=0))
    # the fine history's samples (interpolated between the steps) reach no higher
    names = fine.history_peak_names
    cols = {e: list(fine.history_elements).index(e) for t in vectors.values() for e, _ in t}
    forces = np.zeros((fine.history_t.size, run.structure.n_elements))
    for e, c in cols.items():
        forces[:, e] = fine.history_forces[:, c]
    sampled = np.sqrt(_squared(forces, {n: vectors[n] for n in names}))
    assert np.all(np.nanmax(sampled, axis=0) < np.nanmax(fine.history_peaks, axis=0)
                  + 1e-12)
    # the kernel returning every 3 steps to have its record of 6 rows emptied (no corners
    # here: a row a step), within the 64 parts of the span (5 steps each): the same bit
    # for bit, where without the returns the record overflowed and kept no peaks
    plain = integrate(run.structure, run.y0, span, sample_interval=2e-4, **kw)
    integ = importlib.import_module("torquesplit.solve.integrate")
    monkeypatch.setattr(integ, "_dense_rows", lambda model, plan: 6)
    small = integrate(run.structure, run.y0, span, history_peaks=vectors,
                      sample_interval=2e-4, **kw)
    assert small.n_steps == plain.n_steps == coarse.n_steps
    np.testing.assert_array_equal(small.y_final, plain.y_final)
    np.testing.assert_array_equal(coarse.y_final, plain.y_final)
    np.testing.assert_array_equal(small.history_peaks, coarse.history_peaks)


def test_history_peaks_refuses_bad_terms():
    run, _ = _drive()
    s = run.structure
    with pytest.raises(OptionTypeError, match="history_peaks must map a name"):
        integrate(s, run.y0, (0.0, 1e-4), history_peaks=[("a", 0)])
    with pytest.raises(OptionError, match=r"history_peaks\['a'\] needs one or more terms"):
        integrate(s, run.y0, (0.0, 1e-4), history_peaks={"a": [(0, (1.0, 0.0))]})
    with pytest.raises(OptionError, match="unknown element 'nope'"):
        integrate(s, run.y0, (0.0, 1e-4), history_peaks={"a": [("nope", (1.0, 0.0, 0.0))]})
    # an index is an integer (1.7 was element 1, True element 1), a direction not zero
    for index in (1.7, True, np.float64(2.0)):
        with pytest.raises(OptionTypeError, match="each element is a name or an integer"):
            integrate(s, run.y0, (0.0, 1e-4), history_peaks={"a": [(index, (1, 0, 0))]})
    with pytest.raises(OptionTypeError, match="each dof is a name or an integer index, got 0.5"):
        integrate(s, run.y0, (0.0, 1e-4), history_dofs=[0.5])
    with pytest.raises(OptionError, match=r"history_peaks\['a'\]: a direction of \(0, 0, 0\)"):
        integrate(s, run.y0, (0.0, 1e-4), history_peaks={"a": [(0, (1, 0, 0)), (1, (0, 0, 0))]})
    sol = integrate(s, run.y0, (0.0, 1e-4), history_peaks={"a": [(np.int64(1), (0, 1, 0))]},
                    history_elements=[np.int32(1)], history_dofs=())
    assert sol.history_elements == (1,) and sol.history_peaks.shape[1] == 1


def test_a_dense_record_that_overflows_keeps_no_peaks(monkeypatch):
    """A record with too few rows for a chunk's instants counts those lost; the run then
    keeps no peaks (the bearing table takes the history's) instead of wrong ones."""
    run, vectors = _drive()
    integ = importlib.import_module("torquesplit.solve.integrate")
    monkeypatch.setattr(integ, "_dense_rows", lambda model, plan: 5)
    sol = integrate(run.structure, run.y0, (0.0, 0.002),
                    **dict(run.integrate_kwargs, history_dofs=(), history_peaks=vectors))
    assert sol.success and sol.history_peaks is None
