"""A gear designer's slips that ran without a word (an LTCA reviewer): a misalignment in
the wrong unit, and a modified gear in a mesh that does not use the modification."""

from __future__ import annotations

import tomllib
import warnings

import torquesplit
from torquesplit.model.checks import magnitude_warnings, plausibility_warnings
from torquesplit.model.kinematics import solve_kinematics

from tests.model_texts import RELIEVED_SPUR_LTCA


def _said(data, check) -> dict[str, str]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(data)
    return dict(check(m, solve_kinematics(m)))


def test_a_misalignment_in_the_wrong_unit_is_warned():
    data = tomllib.loads(RELIEVED_SPUR_LTCA)
    data["meshes"]["m"]["misalignment"] = {"lead_mismatch": "20 um",
                                           "shaft_misalignment": "0.5 mrad"}
    assert not [k for k in _said(data, magnitude_warnings) if "misalignment" in k]
    data["meshes"]["m"]["misalignment"] = {"lead_mismatch": 0.002, "shaft_misalignment": 0.2}
    said = _said(data, magnitude_warnings)
    assert "microns" in said["meshes.m.misalignment.lead_mismatch"]
    assert "200 mrad" in said["meshes.m.misalignment.shaft_misalignment"]


def test_a_modified_gear_in_a_mesh_without_ltca_is_said():
    data = tomllib.loads(RELIEVED_SPUR_LTCA)
    data["gears"]["idler"] = {"teeth": 40, "module": "3 mm", "face_width": "30 mm",
                              "place": {"from_gear": "pinion", "angle": "180 deg"}}
    data["meshes"]["n"] = {"gears": ["pinion", "idler"], "stiffness": {"method": "iso6336"},
                           "damping_ratio": 0.05}
    data["loads"]["aux"] = {"body": "idler", "torque": "50 N m"}
    said = _said(data, plausibility_warnings)
    assert "meshes n of this gear do not use it" in said["gears.pinion.modifications"]
    assert "gears.wheel.modifications" not in said  # (its one mesh uses the LTCA)
