"""Messages a reviewer of the planetary and LTCA workflows found missing or misleading:
a floating sun's recipe, the nearest angle that fits, a lead modification the slices
cannot resolve, and the dynamic-run advice printed by the command that analyses
modifications."""

from __future__ import annotations

import tomllib
import warnings

import pytest
from typer.testing import CliRunner

import torquesplit
from model_texts import SPUR_PAIR, write_model
from planetary_models import three_planet_toml
from torquesplit.cli import app
from torquesplit.errors import ModelError
from torquesplit.model.checks import MODIFICATIONS_UNUSED, plausibility_warnings
from torquesplit.model.kinematics import solve_kinematics


def test_a_sun_without_support_is_told_how_to_float():
    """The 'add a support, e.g. 1e8 N/m' hint held the sun: K_gamma 1.054 with a pin
    error, where a floating sun equalises three planets.  A sun gets the recipe."""
    text = three_planet_toml("float").replace(', support = {stiffness = "1e8 N/m"}', "")
    with pytest.raises(ModelError, match=r"planetary\.0\.sun\.support: .*a floating sun, "
                                         r"held by its planet meshes alone: support = "
                                         r"\{floating = true\}"):
        torquesplit.load_model(tomllib.loads(text))
    # and the recipe as told gives a model that loads without a word of floating
    text = three_planet_toml("float").replace('support = {stiffness = "1e8 N/m"}',
                                              "support = {floating = true}", 1)
    def floats(text):
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            torquesplit.load_model(tomllib.loads(text))
        return [w for w in said if "floats" in str(w.message)]

    assert floats(text) == []
    assert floats(text.replace("{floating = true}", '{stiffness = "1 N/m"}'))  # (before)


def test_a_planet_angle_off_the_assembly_condition_is_given_the_nearest_that_fits():
    text = three_planet_toml("angles", extra='angles = ["0 deg", "120 deg", "236.67 deg"]\n')
    with pytest.raises(ModelError, match=r"71\.001 tooth periods.*the nearest for planet 3: "
                                         r"236\.6666667 deg"):
        torquesplit.load_model(tomllib.loads(text))
    # angles in radians to five digits: the message shows the digits it decides by
    # ('at 120 deg ... the nearest: 120 deg' left nothing to change)
    text = three_planet_toml("angles", extra="angles = [0, 2.0944, 4.18879]\n")
    with pytest.raises(ModelError, match=r"at 120\.0002806 deg from planet 1 it is "
                                         r"36\.00008418 tooth periods .*not a whole number "
                                         r"to 1e-06"):
        torquesplit.load_model(tomllib.loads(text))
    # halfway between two that fit: both (the second alone was named)
    text = three_planet_toml("angles", extra='angles = ["0 deg", "120 deg", "235 deg"]\n')
    with pytest.raises(ModelError, match=r"the nearest for planet 3: 233\.3333333 deg or "
                                         r"236\.6666667 deg"):
        torquesplit.load_model(tomllib.loads(text))


def test_crowning_that_too_few_slices_cannot_see_is_said(tmp_path):
    """slices = 1 or 2 with 10 um of crowning gave exactly the unmodified LTCA."""
    data = tomllib.loads(SPUR_PAIR)
    mesh = next(iter(data["meshes"]))
    gear = data["meshes"][mesh]["gears"][0]
    data["gears"][gear]["modifications"] = {"crowning": "10 um"}
    for slices, said in ((2, True), (5, False)):
        data["meshes"][mesh]["stiffness"] = {"method": "ltca", "slices": slices}
        model = torquesplit.load_model(data, check=False)
        found = dict(plausibility_warnings(model, solve_kinematics(model)))
        key = f"meshes.{mesh}.stiffness.slices"
        assert (key in found) == said, found
        if said:
            assert "cannot resolve the lead modification" in found[key]


def test_contact_does_not_advise_using_modifications_in_a_dynamic_run(tmp_path):
    data = tomllib.loads(SPUR_PAIR)
    mesh = next(iter(data["meshes"]))
    gear = data["meshes"][mesh]["gears"][0]
    import tomli_w

    data["gears"][gear]["modifications"] = {"crowning": "10 um"}
    path = write_model(tmp_path, tomli_w.dumps(data))
    res = CliRunner().invoke(app, ["contact", str(path), "--pair", mesh, "--json",
                                   "--harris", "0"])
    assert res.exit_code == 0, res.output
    assert MODIFICATIONS_UNUSED not in res.output
    res = CliRunner().invoke(app, ["check", str(path), "--json"])
    assert MODIFICATIONS_UNUSED in res.output  # (said where it applies)


def test_ltca_tables_at_a_load_the_mesh_does_not_carry_are_said():
    """A pin error put 46 % more on one planet, whose LTCA tables stayed at the nominal
    equal share, silently.  One message per stage mesh, with the planets' range; a
    pair whose given table load is off says the load to give."""
    from planetary_models import small_ltca_raw
    from torquesplit.results.plausibility import ltca_load

    data = small_ltca_raw()
    data["planetary"][0]["pin_errors"] = [{"tangential": "-30 um"}, {}, {}]
    res = torquesplit.simulate(torquesplit.load_model(data), cycles=20)
    said = dict(ltca_load(res, res.metrics()))
    assert set(said) == {"planetary.0.sun_mesh", "planetary.0.ring_mesh"}, said
    assert "per-planet tables are not supported" in said["planetary.0.sun_mesh"]
    even = torquesplit.simulate(torquesplit.load_model(small_ltca_raw()), cycles=20)
    assert ltca_load(even, even.metrics()) == []


