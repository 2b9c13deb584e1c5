"""Meshing-in impact of standard involute teeth under load (Liu et al. 2021 eqs. 6-10).

Under load the tooth pairs already in contact deflect by ``delta`` along the
line of action, so the driven gear lags its rigid position by ``delta / r_bg``.
The next tooth pair therefore meets early, off the theoretical line of action:
the tip corner of the driven gear's tooth hits the driving pinion's flank at a
point D before the theoretical start of contact E (corner contact).  Because D is
off the line of action the two surfaces have a relative normal velocity v_s there,
and the impact force follows from an impact-energy balance (Liu et al. 2021 eq. 10).

All inputs and outputs are SI (m, rad, rad/s, N, kg m^2, N/m^n).

Planar frame used by :func:`meshing_in_point`
---------------------------------------------
Driving pinion centre O_p at the origin, driven gear centre O_g at
(a, 0).  The pinion turns counter-clockwise, the gear clockwise.  The line of
action touches the pinion base circle at N_p = r_bp (cos a_w, -sin a_w) and runs
along d = (sin a_w, cos a_w) towards N_g; positions ``s`` on it are measured from
N_p.  A flank of the pinion that crosses the line of action at s has, at radius
r, the polar angle  s / r_bp - a_w - inv(arccos(r_bp / r)); a gear flank crossing
at s has, about O_g, the polar angle  pi - a_w + (L - s) / r_bg - inv(arccos(r_bg
/ r)) with L = a sin a_w.  The normal distance between a point X and the pinion
flank (along the involute normal through X) is r_bp times their polar-angle
difference, exactly, since both lie on involutes of the same base circle.

Sources
-------
- Liu et al. 2021 eqs. 6-10 (reversal method after Zhou, Tang, Zhong, Chin. J. Mech. Eng.
  44(3) 2008; impact force after Mu, Fang, Li, Proc IMechE K 233(3) 2019).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from torquesplit.errors import ModelError, ModelWarning, warn_user

MIN_PULSE_SAMPLES = 4
"""A force table resolves the impact pulse's peak with this many samples across it."""

__all__ = [
    "involute",
    "loaded_deflection",
    "equivalent_mass",
    "impact_force",
    "impact_duration",
    "meshing_in_radius",
    "MeshingInPoint",
    "meshing_in_point",
    "MeshingInImpact",
    "meshing_in_impact",
]


def involute(angle):
    """inv(a) = tan(a) - a."""
    angle = np.asarray(angle, dtype=float)
    return np.tan(angle) - angle


def loaded_deflection(normal_load: float, loaded_stiffness: float) -> float:
    """Deflection along the line of action of the loaded tooth pair(s), delta = F / k [m].

    ``loaded_stiffness`` is the stiffness of the pairs carrying the load just before
    the next pair engages (single-pair stiffness for 1 < eps_alpha < 2).  In Liu et al. 2021
    this is the normal deformation Z of the loaded tooth contact analysis (eq. 5:
    k = F_n / Z).
    """
    if loaded_stiffness <= 0:
        raise ModelError("loaded_deflection: loaded_stiffness must be positive (N/m).")
    return max(float(normal_load), 0.0) / float(loaded_stiffness)  # Liu et al. 2021 eq. 5


def equivalent_mass(inertia_driving, inertia_driven, base_radius_driving, base_radius_driven):
    """Equivalent mass of the pair along the line of action [kg].

    m_e = J_p J_g / (J_p r_bg^2 + J_g r_bp^2)      # Liu et al. 2021 eq. 10
    """
    jp, jg = float(inertia_driving), float(inertia_driven)
    return jp * jg / (jp * base_radius_driven**2 + jg * base_radius_driving**2)


def impact_force(effective_mass, normal_velocity, impact_stiffness, exponent=1.0):
    """Maximum meshing-in impact force [N], Liu et al. 2021 eq. 10.

    F_s = ((n+1)/2 * m_e * v_s^2 * k_s^(1/n))^(n/(n+1))

    It follows from equating the kinetic energy m_e v_s^2 / 2 with the work of a
    contact law F = k_s delta^n up to the maximum approach.  The printed exponent
    ``n/n+1`` means n/(n+1).  ``impact_stiffness`` k_s has units N/m^n (N/m for
    the default linear contact n = 1, for which F_s = v_s sqrt(m_e k_s)).  The seed
    calls n "the deformation coefficient under the static state": the exponent of
    the load-deflection law of the tooth pair at the engagement point.

    Scaling: F_s ~ v_s^(2n/(n+1)) ~ m_e^(n/(n+1)) ~ k_s^(1/(n+1)).
    """
    if exponent <= 0:
        raise ModelError("impact_force: exponent n must be positive (1 for a linear tooth contact).")
    n = float(exponent)
    v = np.abs(np.asarray(normal_velocity, dtype=float))
    energy_term = (n + 1.0) / 2.0 * effective_mass * v**2 * impact_stiffness ** (1.0 / n)
    return energy_term ** (n / (n + 1.0))  # Liu et al. 2021 eq. 10


