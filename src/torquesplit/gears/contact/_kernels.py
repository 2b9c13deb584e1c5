"""Compiled kernels of the loaded tooth contact analysis, each with its readable twin.

Every ``@njit(cache=True)`` loop of :mod:`torquesplit.gears.contact` lives here.  Each
compiled function says which readable numpy function mirrors it; the tests run both on
the same inputs and require the same answer (``tests/gears/test_contact_kernels.py``).

==============================  =====================================  ==================
compiled                        readable twin                          what
==============================  =====================================  ==================
:func:`contact_deflection`      :func:`contact_deflection_twin`        Weber/Johnson line
                                                                       contact approach
:func:`ltca_solve`              :func:`ltca_solve_twin`                all positions: slice
                                                                       compliance, contact
                                                                       problem, Hertz loop
==============================  =====================================  ==================

Arrays over the contact grid have the shape ``(M, H, K, N)``: M mesh positions, H
helices (1, or 2 for double-helical), K tooth pairs, N slices across the face of one
helix.  All SI: N, m, Pa.  Compliances are along the flank normal.

The contact problem at one position (Conry & Seireg 1971; Dong et al. 2021 eqs. 13-16,
written as a quadratic programme)::

    minimise  1/2 p^T H p + w^T p   subject to  sum(p) = P,  p >= 0

``H`` the compliance of the points (block diagonal: one block per tooth pair), ``w``
the initial separations, ``P`` the load.  Its optimality conditions are the contact
conditions: the gap ``d = H p + w - Z`` (``Z`` the multiplier of the load equation,
the approach of the gear bodies = loaded transmission error) is zero where ``p > 0``
and non-negative where ``p = 0``.  It is solved exactly by the primal active-set
method (Nocedal & Wright, Numerical Optimization, 2nd ed. 2006, Algorithm 16.3): on the
working set A the equality-constrained problem is ``H_AA p_A = Z 1 - w_A``,
``1^T p_A = P``, solved block by block (Cholesky) as ``p_A = Z u - v`` with
``H u = 1``, ``H v = w_A`` and ``Z = (P + sum v) / sum u``.

Hertzian (Weber) contact makes ``H`` depend on the load; the diagonal is the secant
compliance of each slice's line contact at the current load and the quadratic
programme is solved again until the approach and the loads no longer change (a
fixed-point iteration; each pass is exact for its compliance, so ``sum(p) = P`` holds
to round-off at every pass).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from torquesplit._jit_cache import track_imports

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

__all__ = [
    "contact_deflection",
    "contact_deflection_twin",
    "ltca_solve",
    "ltca_solve_twin",
    "position_system",
    "STATUS",
]

#: status codes of :func:`ltca_solve` per position
STATUS = {0: "converged", 1: "active set: iteration limit", 2: "Hertz loop: iteration limit",
          3: "no contact point at this position", 4: "compliance matrix not positive definite"}

_LN_MIN = 0.5  # floor of ln(2 d / a): the formula holds for a << d (see contact_deflection)


# =============================================================================== Hertz
@njit(cache=True)
def contact_deflection(q, radius, depth1, depth2, c1, c2, nu1, nu2):
    """Normal approach of a line contact per unit length load ``q`` [m] (compiled).

    Weber's formula for the flattening of two teeth, measured to points at depths
    ``d1``, ``d2`` inside them (Weber 1949; Weber & Banaschek 1953), identical to
    Johnson, Contact Mechanics (1985), §5.6, for two cylinders::

        delta = (2 q / pi) sum_i c_i [ln(2 d_i / a) - nu_i / (2 (1 - nu_i))]
        a     = sqrt(4 q R / (pi E*)),  1/E* = c_1 + c_2,  c_i = (1 - nu_i^2) / E_i

    ``a`` is the Hertz half-width (Johnson 1985 eq. 4.43), ``R`` the reduced radius of
    curvature.  Valid for ``a << d``: each logarithm is held at ``>= 0.5`` beyond that
    (extreme overload).  Readable twin: :func:`contact_deflection_twin`.
    """
    if q <= 0.0:
        return 0.0
    e_star = 1.0 / (c1 + c2)
    a = math.sqrt(4.0 * q * radius / (math.pi * e_star))  # Johnson 1985 eq. 4.43
    l1 = max(math.log(2.0 * depth1 / a), _LN_MIN)
    l2 = max(math.log(2.0 * depth2 / a), _LN_MIN)
    # Weber & Banaschek 1953 / Johnson 1985 §5.6: approach of two elastic bodies in line contact
    return 2.0 * q / math.pi * (c1 * (l1 - nu1 / (2.0 * (1.0 - nu1)))
                                + c2 * (l2 - nu2 / (2.0 * (1.0 - nu2))))


def contact_deflection_twin(q, radius, depth1, depth2, c1, c2, nu1, nu2):
    """Readable numpy twin of :func:`contact_deflection` (vectorised)."""
    q = np.asarray(q, dtype=float)
    e_star = 1.0 / (c1 + c2)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.sqrt(4.0 * q * radius / (np.pi * e_star))
        l1 = np.maximum(np.log(2.0 * depth1 / a), _LN_MIN)
        l2 = np.maximum(np.log(2.0 * depth2 / a), _LN_MIN)
        d = 2.0 * q / np.pi * (c1 * (l1 - nu1 / (2.0 * (1.0 - nu1)))
                               + c2 * (l2 - nu2 / (2.0 * (1.0 - nu2))))
    return np.where(q > 0, d, 0.0)


# ====================================================================== small algebra
@njit(cache=True)
def _plate_compliance(kb, g, frac, db, coupling, out):
    """Compliance matrix (N x N) of one tooth as a Pasternak plate strip (compiled).

    Stiffness: ``K = diag(kb_j db) + (1/db) L_G`` with ``L_G`` the Laplacian of the
    shear layer (free ends, ``G`` averaged between neighbours); ``out = K^-1``.
    Without coupling the slices are independent: ``out = diag(1 / (kb frac db))``
    (the loaded part of each slice; 0 where frac = 0).
    """
    n = kb.shape[0]
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
    if not coupling or n == 1:
        for i in range(n):
            if frac[i] > 0.0:
                out[i, i] = 1.0 / (kb[i] * frac[i] * db)
        return
    # tridiagonal K: diagonal a, off-diagonal c (symmetric)
    a = np.empty(n)
    c = np.empty(n - 1)
    for i in range(n):
        a[i] = kb[i] * db
    for i in range(n - 1):
        gc = 0.5 * (g[i] + g[i + 1]) / db
        c[i] = -gc
        a[i] += gc
        a[i + 1] += gc
    # inverse column by column with the Thomas algorithm (K is SPD, diagonally dominant)
    cp = np.empty(n)
    dp = np.empty(n)
    for col in range(n):
        # forward sweep
        for i in range(n):
            rhs = 1.0 if i == col else 0.0
            if i == 0:
                cp[0] = c[0] / a[0] if n > 1 else 0.0
                dp[0] = rhs / a[0]
            else:
                den = a[i] - c[i - 1] * cp[i - 1]
                cp[i] = c[i] / den if i < n - 1 else 0.0
                dp[i] = (rhs - c[i - 1] * dp[i - 1]) / den
        out[n - 1, col] = dp[n - 1]
        for i in range(n - 2, -1, -1):
            out[i, col] = dp[i] - cp[i] * out[i + 1, col]


@njit(cache=True)
def _cholesky_solve2(a, n, b1, b2, x1, x2, work):
    """Solve ``a[:n,:n] x = b`` for two right-hand sides by Cholesky (a is overwritten
    by its factor).  Returns False if ``a`` is not positive definite."""
    for j in range(n):
        s = a[j, j]
        for k in range(j):
            s -= a[j, k] * a[j, k]
        if s <= 0.0:
            return False
        ljj = math.sqrt(s)
        a[j, j] = ljj
        for i in range(j + 1, n):
            s2 = a[i, j]
            for k in range(j):
                s2 -= a[i, k] * a[j, k]
            a[i, j] = s2 / ljj
    for rhs in range(2):
        b = b1 if rhs == 0 else b2
        x = x1 if rhs == 0 else x2
        for i in range(n):
            s = b[i]
            for k in range(i):
                s -= a[i, k] * work[k]
            work[i] = s / a[i, i]
        for i in range(n - 1, -1, -1):
            s = work[i]
            for k in range(i + 1, n):
                s -= a[k, i] * x[k]
            x[i] = s / a[i, i]
    return True


# =============================================================================== LTCA
@njit(cache=True)
def _hertz_secant(p, length, radius, d1, d2, c1, c2, nu1, nu2, model, lin):
    """Secant (model 1) compliance of a slice's line contact [m/N] at load ``p`` [N]."""
    if model == 0:
        return lin / length
    q = p / length
    return contact_deflection(q, radius, d1, d2, c1, c2, nu1, nu2) / p


