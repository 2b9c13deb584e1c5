"""Compiled kernels of the dynamic solver: every ``@njit(cache=True)`` function lives here.

Each kernel's docstring names the readable Python twin it mirrors (in
:mod:`torquesplit.solve.reference`); tests check that the two agree.  Nothing in this
module allocates inside a step loop; scratch arrays are allocated once per call (one
call = one chunk of a run, see :func:`torquesplit.solve.integrate.integrate`).

Legend (short symbols are used only inside this module)
--------------------------------------------------------
n        number of DOFs; the state is ``y = [q (n), v (n)]``
ne       number of elements
K P G    excitation slots ``(n_slot, ne)``: stiffness [N/m], additive force [N],
         half-gap [m] of each element at one instant
E ED     excitation slots ``(n_slot, ne)``: error [m] and error rate [m/s]
CY       excitation slot ``(n_slot, ne)`` int64: statistics cycle index of s = f t + phase,
         floor(s) counted one up within CYCLE_EPS below the next integer
S C      ``(n_slot, n_sin)``: sin and cos of every error sinusoid's argument
tv_el    elements whose tables vary in time (frequency > 0)
err_el   elements that own at least one error sinusoid
sin_el   owning element of each error sinusoid
gap_cyc  cycle whose half-gap is cached in gap_val (per element)
has_force  elements with a non-zero additive force table
watch_el elements whose contact state is counted (n_watch of them)
vr_ptr vq_idx vv_idx  V by element (CSR), unsigned: row pointers, indices into y
         of the q and of the v entries
vt_*     V by DOF (CSR of V^T): generalized forces are gathered, not scattered
defl     element deformation delta = V.q - e (ne)
fr_*     tooth friction (seed 003): friction meshes fr_el, their sparse force projections
         W (CSR over friction meshes: fr_ptr, fr_dof, fr_coef, fr_row) and the table
         ``friction_table`` (3 rows per friction mesh); empty without friction
FR       excitation slot ``(n_slot, 3 n_fm)``: friction-table values at one instant
sp_el sp_par  spline radial elements (seed 002 eq. 6): the x / y component elements and
         the law (k, c, S1, S2, F_m, v); empty without splines
MODEL    the 36 model arrays, always passed in the order of :data:`MODEL_ARRAYS`
RECORD   the 18 output arrays, always passed in the order of :data:`RECORD_ARRAYS`

Time of step ``i`` is always computed as ``t0 + i * h`` (never accumulated), so a run
split into chunks whose sizes are multiples of :data:`RESYNC` reproduces the unsplit run
bit for bit.

The right-hand side of a model is either :func:`rhs_slot` (the general element loop) or
the same arithmetic generated for the model as straight-line code
(:mod:`torquesplit.solve.codegen`), called through the first-class function ``rhs_fn``
when its parameter vector ``rhs_par`` is not empty, with the data addresses ``ad_*`` of
the arrays taken once per kernel call.  Both choices are measured, not taste: the call
is written out at each call site (``if gen:``) because passing a numba first-class
function on to another compiled function costs about 150 ns per call, and
``array.ctypes`` at each call costs an atomic reference-count increment and decrement
per array (together more than the generated arithmetic; found with perf).

Tooth friction and splines are handled by two kernels of their own,
:func:`excite_friction` and :func:`rhs_extra`, called after :func:`excite_tables` /
:func:`rhs_slot` only when a model has them (``has_fr``, ``extra``); the kernels get zero
stiffness and damping for the spline component elements, so rhs_slot's element loop and
gather are unchanged.  A model without friction or splines runs exactly the arithmetic
it ran before they existed (bit for bit), at the same cost per step.

Compilation flags: ``error_model="numpy"`` only (no Python zero-division checks; the
inputs are validated in Python).  No fastmath: besides keeping NaN/inf checks valid,
even ``contract`` (FMA) would make the excitation phases ``f t + phase`` round
differently from their numpy twins, and numba compiles a callee with the flags of its
first caller, so flags cannot be confined to a few kernels.  Every kernel must
therefore keep the same flags.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

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
I_FSAL = 9  # dopri: 1 when kfsal holds f(t, y) of the current state
I_LAST_REJECTED = 10  # dopri: the previous attempt was rejected
N_COUNTERS = 11

# ---------------------------------------------------- float64 clock (in/out)
F_T = 0  # time of the current state
F_H = 1  # dopri: proposed next step
F_FACOLD = 2  # dopri: previous accepted error norm (PI control)
F_HMIN = 3  # dopri: smallest accepted step
F_HMAX = 4  # dopri: largest accepted step
N_CLOCK = 5

MESH_KIND = 1
_NO_CYCLE = -(2**62)
CYCLE_EPS = 1e-9
"""Cycle index of the statistics: floor(s), plus one when frac(s) >= 1 - CYCLE_EPS, so a
sample at a cycle boundary whose phase s = f t + phase rounds just below the integer
(e.g. 31.99999999999999) counts in the cycle it starts.  Tables and the half-gap
sequence still use floor(s)."""
RESYNC = 64
"""RK4 recomputes the error sinusoids exactly every RESYNC steps (phasor rotation between)."""
# Slot indices are always passed as int64 variables (np.int64(k)), never as literal
# constants: numba would compile one copy of the callee per literal value.

MODEL_ARRAYS = (
    "inv_mass", "external_force", "ground_damping", "element_kind", "v_ptr", "v_dof",
    "v_coef", "stiffness_table", "frequency", "phase", "damping", "gap_ptr",
    "gap_values", "error_constant", "error_ptr", "error_amplitude", "error_omega",
    "error_phase", "force_table", "tv_el", "err_el", "sin_el", "vr_ptr", "vq_idx",
    "vv_idx", "vt_ptr", "vt_el", "vt_coef", "fr_el", "fr_ptr", "fr_dof", "fr_coef",
    "fr_row", "friction_table", "sp_el", "sp_par",
)
RECORD_ARRAYS = (
    "track_el", "track_base", "cyc_max", "cyc_min", "cyc_sum", "cyc_cnt",
    "sep_count", "back_count", "sep_time", "back_time", "hist_el", "hist_dof", "hist_t", "hist_f",
    "hist_q", "hist_v", "full_t", "full_y",
)

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


# =================================================================== excitation
@njit(cache=True, error_model="numpy")
def init_slots(stiffness_table, force_table, gap_ptr, gap_values, error_constant,
               K, P, G, E, ED, CY):
    """Fill every slot with the time-invariant values (table column 0, first gap).

    Twin: :func:`torquesplit.solve.reference.excitation_numpy` for elements with f == 0.
    """
    for s in range(K.shape[0]):
        for e in range(K.shape[1]):
            K[s, e] = stiffness_table[e, 0]
            P[s, e] = force_table[e, 0]
            G[s, e] = gap_values[gap_ptr[e]]
            E[s, e] = error_constant[e]
            ED[s, e] = 0.0
            CY[s, e] = 0


@njit(cache=True, error_model="numpy")
def scratch_flags(element_kind, gap_ptr, gap_values, force_table, has_force, watch_el):
    """Per-element flags computed once per call: ``has_force[e]`` (a non-zero additive
    force table) and the list ``watch_el`` of elements whose contact state is counted
    (a dead zone somewhere in the gap sequence, or a mesh).  Returns len(watch_el).

    Twin: ``np.any(force_table != 0, axis=1)`` and the masks of
    :func:`record_statistics`.
    """
    n_watch = 0
    for e in range(force_table.shape[0]):
        has_force[e] = False
        for i in range(force_table.shape[1]):
            if force_table[e, i] != 0.0:
                has_force[e] = True
                break
        watch = element_kind[e] == MESH_KIND
        for j in range(gap_ptr[e], gap_ptr[e + 1]):
            if gap_values[j] > 0.0:
                watch = True
        if watch:
            watch_el[n_watch] = e
            n_watch += 1
    return n_watch


@njit(cache=True, error_model="numpy")
def excite_tables(t, slot, tv_el, frequency, phase, stiffness_table, force_table,
                  gap_ptr, gap_values, K, P, G, CY, gap_cyc, gap_val, has_force):
    """Stiffness, additive force, half-gap and cycle index of time-varying elements at t.

    Mesh phase s = f t + phase; tables are interpolated linearly and periodically at
    frac(s) * n_table; the half-gap is entry floor(s) mod n_gaps of the per-cycle
    sequence (cached in ``gap_cyc``/``gap_val`` since the cycle changes rarely).  The
    force table is read only where ``has_force`` (see :func:`scratch_flags`); elsewhere
    P keeps its zero from :func:`init_slots`.  CY is the statistics cycle index (floor(s),
    plus one within CYCLE_EPS below the next integer).
    Twin: :func:`torquesplit.solve.reference.excitation_numpy`.
    """
    n_tab = stiffness_table.shape[1]
    for j in range(tv_el.shape[0]):
        e = tv_el[j]
        s = frequency[e] * t + phase[e]
        fl = math.floor(s)
        x = (s - fl) * n_tab
        i0 = int(x)
        w = x - i0
        if i0 >= n_tab:  # s - fl rounded up to 1.0
            i0 -= n_tab
        i1 = i0 + 1
        if i1 == n_tab:
            i1 = 0
        k0 = stiffness_table[e, i0]
        K[slot, e] = k0 + w * (stiffness_table[e, i1] - k0)
        if has_force[e]:
            p0 = force_table[e, i0]
            P[slot, e] = p0 + w * (force_table[e, i1] - p0)
        c = np.int64(fl)
        if s - fl >= 1.0 - CYCLE_EPS:
            CY[slot, e] = c + 1
        else:
            CY[slot, e] = c
        ng = gap_ptr[e + 1] - gap_ptr[e]
        if ng == 1:
            G[slot, e] = gap_values[gap_ptr[e]]
        else:
            if c != gap_cyc[e]:
                m = c % ng
                if m < 0:
                    m += ng
                gap_cyc[e] = c
                gap_val[e] = gap_values[gap_ptr[e] + m]
            G[slot, e] = gap_val[e]


@njit(cache=True, error_model="numpy")
def excite_friction(t, slot, frequency, phase, fr_el, friction_table, FR):
    """Friction-table values of every friction mesh at t: rows 3 j .. 3 j + 2 of friction
    mesh j, interpolated like the stiffness (periodically at frac(s) n_table, s = f t +
    phase of its mesh element).  Called only for models with tooth friction.
    Twin: the friction part of :func:`torquesplit.solve.reference.excitation_numpy`.
    """
    n_fr = friction_table.shape[1]
    for j in range(fr_el.shape[0]):
        e = fr_el[j]
        s = frequency[e] * t + phase[e]
        fl = math.floor(s)
        x = (s - fl) * n_fr
        i0 = int(x)
        w = x - i0
        if i0 >= n_fr:
            i0 -= n_fr
        i1 = i0 + 1
        if i1 == n_fr:
            i1 = 0
        for r in range(3 * j, 3 * j + 3):
            v0 = friction_table[r, i0]
            FR[slot, r] = v0 + w * (friction_table[r, i1] - v0)


@njit(cache=True, error_model="numpy")
def phasors_exact(t, slot, error_omega, error_phase, S, C):
    """sin and cos of omega t + phi for every error sinusoid.

    Twin: the ``np.sin``/``np.cos`` lines of :func:`reference.excitation_numpy`.
    """
    for i in range(error_omega.shape[0]):
        arg = error_omega[i] * t + error_phase[i]
        S[slot, i] = math.sin(arg)
        C[slot, i] = math.cos(arg)


@njit(cache=True, error_model="numpy")
def advance_errors(src, dst, cos_rot, sin_rot, err_el, error_constant, sin_el,
                   error_amplitude, error_omega, S, C, E, ED):
    """Rotate every phasor of slot ``src`` by a fixed time into slot ``dst`` (angle
    omega dt given as cos, sin) and rebuild the errors of ``dst`` from them.

    Twin: :func:`phasors_exact` + :func:`errors_from_phasors` at the later time (equal
    to round-off), i.e. the error part of :func:`reference.excitation_numpy`.
    """
    for j in range(err_el.shape[0]):
        e = err_el[j]
        E[dst, e] = error_constant[e]
        ED[dst, e] = 0.0
    for i in range(sin_el.shape[0]):
        s0 = S[src, i]
        c0 = C[src, i]
        s1 = s0 * cos_rot[i] + c0 * sin_rot[i]
        c1 = c0 * cos_rot[i] - s0 * sin_rot[i]
        S[dst, i] = s1
        C[dst, i] = c1
        e = sin_el[i]
        a = error_amplitude[i]
        E[dst, e] += a * s1
        ED[dst, e] += a * error_omega[i] * c1


@njit(cache=True, error_model="numpy")
def errors_from_phasors(slot, err_el, error_constant, sin_el, error_amplitude,
                        error_omega, S, C, E, ED):
    """e = e_const + sum A sin(.), e' = sum A omega cos(.) from the phasors of a slot.

    Twin: the error part of :func:`torquesplit.solve.reference.excitation_numpy`.
    """
    for j in range(err_el.shape[0]):
        e = err_el[j]
        E[slot, e] = error_constant[e]
        ED[slot, e] = 0.0
    for i in range(sin_el.shape[0]):
        e = sin_el[i]
        a = error_amplitude[i]
        E[slot, e] += a * S[slot, i]
        ED[slot, e] += a * error_omega[i] * C[slot, i]


@njit(cache=True, error_model="numpy")
def excite_exact(t, slot, frequency, phase, stiffness_table, force_table, gap_ptr,
                 gap_values, error_constant, error_amplitude, error_omega, error_phase,
                 tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C, gap_cyc, gap_val,
                 has_force):
    """Every time-dependent excitation at t, sinusoids evaluated exactly.

    Twin: :func:`torquesplit.solve.reference.excitation_numpy`.
    """
    excite_tables(t, slot, tv_el, frequency, phase, stiffness_table, force_table,
                  gap_ptr, gap_values, K, P, G, CY, gap_cyc, gap_val,
                  has_force)
    phasors_exact(t, slot, error_omega, error_phase, S, C)
    errors_from_phasors(slot, err_el, error_constant, sin_el, error_amplitude,
                        error_omega, S, C, E, ED)


# ======================================================================== rhs
@njit(cache=True, error_model="numpy")
def rhs_slot(y, slot, K, P, G, E, ED, inv_mass, external_force, ground_damping,
             v_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
             dy, force, defl):
    """dy = [v, a] with a = M^-1 (F_ext - C_g v - sum_e V_e f_e) for one excitation slot.

    delta = V.q - e, rate = V.v - e', h = dead zone of half-width g (g == 0: h = delta,
    always in contact), f = k h + c rate (only in contact) + p.  Also writes the
    element forces ``force`` and deformations ``defl``.  V is read row-wise (CSR,
    unsigned indices into y for q and v) and, for the generalized forces, column-wise
    (``vt_*``: a gather per DOF, no scatter).  The kernels get zero stiffness and
    damping for spline component elements (their force here is 0); :func:`rhs_extra`
    adds splines and tooth friction.
    Twin: :func:`torquesplit.solve.reference.rhs_numpy` (with :func:`rhs_extra`).
    """
    n = inv_mass.shape[0]
    for el in range(v_ptr.shape[0] - 1):
        d = -E[slot, el]
        r = -ED[slot, el]
        for j in range(v_ptr[el], v_ptr[el + 1]):
            cf = v_coef[j]
            d += cf * y[vq_idx[j]]
            r += cf * y[vv_idx[j]]
        g = G[slot, el]
        if g > 0.0:
            if d > g:
                fe = K[slot, el] * (d - g) + damping[el] * r
            elif d < -g:
                fe = K[slot, el] * (d + g) + damping[el] * r
            else:
                fe = 0.0
        else:
            fe = K[slot, el] * d + damping[el] * r
        force[el] = fe + P[slot, el]
        defl[el] = d
    for i in range(n):
        vi = y[n + i]
        acc = external_force[i] - ground_damping[i] * vi
        for j in range(vt_ptr[i], vt_ptr[i + 1]):
            acc -= vt_coef[j] * force[vt_el[j]]
        dy[i] = vi
        dy[n + i] = inv_mass[i] * acc


@njit(cache=True, error_model="numpy")
def rhs_extra(y, slot, inv_mass, v_ptr, vq_idx, vv_idx, v_coef, fr_el, fr_ptr, fr_dof,
              fr_coef, fr_row, FR, sp_el, sp_par, dy, force, defl):
    """Spline radial elements and tooth friction, after :func:`rhs_slot` (only called
    for models that have them, so others run exactly the arithmetic they always ran).

    Each spline j gets its radial law (:func:`spline_force`), which overwrites the force
    of its two component elements, and adds -M^-1 V_e f_e of both by a scatter (rhs_slot
    saw them with zero stiffness).  Each friction mesh adds -M^-1 W_e(s) max(f_e, 0):
    friction on the working flank only.
    Twin: the spline and friction parts of :func:`torquesplit.solve.reference.rhs_numpy`.
    """
    n = inv_mass.shape[0]
    for j in range(sp_el.shape[0]):
        spline_force(j, y, sp_el, sp_par, v_ptr, vq_idx, vv_idx, v_coef, force, defl)
        for c in range(2):
            el = sp_el[j, c]
            fe = force[el]
            for i in range(v_ptr[el], v_ptr[el + 1]):
                dy[vv_idx[i]] -= inv_mass[vq_idx[i]] * (v_coef[i] * fe)
    for j in range(fr_el.shape[0]):
        fe = force[fr_el[j]]
        if fe > 0.0:
            for i in range(fr_ptr[j], fr_ptr[j + 1]):
                d = fr_dof[i]
                dy[n + d] -= inv_mass[d] * (fr_coef[i] * FR[slot, fr_row[i]] * fe)


# inlined (numba IR) into rhs_extra: as a call inside its loop it cost an atomic
# reference-count increment and decrement per array argument (a third of a seed 002 step)
@njit(cache=True, error_model="numpy", inline="always")
def spline_force(j, y, sp_el, sp_par, v_ptr, vq_idx, vv_idx, v_coef, force, defl):
    """Radial law of spline j (seed 002 eq. 6, restoring, Coulomb friction regularised).

    d = (dx, dy) from the projection rows of its two component elements, R = |d|,
    Rdot = d.d'/R; F = k R + c Rdot (R < S1), F_m tanh(Rdot / v) (S1 <= R <= S2),
    k (R - S2) + c Rdot + F_m tanh(Rdot / v) (R > S2); writes f_x = F dx / R,
    f_y = F dy / R (0 at R = 0) and the deformations dx, dy.
    Twin: the spline part of :func:`torquesplit.solve.reference.element_forces_numpy`.
    """
    ex = sp_el[j, 0]
    ey = sp_el[j, 1]
    dx = 0.0
    rx = 0.0
    for i in range(v_ptr[ex], v_ptr[ex + 1]):
        dx += v_coef[i] * y[vq_idx[i]]
        rx += v_coef[i] * y[vv_idx[i]]
    dyy = 0.0
    ry = 0.0
    for i in range(v_ptr[ey], v_ptr[ey + 1]):
        dyy += v_coef[i] * y[vq_idx[i]]
        ry += v_coef[i] * y[vv_idx[i]]
    defl[ex] = dx
    defl[ey] = dyy
    rad = math.sqrt(dx * dx + dyy * dyy)
    if rad > 0.0:
        rdot = (dx * rx + dyy * ry) / rad
        k = sp_par[j, 0]
        c = sp_par[j, 1]
        s1 = sp_par[j, 2]
        s2 = sp_par[j, 3]
        fm = sp_par[j, 4]
        if rad < s1:
            f = k * rad + c * rdot
        elif rad <= s2:
            f = fm * math.tanh(rdot / sp_par[j, 5])
        else:
            f = k * (rad - s2) + c * rdot + fm * math.tanh(rdot / sp_par[j, 5])
        force[ex] = f * dx / rad
        force[ey] = f * dyy / rad
    else:
        force[ex] = 0.0
        force[ey] = 0.0


@njit(cache=True, error_model="numpy")
def rhs_at(t, y, inv_mass, external_force, ground_damping, element_kind, v_ptr, v_dof,
           v_coef, stiffness_table, frequency, phase, damping, gap_ptr, gap_values,
           error_constant, error_ptr, error_amplitude, error_omega, error_phase,
           force_table, tv_el, err_el, sin_el, vr_ptr, vq_idx, vv_idx, vt_ptr, vt_el,
           vt_coef, fr_el, fr_ptr, fr_dof, fr_coef, fr_row, friction_table, sp_el,
           sp_par, dy, force, defl):
    """One exact right-hand-side evaluation at (t, y) (allocates; not for loops).

    Twin: :func:`torquesplit.solve.reference.rhs_numpy` and
    :func:`torquesplit.solve.reference.element_forces_numpy`.
    """
    ne = v_ptr.shape[0] - 1
    n_sin = error_omega.shape[0]
    K = np.empty((1, ne))
    P = np.empty((1, ne))
    G = np.empty((1, ne))
    E = np.empty((1, ne))
    ED = np.empty((1, ne))
    CY = np.empty((1, ne), dtype=np.int64)
    S = np.empty((1, n_sin))
    C = np.empty((1, n_sin))
    FR = np.empty((1, friction_table.shape[0]))
    has_fr = fr_el.shape[0] > 0
    extra = has_fr or sp_el.shape[0] > 0
    gap_cyc = np.full(ne, _NO_CYCLE, dtype=np.int64)
    gap_val = np.zeros(ne)
    has_force = np.zeros(ne, dtype=np.bool_)
    scratch_flags(element_kind, gap_ptr, gap_values, force_table, has_force,
                  np.empty(ne, dtype=np.int64))
    s0 = np.int64(0)  # slots are passed as int64 variables, never literals
    init_slots(stiffness_table, force_table, gap_ptr, gap_values, error_constant,
               K, P, G, E, ED, CY)
    excite_exact(t, s0, frequency, phase, stiffness_table, force_table, gap_ptr,
                 gap_values, error_constant, error_amplitude, error_omega, error_phase,
                 tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C, gap_cyc, gap_val, has_force)
    if has_fr:
        excite_friction(t, s0, frequency, phase, fr_el, friction_table, FR)
    rhs_slot(y, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
             vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
             dy, force, defl)
    if extra:
        rhs_extra(y, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                  fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, dy, force,
                  defl)


# ================================================================== recording
@njit(cache=True, error_model="numpy")
def record_statistics(slot, force, defl, G, CY, element_kind, track_el, track_base,
                      cyc_max, cyc_min, cyc_sum, cyc_cnt, sep_count, back_count,
                      sep_time, back_time, weight, counters, watch_el, n_watch):
    """Enter one accepted state in the per-cycle statistics and contact counters.

    Cycle index of tracked element j = CY - track_base[j]; cycles at or beyond the
    capacity (rows of ``cyc_max``) are ignored.  Separation: |delta| <= g with g > 0;
    back-side contact: delta < -g with g > 0, or delta < 0 for a mesh without backlash.
    Only the ``n_watch`` elements of ``watch_el`` can be in either state.  ``weight``
    is the time the sample stands for (added to ``sep_time`` / ``back_time``).
    Twins: :func:`torquesplit.solve.reference.cycle_statistics_numpy` and
    :func:`torquesplit.solve.reference.contact_state_numpy`.
    """
    cap = cyc_max.shape[0]
    for j in range(track_el.shape[0]):
        el = track_el[j]
        c = CY[slot, el] - track_base[j]
        if c >= 0 and c < cap:
            fe = force[el]
            if fe > cyc_max[c, j]:
                cyc_max[c, j] = fe
            if fe < cyc_min[c, j]:
                cyc_min[c, j] = fe
            cyc_sum[c, j] += fe
            cyc_cnt[c, j] += 1
    for j in range(n_watch):
        el = watch_el[j]
        g = G[slot, el]
        d = defl[el]
        if g > 0.0:
            if d < -g:
                back_count[el] += 1
                back_time[el] += weight
            elif d <= g:
                sep_count[el] += 1
                sep_time[el] += weight
        elif element_kind[el] == MESH_KIND and d < 0.0:
            back_count[el] += 1
            back_time[el] += weight
    counters[I_SAMPLES] += 1


@njit(cache=True, error_model="numpy")
def store_history(row, t, y, force, hist_el, hist_dof, hist_t, hist_f, hist_q, hist_v):
    """Write one decimated history row: t, forces of history elements, q and v of DOFs.

    Twin: plain indexing, ``hist_f[row] = force[hist_el]`` etc.
    """
    n = y.shape[0] // 2
    hist_t[row] = t
    for j in range(hist_el.shape[0]):
        hist_f[row, j] = force[hist_el[j]]
    for j in range(hist_dof.shape[0]):
        d = hist_dof[j]
        hist_q[row, j] = y[d]
        hist_v[row, j] = y[n + d]


@njit(cache=True, error_model="numpy")
def bad_state(y, blowup):
    """Index of the first non-finite state or |q| > blowup, or -1 if all is well.

    Twin: ``np.flatnonzero(~np.isfinite(y) | (abs(q) > blowup))[:1]``.
    """
    n = y.shape[0] // 2
    for i in range(n):
        if not abs(y[i]) <= blowup:  # also true for NaN
            return i
    for i in range(n, y.shape[0]):
        if not math.isfinite(y[i]):
            return i
    return -1


# ======================================================================== RK4
@njit(cache=True, error_model="numpy")
def rk4_run(y, t0, h, n_first, n_steps, record_final, record_every, blowup,
            inv_mass, external_force, ground_damping, element_kind, v_ptr, v_dof,
            v_coef, stiffness_table, frequency, phase, damping, gap_ptr, gap_values,
            error_constant, error_ptr, error_amplitude, error_omega, error_phase,
            force_table, tv_el, err_el, sin_el, vr_ptr, vq_idx, vv_idx, vt_ptr, vt_el,
            vt_coef, fr_el, fr_ptr, fr_dof, fr_coef, fr_row, friction_table,
              sp_el, sp_par, track_el, track_base, cyc_max, cyc_min, cyc_sum, cyc_cnt,
            sep_count, back_count, sep_time, back_time, hist_el, hist_dof, hist_t,
            hist_f, hist_q, hist_v, full_t, full_y, rhs_fn, rhs_par, counters,
              clock):
    """Classic fixed-step RK4 over global steps n_first .. n_first + n_steps - 1.

    Step i runs from t0 + i h to t0 + (i + 1) h.  The state at the start of each step
    is recorded (statistics; history when i % record_every == 0; full state when
    ``full_t`` has room); with ``record_final`` the end state is recorded too.  ``y`` is
    advanced in place.  Excitation is evaluated once per distinct stage time (t,
    t + h/2, t + h) and the t + h values are reused by the next step; error sinusoids
    are advanced by phasor rotation and recomputed exactly every RESYNC steps.
    Stops early (status DIVERGED) if the state is non-finite or |q| > blowup.  Models
    with tooth friction or splines also run :func:`excite_friction` after each
    excitation and :func:`rhs_extra` after each right-hand side (``has_fr``, ``extra``).
    The right-hand side is :func:`rhs_slot`, or the model's generated code ``rhs_fn``
    with parameters ``rhs_par`` when these are not empty (see the module docstring).
    Twin: :func:`torquesplit.solve.reference.rk4_numpy`.
    """
    n = inv_mass.shape[0]
    n2 = 2 * n
    ne = v_ptr.shape[0] - 1
    n_sin = error_omega.shape[0]
    K = np.empty((3, ne))
    P = np.empty((3, ne))
    G = np.empty((3, ne))
    E = np.empty((3, ne))
    ED = np.empty((3, ne))
    CY = np.empty((3, ne), dtype=np.int64)
    S = np.empty((3, n_sin))
    C = np.empty((3, n_sin))
    FR = np.empty((3, friction_table.shape[0]))
    gen = rhs_par.shape[0] > 0  # a generated right-hand side was given
    has_fr = fr_el.shape[0] > 0
    extra = has_fr or sp_el.shape[0] > 0
    cos_rot = np.empty(n_sin)
    sin_rot = np.empty(n_sin)
    for i in range(n_sin):
        cos_rot[i] = math.cos(error_omega[i] * 0.5 * h)
        sin_rot[i] = math.sin(error_omega[i] * 0.5 * h)
    k1 = np.empty(n2)
    k2 = np.empty(n2)
    k3 = np.empty(n2)
    k4 = np.empty(n2)
    yt = np.empty(n2)
    gap_cyc = np.full(ne, _NO_CYCLE, dtype=np.int64)
    gap_val = np.zeros(ne)
    has_force = np.zeros(ne, dtype=np.bool_)
    watch_el = np.empty(ne, dtype=np.int64)
    n_watch = scratch_flags(element_kind, gap_ptr, gap_values, force_table, has_force,
                            watch_el)
    force = np.empty(ne)
    defl = np.empty(ne)
    ftmp = np.empty(ne)
    dtmp = np.empty(ne)
    init_slots(stiffness_table, force_table, gap_ptr, gap_values, error_constant,
               K, P, G, E, ED, CY)
    # data addresses for the generated right-hand side (see the module docstring)
    ad_y = y.ctypes.data
    ad_k1 = k1.ctypes.data
    ad_k2 = k2.ctypes.data
    ad_k3 = k3.ctypes.data
    ad_k4 = k4.ctypes.data
    ad_yt = yt.ctypes.data
    ad_force = force.ctypes.data
    ad_defl = defl.ctypes.data
    ad_ftmp = ftmp.ctypes.data
    ad_dtmp = dtmp.ctypes.data
    ad_K = K.ctypes.data
    ad_G = G.ctypes.data
    ad_E = E.ctypes.data
    ad_ED = ED.ctypes.data
    ad_P = P.ctypes.data
    ad_par = rhs_par.ctypes.data
    a = np.int64(0)  # slot of t
    b = np.int64(2)  # slot of t + h
    s_half = np.int64(1)  # slot of t + h/2
    hh = 0.5 * h
    h6 = h / 6.0
    for it in range(n_steps):
        i = n_first + it
        t = t0 + i * h
        if it == 0 or i % RESYNC == 0:
            excite_tables(t, a, tv_el, frequency, phase, stiffness_table, force_table,
                          gap_ptr, gap_values, K, P, G, CY, gap_cyc, gap_val,
                          has_force)
            if has_fr:
                excite_friction(t, a, frequency, phase, fr_el, friction_table, FR)
            phasors_exact(t, a, error_omega, error_phase, S, C)
            errors_from_phasors(a, err_el, error_constant, sin_el, error_amplitude,
                                error_omega, S, C, E, ED)
        # stage 1 at t: its forces are those of the accepted state y(t)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_y, ad_k1, ad_force, ad_defl, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, a * ne)
        else:
            rhs_slot(y, a, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k1, force, defl)
        if extra:
            rhs_extra(y, a, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k1, force,
                      defl)
        record_statistics(a, force, defl, G, CY, element_kind, track_el, track_base,
                          cyc_max, cyc_min, cyc_sum, cyc_cnt, sep_count, back_count,
                          sep_time, back_time, h, counters, watch_el, n_watch)
        if (record_every > 0 and i % record_every == 0
                and counters[I_HIST] < hist_t.shape[0]):
            store_history(counters[I_HIST], t, y, force, hist_el, hist_dof,
                          hist_t, hist_f, hist_q, hist_v)
            counters[I_HIST] += 1
        if counters[I_FULL] < full_t.shape[0]:
            full_t[counters[I_FULL]] = t
            for m in range(n2):
                full_y[counters[I_FULL], m] = y[m]
            counters[I_FULL] += 1
        # stages 2 and 3 at t + h/2
        th = t0 + (i + 0.5) * h
        excite_tables(th, s_half, tv_el, frequency, phase, stiffness_table, force_table,
                      gap_ptr, gap_values, K, P, G, CY, gap_cyc, gap_val,
                      has_force)
        if has_fr:
            excite_friction(th, s_half, frequency, phase, fr_el, friction_table, FR)
        advance_errors(a, s_half, cos_rot, sin_rot, err_el, error_constant, sin_el,
                       error_amplitude, error_omega, S, C, E, ED)
        for m in range(n2):
            yt[m] = y[m] + hh * k1[m]
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k2, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s_half * ne)
        else:
            rhs_slot(yt, s_half, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k2, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s_half, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k2, ftmp,
                      dtmp)
        for m in range(n2):
            yt[m] = y[m] + hh * k2[m]
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k3, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s_half * ne)
        else:
            rhs_slot(yt, s_half, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k3, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s_half, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k3, ftmp,
                      dtmp)
        # stage 4 at t + h
        tb = t0 + (i + 1) * h
        excite_tables(tb, b, tv_el, frequency, phase, stiffness_table, force_table,
                      gap_ptr, gap_values, K, P, G, CY, gap_cyc, gap_val,
                      has_force)
        if has_fr:
            excite_friction(tb, b, frequency, phase, fr_el, friction_table, FR)
        advance_errors(s_half, b, cos_rot, sin_rot, err_el, error_constant, sin_el,
                       error_amplitude, error_omega, S, C, E, ED)
        for m in range(n2):
            yt[m] = y[m] + h * k3[m]
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k4, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, b * ne)
        else:
            rhs_slot(yt, b, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k4, ftmp, dtmp)
        if extra:
            rhs_extra(yt, b, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k4, ftmp,
                      dtmp)
        for m in range(n2):
            y[m] += h6 * (k1[m] + 2.0 * (k2[m] + k3[m]) + k4[m])
        counters[I_STEPS] += 1
        counters[I_RHS] += 4
        clock[F_T] = tb
        bad = bad_state(y, blowup)
        if bad >= 0:
            counters[I_STATUS] = DIVERGED
            counters[I_BAD] = bad
            return
        a, b = b, a
    if record_final and n_steps > 0:
        i = n_first + n_steps
        t = t0 + i * h
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_y, ad_k1, ad_force, ad_defl, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, a * ne)
        else:
            rhs_slot(y, a, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k1, force, defl)
        if extra:
            rhs_extra(y, a, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k1, force,
                      defl)
        record_statistics(a, force, defl, G, CY, element_kind, track_el, track_base,
                          cyc_max, cyc_min, cyc_sum, cyc_cnt, sep_count, back_count,
                          sep_time, back_time, 0.0, counters, watch_el, n_watch)
        if (record_every > 0 and i % record_every == 0
                and counters[I_HIST] < hist_t.shape[0]):
            store_history(counters[I_HIST], t, y, force, hist_el, hist_dof,
                          hist_t, hist_f, hist_q, hist_v)
            counters[I_HIST] += 1
        if counters[I_FULL] < full_t.shape[0]:
            full_t[counters[I_FULL]] = t
            for m in range(n2):
                full_y[counters[I_FULL], m] = y[m]
            counters[I_FULL] += 1


# ============================================================== Dormand-Prince
@njit(cache=True, error_model="numpy")
def hermite(theta, h, y0, f0, y1, f1, out):
    """Cubic Hermite interpolation of the state between two accepted steps.

    Twin: :func:`torquesplit.solve.reference.hermite_numpy`.
    """
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + theta) * h
    h01 = 3.0 * t2 - 2.0 * t3
    h11 = (t3 - t2) * h
    for m in range(out.shape[0]):
        out[m] = h00 * y0[m] + h10 * f0[m] + h01 * y1[m] + h11 * f1[m]


@njit(cache=True, error_model="numpy")
def dopri_run(y, kfsal, t0, t_end, t_stop, rtol, atol, h_max, h_min, max_steps, blowup,
              dt_sample,
              inv_mass, external_force, ground_damping, element_kind, v_ptr, v_dof,
              v_coef, stiffness_table, frequency, phase, damping, gap_ptr, gap_values,
              error_constant, error_ptr, error_amplitude, error_omega, error_phase,
              force_table, tv_el, err_el, sin_el, vr_ptr, vq_idx, vv_idx, vt_ptr, vt_el,
              vt_coef, fr_el, fr_ptr, fr_dof, fr_coef, fr_row, friction_table,
              sp_el, sp_par, track_el, track_base, cyc_max, cyc_min, cyc_sum, cyc_cnt,
              sep_count, back_count, sep_time, back_time, hist_el, hist_dof, hist_t,
              hist_f, hist_q, hist_v, full_t, full_y, rhs_fn, rhs_par, counters,
            clock):
    """Adaptive Dormand-Prince 5(4) with FSAL and PI step-size control (Hairer's DOPRI5).

    Integrates from clock[F_T] until t >= t_stop (never past t_end; the last step is
    shortened to land on t_end), advancing ``y`` in place.  ``kfsal`` carries f(t, y)
    between calls (counters[I_FSAL]).  Error norm: RMS of err_i / (atol_i + rtol
    max(|y_i|, |y_new_i|)).  Every accepted state enters the statistics; the decimated
    (and optional full) histories are written at the uniform times t0 + k dt_sample by
    cubic Hermite interpolation between accepted steps.
    Status: DIVERGED (non-finite or |q| > blowup after an accepted step),
    STEP_UNDERFLOW (h < max(h_min, 10 eps |t|)), MAX_STEPS (accepted steps).
    Right-hand side: as :func:`rk4_run` (``rhs_fn``, ``rhs_par``).
    Twin: :func:`torquesplit.solve.reference.dopri_numpy`.
    """
    n = inv_mass.shape[0]
    n2 = 2 * n
    ne = v_ptr.shape[0] - 1
    n_sin = error_omega.shape[0]
    K = np.empty((2, ne))
    P = np.empty((2, ne))
    G = np.empty((2, ne))
    E = np.empty((2, ne))
    ED = np.empty((2, ne))
    CY = np.empty((2, ne), dtype=np.int64)
    S = np.empty((2, n_sin))
    C = np.empty((2, n_sin))
    FR = np.empty((2, friction_table.shape[0]))
    gen = rhs_par.shape[0] > 0  # a generated right-hand side was given
    has_fr = fr_el.shape[0] > 0
    extra = has_fr or sp_el.shape[0] > 0
    k2 = np.empty(n2)
    k3 = np.empty(n2)
    k4 = np.empty(n2)
    k5 = np.empty(n2)
    k6 = np.empty(n2)
    k7 = np.empty(n2)
    yt = np.empty(n2)
    ynew = np.empty(n2)
    ys = np.empty(n2)
    dys = np.empty(n2)
    gap_cyc = np.full(ne, _NO_CYCLE, dtype=np.int64)
    gap_val = np.zeros(ne)
    has_force = np.zeros(ne, dtype=np.bool_)
    watch_el = np.empty(ne, dtype=np.int64)
    n_watch = scratch_flags(element_kind, gap_ptr, gap_values, force_table, has_force,
                            watch_el)
    force = np.empty(ne)
    defl = np.empty(ne)
    ftmp = np.empty(ne)
    dtmp = np.empty(ne)
    init_slots(stiffness_table, force_table, gap_ptr, gap_values, error_constant,
               K, P, G, E, ED, CY)
    s0 = np.int64(0)  # slot of the stages (and of interpolated samples)
    s1 = np.int64(1)  # slot of t + h: the candidate state, then the accepted one
    n_hist = hist_t.shape[0]
    t = clock[F_T]
    h = clock[F_H]
    facold = clock[F_FACOLD]
    eps = 2.220446049250313e-16
    # data addresses for the generated right-hand side (see the module docstring)
    ad_y = y.ctypes.data
    ad_kfsal = kfsal.ctypes.data
    ad_k2 = k2.ctypes.data
    ad_k3 = k3.ctypes.data
    ad_k4 = k4.ctypes.data
    ad_k5 = k5.ctypes.data
    ad_k6 = k6.ctypes.data
    ad_k7 = k7.ctypes.data
    ad_yt = yt.ctypes.data
    ad_ynew = ynew.ctypes.data
    ad_ys = ys.ctypes.data
    ad_dys = dys.ctypes.data
    ad_force = force.ctypes.data
    ad_defl = defl.ctypes.data
    ad_ftmp = ftmp.ctypes.data
    ad_dtmp = dtmp.ctypes.data
    ad_K = K.ctypes.data
    ad_G = G.ctypes.data
    ad_E = E.ctypes.data
    ad_ED = ED.ctypes.data
    ad_P = P.ctypes.data
    ad_par = rhs_par.ctypes.data
    # current state: f(t, y) and, at the very start, its sample
    if counters[I_FSAL] == 0:
        excite_exact(t, s1, frequency, phase, stiffness_table, force_table, gap_ptr,
                     gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t, s1, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_y, ad_kfsal, ad_force, ad_defl, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s1 * ne)
        else:
            rhs_slot(y, s1, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     kfsal, force, defl)
        if extra:
            rhs_extra(y, s1, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, kfsal, force,
                      defl)
        counters[I_RHS] += 1
        counters[I_FSAL] = 1
        if counters[I_SAMPLES] == 0:
            record_statistics(s1, force, defl, G, CY, element_kind, track_el,
                              track_base, cyc_max, cyc_min, cyc_sum, cyc_cnt,
                              sep_count, back_count, sep_time, back_time, 0.0,
                              counters, watch_el, n_watch)
        while counters[I_NEXT] < n_hist and t0 + counters[I_NEXT] * dt_sample <= t:
            row = counters[I_NEXT]
            store_history(row, t, y, force, hist_el, hist_dof, hist_t, hist_f,
                          hist_q, hist_v)
            if row < full_t.shape[0]:
                full_t[row] = t
                for m in range(n2):
                    full_y[row, m] = y[m]
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
        # stages 2..6 (slot 0), stage 7 at t + hs (slot 1)
        for m in range(n2):
            yt[m] = y[m] + hs * _A21 * kfsal[m]
        excite_exact(t + _C2 * hs, s0, frequency, phase, stiffness_table, force_table,
                     gap_ptr, gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t + _C2 * hs, s0, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k2, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s0 * ne)
        else:
            rhs_slot(yt, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k2, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k2, ftmp,
                      dtmp)
        for m in range(n2):
            yt[m] = y[m] + hs * (_A31 * kfsal[m] + _A32 * k2[m])
        excite_exact(t + _C3 * hs, s0, frequency, phase, stiffness_table, force_table,
                     gap_ptr, gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t + _C3 * hs, s0, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k3, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s0 * ne)
        else:
            rhs_slot(yt, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k3, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k3, ftmp,
                      dtmp)
        for m in range(n2):
            yt[m] = y[m] + hs * (_A41 * kfsal[m] + _A42 * k2[m] + _A43 * k3[m])
        excite_exact(t + _C4 * hs, s0, frequency, phase, stiffness_table, force_table,
                     gap_ptr, gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t + _C4 * hs, s0, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k4, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s0 * ne)
        else:
            rhs_slot(yt, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k4, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k4, ftmp,
                      dtmp)
        for m in range(n2):
            yt[m] = y[m] + hs * (_A51 * kfsal[m] + _A52 * k2[m] + _A53 * k3[m]
                                 + _A54 * k4[m])
        excite_exact(t + _C5 * hs, s0, frequency, phase, stiffness_table, force_table,
                     gap_ptr, gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t + _C5 * hs, s0, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k5, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s0 * ne)
        else:
            rhs_slot(yt, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k5, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k5, ftmp,
                      dtmp)
        for m in range(n2):
            yt[m] = y[m] + hs * (_A61 * kfsal[m] + _A62 * k2[m] + _A63 * k3[m]
                                 + _A64 * k4[m] + _A65 * k5[m])
        t_new = t_end if last else t + hs
        excite_exact(t_new, s0, frequency, phase, stiffness_table, force_table,
                     gap_ptr, gap_values, error_constant, error_amplitude, error_omega,
                     error_phase, tv_el, err_el, sin_el, K, P, G, E, ED, CY, S, C,
                     gap_cyc, gap_val, has_force)
        if has_fr:
            excite_friction(t_new, s0, frequency, phase, fr_el, friction_table, FR)
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_yt, ad_k6, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s0 * ne)
        else:
            rhs_slot(yt, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k6, ftmp, dtmp)
        if extra:
            rhs_extra(yt, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k6, ftmp,
                      dtmp)
        for m in range(n2):
            ynew[m] = y[m] + hs * (_B1 * kfsal[m] + _B3 * k3[m] + _B4 * k4[m]
                                   + _B5 * k5[m] + _B6 * k6[m])
        # stage 7 (FSAL): same time as stage 6, so the excitation is copied
        for el in range(ne):
            K[1, el] = K[0, el]
            P[1, el] = P[0, el]
            G[1, el] = G[0, el]
            E[1, el] = E[0, el]
            ED[1, el] = ED[0, el]
            CY[1, el] = CY[0, el]
        for r in range(FR.shape[1]):
            FR[1, r] = FR[0, r]
        if gen:  # the model's generated code (codegen.py), else the general loop
            rhs_fn(ad_ynew, ad_k7, ad_force, ad_defl, ad_K, ad_G, ad_E, ad_ED, ad_P,
                   ad_par, s1 * ne)
        else:
            rhs_slot(ynew, s1, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                     vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                     k7, force, defl)
        if extra:
            rhs_extra(ynew, s1, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                      fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, k7, force,
                      defl)
        counters[I_RHS] += 6
        acc = 0.0
        for m in range(n2):
            err = hs * (_E1 * kfsal[m] + _E3 * k3[m] + _E4 * k4[m] + _E5 * k5[m]
                        + _E6 * k6[m] + _E7 * k7[m])
            sc = atol[m] + rtol * max(abs(y[m]), abs(ynew[m]))
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
            bad = bad_state(ynew, blowup)
            if bad >= 0:  # stop before recording anything of this step
                for m in range(n2):
                    y[m] = ynew[m]
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
                hermite(theta, hs, y, kfsal, ynew, k7, ys)
                excite_exact(ts, s0, frequency, phase, stiffness_table, force_table,
                             gap_ptr, gap_values, error_constant, error_amplitude,
                             error_omega, error_phase, tv_el, err_el, sin_el,
                             K, P, G, E, ED, CY, S, C, gap_cyc, gap_val, has_force)
                if has_fr:
                    excite_friction(ts, s0, frequency, phase, fr_el, friction_table, FR)
                if gen:  # the model's generated code (codegen.py), else the general loop
                    rhs_fn(ad_ys, ad_dys, ad_ftmp, ad_dtmp, ad_K, ad_G, ad_E, ad_ED, ad_P,
                           ad_par, s0 * ne)
                else:
                    rhs_slot(ys, s0, K, P, G, E, ED, inv_mass, external_force, ground_damping,
                             vr_ptr, vq_idx, vv_idx, v_coef, vt_ptr, vt_el, vt_coef, damping,
                             dys, ftmp, dtmp)
                if extra:
                    rhs_extra(ys, s0, inv_mass, vr_ptr, vq_idx, vv_idx, v_coef, fr_el,
                              fr_ptr, fr_dof, fr_coef, fr_row, FR, sp_el, sp_par, dys, ftmp,
                              dtmp)
                store_history(row, ts, ys, ftmp, hist_el, hist_dof, hist_t, hist_f,
                              hist_q, hist_v)
                if row < full_t.shape[0]:
                    full_t[row] = ts
                    for m in range(n2):
                        full_y[row, m] = ys[m]
                    counters[I_FULL] = row + 1
                counters[I_NEXT] = row + 1
                counters[I_HIST] = row + 1
            for m in range(n2):
                y[m] = ynew[m]
                kfsal[m] = k7[m]
            t = t_new
            clock[F_T] = t
            counters[I_STEPS] += 1
            if hs < clock[F_HMIN]:
                clock[F_HMIN] = hs
            if hs > clock[F_HMAX]:
                clock[F_HMAX] = hs
            record_statistics(s1, force, defl, G, CY, element_kind, track_el, track_base,
                              cyc_max, cyc_min, cyc_sum, cyc_cnt, sep_count,
                              back_count, sep_time, back_time, hs, counters, watch_el,
                              n_watch)
            fac = fac11 / facold ** _BETA
            fac = max(1.0 / _FAC_MAX, min(1.0 / _FAC_MIN, fac / _SAFE))
            h_new = hs / fac
            if counters[I_LAST_REJECTED] == 1 and h_new > hs:
                h_new = hs
            h = h_new
            facold = max(enorm, 1.0e-4)
            counters[I_LAST_REJECTED] = 0
        else:
            counters[I_REJECTED] += 1
            counters[I_LAST_REJECTED] = 1
            h = hs / min(1.0 / _FAC_MIN, fac11 / _SAFE)
    clock[F_T] = t
    clock[F_H] = h
    clock[F_FACOLD] = facold