def impact_duration(effective_mass, normal_velocity, impact_stiffness, exponent=1.0):
    """Contact time of the impact [s] for the contact law F = k_s delta^n.

    t_c = 2 (delta_max / v_s) * sqrt(pi) Gamma(1 + 1/(n+1)) / Gamma(1/2 + 1/(n+1)),
    delta_max = ((n+1) m_e v_s^2 / (2 k_s))^(1/(n+1)).
    For n = 1: t_c = pi sqrt(m_e / k_s) (half period of the mass-spring system),
    for n = 3/2 the classical Hertz value 2.94 delta_max / v_s.  Independent of
    v_s only for n = 1.  Returns 0 for v_s = 0.
    """
    n = float(exponent)
    v = abs(float(normal_velocity))
    if v == 0.0:
        return 0.0
    from scipy.special import gamma as gamma_function

    p = n + 1.0
    delta_max = (p * effective_mass * v**2 / (2.0 * impact_stiffness)) ** (1.0 / p)
    integral = math.sqrt(math.pi) * gamma_function(1.0 + 1.0 / p) / gamma_function(0.5 + 1.0 / p)
    return 2.0 * delta_max / v * integral


def meshing_in_radius(tip_radius_driven, pitch_radius_driving, pitch_radius_driven, angle):
    """Radius r_OpD of the meshing-in point on the driving pinion [m], Liu et al. 2021 eq. 6.

    r_OpD = sqrt(r_ag^2 + (r_p + r_g)^2 - 2 r_ag (r_p + r_g) cos(gamma_g + phi_k + dphi_kg))

    ``angle`` is gamma_g + phi_k + dphi_kg, the angle at the gear centre between
    the centre line and O_g D (law of cosines in triangle O_p O_g D; r_p + r_g is
    the centre distance of a standard pair).
    """
    a = pitch_radius_driving + pitch_radius_driven
    return np.sqrt(
        tip_radius_driven**2 + a**2 - 2.0 * tip_radius_driven * a * np.cos(angle)
    )  # Liu et al. 2021 eq. 6


@dataclass(frozen=True)
class MeshingInPoint:
    """Meshing-in (corner contact) point of a loaded standard involute pair.

    Attributes
    ----------
    point : (x, y) of D in the frame of :mod:`this module <torquesplit.gears.impact>` [m].
    radius_on_driving : |O_p D| [m] (Liu et al. 2021 eq. 6 r_OpD).
    theoretical_start : position of E, the rigid start of contact, along the line
        of action from N_p [m].
    pinion_flank_position : where the engaging pinion flank crosses the line of
        action at the instant of meshing-in [m] (< theoretical_start when loaded).
    offset_from_line : distance of D from the theoretical line of action [m].
    gear_angle : angle at O_g between the centre line and O_g D [rad]
        (= gamma_g + phi_k + dphi_kg of Liu et al. 2021 eq. 6).
    gamma_g : angle at O_g between the centre line and O_g E [rad]
        (Liu et al. 2021: gamma_g = pi/2 - alpha_t - angle(PEO_g)).
    lag_angle : rotation lag of the driven gear from the deflection, advance / r_bg [rad].
    reverse_angle : total angle by which the driven gear meets the pinion early,
        gear_angle - gamma_g [rad] (phi_k + dphi_kg of Liu et al. 2021).
    normal_velocity : relative normal velocity v_s = v_np - v_ng at D [m/s]
        (Liu et al. 2021 eq. 9), positive = approaching.
    phase_lead : how much earlier than the theoretical start the contact occurs,
        in mesh periods (pinion travel / base pitch) [-]; filled by
        :func:`meshing_in_impact`, NaN otherwise.
    """

    point: tuple[float, float]
    radius_on_driving: float
    theoretical_start: float
    pinion_flank_position: float
    offset_from_line: float
    gear_angle: float
    gamma_g: float
    lag_angle: float
    reverse_angle: float
    normal_velocity: float
    phase_lead: float = float("nan")


