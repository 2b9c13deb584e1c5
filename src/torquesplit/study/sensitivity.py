"""Global sensitivity: Morris elementary effects and Sobol indices (scipy.stats.qmc).

Written here on numpy/scipy rather than taken from SALib: the two methods are short, the
study layer needs the sampling to be a pure function of (seed, case index) so that a
case does not depend on the number of workers, and SALib would add pandas and its own
multiprocessing layer as dependencies for about 150 lines of arithmetic.

Factors are sampled in the unit cube and mapped onto their ranges (linear or log).

Morris (Morris 1991; mu* of Campolongo et al. 2007)
    r trajectories of k + 1 points on a p-level grid (p even), step
    Delta = p / (2 (p - 1)); each trajectory changes one factor at a time, in a random
    order and direction.  Elementary effect of factor i: EE_i = (y(x + Delta e_i) - y(x))
    / (+/-Delta), an output change per full range of the factor.  ``mu_star`` = mean |EE|
    (importance), ``mu`` = mean EE (sign), ``sigma`` = standard deviation of EE
    (interaction or non-linearity).  Cost r (k + 1) cases.

Sobol (Saltelli et al. 2010, Table 2: first order (b), total Jansen 1999 (f))
    Base matrices A, B (N x k) from a scrambled Sobol sequence in 2k dimensions; AB_i is
    A with column i from B.  The outputs are first centred on the mean m of y(A), y(B)
    (as SALib does; without it S1 of an output near 1, such as a load-sharing coefficient,
    is a small difference of large products and lands far outside [0, 1]); with
    f = y - m and V = Var[y(A), y(B)]:
    S1_i = mean(f(B) (f(AB_i) - f(A))) / V,  ST_i = mean((f(A) - f(AB_i))^2) / (2 V),
    so both are unchanged by adding a constant to the output.
    Cost N (k + 2) cases, ordered by base row (A_j, B_j, AB_1j ... AB_kj) so that every
    finished prefix of rows is a complete smaller estimate.  ``*_conf``: half-width of the
    95 % bootstrap interval over base rows.

Failed cases (NaN outputs) drop their trajectory or base row from the estimate.
"""

from __future__ import annotations

import numpy as np

from .design import Design, uniform_points
from .errors import StudyError

N_BOOTSTRAP = 200


def sensitivity_design(spec, factors) -> Design:
    """Sampling plan of a ``[sensitivity]`` table; ``factors``: (Parameter, low, high,
    spacing) with SI bounds."""
    k = len(factors)
    rng_seed = spec.seed
    if spec.method == "morris":
        r = spec.trajectories or 10
        p = spec.levels or 4
        if p % 2:
            raise StudyError("sensitivity.levels", f"is {p}; Morris' step Delta = p / (2 (p - 1)) "
                                                   f"needs an even number of levels, e.g. 4")
        unit, steps = morris_trajectories(k, r, p, rng_seed)
        extra = {"method": "morris", "trajectories": r, "levels": p, "steps": steps}
    else:
        n = spec.samples or 64
        unit = saltelli_points(k, n, rng_seed)
        extra = {"method": "sobol", "samples": n}
    values = np.column_stack([_to_range(unit[:, j], lo, hi, sp)
                              for j, (_, lo, hi, sp) in enumerate(factors)])
    extra["ranges"] = [(lo, hi, sp) for _, lo, hi, sp in factors]
    return Design("sensitivity", [f[0] for f in factors], values, extra=extra)


def _to_range(u, low, high, spacing):
    if spacing == "log":
        return low * (high / low) ** u
    return low + u * (high - low)


