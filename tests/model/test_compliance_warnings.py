"""Supports and shafts too soft to carry the nominal load are warned (a first-hour
review: a bearing stiffness in N/mm for N/um and a quill shaft in N mm/rad passed every
check; in a locked train the soft branch merely shed its load, so the load sharing came
out absurd without a word)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import torquesplit
from torquesplit.model.checks import (MAX_NOMINAL_DEFLECTION, MAX_NOMINAL_TWIST,
                                      compliance_warnings)
from torquesplit.model.kinematics import solve_kinematics

from .model_fixtures import pair_dict, rich_dict


def _warnings(data: dict) -> list[tuple[str, str]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(data)
    return compliance_warnings(m, solve_kinematics(m))


def _supported(stiffness) -> dict:
    data = pair_dict()  # (spur: the tooth force lies across the wheel's axis)
    data["gears"]["wheel"]["dofs"] = ["theta", "x", "y"]
    data["gears"]["wheel"]["support"] = {"stiffness": stiffness}
    return data


def test_a_support_that_would_deflect_more_than_half_a_module_is_warned():
    data = _supported("2e8 N/m")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(data)
    kin = solve_kinematics(m)
    assert _warnings(data) == []
    force = next(iter(kin.meshes.values())).force
    # the stiffness at which the nominal tooth force deflects the wheel half a module
    edge = force / (MAX_NOMINAL_DEFLECTION * m.gears["wheel"].module)
    assert _warnings(_supported(f"{1.01 * edge} N/m")) == []
    (loc, msg), = _warnings(_supported(f"{0.99 * edge} N/m"))
    assert loc == "gears.wheel.support.stiffness"
    assert "would deflect" in msg and "the gear's nominal tooth forces" in msg
    # a gear with no translational DOF: its support moves nothing, so nothing is said
    data = _supported("1 N/m")
    data["gears"]["wheel"]["dofs"] = ["theta"]
    assert _warnings(data) == []


def test_a_support_far_softer_than_its_meshes_is_warned_as_floating():
    """A sun between balanced planet meshes carries no resultant: a bare '1500' (N/m)
    held it by its meshes alone (and gave perfect load sharing) without a word."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("lin_parker1999_planetary",
                                   changes={"planetary.0.sun.support.stiffness": 1500})
    found = dict(compliance_warnings(m, solve_kinematics(m)))
    assert "floats" in found["gears.stage_sun.support.stiffness"]
    assert m.written_at("gears.stage_sun.support.stiffness") == (
        "planetary.0.sun.support.stiffness")  # (where check_model reports it)


def test_soft_planet_bearings_are_said_once_for_their_stage():
    """A reviewer: four planet bearings in N/mm gave four warnings at the one field they
    are written in, differing only by the generated planet's name."""
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        torquesplit.load_model("lin_parker1999_planetary",
                               changes={"planetary.0.planet_bearing.stiffness": 1e3})
    soft = [str(w.message) for w in said if "planet_bearing.stiffness" in str(w.message)]
    assert len(soft) == 1, soft


def test_a_shaft_that_twists_too_far_under_its_torque_is_warned():
    data = rich_dict()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(data)
    torque = solve_kinematics(m).bodies["motor"].torque
    edge = abs(torque) / MAX_NOMINAL_TWIST
    data["shafts"]["input"]["torsional_stiffness"] = f"{1.01 * edge} N m/rad"
    assert _warnings(data) == []
    data["shafts"]["input"]["torsional_stiffness"] = f"{0.99 * edge} N m/rad"
    (loc, msg), = _warnings(data)
    assert loc == "shafts.input.torsional_stiffness"
    twist = abs(torque) / (0.99 * edge)
    assert f"{twist:.3g} rad ({math.degrees(twist):.3g} deg)" in msg