def meshing_in_point(
    *,
    base_radius_driving: float,
    base_radius_driven: float,
    tip_radius_driven: float,
    centre_distance: float,
    advance: float,
    omega_driving: float,
    tip_radius_driving: float | None = None,
) -> MeshingInPoint:
    """Locate the meshing-in point and the relative normal velocity there.

    Parameters
    ----------
    base_radius_driving, base_radius_driven : base radii r_bp, r_bg [m].
    tip_radius_driven : tip radius r_ag of the driven gear [m].
    centre_distance : operating centre distance a [m].
    advance : how far the engaging pinion flank is ahead of its rigid conjugate
        position relative to the gear flank, along the line of action [m]:
        the deflection of the loaded pairs (:func:`loaded_deflection`) plus any
        base-pitch excess of the pinion over the gear (p_bp - p_bg).  0 for an
        error-free unloaded pair.
    omega_driving : angular speed of the driving pinion [rad/s] (magnitude).
    tip_radius_driving : optional, to check that D lies on the pinion's flank.

    Returns
    -------
    MeshingInPoint

    Notes
    -----
    Liu et al. 2021 finds D by the reversal method (rotate the driven gear back by the
    reverse angle, eq. 6) and then the velocities (eq. 9).  Here the same point is
    found directly: the pinion flank position s_p is moved back from the rigid
    start E until the driven gear's tip corner, placed ``advance`` behind the
    conjugate position, touches the pinion flank (normal gap = 0).  The seed writes
    phi_k = Z / r_ag for the angle due to the deflection Z; a deflection along
    the line of action turns the gear by Z / r_bg, which we use (``lag_angle``).
    """
    rbp, rbg = float(base_radius_driving), float(base_radius_driven)
    rag, a = float(tip_radius_driven), float(centre_distance)
    if a <= rbp + rbg:
        raise ModelError("meshing_in_point: centre_distance must exceed r_bp + r_bg (metres).")
    if rag <= rbg:
        raise ModelError("meshing_in_point: tip_radius_driven must exceed base_radius_driven.")
    if advance < 0:
        raise ModelError(
            "meshing_in_point: advance must be >= 0 (a negative advance delays contact "
            "and causes no meshing-in impact); pass delta + (p_bp - p_bg) clipped at 0."
        )
    cos_aw = (rbp + rbg) / a
    aw = math.acos(cos_aw)
    line = a * math.sin(aw)
    s_start = line - math.sqrt(rag**2 - rbg**2)  # rigid start of contact E
    if s_start <= 0.0:
        raise ModelError(
            "meshing_in_point: the driven gear's tip circle reaches beyond N_p "
            "(interference); check tip_radius_driven and centre_distance."
        )
    inv_ag = float(involute(math.acos(rbg / rag)))
    og = np.array([a, 0.0])

    def corner(s_p: float) -> np.ndarray:
        s_g = s_p - advance  # gear flank lags the pinion flank by the advance
        theta = math.pi - aw + (line - s_g) / rbg - inv_ag
        return og + rag * np.array([math.cos(theta), math.sin(theta)])

    def gap(s_p: float) -> float:
        x = corner(s_p)
        r = math.hypot(x[0], x[1])
        if r <= rbp:
            return float("inf")
        flank = s_p / rbp - aw - float(involute(math.acos(rbp / r)))
        polar = math.atan2(x[1], x[0])
        diff = (polar - flank + math.pi) % (2.0 * math.pi) - math.pi
        return rbp * diff  # normal distance along the pinion involute normal

    if advance == 0.0:
        s_p = s_start
    else:
        hi = s_start
        step = max(advance, 1e-7)
        lo = hi - step
        while gap(lo) < 0.0:
            step *= 2.0
            lo = hi - step
            if hi - lo > s_start:
                raise ModelError(
                    f"no corner contact: a loaded approach of {advance * 1e6:.4g} um is more "
                    "than this tooth geometry allows (a load far beyond the pair's "
                    "capacity, or a large misalignment or slope): check the load")
        from scipy.optimize import brentq  # here: importing scipy.optimize takes 0.4 s

        try:
            s_p = brentq(gap, lo, hi, xtol=1e-15, rtol=1e-14)
        except ValueError:  # no sign change: the corner never reaches the flank
            raise ModelError(
                f"no corner contact: a loaded approach of {advance * 1e6:.4g} um is more "
                "than this tooth geometry allows (a load far beyond the pair's "
                "capacity, or a large misalignment or slope): check the load") from None
    d = corner(s_p)
    r_d = float(math.hypot(d[0], d[1]))
    if tip_radius_driving is not None and r_d > tip_radius_driving:
        warn_user(
            "meshing_in_point: the meshing-in point lies above the pinion tip circle; "
            "the advance is larger than the tooth geometry can absorb.",
            ModelWarning,
        )
    # distance from the line of action through N_p with direction dvec
    n_p = rbp * np.array([cos_aw, -math.sin(aw)])
    dvec = np.array([math.sin(aw), cos_aw])
    rel = d - n_p
    offset = float(abs(rel[0] * dvec[1] - rel[1] * dvec[0]))

    # velocities: pinion flank normal at D is tangent to the pinion base circle
    ell = math.sqrt(r_d**2 - rbp**2)
    beta_d = (s_p / rbp - aw) - ell / rbp  # tangent-point angle of D's involute normal
    normal = np.array([-math.sin(beta_d), math.cos(beta_d)])
    w_p = abs(float(omega_driving))
    w_g = w_p * rbp / rbg
    v_p = w_p * np.array([-d[1], d[0]])  # counter-clockwise pinion
    rg = d - og
    v_g = w_g * np.array([rg[1], -rg[0]])  # clockwise gear
    v_s = float(np.dot(v_p - v_g, normal))  # Liu et al. 2021 eq. 9: v_s = v_np - v_ng
    if advance == 0.0:
        v_s = 0.0  # conjugate contact on the line of action: exactly zero (removes round-off)

    alpha_ag = math.acos(rbg / rag)
    gamma_g = alpha_ag - aw  # = pi/2 - alpha_t - angle(PEO_g) of Liu et al. 2021 eq. 6
    gear_angle = float(math.atan2(-rg[1], -rg[0]))  # angle from O_g->O_p to O_g->D
    gear_angle = abs(gear_angle)
    return MeshingInPoint(
        point=(float(d[0]), float(d[1])),
        radius_on_driving=r_d,
        theoretical_start=s_start,
        pinion_flank_position=float(s_p),
        offset_from_line=offset,
        gear_angle=gear_angle,
        gamma_g=gamma_g,
        lag_angle=advance / rbg,
        reverse_angle=gear_angle - gamma_g,
        normal_velocity=v_s,
    )