@njit(cache=True)
def _block_solve(b, bptr, cptr, cflat, hs, w, act, amat, rhs1, rhs2, x1, x2, work):
    """Cholesky solve of block b on its working set: fills x1 = u, x2 = v (compressed)
    and returns the number of active points (or -1 if not positive definite)."""
    i0 = bptr[b]
    nbk = bptr[b + 1] - i0
    na = 0
    for i in range(nbk):
        if act[i0 + i]:
            nb2 = 0
            for j in range(nbk):
                if act[i0 + j]:
                    amat[na, nb2] = cflat[cptr[b] + i * nbk + j]
                    nb2 += 1
            amat[na, na] += hs[i0 + i]
            rhs1[na] = 1.0
            rhs2[na] = w[i0 + i]
            na += 1
    if na == 0:
        return 0
    if not _cholesky_solve2(amat, na, rhs1, rhs2, x1, x2, work):
        return -1
    return na


@njit(cache=True)
def _solve_working_set(nb, bptr, cptr, cflat, hs, w, act, P, amat, rhs1, rhs2, x1, x2, work,
                       u_all, v_all, p_hat):
    """p_hat = Z u - v on the working set (0 elsewhere); returns (Z, ok)."""
    su = 0.0
    sv = 0.0
    for b in range(nb):
        na = _block_solve(b, bptr, cptr, cflat, hs, w, act, amat, rhs1, rhs2, x1, x2, work)
        if na < 0:
            return 0.0, False
        i0 = bptr[b]
        m = 0
        for i in range(bptr[b + 1] - i0):
            if act[i0 + i]:
                u_all[i0 + i] = x1[m]
                v_all[i0 + i] = x2[m]
                su += x1[m]
                sv += x2[m]
                m += 1
    if su <= 0.0:
        return 0.0, False
    Z = (P + sv) / su
    n = bptr[nb]
    for i in range(n):
        p_hat[i] = Z * u_all[i] - v_all[i] if act[i] else 0.0
    return Z, True


