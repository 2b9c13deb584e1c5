"""Static and quasi-static equilibrium with dead zones, splines, friction and rigid modes.

Solves ``sum_e V_e f_e(q) + sum_fr W_e max(f_e, 0) = F_ext`` with the static element
laws (damping plays no part):

* ordinary elements: ``f_e = k_e h(V_e.q - e_e; g_e) + p_e``, h the dead zone of
  half-width g (backlash, support clearance);
* spline radial elements (Dong et al. 2021 eq. 6): radial force F(R) along d/R with
  ``F = k R`` (R < S1), ``0`` (S1 <= R <= S2: floating; friction is zero at rest),
  ``k (R - S2)`` (R > S2), i.e. a radial dead zone;
* tooth friction: the projection W_e of the mean friction-table values (``t=None``) or
  of their values at ``t``.

Method.  Without friction the static problem is the minimum of the strain energy
``U(q) - F_eff.q`` (F_eff = F_ext - V^T p), which is convex and piecewise quadratic
for dead zones (and convex for the radial dead zone of a spline when S1 = 0).  It is
minimised by Newton's method with an exact line search along the Newton direction (the
directional derivative is monotone, so a bracketing root search finds the step), which
cannot cycle between contact states the way full active-set steps can.  Elements inside
their dead zone get a tiny regularising stiffness (``regularisation`` x k, centred, so a
member left floating by them stays determined); they are reported in
``StaticSolution.separated`` and their force is exactly zero.  Once the contact states
have settled, the regularisation is dropped again if the elements in contact hold every
DOF on their own, and Newton continues on the exact law, so the equilibrium is then
exact.  Tooth friction is non-conservative; its generalized forces are iterated as
loads (fixed point on the mesh forces, which converges at the rate of the friction
moment per unit load over the mesh arm, about mu), each step solved as above.

Rigid-body modes are the null space of the structure with every dead zone closed.  A
gear train driven and loaded by torques has one (the whole train turning).  Each is
removed by the constraint ``phi_r^T M q = 0`` (zero mass-weighted motion along the
mode), imposed with Lagrange multipliers in every Newton step::

    [ H        M Phi ] [ dq ]   [ -grad          ]
    [ Phi^T M    0   ] [ mu ] = [ -Phi^T M q     ]

The external forces must do no work along a rigid-body mode (the torques must balance);
if they do, :class:`~torquesplit.errors.SolverError` says by how much.  Friction losses
also load the rigid mode: with the lossless balanced load torque a real train
decelerates slowly, with a load torque that takes the losses off the external torques
alone do not balance.  Both are accepted (the external imbalance may be up to twice the
friction's load along the mode); the net load is carried by the constraint as the
d'Alembert force of a uniform acceleration, reported as
``StaticSolution.rigid_acceleration``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from torquesplit._jit_cache import track_imports
from torquesplit._memo import Kept, remember_content
from torquesplit.assembly.structure import (
    SP_CLEARANCE,
    SP_STICK,
    SP_STIFFNESS,
    Structure,
)
from torquesplit.errors import SolverError
from torquesplit.solve import laws
from torquesplit.solve._frozen import freeze_arrays
from torquesplit.solve.laws import CONTACT, FLOAT
from torquesplit.solve.reference import excitation_numpy

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

__all__ = ["StaticSolution", "QuasiStaticSolution", "static_equilibrium", "quasi_static",
           "rigid_body_modes"]

FRONT, SEPARATED, BACK = 1, 0, -1  # contact states of a dead zone; splines: laws.STICK...

_FRICTION_TOL = 1e-13  # relative change of the mesh forces ending the friction iteration
_STEP_TOL = 1e-10  # relative Newton step below which a nonlinear (spline) state has settled
# A Newton iteration whose line search keeps returning steps shorter than _STALL_ALPHA is
# stuck on a kink of a law (a spline's stick limit without regularisation: phi' jumps
# just past alpha = 0) and would spend its whole budget there; after _STALL_STEPS such
# steps in a row it gives up.  Dong et al. 2021's face-gear drive: 4 such iterations in a
# 200-position sweep took 38 % of its line-search evaluations; the smallest step of an
# iteration that went on to converge (1000 positions of every shipped example) was 1.1e-9.
_STALL_ALPHA = 1e-10
_STALL_STEPS = 20


@dataclass(frozen=True, eq=False)
class StaticSolution:
    """Static equilibrium of a structure (SI units)."""

    q: np.ndarray
    """(n_dof,) displacements [m, rad]; zero mass-weighted motion along rigid modes."""
    element_forces: np.ndarray
    """(n_el,) element forces f_e [N] (0 for separated elements; for the two component
    elements of a spline the x and y components of its radial force)."""
    deformations: np.ndarray
    """(n_el,) deformations delta_e = V_e.q - e_e [m]."""
    in_contact: np.ndarray
    """(n_el,) bool: element carries load (|delta| > g, or no dead zone; a spline when
    R < S1 or R > S2)."""
    iterations: int
    """Linear solves (Newton steps, including the first closed-gap solve)."""
    converged: bool
    """False if the iteration did not settle within ``max_iterations`` linear solves."""
    rigid_modes: np.ndarray
    """(n_dof, n_rigid) mass-normalised rigid-body modes (dead zones closed)."""
    separated: tuple[str, ...]
    """Names of elements in separation (regularised with a tiny stiffness); for a spline
    floating in its clearance, its two component elements."""
    t: float | None
    """Time of the excitation used, None for mean values."""
    rigid_acceleration: np.ndarray | None = field(default=None)
    """(n_rigid,) acceleration along each mass-normalised rigid mode that the net load
    along it would cause (phi_r^T of the residual force) [sqrt(kg) m/s^2]; zero up to
    round-off unless tooth friction takes power out of a torque-balanced train."""

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
    planned: int = 0
    """Positions the sweep was asked for; more than ``times.size`` when Ctrl-C stopped it
    (0: as many as it has)."""

    def __post_init__(self):
        freeze_arrays(self)

    @property
    def interrupted(self) -> bool:
        """Ctrl-C stopped the sweep before its last position (the positions done kept)."""
        return self.planned > self.times.size


def rigid_body_modes(structure: Structure, active: np.ndarray | None = None,
                     tolerance: float = 1e-8) -> np.ndarray:
    """Mass-normalised basis (n_dof, n_rigid) of motions that deform no active element.

    ``active`` (n_el bool) defaults to every element whose stiffness table is not all
    zero, dead zones closed.  Computed from the projection vectors alone (singular
    values of V M^-1/2 below ``tolerance`` x the largest), so stiffness magnitudes do
    not affect it.  The inertial stiffness of a turning frame (centripetal softening, pin
    preload: ``Structure.fs_*``) is not an element and does not hold a rigid motion: the rigid
    rotation of a planetary train is that of its kinematics, on which the nominal torques
    balance, and which that stiffness leaves unloaded (``assembly.rotating``).
    """
    s = structure
    if active is None:  # max and min: no temporary the size of the tables (14 MB for a
        # hunting-period table set), which cost more than the rest of this function
        k = s.stiffness_table
        active = (k.max(axis=1) > 0) | (k.min(axis=1) < 0)
    active = np.asarray(active, dtype=bool).copy()
    return rigid_modes_of(s.projection_matrix()[active], s.inv_mass, tolerance)


def rigid_modes_of(V: np.ndarray, inv_mass: np.ndarray, tolerance: float = 1e-8) -> np.ndarray:
    """:func:`rigid_body_modes` of projection rows ``V`` (n_rows, n_dof) and inverse
    masses: the mass-normalised motions no row deforms (the caller's own copy)."""
    return _rigid_modes(np.asarray(V, dtype=float), np.sqrt(np.asarray(inv_mass, float)),
                        float(tolerance)).copy()


@remember_content(kept=16)
def _rigid_modes(V: np.ndarray, d: np.ndarray, tolerance: float) -> np.ndarray:
    """:func:`rigid_body_modes` of the active elements' projections ``V`` and square roots
    ``d`` of the inverse masses, read-only and kept by content (a study case solves two
    equilibria of its own structure, whose projections every case of the study shares:
    an SVD each)."""
    A = V * d[None, :]
    if A.shape[0] == 0:
        phi = np.diag(d)
    else:
        _, sv, vt = np.linalg.svd(A, full_matrices=True)
        rank = int(np.sum(sv > tolerance * sv[0])) if sv.size else 0
        phi = d[:, None] * vt[rank:].T
        # the rank judged on V's columns scaled to one: a body of an inertia 1e12 times
        # smaller than the others' (a unit slip) made its column dominate V M^-1/2 and
        # the others' constraints fall below the tolerance, a false rigid-body mode that
        # the load balance then blamed (a reliability reviewer)
        c = np.linalg.norm(V, axis=0)
        c = 1.0 / np.where(c > 0, c, 1.0)
        _, sc, wt = np.linalg.svd(V * c[None, :], full_matrices=True)
        free = int(np.sum(sc > tolerance * sc[0])) if sc.size else 0
        if free != rank:  # the null space of V, made mass-orthonormal
            N = c[:, None] * wt[free:].T
            w, U = np.linalg.eigh(N.T @ (N / (d * d)[:, None]))
            phi = N @ (U / np.sqrt(w)[None, :]) @ U.T
    phi.setflags(write=False)
    return phi


def regularisation(delta, half_gap, stiffness, reg: float):
    """The static solver's regularisation of dead zones: a spring of ``reg x k`` inside
    the dead zone (clipped to it, so that it adds a constant ``reg k g`` outside), which
    keeps a member floating in its clearance determined.  Returns force, tangent and
    energy (arrays), zero where there is no dead zone (``g <= 0``).  Not a physical law:
    the solution is recomputed without it once the contact states settle."""
    g = np.asarray(half_gap, dtype=float)
    d = np.asarray(delta, dtype=float)
    a = np.abs(d)
    rk, force = regularisation_force(d, g, stiffness, reg)
    inside = np.minimum(a, g)
    return (force, np.where(a <= g, rk, 0.0),
            rk * (0.5 * inside * inside + g * np.maximum(a - g, 0.0)))


def regularisation_force(delta, half_gap, stiffness, reg: float):
    """The spring ``reg x k`` of :func:`regularisation` and its force alone (what the
    line search needs)."""
    g = np.asarray(half_gap, dtype=float)
    rk = np.where(g > 0, reg * np.asarray(stiffness, dtype=float), 0.0)
    return rk, rk * np.clip(np.asarray(delta, dtype=float), -g, g)


@dataclass
class _Loads:
    k: np.ndarray
    p: np.ndarray
    e: np.ndarray
    g: np.ndarray
    W: np.ndarray | None  # friction projections (n_el, n_dof), None without friction
    f_eff: np.ndarray  # F_ext - V^T p


class _StaticProblem:
    """What stays the same for every time of a quasi-static sweep."""

    def __init__(self, structure: Structure, regularisation: float,
                 balance_tolerance: float):
        s = structure
        self.s = s
        self.V = s.projection_matrix()
        self.Kf = s.frame_stiffness_matrix()  # inertial stiffness of turning frames
        self.mass = 1.0 / s.inv_mass
        self.phi = rigid_body_modes(s)
        self.B = self.mass[:, None] * self.phi
        self.balance_tolerance = balance_tolerance
        self.sp_x = s.sp_el[:, 0].astype(int)
        self.sp_y = s.sp_el[:, 1].astype(int)
        self.sp_par = np.ascontiguousarray(s.sp_par, dtype=float)
        self._spline_set = set(self.sp_x.tolist()) | set(self.sp_y.tolist())
        self._spline_row = {int(e): j for j, pair in enumerate(s.sp_el) for e in pair}
        self.reg = self._regularisation(regularisation)
        self._held_cache: dict[bytes, bool] = {}
        self.linear = np.ones(s.n_elements, dtype=bool)  # ordinary (1-D) elements
        self.linear[self.sp_x] = False
        self.linear[self.sp_y] = False
        self.has_gaps = bool(np.any(s.gap_values > 0)
                             or np.any(s.sp_par[:, SP_CLEARANCE] > 0)
                             or np.any(s.sp_par[:, SP_STICK] > 0))

    def _regularisation(self, base: float):
        """The regularisation factor of every element: ``base``, and where a dead zone's
        DOF is softened by a turning frame (a planet floating in its pin clearance:
        -m Omega^2 on its translations), enough that reg k V^2 beats the softening twice
        over: with 1e-9 k the tangent was indefinite and Newton ran a planet 9 m off
        its pin.  Scalar where nothing is softened."""
        s = self.s
        soft = np.maximum(-np.diag(self.Kf), 0.0)
        if not (base > 0 and np.any(soft > 0)):
            return base
        reg = np.full(s.n_elements, float(base))
        spline_gap = np.zeros(s.n_elements)
        spline_gap[self.sp_x] = spline_gap[self.sp_y] = s.sp_par[:, SP_CLEARANCE]
        # only a softened DOF in a motion that the elements without a dead zone (and the
        # frame) leave loose needs more (a planet floating in its pin clearance); where a
        # pin without clearance holds the planet, the spring on its open meshes stays at
        # the base: a larger one carried a force (8 N at 3000 rpm on a Lin & Parker stage)
        # that the reported, unregularised forces leave out
        soft = np.where(self._loose_dofs(spline_gap), soft, 0.0)
        for e in range(s.n_elements):
            gaps = s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]
            k = float(np.max(s.stiffness_table[e])) if s.stiffness_table.shape[1] else 0.0
            if e in self._spline_set:
                k = float(s.sp_par[self._spline_row[e], SP_STIFFNESS])
            if not (k > 0 and (np.any(gaps > 0) or spline_gap[e] > 0)):
                continue
            for j in range(s.v_ptr[e], s.v_ptr[e + 1]):
                i, c = s.v_dof[j], s.v_coef[j]
                if soft[i] > 0 and c != 0:
                    reg[e] = max(reg[e], 2.0 * soft[i] / (k * c * c))
        return reg

    def _loose_dofs(self, spline_gap) -> np.ndarray:
        """(n_dof,) bool: DOFs that take part in a motion (other than a rigid-body mode)
        which the elements without a dead zone and the turning frame's inertial stiffness
        do not hold (an eigenvalue of M^-1/2 (K + K_f) M^-1/2 at most 1e-9 of the largest,
        on the complement of the rigid modes)."""
        s = self.s
        keep = np.ones(s.n_elements, dtype=bool)
        k = (np.min(s.stiffness_table, axis=1) if s.stiffness_table.shape[1]
             else np.zeros(s.n_elements))
        for e in range(s.n_elements):
            if np.any(s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]] > 0) or spline_gap[e] > 0:
                keep[e] = False
            elif e in self._spline_set:
                k[e] = s.sp_par[self._spline_row[e], SP_STIFFNESS]
        K = self.V[keep].T @ (np.maximum(k[keep], 0.0)[:, None] * self.V[keep]) + self.Kf
        d = np.sqrt(s.inv_mass)
        A = d[:, None] * K * d[None, :]
        psi = self.phi / d[:, None]  # the rigid modes in these coordinates (orthonormal)
        P = np.eye(s.n_dof) - psi @ psi.T
        w, U = np.linalg.eigh(P @ A @ P)
        scale = max(float(np.max(np.abs(w))), 1e-300)
        loose = (w <= 1e-9 * scale) & (np.sum((psi.T @ U) ** 2, axis=0) < 0.5)
        return np.any(U[:, loose] ** 2 > 1e-9, axis=1) if loose.any() else np.zeros(
            s.n_dof, dtype=bool)

    # ------------------------------------------------------------------ loads
    def loads(self, t) -> _Loads:
        s = self.s
        if t is None:
            k = s.stiffness_table.mean(axis=1)
            p = s.force_table.mean(axis=1)
            e = s.error_constant.astype(float)
            g = np.array([s.gap_values[s.gap_ptr[i]:s.gap_ptr[i + 1]].mean()
                          for i in range(s.n_elements)])
            fr = None
        else:
            ex = excitation_numpy(s, float(t))
            k, p, e, g, fr = ex.stiffness, ex.force, ex.error, ex.half_gap, ex.friction
        W = s.friction_matrix(fr) if s.n_friction else None
        f_eff = s.external_force - self.V.T @ p
        names = s.metadata.get("torque_fluctuation_elements") if s.metadata else None
        if names and self.phi.shape[1]:
            fluct = [s.element_names.index(name) for name in names]
            # a drive's or load's torque fluctuation accelerates the rigid train: its
            # inertial (d'Alembert) load -M phi phi^T g, phi mass-normalised, balances it
            g_f = -self.V[fluct].T @ p[fluct]
            f_eff = f_eff - self.mass * (self.phi @ (self.phi.T @ g_f))
        return _Loads(k, p, e, g, W, f_eff)

    def check_balance(self, f_eff, friction_load=None):
        """Raise if the effective external forces do work along a rigid-body mode.

        With tooth friction (``friction_load`` = the friction's generalized force
        W^T max(f, 0) at the solution) the external forces may be out of balance by up to
        twice the friction's share along the mode: a load torque may be the lossless
        balance (friction then decelerates the train) or take the losses off.
        """
        s = self.s
        for r in range(self.phi.shape[1]):
            phi = self.phi[:, r]
            work = phi * f_eff
            net = float(work.sum())
            scale = float(np.abs(work).sum())
            allowance = 0.0 if friction_load is None else 2.0 * abs(float(phi @ friction_load))
            if scale > 0 and abs(net) > self.balance_tolerance * scale + allowance:
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

    # ------------------------------------------------------------ element laws
    def forces(self, q, L: _Loads, reg: float):
        """Element forces (without p), tangents, energy and states at q: the static laws
        (:func:`laws.dead_zone`, :func:`laws.spline_force` / :func:`laws.spline_tangent`
        at rest) plus the :func:`regularisation` ``reg``."""
        delta = self.V @ q - L.e
        k, g = L.k, L.g
        h, dh, u = (np.empty_like(delta) for _ in range(3))
        laws.dead_zones(delta, np.asarray(g, dtype=float), h, dh, u)
        fr, kr, ur = regularisation(delta, g, k, reg)
        f = k * h + fr
        kt = k * dh + kr
        state = np.where(g > 0, np.where(delta > g, FRONT, np.where(delta < -g, BACK,
                                                                      SEPARATED)), FRONT)
        state = state.astype(np.int64)
        energy = float(np.sum(np.where(self.linear, k * u + ur, 0.0)))
        sp = np.empty((0, 2, 2))
        if self.s.n_splines:
            ex, ey = self.sp_x, self.sp_y
            f[ex], f[ey], sp, e_sp, state_sp = self._splines(delta, reg, tangent=True)
            energy += e_sp
            kt[ex] = kt[ey] = 0.0
            state[ex] = state[ey] = state_sp
        return delta, f, kt, energy, state, sp

    def force(self, q, L: _Loads, reg: float):
        """The element forces of :meth:`forces` alone (the line search needs no more)."""
        delta = self.V @ q - L.e
        k, g = L.k, L.g
        if self.s.n_splines:  # one compiled pass (the numpy one is ~25 small-array ops)
            f = np.empty_like(delta)
            r = np.asarray(reg, dtype=float)
            _line_forces(delta, np.asarray(g, dtype=float), np.asarray(k, dtype=float),
                         np.full(delta.shape, float(r)) if r.ndim == 0 else r,
                         self.sp_x, self.sp_y, self.sp_par, f)
            return f
        h, dh, u = (np.empty_like(delta) for _ in range(3))
        laws.dead_zones(delta, np.asarray(g, dtype=float), h, dh, u)
        f = k * h + regularisation_force(delta, g, k, reg)[1]
        if self.s.n_splines:
            f[self.sp_x], f[self.sp_y] = self._splines(delta, reg, tangent=False)
        return f

    def _splines(self, delta, reg, tangent: bool):
        """Forces (fx, fy) of the splines at rest plus the regularisation of their radial
        dead zone, reg k min(R, S2) along d / R; with ``tangent`` also their 2 x 2
        tangents, energy and regions."""
        s = self.s
        dx, dy = delta[self.sp_x], delta[self.sp_y]
        zero = np.zeros_like(dx)
        out = np.empty((s.n_splines, 12))
        laws.spline_forces(dx, dy, zero, zero, np.ascontiguousarray(s.sp_par), out)
        rad = np.hypot(dx, dy)
        rk = (reg[self.sp_x] if np.ndim(reg) else reg) * s.sp_par[:, SP_STIFFNESS]
        s2 = s.sp_par[:, SP_CLEARANCE]
        inner = np.minimum(rad, s2)
        f_reg = rk * inner
        moved = rad > 0
        safe = np.where(moved, rad, 1.0)
        nx, ny = np.where(moved, dx / safe, 0.0), np.where(moved, dy / safe, 0.0)
        fx, fy = out[:, 0] + f_reg * nx, out[:, 1] + f_reg * ny
        if not tangent:
            return fx, fy
        nn = np.stack([np.stack([nx * nx, nx * ny], -1), np.stack([nx * ny, ny * ny], -1)], -2)
        radial = np.where(moved & (rad < s2), rk, 0.0)
        tangential = np.where(moved, f_reg / safe, 0.0)
        eye = np.eye(2)[None]
        sp = (out[:, 2:6].reshape(-1, 2, 2) + radial[:, None, None] * nn
              + tangential[:, None, None] * (eye - nn))
        at_rest = ~moved & (s2 > 0)
        sp[at_rest] += rk[at_rest, None, None] * eye
        energy = float(np.sum(out[:, 10] + rk * (0.5 * inner * inner
                                                 + s2 * np.maximum(rad - s2, 0.0))))
        return fx, fy, sp, energy, out[:, 11].astype(np.int64)

    def hessian(self, kt, sp):
        """Tangent stiffness: sum_e kt_e V_e V_e^T plus each spline's 2 x 2 tangent and
        the frame stiffness K_f."""
        V = self.V
        H = V.T @ (kt[:, None] * V) + self.Kf
        for j, h2 in enumerate(sp):
            rows = V[[self.sp_x[j], self.sp_y[j]]]
            H += rows.T @ h2 @ rows
        return H

    # ------------------------------------------------------------------ Newton
    def _kkt(self, H, rhs_top, rhs_bottom, active):
        """Solve the constrained Newton system.  Rows and columns are scaled by the square
        root of the diagonal of H (and the constraint columns to unit size), since the
        stiffnesses of one model span many decades (bearings 1e12 N/m, regularised
        separated elements, N m/rad against N/m), and one step of iterative refinement
        follows."""
        n, r = self.s.n_dof, self.B.shape[1]
        diag = np.abs(np.diag(H))
        sc = np.where(diag > 0, 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0)), 1.0)
        Bs = sc[:, None] * self.B
        cs = 1.0 / np.maximum(np.max(np.abs(Bs), axis=0, initial=0.0), 1e-300)
        A = np.zeros((n + r, n + r))
        A[:n, :n] = sc[:, None] * H * sc[None, :]
        A[:n, n:] = Bs * cs[None, :]
        A[n:, :n] = A[:n, n:].T
        b = np.concatenate([sc * rhs_top, cs * rhs_bottom])
        try:
            x = np.linalg.solve(A, b)
            x = x + np.linalg.solve(A, b - A @ x)
            # backward error: a step that follows a tiny (regularised) stiffness is
            # legitimately huge, a singular system gives no finite or consistent one
            ok = bool(np.all(np.isfinite(x)) and np.all(
                np.abs(A @ x - b) <= 1e-9 * (np.abs(A) @ np.abs(x) + np.abs(b)) + 1e-300))
        except np.linalg.LinAlgError:
            ok = False
        if not ok:
            s = self.s
            free = rigid_body_modes(s, active=active)
            extra = free.shape[1] - self.phi.shape[1]
            if extra <= 0:
                # no free motion by the topology: the system is singular to round-off
                # only (a motion held by elements many decades softer than the rest,
                # whose detection must not depend on the order of the DOFs); the least-
                # squares solution is the equilibrium if it satisfies the equations
                x, *_ = np.linalg.lstsq(A, b, rcond=None)
                if np.all(np.isfinite(x)) and np.all(
                        np.abs(A @ x - b) <= 1e-7 * (np.abs(A) @ np.abs(x) + np.abs(b))
                        + 1e-300):
                    return sc * x[:n]
                lam, vec = np.linalg.eigh(0.5 * (A[:n, :n] + A[:n, :n].T))
                weak = vec[:, 0]
                names = [s.dof_names[i] for i in np.argsort(-np.abs(weak))[:4]
                         if abs(weak[i]) > 1e-3 * np.abs(weak).max()]
                raise SolverError(
                    f"the static stiffness is singular to round-off: the motion of "
                    f"{names} is held only by elements about {abs(lam[0]):.1e} times "
                    f"softer than the others. Stiffen those elements (or remove the "
                    f"DOFs they hold) so that every stiffness is within about 10 decades "
                    f"of the largest.")
            loose = sorted({s.dof_names[i] for c in range(free.shape[1])
                            for i in np.flatnonzero(np.abs(free[:, c]) > 1e-9
                                                    * np.abs(free[:, c]).max())})
            raise SolverError(
                f"the static stiffness is singular beyond the {self.phi.shape[1]} "
                f"rigid-body mode(s): {max(extra, 1)} more free motion(s) involving "
                f"{loose}. Give every DOF a support (bearing, shaft or mesh with non-zero "
                f"stiffness).")
        return sc * x[:n]

    def closed_solve(self, L: _Loads, load):
        """Equilibrium with every dead zone closed and no clearance (a linear spring per
        element): the starting point of the Newton iteration."""
        kt = np.where(L.k > 0, L.k, 0.0)
        H = self.V.T @ (kt[:, None] * self.V) + self.Kf
        return self._kkt(H, load + self.V.T @ (kt * L.e), np.zeros(self.B.shape[1]), kt > 0)

    def _directional(self, q, dq, L, load, reg):
        """phi'(alpha) = grad(q + alpha dq) . dq along the Newton direction, and the size
        of the terms it is made of (its round-off scale)."""
        vdq = self.V @ dq
        fdq = float(load @ dq)
        kq, kdq = self.Kf @ q, self.Kf @ dq  # the frame stiffness (linear in q)

        def dphi(alpha):
            f = self.force(q + alpha * dq, L, reg)
            terms = np.concatenate([f * vdq, (kq + alpha * kdq) * dq])
            return float(terms.sum()) - fdq, float(np.abs(terms).sum()) + abs(fdq)
        return dphi, vdq

    def _kinks(self, delta, vdq, g):
        """Step lengths alpha at which phi' has a kink along delta + alpha V dq: a 1-D
        element's deformation crossing an edge of its dead zone (+-g), a spline's radial
        displacement |(dx, dy) + alpha (vx, vy)| crossing its stick limit or clearance
        (roots of a quadratic)."""
        on = self.linear & (np.asarray(g) > 0) & (vdq != 0)
        d, v, gg = delta[on], vdq[on], np.asarray(g, dtype=float)[on]
        out = [(gg - d) / v, (-gg - d) / v]
        if self.s.n_splines:
            x, y = self.sp_x, self.sp_y
            a = vdq[x] ** 2 + vdq[y] ** 2
            b = 2.0 * (delta[x] * vdq[x] + delta[y] * vdq[y])
            r2 = delta[x] ** 2 + delta[y] ** 2
            for edge in (self.s.sp_par[:, SP_STICK], self.s.sp_par[:, SP_CLEARANCE]):
                c = r2 - edge * edge
                disc = b * b - 4.0 * a * c
                ok = (edge > 0) & (a > 0) & (disc >= 0)
                root = np.sqrt(np.where(ok, disc, 0.0))
                den = np.where(ok, 2.0 * a, 1.0)
                out += [((-b - root) / den)[ok], ((-b + root) / den)[ok]]
        return np.concatenate(out)

    def newton(self, q, L: _Loads, load, reg, budget):
        """Minimise U(q) - load.q on B^T M q = 0 from q; returns (q, solves, converged)."""
        solves = stalled = 0
        delta, f, kt, _, state, sp = self.forces(q, L, reg)
        while solves < budget:
            grad = self.V.T @ f + self.Kf @ q - load
            H = self.hessian(kt, sp)
            active = kt > 0
            for j, h2 in enumerate(sp):
                active[[self.sp_x[j], self.sp_y[j]]] = bool(np.any(h2 != 0))
            dq = self._kkt(H, -grad, -(self.B.T @ q), active)
            solves += 1
            dphi, vdq = self._directional(q, dq, L, load, reg)
            d0 = float(grad @ dq)
            scale = max(float(np.max(np.abs(delta), initial=0.0)),
                        float(np.max(L.g, initial=0.0)),
                        float(np.max(self.s.sp_par[:, SP_CLEARANCE], initial=0.0)), 1e-300)
            step = float(np.max(np.abs(vdq), initial=0.0))
            if step <= 1e-15 * scale or d0 >= 0.0:  # d0 = -dq^T H dq: only if dq ~ 0
                return q + dq, solves, True
            alpha = _line_search(dphi, d0, self._kinks(delta, vdq, L.g))
            stalled = stalled + 1 if alpha < _STALL_ALPHA else 0
            if stalled >= _STALL_STEPS:
                return q, solves, False
            q_new = q + alpha * dq
            delta_n, f_n, kt_n, _, state_n, sp_n = self.forces(q_new, L, reg)
            settled = alpha == 1.0 and np.array_equal(state_n, state)
            if settled:
                nonlinear = any(state_n[self.sp_x[j]] == CONTACT
                                and self.s.sp_par[j, SP_CLEARANCE] > 0
                                for j in range(self.s.n_splines))
                if not nonlinear or step <= _STEP_TOL * scale:
                    return q_new, solves, True
            q, delta, f, kt, state, sp = q_new, delta_n, f_n, kt_n, state_n, sp_n
        return q, solves, False

    def equilibrium(self, q, L: _Loads, reg, budget):
        """Newton, with the friction loads iterated around it; (q, solves, converged)."""
        if L.W is None:
            return self.newton(q, L, L.f_eff, reg, budget)
        solves, ok = 0, False
        f_old = None
        while solves < budget:
            _, f, _, _, _, _ = self.forces(q, L, reg)
            fm = np.maximum(f + L.p, 0.0)
            if f_old is not None:
                change = float(np.max(np.abs(fm - f_old)))
                if change <= _FRICTION_TOL * max(float(np.max(np.abs(fm))), 1e-300):
                    ok = True
                    break
            f_old = fm
            q, n_solves, ok_n = self.newton(q, L, L.f_eff - L.W.T @ fm, reg, budget - solves)
            solves += n_solves
            if not ok_n:
                ok = False
                break
        return q, solves, ok

    def solve(self, t, q0=None, max_iterations=200):
        L = self.loads(t)
        if L.W is None:
            self.check_balance(L.f_eff)
        solves = 0
        if q0 is None or (not self.has_gaps and L.W is None):
            # a linear problem is one solve: from a previous time's q the Newton step
            # would only lose digits (its gradient is a difference of large forces)
            q = self.closed_solve(L, L.f_eff)
            solves = 1
            if not self.has_gaps and L.W is None:
                return self._result(q, L, solves, True)
        else:
            q = np.asarray(q0, dtype=float).copy()
        q, n, ok = self.equilibrium(q, L, self.reg, max_iterations - solves)
        solves += n
        if ok and self.has_gaps and np.any(np.asarray(self.reg) > 0):
            # drop the regularisation where the elements in contact hold every DOF; else
            # keep it only on the open elements (in contact, the clipped spring would add
            # its constant reg k g to the force)
            _, _, _, _, state, _ = self.forces(q, L, 0.0)
            on = (np.abs(L.k) > 0) & (state != SEPARATED) & (state != FLOAT)
            on[self.sp_x] &= state[self.sp_x] != FLOAT
            on[self.sp_x] &= on[self.sp_y]
            on[self.sp_y] = on[self.sp_x]
            held = self._held(on)
            reg2 = 0.0 if held else np.where(on, 0.0, np.broadcast_to(self.reg, on.shape))
            try:
                q2, n2, ok2 = self.equilibrium(q, L, reg2, max_iterations - solves)
            except SolverError:
                n2, ok2 = 1, False
            solves += n2
            if ok2:
                state2 = self.forces(q2, L, 0.0)[4]
                if np.array_equal(state2, state):
                    q = q2
        return self._result(q, L, solves, ok)

    def _held(self, on) -> bool:
        """Whether the elements ``on`` (in contact) hold every DOF the model holds: no
        more rigid-body modes than the model's own.  Kept per contact pattern (a sweep
        over mesh positions meets a few patterns; the SVD per position was a tenth of
        a quasi-static run)."""
        key = np.packbits(on).tobytes()
        held = self._held_cache.get(key)
        if held is None:
            held = rigid_body_modes(self.s, active=on).shape[1] == self.phi.shape[1]
            if len(self._held_cache) < 4096:
                self._held_cache[key] = held
        return held

    def _result(self, q, L: _Loads, solves, ok):
        delta, f, _, _, state, _ = self.forces(q, L, 0.0)
        forces = f + L.p
        contact = (state != SEPARATED) & (state != FLOAT)
        resid = L.f_eff - self.V.T @ f - self.Kf @ q
        if L.W is not None:
            friction_load = L.W.T @ np.maximum(forces, 0.0)
            self.check_balance(L.f_eff, friction_load)
            resid = resid - friction_load
        accel = self.phi.T @ resid
        return dict(q=q, forces=forces, delta=delta, contact=contact, it=solves,
                    converged=bool(ok), accel=accel)


