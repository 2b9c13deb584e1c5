"""Baselines: the same assembled equations integrated in plain Python / numpy / scipy.

* :func:`time_scipy` -- ``scipy.integrate.solve_ivp(method="RK45", rtol=1e-6)`` on
  :func:`torquesplit.solve.reference.rhs_numpy` (the readable numpy twin of the
  kernel), with the engine's own per-state absolute tolerances (``integrate``'s dopri
  default; scipy's default ``atol = 1e-6`` would be larger than the displacements).
* :func:`cached_rhs` -- the same right-hand side with the projection matrix built once
  instead of at every call (``rhs_numpy`` rebuilds it; see RESULTS.md).  It gives the
  same numbers to round-off and shows how much of the scipy ratio is that rebuild.
* :func:`time_numpy_rk4` -- :func:`torquesplit.solve.reference.rk4_numpy`, classic RK4
  with a Python call per stage, for a per-step comparison with the engine.

A run that would exceed ``budget`` wall seconds stops early; it is then reported per
simulated second over the part it did integrate.
"""

from __future__ import annotations

import time

import numpy as np


class _OutOfBudget(Exception):
    pass


def cached_rhs(structure):
    """``rhs_numpy`` with V = ``structure.projection_matrix()`` computed once."""
    from torquesplit.solve.reference import excitation_numpy

    s = structure
    n = s.n_dof
    V = s.projection_matrix()
    VT = np.ascontiguousarray(V.T)

    def rhs(t, y):
        q, v = y[:n], y[n:]
        ex = excitation_numpy(s, t)
        delta = V @ q - ex.error
        rate = V @ v - ex.error_rate
        g = ex.half_gap
        gapped = g > 0.0
        h = np.where(delta > g, delta - g, np.where(delta < -g, delta + g, 0.0))
        h = np.where(gapped, h, delta)
        contact = ~gapped | (np.abs(delta) > g)
        force = ex.stiffness * h + np.where(contact, s.damping * rate, 0.0) + ex.force
        accel = s.inv_mass * (s.external_force - s.ground_damping * v - VT @ force)
        return np.concatenate([v, accel])

    return rhs


def time_scipy(case, n_periods: float, *, cached: bool = False, rtol: float = 1e-6,
               budget: float = 60.0) -> dict:
    """solve_ivp RK45 over ``n_periods`` shortest mesh periods; simulated s per wall s."""
    from scipy.integrate import solve_ivp

    from torquesplit.solve.reference import rhs_numpy

    s = case.structure
    fun = cached_rhs(s) if cached else (lambda t, y: rhs_numpy(s, t, y))
    t_end = n_periods / case.f_max
    state = {"t": 0.0, "n": 0}
    w0 = time.perf_counter()

    def guarded(t, y):
        if time.perf_counter() - w0 > budget:
            raise _OutOfBudget
        state["n"] += 1
        state["t"] = max(state["t"], t)
        return fun(t, y)

    try:
        res = solve_ivp(guarded, (0.0, t_end), case.y0, method="RK45", rtol=rtol,
                        atol=_atol(s, case.y0, rtol))
        wall = time.perf_counter() - w0
        reached, steps, complete = float(res.t[-1]), len(res.t) - 1, res.status == 0
    except _OutOfBudget:
        wall = time.perf_counter() - w0
        reached, steps, complete = state["t"], None, False
    return {"model": case.name, "cached": cached, "t_end": t_end, "simulated": reached,
                "complete": complete, "n_rhs": state["n"], "n_steps": steps, "wall": wall,
                "rhs_us": wall / max(state["n"], 1) * 1e6,
                "sim_per_wall": reached / wall if wall > 0 else float("nan")}


def _atol(structure, y0, rtol):
    """The engine's own dopri default atol (private helper; a crude scale if it moved)."""
    try:
        from torquesplit.solve.integrate import _default_atol

        return _default_atol(structure, rtol)
    except ImportError:
        n = structure.n_dof
        scale = np.maximum(np.abs(y0[:n]).max(), 1e-12)
        return np.full(2 * n, rtol * scale)


def time_numpy_rk4(case, step: float, n_steps: int) -> dict:
    """``reference.rk4_numpy`` for ``n_steps`` steps of ``step`` seconds; us per step."""
    from torquesplit.solve.reference import rk4_numpy

    w0 = time.perf_counter()
    rk4_numpy(case.structure, case.y0, 0.0, step, n_steps)
    wall = time.perf_counter() - w0
    return {"model": case.name, "n_steps": n_steps, "wall": wall,
                "us_per_step": wall / n_steps * 1e6, "sim_per_wall": n_steps * step / wall}


def check_cached_rhs(case, seed: int = 0) -> float:
    """Largest relative difference between ``cached_rhs`` and ``rhs_numpy`` (sanity)."""
    from torquesplit.solve.reference import rhs_numpy

    rng = np.random.default_rng(seed)
    s = case.structure
    y = case.y0 * (1.0 + 0.01 * rng.standard_normal(case.y0.shape))
    y[s.n_dof:] = 1e-3 * rng.standard_normal(s.n_dof)
    t = 0.37 / case.f_max
    a, b = rhs_numpy(s, t, y), cached_rhs(s)(t, y)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(a)), 1e-300))
