"""The compiled kernels' data: three bundles of arrays instead of 70 arguments.

A kernel call takes three named tuples of contiguous arrays (numba types a named tuple
of arrays as one value; passing it costs nothing more than passing its arrays, measured):

=================  ====================================================  ==============
bundle             what it holds                                         lifetime
=================  ====================================================  ==============
:class:`KernelModel`  the structure's arrays in kernel form (SI), with    one per model
                   the index arrays derived for speed (CSR of V by
                   element and by DOF, time-varying elements, ...)
:class:`Work`      scratch: state rows, element forces, excitation       one per run
                   slots, error phasors, gap cache, data addresses for
                   the generated right-hand side
:class:`Record`    what a run keeps: per-cycle statistics of the force   one per run
                   and of the load-sharing ratio, contact counters,
                   decimated and full histories
=================  ====================================================  ==============

Named tuples rather than a numba structref or one packed buffer: they are plain
Python objects on this side (readable, picklable, each array keeps its dtype and
shape), numba caches kernels that take them, and adding a field touches this module,
the kernel that uses it and nothing else.  Rows of :attr:`Work.Y` hold every state-
sized vector of the integrators (the state, the trial state and the stages), so one
stage evaluation (``_kernels._stage``) serves RK4 and Dormand-Prince alike, and the
generated right-hand side gets a row's address as base + row * stride.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from torquesplit._memo import remember_last
from torquesplit.assembly.structure import Structure
from torquesplit.errors import SolverError

__all__ = ["KernelModel", "Work", "Record", "kernel_model", "make_work", "make_record",
           "Y_STATE", "Y_TRIAL", "Y_K1", "Y_KFSAL", "Y_NEW", "Y_SAMPLE", "Y_DSAMPLE",
           "F_MAIN", "F_TMP", "N_SLOT", "SLOT_EVENT", "Y_ALT", "Y_K1ALT", "corner_nodes"]

KernelModel = namedtuple("KernelModel", (
    "inv_mass", "external_force", "ground_damping", "element_kind", "v_ptr", "v_dof",
    "v_coef", "stiffness_table", "frequency", "phase", "damping", "gap_ptr",
    "gap_values", "error_constant", "error_ptr", "error_amplitude", "error_omega",
    "error_phase", "force_table", "tv_el", "err_el", "sin_el", "vr_ptr", "vq_idx",
    "vv_idx", "vt_ptr", "vt_el", "vt_coef", "fr_el", "fr_ptr", "fr_dof", "fr_coef",
    "fr_row", "friction_table", "sp_el", "sp_par", "gy_ptr", "gy_idx", "gy_coef",
    "corner_ptr", "corner_node", "fs_ptr", "fs_idx", "fs_coef", "tv_tab",
))
"""A :class:`~torquesplit.assembly.structure.Structure` in kernel form.

