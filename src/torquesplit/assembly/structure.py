"""The assembled equations of motion as flat arrays for the compiled kernels.

Every layout reduces to the same form (DESIGN.md §4)::

    M q'' = F_ext - C_g q' - sum_e V_e f_e
    delta_e  = V_e . q  - e_e(t)            deformation of element e
    f_e      = k_e(t) h(delta_e; g_e) + c_e (V_e . q' - e_e'(t)) + p_e(t)

with a diagonal mass ``M``, a sparse projection vector ``V_e`` per element, a periodic
stiffness ``k_e(t)`` (one table row sampled over one excitation period), a dead zone
``h`` of half-width ``g_e`` (backlash or clearance; ``g_e = 0`` means always in
contact), an error ``e_e(t)`` made of a constant plus sinusoids, and an additive periodic
force ``p_e(t)`` (meshing-in impact).  Damping acts only while the element is in contact.

All quantities are SI: metres, radians, newtons, newton-metres, kilograms, kg m^2,
seconds.  Rotational DOFs are the vibratory angle about the body's own axis, measured
from the nominal rigid rotation.

Lifetime: a :class:`Structure` is built once per model (or per study case) and never
mutated; the kernels only read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: element kinds
SPRING = 0
MESH = 1


@dataclass(frozen=True)
class Structure:
    """Assembled, immutable system: DOF map, diagonal mass, element arrays (SI)."""

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
    """(n_el,) int64, SPRING or MESH."""
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

    metadata: dict = field(default_factory=dict, compare=False)
    """Free-form information for post-processing (mesh names, stages, body map...)."""

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
        for e in range(self.n_elements):
            sl = slice(self.v_ptr[e], self.v_ptr[e + 1])
            np.add.at(V[e], self.v_dof[sl], self.v_coef[sl])
        return V

    def mean_stiffness(self) -> np.ndarray:
        """(n_el,) mean of each element's stiffness table [N/m]."""
        return self.stiffness_table.mean(axis=1)

    def stiffness_matrix(self, element_stiffness: np.ndarray | None = None) -> np.ndarray:
        """Dense K = sum_e k_e V_e V_e^T, with the mean stiffness unless given."""
        k = self.mean_stiffness() if element_stiffness is None else element_stiffness
        V = self.projection_matrix()
        return V.T @ (k[:, None] * V)

    def damping_matrix(self) -> np.ndarray:
        """Dense C = sum_e c_e V_e V_e^T + diag(ground damping)."""
        V = self.projection_matrix()
        return V.T @ (self.damping[:, None] * V) + np.diag(self.ground_damping)

    def kernel_arrays(self) -> tuple:
        """The arrays in the order the compiled kernels take them."""
        return (
            self.inv_mass, self.external_force, self.ground_damping,
            self.element_kind, self.v_ptr, self.v_dof, self.v_coef,
            self.stiffness_table, self.frequency, self.phase, self.damping,
            self.gap_ptr, self.gap_values,
            self.error_constant, self.error_ptr, self.error_amplitude,
            self.error_omega, self.error_phase, self.force_table,
        )


def build_structure(
    dof_names,
    inv_mass,
    elements,
    *,
    external_force=None,
    ground_damping=None,
    n_table: int = 256,
    metadata: dict | None = None,
) -> Structure:
    """Pack a list of element descriptions into a :class:`Structure`.

    Each element is a dict with keys ``name``, ``kind`` (SPRING or MESH), ``dofs``
    (indices), ``coefs`` (projection coefficients) and optionally ``stiffness`` (a
    scalar or an array sampled over one period, resampled to ``n_table``),
    ``frequency`` [Hz], ``phase`` [cycles], ``damping``, ``gaps`` (scalar or per-cycle
    sequence of half-gaps), ``error_constant``, ``errors`` (list of
    ``(amplitude, omega, phase)``) and ``force`` (array over one period).
    """
    n_dof = len(dof_names)
    inv_mass = np.ascontiguousarray(inv_mass, dtype=np.float64)
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
    src = np.arange(arr.size) / arr.size
    return np.interp(grid, src, arr, period=1.0)