@dataclass(frozen=True)
class MeshingInImpact:
    """Meshing-in impact of one gear pair as a periodic force over the mesh period.

    The force is a half-sine pulse F_s sin(pi tau / t_c), 0 <= tau <= t_c,
    starting at the meshing-in instant of every mesh cycle.  The half sine is the
    exact force history of the impact for a linear contact law (n = 1): the
    equivalent mass m_e hits a spring k_s with speed v_s, F(tau) = v_s sqrt(m_e k_s)
    sin(tau sqrt(k_s/m_e)), which lasts t_c = pi sqrt(m_e/k_s) and peaks at eq. 10.
    For n != 1 the duration is exact (:func:`impact_duration`) and the half sine an
    approximation of the shape.  The pulse is clipped at one mesh period.

    Phase 0 is the theoretical start of contact of a new pair (as in the friction
    and stiffness tables); the pulse starts at phase ``start_phase`` =
    -phase_lead (mod 1), i.e. slightly before it.
    """

    peak_force: float
    duration: float
    mesh_period: float
    start_phase: float
    point: MeshingInPoint
    effective_mass: float
    impact_stiffness: float
    exponent: float

    @property
    def mean_force(self) -> float:
        """Mean of the periodic pulse over one mesh period [N]: 2 F_s t_c / (pi T)."""
        return 2.0 * self.peak_force * min(self.duration, self.mesh_period) / (math.pi * self.mesh_period)

    def force(self, phase, *, remove_mean: bool = False):
        """Impact force [N] at mesh ``phase`` (any real, periodic with period 1).

        ``remove_mean=True`` subtracts :attr:`mean_force`: the seed adds the pulse
        to the mesh force (Liu et al. 2021 eqs. 14-16), which also adds a mean force and
        therefore a mean torque; removing it keeps the transmitted torque unchanged.
        """
        phase = np.asarray(phase, dtype=float)
        if self.duration <= 0.0 or self.peak_force == 0.0:
            out = np.zeros_like(phase)
        else:
            width = min(self.duration, self.mesh_period) / self.mesh_period
            tau = np.mod(phase - self.start_phase, 1.0)
            out = np.where(tau <= width, self.peak_force * np.sin(np.pi * tau / width), 0.0)
        if remove_mean:
            out = out - self.mean_force
        return out

    def pulse_samples(self, n_phases: int) -> float:
        """How many of ``n_phases`` samples per mesh cycle the pulse spans (inf: none)."""
        return self.duration / self.mesh_period * n_phases if self.duration > 0 else math.inf

    def phases_needed(self) -> int:
        """The fewest samples per mesh cycle that resolve the pulse (MIN_PULSE_SAMPLES)."""
        if self.duration <= 0:
            return 1
        return int(math.ceil(MIN_PULSE_SAMPLES * self.mesh_period / self.duration))

    def table(self, n_phases: int = 256, *, remove_mean: bool = False, warn: bool = True):
        """(phase, force) sampled at ``n_phases`` equally spaced phases in [0, 1).

        Warns (unless ``warn`` is False: a caller that says it in its own words) when the
        pulse spans fewer than MIN_PULSE_SAMPLES samples: the table then misses the peak;
        raise ``n_phases`` or evaluate :meth:`force` directly.
        """
        phase = np.arange(n_phases) / n_phases
        if warn and self.pulse_samples(n_phases) < MIN_PULSE_SAMPLES:
            warn_user(
                f"MeshingInImpact.table: the impact pulse spans "
                f"{self.pulse_samples(n_phases):.1f} samples; use "
                f"n_phases >= {self.phases_needed()}.",
                ModelWarning,
            )
        return phase, self.force(phase, remove_mean=remove_mean)