@njit(cache=True, error_model="numpy")
def _line_forces(delta, g, k, reg, sp_x, sp_y, sp_par, f):
    """:meth:`_StaticProblem.force` for a model with splines, compiled: the same laws
    (:func:`laws.dead_zone`, :func:`laws.spline_force` at rest) and regularisation, in the
    same operations (bit for bit), into ``f``.  The line search evaluates it about 15
    times a Newton step; in numpy, its spline part alone was a third of Dong et al.
    2021's quasi-static sweep."""
    for e in range(delta.shape[0]):
        d, ge = delta[e], g[e]
        h, _, _ = laws.dead_zone(d, ge)
        rk = reg[e] * k[e] if ge > 0 else 0.0
        f[e] = k[e] * h + rk * min(max(d, -ge), ge)
    for j in range(sp_x.shape[0]):
        ex, ey = sp_x[j], sp_y[j]
        dx, dy = delta[ex], delta[ey]
        fx, fy = laws.spline_force(dx, dy, 0.0, 0.0, sp_par[j, 0], sp_par[j, 1],
                                   sp_par[j, 2], sp_par[j, 3], sp_par[j, 4], sp_par[j, 5])
        rad = math.hypot(dx, dy)
        if rad > 0:
            f_reg = (reg[ex] * sp_par[j, SP_STIFFNESS]) * min(rad, sp_par[j, SP_CLEARANCE])
            fx += f_reg * (dx / rad)
            fy += f_reg * (dy / rad)
        f[ex] = fx
        f[ey] = fy


