"""Tooth friction: EHL friction coefficient, sliding direction, friction arms.

Everything here takes and returns plain SI floats or numpy arrays
(m, rad, rad/s, N, Pa, Pa s).  The friction-coefficient regression of Xu et al.
is the only place where other units appear, and only inside
:func:`xu_friction_coefficient`, which converts at its entry.

Geometry convention (transverse plane)
--------------------------------------
``N1`` and ``N2`` are the points where the line of action touches the base
circles of gear 1 and gear 2; ``line_length = |N1 N2| = sqrt(a^2 - (rb1 + rb2)^2)``.
A contact point is described by its distance ``s`` from ``N1`` along the line of
action, so that the involute radii of curvature are ``rho1 = s`` and
``rho2 = line_length - s``.  The pitch point is at ``s_P = line_length * rb1 /
(rb1 + rb2)``.

Sign convention for friction
----------------------------
``t`` is the common tangent at the contact, oriented along the rolling
(entrainment) velocity of both surfaces.  ``friction_force`` is the force that
gear 1 exerts on gear 2 along ``t``; gear 1 receives the opposite force.  It
equals ``sign(u1 - u2) * mu * F`` (``u_i = omega_i * rho_i`` rolling velocities), so
it changes sign at the pitch point.  ``moment_1`` / ``moment_2`` are the friction
moments about each gear's axis, positive in that gear's own direction of
rotation: ``moment_1 = -friction_force * rho1``, ``moment_2 = +friction_force * rho2``.
With this convention the friction power ``moment_1*omega1 + moment_2*omega2 =
-mu F |u1 - u2|`` is never positive.

Sources
-------
- Xu H., Kahraman A., Anderson N.E., Maddock D.G., "A model to predict friction
  coefficients and mechanical efficiency of spur and helical gears",
  J. Mech. Des. 129 (2007) 58-68 ("Xu et al. 2007"); as used in Jin et al. 2019 eq. 6.
- Jin et al. 2019 eqs. 14-18: friction stiffness and friction torque coefficient, spur
  and helical (slices).
- Hertz line contact: Johnson, Contact Mechanics (1985), eq. 4.45.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from torquesplit.errors import ModelError

__all__ = [
    "XU_COEFFICIENTS",
    "contact_modulus",
    "equivalent_radius",
    "hertz_max_pressure",
    "rolling_velocities",
    "entrainment_velocity",
    "sliding_velocity",
    "slide_to_roll_ratio",
    "xu_friction_coefficient",
    "friction_direction",
    "friction_arms",
    "friction_stiffness",
    "friction_torque_coefficient",
    "MeshFrictionTable",
    "mesh_friction_table",
]

# Xu et al. 2007, Table 3 (full precision).  Jin et al. 2019 Table 1 prints them
# truncated to 4 decimals (e.g. b1 = -8.9164 instead of -8.916465).
XU_COEFFICIENTS = (
    -8.916465,  # b1
    1.03303,  # b2
    1.036077,  # b3
    -0.354068,  # b4
    2.812084,  # b5
    -0.100601,  # b6
    0.752755,  # b7
    -0.390958,  # b8
    0.620305,  # b9
)


# --------------------------------------------------------------------------- #
# contact mechanics and kinematics
# --------------------------------------------------------------------------- #
def contact_modulus(youngs_modulus_1, poisson_ratio_1, youngs_modulus_2, poisson_ratio_2):
    """Contact modulus E* [Pa], 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2.

    # Johnson (1985) eq. 4.22
    """
    return 1.0 / (
        (1.0 - poisson_ratio_1**2) / youngs_modulus_1
        + (1.0 - poisson_ratio_2**2) / youngs_modulus_2
    )


def equivalent_radius(radius_1, radius_2):
    """Equivalent radius of curvature R = r1 r2 / (r1 + r2) [m] of two convex bodies."""
    radius_1 = np.asarray(radius_1, dtype=float)
    radius_2 = np.asarray(radius_2, dtype=float)
    return radius_1 * radius_2 / (radius_1 + radius_2)


def hertz_max_pressure(
    load_per_width,
    radius_1,
    radius_2,
    youngs_modulus_1=206e9,
    poisson_ratio_1=0.3,
    youngs_modulus_2=206e9,
    poisson_ratio_2=0.3,
):
    """Maximum Hertz pressure of a line contact [Pa].

    p_h = sqrt(w E* / (pi R)), with w the normal load per unit contact length
    [N/m], R the equivalent radius and E* the contact modulus.

    # Johnson (1985) eq. 4.45 (p0 = sqrt(P E*/(pi R)))

    Examples
    --------
    >>> round(float(hertz_max_pressure(260e3, 0.02, 0.065)) / 1e9, 2)
    0.78
    """
    e_star = contact_modulus(youngs_modulus_1, poisson_ratio_1, youngs_modulus_2, poisson_ratio_2)
    radius = equivalent_radius(radius_1, radius_2)
    w = np.maximum(np.asarray(load_per_width, dtype=float), 0.0)
    return np.sqrt(w * e_star / (np.pi * radius))


def rolling_velocities(position, line_length, omega_1, omega_2):
    """Rolling (tangential) surface velocities u1, u2 [m/s] at a contact point.

    u_i = omega_i * rho_i with rho1 = s and rho2 = line_length - s (involute
    radii of curvature, see module docstring).  ``omega_i`` are magnitudes.
    """
    s = np.asarray(position, dtype=float)
    return abs(omega_1) * s, abs(omega_2) * (line_length - s)


def entrainment_velocity(u1, u2):
    """Entrainment (mean rolling) velocity V_e = (u1 + u2) / 2 [m/s].

    Xu et al. 2007 call V_e the entraining velocity; we take the mean rolling
    velocity, the usual EHL definition.  Taking the sum u1 + u2 instead would lower
    mu by the factor 2**b6 = 0.933.
    """
    return 0.5 * (np.asarray(u1, dtype=float) + np.asarray(u2, dtype=float))


def sliding_velocity(u1, u2):
    """Sliding velocity u1 - u2 [m/s] (signed: negative before the pitch point when
    gear 1 is the smaller radius of curvature side)."""
    return np.asarray(u1, dtype=float) - np.asarray(u2, dtype=float)


def slide_to_roll_ratio(u1, u2):
    """Slide-to-roll ratio SR = (u1 - u2) / V_e = 2 (u1 - u2) / (u1 + u2).

    # Xu et al. 2007 (SR = sliding velocity / entraining velocity)
    """
    u1 = np.asarray(u1, dtype=float)
    u2 = np.asarray(u2, dtype=float)
    return 2.0 * (u1 - u2) / (u1 + u2)


def xu_friction_coefficient(
    slide_to_roll,
    hertz_pressure,
    entrainment_velocity,
    viscosity,
    radius,
    roughness,
):
    """EHL friction coefficient of Xu et al. 2007 (Jin et al. 2019 eq. 6).

    mu = exp(f) * P_h^b2 * |SR|^b3 * V_e^b6 * nu_0^b7 * R^b8
    f  = b1 + b4 |SR| P_h log10(nu_0) + b5 exp(-|SR| P_h log10(nu_0)) + b9 exp(S)

    Parameters (all SI)
    -------------------
    slide_to_roll : SR [-]
    hertz_pressure : maximum Hertz pressure P_h [Pa]
    entrainment_velocity : V_e [m/s]
    viscosity : dynamic viscosity of the oil at inlet temperature, ambient
        pressure, nu_0 [Pa s]
    radius : equivalent radius of curvature R [m] (normal plane for helical teeth)
    roughness : composite RMS surface roughness S [m]

    Unit convention of the regression (established in
    tests/gears/test_friction.py::test_unit_convention): P_h in GPa, V_e in m/s,
    nu_0 in cP (= mPa s), R in m, S in um.  With these, mu at Jin et al. 2019's split-stage
    operating point (nu_0 = 5-20 mPa s, S = 0.3-0.9 um) peaks at 0.015-0.045
    towards the ends of the path of contact,
    inside the 0.02-0.08 range reported for lubricated steel gears; R in mm gives
    mu ~ 1e-3 and P_h in MPa makes mu vanish (< 1e-40) where sliding is
    largest, both unphysical.

    Jin et al. 2019 prints the exponents of V_e, nu_0 and R as b4, b5, b6; the
    regression uses b6, b7, b8 (b4 and b5 belong to f only).  mu -> 0 at the pitch
    point (SR = 0), a property of the regression.

    Examples
    --------
    >>> mu = xu_friction_coefficient(0.6, 1.0e9, 15.0, 8e-3, 0.012, 0.9e-6)
    >>> round(float(mu), 3)
    0.032
    """
    b1, b2, b3, b4, b5, b6, b7, b8, b9 = XU_COEFFICIENTS
    sr = np.abs(np.asarray(slide_to_roll, dtype=float))
    ph = np.asarray(hertz_pressure, dtype=float) * 1e-9  # Pa -> GPa
    ve = np.asarray(entrainment_velocity, dtype=float)  # m/s
    nu0 = np.asarray(viscosity, dtype=float) * 1e3  # Pa s -> cP (mPa s)
    r = np.asarray(radius, dtype=float)  # m
    s_um = np.asarray(roughness, dtype=float) * 1e6  # m -> um
    if np.any(nu0 <= 0) or np.any(ve <= 0) or np.any(r <= 0):
        raise ModelError(
            "xu_friction_coefficient: viscosity, entrainment velocity and radius "
            "must be positive; check the lubricant viscosity (Pa s) and the gear speeds."
        )
    x = sr * ph * np.log10(nu0)
    f = b1 + b4 * x + b5 * np.exp(-x) + b9 * np.exp(s_um)  # Xu et al. 2007; Jin et al. 2019 eq. 6
    with np.errstate(divide="ignore"):
        mu = (
            np.exp(f) * ph**b2 * sr**b3 * ve**b6 * nu0**b7 * r**b8
        )  # Xu et al. 2007 (exponents b6, b7, b8; Jin et al. 2019 eq. 6 misprints b4, b5, b6)
    return mu


def friction_direction(u1, u2):
    """Friction direction coefficient lambda = sign(u1 - u2) (Jin et al. 2019 eq. 14).

    It is the sign of the friction force on gear 2 along ``t``; it changes at the
    pitch point where u1 = u2.
    """
    return np.sign(np.asarray(u1, dtype=float) - np.asarray(u2, dtype=float))


def friction_arms(position, line_length):
    """Friction moment arms (rho1, rho2) [m] of a contact at ``position``.

    The friction force lies along the common tangent, perpendicular to the line
    of action, so its arm about gear i's centre is the distance from N_i to the
    contact point along the line of action: R1 = s, R2 = |N1N2| - s.
    Jin et al. 2019 eqs. 15 and 17 use these arms (R_1i, R_2i) without printing them.
    """
    s = np.asarray(position, dtype=float)
    return s, line_length - s


def friction_stiffness(direction, mu, stiffness_per_length, contact_length):
    """Friction stiffness of one tooth pair or slice, Kf = lambda mu k0 l [N/m].

    # Jin et al. 2019 eq. 15 (spur: l = contact length) and eq. 17 (slice: l = dl);
    # summed over tooth pairs (eq. 16) and slices (eq. 18) by the caller.
    """
    return direction * mu * stiffness_per_length * contact_length


def friction_torque_coefficient(direction, mu, stiffness_per_length, contact_length, arm):
    """Friction torque coefficient KTf = lambda mu k0 l R [N] of one pair or slice.

    # Jin et al. 2019 eqs. 15 and 17.  Jin et al. 2019 eq. 14 writes a single direction
    # coefficient lambda_Kf for force and torque; eq. 15 uses separate
    # lambda_1i, lambda_2i for the two gears.  With our sign convention the
    # torque on gear 1 is -lambda mu k l R1 and on gear 2 +lambda mu k l R2.
    """
    return direction * mu * stiffness_per_length * contact_length * arm


# --------------------------------------------------------------------------- #
# mesh-level table over one mesh period
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class MeshFrictionTable:
    """Friction quantities of one gear pair sampled at ``n`` phases of a mesh period.

    Arrays of shape ``(n,)`` are per phase; arrays of shape ``(n, n_pairs)`` are per
    tooth pair (``pair`` k is the pair that entered contact k mesh periods before
    phase 0; entries of pairs out of contact are 0, positions and arms NaN).
    Phase 0 is the instant a new tooth pair enters contact (at ``contact_start``;
    for helical teeth: at the face end z = 0).

    Forces in N, moments in N m, arms/positions in m.  See the module docstring
    for sign conventions.  The ``*_per_load`` arrays are the totals divided by the
    normal mesh load, i.e. the friction stiffness and torque coefficients of seed
    003 eq. 14 divided by the mesh stiffness: the dynamic engine multiplies them by
    the instantaneous normal mesh force.
    """

    phase: np.ndarray
    time: np.ndarray
    mesh_period: float
    normal_load: float
    position: np.ndarray  # (n, n_pairs) load-weighted mean contact position
    pair_load: np.ndarray  # (n, n_pairs) normal load on each pair
    friction_coefficient: np.ndarray  # (n, n_pairs) load-weighted mean mu
    pair_friction_force: np.ndarray  # (n, n_pairs) on gear 2 along t
    arm_1: np.ndarray  # (n, n_pairs) load-weighted mean arm about gear 1
    arm_2: np.ndarray  # (n, n_pairs)
    pair_moment_1: np.ndarray  # (n, n_pairs)
    pair_moment_2: np.ndarray  # (n, n_pairs)
    friction_force: np.ndarray  # (n,) total on gear 2 along t
    moment_1: np.ndarray  # (n,) total on gear 1 (positive = its rotation sense)
    moment_2: np.ndarray  # (n,)
    force_per_load: np.ndarray  # (n,) friction_force / normal_load
    moment_1_per_load: np.ndarray  # (n,) [m]
    moment_2_per_load: np.ndarray  # (n,) [m]
    pitch_point: float  # position of the pitch point along N1N2 [m]
    contact_ratio: float  # transverse contact ratio
    overlap_ratio: float

    @property
    def n_pairs(self) -> int:
        return self.pair_load.shape[1]

    def friction_power(self, omega_1: float, omega_2: float) -> np.ndarray:
        """Friction power moment_1*omega_1 + moment_2*omega_2 [W] (never positive)."""
        return self.moment_1 * abs(omega_1) + self.moment_2 * abs(omega_2)


def _require_positive(name: str, value: float) -> None:
    if not np.isfinite(value) or value <= 0.0:
        raise ModelError(f"mesh_friction_table: {name} = {value!r} must be a positive number (SI units).")


def mesh_friction_table(
    *,
    base_radius_1: float,
    base_radius_2: float,
    centre_distance: float,
    contact_start: float,
    contact_end: float | None = None,
    contact_ratio: float | None = None,
    base_pitch: float,
    omega_1: float,
    normal_load: float,
    face_width: float,
    viscosity: float,
    roughness: float,
    youngs_modulus: tuple[float, float] = (206e9, 206e9),
    poisson_ratio: tuple[float, float] = (0.3, 0.3),
    base_helix_angle: float = 0.0,
    n_phases: int = 256,
    n_slices: int = 40,
    pair_stiffness: Callable[[np.ndarray], np.ndarray] | None = None,
) -> MeshFrictionTable:
    """Friction forces and moments of an external spur or helical pair over one mesh period.

    Parameters
    ----------
    base_radius_1, base_radius_2 : base radii [m]; gear 1 is the gear whose
        tangency point N1 is the origin of ``contact_start``/``contact_end``.
    centre_distance : operating centre distance [m].
    contact_start : start of active contact, distance from N1 along the line of
        action [m].  Contact travels from ``contact_start`` to ``contact_end``
        (increasing when gear 1 drives).
    contact_end, contact_ratio : give exactly one: the end of active contact [m],
        or the transverse contact ratio (then end = start +/- ratio * base_pitch).
    base_pitch : transverse base pitch [m].
    omega_1 : angular speed of gear 1 [rad/s]; omega_2 = omega_1 rb1 / rb2.
    normal_load : total normal tooth load of the mesh [N] (force normal to the
        flanks; for helical teeth the transverse line-of-action force divided by
        cos(base_helix_angle)).
    face_width : face width [m] (one helix of a double-helical gear).
    viscosity : lubricant dynamic viscosity at inlet temperature [Pa s].
    roughness : composite RMS roughness of the flanks [m].
    youngs_modulus, poisson_ratio : of gear 1 and gear 2.
    base_helix_angle : [rad]; 0 for spur teeth.  Helical teeth are cut into
        ``n_slices`` transverse slices, each treated as a spur contact (Jin et al. 2019
        eqs. 17-18), shifted along the line of action by z tan(beta_b).
    n_phases : number of samples over one mesh period.
    pair_stiffness : optional callable k(s) giving the mesh stiffness per unit
        contact length at position s [N/m^2] (vectorised; s is NaN for slices
        out of contact, any value may be returned there); the normal load is
        shared among pairs and slices in proportion to k(s) * dl.  Default:
        uniform, i.e. equal load per unit contact length.

    Returns
    -------
    MeshFrictionTable

    Notes
    -----
    Normal-plane quantities are used for helical teeth: radii of curvature
    rho/cos(beta_b), load per unit length of contact line.  The sliding and
    rolling velocities are perpendicular to the contact lines, so V_e and SR are
    the transverse values.

    Examples
    --------
    >>> import numpy as np
    >>> rb1, rb2 = 0.0501, 0.1585
    >>> a = (rb1 + rb2) / np.cos(np.radians(22.5))
    >>> tab = mesh_friction_table(base_radius_1=rb1, base_radius_2=rb2,
    ...     centre_distance=a, contact_start=0.0121, contact_end=0.0287,
    ...     base_pitch=2 * np.pi * rb1 / 31, omega_1=798.6, normal_load=12.5e3,
    ...     face_width=0.048, viscosity=8e-3, roughness=0.6e-6, n_phases=64)
    >>> bool(np.all(tab.friction_power(798.6, 798.6 * rb1 / rb2) <= 0))
    True
    """
    for name, value in (
        ("base_radius_1", base_radius_1),
        ("base_radius_2", base_radius_2),
        ("centre_distance", centre_distance),
        ("base_pitch", base_pitch),
        ("omega_1", abs(omega_1)),
        ("normal_load", normal_load),
        ("face_width", face_width),
        ("viscosity", viscosity),
    ):
        _require_positive(name, float(value))
    if roughness < 0:
        raise ModelError("mesh_friction_table: roughness must be >= 0 m (composite RMS roughness).")
    if (contact_end is None) == (contact_ratio is None):
        raise ModelError(
            "mesh_friction_table: give exactly one of contact_end (m) or contact_ratio; "
            "e.g. contact_end=0.0287."
        )
    if centre_distance <= base_radius_1 + base_radius_2:
        raise ModelError(
            "mesh_friction_table: centre_distance must exceed the sum of the base radii; "
            "pass the operating centre distance in metres."
        )
    if n_phases < 2 or n_slices < 1:
        raise ModelError("mesh_friction_table: n_phases must be >= 2 and n_slices >= 1.")

    line_length = float(np.sqrt(centre_distance**2 - (base_radius_1 + base_radius_2) ** 2))
    if contact_end is None:
        contact_end = contact_start + float(contact_ratio) * base_pitch
    direction = 1.0 if contact_end > contact_start else -1.0
    path_length = abs(contact_end - contact_start)
    lo, hi = sorted((contact_start, contact_end))
    if lo < 0.0 or hi > line_length:
        raise ModelError(
            f"mesh_friction_table: the path of contact [{lo:.6g}, {hi:.6g}] m must lie on "
            f"the line of action [0, {line_length:.6g}] m (positions measured from N1)."
        )
    eps_alpha = path_length / base_pitch
    helical = base_helix_angle != 0.0
    m = n_slices if helical else 1
    tan_bb = np.tan(abs(base_helix_angle))
    cos_bb = np.cos(base_helix_angle)
    eps_beta = face_width * tan_bb / base_pitch
    n_pairs = int(np.ceil(eps_alpha + eps_beta)) + 1

    omega_1 = abs(float(omega_1))
    omega_2 = omega_1 * base_radius_1 / base_radius_2
    mesh_period = base_pitch / (omega_1 * base_radius_1)
    phase = np.arange(n_phases) / n_phases

    z = (np.arange(m) + 0.5) * face_width / m  # slice centres
    dl = face_width / m / cos_bb  # contact-line length of one slice

    # travelled distance of pair k in slice j: u = (phase + k) p_b - z_j tan(beta_b)
    travel = (
        (phase[:, None, None] + np.arange(n_pairs)[None, :, None]) * base_pitch
        - z[None, None, :] * tan_bb
    )  # (n, K, m)
    in_contact = (travel >= 0.0) & (travel <= path_length)
    s = contact_start + direction * travel
    s = np.where(in_contact, s, np.nan)

    k_line = np.ones_like(s) if pair_stiffness is None else np.asarray(pair_stiffness(s), dtype=float)
    weight = np.where(in_contact, k_line * dl, 0.0)
    total_weight = weight.sum(axis=(1, 2))
    if np.any(total_weight <= 0.0):
        raise ModelError(
            "mesh_friction_table: no tooth pair in contact at some phase; the contact ratio "
            "plus overlap ratio must be at least 1 (check contact_start/contact_end and base_pitch)."
        )
    load = normal_load * weight / total_weight[:, None, None]  # N per slice

    rho1, rho2 = friction_arms(s, line_length)
    u1, u2 = rolling_velocities(s, line_length, omega_1, omega_2)
    ve = entrainment_velocity(u1, u2)
    sr = slide_to_roll_ratio(u1, u2)
    with np.errstate(invalid="ignore"):
        ph = hertz_max_pressure(
            np.where(in_contact, load / dl, 0.0),
            rho1 / cos_bb,
            rho2 / cos_bb,
            youngs_modulus[0],
            poisson_ratio[0],
            youngs_modulus[1],
            poisson_ratio[1],
        )
        radius = equivalent_radius(rho1 / cos_bb, rho2 / cos_bb)
        mu = np.where(
            in_contact,
            xu_friction_coefficient(
                np.where(in_contact, sr, 0.0),
                np.where(in_contact, ph, 0.0),
                np.where(in_contact, ve, 1.0),
                viscosity,
                np.where(in_contact, radius, 1.0),
                roughness,
            ),
            0.0,
        )
    lam = np.where(in_contact, friction_direction(u1, u2), 0.0)  # Jin et al. 2019 eq. 14 lambda
    f = lam * mu * load  # Jin et al. 2019 eq. 5 f = mu F, with direction lambda
    m1 = np.where(in_contact, -f * rho1, 0.0)  # Jin et al. 2019 eq. 8 friction torque terms
    m2 = np.where(in_contact, f * rho2, 0.0)

    pair_load = load.sum(axis=2)  # Jin et al. 2019 eq. 18 (sum over slices)
    pair_force = f.sum(axis=2)
    pair_m1 = m1.sum(axis=2)
    pair_m2 = m2.sum(axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(pair_load > 0, pair_load, np.nan)
        pos_mean = np.nansum(np.where(in_contact, s * load, 0.0), axis=2) / safe
        arm1 = np.nansum(np.where(in_contact, rho1 * load, 0.0), axis=2) / safe
        arm2 = np.nansum(np.where(in_contact, rho2 * load, 0.0), axis=2) / safe
        mu_mean = np.where(
            pair_load > 0, (mu * load).sum(axis=2) / np.where(pair_load > 0, pair_load, 1.0), 0.0
        )

    total_force = pair_force.sum(axis=1)  # Jin et al. 2019 eq. 16 (sum over pairs)
    total_m1 = pair_m1.sum(axis=1)
    total_m2 = pair_m2.sum(axis=1)

    return MeshFrictionTable(
        phase=phase,
        time=phase * mesh_period,
        mesh_period=mesh_period,
        normal_load=float(normal_load),
        position=pos_mean,
        pair_load=pair_load,
        friction_coefficient=mu_mean,
        pair_friction_force=pair_force,
        arm_1=arm1,
        arm_2=arm2,
        pair_moment_1=pair_m1,
        pair_moment_2=pair_m2,
        friction_force=total_force,
        moment_1=total_m1,
        moment_2=total_m2,
        force_per_load=total_force / normal_load,
        moment_1_per_load=total_m1 / normal_load,
        moment_2_per_load=total_m2 / normal_load,
        pitch_point=line_length * base_radius_1 / (base_radius_1 + base_radius_2),
        contact_ratio=eps_alpha,
        overlap_ratio=eps_beta if helical else 0.0,
    )
