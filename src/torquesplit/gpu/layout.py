"""An ensemble's cases split into what the generated code hard-codes and what it reads.

Every case of an ensemble is an assembled structure with its own kernel arrays
(:func:`torquesplit.solve.kernel_data.kernel_model`), initial state, step and tracked
cycles.  Cases whose arrays have the same *pattern* (DOFs, sparsity of V and of the
gyroscopic matrix, which elements are time-varying, have a dead zone, an additive force
table, error sinusoids, tooth friction, spline laws, the corner nodes of their tables,
the tracked elements and load-sharing groups) run the same generated code:
:func:`group_cases` sorts them by pattern.  Within a group, each scalar the code reads is
a *parameter*: one equal in every case becomes a literal of the code (a shared
constant), one that differs becomes a row of the per-case parameter arrays (``P`` for
the dynamics, ``PT`` for times and phases, ``PI`` for integers).  The tables that depend
on the mesh phase (stiffness, additive force, friction, per-cycle half-gap sequences)
are kept once per distinct set (``TK``, ``TF``, ``TFR``, ``GS``; a Monte Carlo of
errors has one set for the whole ensemble) and each case names its set.

Nothing here is a law or a formula: it is bookkeeping of the kernel arrays, so that the
generated code reads exactly the numbers the CPU kernels read.
"""

from __future__ import annotations

import hashlib
import threading
import weakref
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from torquesplit._memo import hash_arrays
from torquesplit.solve import _kernels as kern

__all__ = ["CaseArrays", "Layout", "Group", "group_cases", "pattern_key"]


@dataclass
class CaseArrays:
    """One case as the kernels see it: kernel model, initial state, RK4 plan, tracking."""

    model: object
    """:class:`~torquesplit.solve.kernel_data.KernelModel` of the case."""
    y0: np.ndarray
    t0: float
    h: float
    n_steps: int
    chunk: int
    """Steps per call of the engine's RK4 kernel: corners are found afresh at each
    multiple (``integrate.rk4_chunk``)."""
    track: list[int]
    track_base: np.ndarray
    cap: int
    groups: list[list[int]]
    blowup: float
    group_min: np.ndarray | None = None
    """Per group, the total force below which no ratio is formed (``make_record``'s
    ``group_min``; 0: any positive total)."""


KNOWN_FIELDS = (
    "inv_mass", "external_force", "ground_damping", "element_kind", "v_ptr", "v_dof",
    "v_coef", "stiffness_table", "frequency", "phase", "damping", "gap_ptr",
    "gap_values", "error_constant", "error_ptr", "error_amplitude", "error_omega",
    "error_phase", "force_table", "tv_el", "err_el", "sin_el", "vr_ptr", "vq_idx",
    "vv_idx", "vt_ptr", "vt_el", "vt_coef", "fr_el", "fr_ptr", "fr_dof", "fr_coef",
    "fr_row", "friction_table", "sp_el", "sp_par", "gy_ptr", "gy_idx", "gy_coef",
    "corner_ptr", "corner_node", "fs_ptr", "fs_idx", "fs_coef", "tv_tab",
)
"""The kernel arrays (:class:`~torquesplit.solve.kernel_data.KernelModel` fields) the
generated code reproduces.  A field the engine gains later is a term the GPU kernel
would miss: :func:`unknown_fields` names it and the run is refused (tested: the test
fails when the engine's bundle and this list part)."""


def unknown_fields(model) -> list[str]:
    """Fields of a kernel model that the generated code does not know (see above)."""
    return [f for f in model._fields if f not in KNOWN_FIELDS]


