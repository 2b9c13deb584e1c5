"""Newton's method for harmonic balance and shooting, and Floquet multipliers.

* :func:`solve_hb` - damped Newton on the HB equations (:mod:`.harmonic`).
* :func:`solve_shooting` - Newton on the period map y0 -> y(T) (Keller 1968; Seydel,
  Practical Bifurcation and Stability Analysis, 3rd ed., 2010, section 7.1), the
  monodromy matrix dy(T)/dy0 from the variational equations integrated with the state
  by the compiled RK4 (:func:`._kernels.rk4_variational`).
* :func:`floquet_monodromy` - Floquet multipliers: eigenvalues of the monodromy matrix
  (Seydel 2010, section 7.3) on the quotient by the rigid-body subspace.
* :func:`floquet_hill` - Hill's method on the HB solution (Lazarus & Thomas 2010,
  C. R. Mecanique 338, the eigenvectors most centred in the harmonics select the
  Floquet exponents).

Rigid-body modes: the subspace R spanned by [phi_r, 0] (and [0, phi_r] when no load
characteristic damps the mode) is invariant under the flow and carries no deformation;
residuals, Newton steps and multipliers are taken on the quotient by R (see
:mod:`.problem`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import SolverError
from torquesplit.steady.harmonic import HarmonicBalance, gmres
from torquesplit.steady.problem import PeriodicProblem

log = logging.getLogger(__name__)


@dataclass
class NewtonInfo:
    converged: bool
    iterations: int
    residual: float
    """Final relative residual."""
    history: list
    products: int = 0
    """Shooting, matrix-free: variational products Phi v taken (0: monodromy formed)."""
    anderson: int = 0
    """Shooting: period maps of the Anderson-accelerated fixed-point iteration taken
    before Newton (0: none; all of ``iterations`` when it converged by itself)."""
    run: object = None
    """Shooting with ``record``: the period's record from the returned state."""


FLOOR = 10.0
"""Harmonic-balance Newton accepts a residual up to FLOOR x its tolerance when no step
can lower it any more (its rounding floor)."""


def solve_hb(hb: HarmonicBalance, x0, speed=1.0, tol=1e-10, max_iter=25) -> tuple:
    """Damped Newton on the HB equations from ``x0``; returns (x, NewtonInfo).

    Converged when the largest residual harmonic is below ``tol`` times the largest
    sampled acceleration, or below FLOOR times that when no step lowers it further (the
    rounding floor).  A step that does not lower the residual is halved (up to 12
    times)."""
    x = np.array(x0, dtype=float)
    R, scale = hb.residual(x, speed, linearise=True)
    err = float(np.max(np.abs(R))) / scale
    hist = [err]
    it = 0
    floor = False
    while err > tol and it < max_iter:
        it += 1
        dx = hb.solve_linear(-R, speed)
        alpha = 1.0
        lowered = False
        for _ in range(13):
            xt = x + alpha * dx
            Rt, st = hb.residual(xt, speed, linearise=True)
            et = float(np.max(np.abs(Rt))) / st
            lowered = bool(np.isfinite(et) and et < err * (1 - 1e-4 * alpha))
            if lowered or alpha < 1e-3:
                break
            alpha *= 0.5
        if not lowered and err <= FLOOR * tol:
            # no step lowers a residual this close to the tolerance: it is the rounding
            # floor of the sampled equations (a difference of large element forces)
            floor = True
            break
        if not np.isfinite(et):
            break
        x, R, scale, err = xt, Rt, st, et
        hist.append(err)
        log.debug("HB Newton %d: residual %.3e (step %.3g)", it, err, alpha)
    return x, NewtonInfo(err <= tol or floor, it, err, hist)


