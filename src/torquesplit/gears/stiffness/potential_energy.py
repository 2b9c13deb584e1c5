"""Mesh stiffness by the potential-energy method, with the fillet-foundation term of
Sainsot, Velex & Duverger (2004), and a slice method for helical gears.

Model (per unit face width, transverse plane, one external tooth as a cantilever
on the root circle, loaded at the contact point by a force inclined at the load
angle ``alpha_1`` to the normal of the tooth centreline)::

    1/k_b = int [cos(a1) (x_c - x) - sin(a1) h_c]^2 / (E I_x) dx     bending
    1/k_s = int 1.2 cos^2(a1) / (G A_x) dx                             shear
    1/k_a = int sin^2(a1) / (E A_x) dx                                 axial compression
    I_x = (2 h_x)^3 b / 12,  A_x = 2 h_x b,  G = E / (2 (1 + nu))

(Yang & Lin 1987; Tian 2004; Chaari, Fakhfakh & Haddar 2009), the Hertzian contact
stiffness ``k_h = pi E b / (4 (1 - nu^2))`` (Yang & Lin 1987; for two materials
``k_h = (pi b / 2) / [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]``, which reduces to it), and the
fillet-foundation flexibility (Sainsot, Velex & Duverger 2004, eq. for delta_f)::

    1/k_f = cos^2(a1) / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2(a1))]

with ``X*(h_fi, theta_f) = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F``
(coefficients :data:`SAINSOT_COEFFICIENTS`), ``h_fi = r_f / r_int`` (root radius over
bore/rim inner radius), ``theta_f`` the tooth half angle at the root circle,
``S_f = 2 r_f theta_f`` the tooth thickness at the root circle and ``u_f`` the distance,
along the tooth centreline, from the root circle to the point where the line of the
tooth force crosses the centreline: ``u_f = r_b / cos(a1) - r_f``.

A tooth pair is a series connection and the pairs in contact act in parallel::

    1/k_pair = 1/k_h + sum over both teeth (1/k_b + 1/k_s + 1/k_a [+ 1/k_f]),
    k_mesh = sum over pairs in contact of k_pair.

Tooth geometry: the involute is parametrised by the roll parameter
``u = tan(alpha_r)`` of the point at radius ``r = r_b sqrt(1 + u^2)``; with
``alpha = psi_b - u`` (angular position of its base-circle tangent point from the
centreline, ``psi_b`` the half tooth angle at the base circle)::

    x = r_b [cos(alpha) - u sin(alpha)],  h = r_b [sin(alpha) + u cos(alpha)],
    dx/du = r_b u cos(alpha),  load angle a1 = u_c - psi_b

(Tian 2004 writes the same integrals in ``alpha``).  If the root circle lies inside
the base circle the tooth continues to the root circle as a straight beam of the
base-circle thickness ``2 r_b sin(psi_b)`` (the usual simplification, e.g. Ma et al.
2015); if it lies outside, the involute is cut at the root circle.  The trochoidal
fillet, tip relief and friction are not modelled.

Helical and double-helical gears: the face width (of one helix) is cut into ``N``
thin transverse slices, each a spur pair with the transverse tooth form, shifted
in mesh phase by its helix stagger ``y tan(beta_b) / p_bt``; the slices act in
parallel and are not coupled.  Each slice's transverse compliance ``c_t`` (force and
deflection along the transverse line of action) is converted to the normal of the
flank, the direction of the 3-D line of action: ``c_n = c_t cos^2(beta_b)``; its
Hertzian line has length ``db / cos(beta_b)``.  For spur gears this is the plain
method.  Result in N/m along the normal to the flanks.

References
----------
D.C.H. Yang, J.Y. Lin, Hertzian damping, tooth friction and bending elasticity in
gear impact dynamics, J. Mech. Trans. Autom. Des. 109 (1987) 189-196.
X. Tian, Dynamic simulation for system response of gearbox including localized gear
faults, MSc thesis, University of Alberta, 2004.
P. Sainsot, P. Velex, O. Duverger, Contribution of gear body to tooth deflections --
a new bidimensional analytical formula, J. Mech. Des. 126 (2004) 748-752.
F. Chaari, T. Fakhfakh, M. Haddar, Analytical modelling of spur gear tooth crack and
influence on gearmesh stiffness, Eur. J. Mech. A/Solids 28 (2009) 461-468.
H. Ma, J. Zeng, R. Feng, X. Pang, Q. Wang, B. Wen, Review on dynamics of cracked gear
systems, Eng. Fail. Anal. 55 (2015) 224-245.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import GearGeometry, PairGeometry
from torquesplit.gears.stiffness.phasing import (
    in_contact,
    pair_positions,
    phase_grid,
    require_contact,
    slice_offsets,
)
from torquesplit.gears.stiffness.result import MeshStiffness

__all__ = [
    "SAINSOT_COEFFICIENTS",
    "ToothCompliance",
    "tooth_compliance",
    "hertz_compliance",
    "pair_compliance",
    "potential_energy_stiffness",
]

#: Sainsot, Velex & Duverger (2004), Table 1: rows L*, M*, P*, Q*; columns A..F of
#: X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F.
SAINSOT_COEFFICIENTS = np.array([
    [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],   # L*
    [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],   # M*
    [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],    # P*
    [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],  # Q*
])

#: Default ratio r_int / r_f of bore (or rim inner) radius to root radius when none is given.
DEFAULT_BORE_RATIO = 0.5

_GAUSS_INVOLUTE = np.polynomial.legendre.leggauss(40)
_GAUSS_STRAIGHT = np.polynomial.legendre.leggauss(6)


@dataclass(frozen=True)
class ToothCompliance:
    """Compliance terms of one tooth per unit face width [m^2/N] (i.e. ``b / k``),
    transverse plane, at each requested contact point."""

    bending: np.ndarray
    shear: np.ndarray
    axial: np.ndarray
    fillet: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.bending + self.shear + self.axial + self.fillet


def _sainsot_factors(h_fi: float, theta_f: float) -> np.ndarray:
    """L*, M*, P*, Q* of Sainsot et al. (2004) for given h_fi and theta_f [rad]."""
    a, b, c, d, e, f = SAINSOT_COEFFICIENTS.T
    # Sainsot, Velex & Duverger 2004, polynomial X*(h_fi, theta_f)
    return a / theta_f ** 2 + b * h_fi ** 2 + c * h_fi / theta_f + d / theta_f + e * h_fi + f


def tooth_compliance(gear: GearGeometry, roll, *, young_modulus: float, poisson_ratio: float,
                     fillet_foundation: bool = True, bore_radius: float | None = None) -> ToothCompliance:
    """Bending, shear, axial and fillet-foundation compliance of one external tooth.

    Parameters
    ----------
    gear : GearGeometry
        External gear; its transverse tooth form is used.
    roll : array_like
        Roll parameter ``u_c = tan(alpha_c) = rho / r_b`` of the contact point(s)
        (``rho`` the distance from the base-circle tangent point) [-].
    young_modulus, poisson_ratio : float
        ``E`` [Pa], ``nu`` [-].
    fillet_foundation : bool
        Include the Sainsot et al. (2004) term.
    bore_radius : float, optional
        Bore or rim inner radius ``r_int`` [m] for ``h_fi = r_f / r_int``; default
        ``DEFAULT_BORE_RATIO * r_f``.

    Returns
    -------
    ToothCompliance
        Per unit face width [m^2/N], same shape as ``roll``.
    """
    if gear.internal:
        raise ModelError([("internal", "the potential-energy method is implemented for external teeth "
                                       "only; use method='iso6336' or a table for ring gears")])
    E, nu = float(young_modulus), float(poisson_ratio)
    u_c = np.asarray(roll, dtype=float)
    shape = u_c.shape
    u_c = u_c.ravel()
    rb, psi, rf = gear.base_radius, gear.base_half_angle, gear.root_radius
    a1 = u_c - psi                                   # load angle (Tian 2004: alpha_1)
    ca, sa = np.cos(a1), np.sin(a1)
    # contact point: x_c = r_b [cos(a1) + u_c sin(a1)], h_c = r_b [u_c cos(a1) - sin(a1)]
    x_c = rb * (ca + u_c * sa)
    h_c = rb * (u_c * ca - sa)

    def integrands(x, h):
        lever = ca[:, None] * (x_c[:, None] - x) - sa[:, None] * h_c[:, None]
        bend = 3.0 * lever ** 2 / (2.0 * E * h ** 3)          # M^2 / (E I) per unit width
        shear = 1.2 * (1.0 + nu) * ca[:, None] ** 2 / (E * h)  # 1.2 F_b^2 / (G A)
        axial = sa[:, None] ** 2 / (2.0 * E * h)                # F_a^2 / (E A)
        return bend, shear, axial

    # involute part, u from u0 (base circle or root circle) to u_c, Gauss-Legendre
    u0 = math.sqrt(rf * rf / (rb * rb) - 1.0) if rf > rb else 0.0
    t, w = _GAUSS_INVOLUTE
    span = np.clip(u_c - u0, 0.0, None)
    u = u0 + 0.5 * span[:, None] * (t + 1.0)
    al = psi - u
    x = rb * (np.cos(al) - u * np.sin(al))
    h = rb * (np.sin(al) + u * np.cos(al))
    dxdu = rb * u * np.cos(al)
    jac = 0.5 * span[:, None] * w * dxdu
    b_, s_, a_ = integrands(x, h)
    bending = (b_ * jac).sum(axis=1)
    shear = (s_ * jac).sum(axis=1)
    axial = (a_ * jac).sum(axis=1)

    # straight part of base-circle thickness between root circle and base circle
    if rf < rb:
        h_b = rb * math.sin(psi)
        x_r, x_b = math.sqrt(rf * rf - h_b * h_b), rb * math.cos(psi)
        t2, w2 = _GAUSS_STRAIGHT
        xs = x_r + 0.5 * (x_b - x_r) * (t2 + 1.0)
        hs = np.full_like(xs, h_b)
        b2, s2, a2 = integrands(xs[None, :], hs[None, :])
        wj = 0.5 * (x_b - x_r) * w2
        bending = bending + (b2 * wj).sum(axis=1)
        shear = shear + (s2 * wj).sum(axis=1)
        axial = axial + (a2 * wj).sum(axis=1)

    fillet = np.zeros_like(bending)
    if fillet_foundation:
        r_int = DEFAULT_BORE_RATIO * rf if bore_radius is None else float(bore_radius)
        if not (0 < r_int < rf):
            raise ModelError([("bore_radius", f"must lie between 0 and the root radius {rf:.6g} m, "
                                              f"got {r_int!r}")])
        theta_f = gear.root_half_angle
        L, M, P, Q = _sainsot_factors(rf / r_int, theta_f)
        s_f = 2.0 * rf * theta_f                        # tooth thickness at the root circle
        u_f = rb / ca - rf                              # force line meets the centreline at r_b/cos(a1)
        ratio = u_f / s_f
        # Sainsot, Velex & Duverger 2004: delta_f = F cos^2(a_m)/(E b) [L* (u_f/S_f)^2 + M* u_f/S_f + P* (1 + Q* tan^2 a_m)]
        fillet = ca ** 2 / E * (L * ratio ** 2 + M * ratio + P * (1.0 + Q * np.tan(a1) ** 2))

    return ToothCompliance(*(c.reshape(shape) for c in (bending, shear, axial, fillet)))


def hertz_compliance(young_modulus, poisson_ratio) -> float:
    """Hertzian contact compliance per unit contact-line length [m^2/N].

    ``b / k_h = (2 / pi) [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]``, i.e. for one material
    ``k_h = pi E b / (4 (1 - nu^2))`` (Yang & Lin 1987).
    """
    (e1, e2), (n1, n2) = _two(young_modulus, "young_modulus"), _two(poisson_ratio, "poisson_ratio")
    # Yang & Lin 1987: k_h = pi E b / (4 (1 - nu^2)), written for two materials
    return 2.0 / math.pi * ((1.0 - n1 ** 2) / e1 + (1.0 - n2 ** 2) / e2)


def _two(value, name) -> tuple[float, float]:
    if np.ndim(value) == 0:
        v = (float(value), float(value))
    else:
        if len(value) != 2:
            raise ModelError([(name, "give one value or a pair (gear 1, gear 2)")])
        v = (float(value[0]), float(value[1]))
    if name == "young_modulus" and not all(x > 0 for x in v):
        raise ModelError([(name, f"must be positive, in Pa (steel: 206e9), got {value!r}")])
    if name == "poisson_ratio" and not all(0 <= x < 0.5 for x in v):
        raise ModelError([(name, f"must lie in [0, 0.5), got {value!r}")])
    return v


def _two_radii(value) -> tuple[float | None, float | None]:
    if value is None or np.ndim(value) == 0:
        return value, value
    return value[0], value[1]


def pair_compliance(pair: PairGeometry, s, *, young_modulus=206e9, poisson_ratio=0.3,
                    fillet_foundation: bool = True, bore_radius=None) -> dict[str, np.ndarray]:
    """Compliance of one tooth pair in contact at path positions ``s`` [m], per unit face width.

    Returns a dict of arrays [m^2/N] (``b / k``): ``tooth1`` and ``tooth2``
    (:class:`ToothCompliance` totals, transverse plane), ``hertz`` (per unit contact
    length), and ``normal`` = ``cos^2(beta_b) (tooth1 + tooth2) + cos(beta_b) hertz``,
    the compliance of a face slice of unit width along the flank normal
    (``1/normal`` is the stiffness per unit face width).
    """
    if pair.is_internal:
        raise ModelError([("gear2.internal", "the potential-energy method is implemented for external "
                                             "pairs only; use method='iso6336' or a table for ring gears")])
    (e1, e2), (n1, n2) = _two(young_modulus, "young_modulus"), _two(poisson_ratio, "poisson_ratio")
    r1, r2 = _two_radii(bore_radius)
    rho1, rho2 = pair.roll_distances(s)
    g1, g2 = pair.gear1, pair.gear2
    c1 = tooth_compliance(g1, rho1 / g1.base_radius, young_modulus=e1, poisson_ratio=n1,
                          fillet_foundation=fillet_foundation, bore_radius=r1)
    c2 = tooth_compliance(g2, rho2 / g2.base_radius, young_modulus=e2, poisson_ratio=n2,
                          fillet_foundation=fillet_foundation, bore_radius=r2)
    h = hertz_compliance((e1, e2), (n1, n2))
    cb = math.cos(pair.base_helix_angle)
    return {"tooth1": c1.total, "tooth2": c2.total, "hertz": h,
            "normal": cb * cb * (c1.total + c2.total) + cb * h,
            "components1": c1, "components2": c2}


def potential_energy_stiffness(pair: PairGeometry, n: int = 256, *, young_modulus=206e9,
                               poisson_ratio=0.3, fillet_foundation: bool = True, bore_radius=None,
                               slices: int | None = None, stagger: float = 0.0,
                               grid: int = 512) -> MeshStiffness:
    """Mesh stiffness over one mesh cycle by the potential-energy method [N/m].

    Parameters
    ----------
    pair : PairGeometry
        External spur, helical or double-helical pair.
    n : int
        Number of uniform phase samples.
    young_modulus, poisson_ratio : float or (float, float)
        Material of gear 1 and gear 2 [Pa], [-]; default steel 206 GPa, 0.3.
    fillet_foundation : bool
        Include the fillet-foundation flexibility (Sainsot et al. 2004).
    bore_radius : float or (float, float), optional
        Bore / rim inner radius ``r_int`` of each gear [m] (fillet-foundation term);
        default half the root radius.
    slices : int, optional
        Number of face slices of a helical pair (default 50).  A spur pair's slices
        are all in phase, so it is computed unsliced whatever the value.
    stagger : float
        Phase offset of the second helix of a double-helical pair [cycles].
    grid : int
        Helical pairs: the single-pair compliance is tabulated on ``grid`` points of
        the path of contact and interpolated for the slices.

    Returns
    -------
    MeshStiffness
        ``info`` holds the contact ratios and the single-pair stiffness at the pitch point.

    Examples
    --------
    >>> import math
    >>> from torquesplit.gears.geometry import GearGeometry, PairGeometry
    >>> a = math.radians(20)
    >>> p = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
    ...                  GearGeometry(40, 2e-3, a, face_width=0.02))
    >>> k = potential_energy_stiffness(p, 64)
    >>> 1e8 < k.mean < 1e9
    True
    """
    require_contact(pair)
    opts = dict(young_modulus=young_modulus, poisson_ratio=poisson_ratio,
                fillet_foundation=fillet_foundation, bore_radius=bore_radius)
    phase = phase_grid(n)
    helical = pair.gear1.beta > 0
    if not helical:
        # all slices of a spur pair are in phase: the result does not depend on `slices`
        if slices is not None and not (isinstance(slices, (int, np.integer)) and slices >= 1):
            raise ModelError([("slices", f"must be a positive integer, got {slices!r}")])
        if stagger:
            raise ModelError([("stagger", "applies to double-helical pairs only")])
        s = pair_positions(pair, phase)                       # (n, K)
        mask = in_contact(pair, s)
        comp = np.full(s.shape, np.inf)
        comp[mask] = pair_compliance(pair, s[mask], **opts)["normal"]
        k = (pair.face_width / comp).sum(axis=-1)
    else:
        slices = 50 if slices is None else slices
        if stagger and not pair.double_helical:
            raise ModelError([("stagger", "applies to double-helical pairs only")])
        s_grid = np.linspace(pair.path_start, pair.path_end, int(grid))
        k_grid = 1.0 / pair_compliance(pair, s_grid, **opts)["normal"]   # per unit face width
        lag, db = slice_offsets(pair, slices)

        def one_helix(offset: float) -> np.ndarray:
            ph = np.mod(phase + offset, 1.0)
            s = pair_positions(pair, ph, lag)                   # (n, slices, K)
            mask = in_contact(pair, s)
            kk = np.where(mask, np.interp(s, s_grid, k_grid), 0.0)
            return db * kk.sum(axis=(-1, -2))

        k = one_helix(0.0)
        if pair.double_helical:
            k = k + one_helix(stagger)
    k_pitch = 1.0 / float(pair_compliance(pair, np.array([0.0]), **opts)["normal"][0])
    info = {
        "transverse_contact_ratio": pair.transverse_contact_ratio,
        "overlap_contact_ratio": pair.overlap_contact_ratio,
        "single_pair_stiffness_per_width_at_pitch_point": k_pitch,
        "fillet_foundation": fillet_foundation,
        "slices": 1 if not helical else slices,
    }
    return MeshStiffness.from_samples(k, "potential_energy", info)
