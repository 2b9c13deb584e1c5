"""Planetary review: the computed mass of a ring (the rim from its root circle outwards,
not a solid disc), errors in bare metres refused, the pin_radius, bare-radian angle and
missing-table messages."""

from __future__ import annotations

import copy
import math
import re
import tomllib
import warnings

import pytest

from planetary_models import three_planet_toml
import torquesplit
from torquesplit.errors import ModelError, ModelWarning
from torquesplit.model.kinematics import solve_kinematics

#: the reviewer's helical 3-planet stage (24/30/84, m_n 3 mm, 15 deg, 50 mm wide)
P3 = tomllib.loads(three_planet_toml(
    "p3", face_width="50 mm", carrier='polar_inertia = "0.5 kg m^2", mass = "20 kg"',
    damping_ratio=None,
    extra='pressure_angle = "20 deg"\nhelix_angle = "15 deg"\nhand = "right"\n'))


def _raw(**stage):
    raw = copy.deepcopy(P3)
    for key, value in stage.items():
        target, *path = key.split("__")
        node = raw["planetary"][0]
        for part in [target, *path][:-1]:
            node = node.setdefault(part, {})
        node[([target, *path])[-1]] = value
    return raw


def _load(raw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return torquesplit.load_model(raw)


def _issue(raw) -> tuple[str, str]:
    with pytest.raises(ModelError) as exc:
        _load(raw)
    (loc, msg), = exc.value.issues
    assert "\n" not in msg
    return loc, msg


def _ring_annulus(ro):
    """Mass and inertia of the ring's rim by hand: m_t = 3 mm / cos 15 deg, root radius
    r + 1.25 m_n, out to ``ro`` [m]."""
    r = 84 * 3e-3 / math.cos(math.radians(15)) / 2
    rf = r + 1.25 * 3e-3
    m = 7850 * math.pi * (ro**2 - rf**2) * 0.05
    return m, m * (ro**2 + rf**2) / 2, rf


# ------------------------------------------------------------------ 1. ring mass
def test_a_ring_is_its_rim_from_the_root_circle_with_3_5_modules_by_default():
    ring = solve_kinematics(_load(_raw())).bodies["st_ring"]
    rf = _ring_annulus(0.1)[2]
    m, j, _ = _ring_annulus(rf + 3.5 * 3e-3)
    assert ring.mass == pytest.approx(m, rel=1e-9) and ring.mass_computed
    assert ring.polar_inertia == pytest.approx(j, rel=1e-9)
    # a rim of a few kg, not the 20.98 kg / 0.1785 kg m^2 of a solid disc of the pitch circle
    assert 3.5 < ring.mass < 3.7 and 0.06 < ring.polar_inertia < 0.08


def test_a_rings_outer_diameter_or_rim_thickness_gives_its_rim():
    ring = solve_kinematics(_load(_raw(ring__outer_diameter="300 mm"))).bodies["st_ring"]
    assert ring.mass == pytest.approx(_ring_annulus(0.150)[0], rel=1e-9)
    rf = _ring_annulus(0.1)[2]
    ring = solve_kinematics(_load(_raw(ring__rim_thickness="20 mm"))).bodies["st_ring"]
    assert ring.polar_inertia == pytest.approx(_ring_annulus(rf + 0.02)[1], rel=1e-9)
    # given values win
    ring = solve_kinematics(_load(_raw(ring__mass="9 kg"))).bodies["st_ring"]
    assert ring.mass == 9 and not ring.mass_computed


def test_a_general_internal_gear_is_a_rim_too():
    from torquesplit.model.kinematics import gear_mass_properties

    g = _load(_raw()).gears["st_ring"]
    assert g.gear_type == "internal" and g.outer_diameter is None
    mass, inertia, mc, ic = gear_mass_properties(g.model_copy(update={"rim_thickness": 0.02}))
    rf = _ring_annulus(0.1)[2]
    assert mass == pytest.approx(_ring_annulus(rf + 0.02)[0], rel=1e-9) and mc and ic


@pytest.mark.parametrize("stage, loc, words", [
    ({"ring__outer_diameter": "200 mm"}, "planetary.0.ring.outer_diameter",
     ("root circle", "268.39")),
    ({"sun__rim_thickness": "10 mm"}, "planetary.0.sun.rim_thickness", ("internal",)),
    ({"ring__rim_thickness": "10 mm", "ring__outer_diameter": "300 mm"},
     "planetary.0.ring.rim_thickness", ("remove one",)),
])
def test_a_rim_that_cannot_be_is_refused_naming_the_field(stage, loc, words):
    got, msg = _issue(_raw(**stage))
    assert got == loc and all(w in msg for w in words), (got, msg)


def test_check_says_what_a_computed_ring_is():
    from rich.console import Console

    from torquesplit.model.summary import render_summary, summary

    console = Console(width=300, record=True)
    render_summary(summary(_load(_raw())), console)
    text = console.export_text()
    assert "(computed: rim 10.5 mm = 3.5 m_n, d_o 289.39 mm)" in text, text


# ------------------------------------------------------------------ 2. bare metres
@pytest.mark.parametrize("stage, loc, fix", [
    ({"pin_errors": [{"tangential": 20}, {}, {}]}, "planetary.0.pin_errors.0.tangential",
     "write '20 um'"),
    ({"pin_errors": [{}, {}, {"radial": -5}]}, "planetary.0.pin_errors.2.radial",
     "write '-5 um'"),
    ({"sun__errors": {"eccentricity": 20}}, "planetary.0.sun.errors.eccentricity",
     "write '20 um'"),
    ({"ring__errors": {"installation": 15}}, "planetary.0.ring.errors.installation",
     "write '15 um'"),
    ({"planet__errors": {"tooth_thickness": "10 mm"}},
     "planetary.0.planet.errors.tooth_thickness", "write '10 um'"),
    ({"carrier__eccentricity": 8}, "planetary.0.carrier.eccentricity", "write '8 um'"),
])
def test_an_error_larger_than_the_module_is_refused_with_the_fix(stage, loc, fix):
    got, msg = _issue(_raw(**stage))
    assert got == loc and fix in msg and "larger than the module (3 mm)" in msg, (got, msg)
    if "mm" not in str(stage):
        assert "bare number is read in metres" in msg, msg


def test_errors_below_the_module_are_not_refused():
    _load(_raw(pin_errors=[{"tangential": "2.9 mm"}, {}, {}],
               sun__errors={"eccentricity": "20 um"}, carrier__eccentricity="1 mm"))


# ------------------------------------------------------------------ 3. pin radius
@pytest.mark.parametrize("radius, side, offset", [
    ("80 mm", "3.85737 mm inside", None), ("83.86 mm", "2.629 um outside", "2.629 um")])
def test_a_pin_radius_off_the_mesh_circle_says_where_and_the_exact_value(radius, side, offset):
    loc, msg = _issue(_raw(pin_radius=radius))
    assert loc == "planetary.0.pin_radius" and f"{side} the circle" in msg, msg
    assert "pin_radius = '83.8573706 mm'" in msg and "tolerance 1e-06" in msg, msg
    # a small offset is a real pin error: pointed to; 3.9 mm is beyond the module
    assert ("pin_errors = [{radial = '2.629 um'}" in msg) == (offset is not None), msg


def test_the_exact_pin_radius_is_accepted():
    _load(_raw(pin_radius="83.8573706 mm"))


# ------------------------------------------------------------------ 4. bare angles
def test_bare_angles_in_degrees_get_the_unit_hint():
    loc, msg = _issue(_raw(angles=[0, 90, 180]))
    assert loc == "planetary.0.angles" and "read in radians" in msg, msg
    assert "write '90 deg'" in msg, msg
    # radians within a turn: no hint; every planet that does not fit is said at once
    with pytest.raises(ModelError) as exc:
        _load(_raw(angles=[0, 2, 4]))
    said = [msg for _, msg in exc.value.issues]
    assert [m.split(":")[0] for m in said] == ["planet 2 does not fit",
                                               "planet 3 does not fit"], said
    assert all("radians" not in m and "multiples of 360 deg" in m for m in said), said


# ------------------------------------------------------------------ 5. --set of a table
@pytest.mark.parametrize("arg, field, value", [
    ("planetary.0.sun.errors.eccentricity=20 um", "eccentricity", 2e-5),
    ("planetary.0.ring.errors.installation_phase=0.5", "installation_phase", 0.5),
])
def test_set_into_a_schema_table_the_file_lacks_creates_it(arg, field, value):
    """A table the schema knows but the file does not write is created by --set (the
    member's errors here; a model's [analysis] likewise)."""
    from torquesplit.model.overrides import apply_assignments

    data, _ = apply_assignments(P3, [arg])
    member = arg.split(".")[2]
    assert _load(data).gears[f"st_{member}"].errors.model_dump()[field] == pytest.approx(value)
    assert "errors" not in P3["planetary"][0][member]  # (the file's data unchanged)
    data, _ = apply_assignments(P3, ["analysis.table_points=1024"])
    assert _load(data).analysis.table_points == 1024


def test_set_into_an_unknown_table_still_lists_what_exists():
    from torquesplit.model.overrides import apply_assignments

    with pytest.raises(ModelError) as exc:
        apply_assignments(P3, ["planetary.0.sun.erors.eccentricity=20 um"])
    (loc, msg), = exc.value.issues
    assert "does not exist" in msg and "{" not in msg, msg


def test_a_stage_that_nothing_holds_names_the_ring_and_carrier_not_the_planets():
    """A planetary analyst's stage without the ring's torsional_support was told that
    its planets 'can turn freely against the rest': the planets spin fastest in the free
    motion, but it is the ring and the carrier that nothing holds."""
    from planetary_models import load, lp_raw

    raw = lp_raw()
    del raw["planetary"][0]["ring"]["torsional_support"]
    with pytest.raises(ModelError) as exc:
        load(raw)
    said = str(exc.value)
    assert "'stage_ring', 'stage_carrier' (with the planets) can turn freely" in said, said
    assert "planet1'" not in said


def test_a_load_on_a_planet_of_a_turning_carrier_is_named():
    """A balanced load on a planet was told that the power does not balance, to set the
    load's torque to "balanced" (it was): the planet is named, and where to put it."""
    from planetary_models import load, lp_raw

    raw = lp_raw()
    raw["loads"]["output"]["body"] = "stage_planet1"
    with pytest.raises(ModelError) as exc:
        load(raw)
    said = str(exc.value)
    assert ("loads.output.body: 'stage_planet1' is a planet of the turning carrier "
            "'stage_carrier'") in said, said
    assert "power does not balance" not in said


def test_a_stage_name_with_a_space_says_what_a_name_may_hold():
    """'st age', quoted, was told it 'must be text ... write it in quotes'."""
    from planetary_models import load, lp_raw

    raw = lp_raw(name="st age")
    with pytest.raises(ModelError, match=r"planetary\.0\.name: 'st age' is not a name this "
                                         r"field takes; use letters, digits and '_'"):
        load(raw)


def test_shifted_planets_that_do_not_fit_are_told_the_sun_shift_that_closes_the_gap():
    """A planet shift of 0.3 with an unshifted sun and ring (27/33/93): the message gave
    the unshifted tooth-count rule only."""
    from planetary_models import load, lp_raw

    raw = lp_raw(planet={**lp_raw()["planetary"][0]["planet"], "profile_shift": 0.3})
    with pytest.raises(ModelError) as exc:
        load(raw)
    said = str(exc.value)
    found = re.search(r"a sun profile_shift of (-?[\d.]+) closes the gap", said)
    assert found, said
    x = float(found.group(1))
    raw["planetary"][0]["sun"]["profile_shift"] = x  # it does
    load(raw)