@njit(cache=True)
def _gaps(nb, bptr, cptr, cflat, hs, w, p, Z, d):
    """Gap d = H p + w - Z at every point (H block diagonal)."""
    for b in range(nb):
        i0 = bptr[b]
        nbk = bptr[b + 1] - i0
        for i in range(nbk):
            s = hs[i0 + i] * p[i0 + i]
            for j in range(nbk):
                s += cflat[cptr[b] + i * nbk + j] * p[i0 + j]
            d[i0 + i] = s + w[i0 + i] - Z


@njit(cache=True)
def _active_set(nb, bptr, cptr, cflat, hs, w, act, p, P, tol_d, maxit, amat, rhs1, rhs2, x1, x2,
                work, u_all, v_all, p_hat, d):
    """Primal active-set method (Nocedal & Wright 2006, Algorithm 16.3) from a feasible
    ``p`` with working set ``act``.  Returns (Z, iterations, status) with status 0
    (solved), 1 (iteration limit) or 4 (not positive definite)."""
    n = bptr[nb]
    Z = 0.0
    for it in range(maxit):
        Z, ok = _solve_working_set(nb, bptr, cptr, cflat, hs, w, act, P, amat, rhs1, rhs2,
                                   x1, x2, work, u_all, v_all, p_hat)
        if not ok:
            return Z, it, 4
        # step towards p_hat, blocked by the first load that would turn negative
        alpha = 1.0
        block = -1
        for i in range(n):
            if act[i] and p_hat[i] < 0.0:
                den = p[i] - p_hat[i]
                r = p[i] / den if den > 0.0 else 0.0
                if r < alpha:
                    alpha = r
                    block = i
        if block < 0:
            for i in range(n):
                p[i] = p_hat[i]
            _gaps(nb, bptr, cptr, cflat, hs, w, p, Z, d)
            jmin = -1
            dmin = -tol_d
            for i in range(n):
                if not act[i] and d[i] < dmin:
                    dmin = d[i]
                    jmin = i
            if jmin < 0:
                return Z, it + 1, 0
            act[jmin] = True
        else:
            for i in range(n):
                if act[i]:
                    p[i] += alpha * (p_hat[i] - p[i])
                    if p[i] < 0.0:  # round-off
                        p[i] = 0.0
            p[block] = 0.0
            act[block] = False  # the blocking load leaves the working set
    return Z, maxit, 1


