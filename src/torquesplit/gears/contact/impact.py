"""Meshing-in impact from the loaded geometry of an LTCA (Liu et al. 2021 eqs. 6-10).

Liu et al. 2021 §2.4: under load the driven gear lags its rigid position by the loaded
transmission error of the pairs in contact, so the next tooth pair meets before its
theoretical start of contact, at the tip corner of the driven gear (eq. 7: the
backward angle is the difference between the loaded transmission error of the pair
in contact and the unloaded one of the next pair).  A modification that removes
material at that corner delays the contact: where the relief exceeds the loaded
approach, there is no premature contact and no impact.

Here, for the helix in which a new pair enters at mesh phase ``phi_e`` (the face end
``y = 0`` of that helix, path position ``s_A``: the driver's start of active profile,
the driven gear's tip):

* ``Z`` -- loaded transmission error of the pairs in contact *before* the new pair
  enters: the LTCA's transmission error as the phase tends to ``phi_e`` from below
  (approach along the flank normal, measured from the conjugate unmodified position).
  At ``phi_e`` itself the new pair already shares the load: a spur pair's transmission
  error drops there from its single-pair to its double-pair value;
* ``w_c`` -- initial separation of the engaging corner (modifications of both gears
  at ``s_A``, ``y = 0``, misalignment and pitch deviation; the same reference as ``Z``);
* the premature approach ``Z - w_c`` along the normal, ``(Z - w_c) / cos(beta_b)`` in
  the transverse plane, is the ``advance`` of
  :func:`torquesplit.gears.impact.meshing_in_point`, which finds the corner contact
  point D off the line of action and the relative normal velocity there (eqs. 6-9, in
  the transverse section at the face end);
* the normal velocity along the flank normal is the transverse one times
  ``cos(beta_b)``; the impact force is eq. 10 with the equivalent mass of eq. 10 and
  the single-pair stiffness ``k_s`` = mean LTCA stiffness / total contact ratio (the
  stiffness of one tooth pair on average; the paper does not say how it takes k_s).

Internal pairs are not supported (the corner geometry of
:func:`~torquesplit.gears.impact.meshing_in_point` is that of an external pair).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError, ModelWarning, warn_user
from torquesplit.gears import impact as gim

__all__ = ["LoadedMeshingIn", "loaded_meshing_in"]


@dataclass(frozen=True)
class LoadedMeshingIn:
    """Meshing-in of the next tooth pair under load, from an LTCA (SI).

    Attributes
    ----------
    helix : int
        Helix whose engagement gives the larger premature approach.
    entry_phase : float
        Mesh phase at which the new pair of that helix reaches its start of contact.
    approach : float
        Loaded transmission error of the pairs in contact just before it [m] (normal).
    corner_separation : float
        Initial separation where the engaging pair first touches [m] (normal): the
        face-end corner of a helical pair, the least along the face of a spur pair
        (:func:`_entry_separation`).
    advance : float
        Premature approach ``max(approach - corner_separation, 0)`` [m] (normal).
    impact : MeshingInImpact or None
        The impact (None when there is no premature contact).
    """

    helix: int
    entry_phase: float
    approach: float
    corner_separation: float
    advance: float
    impact: gim.MeshingInImpact | None

    @property
    def peak_force(self) -> float:
        """Maximum meshing-in impact force [N] (0 without premature contact)."""
        return 0.0 if self.impact is None else float(self.impact.peak_force)

    def force(self, phase) -> np.ndarray:
        """Impact force at mesh phases [N]."""
        if self.impact is None:
            return np.zeros_like(np.asarray(phase, dtype=float))
        return self.impact.force(phase)


def _before(phase, values, at: float, state=None) -> float:
    """The limit of the periodic samples ``values(phase)`` as the phase tends to ``at``
    from below: linear through the two samples before ``at`` where both have the same
    ``state`` (the number of loaded tooth pairs), else the last sample's value (a line
    through samples on both sides of a jump lands far off it; a sample at ``at`` itself
    belongs to the other side of the jump)."""
    back = np.mod(at - np.asarray(phase, dtype=float), 1.0)
    back[back < 1e-9] = np.inf  # (a sample on ``at`` itself)
    i1, i2 = np.argsort(back)[:2]
    if state is not None and state[i1] != state[i2]:
        return float(values[i1])
    d1, d2 = back[i1], back[i2]
    return float(values[i1] + (values[i1] - values[i2]) * d1 / (d2 - d1))


#: face positions where a spur pair's entering contact line is searched for its least
#: separation (:func:`_entry_separation`)
ENTRY_FACE_POINTS = 41


def _entry_separation(cm, helix: int) -> float:
    """The separation of the flanks where the new pair first touches [m]: a helical
    pair's contact line enters at the face-end corner (y = 0); a spur pair's enters along
    the whole face at once, so it touches first where its separation is least (mid-face
    on a crowned lead: the corner alone made 5 um of crowning cancel a 534 N impact)."""
    pair = cm.pair
    s0 = np.array([pair.path_start])
    if abs(pair.base_helix_angle) > 1e-12:
        y = np.array([0.0])
    else:
        y = np.linspace(0.0, pair.face_width, ENTRY_FACE_POINTS)
    w = cm.raw_separation(s0, y, helix)
    return float(np.min(w) - cm.separation_shift)


def loaded_meshing_in(result, *, omega_driving: float, inertia_driving: float,
                      inertia_driven: float, exponent: float = 1.0,
                      impact_stiffness: float | None = None) -> LoadedMeshingIn:
    """Meshing-in impact of an LTCA result (gear 1 of its pair drives).

    Parameters
    ----------
    result : LtcaResult
    omega_driving : float
        Angular speed of the driving gear (gear 1) [rad/s].
    inertia_driving, inertia_driven : float
        Polar moments of inertia [kg m^2] (Liu et al. 2021 eq. 10, J_p, J_g).
    exponent : float
        ``n`` of the contact law (1 = linear).
    impact_stiffness : float, optional
        ``k_s`` [N/m^n]; default mean secant stiffness / total contact ratio.
    """
    cm = result.model
    pair = cm.pair
    if pair.is_internal:
        raise ModelError([("impact", "meshing-in impact from the LTCA is implemented for external "
                                     "pairs; set impact = false for this internal mesh")])
    cb = cm.normal_factor
    phase = cm.phase
    best = None
    for h in range(cm.helices):
        entry = float(np.mod(-h * cm.options.stagger, 1.0))
        loaded = (result.pair_load[:, h] > 1e-9 * result.load).sum(axis=1)
        z = _before(phase, result.approach(h), entry, loaded)
        w_c = _entry_separation(cm, h)
        adv = z - w_c
        if best is None or adv > best[3]:
            best = (h, entry, z, adv, w_c)
    h, entry, z, adv, w_c = best
    if adv <= 0.0:
        return LoadedMeshingIn(h, entry, z, w_c, 0.0, None)
    k_s = impact_stiffness
    if k_s is None:
        k_s = float(result.stiffness_secant.mean()) / pair.total_contact_ratio
    g1, g2 = pair.gear1, pair.gear2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)   # re-issued below with the mesh context
        point = gim.meshing_in_point(
            base_radius_driving=g1.base_radius, base_radius_driven=g2.base_radius,
            tip_radius_driven=g2.tip_radius, centre_distance=pair.operating_center_distance,
            advance=adv / cb, omega_driving=omega_driving)
    lead = (point.theoretical_start - point.pinion_flank_position) / pair.base_pitch
    m_e = gim.equivalent_mass(inertia_driving, inertia_driven, g1.base_radius, g2.base_radius)
    v_n = max(point.normal_velocity, 0.0) * cb          # transverse -> flank normal
    peak = float(gim.impact_force(m_e, v_n, k_s, exponent))   # Liu et al. 2021 eq. 10
    duration = gim.impact_duration(m_e, v_n, k_s, exponent)
    mesh_period = pair.base_pitch / (abs(omega_driving) * g1.base_radius)
    if duration > mesh_period:
        warn_user(f"meshing-in impact lasts {duration / mesh_period:.2f} mesh periods; the "
                      "pulse is clipped at one mesh period (check the inertias)", ModelWarning)
    imp = gim.MeshingInImpact(
        peak_force=peak, duration=duration, mesh_period=mesh_period,
        start_phase=float(np.mod(entry - lead, 1.0)), point=point, effective_mass=m_e,
        impact_stiffness=float(k_s), exponent=float(exponent))
    return LoadedMeshingIn(h, entry, z, w_c, float(adv), imp)
