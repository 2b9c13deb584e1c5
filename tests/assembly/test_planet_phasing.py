"""Mesh phasing from the involute geometry (assembly/excitation.py ``mesh_phases``)
against a hand construction, the published planetary phasing relations and the
clocking rule of split paths; the warning when a flank is not determined."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from planetary_models import load, lp_raw

import torquesplit
from torquesplit.assembly.excitation import mesh_phases
from torquesplit.errors import ModelWarning
from torquesplit.gears import line_of_action as loa
from torquesplit.model.kinematics import solve_kinematics


def _inv(a):
    return math.tan(a) - a


def _hand_phase(model, kin, mesh, gear):
    """Phase of ``mesh`` at t = 0 seen from the external gear ``gear`` whose reference
    tooth is centred on its x axis, constructed from the tooth flanks: the loaded flank's
    polar angle at the start of active contact -- where the driven gear's tip circle cuts
    the line of action before the pitch point -- and the time a tooth takes to reach it.
    Uses the involute polar angle psi_b -+ inv(alpha_r), not the roll-distance formula."""
    mk = kin.meshes[mesh]
    g = model.gears[gear]
    mod, alpha = g.module, g.pressure_angle
    c = kin.bodies[gear].position[:2]
    rb = g.teeth * mod / 2 * math.cos(alpha)
    psi_b = (math.pi / 2 + 2 * g.profile_shift * math.tan(alpha)) / g.teeth + _inv(alpha)
    drv = model.gears[mk.driven]
    tip = drv.teeth * drv.module / 2 + (drv.module * (1 + drv.profile_shift) *
                                        (-1 if drv.gear_type == "internal" else 1))
    p = mk.contact_point[:2]
    n = mk.line_of_action[:2] / np.linalg.norm(mk.line_of_action[:2])
    d = p - kin.bodies[mk.driven].position[:2]
    b, cc = d @ n, d @ d - tip**2
    roots = [-b + math.sqrt(b * b - cc), -b - math.sqrt(b * b - cc)]
    start = p + max(t for t in roots if t < 0) * n
    rel = start - c
    phi_a, r_a = math.atan2(rel[1], rel[0]), float(np.hypot(*rel))
    w = mk.driver_speed if gear == mk.driver else mk.driven_speed
    sigma = 1.0 if w > 0 else -1.0
    front = (gear == mk.driver) == (sigma > 0)  # loaded flank on the CCW side of the tooth
    alpha_r = math.acos(rb / r_a)
    flank = psi_b - _inv(alpha_r) if front else -psi_b + _inv(alpha_r)
    return (sigma * g.teeth * (flank - phi_a) / (2 * math.pi)) % 1.0


def _diff(a, b):
    return (a - b + 0.5) % 1.0 - 0.5


@pytest.mark.parametrize("teeth", [(42, 48, 138), (25, 35, 95)])
def test_planet_sun_and_ring_phases_from_the_flanks(teeth):
    """A planet's sun mesh and ring mesh load opposite flanks, each from its own start
    of contact: the relative phase from the involute geometry equals the hand
    construction of the flanks (1e-9 cycles), and is not the 0 of the same-flank rule."""
    zs, zp, zr = teeth
    raw = lp_raw(3)
    st = raw["planetary"][0]
    st["sun"]["teeth"], st["planet"]["teeth"], st["ring"]["teeth"] = zs, zp, zr
    model = load(raw)
    kin = solve_kinematics(model)
    ph = mesh_phases(model, kin)
    for i in (1, 2, 3):
        sun, ring, planet = f"stage_sun_planet{i}", f"stage_ring_planet{i}", f"stage_planet{i}"
        ours = _diff(ph[ring], ph[sun])
        hand = _diff(_hand_phase(model, kin, ring, planet), _hand_phase(model, kin, sun, planet))
        assert ours == pytest.approx(hand, abs=1e-9)
        assert abs(ours) > 0.05
    # every planet the same: the relative phase does not depend on the planet's angle
    rel = [_diff(ph[f"stage_ring_planet{i}"], ph[f"stage_sun_planet{i}"]) for i in (1, 2, 3)]
    assert np.ptp(rel) < 1e-9


def test_sun_and_ring_phases_follow_the_published_relations():
    """Parker & Lin 2004: the sun-planet mesh of the planet at psi_n lags that of the first
    by z_s psi_n / 360 deg cycles, the ring-planet mesh by z_r psi_n / 360 deg, with the
    sign of each gear's rotation in the carrier's frame (gamma_sn = -sigma_s z_s psi_n /
    2 pi, gamma_rn = -sigma_r z_r psi_n / 2 pi); unequally spaced planets at multiples of
    360 / (z_s + z_r) = 2 deg.  The table of the four planets is the published relation's."""
    angles = [0.0, 88.0, 180.0, 268.0]
    model = load(lp_raw(4, angles=[f"{a} deg" for a in angles]))
    kin = solve_kinematics(model)
    ph = mesh_phases(model, kin)
    sig_s = math.copysign(1.0, kin.meshes["stage_sun_planet1"].driver_speed)
    sig_r = math.copysign(1.0, kin.meshes["stage_ring_planet1"].driven_speed)
    assert sig_s == -sig_r  # sun and ring turn opposite ways in the carrier frame
    for i, psi in enumerate(angles, start=1):
        g_s = (-sig_s * 42 * psi / 360.0) % 1.0
        g_r = (-sig_r * 138 * psi / 360.0) % 1.0
        assert _diff(ph[f"stage_sun_planet{i}"], ph["stage_sun_planet1"]) == \
            pytest.approx(_diff(g_s, 0.0), abs=1e-9)
        assert _diff(ph[f"stage_ring_planet{i}"], ph["stage_ring_planet1"]) == \
            pytest.approx(_diff(g_r, 0.0), abs=1e-9)


