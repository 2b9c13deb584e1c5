"""Contact frame and line of action of a mesh, from the layout and the power flow.

One formulation for every pair (docs/theory/model.md).  At the mean contact point P each gear
``i`` has its axis ``a_i``, the radial unit vector ``e_r,i`` from its axis to P and the
tangent ``t_i = a_i x e_r,i``.  The force the driver exerts on the driven gear acts along

* cylindrical pairs (spur, helical, double-helical, internal), transverse working
  pressure angle ``alpha_wt`` and base helix angle ``beta_b``::

      n = cos(beta_b) (cos(alpha_wt) e_t + sep sin(alpha_wt) e_r) - h s sin(beta_b) a

* conical pairs (bevel, face), normal pressure angle ``alpha_n``, spiral angle ``psi``
  and pitch-cone angle ``gamma`` of the driver::

      n = cos(alpha_n) cos(psi) e_t + sep sin(alpha_n) m - h s cos(alpha_n) sin(psi) g

  with ``m = cos(gamma) e_r - sin(gamma) a`` the outward normal of the pitch cone and
  ``g = sin(gamma) e_r + cos(gamma) a`` the cone element (apex to heel).  For gamma = 0
  and psi = beta this is the cylindrical form written with normal angles; Jin et al. 2019 eq. 4
  and Dong et al. 2021 eq. 2 are special cases of it.

Here ``e_t = s t`` is the direction in which the driver's contact point moves (s is the
sign of the driver's speed about its axis), ``sep = +1`` for an external driver and -1
for an internal one (the separating force pushes the driven gear away from the driver's
flank), and ``h = +1`` for a right hand, -1 for a left hand (0 for spur gears).  For a
double-helical pair the axial components of the two helices cancel: n keeps only its
transverse part and is not renormalised (``|n| = cos(beta_b)``), so that ``V . q`` is the
normal flank deflection and the mesh force is the normal force of both helices.  The projection coefficient of a
gear's rotation is its arm ``(rho x n) . a = r n . t``; for the driver this is
``s r_b cos(beta_b)`` for a cylindrical pair.

Bevel and face gears: the axis of a bevel or face gear points from the cone apex
towards its back; ``module`` is the outer transverse module and the contact point lies
at the mean cone distance.  A face gear meshes with a cylindrical pinion whose pitch
cone angle is 0 and the face gear's is the shaft angle.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .geometry import GearGeometry, PairGeometry
from .vectors import cross


@dataclass(frozen=True)
class ContactFrame:
    """Geometry of one mesh at its mean contact point (SI, global frame)."""

    gears: tuple[str, str]
    contact_point: np.ndarray
    radial: tuple[np.ndarray, np.ndarray]
    tangent: tuple[np.ndarray, np.ndarray]
    pitch_radii: tuple[float, float]
    base_radii: tuple[float, float]
    speed_ratio: float
    """omega_b / omega_a, signed about each gear's own axis."""
    conical: bool
    cone_angles: tuple[float, float]
    working_pressure_angle: float
    """Transverse working pressure angle (cylindrical) or normal pressure angle (conical)."""
    base_helix_angle: float
    transverse_contact_ratio: float
    overlap_contact_ratio: float
    center_distance: float
    pair_geometry: PairGeometry | None


def gear_geometry(gear, teeth=None) -> GearGeometry:
    """Involute geometry of a schema gear (``teeth`` overrides, for virtual gears)."""
    return _geometry(teeth if teeth is not None else gear.teeth, gear.module,
                     gear.pressure_angle, abs(gear.helix_angle), gear.face_width,
                     gear.profile_shift, gear.gear_type)


@functools.lru_cache(maxsize=1024, typed=True)  # (typed: 20.0 teeth is refused, 20 not)
def _geometry(teeth, module, pressure_angle, helix_angle, face_width, profile_shift,
              gear_type) -> GearGeometry:
    """One (immutable) geometry per set of values: a model's set-up asks for each gear's
    about ten times, and its derived radii and angles are computed once."""
    return GearGeometry(teeth=teeth, normal_module=module,
                        normal_pressure_angle=pressure_angle, helix_angle=helix_angle,
                        face_width=face_width, profile_shift=profile_shift,
                        internal=gear_type == "internal",
                        double_helical=gear_type == "double_helical")