@njit(cache=True)
def ltca_solve(zone, frac, kb1, kb2, g1, g2, loc, w, radius, depth1, depth2, db, length,
               c1, c2, nu1, nu2, model, lin, coupling, P, tol, maxit):
    """Loaded tooth contact analysis at every mesh position (compiled).

    Parameters
    ----------
    zone : (M, H, K, N) bool
        Potential contact points (slice j of tooth pair k of helix h on the active path).
    frac : (M, H, K, N)
        Fraction of the slice's contact line that lies on the active path (0..1): the
        slice's local compliance and contact line are those of this part of the slice
        (and, without coupling, its bending too), so that the stiffness grows
        continuously as a contact line enters the field of action.
    kb1, kb2 : (M, H, K, N)
        Bending (plate) stiffness per unit face width of the pinion / wheel tooth at the
        slice's contact-line height, along the flank normal [N/m^2].
    g1, g2 : (M, H, K, N)
        Pasternak shear-layer parameter of each tooth [N] (coupling of neighbouring slices).
    loc : (M, H, K, N)
        Local compliance per unit face width (shear, axial, fillet of both teeth) [m^2/N].
    w : (M, H, K, N)
        Initial separation [m].
    radius, depth1, depth2 : (M, H, K, N)
        Reduced radius of curvature (normal plane) and Weber depths [m].
    db, length : float
        Slice width along the face and contact-line length of a slice [m].
    c1, c2, nu1, nu2 : float
        ``(1 - nu^2)/E`` [1/Pa] and Poisson's ratios of the two gears.
    model : int
        0: linear contact compliance ``lin`` per unit length [m^2/N]; 1: Weber.
    coupling : bool
        Couple neighbouring slices of a tooth (Pasternak strip).
    P : float
        Normal load [N].
    tol : float
        Relative tolerance of the Hertz loop (approach and loads).
    maxit : int
        Iteration limit of each loop.

    Returns
    -------
    p : (M, H, K, N) slice loads [N]; Z : (M,) approach [m]; k_tan : (M,) tangent
    stiffness [N/m]; iterations : (M,) active-set iterations; status : (M,) (see STATUS).

    Readable twin: :func:`ltca_solve_twin`.
    """
    M, H, K, N = zone.shape
    p_out = np.zeros((M, H, K, N))
    Z_out = np.zeros(M)
    kt_out = np.zeros(M)
    it_out = np.zeros(M, dtype=np.int64)
    st_out = np.zeros(M, dtype=np.int64)
    nmax = H * K * N
    # work arrays
    plate1 = np.empty((N, N))
    plate2 = np.empty((N, N))
    cflat = np.empty(H * K * N * N)
    bptr = np.empty(H * K + 1, dtype=np.int64)
    cptr = np.empty(H * K + 1, dtype=np.int64)
    idx = np.empty((nmax, 3), dtype=np.int64)
    wv = np.empty(nmax)
    hs = np.empty(nmax)
    ht = np.empty(nmax)
    rr = np.empty(nmax)
    ln = np.empty(nmax)
    dd1 = np.empty(nmax)
    dd2 = np.empty(nmax)
    act = np.zeros(nmax, dtype=np.bool_)
    p = np.zeros(nmax)
    p_old = np.zeros(nmax)
    amat = np.empty((N, N))
    rhs1 = np.empty(N)
    rhs2 = np.empty(N)
    x1 = np.empty(N)
    x2 = np.empty(N)
    work = np.empty(N)
    u_all = np.empty(nmax)
    v_all = np.empty(nmax)
    p_hat = np.empty(nmax)
    d = np.empty(nmax)
    e_star = 1.0 / (c1 + c2)
    est_prev = -1.0
    for m in range(M):
        # ---- points and compliance blocks of this position
        nb = 0
        n = 0
        bptr[0] = 0
        cptr[0] = 0
        for h in range(H):
            for k in range(K):
                cnt = 0
                for j in range(N):
                    if zone[m, h, k, j]:
                        cnt += 1
                if cnt == 0:
                    continue
                _plate_compliance(kb1[m, h, k], g1[m, h, k], frac[m, h, k], db, coupling, plate1)
                _plate_compliance(kb2[m, h, k], g2[m, h, k], frac[m, h, k], db, coupling, plate2)
                ii = 0
                for j in range(N):
                    if not zone[m, h, k, j]:
                        continue
                    jj = 0
                    for j2 in range(N):
                        if not zone[m, h, k, j2]:
                            continue
                        v = plate1[j, j2] + plate2[j, j2]
                        if j == j2:
                            v += loc[m, h, k, j] / (frac[m, h, k, j] * db)
                        cflat[cptr[nb] + ii * cnt + jj] = v
                        jj += 1
                    idx[n, 0] = h
                    idx[n, 1] = k
                    idx[n, 2] = j
                    wv[n] = w[m, h, k, j]
                    rr[n] = radius[m, h, k, j]
                    ln[n] = frac[m, h, k, j] * length
                    dd1[n] = depth1[m, h, k, j]
                    dd2[n] = depth2[m, h, k, j]
                    ii += 1
                    n += 1
                nb += 1
                bptr[nb] = n
                cptr[nb] = cptr[nb - 1] + cnt * cnt
        if n == 0:
            st_out[m] = 3
            continue
        # ---- initial secant compliance at the mean line load; feasible start
        p_ref = P / n
        diag_mean = 0.0
        for b in range(nb):
            nbk = bptr[b + 1] - bptr[b]
            for i in range(nbk):
                diag_mean += cflat[cptr[b] + i * nbk + i]
        for i in range(n):
            hs[i] = _hertz_secant(p_ref * ln[i] / length, ln[i], rr[i], dd1[i], dd2[i], c1, c2,
                                  nu1, nu2, model, lin)
            diag_mean += hs[i]
        diag_mean /= n
        wmin = wv[0]
        for i in range(n):
            wmin = min(wmin, wv[i])
        est = est_prev if est_prev > 0.0 else 3.0 * P * diag_mean / n
        cnt_a = 0
        for i in range(n):
            act[i] = wv[i] <= wmin + est
            if act[i]:
                cnt_a += 1
        for i in range(n):
            p[i] = P / cnt_a if act[i] else 0.0
        tol_d = 1e-12 * (P * diag_mean + abs(wmin) + est)
        # ---- Hertz fixed point around the exact contact solve
        Z = 0.0
        iters = 0
        status = 2
        for outer in range(maxit):
            for i in range(n):
                p_old[i] = p[i]
            Z_old = Z
            Z, it, code = _active_set(nb, bptr, cptr, cflat, hs, wv, act, p, P, tol_d, maxit,
                                      amat, rhs1, rhs2, x1, x2, work, u_all, v_all, p_hat, d)
            iters += it
            if code != 0:
                status = code
                break
            if model == 0:
                status = 0
                break
            dp = 0.0
            for i in range(n):
                dp = max(dp, abs(p[i] - p_old[i]))
            if outer > 0 and abs(Z - Z_old) <= tol * abs(Z) and dp <= tol * P:
                status = 0
                break
            for i in range(n):
                pi = p[i] if p[i] > 1e-6 * p_ref * ln[i] / length else p_ref * ln[i] / length
                hs[i] = _hertz_secant(pi, ln[i], rr[i], dd1[i], dd2[i], c1, c2, nu1, nu2,
                                      model, lin)
        # ---- tangent stiffness on the final contact set: 1^T (C + diag(h_t))^-1 1
        for i in range(n):
            if model == 1 and act[i] and p[i] > 0.0:
                ht[i] = hs[i] - 1.0 / (math.pi * e_star * ln[i])
            else:
                ht[i] = hs[i]
        kt = 0.0
        for b in range(nb):
            na = _block_solve(b, bptr, cptr, cflat, ht, wv, act, amat, rhs1, rhs2, x1, x2, work)
            for i in range(max(na, 0)):
                kt += x1[i]
        # ---- outputs
        for i in range(n):
            p_out[m, idx[i, 0], idx[i, 1], idx[i, 2]] = p[i]
        Z_out[m] = Z
        kt_out[m] = kt
        it_out[m] = iters
        st_out[m] = status
        est_prev = 1.5 * (Z - wmin) if Z > wmin else -1.0
    return p_out, Z_out, kt_out, it_out, st_out