class IdentityMemo:
    """Values computed once per tuple of array *objects* (checked by weak reference, so a
    recycled ``id`` never hits).  A study's cases share their phase tables (the host
    side of the GPU backend makes them share the objects; Ji & Li's drive has 14 MB of
    tables a case): anything computed from a table is computed once, not once a case."""

    def __init__(self, size: int = 64):
        self._entries: OrderedDict = OrderedDict()
        self._size = size
        self._lock = threading.RLock()  # a weakref callback may run while it is held

    def peek(self, arrays: tuple):
        """The value kept for these very objects, or None."""
        with self._lock:
            hit = self._entries.get(tuple(id(a) for a in arrays))
        if hit is not None and all(r() is a for r, a in zip(hit[0], arrays, strict=True)):
            return hit[1]
        return None

    def put(self, arrays: tuple, value) -> None:
        """Keep ``value`` for these objects, until one of them dies (then it goes: a value
        such as a table's copy must not outlive the cases that use it)."""
        key = tuple(id(a) for a in arrays)
        refs = [weakref.ref(a, lambda r, key=key: self._drop(key, r)) for a in arrays]
        with self._lock:
            self._entries[key] = (refs, value)
            while len(self._entries) > self._size:
                self._entries.popitem(last=False)

    def _drop(self, key, ref) -> None:
        with self._lock:
            hit = self._entries.get(key)
            if hit is not None and any(r is ref for r in hit[0]):
                del self._entries[key]

    def __len__(self) -> int:
        return len(self._entries)

    def get(self, arrays: tuple, compute):
        """The value kept for these objects, else ``compute()`` (then kept)."""
        value = self.peek(arrays)
        if value is None:
            value = compute()
            self.put(arrays, value)
        return value


_HAS_FORCE = IdentityMemo()


def has_force(m) -> np.ndarray:
    """Elements with a force table (a meshing-in impact or friction force row)."""
    return _HAS_FORCE.get((m.force_table,), lambda: np.any(m.force_table != 0.0, axis=1))


def _gapped(m) -> np.ndarray:
    gp, gv = m.gap_ptr, m.gap_values
    return np.array([bool(np.any(gv[gp[e]:gp[e + 1]] > 0.0)) for e in range(len(gp) - 1)],
                    dtype=bool)


def pattern_key(case: CaseArrays) -> str:
    """What the generated code depends on besides values (see the module docstring)."""
    m = case.model
    h = hashlib.sha256()
    ne = m.damping.shape[0]
    parts = [
        np.int64(m.inv_mass.shape[0]), np.int64(ne), m.element_kind, m.vr_ptr, m.vq_idx,
        m.vt_ptr, m.vt_el, m.gy_ptr, m.gy_idx, m.fs_ptr, m.fs_idx, m.frequency > 0.0,
        has_force(m), _gapped(m), np.diff(m.gap_ptr), m.error_ptr,
        m.fr_el, m.fr_ptr, m.fr_dof, m.fr_row, m.sp_el, m.corner_ptr, m.corner_node,
        np.int64(m.stiffness_table.shape[1]), np.int64(m.friction_table.shape[1]),
        np.asarray(case.track, dtype=np.int64),
        np.asarray([len(g) for g in case.groups], dtype=np.int64),
        np.asarray([c for g in case.groups for c in g], dtype=np.int64),
        np.float64(case.blowup),
    ]
    return hash_arrays(h, parts).hexdigest()


def group_cases(cases: list[CaseArrays]) -> dict[str, list[int]]:
    """Case indices by pattern key (in first-seen order)."""
    groups: dict[str, list[int]] = {}
    for i, c in enumerate(cases):
        groups.setdefault(pattern_key(c), []).append(i)
    return groups


