"""Speed sweeps: pseudo-arclength continuation of the periodic state in speed.

The harmonic-balance equations R(x, s) = 0 (:mod:`.harmonic`) are followed in the
speed factor s by pseudo-arclength continuation (Keller 1977; Seydel, Practical
Bifurcation and Stability Analysis, 2010, section 4.5): tangent predictor, corrector on
``[R(x, s); t.(z - z_pred)] = 0`` with the bordered Jacobian (dR/ds by a finite
difference), step length adapted to the Newton iterations.  The branch may turn back
(fold of a softening backlash response); folds are found where ds/d(arclength)
changes sign and reported as jump speeds.  Each point gets its Floquet multipliers
(unstable where one leaves the unit circle).  Torques are held at the model's values;
the excitation tables, functions of the mesh phase, stay.

A failed corrector halves the step; below the smallest step the sweep stops and the
curve computed so far is returned with the reason (``SpeedSweep.message``).
:func:`stepped_sweep` is the time-integration cross-check: constant-speed RK4 runs at
increasing (run-up) or decreasing (run-down) speeds, each started from the previous
end state.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from torquesplit.errors import (
    ModelWarning,
    OptionError,
    SolverError,
    interrupt_name,
    warn_user,
)
from torquesplit.steady.harmonic import HarmonicBalance
from torquesplit.steady.newton import floquet_hill, floquet_monodromy
from torquesplit.steady.solution import (
    ENERGY_TOL,
    HARMONICS_PER_CYCLE,
    _initial_hb,
    converged_hb,
    hill_applies,
)

log = logging.getLogger(__name__)


def instability(mu) -> str:
    """How a periodic orbit with Floquet multipliers ``mu`` loses stability, from the
    largest: "" (stable, or not computed), "period doubling" (a real multiplier below -1:
    the response is an orbit of twice the period or longer, not this one), "fold" (a real
    one above 1: a jump to another branch) or "torus" (a complex pair: a quasi-periodic
    response, Neimark-Sacker)."""
    if mu is None or not np.size(mu):
        return ""
    mu = np.asarray(mu, dtype=complex)
    top = mu[np.argmax(np.abs(mu))]
    if abs(top) <= 1 + 1e-6:
        return ""
    if abs(top.imag) > 1e-6 * abs(top):
        return "torus"
    return "period doubling" if top.real < 0 else "fold"


def flag_runs(flags) -> list[tuple[int, int]]:
    """(first, last) index of each run of consecutive true ``flags`` (the period-doubling
    bands of a sweep: its line and its figure)."""
    out, start = [], None
    for i, f in enumerate(np.append(np.asarray(flags, bool), False)):
        if f and start is None:
            start = i
        elif not f and start is not None:
            out.append((start, i - 1))
            start = None
    return out


@dataclass
class SweepPoint:
    speed: float
    """Speed factor."""
    x: np.ndarray
    stable: bool | None
    max_multiplier: float
    iterations: int
    instability: str = ""
    """:func:`instability` of the point's orbit."""


@dataclass
class SpeedSweep:
    """A continuation curve (points in arclength order) and what was found on it."""

    points: list
    folds: list
    """Speed factors of the turning points, with the direction the branch took there."""
    message: str
    complete: bool
    reference_speed: float
    """Speed of the first drive at factor 1 [rad/s]."""
    wall_time: float = 0.0
    metrics: dict = field(default_factory=dict)


PRECONDITIONER_REUSE = 0.01
"""Relative speed change after which a continuation rebuilds its GMRES preconditioner."""


END_TOL = 1e-3
"""A continuation point short of the sweep's end by less than this share of the step is
the end: it is replaced by the state at the end itself (not followed by it)."""

FOLD_RESOLUTION = 1e-3
"""Turning points closer than this share of the speed range to a turning point of the
opposite kind just before them are a zig-zag of the branch's numerical tangent, not a
jump (shooting across the kinks of a contact that is just lost: the period map is only
piecewise smooth there); :func:`merge_folds` drops such pairs."""


