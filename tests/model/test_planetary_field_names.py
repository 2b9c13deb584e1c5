"""Errors and warnings about a ``[[planetary]]`` stage name the field as the user wrote it
(``planetary.0.planet.modifications.crowning``, ``planetary.0.pin_errors.1``), never a
generated gear, body or mesh; tooth modifications of its members are validated as those
of ``[gears.NAME]``."""

from __future__ import annotations

import json
import re
import warnings

import pytest
from planetary_models import general_elements, small_ltca_raw
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError, ModelWarning

_GENERATED = re.compile(r"\b(gears|bodies|meshes)\.st_")


def _issues(raw: dict) -> list[tuple[str, str]]:
    with pytest.raises(ModelError) as exc:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModelWarning)
            torquesplit.load_model(raw)
    for loc, msg in exc.value.issues:
        assert not _GENERATED.match(loc) and "\n" not in msg and ";" in msg, (loc, msg)
    return exc.value.issues


def _warnings(raw: dict) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        torquesplit.load_model(raw)
    found = [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]
    assert not [w for w in found if _GENERATED.match(w)], found
    return found


@pytest.mark.parametrize("member", ["sun", "planet", "ring"])
def test_a_second_helix_is_refused_naming_the_field(member):
    raw = small_ltca_raw(**{member: {"crowning": "3 um", "second_helix": {"crowning": "5 um"}}})
    (loc, msg), = _issues(raw)
    assert loc == f"planetary.0.{member}.modifications.second_helix", loc
    # not "set kind = 'double_helical'" (as for [gears.NAME]): a stage has one helix
    assert "remove second_helix" in msg and "double_helical" not in msg, msg


@pytest.mark.parametrize("member", ["sun", "planet"])
def test_a_double_helical_member_is_refused_naming_its_kind(member):
    raw = small_ltca_raw()
    raw["planetary"][0].update(helix_angle="20 deg", hand="right")
    raw["planetary"][0][member]["kind"] = "double_helical"
    (loc, msg), = _issues(raw)
    assert loc == f"planetary.0.{member}.kind" and "one helix" in msg, (loc, msg)


def test_a_relief_longer_than_the_active_profile_names_the_members_field_and_mate():
    too_long = {"tip_relief": {"amount": "10 um", "length": "30 mm"}}
    issues = _issues(small_ltca_raw(planet=too_long))
    # the planet is checked against the sun and the ring (once each, not once a planet)
    assert {loc for loc, _ in issues} == {"planetary.0.planet.modifications.tip_relief.length"}
    assert sorted(msg.split(":")[0] for _, msg in issues) == [
        "in the mesh with planetary.0.ring", "in the mesh with planetary.0.sun"], issues
    (loc, msg), = _issues(small_ltca_raw(ring=too_long))
    assert loc == "planetary.0.ring.modifications.tip_relief.length" and "reduce" in msg


def test_modification_amounts_in_mm_warn_once_naming_the_field():
    found = _warnings(small_ltca_raw(planet={"crowning": "1 mm"}, ring={"crowning": "2 mm"}))
    planet = [w for w in found if w.startswith("planetary.0.planet.modifications.crowning:")]
    ring = [w for w in found if w.startswith("planetary.0.ring.modifications.crowning:")]
    assert len(planet) == 1 and len(ring) == 1, found


def test_unused_modifications_and_misalignment_name_the_stage_tables_to_set():
    raw = small_ltca_raw(planet={"crowning": "3 um"}, ring={"crowning": "3 um"})
    stage = raw["planetary"][0]
    stage["sun_mesh"] = {"stiffness": "5e8 N/m", "misalignment": {"lead_mismatch": "5 um"}}
    stage["ring_mesh"] = {"stiffness": "5e8 N/m"}
    found = _warnings(raw)
    said = {w.split(": ")[0]: w for w in found}
    assert "planetary.0.ring_mesh or remove" in said["planetary.0.ring.modifications"]
    assert "planetary.0.sun_mesh and/or planetary.0.ring_mesh" in \
        said["planetary.0.planet.modifications"]
    assert "planetary.0.sun_mesh.misalignment" in said
    # with the LTCA on the sun meshes the planet's modification is used: no warning
    stage["sun_mesh"]["stiffness"] = {"method": "ltca"}
    stage.pop("ring_mesh")
    stage["ring_mesh"] = {"stiffness": "5e8 N/m"}
    assert "planetary.0.planet.modifications" not in {w.split(": ")[0] for w in _warnings(raw)}


@pytest.mark.parametrize("field", ["radial", "tangential"])
def test_pin_error_warnings_name_the_stages_pin_errors(field):
    raw = small_ltca_raw()
    raw["planetary"][0]["pin_errors"] = [{}, {field: "0.5 mm"}, {}]
    found = _warnings(raw)
    assert found and all(w.startswith(f"planetary.0.pin_errors.1.{field}:") for w in found), \
        found


@pytest.mark.parametrize("change, where", [
    ({"carrier": {"polar_inertia": "0.05 kg m^2", "dofs": ["theta", "x", "y"],
                  "support": {"stiffness": "1e8 N/m"}}}, "planetary.0.carrier.mass"),
    ({"module": "2 m"}, "planetary.0.module"),
    ({"sun": {"teeth": 2}}, "planetary.0.sun.teeth"),
    ({"ring": {"teeth": 69, "profile_shift": -3}}, "planetary.0.ring.profile_shift"),
])
def test_errors_of_the_generated_elements_name_the_stages_field(change, where):
    raw = small_ltca_raw()
    raw["planetary"][0].update(change)
    (loc, msg), = _issues(raw)
    assert loc == where, (loc, msg)


def test_the_general_elements_written_back_keep_their_own_names():
    """A model written back has no [[planetary]] table: its messages name what it holds."""
    raw = small_ltca_raw()
    raw["planetary"][0]["pin_errors"] = [{}, {"radial": "0.5 mm"}, {}]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        written = general_elements(torquesplit.load_model(raw))
    found = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        torquesplit.load_model(written)
    found = [str(w.message) for w in caught]
    assert found and all(w.startswith("gears.st_planet2.support.pin_error.radial:")
                         for w in found), found


def test_set_of_a_planet_modification_warns_on_the_argument(tmp_path):
    path = tmp_path / "stage.json"
    path.write_text(json.dumps(small_ltca_raw(planet={"crowning": "3 um"})))
    arg = "planetary.0.planet.modifications.crowning=1 mm"
    res = CliRunner().invoke(app, ["check", str(path), "--set", arg])
    assert res.exit_code == 0, res.output
    assert f"warning: --set {arg}: planetary.0.planet.modifications.crowning: 1 mm" \
        in res.stderr, res.stderr


def test_run_names_the_stages_field_when_the_assembly_refuses(tmp_path):
    """'run' checks less than 'check' before it assembles: the assembly's refusal (a
    bearing with two stiffnesses in the turning carrier's frame) names the field too."""
    raw = small_ltca_raw()
    raw["planetary"][0]["ring"].update(dofs=["theta", "x", "y"], support={
        "stiffness": "1e8 N/m", "stiffness_y": "2e8 N/m"})
    path = tmp_path / "stage.json"
    path.write_text(json.dumps(raw))
    res = CliRunner().invoke(app, ["run", str(path), "--cycles", "5"])
    assert res.exit_code == 2, res.output
    assert "error: planetary.0.ring.support.stiffness_y: " in res.stderr, res.stderr
