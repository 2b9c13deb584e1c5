"""The result type of every mesh-stiffness method: one mesh cycle, sampled uniformly."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from torquesplit.errors import ModelError

__all__ = ["MeshStiffness", "periodic_resample"]


def _readonly(a) -> np.ndarray:
    a = np.array(a, dtype=float)  # a private copy
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class MeshStiffness:
    """Mesh stiffness over one tooth-mesh period.

    Attributes
    ----------
    phase : ndarray
        ``n`` uniform mesh phases ``k/n`` in [0, 1) [cycles].  Phase 0 is the instant
        a new tooth pair enters contact at the start of active profile.
    stiffness : ndarray
        Mesh stiffness at each phase [N/m], along the normal to the tooth flanks
        (the 3-D line of action; equal to the transverse line of action for spur gears).
        For double-helical pairs: both helices together.
    mean : float
        Mean over the cycle [N/m].
    peak_to_peak : float
        ``max - min`` over the cycle [N/m].
    method : str
        Name of the method that produced it.
    info : Mapping
        Method-specific extras (e.g. ISO ``c_prime``, contact ratios), SI units.

    Build one with :meth:`from_samples`; the arrays are read-only.
    """

    phase: np.ndarray
    stiffness: np.ndarray
    mean: float
    peak_to_peak: float
    method: str
    info: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def from_samples(cls, stiffness, method: str, info: Mapping[str, Any] | None = None) -> "MeshStiffness":
        """Wrap ``n`` stiffness samples taken at phases ``k/n`` [N/m]."""
        k = _readonly(stiffness)
        if k.ndim != 1 or k.size < 2:
            raise ModelError([("stiffness", "needs a 1-D array of at least 2 samples over one mesh cycle")])
        if not np.all(np.isfinite(k)):
            raise ModelError([("stiffness", "contains non-finite values")])
        if np.any(k < 0):
            raise ModelError([("stiffness", f"contains negative values (min {k.min():.4g} N/m); "
                                            "a mesh stiffness must be >= 0")])
        phase = _readonly(np.arange(k.size) / k.size)
        return cls(phase=phase, stiffness=k, mean=float(k.mean()),
                   peak_to_peak=float(k.max() - k.min()), method=method,
                   info=MappingProxyType(dict(info or {})))

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.stiffness.size)

    @property
    def minimum(self) -> float:
        return float(self.stiffness.min())

    @property
    def maximum(self) -> float:
        return float(self.stiffness.max())

    @property
    def fluctuation(self) -> float:
        """``peak_to_peak / mean`` [-]."""
        return self.peak_to_peak / self.mean if self.mean else 0.0

    def __call__(self, phase) -> np.ndarray:
        """Stiffness at arbitrary phases [N/m] (periodic linear interpolation)."""
        return np.interp(np.mod(np.asarray(phase, dtype=float), 1.0),
                         np.append(self.phase, 1.0), np.append(self.stiffness, self.stiffness[0]))

    def resample(self, n: int) -> "MeshStiffness":
        """The same waveform on ``n`` uniform phases (periodic linear interpolation)."""
        return MeshStiffness.from_samples(self(np.arange(n) / n), self.method, self.info)

    def fourier(self, harmonics: int) -> tuple[float, np.ndarray, np.ndarray]:
        """Fourier coefficients ``(mean, a, b)`` so that
        ``k(phi) ~ mean + sum_k a_k cos(2 pi k phi) + b_k sin(2 pi k phi)``, k = 1..harmonics."""
        n = self.n
        if harmonics >= n // 2:
            raise ModelError([("harmonics", f"must be below n/2 = {n // 2} for {n} samples")])
        c = np.fft.rfft(self.stiffness) / n
        return float(c[0].real), 2.0 * c[1:harmonics + 1].real, -2.0 * c[1:harmonics + 1].imag


def periodic_resample(phase, values, n: int) -> np.ndarray:
    """Resample samples ``values`` given at ``phase`` (cycles, any order, any range; taken
    modulo 1) onto ``n`` uniform phases ``k/n`` by periodic linear interpolation."""
    phase = np.asarray(phase, dtype=float).ravel()
    values = np.asarray(values, dtype=float).ravel()
    if phase.shape != values.shape or phase.size < 2:
        raise ModelError([("table", "phase and stiffness need the same length, at least 2 points")])
    if not (np.all(np.isfinite(phase)) and np.all(np.isfinite(values))):
        raise ModelError([("table", "contains non-finite values")])
    p = np.mod(phase, 1.0)
    order = np.argsort(p, kind="stable")
    p, v = p[order], values[order]
    keep = np.concatenate(([True], np.diff(p) > 1e-12))  # a point at 1.0 duplicates 0.0
    p, v = p[keep], v[keep]
    if p.size < 2:
        raise ModelError([("table", "needs at least 2 distinct phases in one cycle")])
    pe = np.concatenate((p[-1:] - 1.0, p, p[:1] + 1.0))
    ve = np.concatenate((v[-1:], v, v[:1]))
    return np.interp(np.arange(n) / n, pe, ve)