# ------------------------------------------------------------------------ rigid subspace
def rigid_subspace(p: PeriodicProblem) -> np.ndarray:
    """Orthonormal (2n, k) basis of the invariant rigid subspace R."""
    n = p.n
    cols = []
    for r in range(p.nr):
        z = np.zeros(2 * n)
        z[:n] = p.rigid[:, r]
        cols.append(z)
        if not p.rigid_damped[r]:
            z = np.zeros(2 * n)
            z[n:] = p.rigid[:, r]
            cols.append(z)
    if not cols:
        return np.zeros((2 * n, 0))
    q, _ = np.linalg.qr(np.array(cols).T)
    return q


def complement(p: PeriodicProblem) -> np.ndarray:
    """Orthonormal (2n, 2n - k) basis of the complement of R, block by block: its columns
    are pure displacements (orthogonal to the rigid modes) or pure velocities (orthogonal
    to the undamped ones), as R's are.  (A complement of R in the whole state space, from
    a QR of [R, I], mixed the two in some columns; the continuation's metric, which weights
    displacements and velocities apart, then over-weighted a velocity by omega T.)"""
    n = p.n
    if p.nr == 0:
        return np.eye(2 * n)

    def perp(B):
        if B.shape[1] == 0:
            return np.eye(n)
        u, sv, _ = np.linalg.svd(B, full_matrices=True)
        rank = int(np.sum(sv > 1e-10 * sv[0]))
        return u[:, rank:]

    cd = perp(p.rigid)
    cv = perp(p.rigid[:, ~np.asarray(p.rigid_damped, bool)])
    Q = np.zeros((2 * n, cd.shape[1] + cv.shape[1]))
    Q[:n, :cd.shape[1]] = cd
    Q[n:, cd.shape[1]:] = cv
    return Q


def floquet_monodromy(p: PeriodicProblem, Phi) -> np.ndarray:
    """Floquet multipliers of the monodromy ``Phi`` without the rigid-body ones, sorted
    by decreasing modulus."""
    Q = complement(p)
    mu = np.linalg.eigvals(Q.T @ Phi @ Q)
    return mu[np.argsort(-np.abs(mu))]


def floquet_hill(hb: HarmonicBalance, x, speed=1.0, harmonics: int | None = None
                 ) -> np.ndarray:
    """Floquet multipliers of the HB solution ``x`` by Hill's method with ``harmonics``
    (default min(H, 10)) Hill harmonics; rigid-body multipliers left out."""
    p = hb.p
    Hh = min(hb.H, 10) if harmonics is None else int(harmonics)
    q, v, _ = hb.waveforms(x, speed)
    _, lam = hb.split(x)
    t = hb.times(speed)
    lin = p.linearise(t, hb._states(q, v, lam), speed)
    Q = complement(p)
    m = Q.shape[1]
    A = np.empty((hb.N, m, m))
    for j in range(hb.N):
        A[j] = Q.T @ p.state_matrix(lin, j, speed) @ Q
    Ahat = np.fft.fft(A, axis=0) / hb.N  # Ahat[k] multiplies exp(i k w t)
    w = hb.omega(speed)
    ks = np.arange(-Hh, Hh + 1)
    big = np.zeros(((2 * Hh + 1) * m, (2 * Hh + 1) * m), dtype=complex)
    for a, k in enumerate(ks):
        for b, l in enumerate(ks):
            d = k - l
            if abs(d) >= hb.N // 2:
                continue
            blk = Ahat[d % hb.N].copy()
            if k == l:
                blk -= 1j * k * w * np.eye(m)
            big[a * m:(a + 1) * m, b * m:(b + 1) * m] = blk
    ev, vec = np.linalg.eig(big)
    wgt = np.abs(vec.reshape(2 * Hh + 1, m, -1)) ** 2
    wgt = wgt.sum(axis=1)
    centre = (ks[:, None] * wgt).sum(axis=0) / wgt.sum(axis=0)
    period = 1.0 / (p.frequency * speed)
    picked: list[complex] = []
    # the most centred first; a copy shifted by i k omega (same multiplier) is skipped,
    # which matters where exponents sit on the strip's edge (real negative multipliers)
    for i in np.argsort(np.abs(centre)):
        mu_i = np.exp(ev[i] * period)
        if any(abs(mu_i - m0) <= 1e-7 * max(1.0, abs(m0)) for m0 in picked):
            continue
        picked.append(mu_i)
        if len(picked) == m:
            break
    mu = np.array(picked)
    return mu[np.argsort(-np.abs(mu))]


