"""ISO 1328-1:2013 flank tolerances per accuracy grade, and a Monte Carlo sampler.

Inputs and outputs are SI (module, diameter and face width in m; tolerances in
m).  The standard's formulas are written in mm (geometry) and um (tolerances); the
conversion happens inside :func:`_base_um` only.

Tolerance formulas (ISO 1328-1:2013, clause 5.3; grade A = 1 .. 11; the values
for grade A are the grade-5 values times the step factor sqrt(2)^(A-5), 5.2.2):

    f_pT  = (0.001 d + 0.4 m_n + 5)                 sqrt(2)^(A-5)   eq. (5)
    F_pT  = (0.002 d + 0.55 sqrt(d) + 0.7 m_n + 12) sqrt(2)^(A-5)   eq. (6)
    f_HaT = (0.4 m_n + 0.001 d + 4)                 sqrt(2)^(A-5)   eq. (7)
    f_faT = (0.55 m_n + 5)                          sqrt(2)^(A-5)   eq. (8)
    F_aT  = sqrt(f_HaT^2 + f_faT^2)                                  eq. (9)
    f_HbT = (0.05 sqrt(d) + 0.35 sqrt(b) + 4)       sqrt(2)^(A-5)   eq. (10)
    f_fbT = (0.07 sqrt(d) + 0.45 sqrt(b) + 4)       sqrt(2)^(A-5)   eq. (11)
    F_bT  = sqrt(f_HbT^2 + f_fbT^2)                                  eq. (12)
    F_rT  = 0.9 F_pT                    (runout; ISO 1328-1:2013 annex on runout)

d, m_n, b in mm, tolerances in um.  The grade-5 single pitch tolerance has the
constant term 5 um; "5 um grade-5 base with a sqrt(2) step per grade".
Rounding (5.2.3, optional here): > 10 um to 1 um, 5-10 um to 0.5 um, < 5 um to
0.1 um.  Scope (5.2.1): 5 <= z <= 1000, 5 mm <= d <= 15000 mm,
0.5 mm <= m_n <= 70 mm, 4 mm <= b <= 1200 mm, beta <= 45 deg.

The runout formula and its placement in the standard should be checked against
the document; the equation numbers (5)-(12) are those of ISO 1328-1:2013.

Liu et al. 2021 Table 2 ("grade 5", eccentricity = installation error): 8 um for the
34-tooth spur pinion (d = 119 mm), 12 um for the 107-tooth gear (d = 374.5 mm),
8 um for the 23-tooth double-helical pinion (d = 105.3 mm).  These are close to
half the grade-5 runout tolerance F_rT / 2 = 9.3, 11.6, 9.3 um (an eccentricity
e gives a runout of 2 e); see tests/gears/test_grades.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from torquesplit.errors import ModelError

__all__ = [
    "GRADES",
    "grade_factor",
    "round_tolerance",
    "single_pitch_tolerance",
    "total_cumulative_pitch_tolerance",
    "profile_slope_tolerance",
    "profile_form_tolerance",
    "profile_total_tolerance",
    "helix_slope_tolerance",
    "helix_form_tolerance",
    "helix_total_tolerance",
    "runout_tolerance",
    "FlankTolerances",
    "flank_tolerances",
    "GearErrorSample",
    "sample_gear_errors",
    "sample_within",
    "sample_pitch_deviations",
]

GRADES = tuple(range(1, 12))
_STEP = math.sqrt(2.0)


def _check_grade(grade: int) -> int:
    if int(grade) != grade or int(grade) not in GRADES:
        raise ModelError(f"ISO 1328-1:2013 accuracy grade must be an integer 1..11, got {grade!r}.")
    return int(grade)


def _check_scope(module: float, reference_diameter: float, face_width: float | None = None) -> None:
    m_mm, d_mm = module * 1e3, reference_diameter * 1e3
    problems = []
    if not 0.5 <= m_mm <= 70.0:
        problems.append(f"module {m_mm:g} mm outside 0.5-70 mm")
    if not 5.0 <= d_mm <= 15000.0:
        problems.append(f"reference diameter {d_mm:g} mm outside 5-15000 mm")
    if face_width is not None and not 4.0 <= face_width * 1e3 <= 1200.0:
        problems.append(f"face width {face_width * 1e3:g} mm outside 4-1200 mm")
    if problems:
        raise ModelError(
            "ISO 1328-1:2013 formulas apply only within their scope (5.2.1): "
            + "; ".join(problems)
            + ". Give SI values (metres), or agree tolerances outside the scope separately."
        )


def grade_factor(grade: int) -> float:
    """Step factor sqrt(2)^(A-5) between grade A and grade 5 (ISO 1328-1:2013, 5.2.2)."""
    return _STEP ** (_check_grade(grade) - 5)


def round_tolerance(value: float) -> float:
    """Round a tolerance [m] by ISO 1328-1:2013, 5.2.3 (half up).

    > 10 um: to 1 um; 5 - 10 um: to 0.5 um; < 5 um: to 0.1 um.
    """
    um = value * 1e6
    if um > 10.0:
        r = math.floor(um + 0.5)
    elif um >= 5.0:
        r = math.floor(2.0 * um + 0.5) / 2.0
    else:
        r = math.floor(10.0 * um + 0.5) / 10.0
    return r * 1e-6


def _base_um(kind: str, m: float, d: float, b: float | None) -> float:
    """Grade-5 value in um; m, d, b in mm."""
    if kind == "f_pT":
        return 0.001 * d + 0.4 * m + 5.0  # ISO 1328-1:2013 eq. (5)
    if kind == "F_pT":
        return 0.002 * d + 0.55 * math.sqrt(d) + 0.7 * m + 12.0  # ISO 1328-1:2013 eq. (6)
    if kind == "f_HaT":
        return 0.4 * m + 0.001 * d + 4.0  # ISO 1328-1:2013 eq. (7)
    if kind == "f_faT":
        return 0.55 * m + 5.0  # ISO 1328-1:2013 eq. (8)
    if kind == "f_HbT":
        return 0.05 * math.sqrt(d) + 0.35 * math.sqrt(b) + 4.0  # ISO 1328-1:2013 eq. (10)
    if kind == "f_fbT":
        return 0.07 * math.sqrt(d) + 0.45 * math.sqrt(b) + 4.0  # ISO 1328-1:2013 eq. (11)
    raise KeyError(kind)


def _tol(kind, grade, module, reference_diameter, face_width=None):
    _check_scope(module, reference_diameter, face_width)
    b_mm = None if face_width is None else face_width * 1e3
    return _base_um(kind, module * 1e3, reference_diameter * 1e3, b_mm) * grade_factor(grade) * 1e-6


def single_pitch_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """f_pT [m], ISO 1328-1:2013 eq. (5)."""
    return _tol("f_pT", grade, module, reference_diameter)


def total_cumulative_pitch_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """F_pT [m], ISO 1328-1:2013 eq. (6)."""
    return _tol("F_pT", grade, module, reference_diameter)


def profile_slope_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """f_HaT [m] (+/-), ISO 1328-1:2013 eq. (7)."""
    return _tol("f_HaT", grade, module, reference_diameter)


def profile_form_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """f_faT [m], ISO 1328-1:2013 eq. (8)."""
    return _tol("f_faT", grade, module, reference_diameter)


def profile_total_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """F_aT = sqrt(f_HaT^2 + f_faT^2) [m], ISO 1328-1:2013 eq. (9) (unrounded parts)."""
    return math.hypot(
        profile_slope_tolerance(grade, module, reference_diameter),
        profile_form_tolerance(grade, module, reference_diameter),
    )


def helix_slope_tolerance(grade: int, module: float, reference_diameter: float, face_width: float) -> float:
    """f_HbT [m] (+/-), ISO 1328-1:2013 eq. (10)."""
    return _tol("f_HbT", grade, module, reference_diameter, face_width)


def helix_form_tolerance(grade: int, module: float, reference_diameter: float, face_width: float) -> float:
    """f_fbT [m], ISO 1328-1:2013 eq. (11)."""
    return _tol("f_fbT", grade, module, reference_diameter, face_width)


def helix_total_tolerance(grade: int, module: float, reference_diameter: float, face_width: float) -> float:
    """F_bT = sqrt(f_HbT^2 + f_fbT^2) [m], ISO 1328-1:2013 eq. (12)."""
    return math.hypot(
        helix_slope_tolerance(grade, module, reference_diameter, face_width),
        helix_form_tolerance(grade, module, reference_diameter, face_width),
    )


def runout_tolerance(grade: int, module: float, reference_diameter: float) -> float:
    """F_rT = 0.9 F_pT [m] (ISO 1328-1:2013, runout annex)."""
    return 0.9 * total_cumulative_pitch_tolerance(grade, module, reference_diameter)


@dataclass(frozen=True)
class FlankTolerances:
    """ISO 1328-1:2013 tolerances of one gear [m]."""

    grade: int
    single_pitch: float  # f_pT, +/-
    total_cumulative_pitch: float  # F_pT
    profile_slope: float  # f_HaT, +/-
    profile_form: float  # f_faT
    profile_total: float  # F_aT
    helix_slope: float  # f_HbT, +/-
    helix_form: float  # f_fbT
    helix_total: float  # F_bT
    runout: float  # F_rT

    def rounded(self) -> "FlankTolerances":
        """Copy with every tolerance rounded by 5.2.3 (totals from unrounded parts)."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        return FlankTolerances(
            **{k: (v if k == "grade" else round_tolerance(v)) for k, v in values.items()}
        )


