"""Load-sharing coefficients and dynamic factors, by the papers' definitions.

Meshes are grouped into *load-sharing groups*: meshes with the same ``path`` and
``stage`` labels (model file) carry parallel shares of one flow of power.  In a group
of N meshes each definition forms ``N X_i / sum_j X_j`` of some per-mesh quantity X,
so a perfect split gives 1 for every mesh.  Only the ``mean_force`` coefficients of a
group sum to N; the others take each mesh's largest ratio over time, cycles or positions
(``engineering``: the mean of its per-cycle peaks), so their sum can exceed N.
Every definition is computed from quantities the integrator streams at every step (per
mesh cycle: force max, min and mean, and the largest instantaneous ratio), never from
the decimated history, so a coefficient does not depend on how often the history is
sampled, and it converges with the step:

==================  =============================================================
definition          X and reduction
==================  =============================================================
``cycle_peak``      X = peak force of each mesh in mesh cycle k; the coefficient
                    is the largest over meshes and settled cycles (Liu et al. 2021
                    eqs. 17-19)
``instantaneous``   X = force at each instant; the largest over the settled part
                    (Ji & Li eq. 18, g_i)
``engineering``     mean over settled mesh cycles of the per-cycle peak of the
                    instantaneous coefficient (Ji & Li eq. 18, engineering
                    coefficient g_it: "average value of the periodic peak")
``mean_force``      X = mean force over the settled part (Dong et al. 2021 eq. 12)
``static_torque``   X = quasi-static force at each mesh position; the largest over
                    the positions (Mo et al. 2017 eqs. 14-15); quasi-static runs only
==================  =============================================================

Dynamic factors (per mesh, over the settled part), named for what they are:

* ``dynamic_factor`` = peak force / the mesh's own static force: the dynamic
  amplification of the mesh's load in the K_v sense (ISO 6336-1), >= 1 for a mesh that
  stays in contact; static maldistribution is not in it;
* ``dynamic_factor_engineering`` = mean over cycles of the per-cycle peak / static force;
* ``peak_to_nominal`` = peak force / the equal-split nominal force of
  :mod:`torquesplit.model.kinematics`: load sharing and dynamics together (Ji & Li eq.
  19, G_i: the largest over the group's meshes);
* ``peak_to_nominal_engineering`` (per group) = mean over settled cycles of the
  largest member's per-cycle peak / nominal force (Ji & Li eq. 19, engineering
  coefficient G_it).

The transient is excluded by a settle criterion (:func:`settle`): one settle time per
group, used by every metric of that group, except ``mean_force``: its means are over the
same span for every group, from the latest group settle time (:func:`common_first_cycle`),
so that the stages of one locked train, which carry the same mean path torques, give the
same coefficients (over each group's own span they differed by the drift of the slow
excitations between the two starts: a reviewer's 1.2014 and 1.2119).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import OptionError

DEFINITIONS = ("cycle_peak", "instantaneous", "engineering", "mean_force", "static_torque")
DYNAMIC_DEFINITIONS = DEFINITIONS[:4]

DEFINITION_TEXT = {
    "cycle_peak": "ratio of the meshes' peak forces in each mesh cycle, largest over the "
                  "settled cycles (Liu et al. 2021 eqs. 17-19)",
    "instantaneous": "ratio of the meshes' forces at each instant, largest over the settled "
                     "part (Ji & Li eq. 18)",
    "engineering": "mean over settled mesh cycles of the per-cycle peak of the "
                   "instantaneous ratio (Ji & Li eq. 18, engineering coefficient g_it)",
    "mean_force": "ratio of the meshes' mean forces over the settled part, one span for "
                  "every group (Dong et al. 2021 eq. 12)",
    "static_torque": "ratio of quasi-static mesh forces, largest over the mesh positions "
                     "(Mo et al. 2017 eqs. 14-15)",
}
"""What each definition measures, in one line (tables, plots, docs)."""

DEFINITION_USE = {
    "mean_force": "report it as the mesh load factor K_gamma of ISO 6336-1 / AGMA 6123 "
                  "(the default): the share of the mean load a path carries, without the "
                  "dynamic increment, which the dynamic factor gives (K_v sense)",
    "cycle_peak": "report it to compare with Liu et al. 2021, or when the worst cycle's "
                  "peak sharing matters; it contains the dynamics (do not multiply it by a "
                  "dynamic factor)",
    "engineering": "report it to compare with Ji & Li: a repeatable peak-sharing number, "
                   "less sensitive to single cycles than 'instantaneous'",
    "instantaneous": "an upper bound: meshes out of phase give spikes even when they share "
                     "equally; use it to look for extreme instants, not as a design value",
    "static_torque": "the sharing set by errors and compliances alone, without dynamics "
                     "(compare with Mo et al. 2017); `torquesplit static` computes it",
}
"""When to report each definition, in one line (``run --help``, the table's footnote,
docs/load-sharing.md)."""

#: the definition of a new model: the mean-force ratio is the mesh load factor K_gamma
#: of the design standards (ISO 6336-1, AGMA 6123), which combines with the dynamic
#: factor K_v (``dynamic_factor``) as the standards multiply them
STANDARD_DEFINITION = "mean_force"


@dataclass(frozen=True)
class Settling:
    """Where the transient ends: per mesh and, consistently, per load-sharing group."""

    start_time: float
    """Latest group settle time [s] (every group is settled from then on)."""
    settled: bool
    """False if some mesh never settled (then the last half of the run is used)."""
    first_cycle: dict[str, int]
    """Mesh -> first cycle used by every metric: the first cycle of the mesh that starts
    at or after its group's settle time."""
    group_time: dict[str, float] = field(default_factory=dict)
    """Group -> settle time [s]: the latest of its meshes' own settle times."""
    own_first_cycle: dict[str, int] = field(default_factory=dict)
    """Mesh -> first settled cycle by its own peaks alone."""
    short: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Mesh -> (its cycles, the window it needs) where the run holds fewer than two
    windows: too short to check settling over the longest excitation period, so not
    settled (its metrics then use a shorter window, a best effort)."""
    shrunk: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Mesh -> (its cycles, the window it needs) where the run holds two to four windows,
    so its windows shrank to a quarter of the run, shorter than the longest excitation
    period, and they did not show it settled: the response's own variation over that
    period cannot be told from a transient (run at least four windows)."""
    mean_first_cycle: dict[str, int] = field(default_factory=dict)
    """Mesh -> first cycle of the mean forces (mean_force coefficients, the mean F
    column, the drift check): every group over one span, from ``start_time``
    (:func:`common_first_cycle`); empty: ``first_cycle``."""
    periodic: bool = False
    """A periodic state's record (:func:`periodic`): no transient; ``start_time`` is
    where the slowest group's first whole cycle of the repeated state begins."""

    @property
    def mean_first(self) -> dict[str, int]:
        """:attr:`mean_first_cycle`, or :attr:`first_cycle` where it is not set."""
        return self.mean_first_cycle or self.first_cycle