Besides the structure's own arrays (see its docstring): ``tv_el`` elements with a
time-varying table (f > 0), those whose stiffness or additive-force table changes over
the cycle first (their number ``tv_tab[0]``; the others' tables are constant, and only
their cycle index and half-gap are time-varying); ``err_el`` elements owning an error
sinusoid and ``sin_el`` the owner of each sinusoid; ``vr_ptr vq_idx vv_idx`` V by element (unsigned; indices
into the state of the q and of the v entries); ``vt_ptr vt_el vt_coef`` V by DOF (the
generalized forces are gathered, not scattered); ``gy_ptr gy_idx gy_coef`` the
gyroscopic matrix G by row (generalized force -G v); spline component elements get zero
stiffness and damping in ``stiffness_table`` / ``damping`` (their law is applied apart);
``corner_node[corner_ptr[e]:corner_ptr[e+1]]`` the table nodes where element e's force has
a corner (:func:`corner_nodes`): the integrators also sample the statistics there;
``fs_ptr fs_idx fs_coef`` the frame stiffness K_f by row (generalized force -K_f q).
"""

Work = namedtuple("Work", (
    "Y", "F", "D", "K", "P", "G", "E", "ED", "CY", "S", "C", "FR", "gap_cyc", "gap_val",
    "has_force", "watch_el", "rot", "addr", "par", "next_node", "lim",
))
"""Scratch of one run.  ``Y`` (12, 2 n): state-sized rows (see the ``Y_*`` indices);
``F``/``D`` (2, n_el): element forces / deformations of the evaluation whose statistics
are recorded (row F_MAIN) and of the other stages (F_TMP); ``K P G E ED CY`` (N_SLOT,
n_el) excitation slots: stiffness, additive force, half-gap, error, error rate,
statistics cycle index; ``S C`` (N_SLOT, n_sin) sin and cos of every error sinusoid;
``FR`` (N_SLOT, 3 n_fm) friction-table values; ``gap_cyc``/``gap_val`` the cached
half-gap of each element's current cycle; ``has_force`` elements with a non-zero
additive force table; ``watch_el`` elements whose contact state is counted; ``rot``
(2, n_sin) cos and sin of the phasor rotation over half an RK4 step; ``addr`` data
addresses for the generated right-hand side (``A_*``, the last its own); ``par`` its
parameter vector (empty for the general kernel), held here so that its address stays valid;
``next_node`` the absolute table node (cycle x n_table + node) of each element's next
corner; ``lim`` (2 n) the bound of each entry of a state that the divergence check
applies (set by the kernels at their start: ``_kernels.state_limits``)."""

Record = namedtuple("Record", (
    "track_el", "track_base", "trk_cont", "cyc_max", "cyc_min", "cyc_sum", "cyc_cnt", "cyc_wt",
    "prev_t", "prev_f", "prev_c", "pk_t", "pk_f", "pk_g", "pk_k", "pk_n", "pk_x",
    "grp_ptr", "grp_col", "grp_min", "rat_max", "rat_min",
    "sep_count", "back_count", "sep_time", "back_time", "contact_t", "contact_prev",
    "hist_el", "hist_dof", "hist_t", "hist_f", "hist_q", "hist_v", "full_t", "full_y",
    "dense", "dense_el", "dense_dir",
))
"""Outputs of a run.  Per tracked element: ``trk_cont`` 1 where its force is continuous
at its cycle starts (:func:`continuous_start`), else 0.  Per tracked element (columns)
and cycle (rows, counted from the cycle containing the start time): force max, min,
time integral (trapezoid rule over the step samples and the corner instants, each half-interval in its end's cycle) and
its time (``cyc_wt``: their ratio is the cycle's mean force), sample count; the last
instant entered (``prev_t`` (1,), NaN before the first; ``prev_f``, ``prev_c`` its
forces and cycles); for the peaks between the instants, the last two (slots
alternating): ``pk_t`` (2,) their times, ``pk_g`` (n_tr, 2) contact regimes, ``pk_k``
(2,) whether each is a corner, ``pk_f`` (n_tr,) the older one's forces (the last one's
are ``prev_f``), ``pk_n`` (1,) instants entered, ``pk_x`` (1,) whether the next sample
is a corner; per
load-sharing group (``grp_col[grp_ptr[g]:grp_ptr[g+1]]`` its tracked columns) the
largest and smallest instantaneous ratio ``N f_i / sum_j f_j`` of each member in each of
its cycles (``rat_max``, ``rat_min``), formed only while the group's total force exceeds
``grp_min[g]`` (the ratio of nearly nothing is not load sharing); per element the samples and time in separation
and in back-side contact, with the last two samples' times (``contact_t`` (2,)) and,
per element, the last one's delta + g and delta - g and the one before's delta + g
(``contact_prev`` (n_el, 3)); the decimated history and the optional full state; the dense
record of the instants (``dense``: rows t, kink, then each force vector's squared
magnitude; ``dense_el`` and ``dense_dir`` the vectors' layout,
:func:`torquesplit.solve._kernels.dense_row`), which
:mod:`~torquesplit.solve.vector_peaks` reduces between chunks."""

#: ``Record.dense_el``'s header: rows written, rows lost, vectors, pairs, whether the
#: tables' corners are instants of the record (1: some term has corners); the layout follows
DENSE_HEAD = 5

# rows of Work.Y
Y_STATE = 0  # the state (copied in and out of the caller's y)
Y_TRIAL = 1  # stage argument
Y_K1 = 2  # rk4: k1..k4 in rows 2..5
Y_KFSAL = 2  # dopri: f(t, y) of the current state, k2..k7 in rows 3..8
Y_NEW = 9  # dopri: candidate state
Y_SAMPLE = 10  # interpolated sample state (dopri history, corner events)
Y_DSAMPLE = 11  # its derivative
Y_ALT = 12  # rk4: the other state row (the previous state, kept for corner events)
Y_K1ALT = 13  # rk4: its k1
N_ROWS = 14
# rows of Work.F / Work.D
F_MAIN = 0
F_TMP = 1
#: excitation slots (rk4: t, t + h/2, t + h; dopri: stages, accepted state; last: events)
N_SLOT = 4
SLOT_EVENT = 3
CORNER_TOL = 0.05
"""A table node is a corner of an element's excitation when the table's second
difference there exceeds CORNER_TOL x the table's range: the edges of a rectangular
stiffness wave (single / double tooth contact), the start of a meshing-in impact pulse,
the jumps of a tooth-friction table (each row on its own range: Jin et al. 2019's
herringbone meshes have 56 per cycle; stepped over, they left RK4 second order there,
waveform 4.7e-3 of its amplitude off at 100 steps per cycle, 3.3e-4 with them, for
about 20 % more right-hand-side calls); and node 0 where the half-gap changes from cycle
to cycle.  RK4 steps through corners in
sub-steps that end on them, and the forces there enter the per-cycle extremes: the
largest force or load-sharing ratio often sits on such an edge, where step samples alone
converge only like h, and an RK4 step across a kink of the right-hand side loses its
order.  The smaller kinks of a finely sampled smooth curve (an impact pulse, an ISO
shape: second differences of a few 1e-3 of the range) are not corners: stepping over
them costs nothing measurable (measured: the metrics of the shipped examples move by
less than 1e-6 between 0.05 and 1e-3) while treating them as corners would double the
steps of the Liu et al. 2021 model."""
# indices of Work.addr; A_SELF: the address of Work.addr's own data, which the generated
# right-hand side takes instead of the seven addresses A_K..A_FR (it loads them itself)
A_Y, A_F, A_D, A_K, A_G, A_E, A_ED, A_P, A_PAR, A_FR, A_SELF = range(11)


def _check(s: Structure) -> None:
    n_el = s.n_elements
    if np.any(np.diff(s.gap_ptr) < 1):
        bad = [s.element_names[e] for e in np.flatnonzero(np.diff(s.gap_ptr) < 1)]
        raise SolverError(f"elements {bad} have no half-gap value; give gaps=0.0 for no "
                          "dead zone when building the structure.")
    if np.any(s.frequency < 0) or not np.all(np.isfinite(s.frequency)):
        raise SolverError("excitation frequencies must be finite and >= 0 Hz; check the "
                          "mesh frequencies of the structure.")
    nnz = len(s.v_dof)
    if (len(s.v_ptr) != n_el + 1 or s.v_ptr[0] != 0 or s.v_ptr[-1] != nnz
            or np.any(np.diff(s.v_ptr) < 0) or len(s.v_coef) != nnz
            or (nnz and (np.min(s.v_dof) < 0 or np.max(s.v_dof) >= s.n_dof))):
        raise SolverError("the projection arrays (v_ptr, v_dof, v_coef) of the structure are "
                          "inconsistent; rebuild it with build_structure.")
    if (len(s.error_ptr) != n_el + 1 or s.error_ptr[-1] != len(s.error_amplitude)
            or len(s.gap_ptr) != n_el + 1 or s.gap_ptr[-1] != len(s.gap_values)
            or s.stiffness_table.shape != s.force_table.shape
            or s.stiffness_table.shape[0] != n_el):
        raise SolverError("the excitation arrays of the structure are inconsistent; "
                          "rebuild it with build_structure.")
    if s.n_table < 1:
        raise SolverError("stiffness tables are empty; build the structure with n_table >= 1.")
    n_fm, n_fe = len(s.fr_el), len(s.fr_dof)
    if (len(s.fr_ptr) != n_fm + 1 or s.fr_ptr[0] != 0 or s.fr_ptr[-1] != n_fe
            or np.any(np.diff(s.fr_ptr) < 0) or len(s.fr_coef) != n_fe
            or len(s.fr_row) != n_fe or s.friction_table.shape[0] != 3 * n_fm
            or (n_fm and s.friction_table.shape[1] < 1)
            or (n_fm and (np.min(s.fr_el) < 0 or np.max(s.fr_el) >= n_el))
            or (n_fe and (np.min(s.fr_dof) < 0 or np.max(s.fr_dof) >= s.n_dof
                          or np.min(s.fr_row) < 0 or np.max(s.fr_row) >= 3 * n_fm))):
        raise SolverError("the tooth-friction arrays (fr_*, friction_table) of the structure "
                          "are inconsistent; rebuild it with build_structure.")
    n_sp = s.sp_el.shape[0] if s.sp_el.ndim == 2 else -1
    if (s.sp_el.ndim != 2 or s.sp_el.shape[1] != 2 or s.sp_par.shape != (n_sp, 6)
            or (n_sp and (np.min(s.sp_el) < 0 or np.max(s.sp_el) >= n_el))
            or (n_sp and not np.all(s.sp_par[:, 5] > 0))):
        raise SolverError("the spline arrays (sp_el, sp_par) of the structure are "
                          "inconsistent; rebuild it with build_structure.")
    n_gy = len(s.gy_idx)
    gy_ptr = _gy_ptr(s)
    if (len(gy_ptr) != s.n_dof + 1 or gy_ptr[0] != 0 or gy_ptr[-1] != n_gy
            or np.any(np.diff(gy_ptr) < 0) or len(s.gy_coef) != n_gy
            or (n_gy and (np.min(s.gy_idx) < 0 or np.max(s.gy_idx) >= s.n_dof))):
        raise SolverError("the gyroscopic arrays (gy_ptr, gy_idx, gy_coef) of the structure "
                          "are inconsistent; rebuild it with build_structure.")
    n_fs = len(s.fs_idx)
    fs_ptr = _fs_ptr(s)
    if (len(fs_ptr) != s.n_dof + 1 or fs_ptr[0] != 0 or fs_ptr[-1] != n_fs
            or np.any(np.diff(fs_ptr) < 0) or len(s.fs_coef) != n_fs
            or (n_fs and (np.min(s.fs_idx) < 0 or np.max(s.fs_idx) >= s.n_dof))):
        raise SolverError("the frame stiffness arrays (fs_ptr, fs_idx, fs_coef) of the "
                          "structure are inconsistent; rebuild it with build_structure.")


def _gy_ptr(s: Structure) -> np.ndarray:
    """Row pointer of the gyroscopic matrix (an empty one means no entries)."""
    return s.gy_ptr if len(s.gy_ptr) else np.zeros(s.n_dof + 1, dtype=np.int64)


def _fs_ptr(s: Structure) -> np.ndarray:
    """Row pointer of the frame stiffness matrix (an empty one means no entries)."""
    return s.fs_ptr if len(s.fs_ptr) else np.zeros(s.n_dof + 1, dtype=np.int64)


def table_array(a) -> np.ndarray:
    """A phase table as the kernels take it: the array itself where it is contiguous,
    float64 and writable (the kernels only read it), else a copy that is (a read-only
    array would be typed apart by numba: a new compilation)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    return a if a.flags.writeable else a.copy()


@remember_last(replay=False)
def kernel_model(structure: Structure) -> KernelModel:
    """The structure's arrays in kernel form (contiguous, writable, derived index arrays
    included); raises :class:`~torquesplit.errors.SolverError` if inconsistent.  The
    phase tables are the structure's own arrays where they already are so
    (:func:`table_array`): copying them cost about 4 ms of every run of Ji & Li's drive
    (two 14 x 65536 tables).  Kept per live structure (a Structure is frozen; the
    kernels only read the model): the corner search alone cost 6 ms of every run of that
    drive, which a study case that runs until settled repeats per run length.  So a
    structure's arrays must not be changed in place once it has run: build another
    (``dataclasses.replace``), as every part of torquesplit does."""
    s = structure
    _check(s)
    n_el = s.n_elements

    def f8(a):
        return np.array(a, dtype=np.float64, order="C", copy=True)

    def i8(a):
        return np.array(a, dtype=np.int64, order="C", copy=True)

    def u8(a):
        return np.array(a, dtype=np.uint64, order="C", copy=True)

    varying = s.frequency > 0.0
    sin_el = np.repeat(np.arange(n_el, dtype=np.int64), np.diff(s.error_ptr))
    err_el = np.unique(sin_el)
    # V by DOF (CSR of V^T) for gathering the generalized forces
    owner = np.repeat(np.arange(n_el, dtype=np.int64), np.diff(s.v_ptr))
    order = np.lexsort((owner, s.v_dof))
    vt_ptr = np.zeros(s.n_dof + 1, dtype=np.int64)
    np.add.at(vt_ptr, np.asarray(s.v_dof, dtype=np.int64) + 1, 1)
    # spline component elements: zero stiffness and damping in the element loop (their
    # force there is 0); the kernels' rhs_extra applies the radial law
    comps = np.asarray(s.sp_el, dtype=np.int64).ravel()
    ktab, damp = (f8 if comps.size else table_array)(s.stiffness_table), f8(s.damping)
    ktab[comps] = 0.0
    damp[comps] = 0.0
    n_fm = len(s.fr_el)
    n_sp = s.sp_el.shape[0]
    # the time-varying elements, those whose tables change over the cycle first
    ftab = table_array(s.force_table)
    changes = [bool(np.any(ktab[e] != ktab[e, 0]) or np.any(ftab[e] != ftab[e, 0]))
               for e in np.flatnonzero(varying)]
    tv_el = np.flatnonzero(varying)[np.argsort(np.logical_not(changes), kind="stable")]
    n_tables = int(np.sum(changes))
    return KernelModel(
        inv_mass=f8(s.inv_mass), external_force=f8(s.external_force),
        ground_damping=f8(s.ground_damping), element_kind=i8(s.element_kind),
        v_ptr=i8(s.v_ptr), v_dof=i8(s.v_dof), v_coef=f8(s.v_coef), stiffness_table=ktab,
        frequency=f8(s.frequency), phase=f8(s.phase), damping=damp, gap_ptr=i8(s.gap_ptr),
        gap_values=f8(s.gap_values), error_constant=f8(s.error_constant),
        error_ptr=i8(s.error_ptr), error_amplitude=f8(s.error_amplitude),
        error_omega=f8(s.error_omega), error_phase=f8(s.error_phase),
        force_table=ftab, tv_el=i8(tv_el),
        err_el=i8(err_el),
        sin_el=i8(sin_el), vr_ptr=u8(s.v_ptr), vq_idx=u8(s.v_dof),
        vv_idx=u8(np.asarray(s.v_dof) + s.n_dof), vt_ptr=u8(np.cumsum(vt_ptr)),
        vt_el=u8(owner[order]), vt_coef=f8(np.asarray(s.v_coef)[order]),
        fr_el=i8(s.fr_el), fr_ptr=i8(s.fr_ptr), fr_dof=i8(s.fr_dof), fr_coef=f8(s.fr_coef),
        fr_row=i8(s.fr_row),
        friction_table=(table_array(s.friction_table).reshape(3 * n_fm, -1) if n_fm
                        else np.zeros((0, 1))),
        sp_el=i8(s.sp_el).reshape(n_sp, 2), sp_par=f8(s.sp_par).reshape(n_sp, 6),
        gy_ptr=u8(_gy_ptr(s)), gy_idx=u8(np.asarray(s.gy_idx) + s.n_dof),
        gy_coef=f8(s.gy_coef), **_corners(s), fs_ptr=u8(_fs_ptr(s)), fs_idx=u8(s.fs_idx),
        fs_coef=f8(s.fs_coef), tv_tab=i8([n_tables]),
    )


def corner_nodes(table: np.ndarray, tolerance: float = CORNER_TOL) -> np.ndarray:
    """Nodes of a periodic table (one period) where its second difference exceeds
    ``tolerance`` x its range: the corners of its piecewise-linear interpolant."""
    t = np.asarray(table, dtype=float)
    span = float(t.max() - t.min()) if t.size else 0.0
    if t.size < 3 or not span > 0:
        return np.zeros(0, dtype=np.int64)
    second = np.roll(t, -1) - 2.0 * t + np.roll(t, 1)
    return np.flatnonzero(np.abs(second) > tolerance * span).astype(np.int64)


def _corners(s: Structure) -> dict:
    """CSR of the corner nodes of each time-varying element (see CORNER_TOL)."""
    ptr = np.zeros(s.n_elements + 1, dtype=np.int64)
    nodes: list[np.ndarray] = []
    comps = set(np.asarray(s.sp_el, dtype=np.int64).ravel().tolist())
    friction_rows = {int(e): np.asarray(s.friction_table)[3 * j:3 * j + 3]
                     for j, e in enumerate(np.asarray(s.fr_el))}
    for e in range(s.n_elements):
        if not s.frequency[e] > 0 or e in comps:
            c = np.zeros(0, dtype=np.int64)
        else:
            c = np.union1d(corner_nodes(s.stiffness_table[e]), corner_nodes(s.force_table[e]))
            for row in friction_rows.get(e, ()):
                # tooth friction: the sliding direction flips where a contact line (or a
                # slice of one) crosses the pitch point, and a pair's share jumps where it
                # enters or leaves; on the same table nodes as the stiffness (one n_table)
                if row.shape[0] != s.stiffness_table.shape[1]:
                    raise ValueError("friction and stiffness tables must have the same "
                                     "number of points per mesh cycle")
                c = np.union1d(c, corner_nodes(row))
            gaps = s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]
            if np.ptp(gaps) > 0:  # the half-gap jumps at the start of a cycle
                c = np.union1d(c, [0])
        nodes.append(c.astype(np.int64))
        ptr[e + 1] = ptr[e] + c.size
    return dict(corner_ptr=ptr, corner_node=(np.concatenate(nodes) if nodes
                                             else np.zeros(0, dtype=np.int64)))


