"""Meshing gears offset along their axis: faces that never overlap are refused, faces
that overlap over part of the narrower one are warned of (the stiffness is the whole
face's)."""

from __future__ import annotations

import tomllib
import warnings

import pytest
from model_texts import SPUR_PAIR
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError, ModelWarning

#: the spur pair of the tests, the wheel placed by hand (OFFSET: its axial position)
PAIR = (SPUR_PAIR.replace('face_width = "20 mm"', 'face_width = "PINION_WIDTH"', 1)
        .replace('place = {from_gear = "pinion", angle = "0 deg"}',
                 'position = ["60 mm", "0 mm", "OFFSET"]')
        .replace("[meshes.m]", "[meshes.m1]"))


def _text(offset: str, pinion_width: str = "20 mm") -> str:
    return PAIR.replace("OFFSET", offset).replace("PINION_WIDTH", pinion_width)


def _warnings(text: str) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(tomllib.loads(text))
    return [str(w.message) for w in caught if issubclass(w.category, ModelWarning)
            and "touch" in str(w.message)]


@pytest.mark.parametrize("offset", ["20 mm", "35 mm", "-20 mm"])
def test_faces_that_do_not_overlap_are_refused(offset):
    with pytest.raises(ModelError) as err:
        torquesplit.load_model(tomllib.loads(_text(offset)))
    distance = offset.lstrip("-")
    assert err.value.issues == [("meshes.m1", (
        f"the centres of pinion and wheel are {distance} apart along their axis, with faces "
        f"20 mm and 20 mm wide: their faces do not overlap and the teeth never touch; give "
        f"both gears the same axial position (the component of 'position' along 'axis')"))]


def test_the_check_command_refuses_them_in_one_line(tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(_text("100 mm"), encoding="utf-8")
    res = CliRunner().invoke(app, ["check", str(path)])
    assert res.exit_code == 2, res.output
    errors = [ln for ln in res.stderr.splitlines() if ln.startswith("error:")]
    assert len(errors) == 1 and "meshes.m1: the centres of pinion and wheel are 100 mm" \
        in errors[0], res.stderr


@pytest.mark.parametrize("offset, touch", [("5 mm", "15 mm"), ("-15 mm", "5 mm")])
def test_a_partial_overlap_is_warned_of_with_the_width_in_contact(offset, touch):
    found = _warnings(_text(offset))
    assert len(found) == 1
    assert f"meshes.m1: the centres of pinion and wheel are {offset.lstrip('-')} apart" \
        in found[0]
    assert f"the teeth touch over {touch} only, but the mesh stiffness is that of the " \
        "whole 20 mm face" in found[0]


@pytest.mark.parametrize("offset, pinion_width", [("0 mm", "20 mm"),
                                                  ("2.5 mm", "25 mm"),    # wheel inside
                                                  ("-2.5 mm", "25 mm")])
def test_a_narrower_face_inside_the_wider_one_passes(offset, pinion_width):
    assert _warnings(_text(offset, pinion_width)) == []


def test_gears_without_a_stated_plane_are_not_judged():
    """A gear on a shaft without a position takes its shaft's body's centre, a stand-in
    for its plane: no check (the same file with that plane given is refused)."""
    hub = """
[bodies.hub]
polar_inertia = "0.01 kg m^2"
position = ["60 mm", "0 mm", "100 mm"]
[shafts.s]
connects = ["wheel", "hub"]
diameter = "20 mm"
length = "100 mm"
"""
    text = _text("100 mm").replace('position = ["60 mm", "0 mm", "100 mm"]\n', "") + hub
    model = torquesplit.load_model(tomllib.loads(text))
    assert model.gears["wheel"].position is None
    with pytest.raises(ModelError, match="their faces do not overlap"):
        torquesplit.load_model(tomllib.loads(_text("100 mm") + hub))


def test_a_double_helical_pair_offset_along_its_axis_is_said_to_misalign_its_apexes():
    """Its face is two helices, not one block: an offset puts the apexes apart, which the
    model does not represent (a checks reviewer: the overlap said was wrong for them)."""
    text = _text("5 mm").replace('"60 mm"', '"69.28203230 mm"')  # (m_t = 2 mm / cos 30)
    for gear in ("pinion", "wheel"):
        hand = "right" if gear == "pinion" else "left"
        text = text.replace(f"[gears.{gear}]\n", f'[gears.{gear}]\nkind = "double_helical"\n'
                            f'helix_angle = "30 deg"\nhand = "{hand}"\n')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(tomllib.loads(text))
    said = [str(w.message) for w in caught if "apexes" in str(w.message)]
    assert len(said) == 1 and "the apexes of these double-helical gears do not line up" \
        in said[0] and "touch over" not in said[0], [str(w.message) for w in caught]