@dataclass(frozen=True)
class LoadSharing:
    """Coefficients of one definition: per mesh, per group and for the system."""

    definition: str
    per_mesh: dict[str, float]
    per_group: dict[str, float]
    system: float
    groups: dict[str, list[str]]
    per_cycle: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    """Mesh -> the definition's coefficient in every mesh cycle of the run (NaN where a
    cycle has no sample): the cycle-peak ratio, the per-cycle peak of the instantaneous
    ratio, or the ratio of the cycle means (``mean_force``)."""
    cycle_time: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    """Mesh -> start time of each of those cycles [s]."""
    position_mean: dict[str, float] = field(default_factory=dict)
    """``static_torque`` only: mesh -> N x its force averaged over the mesh positions /
    the sum of its group's averages (the mean load of a path over the mean of all: the
    planets' K_gamma of AGMA 6123 / ISO 6336-1, :mod:`torquesplit.metrics.planetary`)."""

    @property
    def load_sharing(self) -> "LoadSharing":
        """This object: code written for a run's ``metrics().load_sharing`` (a
        :class:`~torquesplit.results.Metrics`) reads a quasi-static sweep's
        ``metrics()``, which is the load sharing itself, the same way (a Python API
        reviewer's code broke on the other result type)."""
        return self

    def __repr__(self) -> str:
        return (f"LoadSharing({self.definition!r}: system {self.system:#.5g}, "
                f"{len(self.per_group)} group{'s' if len(self.per_group) != 1 else ''}, "
                f"{len(self.per_mesh)} mesh{'es' if len(self.per_mesh) != 1 else ''})")


