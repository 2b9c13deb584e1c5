"""User-supplied mesh stiffness: a constant, a table against mesh phase, a Fourier
series, or tables at several load levels interpolated in load.

Typical sources: an LTCA or FE program (Liu et al. 2021 §2.3, Dong et al. 2021 §5), a test rig, or
a paper's figure.  Phases are in cycles of the tooth-mesh period (0..1, taken modulo
1); stiffness in N/m along the normal to the flanks (the convention of
:class:`~torquesplit.gears.stiffness.result.MeshStiffness`).
"""

from __future__ import annotations

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.stiffness.phasing import phase_grid
from torquesplit.gears.stiffness.result import MeshStiffness, periodic_resample

__all__ = [
    "constant_stiffness",
    "table_stiffness",
    "fourier_stiffness",
    "load_table_stiffness",
]


def constant_stiffness(mean: float, n: int = 256) -> MeshStiffness:
    """A time-invariant mesh stiffness ``mean`` [N/m] sampled at ``n`` phases.

    >>> constant_stiffness(4.6e9, 8).peak_to_peak
    0.0
    """
    if not (np.isfinite(mean) and mean > 0):
        raise ModelError([("mean", f"must be a positive stiffness in N/m, got {mean!r}")])
    return MeshStiffness.from_samples(np.full(phase_grid(n).size, float(mean)), "constant")


def table_stiffness(phase, stiffness, n: int = 256) -> MeshStiffness:
    """Stiffness samples against mesh phase, resampled periodically onto ``n`` phases.

    Parameters
    ----------
    phase : array_like
        Mesh phase of each sample [cycles]; any order, taken modulo 1 (a sample at
        1.0 duplicates the one at 0.0 and is dropped).
    stiffness : array_like
        Stiffness at each phase [N/m].
    n : int
        Number of output samples.

    >>> k = table_stiffness([0.0, 0.5], [1e9, 2e9], n=4)
    >>> k.stiffness.tolist()
    [1000000000.0, 1500000000.0, 2000000000.0, 1500000000.0]
    """
    k = periodic_resample(phase, stiffness, phase_grid(n).size)
    return MeshStiffness.from_samples(k, "table")


def fourier_stiffness(mean: float, cos=(), sin=(), n: int = 256) -> MeshStiffness:
    """Mesh stiffness from a Fourier series in the mesh phase [N/m].

    ``k(phi) = mean + sum_k a_k cos(2 pi k phi) + b_k sin(2 pi k phi)``, k = 1, 2, ...;
    ``cos`` holds ``a_k``, ``sin`` holds ``b_k`` (either may be shorter; missing
    terms are 0).  This is the form in which Liu et al. 2021 passes its LTCA stiffness to
    the dynamic model (§2.3).

    >>> k = fourier_stiffness(1e9, cos=[1e8], n=4)
    >>> [float(round(v / 1e8, 6)) for v in k.stiffness]
    [11.0, 10.0, 9.0, 10.0]
    """
    a = np.atleast_1d(np.asarray(cos, dtype=float))
    b = np.atleast_1d(np.asarray(sin, dtype=float))
    phase = phase_grid(n)
    k = np.full(phase.size, float(mean))
    for i, ak in enumerate(a, start=1):
        k += ak * np.cos(2.0 * np.pi * i * phase)
    for i, bk in enumerate(b, start=1):
        k += bk * np.sin(2.0 * np.pi * i * phase)
    if np.any(k < 0):
        raise ModelError([("fourier", f"the series goes negative (min {k.min():.4g} N/m); "
                                      "check the signs and sizes of the coefficients")])
    return MeshStiffness.from_samples(k, "fourier")


def load_table_stiffness(loads, phase, stiffness, load: float, n: int = 256) -> MeshStiffness:
    """Stiffness tables at several load levels, interpolated linearly in load.

    Parameters
    ----------
    loads : array_like, shape (m,)
        Load level of each table (torque [N m] or force [N], any one quantity,
        strictly increasing).
    phase : array_like, shape (p,) or (m, p)
        Mesh phase of the samples [cycles]; one row for all tables or one per table.
    stiffness : array_like, shape (m, p)
        Stiffness samples [N/m], one row per load level.
    load : float
        Load at which to evaluate, within ``[loads[0], loads[-1]]`` (no extrapolation).
    n : int
        Number of output samples.
    """
    loads = np.asarray(loads, dtype=float)
    stiffness = np.asarray(stiffness, dtype=float)
    phase = np.asarray(phase, dtype=float)
    if loads.ndim != 1 or loads.size < 1 or np.any(np.diff(loads) <= 0):
        raise ModelError([("loads", "need a strictly increasing 1-D array of load levels")])
    if stiffness.ndim != 2 or stiffness.shape[0] != loads.size:
        raise ModelError([("stiffness", f"needs one row per load level: shape ({loads.size}, p), "
                                        f"got {stiffness.shape}")])
    phases = np.broadcast_to(phase, stiffness.shape) if phase.ndim == 1 else phase
    if phases.shape != stiffness.shape:
        raise ModelError([("phase", "needs shape (p,) or the shape of stiffness")])
    if not (loads[0] <= load <= loads[-1]):
        raise ModelError([("load", f"{load:g} lies outside the tabulated range "
                                   f"[{loads[0]:g}, {loads[-1]:g}]; add a table at that load")])
    rows = np.array([periodic_resample(p, k, phase_grid(n).size) for p, k in zip(phases, stiffness)])
    if loads.size == 1:
        k = rows[0]
    else:
        j = int(np.clip(np.searchsorted(loads, load, side="right") - 1, 0, loads.size - 2))
        w = (load - loads[j]) / (loads[j + 1] - loads[j])
        k = (1.0 - w) * rows[j] + w * rows[j + 1]
    return MeshStiffness.from_samples(k, "table", {"load": float(load)})