def bordered_solve(J, Rs, tw, rhs):
    """Solve the dense bordered system [[J, Rs], [tw^T]] z = rhs (least squares if it is
    singular)."""
    n = J.shape[0]
    B = np.zeros((n + 1, n + 1))
    B[:n, :n] = J
    B[:n, n] = Rs
    B[n] = tw
    try:
        return np.linalg.solve(B, rhs)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(B, rhs, rcond=None)[0]


def merge_folds(folds, gap):
    """``folds`` without consecutive opposite pairs closer than ``gap`` in speed."""
    out = []
    for f in folds:
        if out and out[-1][1] != f[1] and abs(out[-1][0] - f[0]) < gap:
            out.pop()
        else:
            out.append(f)
    return out


class Continuation:
    """Pseudo-arclength continuation of ``hb`` (a :class:`HarmonicBalance`) in speed."""

    def __init__(self, hb: HarmonicBalance, tol=1e-9, stability=True, steps_per_period=None):
        self.hb = hb
        self.tol = tol
        self.stability = stability
        self.steps = steps_per_period
        self.eps = 1e-6
        self._pc = None  # (speed it was built at, preconditioner)

    def _R(self, x, s, lin=False):
        return self.hb.residual(x, s, linearise=lin)

    def _Rs(self, x, s, R0):
        R1, _ = self.hb.residual(x, s + self.eps)
        return (R1 - R0) / self.eps

    def _solve_bordered(self, s, Rs, tw, rhs):
        """[[J, Rs], [tw^T]] dz = rhs at the last linearised point."""
        hb = self.hb
        n = hb.size
        if n <= 1500:
            return bordered_solve(hb.dense_jacobian(s), Rs, tw, rhs)
        from torquesplit.steady.harmonic import gmres

        def mv(z):
            return np.concatenate([hb.jvp(z[:n], s)[0] + Rs * z[n], [tw @ z]])

        # the preconditioner (the time-averaged system inverted harmonic by harmonic) is
        # kept while the speed moves by less than PRECONDITIONER_REUSE: a slightly stale
        # one costs GMRES a few iterations, not accuracy (the residual is the true one)
        fresh = self._pc is None or abs(s - self._pc[0]) > PRECONDITIONER_REUSE * self._pc[0]
        while True:
            if fresh:
                self._pc = (s, hb.preconditioner(s))
            P = self._pc[1]
            sol, res = gmres(mv, rhs, lambda z: np.concatenate([P(z[:n]), [z[n]]]), 1e-8, 80)
            if res <= 1e-4 or fresh:
                break
            fresh = True
        if res > 1e-4:
            raise SolverError(f"bordered solve did not converge ({res:.1e})")
        return sol

    def _weights(self, x):
        return 1.0 / max(float(np.linalg.norm(x)), 1e-300)

    def lowest_speed(self, s0, s1) -> float:
        """Below this speed factor the branch has left the range backwards."""
        return min(s0, s1) - 0.5 * abs(s1 - s0)

    remedy = ("Use more harmonics (--harmonics), a smaller --max-step, or the shooting "
              "continuation (--method shooting).")
    """What to try when the corrector fails (said in the message)."""

    def _tangent_system(self, x, s, tw, rhs):
        """Solve the bordered system [[dR/dx, dR/ds], [tw]] t = rhs at (x, s)."""
        R0, _ = self._R(x, s, lin=True)
        return self._solve_bordered(s, self._Rs(x, s, R0), tw, rhs)

    def tangent(self, x, s, prev=None):
        """Unit tangent of the branch at (x, s) in the weighted metric, oriented along
        ``prev`` (the previous tangent with its state part already weighted twice)."""
        n = self.size
        tw = np.zeros(n + 1)
        if prev is None:
            tw[n] = 1.0
        else:
            tw[:] = prev
        rhs = np.zeros(n + 1)
        rhs[n] = 1.0
        t = self._tangent_system(x, s, tw, rhs)
        w = self._weights(x)
        t = t / math.sqrt(float(np.linalg.norm(w * t[:n])) ** 2 + t[n] ** 2)
        if prev is not None and (t[:n] @ prev[:n] + t[n] * prev[n]) < 0:
            t = -t
        return t

    def correct(self, z_pred, t, max_iter=10):
        hb = self.hb
        n = hb.size
        z = z_pred.copy()
        w = self._weights(z[:n])
        tw = np.concatenate([t[:n] * w * w, [t[n]]])
        err = math.inf
        for it in range(1, max_iter + 1):
            x, s = z[:n], z[n]
            if not s > 0:
                return None, it
            R, scale = self._R(x, s, lin=True)
            err = float(np.max(np.abs(R))) / scale
            arc = tw @ (z - z_pred)
            if err <= self.tol and abs(arc) < 1e-9:
                return z, it
            Rs = self._Rs(x, s, R)
            dz = self._solve_bordered(s, Rs, tw, -np.concatenate([R, [arc]]))
            z = z + dz
            if not np.all(np.isfinite(z)):
                return None, it
        R, scale = self._R(z[:n], z[n], lin=True)
        err = float(np.max(np.abs(R))) / scale
        return (z if err <= 10 * self.tol else None), max_iter

    def multipliers(self, x, s):
        hb = self.hb
        p = hb.p
        if hill_applies(p, hb.H, p.frequency * s):
            return floquet_hill(hb, x, s, hb.H)
        q, v, _ = hb.waveforms(x, s)
        _, lam = hb.split(x)
        y0 = hb._states(q, v, lam)[0]
        T = 1.0 / (p.frequency * s)
        steps = p.rk4_steps(T, self.steps, 1) if self.steps else p.rk4_steps(T)
        _, Phi = p.integrate_variational(y0, 0.0, T, steps, s)
        return floquet_monodromy(p, Phi)

    @property
    def size(self) -> int:
        return self.hb.size

    def solve(self, x0, s):
        """The periodic state at speed factor s from ``x0``: (x, NewtonInfo)."""
        from torquesplit.steady.newton import solve_hb

        return solve_hb(self.hb, x0, s, self.tol)

    def run(self, x0, s0, s1, step, max_step, min_step, max_points=2000, progress=None):
        n = self.size
        direction = 1.0 if s1 > s0 else -1.0
        x, info = self.solve(x0, s0)
        if not info.converged:
            raise SolverError(f"no periodic state at the start of the sweep (speed factor "
                              f"{s0:.4g}, residual {info.residual:.1e}); start the sweep "
                              f"elsewhere, use more harmonics, or keep fewer excitations.")
        pts = []
        folds = []
        z = np.concatenate([x, [s0]])
        t = self.tangent(x, s0)
        if t[n] * direction < 0:
            t = -t
        message = "complete"
        complete = True
        h = step
        try:  # Ctrl-C keeps the curve computed so far, as any other stop does
            while len(pts) < max_points:
                mu = self.multipliers(z[:n], z[n]) if self.stability else None
                m = float(np.max(np.abs(mu))) if mu is not None and mu.size else math.nan
                pts.append(SweepPoint(float(z[n]), z[:n].copy(),
                                      None if mu is None else bool(m <= 1 + 1e-6), m, 0,
                                      instability(mu)))
                if progress is not None:
                    progress(min(1.0, abs(z[n] - s0) / abs(s1 - s0)))
                # at or past the end (or short of it by a rounding of the arclength step:
                # a reviewer's sweep ended 759.99985, 760 rpm): the state at the end itself
                if (z[n] - s1) * direction >= -END_TOL * step:
                    if z[n] != s1 and len(pts) > 1:
                        x_end, info_end = self.solve(z[:n].copy(), s1)
                        if info_end.converged:
                            mu = self.multipliers(x_end, s1) if self.stability else None
                            m = float(np.max(np.abs(mu))) if mu is not None and mu.size \
                                else math.nan
                            pts[-1] = SweepPoint(float(s1), x_end.copy(), None if mu is None
                                                 else bool(m <= 1 + 1e-6), m, 0,
                                                 instability(mu))
                    break
                while True:
                    z_pred = z + h * t
                    try:
                        zc, its = self.correct(z_pred, t)
                    except SolverError as exc:
                        zc, its = None, 99
                        log.info("corrector failed: %s", exc)
                    if zc is not None:
                        break
                    h *= 0.5
                    if h < min_step:
                        message = (f"continuation failed at speed factor {z[n]:.6g}: the "
                                   f"corrector did not converge down to the smallest step "
                                   f"{min_step:.3g}; the curve up to there is kept. "
                                   f"{self.remedy}")
                        complete = False
                        break
                if zc is None:
                    break
                try:
                    t_new = self.tangent(zc[:n], zc[n], np.concatenate(
                        [t[:n] * self._weights(zc[:n]) ** 2, [t[n]]]))
                except SolverError as exc:
                    message = f"tangent failed at speed factor {zc[n]:.6g} ({exc}); curve kept."
                    complete = False
                    break
                if t_new[n] * t[n] < 0:  # fold: ds/darc changed sign
                    a = t[n] / (t[n] - t_new[n])
                    s_f = z[n] + a * (zc[n] - z[n])
                    folds.append((float(s_f), "turns back" if t[n] * direction > 0 else "turns on"))
                z, t = zc, t_new
                h = min(max_step, h * (1.5 if its <= 3 else (1.0 if its <= 5 else 0.6)))
                # backwards out of the range: below it on a rising sweep, above it on a
                # falling one (a falling sweep had no upper guard: it turned at a fold and
                # ran to 958,635 rpm; and its end, overshot below, read as 'backwards')
                if (zc[n] < self.lowest_speed(s0, s1) if direction > 0
                        else zc[n] > max(s0, s1) + 0.5 * abs(s1 - s0)):
                    message = "the branch left the speed range backwards; curve kept."
                    if folds:  # (at a fold the response jumps: the rest of the range is
                        # on another branch, which a sweep from the other end follows)
                        message = (f"the branch turned back at a fold near speed factor "
                                   f"{folds[-1][0]:.6g} (a jump: beyond it the response is "
                                   f"on another branch) and left the speed range; curve "
                                   f"kept: a sweep from the other end of the range follows "
                                   f"the branch there")
                    complete = False
                    break
            else:
                message = f"stopped after {max_points} points; curve kept."
                complete = False
        except KeyboardInterrupt:
            if not pts:  # nothing to keep: the caller stops (a Ctrl-C while the kernels
                # compiled gave an empty curve whose checks then called a half-built
                # kernel: numba's RuntimeError)
                raise
            message = (f"interrupted ({interrupt_name()}) after {len(pts)} points; the curve "
                       f"up to there is kept.")
            complete = False
        return pts, merge_folds(folds, FOLD_RESOLUTION * abs(s1 - s0)), message, complete