def make_work(m: KernelModel, rhs_parameters: np.ndarray | None = None) -> Work:
    """Scratch for one run of model ``m``, with the time-invariant excitation values in
    every slot (stiffness and force table column 0, first half-gap, constant error) and
    the data addresses of the generated right-hand side's parameters ``rhs_parameters``
    (kept alive by the returned bundle)."""
    n = m.inv_mass.shape[0]
    ne = m.damping.shape[0]
    n_sin = m.error_omega.shape[0]
    par = (np.zeros(0) if rhs_parameters is None
           else np.ascontiguousarray(rhs_parameters, dtype=np.float64))

    def slots(values, dtype=np.float64):
        return np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=dtype),
                                                    (N_SLOT, ne)))

    first_gap = m.gap_values[m.gap_ptr[:-1]] if ne else np.zeros(0)
    has_force = np.any(m.force_table != 0.0, axis=1)
    gapped = np.array([np.any(m.gap_values[m.gap_ptr[e]:m.gap_ptr[e + 1]] > 0.0)
                       for e in range(ne)], dtype=bool)
    watch = np.flatnonzero(gapped | (m.element_kind == 1)).astype(np.int64)
    w = Work(
        Y=np.zeros((N_ROWS, 2 * n)), F=np.zeros((2, ne)), D=np.zeros((2, ne)),
        K=slots(m.stiffness_table[:, 0] if ne else 0.0),
        P=slots(m.force_table[:, 0] if ne else 0.0), G=slots(first_gap),
        E=slots(m.error_constant), ED=slots(0.0), CY=slots(0, np.int64),
        S=np.zeros((N_SLOT, n_sin)), C=np.zeros((N_SLOT, n_sin)),
        FR=np.zeros((N_SLOT, m.friction_table.shape[0])),
        gap_cyc=np.full(ne, -(2**62), dtype=np.int64), gap_val=np.zeros(ne),
        has_force=has_force, watch_el=watch, rot=np.zeros((2, n_sin)),
        addr=np.zeros(A_SELF + 1, dtype=np.uint64), par=par,
        next_node=np.zeros(ne, dtype=np.int64), lim=np.zeros(2 * n),
    )
    # every scratch array on a cache line (the parameters are the caller's)
    w = Work(*(aligned(x) if isinstance(x, np.ndarray) and x is not par else x for x in w))
    for i, arr in ((A_Y, w.Y), (A_F, w.F), (A_D, w.D), (A_K, w.K), (A_G, w.G), (A_E, w.E),
                   (A_ED, w.ED), (A_P, w.P), (A_PAR, par), (A_FR, w.FR)):
        w.addr[i] = arr.ctypes.data
    w.addr[A_SELF] = w.addr.ctypes.data
    return w


