"""Compiled kernels of the periodic steady-state solvers (every ``@njit`` loop here).

Nothing here writes a force law: each kernel calls the integrators' own excitation
(:func:`torquesplit.solve._kernels.excite`), their one right-hand-side evaluation
(:func:`torquesplit.solve._kernels._stage`, inlined) and the element laws with their
derivatives from :mod:`torquesplit.solve.laws` (``spring_force`` -> (f, df/dd, df/dr),
``spline_tangent``, ``positive_part``).  The linearisation of one state is kept as
per-element slopes, so a Jacobian-vector product costs one pass over the projections.

=====================  ==============================================================
kernel                 what it computes
=====================  ==============================================================
:func:`sample_rhs`     acceleration, element forces and deformations at many (t, y)
                       (the alternating frequency-time evaluation of harmonic balance)
:func:`sample_linearise`  the element slopes at many (t, y): df/dd, df/dr of every
                       element, the 2-D tangents of splines, the friction-table values
                       and the slope of max(f, 0) of friction meshes
:func:`sample_jvp`     d(acceleration) = A_q dq + A_v dv at every sample, for a batch of
                       directions (the Jacobian of harmonic balance, matrix-free)
:func:`rk4_variational`  classic RK4 of the state together with its variational
                       equations dPhi/dt = A(t, y) Phi (the monodromy for shooting
                       and Floquet multipliers), exact excitation at every stage
:func:`rk4_samples`    RK4 of the state alone, stepping through the tables' corners as
                       ``_kernels.rk4_run`` does, with samples and corner instants
=====================  ==============================================================

Twin: :func:`torquesplit.solve.reference.rhs_numpy` (tests compare the acceleration and
finite differences of it with the slopes).

Legend: ``n`` DOFs, ``ne`` elements, ``ns`` splines, ``nf`` friction meshes; a sample's
linearisation is ``KD[j, e]`` (df/dd), ``CR[j, e]`` (df/dr), ``SPT[j, k, 0:8]``
(jxx jxy jyx jyy cxx cxy cyx cyy of spline k), ``FRV[j, r]`` (friction-table row r) and
``FPS[j, i]`` (d max(f, 0)/df of friction mesh i).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from torquesplit._jit_cache import track_imports
from torquesplit.solve import laws
from torquesplit.solve._kernels import (
    MERGE,
    _rk4_step,
    _stage,
    advance_corners,
    bad_state,
    excite,
    first_corners,
    state_limits,
    sub_step_end,
)
from torquesplit.solve.kernel_data import F_MAIN, Y_K1, Y_STATE, Y_TRIAL

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

_kernel = njit(cache=True, error_model="numpy", _nrt=False)
_inline = njit(inline="always", error_model="numpy")

NO_BLOWUP = 1.7976931348623157e308
"""The divergence check of the period maps: a non-finite state only (``state_limits``
with the largest float as the bound of |q|, so that an infinite displacement counts)."""


@_kernel
def sample_rhs(ts, Y, m, w, rhs_fn, gen, A, F, D):
    """At each sample j: state ``Y[j]`` = [q, v] at time ``ts[j]`` -> acceleration
    ``A[j]`` (n), element forces ``F[j]`` and deformations ``D[j]`` (ne).  Exact
    excitation at every sample (slot 0)."""
    n = A.shape[1]
    ne = F.shape[1]
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    s0 = np.int64(0)
    WY, WF, WD = w.Y, w.F, w.D
    for j in range(ts.shape[0]):
        excite(ts[j], s0, np.int64(-1), m, w)
        for k in range(2 * n):
            WY[Y_STATE, k] = Y[j, k]
        _stage(s0, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)
        for i in range(n):
            A[j, i] = WY[Y_K1, n + i]
        for e in range(ne):
            F[j, e] = WF[F_MAIN, e]
            D[j, e] = WD[F_MAIN, e]


@_inline
def _linearise(slot, iy, m, w, force, kd, cr, spt, frv, fps):
    """Slopes of every element law at state row ``iy`` of w.Y with the excitation of
    ``slot`` (already computed) into the 1-D outputs; ``force`` gets the forces (the
    friction slope needs them).  Deformation and rate are the projections V.q - e,
    V.v - e'; the laws give the rest."""
    Y = w.Y
    K, P, G, E, ED, FR = w.K, w.P, w.G, w.E, w.ED, w.FR
    v_ptr, v_dof, v_coef, damping = m.v_ptr, m.v_dof, m.v_coef, m.damping
    sp_el, sp_par, fr_el = m.sp_el, m.sp_par, m.fr_el
    n = m.inv_mass.shape[0]
    for el in range(v_ptr.shape[0] - 1):
        d = -E[slot, el]
        r = -ED[slot, el]
        for j in range(v_ptr[el], v_ptr[el + 1]):
            d += v_coef[j] * Y[iy, v_dof[j]]
            r += v_coef[j] * Y[iy, n + v_dof[j]]
        f, fd, fr = laws.spring_force(K[slot, el], damping[el], d, r, G[slot, el])
        kd[el] = fd
        cr[el] = fr
        force[el] = f + P[slot, el]
    for k in range(sp_el.shape[0]):
        ex = sp_el[k, 0]
        ey = sp_el[k, 1]
        dx = -E[slot, ex]
        rx = -ED[slot, ex]
        for j in range(v_ptr[ex], v_ptr[ex + 1]):
            dx += v_coef[j] * Y[iy, v_dof[j]]
            rx += v_coef[j] * Y[iy, n + v_dof[j]]
        dy = -E[slot, ey]
        ry = -ED[slot, ey]
        for j in range(v_ptr[ey], v_ptr[ey + 1]):
            dy += v_coef[j] * Y[iy, v_dof[j]]
            ry += v_coef[j] * Y[iy, n + v_dof[j]]
        (spt[k, 0], spt[k, 1], spt[k, 2], spt[k, 3], spt[k, 4], spt[k, 5], spt[k, 6],
         spt[k, 7], _, _) = laws.spline_tangent(dx, dy, rx, ry, sp_par[k, 0], sp_par[k, 1],
                                                sp_par[k, 2], sp_par[k, 3], sp_par[k, 4],
                                                sp_par[k, 5])
        fx, fy = laws.spline_force(dx, dy, rx, ry, sp_par[k, 0], sp_par[k, 1], sp_par[k, 2],
                                   sp_par[k, 3], sp_par[k, 4], sp_par[k, 5])
        force[ex] = fx
        force[ey] = fy
        kd[ex] = 0.0
        kd[ey] = 0.0
        cr[ex] = 0.0
        cr[ey] = 0.0
    for r in range(FR.shape[1]):
        frv[r] = FR[slot, r]
    for i in range(fr_el.shape[0]):
        _, slope = laws.positive_part(force[fr_el[i]])
        fps[i] = slope