class ShootingContinuation(Continuation):
    """Pseudo-arclength continuation in speed of the shooting equations
    G(x, s) = Q^T (phi_T(s)(Q x) - Q x) = 0, x the state's coordinates on the complement
    Q of the rigid subspace (:func:`~torquesplit.steady.newton.complement`) and phi the
    period map stepping through the tables' corners.  The period is T = 1 / (f0 s) in a
    fixed number of RK4 steps (those of the lowest speed the branch may reach), so G is
    smooth in s.  At every point the monodromy Phi (variational equations) gives the
    Jacobian Q^T Phi Q - I of the tangent and of the next point's corrector (a chord
    iteration: the corrector only integrates the state), and the Floquet multipliers;
    dG/ds is a forward difference.  Per point: one monodromy and a few state periods."""

    def __init__(self, problem, period, s_low, q_static, tol=1e-9, stability=True,
                 steps_per_cycle=None):
        from torquesplit.steady.newton import complement

        self.p = problem
        self.tol = tol
        self.stability = stability
        self.Q = complement(problem)
        n = problem.n
        # complement columns are pure displacement or pure velocity (the rigid subspace is)
        is_v = np.abs(self.Q[n:]).sum(axis=0) > np.abs(self.Q[:n]).sum(axis=0)
        size = max(float(np.linalg.norm(self.Q[:n].T @ q_static)), 1e-300)
        w_v = 2 * math.pi * problem.frequency  # omega at the model's speed
        self._w = np.where(is_v, 1.0 / (w_v * size), 1.0 / size)
        order = max(period.max_order, 1)
        self.s_low = s_low
        self.steps = problem.rk4_steps(1.0 / (problem.frequency * s_low), steps_per_cycle,
                                       order)
        self._J = None  # (z it was formed at, Jacobian, multipliers)

    @property
    def size(self) -> int:
        return self.Q.shape[1]

    def lowest_speed(self, s0, s1) -> float:
        return self.s_low

    remedy = ("Use more RK4 steps per cycle (--steps-per-cycle), a smaller --max-step, or "
              "harmonic balance (--method hb), whose smoothing can pass a grazing contact.")

    def _weights(self, x):
        """Per-coordinate weights of the arclength metric, the same all along the branch:
        displacements over the static deflection's size, velocities over omega times it
        (a velocity is omega times a displacement), so that neither dominates the step
        (the state at t = 0 itself passes near zero where the phase turns)."""
        return self._w

    def period(self, s):
        return 1.0 / (self.p.frequency * s)

    def state(self, x):
        return self.Q @ x

    def G(self, x, s):
        y = self.Q @ x
        yT = self.p.integrate(y, 0.0, self.period(s), self.steps, every=self.steps,
                              speed=s, max_rows=1)[3]
        return self.Q.T @ (yT - y)

    def Gs(self, x, s, G0):
        eps = 1e-7 * s
        return (self.G(x, s + eps) - G0) / eps

    def error(self, x, s, G):
        """Defect over the largest deformation (velocities over omega), as shooting."""
        p = self.p
        n = p.n
        V = p.structure.projection_matrix()
        y, d = self.Q @ x, self.Q @ G
        w = 2 * math.pi / self.period(s)
        scale = max(float(np.max(np.abs(V @ y[:n]), initial=0.0)), 1e-300)
        return max(float(np.max(np.abs(V @ d[:n]), initial=0.0)),
                   float(np.max(np.abs(V @ d[n:]), initial=0.0)) / w) / scale

    def jacobian(self, x, s):
        """Q^T Phi Q - I at (x, s), and the Floquet multipliers (eigenvalues of
        Q^T Phi Q), kept for the point."""
        _, Phi = self.p.integrate_variational(self.Q @ x, 0.0, self.period(s), self.steps, s)
        M = self.Q.T @ Phi @ self.Q
        mu = np.linalg.eigvals(M)
        self._J = (np.concatenate([x, [s]]), M - np.eye(self.size),
                   mu[np.argsort(-np.abs(mu))])
        return self._J[1]

    def solve(self, x0, s):
        from torquesplit.steady.newton import solve_shooting

        y, _, info = solve_shooting(self.p, self.Q @ x0, self.steps, s, self.tol,
                                    krylov=False, monodromy=False)
        return self.Q.T @ y, info

    def _tangent_system(self, x, s, tw, rhs):
        J = self.jacobian(x, s)  # also the next corrector's and the multipliers
        return bordered_solve(J, self.Gs(x, s, self.G(x, s)), tw, rhs)

    def correct(self, z_pred, t, max_iter=12):
        """Chord iterations with the Jacobian of the last point (formed again once if
        they stall)."""
        n = self.size
        z = z_pred.copy()
        w = self._weights(z[:n])
        tw = np.concatenate([t[:n] * w * w, [t[n]]])
        J = self._J[1] if self._J is not None else self.jacobian(z[:n], z[n])
        last = math.inf
        refreshed = False
        for it in range(1, max_iter + 1):
            x, s = z[:n], z[n]
            if not s > 0:
                return None, it
            G = self.G(x, s)
            err = self.error(x, s, G)
            arc = tw @ (z - z_pred)
            if err <= self.tol and abs(arc) < 1e-9:
                return z, it
            if err > 0.5 * last and not refreshed:  # the chord stalls: a fresh Jacobian
                J = self.jacobian(x, s)
                refreshed = True
            last = err
            dz = bordered_solve(J, self.Gs(x, s, G), tw, -np.concatenate([G, [arc]]))
            z = z + dz
            if not np.all(np.isfinite(z)):
                return None, it
        return None, max_iter

    def multipliers(self, x, s):
        z = np.concatenate([x, [s]])
        if self._J is None or not np.array_equal(self._J[0], z):
            self.jacobian(x, s)
        return self._J[2]


