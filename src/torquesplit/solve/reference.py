"""Readable numpy twins of the compiled kernels in :mod:`torquesplit.solve._kernels`.

These functions say in plain numpy what the kernels compute.  They are slow (a Python
call per step) and exist for three uses: documentation, tests that compare kernel and
twin, and baselines (e.g. ``scipy.integrate.solve_ivp(lambda t, y: rhs_numpy(s, t, y),
...)``).  Symbols follow :mod:`torquesplit.assembly.structure`.  The element laws and
the table interpolation are not re-typed here: they are the functions of
:mod:`torquesplit.solve.laws` (through its batch evaluators), so a twin checks the
kernels' loops, gathers and bookkeeping against plain numpy linear algebra.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from torquesplit.assembly.structure import (
    MESH,
    Structure,
)
from torquesplit.solve import laws

__all__ = [
    "Excitation",
    "excitation_numpy",
    "element_forces_numpy",
    "rhs_numpy",
    "spline_law_numpy",
    "friction_matrix_numpy",
    "cycle_index_numpy",
    "contact_state_numpy",
    "hermite_numpy",
    "cycle_statistics_numpy",
    "rk4_numpy",
    "corner_times_numpy",
    "dopri_numpy",
]


@dataclass(frozen=True)
class Excitation:
    """Every element's time-dependent quantities at one instant (all shape (n_el,))."""

    stiffness: np.ndarray
    """k_e(t) [N/m]."""
    force: np.ndarray
    """Additive force p_e(t) [N]."""
    half_gap: np.ndarray
    """Half-gap g_e of the current excitation cycle [m]."""
    error: np.ndarray
    """e_e(t) [m]."""
    error_rate: np.ndarray
    """e_e'(t) [m/s]."""
    cycle: np.ndarray
    """Statistics cycle index of s = f t + phase (int64; 0 for f == 0): floor(s), plus one
    within CYCLE_EPS below the next integer (see :func:`cycle_index_numpy`)."""
    friction: np.ndarray
    """(3 n_fm,) friction-table values: per unit normal load, the friction force and the
    friction moments on driver and driven gear of each friction mesh."""


def cycle_index_numpy(s):
    """Statistics cycle index of mesh phases ``s``: floor(s), plus one when
    frac(s) >= 1 - CYCLE_EPS (a sample at a cycle boundary counts in the cycle it starts,
    even if s rounds to just below the integer).  Twin of the CY lines of
    ``_kernels.excite_tables``."""
    s = np.asarray(s, dtype=float)
    out = np.array([laws.stat_cycle(float(x), float(np.floor(x))) for x in s.ravel()],
                   dtype=np.int64)
    return out.reshape(s.shape)


def excitation_numpy(structure: Structure, t: float) -> Excitation:
    """Excitation of every element at time ``t``.

    Mesh phase s = f t + phase.  Stiffness and additive force are interpolated linearly
    and periodically in their table at frac(s) * n_table (column 0 when f == 0); the
    half-gap is entry floor(s) mod n_gaps of the element's per-cycle sequence; the error
    is e = e_const + sum A sin(omega t + phi) and its rate sum A omega cos(omega t + phi).
    The friction rows of each friction mesh are interpolated like the tables, at the
    phase of its mesh element.
    Twin of ``_kernels.excite_exact`` (and ``init_slots``, ``excite_friction``).
    """
    s = structure
    n_el = s.n_elements
    varying = s.frequency > 0.0
    mesh_phase = np.where(varying, s.frequency * t + s.phase, 0.0)
    cycle = np.floor(mesh_phase)
    stiffness = np.empty(n_el)
    force = np.empty(n_el)
    laws.periodic_values(np.ascontiguousarray(s.stiffness_table), mesh_phase, stiffness)
    laws.periodic_values(np.ascontiguousarray(s.force_table), mesh_phase, force)
    n_gaps = np.diff(s.gap_ptr)
    half_gap = s.gap_values[s.gap_ptr[:-1] + np.mod(cycle.astype(np.int64), n_gaps)]
    stat_cycle = np.where(varying, cycle_index_numpy(mesh_phase), 0)

    owner = np.repeat(np.arange(n_el), np.diff(s.error_ptr))
    arg = s.error_omega * t + s.error_phase
    error = s.error_constant.astype(float).copy()
    error_rate = np.zeros(n_el)
    np.add.at(error, owner, s.error_amplitude * np.sin(arg))
    np.add.at(error_rate, owner, s.error_amplitude * s.error_omega * np.cos(arg))

    friction = np.zeros(s.friction_table.shape[0])
    if s.n_friction:
        rows = np.repeat(np.asarray(s.fr_el), 3)
        laws.periodic_values(np.ascontiguousarray(s.friction_table),
                             s.frequency[rows] * t + s.phase[rows], friction)
    return Excitation(stiffness, force, half_gap, error, error_rate, stat_cycle, friction)


