"""Gears that do not mesh but would occupy the same space are refused (a placement angle
typed wrong); gears side by side along an axis, meshing pairs and planets inside their
ring pass."""

from __future__ import annotations

import json
import re
import tomllib
import warnings
from pathlib import Path

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError, ModelWarning

ROOT = Path(__file__).resolve().parents[2]


def _tutorial_model() -> str:
    """The three-branch model of docs/tutorial.md (its first ```toml block)."""
    text = (ROOT / "docs" / "tutorial.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```toml\n(.*?)```", text, re.S)
    return next(b for b in blocks if "[gears.b2]" in b and "[gears.p2]" in b)


def _load(text_or_dict):
    data = tomllib.loads(text_or_dict) if isinstance(text_or_dict, str) else text_or_dict
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return torquesplit.load_model(data)


def _collide(text: str) -> str:
    """b2 and p2 moved to 100 deg: b1/b2 (120 mm pitch) 15.7 mm apart, and p1/p2."""
    data = tomllib.loads(text)
    data["gears"]["b2"]["place"]["angle"] = "100 deg"
    data["gears"]["p2"]["place"]["angle"] = "100 deg"
    return data


def test_the_tutorial_layout_passes():
    _load(_tutorial_model())


def test_overlapping_branch_gears_are_refused_with_one_line_each():
    with pytest.raises(ModelError) as err:
        _load(_collide(_tutorial_model()))
    issues = dict(err.value.issues)
    msg = issues["gears.b2"]
    assert msg == ("gears b1 and b2 overlap: centre distance 15.69 mm < sum of tip radii 126 mm "
                   "with their faces in the same plane; check gears.b2.place / position")
    assert issues["gears.p2"].startswith("gears p1 and p2 overlap")
    assert len(issues) == 2


def test_check_cli_refuses_the_overlap(tmp_path):
    path = tmp_path / "collide.json"
    path.write_text(json.dumps(_collide(_tutorial_model())), encoding="utf-8")
    res = CliRunner().invoke(app, ["check", str(path)])
    assert res.exit_code == 2, res.output
    errors = [ln for ln in res.stderr.splitlines() if ln.startswith("error:")]
    assert len(errors) == 2
    assert errors[0].endswith("gears.b2: gears b1 and b2 overlap: centre distance 15.69 mm < "
                              "sum of tip radii 126 mm with their faces in the same plane; "
                              "check gears.b2.place / position")


REVERTED = """
[model]
name = "reverted two-stage train: the output wheel behind the input pinion"
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
[gears.pinion2]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = ["60 mm", "0 mm", "OFFSET"]
[gears.wheel2]
teeth = 40
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "pinion2", angle = "180 deg"}
[shafts.counter]
connects = ["wheel", "pinion2"]
diameter = "20 mm"
length = "30 mm"
[meshes.m1]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"
[meshes.m2]
gears = ["pinion2", "wheel2"]
stiffness = "4e8 N/m"
[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"
[loads.out]
body = "wheel2"
torque = "balanced"
"""


@pytest.mark.parametrize("offset", ["30 mm",    # stacked: the faces in different planes
                                    "20 mm",    # the faces just touching
                                    "-25 mm"])  # in front
def test_coaxial_gears_in_different_planes_pass(offset):
    model = _load(REVERTED.replace("OFFSET", offset))
    # the wheel and pinion2 share a shaft and overlap in plan: not a collision either
    assert model.gears["wheel2"].place is not None


@pytest.mark.parametrize("offset", ["10 mm", "0 mm", "-19 mm"])
def test_coaxial_gears_whose_faces_overlap_are_refused(offset):
    with pytest.raises(ModelError) as err:
        _load(REVERTED.replace("OFFSET", offset))
    assert err.value.issues == [("gears.wheel2", (
        "gears pinion and wheel2 overlap: centre distance 0 mm < sum of tip radii 64 mm with "
        "their faces in the same plane; check gears.wheel2.place / position")), (
        "gears.wheel2", "gears wheel and wheel2 overlap: centre distance 60 mm < sum of tip "
        "radii 84 mm with their faces in the same plane; check gears.wheel2.place / position")]


RING = """
[model]
name = "gear inside a ring"
[gears.ring]
teeth = 80
module = "2 mm"
kind = "internal"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
[gears.p]
teeth = 20
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "ring", angle = "0 deg"}
[gears.q]
teeth = 20
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "p", angle = "ANGLE"}
[meshes.m1]
gears = ["q", "p"]
stiffness = "4e8 N/m"
[meshes.m2]
gears = ["p", "ring"]
stiffness = "4e8 N/m"
[drives.motor]
body = "q"
speed = "3000 rpm"
torque = "100 N m"
[loads.out]
body = "ring"
"""


@pytest.mark.parametrize("angle", ["180 deg", "125 deg"])
def test_a_gear_inside_the_tip_circle_of_a_ring_it_does_not_mesh_with_passes(angle):
    _load(RING.replace("ANGLE", angle))  # p meshes with the ring: its teeth reach in


@pytest.mark.parametrize("angle", ["112.5 deg",   # q's tip 80 mm: between ring tip and root
                                   "90 deg"])      # through the teeth into the rim