def group_meshes(mesh_meta: dict[str, dict]) -> dict[str, list[str]]:
    """Load-sharing groups keyed ``"path/stage"`` (or ``"stage"`` without a path)."""
    groups: dict[str, list[str]] = {}
    for name, meta in mesh_meta.items():
        key = f"{meta['path']}/{meta['stage']}" if meta.get("path") else str(meta["stage"])
        groups.setdefault(key, []).append(name)
    return groups


START_TOLERANCE = 1e-4
"""A window whose mean or largest peak lies outside the range of the last half's windows
by more than this [x the last window's largest peak] is still transient (:func:`settle`):
below the fifth digit of a printed dynamic factor."""


def settle(cycle_max: np.ndarray, cycle_start: np.ndarray, names, window=20,
           tolerance: float = 0.01, groups: dict[str, list[str]] | None = None) -> Settling:
    """Find where the transient ends, from the per-cycle peak forces.

    Per mesh, the peaks are averaged over consecutive windows of W cycles (``window``:
    one value, or one per mesh; W should cover the longest excitation period, e.g. a
    gear revolution when errors rotate with the gears) aligned with the end of the run.
    The last window is the reference; the mesh is settled from the start of the window
    after the last one whose mean or largest peak differs from the reference's by more
    than ``tolerance`` x the reference's largest peak (else the run is not settled, see
    below), and in any case from the window after the last one that lies outside the
    range of the windows of the run's last half (two or more) by more than
    :data:`START_TOLERANCE` x that peak or, if more, half that range, in the leading run
    of such windows: a start-up peak within the tolerance (0.8 %
    above the steady ones on a single spur pair) is still transient and must not set the
    dynamic factor, while the windows of a response that does not repeat over W vary by
    as much as the last half's do.  The cycles before the first
    whole window (fewer than W) are never counted as settled: they were not checked.  A
    drift that lasts until the end leaves only the last windows, and a mesh whose settled
    part is shorter than a quarter of its cycles, or is the last window alone (which
    nothing confirms: the transient may end inside it), is reported as not settled (its
    last half is used).  A run shorter than two windows cannot show that the response repeats
    over the longest excitation period: it is reported as not settled (``short``), and
    its windows shrink to a quarter of its cycles.  A group is settled from the latest
    settle time of its meshes, and every metric of the group starts there.
    """
    own: dict[str, int] = {}
    short: dict[str, tuple[int, int]] = {}
    shrunk: dict[str, tuple[int, int]] = {}
    settled = True
    t_own: dict[str, float] = {}
    for j, name in enumerate(names):
        peaks = cycle_max[:, j]
        idx = np.flatnonzero(np.isfinite(peaks))
        peaks = peaks[idx]
        n = peaks.size
        w_req = int(window[j] if np.ndim(window) else window)
        w = max(2, min(w_req, n // 4))
        if n < 2 * w_req:
            short[name] = (n, w_req)
            settled = False
        k_set = n // 2
        ok = False
        if n >= 2 * w:
            n_win = n // w
            start = n - n_win * w  # windows aligned with the end; cycles before: unchecked
            blocks = peaks[start:].reshape(n_win, w)
            ref_mean, ref_max = blocks[-1].mean(), blocks[-1].max()
            scale = max(abs(ref_max), 1e-300)
            good = ((np.abs(blocks.mean(axis=1) - ref_mean) <= tolerance * scale)
                    & (np.abs(blocks.max(axis=1) - ref_max) <= tolerance * scale))
            bad = np.flatnonzero(~good)
            b0 = int(bad[-1]) + 1 if bad.size else 0
            if n_win - n_win // 2 >= 2:  # (a range needs two windows at least)
                inside = np.ones(n_win, dtype=bool)
                for stat in (blocks.mean(axis=1), blocks.max(axis=1)):
                    lo, hi = stat[n_win // 2:].min(), stat[n_win // 2:].max()
                    margin = max(START_TOLERANCE * scale, 0.5 * (hi - lo))
                    inside &= (stat >= lo - margin) & (stat <= hi + margin)
                # the start-up transient is the leading run of windows outside the range
                # (a later one outside it is the response's own variation)
                b0 = max(b0, int(np.argmax(inside)) if inside.any() else 0)
            k_set = start + b0 * w
            # settled needs two windows that agree at least: the last one alone, the
            # reference, may hold the transient's end itself (a run of 2-4 windows whose
            # transient reached into its last one was reported settled from it)
            ok = (n - k_set) >= n / 4 and b0 <= n_win - 2
        if not ok:
            settled = False
            k_set = n // 2 if n else 0
            if w < w_req and name not in short:
                shrunk[name] = (n, w_req)
        c = int(idx[k_set]) if n else 0
        own[name] = c
        t_own[name] = float(cycle_start[c, j]) if n else -math.inf
    groups = groups or {name: [name] for name in names}
    col = {n: j for j, n in enumerate(names)}
    group_time = {g: max(t_own[m] for m in ms) for g, ms in groups.items()}
    first = {}
    for g, ms in groups.items():
        for m in ms:
            starts = cycle_start[:, col[m]]
            # first cycle starting at or after the group's settle time (round-off aside)
            first[m] = _first_cycle_from(starts, group_time[g], own[m])
    start_time = max(group_time.values()) if group_time else 0.0
    return Settling(start_time=start_time, settled=settled, first_cycle=first,
                    group_time=group_time, own_first_cycle=own, short=short,
                    shrunk=shrunk)


def _first_cycle_from(starts: np.ndarray, t: float, least: int) -> int:
    """The first cycle of ``starts`` starting at or after ``t`` (round-off aside), not
    before cycle ``least``, and not past the last."""
    tol = 1e-9 * max(abs(t), 1e-300)
    k = int(np.searchsorted(starts, t - tol, side="left"))
    return min(max(k, least), max(len(starts) - 1, 0))


def common_first_cycle(settling: "Settling", cycle_start: np.ndarray, names) -> dict[str, int]:
    """Mesh -> its first cycle starting at or after the latest group settle time
    (``settling.start_time``), and not before its group's settled cycle: the start of a
    span common to every group."""
    return {m: _first_cycle_from(cycle_start[:, j], settling.start_time,
                                 settling.first_cycle[m]) for j, m in enumerate(names)}


def periodic(cycle_max: np.ndarray, cycle_start: np.ndarray, names,
             groups: dict[str, list[str]] | None = None) -> Settling:
    """Settling of a periodic state's record (the steady state repeated): no transient,
    every complete cycle counts, from each mesh's first one (the record holds whole
    periods of each mesh's cycles, so every mean is over whole periods)."""
    first: dict[str, int] = {}
    t_own: dict[str, float] = {}
    for j, name in enumerate(names):
        idx = np.flatnonzero(np.isfinite(cycle_max[:, j]))
        first[name] = int(idx[0]) if idx.size else 0
        t_own[name] = float(cycle_start[first[name], j]) if idx.size else -math.inf
    groups = groups or {name: [name] for name in names}
    group_time = {g: max(t_own[m] for m in ms) for g, ms in groups.items()}
    return Settling(start_time=max(group_time.values()) if group_time else 0.0,
                    settled=True, first_cycle=first, group_time=group_time,
                    own_first_cycle=dict(first), periodic=True)


def _ratio(x: np.ndarray) -> np.ndarray:
    """N x_i / sum_j x_j along the last axis (NaN where the sum vanishes)."""
    s = _row_sums(x)
    with np.errstate(invalid="ignore", divide="ignore"):
        return x.shape[-1] * x / np.where(s != 0, s, np.nan)


def _row_sums(x: np.ndarray) -> np.ndarray:
    """``x.sum(axis=-1, keepdims=True)`` of a (cycles, members) array, bit for bit: numpy
    adds fewer than eight values one by one to 0.0, which column by column does too,
    without its slow reduction over a short last axis (75 us for 5136 cycles of two
    members against 5)."""
    n = x.shape[-1]
    if x.ndim != 2 or not 1 <= n <= 7 or x.dtype != np.float64:
        return x.sum(axis=-1, keepdims=True)
    s = 0.0 + x[:, :1]  # (0.0 + -0.0 is 0.0, as numpy's)
    for k in range(1, n):
        s += x[:, k:k + 1]
    return s


def _row_max(x: np.ndarray) -> np.ndarray:
    """``x.max(axis=-1)`` of a (cycles, members) array without NaN, column by column (the
    same rule at equal values: the earlier one is kept)."""
    n = x.shape[-1]
    if x.ndim != 2 or not 1 <= n <= 7 or x.dtype != np.float64:
        return x.max(axis=-1)
    m = x[:, 0].copy()
    for k in range(1, n):
        np.maximum(m, x[:, k], out=m)
    return m


def _system(per_group: dict[str, float]) -> float:
    """The system's coefficient: the largest of its groups' (Ji & Li eq. 19), NaN when a
    group has none (a run too short for a whole cycle of it: the largest is then not
    known; Python's max() skipped a NaN or not depending on the groups' order)."""
    values = np.array(list(per_group.values()), dtype=float)
    if not values.size or not np.isfinite(values).all():
        return math.nan
    return float(values.max())


def _nanmax(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(np.nanmax(x)) if np.isfinite(x).any() else math.nan


def _nanmean(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(np.nanmean(x)) if np.isfinite(x).any() else math.nan


def cycle_peak(cycle_max, cycle_start, names, groups, first_cycle) -> LoadSharing:
    """Liu et al. 2021 eqs. 17-19: coefficients from per-cycle peak forces."""
    col = {n: j for j, n in enumerate(names)}
    per_mesh, per_group, per_cycle, times = {}, {}, {}, {}
    for g, members in groups.items():
        x = np.stack([cycle_max[:, col[m]] for m in members], axis=-1)
        r = _ratio(x)  # Liu et al. 2021 eq. 17: LSC_i(k) = N F_max,i(k) / sum_j F_max,j(k)
        for i, m in enumerate(members):
            per_cycle[m] = r[:, i]
            times[m] = cycle_start[:, col[m]]
            per_mesh[m] = _nanmax(r[first_cycle[m]:, i])
        per_group[g] = max(per_mesh[m] for m in members)  # eq. 18
    return LoadSharing("cycle_peak", per_mesh, per_group, _system(per_group), groups,
                       per_cycle, times)


def span_mean(cycle_mean, cycle_count) -> float:
    """The count-weighted mean of the cycle means of one mesh over a span of cycles; NaN
    where the span holds no sample (a run too short for a whole cycle of the mesh past
    its settle time: it read 0, and its group's coefficient N F_i / sum F became N)."""
    c = np.asarray(cycle_count)
    total = c.sum()
    if total <= 0:
        return math.nan
    return float((np.nan_to_num(np.asarray(cycle_mean, dtype=float)) * c).sum() / total)


def mean_force(cycle_mean, cycle_count, cycle_start, names, groups,
               first_cycle) -> LoadSharing:
    """Dong et al. 2021 eq. 12: coefficients from mean forces (count-weighted cycle
    means over the settled part)."""
    col = {n: j for j, n in enumerate(names)}
    per_mesh, per_group, per_cycle, times = {}, {}, {}, {}
    for g, members in groups.items():
        means = [span_mean(cycle_mean[first_cycle[m]:, col[m]],
                           cycle_count[first_cycle[m]:, col[m]]) for m in members]
        r = _ratio(np.asarray(means))  # (a member without a mean: NaN for every member)
        rc = _ratio(np.stack([cycle_mean[:, col[m]] for m in members], axis=-1))
        for i, m in enumerate(members):
            per_mesh[m] = float(r[i])
            per_cycle[m] = rc[:, i]
            times[m] = cycle_start[:, col[m]]
        per_group[g] = _nanmax([per_mesh[m] for m in members])
    return LoadSharing("mean_force", per_mesh, per_group, _system(per_group), groups,
                       per_cycle, times)


def instantaneous(cycle_ratio_max, cycle_start, names, groups, first_cycle,
                  definition="instantaneous") -> LoadSharing:
    """Ji & Li eq. 18 from the streamed per-cycle peaks of the instantaneous ratio
    ``N F_i(t) / sum_j F_j(t)`` (``Solution.cycle_ratio_max``): the largest over the
    settled cycles (``instantaneous``, g_i) or their mean (``engineering``, g_it)."""
    if definition not in ("instantaneous", "engineering"):
        raise OptionError(f"definition must be 'instantaneous' or 'engineering', got "
                         f"{definition!r}")
    col = {n: j for j, n in enumerate(names)}
    reduce = _nanmax if definition == "instantaneous" else _nanmean
    per_mesh, per_group, per_cycle, times = {}, {}, {}, {}
    for g, members in groups.items():
        for m in members:
            peaks = cycle_ratio_max[:, col[m]]
            per_cycle[m] = peaks.copy()  # (the caller's: the run's statistics are read-only)
            times[m] = cycle_start[:, col[m]]
            per_mesh[m] = reduce(peaks[first_cycle[m]:])
        per_group[g] = max(per_mesh[m] for m in members)
    return LoadSharing(definition, per_mesh, per_group, _system(per_group), groups,
                       per_cycle, times)


def static_torque(times, forces, names, groups) -> LoadSharing:
    """Mo et al. 2017 eqs. 14-15: ratios of the quasi-static mesh forces at every mesh
    position (``forces`` (n_positions, n_meshes)), the largest over the positions."""
    col = {n: j for j, n in enumerate(names)}
    per_mesh, per_group, per_cycle, ts, mean = {}, {}, {}, {}, {}
    for g, members in groups.items():
        f = forces[:, [col[m] for m in members]]
        r = _ratio(f)  # Mo et al. 2017 eq. 14
        with np.errstate(invalid="ignore"):
            r_mean = _ratio(np.nanmean(f, axis=0)) if len(f) else np.full(len(members), np.nan)
        for i, m in enumerate(members):
            per_cycle[m] = r[:, i]
            ts[m] = np.asarray(times, dtype=float)
            per_mesh[m] = _nanmax(r[:, i])
            mean[m] = float(r_mean[i])
        per_group[g] = max(per_mesh[m] for m in members)  # eq. 15
    return LoadSharing("static_torque", per_mesh, per_group, _system(per_group),
                       groups, per_cycle, ts, mean)


@dataclass(frozen=True)
class DynamicFactors:
    """Dynamic factors per mesh and per group (see the module docstring)."""

    dynamic_factor: dict[str, float]
    """Mesh -> settled peak force / the mesh's own static force (K_v sense)."""
    dynamic_factor_engineering: dict[str, float]
    """Mesh -> mean over settled cycles of the per-cycle peak / static force."""
    peak_to_nominal: dict[str, float]
    """Mesh -> settled peak force / equal-split nominal force."""
    per_group_dynamic_factor: dict[str, float]
    """Group -> largest member dynamic factor."""
    per_group_peak_to_nominal: dict[str, float]
    """Group -> largest member peak / nominal (Ji & Li eq. 19, G_i)."""
    per_group_peak_to_nominal_engineering: dict[str, float]
    """Group -> mean over settled cycles of the largest member's per-cycle peak /
    nominal force (Ji & Li eq. 19, engineering coefficient G_it)."""


def dynamic_factors(cycle_max, names, groups, first_cycle, static_force, nominal_force,
                    min_static_fraction: float = 1e-3) -> DynamicFactors:
    """Dynamic factors from the per-cycle peaks (see the module docstring).

    A mesh whose static force is below ``min_static_fraction`` of its nominal force
    (unloaded, or loaded on its back flank) has no dynamic factor (NaN): a ratio to a
    vanishing load means nothing.
    """
    col = {n: j for j, n in enumerate(names)}
    dyn, dyn_eng, ptn = {}, {}, {}
    for m in names:
        p = cycle_max[first_cycle[m]:, col[m]]
        p = p[np.isfinite(p)]
        f_s, f_0 = static_force[m], nominal_force[m]
        peak = float(p.max()) if p.size else math.nan
        mean_peak = float(p.mean()) if p.size else math.nan
        loaded = f_s > min_static_fraction * abs(f_0)
        dyn[m] = peak / f_s if loaded else math.nan
        dyn_eng[m] = mean_peak / f_s if loaded else math.nan
        ptn[m] = peak / f_0 if f_0 != 0 else math.nan
    g_dyn, g_ptn, g_ptn_eng = {}, {}, {}
    for g, members in groups.items():
        g_dyn[g] = _nanmax([dyn[m] for m in members])
        g_ptn[g] = _nanmax([ptn[m] for m in members])
        # Ji & Li eq. 19: G = max_i F_i / F_0, averaged over the periodic (cycle) peaks
        k0 = max(first_cycle[m] for m in members)
        x = np.stack([cycle_max[k0:, col[m]] / nominal_force[m] for m in members], axis=-1)
        finite = np.isfinite(x[:, 0])
        for k in range(1, x.shape[1]):  # (np.all over the short axis: slow, as below)
            finite &= np.isfinite(x[:, k])
        x = x[finite]
        g_ptn_eng[g] = float(_row_max(x).mean()) if x.size else math.nan
    return DynamicFactors(dyn, dyn_eng, ptn, g_dyn, g_ptn, g_ptn_eng)