def flank_tolerances(
    grade: int, module: float, reference_diameter: float, face_width: float
) -> FlankTolerances:
    """All flank tolerances of a gear (unrounded; call ``.rounded()`` for 5.2.3).

    Examples
    --------
    >>> t = flank_tolerances(5, 3.5e-3, 0.119, 0.052)
    >>> round(t.single_pitch * 1e6, 3)
    6.519
    """
    g = _check_grade(grade)
    return FlankTolerances(
        grade=g,
        single_pitch=single_pitch_tolerance(g, module, reference_diameter),
        total_cumulative_pitch=total_cumulative_pitch_tolerance(g, module, reference_diameter),
        profile_slope=profile_slope_tolerance(g, module, reference_diameter),
        profile_form=profile_form_tolerance(g, module, reference_diameter),
        profile_total=profile_total_tolerance(g, module, reference_diameter),
        helix_slope=helix_slope_tolerance(g, module, reference_diameter, face_width),
        helix_form=helix_form_tolerance(g, module, reference_diameter, face_width),
        helix_total=helix_total_tolerance(g, module, reference_diameter, face_width),
        runout=runout_tolerance(g, module, reference_diameter),
    )


# --------------------------------------------------------------------------- #
# Monte Carlo sampling
# --------------------------------------------------------------------------- #
_DISTRIBUTIONS = ("uniform", "normal")


