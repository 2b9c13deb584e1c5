"""A mesh that separates in the start-up transient only: warned of as such, and the case
stays ``ok``; one that separates in the settled response is ``contact_lost`` (the same
rule in ``torquesplit run``'s warning and a study's status)."""

from __future__ import annotations

import types

import pytest

from torquesplit.results.plausibility import FRACTION_FLOOR, contact_loss, contact_lost
from torquesplit.study import run_study

#: a reviewer's two-path split: pinion, two idlers, output; 80 um backlash on every mesh
SPLIT = """
[model]
name = "two-path split"
[gears.pinion]
teeth = 20
module = "3 mm"
face_width = "50 mm"
position = ["0 mm", "0 mm", "0 mm"]
dofs = ["theta", "x", "y"]
support = {stiffness = "5e5 N/mm", damping_ratio = 0.02}
[gears.idler1]
teeth = 40
module = "3 mm"
face_width = "50 mm"
position = ["64 mm", "63.27716808 mm", "0 mm"]
dofs = ["theta", "x", "y"]
support = {stiffness = "5e5 N/mm", damping_ratio = 0.02}
[gears.idler2]
teeth = 40
module = "3 mm"
face_width = "50 mm"
position = ["64 mm", "-63.27716808 mm", "0 mm"]
dofs = ["theta", "x", "y"]
support = {stiffness = "5e5 N/mm", damping_ratio = 0.02}
[gears.output]
teeth = 60
module = "3 mm"
face_width = "50 mm"
position = ["200 mm", "0 mm", "0 mm"]
[meshes.p1]
gears = ["pinion", "idler1"]
stiffness = {method = "iso6336"}
damping_ratio = 0.05
backlash = "80 um"
[meshes.p2]
gears = ["pinion", "idler2"]
stiffness = {method = "iso6336"}
damping_ratio = 0.05
backlash = "80 um"
transmission_error = {constant = "10 um"}
[meshes.o1]
gears = ["idler1", "output"]
stiffness = {method = "iso6336"}
damping_ratio = 0.05
backlash = "80 um"
[meshes.o2]
gears = ["idler2", "output"]
stiffness = {method = "iso6336"}
damping_ratio = 0.05
backlash = "80 um"
[drives.motor]
body = "pinion"
speed = "3000 rpm"
power = "POWER"
[loads.out]
body = "output"
speed_coefficient = "50 N m s/rad"
"""


def _study(tmp_path, power: str, error: str) -> dict:
    model = tmp_path / f"split_{power.split()[0]}.toml"
    model.write_text(SPLIT.replace("POWER", power), encoding="utf-8")
    data = {"study": {"name": "start-up", "model": str(model),
                      "outputs": ["contact_loss.p1", "min_force.p1"]},
            "analysis": {"cycles": 150},
            "grid": {"parameters": [{"path": "meshes.p2.transmission_error.constant",
                                     "values": [error]}]}}
    ds = run_study(data, workers=1)
    return {"status": str(ds["status"].values[0]), "reason": str(ds["reason"].values[0]),
            "warnings": str(ds["warnings"].values[0]),
            "loss": float(ds["contact_loss.p1"].values[0]),
            "min": float(ds["min_force.p1"].values[0])}


def test_a_loss_in_the_start_up_alone_leaves_the_case_ok_and_says_so(tmp_path):
    case = _study(tmp_path, "150 kW", "-20 um")
    assert case["loss"] > FRACTION_FLOOR and case["min"] > 0.0
    assert case["status"] == "ok", case
    assert "meshes.p1: contact loss" in case["warnings"]
    assert "in the start-up transient only: the settled response's smallest force is " \
        "positive" in case["warnings"]


def test_a_loss_in_the_settled_response_is_contact_lost(tmp_path):
    """A tenth of the power: 80 um of backlash against the idler's 20 um error offset."""
    case = _study(tmp_path, "15 kW", "-20 um")
    assert case["min"] <= 0.0 and case["loss"] > FRACTION_FLOOR
    assert case["status"] == "contact_lost", case
    assert case["reason"].startswith("contact lost in p1")
    said = case["warnings"].split("meshes.p1: contact loss")[1]
    assert "of the whole run, start-up included: the teeth separate" in said[:80]
    assert "start-up transient only" not in said


def _row(loss, min_force):
    return types.SimpleNamespace(mesh="m", contact_loss=loss, min_force=min_force)


@pytest.mark.parametrize("loss, min_force, lost", [
    (0.5 * FRACTION_FLOOR, 0.0, False),       # rounding: under the floor
    (2 * FRACTION_FLOOR, 0.0, True),          # separated in the settled part
    (2 * FRACTION_FLOOR, -3.0, True),
    (2 * FRACTION_FLOOR, float("nan"), True),  # no settled cycles: not excused
    (2 * FRACTION_FLOOR, 40.0, False)])       # the start-up only
def test_the_rule(loss, min_force, lost):
    assert contact_lost(_row(loss, min_force)) is lost


def test_a_periodic_state_has_no_start_up_to_blame():
    metrics = types.SimpleNamespace(rows=[_row(0.01, 40.0)])
    (loc, msg), = contact_loss(types.SimpleNamespace(periodic=True), metrics)
    assert loc == "meshes.m" and "of the periodic state: the teeth separate" in msg


def test_a_study_whose_first_case_no_run_accepts_is_refused_before_it_starts():
    """A shaft diameter of 200 (read in m) put every gear out of its mesh: each case was
    refused as it ran and the study exited 0 (a studies reviewer).  The first case is
    checked as `torquesplit check` checks a model, before anything runs."""
    from torquesplit.errors import StudyError

    spec = {"study": {"name": "b", "model": "ji_li_mill_drive",
                      "outputs": ["load_sharing.engineering"]},
            "analysis": {"cycles": 20},
            "grid": {"parameters": [{"path": "shafts.drive1.diameter",
                                     "values": [200, 300]}]}}
    with pytest.raises(StudyError, match=r"case 0 \(shafts\.drive1\.diameter = 200 m\) gives "
                                         r"an invalid model: .*more than the whole depth"):
        run_study(spec, workers=1)