def spline_law_numpy(par, dx, dy, rx=0.0, ry=0.0):
    """Radial force of a spline at relative displacement (dx, dy) and rate (rx, ry):
    :func:`torquesplit.solve.laws.spline_force` for a row ``par`` of
    ``structure.sp_par`` (k, c, S1, S2, F_m, v).  Returns (f_x, f_y)."""
    return laws.spline_force(float(dx), float(dy), float(rx), float(ry), *map(float, par))


def friction_matrix_numpy(structure: Structure, t: float) -> np.ndarray:
    """Dense (n_el, n_dof) friction projections W_e(s(t)) (zero rows without friction).

    The generalized force of tooth friction is -W_e max(f_e, 0): friction acts on the
    working flank only (see docs/theory/model.md)."""
    return structure.friction_matrix(excitation_numpy(structure, t).friction)


def element_forces_numpy(structure: Structure, t: float, y: np.ndarray):
    """Element forces f_e and deformations delta_e at (t, y); returns ``(force, delta)``.

    delta = V.q - e, rate = V.v - e', h = dead zone of half-width g (h = delta when
    g == 0), f = k h + c rate (in contact only) + p; the two component elements of a
    spline then get the radial law (:func:`spline_law_numpy`).
    Twin of the element loop of ``_kernels.rhs_slot`` and of the splines in
    ``_kernels.rhs_extra`` (the laws are :mod:`torquesplit.solve.laws`).
    """
    n = structure.n_dof
    y = np.asarray(y, dtype=float)
    q, v = y[:n], y[n:]
    ex = excitation_numpy(structure, t)
    V = structure.projection_matrix()
    delta = V @ q - ex.error
    rate = V @ v - ex.error_rate
    f = np.empty(structure.n_elements)
    laws.spring_forces(ex.stiffness, np.asarray(structure.damping, dtype=float), delta, rate,
                       ex.half_gap, f, np.empty_like(f), np.empty_like(f))
    force = f + ex.force
    for (e_x, e_y), par in zip(structure.sp_el, structure.sp_par, strict=True):
        force[e_x], force[e_y] = spline_law_numpy(par, delta[e_x], delta[e_y],
                                                  rate[e_x], rate[e_y])
    return force, delta


def rhs_numpy(structure: Structure, t: float, y: np.ndarray) -> np.ndarray:
    """Right-hand side of the first-order system:
    dy/dt = [v, M^-1 (F - C_g v - V^T f - W(t)^T max(f, 0) - G v - K_f q)].

    W(t) holds the tooth-friction projections (:func:`friction_matrix_numpy`); f includes
    the spline forces; G is the gyroscopic matrix.  Twin of ``_kernels.rhs_slot`` +
    ``_kernels.rhs_extra`` / ``_kernels.evaluate``.  Usable directly with :func:`scipy.integrate.solve_ivp`.
    """
    n = structure.n_dof
    y = np.asarray(y, dtype=float)
    v = y[n:]
    force, _ = element_forces_numpy(structure, t, y)
    V = structure.projection_matrix()
    gen = structure.external_force - structure.ground_damping * v - V.T @ force
    if structure.n_gyroscopic:
        gen = gen - structure.gyroscopic_matrix() @ v
    if structure.n_frame_stiffness:
        gen = gen - structure.frame_stiffness_matrix() @ y[:n]
    if structure.n_friction:
        gen = gen - friction_matrix_numpy(structure, t).T @ np.maximum(force, 0.0)
    accel = structure.inv_mass * gen
    return np.concatenate([v, accel])


