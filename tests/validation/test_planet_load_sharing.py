"""Planet load sharing (the mesh-load factor K_gamma) with pin position errors and
carrier eccentricity, against a hand calculation of the path compliances and the
published results for a fixed and a floating sun.

Hand calculation (Lin & Parker 1999 coordinates, ring and carrier on rigid bearings,
sun fixed or on a bearing k_s, spur meshes k, planet bearings k_p, pressure angle alpha).
A planet carries equal sun and ring mesh forces F_i (its moment balance), its radial
motion drops out (the two radial components cancel), and the sum of its two mesh
deflections gives, with e_i its pin's tangential error::

    F_i = (D + p_i . s - 2 cos(alpha) e_i) / C,     C = 2 / k + 4 cos^2(alpha) / k_p

D common to all planets (sun, ring and carrier rotations), s the sun's translation and
p_i = (-sin(psi_i - alpha), cos(psi_i - alpha)) its sun mesh's direction.  With
sum F_i = T / r_bs and the sun's balance sum F_i p_i + k_s s = 0 (s = 0 for a fixed sun)
the F_i follow from a 3 x 3 linear system.  Published results checked: a floating sun
equalises three planets whatever their pin errors (Kahraman 1994; Bodas & Kahraman 2004;
Singh 2010 -- statically determinate), but not four, where it leaves opposite planets
equal (Singh 2010); on a fixed sun K_gamma - 1 grows in proportion to the error
(Bodas & Kahraman 2004).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from planetary_models import LP, load, lp_raw

import torquesplit
from torquesplit.assembly.assemble import assemble
from torquesplit.metrics.planetary import planet_load_sharing
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.quasistatic import quasi_static_load_sharing
from torquesplit.solve import static_equilibrium

T_SUN = 100.0  # N m, the example's input torque
RB_S = 2.25e-3 * 42 / 2 * math.cos(LP["alpha"])


def _model(planets, tangential, sun_bearing=None, eccentricity=None):
    """The example with rigid ring and carrier bearings (no translations), the sun fixed
    (``sun_bearing`` None) or on a bearing, and tangential pin errors [m]."""
    raw = lp_raw(planets)
    st = raw["planetary"][0]
    for member in ("ring", "carrier"):
        st[member]["dofs"] = ["theta"]
        st[member].pop("support", None)
    if sun_bearing is None:
        st["sun"]["dofs"] = ["theta"]
        st["sun"].pop("support")
    else:
        st["sun"]["support"] = {"stiffness": sun_bearing}
    st["pin_errors"] = [{"tangential": e} for e in tangential]
    if eccentricity is not None:
        st["carrier"].update(eccentricity=eccentricity[0], eccentricity_phase=eccentricity[1])
    return load(raw)


def _hand(planets, tangential, sun_bearing=None):
    """Sun mesh forces F_i of the hand calculation (module docstring)."""
    a, k, kp = LP["alpha"], LP["k_mesh"], LP["k_bearing"]
    c = 2 / k + 4 * math.cos(a) ** 2 / kp
    psi = [2 * math.pi * i / planets for i in range(planets)]
    p = np.array([[-math.sin(s - a), math.cos(s - a)] for s in psi])
    e = np.asarray(tangential, dtype=float)
    f_tot = T_SUN / RB_S
    # unknowns D, s_x, s_y: F_i = (D + p_i . s - 2 cos(a) e_i) / C
    rows = [np.concatenate([[planets / c], p.sum(axis=0) / c])]
    rhs = [f_tot + (2 * math.cos(a) / c) * e.sum()]
    if sun_bearing is None:
        rows += [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        rhs += [0.0, 0.0]
    else:
        for j in range(2):
            row = np.concatenate([[p[:, j].sum() / c], (p.T @ p)[j] / c])
            row[1 + j] += sun_bearing
            rows.append(row)
            rhs.append((2 * math.cos(a) / c) * (p[:, j] * e).sum())
    x = np.linalg.solve(np.array(rows), np.array(rhs))
    return (x[0] + p @ x[1:] - 2 * math.cos(a) * e) / c


def _sun_forces(model):
    s = assemble(model, options={"rotating_frame": False})
    f = static_equilibrium(s).element_forces
    names = s.element_names
    n = len([m for m in names if m.startswith("stage_sun_planet")])
    ring = np.array([f[names.index(f"stage_ring_planet{i}")] for i in range(1, n + 1)])
    sun = np.array([f[names.index(f"stage_sun_planet{i}")] for i in range(1, n + 1)])
    np.testing.assert_allclose(ring, sun, rtol=1e-9)  # equal on both meshes of a planet
    return sun


def test_equal_planets_share_exactly():
    """Equally spaced planets without errors: every planet carries T / (N r_bs) at every
    mesh position of the quasi-static sweep (K_gamma = 1 to 1e-9)."""
    qs = quasi_static_load_sharing(load(lp_raw(4)), revolutions=0.05)
    k = planet_load_sharing(qs.metrics(), qs.kinematics)
    assert k.per_stage["stage_carrier"] == pytest.approx(1.0, abs=1e-9)
    assert set(k.per_planet) == {f"stage_planet{i}" for i in range(1, 5)}
    f = qs.mesh_forces()
    np.testing.assert_allclose(f[:, :4] / f[:, :4].mean(axis=1, keepdims=True), 1.0,
                               atol=1e-12)
    # the nominal T / (N r_bs), to the turning frame's m Omega^2 / k (the centrifugal
    # preload is linearised about the undeflected geometry)
    np.testing.assert_allclose(f[:, :4], T_SUN / (4 * RB_S), rtol=1e-6)


@pytest.mark.parametrize("planets", [3, 4])
@pytest.mark.parametrize("sun_bearing", [None, 2e7])
def test_tangential_pin_error_against_path_compliances(planets, sun_bearing):
    """One planet's pin 20 um ahead (tangential): the sun mesh forces equal the hand
    calculation to 1e-9, for a fixed sun and a sun on a 2e7 N/m bearing."""
    errors = [20e-6] + [0.0] * (planets - 1)
    ours = _sun_forces(_model(planets, errors, sun_bearing))
    np.testing.assert_allclose(ours, _hand(planets, errors, sun_bearing), rtol=1e-9)
    assert ours[0] < ours[1]  # the pin ahead in the carrier's turning unloads its planet


def test_floating_sun_equalises_three_planets_but_not_four():
    """Published: a floating sun equalises three planets whatever the pin errors (the
    system is statically determinate) but not four, where opposite planets carry equal
    loads (Singh 2010); a fixed sun does neither."""
    floating = 1.0  # N/m: a sun held by its meshes only
    f3 = _sun_forces(_model(3, [30e-6, -10e-6, 0.0], floating))
    assert np.ptp(f3) / f3.mean() < 1e-6
    f4 = _sun_forces(_model(4, [30e-6, 0.0, 0.0, 0.0], floating))
    assert f4[0] == pytest.approx(f4[2], rel=1e-6) and f4[1] == pytest.approx(f4[3], rel=1e-6)
    assert f4.max() / f4.mean() > 1.01
    fixed = _sun_forces(_model(3, [30e-6, -10e-6, 0.0]))
    assert fixed.max() / fixed.mean() > 1.05


def test_fixed_sun_factor_grows_with_the_error():
    """K_gamma - 1 of a fixed sun is proportional to the pin error (Bodas & Kahraman
    2004: linear in the error until a planet unloads)."""
    k = []
    for e in (5e-6, 10e-6, 20e-6):
        f = _sun_forces(_model(4, [-e, 0.0, 0.0, 0.0]))
        k.append(f.max() / f.mean() - 1.0)
    assert k[1] / k[0] == pytest.approx(2.0, rel=1e-9)
    assert k[2] / k[0] == pytest.approx(4.0, rel=1e-9)


def test_carrier_eccentricity_is_a_pin_error_of_every_planet():
    """A carrier eccentricity e (fixed in the carrier's frame) shifts every pin by e: the
    planets share as with the tangential pin errors e . t_i (the radial parts do not
    change the sharing to first order), by hand."""
    e, phase = 15e-6, math.radians(30)
    ours = _sun_forces(_model(4, [0.0] * 4, eccentricity=(e, phase)))
    tangential = [e * math.sin(phase - 2 * math.pi * i / 4) for i in range(4)]
    np.testing.assert_allclose(ours, _hand(4, tangential), rtol=1e-7)


def test_quasi_static_and_dynamic_planet_load_sharing():
    """With a pin error, K_gamma from the quasi-static sweep (the standards' factor, with
    the turning frame's centrifugal terms) agrees with the hand value to 1e-4, and the
    dynamic mean-force K_gamma of a short run (constant mesh stiffness) with it to 1 %."""
    model = _model(4, [-20e-6, 0.0, 0.0, 0.0])
    f = _hand(4, [-20e-6, 0.0, 0.0, 0.0])
    qs = quasi_static_load_sharing(model, revolutions=0.05)
    k_qs = planet_load_sharing(qs.metrics(), qs.kinematics)
    assert k_qs.per_stage["stage_carrier"] == pytest.approx(f.max() / f.mean(), rel=1e-4)
    res = torquesplit.simulate(model, cycles=80)
    assert res.success
    k_dyn = planet_load_sharing(res.metrics("mean_force").load_sharing, res.kinematics)
    assert k_dyn.per_stage["stage_carrier"] == pytest.approx(
        k_qs.per_stage["stage_carrier"], rel=1e-2)
    values = k_dyn.values()
    assert values["planet_load_sharing.mean_force"] == k_dyn.per_stage["stage_carrier"]
    assert "planet_load_sharing.mean_force.stage_planet1" in values
    kin = solve_kinematics(model)
    assert kin.meshes["stage_sun_planet1"].force == pytest.approx(T_SUN / (4 * RB_S))
