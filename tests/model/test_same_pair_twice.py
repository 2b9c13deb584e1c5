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


def test_a_support_stiffness_off_by_a_unit_is_said_by_check_run_and_static(tmp_path):
    """'500 N/mm' for '500 N/um': the pinion sat millimetres off its centre without a word
    from check, run or static (a reviewer's 21 mm)."""
    from typer.testing import CliRunner

    from model_texts import SPUR_PAIR
    from torquesplit.cli import app

    slip = SPUR_PAIR.replace('position = ["0 mm", "0 mm", "0 mm"]\n',
                             'position = ["0 mm", "0 mm", "0 mm"]\ndofs = ["x", "y", "theta"]\n'
                             'mass = "0.5 kg"\nsupport = { stiffness = "500 N/mm" }\n')
    for text, expected in ((slip, 1), (slip.replace("500 N/mm", "500 N/um"), 0)):
        path = tmp_path / f"pair{expected}.toml"
        path.write_text(text)
        for command in (["check"], ["run", "--cycles", "20"], ["static"], ["modes"],
                        ["steady"]):
            res = CliRunner().invoke(app, [command[0], str(path), *command[1:]])
            said = [ln for ln in res.stderr.splitlines()
                    if "gears.pinion.support: the static deflection of pinion" in ln]
            assert len(said) == expected, (command, res.stderr)


def test_a_deflection_on_a_spline_names_the_spline():
    """A fuzzer's spline of 1 N/m (or of 5 mm clearance) was blamed on gears.O4.support, a
    table the file does not have, as 'a support or shaft stiffness far too small'."""
    from types import SimpleNamespace

    import torquesplit
    from torquesplit.model.checks import deflection_warnings

    dong = torquesplit.load_model("dong2021_face_gear")
    assert "O4" in dong.splines["spline4"].connects and dong.gears["O4"].support is None
    structure = SimpleNamespace(dof_names=["O4.x", "O4.theta", "O1.y"])
    ((loc, msg), (loc1, msg1)) = deflection_warnings(dong, structure, [5e-3, 1.0, 6e-3])
    assert loc == "splines.spline4" and "the stiffness of spline spline4 far too small" in msg
    assert "radial clearance too large" in msg
    assert loc1 == "gears.O1.support" and "a support or shaft stiffness" in msg1


def test_a_gear_deflected_beyond_its_tooth_depth_is_refused_not_warned_of():
    """Supports in N/m for N/mm moved a reviewer's idler 26 mm (module 3 mm), and the run
    printed a load-sharing table under a warning: beyond the whole tooth depth (2.25
    modules) the teeth are out of the mesh."""
    from types import SimpleNamespace

    import torquesplit
    from torquesplit.model.checks import deflection_issues, deflection_warnings

    dong = torquesplit.load_model("dong2021_face_gear")
    m = dong.gears["O1"].module
    structure = SimpleNamespace(dof_names=["O1.x", "O1.y"])
    below, beyond = [0.0, 2.2 * m], [0.0, 2.3 * m]
    assert deflection_issues(dong, structure, below) == []
    assert len(deflection_warnings(dong, structure, below)) == 1
    assert deflection_warnings(dong, structure, beyond) == []
    (loc, msg), = deflection_issues(dong, structure, beyond)
    assert loc == "gears.O1.support" and "more than the whole depth of its teeth" in msg
    from torquesplit.model.checks import _plane_translation

    plane = _plane_translation(dong.gears["O1"], {"x": 0.0, "y": 2.3 * m})
    assert f"the static deflection of O1 in its plane is {1e3 * plane:.4g} mm" in msg


def test_an_axial_float_beyond_the_tooth_depth_is_warned_of_not_refused():
    """Along its axis a gear stays in mesh (a helical gear floats axially): only its
    translation in its plane is held against the tooth depth."""
    import tomllib
    from types import SimpleNamespace

    import torquesplit
    from model_texts import SPUR_PAIR
    from torquesplit.model.checks import deflection_issues, deflection_warnings

    model = torquesplit.load_model(tomllib.loads(SPUR_PAIR))  # (axes along z)
    m = model.gears["pinion"].module
    structure = SimpleNamespace(dof_names=["pinion.z", "pinion.x"])
    assert deflection_issues(model, structure, [3 * m, 0.0]) == []
    (_, msg), = deflection_warnings(model, structure, [3 * m, 0.0])
    assert "pinion.z" in msg and "more than half the module" in msg
    (_, msg), = deflection_issues(model, structure, [3 * m, 0.1 * m + 2.25 * m])
    assert f"the static deflection of pinion in its plane is {2.35e3 * m:.4g} mm" in msg
    # the verdict does not depend on the model's orientation: 3 modules at 45 deg in the
    # plane (2.12 along x and y, each below the tooth depth) are refused too
    diagonal = SimpleNamespace(dof_names=["pinion.x", "pinion.y"])
    (_, msg), = deflection_issues(model, diagonal, [2.12 * m, 2.12 * m])
    assert f"in its plane is {2.12e3 * m * 2**0.5:.4g} mm" in msg
    # a slanted axis: the translation's component along it is taken out
    from torquesplit.model.checks import _plane_translation

    slanted = SimpleNamespace(axis=(1.0, 1.0, 0.0))
    assert _plane_translation(slanted, {"x": 1.0, "y": 1.0}) < 1e-12
    assert abs(_plane_translation(slanted, {"x": 1.0, "y": -1.0}) - 2**0.5) < 1e-12
    assert abs(_plane_translation(slanted, {"loa": 3.0, "z": 4.0}) - 5.0) < 1e-12