@_inline
def _jvp(m, kd, cr, spt, frv, fps, DQ, DV, OUT, DF):
    """OUT[:, c] = A_q DQ[:, c] + A_v DV[:, c] for every column c of the (n, n_col)
    arrays, for one linearisation (``DF`` scratch (ne, n_col)): -M^-1 [sum_e V_e (kd_e
    V_e.dq + cr_e V_e.dv) + splines + friction slopes + C_g dv + G dv + K_f dq].  The
    columns are the innermost loop (contiguous, vectorised): the monodromy's 2n columns
    go through each element once."""
    v_ptr, v_dof, v_coef = m.v_ptr, m.v_dof, m.v_coef
    inv_mass, ground = m.inv_mass, m.ground_damping
    sp_el, fr_el, fr_ptr, fr_dof, fr_coef, fr_row = (m.sp_el, m.fr_el, m.fr_ptr, m.fr_dof,
                                                     m.fr_coef, m.fr_row)
    gy_ptr, gy_idx, gy_coef = m.gy_ptr, m.gy_idx, m.gy_coef
    fs_ptr, fs_idx, fs_coef = m.fs_ptr, m.fs_idx, m.fs_coef
    n = inv_mass.shape[0]
    ne = v_ptr.shape[0] - 1
    nc = DQ.shape[1]
    for i in range(n):
        g = ground[i]
        for c in range(nc):
            OUT[i, c] = -g * DV[i, c]
        for j in range(gy_ptr[i], gy_ptr[i + 1]):
            k = np.int64(gy_idx[j]) - n
            cf = gy_coef[j]
            for c in range(nc):
                OUT[i, c] -= cf * DV[k, c]
        for j in range(fs_ptr[i], fs_ptr[i + 1]):
            k = np.int64(fs_idx[j])
            cf = fs_coef[j]
            for c in range(nc):
                OUT[i, c] -= cf * DQ[k, c]
    for el in range(ne):
        a = kd[el]
        b = cr[el]
        j0 = v_ptr[el]
        j1 = v_ptr[el + 1]
        if (a == 0.0 and b == 0.0) or j1 == j0:
            for c in range(nc):
                DF[el, c] = 0.0
            continue
        ca = a * v_coef[j0]
        cb = b * v_coef[j0]
        d = v_dof[j0]
        for c in range(nc):  # columns innermost: contiguous, vectorised
            DF[el, c] = ca * DQ[d, c] + cb * DV[d, c]
        for j in range(j0 + 1, j1):
            ca = a * v_coef[j]
            cb = b * v_coef[j]
            d = v_dof[j]
            for c in range(nc):
                DF[el, c] += ca * DQ[d, c] + cb * DV[d, c]
    for k in range(sp_el.shape[0]):
        ex = sp_el[k, 0]
        ey = sp_el[k, 1]
        for c in range(nc):
            ax = 0.0
            bx = 0.0
            for j in range(v_ptr[ex], v_ptr[ex + 1]):
                ax += v_coef[j] * DQ[v_dof[j], c]
                bx += v_coef[j] * DV[v_dof[j], c]
            ay = 0.0
            by = 0.0
            for j in range(v_ptr[ey], v_ptr[ey + 1]):
                ay += v_coef[j] * DQ[v_dof[j], c]
                by += v_coef[j] * DV[v_dof[j], c]
            DF[ex, c] = spt[k, 0] * ax + spt[k, 1] * ay + spt[k, 4] * bx + spt[k, 5] * by
            DF[ey, c] = spt[k, 2] * ax + spt[k, 3] * ay + spt[k, 6] * bx + spt[k, 7] * by
    for el in range(ne):
        for j in range(v_ptr[el], v_ptr[el + 1]):
            cf = v_coef[j]
            d = v_dof[j]
            for c in range(nc):
                OUT[d, c] -= cf * DF[el, c]
    for i in range(fr_el.shape[0]):
        e = fr_el[i]
        slope = fps[i]
        if slope == 0.0:
            continue
        for j in range(fr_ptr[i], fr_ptr[i + 1]):
            cf = fr_coef[j] * frv[fr_row[j]] * slope
            d = fr_dof[j]
            for c in range(nc):
                OUT[d, c] -= cf * DF[e, c]
    for i in range(n):
        im = inv_mass[i]
        for c in range(nc):
            OUT[i, c] *= im