def _line_search(dphi, d0: float, kinks=()) -> float:
    """Step along a descent direction: 1 if phi'(1) <= 0 (up to round-off), else the
    root of the monotone phi' in (0, 1).  The bracket is first narrowed, by bisection over
    the sorted ``kinks`` (where phi' changes slope: dead-zone edges, spline radii), to one
    smooth piece of phi'; the root inside it by regula falsi (Illinois variant), which on
    a linear piece lands on it at the first step.  A root at a kink is found at that kink: regula falsi
    across a kink only converges linearly (20-odd evaluations of phi' per step)."""
    d1, size = dphi(1.0)
    if d1 <= 1e-12 * size + 1e-10 * abs(d0):
        return 1.0
    a, da, b, db = 0.0, d0, 1.0, d1
    ks = np.unique(np.asarray(kinks, dtype=float))
    ks = ks[(ks > 0.0) & (ks < 1.0)]
    lo, hi = 0, ks.size
    while lo < hi:
        mid = (lo + hi) // 2
        c = float(ks[mid])
        dc, size = dphi(c)
        if abs(dc) <= 1e-12 * size + 1e-12 * abs(d0):
            return c
        if dc > 0:
            b, db, hi = c, dc, mid
        else:
            a, da, lo = c, dc, mid + 1
    c = 1.0
    for _ in range(200):
        c = b - db * (b - a) / (db - da)
        if not a < c < b:
            c = 0.5 * (a + b)
        dc, size = dphi(c)
        if abs(dc) <= 1e-12 * size + 1e-12 * abs(d0) or b - a <= 1e-15:
            break
        if dc > 0:
            b, db = c, dc
            da *= 0.5
        else:
            a, da = c, dc
            db *= 0.5
    return c