@dataclass
class Layout:
    """The pattern of a group in index form (taken from its first case; equal in every
    case of the group by construction of the pattern key)."""

    n: int
    ne: int
    n_table: int
    n_fr: int
    element_kind: np.ndarray
    v_ptr: np.ndarray
    v_dof: np.ndarray
    vt_ptr: np.ndarray
    vt_el: np.ndarray
    gy_ptr: np.ndarray
    gy_col: np.ndarray
    """Gyroscopic column as a velocity index (0..n-1)."""
    fs_ptr: np.ndarray
    fs_col: np.ndarray
    """Frame stiffness K_f by row: its columns (displacement indices)."""
    tv: np.ndarray
    """Time-varying elements (frequency > 0), in index order."""
    has_force: np.ndarray
    gapped: np.ndarray
    n_gaps: np.ndarray
    error_ptr: np.ndarray
    err_el: np.ndarray
    fr_el: np.ndarray
    fr_ptr: np.ndarray
    fr_dof: np.ndarray
    fr_row: np.ndarray
    sp_el: np.ndarray
    corner_ptr: np.ndarray
    corner_node: np.ndarray
    track: list[int]
    groups: list[list[int]]
    watch: np.ndarray
    """Elements whose contact state is counted (as ``make_work``'s ``watch_el``)."""
    blowup: float

    @property
    def n_sin(self) -> int:
        return int(self.error_ptr[-1])

    @property
    def corner_elements(self) -> list[int]:
        return [int(e) for e in self.tv if self.corner_ptr[e + 1] > self.corner_ptr[e]]

    @classmethod
    def of(cls, case: CaseArrays) -> "Layout":
        m = case.model
        n = m.inv_mass.shape[0]
        gapped = _gapped(m)
        kind = np.asarray(m.element_kind)
        return cls(
            n=n, ne=m.damping.shape[0], n_table=m.stiffness_table.shape[1],
            n_fr=m.friction_table.shape[1], element_kind=kind,
            v_ptr=np.asarray(m.vr_ptr, dtype=np.int64),
            v_dof=np.asarray(m.vq_idx, dtype=np.int64),
            vt_ptr=np.asarray(m.vt_ptr, dtype=np.int64),
            vt_el=np.asarray(m.vt_el, dtype=np.int64),
            gy_ptr=np.asarray(m.gy_ptr, dtype=np.int64),
            gy_col=np.asarray(m.gy_idx, dtype=np.int64) - n,
            fs_ptr=np.asarray(m.fs_ptr, dtype=np.int64),
            fs_col=np.asarray(m.fs_idx, dtype=np.int64),
            tv=np.flatnonzero(m.frequency > 0.0),
            has_force=has_force(m), gapped=gapped,
            n_gaps=np.diff(m.gap_ptr), error_ptr=np.asarray(m.error_ptr),
            err_el=np.asarray(m.err_el), fr_el=np.asarray(m.fr_el),
            fr_ptr=np.asarray(m.fr_ptr), fr_dof=np.asarray(m.fr_dof),
            fr_row=np.asarray(m.fr_row), sp_el=np.asarray(m.sp_el).reshape(-1, 2),
            corner_ptr=np.asarray(m.corner_ptr), corner_node=np.asarray(m.corner_node),
            track=list(case.track), groups=[list(g) for g in case.groups],
            watch=np.flatnonzero(gapped | (kind == kern.MESH_KIND)),
            blowup=float(case.blowup),
        )


# ---------------------------------------------------------------------- parameters
#: parameter families: (name, kind) with kind "d" dynamics (P, float of the precision),
#: "t" time (PT, always float64), "i" integer (PI)
_D, _T, _I = "d", "t", "i"


@dataclass
class Group:
    """One pattern's cases as arrays for the generated code.

    ``columns[name]`` is, for a scalar parameter ``name`` (e.g. ``("v", 7)``), either
    ``("lit", value)`` (equal in every case) or ``(array, row)`` (row of ``P``, ``PT``
    or ``PI``).  ``P`` (n_p, n_cases), ``PT`` (n_t, n_cases) float64, ``PI`` (n_i,
    n_cases) int64 hold the varying ones, the case index last (adjacent threads read
    adjacent words)."""

    layout: Layout
    cases: list[int]
    columns: dict = field(default_factory=dict)
    P: np.ndarray | None = None
    PT: np.ndarray | None = None
    PI: np.ndarray | None = None
    Y0: np.ndarray | None = None
    TK: np.ndarray | None = None
    TF: np.ndarray | None = None
    TFR: np.ndarray | None = None
    GS: np.ndarray | None = None
    CN: np.ndarray | None = None
    cap_max: int = 0

    @property
    def n_cases(self) -> int:
        return len(self.cases)


PER_CASE = ("t0", "h", "n_steps", "chunk", "cap", "base")
"""Parameters never made literals: the run plan.  A settle rule's rounds (another run
length each) and batches of another length then reuse the compiled kernel."""