def meshing_in_impact(
    *,
    base_radius_driving: float,
    base_radius_driven: float,
    tip_radius_driven: float,
    centre_distance: float,
    base_pitch: float,
    omega_driving: float,
    normal_load: float,
    loaded_stiffness: float,
    inertia_driving: float,
    inertia_driven: float,
    impact_stiffness: float,
    exponent: float = 1.0,
    base_pitch_difference: float = 0.0,
) -> MeshingInImpact:
    """Meshing-in impact of a standard involute pair (Liu et al. 2021 eqs. 6-10).

    Steps: deflection delta = F / k (eq. 5) -> advance = delta + (p_bp - p_bg)
    -> meshing-in point D off the line of action (eqs. 6-8, reversal method)
    -> relative normal velocity v_s at D (eq. 9) -> equivalent mass and peak
    force F_s (eq. 10) -> half-sine pulse of duration t_c per mesh cycle.

    Parameters
    ----------
    base_pitch : transverse base pitch [m] (for the mesh period and the phase).
    normal_load : mesh force along the line of action [N].
    loaded_stiffness : stiffness of the pair(s) loaded just before the new pair
        engages [N/m].
    inertia_driving, inertia_driven : polar moments of inertia J_p, J_g [kg m^2].
    impact_stiffness : k_s, single-pair stiffness at the engagement point [N/m^n].
    exponent : n of the contact law F = k_s delta^n (1 = linear).
    base_pitch_difference : p_bp - p_bg [m]; a longer pinion pitch also makes the
        next pair engage early.

    Examples
    --------
    >>> imp = meshing_in_impact(base_radius_driving=0.0550, base_radius_driven=0.1731,
    ...     tip_radius_driven=0.1908, centre_distance=0.24675, base_pitch=0.01016,
    ...     omega_driving=798.6, normal_load=12e3, loaded_stiffness=1.2e9,
    ...     inertia_driving=0.005, inertia_driven=0.2, impact_stiffness=1.0e9)
    >>> imp.peak_force > 0
    True
    """
    advance = loaded_deflection(normal_load, loaded_stiffness) + float(base_pitch_difference)
    advance = max(advance, 0.0)
    point = meshing_in_point(
        base_radius_driving=base_radius_driving,
        base_radius_driven=base_radius_driven,
        tip_radius_driven=tip_radius_driven,
        centre_distance=centre_distance,
        advance=advance,
        omega_driving=omega_driving,
    )
    lead = (point.theoretical_start - point.pinion_flank_position) / base_pitch
    point = replace(point, phase_lead=lead)
    m_e = equivalent_mass(inertia_driving, inertia_driven, base_radius_driving, base_radius_driven)
    v_s = max(point.normal_velocity, 0.0)
    peak = float(impact_force(m_e, v_s, impact_stiffness, exponent))
    duration = impact_duration(m_e, v_s, impact_stiffness, exponent)
    mesh_period = base_pitch / (abs(omega_driving) * base_radius_driving)
    if duration > mesh_period:
        warn_user(
            f"meshing_in_impact: the impact lasts {duration / mesh_period:.2f} mesh periods; "
            "the pulse is clipped at one mesh period (check impact_stiffness and the inertias).",
            ModelWarning,
        )
    return MeshingInImpact(
        peak_force=peak,
        duration=duration,
        mesh_period=mesh_period,
        start_phase=float(np.mod(-lead, 1.0)),
        point=point,
        effective_mass=m_e,
        impact_stiffness=float(impact_stiffness),
        exponent=float(exponent),
    )
