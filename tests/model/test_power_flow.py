"""The equal-split nominal power flow (model/kinematics._power_flow) on branches of unequal
length: each branch of a split carries its share, however many bodies it has."""

from __future__ import annotations

import tomllib

import pytest
from model_texts import split_model

import torquesplit

#: branch 'a' of the two-path split gets a hub body between two elastic shafts (a torque
#: meter, a coupling hub): one body more than branch 'b'
_LONGER_BRANCH = {
    '''[shafts.sa]
connects = ["a", "a2"]
rigid = true''': '''[bodies.hub]
polar_inertia = "1e-4 kg m^2"
position = ["-60 mm", "0 mm", "-20 mm"]

[shafts.sa]
connects = ["a", "hub"]
torsional_stiffness = "2e4 N m/rad"

[shafts.sa2]
connects = ["hub", "a2"]
torsional_stiffness = "2e4 N m/rad"''',
    '''[gears.a2]
teeth = 20''': '''[gears.a2]
position = ["-60 mm", "0 mm", "-40 mm"]
teeth = 20''',
    '''[gears.b2]
teeth = 20''': '''[gears.b2]
position = ["60 mm", "0 mm", "-40 mm"]
teeth = 20''',
    '52.91502622129181 mm", "0 mm"': '52.91502622129181 mm", "-40 mm"',
}


def _model(replacements: dict[str, str]):
    text = split_model()
    for old, new in replacements.items():
        assert old in text
        text = text.replace(old, new)
    return torquesplit.load_model(tomllib.loads(text))


def test_a_branch_with_one_body_more_carries_its_half():
    """Counting hops to the load gave the longer branch no power and refused the model
    ("meshes.a2: carries no nominal load")."""
    kin = torquesplit.solve_kinematics(_model(_LONGER_BRANCH))
    m = kin.meshes
    assert m["a1"].force == pytest.approx(m["b1"].force, rel=1e-12)
    assert m["a2"].force == pytest.approx(m["b2"].force, rel=1e-12)
    # 100 N m in, split in two: each first-stage mesh carries 50 N m on the pinion
    assert m["a1"].force * m["a1"].arm_driver == pytest.approx(50.0, rel=1e-12)
    assert kin.bodies["hub"].torque == pytest.approx(kin.bodies["a"].torque, rel=1e-12)
    assert [m[n].driver for n in ("a1", "b1", "a2", "b2")] == ["pinion", "pinion", "a2", "b2"]


def test_the_equal_length_split_is_unchanged():
    kin = torquesplit.solve_kinematics(_model({}))
    m = kin.meshes
    assert m["a1"].force * m["a1"].arm_driver == pytest.approx(50.0, rel=1e-12)
    assert m["a2"].force == pytest.approx(m["b2"].force, rel=1e-12)


_SPEED_HELD = {'''[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "out"''': '''[drives.motor]
body = "pinion"
speed = "3000 rpm"
mode = "speed"

[loads.out]
body = "out"
torque = "600 N m"'''}


def test_a_speed_held_drive_puts_in_what_the_given_load_takes():
    """A 'speed' drive needed a power balancing the loads to 1e-3 (computed by hand);
    without power or torque it now takes the loads' power."""
    kin = torquesplit.solve_kinematics(_model(_SPEED_HELD))
    # 600 N m at a third of the speed: 200 N m... at the pinion, 100 N m (ratio 2 x 3)
    assert kin.drive_torques["motor"] == pytest.approx(100.0, rel=1e-12)
    assert kin.input_power == pytest.approx(kin.output_power, rel=1e-12)
    assert kin.meshes["a1"].force * kin.meshes["a1"].arm_driver == pytest.approx(50.0,
                                                                                rel=1e-12)


@pytest.mark.parametrize("change, location, words", [
    ({'torque = "600 N m"': ""}, "loads.out.torque", "this load is 'balanced'"),
    ({'mode = "speed"': 'mode = "torque"'}, "drives.motor", "neither 'power' nor 'torque'"),
])
def test_an_open_speed_drive_needs_the_loads_torques(change, location, words):
    replacements = dict(_SPEED_HELD)
    key = next(iter(replacements))
    for old, new in change.items():
        replacements[key] = replacements[key].replace(old, new)
    with pytest.raises(torquesplit.ModelError) as info:
        _model(replacements)
    assert any(loc == location and words in msg for loc, msg in info.value.issues), \
        info.value.issues