def static_equilibrium(
    structure: Structure,
    t: float | None = None,
    *,
    regularisation: float = 1e-9,
    balance_tolerance: float = 1e-8,
    max_iterations: int = 200,
    initial=None,
) -> StaticSolution:
    """Static equilibrium ``sum_e V_e f_e(q) = F_ext`` with dead zones and rigid modes.

    Parameters
    ----------
    structure : Structure
    t : float, optional
        None: mean stiffness, constant error part, mean additive force, mean half-gap and
        mean friction table of each element.  A time: the values of the excitation at
        ``t``.
    regularisation : float
        Stiffness of a separated element as a fraction of its own.
    balance_tolerance : float
        Largest net load along a rigid-body mode, as a fraction of the applied load,
        accepted as round-off.
    max_iterations : int
        Linear solves (Newton steps) before giving up (``converged=False``).
    initial : array, optional
        Displacements to start Newton from (e.g. the equilibrium at a nearby time or
        of the mean stiffness), instead of the closed-contact linear solve.

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
    key = None
    if t is None and initial is None:
        key = _mean_key(problem, regularisation, balance_tolerance, max_iterations)
        kept = _MEAN_SOLUTIONS.get(key)
        if kept is not None:
            return kept
    r = problem.solve(t, q0=initial, max_iterations=max_iterations)
    names = tuple(structure.element_names[i] for i in np.flatnonzero(~r["contact"]))
    sol = StaticSolution(q=r["q"], element_forces=r["forces"], deformations=r["delta"],
                         in_contact=r["contact"], iterations=r["it"],
                         converged=r["converged"], rigid_modes=problem.phi,
                         separated=names, t=None if t is None else float(t),
                         rigid_acceleration=r["accel"])
    if key is not None:
        _MEAN_SOLUTIONS.put(key, sol)
    return sol


_MEAN_SOLUTIONS = Kept(8)
"""Mean-excitation equilibria solved in this process, by :func:`_mean_key` (the oldest of
more than 8 dropped): a Monte Carlo of errors that turn with the gears
(eccentricity, run-out; they average out of the mean excitation) gives every case the
same mean problem, whose solve was a quarter of a Dong et al. 2021 case's overhead.
The solution's arrays are read-only, so a kept one is handed out as it is."""