@_kernel
def sample_linearise(ts, Y, m, w, F, KD, CR, SPT, FRV, FPS):
    """The slopes of every element law at each sample (see the module legend); ``F``
    gets the element forces."""
    s0 = np.int64(0)
    n2 = Y.shape[1]
    WY = w.Y
    for j in range(ts.shape[0]):
        excite(ts[j], s0, np.int64(-1), m, w)
        for k in range(n2):
            WY[Y_STATE, k] = Y[j, k]
        _linearise(s0, Y_STATE, m, w, F[j], KD[j], CR[j], SPT[j], FRV[j], FPS[j])


@_kernel
def sample_jvp(m, KD, CR, SPT, FRV, FPS, dQ, dV, out, df):
    """``out[c, j] = A_q(t_j) dQ[c, j] + A_v(t_j) dV[c, j]`` for every direction c and
    sample j (arrays (n_dir, n_samples, n)); ``df`` scratch (ne,)."""
    nd, N, n = dQ.shape
    # one column each: views made once (a reshape per sample costs more than its jvp)
    DQ = dQ.reshape((nd, N, n, 1))
    DV = dV.reshape((nd, N, n, 1))
    OUT = out.reshape((nd, N, n, 1))
    DF = df.reshape((df.shape[0], 1))
    for c in range(nd):
        for j in range(N):
            _jvp(m, KD[j], CR[j], SPT[j], FRV[j], FPS[j], DQ[c, j], DV[c, j], OUT[c, j], DF)


@njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True,
      no_cfunc_wrapper=True)  # (called from the kernels only: no Python entry to compile)
def _var_stage(slot, iy, idy, m, w, rhs_fn, gen, extra, Pin, Pout, force, kd, cr, spt,
               frv, fps, DF):
    """One stage of the state (row idy of w.Y) and of its variations:
    Pout[:, c] = A(t, y) Pin[:, c] for every column c (first-order form); ``DF``
    scratch (ne, n_col)."""
    _stage(slot, iy, idy, F_MAIN, m, w, rhs_fn, gen, extra)
    if Pin.shape[1] == 0:  # the state alone
        return
    _linearise(slot, iy, m, w, force, kd, cr, spt, frv, fps)
    n = m.inv_mass.shape[0]
    for i in range(n):
        for c in range(Pin.shape[1]):
            Pout[i, c] = Pin[n + i, c]
    _jvp(m, kd, cr, spt, frv, fps, Pin[:n], Pin[n:], Pout[n:], DF)


@_inline
def _var_trial(w, k_row, Phi, K, PT, scale):
    """Trial state y + scale k (row Y_TRIAL of w.Y) and variations Phi + scale K (PT)."""
    Y = w.Y
    for k in range(Y.shape[1]):
        Y[Y_TRIAL, k] = Y[Y_STATE, k] + scale * Y[k_row, k]
        for c in range(PT.shape[1]):
            PT[k, c] = Phi[k, c] + scale * K[k, c]


@_inline
def _var_step(t_mid, t_end, hs, sa, sb, m, w, rhs_fn, gen, extra, Phi, S, force, kd, cr,
              spt, frv, fps, DF):
    """One classic RK4 step of length hs of the state (row Y_STATE) and its variations
    Phi, from the excitation already in slot ``sa`` to t_end (into slot ``sb``), midpoint
    t_mid (slot 1), both evaluated exactly: the arithmetic of ``_kernels._rk4_step``.
    Returns True if the state became non-finite."""
    Y = w.Y
    n2 = Y.shape[1]
    nc = Phi.shape[1]
    s0 = sa
    s1 = np.int64(1)
    s2 = sb
    # rows as int64 variables: literal rows would compile _var_stage once per value
    y_state = np.int64(Y_STATE)
    y_trial = np.int64(Y_TRIAL)
    k1 = np.int64(Y_K1)
    k2 = np.int64(Y_K1 + 1)
    k3 = np.int64(Y_K1 + 2)
    k4 = np.int64(Y_K1 + 3)
    hh = 0.5 * hs
    K1, K2, K3, K4, PT = S[0], S[1], S[2], S[3], S[4]
    _var_stage(s0, y_state, k1, m, w, rhs_fn, gen, extra, Phi, K1, force, kd, cr, spt, frv,
               fps, DF)
    excite(t_mid, s1, np.int64(-1), m, w)
    _var_trial(w, k1, Phi, K1, PT, hh)
    _var_stage(s1, y_trial, k2, m, w, rhs_fn, gen, extra, PT, K2, force, kd, cr, spt, frv,
               fps, DF)
    _var_trial(w, k2, Phi, K2, PT, hh)
    _var_stage(s1, y_trial, k3, m, w, rhs_fn, gen, extra, PT, K3, force, kd, cr, spt, frv,
               fps, DF)
    excite(t_end, s2, np.int64(-1), m, w)
    _var_trial(w, k3, Phi, K3, PT, hs)
    _var_stage(s2, y_trial, k4, m, w, rhs_fn, gen, extra, PT, K4, force, kd, cr, spt, frv,
               fps, DF)
    h6 = hs / 6.0
    bad = False
    for k in range(n2):
        Y[Y_STATE, k] += h6 * (Y[k1, k] + 2.0 * (Y[k2, k] + Y[k3, k]) + Y[k4, k])
        if not np.isfinite(Y[Y_STATE, k]):
            bad = True
        for c in range(nc):
            Phi[k, c] += h6 * (K1[k, c] + 2.0 * (K2[k, c] + K3[k, c]) + K4[k, c])
    return bad


