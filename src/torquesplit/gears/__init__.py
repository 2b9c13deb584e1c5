"""Gear-pair physics: everything the mesh element needs, as pure SI functions.

=====================  ===============================================================
module                 content
=====================  ===============================================================
``geometry``           involute geometry of spur, helical, double-helical and internal
                       pairs: radii, working pressure angle, contact ratios, path of
                       contact, curvature and sliding
``line_of_action``     contact frame and 3-D line of action of a mesh from the layout and
                       the power flow (cylindrical, bevel, face, double-helical)
``stiffness``          mesh stiffness k(phase): constant, ISO 6336-1, potential energy,
                       tables, Fourier series, load fit (Dong et al. 2021 eqs. 17-18)
``errors``             eccentricity, installation, tooth-thickness, pitch and run-out
                       errors along the line of action (seeds 000, 002, 004)
``backlash``           constant and random per-engagement backlash (Ji & Li eq. 14)
``friction``           EHL tooth friction coefficient and friction tables (Jin et al. 2019)
``impact``             meshing-in impact (Liu et al. 2021 eqs. 6-10)
``grades``             ISO 1328-1 tolerances per accuracy grade, error sampling
=====================  ===============================================================

Conventions: SI units; angles in radians; phase 0 of a mesh cycle is when a new tooth
pair enters contact; a positive line-of-action error opens the mesh.
"""