def shooting_point_metrics(cont: ShootingContinuation, x, s, track, groups, static_forces,
                           nominal):
    """As :func:`point_metrics`, from one period of the shooting state integrated with its
    samples and the forces at the tables' corners (peaks and the load-sharing ratio's
    extremes take both; means and the RMS transmission error the samples)."""
    p = cont.p
    T = cont.period(s)
    r = p.run(cont.state(x), 0.0, T, cont.steps, every=cont.steps, speed=s,
              corners=True, track=track)
    f = r.track_forces[:-1]
    peak, mean = record_extremes(p, r, T, s, track, periodic=True)
    t = np.arange(f.shape[0]) * (T / cont.steps)
    return _point_outputs(f, np.vstack([f, r.corner_forces[:, track]]),
                          r.track_deformations[:-1] + p.line_errors(track, t, s), groups,
                          static_forces, nominal, peak, mean)


def record_extremes(p, r, span, speed, track, periodic):
    """Peak force and time mean of each ``track`` element over a record ``r`` of
    :meth:`PeriodicProblem.run` spanning ``span`` from 0, as the integrators' statistics
    take them: the peaks of the samples, the corner instants and the parabolas between
    them (:func:`~torquesplit.steady.api.between_samples`), the mean by the trapezoid
    rule with the corners as breakpoints.  ``periodic``: the record is one period."""
    from torquesplit.steady.api import (
        between_samples,
        cycle_integrals,
        half_gaps,
        period_weights,
    )

    s = p.structure
    n = r.track_forces.shape[0] - (1 if periodic else 0)
    t = np.arange(n) * (span / (r.track_forces.shape[0] - 1))
    tc = r.corner_t
    kinks = p.corner_times(0.0, span, speed)
    peak = np.empty(len(track))
    mean = np.empty(len(track))
    if periodic:
        ws, wc = period_weights(t, tc, span)
    for j, e in enumerate(track):
        f, d = r.track_forces[:n, j], r.track_deformations[:n, j]
        fc = r.corner_forces[:, e]
        vmax, _ = between_samples(t, f, d, half_gaps(s, e, t), span, tc, fc,
                                  r.corner_deformations[:, e], half_gaps(s, e, tc),
                                  periodic=periodic, kinks=kinks)
        peak[j] = max(f.max(), fc.max(initial=-np.inf), vmax.max())
        if periodic:
            mean[j] = (ws @ f + wc @ fc) / span
        else:  # the record as one cycle
            tt = np.concatenate([t, tc])
            o = np.argsort(tt, kind="stable")
            total, time = cycle_integrals(tt[o], np.concatenate([f, fc])[o],
                                          np.zeros(tt.size, dtype=np.int64), 1, 0.0, span)
            mean[j] = total[0] / time[0]
    return peak, mean