ALIGN = 64
"""Bytes to which :func:`aligned` aligns an array's start (a cache line)."""


def aligned(a: np.ndarray) -> np.ndarray:
    """A C-contiguous copy of ``a`` that starts on an ALIGN-byte boundary.  numpy aligns
    to 16 bytes only, so where a run's scratch arrays started was luck, and with it the
    speed of the step: Ji & Li's literal-code step took 224-268 ns (median 236) over 10
    processes with numpy's alignment, 228-235 ns (median 232) over 10 with every scratch
    array of :func:`make_work` aligned (what spread remains: other arrays' placement)."""
    buf = np.empty(a.nbytes + ALIGN, dtype=np.uint8)
    start = (-buf.ctypes.data) % ALIGN
    out = buf[start:start + a.nbytes].view(a.dtype).reshape(a.shape)
    out[...] = a
    return out


def continuous_start(corner_ptr, corner_node, e: int) -> bool:
    """Whether element ``e``'s force is continuous where its cycles begin: no corner of
    its table (a jump of stiffness or force, a half-gap changing per cycle) at node 0,
    so the force interpolated at a cycle start belongs to both cycles' extremes."""
    k = int(corner_ptr[e])
    return not (k < int(corner_ptr[e + 1]) and int(corner_node[k]) == 0)


