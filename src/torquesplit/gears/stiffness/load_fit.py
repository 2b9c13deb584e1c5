"""Load-dependent mesh stiffness from three loaded transmission-error levels
(Dong et al. 2021 §5, eqs. 17-18).

Dong et al. 2021 splits the loaded angular transmission error of a pair at each mesh
position into a geometric part (constant), a bending part (linear in torque) and a
Hertzian contact part (torque to the power 2/3)::

    dphi(T) = sign(T) (a + b |T| + c |T|^(2/3))                      (Dong et al. 2021 eq. 17)

fits ``a, b, c`` from LTCA results at 0.1, 0.5 and 0.9 of the nominal torque, and
turns it into a mesh stiffness::

    k(T) = T / (r_b^2 cos(alpha_n) cos(beta)) / dphi(T)                (Dong et al. 2021 eq. 18)

Note on eq. 17: the paper prints ``(T/|T|)(a + b T + c T^(2/3))``; for a negative
torque that changes the sign of the bending term only.  The physically consistent
odd function ``sign(T)(a + b|T| + c|T|^(2/3))`` is used.  Note on eq. 18: this is a
secant stiffness (load over total deflection, including the load-independent part
``a``); it is what the paper uses.

Units: torque [N m], angle [rad], base radius [m], stiffness [N/m].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.stiffness.result import MeshStiffness, periodic_resample

__all__ = ["LoadDeflectionFit", "fit_load_deflection", "load_fit_stiffness"]


@dataclass(frozen=True)
class LoadDeflectionFit:
    """Coefficients of Dong et al. 2021 eq. 17, one set per mesh position (or a single set).

    ``a`` [rad], ``b`` [rad/(N m)], ``c`` [rad/(N m)^(2/3)]; arrays of shape (p,) for
    p mesh positions uniformly spread over one mesh cycle, or scalars.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray

    def angular_deflection(self, torque: float) -> np.ndarray:
        """``dphi(T) = sign(T)(a + b|T| + c|T|^(2/3))`` [rad] (Dong et al. 2021 eq. 17)."""
        t = abs(float(torque))
        # Dong et al. 2021 eq. 17 (odd-symmetric form, see module docstring)
        return np.sign(torque) * (self.a + self.b * t + self.c * t ** (2.0 / 3.0))

    def stiffness(self, torque: float, base_radius: float, normal_pressure_angle: float,
                  helix_angle: float = 0.0) -> np.ndarray:
        """Mesh stiffness at torque ``T`` [N/m] (Dong et al. 2021 eq. 18).

        ``k = T / (r_b^2 cos(alpha_n) cos(beta)) / dphi(T)`` with ``r_b`` the base
        radius of the gear to which ``T`` and ``dphi`` refer.
        """
        if torque == 0:
            raise ModelError([("torque", "the secant stiffness of Dong et al. 2021 eq. 18 needs a non-zero torque")])
        dphi = self.angular_deflection(torque)
        if np.any(dphi * np.sign(torque) <= 0):
            raise ModelError([("torque", "the fitted deflection is not positive at this torque; "
                                         "evaluate within the fitted load range")])
        # Dong et al. 2021 eq. 18
        return (torque / (base_radius ** 2 * np.cos(normal_pressure_angle) * np.cos(helix_angle))
                / dphi)


def fit_load_deflection(torques, deflections) -> LoadDeflectionFit:
    """Fit ``a, b, c`` of Dong et al. 2021 eq. 17 to loaded transmission errors.

    Parameters
    ----------
    torques : array_like, shape (m,)
        Torques [N m], at least three distinct magnitudes (the paper: 0.1, 0.5, 0.9
        of the nominal torque), all of one sign.
    deflections : array_like, shape (m,) or (m, p)
        Angular transmission error [rad] at each torque, optionally at ``p`` mesh
        positions.  Exactly solved for three torques, least squares for more.
    """
    t = np.asarray(torques, dtype=float)
    d = np.asarray(deflections, dtype=float)
    if t.ndim != 1 or t.size < 3 or np.unique(np.abs(t)).size < 3:
        raise ModelError([("torques", "need at least three distinct load levels (e.g. 0.1, 0.5, 0.9 T)")])
    if np.any(t == 0) or not (np.all(t > 0) or np.all(t < 0)):
        raise ModelError([("torques", "must be non-zero and of one sign")])
    if d.shape[0] != t.size:
        raise ModelError([("deflections", f"need one row per torque ({t.size}), got shape {d.shape}")])
    s = np.sign(t[0])
    ta = np.abs(t)
    A = np.column_stack((np.ones_like(ta), ta, ta ** (2.0 / 3.0)))
    rhs = s * d  # sign(T) dphi = a + b|T| + c|T|^(2/3)
    coef, *_ = np.linalg.lstsq(A, rhs, rcond=None)
    return LoadDeflectionFit(a=coef[0], b=coef[1], c=coef[2])


def load_fit_stiffness(fit: LoadDeflectionFit, torque: float, base_radius: float,
                       normal_pressure_angle: float, helix_angle: float = 0.0,
                       n: int = 256) -> MeshStiffness:
    """Mesh stiffness over one mesh cycle at ``torque`` from a per-position fit (Dong et al. 2021
    eqs. 17-18), resampled periodically onto ``n`` phases [N/m].

    The ``p`` positions of the fit are taken as uniformly spaced over one mesh cycle,
    the first at phase 0.
    """
    k = np.atleast_1d(fit.stiffness(torque, base_radius, normal_pressure_angle, helix_angle))
    if k.size == 1:
        samples = np.full(n, float(k[0]))
    else:
        samples = periodic_resample(np.arange(k.size) / k.size, k, n)
    return MeshStiffness.from_samples(samples, "load_fit", {"torque": float(torque)})
