"""Metrics of a run: load-sharing coefficients and dynamic load factors.

``load_sharing`` holds every definition the papers use, selectable by name
(``cycle_peak``, ``instantaneous``, ``engineering``, ``mean_force``,
``static_torque``), the settle criterion that excludes the transient, and the dynamic
load factors.  ``planetary`` gives the mesh-load factor K_gamma of every planetary
stage (largest planet load over the mean) from any of those definitions.
"""