def make_record(track_el, track_base, n_cycles_cap: int, groups, n_el: int, hist_el,
                hist_dof, n_hist: int, n_full: int, n_dof: int, group_min=None,
                continuous=None, dense=None, n_dense: int = 0) -> Record:
    """Output arrays of a run.  ``groups``: lists of tracked columns, one per
    load-sharing group (the ratio statistics); ``group_min``: the group total force below
    which no ratio is formed [N] (default 0: any positive total); ``continuous``: per
    tracked element, whether its force is continuous at its cycle starts (default none:
    no forces interpolated at cycle starts); ``dense``: the force vectors whose squared
    magnitudes the dense record keeps at every instant, ``(pairs, ptr, axes, elements,
    directions, corners)`` as :class:`~.vector_peaks.VectorPeaks` lays them out, ``n_dense`` its
    rows (none without vectors)."""
    n_tr = len(track_el)
    cap = int(n_cycles_cap)
    grp_ptr = np.zeros(len(groups) + 1, dtype=np.int64)
    grp_ptr[1:] = np.cumsum([len(g) for g in groups])
    grp_col = np.array([c for g in groups for c in g], dtype=np.int64)
    n_he, n_hd = len(hist_el), len(hist_dof)
    return Record(
        track_el=np.asarray(track_el, dtype=np.int64),
        track_base=np.asarray(track_base, dtype=np.int64),
        trk_cont=(np.zeros(n_tr, dtype=np.int64) if continuous is None
                  else np.asarray(continuous, dtype=np.int64).reshape(n_tr)),
        cyc_max=np.full((cap, n_tr), -np.inf), cyc_min=np.full((cap, n_tr), np.inf),
        cyc_sum=np.zeros((cap, n_tr)), cyc_cnt=np.zeros((cap, n_tr), dtype=np.int64),
        cyc_wt=np.zeros((cap, n_tr)), prev_t=np.full(1, np.nan), prev_f=np.zeros(n_tr),
        prev_c=np.zeros(n_tr, dtype=np.int64), pk_t=np.zeros(2), pk_f=np.zeros(n_tr),
        pk_g=np.zeros((n_tr, 2), dtype=np.int64),
        pk_k=np.zeros(2, dtype=np.int64), pk_n=np.zeros(1, dtype=np.int64),
        pk_x=np.zeros(1, dtype=np.int64), grp_ptr=grp_ptr, grp_col=grp_col,
        grp_min=(np.zeros(len(groups)) if group_min is None
                 else np.asarray(group_min, dtype=np.float64).reshape(len(groups))),
        rat_max=np.full((cap, n_tr), -np.inf), rat_min=np.full((cap, n_tr), np.inf),
        sep_count=np.zeros(n_el, dtype=np.int64), back_count=np.zeros(n_el, dtype=np.int64),
        sep_time=np.zeros(n_el), back_time=np.zeros(n_el), contact_t=np.zeros(2),
        contact_prev=np.zeros((n_el, 3)),
        hist_el=np.asarray(hist_el, dtype=np.int64),
        hist_dof=np.asarray(hist_dof, dtype=np.int64),
        hist_t=np.zeros(n_hist), hist_f=np.zeros((n_hist, n_he)),
        hist_q=np.zeros((n_hist, n_hd)), hist_v=np.zeros((n_hist, n_hd)),
        full_t=np.zeros(n_full), full_y=np.zeros((n_full, 2 * n_dof)),
        **_dense_arrays(dense, n_dense),
    )


