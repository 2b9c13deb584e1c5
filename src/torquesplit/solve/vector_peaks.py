"""Largest magnitudes of force vectors (a body's bearing force) at every instant of a run.

The bearing table's peak |F| came from the decimated history, so it moved with the
sampling: 4.3 % on the split-path differential between 20 and 33 samples per period.
The kernels now keep, for runs that ask for it, a dense record of the instants
(every step, and the tables' corners where a vector's term has them) with each vector's
squared magnitude (``Record.dense``,
:func:`torquesplit.solve._kernels.dense_row`).  Between chunks of the run
:func:`enter_dense` takes each one's largest per history interval and the peak between
instants (the vertex of the parabola through three of them, as the kernels do for a
mesh force), and empties the record.  It is compiled apart from the kernels: reducing
the peaks inside the kernels doubled their cold compile and cost 14-19 % of a step
(branch ``bearing-peak-stream``).

A history row j (time t_j) holds the largest over the instants in (t_{j-1}, t_j], its own
included, and the last row those after it too; a peak between instants goes to the
interval of the middle one.
Twin: :func:`vector_peaks_numpy`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from torquesplit._jit_cache import track_imports
from torquesplit.solve._kernels import vertex  # the mesh forces' peak between instants

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

__all__ = ["VectorPeaks", "enter_dense", "vector_peaks_numpy"]


@njit(cache=True, error_model="numpy", _nrt=False)
def enter_dense(buf, n, row_t0, row_dt, peaks, last, rows):
    """Enter the ``n`` first rows of the dense record ``buf`` (t, kink, each vector's
    squared magnitude) in ``peaks`` (n_rows, n_vectors), their largest per history
    interval.  History row j of a time t is ceil((t - row_t0) / row_dt), the last row
    of ``peaks`` for the instants after it (a run whose end falls between two records:
    a history of one row kept a peak of 0, a reviewer); ``rows`` is scratch space for
    them (at least ``n``).
    ``last`` (n_vectors, 7) carries the last two instants of each vector from one call
    to the next: times, squared magnitudes, the last one's kink and row, and the count
    entered (zeros to start).  One vector at a time over the instants, its state in
    locals."""
    n_v = peaks.shape[1]
    n_rows = peaks.shape[0]
    for i in range(n):
        rows[i] = min(max(math.ceil((buf[i, 0] - row_t0) / row_dt - 1e-9), 0), n_rows - 1)
    for v in range(n_v):
        t0, t1, f0, f1 = last[v, 0], last[v, 1], last[v, 2], last[v, 3]
        k1, j1, seen = last[v, 4], np.int64(last[v, 5]), np.int64(last[v, 6])
        cur_j = np.int64(-1)  # the row being filled and its largest so far
        cur = -np.inf
        for i in range(n):
            f = buf[i, 2 + v]
            j = rows[i]
            if j != cur_j:
                if 0 <= cur_j < n_rows and cur > peaks[cur_j, v]:
                    peaks[cur_j, v] = cur
                cur_j = j
                cur = -np.inf
            cur = max(cur, f)
            t = buf[i, 0]
            # the peak between the instants: the middle of the last three the largest and
            # no corner of the tables (where the force may have a kink: exact as it is);
            # not where it would differ from the middle one by round-off only (a force
            # constant to round-off, the planets' bearings of Lin & Parker's stage, has an
            # extremum at every third instant: 4.7 ns a vector and instant, against 1.7)
            if (f1 >= f and f1 >= f0 and f1 - min(f0, f) > 1e-13 * f1 and k1 == 0.0
                    and seen >= 2 and t0 < t1 < t):
                top = vertex(t0, t1, t, f0, f1, f)
                if j1 == cur_j:
                    cur = max(cur, top)
                elif 0 <= j1 < n_rows and top > peaks[j1, v]:
                    peaks[j1, v] = top
            t0, t1, f0, f1 = t1, t, f1, f
            k1 = buf[i, 1]
            j1 = j
            seen += 1
        if 0 <= cur_j < n_rows and cur > peaks[cur_j, v]:
            peaks[cur_j, v] = cur
        last[v, 0], last[v, 1], last[v, 2], last[v, 3] = t0, t1, f0, f1
        last[v, 4], last[v, 5], last[v, 6] = k1, j1, seen


@dataclass
class VectorPeaks:
    """The vectors of a run (``integrate``'s ``history_peaks``) laid out for the dense
    record (:func:`~.kernel_data.make_record`'s ``dense``), and their peaks per history
    row."""

    names: tuple[str, ...]
    layout: tuple
    """(pairs, ptr, axes, elements, directions, corners): the pairs' two elements (n_p,
    2), whose squared magnitude is the sum of their squared forces; then vector n_p + g's
    terms are ``ptr[g]:ptr[g+1]``, each an element's force times its direction, and
    ``axes[g]`` 1 where they lie along distinct unit axes (the sum of the squares too);
    whether the tables' corners are instants of the record."""
    row_t0: float
    row_dt: float
    peaks: np.ndarray
    """(n_rows, n_vectors) largest squared magnitude per history interval (-inf: none)."""
    last: np.ndarray
    rows: np.ndarray
    """Scratch: the history row of each instant of a chunk."""

    @classmethod
    def build(cls, vectors: dict, n_rows: int, row_t0: float, row_dt: float,
              corner_elements=()):
        """``vectors``: name -> [(element index, direction (3,))].  The pairs (two
        distinct elements along two distinct unit axes: a support's x and y) come first,
        in the record and in ``names``.  ``corner_elements``: the elements whose tables
        have corners; where a vector has such a term, the corners are instants of the
        record (a peak of its force can sit on one)."""
        def is_axes(terms):  # distinct elements along distinct unit axes
            d = np.array([np.asarray(u, float) for _, u in terms]).reshape(-1, 3)
            axis = [int(np.argmax(np.abs(r))) for r in d]
            return (all(abs(r[a]) == 1.0 and np.count_nonzero(r) == 1
                        for r, a in zip(d, axis, strict=True))
                    and len(set(axis)) == len(d) and len({e for e, _ in terms}) == len(d))

        pairs = {n: t for n, t in vectors.items() if len(t) == 2 and is_axes(t)}
        rest = {n: t for n, t in vectors.items() if n not in pairs}
        ptr = np.zeros(len(rest) + 1, dtype=np.int64)
        elements, dirs, axes = [], [], []
        for v, terms in enumerate(rest.values()):
            ptr[v + 1] = ptr[v] + len(terms)
            elements += [int(e) for e, _ in terms]
            dirs.append(np.array([np.asarray(u, float) for _, u in terms]).reshape(-1, 3))
            axes.append(int(is_axes(terms)))
        layout = (np.array([[e for e, _ in t] for t in pairs.values()],
                           dtype=np.int64).reshape(-1, 2),
                  ptr, np.array(axes, dtype=np.int64), np.array(elements, dtype=np.int64),
                  np.concatenate(dirs) if dirs else np.zeros((0, 3)),
                  any(e in set(corner_elements) for t in vectors.values() for e, _ in t))
        return cls(names=(*pairs, *rest), layout=layout, row_t0=float(row_t0),
                   row_dt=float(row_dt), peaks=np.full((n_rows, len(vectors)), -np.inf),
                   last=np.zeros((len(vectors), 7)), rows=np.zeros(0, dtype=np.int64))

    def drain(self, rec) -> None:
        """Enter the dense record's rows (``rec``, a :class:`~.kernel_data.Record`) and
        empty it for the next chunk."""
        n = int(rec.dense_el[0])
        if n:
            if self.rows.shape[0] < n:
                self.rows = np.zeros(rec.dense.shape[0], dtype=np.int64)
            enter_dense(rec.dense, n, self.row_t0, self.row_dt, self.peaks, self.last,
                        self.rows)
        rec.dense_el[0] = 0

    def lost(self, rec) -> int:
        """Instants the dense record had no room for (then the peaks are incomplete)."""
        return int(rec.dense_el[1])

    def magnitudes(self, n_rows: int) -> np.ndarray:
        """(n_rows, n_vectors) largest magnitude per history interval [N] (NaN: none)."""
        p = self.peaks[:n_rows]
        return np.where(np.isfinite(p), np.sqrt(np.maximum(p, 0.0)), np.nan)


def vector_peaks_numpy(t, kink, forces, vectors, row_t0, row_dt, n_rows) -> np.ndarray:
    """Twin of :func:`enter_dense` in plain numpy, all instants at once: ``t`` (n,),
    ``kink`` (n,), ``forces`` (n, n_el) by element index, ``vectors`` as
    :meth:`VectorPeaks.build` takes them.  Returns the (n_rows, n_vectors) squared
    magnitudes' largest per row (-inf: none)."""
    t = np.asarray(t, float)
    out = np.full((n_rows, len(vectors)), -np.inf)
    rows = np.clip(np.ceil((t - row_t0) / row_dt - 1e-9).astype(np.int64), 0, n_rows - 1)
    for v, terms in enumerate(vectors.values()):
        vec = sum(forces[:, e][:, None] * np.asarray(d, float)[None, :] for e, d in terms)
        f = (vec ** 2).sum(axis=1)
        for i in range(t.size):
            if rows[i] < n_rows:
                out[rows[i], v] = max(out[rows[i], v], f[i])
            if 1 <= i < t.size - 1 and kink[i] == 0 and f[i] >= f[i - 1] and f[i] >= f[
                    i + 1] and f[i] - min(f[i - 1], f[i + 1]) > 1e-13 * f[i] and rows[
                    i] < n_rows:
                h0, h1 = t[i] - t[i - 1], t[i + 1] - t[i]
                d1, d2 = (f[i] - f[i - 1]) / h0, (f[i + 1] - f[i]) / h1
                a = (d2 - d1) / (h0 + h1)
                s = (d1 * h1 + d2 * h0) / (h0 + h1)
                top = f[i] if a == 0 else f[i] - s * s / (4 * a)
                out[rows[i], v] = max(out[rows[i], v], top)
    return out