def _mean_key(problem: _StaticProblem, *settings) -> bytes:
    """Digest of everything the mean-excitation solve of ``problem`` reads: the mean
    loads, the projections, masses, rigid modes, frame stiffness, spline parameters,
    regularisation, the names its messages use and the solver ``settings``."""
    import hashlib

    from torquesplit._memo import hash_arrays

    s, L = problem.s, problem.loads(None)
    h = hash_arrays(hashlib.blake2b(digest_size=20), (
        problem.V, problem.Kf, problem.mass, problem.phi, problem.sp_par, s.sp_el,
        np.asarray(problem.reg, dtype=float), problem.linear, L.k, L.p, L.e, L.g, L.f_eff,
        np.empty(0) if L.W is None else L.W))
    h.update(repr((problem.has_gaps, s.dof_names, s.element_names, settings)).encode())
    return h.digest()


def quasi_static(
    structure: Structure,
    times,
    *,
    regularisation: float = 1e-9,
    balance_tolerance: float = 1e-8,
    max_iterations: int = 200,
    progress=None,
) -> QuasiStaticSolution:
    """Static equilibrium at each time of ``times`` (mesh positions), e.g. for load
    sharing without dynamics.

    The projection matrix, rigid-body modes and their constraint are built once; each
    time starts its Newton iteration from the previous time's displacements, so a
    smooth sweep usually needs one or two linear solves per time.  ``progress``, if
    given, is called with the fraction of times done (about a hundred times).  Inside
    :func:`torquesplit.solve.integrate.stop_on_interrupt`, Ctrl-C ends the sweep with the
    positions done (``interrupted``; raised again if none is).
    """
    from .integrate import _interrupted

    times = np.atleast_1d(np.asarray(times, dtype=float))
    problem = _StaticProblem(structure, regularisation, balance_tolerance)
    n, n_el, nt = structure.n_dof, structure.n_elements, times.size
    Q = np.zeros((nt, n))
    F = np.zeros((nt, n_el))
    D = np.zeros((nt, n_el))
    C = np.zeros((nt, n_el), dtype=bool)
    conv = np.zeros(nt, dtype=bool)
    its = np.zeros(nt, dtype=np.int64)
    q = None
    every = max(1, nt // 100)
    done = 0
    try:
        for i, t in enumerate(times):
            if progress is not None and i % every == 0:
                progress(i / nt)
            r = problem.solve(t, q, max_iterations)
            q = r["q"] if r["converged"] else None
            Q[i], F[i], D[i], C[i] = r["q"], r["forces"], r["delta"], r["contact"]
            conv[i], its[i] = r["converged"], r["it"]
            done = i + 1
    except BaseException as exc:
        if done == 0 or not _interrupted(exc):
            raise
    cut = slice(0, done)
    return QuasiStaticSolution(times=times[cut], q=Q[cut], element_forces=F[cut],
                               deformations=D[cut], in_contact=C[cut], converged=conv[cut],
                               iterations=its[cut], rigid_modes=problem.phi, planned=nt)