def sample_within(tolerance: float, size, rng, distribution: str = "normal", *, signed: bool = True):
    """Draw deviations inside a tolerance [m].

    signed=True: in [-T, +T] (deviations with a sign, e.g. single pitch, slopes).
    signed=False: in [0, T] (magnitudes, e.g. runout, total deviations).
    "uniform": uniform in the band.  "normal": normal N(0, (T/3)^2) truncated to
    the band (+/- 3 sigma = tolerance), folded to |x| for magnitudes (half-normal).
    Reproducible from ``rng`` (numpy Generator or int seed).
    """
    if distribution not in _DISTRIBUTIONS:
        raise ModelError(
            f"sample_within: distribution must be one of {_DISTRIBUTIONS}, got {distribution!r}."
        )
    if tolerance < 0:
        raise ModelError("sample_within: tolerance must be >= 0 m.")
    gen = np.random.default_rng(rng)
    u = gen.random(size)
    if tolerance == 0:
        return np.zeros_like(u)
    if distribution == "uniform":
        return (2.0 * u - 1.0) * tolerance if signed else u * tolerance
    from scipy.stats import truncnorm  # here: importing scipy.stats takes about 0.5 s

    sigma = tolerance / 3.0
    if signed:
        return truncnorm.ppf(u, -3.0, 3.0, loc=0.0, scale=sigma)
    return truncnorm.ppf(u, 0.0, 3.0, loc=0.0, scale=sigma)


