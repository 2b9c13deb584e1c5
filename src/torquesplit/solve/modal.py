"""Undamped modes of a structure linearised about a displacement state.

The linearisation is the derivative of the element laws (:mod:`torquesplit.solve.laws`)
at the linearisation state: each element contributes ``k_e dh/dd V_e V_e^T`` with its
mean stiffness and the slope of :func:`~torquesplit.solve.laws.dead_zone` at
``V_e.q - e_e`` (constant error, mean half-gap): 1 in contact, 0 when separated.  A
spline radial element contributes the Jacobian of
:func:`~torquesplit.solve.laws.spline_tangent` at rest in the plane of its two
component rows: ``k`` in both directions when sticking (or without clearance), nothing
while floating, and ``k`` radially, ``k (R - S2) / R`` tangentially once its clearance
has closed; half of its strain energy is assigned to each of its two component elements.
A structure with a gyroscopic matrix G (bodies in a rotating frame) has the quadratic
eigenproblem ``(K + i omega G - omega^2 M) phi = 0``: it is solved in first-order form and
its modes are complex (forward and backward whirl split by G).  Tooth friction (non-conservative) and the spline
friction are left out: these are the modes of the conservative system.  The generalized
eigenproblem ``K phi = omega^2 M phi`` is solved in the symmetric form
``(M^-1/2 K M^-1/2) psi = omega^2 psi`` with ``phi = M^-1/2 psi`` (mass-normalised:
``phi^T M phi = 1``).  Modes with ``omega^2`` below ``rigid_tolerance`` x the largest
are rigid-body modes; they are reported apart and left out of the frequency list.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit.assembly.structure import Structure
from torquesplit.errors import OptionError
from torquesplit.solve import laws
from torquesplit.solve._frozen import freeze_arrays

__all__ = ["ModalSolution", "modal_analysis", "DEGENERATE_RTOL"]

DEGENERATE_RTOL = 1e-6
"""Modes whose frequencies agree to this relative difference form one degenerate group
(the planets' translational pairs of a carrier at rest, symmetric layouts)."""


@dataclass(frozen=True, eq=False)
class ModalSolution:
    """Natural frequencies and modes (SI; columns are modes, ascending frequency)."""

    frequencies: np.ndarray
    """(n_modes,) natural frequencies [Hz] of the elastic modes; a negative value marks
    a statically unstable mode (negative stiffness), its magnitude sqrt(|lambda|)/2 pi."""
    mode_shapes: np.ndarray
    """(n_dof, n_modes) mass-normalised mode shapes, phi^H M phi = 1 (complex with a
    gyroscopic matrix): [kg^-1/2] on translations, [rad m^-1 kg^-1/2] on rotations
    (M in kg and kg m^2; the modal coordinate in m kg^1/2)."""
    strain_energy_fraction: np.ndarray
    """(n_modes, n_el) share of each element in the mode's strain energy (rows sum to 1)."""
    damping_ratios: np.ndarray
    """(n_modes,) modal damping estimate Re(phi^H C phi) / (2 omega + Im(phi^H G phi)):
    the first-order change of the eigenvalue by C, the coupling of modes through C
    ignored (phi^T C phi / (2 omega) without a gyroscopic matrix G)."""
    rigid_modes: np.ndarray
    """(n_dof, n_rigid) mass-normalised rigid-body modes."""
    active: np.ndarray
    """(n_el,) bool: elements in contact at the linearisation state."""
    dof_names: tuple[str, ...]
    element_names: tuple[str, ...]

    def __post_init__(self):
        freeze_arrays(self)

    @property
    def n_modes(self) -> int:
        return int(self.frequencies.shape[0])

    def dominant_elements(self, mode: int, n: int = 3, *, group_rtol: float | None = None
                          ) -> list[tuple[str, float]]:
        """The ``n`` elements with the largest strain-energy share in ``mode``; with
        ``group_rtol``, in the degenerate group of ``mode`` (:meth:`group_of`,
        :meth:`group_shares`), whose shares do not depend on the basis the eigensolver
        returned for it, as a single mode's of the group do."""
        frac = (self.strain_energy_fraction[mode] if group_rtol is None
                else self.group_shares(self.group_of(mode, group_rtol)))
        order = np.argsort(-frac)[:n]
        return [(self.element_names[i], float(frac[i])) for i in order]

    def group_of(self, mode: int, rtol: float = DEGENERATE_RTOL) -> list[int]:
        """``mode`` and its neighbours in frequency within ``rtol`` (relative): its
        degenerate group (modes in ascending frequency)."""
        f = self.frequencies
        near = abs(f - f[mode]) <= rtol * max(abs(float(f[mode])), 1e-300)
        lo, hi = mode, mode
        while lo > 0 and near[lo - 1]:
            lo -= 1
        while hi + 1 < len(f) and near[hi + 1]:
            hi += 1
        return list(range(lo, hi + 1))

    def group_shares(self, members) -> np.ndarray:
        """(n_el,) each element's share of the strain energy of the modes ``members``
        together: the sum over them of each mode's shares weighted by its strain energy
        omega^2 / 2 (mass-normalised modes), over the total -- the trace of the element's
        stiffness over the group's subspace, the same in any basis of it."""
        m = list(members)
        e = (np.asarray(self.frequencies)[m] ** 2)[:, None] * self.strain_energy_fraction[m]
        return e.sum(axis=0) / max(float(e.sum()), 1e-300)


def _orthonormal_groups(phi: np.ndarray, freqs: np.ndarray, mass: np.ndarray
                        ) -> np.ndarray:
    """The modes of each degenerate group (:data:`DEGENERATE_RTOL`) made orthonormal
    in the mass metric (phi^H M phi = I over the group; Cholesky of its Gram matrix).
    The gyroscopic solver returns each mode mass-normalised, but a repeated pair's two
    complex shapes need not be orthogonal, and then the group's strain energy summed
    over them (:meth:`ModalSolution.group_shares`) depended on the basis: 30 / 28 / 17 %
    for three of five identical planets of a turning carrier, where each takes a fifth.
    Any combination within the group is still a mode of its frequency."""
    out = np.array(phi, copy=True)
    i = 0
    while i < len(freqs):
        j = i + 1
        while j < len(freqs) and (abs(freqs[j] - freqs[i])
                                  <= DEGENERATE_RTOL * max(abs(float(freqs[i])), 1e-300)):
            j += 1
        if j - i > 1:
            block = out[:, i:j]
            gram = block.conj().T @ (mass[:, None] * block)
            L = np.linalg.cholesky(0.5 * (gram + gram.conj().T))
            out[:, i:j] = np.linalg.solve(L.conj(), block.T).T  # block @ inv(L^H)
        i = j
    return out


def modal_analysis(structure: Structure, q=None, *, rigid_tolerance: float = 1e-10
                   ) -> ModalSolution:
    """Natural frequencies, mass-normalised modes and modal strain energy per element.

    Parameters
    ----------
    structure : Structure
    q : array_like, optional
        Displacements (n_dof) to linearise about, typically
        ``static_equilibrium(structure).q``.  None: every element in contact.
    rigid_tolerance : float
        Eigenvalues omega^2 below this fraction of the largest are rigid-body modes.

    Examples
    --------
    >>> from torquesplit.assembly.structure import build_structure
    >>> s = build_structure(["m.x"], [1.0], [dict(name="k", dofs=[0], coefs=[1.0],
    ...                                           stiffness=(2 * 3.141592653589793)**2)])
    >>> modal_analysis(s).frequencies
    array([1.])
    """
    s = structure
    V = s.projection_matrix()
    k = s.mean_stiffness()
    g = np.array([s.gap_values[s.gap_ptr[i]:s.gap_ptr[i + 1]].mean()
                  for i in range(s.n_elements)])
    if q is None:  # every element in contact: the slope of the law beyond its dead zone
        delta = None
        slope = np.ones(s.n_elements)
    else:
        q = np.asarray(q, dtype=float)
        if q.shape != (s.n_dof,):
            raise OptionError(f"q must hold {s.n_dof} displacements, got shape {q.shape}; "
                             "pass e.g. static_equilibrium(structure).q.")
        delta = V @ q - s.error_constant
        h, slope, u = (np.empty(s.n_elements) for _ in range(3))
        laws.dead_zones(delta, g, h, slope, u)
    k_act = k * slope
    active = slope > 0
    sp_tangent = []  # (x element, y element, 2 x 2 tangent, their two rows of V)
    for j in range(s.n_splines):
        ex, ey = (int(i) for i in s.sp_el[j])
        dx, dy = (0.0, 0.0) if delta is None else (delta[ex], delta[ey])
        h2 = _spline_tangent(s.sp_par[j], dx, dy, closed=delta is None)
        c2 = _spline_damping(s.sp_par[j], dx, dy, closed=delta is None)
        k_act[ex] = k_act[ey] = 0.0
        active[ex] = active[ey] = bool(np.any(h2 != 0))
        sp_tangent.append((ex, ey, h2, c2, V[[ex, ey]]))
    K = V.T @ (k_act[:, None] * V) + s.frame_stiffness_matrix()
    for _, _, h2, _, rows in sp_tangent:
        K = K + rows.T @ h2 @ rows
    # damping: each element's along its projection while in contact; a radial law's as it
    # acts, on the radial rate only (its 2 x 2 rate tangent), not on both components
    c_el = np.where(active, s.damping, 0.0)
    for ex, ey, _, _, _ in sp_tangent:
        c_el[ex] = c_el[ey] = 0.0
    C = V.T @ (c_el[:, None] * V) + np.diag(s.ground_damping)
    for _, _, _, c2, rows in sp_tangent:
        C = C + rows.T @ c2 @ rows
    Gm = s.gyroscopic_matrix() if s.n_gyroscopic else None
    if Gm is not None:
        freqs, phi_e, phi_r, lam_e = _gyroscopic_modes(K, Gm, s.inv_mass, rigid_tolerance)
        phi_e = _orthonormal_groups(phi_e, freqs, 1.0 / np.asarray(s.inv_mass))
    else:
        d = np.sqrt(s.inv_mass)
        A = d[:, None] * K * d[None, :]
        A = 0.5 * (A + A.T)
        lam, psi = np.linalg.eigh(A)
        lam_max = float(np.max(np.abs(lam))) if lam.size else 0.0
        rigid = np.abs(lam) <= rigid_tolerance * lam_max
        phi = d[:, None] * psi
        lam_e = lam[~rigid]
        phi_e = phi[:, ~rigid]
        phi_r = phi[:, rigid]
        freqs = np.sign(lam_e) * np.sqrt(np.abs(lam_e)) / (2 * math.pi)
    energy = k_act[None, :] * np.abs(V @ phi_e).T ** 2
    for ex, ey, h2, _, rows in sp_tangent:
        # the law's energy u^H h2 u, each component's term u_i^H (h2 u)_i (a bearing's
        # motion along x stores its energy in the x component, not half in each)
        u = rows @ phi_e  # (2, n_modes)
        hu = h2 @ u
        energy[:, ex] = np.real(u[0].conj() * hu[0])
        energy[:, ey] = np.real(u[1].conj() * hu[1])
    total = energy.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(total != 0, energy / total, 0.0)
    # (lam^2 M + lam (G + C) + K) phi = 0, lam = i omega + d: phi^H (2 lam M + G) phi dlam
    # = -lam phi^H C phi gives -Re(dlam) / omega = phi^H C phi / (2 omega + Im(phi^H G phi))
    # (phi^H M phi = 1; the left eigenvector of the undamped gyroscopic problem is phi)
    omega = np.sqrt(np.abs(lam_e))
    denom = 2 * omega
    if Gm is not None and omega.size:
        denom = denom + np.imag(np.einsum("im,ij,jm->m", phi_e.conj(), Gm, phi_e))
    zeta = (np.real(np.einsum("im,ij,jm->m", phi_e.conj(), C, phi_e)) / denom
            if omega.size else np.zeros(0))
    # an undamped mode's ratio is rounding (-3e-19 was printed): 0
    zeta = np.where(np.abs(zeta) < 1e-12, 0.0, zeta)
    return ModalSolution(frequencies=freqs, mode_shapes=phi_e,
                         strain_energy_fraction=fraction, damping_ratios=zeta,
                         rigid_modes=phi_r, active=active,
                         dof_names=tuple(s.dof_names), element_names=tuple(s.element_names))


def _gyroscopic_modes(K, Gm, inv_mass, rigid_tolerance):
    """Modes of M q'' + G q' + K q = 0 (G skew-symmetric): first-order eigenproblem.

    Returns frequencies [Hz] (ascending, one per conjugate pair), complex mode shapes
    normalised to phi^H M phi = 1, the rigid modes and omega^2 of each mode."""
    n = K.shape[0]
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -inv_mass[:, None] * K
    A[n:, n:] = -inv_mass[:, None] * Gm
    lam, vec = np.linalg.eig(A)
    scale = float(np.max(np.abs(lam))) if lam.size else 0.0
    rigid = np.abs(lam) ** 2 <= rigid_tolerance * scale**2
    real = np.abs(lam.imag) <= 1e-9 * scale
    # oscillatory modes: one per conjugate pair; a real pair +-s (a statically unstable
    # mode, e.g. divergence of a fast-turning carrier) is kept once, as frequency -s/2pi
    osc = ~rigid & ~real & (lam.imag > 0)
    div = ~rigid & real & (lam.real > 0)
    w_all = np.where(osc, lam.imag, -lam.real)
    keep = osc | div
    order = np.argsort(w_all[keep])
    w = w_all[keep][order]
    phi = vec[:n][:, keep][:, order]
    mass = 1.0 / inv_mass
    norm = np.sqrt(np.real(np.einsum("im,i,im->m", phi.conj(), mass, phi)))
    phi = phi / norm[None, :]
    # rigid modes: the null space of K (real), mass-normalised
    d = np.sqrt(inv_mass)
    lk, psi = np.linalg.eigh(0.5 * (d[:, None] * K * d[None, :] + (d[:, None] * K * d[None, :]).T))
    lk_max = float(np.max(np.abs(lk))) if lk.size else 0.0
    phi_r = d[:, None] * psi[:, np.abs(lk) <= rigid_tolerance * lk_max]
    return w / (2 * math.pi), phi, phi_r, np.sign(w) * w**2


def _spline_damping(par, dx: float, dy: float, closed: bool) -> np.ndarray:
    """2 x 2 rate tangent (damping) of a spline's law at rest at (dx, dy) without its
    friction: c on the radial direction in contact and in the stick region, nothing
    floating (:func:`laws.spline_tangent` with no friction force); ``closed``: as in
    contact, isotropic at R = 0.  The friction is left out as for the stiffness: its
    regularised slope at rest, F_m / v, is a viscous damping of the regularisation's
    making (a ratio of 42 on a reviewer's quill mode), not the spline's."""
    if closed:
        return float(par[1]) * np.eye(2)
    p = [float(v) for v in par]
    p[4] = 0.0  # friction_force
    t = laws.spline_tangent(float(dx), float(dy), 0.0, 0.0, *p)
    return np.array([[t[4], t[5]], [t[6], t[7]]])


def _spline_tangent(par, dx: float, dy: float, closed: bool) -> np.ndarray:
    """2 x 2 tangent stiffness of a spline's law at rest at (dx, dy)
    (:func:`laws.spline_tangent`); ``closed``: as in contact at its clearance."""
    if closed:
        return float(par[0]) * np.eye(2)
    t = laws.spline_tangent(float(dx), float(dy), 0.0, 0.0, *map(float, par))
    return np.array([[t[0], t[1]], [t[2], t[3]]])