def test_a_speed_held_sun_puts_in_what_the_carrier_takes():
    """The same on a planetary stage (its torques come from the epicyclic equations)."""
    from torquesplit.model.overrides import read_raw

    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    raw["drives"]["input"].pop("torque")
    raw["drives"]["input"]["mode"] = "speed"
    raw["loads"]["output"]["torque"] = "400 N m"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kin = torquesplit.solve_kinematics(torquesplit.load_model(raw))
    sun, carrier = kin.bodies["stage_sun"], kin.bodies["stage_carrier"]
    assert kin.drive_torques["input"] * abs(sun.speed) == pytest.approx(
        400.0 * abs(carrier.speed), rel=1e-12)


def test_a_speed_drive_that_would_have_to_take_power_out_is_refused_as_such():
    """A differential: the sun driven at 1000 rpm with 100 N m, the ring held at -200 rpm
    by a 'speed' drive, the carrier loaded with 50 N m.  The ring would have to take the
    difference out (a brake): a drive cannot, and the message said "nothing is left"."""
    from torquesplit.model.overrides import read_raw

    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    raw["planetary"][0]["ring"].pop("torsional_support")
    raw["drives"]["ring"] = {"body": "stage_ring", "speed": "-200 rpm", "mode": "speed"}
    raw["loads"]["output"]["torque"] = "50 N m"
    with pytest.raises(torquesplit.ModelError) as info:
        torquesplit.load_model(raw)
    (loc, msg), = info.value.issues
    assert loc == "drives.ring"
    # carrier (42 x 1000 - 138 x 200) / 180 = 80 rpm: 50 N m take 0.419 kW of 10.472 kW
    assert "put in 10.472 kW and the loads take 0.418879 kW" in msg
    assert "would have to take 10.0531 kW out" in msg and "nothing is left" not in msg


_CHAIN = """
[model]
name = "three gears"

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

[gears.wheel2]
teeth = 40
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "WHERE", angle = "ANGLE"}

[meshes.m1]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"

[meshes.m2]
gears = ["SECOND", "wheel2"]
stiffness = "4e8 N/m"

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "TORQUE"
"""


def _chain(second: str, extra: str, torque: str = "100 N m"):
    """pinion -> wheel, and wheel2 on the wheel (a chain) or on the pinion (a fork)."""
    text = (_CHAIN.replace("WHERE", second).replace("SECOND", second)
            .replace("ANGLE", "0 deg" if second == "wheel" else "180 deg")
            .replace("TORQUE", torque)) + extra
    return torquesplit.solve_kinematics(torquesplit.load_model(tomllib.loads(text)))


def _torque(kin, mesh):
    return kin.meshes[mesh].force * kin.meshes[mesh].arm_driver


def test_a_second_drive_on_an_intermediate_gear():
    """Both drives sat at one potential: the mesh between them got no power and the model
    was refused (a reviewer's regression of the potential)."""
    kin = _chain("wheel", '[drives.motor2]\nbody = "wheel"\nspeed = "-1500 rpm"\n'
                          'torque = "50 N m"\n[loads.out]\nbody = "wheel2"\n')
    assert _torque(kin, "m1") == pytest.approx(100.0, rel=1e-12)  # the pinion's own
    assert kin.meshes["m2"].force * kin.meshes["m2"].arm_driven == pytest.approx(
        250.0, rel=1e-12)  # the wheel passes on both drives' power


def test_a_power_take_off_on_an_intermediate_gear():
    """A load on the wheel took everything downstream of it (refused: m2 carried none)."""
    kin = _chain("wheel", '[loads.pump]\nbody = "wheel"\ntorque = "50 N m"\n'
                          '[loads.out]\nbody = "wheel2"\n')
    assert _torque(kin, "m1") == pytest.approx(100.0, rel=1e-12)
    assert kin.meshes["m2"].force * kin.meshes["m2"].arm_driven == pytest.approx(
        150.0, rel=1e-12)  # 200 N m at the wheel, less the pump's 50


def test_loads_with_given_torques_take_them_in_a_fork():
    """Split equally, the two branches' nominal forces were 150/150 N m at the pinion for
    loads of 200 and 600 N m on wheels of the same ratio."""
    kin = _chain("pinion", '[loads.out]\nbody = "wheel"\ntorque = "200 N m"\n'
                           '[loads.out2]\nbody = "wheel2"\ntorque = "600 N m"\n',
                 torque="400 N m")
    assert _torque(kin, "m1") == pytest.approx(100.0, rel=1e-12)
    assert _torque(kin, "m2") == pytest.approx(300.0, rel=1e-12)