@dataclass(frozen=True)
class GearErrorSample:
    """Errors of one gear for ``n`` Monte Carlo cases [m, rad]; arrays of shape (n,)."""

    eccentricity: np.ndarray  # runout / 2, >= 0
    eccentricity_phase: np.ndarray  # uniform in [0, 2 pi)
    runout: np.ndarray  # in [0, F_rT]
    single_pitch: np.ndarray  # in [-f_pT, f_pT]
    total_cumulative_pitch: np.ndarray  # in [0, F_pT]
    profile_slope: np.ndarray  # in [-f_HaT, f_HaT]
    helix_slope: np.ndarray  # in [-f_HbT, f_HbT]
    tolerances: FlankTolerances


def sample_gear_errors(
    grade: int,
    module: float,
    reference_diameter: float,
    face_width: float,
    n_samples: int,
    rng,
    distribution: str = "normal",
) -> GearErrorSample:
    """Draw gear errors for Monte Carlo from an ISO 1328-1:2013 grade.

    The eccentricity is half the drawn runout (a ring offset e gives a runout 2e),
    its phase is uniform.  Each quantity uses its own child generator spawned from
    ``rng``, so adding a field later does not change the others; case i depends
    only on ``rng`` and i, not on how cases are split among workers if the caller
    draws all n at once.

    Examples
    --------
    >>> s = sample_gear_errors(5, 3.5e-3, 0.119, 0.052, 1000, 42)
    >>> bool((s.runout <= s.tolerances.runout).all())
    True
    """
    tol = flank_tolerances(grade, module, reference_diameter, face_width)
    gen = np.random.default_rng(rng)
    children = gen.spawn(6)
    runout = sample_within(tol.runout, n_samples, children[0], distribution, signed=False)
    return GearErrorSample(
        eccentricity=0.5 * runout,
        eccentricity_phase=children[1].uniform(0.0, 2.0 * np.pi, n_samples),
        runout=runout,
        single_pitch=sample_within(tol.single_pitch, n_samples, children[2], distribution),
        total_cumulative_pitch=sample_within(
            tol.total_cumulative_pitch, n_samples, children[3], distribution, signed=False
        ),
        profile_slope=sample_within(tol.profile_slope, n_samples, children[4], distribution),
        helix_slope=sample_within(tol.helix_slope, n_samples, children[5], distribution),
        tolerances=tol,
    )


def sample_pitch_deviations(
    grade: int, module: float, reference_diameter: float, teeth: int, rng, distribution: str = "normal"
):
    """Single pitch deviations of all teeth of one gear and their cumulative sum [m].

    Single deviations are drawn inside +/- f_pT and made to close over the
    revolution (mean removed: the pitches must add up to 2 pi r).  If a single
    deviation then exceeds f_pT, or the cumulative range exceeds F_pT, the whole
    set is scaled down to fit.
    Returns (single, cumulative) arrays of length ``teeth``; ``cumulative`` can be
    passed to :func:`torquesplit.gears.errors.pitch_error_from_deviations`.
    """
    if int(teeth) < 5:
        raise ModelError("sample_pitch_deviations: ISO 1328-1 applies to gears with 5..1000 teeth.")
    f_pt = single_pitch_tolerance(grade, module, reference_diameter)
    f_p = total_cumulative_pitch_tolerance(grade, module, reference_diameter)
    single = sample_within(f_pt, int(teeth), rng, distribution)
    single = single - single.mean()
    cumulative = np.cumsum(single)
    span = cumulative.max() - cumulative.min()
    peak = np.abs(single).max()
    factor = min(1.0, f_p / span if span > 0 else 1.0, f_pt / peak if peak > 0 else 1.0)
    single = single * factor
    cumulative = np.cumsum(single)
    return single, cumulative