def test_every_problem_of_a_planetary_stage_is_said_at_once(tmp_path):
    """A stage with five planets that break the assembly condition and overlap, or with
    two pin errors for three planets and a ring that cannot mesh, said one problem per
    attempt."""
    text = three_planet_toml("five").replace("planets = 3", "planets = 5")
    with pytest.raises(ModelError) as info:
        torquesplit.load_model(tomllib.loads(text))
    said = [msg for _, msg in info.value.issues]
    assert any("does not fit" in m for m in said) and any("planets overlap" in m
                                                          for m in said), said
    text = three_planet_toml("two", teeth=(24, 30, 85),
                             extra='pin_errors = [{tangential = "5 um"}, {}]\n')
    with pytest.raises(ModelError) as info:
        torquesplit.load_model(tomllib.loads(text))
    # (the tooth counts together: the stage, not the ring's line, which a --set of the
    # sun's teeth was blamed on, a planetary reviewer)
    assert [loc for loc, _ in info.value.issues] == ["planetary.0.pin_errors", "planetary.0"]
    assert info.value.issues[1][1].startswith("sun 24, planet 30 and ring 85 teeth: ")
    model = tmp_path / "stage.toml"
    model.write_text(three_planet_toml("two", teeth=(24, 30, 84)))
    res = CliRunner().invoke(app, ["check", str(model), "--set", "planetary.0.sun.teeth=25"])
    assert res.exit_code == 2
    assert "with --set planetary.0.sun.teeth=25: planetary.0: sun 25, planet 30" in res.output
    assert "ring.teeth" not in res.output


def test_contact_says_every_bad_load_with_the_models_problems(tmp_path, monkeypatch):
    """'--load "40 kg" --load "-5 kN" --set <negative crowning>' said the crowning only."""
    import torquesplit.gears.contact.coupling as coupling

    def computed(*args, **kwargs):
        raise AssertionError("the command computed before refusing")

    monkeypatch.setattr(coupling, "contact_model_for_mesh", computed)
    data = tomllib.loads(SPUR_PAIR)
    mesh = next(iter(data["meshes"]))
    gear = data["meshes"][mesh]["gears"][0]
    path = write_model(tmp_path, SPUR_PAIR)
    res = CliRunner().invoke(app, ["contact", str(path), "--pair", mesh, "--load", "40 kg",
                                   "--load", "-5 kN", "--set",
                                   f'gears.{gear}.modifications.crowning="-5 um"'])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 3 and all(ln.startswith("error: ") for ln in lines), res.output
    assert "'40 kg' is neither a force nor a torque" in lines[0]
    assert "'-5 kN' must be positive" in lines[1] and "crowning" in lines[2]


@pytest.mark.parametrize("member, said", [
    ("planet", r"a planet is an external gear \(it meshes with the sun and inside the "
               r"ring\), so it cannot be internal; remove 'kind' \(only the ring is internal\)"),
    ("sun", r"the sun is an external gear \(the planets mesh around it\)"),
])
def test_an_internal_sun_or_planet_is_told_why_not(member, said):
    """'the planet meshes outside the planets' teeth and cannot be internal' (a review)."""
    data = tomllib.loads(three_planet_toml("kind"))
    data["planetary"][0][member]["kind"] = "internal"
    with pytest.raises(ModelError, match=rf"planetary\.0\.{member}\.kind: {said}"):
        torquesplit.load_model(data)


def test_missing_fields_of_two_tables_are_two_lines_each_at_its_table(tmp_path):
    """A planetary reviewer: two missing fields in different tables came out as one line
    with the first one's line number ('m.toml:90: drives.input.body, planetary.0.module:
    required field is missing'); and a carrier without the mass its DOFs need was not
    said beside a missing planet tooth count (the expansion it is checked in never ran)."""
    text = (torquesplit.example_path("lin_parker1999_planetary")).read_text()
    text = text.replace('module = "2.25 mm"', "", 1).replace('body = "stage_sun"\n', "", 1)
    model = tmp_path / "m.toml"
    model.write_text(text)
    res = CliRunner().invoke(app, ["check", str(model)])
    assert res.exit_code == 2
    lines = [x for x in res.output.splitlines() if "required field is missing" in x]
    assert len(lines) == 2, res.output
    assert any(":49: planetary.0.module:" in x for x in lines)  # (its [[planetary]] table)
    assert any(": drives.input.body:" in x and ":49:" not in x for x in lines)
    text = (torquesplit.example_path("lin_parker1999_planetary")).read_text()
    text = text.replace('mass = "5.43 kg"', "", 1).replace("teeth = 48 ", "", 1)
    model.write_text(text)
    with pytest.raises(ModelError) as info:
        torquesplit.load_model(model)
    assert [loc for loc, _ in info.value.issues] == ["planetary.0.planet.teeth",
                                                     "planetary.0.carrier.mass"]
