"""Compiled kernels of the dynamic solver: every ``@njit(cache=True)`` loop lives here.

Each kernel's docstring names the readable Python twin it mirrors (in
:mod:`torquesplit.solve.reference`); tests check that the two agree.  Element force
laws are not written here: they come from :mod:`torquesplit.solve.laws`, inlined.
Nothing allocates inside a step loop; the scratch is one :class:`~.kernel_data.Work`
bundle per run.

Data (see :mod:`torquesplit.solve.kernel_data`): ``m`` the model
(:class:`KernelModel`), ``w`` the scratch (:class:`Work`), ``r`` the outputs
(:class:`Record`).  Legend of the short names used inside kernels:

n        number of DOFs; a state row of ``w.Y`` is ``[q (n), v (n)]``
ne       number of elements
slot     excitation slot (row of w.K, w.P, w.G, w.E, w.ED, w.CY, w.S, w.C, w.FR)
iy idy   rows of w.Y: the state a right-hand side reads and where it writes dy/dt
i_f      row of w.F / w.D where it writes the element forces and deformations
gen      a generated right-hand side ``rhs_fn`` replaces :func:`rhs_slot`

Time of step ``i`` is always computed as ``t0 + i * h`` (never accumulated), so a run
split into chunks whose sizes are multiples of :data:`RESYNC` reproduces the unsplit run
bit for bit.

One stage evaluation, :func:`_stage`, serves both integrators: the model's generated
straight-line code (:mod:`torquesplit.solve.codegen`, called through the first-class
function ``rhs_fn`` with data addresses computed from ``w.addr``) or the general
element loop :func:`rhs_slot`, then :func:`rhs_extra` for splines and tooth friction when
the model has them.  ``_stage`` is inlined by numba (a first-class function passed on to
a compiled callee costs about 150 ns per call; ``array.ctypes`` per call an atomic
reference-count pair per array: both measured, hence the precomputed addresses).

Compilation flags: ``error_model="numpy"`` only (no Python zero-division checks; the
inputs are validated in Python).  No fastmath: besides keeping NaN/inf checks valid,
even ``contract`` (FMA) would make the excitation phases ``f t + phase`` round
differently from their numpy twins, and numba compiles a callee with the flags of its
first caller, so flags cannot be confined to a few kernels.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from torquesplit._jit_cache import track_imports
from torquesplit.solve import laws
from torquesplit.solve.kernel_data import (
    A_D,
    A_F,
    A_SELF,
    A_Y,
    DENSE_HEAD,
    F_MAIN,
    F_TMP,
    SLOT_EVENT,
    Y_DSAMPLE,
    Y_K1,
    Y_KFSAL,
    Y_NEW,
    Y_SAMPLE,
    Y_STATE,
    Y_TRIAL,
)

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

# ----------------------------------------------------------------- status codes
FINISHED = 0
DIVERGED = 1
STEP_UNDERFLOW = 2
MAX_STEPS = 3

# ----------------------------------------------------- int64 counters (in/out)
I_STATUS = 0
I_STEPS = 1
I_REJECTED = 2
I_RHS = 3
I_SAMPLES = 4  # accepted states entered in the statistics
I_HIST = 5  # rows written to the history arrays
I_FULL = 6  # rows written to the full-state arrays
I_NEXT = 7  # dopri: index of the next uniform sample time
I_BAD = 8  # index into y of the state that diverged
I_FSAL = 9  # dopri: 1 when Y_KFSAL holds f(t, y) of the current state
I_LAST_REJECTED = 10  # dopri: the previous attempt was rejected
I_EVENTS = 11  # corners sampled (see record_extrema)
N_COUNTERS = 12

# ---------------------------------------------------- float64 clock (in/out)
F_T = 0  # time of the current state
F_H = 1  # dopri: proposed next step
F_FACOLD = 2  # dopri: previous accepted error norm (PI control)
F_HMIN = 3  # dopri: smallest accepted step
F_HMAX = 4  # dopri: largest accepted step
N_CLOCK = 5

MESH_KIND = 1
_FLOAT_MAX = 1.7976931348623157e308  # the largest finite float64
CYCLE_EPS = laws.CYCLE_EPS
RESYNC = 64
"""RK4 recomputes the error sinusoids exactly every RESYNC steps (phasor rotation between)."""
# Slot and row indices are passed as int64 variables (np.int64(k)) where a callee is not
# inlined: numba would compile one copy of the callee per literal value.

# Dormand & Prince 5(4) (Hairer, Norsett & Wanner, Solving ODE I, table 5.2)
_C2, _C3, _C4, _C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
_A21 = 1.0 / 5.0
_A31, _A32 = 3.0 / 40.0, 9.0 / 40.0
_A41, _A42, _A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
_A51, _A52, _A53, _A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
_A61, _A62, _A63 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0
_A64, _A65 = 49.0 / 176.0, -5103.0 / 18656.0
_B1, _B3, _B4 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0
_B5, _B6 = -2187.0 / 6784.0, 11.0 / 84.0
_E1, _E3, _E4 = 71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0
_E5, _E6, _E7 = -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0
# step-size control (Hairer's DOPRI5 defaults, PI control)
_SAFE = 0.9
_FAC_MIN = 0.2  # largest decrease: h_new >= 0.2 h
_FAC_MAX = 10.0  # largest increase: h_new <= 10 h
_BETA = 0.04
_EXPO1 = 0.2 - _BETA * 0.75

# A kernel called from Python (integrate, the steady-state solvers, tests).
_kernel = njit(cache=True, error_model="numpy", _nrt=False)
# A kernel called only from other kernels: without the Python and C entry points numba
# otherwise compiles for every function.  The Python one unboxes the bundles (m alone
# holds 44 arrays) and cost more LLVM time than most of these functions' bodies: the
# first RK4 run's compilation went from about 19-21 s to 12-15 s
# (benchmarks/bench_compile.py).  Called from Python, one of these crashes the
# interpreter: tests/solve/test_kernel_entry_points.py keeps Python code from it.
_inner = njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True,
              no_cfunc_wrapper=True)
_inline = njit(inline="always", error_model="numpy", _nrt=False)
# An ordinary compiled callee (LLVM may still inline it), called from kernels only (no
# entry points, as _inner): excite is large and is called from four places, and
# inlining it in numba's IR cost 8 s of cold compile for no measurable speed
# (benchmarks/bench_compile.py, bench_engine.py).
_callee = njit(error_model="numpy", _nrt=False, no_cpython_wrapper=True,
               no_cfunc_wrapper=True)


# =================================================================== excitation
@_callee
def excite(t, slot, src, m, w):
    """Every time-dependent excitation at t into ``slot``.

    Time-varying tables (stiffness, additive force, friction) are interpolated at the
    mesh phase s = f t + phase (:func:`laws.table_phase`; the elements ``m.tv_el``
    after the first ``m.tv_tab[0]`` have constant tables, already in every slot, and
    need only their cycle: -7 % on Lin & Parker's planetary step); the half-gap is entry
    floor(s) mod n_gaps of the element's per-cycle sequence (cached in ``w.gap_cyc`` /
    ``w.gap_val``); CY is the statistics cycle index (:func:`laws.stat_cycle`).  Error
    sinusoids are evaluated exactly when ``src < 0``, else advanced from slot ``src``
    by the phasor rotation ``w.rot`` (cos, sin of omega dt).
    Twin: :func:`torquesplit.solve.reference.excitation_numpy`.
    """
    # every array is taken out of its bundle once, before the loops: an attribute of a
    # bundle read inside a loop costs an atomic reference-count pair per read (measured:
    # five times slower steps)
    K, P, G, CY, FR = w.K, w.P, w.G, w.CY, w.FR
    E, ED, S, C, rot = w.E, w.ED, w.S, w.C, w.rot
    gap_cyc, gap_val, has_force = w.gap_cyc, w.gap_val, w.has_force
    tv_el, frequency, phase = m.tv_el, m.frequency, m.phase
    ktab, ftab, frtab = m.stiffness_table, m.force_table, m.friction_table
    gap_ptr, gap_values, fr_el = m.gap_ptr, m.gap_values, m.fr_el
    err_el, error_constant, sin_el = m.err_el, m.error_constant, m.sin_el
    error_omega, error_phase, error_amplitude = m.error_omega, m.error_phase, m.error_amplitude
    n_tab = ktab.shape[1]
    # indices as uint64: numba then emits no negative-index wraparound per access
    # (Liu et al. 2021's step: -10 %, Ji & Li's -4.5 %; they are non-negative by
    # construction)
    us = np.uint64(slot)
    n_tables = m.tv_tab[0]
    for j in range(tv_el.shape[0]):
        e = np.uint64(tv_el[j])
        s = frequency[e] * t + phase[e]
        if j < n_tables:
            i0, i1, wt, fl = laws.table_phase(s, n_tab)
            u0 = np.uint64(i0)
            u1 = np.uint64(i1)
            K[us, e] = laws.lerp(ktab[e, u0], ktab[e, u1], wt)
            if has_force[e]:
                P[us, e] = laws.lerp(ftab[e, u0], ftab[e, u1], wt)
        else:  # constant tables (in every slot since make_work): the cycle only
            fl = math.floor(s)
        CY[us, e] = laws.stat_cycle(s, fl)
        g0 = gap_ptr[e]
        ng = gap_ptr[e + np.uint64(1)] - g0
        if ng > 1:  # one half-gap: constant, set in every slot by make_work
            c = np.int64(fl)
            if c != gap_cyc[e]:
                k = c % ng
                if k < 0:
                    k += ng
                gap_cyc[e] = c
                gap_val[e] = gap_values[np.uint64(g0 + k)]
            G[us, e] = gap_val[e]
    n_fr = frtab.shape[1]
    for j in range(fr_el.shape[0]):
        e = np.uint64(fr_el[j])
        s = frequency[e] * t + phase[e]
        i0, i1, wt, _ = laws.table_phase(s, n_fr)
        u0 = np.uint64(i0)
        u1 = np.uint64(i1)
        for row in range(3 * j, 3 * j + 3):
            ur = np.uint64(row)
            FR[us, ur] = laws.lerp(frtab[ur, u0], frtab[ur, u1], wt)
    for j in range(err_el.shape[0]):
        e = np.uint64(err_el[j])
        E[us, e] = error_constant[e]
        ED[us, e] = 0.0
    us_src = np.uint64(src)
    for i in range(sin_el.shape[0]):
        ui = np.uint64(i)
        if src < 0:
            arg = error_omega[ui] * t + error_phase[ui]
            s1 = math.sin(arg)
            c1 = math.cos(arg)
        else:
            s0 = S[us_src, ui]
            c0 = C[us_src, ui]
            s1 = s0 * rot[0, ui] + c0 * rot[1, ui]
            c1 = c0 * rot[0, ui] - s0 * rot[1, ui]
        S[us, ui] = s1
        C[us, ui] = c1
        e = np.uint64(sin_el[ui])
        a = error_amplitude[ui]
        E[us, e] += a * s1
        ED[us, e] += a * error_omega[ui] * c1


@_inner
def copy_slot(src, dst, w):
    """Copy the excitation of slot ``src`` into slot ``dst`` (same time)."""
    K, P, G, E, ED, CY, FR, S, C = w.K, w.P, w.G, w.E, w.ED, w.CY, w.FR, w.S, w.C
    for e in range(K.shape[1]):
        K[dst, e] = K[src, e]
        P[dst, e] = P[src, e]
        G[dst, e] = G[src, e]
        E[dst, e] = E[src, e]
        ED[dst, e] = ED[src, e]
        CY[dst, e] = CY[src, e]
    for row in range(FR.shape[1]):
        FR[dst, row] = FR[src, row]
    for i in range(S.shape[1]):
        S[dst, i] = S[src, i]
        C[dst, i] = C[src, i]


# ======================================================================== rhs
@_inner
def rhs_slot(slot, iy, idy, i_f, m, w):
    """Row ``idy`` of w.Y = dy/dt = [v, a] at state row ``iy`` for excitation ``slot``.

    a = M^-1 (F_ext - C_g v - sum_e V_e f_e - G v - K_f q); element e: delta = V.q - e,
    rate = V.v - e', force :func:`laws.spring_force` (k, c, delta, rate, half-gap) plus
    the additive force p.  Writes the forces and deformations into row ``i_f`` of w.F /
    w.D.  V is read by element (CSR, unsigned indices into the state) and, for the
    generalized forces, by DOF (a gather per DOF, no scatter).  Spline component
    elements have zero stiffness and damping here (force 0); :func:`rhs_extra`, which
    :func:`_stage` calls after this one where the model has splines or tooth friction,
    adds them.
    Twin: :func:`torquesplit.solve.reference.rhs_numpy` (with :func:`rhs_extra`).
    """
    Y, force, defl = w.Y, w.F, w.D
    K, P, G, E, ED = w.K, w.P, w.G, w.E, w.ED
    v_coef, vq_idx, vv_idx, vr_ptr = m.v_coef, m.vq_idx, m.vv_idx, m.vr_ptr
    damping, inv_mass = m.damping, m.inv_mass
    external_force, ground_damping = m.external_force, m.ground_damping
    vt_ptr, vt_el, vt_coef = m.vt_ptr, m.vt_el, m.vt_coef
    gy_ptr, gy_idx, gy_coef = m.gy_ptr, m.gy_idx, m.gy_coef
    fs_ptr, fs_idx, fs_coef = m.fs_ptr, m.fs_idx, m.fs_coef
    n = inv_mass.shape[0]
    for el in range(vr_ptr.shape[0] - 1):
        d = -E[slot, el]
        r = -ED[slot, el]
        for j in range(vr_ptr[el], vr_ptr[el + 1]):
            cf = v_coef[j]
            d += cf * Y[iy, vq_idx[j]]
            r += cf * Y[iy, vv_idx[j]]
        fe, _, _ = laws.spring_force(K[slot, el], damping[el], d, r, G[slot, el])
        force[i_f, el] = fe + P[slot, el]
        defl[i_f, el] = d
    for i in range(n):
        vi = Y[iy, n + i]
        acc = external_force[i] - ground_damping[i] * vi
        for j in range(vt_ptr[i], vt_ptr[i + 1]):
            acc -= vt_coef[j] * force[i_f, vt_el[j]]
        for j in range(gy_ptr[i], gy_ptr[i + 1]):
            acc -= gy_coef[j] * Y[iy, gy_idx[j]]
        for j in range(fs_ptr[i], fs_ptr[i + 1]):
            acc -= fs_coef[j] * Y[iy, fs_idx[j]]
        Y[idy, i] = vi
        Y[idy, n + i] = inv_mass[i] * acc


@_inner
def rhs_extra(slot, iy, idy, i_f, m, w):
    """Spline radial elements and tooth friction, after :func:`rhs_slot` (called only for
    models that have them, so others run exactly the arithmetic they always ran).
    The generated code writes both out itself, in the same order.

    Each spline gets its radial law (:func:`laws.spline_force` on the relative
    displacement given by the projection rows of its two component elements), which
    overwrites their forces and deformations, and adds -M^-1 V_e f_e of both (rhs_slot
    saw them with zero stiffness).  Each friction mesh adds -M^-1 W_e(s) max(f_e, 0)
    (:func:`laws.positive_part`: friction on the working flank only).
    Twin: the spline and friction parts of :func:`torquesplit.solve.reference.rhs_numpy`.
    """
    Y, force, defl, E, ED = w.Y, w.F, w.D, w.E, w.ED
    v_ptr, vq_idx, vv_idx, v_coef = m.vr_ptr, m.vq_idx, m.vv_idx, m.v_coef
    inv_mass, sp_el, sp_par, FR = m.inv_mass, m.sp_el, m.sp_par, w.FR
    fr_el, fr_ptr, fr_dof, fr_coef, fr_row = m.fr_el, m.fr_ptr, m.fr_dof, m.fr_coef, m.fr_row
    n = inv_mass.shape[0]
    for j in range(sp_el.shape[0]):
        ex = sp_el[j, 0]
        ey = sp_el[j, 1]
        # the relative displacement less the components' errors (a radial bearing's seat
        # offset and eccentricity; 0 for a spline)
        dx = -E[slot, ex]
        rx = -ED[slot, ex]
        for i in range(v_ptr[ex], v_ptr[ex + 1]):
            dx += v_coef[i] * Y[iy, vq_idx[i]]
            rx += v_coef[i] * Y[iy, vv_idx[i]]
        dyy = -E[slot, ey]
        ry = -ED[slot, ey]
        for i in range(v_ptr[ey], v_ptr[ey + 1]):
            dyy += v_coef[i] * Y[iy, vq_idx[i]]
            ry += v_coef[i] * Y[iy, vv_idx[i]]
        fx, fy = laws.spline_force(dx, dyy, rx, ry, sp_par[j, 0], sp_par[j, 1], sp_par[j, 2],
                                   sp_par[j, 3], sp_par[j, 4], sp_par[j, 5])
        defl[i_f, ex] = dx
        defl[i_f, ey] = dyy
        force[i_f, ex] = fx
        force[i_f, ey] = fy
        for el in (ex, ey):
            fe = force[i_f, el]
            for i in range(v_ptr[el], v_ptr[el + 1]):
                Y[idy, vv_idx[i]] -= inv_mass[vq_idx[i]] * (v_coef[i] * fe)
    for j in range(fr_el.shape[0]):
        fp, _ = laws.positive_part(force[i_f, fr_el[j]])
        if fp > 0.0:
            for i in range(fr_ptr[j], fr_ptr[j + 1]):
                d = fr_dof[i]
                Y[idy, n + d] -= inv_mass[d] * (fr_coef[i] * FR[slot, fr_row[i]] * fp)


@njit(inline="always", error_model="numpy")
def _stage(slot, iy, idy, i_f, m, w, rhs_fn, gen, extra):
    """One right-hand-side evaluation (the only one both integrators use): the
    generated code ``rhs_fn`` (splines and tooth friction included) if ``gen``, else
    :func:`rhs_slot` (which adds :func:`rhs_extra` if the model has splines or tooth
    friction).
    (Called where it is not needed, rhs_extra would still cost the passing of the
    model's arrays: 20 % of a Dong et al. 2021 step.)"""
    if gen:
        a = w.addr
        row = np.uint64(8 * w.Y.shape[1])
        el = np.uint64(8 * w.F.shape[1])
        # six arguments, all passed in registers (the code loads the other addresses
        # from the block at a[A_SELF]): twelve put six on the stack at every call, 3-4 %
        # of an RK4 step (Ji & Li, Liu et al. 2021; benchmarks/README.md)
        rhs_fn(a[A_SELF], a[A_Y] + row * np.uint64(iy), a[A_Y] + row * np.uint64(idy),
               a[A_F] + el * np.uint64(i_f), a[A_D] + el * np.uint64(i_f),
               np.int64(slot * w.F.shape[1]))
    else:
        rhs_slot(slot, np.int64(iy), np.int64(idy), np.int64(i_f), m, w)
        if extra:
            rhs_extra(slot, np.int64(iy), np.int64(idy), np.int64(i_f), m, w)


@_kernel
def evaluate(t, m, w, rhs_fn, gen):
    """One exact evaluation at time t of the state in row Y_STATE: dy/dt into row Y_K1,
    element forces and deformations into row F_MAIN (slot 0; the generated code if
    ``gen``, else the general kernel).
    Twin: :func:`torquesplit.solve.reference.rhs_numpy` and
    :func:`torquesplit.solve.reference.element_forces_numpy`.
    """
    s0 = np.int64(0)
    excite(t, s0, np.int64(-1), m, w)
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    _stage(s0, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)


# ================================================================== recording
@_inline
def start_fraction(c, base, phase, frequency, ta, span):
    """Where the start of cycle c (statistics index + ``base``) of an element of
    ``frequency`` and ``phase`` falls in the interval from ``ta`` of length ``span``: the
    fraction in [0, 1] (1 for an interval of no length)."""
    tb = (c + base - phase) / frequency
    return min(max((tb - ta) / span, 0.0), 1.0) if span > 0.0 else 1.0


@_inline
def enter_both(v, cp, c, j, mx, mn):
    """``v`` (a value at a cycle start) into column j's max ``mx`` and min ``mn`` of both
    cycles it divides, ``cp`` and ``c`` (those within the arrays' rows)."""
    cap = mx.shape[0]
    for cb in (cp, c):
        if cb >= 0 and cb < cap:
            if v > mx[cb, j]:
                mx[cb, j] = v
            if v < mn[cb, j]:
                mn[cb, j] = v


@_inline
def ratio_starts(t, slot, i_f, m, w, r):
    """The instantaneous load-sharing ratio N f_j / sum_i f_i (Ji & Li eq. 18) at each
    cycle start of a group member j between the last instant entered and ``t``, into the
    max and min of both cycles it divides, where j's force is continuous there
    (``r.trk_cont``): every member's force interpolated linearly at that start, as
    :func:`force_instant` does for the force.  Without it the ratio's extremes at a cycle
    start (a ratio still rising as its cycle ends) were missed by up to its slope times
    a step, first order.  Runs before :func:`force_instant` (which overwrites the last
    instant's forces).  Twin: :func:`torquesplit.solve.reference.cycle_ratio_numpy`."""
    force, CY = w.F, w.CY
    track_el, track_base, trk_cont = r.track_el, r.track_base, r.trk_cont
    grp_ptr, grp_col, grp_min = r.grp_ptr, r.grp_col, r.grp_min
    rat_max, rat_min, prev_f, prev_c = r.rat_max, r.rat_min, r.prev_f, r.prev_c
    ta = r.prev_t[0]
    span = t - ta
    if not (span >= 0.0):  # NaN before the first instant: no interval yet
        return
    for g in range(grp_ptr.shape[0] - 1):
        for k in range(grp_ptr[g], grp_ptr[g + 1]):
            j = grp_col[k]
            el = track_el[j]
            c = CY[slot, el] - track_base[j]
            cp = prev_c[j]
            if c != cp + 1 or trk_cont[j] == 0:
                continue
            th = start_fraction(c, track_base[j], m.phase[el], m.frequency[el], ta, span)
            total = 0.0  # (of the loads the teeth carry, as ratio_sample)
            for kk in range(grp_ptr[g], grp_ptr[g + 1]):
                i = grp_col[kk]
                fa = prev_f[i]
                total += laws.positive_part(fa + th * (force[i_f, track_el[i]] - fa))[0]
            if total > grp_min[g]:
                fa = prev_f[j]
                fb = laws.positive_part(fa + th * (force[i_f, el] - fa))[0]
                ratio = (grp_ptr[g + 1] - grp_ptr[g]) * fb / total
                enter_both(ratio, cp, c, j, rat_max, rat_min)


@_inline
def regime(d, g):
    """Contact regime of an element with deformation ``d`` and half-gap ``g``: 1 in
    contact (d > g, or no gap), -1 in back-side contact (d < -g), 0 apart."""
    if g > 0.0:
        if d > g:
            return 1
        if d < -g:
            return -1
        return 0
    return 1


@_inline
def vertex(t0, t1, t2, f0, f1, f2):
    """Value at the vertex of the parabola through (t0, f0), (t1, f1), (t2, f2), t0 < t1
    < t2: f1 - s^2 / (4 a), s its slope at t1, a half its curvature (f1 if a = 0)."""
    d1 = (f1 - f0) / (t1 - t0)
    d2 = (f2 - f1) / (t2 - t1)
    a = (d2 - d1) / (t2 - t0)
    if a == 0.0:
        return f1
    s = (d1 * (t2 - t1) + d2 * (t1 - t0)) / (t2 - t0)
    return f1 - s * s / (4.0 * a)


@_inline
def force_instant(t, kink, full, count, slot, i_f, m, w, r):
    """The forces (row ``i_f``) at the instant ``t`` into the cycles' statistics, one
    pass over the tracked elements (one pass, not one per quantity: each element's
    cycle, force and last instant are loaded once; Ji & Li's step -2 %).  Per element:

    * **extremes**: the force into its cycle's max and min (and, with ``count``, the
      cycle's sample count: a sample of the run, not a corner instant);
    * with ``full`` (an instant of the time record: a step sample or an RK4 corner;
      they come in time order):

      - **the peak between the instants**: where the middle one of the last three is the
        largest (smallest), is not a corner (``kink``: a kink or jump of the force may
        sit there; as an end point it is exact) and all three share one contact regime,
        the vertex of the parabola through them enters the middle instant's cycle
        maximum (minimum).  A peak between two steps was otherwise missed by up to
        (omega h)^2 / 8 of the oscillation (6e-4 of a dynamic factor at 100 steps per
        cycle);
      - **the cycle means**: the time integral by the trapezoid rule over the interval
        from the last instant, split where a cycle of the element begins (the linear
        interpolant integrated on each side, so that a cycle's mean is second order in
        the step; a table ramp steeper than a step or an impact pulse between two steps
        is then integrated, not missed).  Where a cycle begins and the force is
        continuous there (``r.trk_cont``: no corner of its table at node 0,
        :func:`kernel_data.continuous_start`), the force interpolated at that start also
        enters both cycles' max and min (on an instant, that instant's force): a force
        still rising (falling) across the boundary has the ending cycle's extreme there,
        which its samples alone miss by up to its slope times a step (first order:
        constant-stiffness meshes under slower errors, Mo et al. 2017).

    The last instant's forces and cycles (``r.prev_f``, ``r.prev_c``) are then this
    one's.  ``full`` and ``count`` are integers, not literal bools: numba would compile
    one copy per literal value.
    Twin: :func:`torquesplit.solve.reference.cycle_statistics_numpy`."""
    force, defl, CY, G = w.F, w.D, w.CY, w.G
    track_el, track_base, trk_cont = r.track_el, r.track_base, r.trk_cont
    cyc_max, cyc_min, cyc_cnt = r.cyc_max, r.cyc_min, r.cyc_cnt
    cyc_sum, cyc_wt, prev_f, prev_c = r.cyc_sum, r.cyc_wt, r.prev_f, r.prev_c
    pk_t, pk_f, pk_g, pk_k = r.pk_t, r.pk_f, r.pk_g, r.pk_k
    phase, frequency = m.phase, m.frequency
    cap = cyc_max.shape[0]
    # the peaks: the two instants before this one alternate between the slots of pk_t,
    # pk_g, pk_k: o the older, p the last
    n = r.pk_n[0]
    o = n & 1
    p = 1 - o
    smooth = n >= 2 and pk_k[p] == 0
    t0 = pk_t[o]
    t1 = pk_t[p]
    # the means: the interval from the last instant (NaN before the first: no interval)
    ta = r.prev_t[0]
    span = t - ta
    first = not (span >= 0.0)
    for j in range(track_el.shape[0]):
        el = track_el[j]
        c = CY[slot, el] - track_base[j]
        fe = force[i_f, el]
        if c >= 0 and c < cap:
            if fe > cyc_max[c, j]:
                cyc_max[c, j] = fe
            if fe < cyc_min[c, j]:
                cyc_min[c, j] = fe
            if count != 0:
                cyc_cnt[c, j] += 1
        if full == 0:
            continue
        f1 = prev_f[j]  # the last instant's force and cycle
        c1 = prev_c[j]
        # the peak between the instants (f0, f1, fe at t0, t1, t)
        g2 = regime(defl[i_f, el], G[slot, el])
        if smooth:
            f0 = pk_f[j]
            if (f1 - f0) * (fe - f1) <= 0.0 and (f1 != f0 or f1 != fe):  # an extremum
                g1 = pk_g[j, p]
                if g1 != 0 and pk_g[j, o] == g1 and g2 == g1 and c1 >= 0 and c1 < cap:
                    if f1 >= f0 and f1 >= fe:
                        v = vertex(t0, t1, t, f0, f1, fe)
                        if v > cyc_max[c1, j]:
                            cyc_max[c1, j] = v
                    elif f1 <= f0 and f1 <= fe:
                        v = vertex(t0, t1, t, f0, f1, fe)
                        if v < cyc_min[c1, j]:
                            cyc_min[c1, j] = v
        pk_f[j] = f1  # the last instant's force becomes the older one
        pk_g[j, o] = g2
        # the cycle means over the interval from the last instant
        if not first:
            if c == c1 + 1:  # the interval holds the start of cycle c: split it there
                th = start_fraction(c, track_base[j], phase[el], frequency[el], ta, span)
                fb = f1 + th * (fe - f1)
                da = th * span
                db = span - da
                if c1 >= 0 and c1 < cap:
                    cyc_sum[c1, j] += 0.5 * da * (f1 + fb)
                    cyc_wt[c1, j] += da
                if c >= 0 and c < cap:
                    cyc_sum[c, j] += 0.5 * db * (fb + fe)
                    cyc_wt[c, j] += db
                if trk_cont[j] != 0:  # (on an instant too: fb is that force)
                    enter_both(fb, c1, c, j, cyc_max, cyc_min)
            else:  # one cycle (or, past a skipped cycle, half to each end's cycle)
                half = 0.5 * span
                if c1 >= 0 and c1 < cap:
                    cyc_sum[c1, j] += half * f1
                    cyc_wt[c1, j] += half
                if c >= 0 and c < cap:
                    cyc_sum[c, j] += half * fe
                    cyc_wt[c, j] += half
        prev_f[j] = fe
        prev_c[j] = c
    if full != 0:
        pk_t[o] = t
        pk_k[o] = kink
        r.pk_n[0] = n + 1
        r.prev_t[0] = t


@_inline
def ratio_sample(slot, i_f, w, r):
    """The instantaneous load-sharing ratio N f_i / sum_j f_j (Ji & Li eq. 18) of every
    group member at this instant (forces in row ``i_f``) into its cycle's max and min.
    Formed from the loads the teeth carry (:func:`laws.positive_part`: a damping force
    exceeding the elastic one while a mesh separates is no tension of the teeth, and
    would lift another member's ratio above N: Liu et al. 2021's spur stage gave 78 for
    two meshes), and only while the group's total exceeds ``r.grp_min``.
    Twin: :func:`torquesplit.solve.reference.cycle_ratio_numpy`."""
    force, CY = w.F, w.CY
    track_el, track_base = r.track_el, r.track_base
    grp_ptr, grp_col, rat_max, rat_min = r.grp_ptr, r.grp_col, r.rat_max, r.rat_min
    grp_min = r.grp_min
    cap = rat_max.shape[0]
    for g in range(grp_ptr.shape[0] - 1):
        total = 0.0
        for k in range(grp_ptr[g], grp_ptr[g + 1]):
            total += laws.positive_part(force[i_f, track_el[grp_col[k]]])[0]
        if total > grp_min[g]:
            nm = grp_ptr[g + 1] - grp_ptr[g]
            for k in range(grp_ptr[g], grp_ptr[g + 1]):
                j = grp_col[k]
                el = track_el[j]
                c = CY[slot, el] - track_base[j]
                if c >= 0 and c < cap:
                    ratio = nm * laws.positive_part(force[i_f, el])[0] / total
                    if ratio > rat_max[c, j]:
                        rat_max[c, j] = ratio
                    if ratio < rat_min[c, j]:
                        rat_min[c, j] = ratio


@_callee
def enter_instant(t, kink, full, count, slot, i_f, m, w, r):
    """Every statistic of the forces (row ``i_f``) at the instant ``t``: with ``full``
    (an instant of the time record) the load-sharing ratio at the cycle starts passed
    since the last instant (:func:`ratio_starts`, which reads the last instant's forces
    of every group member), then per element its extremes, peak between the instants and
    cycle means (:func:`force_instant`, which replaces the last instant's forces; with
    ``count`` the sample counts), and always the instantaneous ratio
    (:func:`ratio_sample`).  One compiled callee for :func:`record` and
    :func:`record_extrema`: inlined, these were compiled once per call site of those two
    (rk4_run, record_extrema, dopri_run twice), seconds of cold compile each."""
    if full != 0:
        ratio_starts(t, slot, i_f, m, w, r)
    force_instant(t, kink, full, count, slot, i_f, m, w, r)
    ratio_sample(slot, i_f, w, r)


@_callee
def dense_row(t, kink, i_f, force, head, buf, dirs):
    """The instant ``t`` (forces ``force[i_f]``; ``kink`` 1 at a corner of the tables)
    into the dense record ``buf`` of a run that keeps one: each force vector's squared
    magnitude, reduced between chunks (:mod:`~torquesplit.solve.vector_peaks`); a full
    buffer counts the rows lost.  ``head`` (``Record.dense_el``): rows written and lost,
    the numbers of vectors and of pairs, whether corners are entered, the pairs' two
    elements each (a support's x and y: the sum of their squared forces), then the other
    vectors' pointers to their terms, flags (1: distinct unit axes, the sum of the
    squared forces) and terms' elements; ``dirs`` those terms' directions.  A callee
    with its arrays alone, called only where the run keeps vectors: inlined, in
    :func:`record` or in the RK4 loop, it slowed the step of runs without them by 1-4 %
    (same-process A/B)."""
    k = head[0]
    if k >= buf.shape[0]:
        head[1] += 1
        return
    n_v = head[2]
    n_p = head[3]
    buf[k, 0] = t
    buf[k, 1] = kink
    for v in range(n_p):  # (pairs: no pointers, flags or directions to load)
        x = force[i_f, head[DENSE_HEAD + 2 * v]]
        y = force[i_f, head[DENSE_HEAD + 2 * v + 1]]
        buf[k, 2 + v] = x * x + y * y
    n_g = n_v - n_p
    ptr = DENSE_HEAD + 2 * n_p  # vector n_p + g: terms from head[ptr + g], flag below
    el = ptr + 2 * n_g + 1
    for g in range(n_g):
        a0 = head[ptr + g]
        a1 = head[ptr + g + 1]
        if head[ptr + n_g + 1 + g] != 0:
            f = 0.0
            for j in range(a0, a1):
                x = force[i_f, head[el + j]]
                f += x * x
        else:
            sx = 0.0
            sy = 0.0
            sz = 0.0
            for j in range(a0, a1):
                x = force[i_f, head[el + j]]
                sx += x * dirs[j, 0]
                sy += x * dirs[j, 1]
                sz += x * dirs[j, 2]
            f = sx * sx + sy * sy + sz * sz
        buf[k, 2 + n_p + g] = f
    head[0] = k + 1


@_inline
def record(t, slot, i_f, m, w, r, counters):
    """Enter one accepted state at time ``t`` (forces in row ``i_f``) in the statistics.

    Per tracked element j: cycle c = CY - track_base[j] (cycles at or beyond the
    capacity are ignored); force max, min and sample count of the cycle, the peak
    between the samples and its time integral (:func:`force_instant`); per load-sharing
    group the instantaneous ratio N f_i / sum_j f_j of each member (Ji & Li eq. 18) and
    its max and min in the member's cycle.  Contact counters: separation |delta| <= g
    with g > 0; back-side contact delta < -g with g > 0, or delta < 0 for a mesh
    without backlash.  Their times: over the interval since the last sample, delta + g
    and delta - g follow the parabola through the last three samples (the chord for
    the second sample), split where they change sign (:func:`laws.contact_shares`;
    counted by whole steps, the time moved by tens of per cent with the step where the
    back flank is only grazed).
    Twins: :func:`torquesplit.solve.reference.cycle_statistics_numpy`,
    :func:`torquesplit.solve.reference.contact_state_numpy`,
    :func:`torquesplit.solve.reference.contact_times_numpy`.
    """
    defl, G, watch_el = w.D, w.G, w.watch_el
    sep_count, sep_time, back_count, back_time = (r.sep_count, r.sep_time, r.back_count,
                                                  r.back_time)
    element_kind = m.element_kind
    # per element, the last sample's delta + g and delta - g, the one before's delta + g;
    # h0 and h1 the last two intervals between samples (0: none yet)
    last = r.contact_prev
    n_s = counters[I_SAMPLES]
    h1 = t - r.contact_t[0] if n_s > 0 else 0.0
    h0 = r.contact_t[0] - r.contact_t[1] if n_s > 1 else 0.0
    # the parabola's sag over the interval (h1^2 times the second divided difference):
    # k_sag ((lo - lo1) - (lo1 - lo0) k_ratio), 0 without a sample before the interval
    k_sag = h1 / (h0 + h1) if h0 > 0.0 and h1 > 0.0 else 0.0
    k_ratio = h1 / h0 if k_sag != 0.0 else 0.0
    r.contact_t[1] = r.contact_t[0]
    r.contact_t[0] = t
    # the row as an int64 variable: a literal row would compile a second enter_instant
    enter_instant(t, r.pk_x[0], np.int64(1), np.int64(1), slot, np.int64(i_f), m, w, r)
    if r.dense_el[2] > 0:  # (the bearing table's vectors: runs that keep them)
        dense_row(t, r.pk_x[0], np.int64(i_f), w.F, r.dense_el, r.dense, r.dense_dir)
    r.pk_x[0] = 0
    for j in range(watch_el.shape[0]):
        el = watch_el[j]
        g = G[slot, el]
        d = defl[i_f, el]
        state = 0  # 1: separated, 2: back-side contact
        if g > 0.0:
            lo = d + g
            hi = d - g
            if lo < 0.0:
                back_count[el] += 1
                state = 2
            elif hi <= 0.0:
                sep_count[el] += 1
                state = 1
        elif element_kind[el] == MESH_KIND:
            lo = d
            hi = d
            if d < 0.0:
                back_count[el] += 1
                state = 2
        else:  # (a clearance element in a cycle without clearance: no state, no time)
            last[el, 2] = last[el, 0]
            last[el, 0] = d
            last[el, 1] = d
            continue
        lo1 = last[el, 0]
        f_back, f_sep = laws.contact_shares(last[el, 2], lo1, last[el, 1], lo, hi, state,
                                            k_sag, k_ratio)
        if f_back != 0.0:
            back_time[el] += h1 * f_back
        if f_sep != 0.0:
            sep_time[el] += h1 * f_sep
        last[el, 2] = lo1
        last[el, 0] = lo
        last[el, 1] = hi
    counters[I_SAMPLES] += 1


@_inner
def record_extrema(t, mean, slot, i_f, m, w, r):
    """Enter the forces of row ``i_f`` at time ``t`` in the per-cycle max / min of the
    force and of the instantaneous load-sharing ratio (a corner event: an instant, not a
    sample of the run, so no counts or contact time), and with ``mean`` in the cycles'
    time integrals (:func:`force_instant`: RK4's corners come in time order, not
    Dormand-Prince's, taken element by element).  ``mean`` is an integer, not a literal
    bool: numba would compile one copy per literal value.  Twin: the max / min part of
    :func:`record`."""
    # RK4's corners (``mean``): instants in time order, corners among the samples;
    # Dormand-Prince's, element by element: the ratio only, and no parabola across the step
    enter_instant(t, np.int64(1), mean, np.int64(0), slot, i_f, m, w, r)
    # (only where a vector's term has corners: a kink of another element's force does
    # not make a vector's peak, and Ji & Li's supports paid for a row at each of its
    # meshes' 16 corners a cycle.  Dormand-Prince's come element by element, not in time
    # order: the reduction takes no parabola through an instant out of order or a corner,
    # nor through the end of a step that held corners, which its kink marks)
    if r.dense_el[4] != 0:
        dense_row(t, np.int64(1), i_f, w.F, r.dense_el, r.dense, r.dense_dir)
    if mean == 0:
        r.pk_k[(r.pk_n[0] - 1) & 1] = 1
        r.pk_x[0] = 1


@_inner
def first_corners(t, m, w):
    """Set ``w.next_node`` of every element with corners to its first corner node after
    time t (absolute node: cycle x n_table + node); returns the earliest corner time."""
    n_tab = m.stiffness_table.shape[1]
    corner_ptr, corner_node, next_node = m.corner_ptr, m.corner_node, w.next_node
    frequency, phase, track_el = m.frequency, m.phase, m.tv_el
    for j in range(track_el.shape[0]):
        e = track_el[j]
        c0 = corner_ptr[e]
        c1 = corner_ptr[e + 1]
        if c1 == c0:
            continue
        x = (frequency[e] * t + phase[e]) * n_tab
        base = np.int64(math.floor(x / n_tab)) * n_tab
        node = base + corner_node[c0]
        k = c0
        while node <= x:
            k += 1
            if k == c1:
                k = c0
                base += n_tab
            node = base + corner_node[k]
        next_node[e] = node
    return next_corner_time(m, w)


@_inner
def next_corner_time(m, w):
    """Earliest time of the elements' next corners (``w.next_node``); inf if none."""
    n_tab = m.stiffness_table.shape[1]
    corner_ptr, next_node = m.corner_ptr, w.next_node
    frequency, phase, track_el = m.frequency, m.phase, m.tv_el
    earliest = math.inf
    for j in range(track_el.shape[0]):
        e = track_el[j]
        if corner_ptr[e + 1] > corner_ptr[e]:
            tc = (next_node[e] / n_tab - phase[e]) / frequency[e]
            if tc < earliest:
                earliest = tc
    return earliest


@_inline
def _following_corner(node, c0, c1, n_tab, corner_node):
    """The absolute table node (cycle x n_tab + node) of the element's corner after
    ``node``: the next of its corners ``corner_node[c0:c1]`` in the same table cycle, else
    the first of the next cycle."""
    base = (node // n_tab) * n_tab
    p = node - base
    k = c0
    while k < c1 and corner_node[k] <= p:
        k += 1
    if k == c1:
        return base + n_tab + corner_node[c0]
    return base + corner_node[k]


@_inner
def advance_corners(t, m, w):
    """Move every element whose next corner is at or before t to its following corner;
    returns the earliest next corner time."""
    n_tab = m.stiffness_table.shape[1]
    corner_ptr, corner_node, next_node = m.corner_ptr, m.corner_node, w.next_node
    frequency, phase, tv_el = m.frequency, m.phase, m.tv_el
    earliest = math.inf
    for j in range(tv_el.shape[0]):
        e = tv_el[j]
        c0 = corner_ptr[e]
        c1 = corner_ptr[e + 1]
        if c1 == c0:
            continue
        while True:
            node = next_node[e]
            tc = (node / n_tab - phase[e]) / frequency[e]
            if tc > t:
                break
            next_node[e] = _following_corner(node, c0, c1, n_tab, corner_node)
        if tc < earliest:
            earliest = tc
    return earliest


@_inner
def corner_events(t_a, t_b, ya, fa, yb, fb, m, w, r, rhs_fn, gen, counters):
    """Sample the statistics at every corner of an element's force inside the step
    (t_a, t_b) (see ``kernel_data.CORNER_TOL``): the state there by cubic Hermite
    interpolation between rows (ya, fa) and (yb, fb) of w.Y, the excitation exactly, the
    forces by the stage evaluation, then :func:`record_extrema` (Dormand-Prince; RK4
    steps through the corners instead, :func:`rk4_through_corners`).  The largest force
    and load-sharing ratio then do not depend on where the steps fall.  Returns the
    earliest next corner time (the callers skip the call until then)."""
    n_tab = m.stiffness_table.shape[1]
    corner_ptr, corner_node, next_node = m.corner_ptr, m.corner_node, w.next_node
    frequency, phase, track_el = m.frequency, m.phase, m.tv_el
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    h = t_b - t_a
    slot = np.int64(SLOT_EVENT)
    for j in range(track_el.shape[0]):
        e = track_el[j]
        c0 = corner_ptr[e]
        c1 = corner_ptr[e + 1]
        if c1 == c0:
            continue
        while True:
            node = next_node[e]
            tc = (node / n_tab - phase[e]) / frequency[e]
            if tc >= t_b:
                break
            if tc > t_a:
                hermite((tc - t_a) / h, h, ya, fa, yb, fb, np.int64(Y_SAMPLE), w)
                excite(tc, slot, np.int64(-1), m, w)
                _stage(slot, Y_SAMPLE, Y_DSAMPLE, F_TMP, m, w, rhs_fn, gen, extra)
                record_extrema(tc, np.int64(0), slot, np.int64(F_TMP), m, w, r)
                counters[I_EVENTS] += 1
            next_node[e] = _following_corner(node, c0, c1, n_tab, corner_node)
    return next_corner_time(m, w)


@_inner
def store_history(row, t, iy, i_f, w, r):
    """One decimated history row: t, forces of history elements, q and v of DOFs.
    Twin: plain indexing, ``hist_f[row] = force[hist_el]`` etc."""
    Y, F, hist_el, hist_dof = w.Y, w.F, r.hist_el, r.hist_dof
    hist_f, hist_q, hist_v = r.hist_f, r.hist_q, r.hist_v
    n = Y.shape[1] // 2
    r.hist_t[row] = t
    for j in range(hist_el.shape[0]):
        hist_f[row, j] = F[i_f, hist_el[j]]
    for j in range(hist_dof.shape[0]):
        d = hist_dof[j]
        hist_q[row, j] = Y[iy, d]
        hist_v[row, j] = Y[iy, n + d]


@_inner
def store_full(row, t, iy, w, r):
    """One full-state row (when ``full_t`` has room)."""
    Y, full_y = w.Y, r.full_y
    r.full_t[row] = t
    for k in range(Y.shape[1]):
        full_y[row, k] = Y[iy, k]


@_inline
def state_limits(blowup, w):
    """The bounds :func:`bad_state` checks, into ``w.lim``: |q| <= blowup for every
    displacement, |v| <= the largest float (finite) for every velocity."""
    lim = w.lim
    n = lim.shape[0] // 2
    for i in range(n):
        lim[i] = blowup
    for i in range(n, lim.shape[0]):
        lim[i] = _FLOAT_MAX


@_inline
def bad_state(iy, w):
    """Index of the first entry of state row ``iy`` outside its bound in ``w.lim`` (a
    non-finite entry, or |q| > blowup: :func:`state_limits`), or -1.
    Twin: ``np.flatnonzero(~np.isfinite(y) | (abs(q) > blowup))[:1]``."""
    y = w.Y
    lim = w.lim
    # fast path without a branch per entry: one conjunction of comparisons (false for
    # NaN) over the whole row against one bound per entry (a sum of x - x was a chain
    # of dependent additions; one loop per half of the row, each with its own vector
    # set-up, cost 3 % more of Ji & Li's step)
    ok = True
    for i in range(y.shape[1]):
        ok &= abs(y[iy, i]) <= lim[i]
    if ok:
        return -1
    for i in range(y.shape[1]):
        if not abs(y[iy, i]) <= lim[i]:  # also true for NaN
            return i
    return -1


# ======================================================================== RK4
MERGE = 1e-6
"""A corner within MERGE x h of the end of its step (or of the previous corner) takes no
sub-step of its own: every loop through the corners (``rk4_through_corners``, the
steady-state kernels, the GPU source) splits a step by :func:`sub_step_end` alone."""


@_inline
def sub_step_end(t_corner, tb, h):
    """End of the next sub-step of a step ending at tb: the next corner, or tb when that
    corner lies within MERGE h of it."""
    return t_corner if t_corner < tb - MERGE * h else tb


@njit(inline="always", error_model="numpy")
def _rk4_step(t_mid, t_end, hs, s_half, sb, src_half, src_end, m, w, rhs_fn, gen, extra):
    """One classic RK4 step of length hs, the state in row Y_STATE and its derivative
    already in row Y_K1: excitation of the midpoint t_mid into s_half and of t_end into
    sb (phasors rotated from src_half / src_end, or exact when those are -1), stages 2-4,
    the state advanced in place.  The times are passed, not summed, so that step i always
    sees t0 + (i + 1/2) h and t0 + (i + 1) h exactly."""
    Y = w.Y
    n2 = Y.shape[1]
    hh = 0.5 * hs
    # stages 2-4 as one loop: numba then inlines the stage and the excitation call once,
    # not three and two times (the kernels that inline this step compile faster)
    for s in range(3):
        last = s == 2
        if s != 1:  # stage 2 at t + h/2, stage 4 at t + h (stage 3 shares stage 2's)
            excite(t_end if last else t_mid, sb if last else s_half,
                   src_end if last else src_half, m, w)
        c = hs if last else hh
        ks = Y_K1 + s
        for k in range(n2):
            Y[Y_TRIAL, k] = Y[Y_STATE, k] + c * Y[ks, k]
        _stage(sb if last else s_half, Y_TRIAL, ks + 1, F_TMP, m, w, rhs_fn, gen, extra)
    k1 = Y_K1
    k2 = Y_K1 + 1
    k3 = Y_K1 + 2
    k4 = Y_K1 + 3
    h6 = hs / 6.0
    for k in range(n2):
        Y[Y_STATE, k] += h6 * (Y[k1, k] + 2.0 * (Y[k2, k] + Y[k3, k]) + Y[k4, k])


@_inner
def rk4_through_corners(t, tb, t_corner, sa, sb, m, w, r, rhs_fn, gen, counters):
    """The RK4 step from t to tb when corners of the tables fall inside it: sub-steps
    that end exactly on each corner (``kernel_data.CORNER_TOL``), so that no RK4 step
    straddles a kink of the right-hand side (which would cost RK4 its order: the error
    of a step across a corner is first order in the step), and the forces at every
    corner enter the per-cycle extremes (:func:`record_extrema`) from the exact state.
    Excitation exactly at every sub-step time (no phasor rotation).  Returns the slot
    that holds the excitation at tb and the next corner time."""
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    s_half = np.int64(1)
    minus = np.int64(-1)
    h = tb - t
    ts = t
    first = True
    while True:
        te = sub_step_end(t_corner, tb, h)
        if not first:  # the corner: its exact forces, and k1 of the next sub-step
            _stage(sa, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)
            record_extrema(ts, np.int64(1), sa, np.int64(F_MAIN), m, w, r)
            counters[I_RHS] += 1
            counters[I_EVENTS] += 1
        if te - ts > MERGE * h:
            _rk4_step(ts + 0.5 * (te - ts), te, te - ts, s_half, sb, minus, minus, m, w,
                      rhs_fn, gen, extra)
            counters[I_RHS] += 3
            sa, sb = sb, sa
            ts = te
            first = False
        elif first:  # a corner on the step's start: its sample (the last instant) is that corner
            r.pk_k[(r.pk_n[0] - 1) & 1] = 1
            if r.dense_el[0] > 0:  # (and the dense record's last row: its parabola through
                # the corner overshot the corner's force, 2.6e-4 on a rectangular wave)
                r.dense[r.dense_el[0] - 1, 1] = 1.0
        if te >= tb:
            if t_corner <= tb + MERGE * h:  # a corner on the step's end: so is its sample
                r.pk_x[0] = 1
            break
        t_corner = advance_corners(te, m, w)
    if ts < tb:  # the last corner fell within MERGE h of tb: nothing left to step
        excite(tb, sa, minus, m, w)
    return sa, advance_corners(tb, m, w)


@_kernel
def rk4_run(t0, h, n_first, n_steps, record_final, record_every, blowup, m, w, r,
            rhs_fn, gen, counters, clock):
    """Classic fixed-step RK4 over global steps n_first .. n_first + n_steps - 1.

    Step i runs from t0 + i h to t0 + (i + 1) h; the state is row Y_STATE of w.Y,
    advanced in place.  The state at the start of each step is recorded (statistics;
    history when i % record_every == 0; full state while ``r.full_t`` has room); with
    ``record_final`` the end state is recorded too.  A step that contains corners of the
    tables (stiffness waves, impact-force edges, backlash changing at a cycle) is taken
    in sub-steps that end on them (:func:`rk4_through_corners`).  Excitation is
    evaluated once per distinct stage time (t, t + h/2, t + h) and the t + h values are
    reused by the next step; error sinusoids are advanced by phasor rotation and
    recomputed exactly every RESYNC steps (and at sub-steps).  Stops early (status
    DIVERGED) if the state is non-finite or |q| > blowup.
    Twin: :func:`torquesplit.solve.reference.rk4_numpy`.
    """
    rot, error_omega = w.rot, m.error_omega
    state_limits(blowup, w)
    n_hist = r.hist_t.shape[0]
    n_full = r.full_t.shape[0]
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    for i in range(error_omega.shape[0]):
        rot[0, i] = math.cos(error_omega[i] * 0.5 * h)
        rot[1, i] = math.sin(error_omega[i] * 0.5 * h)
    a = np.int64(0)  # slot of t
    b = np.int64(2)  # slot of t + h
    s_half = np.int64(1)  # slot of t + h/2
    t_corner = math.inf  # earliest corner still ahead
    if m.corner_node.shape[0] > 0 and n_steps > 0:
        t_corner = first_corners(t0 + n_first * h, m, w)
    # the next step indices that are multiples of RESYNC and of record_every (counted, not
    # found by an integer division per step)
    next_sync = (n_first // RESYNC + 1) * RESYNC
    every = record_every if record_every > 0 else n_first + n_steps + 1
    next_rec = -(-n_first // every) * every
    # one pass per step, and one more for the end state with ``record_final`` (the same
    # code: numba inlines record and _stage once, not twice, which saves cold compile)
    n_pass = n_steps + 1 if record_final and n_steps > 0 else n_steps
    # steps taken, and those without corners (4 rhs each), counted in locals and written
    # to ``counters`` and ``clock`` once at the end: stores to them at every step cost 2 %
    # of Ji & Li's step (same-process A/B, literal code)
    done = 0
    plain = 0
    for it in range(n_pass):
        i = n_first + it
        t = t0 + i * h
        last = it == n_steps
        if it == 0 or (i == next_sync and not last):
            excite(t, a, np.int64(-1), m, w)
            if i == next_sync:
                next_sync += RESYNC
        # stage 1 at t: its forces are those of the accepted state y(t)
        _stage(a, Y_STATE, Y_K1, F_MAIN, m, w, rhs_fn, gen, extra)
        record(t, a, F_MAIN, m, w, r, counters)
        if i == next_rec:
            next_rec += every
            if record_every > 0 and counters[I_HIST] < n_hist:
                store_history(counters[I_HIST], t, np.int64(Y_STATE), np.int64(F_MAIN), w, r)
                counters[I_HIST] += 1
        if counters[I_FULL] < n_full:
            store_full(counters[I_FULL], t, np.int64(Y_STATE), w, r)
            counters[I_FULL] += 1
        if last:
            break
        tb = t0 + (i + 1) * h
        if t_corner < tb:
            a, t_corner = rk4_through_corners(t, tb, t_corner, a, b, m, w, r, rhs_fn, gen,
                                              counters)
            b = np.int64(2) - a
            counters[I_RHS] += 1
        else:
            _rk4_step(t0 + (i + 0.5) * h, tb, h, s_half, b, a, s_half, m, w, rhs_fn, gen,
                      extra)
            a, b = b, a
            plain += 1
        done += 1
        bad = bad_state(Y_STATE, w)
        if bad >= 0:
            counters[I_STATUS] = DIVERGED
            counters[I_BAD] = bad
            break
    counters[I_STEPS] += done
    counters[I_RHS] += 4 * plain
    if done > 0:
        clock[F_T] = t0 + (n_first + done) * h


# ============================================================== Dormand-Prince
@_inner
def hermite(theta, h, i0, if0, i1, if1, iout, w):
    """Cubic Hermite interpolation between rows (y0, f0) and (y1, f1) of w.Y into row
    ``iout``.  Twin: :func:`torquesplit.solve.reference.hermite_numpy`."""
    Y = w.Y
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + theta) * h
    h01 = 3.0 * t2 - 2.0 * t3
    h11 = (t3 - t2) * h
    for k in range(Y.shape[1]):
        Y[iout, k] = h00 * Y[i0, k] + h10 * Y[if0, k] + h01 * Y[i1, k] + h11 * Y[if1, k]


@_kernel
def dopri_run(t0, t_end, t_stop, rtol, atol, h_max, h_min, max_steps, blowup, dt_sample,
              m, w, r, rhs_fn, gen, counters, clock):
    """Adaptive Dormand-Prince 5(4) with FSAL and PI step-size control (Hairer's DOPRI5).

    Integrates from clock[F_T] until t >= t_stop (never past t_end; the last step is
    shortened to land on t_end), advancing row Y_STATE in place; row Y_KFSAL carries
    f(t, y) between calls (counters[I_FSAL]).  Error norm: RMS of err_i / (atol_i +
    rtol max(|y_i|, |y_new_i|)).  Every accepted state enters the statistics, and so do
    the forces at the corners inside each accepted step (:func:`corner_events`); the
    decimated (and optional full) histories are written at the uniform times
    t0 + k dt_sample by cubic Hermite interpolation between accepted steps.  A run
    that keeps a dense record (:func:`dense_row`) returns when it is half full, for the
    caller to empty it.
    Status: DIVERGED (non-finite or |q| > blowup after an accepted step),
    STEP_UNDERFLOW (h < max(h_min, 10 eps |t|)), MAX_STEPS (accepted steps).
    Twin: :func:`torquesplit.solve.reference.dopri_numpy`.
    """
    Y = w.Y
    n2 = Y.shape[1]
    n_full = r.full_t.shape[0]
    state_limits(blowup, w)
    extra = m.fr_el.shape[0] > 0 or m.sp_el.shape[0] > 0
    t_corner = math.inf  # earliest corner still to be sampled
    if m.corner_node.shape[0] > 0:
        t_corner = first_corners(clock[F_T], m, w)
    # rows as int64 variables (np.int64): a literal row passed to a compiled callee
    # (hermite, corner_events) would compile it once per value
    y_state = np.int64(Y_STATE)
    y_new = np.int64(Y_NEW)
    kf = np.int64(Y_KFSAL)
    k2 = kf + 1
    k3 = kf + 2
    k4 = kf + 3
    k5 = kf + 4
    k6 = kf + 5
    k7 = kf + 6
    s0 = np.int64(0)  # slot of the stages (and of interpolated samples)
    s1 = np.int64(1)  # slot of t + h: the candidate state, then the accepted one
    n_hist = r.hist_t.shape[0]
    t = clock[F_T]
    h = clock[F_H]
    facold = clock[F_FACOLD]
    eps = 2.220446049250313e-16
    # current state: f(t, y) and, at the very start, its sample
    if counters[I_FSAL] == 0:
        excite(t, s1, np.int64(-1), m, w)
        _stage(s1, Y_STATE, kf, F_MAIN, m, w, rhs_fn, gen, extra)
        counters[I_RHS] += 1
        counters[I_FSAL] = 1
        if counters[I_SAMPLES] == 0:
            record(t, s1, F_MAIN, m, w, r, counters)
        while counters[I_NEXT] < n_hist and t0 + counters[I_NEXT] * dt_sample <= t:
            row = counters[I_NEXT]
            store_history(row, t, np.int64(Y_STATE), np.int64(F_MAIN), w, r)
            if row < n_full:
                store_full(row, t, np.int64(Y_STATE), w, r)
                counters[I_FULL] = row + 1
            counters[I_NEXT] = row + 1
            counters[I_HIST] = row + 1
    while t < t_stop:
        if counters[I_STEPS] >= max_steps:
            counters[I_STATUS] = MAX_STEPS
            break
        hs = min(h, h_max)
        last = False
        if t + 1.01 * hs >= t_end:
            if t_end - t <= h_max:
                hs = t_end - t
                last = True
            else:  # two equal steps rather than one full and one tiny
                hs = 0.5 * (t_end - t)
        if hs < max(h_min, 10.0 * eps * abs(t)):
            counters[I_STATUS] = STEP_UNDERFLOW
            clock[F_H] = hs
            break
        # stages 2..6 (slot 0), stage 7 at t + hs (slot 1).  Stages 2-6 as one loop:
        # numba then inlines the stage and the excitation call once, not five times
        # (faster cold compile); each stage's sum is written out as it was
        t_new = t_end if last else t + hs
        for st in range(5):
            if st == 0:
                for k in range(n2):
                    Y[Y_TRIAL, k] = Y[Y_STATE, k] + hs * _A21 * Y[kf, k]
                t_st = t + _C2 * hs
            elif st == 1:
                for k in range(n2):
                    Y[Y_TRIAL, k] = Y[Y_STATE, k] + hs * (_A31 * Y[kf, k] + _A32 * Y[k2, k])
                t_st = t + _C3 * hs
            elif st == 2:
                for k in range(n2):
                    Y[Y_TRIAL, k] = Y[Y_STATE, k] + hs * (_A41 * Y[kf, k] + _A42 * Y[k2, k]
                                                         + _A43 * Y[k3, k])
                t_st = t + _C4 * hs
            elif st == 3:
                for k in range(n2):
                    Y[Y_TRIAL, k] = Y[Y_STATE, k] + hs * (_A51 * Y[kf, k] + _A52 * Y[k2, k]
                                                         + _A53 * Y[k3, k] + _A54 * Y[k4, k])
                t_st = t + _C5 * hs
            else:
                for k in range(n2):
                    Y[Y_TRIAL, k] = Y[Y_STATE, k] + hs * (_A61 * Y[kf, k] + _A62 * Y[k2, k]
                                                         + _A63 * Y[k3, k] + _A64 * Y[k4, k]
                                                         + _A65 * Y[k5, k])
                t_st = t_new
            excite(t_st, s0, np.int64(-1), m, w)
            _stage(s0, Y_TRIAL, k2 + st, F_TMP, m, w, rhs_fn, gen, extra)
        for k in range(n2):
            Y[Y_NEW, k] = Y[Y_STATE, k] + hs * (_B1 * Y[kf, k] + _B3 * Y[k3, k]
                                               + _B4 * Y[k4, k] + _B5 * Y[k5, k]
                                               + _B6 * Y[k6, k])
        # stage 7 (FSAL): same time as stage 6, so the excitation is copied
        copy_slot(s0, s1, w)
        _stage(s1, Y_NEW, k7, F_MAIN, m, w, rhs_fn, gen, extra)
        counters[I_RHS] += 6
        acc = 0.0
        for k in range(n2):
            err = hs * (_E1 * Y[kf, k] + _E3 * Y[k3, k] + _E4 * Y[k4, k] + _E5 * Y[k5, k]
                        + _E6 * Y[k6, k] + _E7 * Y[k7, k])
            sc = atol[k] + rtol * max(abs(Y[Y_STATE, k]), abs(Y[Y_NEW, k]))
            acc += (err / sc) ** 2
        enorm = math.sqrt(acc / n2)
        if not math.isfinite(enorm):
            counters[I_REJECTED] += 1
            counters[I_LAST_REJECTED] = 1
            h = hs * _FAC_MIN
            continue
        fac11 = enorm ** _EXPO1
        if enorm <= 1.0:
            # ------------------------------------------------ accepted
            bad = bad_state(Y_NEW, w)
            if bad >= 0:  # stop before recording anything of this step
                for k in range(n2):
                    Y[Y_STATE, k] = Y[Y_NEW, k]
                t = t_new
                counters[I_STEPS] += 1
                counters[I_STATUS] = DIVERGED
                counters[I_BAD] = bad
                break
            while (counters[I_NEXT] < n_hist
                   and t0 + counters[I_NEXT] * dt_sample <= t_new + 1e-9 * dt_sample):
                row = counters[I_NEXT]
                ts = t0 + row * dt_sample
                theta = (ts - t) / hs
                if theta > 1.0:
                    theta = 1.0
                hermite(theta, hs, y_state, kf, y_new, k7, np.int64(Y_SAMPLE), w)
                excite(ts, s0, np.int64(-1), m, w)
                _stage(s0, Y_SAMPLE, Y_DSAMPLE, F_TMP, m, w, rhs_fn, gen, extra)
                store_history(row, ts, np.int64(Y_SAMPLE), np.int64(F_TMP), w, r)
                if row < n_full:
                    store_full(row, ts, np.int64(Y_SAMPLE), w, r)
                    counters[I_FULL] = row + 1
                counters[I_NEXT] = row + 1
                counters[I_HIST] = row + 1
            if t_corner < t_new:
                t_corner = corner_events(t, t_new, y_state, kf, y_new, k7, m, w, r, rhs_fn,
                                         gen, counters)
            for k in range(n2):
                Y[Y_STATE, k] = Y[Y_NEW, k]
                Y[kf, k] = Y[k7, k]
            t = t_new
            clock[F_T] = t
            counters[I_STEPS] += 1
            if hs < clock[F_HMIN]:
                clock[F_HMIN] = hs
            if hs > clock[F_HMAX]:
                clock[F_HMAX] = hs
            record(t, s1, F_MAIN, m, w, r, counters)
            fac = fac11 / facold ** _BETA
            fac = max(1.0 / _FAC_MAX, min(1.0 / _FAC_MIN, fac / _SAFE))
            h_new = hs / fac
            if counters[I_LAST_REJECTED] == 1 and h_new > hs:
                h_new = hs
            h = h_new
            facold = max(enorm, 1.0e-4)
            counters[I_LAST_REJECTED] = 0
            if r.dense_el[2] > 0 and 2 * r.dense_el[0] >= r.dense.shape[0]:
                break  # (the dense record half full: the caller empties it, calls again)
        else:
            counters[I_REJECTED] += 1
            counters[I_LAST_REJECTED] = 1
            h = hs / min(1.0 / _FAC_MIN, fac11 / _SAFE)
    clock[F_T] = t
    clock[F_H] = h
    clock[F_FACOLD] = facold