# ====================================================================== readable twin
def _plate_compliance_twin(kb, g, frac, db, coupling):
    """Readable twin of :func:`_plate_compliance`: the Pasternak strip, inverted by numpy."""
    n = kb.size
    if not coupling or n == 1:
        with np.errstate(divide="ignore"):
            return np.diag(np.where(frac > 0, 1.0 / (kb * frac * db), 0.0))
    K = np.diag(kb * db)
    gc = 0.5 * (g[:-1] + g[1:]) / db          # shear springs between neighbouring slices
    for i, gi in enumerate(gc):
        K[i, i] += gi
        K[i + 1, i + 1] += gi
        K[i, i + 1] -= gi
        K[i + 1, i] -= gi
    return np.linalg.inv(K)


def position_system(zone, frac, kb1, kb2, g1, g2, loc, w, radius, depth1, depth2, db, length,
                    coupling, m):
    """The contact problem at position ``m`` as dense arrays (readable twin of the block
    assembly inside :func:`ltca_solve`).

    Returns ``(C, where, w, radius, depth1, depth2, line_length)``: the elastic
    compliance (n x n, without the contact term), the ``(h, k, j)`` index of each point,
    and per point the separation, contact geometry and contact-line length.
    """
    H, K = zone.shape[1], zone.shape[2]
    blocks = []
    for h in range(H):
        for k in range(K):
            js = np.flatnonzero(zone[m, h, k])
            if js.size == 0:
                continue
            fr = frac[m, h, k]
            c = (_plate_compliance_twin(kb1[m, h, k], g1[m, h, k], fr, db, coupling)
                 + _plate_compliance_twin(kb2[m, h, k], g2[m, h, k], fr, db, coupling))
            c = c[np.ix_(js, js)] + np.diag(loc[m, h, k, js] / (fr[js] * db))
            blocks.append(((h, k, js), c))
    n = sum(b[0][2].size for b in blocks)
    C = np.zeros((n, n))
    where = []
    i0 = 0
    for (h, k, js), c in blocks:
        C[i0:i0 + js.size, i0:i0 + js.size] = c
        where += [(h, k, int(j)) for j in js]
        i0 += js.size

    def pick(a):
        return np.array([a[m][t] for t in where])

    return (C, where, pick(w), pick(radius), pick(depth1), pick(depth2),
            pick(frac) * length)


