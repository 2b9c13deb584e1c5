"""Generated N-branch split models for the speed benchmarks (not shipped, not tested).

:func:`split_model_text` writes a model file (TOML text) of a coaxial, two-stage,
N-branch locked-train split drive::

    sun (input, coaxial with the output)
     |-- mesh s<i> --> wheel<i>   (N wheels at 360 i / N deg, plane z = 0)
                         |  elastic torsion shaft t<i> (100 mm long)
                       pinion<i>  (coaxial with wheel<i>, plane z = -100 mm)
     <-- mesh c<i> --  pinion<i> drives the output gear "ring" (coaxial with the sun)

Every gear has x, y and theta DOFs on isotropic supports (bend-torsion model), so the
structure has 3 (2 + 2N) + 2 DOFs (motor and load bodies add one rotation each) and
4N + 2N + 2 + ... elements (meshes, shafts, supports).

Geometry (spur, module 2 mm, 20 deg, no profile shift) is consistent: both stages have
the same centre distance, a = m (z_sun + z_wheel) / 2 = m (z_pinion + z_ring) / 2, so the
pinions mesh with an output gear coaxial with the sun.  The teeth are chosen so that
N wheels fit around the sun without their tip circles touching::

    2 a sin(pi / N) > m (z_wheel + 2) + clearance      (adjacent wheels)

and likewise for the pinions around the ring.  The wheels are 20 teeth, the pinions 18;
the sun is the smallest tooth count (>= 20) that fits, the ring 2 teeth more.

All numbers are benchmark choices (not from a paper): mesh stiffness 4e8 N/m with a
10 % peak-to-peak single/double contact wave, damping ratio 0.05, backlash 0.01 mm,
supports 1e9 N/m, torsion shafts 2e5 N m/rad; 3000 rpm; input torque set for a 5 kN
tangential tooth force per branch at the sun (13 um mesh deflection, more than the
5 um half-backlash, so the static active-set iteration starts in contact: with a
larger backlash ``static_equilibrium`` raises a false 'singular stiffness' error, see
RESULTS.md).
"""

from __future__ import annotations

import math
import tomllib

MODULE_MM = 2.0
Z_WHEEL = 20
Z_PINION = 18
CLEARANCE_MM = 2.0  # between adjacent tip circles
TOOTH_FORCE_N = 5000.0  # nominal tangential force per branch mesh at the sun


def branch_teeth(n_branches: int) -> tuple[int, int, int, int]:
    """(z_sun, z_wheel, z_pinion, z_ring) such that n_branches wheels fit around the sun."""
    if n_branches < 1:
        raise ValueError(f"n_branches must be >= 1, got {n_branches}.")
    z_wheel, z_pinion = Z_WHEEL, Z_PINION
    s = math.sin(math.pi / n_branches) if n_branches > 1 else 1.0
    z_sun = 20
    while True:
        z_ring = z_sun + z_wheel - z_pinion
        a = MODULE_MM * (z_sun + z_wheel) / 2.0
        gap_wheels = 2.0 * a * s - MODULE_MM * (z_wheel + 2)
        gap_pinions = 2.0 * a * s - MODULE_MM * (z_pinion + 2)
        if n_branches == 1 or (gap_wheels > CLEARANCE_MM and gap_pinions > CLEARANCE_MM):
            return z_sun, z_wheel, z_pinion, z_ring
        z_sun += 1


def split_model_text(n_branches: int) -> str:
    """TOML text of the N-branch split model described in the module docstring."""
    n = int(n_branches)
    z_sun, z_wheel, z_pinion, z_ring = branch_teeth(n)
    a = MODULE_MM * (z_sun + z_wheel) / 2.0  # both stages [mm]
    r_sun_m = MODULE_MM * z_sun / 2.0 * 1e-3
    torque = n * TOOTH_FORCE_N * r_sun_m  # the same tooth force in every model
    out = [f'''
[model]
name = "bench_split_{n}"
description = "generated {n}-branch coaxial locked-train split drive (benchmark)"

[bodies.motor]
polar_inertia = "0.01 kg m^2"
position = ["0 mm", "0 mm", "100 mm"]

[bodies.load]
polar_inertia = "5 kg m^2"
position = ["0 mm", "0 mm", "-200 mm"]

[gears.sun]
teeth = {z_sun}
module = "{MODULE_MM} mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
dofs = ["x", "y", "theta"]
support = {{ stiffness = "1e9 N/m", damping_ratio = 0.05 }}

[gears.ring]
teeth = {z_ring}
module = "{MODULE_MM} mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "-100 mm"]
dofs = ["x", "y", "theta"]
support = {{ stiffness = "1e9 N/m", damping_ratio = 0.05 }}

[shafts.input]
connects = ["motor", "sun"]
torsional_stiffness = "1e5 N m/rad"
damping_ratio = 0.02

[shafts.output]
connects = ["ring", "load"]
torsional_stiffness = "1e6 N m/rad"
damping_ratio = 0.02

[drives.motor]
body = "motor"
speed = "3000 rpm"
torque = "{torque:g} N m"

[loads.load]
body = "load"
torque = "balanced"

[analysis]
method = "rk4"
steps_per_period = 100
''']
    for i in range(n):
        ang = 2.0 * math.pi * i / n
        x, y = a * math.cos(ang), a * math.sin(ang)
        out.append(f'''
[gears.wheel{i}]
teeth = {z_wheel}
module = "{MODULE_MM} mm"
face_width = "20 mm"
position = ["{x!r} mm", "{y!r} mm", "0 mm"]
dofs = ["x", "y", "theta"]
support = {{ stiffness = "1e9 N/m", damping_ratio = 0.05 }}

[gears.pinion{i}]
teeth = {z_pinion}
module = "{MODULE_MM} mm"
face_width = "20 mm"
position = ["{x!r} mm", "{y!r} mm", "-100 mm"]
dofs = ["x", "y", "theta"]
support = {{ stiffness = "1e9 N/m", damping_ratio = 0.05 }}

[shafts.t{i}]
connects = ["wheel{i}", "pinion{i}"]
torsional_stiffness = "2e5 N m/rad"
damping_ratio = 0.02

[meshes.s{i}]
gears = ["sun", "wheel{i}"]
stiffness = {{ method = "constant", value = "4e8 N/m", peak_to_peak = 0.1 }}
damping_ratio = 0.05
backlash = "0.01 mm"
stage = "split"

[meshes.c{i}]
gears = ["pinion{i}", "ring"]
stiffness = {{ method = "constant", value = "4e8 N/m", peak_to_peak = 0.1 }}
damping_ratio = 0.05
backlash = "0.01 mm"
stage = "combine"
''')
    return "".join(out)


def split_model(n_branches: int):
    """The validated :class:`~torquesplit.model.schema.Model` of :func:`split_model_text`."""
    from torquesplit import load_model

    return load_model(tomllib.loads(split_model_text(n_branches)))


if __name__ == "__main__":  # python benchmarks/models.py 4  -> prints the model file
    import sys

    print(split_model_text(int(sys.argv[1]) if len(sys.argv) > 1 else 2))
