"""Static and quasi-static equilibrium with dead zones and rigid-body modes.

Solves ``sum_e V_e f_e(q) = F_ext`` with ``f_e = k_e h(V_e.q - e_e; g_e) + p_e``
(damping plays no part).  The dead zone ``h`` makes the problem piecewise linear, so
the "Newton" iteration is an active-set iteration: with each element's contact state
fixed (front contact, back contact, separated) the equations are linear; solve, update
the states from the new deformations, repeat until no state changes.  Separated
elements get a tiny regularising stiffness (``regularisation`` x k) during the
iteration so that a member left floating by them stays determined; they are reported
in ``StaticSolution.separated`` and their force is exactly zero.  Once the contact
states have settled, the regularisation is dropped again if the elements in contact
hold every DOF on their own, so the equilibrium is then exact.

Rigid-body modes are the null space of the structure with every dead zone closed.  A
gear train driven and loaded by torques has one (the whole train turning).  Each is
removed by the constraint ``phi_r^T M q = 0`` (zero mass-weighted motion along the
mode), imposed with Lagrange multipliers::

    [ K_s    M Phi ] [ q  ]   [ F_ext - V^T p + sum_active k_e V_e (e_e + s_e g_e) ]
    [ Phi^T M   0  ] [ mu ] = [ 0                                                  ]

The external forces must do no work along a rigid-body mode (the torques must
balance); if they do, :class:`~torquesplit.errors.SolverError` says by how much.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from torquesplit.assembly.structure import Structure
from torquesplit.errors import SolverError
from torquesplit.solve._frozen import freeze_arrays
from torquesplit.solve.reference import excitation_numpy

__all__ = ["StaticSolution", "QuasiStaticSolution", "static_equilibrium", "quasi_static",
           "rigid_body_modes"]

FRONT, SEPARATED, BACK = 1, 0, -1


@dataclass(frozen=True, eq=False)
class StaticSolution:
    """Static equilibrium of a structure (SI units)."""

    q: np.ndarray
    """(n_dof,) displacements [m, rad]; zero mass-weighted motion along rigid modes."""
    element_forces: np.ndarray
    """(n_el,) element forces f_e [N] (0 for separated elements)."""
    deformations: np.ndarray
    """(n_el,) deformations delta_e = V_e.q - e_e [m]."""
    in_contact: np.ndarray
    """(n_el,) bool: element carries load (|delta| > g, or no dead zone)."""
    iterations: int
    """Active-set iterations (linear solves)."""
    converged: bool
    """False if the contact states kept changing (cycling) within ``max_iterations``."""
    rigid_modes: np.ndarray
    """(n_dof, n_rigid) mass-normalised rigid-body modes (dead zones closed)."""
    separated: tuple[str, ...]
    """Names of elements in separation (regularised with a tiny stiffness)."""
    t: float | None
    """Time of the excitation used, None for mean values."""

    def __post_init__(self):
        freeze_arrays(self)

    @property
    def y0(self) -> np.ndarray:
        """``[q, 0]``: a state to start :func:`~torquesplit.solve.integrate.integrate` from."""
        return np.concatenate([self.q, np.zeros_like(self.q)])


@dataclass(frozen=True, eq=False)
class QuasiStaticSolution:
    """Static equilibrium at a sequence of times (rows = times)."""

    times: np.ndarray
    q: np.ndarray
    """(n_times, n_dof) [m, rad]."""
    element_forces: np.ndarray
    """(n_times, n_el) [N]."""
    deformations: np.ndarray
    """(n_times, n_el) [m]."""
    in_contact: np.ndarray
    """(n_times, n_el) bool."""
    converged: np.ndarray
    """(n_times,) bool."""
    iterations: np.ndarray
    """(n_times,) int."""
    rigid_modes: np.ndarray
    """(n_dof, n_rigid) mass-normalised rigid-body modes."""

    def __post_init__(self):
        freeze_arrays(self)


def rigid_body_modes(structure: Structure, active: np.ndarray | None = None,
                     tolerance: float = 1e-8) -> np.ndarray:
    """Mass-normalised basis (n_dof, n_rigid) of motions that deform no active element.

    ``active`` (n_el bool) defaults to every element whose stiffness table is not all
    zero, dead zones closed.  Computed from the projection vectors alone (singular
    values of V M^-1/2 below ``tolerance`` x the largest), so stiffness magnitudes do
    not affect it.
    """
    s = structure
    if active is None:
        active = np.abs(s.stiffness_table).max(axis=1) > 0
    d = np.sqrt(s.inv_mass)
    A = s.projection_matrix()[np.asarray(active, dtype=bool)] * d[None, :]
    if A.shape[0] == 0:
        return np.diag(d)
    _, sv, vt = np.linalg.svd(A, full_matrices=True)
    rank = int(np.sum(sv > tolerance * sv[0])) if sv.size else 0
    return d[:, None] * vt[rank:].T


class _StaticProblem:
    """What stays the same for every time of a quasi-static sweep."""

    def __init__(self, structure: Structure, regularisation: float,
                 balance_tolerance: float):
        s = structure
        self.s = s
        self.V = s.projection_matrix()
        self.mass = 1.0 / s.inv_mass
        self.phi = rigid_body_modes(s)
        self.B = self.mass[:, None] * self.phi
        self.reg = regularisation
        self.balance_tolerance = balance_tolerance

    def loads(self, t):
        s = self.s
        if t is None:
            k = s.stiffness_table.mean(axis=1)
            p = s.force_table.mean(axis=1)
            e = s.error_constant.astype(float)
            g = np.array([s.gap_values[s.gap_ptr[i]:s.gap_ptr[i + 1]].mean()
                          for i in range(s.n_elements)])
        else:
            ex = excitation_numpy(s, float(t))
            k, p, e, g = ex.stiffness, ex.force, ex.error, ex.half_gap
        return k, p, e, g

    def check_balance(self, f_eff):
        """Raise if the effective external forces do work along a rigid-body mode."""
        s = self.s
        for r in range(self.phi.shape[1]):
            phi = self.phi[:, r]
            work = phi * f_eff
            net = float(work.sum())
            scale = float(np.abs(work).sum())
            if scale > 0 and abs(net) > self.balance_tolerance * scale:
                j = int(np.argmax(np.abs(work)))
                unit = "N m" if s.dof_names[j].endswith("theta") else "N"
                moving = [s.dof_names[i] for i in np.argsort(-np.abs(phi * np.sqrt(
                    self.mass)))[:4] if abs(phi[i]) > 1e-12 * np.abs(phi).max()]
                raise SolverError(
                    f"the external forces do not balance: along rigid-body mode {r + 1} "
                    f"(moving {', '.join(moving)}) the net load is {net / phi[j]:.6g} "
                    f"{unit} referred to '{s.dof_names[j]}' "
                    f"({100 * abs(net) / scale:.3g} % of the applied load), so no static "
                    f"equilibrium exists. Make the drive and load torques consistent with "
                    f"the gear ratios (output torque = input torque x ratio, minus losses).")

    def solve(self, t, states=None, max_iterations=50):
        s = self.s
        V, B = self.V, self.B
        n, r = s.n_dof, B.shape[1]
        k, p, e, g = self.loads(t)
        f_eff = s.external_force - V.T @ p
        self.check_balance(f_eff)
        stiff = k > 0
        gapped = g > 0
        if states is None:
            states = np.full(s.n_elements, FRONT)
            first_linear = True  # first pass: every dead zone ignored (h = delta)
        else:
            states = np.asarray(states).copy()
            first_linear = False
        seen = set()
        converged = False
        it = 0
        q = np.zeros(n)

        def linear_solve(k_eff, target):
            A = np.zeros((n + r, n + r))
            A[:n, :n] = V.T @ (k_eff[:, None] * V)
            A[:n, n:] = B
            A[n:, :n] = B.T
            rhs = np.concatenate([f_eff + V.T @ (k_eff * target), np.zeros(r)])
            return self._solve(A, rhs, k_eff)[:n]

        for it in range(1, max_iterations + 1):  # noqa: B007 (returned)
            offset = np.where(gapped & ~first_linear, states * g, 0.0)
            on = stiff & ((states != SEPARATED) | first_linear)
            k_eff = np.where(on, k, self.reg * np.abs(k))
            q = linear_solve(k_eff, e + np.where(on, offset, 0.0))
            delta = V @ q - e
            new = np.where(delta > g, FRONT, np.where(delta < -g, BACK, SEPARATED))
            new = np.where(gapped, new, FRONT)
            if not first_linear and np.array_equal(new, states):
                converged = True
                break
            key = new.tobytes()
            if key in seen:
                break  # cycling between contact states
            seen.add(key)
            states, first_linear = new, False
        separated = stiff & (states == SEPARATED)
        if converged and separated.any():
            # drop the regularisation if the contact elements alone hold every DOF
            on = stiff & ~separated
            if rigid_body_modes(self.s, active=on).shape[1] == self.phi.shape[1]:
                q_exact = linear_solve(np.where(on, k, 0.0), e + np.where(on, states * g, 0.0))
                d_exact = V @ q_exact - e
                check = np.where(d_exact > g, FRONT, np.where(d_exact < -g, BACK, SEPARATED))
                if np.array_equal(np.where(gapped, check, FRONT), states):
                    q = q_exact
        delta = V @ q - e
        h = np.where(gapped, np.where(delta > g, delta - g,
                                      np.where(delta < -g, delta + g, 0.0)), delta)
        forces = k * h + p
        contact = ~gapped | (np.abs(delta) > g)
        return q, forces, delta, contact, it, converged, states

    def _solve(self, A, b, k_eff):
        try:
            x = np.linalg.solve(A, b)
            ok = np.all(np.isfinite(x)) and np.allclose(A @ x, b, rtol=1e-6,
                                                        atol=1e-9 * np.abs(b).max())
        except np.linalg.LinAlgError:
            ok = False
        if not ok:
            s = self.s
            free = rigid_body_modes(s, active=k_eff > 0)
            extra = free.shape[1] - self.phi.shape[1]
            loose = sorted({s.dof_names[i] for c in range(free.shape[1])
                            for i in np.flatnonzero(np.abs(free[:, c]) > 1e-9
                                                    * np.abs(free[:, c]).max())})
            raise SolverError(
                f"the static stiffness is singular beyond the {self.phi.shape[1]} "
                f"rigid-body mode(s): {extra} more free motion(s) involving {loose}. "
                f"Give every DOF a support (bearing, shaft or mesh with non-zero "
                f"stiffness).")
        return x


def static_equilibrium(
    structure: Structure,
    t: float | None = None,
    *,
    regularisation: float = 1e-9,
    balance_tolerance: float = 1e-8,
    max_iterations: int = 50,
) -> StaticSolution:
    """Static equilibrium ``sum_e V_e f_e(q) = F_ext`` with dead zones and rigid modes.

    Parameters
    ----------
    structure : Structure
    t : float, optional
        None: mean stiffness, constant error part, mean additive force and mean half-gap
        of each element.  A time: the values of the excitation at ``t``.
    regularisation : float
        Stiffness of a separated element as a fraction of its own.
    balance_tolerance : float
        Largest net load along a rigid-body mode, as a fraction of the applied load,
        accepted as round-off.
    max_iterations : int
        Active-set iterations before giving up (``converged=False``).

    Raises
    ------
    SolverError
        The loads do not balance along a rigid-body mode, or a DOF has no support.

    Examples
    --------
    >>> from torquesplit.assembly.structure import MESH, build_structure
    >>> s = build_structure(["g1.theta", "g2.theta"], [100.0, 25.0],
    ...     [dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[0.05, -0.1],
    ...           stiffness=2e8)], external_force=[100.0, -200.0])
    >>> sol = static_equilibrium(s)
    >>> round(float(sol.element_forces[0]), 6), round(float(sol.deformations[0]), 12)
    (2000.0, 1e-05)
    """
    problem = _StaticProblem(structure, regularisation, balance_tolerance)
    q, f, d, c, it, conv, _ = problem.solve(t, max_iterations=max_iterations)
    names = tuple(structure.element_names[i] for i in np.flatnonzero(~c))
    return StaticSolution(q=q, element_forces=f, deformations=d, in_contact=c,
                          iterations=it, converged=conv, rigid_modes=problem.phi,
                          separated=names, t=None if t is None else float(t))


def quasi_static(
    structure: Structure,
    times,
    *,
    regularisation: float = 1e-9,
    balance_tolerance: float = 1e-8,
    max_iterations: int = 50,
) -> QuasiStaticSolution:
    """Static equilibrium at each time of ``times`` (mesh positions), e.g. for load
    sharing without dynamics.

    The projection matrix, rigid-body modes and their constraint are built once; each
    time starts its active-set iteration from the previous time's contact states, so a
    smooth sweep usually needs one or two linear solves per time.
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    problem = _StaticProblem(structure, regularisation, balance_tolerance)
    n, n_el, nt = structure.n_dof, structure.n_elements, times.size
    Q = np.zeros((nt, n))
    F = np.zeros((nt, n_el))
    D = np.zeros((nt, n_el))
    C = np.zeros((nt, n_el), dtype=bool)
    conv = np.zeros(nt, dtype=bool)
    its = np.zeros(nt, dtype=np.int64)
    states = None
    for i, t in enumerate(times):
        q, f, d, c, it, ok, states = problem.solve(t, states, max_iterations)
        Q[i], F[i], D[i], C[i], conv[i], its[i] = q, f, d, c, ok, it
    return QuasiStaticSolution(times=times, q=Q, element_forces=F, deformations=D,
                               in_contact=C, converged=conv, iterations=its,
                               rigid_modes=problem.phi)