def _scalars(L: Layout, c: CaseArrays) -> list[tuple[tuple, str, float]]:
    """Every scalar parameter of one case: (name, kind, value), in a fixed order (the
    arrays read as Python lists, not a numpy scalar a value)."""
    m = c.model
    out: list[tuple[tuple, str, float]] = []
    add = out.append
    for j, v in enumerate(m.v_coef.tolist()):
        add((("v", j), _D, v))
    for j, v in enumerate(m.vt_coef.tolist()):
        add((("vt", j), _D, v))
    tv = set(L.tv.tolist())
    damping, e0 = m.damping.tolist(), m.error_constant.tolist()
    k0, p0 = m.stiffness_table[:, 0].tolist(), m.force_table[:, 0].tolist()
    gaps, gap_ptr = m.gap_values.tolist(), m.gap_ptr.tolist()
    frequency, phase = m.frequency.tolist(), m.phase.tolist()
    n_gaps, has_force = L.n_gaps.tolist(), L.has_force.tolist()
    for e in range(L.ne):
        add((("damp", e), _D, damping[e]))
        add((("E0", e), _D, e0[e]))
        if e not in tv:
            add((("K0", e), _D, k0[e]))
        if e not in tv or not has_force[e]:
            add((("P0", e), _D, p0[e]))
        if n_gaps[e] == 1 or e not in tv:  # a static element keeps its first half-gap
            add((("G0", e), _D, gaps[gap_ptr[e]]))
        if e in tv:
            add((("f", e), _T, frequency[e]))
            add((("ph", e), _T, phase[e]))
    ea, ew, ep = (m.error_amplitude.tolist(), m.error_omega.tolist(),
                  m.error_phase.tolist())
    for i in range(L.n_sin):
        add((("ea", i), _D, ea[i]))
        add((("ew", i), _T, ew[i]))
        add((("ep", i), _T, ep[i]))
    im, ef, cg = m.inv_mass.tolist(), m.external_force.tolist(), m.ground_damping.tolist()
    for i in range(L.n):
        add((("im", i), _D, im[i]))
        add((("ef", i), _D, ef[i]))
        add((("cg", i), _D, cg[i]))
    for j, v in enumerate(m.gy_coef.tolist()):
        add((("gy", j), _D, v))
    for j, v in enumerate(m.fs_coef.tolist()):
        add((("fs", j), _D, v))
    for j, v in enumerate(m.fr_coef.tolist()):
        add((("frc", j), _D, v))
    for j, row in enumerate(np.asarray(m.sp_par).reshape(-1, 6).tolist()
                            if m.sp_par.shape[0] else []):
        for k in range(6):
            add((("sp", j, k), _D, row[k]))
    add((("t0",), _T, float(c.t0)))
    add((("h",), _T, float(c.h)))
    add((("n_steps",), _I, int(c.n_steps)))
    add((("chunk",), _I, int(c.chunk)))
    add((("cap",), _I, int(c.cap)))
    for j, v in enumerate(np.asarray(c.track_base).tolist()[:len(c.track)]):
        add((("base", j), _I, v))
    gmin = [0.0] * len(c.groups) if c.group_min is None else np.asarray(
        c.group_min, dtype=float).tolist()
    for k in range(len(c.groups)):
        add((("gmin", k), _T, gmin[k]))
    return out


def _phase_tables(L: Layout, m) -> tuple[np.ndarray, ...]:
    """A kernel model's phase tables: stiffness and force rows of the time-varying
    elements (force only where it has one), friction rows."""
    tk = m.stiffness_table[L.tv]
    tf = m.force_table[[e for e in L.tv if L.has_force[e]]]
    return tk, tf, m.friction_table


def _gap_sequences(L: Layout, m) -> np.ndarray:
    """The multi-value half-gap sequences of the time-varying elements, concatenated."""
    multi = [int(e) for e in L.tv if L.n_gaps[e] > 1]
    return (np.concatenate([m.gap_values[m.gap_ptr[e]:m.gap_ptr[e + 1]] for e in multi])
            if multi else np.zeros(0))


