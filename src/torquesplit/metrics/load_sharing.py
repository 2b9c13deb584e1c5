"""Load-sharing coefficients and dynamic load factors, by the seeds' definitions.

Meshes are grouped into *load-sharing groups*: meshes with the same ``path`` and
``stage`` labels (model file) carry parallel shares of one flow of power.  In a group
of N meshes each definition forms ``N X_i / sum_j X_j`` of some per-mesh quantity X,
so a perfect split gives 1 for every mesh and the coefficients of a group sum to N:

==================  =============================================================
definition          X and reduction
==================  =============================================================
``cycle_peak``      X = peak force of each mesh in mesh cycle k; the coefficient
                    is the largest over meshes and settled cycles
                    (seed 000 eqs. 17-19)
``instantaneous``   X = force at each instant; largest over the settled samples
                    (seed 001 eq. 18, g_i)
``engineering``     mean over settled mesh cycles of the per-cycle peak of the
                    instantaneous coefficient (seed 001, g_it: "average value of the
                    periodic peak")
``mean_force``      X = mean force over the settled window (seed 002 eq. 12, Omega)
``static_torque``   X = quasi-static force at each mesh position; largest over the
                    positions (seed 004 eqs. 14-15)
==================  =============================================================

Dynamic load factors (per mesh): ``peak`` = largest settled force / nominal static
force (ISO sense; seed 000 DLF); ``engineering`` = mean over settled cycles of the
per-cycle peak / nominal force (seed 001 eq. 19, G_it).  The nominal static force is
the equal-split tooth force of :mod:`torquesplit.model.kinematics`.

The transient is excluded by a settle criterion: per-cycle peaks are averaged over
windows of W cycles (at least the longest excitation period); the run is settled from
the earliest window after which every window's mean and largest peak stay within
``tolerance`` of the last window's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

DEFINITIONS = ("cycle_peak", "instantaneous", "engineering", "mean_force", "static_torque")


@dataclass(frozen=True)
class Settling:
    """Where the transient ends, per tracked mesh."""

    start_time: float
    """Earliest time from which every mesh is settled [s]."""
    settled: bool
    """False if some mesh never settled (then the last half of the run is used)."""
    first_cycle: dict[str, int]
    """Mesh -> first settled cycle index."""


@dataclass(frozen=True)
class LoadSharing:
    """Coefficients of one definition: per mesh, per group and for the system."""

    definition: str
    per_mesh: dict[str, float]
    per_group: dict[str, float]
    system: float
    groups: dict[str, list[str]]
    per_cycle: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    """Mesh -> coefficient in each settled cycle (cycle-based definitions)."""


def group_meshes(mesh_meta: dict[str, dict]) -> dict[str, list[str]]:
    """Load-sharing groups keyed ``"path/stage"`` (or ``"stage"`` without a path)."""
    groups: dict[str, list[str]] = {}
    for name, meta in mesh_meta.items():
        key = f"{meta['path']}/{meta['stage']}" if meta.get("path") else str(meta["stage"])
        groups.setdefault(key, []).append(name)
    return groups


def settle(cycle_max: np.ndarray, cycle_start: np.ndarray, names, window=20,
           tolerance: float = 0.01) -> Settling:
    """Find the first settled cycle of each mesh from its per-cycle peaks.

    The peaks are averaged over consecutive windows of W cycles (``window``: one
    value, or one per mesh; W should cover the longest excitation period, e.g. a
    gear revolution when errors rotate with the gears).  The last window is the
    reference; the run is settled from the earliest window after which every window's
    mean and largest peak stay within ``tolerance`` of the reference (relative to the
    reference's largest peak).  A slow drift that lasts until the end therefore leaves
    only the last windows, and a run whose settled part is shorter than a quarter of
    the run is reported as not settled.
    """
    first = {}
    settled = True
    t0 = 0.0
    for j, name in enumerate(names):
        peaks = cycle_max[:, j]
        valid = np.isfinite(peaks)
        idx = np.flatnonzero(valid)
        peaks = peaks[valid]
        n = peaks.size
        w_req = int(window[j] if np.ndim(window) else window)
        w = max(2, min(w_req, n // 4))
        k_set = n // 2
        ok = False
        if n >= 2 * w:
            n_win = n // w
            start = n - n_win * w  # align the windows with the end of the run
            blocks = peaks[start:].reshape(n_win, w)
            ref_mean, ref_max = blocks[-1].mean(), blocks[-1].max()
            scale = max(abs(ref_max), 1e-300)
            good = ((np.abs(blocks.mean(axis=1) - ref_mean) <= tolerance * scale)
                    & (np.abs(blocks.max(axis=1) - ref_max) <= tolerance * scale))
            bad = np.flatnonzero(~good)
            b0 = int(bad[-1]) + 1 if bad.size else 0
            k_set = start + b0 * w if b0 else 0
            ok = (n - k_set) >= n / 4
        if not ok:
            settled = False
            k_set = min(k_set, n // 2)
        c = int(idx[k_set]) if n else 0
        first[name] = c
        if n:
            t0 = max(t0, float(cycle_start[c, j]))
    return Settling(start_time=t0, settled=settled, first_cycle=first)


def _ratio(x: np.ndarray) -> np.ndarray:
    """N x_i / sum_j x_j along the last axis (NaN where the sum vanishes)."""
    s = x.sum(axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return x.shape[-1] * x / np.where(s != 0, s, np.nan)


def cycle_peak(cycle_max, names, groups, first_cycle) -> LoadSharing:
    """seed 000 eqs. 17-19: coefficients from per-cycle peak forces."""
    col = {n: j for j, n in enumerate(names)}
    per_mesh, per_group, per_cycle = {}, {}, {}
    for g, members in groups.items():
        k0 = max(first_cycle[m] for m in members)
        x = np.stack([cycle_max[k0:, col[m]] for m in members], axis=-1)
        x = x[np.all(np.isfinite(x), axis=-1)]
        r = _ratio(x)  # seed 000 eq. 17: LSC_i(k) = N F_max,i(k) / sum_j F_max,j(k)
        for i, m in enumerate(members):
            per_cycle[m] = r[:, i]
            per_mesh[m] = float(np.nanmax(r[:, i])) if r.size else math.nan
        per_group[g] = max(per_mesh[m] for m in members)  # seed 000 eq. 18
    system = max(per_group.values())  # seed 000 eq. 19
    return LoadSharing("cycle_peak", per_mesh, per_group, system, groups, per_cycle)


def mean_force(cycle_mean, cycle_count, names, groups, first_cycle) -> LoadSharing:
    """seed 002 eq. 12: coefficients from mean forces (count-weighted cycle means)."""
    col = {n: j for j, n in enumerate(names)}
    per_mesh, per_group = {}, {}
    for g, members in groups.items():
        k0 = max(first_cycle[m] for m in members)
        means = []
        for m in members:
            c = cycle_count[k0:, col[m]]
            v = np.nan_to_num(cycle_mean[k0:, col[m]])
            means.append(float((v * c).sum() / max(c.sum(), 1)))
        r = _ratio(np.asarray(means))
        for i, m in enumerate(members):
            per_mesh[m] = float(r[i])
        per_group[g] = max(per_mesh[m] for m in members)
    return LoadSharing("mean_force", per_mesh, per_group, max(per_group.values()), groups)


def instantaneous(t, forces, names, groups, start_time, cycle_frequency=None,
                  definition="instantaneous") -> LoadSharing:
    """seed 001 eq. 18 (and seed 004 eq. 14 on quasi-static forces).

    ``forces`` (n_samples, n_meshes) sampled at ``t``.  With ``definition ==
    'engineering'`` the per-cycle peaks of the coefficient (cycles of
    ``cycle_frequency[group]`` Hz) are averaged instead of taking the largest.
    """
    col = {n: j for j, n in enumerate(names)}
    keep = t >= start_time
    per_mesh, per_group, per_cycle = {}, {}, {}
    for g, members in groups.items():
        x = forces[keep][:, [col[m] for m in members]]
        r = _ratio(x)  # seed 001 eq. 18: g = N F_i / sum_j F_j
        if definition == "engineering":
            f = cycle_frequency[g]
            k = np.floor((t[keep] - t[keep][0]) * f).astype(np.int64) if x.size else np.zeros(0)
            for i, m in enumerate(members):
                peaks = _per_bin_max(k, r[:, i])
                per_cycle[m] = peaks
                per_mesh[m] = float(np.nanmean(peaks)) if peaks.size else math.nan
        else:
            for i, m in enumerate(members):
                per_mesh[m] = float(np.nanmax(r[:, i])) if r.size else math.nan
        per_group[g] = max(per_mesh[m] for m in members)
    return LoadSharing(definition, per_mesh, per_group, max(per_group.values()), groups,
                       per_cycle)


def _per_bin_max(bins: np.ndarray, values: np.ndarray) -> np.ndarray:
    if bins.size == 0:
        return np.zeros(0)
    out = np.full(int(bins.max()) + 1, np.nan)
    np.fmax.at(out, bins, values)
    # drop the incomplete first/last bins
    return out[1:-1] if out.size > 2 else out


@dataclass(frozen=True)
class DynamicFactors:
    """Dynamic load factors per mesh: peak and engineering (mean of cycle peaks)."""

    peak: dict[str, float]
    engineering: dict[str, float]
    per_group_peak: dict[str, float]
    per_group_engineering: dict[str, float]


def dynamic_factors(cycle_max, names, groups, first_cycle, nominal_force) -> DynamicFactors:
    """Peak dynamic force / nominal static force (ISO sense; seed 000 DLF; seed 001 eq. 19)."""
    col = {n: j for j, n in enumerate(names)}
    peak, eng = {}, {}
    for m in names:
        p = cycle_max[first_cycle[m]:, col[m]]
        p = p[np.isfinite(p)]
        f0 = nominal_force[m]
        peak[m] = float(p.max() / f0) if p.size else math.nan
        eng[m] = float(p.mean() / f0) if p.size else math.nan
    gp, ge = {}, {}
    for g, members in groups.items():
        gp[g] = max(peak[m] for m in members)
        # seed 001 eq. 19: G = max_i F_i / F_0, averaged over the periodic peaks
        k0 = max(first_cycle[m] for m in members)
        x = np.stack([cycle_max[k0:, col[m]] / nominal_force[m] for m in members], axis=-1)
        x = x[np.all(np.isfinite(x), axis=-1)]
        ge[g] = float(x.max(axis=-1).mean()) if x.size else math.nan
    return DynamicFactors(peak, eng, gp, ge)