def _point_outputs(f, f_all, d, groups, static_forces, nominal, peak, mean):
    """A sweep point's outputs per tracked mesh from its force samples ``f``, those and
    any instants between them ``f_all`` (the load-sharing ratio's extremes), the
    transmission-error samples ``d`` (deformation plus error: ``V q``), the peak forces
    ``peak`` and mean forces ``mean`` (:func:`record_extremes`): peak force, dynamic factors, load sharing (the ratio of
    the mean forces in its group, Dong et al. 2021 eq. 12, whatever the model's
    definition, and the largest instantaneous ratio, Ji & Li eq. 18), RMS
    transmission error, mean force, contact loss (the fraction of the samples in which
    the mesh carries no force)."""
    lsc = np.full(f.shape[1], np.nan)
    lsc_inst = np.full(f.shape[1], np.nan)
    mean = np.asarray(mean, dtype=float)
    for cols in groups:
        sub = f_all[:, cols]
        tot = sub.sum(axis=1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = len(cols) * sub / np.where(tot != 0, tot, np.nan)  # Ji & Li eq. 18
            # Dong et al. 2021 eq. 12: N mean F_i / sum_j mean F_j
            lsc[cols] = len(cols) * mean[cols] / mean[cols].sum()
        lsc_inst[cols] = np.nanmax(r, axis=0)
    rms = np.sqrt(np.mean((d - d.mean(axis=0)) ** 2, axis=0))
    # out of contact the mesh law's force is exactly 0 (samples uniform in time)
    loss = np.mean(f == 0.0, axis=0)
    return dict(peak_force=peak, dynamic_factor=peak / static_forces,
                peak_to_nominal=peak / nominal, load_sharing=lsc,
                load_sharing_instantaneous=lsc_inst, rms_transmission_error=rms,
                mean_force=mean, contact_loss=loss)


def continue_in_speed_shooting(problem, period, q_static, s0, s1, *, points=50,
                               stability=True, max_step=None, tol=1e-9, progress=None,
                               steps_per_cycle=None):
    """Continuation of the shooting state of ``problem`` from speed factor s0 to s1
    (:class:`ShootingContinuation`); returns (continuation, points, folds, message,
    complete, seconds).  The branch may dip to 0.8 x the lower end of the range."""
    t0 = time.perf_counter()
    _check_range(s0, s1)
    cont = ShootingContinuation(problem, period, 0.8 * min(s0, s1), q_static, tol,
                                stability, steps_per_cycle)
    y = problem.settled_start(np.concatenate([q_static, np.zeros(problem.n)]),
                              cont.period(s0), cont.steps, s0, period.max_order)
    step = abs(s1 - s0) / max(points - 1, 1)
    max_step = step * 2 if max_step is None else max_step
    pts, folds, msg, complete = cont.run(cont.Q.T @ y, s0, s1, step, max_step, step * 1e-3,
                                         progress=progress)
    return cont, pts, folds, msg, complete, time.perf_counter() - t0


def _check_range(s0, s1):
    if not (s0 > 0 and s1 > 0 and math.isfinite(s0) and math.isfinite(s1)) or s0 == s1:
        raise OptionError(f"the speed range {s0:.4g}..{s1:.4g} (times the model's speed) "
                          f"must be two different positive speeds; e.g. from '1000 rpm' to "
                          f"'3000 rpm' (--from, --to; in Python start=, stop=).")


def continue_in_speed(problem, period, q_static, s0, s1, *, points=50, harmonics=None,
                      samples=None, stability=True, max_step=None, tol=1e-9,
                      progress=None, initial=None):
    """Continuation of the HB state of ``problem`` from speed factor s0 to s1."""
    t0 = time.perf_counter()
    _check_range(s0, s1)
    order = max(period.max_order, 1)
    if harmonics is None:  # as steady_state chooses them at the first speed, then kept
        hb, x0, info, energy = converged_hb(problem, HARMONICS_PER_CYCLE * order, samples,
                                            s0, q_static, initial, tol, smallest=True)
        if not info.converged:  # let the continuation's corrector report the failure
            x0 = _initial_hb(hb, q_static, initial)
        elif energy > ENERGY_TOL:
            warn_user(
                f"the sweep keeps {hb.H} harmonics, the most it could converge at its first "
                f"speed, with {energy:.1e} of the velocity energy in the top quarter (above "
                f"{ENERGY_TOL:.0e}): peak forces may be off in the last digits; keep one "
                f"stage's excitations (--keep) for a shorter period", ModelWarning)
    else:
        hb = HarmonicBalance(problem, int(harmonics), samples)
        x0 = _initial_hb(hb, q_static, initial)
    step = abs(s1 - s0) / max(points - 1, 1)
    max_step = step * 2 if max_step is None else max_step
    cont = Continuation(hb, tol, stability)
    pts, folds, msg, complete = cont.run(x0, s0, s1, step, max_step, step * 1e-3,
                                         progress=progress)
    return hb, pts, folds, msg, complete, time.perf_counter() - t0


def point_metrics(hb: HarmonicBalance, x, s, track, groups, static_forces, nominal,
                  per_cycle=32, order=1):
    """Per-mesh peak force, dynamic factors, load sharing (instantaneous ratio, largest
    over the period) and RMS transmission error of one HB point."""
    from torquesplit.steady.harmonic import default_samples

    N = max(hb.N, per_cycle * order)
    if N != hb.N:
        hb2 = HarmonicBalance(hb.p, hb.H, max(N, default_samples(hb.H)))
        from torquesplit.steady.solution import pad_coefficients
        x2 = pad_coefficients(x, hb2)
    else:
        hb2, x2 = hb, x
    _, _, F, D, _, _ = hb2.residual_samples(x2, s)
    f = F[:, track]
    te = D[:, track] + hb2.p.line_errors(track, hb2.times(s), s)
    # the samples' extremes (a truncated series rings between them: no parabola)
    return _point_outputs(f, f, te, groups, static_forces, nominal,
                          f.max(axis=0), f.mean(axis=0))


def stepped_sweep(problem, period, q_static, speeds, *, settle_periods=200,
                  record_periods=1, steps_per_cycle=None, track=(), progress=None):
    """Time-integration cross-check: RK4 (through the tables' corners) at each speed
    factor of ``speeds`` in order, ``settle_periods`` periods from the previous end state
    (the first from the static state), then ``record_periods`` recorded.  Returns the
    per-mesh peak forces (n_speeds, n_track) and the RMS transmission errors."""
    p = problem
    y = np.concatenate([q_static, np.zeros(p.n)])
    peaks = np.full((len(speeds), len(track)), np.nan)
    rms = np.full((len(speeds), len(track)), np.nan)
    order = max(period.max_order, 1)
    for i, s in enumerate(speeds):
        T = 1.0 / (period.frequency * s)
        steps = p.rk4_steps(T, steps_per_cycle, order)
        try:
            _, _, _, y = p.integrate(y, 0.0, settle_periods * T, settle_periods * steps,
                                     every=settle_periods * steps, speed=s)
            r = p.run(y, 0.0, record_periods * T, record_periods * steps,
                      every=record_periods * steps, speed=s, corners=True, track=track)
        except SolverError:
            break
        y = r.y_end
        if len(track):
            # the peaks at the tables' corners and between the samples too, as the
            # integrators' statistics take them
            peaks[i] = record_extremes(p, r, record_periods * T, s, list(track),
                                       periodic=False)[0]
            t = np.arange(r.track_deformations.shape[0]) * (T / steps)
            d = r.track_deformations + p.line_errors(track, t, s)  # (the TE: V q)
            rms[i] = np.sqrt(np.mean((d - d.mean(axis=0)) ** 2, axis=0))
        if progress is not None:
            progress((i + 1) / len(speeds))
    return peaks, rms