def build_group(cases: list[CaseArrays], indices: list[int], precision) -> Group:
    """The :class:`Group` of the cases ``indices`` (one pattern) for a dynamics float
    type ``precision`` (np.float64 or np.float32)."""
    first = cases[indices[0]]
    L = Layout.of(first)
    g = Group(layout=L, cases=list(indices))
    per_case = [_scalars(L, cases[i]) for i in indices]
    names = [name for name, _, _ in per_case[0]]
    kinds = [kind for _, kind, _ in per_case[0]]
    for row in per_case[1:]:  # same pattern: same catalogue (else a bug here)
        if [name for name, _, _ in row] != names:
            raise AssertionError("cases of one pattern gave different parameter lists")
    # every case's values as one (cases x parameters) array per kind: the columns
    # equal in every case bit for bit (-0.0 and 0.0 differ, as they may in the code)
    # become literals
    is_int = [kind == _I for kind in kinds]
    fl = np.array([[v for (_, _, v), i in zip(row, is_int) if not i] for row in per_case],
                  dtype=np.float64).reshape(len(per_case), -1)
    it = np.array([[v for (_, _, v), i in zip(row, is_int) if i] for row in per_case],
                  dtype=np.int64).reshape(len(per_case), -1)
    bits = fl.view(np.int64)
    same_f = (bits == bits[:1]).all(axis=0)
    same_i = (it == it[:1]).all(axis=0)
    rows_d, rows_t, rows_i = [], [], []
    kf = ki = 0
    for name, kind, i in zip(names, kinds, is_int, strict=True):
        if i:
            col, same, ki = it[:, ki], same_i[ki], ki + 1
        else:
            col, same, kf = fl[:, kf], same_f[kf], kf + 1
        if same and name[0] not in PER_CASE:
            g.columns[name] = ("lit", col[0].item())
            continue
        target = {_D: rows_d, _T: rows_t, _I: rows_i}[kind]
        g.columns[name] = ({_D: "P", _T: "PT", _I: "PI"}[kind], len(target))
        target.append(col)
    n_c = len(indices)
    # table sets, de-duplicated (a case reads set PI[tset]).  The phase tables are
    # copied and compared once per table memory (the cases of a study share it), the
    # small gap sequences per case: a key of both made every case of a backlash Monte
    # Carlo copy and hash its 12 MB of tables (1 ms a case here; the H200 host's whole
    # set-up was 4 ms a case)
    sets: dict[tuple, int] = {}
    by_object: dict[tuple, int] = {}  # table memory -> index in `phase`
    by_content: dict[bytes, int] = {}
    phase: list[tuple] = []
    tset = np.zeros(n_c, dtype=np.int64)
    tables = []
    for k, i in enumerate(indices):
        m = cases[i].model
        # the tables' memory, not their objects: a kernel model's view of its structure's
        # table is a new object each time (the cases, and so the memory, live through
        # the loop)
        obj = tuple((a.__array_interface__["data"][0], a.shape, a.strides) for a in (
            m.stiffness_table, m.force_table, m.friction_table))
        b = by_object.get(obj)
        if b is None:
            t = _phase_tables(L, m)
            content = b"".join(np.ascontiguousarray(a, dtype=np.float64).tobytes()
                               for a in t)
            b = by_object[obj] = by_content.setdefault(content, len(phase))
            if b == len(phase):
                phase.append(t)
        gs = _gap_sequences(L, m)
        key = (b, np.ascontiguousarray(gs, dtype=np.float64).tobytes())
        if key not in sets:
            sets[key] = len(tables)
            tables.append((*phase[b], gs))
        tset[k] = sets[key]
    if len(tables) > 1:
        g.columns[("tset",)] = ("PI", len(rows_i))
        rows_i.append(tset)
    else:
        g.columns[("tset",)] = ("lit", 0)

    def stack(j):
        arr = np.array([t[j] for t in tables], dtype=np.float64)
        if arr.size == 0:  # numba and the simulator want a non-empty array
            return np.zeros((len(tables), 1, 1))
        return np.ascontiguousarray(arr.reshape(len(tables), arr.shape[1], arr.shape[2]))

    g.TK, g.TF, g.TFR = stack(0), stack(1), stack(2)
    gs = np.array([t[3] for t in tables], dtype=np.float64)
    g.GS = np.ascontiguousarray(gs) if gs.size else np.zeros((len(tables), 1))
    g.CN = (np.ascontiguousarray(L.corner_node, dtype=np.int64) if L.corner_node.size
            else np.zeros(1, dtype=np.int64))

    def matrix(rows, dtype):
        if not rows:
            return np.zeros((1, n_c), dtype=dtype)
        return np.ascontiguousarray(np.array(rows, dtype=dtype).reshape(len(rows), n_c))

    g.P = matrix(rows_d, precision)
    g.PT = matrix(rows_t, np.float64)
    g.PI = matrix(rows_i, np.int64)
    g.Y0 = np.ascontiguousarray(np.array([cases[i].y0 for i in indices], dtype=np.float64).T)
    g.cap_max = max(int(cases[i].cap) for i in indices)
    return g