def ltca_solve_twin(zone, frac, kb1, kb2, g1, g2, loc, w, radius, depth1, depth2, db, length,
                    c1, c2, nu1, nu2, model, lin, coupling, P, tol, maxit):
    """Readable twin of :func:`ltca_solve`: dense matrices, numpy solves, the same
    primal active-set method and Hertz fixed point, started from all points."""
    M = zone.shape[0]
    p_out = np.zeros(zone.shape)
    Z_out = np.zeros(M)
    kt_out = np.zeros(M)
    e_star = 1.0 / (c1 + c2)

    def secant(p, i):
        if model == 0:
            return lin / Ln[i]
        q = p / Ln[i]
        return float(contact_deflection_twin(q, R[i], D1[i], D2[i], c1, c2, nu1, nu2)) / p

    for m in range(M):
        C, where, wv, R, D1, D2, Ln = position_system(zone, frac, kb1, kb2, g1, g2, loc, w, radius,
                                                      depth1, depth2, db, length, coupling, m)
        n = len(where)
        p_ref = P / n
        hs = np.array([secant(p_ref * Ln[i] / length, i) for i in range(n)])
        act = np.ones(n, bool)
        p = np.full(n, P / n)
        Z = 0.0
        for outer in range(maxit):
            Hm = C + np.diag(hs)
            p_old, Z_old = p.copy(), Z
            for _ in range(maxit):  # Nocedal & Wright 2006, Algorithm 16.3
                A = np.flatnonzero(act)
                Haa = Hm[np.ix_(A, A)]
                u = np.linalg.solve(Haa, np.ones(A.size))
                v = np.linalg.solve(Haa, wv[A])
                Z = (P + v.sum()) / u.sum()
                p_hat = np.zeros(n)
                p_hat[A] = Z * u - v
                neg = A[p_hat[A] < 0]
                if neg.size == 0:
                    p = p_hat
                    d = Hm @ p + wv - Z
                    cand = np.flatnonzero(~act)
                    tol_d = 1e-12 * (P * np.mean(np.diag(Hm)) + abs(wv.min()))
                    if cand.size == 0 or d[cand].min() >= -tol_d:
                        break
                    act[cand[np.argmin(d[cand])]] = True
                else:
                    ratios = p[neg] / (p[neg] - p_hat[neg])
                    alpha = ratios.min()
                    blocking = neg[np.argmin(ratios)]
                    p = np.where(act, np.maximum(p + alpha * (p_hat - p), 0.0), 0.0)
                    p[blocking] = 0.0
                    act[blocking] = False
            if model == 0:
                break
            if outer > 0 and abs(Z - Z_old) <= tol * abs(Z) and np.abs(p - p_old).max() <= tol * P:
                break
            ref = p_ref * Ln / length
            hs = np.array([secant(p[i] if p[i] > 1e-6 * ref[i] else ref[i], i) for i in range(n)])
        ht = hs.copy()
        if model == 1:
            ht[act & (p > 0)] -= 1.0 / (np.pi * e_star * Ln[act & (p > 0)])
        A = np.flatnonzero(act)
        kt = np.linalg.solve((C + np.diag(ht))[np.ix_(A, A)], np.ones(A.size)).sum()
        for i, t in enumerate(where):
            p_out[m][t] = p[i]
        Z_out[m] = Z
        kt_out[m] = kt
    return p_out, Z_out, kt_out