def test_idler_loads_opposite_flanks():
    """An idler (driven by one gear, driving the next) loads opposite flanks, like a
    planet: its two meshes' relative phase is the hand construction's, and differs from
    the same-flank clocking rule -z sigma (theta_2 - theta_1) / 2 pi."""
    text = """
[model]
name = "idler"
[gears.a]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = [0, 0, 0]
[gears.b]
teeth = 31
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "a", angle = "0 deg"}
[gears.c]
teeth = 27
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "b", angle = "70 deg"}
[meshes.ab]
gears = ["a", "b"]
stiffness = "4e8 N/m"
[meshes.bc]
gears = ["b", "c"]
stiffness = "4e8 N/m"
[drives.d]
body = "a"
speed = "1000 rpm"
torque = "50 N m"
[loads.l]
body = "c"
"""
    import tomllib

    model = load(tomllib.loads(text))
    kin = solve_kinematics(model)
    ph = mesh_phases(model, kin)
    ours = _diff(ph["bc"], ph["ab"])
    hand = _diff(_hand_phase(model, kin, "bc", "b"), _hand_phase(model, kin, "ab", "b"))
    assert ours == pytest.approx(hand, abs=1e-9)
    axis = kin.bodies["b"].axis
    e1 = loa.reference_direction(axis, 0.0)
    e2 = np.cross(axis, e1)

    def ang(m):
        r = kin.meshes[m].contact_point - kin.bodies["b"].position
        return math.atan2(r @ e2, r @ e1)

    same_flank = (-31 * math.copysign(1, kin.bodies["b"].speed)
                  * (ang("bc") - ang("ab")) / (2 * math.pi))
    assert abs(_diff(ours, same_flank)) > 0.05


def test_split_paths_keep_the_clocking_rule():
    """Congruent meshes on the same flank (a pinion driving two alike branches): the
    involute construction reduces to the clocking rule of split-torque designs, so the
    seed examples' phases are unchanged where their gears load one flank."""
    model = torquesplit.load_model(torquesplit.example_path("seed001_mill_drive"))
    kin = solve_kinematics(model)
    ph = mesh_phases(model, kin)
    for gear in ("z1", "z6"):  # the pinion of the split, the combining gear
        meshes = [n for n, m in model.meshes.items() if gear in m.gears]
        assert len(meshes) == 2
        axis = kin.bodies[gear].axis
        e1 = loa.reference_direction(axis, 0.0)
        e2 = np.cross(axis, e1)

        def ang(m):
            r = kin.meshes[m].contact_point - kin.bodies[gear].position
            return math.atan2(r @ e2, r @ e1)

        z = model.gears[gear].teeth
        s = math.copysign(1, kin.bodies[gear].speed)
        for m in meshes[1:]:
            rule = -z * s * (ang(m) - ang(meshes[0])) / (2 * math.pi)
            assert _diff(ph[m] - ph[meshes[0]], rule) == pytest.approx(0.0, abs=1e-9)


def test_flank_not_determined_by_the_power_flow_warns():
    """A planet meshing with the sun only carries no load: its flank is not determined by
    the nominal torques, and the kinematics say so (the first listed gear is taken)."""
    data = lp_raw(3)
    model = load(data)
    from torquesplit.model.io import model_from_dict, model_to_dict

    d = model_to_dict(model)
    d["gears"]["idle"] = dict(d["gears"]["stage_planet1"])
    d["gears"]["idle"].pop("place")  # in another plane, where it fits between the planets
    a_w = 2.25e-3 * (42 + 48) / 2
    d["gears"]["idle"]["position"] = [a_w * math.cos(math.pi / 3), a_w * math.sin(math.pi / 3),
                                      0.05]
    d["meshes"]["idle_mesh"] = {"gears": ["stage_sun", "idle"], "stiffness": 5e8}
    m2 = torquesplit.load_model(model_from_dict(d), check=False)
    with pytest.warns(ModelWarning, match="meshes.idle_mesh: no power passes this mesh.*"
                      "give 'driver'"):
        kin = solve_kinematics(m2)
    # the last model's kinematics are kept, and their warning is given again
    with pytest.warns(ModelWarning, match="meshes.idle_mesh: no power passes this mesh"):
        assert solve_kinematics(m2) is kin
    d["meshes"]["idle_mesh"]["driver"] = "stage_sun"
    m3 = torquesplit.load_model(model_from_dict(d), check=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        solve_kinematics(m3)
