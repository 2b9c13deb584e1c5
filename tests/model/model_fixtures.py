"""Small valid models shared by the model tests (TOML text, parsed on use)."""

from __future__ import annotations

import copy
import tomllib

#: A tiny spur pair (20/40 teeth, 2 mm) used by the fuzzing and bad-input tests.
PAIR_TOML = """\
[model]
name = "spur pair"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "pinion", angle = "0 deg"}

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"
damping_ratio = 0.05

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "wheel"
"""

#: A helical pair with more of the schema in use: a motor body on an elastic shaft,
#: supports (stiffness and shaft bending), a stiffness table, a random backlash,
#: gear errors and analysis settings.  Used as a second seed of the fuzz test.
RICH_TOML = """\
[model]
name = "rich helical pair"
description = "fuzz seed"

[bodies.motor]
polar_inertia = "0.05 kg m^2"

[shafts.input]
connects = ["motor", "pinion"]
torsional_stiffness = "2e4 N m/rad"
damping_ratio = 0.02

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
helix_angle = "15 deg"
hand = "right"
position = [0.0, 0.0, 0.0]
mass = "0.3 kg"
dofs = ["x", "y", "theta"]
support = {stiffness = "1e8 N/m", damping_ratio = 0.03}
errors = {eccentricity = "5 um", eccentricity_phase = "30 deg"}

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
helix_angle = "15 deg"
hand = "left"
place = {from_gear = "pinion", angle = "30 deg"}
dofs = ["x", "y", "theta"]
support = {shaft = {diameter = "30 mm", span = "200 mm", position = "100 mm"}}

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = {method = "table", phase = [0.0, 0.5], values = ["4e8 N/m", "3e8 N/m"]}
damping_ratio = 0.05
backlash = {nominal = "100 um", tolerance = "10 um", distribution = "normal", seed = 3}
transmission_error = {amplitude = "5 um"}

[drives.motor]
body = "motor"
speed = "3000 rpm"
power = "30 kW"

[loads.out]
body = "wheel"
torque = "balanced"
speed_coefficient = 0.1

[analysis]
method = "rk4"
cycles = 50
"""


def pair_dict() -> dict:
    """A fresh (deep-copied) dict of the spur pair."""
    return copy.deepcopy(_PAIR)


def rich_dict() -> dict:
    """A fresh (deep-copied) dict of the rich helical pair."""
    return copy.deepcopy(_RICH)


_PAIR = tomllib.loads(PAIR_TOML)
_RICH = tomllib.loads(RICH_TOML)
