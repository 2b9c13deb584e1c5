"""Slice compliance of a tooth pair along the path of contact (tables for the LTCA).

Per unit face width and in the transverse plane, each tooth contributes the
potential-energy terms of :mod:`torquesplit.gears.stiffness.potential_energy`
(bending, shear, axial compression -- Yang & Lin 1987, Tian 2004 -- and the
fillet foundation of Sainsot, Velex & Duverger 2004).  The LTCA splits them:

* **bending** is the plate part that neighbouring slices share.  Each tooth is a strip
  of slices resting on a Pasternak foundation (Winkler springs plus a shear layer,
  Pasternak 1954; used for gear teeth by Seager 1967 and Ajmi & Velex 2005)::

      k_b w - G w'' = q(y)            (per unit face width, y across the face)

  ``k_b`` is the bending stiffness per unit width of the slice (the inverse of the
  potential-energy bending compliance).  ``G`` follows from the Kirchhoff plate energy
  (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, 1959, §10) of a
  cantilever strip of length ``h`` (root circle to load point, measured along the tooth
  centreline) deflecting in the cantilever shape ``phi(x) = x^2 (3h - x) / (2 h^3)``
  times ``w(y)`` -- a Ritz approximation: bending across the face gives
  ``k_b = 3D/h^3``, the twisting term ``2 (1 - nu) D w'^2 int phi'^2 dx`` gives
  ``G = 2 (1 - nu) D * 6 / (5 h)``, so::

      G = (4 (1 - nu) / 5) h^2 k_b         decay length lambda = sqrt(G/k_b) ~ 0.75 h

  (the plate modulus D cancels; ``k_b`` is taken from the potential-energy bending term
  so that a uniformly loaded face reproduces the potential-energy method exactly);
* **shear, axial compression and fillet foundation** are local to the slice (the
  fillet-foundation term is in reality not local; this is the usual slice approximation);
* **contact**: Hertzian line contact of the slice, either linear (Yang & Lin 1987,
  as in the potential-energy method) or load dependent after Weber (1949) / Johnson
  (1985) §5.6 (:func:`torquesplit.gears.contact._kernels.contact_deflection`), with the
  reduced radius of curvature of the flanks in the normal plane and the depths ``d``
  from the contact point to the tooth centreline along the line of the force.

Ring gears (internal pairs): ISO 6336-1 treats the teeth of an internal gear as those of
the basic rack (virtual tooth number infinite).  Their bending, shear, axial and fillet
terms are here those of an external tooth of :data:`RACK_TEETH` teeth with the same
module, pressure angle, addendum, dedendum and tool, loaded at the same height above its
reference circle (an approximation, stated), without the fillet-foundation term: the fit
of Sainsot et al. is for external gears (it turns negative for the proxy's tiny root
angle), and the foundation of a ring's teeth is its rim, which is not modelled.

Normal direction: a transverse compliance ``c_t`` becomes ``cos^2(beta_b) c_t`` along the
flank normal; a slice of axial width ``db`` has a contact line ``db / cos(beta_b)`` long
(as in :func:`~torquesplit.gears.stiffness.potential_energy.pair_compliance`).

All SI.  Tables are sampled on ``grid`` points over the active path ``[s_A, s_E]`` and
interpolated linearly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import GearGeometry, PairGeometry
from torquesplit.gears.stiffness.potential_energy import (
    _two,
    _two_radii,
    tooth_compliance,
)

__all__ = ["RACK_TEETH", "SliceTables", "slice_tables", "pasternak_parameter", "rack_proxy"]

#: tooth count of the external gear that stands in for the basic rack (ring-gear teeth)
RACK_TEETH = 1000


def pasternak_parameter(lever, bending_stiffness, poisson_ratio):
    """Shear-layer parameter ``G = 4 (1 - nu) h^2 k_b / 5`` of a tooth strip [N]
    (Ritz approximation of the Kirchhoff plate, see the module docstring)."""
    # Timoshenko & Woinowsky-Krieger 1959 plate energy, Ritz with the cantilever shape
    return 0.8 * (1.0 - poisson_ratio) * np.asarray(lever) ** 2 * np.asarray(bending_stiffness)


def rack_proxy(ring: GearGeometry) -> GearGeometry:
    """External gear of :data:`RACK_TEETH` teeth standing in for the teeth of a ring gear.

    The ring's profile shift ``x`` (positive away from the axis, see geometry.py) gives
    the ring tooth an addendum ``m (h_a - x)`` and a dedendum ``m (h_f + x)``: the proxy
    gets ``x_proxy = -x``, which gives it the same addendum, dedendum and tooth thickness.
    """
    return GearGeometry(RACK_TEETH, ring.normal_module, ring.normal_pressure_angle,
                        ring.helix_angle, ring.face_width, -ring.profile_shift, ring.addendum,
                        ring.dedendum, False, False, ring.tool_tip_radius)


@dataclass(frozen=True)
class SliceTables:
    """Tooth and contact properties of a pair along the active path (SI).

    Attributes (arrays over ``s``, the transverse path position [m]):
    ``bending1/2`` transverse bending compliance per unit face width [m^2/N];
    ``local1/2`` shear + axial + fillet compliance per unit face width [m^2/N];
    ``lever1/2`` cantilever length root circle -> load point [m];
    ``depth1/2`` distance contact point -> tooth centreline along the force [m];
    ``radius`` reduced radius of curvature of the flanks in the normal plane [m].
    """

    s: np.ndarray
    bending1: np.ndarray
    bending2: np.ndarray
    local1: np.ndarray
    local2: np.ndarray
    lever1: np.ndarray
    lever2: np.ndarray
    depth1: np.ndarray
    depth2: np.ndarray
    radius: np.ndarray


def _tooth_table(gear: GearGeometry, roll, E, nu, fillet_foundation, bore_radius):
    """(bending, local, lever, depth) of an external tooth at roll parameters ``roll``."""
    c = tooth_compliance(gear, roll, young_modulus=E, poisson_ratio=nu,
                         fillet_foundation=fillet_foundation, bore_radius=bore_radius)
    # contact point on the tooth (Tian 2004, as in potential_energy.tooth_compliance):
    # load angle a1 = u_c - psi_b; x_c along the centreline, h_c half thickness there
    u = np.asarray(roll, dtype=float)
    rb, psi, rf = gear.base_radius, gear.base_half_angle, gear.root_radius
    a1 = u - psi
    x_c = rb * (np.cos(a1) + u * np.sin(a1))
    h_c = rb * (u * np.cos(a1) - np.sin(a1))
    lever = np.maximum(x_c - rf, 1e-3 * gear.normal_module)
    depth = np.maximum(h_c / np.cos(a1), 1e-3 * gear.normal_module)
    return c.bending, c.shear + c.axial + c.fillet, lever, depth


def slice_tables(pair: PairGeometry, *, young_modulus=206e9, poisson_ratio=0.3,
                 fillet_foundation: bool = True, bore_radius=None, grid: int = 256) -> SliceTables:
    """Slice properties of ``pair`` on ``grid`` points of the active path.

    Parameters
    ----------
    pair : PairGeometry
        Spur, helical, double-helical or internal pair.
    young_modulus, poisson_ratio : float or (float, float)
        Materials of gear 1 and gear 2 [Pa], [-].
    fillet_foundation : bool
        Include the Sainsot et al. (2004) fillet-foundation term.
    bore_radius : float or (float, float), optional
        Bore / rim inner radius of each gear [m] (default half the root radius; for a
        ring gear it stands for the proxy's).
    grid : int
        Number of samples.
    """
    if not (isinstance(grid, (int, np.integer)) and grid >= 8):
        raise ModelError([("grid", f"must be an integer >= 8, got {grid!r}; give e.g. 256")])
    (e1, e2), (n1, n2) = _two(young_modulus, "young_modulus"), _two(poisson_ratio, "poisson_ratio")
    b1, b2 = _two_radii(bore_radius)
    s = np.linspace(pair.path_start, pair.path_end, int(grid))
    rho1, rho2 = pair.roll_distances(s)
    g1 = pair.gear1
    bend1, loc1, lev1, dep1 = _tooth_table(g1, rho1 / g1.base_radius, e1, n1, fillet_foundation, b1)
    g2 = pair.gear2
    if pair.is_internal:
        proxy = rack_proxy(g2)
        r2 = np.sqrt(g2.base_radius ** 2 + rho2 ** 2)
        eta = g2.reference_radius - r2            # height above the ring's reference circle
        r_proxy = proxy.reference_radius + eta
        roll2 = np.sqrt(np.maximum(r_proxy ** 2 / proxy.base_radius ** 2 - 1.0, 0.0))
        # no fillet foundation: Sainsot et al.'s fit is for external gears (it turns
        # negative for the proxy's tiny root angle); a ring's foundation is its rim
        bend2, loc2, lev2, dep2 = _tooth_table(proxy, roll2, e2, n2, False, None)
    else:
        bend2, loc2, lev2, dep2 = _tooth_table(g2, rho2 / g2.base_radius, e2, n2,
                                               fillet_foundation, b2)
    for name, v in (("gear1", bend1), ("gear1", loc1), ("gear2", bend2), ("gear2", loc2)):
        if not np.all(v > 0):
            raise ModelError([("fillet_foundation", (
                f"the tooth compliance of {name} is not positive on the path of contact (the "
                "fillet-foundation fit of Sainsot et al. 2004 is outside its range for this "
                "tooth); set fillet_foundation = false"))])
    r1n, r2n = pair.curvature_radii(s, normal=True)
    radius = r1n * r2n / (r1n + r2n)
    if np.any(radius <= 0):
        raise ModelError([("geometry", "non-positive reduced radius of curvature on the path "
                                       "(check the internal pair's tooth counts)")])
    return SliceTables(s=s, bending1=bend1, bending2=bend2, local1=loc1, local2=loc2,
                       lever1=lev1, lever2=lev2, depth1=dep1, depth2=dep2, radius=radius)


def interpolate(tables: SliceTables, s) -> dict[str, np.ndarray]:
    """Every table at path positions ``s`` (clipped to the active path)."""
    sc = np.clip(s, tables.s[0], tables.s[-1])
    return {name: np.interp(sc, tables.s, getattr(tables, name))
            for name in ("bending1", "bending2", "local1", "local2", "lever1", "lever2",
                         "depth1", "depth2", "radius")}


def normal_factor(pair: PairGeometry) -> float:
    """``cos(beta_b)`` of the pair."""
    return math.cos(pair.base_helix_angle)