def contact_state_numpy(structure: Structure, t: float, y: np.ndarray):
    """Which elements are separated and which touch on their back side at (t, y).

    Separated: |delta| <= g with g > 0.  Back-side contact: delta < -g with g > 0, or
    delta < 0 for a mesh without backlash.  Returns two boolean arrays (n_el,).
    Twin of the contact counters in ``_kernels.record``.
    """
    _, delta = element_forces_numpy(structure, t, y)
    g = excitation_numpy(structure, t).half_gap
    gapped = g > 0
    separated = gapped & (np.abs(delta) <= g)
    back = np.where(gapped, delta < -g, (structure.element_kind == MESH) & (delta < 0))
    return separated, back


def negative_share_numpy(a, b, c):
    """The fraction of [0, 1] where q(u) = a + (b - a) u + c u (u - 1) is negative,
    elementwise, from q's roots (the parabola through three samples, ``c`` = 0 the
    chord).  Twin of ``laws.negative_share``, without its shortcuts."""
    a, b, c = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (a, b, c)))
    out = np.empty(a.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        chord = np.where(a < 0, np.where(b < 0, 1.0, a / (a - b)),
                         np.where(b < 0, b / (b - a), 0.0))
    for i in np.ndindex(a.shape):
        if c[i] == 0.0:
            out[i] = chord[i]
            continue
        roots = np.roots([c[i], b[i] - a[i] - c[i], a[i]])
        roots = np.sort(roots[np.abs(roots.imag) == 0].real)
        if roots.size < 2 or roots[0] == roots[1]:
            out[i] = 1.0 if c[i] < 0 else 0.0
            continue
        inside = max(min(roots[1], 1.0) - max(roots[0], 0.0), 0.0)
        out[i] = inside if c[i] > 0 else 1.0 - inside
    return out


def contact_times_numpy(structure: Structure, times, ys):
    """Time in separation and in back-side contact [s] (two arrays (n_el,)) over the
    samples (t_k, y_k): between two samples delta + g and delta - g (delta alone for a
    mesh without backlash) follow the parabola through that interval's two samples and
    the one before (the first interval: the chord), and the interval is split where
    they change sign (:func:`negative_share_numpy`).  An interval that ends in a cycle
    without clearance of an element other than a mesh counts nothing.  Twin of the
    contact times in ``_kernels.record``."""
    mesh = structure.element_kind == MESH
    lo, hi, gapped = [], [], []
    for t, y in zip(times, ys, strict=True):
        _, delta = element_forces_numpy(structure, t, y)
        g = excitation_numpy(structure, t).half_gap
        gap = np.where(g > 0, g, 0.0)
        lo.append(delta + gap)
        hi.append(delta - gap)
        gapped.append(g > 0)
    lo, hi, gapped = np.array(lo), np.array(hi), np.array(gapped)
    h = np.diff(np.asarray(times, dtype=float))[:, None]
    # the sag of the parabola through samples k-2, k-1, k over (t_k-1, t_k): h_k^2 times
    # its second divided difference (Newton), of delta + g for both
    c = np.zeros_like(lo[1:])
    c[1:] = h[1:] ** 2 * ((lo[2:] - lo[1:-1]) / h[1:] - (lo[1:-1] - lo[:-2]) / h[:-1]) / (
        h[1:] + h[:-1])
    back = negative_share_numpy(lo[:-1], lo[1:], c)
    sep = np.maximum(negative_share_numpy(hi[:-1], hi[1:], c) - back, 0.0)
    end = gapped[1:]  # (the state at each interval's end decides whether it counts)
    return ((h * np.where(end | mesh, sep, 0.0)).sum(axis=0),
            (h * np.where(end | mesh, back, 0.0)).sum(axis=0))


def hermite_numpy(theta, h, y0, f0, y1, f1):
    """Cubic Hermite interpolant between (y0, f0) and (y1, f1) at t0 + theta h.

    Twin of ``_kernels.hermite``.
    """
    h00 = 2 * theta**3 - 3 * theta**2 + 1
    h10 = theta**3 - 2 * theta**2 + theta
    h01 = -2 * theta**3 + 3 * theta**2
    h11 = theta**3 - theta**2
    return h00 * y0 + h10 * h * f0 + h01 * y1 + h11 * h * f1


def cycle_statistics_numpy(times, forces, frequency, phase, t0, n_cycles_cap,
                           counted=None, regimes=None, corners=(), continuous_start=False):
    """Per-excitation-cycle max, min, mean and sample count of one element's force at the
    instants ``times`` (increasing: the step samples and any corner instants between).

    Cycle index of an instant at t is c(f t + phase) - c(f t0 + phase), c the statistics
    cycle index (:func:`cycle_index_numpy`).  Mean: the trapezoid rule over the intervals
    between consecutive instants, an interval that holds the start of a cycle split there
    (the linear interpolant integrated on each side; past a skipped cycle, half to each
    end's cycle), divided by the time so entered.  ``counted``: which instants are
    samples of the run (the counts; default all), the others corner instants.  Extremes
    between the instants: where the middle one of three consecutive instants is the
    largest (smallest), is no corner and all three share one contact regime
    (``regimes``: default all 1; 0 apart), the vertex of the parabola through them, in
    the middle instant's cycle.  ``corners``: every corner time; a sample within
    ``_kernels.MERGE`` steps of one is that corner.  ``continuous_start``: the force is
    continuous where a cycle begins (no table corner at node 0,
    ``kernel_data.continuous_start``): the force interpolated at each cycle start enters
    both cycles' max and min.  Returns four arrays of length
    ``n_cycles_cap`` (max -inf / min +inf / mean NaN where empty).  Twin of the cycle
    part of ``_kernels.record``, ``_kernels.force_instant``
    (whose parabola formula, ``_kernels.vertex``, it calls).
    """
    times = np.asarray(times, dtype=float)
    forces = np.asarray(forces, dtype=float)
    idx = (cycle_index_numpy(frequency * times + phase)
           - cycle_index_numpy(frequency * t0 + phase)).astype(int)
    cmax = np.full(n_cycles_cap, -np.inf)
    cmin = np.full(n_cycles_cap, np.inf)
    csum = np.zeros(n_cycles_cap)
    cwt = np.zeros(n_cycles_cap)
    ccnt = np.zeros(n_cycles_cap, dtype=np.int64)
    ok = (idx >= 0) & (idx < n_cycles_cap)
    np.maximum.at(cmax, idx[ok], forces[ok])
    np.minimum.at(cmin, idx[ok], forces[ok])
    cnt = ok if counted is None else ok & np.asarray(counted, dtype=bool)
    np.add.at(ccnt, idx[cnt], 1)
    base = int(cycle_index_numpy(frequency * t0 + phase))
    for a in range(times.size - 1):  # each interval, split where a cycle begins
        ta, tb, fa, fb, ca, cb = (times[a], times[a + 1], forces[a], forces[a + 1],
                                  idx[a], idx[a + 1])
        span = tb - ta
        if cb == ca + 1:
            tc = (cb + base - phase) / frequency
            th = min(max((tc - ta) / span, 0.0), 1.0) if span > 0 else 1.0
            fc = fa + th * (fb - fa)
            parts = ((ca, th * span, 0.5 * th * span * (fa + fc)),
                     (cb, span - th * span, 0.5 * (span - th * span) * (fc + fb)))
            if continuous_start:
                for c in (ca, cb):
                    if 0 <= c < n_cycles_cap:
                        cmax[c] = max(cmax[c], fc)
                        cmin[c] = min(cmin[c], fc)
        else:
            parts = ((ca, 0.5 * span, 0.5 * span * fa), (cb, 0.5 * span, 0.5 * span * fb))
        for c, dt, integral in parts:
            if 0 <= c < n_cycles_cap:
                csum[c] += integral
                cwt[c] += dt
    mean = np.full(n_cycles_cap, np.nan)
    np.divide(csum, cwt, out=mean, where=cwt > 0)
    step = np.ones(times.size, dtype=bool) if counted is None else np.asarray(counted, bool)
    reg = np.ones(times.size, dtype=np.int64) if regimes is None else np.asarray(regimes)
    from torquesplit.solve._kernels import MERGE, vertex  # (the parabola's formula)

    kinks = np.asarray(corners, dtype=float)
    h = np.min(np.diff(times[step])) if np.sum(step) > 1 else 0.0
    kink = ~step.copy()
    if kinks.size:
        kink |= step & (np.min(np.abs(times[:, None] - kinks[None, :]), axis=1)
                        <= MERGE * h * (1 + 1e-9))
    for b in range(1, times.size - 1):
        a, c = b - 1, b + 1
        f0, f1, f2 = forces[a], forces[b], forces[c]
        cb = idx[b]
        if (kink[b] or reg[b] == 0 or reg[a] != reg[b] or reg[c] != reg[b]
                or not 0 <= cb < n_cycles_cap or (f1 == f0 and f1 == f2)):
            continue
        if f1 >= f0 and f1 >= f2:
            cmax[cb] = max(cmax[cb], vertex(times[a], times[b], times[c], f0, f1, f2))
        elif f1 <= f0 and f1 <= f2:
            cmin[cb] = min(cmin[cb], vertex(times[a], times[b], times[c], f0, f1, f2))
    return cmax, cmin, mean, ccnt


def cycle_ratio_numpy(times, forces, frequency, phase, t0, n_cycles_cap, group_min=0.0,
                      continuous_start=None):
    """Per-cycle max and min of the instantaneous load-sharing ratio N f_j / sum_i f_i
    (Ji & Li eq. 18) of each member j of one group, from the loads the members' teeth
    carry (the positive parts of their forces ``forces`` (n_instants, N), no tension) at
    the instants ``times`` (increasing); member j's cycles as in
    :func:`cycle_statistics_numpy` from ``frequency[j]``, ``phase[j]``.  A ratio enters
    only where the group's total force exceeds ``group_min``.  Where member j's force is
    continuous at its cycle starts (``continuous_start[j]``), the ratio of the forces
    interpolated linearly at each start between two instants enters both cycles.  Twin
    of the ratio part of ``_kernels.record`` and of ``_kernels.ratio_starts``; returns
    (max, min), each (n_cycles_cap, N), -inf / +inf where empty."""
    times = np.asarray(times, dtype=float)
    raw = np.asarray(forces, dtype=float)
    forces = np.maximum(raw, 0.0)
    nm = forces.shape[1]
    cont = np.zeros(nm, bool) if continuous_start is None else np.asarray(continuous_start)
    rmax = np.full((n_cycles_cap, nm), -np.inf)
    rmin = np.full((n_cycles_cap, nm), np.inf)
    total = forces.sum(axis=1)
    for j in range(nm):
        base = int(cycle_index_numpy(frequency[j] * t0 + phase[j]))
        idx = (cycle_index_numpy(frequency[j] * times + phase[j]) - base).astype(int)
        ok = (idx >= 0) & (idx < n_cycles_cap) & (total > group_min)
        ratio = nm * forces[ok, j] / total[ok]
        np.maximum.at(rmax[:, j], idx[ok], ratio)
        np.minimum.at(rmin[:, j], idx[ok], ratio)
        if not cont[j]:
            continue
        for a in np.flatnonzero(np.diff(idx) == 1):  # an interval holding a cycle start
            ta, span, cb = times[a], times[a + 1] - times[a], idx[a + 1]
            tc = (cb + base - phase[j]) / frequency[j]
            th = min(max((tc - ta) / span, 0.0), 1.0) if span > 0 else 1.0
            fc = np.maximum(raw[a] + th * (raw[a + 1] - raw[a]), 0.0)
            if fc.sum() > group_min:
                for c in (cb - 1, cb):
                    if 0 <= c < n_cycles_cap:
                        r = nm * fc[j] / fc.sum()
                        rmax[c, j] = max(rmax[c, j], r)
                        rmin[c, j] = min(rmin[c, j], r)
    return rmax, rmin


def rk4_numpy(structure: Structure, y0, t0: float, h: float, n_steps: int, times=None):
    """Classic RK4 with a Python call per stage; returns ``(t, y)`` of all steps.

    ``times``: an explicit, increasing time grid instead of ``t0 + i h`` (e.g. the steps
    with the table corners inserted, as the kernel takes them with ``corners=True``).
    Twin of ``_kernels.rk4_run`` (which advances error sinusoids by phasor rotation, so
    the two agree to round-off, not bit for bit).
    """
    grid = (np.asarray(times, dtype=float) if times is not None
            else t0 + h * np.arange(n_steps + 1))
    y = np.array(y0, dtype=float)
    ys = [y.copy()]
    for ta, tb in zip(grid[:-1], grid[1:]):
        hs = tb - ta
        k1 = rhs_numpy(structure, ta, y)
        k2 = rhs_numpy(structure, ta + 0.5 * hs, y + 0.5 * hs * k1)
        k3 = rhs_numpy(structure, ta + 0.5 * hs, y + 0.5 * hs * k2)
        k4 = rhs_numpy(structure, tb, y + hs * k3)
        y = y + hs / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
        ys.append(y.copy())
    return grid, np.array(ys)


def corner_times_numpy(structure: Structure, t0: float, t1: float) -> np.ndarray:
    """Times in (t0, t1) at the corners of every element's tables
    (:func:`torquesplit.solve.kernel_data.corner_nodes`; node 0 where the half-gap
    changes from cycle to cycle).  Twin of the corner bookkeeping of the kernels."""
    from torquesplit.solve.kernel_data import kernel_model

    m = kernel_model(structure)
    n_tab = structure.n_table
    out = []
    for e in np.flatnonzero(structure.frequency > 0):
        nodes = m.corner_node[m.corner_ptr[e]:m.corner_ptr[e + 1]]
        f, ph = structure.frequency[e], structure.phase[e]
        for c in range(int(np.floor(f * t0 + ph)) - 1, int(np.ceil(f * t1 + ph)) + 1):
            for node in nodes:
                tc = ((c * n_tab + node) / n_tab - ph) / f
                if t0 < tc < t1:
                    out.append(tc)
    return np.unique(out)


# Dormand & Prince 5(4) tableau (Hairer, Norsett & Wanner, Solving ODE I, table 5.2)
_DP_C = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1])
_DP_A = [
    [],
    [1 / 5],
    [3 / 40, 9 / 40],
    [44 / 45, -56 / 15, 32 / 9],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
    [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
]
_DP_E = np.array([71 / 57600, 0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])


def dopri_numpy(structure: Structure, y0, t_span, *, rtol, atol, h0, h_max=np.inf,
                max_steps=100_000):
    """Adaptive Dormand-Prince 5(4) with PI step control; returns ``(t, y, n_rejected)``.

    Error norm: RMS of err_i / (atol_i + rtol max(|y_i|, |y_new_i|)).  Step control:
    h_new = h / clip(err^0.17 / err_old^0.04 / 0.9, 0.1, 5) after acceptance,
    h / min(5, err^0.17 / 0.9) after rejection (no increase right after a rejection).
    Twin of ``_kernels.dopri_run`` (same step sequence up to round-off).
    """
    t0, t_end = map(float, t_span)
    y = np.array(y0, dtype=float)
    atol = np.broadcast_to(np.asarray(atol, dtype=float), y.shape)
    t, h, facold, last_rejected, n_rejected = t0, float(h0), 1e-4, False, 0
    ts, ys = [t], [y.copy()]
    f = rhs_numpy(structure, t, y)
    while t < t_end and len(ts) <= max_steps:
        hs = min(h, h_max)
        last = False
        if t + 1.01 * hs >= t_end:
            if t_end - t <= h_max:
                hs, last = t_end - t, True
            else:
                hs = 0.5 * (t_end - t)
        k = [f]
        for i in range(1, 7):
            yi = y + hs * sum(a * kj for a, kj in zip(_DP_A[i], k, strict=False))
            ti = t_end if (last and i >= 5) else t + _DP_C[i] * hs
            k.append(rhs_numpy(structure, ti, yi))
            if i == 6:
                y_new = yi
        err = hs * sum(e * kj for e, kj in zip(_DP_E, k, strict=True))
        scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
        enorm = np.sqrt(np.mean((err / scale) ** 2))
        if not np.isfinite(enorm):
            n_rejected, last_rejected, h = n_rejected + 1, True, hs * 0.2
            continue
        fac11 = enorm**0.17
        if enorm <= 1.0:
            t = t_end if last else t + hs
            y, f = y_new, k[6]
            ts.append(t)
            ys.append(y.copy())
            fac = np.clip(fac11 / facold**0.04 / 0.9, 0.1, 5.0)
            h_new = hs / fac
            if last_rejected:
                h_new = min(h_new, hs)
            h, facold, last_rejected = h_new, max(enorm, 1e-4), False
        else:
            n_rejected, last_rejected = n_rejected + 1, True
            h = hs / min(5.0, fac11 / 0.9)
    return np.array(ts), np.array(ys), n_rejected
