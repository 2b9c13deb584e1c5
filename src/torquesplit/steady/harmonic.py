"""Harmonic balance with alternating frequency-time evaluation (AFT).

The periodic displacement is a truncated Fourier series of the fundamental
omega = 2 pi f0 (Cameron & Griffin 1989, the AFT scheme; Krack & Gross, Harmonic
Balance for Nonlinear Vibration Problems, 2019, ch. 2-3)::

    q(t) = a_0 + sum_{k=1..H} a_k cos(k omega t) + b_k sin(k omega t)

Its samples at N equally spaced instants of the period go through the model's own
compiled right-hand side (every element law, dead zone, spline and friction), the
residual ``q'' - a(t, q, q') (+ the rigid-mode terms of :mod:`.problem`)`` is
transformed back by FFT, and its first H harmonics are required to vanish (Galerkin).
Newton's method solves the equations; the Jacobian is the AFT of the law slopes (the
laws' analytic derivatives), applied matrix-free and solved by GMRES, preconditioned by
the exact inverse of the time-averaged system harmonic by harmonic (a dense solve for
small systems).  Unknown vector ``x = [u, lambda]``: ``u`` (2H+1, n) holds a_0, a_1,
b_1, ..., lambda one value per rigid mode.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from torquesplit.errors import OptionError, SolverError
from torquesplit.steady.problem import PeriodicProblem

log = logging.getLogger(__name__)

DENSE_LIMIT = 1500
"""Unknowns up to which the Jacobian is formed densely and factorised."""


def default_samples(harmonics: int) -> int:
    """Time samples per period for H harmonics: the next fast FFT length >= 3 H + 2
    (the AFT of products and dead zones aliases less with oversampling), at least 16."""
    from scipy.fft import next_fast_len

    return max(16, next_fast_len(3 * harmonics + 2, real=True))


class HarmonicBalance:
    """The HB equations of ``problem`` with ``harmonics`` H and ``samples`` N."""

    def __init__(self, problem: PeriodicProblem, harmonics: int, samples: int | None = None):
        H = int(harmonics)
        if H < 1:
            raise OptionError("harmonics must be >= 1; e.g. harmonics=16 per excitation cycle.")
        N = default_samples(H) if samples is None else int(samples)
        if N < 2 * H + 2:
            raise OptionError(f"{N} time samples cannot carry {H} harmonics; use at least "
                              f"2 H + 2 = {2 * H + 2} samples.")
        self.p = problem
        self.H = H
        self.N = N
        self.n = problem.n
        self.size = (2 * H + 1) * self.n + problem.nr
        self._lin = None
        self._lin_speed = None

    # ------------------------------------------------------------------ layout
    def split(self, x):
        n, H = self.n, self.H
        u = x[:(2 * H + 1) * n].reshape(2 * H + 1, n)
        return u, x[(2 * H + 1) * n:]

    def to_complex(self, u):
        c = np.empty((self.H + 1, self.n), dtype=complex)
        c[0] = u[0]
        c[1:] = 0.5 * (u[1::2] - 1j * u[2::2])
        return c

    def from_complex(self, c):
        u = np.empty((2 * self.H + 1,) + c.shape[1:])
        u[0] = c[0].real
        u[1::2] = 2 * c[1:].real
        u[2::2] = -2 * c[1:].imag
        return u

    def omega(self, speed=1.0):
        return 2 * math.pi * self.p.frequency * speed

    def times(self, speed=1.0):
        return np.arange(self.N) / (self.N * self.p.frequency * speed)

    def _time(self, c):
        spec = np.zeros((self.N // 2 + 1,) + c.shape[1:], dtype=complex)
        spec[:self.H + 1] = c * self.N
        return np.fft.irfft(spec, n=self.N, axis=0)

    def _freq(self, x):
        return np.fft.rfft(x, axis=0)[:self.H + 1] / self.N

    def waveforms(self, x, speed=1.0, shift=0.0):
        """(q, v, q'') samples (N, n) of the solution ``x`` (at the sample times moved
        by ``shift`` sample intervals)."""
        u, _ = self.split(x)
        c = self.to_complex(u)
        if shift:
            c = c * np.exp(2j * np.pi * shift * np.arange(self.H + 1) / self.N)[:, None]
        k = np.arange(self.H + 1)[:, None] * self.omega(speed)
        qva = self._time(np.stack([c, 1j * k * c, -(k**2) * c], axis=1))  # one transform
        return qva[:, 0], qva[:, 1], qva[:, 2]

    def evaluate_at(self, x, t, speed=1.0):
        """q, v at arbitrary times t (direct sums; for checks off the sample grid)."""
        u, _ = self.split(x)
        w = self.omega(speed)
        k = np.arange(1, self.H + 1)
        ph = np.outer(t, k) * w
        cs, sn = np.cos(ph), np.sin(ph)
        q = u[0] + cs @ u[1::2] + sn @ u[2::2]
        v = (-sn * k * w) @ u[1::2] + (cs * k * w) @ u[2::2]
        acc = (-cs * (k * w) ** 2) @ u[1::2] + (-sn * (k * w) ** 2) @ u[2::2]
        return q, v, acc

    # ------------------------------------------------------------------ residual
    def _states(self, q, v, lam):
        p = self.p
        vv = v
        if p.nr and np.any(p.rigid_damped):
            vv = v + (p.rigid[:, p.rigid_damped] @ lam[p.rigid_damped])[None, :]
        return np.hstack([q, vv])

    def residual_samples(self, x, speed=1.0, shift=0.0):
        """Equation residual q'' - a(t, q, v) (+ rigid terms) at the samples (moved by
        ``shift`` sample intervals), with the accelerations a, forces and deformations."""
        _, lam = self.split(x)
        t = self.times(speed) + shift / (self.N * self.p.frequency * speed)
        q, v, acc = self.waveforms(x, speed, shift)
        a, f, d = self.p.accelerations(t, self._states(q, v, lam), speed)
        r = acc - a
        p = self.p
        if p.nr and np.any(~p.rigid_damped):
            r = r + (p.rigid[:, ~p.rigid_damped] @ lam[~p.rigid_damped])[None, :]
        return r, a, f, d, q, v

    def residual(self, x, speed=1.0, linearise=False):
        """The HB equations R(x) (length ``size``) and the scale of the accelerations."""
        r, a, _, _, q, v = self.residual_samples(x, speed)
        if linearise:
            _, lam = self.split(x)
            self._lin = self.p.linearise(self.times(speed), self._states(q, v, lam), speed)
            self._lin_speed = speed
        R = np.concatenate([self.from_complex(self._freq(r)).ravel(), self._constraint(x)])
        scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(r + a))), 1e-300)
        return R, scale

    def _constraint(self, x):
        u, _ = self.split(x)
        p = self.p
        return (p.rigid.T @ (p.mass * u[0])) * self.omega() ** 2 if p.nr else np.zeros(0)

    # ------------------------------------------------------------------ Jacobian
    def jvp(self, dx, speed=None):
        """J dx at the last linearised point (matrix-free AFT)."""
        speed = self._lin_speed if speed is None else speed
        dx = np.atleast_2d(dx)  # (n_dir, size)
        n, H, p = self.n, self.H, self.p
        nd = dx.shape[0]
        U = dx[:, :(2 * H + 1) * n].reshape(nd, 2 * H + 1, n)
        lam = dx[:, (2 * H + 1) * n:]
        c = np.stack([self.to_complex(U[i]) for i in range(nd)], axis=1)  # (H+1, nd, n)
        k = (np.arange(H + 1) * self.omega(speed))[:, None, None]
        # q, q', q'' of every direction in one transform: (N, 3, nd, n)
        qva = self._time(np.stack([c, 1j * k * c, -(k**2) * c], axis=1))
        dq, dv, dacc = (np.moveaxis(qva[:, i], 1, 0) for i in range(3))
        if p.nr and np.any(p.rigid_damped):
            dv_in = dv + (lam[:, p.rigid_damped] @ p.rigid[:, p.rigid_damped].T)[:, None, :]
        else:
            dv_in = dv
        r = dacc - p.jvp(self._lin, dq, dv_in, speed)
        if p.nr and np.any(~p.rigid_damped):
            r = r + (lam[:, ~p.rigid_damped] @ p.rigid[:, ~p.rigid_damped].T)[:, None, :]
        R = self.from_complex(self._freq(np.moveaxis(r, 0, 1)))  # (2H+1, nd, n)
        R = np.moveaxis(R, 1, 0).reshape(nd, -1)
        if p.nr:
            con = (U[:, 0, :] * p.mass) @ p.rigid * self.omega() ** 2
            R = np.hstack([R, con])
        return R

    def dense_jacobian(self, speed=None):
        out = np.empty((self.size, self.size))
        step = 256
        for i in range(0, self.size, step):
            cols = np.eye(self.size)[i:i + step]
            out[:, i:i + step] = self.jvp(cols, speed).T
        return out

    def preconditioner(self, speed=None):
        """Inverse of the time-averaged system, harmonic by harmonic, as a function."""
        speed = self._lin_speed if speed is None else speed
        p, n, H = self.p, self.n, self.H
        aq, av = p.mean_jacobian(self._lin, speed)
        w = self.omega(speed)
        k = np.arange(1, H + 1)[:, None, None]
        Z = -(k * w) ** 2 * np.eye(n)[None] - aq[None] - 1j * k * w * av[None]
        try:
            Zi = np.linalg.inv(Z)
        except np.linalg.LinAlgError:
            Zi = np.linalg.pinv(Z)
        nr = p.nr
        Z0 = np.zeros((n + nr, n + nr))
        Z0[:n, :n] = -aq
        for r in range(nr):
            phi = p.rigid[:, r]
            Z0[:n, n + r] = -(av @ phi) if p.rigid_damped[r] else phi
            Z0[n + r, :n] = phi * p.mass * w**2
        Z0i = np.linalg.pinv(Z0)

        def apply(rhs):
            u = rhs[:(2 * H + 1) * n].reshape(2 * H + 1, n)
            out = np.empty_like(rhs)
            ou = out[:(2 * H + 1) * n].reshape(2 * H + 1, n)
            z0 = Z0i @ np.concatenate([u[0], rhs[(2 * H + 1) * n:]])
            ou[0] = z0[:n]
            out[(2 * H + 1) * n:] = z0[n:]
            rho = 0.5 * (u[1::2] - 1j * u[2::2])
            c = np.matmul(Zi, rho[:, :, None])[:, :, 0]
            ou[1::2] = 2 * c.real
            ou[2::2] = -2 * c.imag
            return out

        return apply

    def solve_linear(self, rhs, speed=None, rtol=1e-7):
        """Solve J dx = rhs at the linearised point: dense LU for small systems, else
        preconditioned GMRES (dense fallback when GMRES stalls and the size allows)."""
        if self.size <= DENSE_LIMIT:
            J = self.dense_jacobian(speed)
            try:
                sol = np.linalg.solve(J, rhs)
                if np.all(np.isfinite(sol)):
                    return sol
            except np.linalg.LinAlgError:
                pass
            return np.linalg.lstsq(J, rhs, rcond=None)[0]
        M = self.preconditioner(speed)
        sol, res = gmres(lambda v: self.jvp(v, speed)[0], rhs, M, rtol, 60)
        if res > rtol:
            log.info("GMRES stopped at relative residual %.2e", res)
            if res > 1e-3:
                raise SolverError(f"the linear solve of a Newton step did not converge "
                                  f"(GMRES residual {res:.1e}); the Jacobian is nearly "
                                  f"singular (a turning point or instability): use "
                                  f"method='shooting' or continuation in speed.")
        return sol


def gmres(matvec, b, precond, rtol=1e-7, max_iter=60):
    """Right-preconditioned GMRES without restarts (Saad & Schultz 1986), with one
    re-orthogonalisation per step.  Returns (x, relative residual)."""
    beta = float(np.linalg.norm(b))
    if beta == 0:
        return np.zeros_like(b), 0.0
    V = np.empty((max_iter + 1, b.size))
    Hm = np.zeros((max_iter + 1, max_iter))
    V[0] = b / beta
    res = 1.0
    y = np.zeros(0)
    j = 0
    for j in range(max_iter):
        w = matvec(precond(V[j]))
        for _ in range(2):
            h = V[:j + 1] @ w
            w = w - h @ V[:j + 1]
            Hm[:j + 1, j] += h
        Hm[j + 1, j] = np.linalg.norm(w)
        e1 = np.zeros(j + 2)
        e1[0] = beta
        y = np.linalg.lstsq(Hm[:j + 2, :j + 1], e1, rcond=None)[0]
        res = float(np.linalg.norm(Hm[:j + 2, :j + 1] @ y - e1)) / beta
        if res <= rtol or Hm[j + 1, j] <= 1e-14 * beta:
            break
        V[j + 1] = w / Hm[j + 1, j]
    return precond(y @ V[:j + 1]), res
