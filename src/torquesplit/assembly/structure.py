"""The assembled equations of motion as flat arrays for the compiled kernels.

Every layout reduces to the same form (docs/theory/model.md)::

    M q'' = F_ext - C_g q' - G q' - K_f q - sum_e V_e f_e
    delta_e  = V_e . q  - e_e(t)            deformation of element e
    f_e      = k_e(t) h(delta_e; g_e) + c_e (V_e . q' - e_e'(t)) + p_e(t)

with a diagonal mass ``M``, a sparse projection vector ``V_e`` per element, a periodic
stiffness ``k_e(t)`` (one table row sampled over one excitation period), a dead zone
``h`` of half-width ``g_e`` (backlash or clearance; ``g_e = 0`` means always in
contact), an error ``e_e(t)`` made of a constant plus sinusoids, and an additive periodic
force ``p_e(t)`` (meshing-in impact).  Damping acts only while the element is in contact.

Two optional extensions, both empty (and free) when a model does not use them:

* **Tooth friction** of a mesh element e (Jin et al. 2019): a second, phase-dependent
  projection ``W_e(s)`` used only to apply forces.  The generalized force of the mesh
  becomes ``-V_e f_e - W_e(s) max(f_e, 0)``; the deformation still uses ``V_e`` only.
  ``W_e`` is stored sparsely (``fr_*``): entry i contributes
  ``fr_coef[i] * friction_table[fr_row[i], s]`` on DOF ``fr_dof[i]``, the table rows
  being the friction force and the two friction moments per unit normal load over one
  mesh cycle (see :mod:`torquesplit.assembly.excitation`).
* **Spline radial elements** (Dong et al. 2021 eq. 6): a 2-D radial law between a floating
  member and its hub.  It is stored as two ordinary elements (kind SPLINE) whose
  projection rows give the relative displacement components ``d = (dx, dy)`` (hub
  minus floating member); ``sp_el`` pairs them and ``sp_par`` holds the law.  With
  ``R = |d|`` and ``Rdot = d.d'/R`` the radial force is
  ``F = k R + c Rdot`` (R < S1), ``F = F_m tanh(Rdot / v)`` (S1 <= R <= S2),
  ``F = k (R - S2) + c Rdot + F_m tanh(Rdot / v)`` (R > S2), and the two component
  elements carry ``f_x = F dx / R`` and ``f_y = F dy / R`` (0 at R = 0), so the usual
  ``-V_e f_e`` applies it.  A bearing with a radial clearance is the same law without
  stick limit and friction (``F = k (R - S2) + c Rdot`` beyond S2) on the body's two
  translations across its axis, less their errors (``d = V q - e``, as every element).

All quantities are SI: metres, radians, newtons, newton-metres, kilograms, kg m^2,
seconds.  Rotational DOFs are the vibratory angle about the body's own axis, measured
from the nominal rigid rotation.

Lifetime: a :class:`Structure` is built once per model (or per study case) and never
mutated; the kernels only read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import OptionError

#: element kinds
SPRING = 0
MESH = 1
SPLINE = 2
"""Component (x or y) of a spline radial element; see ``sp_el`` / ``sp_par``."""

#: rows of the friction table per friction mesh: force, moment on driver, on driven
FRICTION_ROWS = 3
#: columns of ``sp_par``
SP_STIFFNESS, SP_DAMPING, SP_STICK, SP_CLEARANCE, SP_FRICTION, SP_VELOCITY = range(6)


def _empty_int(*shape):
    return np.zeros(shape or (0,), dtype=np.int64)


def _empty_float(*shape):
    return np.zeros(shape or (0,), dtype=np.float64)


@dataclass(frozen=True)
class Structure:
    """Assembled, immutable system: DOF map, diagonal mass, element arrays (SI).

    Immutable means its arrays too: the solvers keep what they derive from a structure
    for as long as it lives (kernel arrays, the step check's eigenvalues), so change a
    structure by building another (``dataclasses.replace``), never in place."""

    dof_names: tuple[str, ...]
    """One name per DOF, ``"<body>.<x|y|z|theta>"``."""
    inv_mass: np.ndarray
    """(n_dof,) inverse mass or inverse polar inertia."""
    external_force: np.ndarray
    """(n_dof,) constant generalized forces: drive and load torques [N, N m]."""
    ground_damping: np.ndarray
    """(n_dof,) damping to ground (speed characteristic of a load) [N s/m, N m s/rad]."""

    element_names: tuple[str, ...]
    element_kind: np.ndarray
    """(n_el,) int64, SPRING, MESH or SPLINE."""
    v_ptr: np.ndarray
    """(n_el + 1,) int64: entries of element e are v_dof[v_ptr[e]:v_ptr[e+1]]."""
    v_dof: np.ndarray
    """(nnz,) int64 DOF index of each projection entry."""
    v_coef: np.ndarray
    """(nnz,) float64 projection coefficient [-] for translations, [m] for rotations."""

    stiffness_table: np.ndarray
    """(n_el, n_table) stiffness over one excitation period [N/m]; constant rows for springs."""
    frequency: np.ndarray
    """(n_el,) excitation (mesh) frequency [Hz]; 0 for time-invariant elements."""
    phase: np.ndarray
    """(n_el,) excitation phase at t = 0 [cycles, 0..1)."""
    damping: np.ndarray
    """(n_el,) viscous damping along the element [N s/m]."""

    gap_ptr: np.ndarray
    """(n_el + 1,) int64: half-gap sequence of element e is gap_values[gap_ptr[e]:gap_ptr[e+1]]."""
    gap_values: np.ndarray
    """Half-gap per excitation cycle [m] (backlash / clearance); the sequence repeats.
    A single 0 means no dead zone."""

    error_constant: np.ndarray
    """(n_el,) constant error along the element [m]."""
    error_ptr: np.ndarray
    """(n_el + 1,) int64 pointer into the sinusoid arrays."""
    error_amplitude: np.ndarray
    """Amplitude of each error sinusoid [m]: e = A sin(omega t + phi)."""
    error_omega: np.ndarray
    """Angular frequency of each error sinusoid [rad/s]."""
    error_phase: np.ndarray
    """Phase of each error sinusoid [rad]."""

    force_table: np.ndarray
    """(n_el, n_table) additive periodic force along the element [N] (impact); zeros if none."""

    fr_el: np.ndarray = field(default_factory=_empty_int)
    """(n_fm,) int64 element index of each mesh with tooth friction."""
    fr_ptr: np.ndarray = field(default_factory=lambda: _empty_int(1))
    """(n_fm + 1,) int64: friction entries of friction mesh j are fr_*[fr_ptr[j]:fr_ptr[j+1]]."""
    fr_dof: np.ndarray = field(default_factory=_empty_int)
    """(n_fe,) int64 DOF of each friction entry."""
    fr_coef: np.ndarray = field(default_factory=_empty_float)
    """(n_fe,) float64 coefficient of each friction entry [-]: W_i(s) = coef * table[row, s]."""
    fr_row: np.ndarray = field(default_factory=_empty_int)
    """(n_fe,) int64 row of ``friction_table`` of each entry."""
    friction_table: np.ndarray = field(default_factory=lambda: _empty_float(0, 1))
    """(3 n_fm, n_table) per unit normal load over one mesh cycle: rows 3j, 3j+1, 3j+2 of
    friction mesh j are the friction force [-], and the friction moments on the driver
    and on the driven gear [m] (positive in each gear's direction of rotation)."""
    sp_el: np.ndarray = field(default_factory=lambda: _empty_int(0, 2))
    """(n_sp, 2) int64: the x and y component elements of each spline radial element."""
    sp_par: np.ndarray = field(default_factory=lambda: _empty_float(0, 6))
    """(n_sp, 6) float64: stiffness k [N/m], damping c [N s/m], stick limit S1 [m],
    radial clearance S2 [m], friction force F_m [N], velocity scale v [m/s] of the
    regularised Coulomb friction (columns SP_*)."""

    gy_ptr: np.ndarray = field(default_factory=_empty_int)
    """(n_dof + 1,) int64, or empty for none: the gyroscopic matrix G by row (CSR).  The
    generalized force on DOF i is ``-sum_j G_ij v_j`` (Coriolis coupling of the
    translations of a body in a rotating frame: skew-symmetric, does no work)."""
    gy_idx: np.ndarray = field(default_factory=_empty_int)
    """(n_gy,) int64 column (DOF) of each entry of G."""
    gy_coef: np.ndarray = field(default_factory=_empty_float)
    """(n_gy,) float64 value of each entry of G [N s/m, N m s/rad]."""

    fs_ptr: np.ndarray = field(default_factory=_empty_int)
    """(n_dof + 1,) int64, or empty for none: the frame stiffness matrix K_f by row (CSR).
    The generalized force on DOF i is ``-sum_j K_f,ij q_j``: the inertial stiffness of a
    turning frame (centripetal softening -m Omega^2 of a body's in-plane translations, a
    held carrier's pin preload: :mod:`~torquesplit.assembly.rotating`).  Not an element: it
    holds nothing and carries no force of its own."""
    fs_idx: np.ndarray = field(default_factory=_empty_int)
    """(n_fs,) int64 column (DOF) of each entry of K_f."""
    fs_coef: np.ndarray = field(default_factory=_empty_float)
    """(n_fs,) float64 value of each entry of K_f [N/m, N m/rad]."""

    metadata: dict = field(default_factory=dict, compare=False)
    """Free-form information for post-processing (mesh names, stages, body map...)."""

    def __repr__(self) -> str:
        """One line (the generated repr printed every array: 6 000 characters for a
        14-DOF drive)."""
        kinds = np.asarray(self.element_kind)
        counts = [(int(np.sum(kinds == k)), word) for k, word in
                  ((MESH, "meshes"), (SPRING, "springs"), (SPLINE, "spline components"))]
        parts = ", ".join(f"{n} {word}" for n, word in counts if n)
        varying = int(np.sum(np.asarray(self.frequency) > 0))
        return (f"<Structure: {self.n_dof} DOFs, {self.n_elements} elements ({parts}), "
                f"{varying} time-varying; .dof_names, .element_names, "
                f".projection_matrix()>")

    # ------------------------------------------------------------------ sizes
    @property
    def n_dof(self) -> int:
        return int(self.inv_mass.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.element_kind.shape[0])

    @property
    def n_table(self) -> int:
        return int(self.stiffness_table.shape[1])

    def projection_matrix(self) -> np.ndarray:
        """Dense (n_el, n_dof) matrix whose rows are the projection vectors V_e."""
        V = np.zeros((self.n_elements, self.n_dof))
        owner = np.repeat(np.arange(self.n_elements), np.diff(self.v_ptr))
        # (one call: an element's entries on one DOF are summed in their order, as before)
        np.add.at(V, (owner, np.asarray(self.v_dof, dtype=np.int64)), self.v_coef)
        return V

    @property
    def n_friction(self) -> int:
        """Number of meshes with tooth friction."""
        return int(self.fr_el.shape[0])

    @property
    def n_splines(self) -> int:
        """Number of spline radial elements (each is two component elements)."""
        return int(self.sp_el.shape[0])

    def friction_matrix(self, values: np.ndarray | None = None) -> np.ndarray:
        """Dense (n_el, n_dof) friction projections W_e for friction-table values
        ``values`` (one per row of ``friction_table``); the mean of each row if None.
        Rows of elements without friction are zero."""
        vals = self.friction_table.mean(axis=1) if values is None else np.asarray(values)
        W = np.zeros((self.n_elements, self.n_dof))
        for j, e in enumerate(self.fr_el):
            sl = slice(self.fr_ptr[j], self.fr_ptr[j + 1])
            np.add.at(W[e], self.fr_dof[sl], self.fr_coef[sl] * vals[self.fr_row[sl]])
        return W

    @property
    def n_gyroscopic(self) -> int:
        """Number of non-zero entries of the gyroscopic matrix."""
        return int(self.gy_idx.shape[0])

    def gyroscopic_matrix(self) -> np.ndarray:
        """Dense (n_dof, n_dof) gyroscopic matrix G (generalized force -G v)."""
        Gm = np.zeros((self.n_dof, self.n_dof))
        for i in range(self.n_dof if self.gy_ptr.size else 0):
            sl = slice(self.gy_ptr[i], self.gy_ptr[i + 1])
            np.add.at(Gm[i], self.gy_idx[sl], self.gy_coef[sl])
        return Gm

    @property
    def n_frame_stiffness(self) -> int:
        """Number of non-zero entries of the frame stiffness matrix."""
        return int(self.fs_idx.shape[0])

    def frame_stiffness_matrix(self) -> np.ndarray:
        """Dense (n_dof, n_dof) frame stiffness K_f (generalized force -K_f q)."""
        Km = np.zeros((self.n_dof, self.n_dof))
        for i in range(self.n_dof if self.fs_ptr.size else 0):
            sl = slice(self.fs_ptr[i], self.fs_ptr[i + 1])
            np.add.at(Km[i], self.fs_idx[sl], self.fs_coef[sl])
        return Km

    def mean_stiffness(self) -> np.ndarray:
        """(n_el,) mean of each element's stiffness table [N/m]."""
        return self.stiffness_table.mean(axis=1)

    def stiffness_matrix(self, element_stiffness: np.ndarray | None = None) -> np.ndarray:
        """Dense K = sum_e k_e V_e V_e^T + K_f, with the mean stiffness unless given."""
        k = self.mean_stiffness() if element_stiffness is None else element_stiffness
        V = self.projection_matrix()
        return V.T @ (k[:, None] * V) + self.frame_stiffness_matrix()

    def element_damping(self) -> np.ndarray:
        """Damping c_e of every element, a spline component's with the largest tangent of
        its regularised friction, F_m / v, added (the stiffest damping the run can meet;
        the RK4 stability check uses it)."""
        c = self.damping.astype(float).copy()
        for j in range(self.n_splines):
            par = self.sp_par[j]
            if par[SP_FRICTION] > 0 and par[SP_VELOCITY] > 0:
                c[self.sp_el[j]] += par[SP_FRICTION] / par[SP_VELOCITY]
        return c

    def damping_matrix(self) -> np.ndarray:
        """Dense C = sum_e c_e V_e V_e^T + diag(ground damping), c_e from
        :meth:`element_damping`."""
        V = self.projection_matrix()
        c = self.element_damping()
        return V.T @ (c[:, None] * V) + np.diag(self.ground_damping)


def merged_entries(entries) -> list[tuple[int, int, float]]:
    """``(i, j, value)`` entries sorted, those on one (i, j) added into one (in sorted
    order): each costs a multiply-add per right-hand side (a free carrier's rotation row
    had one per planet direction for the same entry)."""
    out: list[list] = []
    for i, j, v in sorted((int(i), int(j), float(v)) for i, j, v in entries):
        if out and out[-1][0] == i and out[-1][1] == j:
            out[-1][2] += v
        else:
            out.append([i, j, v])
    return [(i, j, v) for i, j, v in out]


def build_structure(
    dof_names,
    inv_mass,
    elements,
    *,
    external_force=None,
    ground_damping=None,
    gyroscopic=(),
    frame_stiffness=(),
    n_table: int = 256,
    metadata: dict | None = None,
) -> Structure:
    """Pack a list of element descriptions into a :class:`Structure`.

    Each element is a dict with keys ``name``, ``kind`` (SPRING, MESH or SPLINE),
    ``dofs`` (indices), ``coefs`` (projection coefficients) and optionally
    ``stiffness`` (a scalar or an array sampled over one period, resampled to
    ``n_table``), ``frequency`` [Hz], ``phase`` [cycles], ``damping``, ``gaps`` (scalar
    or per-cycle sequence of half-gaps), ``error_constant``, ``errors`` (list of
    ``(amplitude, omega, phase)``) and ``force`` (array over one period).

    A MESH may carry ``friction``: a dict with ``table`` (3 arrays over one mesh cycle:
    friction force, moment on the driver, moment on the driven gear, per unit normal
    load; resampled to ``n_table``), ``dofs``, ``coefs`` and ``rows`` (0, 1 or 2: the
    table row each entry scales).  See the module docstring.

    A SPLINE describes a whole radial element and becomes two component elements named
    ``<name>.x`` and ``<name>.y`` (or ``component_names``): give ``x`` and ``y`` as
    ``(dofs, coefs)`` (the rows of the relative displacement hub - floating member; either
    may be empty), and ``stiffness``, ``damping``, ``stick_limit``, ``clearance``,
    ``friction_force`` and ``velocity_scale`` (scalars, SI); optionally each component's
    error ``error_constant_x`` / ``errors_x`` (and ``_y``), subtracted from its
    displacement like an element's (a radial bearing's seat offset and eccentricity).

    ``gyroscopic`` lists ``(i, j, g)`` entries of the gyroscopic matrix: the generalized
    force on DOF i gets ``-g v_j`` (entries on one (i, j) add up); ``frame_stiffness``
    lists ``(i, j, k)`` entries of the frame stiffness matrix: DOF i gets ``-k q_j``.
    """
    n_dof = len(dof_names)
    inv_mass = np.ascontiguousarray(inv_mass, dtype=np.float64)
    expanded: list[dict] = []
    splines: list[tuple[int, int, list[float]]] = []
    for el in elements:
        if el.get("kind", SPRING) != SPLINE:
            expanded.append(el)
            continue
        k = float(el.get("stiffness", 0.0))
        c = float(el.get("damping", 0.0))
        idx = []
        names = el.get("component_names", ("x", "y"))
        for comp, label in zip(("x", "y"), names, strict=True):
            dofs, coefs = el.get(comp, ((), ()))
            idx.append(len(expanded))
            expanded.append({"name": f"{el['name']}.{label}", "kind": SPLINE,
                             "dofs": list(dofs), "coefs": list(coefs), "stiffness": k,
                             "damping": c,
                             "error_constant": el.get(f"error_constant_{comp}", 0.0),
                             "errors": el.get(f"errors_{comp}", [])})
        s1 = float(el.get("stick_limit", 0.0))
        s2 = float(el.get("clearance", 0.0))
        if not 0.0 <= s1 <= s2:
            raise OptionError(f"spline {el['name']!r}: need 0 <= stick_limit <= clearance, got "
                             f"{s1!r} and {s2!r} m")
        par = [k, c, s1, s2, float(el.get("friction_force", 0.0)),
               float(el.get("velocity_scale", 1e-4))]
        if par[SP_FRICTION] < 0 or not par[SP_VELOCITY] > 0:
            raise OptionError(f"spline {el['name']!r}: friction_force must be >= 0 N and "
                             f"velocity_scale > 0 m/s")
        splines.append((idx[0], idx[1], par))
    elements = expanded
    n_el = len(elements)
    kind = np.zeros(n_el, dtype=np.int64)
    v_ptr = np.zeros(n_el + 1, dtype=np.int64)
    v_dof: list[int] = []
    v_coef: list[float] = []
    ktab = np.zeros((n_el, n_table))
    ftab = np.zeros((n_el, n_table))
    freq = np.zeros(n_el)
    phase = np.zeros(n_el)
    damp = np.zeros(n_el)
    gap_ptr = np.zeros(n_el + 1, dtype=np.int64)
    gaps: list[float] = []
    e_const = np.zeros(n_el)
    e_ptr = np.zeros(n_el + 1, dtype=np.int64)
    e_amp: list[float] = []
    e_om: list[float] = []
    e_ph: list[float] = []
    fr_el: list[int] = []
    fr_ptr = [0]
    fr_dof: list[int] = []
    fr_coef: list[float] = []
    fr_row: list[int] = []
    fr_tab: list[np.ndarray] = []
    grid = np.arange(n_table) / n_table
    for i, el in enumerate(elements):
        kind[i] = el.get("kind", SPRING)
        v_dof.extend(int(d) for d in el["dofs"])
        v_coef.extend(float(c) for c in el["coefs"])
        v_ptr[i + 1] = len(v_dof)
        ktab[i] = _resample_periodic(el.get("stiffness", 0.0), grid)
        if "force" in el:
            ftab[i] = _resample_periodic(el["force"], grid)
        freq[i] = el.get("frequency", 0.0)
        phase[i] = el.get("phase", 0.0) % 1.0
        damp[i] = el.get("damping", 0.0)
        g = np.atleast_1d(np.asarray(el.get("gaps", 0.0), dtype=float))
        gaps.extend(g.tolist())
        gap_ptr[i + 1] = len(gaps)
        e_const[i] = el.get("error_constant", 0.0)
        for amp, om, ph in el.get("errors", ()):
            e_amp.append(amp)
            e_om.append(om)
            e_ph.append(ph)
        e_ptr[i + 1] = len(e_amp)
        fr = el.get("friction")
        if fr is not None:
            if kind[i] != MESH:
                raise OptionError(f"element {el['name']!r}: only a MESH can have tooth friction")
            table = fr["table"]
            if len(table) != FRICTION_ROWS:
                raise OptionError(f"element {el['name']!r}: the friction table needs 3 rows "
                                 "(force, moment on driver, moment on driven gear)")
            base = FRICTION_ROWS * len(fr_el)
            fr_el.append(i)
            fr_tab.extend(_resample_periodic(row, grid) for row in table)
            for d, c, r in zip(fr["dofs"], fr["coefs"], fr["rows"], strict=True):
                if not 0 <= int(r) < FRICTION_ROWS:
                    raise OptionError(f"element {el['name']!r}: friction rows are 0, 1 or 2")
                fr_dof.append(int(d))
                fr_coef.append(float(c))
                fr_row.append(base + int(r))
            fr_ptr.append(len(fr_dof))
    gy = merged_entries(gyroscopic)
    for i, j, g in gy:
        if not (0 <= i < n_dof and 0 <= j < n_dof and np.isfinite(g)):
            raise OptionError(f"gyroscopic entry ({i}, {j}, {g}) is out of range or not "
                             f"finite; DOF indices are 0..{n_dof - 1}")
    gy_ptr = np.zeros(n_dof + 1, dtype=np.int64)
    for i, _, _ in gy:
        gy_ptr[i + 1] += 1
    fs = merged_entries(frame_stiffness)
    for i, j, k in fs:
        if not (0 <= i < n_dof and 0 <= j < n_dof and np.isfinite(k)):
            raise OptionError(f"frame stiffness entry ({i}, {j}, {k}) is out of range or not "
                             f"finite; DOF indices are 0..{n_dof - 1}")
    fs_ptr = np.zeros(n_dof + 1, dtype=np.int64)
    for i, _, _ in fs:
        fs_ptr[i + 1] += 1
    return Structure(
        dof_names=tuple(dof_names),
        inv_mass=inv_mass,
        external_force=_vec(external_force, n_dof),
        ground_damping=_vec(ground_damping, n_dof),
        element_names=tuple(el["name"] for el in elements),
        element_kind=kind,
        v_ptr=v_ptr,
        v_dof=np.asarray(v_dof, dtype=np.int64),
        v_coef=np.asarray(v_coef, dtype=np.float64),
        stiffness_table=ktab,
        frequency=freq,
        phase=phase,
        damping=damp,
        gap_ptr=gap_ptr,
        gap_values=np.asarray(gaps, dtype=np.float64),
        error_constant=e_const,
        error_ptr=e_ptr,
        error_amplitude=np.asarray(e_amp, dtype=np.float64),
        error_omega=np.asarray(e_om, dtype=np.float64),
        error_phase=np.asarray(e_ph, dtype=np.float64),
        force_table=ftab,
        fr_el=np.asarray(fr_el, dtype=np.int64),
        fr_ptr=np.asarray(fr_ptr, dtype=np.int64),
        fr_dof=np.asarray(fr_dof, dtype=np.int64),
        fr_coef=np.asarray(fr_coef, dtype=np.float64),
        fr_row=np.asarray(fr_row, dtype=np.int64),
        friction_table=(np.asarray(fr_tab, dtype=np.float64) if fr_tab
                        else np.zeros((0, n_table))),
        sp_el=np.asarray([[a, b] for a, b, _ in splines], dtype=np.int64).reshape(-1, 2),
        sp_par=np.asarray([p for _, _, p in splines], dtype=np.float64).reshape(-1, 6),
        gy_ptr=np.cumsum(gy_ptr),
        gy_idx=np.asarray([j for _, j, _ in gy], dtype=np.int64),
        gy_coef=np.asarray([g for _, _, g in gy], dtype=np.float64),
        fs_ptr=np.cumsum(fs_ptr),
        fs_idx=np.asarray([j for _, j, _ in fs], dtype=np.int64),
        fs_coef=np.asarray([k for _, _, k in fs], dtype=np.float64),
        metadata=dict(metadata or {}),
    )


def _vec(x, n: int) -> np.ndarray:
    if x is None:
        return np.zeros(n)
    return np.ascontiguousarray(np.broadcast_to(np.asarray(x, dtype=np.float64), (n,)))


def _resample_periodic(values, grid: np.ndarray) -> np.ndarray:
    """A scalar, or samples over one period at uniform phases, resampled to ``grid``."""
    arr = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if arr.size == 1:
        return np.full(grid.shape, arr[0])
    if arr.size == grid.size:  # already on the grid (a hunting-period table): interp would
        return arr             # return it unchanged, at 1.5 ms for 65,536 samples
    src = np.arange(arr.size) / arr.size
    return np.interp(grid, src, arr, period=1.0)


def element_units(structure: Structure) -> list[str]:
    """Unit of each element's force: ``"N m"`` for a spring that joins rotations only
    (shaft, spline torsion, torsional support: its force is a torque), else ``"N"`` (a
    mesh's normal force also on a torsional model, whose projection holds base radii)."""
    theta = np.array([n.endswith(".theta") for n in structure.dof_names], dtype=bool)
    out = []
    for e in range(len(structure.element_names)):
        dofs = structure.v_dof[structure.v_ptr[e]:structure.v_ptr[e + 1]]
        torque = structure.element_kind[e] == SPRING and dofs.size and theta[dofs].all()
        out.append("N m" if torque else "N")
    return out


def dof_units(structure: Structure) -> list[str]:
    """Unit of each DOF's displacement: ``"rad"`` for a rotation (``*.theta``), else
    ``"m"``."""
    return ["rad" if n.endswith(".theta") else "m" for n in structure.dof_names]


def history_elements(structure: Structure, mesh_names) -> list[int]:
    """Elements whose forces a run's history keeps, in its column order: the meshes (as
    named), the supports (bearing forces), then every other element (shaft and spline
    torques, torsional supports)."""
    names = list(structure.element_names)
    track = [names.index(m) for m in mesh_names]
    supports = [i for i, n in enumerate(names) if ".support." in n and i not in track]
    rest = [i for i in range(len(names)) if i not in track and i not in supports]
    return track + supports + rest