# ------------------------------------------------------------------------ shooting
def _deformation_scale(p: PeriodicProblem, y):
    V = p.structure.projection_matrix()
    n = p.n
    return V, max(float(np.max(np.abs(V @ y[:n]), initial=0.0)), 1e-300)


KRYLOV_WORK = 200_000
"""Above this many RK4 column-steps per monodromy (steps per period x columns), shooting
solves its Newton steps matrix-free (:func:`solve_shooting`)."""
KRYLOV_RTOL = 1e-4
"""A matrix-free Newton step is accepted when GMRES has reached its forcing term or this
relative residual, whichever is looser (an inexact Newton step: the defect still has to
fall below the shooting tolerance); otherwise the step is taken with the monodromy."""


PICARD_RHO = 0.1
"""Newton-Picard steps are taken only where no mode of the linearised model (maximum
stiffness, gaps closed) keeps more than this of itself over the period (|exp(lambda T)|):
the step takes the monodromy as 0 outside the kept products' span, which holds only if
every mode there has decayed.  Liu et al. 2021's full period qualifies (largest 0.088,
the step takes the defect 7e-8 -> 7e-10); Jin et al. 2019's (0.47) and Ji & Li's (0.88)
do not (there a Newton-Picard step gained 2.6x and lost 3.4x)."""


ANDERSON_MAPS = 20
"""Period maps the Anderson-accelerated iteration of matrix-free shooting may take (its
memory: every map so far) before Newton-Krylov goes on from its best state."""
ANDERSON_STALL = 8
"""... or after this many maps without a tenfold fall of its smallest defect."""


def matrix_free(p: PeriodicProblem, steps: int) -> bool:
    """Whether shooting solves for the periodic state without forming the monodromy:
    when the monodromy (2n variational columns) would cost more than ``KRYLOV_WORK``
    column-steps."""
    return steps * 2 * p.n > KRYLOV_WORK


def _slow_modes(p: PeriodicProblem, T: float) -> int:
    """Eigenvalues of the linearised model (the rigid modes' left out) whose multiplier
    over the period T exceeds PICARD_RHO (a pair counts twice)."""
    from torquesplit.solve.stability import system_eigenvalues

    lam = system_eigenvalues(p.structure)
    # a rigid mode's position and velocity: the two eigenvalues nearest 0 per rigid mode
    # (0 and, with a load characteristic, -c/J), outside the complement Newton works in
    lam = lam[np.argsort(np.abs(lam))][2 * p.nr:]
    return int(np.sum(np.exp(lam.real * T) > PICARD_RHO))