def _dense_arrays(dense, n_dense: int) -> dict:
    """The dense record's arrays of :func:`make_record` (see :data:`Record`);
    ``dense``: ``(pairs, ptr, axes, elements, directions, corners)``, the pairs' elements
    (n_p, 2), then the other vectors' terms, and whether the record takes the corners."""
    if dense is None or len(dense[0]) + len(dense[1]) - 1 <= 0:
        return dict(dense=np.zeros((0, 2)), dense_el=np.zeros(DENSE_HEAD, dtype=np.int64),
                    dense_dir=np.zeros((0, 3)))
    pairs, ptr, axes, elements, dirs, corners = (np.asarray(a) for a in dense)
    n_p, n_v = len(pairs), len(pairs) + len(ptr) - 1
    head = np.array([0, 0, n_v, n_p, int(corners)], dtype=np.int64)
    return dict(dense=np.zeros((int(n_dense), 2 + n_v)),
                dense_el=np.concatenate([head, pairs.reshape(-1), ptr, axes,
                                         elements]).astype(np.int64),
                dense_dir=np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3))


def record_bytes(n_cycles_cap: int, n_tracked: int, n_hist: int, n_hist_el: int,
                 n_hist_dof: int, n_full: int, n_dof: int) -> int:
    """Bytes of the output arrays :func:`make_record` would allocate."""
    return 8 * (n_hist * (1 + n_hist_el + 2 * n_hist_dof) + n_full * (1 + 2 * n_dof)
                + 7 * n_cycles_cap * n_tracked)
