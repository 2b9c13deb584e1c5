"""Backlash sequences per engagement (Ji & Li eqs. 13-14) and contact-loss check.

A :class:`BacklashSequence` holds one backlash value per mesh cycle ("engagement")
over one hunting period and repeats it, so b(t) is piecewise constant and periodic:

    b(t) = values[k mod N],  k = floor(t / T_mesh),  N = lcm(z1, z2)   # Ji & Li eq. 14

N = lcm(z1, z2) mesh cycles is the hunting period after which the same pinion
tooth meets the same gear tooth again.  All values are SI (m, s).

What "backlash" means here
--------------------------
Ji & Li uses the symmetric dead zone of eq. 13, f(Y) = Y - b for Y > b, 0 for
|Y| <= b, Y + b for Y < -b, with b = *half* the circumferential clearance along
the line of action.  Changing b from one engagement to the next moves the
working (drive-side) flank by the change in b.  Ji & Li draws b per engagement from
a normal distribution inside 0.522-0.851 mm (first stage) with a mesh stiffness of
4.5e9 N/m: consecutive values differ by ~0.1 mm while the static deflection is
F/k ~ 10-100 um, so every upward jump larger than F/k opens the mesh (contact loss
followed by impact).  :func:`contact_loss` detects this.  If the scatter is
meant to be a variation of the clearance only (tooth thickness), the drive flank
should stay put and only the coast-side clearance vary; then no loss of contact
follows from the sequence (see docs/theory/excitations.md).

Misprints in Ji & Li around eq. 14: t_h = 0.042388 s is ten mesh periods
(the first-stage mesh frequency is 235.91667 Hz, T = 4.2388 ms); 3192 = lcm(19,
168) is right for the first stage but the second stage (17/91 teeth) has lcm =
1547, not 1530; the first value printed, 0.513 mm, lies outside the stated band
0.522-0.851 mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import truncnorm

from torquesplit.errors import ModelError

__all__ = [
    "hunting_period_cycles",
    "BacklashSequence",
    "constant_backlash",
    "random_backlash",
    "backlash_from_tooth_thickness",
    "ContactLossReport",
    "contact_loss",
]


def hunting_period_cycles(teeth_1: int, teeth_2: int) -> int:
    """Number of mesh cycles after which the same tooth pair meets again: lcm(z1, z2)."""
    z1, z2 = int(teeth_1), int(teeth_2)
    if z1 < 1 or z2 < 1:
        raise ModelError("hunting_period_cycles: tooth numbers must be positive integers.")
    return math.lcm(z1, z2)


@dataclass(frozen=True)
class BacklashSequence:
    """Backlash per engagement over one hunting period, repeated periodically.

    values : backlash b_k [m] of engagement k = 0 .. N-1 (same meaning as b in the
        dead zone of Ji & Li eq. 13, i.e. half the clearance if the dead zone is
        symmetric).
    mesh_period : duration of one engagement T_mesh [s] (t_h of Ji & Li eq. 14).
    """

    values: np.ndarray
    mesh_period: float

    def __post_init__(self):
        v = np.atleast_1d(np.asarray(self.values, dtype=float)).copy()
        if v.ndim != 1 or v.size == 0:
            raise ModelError("BacklashSequence: values must be a non-empty 1-D array (metres).")
        if np.any(v < 0):
            raise ModelError("BacklashSequence: backlash values must be >= 0 m.")
        if not self.mesh_period > 0:
            raise ModelError("BacklashSequence: mesh_period must be positive (seconds).")
        v.setflags(write=False)
        object.__setattr__(self, "values", v)

    @property
    def n_engagements(self) -> int:
        return self.values.size

    @property
    def period(self) -> float:
        """Repetition period N * T_mesh [s] (T of Ji & Li eq. 14)."""
        return self.values.size * self.mesh_period

    def engagement_index(self, t):
        """Index k mod N of the engagement active at time ``t``."""
        k = np.floor(np.asarray(t, dtype=float) / self.mesh_period).astype(np.int64)
        return np.mod(k, self.values.size)

    def at(self, t):
        """b(t) [m], piecewise constant and periodic (Ji & Li eq. 14)."""
        return self.values[self.engagement_index(t)]

    def jumps(self) -> np.ndarray:
        """b_{k+1} - b_k for k = 0 .. N-1 (the last wraps to the first) [m]."""
        return np.roll(self.values, -1) - self.values


def constant_backlash(value: float, teeth_1: int, teeth_2: int, mesh_period: float) -> BacklashSequence:
    """The same backlash for every engagement over the hunting period."""
    n = hunting_period_cycles(teeth_1, teeth_2)
    return BacklashSequence(np.full(n, float(value)), mesh_period)


def random_backlash(
    lower: float,
    upper: float,
    teeth_1: int,
    teeth_2: int,
    mesh_period: float,
    rng: np.random.Generator | int | None,
    *,
    mean: float | None = None,
    std: float | None = None,
) -> BacklashSequence:
    """One backlash per engagement drawn from a normal law truncated to [lower, upper].

    Ji & Li (text above eq. 14): "randomly selected according to the normal
    distribution between 0.522 mm ~ 0.851 mm".  The seed gives neither mean nor
    standard deviation; defaults: mean = band centre, std = band width / 6 (the
    band is +/- 3 sigma).  Values are drawn by inverse CDF, so the result depends
    only on ``rng`` (a numpy Generator or an integer seed) and is reproducible.
    N = lcm(z1, z2) values are drawn and repeated.

    Examples
    --------
    >>> seq = random_backlash(0.522e-3, 0.851e-3, 19, 168, 4.2388e-3, 7)
    >>> seq.n_engagements
    3192
    """
    if not upper > lower:
        raise ModelError("random_backlash: upper must exceed lower (metres), e.g. 0.522e-3, 0.851e-3.")
    if lower < 0:
        raise ModelError("random_backlash: the tolerance band must be >= 0 m.")
    mu = 0.5 * (lower + upper) if mean is None else float(mean)
    sigma = (upper - lower) / 6.0 if std is None else float(std)
    if sigma <= 0:
        raise ModelError("random_backlash: std must be positive (metres).")
    n = hunting_period_cycles(teeth_1, teeth_2)
    gen = np.random.default_rng(rng)
    a, b = (lower - mu) / sigma, (upper - mu) / sigma
    u = gen.random(n)
    values = truncnorm.ppf(u, a, b, loc=mu, scale=sigma)
    return BacklashSequence(np.clip(values, lower, upper), mesh_period)


def backlash_from_tooth_thickness(
    nominal: float,
    thickness_deviations_1,
    thickness_deviations_2,
    mesh_period: float,
    pressure_angle: float,
) -> BacklashSequence:
    """Backlash per engagement from per-tooth thickness deviations of both gears.

    Engagement k pairs tooth k mod z1 with tooth k mod z2, so the sequence repeats
    after lcm(z1, z2) engagements by construction.  A thickness deviation Delta s
    (circular, at the circle of pressure angle alpha) changes the normal clearance
    by -Delta s cos(alpha); b being half the clearance:
    b_k = nominal - (Delta s1[k mod z1] + Delta s2[k mod z2]) cos(alpha) / 2.
    A physical alternative to independent draws per engagement.
    """
    s1 = np.asarray(thickness_deviations_1, dtype=float)
    s2 = np.asarray(thickness_deviations_2, dtype=float)
    n = hunting_period_cycles(s1.size, s2.size)
    k = np.arange(n)
    values = nominal - 0.5 * (s1[k % s1.size] + s2[k % s2.size]) * math.cos(pressure_angle)
    if np.any(values < 0):
        raise ModelError(
            "backlash_from_tooth_thickness: thickness deviations exceed the nominal "
            "backlash (negative clearance); reduce the deviations or raise the nominal."
        )
    return BacklashSequence(values, mesh_period)


@dataclass(frozen=True)
class ContactLossReport:
    """Result of :func:`contact_loss`.

    lost : bool per engagement transition k -> k+1 (wrapping), True when the jump
        in backlash exceeds the static deflection so that the working flanks
        separate.
    margin : static deflection minus the jump [m] per transition (negative = loss).
    static_deflection : F / k [m] per transition.
    """

    lost: np.ndarray
    margin: np.ndarray
    static_deflection: np.ndarray

    @property
    def any(self) -> bool:
        return bool(np.any(self.lost))

    @property
    def count(self) -> int:
        return int(np.count_nonzero(self.lost))

    @property
    def worst_margin(self) -> float:
        return float(np.min(self.margin))


def contact_loss(sequence: BacklashSequence, force, mesh_stiffness) -> ContactLossReport:
    """Detect loss of contact caused by backlash jumps in the symmetric dead zone.

    With Ji & Li eq. 13 the relative displacement during engagement k under the
    mesh force F is Y = b_k + F / k_m.  At the switch to engagement k+1 the
    displacement is continuous, so the deflection becomes
    F / k_m - (b_{k+1} - b_k); the mesh opens when b_{k+1} - b_k > F / k_m.

    Parameters
    ----------
    sequence : the backlash sequence.
    force : mesh force [N], scalar or one value per engagement (the force at the
        end of engagement k).
    mesh_stiffness : [N/m], scalar or one value per engagement.

    Examples
    --------
    >>> seq = BacklashSequence([0.6e-3, 0.7e-3, 0.65e-3], 4e-3)
    >>> contact_loss(seq, 2.0e5, 4.5e9).count
    1
    """
    n = sequence.n_engagements
    f = np.broadcast_to(np.asarray(force, dtype=float), (n,))
    k = np.broadcast_to(np.asarray(mesh_stiffness, dtype=float), (n,))
    if np.any(k <= 0):
        raise ModelError("contact_loss: mesh_stiffness must be positive (N/m).")
    deflection = np.maximum(f, 0.0) / k
    margin = deflection - sequence.jumps()
    return ContactLossReport(lost=margin < 0.0, margin=margin, static_deflection=deflection)