@_inline
def _next_step(corners, t_corner, t, tb, ts, h):
    """The next (sub-)step of the step from t to tb, from ts: ``(te, go, t_mid, hs)``,
    its end, whether to take it (a sub-step ending within MERGE h of ts is skipped), its
    midpoint and length.  A plain step (no ``corners``) is t + h/2 and h as they are;
    through corners each sub-step ends on the next one (:func:`sub_step_end`).  Shared by
    :func:`rk4_variational` and :func:`rk4_samples`, which take both kinds of step
    through one call of the step (inlined once: faster cold compile)."""
    if corners:
        te = sub_step_end(t_corner, tb, h)
        return te, te - ts > MERGE * h, ts + 0.5 * (te - ts), te - ts
    return tb, True, t + 0.5 * h, h


@njit(cache=True, error_model="numpy", _nrt=False, nogil=True)  # threads: column blocks
def rk4_variational(t0, h, n_steps, m, w, rhs_fn, gen, Phi, S, force, kd, cr, spt, frv,
                    fps, DF):
    """Classic RK4 from state row Y_STATE of w.Y and variations ``Phi`` (2n, n_col) over
    ``n_steps`` steps of ``h`` from ``t0``, both advanced in place, stepping through the
    tables' corners in the sub-steps :func:`rk4_samples` takes: the variations obey the
    RK4 discretisation of dPhi/dt = A(t, y(t)) Phi, so Phi is the exact derivative of
    the discrete period map that shooting solves for (and its Floquet multipliers those
    of that map).  ``S`` scratch (5, 2n, n_col), ``DF`` (ne, n_col).
    Returns 0, or 1 if the state became non-finite."""
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    t_corner = math.inf
    if m.corner_node.shape[0] > 0 and n_steps > 0:
        t_corner = first_corners(t0, m, w)
    a = np.int64(0)  # slot of the excitation at the current time
    b = np.int64(2)
    excite(t0, a, np.int64(-1), m, w)
    for it in range(n_steps):
        t = t0 + it * h
        tb = t0 + (it + 1) * h
        corners = t_corner < tb
        ts = t
        while True:
            te, go, t_mid, hs = _next_step(corners, t_corner, t, tb, ts, h)
            if go:
                if _var_step(t_mid, te, hs, a, b, m, w, rhs_fn, gen, extra, Phi, S, force,
                             kd, cr, spt, frv, fps, DF):
                    return 1
                a, b = b, a
                ts = te
            if te >= tb:
                break
            t_corner = advance_corners(te, m, w)
        if corners:
            if ts < tb:  # the last corner fell within MERGE h of tb
                excite(tb, a, np.int64(-1), m, w)
            t_corner = advance_corners(tb, m, w)
    return 0


