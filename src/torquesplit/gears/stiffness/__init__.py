"""Mesh stiffness of a gear pair over one tooth-mesh period.

=====================  ==========================================================
module                 what it does
=====================  ==========================================================
``result``             :class:`MeshStiffness`, the common result (phase, stiffness,
                       mean, peak-to-peak, method); periodic resampling
``phasing``            where each tooth pair / face slice is at a given mesh phase;
                       contact-line length in the field of action
``iso6336``            ISO 6336-1 method B: ``q'``, ``c'``, ``c_gamma``; a waveform
                       shaped by the contact-line length
``potential_energy``   potential-energy method (bending, shear, axial compression,
                       Hertz, fillet foundation after Sainsot et al. 2004); slices
                       for helical and double-helical pairs
``tables``             constant, table against phase, Fourier series, tables at
                       several loads interpolated in load
``load_fit``           Dong et al. 2021 eqs. 17-18: fit of loaded transmission error against
                       torque and the resulting stiffness
``dispatch``           :func:`mesh_stiffness` (method by name) and
                       :func:`compare_methods`
=====================  ==========================================================

Conventions
-----------
* SI units throughout: N/m for stiffness, N/m^2 for stiffness per unit face width,
  metres, radians.
* ``n`` samples at the uniform phases ``k/n`` (k = 0..n-1) of one mesh period,
  endpoint excluded; phase 0 is the instant a new tooth pair enters contact at the
  start of active profile (for helical gears at the reference face end).
* Stiffness acts along the normal to the tooth flanks (the 3-D line of action of the
  assembled mesh element); for spur gears this is the transverse line of action.
* Double-helical pairs: ``face_width`` is one helix; results cover both helices.

Examples
--------
>>> import math
>>> from torquesplit.gears.geometry import GearGeometry, PairGeometry
>>> a = math.radians(20)
>>> pair = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
...                     GearGeometry(40, 2e-3, a, face_width=0.02))
>>> k = mesh_stiffness(pair, "iso6336", n=128)
>>> round(k.info["c_prime_iso"], 2)
12.69
"""

from torquesplit.gears.geometry import mesh_frequency, mesh_period
from torquesplit.gears.stiffness.dispatch import METHODS, MethodComparison, compare_methods, mesh_stiffness
from torquesplit.gears.stiffness.iso6336 import (
    Iso6336Values,
    basic_rack_factor,
    blank_factor,
    iso6336_mesh_stiffness_value,
    iso6336_stiffness,
    iso6336_values,
    minimum_flexibility,
)
from torquesplit.gears.stiffness.load_fit import LoadDeflectionFit, fit_load_deflection, load_fit_stiffness
from torquesplit.gears.stiffness.potential_energy import (
    ToothCompliance,
    pair_compliance,
    potential_energy_stiffness,
    tooth_compliance,
)
from torquesplit.gears.stiffness.result import MeshStiffness
from torquesplit.gears.stiffness.tables import (
    constant_stiffness,
    fourier_stiffness,
    load_table_stiffness,
    table_stiffness,
)

__all__ = [
    "METHODS",
    "Iso6336Values",
    "LoadDeflectionFit",
    "MeshStiffness",
    "MethodComparison",
    "ToothCompliance",
    "basic_rack_factor",
    "blank_factor",
    "compare_methods",
    "constant_stiffness",
    "fit_load_deflection",
    "fourier_stiffness",
    "iso6336_mesh_stiffness_value",
    "iso6336_stiffness",
    "iso6336_values",
    "load_fit_stiffness",
    "load_table_stiffness",
    "mesh_frequency",
    "mesh_period",
    "mesh_stiffness",
    "minimum_flexibility",
    "pair_compliance",
    "potential_energy_stiffness",
    "table_stiffness",
    "tooth_compliance",
]
