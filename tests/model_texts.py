"""Small model files as TOML text, shared by the tests."""

from __future__ import annotations

import math
import re
from pathlib import Path

TUTORIAL = Path(__file__).resolve().parents[1] / "docs" / "tutorial.md"


def tutorial_model() -> str:
    """The three-branch split drive of docs/tutorial.md, as the tutorial writes it."""
    text = TUTORIAL.read_text(encoding="utf-8")
    return re.search(r"```toml\n(.*?)```", text, re.S).group(1)


def write_tutorial_model(folder: Path, name: str = "three_branch.toml") -> Path:
    """:func:`tutorial_model` written to ``folder / name``."""
    path = Path(folder) / name
    path.write_text(tutorial_model(), encoding="utf-8")
    return path


SPUR_PAIR = """
[model]
name = "spur pair"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"
position = ["0 mm", "0 mm", "0 mm"]

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
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


PARAMETRIC_PAIR = """
[model]
name = "pair_param"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
polar_inertia = "1e-3 kg m^2"

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "pinion", angle = "0 deg"}
polar_inertia = "4e-3 kg m^2"

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = {method = "fourier", mean = "4e8 N/m", cos = ["1.2e8 N/m"], sin = []}
damping_ratio = 0.05
backlash = "100 um"

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "wheel"
"""
"""A single spur pair (natural frequency 2675 Hz) with a +-30 % stiffness wave and
backlash: period doubling near 16052 rpm (mesh frequency twice the natural one), contact
loss above its primary resonance (a reviewer's model)."""

PAIR_4MM = """
[model]
name = "4 mm pair"

[gears.pinion]
teeth = 20
module = "4 mm"
face_width = "25 mm"
position = ["0 mm", "0 mm", "0 mm"]
polar_inertia = "0.002 kg m^2"
mass = "2 kg"

[gears.wheel]
teeth = 40
module = "4 mm"
face_width = "25 mm"
place = {from_gear = "pinion", angle = "0 deg"}
polar_inertia = "0.03 kg m^2"
mass = "6 kg"

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"
damping_ratio = 0.05

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "200 N m"

[loads.out]
body = "wheel"
"""
"""A torsional 20/40-tooth, 4 mm spur pair with masses (reviewers' models)."""


def split_model(error_a: str = "0 um", extra: str = "") -> str:
    """A torsional locked-train split: pinion -> A, B (40 t) -> A2, B2 (20 t) -> out (60 t).

    The output gear sits on the y axis so that it meshes with both second-stage
    pinions: its centre distance to each is 80 mm, they are 60 mm off the axis.
    """
    y_out = math.sqrt(80.0**2 - 60.0**2)
    return f"""
[model]
name = "two-path split"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"
position = ["0 mm", "0 mm", "0 mm"]

[gears.a]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
place = {{from_gear = "pinion", angle = "180 deg"}}

[gears.b]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
place = {{from_gear = "pinion", angle = "0 deg"}}

[gears.a2]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"

[gears.b2]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"

[gears.out]
teeth = 60
module = "2 mm"
face_width = "20 mm"
polar_inertia = "3e-3 kg m^2"
position = ["0 mm", "{y_out!r} mm", "0 mm"]

[shafts.sa]
connects = ["a", "a2"]
rigid = true

[shafts.sb]
connects = ["b", "b2"]
rigid = true

[meshes.a1]
gears = ["pinion", "a"]
stiffness = "4e8 N/m"
damping_ratio = 0.05
stage = "split"
transmission_error = {{constant = "{error_a}"}}

[meshes.b1]
gears = ["pinion", "b"]
stiffness = "4e8 N/m"
damping_ratio = 0.05
stage = "split"

[meshes.a2]
gears = ["a2", "out"]
stiffness = "4e8 N/m"
damping_ratio = 0.05
stage = "combine"

[meshes.b2]
gears = ["b2", "out"]
stiffness = "4e8 N/m"
damping_ratio = 0.05
stage = "combine"

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "out"
{extra}
"""


def write_model(tmp_path, text: str, name: str = "model.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


#: a spur pair with tip relief and crowning whose mesh stiffness and transmission error
#: come from the LTCA
RELIEVED_SPUR_LTCA = """\
[model]
name = "relieved spur pair"

[gears.pinion]
teeth = 25
module = "3 mm"
face_width = "30 mm"
position = ["0 mm", "0 mm", "0 mm"]
[gears.pinion.modifications]
tip_relief = {amount = "15 um", length = "5 mm"}
crowning = "5 um"

[gears.wheel]
teeth = 50
module = "3 mm"
face_width = "30 mm"
place = {from_gear = "pinion", angle = "0 deg"}
[gears.wheel.modifications]
tip_relief = {amount = "15 um", length = "5 mm", shape = "parabolic"}

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = {method = "ltca", slices = 6, ltca = {positions = 32}}
damping_ratio = 0.05

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "150 N m"

[loads.out]
body = "wheel"
"""


#: a reviewer's two-path split-torque spur reducer (500 kW at 6000 rpm, ratio 10.2): input
#: pinion to two idlers, shafts of unequal torsional stiffness to two pinions on a bull
#: gear; backlash on every mesh and an eccentricity on idler i1 (its mesh a1 loses contact
#: and its damping pulls as the teeth separate)
TWO_PATH_SPUR_REDUCER = """\
[model]
name = "split2"
description = "Two-path split-torque spur reducer, 500 kW at 6000 rpm, ratio 10.2"
reference = "reviewer's own layout"

[gears.input]
teeth = 24
module = "3 mm"
face_width = "40 mm"
position = ["0 mm", "0 mm", "0 mm"]
dofs = ["x", "y", "theta"]
support = { stiffness = "300 N/um", damping_ratio = 0.05 }

[gears.i1]
teeth = 60
module = "3 mm"
face_width = "38 mm"
place = { from_gear = "input", angle = "60 deg" }
dofs = ["x", "y", "theta"]
support = { stiffness = "500 N/um", damping_ratio = 0.05 }
errors = { eccentricity = "20 um", eccentricity_phase = "0 deg" }

[gears.i2]
teeth = 60
module = "3 mm"
face_width = "38 mm"
place = { from_gear = "input", angle = "-60 deg" }
dofs = ["x", "y", "theta"]
support = { stiffness = "500 N/um", damping_ratio = 0.05 }

[gears.bull]
teeth = 90
module = "4 mm"
face_width = "55 mm"
position = ["258.6246 mm", "0 mm", "-100 mm"]
bore_diameter = "120 mm"
dofs = ["x", "y", "theta"]
support = { stiffness = "1000 N/um", damping_ratio = 0.05 }

[gears.p1]
teeth = 22
module = "4 mm"
face_width = "60 mm"
place = { from_gear = "bull", angle = "150.8473 deg" }

[gears.p2]
teeth = 22
module = "4 mm"
face_width = "60 mm"
place = { from_gear = "bull", angle = "-150.8473 deg" }

[shafts.s1]
connects = ["i1", "p1"]
diameter = "35 mm"
length = "100 mm"
damping_ratio = 0.02

[shafts.s2]
connects = ["i2", "p2"]
torsional_stiffness = "2.0e5 N m/rad"
damping_ratio = 0.02

[meshes.a1]
gears = ["input", "i1"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
backlash = "80 um"
stage = "first"

[meshes.a2]
gears = ["input", "i2"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
backlash = "80 um"
stage = "first"

[meshes.b1]
gears = ["p1", "bull"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
backlash = "100 um"
stage = "second"

[meshes.b2]
gears = ["p2", "bull"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
backlash = "100 um"
stage = "second"

[drives.turbine]
body = "input"
speed = "6000 rpm"
power = "500 kW"

[loads.rotor]
body = "bull"
torque = "balanced"
speed_coefficient = "50 N m s/rad"

[analysis]
cycles = 40
"""