@_inline
def _keep(row, t, w, out_t, out_y, out_f, out_d):
    """Time, state (row Y_STATE), forces and deformations (row F_MAIN) into row ``row``
    of the outputs while they have rows; returns the next row."""
    if row >= out_t.shape[0]:
        return row
    Y, F, D = w.Y, w.F, w.D
    out_t[row] = t
    for k in range(out_y.shape[1]):
        out_y[row, k] = Y[Y_STATE, k]
    for e in range(out_f.shape[1]):
        out_f[row, e] = F[F_MAIN, e]
        out_d[row, e] = D[F_MAIN, e]
    return row + 1


@_kernel
def rk4_samples(t0, h, n_steps, every, m, w, rhs_fn, gen, out_t, out_y, out_f, out_d, c_t,
                c_y, c_f, c_d, track, fine_f, fine_d):
    """Classic RK4 from state row Y_STATE over ``n_steps`` steps of ``h`` from ``t0``, as
    ``_kernels.rk4_run`` steps: the excitation exact at each distinct stage time, and a
    step that holds corners of the tables taken in sub-steps that end on them (so that no
    step straddles a kink of the right-hand side, which would cost RK4 its order).
    Every ``every`` steps (and at the start) the time, state, element forces and
    deformations are stored in ``out_*`` while they have rows; the forces and
    deformations of the elements ``track`` at every step in ``fine_*`` while they have
    rows; the time, forces and deformations at every corner in ``c_t``, ``c_f``, ``c_d``
    while they have rows (the state in ``c_y`` too while it has rows).  Returns (rows, corner rows), rows -1
    if the state became non-finite."""
    Y, F, D = w.Y, w.F, w.D
    n2 = Y.shape[1]
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    minus = np.int64(-1)
    s_half = np.int64(1)
    a = np.int64(0)  # slot of the excitation at the current time
    b = np.int64(2)
    row = 0
    crow = 0
    n_fine = fine_f.shape[0]
    t_corner = math.inf
    if m.corner_node.shape[0] > 0 and n_steps > 0:
        t_corner = first_corners(t0, m, w)
    state_limits(NO_BLOWUP, w)
    excite(t0, a, minus, m, w)
    for it in range(n_steps + 1):
        t = t0 + it * h
        _stage(a, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)
        if it % every == 0:
            row = _keep(row, t, w, out_t, out_y, out_f, out_d)
        if it < n_fine:
            for j in range(track.shape[0]):
                fine_f[it, j] = F[F_MAIN, track[j]]
                fine_d[it, j] = D[F_MAIN, track[j]]
        if it == n_steps:
            break
        tb = t0 + (it + 1) * h
        corners = t_corner < tb
        ts = t
        first = True
        while True:
            te, go, t_mid, hs = _next_step(corners, t_corner, t, tb, ts, h)
            if corners:
                if not first:  # at a corner: its forces, and k1 of the next sub-step
                    _stage(a, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)
                    if crow < c_t.shape[0]:
                        c_t[crow] = ts
                        if crow < c_y.shape[0]:
                            for k in range(n2):
                                c_y[crow, k] = Y[Y_STATE, k]
                        for e in range(c_f.shape[1]):
                            c_f[crow, e] = F[F_MAIN, e]
                            c_d[crow, e] = D[F_MAIN, e]
                        crow += 1
            if go:
                _rk4_step(t_mid, te, hs, s_half, b, minus, minus, m, w, rhs_fn, gen, extra)
                a, b = b, a
                ts = te
                first = False
            if te >= tb:
                break
            t_corner = advance_corners(te, m, w)
        if corners:
            if ts < tb:  # the last corner fell within MERGE h of tb
                excite(tb, a, minus, m, w)
            t_corner = advance_corners(tb, m, w)
        if bad_state(Y_STATE, w) >= 0:
            return -1, crow
    return row, crow
