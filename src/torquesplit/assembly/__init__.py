"""Model -> Structure: the assembled equations of motion as flat arrays.

=================  ==================================================================
module             content
=================  ==================================================================
``structure``      :class:`Structure` (frozen): DOFs, diagonal mass, element arrays
``assemble``       numbering of DOFs and the element list (meshes, shafts, supports,
                   splines), drives and loads
``excitation``     per-mesh tables: stiffness, phasing, backlash, errors, impact
``rotating``       terms of the bodies measured in a turning carrier's frame: Coriolis,
                   centripetal, centrifugal, pin preload
=================  ==================================================================
"""
