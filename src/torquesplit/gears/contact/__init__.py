"""Loaded tooth contact analysis (LTCA) of cylindrical gear pairs with tooth modifications.

=================  =====================================================================
module             what it does
=================  =====================================================================
``modifications``  tip/root relief (linear, parabolic, Liu et al. 2021 eq. 20 curve),
                   crowning, end relief, helix slope; the y1..y6 topological preset of
                   Liu et al. 2021; misalignment and base pitch deviation; the initial
                   separation they give at any point of the flanks
``compliance``     slice properties along the path of contact: potential-energy
                   bending (shared by neighbouring slices through a Pasternak strip),
                   shear, axial and fillet-foundation compliance, contact geometry
``_kernels``       the compiled kernels (numba, ``cache=True``) with their readable
                   numpy twins: Weber/Johnson line-contact approach, the contact problem
                   at every position (primal active-set method, Hertz fixed point)
``ltca``           :class:`ContactModel` (built once per pair and modification),
                   :class:`LtcaResult` (one load), :class:`HarrisMap` (several loads),
                   :func:`ltca_stiffness` (the ``"ltca"`` mesh-stiffness method)
``impact``         meshing-in impact from the loaded geometry (Liu et al. 2021 eqs. 6-10)
``coupling``       a mesh of a model -> stiffness table, transmission-error excitation and
                   impact force for the assembly (``stiffness.method = "ltca"``)
``cache``          on-disk cache of those tables keyed by a hash of every input
=================  =====================================================================

The model
---------
At each of ``M`` uniform mesh positions ``phi_m = m / M`` (phase 0: a new tooth pair
enters contact at the driver's start of active profile, at the entry end of the face),
the face of each helix is cut into ``N`` slices; slice ``j`` of tooth pair ``k`` touches
at the transverse path position ``s = s_A + (phi + k) p_bt - y_j tan(beta_b)``
(:mod:`torquesplit.gears.stiffness.phasing`), and is a potential contact point while
``s`` lies on the active path.  Each point has

* a compliance: the tooth bending of both teeth (a Pasternak strip per tooth, so that
  neighbouring slices share load), shear, axial compression and fillet foundation
  (Yang & Lin 1987; Tian 2004; Sainsot, Velex & Duverger 2004: the terms of the
  potential-energy method, per unit face width) and the Hertzian contact of the
  slice (Weber 1949 / Johnson 1985 §5.6, load dependent; or Yang & Lin's linear one);
* an initial separation from the modifications of both flanks, the misalignment and the
  base pitch deviation (Liu et al. 2021 eq. 22; Dong et al. 2021 eq. 13: ``w = delta + b``).

The contact problem -- loads ``p >= 0``, gaps closed where loaded and open elsewhere,
``sum(p) = P`` -- is solved exactly at every position (Conry & Seireg 1971 formulation
as a quadratic programme; primal active-set method, Nocedal & Wright 2006 Alg. 16.3),
the Hertz compliance updated from the loads until nothing changes.  Outputs per
position: loaded static transmission error ``Z`` (approach along the flank normal),
slice loads, secant ``P/Z`` (Liu et al. 2021 eq. 5) and tangent ``dP/dZ`` stiffness,
maximum Hertz pressure, loaded tooth pairs; over loads, the Harris map.

Conventions
-----------
* SI throughout: N, m, Pa, rad; transmission error also in arc seconds of gear 2
  (Liu et al. 2021 eq. 3).  Forces, deflections and stiffnesses act along the flank
  normal (the 3-D line of action of the mesh element).
* Gear 1 of the :class:`~torquesplit.gears.geometry.PairGeometry` drives.
* Arrays over the contact grid have the shape ``(M, H, K, N)``: positions, helices
  (2 for double-helical pairs: the second helix mirrors the first, its phase offset by
  ``stagger``), tooth pairs (k = 0 the newest), slices (``y`` from the entry end).
* Double-helical pairs: ``face_width`` is one helix; both helices share the approach of
  the gear bodies (no axial float) and split the load as the contact decides.

Not modelled: gear body, rim and shaft deflection (beyond the fillet foundation);
friction; the coast flank; a groove between the helices; edge contact beyond the tip.

Examples
--------
>>> import math
>>> from torquesplit.gears.geometry import GearGeometry, PairGeometry
>>> a = math.radians(20)
>>> pair = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
...                     GearGeometry(40, 2e-3, a, face_width=0.02))
>>> relief = ToothModification(FlankModification(tip_relief=Relief(10e-6, length=1.5e-3)))
>>> cm = ContactModel(pair, (relief, relief), options=LtcaOptions(positions=32, slices=4))
>>> res = cm.solve(1500.0)
>>> res.converged
True
"""

from torquesplit.gears.contact.impact import LoadedMeshingIn, loaded_meshing_in
from torquesplit.gears.contact.ltca import (
    ARCSEC_PER_RAD,
    ContactModel,
    HarrisMap,
    LtcaOptions,
    LtcaResult,
    ltca_stiffness,
)
from torquesplit.gears.contact.modifications import (
    EndRelief,
    FlankModification,
    Misalignment,
    Relief,
    ToothModification,
    liu2021_topological,
)

__all__ = [
    "ARCSEC_PER_RAD",
    "ContactModel",
    "EndRelief",
    "FlankModification",
    "HarrisMap",
    "LoadedMeshingIn",
    "LtcaOptions",
    "LtcaResult",
    "Misalignment",
    "Relief",
    "ToothModification",
    "liu2021_topological",
    "loaded_meshing_in",
    "ltca_stiffness",
]