def solve_shooting(p: PeriodicProblem, y0, steps: int, speed=1.0, tol=1e-9, max_iter=25,
                   krylov: bool | None = None, monodromy: bool = True,
                   newton_picard: bool = True, anderson: bool | None = None, record=None,
                   say=None):
    """Newton on the period map: returns (y0, monodromy or None, NewtonInfo).

    Converged when one period returns to the start within ``tol`` of the largest
    element deformation (velocities: divided by omega).

    ``anderson`` (default: where matrix-free, ``krylov``): first the fixed-point iteration
    y -> y(T) from ``y0``, Anderson-accelerated with every map so far (Walker & Ni 2011,
    SIAM J. Numer. Anal. 49(4), eqs. 2.1-2.2; the least squares in the norm of the
    convergence test): on a linear map its iterates are GMRES's (their Theorem 2.2), so
    each period map is a defect and a product at once, where Newton-Krylov pays one map
    for each.  On Liu et al. 2021's full period it converges in 5 maps from the static
    state, where settling, Newton-Krylov and a map for the waveforms took 8.  Where it
    has not converged in
    ``ANDERSON_MAPS`` maps, or its smallest defect has not fallen tenfold in
    ``ANDERSON_STALL``, (or a map from an extrapolated state diverges), Newton goes on
    from its best state.

    ``record(y)``, if given, is called instead of the plain period map for every defect
    (not for the products): it returns the period's :class:`~.problem.Run` from ``y``,
    and that of the returned state is ``NewtonInfo.run`` (the solution's waveforms, with
    no further period map).

    ``krylov``: solve each Newton step (Phi - I) dy = -d by GMRES on the complement of
    the rigid subspace with the products Phi v as finite differences of the period map
    (Jacobian-free Newton-Krylov; Kelley, Solving Nonlinear Equations with Newton's
    Method, SIAM 2003, sections 3.2 and 3.2.1), one state integration each, instead of
    forming the monodromy (2n variational columns).  On a long period most multipliers are
    tiny (every mode decays many times over it), so GMRES needs a few products; where it
    has not converged after about the work of one monodromy, the step is taken with the
    full monodromy, and so are the following.  Default: on when the monodromy would cost
    more than ``KRYLOV_WORK`` column-steps.  The monodromy is returned only when it was
    formed at the returned state (None otherwise); with ``monodromy=False`` it is formed
    only for the Newton steps that need it (never at the returned state).

    ``newton_picard``: after a matrix-free step, the next one is taken on the products it
    made, without new ones (Newton in their span, the rest of the monodromy taken as 0:
    Lust, Roose, Spence & Champneys 1998, SIAM J. Sci. Comput. 19(4)) where every mode of
    the linearised model decays over the period (:data:`PICARD_RHO`); where the defect
    does not then fall tenfold, GMRES from there on.  ``say(text)``, if given, hears of
    each Newton step (its defect and the products so far)."""
    n = p.n
    T = 1.0 / (p.frequency * speed)
    w = 2 * math.pi / T
    R = rigid_subspace(p)
    Pr = np.eye(2 * n) - R @ R.T  # orthogonal projector on the complement
    Q = complement(p)
    m = Q.shape[1]
    if krylov is None:
        krylov = matrix_free(p, steps)
    if anderson is None:
        anderson = krylov
    cap = min(m, max(4, (2 + 2 * n) // 3))  # products that cost about one monodromy
    y = np.array(y0, dtype=float)
    y = Pr @ y
    V, _ = _deformation_scale(p, y)
    hist = []
    Phi = None
    it = 0
    err = math.inf
    best = (math.inf, y)  # the Newton iterate of smallest defect
    products = [0]
    runs = [None]  # the record of the last defect map

    def period_map(y):
        # RK4 through the tables' corners, as the integrators step (the variational
        # equations take the same sub-steps: the monodromy is this map's derivative)
        return p.integrate(y, 0.0, T, steps, every=steps, speed=speed, max_rows=1)[3]

    def defect_map(y):
        if record is None:
            return period_map(y)
        runs[0] = record(y)
        return runs[0].y_end

    def measure(y, yT):
        """The projected defect and its size relative to the largest deformation."""
        d = Pr @ (yT - y)
        scale = max(float(np.max(np.abs(V @ y[:n]), initial=0.0)),
                    float(np.max(np.abs(V @ yT[:n]), initial=0.0)), 1e-300)
        return d, max(float(np.max(np.abs(V @ d[:n]), initial=0.0)),
                      float(np.max(np.abs(V @ d[n:]), initial=0.0)) / w) / scale

    known = None
    aa_maps = 0
    if anderson:
        y, known, err, hist, aa_maps = _anderson(
            defect_map, lambda y: Pr @ y, measure,
            lambda d: np.concatenate([V @ d[:n], V @ d[n:] / w]), y, tol, say)
        if err <= tol:
            return y, None, NewtonInfo(True, aa_maps, err, hist, 0, aa_maps, runs[0])
    # products of the last GMRES solve, (z, (Phi - I) z) in complement coordinates: the
    # next Newton step is taken on them first (see the Newton-Picard step below)
    kept_z: list[np.ndarray] = []
    kept_az: list[np.ndarray] = []
    recycle = newton_picard and krylov
    recycled = False
    n_slow = _slow_modes(p, T) if recycle else 0

    while True:
        # (the map of the Anderson iteration's best state is known)
        yT = defect_map(y) if known is None else known
        known = None
        Phi = None
        if not krylov and monodromy:
            Phi = p.integrate_variational(y, 0.0, T, steps, speed)[1]
        d, err = measure(y, yT)
        if recycled and err > 0.1 * hist[-1]:
            recycle = False  # the Newton-Picard step did not pay: GMRES from here on
        recycled = False
        hist.append(err)
        if err < best[0]:
            best = (err, y)
        log.debug("shooting Newton %d: defect %.3e", it, err)
        if say is not None:
            say(f"shooting, Newton step {it}: defect {err:.1e} (tolerance {tol:.0e})"
                + (f", {products[0]} products" if products[0] else ""))
        if err <= tol or it >= max_iter:
            break
        it += 1
        dy = None
        if krylov:
            # forcing term: aim at a tenth of the tolerance in one step (Kelley 2003, eq.
            # 3.6 ff.), no tighter (a defect just above the tolerance needs little)
            rtol = min(0.5, max(0.1 * tol / err, 1e-10))
            size = float(np.linalg.norm(y))
            rhs = -(Q.T @ d)

            def product(z, y=y, yT=yT, size=size):
                products[0] += 1
                # Kelley 2003, eq. 3.8 with the map's relative error: rounding over the
                # steps of one period, at worst eps per step (sqrt(eps) alone leaves
                # the differences in the rounding noise of a long period)
                step = math.sqrt(np.finfo(float).eps * steps) * max(size, 1e-30) / max(
                    float(np.linalg.norm(z)), 1e-300)
                az = Q.T @ (period_map(y + step * (Q @ z)) - yT) / step - z
                kept_z.append(np.array(z))
                kept_az.append(az)
                return az

            if recycle and kept_z and n_slow == 0:
                # Newton-Picard (Lust et al. 1998) on the last solve's products, no new
                # ones: Newton in their span, where the slow multipliers are, and outside
                # it Phi taken as 0 (every other mode has decayed over the period), i.e.
                # dz = Z c - r with c the least-squares fit of the right-hand side by the
                # products and r what it leaves.  Not checked by a product: at a defect
                # near the tolerance a difference product is mostly rounding; the next
                # defect (the exact map) says whether it paid
                Z, AZ = np.array(kept_z).T, np.array(kept_az).T
                c = np.linalg.lstsq(AZ, rhs, rcond=None)[0]
                dy = Q @ (Z @ c - (rhs - AZ @ c))
                recycled = True
                log.debug("shooting Newton %d: Newton-Picard step on %d kept products", it,
                          len(kept_z))
            else:
                kept_z.clear()
                kept_az.clear()
                dz, res = gmres(product, rhs, lambda v: v, rtol, cap)
                if res <= max(rtol, KRYLOV_RTOL):
                    dy = Q @ dz
                else:
                    log.info("Newton-Krylov shooting: GMRES at %.1e after %d products; the "
                             "full monodromy from here on", res, cap)
                    krylov = False
                    _, Phi = p.integrate_variational(y, 0.0, T, steps, speed)
        if dy is None:
            if Phi is None:
                Phi = p.integrate_variational(y, 0.0, T, steps, speed)[1]
            A = np.vstack([Pr @ (Phi - np.eye(2 * n)), R.T])
            b = -np.concatenate([d, R.T @ y])
            dy = np.linalg.lstsq(A, b, rcond=None)[0]
        y = y + dy
        if not np.all(np.isfinite(y)):
            raise SolverError("the shooting iteration diverged; start from a better guess "
                              "(the harmonic-balance solution or a converged neighbour).")
    if err > tol and not anderson and best[0] < math.inf:
        # Newton stalls where the flow is not smooth (teeth that separate: the damping
        # force jumps at an instant the variational equations do not move with, so the
        # monodromy misses a term); a stable orbit still attracts the period map itself:
        # the Anderson-accelerated fixed-point iteration from the best Newton iterate
        log.info("shooting: Newton at %.1e after %d steps; Anderson-accelerated period "
                 "maps from its best iterate", err, it)
        y2, g2, err2, hist2, maps2 = _anderson(
            defect_map, lambda y: Pr @ y, measure,
            lambda d: np.concatenate([V @ d[:n], V @ d[n:] / w]), best[1], tol, say)
        hist += hist2
        aa_maps += maps2
        if err2 < err:
            y, err, Phi = y2, err2, None
            if g2 is None and record is not None:  # the waveforms of the state kept
                defect_map(y)
            if monodromy and not krylov:  # (its stability: the caller's multipliers)
                Phi = p.integrate_variational(y, 0.0, T, steps, speed)[1]
        elif record is not None:  # the last map was Anderson's: record Newton's state
            defect_map(y)
    return y, (None if krylov else Phi), NewtonInfo(err <= tol, aa_maps + it, err, hist,
                                                    products[0], aa_maps, runs[0])


def _anderson(G, project, measure, weigh, y, tol, say):
    """Anderson-accelerated fixed-point iteration y -> project(G(y)) from ``y`` (Walker &
    Ni 2011, "Anderson acceleration for fixed-point iterations", SIAM J. Numer. Anal.
    49(4), eqs. 2.1-2.2: memory of every map but the first, no damping): the next state is
    g_k - dG gamma with gamma the least-squares fit of the residual f_k = g_k - y_k by
    the differences dF of the residuals (in the norm ``weigh``; columns scaled to unit
    length, which the fit does not depend on), dG those of the maps.  ``measure(y, g)``
    gives (defect, its relative size).  Returns the best state, its map (None where a
    later map was taken: ``G`` may keep only the last map's record), its defect size, the
    defect history and the maps taken."""
    fs: list[np.ndarray] = []
    gs: list[np.ndarray] = []
    hist: list[float] = []
    best = (math.inf, y, None, None)
    gained_at, gained = 0, math.inf  # map and defect of the last tenfold fall
    for k in range(ANDERSON_MAPS):
        try:
            g = project(G(y))
        except SolverError:  # an extrapolated state diverged: Newton from the best
            log.info("Anderson shooting: a map diverged; Newton from the best state")
            break
        _, err = measure(y, g)
        hist.append(err)
        log.debug("Anderson shooting %d: defect %.3e", k, err)
        if say is not None:
            say(f"shooting, Anderson step {k}: defect {err:.1e} (tolerance {tol:.0e})")
        if err < best[0]:
            best = (err, y, g, k)
        if err <= 0.1 * gained:
            gained_at, gained = k, err
        if err <= tol or k - gained_at >= ANDERSON_STALL:
            break
        if k > 0:  # the first map only settles: from the guess (often the static state,
            fs.append(weigh(g - y))  # with none of the motion) to near the orbit, it
            gs.append(g)  # spans a jump the secants of the others should not fit
        if len(fs) < 2:
            y = g
            continue
        dF = np.diff(np.array(fs), axis=0).T
        dG = np.diff(np.array(gs), axis=0).T
        size = np.linalg.norm(dF, axis=0)
        size[size == 0.0] = 1.0
        gamma = np.linalg.lstsq(dF / size, fs[-1], rcond=None)[0] / size
        y = g - dG @ gamma
        if not np.all(np.isfinite(y)):
            break
    err, y, g, k = best
    if k != len(hist) - 1:  # a later map overwrote the best one's record: map it again
        g = None
    return y, g, err, hist, len(hist)
