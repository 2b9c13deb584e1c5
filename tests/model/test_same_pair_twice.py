"""Two meshes joining the same two gears double the mesh: said (a reviewer's model was
accepted silently)."""

import tomllib
import warnings

import torquesplit
from test_friction_drift import PAIR


def test_a_second_mesh_on_the_same_gears_is_said():
    text = PAIR.replace("friction = { model = \"constant\", coefficient = 0.1 }\n", "")
    twice = text + '\n[meshes.m2]\ngears = ["wheel", "pinion"]\nstiffness = "4e8 N/m"\n'
    for source, expected in ((text, 0), (twice, 1)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            torquesplit.load_model(tomllib.loads(source))
        said = [str(w.message) for w in caught if "joins the same gears" in str(w.message)]
        assert len(said) == expected, said
    assert said[0].startswith("meshes.m2: joins the same gears as meshes.m")


def test_two_speed_drives_on_one_train_are_said():
    """Both gears held at speed: the mesh carried nothing (static force 0, load sharing
    NaN) and 'check' reported a power balance of 0 without a word."""
    text = PAIR.replace("friction = { model = \"constant\", coefficient = 0.1 }\n", "")
    text = text.replace('torque = "200 N m"\n', 'torque = "200 N m"\nmode = "speed"\n')
    locked = text + ('\n[drives.brake]\nbody = "wheel"\nspeed = "-1500 rpm"\n'
                     'torque = "400 N m"\nmode = "speed"\n')
    for source, expected in ((text, 0), (locked, 1)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            torquesplit.load_model(tomllib.loads(source))
        said = [str(w.message) for w in caught if "both prescribe the speed" in str(w.message)]
        assert len(said) == expected, [str(w.message) for w in caught]


def test_modifications_without_ltca_say_that_contact_uses_them():
    """The warning said only 'ltca' uses modifications, while 'torquesplit contact'
    analysed them (a reviewer)."""
    from model_texts import SPUR_PAIR

    text = SPUR_PAIR.replace('place = {from_gear = "pinion", angle = "0 deg"}\n',
                             'place = {from_gear = "pinion", angle = "0 deg"}\n'
                             'modifications = {crowning = "5 um"}\n')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(tomllib.loads(text))
    said = [str(w.message) for w in caught if "gears.wheel.modifications" in str(w.message)]
    assert len(said) == 1 and "'torquesplit contact' analyses them either way" in said[0]