# ============================================================================ Morris
def morris_trajectories(k: int, r: int, levels: int, seed: int):
    """Unit-cube points of ``r`` Morris trajectories ((r (k + 1), k)) and, per
    trajectory and step, (factor, signed Delta)."""
    rng = np.random.default_rng(seed)
    delta = levels / (2.0 * (levels - 1))
    grid = np.arange(levels // 2) / (levels - 1)  # starts from which +Delta stays in [0, 1]
    points = np.empty((r * (k + 1), k))
    steps = np.empty((r, k, 2))
    for t in range(r):
        x = rng.choice(grid, size=k)
        direction = rng.choice([-1.0, 1.0], size=k)
        x = np.where(direction < 0, x + delta, x)
        order = rng.permutation(k)
        row = t * (k + 1)
        points[row] = x
        for j, i in enumerate(order):
            x = x.copy()
            x[i] += direction[i] * delta
            points[row + j + 1] = x
            steps[t, j] = (i, direction[i] * delta)
    return points, steps


def morris_indices(design: Design, y: np.ndarray) -> dict[str, np.ndarray]:
    """mu, mu_star, sigma (and mu_star_conf) of each factor from the outputs ``y`` of
    every case (NaN for failed or missing cases)."""
    k = len(design.parameters)
    steps = design.extra["steps"]
    r = steps.shape[0]
    y = np.asarray(y, dtype=float)[: r * (k + 1)].reshape(r, k + 1)
    ok = np.all(np.isfinite(y), axis=1)
    ee = np.full((r, k), np.nan)
    for t in np.flatnonzero(ok):
        for j in range(k):
            i, d = int(steps[t, j, 0]), steps[t, j, 1]
            ee[t, i] = (y[t, j + 1] - y[t, j]) / d
    ee = ee[ok]
    n = ee.shape[0]
    nan = np.full(k, np.nan)
    if n == 0:
        return {"mu": nan, "mu_star": nan, "sigma": nan, "mu_star_conf": nan,
                "trajectories_used": np.array(0)}
    rng = np.random.default_rng(0)
    boot = np.array([np.abs(ee[rng.integers(0, n, n)]).mean(axis=0)
                     for _ in range(N_BOOTSTRAP)]) if n > 1 else np.full((1, k), np.nan)
    return {"mu": ee.mean(axis=0), "mu_star": np.abs(ee).mean(axis=0),
            "sigma": ee.std(axis=0, ddof=1) if n > 1 else nan,
            "mu_star_conf": 1.96 * boot.std(axis=0), "trajectories_used": np.array(n)}


# ============================================================================ Sobol
def saltelli_points(k: int, n: int, seed: int) -> np.ndarray:
    """Unit-cube points (n (k + 2), k): for each base row j, A_j, B_j, AB_1j ... AB_kj."""
    base = uniform_points("sobol", n, 2 * k, seed)
    a, b = base[:, :k], base[:, k:]
    out = np.empty((n, k + 2, k))
    out[:, 0] = a
    out[:, 1] = b
    for i in range(k):
        ab = a.copy()
        ab[:, i] = b[:, i]
        out[:, 2 + i] = ab
    return out.reshape(n * (k + 2), k)


def sobol_indices(design: Design, y: np.ndarray) -> dict[str, np.ndarray]:
    """First-order and total Sobol indices (and bootstrap half-widths) of each factor."""
    k = len(design.parameters)
    n = design.extra["samples"]
    y = np.asarray(y, dtype=float)[: n * (k + 2)].reshape(n, k + 2)
    y = y[np.all(np.isfinite(y), axis=1)]
    nan = np.full(k, np.nan)
    if y.shape[0] < 2:
        return {"S1": nan, "ST": nan, "S1_conf": nan, "ST_conf": nan,
                "samples_used": np.array(y.shape[0])}

    def estimate(rows):
        centre = np.mean(rows[:, :2])
        fa, fb, fab = rows[:, 0] - centre, rows[:, 1] - centre, rows[:, 2:] - centre
        v = np.var(np.concatenate([fa, fb]))
        if not v > 0:
            return nan, nan
        s1 = np.mean(fb[:, None] * (fab - fa[:, None]), axis=0) / v
        st = 0.5 * np.mean((fa[:, None] - fab) ** 2, axis=0) / v
        return s1, st

    s1, st = estimate(y)
    rng = np.random.default_rng(0)
    m = y.shape[0]
    boot = [estimate(y[rng.integers(0, m, m)]) for _ in range(N_BOOTSTRAP)]
    b1 = np.array([b[0] for b in boot])
    bt = np.array([b[1] for b in boot])
    return {"S1": s1, "ST": st, "S1_conf": 1.96 * np.nanstd(b1, axis=0),
            "ST_conf": 1.96 * np.nanstd(bt, axis=0), "samples_used": np.array(m)}


def indices(design: Design, y: np.ndarray) -> dict[str, np.ndarray]:
    """The design's indices: Morris or Sobol."""
    if design.extra["method"] == "morris":
        return morris_indices(design, y)
    return sobol_indices(design, y)


def ranking_key(design: Design) -> str:
    """The index that ranks factors: mu_star (Morris) or ST (Sobol)."""
    return "mu_star" if design.extra["method"] == "morris" else "ST"