@pytest.mark.parametrize("name", torquesplit.example_names())
def test_no_shipped_example_warns_but_where_its_file_accepts_it(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(name)
    from torquesplit.model.checks import accepted

    left = [loc for loc, _ in compliance_warnings(m, solve_kinematics(m))
            if accepted(m, loc) is None]
    assert left == []


def test_a_drive_far_too_light_for_its_gears_is_warned_once():
    """A first-hour review: power = 5000 (read in W, meant kW) gave 0.8 N/mm of face
    width and no word; the run then spoke of contact loss and resonance."""
    from torquesplit.model.checks import MIN_LOAD_PER_WIDTH, magnitude_warnings

    def light(torque):
        data = pair_dict()
        data["drives"]["motor"]["torque"] = torque
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = torquesplit.load_model(data)
        kin = solve_kinematics(m)
        return m, kin, [w for w in magnitude_warnings(m, kin) if "N/mm of face width" in w[1]]

    m, kin, said = light("100 N m")
    per_width = kin.meshes["m"].force / m.gears["pinion"].face_width
    assert said == [] and per_width > MIN_LOAD_PER_WIDTH
    _, _, said = light(f"{100 * 0.99 * MIN_LOAD_PER_WIDTH / per_width} N m")
    (loc, msg), = said
    assert loc == "meshes.m" and "wrong unit" in msg


def test_a_floating_sun_among_unequally_spaced_planets_is_said_to_float():
    """The floating-sun recipe (a support of 1 N/m) on a stage with unequal spacing: the
    sun's nominal resultant made it a unit slip ('would deflect 327.5 m'), not the
    floating member the error that recommends the recipe promises (a planetary
    reviewer); one mesh alone cannot centre a gear, so a pair keeps the slip warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("lin_parker1999_planetary", changes={
            "planetary.0.sun.support.stiffness": 1.0,
            "planetary.0.angles": ["0 deg", "80 deg", "180 deg", "270 deg"]})
    kin = solve_kinematics(m)
    sun = next(n for n in m.gears if n.endswith("_sun"))
    resultant = sum((-1.0 if sun == mk.driver else 1.0) * mk.force
                    * np.asarray(mk.line_of_action, float)
                    for mk in kin.meshes.values() if sun in (mk.driver, mk.driven))
    assert float(np.linalg.norm(resultant[:2])) > 100.0  # (a resultant)
    msg = dict(compliance_warnings(m, kin))[f"gears.{sun}.support.stiffness"]
    assert "floats, held by its meshes alone" in msg and "would deflect" not in msg
    (loc, msg), = _warnings(_supported("1 N/m"))
    assert "would deflect" in msg


def test_a_sun_said_to_float_is_not_warned_of_floating():
    """The floating-sun recipe warned on every command, and the warning said to accept
    it (a planetary reviewer): ``support = {floating = true}`` says it once, in the
    model, with a negligible stiffness; a gear with fewer than three meshes that cannot
    centre it is still warned that it deflects."""
    from torquesplit.model.schema import FLOATING_STIFFNESS, Support

    assert Support.model_validate({"floating": True}).stiffness == FLOATING_STIFFNESS == 1.0
    changes = {"planetary.0.sun.support.stiffness": "1 N/m",
               "planetary.0.sun.support.floating": True,
               "planetary.0.angles": ["0 deg", "80 deg", "180 deg", "270 deg"]}
    m = torquesplit.load_model("lin_parker1999_planetary", changes=changes)
    sun = next(n for n in m.gears if n.endswith("_sun"))
    assert m.gears[sun].support.floating and m.gears[sun].support.stiffness == 1.0
    assert not [w for w in compliance_warnings(m, solve_kinematics(m))
                if w[0].startswith(f"gears.{sun}.")]
    # the same sun written the old way is warned, and told of the field
    del changes["planetary.0.sun.support.floating"]
    m = torquesplit.load_model("lin_parker1999_planetary", changes=changes)
    msg = dict(compliance_warnings(m, solve_kinematics(m)))[f"gears.{sun}.support.stiffness"]
    assert "floating = true" in msg and "accepted_warnings" not in msg
    # one mesh cannot centre a gear: said to float, it is still warned that it deflects
    data = _supported("1 N/m")
    data["gears"]["wheel"]["support"] = {"floating": True}
    (loc, msg), = _warnings(data)
    assert "would deflect" in msg
    data["gears"]["wheel"]["support"] = {"floating": True, "shaft": {
        "diameter": "80 mm", "span": "300 mm", "position": "150 mm"}}
    with pytest.raises(torquesplit.errors.ModelError,
                       match="floating: a floating member is held by its meshes"):
        torquesplit.load_model(data)
