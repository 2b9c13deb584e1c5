"""Involute geometry of cylindrical gear pairs (spur, helical, double-helical, internal).

Everything here is SI: metres, radians, rad/s, seconds.  No units library.

Conventions
-----------
* **Normal module and pressure angle.**  A gear is described in the normal section
  (``normal_module``, ``normal_pressure_angle``), as gears are cut with a standard
  basic rack; transverse quantities follow (ISO 21771:2007 §4).
* **Helix angle** is the reference helix angle; its sign gives the hand (+ right,
  - left) and is only carried along -- all geometry uses ``abs(helix_angle)``.
* **Double-helical gears** (``double_helical=True``): ``face_width`` is the face width
  of ONE helix.  The overlap ratio is computed for one helix (the two helices mesh in
  parallel, each with the full transverse and overlap ratio of its own half), and
  the total active face width is ``2 * face_width``.  This is the convention that
  reproduces the total contact ratio 3.42 quoted for the double-helical pair of
  Liu et al. 2021 (Table 1: z = 23/215, m_n = 3.965 mm, b = 50 mm, beta = 30 deg gives
  eps_alpha = 1.4145, eps_beta = 2.0070, eps_gamma = 3.4215; with b = 25 mm per
  helix it would be 2.42, and reading 3.965 mm as a transverse module gives 3.73).
* **Internal gears** (ring gears): give a *positive* tooth count and ``internal=True``
  (a negative tooth count is refused).  The profile-shift coefficient ``x`` follows
  the handbook convention in which ``x > 0`` moves the tooth profile (the cutting
  tool) *away from the gear axis* for external and internal gears alike; for a ring
  gear that enlarges both tip and root radius:
  ``r_a = r - m_n (h_a - x)``, ``r_f = r + m_n (h_f + x)``.
  ISO 21771 instead uses a signed tooth count and the opposite sign of ``x`` for
  internal gears; ``x_ISO = -x`` here.
* **Pair**: ``gear1`` is the pinion (external), ``gear2`` the wheel or the ring.
  Positions along the path of contact are signed distances ``s`` from the pitch
  point measured on the transverse line of action, positive in the direction the
  contact point travels when gear 1 drives (from the approach into the recess).
* No tip shortening or tip chamfer is applied: tip radii come from the addendum
  coefficients as given.

References
----------
ISO 21771:2007, Gears -- Cylindrical involute gears and gear pairs -- Concepts and
geometry.  ISO 6336-1:2019 (contact ratios, virtual tooth numbers).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from torquesplit.errors import ModelError, OptionTypeError

__all__ = [
    "GearGeometry",
    "PairGeometry",
    "involute",
    "inverse_involute",
    "mesh_period",
    "mesh_frequency",
]


def involute(angle):
    """Involute function ``inv(a) = tan(a) - a`` (ISO 21771 eq. (3.1)) [rad]."""
    return np.tan(angle) - angle


def inverse_involute(value: float) -> float:
    """Angle ``a`` in [0, pi/2) with ``tan(a) - a = value`` (Newton iteration) [rad]."""
    if value < 0.0:
        raise ModelError(
            [("", f"inverse involute of a negative value ({value:g}) is undefined; "
                  "check the profile shifts and the centre distance")]
        )
    if value == 0.0:
        return 0.0
    # start from the small-angle series inv(a) ~ a^3/3, then Newton on tan(a) - a
    a = min((3.0 * value) ** (1.0 / 3.0), 1.5)
    for _ in range(60):
        t = math.tan(a)
        f = t - a - value
        step = f / (t * t)
        a_new = a - step
        if a_new <= 0.0:
            a_new = 0.5 * a
        if a_new >= math.pi / 2:
            a_new = 0.5 * (a + math.pi / 2)
        if abs(a_new - a) < 1e-15:
            a = a_new
            break
        a = a_new
    return a


def mesh_period(teeth: int, angular_speed: float | None = None, *, rpm: float | None = None) -> float:
    """Tooth-mesh period of a gear with ``teeth`` turning at a given speed [s].

    ``T_m = 2 pi / (z omega)``.  Give exactly one of ``angular_speed`` [rad/s] or
    ``rpm`` [1/min].

    >>> round(mesh_period(20, rpm=3000), 6)
    0.001
    """
    omega = _angular_speed(angular_speed, rpm)
    if teeth <= 0:
        raise ModelError([("teeth", f"must be a positive tooth count, got {teeth}")])
    return 2.0 * math.pi / (teeth * abs(omega))


def mesh_frequency(teeth: int, angular_speed: float | None = None, *, rpm: float | None = None) -> float:
    """Tooth-mesh frequency ``z omega / (2 pi)`` [Hz]; same arguments as :func:`mesh_period`."""
    return 1.0 / mesh_period(teeth, angular_speed, rpm=rpm)


def _angular_speed(angular_speed: float | None, rpm: float | None) -> float:
    if (angular_speed is None) == (rpm is None):
        raise OptionTypeError(
            "give exactly one of angular_speed [rad/s] or rpm=[1/min], "
            "e.g. mesh_period(23, rpm=2423)"
        )
    omega = angular_speed if angular_speed is not None else rpm * 2.0 * math.pi / 60.0
    if omega == 0.0 or not math.isfinite(omega):
        raise ModelError([("speed", f"must be finite and non-zero, got {omega!r}")])
    return float(omega)


@dataclass(frozen=True)
class GearGeometry:
    """One cylindrical involute gear (SI units).

    Parameters
    ----------
    teeth : int
        Number of teeth ``z`` (positive; use ``internal=True`` for a ring gear).
    normal_module : float
        Normal module ``m_n`` [m].
    normal_pressure_angle : float
        Normal pressure angle ``alpha_n`` of the basic rack [rad].
    helix_angle : float
        Reference helix angle ``beta`` [rad]; 0 for spur.  Sign = hand.
    face_width : float
        Face width ``b`` [m]; for a double-helical gear the width of ONE helix.
    profile_shift : float
        Profile-shift coefficient ``x`` [-] (see module docstring for internal gears).
    addendum : float
        Addendum coefficient ``h_a* = h_aP / m_n`` [-], default 1.0.
    dedendum : float
        Dedendum coefficient ``h_f* = h_fP / m_n`` [-], default 1.25.
    internal : bool
        True for an internal (ring) gear.
    double_helical : bool
        True for a double-helical (herringbone) gear: two mirrored helices of
        ``face_width`` each.
    tool_tip_radius : float
        Tip-radius coefficient ``rho_fP / m_n`` of the generating rack [-], default
        0.38 (ISO 53 profile A); used for the root fillet angle of the
        potential-energy stiffness.

    Examples
    --------
    >>> import math
    >>> g = GearGeometry(20, 2e-3, math.radians(20), face_width=20e-3)
    >>> round(g.base_radius * 1e3, 5)
    18.79385
    """

    teeth: int
    normal_module: float
    normal_pressure_angle: float
    helix_angle: float = 0.0
    face_width: float = 0.0
    profile_shift: float = 0.0
    addendum: float = 1.0
    dedendum: float = 1.25
    internal: bool = False
    double_helical: bool = False
    tool_tip_radius: float = 0.38

    def __post_init__(self) -> None:
        issues = []
        if not isinstance(self.teeth, (int, np.integer)) or isinstance(self.teeth, bool):
            issues.append(("teeth", f"must be an integer, got {self.teeth!r}"))
        elif self.teeth < 0:
            issues.append(("teeth", f"is negative ({self.teeth}); give a positive tooth "
                                    "count and internal=True for a ring gear"))
        elif self.teeth < 3:
            issues.append(("teeth", f"must be at least 3, got {self.teeth}"))
        if not (self.normal_module > 0 and math.isfinite(self.normal_module)):
            issues.append(("normal_module", f"must be a positive length in metres, got {self.normal_module!r}"))
        elif self.normal_module > 0.1:
            # (a bare number typed in mm is below 100; '2 km' is not a slip of that kind)
            hint = (f"a bare number is read in metres: write '{self.normal_module:g} mm' (or "
                    f"{self.normal_module:g}e-3)" if self.normal_module < 100 else
                    "check the value and its unit (modules are 0.05-100 mm: write e.g. "
                    "'3 mm')")
            issues.append(("normal_module", f"{self.normal_module:g} m is implausibly "
                                            f"large; {hint}"))
        if not (0 < self.normal_pressure_angle < math.radians(45)):
            issues.append(("normal_pressure_angle", f"must lie in (0, 45 deg) and is in radians, "
                                                    f"got {self.normal_pressure_angle!r}"))
        if not (abs(self.helix_angle) < math.radians(60)):
            issues.append(("helix_angle", f"must be below 60 deg in magnitude and is in radians, "
                                          f"got {self.helix_angle!r}"))
        if not (self.face_width >= 0 and math.isfinite(self.face_width)):
            issues.append(("face_width", f"must be a non-negative length in metres, got {self.face_width!r}"))
        if self.addendum <= 0 or self.dedendum <= 0:
            issues.append(("addendum", "addendum and dedendum coefficients must be positive"))
        if self.double_helical and self.helix_angle == 0:
            issues.append(("double_helical", "a double-helical gear needs a non-zero helix_angle"))
        if self.tool_tip_radius < 0:
            issues.append(("tool_tip_radius", "must be non-negative"))
        if issues:
            raise ModelError(issues, source="GearGeometry")
        if not self.internal and self.tip_thickness <= 0.0:
            raise ModelError(
                [("addendum", f"the teeth are pointed: with profile shift x = "
                              f"{self.profile_shift:g} the tooth thickness at the tip circle "
                              f"is {1e3 * self.tip_thickness:.3g} mm (it must stay positive, "
                              f"usually above 0.2 m_n); change the profile shift towards 0")],
                source="GearGeometry",
            )
        if self.base_radius >= self.tip_radius and self.internal:
            raise ModelError(
                [("addendum", f"the tip circle of the ring gear (r_a = {self.tip_radius:.6g} m) lies "
                              f"inside its base circle (r_b = {self.base_radius:.6g} m); reduce the "
                              "addendum or increase the profile shift")],
                source="GearGeometry",
            )

    # -- basic transverse quantities (ISO 21771 §4) --------------------------------
    @cached_property
    def beta(self) -> float:
        """Magnitude of the reference helix angle [rad]."""
        return abs(self.helix_angle)

    @cached_property
    def transverse_module(self) -> float:
        """``m_t = m_n / cos(beta)`` [m] (ISO 21771 eq. (4.3))."""
        return self.normal_module / math.cos(self.beta)

    @cached_property
    def transverse_pressure_angle(self) -> float:
        """``alpha_t = atan(tan(alpha_n) / cos(beta))`` [rad] (ISO 21771 eq. (4.4))."""
        return math.atan(math.tan(self.normal_pressure_angle) / math.cos(self.beta))

    @cached_property
    def base_helix_angle(self) -> float:
        """``beta_b = atan(tan(beta) cos(alpha_t))`` [rad] (ISO 21771 eq. (4.12))."""
        return math.atan(math.tan(self.beta) * math.cos(self.transverse_pressure_angle))

    @cached_property
    def reference_radius(self) -> float:
        """``r = z m_t / 2`` [m]."""
        return 0.5 * self.teeth * self.transverse_module

    @cached_property
    def base_radius(self) -> float:
        """``r_b = r cos(alpha_t)`` [m]."""
        return self.reference_radius * math.cos(self.transverse_pressure_angle)

    @cached_property
    def tip_radius(self) -> float:
        """Tip radius [m]: ``r + m_n (h_a + x)``; internal ``r - m_n (h_a - x)``."""
        m = self.normal_module
        if self.internal:
            return self.reference_radius - m * (self.addendum - self.profile_shift)
        return self.reference_radius + m * (self.addendum + self.profile_shift)

    @cached_property
    def root_radius(self) -> float:
        """Root radius [m]: ``r - m_n (h_f - x)``; internal ``r + m_n (h_f + x)``."""
        m = self.normal_module
        if self.internal:
            return self.reference_radius + m * (self.dedendum + self.profile_shift)
        return self.reference_radius - m * (self.dedendum - self.profile_shift)

    @cached_property
    def transverse_base_pitch(self) -> float:
        """``p_bt = 2 pi r_b / z = pi m_t cos(alpha_t)`` [m]."""
        return 2.0 * math.pi * self.base_radius / self.teeth

    @cached_property
    def normal_base_pitch(self) -> float:
        """``p_bn = pi m_n cos(alpha_n)`` [m]."""
        return math.pi * self.normal_module * math.cos(self.normal_pressure_angle)

    @cached_property
    def total_face_width(self) -> float:
        """Active face width of the gear [m]: ``2 b`` if double-helical, else ``b``."""
        return 2.0 * self.face_width if self.double_helical else self.face_width

    @cached_property
    def virtual_teeth(self) -> float:
        """Virtual number of teeth ``z_n = z / (cos^2(beta_b) cos(beta))`` [-]
        (ISO 6336-1:2019, used by the single stiffness); infinite for internal gears."""
        if self.internal:
            return math.inf
        return self.teeth / (math.cos(self.base_helix_angle) ** 2 * math.cos(self.beta))

    @cached_property
    def base_half_angle(self) -> float:
        """Half the angle the tooth subtends at the base circle [rad] (external gears).

        ``psi_b = (pi/2 + 2 x tan(alpha_n)) / z + inv(alpha_t)``: the transverse
        reference tooth thickness ``s_t = m_t (pi/2 + 2 x tan(alpha_n))`` (ISO 21771
        eq. (4.29), no backlash allowance) carried down the involute to the base circle.
        This is ``alpha_2`` of Yang & Lin (1987) and Tian (2004).
        """
        if self.internal:
            raise ModelError([("internal", "the tooth half angle is defined for external gears only")])
        return ((math.pi / 2 + 2.0 * self.profile_shift * math.tan(self.normal_pressure_angle))
                / self.teeth + float(involute(self.transverse_pressure_angle)))

    @cached_property
    def tip_thickness(self) -> float:
        """Transverse tooth thickness on the tip circle [m] (external gears; negative where
        the flanks cross below the tip: a pointed tooth).

        ``s_at = 2 r_a (psi_b - inv(alpha_at))`` with ``cos(alpha_at) = r_b / r_a`` and
        ``psi_b`` the half angle at the base circle (:attr:`base_half_angle`; ISO 21771
        tooth thickness carried along the involute)."""
        ra, rb = self.tip_radius, self.base_radius
        if ra <= rb:
            return 2.0 * ra * self.base_half_angle
        return 2.0 * ra * (self.base_half_angle - float(involute(math.acos(rb / ra))))

    @cached_property
    def root_half_angle(self) -> float:
        """Half angle ``theta_f`` of the tooth at the root circle [rad] (external gears).

        Angular position of the point where the root fillet, generated by the rounded
        tip of the basic rack (tip radius ``rho = tool_tip_radius * m_n``), meets the
        root circle, measured from the tooth centreline.  In the transverse plane the
        centre of the tool tip round sits at depth ``h_fP - rho`` below the generating
        line and ``(h_fP - x m_n - rho) tan(alpha_t) + rho / cos(alpha_t)`` beyond the
        half tooth thickness; dividing by the reference radius and using
        ``s_t = m_t (pi/2 + 2 x tan(alpha_n))`` the profile shift cancels:
        ``theta_f = [pi m_t/4 + (h_fP - rho) tan(alpha_t) + rho / cos(alpha_t)] / r``.
        Used for ``S_f`` of the fillet-foundation term (Sainsot et al. 2004).
        """
        if self.internal:
            raise ModelError([("internal", "the root half angle is defined for external gears only")])
        at = self.transverse_pressure_angle
        rho = self.tool_tip_radius * self.normal_module
        h_f = self.dedendum * self.normal_module
        num = (math.pi * self.transverse_module / 4.0 + (h_f - rho) * math.tan(at)
               + rho / math.cos(at))
        return num / self.reference_radius


@dataclass(frozen=True)
class PairGeometry:
    """A meshing pair of cylindrical involute gears (SI units).

    ``gear1`` is the pinion (external); ``gear2`` the wheel, or a ring gear if
    ``gear2.internal``.  Both must share normal module, normal pressure angle and
    helix-angle magnitude.  If ``center_distance`` is None the operating centre
    distance follows from the profile shifts (zero backlash); otherwise the working
    pressure angle follows from the given centre distance.

    Examples
    --------
    >>> import math
    >>> a = math.radians(20)
    >>> p = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
    ...                  GearGeometry(40, 2e-3, a, face_width=0.02))
    >>> round(p.transverse_contact_ratio, 4)
    1.6352
    """

    gear1: GearGeometry
    gear2: GearGeometry
    center_distance: float | None = None

    def __post_init__(self) -> None:
        g1, g2 = self.gear1, self.gear2
        issues = []
        if g1.internal:
            issues.append(("gear1.internal", "the pinion (gear1) must be an external gear; "
                                             "put the ring gear second"))
        if not math.isclose(g1.normal_module, g2.normal_module, rel_tol=1e-9):
            issues.append(("gear2.normal_module", f"{g2.normal_module} differs from the pinion's "
                                                  f"{g1.normal_module}; meshing gears share the module"))
        if not math.isclose(g1.normal_pressure_angle, g2.normal_pressure_angle, rel_tol=1e-9):
            issues.append(("gear2.normal_pressure_angle", "differs from the pinion's; meshing gears "
                                                          "share the normal pressure angle"))
        if not math.isclose(g1.beta, g2.beta, rel_tol=1e-9, abs_tol=1e-12):
            issues.append(("gear2.helix_angle", "magnitude differs from the pinion's; meshing "
                                                "helical gears share the helix angle"))
        if g1.double_helical != g2.double_helical:
            issues.append(("gear2.double_helical", "both gears of a double-helical pair must be "
                                                   "double-helical"))
        if g2.internal and g2.teeth <= g1.teeth:
            issues.append(("gear2.teeth", "a ring gear needs more teeth than its pinion"))
        if self.center_distance is not None and not (self.center_distance > 0):
            issues.append(("center_distance", f"must be a positive length in metres, got "
                                              f"{self.center_distance!r}"))
        if issues:
            raise ModelError(issues, source="PairGeometry")
        if self.center_distance is not None:
            c = self.reference_center_distance * math.cos(g1.transverse_pressure_angle) / self.center_distance
            if not (0 < c < 1):
                raise ModelError([("center_distance", f"{self.center_distance:.6g} m cannot be reached "
                                   "with these gears (no real working pressure angle)")],
                                 source="PairGeometry")
        self._check_interference()

    # -- sign helpers ----------------------------------------------------------------
    @property
    def is_internal(self) -> bool:
        """True if gear 2 is a ring gear."""
        return self.gear2.internal

    @property
    def _sigma(self) -> int:
        return -1 if self.is_internal else 1

    @property
    def gear_ratio(self) -> float:
        """``u = z2 / z1`` [-]."""
        return self.gear2.teeth / self.gear1.teeth

    @property
    def transverse_pressure_angle(self) -> float:
        """Reference transverse pressure angle ``alpha_t`` [rad]."""
        return self.gear1.transverse_pressure_angle

    @property
    def base_helix_angle(self) -> float:
        """Base helix angle ``beta_b`` [rad]."""
        return self.gear1.base_helix_angle

    @property
    def face_width(self) -> float:
        """Common face width [m] (of one helix for double-helical pairs): the smaller of the two."""
        return min(self.gear1.face_width, self.gear2.face_width)

    @property
    def total_face_width(self) -> float:
        """Active face width of the pair [m]: ``2 b`` for double-helical, else ``b``."""
        return 2.0 * self.face_width if self.gear1.double_helical else self.face_width

    @property
    def double_helical(self) -> bool:
        return self.gear1.double_helical

    @property
    def reference_center_distance(self) -> float:
        """``a = r2 + r1`` (external) or ``r2 - r1`` (internal) [m]."""
        return self.gear2.reference_radius + self._sigma * self.gear1.reference_radius

    @cached_property
    def working_pressure_angle(self) -> float:
        """Working transverse pressure angle ``alpha_wt`` [rad].

        From the profile shifts (ISO 21771 eq. (5.6))::

            inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2)

        with, for an internal pair, ``z2 -> -z2`` and ``x2 -> -x2`` (this module's
        sign convention), i.e. ``2 tan(alpha_n) (x2 - x1) / (z2 - z1)``.  If a centre
        distance is given: ``cos(alpha_wt) = a cos(alpha_t) / a_w``.
        """
        at = self.transverse_pressure_angle
        if self.center_distance is not None:
            return math.acos(self.reference_center_distance * math.cos(at) / self.center_distance)
        s = self._sigma
        x_sum = self.gear1.profile_shift + s * self.gear2.profile_shift
        z_sum = self.gear1.teeth + s * self.gear2.teeth
        inv_wt = float(involute(at)) + 2.0 * math.tan(self.gear1.normal_pressure_angle) * x_sum / z_sum
        return inverse_involute(inv_wt)

    @cached_property
    def operating_center_distance(self) -> float:
        """Operating centre distance ``a_w = a cos(alpha_t) / cos(alpha_wt)`` [m] (ISO 21771 eq. (5.8))."""
        if self.center_distance is not None:
            return float(self.center_distance)
        return (self.reference_center_distance * math.cos(self.transverse_pressure_angle)
                / math.cos(self.working_pressure_angle))

    @property
    def working_pitch_radii(self) -> tuple[float, float]:
        """Working pitch radii ``r_w = r_b / cos(alpha_wt)`` of gear 1 and gear 2 [m]."""
        c = math.cos(self.working_pressure_angle)
        return self.gear1.base_radius / c, self.gear2.base_radius / c

    @property
    def base_pitch(self) -> float:
        """Transverse base pitch ``p_bt`` [m] (spacing of tooth pairs along the line of action)."""
        return self.gear1.transverse_base_pitch

    @property
    def normal_base_pitch(self) -> float:
        """Normal base pitch ``p_bn = p_bt cos(beta_b)`` [m]."""
        return self.gear1.normal_base_pitch

    # -- path of contact ----------------------------------------------------------------
    @cached_property
    def _tangent_lengths(self) -> tuple[float, float, float, float]:
        """(distance T1->pitch point, T2->pitch point, T1->pinion tip point,
        T2->wheel tip point) along the transverse line of action [m]."""
        g1, g2 = self.gear1, self.gear2
        t = math.tan(self.working_pressure_angle)
        return (g1.base_radius * t, g2.base_radius * t,
                math.sqrt(g1.tip_radius ** 2 - g1.base_radius ** 2),
                math.sqrt(g2.tip_radius ** 2 - g2.base_radius ** 2))

    @property
    def path_start(self) -> float:
        """Start of active contact A, signed distance from the pitch point [m] (negative).

        The wheel tip meets the line of action at ``sqrt(r_a2^2 - r_b2^2)`` from the
        wheel's tangent point T2; for an external pair T2 lies beyond the pitch point
        (``s_A = r_b2 tan(alpha_wt) - sqrt(r_a2^2 - r_b2^2)`` with a minus sign), for an
        internal pair on the same side as T1 (``s_A = sqrt(r_a2^2 - r_b2^2) - r_b2 tan(alpha_wt)``).
        """
        p1, p2, e1, e2 = self._tangent_lengths
        if self.is_internal:
            return e2 - p2
        return -(e2 - p2)

    @property
    def path_end(self) -> float:
        """End of active contact E (pinion tip), signed distance from the pitch point [m]:
        ``s_E = sqrt(r_a1^2 - r_b1^2) - r_b1 tan(alpha_wt)``."""
        p1, p2, e1, e2 = self._tangent_lengths
        return e1 - p1

    @property
    def path_length(self) -> float:
        """Length of path of contact ``g_alpha = s_E - s_A`` [m] (ISO 6336-1 / ISO 21771 eq. (5.19))."""
        return self.path_end - self.path_start

    @property
    def transverse_contact_ratio(self) -> float:
        """``eps_alpha = g_alpha / p_bt`` [-]."""
        return self.path_length / self.base_pitch

    @property
    def overlap_contact_ratio(self) -> float:
        """``eps_beta = b sin(beta) / (pi m_n)`` [-]; for double-helical pairs with ``b``
        the face width of ONE helix (see module docstring)."""
        g = self.gear1
        return self.face_width * math.sin(g.beta) / (math.pi * g.normal_module)

    @property
    def total_contact_ratio(self) -> float:
        """``eps_gamma = eps_alpha + eps_beta`` [-]."""
        return self.transverse_contact_ratio + self.overlap_contact_ratio

    def _check_interference(self) -> None:
        p1, p2, e1, e2 = self._tangent_lengths
        issues = []
        if self.path_start < -p1 - 1e-12:
            issues.append(("gear2.addendum", "the wheel tip reaches past the pinion's base-circle tangent "
                                             "point (involute interference); increase the pinion profile "
                                             "shift or reduce the wheel addendum"))
        if not self.is_internal and self.path_end > p2 + 1e-12:
            issues.append(("gear1.addendum", "the pinion tip reaches past the wheel's base-circle tangent "
                                             "point (involute interference); increase the wheel profile "
                                             "shift or reduce the pinion addendum"))
        if self.path_length <= 0:
            issues.append(("addendum", "the tip circles do not overlap on the line of action: no contact"))
        if issues:
            raise ModelError(issues, source="PairGeometry")

    def contact_positions(self, n: int = 101) -> np.ndarray:
        """``n`` equally spaced positions ``s`` from start to end of active contact [m]."""
        return np.linspace(self.path_start, self.path_end, n)

    def roll_distances(self, s) -> tuple[np.ndarray, np.ndarray]:
        """Distances from the base-circle tangent points T1, T2 to the contact point [m].

        ``rho1 = r_b1 tan(alpha_wt) + s``; ``rho2 = r_b2 tan(alpha_wt) - s`` (external) or
        ``r_b2 tan(alpha_wt) + s`` (internal).  Always positive inside the path.
        """
        s = np.asarray(s, dtype=float)
        p1, p2, _, _ = self._tangent_lengths
        return p1 + s, (p2 + s) if self.is_internal else (p2 - s)

    def curvature_radii(self, s, normal: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Radii of curvature of both flanks at positions ``s`` along the path [m].

        Transverse plane: the involute's radius of curvature is its distance from the
        base-circle tangent point (ISO 21771 §4.3); the ring gear's flank is concave and
        is returned negative.  With ``normal=True`` the normal-plane radii
        ``rho_n = rho_t / cos(beta_b)`` are returned (ISO 6336-2 / Niemann).
        The reduced radius is ``rho1 rho2 / (rho1 + rho2)`` with these signs.
        """
        r1, r2 = self.roll_distances(s)
        if self.is_internal:
            r2 = -r2
        if normal:
            c = math.cos(self.base_helix_angle)
            return r1 / c, r2 / c
        return r1, r2

    def surface_velocities(self, s, pinion_speed: float) -> tuple[np.ndarray, np.ndarray]:
        """Rolling (entrainment) and sliding velocity at positions ``s`` [m/s].

        With tangential flank velocities ``v1 = omega1 rho1`` and
        ``v2 = omega2 |rho2|``, ``omega2 = omega1 r_b1 / r_b2`` (both measured
        perpendicular to the line of action in the transverse plane):
        entrainment ``u = (v1 + v2) / 2`` and sliding ``v_s = v1 - v2``, which is
        ``omega1 s (1 + z1/z2)`` for an external and ``omega1 s (1 - z1/z2)`` for an
        internal pair (zero at the pitch point, positive in the recess).
        ``pinion_speed`` is ``omega1`` [rad/s]; its sign is kept.
        """
        r1, r2 = self.roll_distances(s)
        w1 = float(pinion_speed)
        w2 = w1 * self.gear1.base_radius / self.gear2.base_radius
        v1 = w1 * r1
        v2 = w2 * r2
        return 0.5 * (v1 + v2), v1 - v2

    def mesh_period(self, pinion_speed: float) -> float:
        """Tooth-mesh period ``2 pi / (z1 |omega1|)`` [s] for pinion speed [rad/s]."""
        return mesh_period(self.gear1.teeth, pinion_speed)

    def mesh_frequency(self, pinion_speed: float) -> float:
        """Tooth-mesh frequency ``z1 |omega1| / (2 pi)`` [Hz] for pinion speed [rad/s]."""
        return 1.0 / self.mesh_period(pinion_speed)