def test_a_gear_reaching_into_the_teeth_of_a_ring_is_refused(angle):
    with pytest.raises(ModelError) as err:
        _load(RING.replace("ANGLE", angle))
    (loc, msg), = err.value.issues
    assert loc == "gears.q"
    assert msg.startswith("gears ring and q overlap: q (tip radius 22 mm")
    assert "reaches into the teeth of internal gear ring (tip radius 78 mm, root radius " \
           "82.5 mm)" in msg and msg.endswith("check gears.q.place / position")


@pytest.mark.parametrize("name", torquesplit.example_names())
def test_every_example_has_no_overlap(name):
    from torquesplit.model.checks import overlap_issues
    from torquesplit.model.kinematics import solve_kinematics

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        model = torquesplit.load_model(torquesplit.example_path(name), check=False)
    assert overlap_issues(model, solve_kinematics(model)) == []


RIM = """
[model]
name = "ring and a gear beside it"

[gears.ring]
teeth = 80
module = "2 mm"
kind = "internal"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
RIM_FIELD
[gears.p]
teeth = 20
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "ring", angle = "0 deg"}
[gears.r2]
teeth = 60
module = "2 mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "30 mm"]
[gears.x]
teeth = 48
module = "2 mm"
face_width = "20 mm"
position = ["108 mm", "0 mm", "30 mm"]
[gears.x2]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = ["108 mm", "0 mm", "0 mm"]
[shafts.input]
connects = ["x2", "x"]
rigid = true
[shafts.ring_shaft]
connects = ["r2", "ring"]
rigid = true
[meshes.m1]
gears = ["x", "r2"]
stiffness = "4e8 N/m"
[meshes.m2]
gears = ["ring", "p"]
stiffness = "4e8 N/m"
[drives.motor]
body = "x2"
speed = "3000 rpm"
torque = "100 N m"
[loads.out]
body = "p"
"""


def _rim_model(field: str):
    data = tomllib.loads(RIM.replace("RIM_FIELD", field))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        torquesplit.load_model(data)
    return [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]


def test_a_gear_in_the_given_rim_of_a_ring_is_refused():
    """x2 (tip radius 22 mm, 108 mm from the ring's axis, in its plane) clears the ring's
    teeth (root radius 82.5 mm) but not a 5 mm rim (outer radius 87.5 mm)."""
    for field in ('rim_thickness = "5 mm"', 'outer_diameter = "175 mm"'):
        with pytest.raises(ModelError) as err:
            _rim_model(field)
        (loc, msg), = err.value.issues
        assert loc == "gears.x2"
        assert msg.startswith("gears ring and x2 overlap: x2 (tip radius 22 mm, centre 108 mm "
                              "from ring's) reaches into the teeth or rim of internal gear "
                              "ring (tip radius 78 mm, outer radius of its rim 87.5 mm)")


def test_a_gear_in_the_assumed_rim_of_a_ring_is_warned_of():
    """Without a rim in the file the ring's rim is assumed 3.5 m_n = 7 mm (outer radius
    89.5 mm, as its computed mass): a warning naming both fields, no refusal."""
    msgs = [m for m in _rim_model("") if "rim" in m]
    assert len(msgs) == 1 and msgs[0].startswith(
        "gears.x2: x2 (tip radius 22 mm, centre 108 mm from ring's) reaches into the rim of "
        "internal gear ring as assumed (outer radius 89.5 mm, 3.5 normal modules outside its "
        "root circle); give gears.ring.rim_thickness or gears.ring.outer_diameter")


def test_a_gear_outside_a_thin_rim_passes():
    assert not [m for m in _rim_model('rim_thickness = "2 mm"') if "overlap" in m or
                "rim" in m]


def test_the_rim_of_a_planetary_stage_ring_is_named_as_written():
    """A [[planetary]] ring has no [gears.*] table of its own: the rim fields are the
    stage's (the reviewer's case: 'give gears.st_ring.rim_thickness' named a table the
    file does not have)."""
    import sys

    from torquesplit.model.checks import _rim_fields

    sys.path.insert(0, str(ROOT / "tests"))
    from planetary_models import three_planet_toml

    model = _load(three_planet_toml("st"))
    ring = next(n for n, g in model.gears.items() if g.gear_type == "internal")
    assert _rim_fields(model, ring) == ("planetary.0.ring.rim_thickness or "
                                        "planetary.0.ring.outer_diameter")


def test_a_gear_of_the_users_own_on_a_stages_planet_is_the_one_to_move():
    """An idler of the user's placed on a [[planetary]] stage's planet: the error names
    the idler's place (it named the generated planet, which the file does not have)."""
    from torquesplit.model.reader import read_model_file

    data = read_model_file(torquesplit.example_path("lin_parker1999_planetary"))
    data["gears"] = {"idler": {"teeth": 30, "module": "2.25 mm",
                               "pressure_angle": "24.6 deg", "face_width": "30 mm",
                               "place": {"from_gear": "stage_sun", "angle": "45 deg"}}}
    data["meshes"] = {"extra": {"gears": ["stage_sun", "idler"], "stiffness": "5e8 N/m"}}
    data["loads"]["out2"] = {"body": "idler"}
    with pytest.raises(ModelError) as info:
        _load(data)
    overlaps = [(loc, msg) for loc, msg in info.value.issues if "overlap" in msg]
    assert overlaps and all(loc == "gears.idler" and "check gears.idler.place" in msg
                            for loc, msg in overlaps), overlaps