def _perp_unit(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    w = v - axis * float(v @ axis)
    n = float(np.linalg.norm(w))
    if n < 1e-12:
        trial = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        w = trial - axis * float(trial @ axis)
        n = float(np.linalg.norm(w))
    return w / n


def _closest_point_on_line(p1, d1, p2, d2) -> np.ndarray:
    """Point of line (p1, d1) closest to line (p2, d2) (the apex of crossed axes)."""
    w = p1 - p2
    b = float(d1 @ d2)
    den = 1.0 - b * b
    if den < 1e-12:
        return p1.copy()
    t = (b * float(d2 @ w) - float(d1 @ w)) / den
    return p1 + t * d1


def reference_direction(axis: np.ndarray, angle: float) -> np.ndarray:
    """Unit vector in the plane normal to ``axis`` at ``angle`` from its x reference.

    The reference is the global x axis projected on the plane (global y if the axis is
    along x); angles are counter-clockwise about ``axis``.
    """
    e1 = _perp_unit(np.array([1.0, 0.0, 0.0]), axis)
    e2 = cross(axis, e1)
    return math.cos(angle) * e1 + math.sin(angle) * e2


def is_conical(gear_a, gear_b) -> bool:
    return bool({gear_a.gear_type, gear_b.gear_type} & {"bevel", "face"})


def cylindrical_pair(gear_a, gear_b) -> PairGeometry:
    """PairGeometry of two cylindrical gears (an internal gear is always put second)."""
    if gear_a.gear_type == "internal":
        return _pair(gear_geometry(gear_b), gear_geometry(gear_a))
    return _pair(gear_geometry(gear_a), gear_geometry(gear_b))


@functools.lru_cache(maxsize=1024)
def _pair(gear_1: GearGeometry, gear_2: GearGeometry) -> PairGeometry:
    """One (immutable) pair per pair of geometries: a model's set-up asks for each mesh's
    about four times (its checks and interference test ran each time)."""
    return PairGeometry(gear_1, gear_2)


def placed_position(model, name, ref, ref_position, ref_axis, angle) -> np.ndarray:
    """Centre of gear ``name`` placed from mating gear ``ref`` at a centre-line angle."""
    g, r = model.gears[name], model.gears[ref]
    direction = reference_direction(ref_axis, angle)
    if "face" in (g.gear_type, r.gear_type):
        raise ValueError(
            f"gear {name!r} meshes with {ref!r} as a face-gear pair: 'place' is for parallel "
            f"axes; give the face gear and its pinion explicit 'position' and 'axis'")
    if is_conical(g, r):
        # a bevel pair's contact frame follows from the axes alone; the centre is put at
        # the mating gear's pitch radius in the given direction (used for display only)
        return ref_position + (r.teeth * r.module / 2) * direction
    pair = cylindrical_pair(r, g)
    return ref_position + pair.operating_center_distance * direction


def contact_frame(model, mesh_name: str, positions: dict, axes: dict) -> ContactFrame:
    """The contact frame of a mesh; raises ValueError with a fix if the layout is wrong."""
    mesh = model.meshes[mesh_name]
    na, nb = mesh.gears
    ga, gb = model.gears[na], model.gears[nb]
    aa, ab = axes[na], axes[nb]
    if is_conical(ga, gb):
        return _conical_frame(mesh, na, nb, ga, gb, aa, ab, positions)
    if abs(abs(float(aa @ ab)) - 1) > 1e-6:
        raise ValueError(
            f"gears {na!r} and {nb!r} are cylindrical but their axes are not parallel; give them "
            f"the same 'axis', or set kind = 'bevel' / 'face' for crossed axes")
    pair = cylindrical_pair(ga, gb)
    d = positions[nb] - positions[na]
    d_perp = d - aa * float(d @ aa)
    dist = float(np.linalg.norm(d_perp))
    aw = pair.operating_center_distance
    if dist < 1e-9 or abs(dist - aw) > 1e-3 * aw:
        raise ValueError(
            f"the positions put gears {na!r} and {nb!r} {dist * 1e3:.4f} mm apart, but their "
            f"operating centre distance is {aw * 1e3:.4f} mm (from teeth, module and profile "
            f"shift); correct 'position', or use place = {{from_gear = ..., angle = ...}}")
    u = d_perp / dist
    ra, rb = pair.working_pitch_radii
    rba, rbb = pair.gear1.base_radius, pair.gear2.base_radius
    if ga.gear_type == "internal":
        ra, rb, rba, rbb = rb, ra, rbb, rba
    internal_b = gb.gear_type == "internal"
    internal_a = ga.gear_type == "internal"
    if internal_b:  # pinion a inside ring b: contact on the far side from the ring centre
        point = positions[na] - ra * u
        er_a, er_b = -u, -u
    elif internal_a:
        point = positions[nb] - rb * (-u)
        er_a, er_b = u, u
    else:
        point = positions[na] + ra * u
        er_a, er_b = u, -u
    ta, tb = cross(aa, er_a), cross(ab, er_b)
    ratio = (ga.teeth / gb.teeth) * float(ta @ tb)
    return ContactFrame(
        gears=(na, nb), contact_point=point, radial=(er_a, er_b), tangent=(ta, tb),
        pitch_radii=(ra, rb), base_radii=(rba, rbb), speed_ratio=ratio, conical=False,
        cone_angles=(0.0, 0.0), working_pressure_angle=pair.working_pressure_angle,
        base_helix_angle=pair.base_helix_angle,
        transverse_contact_ratio=pair.transverse_contact_ratio,
        overlap_contact_ratio=pair.overlap_contact_ratio,
        center_distance=aw, pair_geometry=pair,
    )


def _conical_frame(mesh, na, nb, ga, gb, aa, ab, positions) -> ContactFrame:
    cos_sigma = float(np.clip(aa @ ab, -1.0, 1.0))
    sigma = mesh.shaft_angle if mesh.shaft_angle is not None else math.acos(cos_sigma)
    if abs(math.sin(sigma)) < 1e-6:
        raise ValueError(
            f"bevel/face gears {na!r} and {nb!r} have parallel axes; give their axes at the shaft "
            f"angle (each pointing from the cone apex towards the gear's back)")
    if not math.isclose(math.cos(sigma), cos_sigma, abs_tol=1e-6):
        raise ValueError(
            f"shaft_angle {math.degrees(sigma):g} deg contradicts the axes of {na!r} and {nb!r} "
            f"({math.degrees(math.acos(cos_sigma)):g} deg apart); correct one of them")
    za, zb = ga.teeth, gb.teeth
    if ga.gear_type == "face" and gb.gear_type != "face":
        gam_a, gam_b = sigma, 0.0
    elif gb.gear_type == "face" and ga.gear_type != "face":
        gam_a, gam_b = 0.0, sigma
    else:
        # pitch-cone angles of a bevel pair: tan(gamma_1) = sin(S) / (z2/z1 + cos(S))
        gam_a = math.atan2(math.sin(sigma), zb / za + math.cos(sigma))
        gam_b = sigma - gam_a
    if ga.cone_angle is not None:
        gam_a = ga.cone_angle
    if gb.cone_angle is not None:
        gam_b = gb.cone_angle
    face = "face" in (ga.gear_type, gb.gear_type)
    if face:
        # face gear on a cylindrical pinion: pitch radii z m / 2 (their ratio is the
        # speed ratio); the contact lies on the pinion's pitch cylinder on the side of
        # the face gear, at the face gear's pitch radius from its axis (positions decide
        # at which end of the pinion a face gear sits)
        ip, jf = (0, 1) if gb.gear_type == "face" else (1, 0)
        names, gears, axes_ = (na, nb), (ga, gb), (aa, ab)
        cp, cf = positions[names[ip]], positions[names[jf]]
        ap, af = axes_[ip], axes_[jf]
        rp = gears[ip].teeth * gears[ip].module / 2
        rf = gears[jf].teeth * gears[jf].module / 2
        er_p = _perp_unit(cf - cp, ap)
        apex = _closest_point_on_line(cp, ap, cf, af)
        side = float((cp - apex) @ ap)
        side = 1.0 if side >= 0 else -1.0
        point = apex + side * rf * ap + rp * er_p
        er_f = _perp_unit(point - cf, af)
        radials = [None, None]
        radials[ip], radials[jf] = er_p, er_f
        radii = [0.0, 0.0]
        radii[ip], radii[jf] = rp, rf
        er_a, er_b = radials
        ra, rb = radii
    else:
        e_perp = _perp_unit(ab, aa)
        g_line = math.cos(gam_a) * aa + math.sin(gam_a) * e_perp
        er_a = e_perp
        er_b = _perp_unit(g_line, ab)

        def mean_radius(g, gam):
            # mean pitch radius at mid face width along the cone
            r_outer = g.teeth * g.module / 2
            return r_outer - 0.5 * g.face_width * math.sin(gam)

        ra, rb = mean_radius(ga, gam_a), mean_radius(gb, gam_b)
        point = positions[na] + ra * er_a
    ta, tb = cross(aa, er_a), cross(ab, er_b)
    ratio = (za / zb) * float(ta @ tb)
    # contact ratio from the virtual (Tredgold) spur/helical gears z_v = z / cos(gamma)
    eps_a, eps_b, pair = float("nan"), float("nan"), None
    try:
        zva = max(int(round(za / max(math.cos(gam_a), 1e-3))), 5)
        zvb = max(int(round(zb / max(math.cos(gam_b), 1e-3))), 5)
        pair = PairGeometry(gear_geometry(ga, zva), gear_geometry(gb, zvb))
        eps_a, eps_b = pair.transverse_contact_ratio, pair.overlap_contact_ratio
    except Exception:  # geometry of a virtual gear outside the involute model
        pair = None
    alpha_n = ga.pressure_angle
    return ContactFrame(
        gears=(na, nb), contact_point=point, radial=(er_a, er_b), tangent=(ta, tb),
        pitch_radii=(ra, rb),
        base_radii=(ra * math.cos(alpha_n), rb * math.cos(alpha_n)),
        speed_ratio=ratio, conical=True, cone_angles=(gam_a, gam_b),
        working_pressure_angle=alpha_n, base_helix_angle=abs(ga.helix_angle),
        transverse_contact_ratio=eps_a, overlap_contact_ratio=eps_b,
        center_distance=float("nan"), pair_geometry=None,
    )


def _hand(gear) -> int:
    if gear.gear_type == "double_helical" or gear.helix_angle == 0 or gear.hand is None:
        return 0
    return 1 if gear.hand == "right" else -1


def line_of_action(model, mesh_name: str, frame: ContactFrame, driver: str, speeds: dict):
    """Unit force direction n (driver on driven) and the arms of driver and driven.

    Returns ``(n, arm_driver, arm_driven)``, the arms being ``r_i n . t_i``.
    """
    i = frame.gears.index(driver)
    j = 1 - i
    gd = model.gears[driver]
    a = np.asarray(gd.axis, dtype=float)
    a = a / np.linalg.norm(a)
    s = 1.0 if speeds[driver] > 0 else -1.0
    er = frame.radial[i]
    et = s * frame.tangent[i]
    sep = -1.0 if gd.gear_type == "internal" else 1.0
    h = _hand(gd)
    if frame.conical:
        alpha_n = gd.pressure_angle
        psi = abs(gd.helix_angle)
        gam = frame.cone_angles[i]
        m = math.cos(gam) * er - math.sin(gam) * a
        g = math.sin(gam) * er + math.cos(gam) * a
        # conical line of action (Jin et al. 2019 eq. 4 / Dong et al. 2021 eq. 2 in vector form)
        n = (math.cos(alpha_n) * math.cos(psi) * et + sep * math.sin(alpha_n) * m
             - h * s * math.cos(alpha_n) * math.sin(psi) * g)
    else:
        alpha = frame.working_pressure_angle
        beta_b = frame.base_helix_angle
        n = (math.cos(beta_b) * (math.cos(alpha) * et + sep * math.sin(alpha) * er)
             - h * s * math.sin(beta_b) * a)
    if gd.gear_type != "double_helical":
        n = n / np.linalg.norm(n)
    # double-helical: the axial components of the two helices cancel, so n keeps only its
    # transverse part, |n| = cos(beta_b): V.q is then the normal deflection of the flanks
    # and the force along n is the normal tooth force of both helices together.
    arm_d = frame.pitch_radii[i] * float(n @ frame.tangent[i])
    arm_n = frame.pitch_radii[j] * float(n @ frame.tangent[j])
    return n, arm_d, arm_n
