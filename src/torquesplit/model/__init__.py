"""Model files: schema, units, reading, checks, kinematics.

================  ===================================================================
module            content
================  ===================================================================
``schema``        pydantic schema of a model file; every quantity SI after validation
``units``         pint at the edge: "50 um", "8780 rpm" -> SI floats
``io``            read TOML/JSON, schema errors -> ModelError naming field and fix
``checks``        references, topology, meshing compatibility, plausibility warnings
``kinematics``    layout, speeds, power flow, torques, tooth forces (equal split)
``epicyclic``     carriers, planets, held members: speeds and nominal torques in every
                  carrier's frame (Willis), the frames of the bodies' translations
``planetary``     the ``[[planetary]]`` shorthand, expanded to the general sections
``summary``       the ``torquesplit check`` summary
``overrides``     change fields by path (``--set shafts.s1.diameter='250 mm'``)
``docs``          generates docs/model-file.md from the schema
================  ===================================================================
"""
