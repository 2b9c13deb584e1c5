"""Planetary stages from the general elements: the [[planetary]] shorthand, epicyclic
kinematics (Willis), planet bearings on the carrier, held members, pin errors, carrier
eccentricity and the rotating frame (Coriolis, centripetal, centrifugal)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from planetary_models import LP, compound_raw, general_elements, load, lp_model, lp_raw

import torquesplit
from torquesplit.assembly.assemble import assemble
from torquesplit.errors import ModelError
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.solve import modal_analysis, static_equilibrium
from torquesplit.solve.static import rigid_body_modes

ZS, ZP, ZR = 42, 48, 138  # the example's tooth counts
A_W = 2.25e-3 * (ZS + ZP) / 2  # centre distance = pin radius [m]
RB_S = 2.25e-3 * ZS / 2 * math.cos(math.radians(24.6))


def _row(structure, element):
    """Projection row of an element by DOF name."""
    e = structure.element_names.index(element)
    sl = slice(structure.v_ptr[e], structure.v_ptr[e + 1])
    return {structure.dof_names[d]: c for d, c in zip(structure.v_dof[sl], structure.v_coef[sl])}


def test_shorthand_is_the_general_elements():
    """The [[planetary]] table is sugar: the model it expands to, written out as general
    sections and read again, assembles to the same equations."""
    model = lp_model(4)
    data = general_elements(model)
    assert "planetary" not in data and "stage_carrier" in data["bodies"]
    a, b = torquesplit.assemble(model), torquesplit.assemble(load(data))
    assert a.dof_names == b.dof_names and a.element_names == b.element_names
    np.testing.assert_array_equal(a.stiffness_matrix(), b.stiffness_matrix())
    np.testing.assert_array_equal(a.gyroscopic_matrix(), b.gyroscopic_matrix())
    np.testing.assert_array_equal(a.external_force, b.external_force)


def test_willis_speeds_torques_and_drivers():
    """Ring held: w_c = w_s z_s / (z_s + z_r), the planet turns at w_c - (w_s - w_c) z_s /
    z_p; the ring reacts T z_r / z_s, the carrier takes T (1 + z_r / z_s); each sun mesh
    carries T / (N r_bs) at the mesh frequency z_s (w_s - w_c) / 2 pi (by hand)."""
    kin = solve_kinematics(lp_model(4))
    ws = kin.bodies["stage_sun"].speed
    wc = kin.bodies["stage_carrier"].speed
    assert wc == pytest.approx(ws * ZS / (ZS + ZR), rel=1e-12)
    assert kin.bodies["stage_planet3"].speed == pytest.approx(wc - (ws - wc) * ZS / ZP, rel=1e-12)
    assert kin.bodies["stage_ring"].speed == 0.0
    assert abs(kin.reactions["stage_ring"]) == pytest.approx(100.0 * ZR / ZS, rel=1e-9)
    assert kin.load_torques["output"] == pytest.approx(100.0 * (1 + ZR / ZS), rel=1e-9)
    for i in range(1, 5):
        sun, ring = kin.meshes[f"stage_sun_planet{i}"], kin.meshes[f"stage_ring_planet{i}"]
        assert (sun.driver, ring.driver) == ("stage_sun", f"stage_planet{i}")
        assert sun.force == pytest.approx(100.0 / (4 * RB_S), rel=1e-9)
        assert ring.force == pytest.approx(sun.force, rel=1e-9)
        assert sun.frequency == pytest.approx(ZS * (ws - wc) / (2 * math.pi), rel=1e-12)
        assert sun.carrier == "stage_carrier"
    assert kin.input_power == pytest.approx(kin.output_power, rel=1e-9)


def test_star_and_differential_speeds():
    """Carrier held (star): the ring turns at -w_s z_s / z_r.  Nothing held, sun and
    ring driven through two paths (the differential example): w_c = (z_s w_s + z_r w_r) /
    (z_s + z_r) and the ring takes z_r / z_s times the sun's torque."""
    star = solve_kinematics(torquesplit.load_model(torquesplit.example_path(
        "lin_parker1999_star")))
    ws = star.bodies["stage_sun"].speed
    assert star.bodies["stage_carrier"].speed == 0.0
    assert star.bodies["stage_ring"].speed == pytest.approx(-ws * ZS / ZR, rel=1e-12)
    diff = solve_kinematics(torquesplit.load_model(torquesplit.example_path(
        "split_path_planetary_differential")))
    w = {b: diff.bodies[b].speed for b in ("stage_sun", "stage_ring", "stage_carrier")}
    assert w["stage_carrier"] == pytest.approx((30 * w["stage_sun"] + 90 * w["stage_ring"])
                                               / 120, rel=1e-12)
    t_sun = diff.bodies["stage_sun"].torque
    assert diff.bodies["stage_ring"].torque == pytest.approx(3 * t_sun, rel=1e-9)
    p_a = diff.meshes["path_a"].power
    assert p_a / diff.input_power == pytest.approx(
        t_sun * abs(w["stage_sun"]) / diff.input_power, rel=1e-9)


def test_ring_mesh_listing_order_does_not_matter():
    """The driving flank follows from the torques, not from the order the gears are
    listed in (issue 16: listing a ring mesh the other way round moved modes by 8 %)."""
    model = lp_model(4)
    data = general_elements(model)
    for name, mesh in data["meshes"].items():
        if "ring" in name:
            mesh["gears"] = mesh["gears"][::-1]
    other = load(data)
    for a, b in ((model, other),):
        ka, kb = solve_kinematics(a), solve_kinematics(b)
        assert {n: m.driver for n, m in ka.meshes.items()} == \
            {n: m.driver for n, m in kb.meshes.items()}
    fa = modal_analysis(torquesplit.assemble(model)).frequencies
    fb = modal_analysis(torquesplit.assemble(other)).frequencies
    np.testing.assert_allclose(fa, fb, rtol=1e-10)


def test_planet_bearing_follows_the_carrier_rotation():
    """A planet pin at radius R moves with the carrier's rotation: the bearing's
    deformation along y of planet 1 (on the x axis) is y_p - y_c - R theta_c (Lin & Parker
    1999: -x_c sin(psi) + y_c cos(psi) + u_c - eta)."""
    s = torquesplit.assemble(lp_model(4))
    row = _row(s, "stage_planet1.support.y")
    assert row == pytest.approx({"stage_planet1.y": 1.0, "stage_carrier.y": -1.0,
                                 "stage_carrier.theta": -A_W}, rel=1e-12)
    row = _row(s, "stage_planet2.support.x")  # planet 2 at 90 deg: tangential is -x
    assert row["stage_carrier.theta"] == pytest.approx(A_W, rel=1e-12)
    assert "stage_planet1.theta" not in _row(s, "stage_planet1.support.x")


def test_pin_errors_and_carrier_eccentricity_offset_the_bearings():
    """A pin error (radial e_r, tangential e_t) of planet 2 at 90 deg is the offset
    (-e_t, e_r) of its bearing; the carrier's eccentricity, fixed in its own frame, a
    constant offset of its support."""
    raw = lp_raw(4, pin_errors=[{}, {"radial": "20 um", "tangential": "-7 um"}, {}, {}])
    raw["planetary"][0]["carrier"].update(eccentricity="10 um", eccentricity_phase="30 deg")
    s = torquesplit.assemble(load(raw))
    err = dict(zip(s.element_names, s.error_constant))
    assert err["stage_planet2.support.x"] == pytest.approx(7e-6, rel=1e-12)
    assert err["stage_planet2.support.y"] == pytest.approx(20e-6, rel=1e-12)
    assert err["stage_planet1.support.x"] == 0.0
    assert err["stage_carrier.support.x"] == pytest.approx(10e-6 * math.cos(math.pi / 6))
    assert err["stage_carrier.support.y"] == pytest.approx(10e-6 * math.sin(math.pi / 6))
    assert s.error_amplitude.size == 0  # nothing turns in the carrier's frame


def test_rotating_frame_terms():
    """In the turning carrier's frame every translating body gets G_xy = -2 m Omega,
    G_yx = +2 m Omega, a centripetal frame stiffness -m Omega^2 on x and y, and a planet
    the centrifugal force m Omega^2 R (Lin & Parker 1999 eq. 1 with Omega_c)."""
    model = lp_model(4)
    kin = solve_kinematics(model)
    om = kin.bodies["stage_carrier"].speed
    s = assemble(model, kin)
    G = s.gyroscopic_matrix()
    np.testing.assert_allclose(G, -G.T, atol=0)
    idx = {n: i for i, n in enumerate(s.dof_names)}
    Kf = s.frame_stiffness_matrix()
    for body, m in (("stage_sun", LP["m_s"]), ("stage_ring", LP["m_r"]),
                    ("stage_carrier", LP["m_c"]), ("stage_planet3", LP["m_p"])):
        assert G[idx[f"{body}.x"], idx[f"{body}.y"]] == pytest.approx(-2 * m * om, rel=1e-12)
        for d in ("x", "y"):
            assert Kf[idx[f"{body}.{d}"], idx[f"{body}.{d}"]] == pytest.approx(-m * om**2,
                                                                              rel=1e-12)
        assert Kf[idx[f"{body}.x"], idx[f"{body}.y"]] == pytest.approx(0.0, abs=1e-9 * m * om**2)
    assert s.external_force[idx["stage_planet1.x"]] == pytest.approx(
        LP["m_p"] * om**2 * A_W, rel=1e-12)
    still = assemble(model, kin, options={"rotating_frame": False})
    assert still.n_gyroscopic == 0 and still.n_frame_stiffness == 0
    with pytest.raises(ValueError, match="rotating_frame must be true or false"):
        assemble(model, kin, options={"rotating_frame": "yes"})


def _lin_parker_first_order(planets, omega, alpha, without_rigid_carrier=False):
    """Lin & Parker 1999 eq. 1 written out from the paper's deflections (independent of
    the assembly): M q'' + Omega G q' + (K_b + K_m - Omega^2 K_Omega) q = 0 in the
    coordinates (x, y, u) of carrier, ring, sun and (zeta, eta, u) of each planet."""
    n = 3 * (3 + planets)
    K, M, G, KO = (np.zeros((n, n)) for _ in range(4))
    c, r, s = 0, 3, 6
    masses = ((c, LP["m_c"], LP["i_c"]), (r, LP["m_r"], LP["i_r"]), (s, LP["m_s"], LP["i_s"]))
    for b, m, i in masses + tuple((9 + 3 * k, LP["m_p"], LP["i_p"]) for k in range(planets)):
        M[b, b] = M[b + 1, b + 1] = m
        M[b + 2, b + 2] = i
        G[b, b + 1], G[b + 1, b] = -2 * m, 2 * m
        KO[b, b] = KO[b + 1, b + 1] = m
    kb, km = LP["k_bearing"], LP["k_mesh"]
    for b in (c, r, s):
        K[b, b] += kb
        K[b + 1, b + 1] += kb
    K[r + 2, r + 2] += LP["k_ru"]

    def spring(v, k):
        K[:] += k * np.outer(v, v)

    for k in range(planets):
        psi = 2 * math.pi * k / planets
        p = 9 + 3 * k
        v = np.zeros(n)  # sun-planet deflection
        v[[s, s + 1, s + 2, p, p + 1, p + 2]] = (-math.sin(psi - alpha), math.cos(psi - alpha),
                                                1.0, -math.sin(alpha), -math.cos(alpha), 1.0)
        spring(v, km)
        v = np.zeros(n)  # ring-planet deflection
        v[[r, r + 1, r + 2, p, p + 1, p + 2]] = (-math.sin(psi + alpha), math.cos(psi + alpha),
                                                1.0, math.sin(alpha), -math.cos(alpha), -1.0)
        spring(v, km)
        v = np.zeros(n)  # planet bearing, radial
        v[[c, c + 1, p]] = (math.cos(psi), math.sin(psi), -1.0)
        spring(v, kb)
        v = np.zeros(n)  # planet bearing, tangential
        v[[c, c + 1, c + 2, p + 1]] = (-math.sin(psi), math.cos(psi), 1.0, -1.0)
        spring(v, kb)
    Kt = K - omega**2 * KO
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(M, Kt), -np.linalg.solve(M, omega * G)]])
    return np.linalg.eigvals(A)


def _first_order(structure, drop=()):
    """Eigenvalues of the first-order system; ``drop=("carrier_turn",)`` leaves out the
    frame-stiffness entries of the carrier's rotation (the centripetal softening measured
    from where the carrier's rotation takes a planet: rows and columns of the rotations),
    which the paper's absolute planet translations do not have."""
    keep = [i for i, nm in enumerate(structure.element_names) if not any(d in nm for d in drop)]
    V = structure.projection_matrix()[keep]
    Kf = structure.frame_stiffness_matrix()
    if "carrier_turn" in drop:
        rot = [i for i, nm in enumerate(structure.dof_names) if nm.endswith(".theta")]
        Kf[rot, :] = 0.0
        Kf[:, rot] = 0.0
    K = V.T @ (structure.mean_stiffness()[keep][:, None] * V) + Kf
    n = structure.n_dof
    inv_m = structure.inv_mass
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-inv_m[:, None] * K, -inv_m[:, None] * structure.gyroscopic_matrix()]])
    return np.linalg.eigvals(A)


def _sorted(lam):
    lam = lam[np.abs(lam) > 1e-3]
    return lam[np.lexsort((np.round(lam.real, 3), np.round(lam.imag, 3)))]


@pytest.mark.parametrize("planets", [3, 4])
def test_turning_frame_equals_the_published_equations(planets):
    """At a carrier speed of 6500 rpm (sun 34 000 rpm) the assembled equations have
    the eigenvalues of Lin & Parker 1999 eq. 1 with Omega_c = the carrier speed, written
    out in the paper's coordinates (independent of the assembly), to 1e-8 -- once the
    softening's terms of the carrier's rotation, which the paper omits, are taken out."""
    raw = lp_raw(planets)
    raw["drives"]["input"]["speed"] = "34000 rpm"
    model = load(raw)
    om = solve_kinematics(model).bodies["stage_carrier"].speed
    assert om > 600  # the Coriolis terms are not small
    ours = _sorted(_first_order(torquesplit.assemble(model), drop=("carrier_turn",)))
    paper = _sorted(_lin_parker_first_order(planets, om, LP["alpha"]))
    assert ours.size == paper.size
    np.testing.assert_allclose(ours, paper, rtol=1e-8, atol=1e-6 * np.abs(paper).max())


def test_rigid_rotation_stays_rigid_in_the_turning_frame():
    """With the softening measured from where the carrier's rotation takes each planet,
    the rotation of carrier, sun and planets together (ring held) is still a
    zero-frequency mode at speed: the stiffness matrix has the kinematic rigid rotation
    (that of the projections alone) in its null space to round-off, so torques balanced
    by the gear ratios load it with nothing; with the paper's absolute translations it
    would diverge."""
    raw = lp_raw(4)
    raw["drives"]["input"]["speed"] = "34000 rpm"
    s = torquesplit.assemble(load(raw))
    sol = modal_analysis(s, static_equilibrium(s).q)
    assert sol.rigid_modes.shape[1] == 1 and np.all(sol.frequencies > 0)
    d = np.sqrt(s.inv_mass)
    lam = np.linalg.eigvalsh(d[:, None] * s.stiffness_matrix() * d[None, :])
    assert abs(lam[0]) < 1e-12 * lam[-1] and lam[1] > 1e-4 * lam[-1]
    phi = rigid_body_modes(s)[:, 0]
    K = s.stiffness_matrix()
    assert np.linalg.norm(K @ phi) < 1e-12 * np.linalg.norm(K) * np.linalg.norm(phi)
    lam = _first_order(s, drop=("carrier_turn",))
    assert np.max(lam.real) > 1.0  # the spurious divergence without those terms


def test_star_is_the_planetary_with_the_carrier_held():
    """The star example (carrier held rigidly, ring free) assembles to the planetary
    example's stationary-carrier equations with the carrier's rotation removed and the
    ring's torsional spring dropped; and the sun torque gives the same mesh forces."""
    planetary = torquesplit.assemble(lp_model(4), options={"rotating_frame": False})
    star = torquesplit.assemble(torquesplit.load_model(
        torquesplit.example_path("lin_parker1999_star")))
    keep_el = [i for i, n in enumerate(planetary.element_names)
               if n != "stage_ring.torsional_support"]
    keep_dof = [i for i, n in enumerate(planetary.dof_names) if n != "stage_carrier.theta"]
    V = planetary.projection_matrix()[keep_el][:, keep_dof]
    K = V.T @ (planetary.mean_stiffness()[keep_el][:, None] * V)
    d = np.sqrt(planetary.inv_mass[keep_dof])
    lam = np.linalg.eigvalsh(d[:, None] * K * d[None, :])
    expected = np.sqrt(lam[lam > 1e-9 * lam.max()]) / (2 * math.pi)
    assert [n for n in planetary.dof_names if n != "stage_carrier.theta"] == \
        [n for n in star.dof_names]
    np.testing.assert_allclose(modal_analysis(star).frequencies, expected, rtol=1e-9)
    fp = static_equilibrium(planetary).element_forces[:8]
    fs = static_equilibrium(star).element_forces[:8]
    np.testing.assert_allclose(fs, fp, rtol=1e-9)


def test_torsional_support_elastic_and_rigid():
    raw = lp_raw(4)
    s = torquesplit.assemble(load(raw))
    k = dict(zip(s.element_names, s.stiffness_table[:, 0]))
    rbr = 2.25e-3 * ZR / 2 * math.cos(LP["alpha"])
    assert k["stage_ring.torsional_support"] == pytest.approx(1e9 * 0.1411589**2, rel=1e-9)
    assert rbr == pytest.approx(0.1411589, rel=1e-6)
    raw["planetary"][0]["ring"]["torsional_support"] = {"rigid": True}
    rigid = torquesplit.assemble(load(raw))
    assert "stage_ring.theta" not in rigid.dof_names
    assert rigid.n_dof == s.n_dof - 1


def test_planets_rigid_on_their_pins():
    """A planet without translations rides its pin: its mass moves with the carrier
    (m R^2 on its rotation) and its meshes with the pin.  The modes of the rotational
    model equal those of planets on bearings a million times stiffer."""
    def model(rigid):
        raw = lp_raw(3)
        st = raw["planetary"][0]
        for member in ("sun", "ring", "carrier"):
            st[member]["dofs"] = ["theta"]
            st[member].pop("support", None)
        if rigid:
            st["planet"]["dofs"] = ["theta"]
        else:
            st["planet_bearing"] = {"stiffness": "1e14 N/m"}
        return torquesplit.assemble(load(raw), options={"rotating_frame": False})

    r, b = model(True), model(False)
    assert r.n_dof == 6  # sun, ring, carrier and three planet rotations
    f_r = modal_analysis(r).frequencies
    f_b = modal_analysis(b).frequencies
    np.testing.assert_allclose(f_r, f_b[:f_r.size], rtol=1e-5)


def _mesh_forces(structure, solution):
    return {n: float(solution.element_forces[i]) for i, n in enumerate(structure.element_names)
            if structure.element_kind[i] == 1}


def _rigid_and_stiff_pins(raw):
    """Static mesh forces of the stage ``raw`` with its planets rigid on their pins, and
    with them on bearings of 1e14 N/m (a million times the example's)."""
    out = []
    for rigid in (True, False):
        data = copy.deepcopy(raw)
        st = data["planetary"][0]
        if rigid:
            st["planet"]["dofs"] = ["theta"]
        else:
            st["planet_bearing"] = {"stiffness": "1e14 N/m"}
        s = torquesplit.assemble(load(data))
        out.append(_mesh_forces(s, static_equilibrium(s)))
    return out


def test_a_planet_rigid_on_its_pin_is_displaced_by_its_pin_error():
    """A tangential pin error of 20 um on a planet without translations loads its meshes
    as it does a planet on a bearing a million times stiffer (it was ignored: equal
    sharing)."""
    r, b = _rigid_and_stiff_pins(lp_raw(4, pin_errors=[{"tangential": "20 um"}, {}, {}, {}]))
    assert r.keys() == b.keys() and len(r) == 8
    for name in r:
        assert r[name] == pytest.approx(b[name], rel=1e-4), name
    assert r["stage_sun_planet2"] - r["stage_sun_planet1"] > 1e3  # [N]: far from equal


def test_a_compound_planet_gear_moves_with_its_shaft():
    """A gear without translations on a planet's shaft (a compound planet's ring gear)
    moves with the planet's bearing, not rigidly with the carrier's pin: its mass in the
    planet's Coriolis term, and the same mesh forces, bearing forces and modes as with
    that gear on a bearing of 1e14 N/m on its shaft partner; the pin bearing carries the
    carrier torque, T_c / (N R) = 900 N m / (3 x 60 mm) = 5 kN tangentially (it carried
    the sun mesh's share alone)."""
    def solve(**kw):
        s = torquesplit.assemble(load(compound_raw(**kw)))
        st = static_equilibrium(s)
        f = dict(zip(s.element_names, st.element_forces))
        return s, _mesh_forces(s, st), f, modal_analysis(s, st.q).frequencies

    s0, mesh0, f0, _ = solve()
    assert "pb0.x" not in s0.dof_names
    # the Coriolis term of the planet's translations carries both gears' mass, 2 m Omega_c
    i, j = (s0.dof_names.index(f"pa0.{d}") for d in "xy")
    omega_c = 100.0 * 2 * math.pi / 60  # 900 rpm / 9
    assert abs(s0.gyroscopic_matrix()[i, j]) == pytest.approx(2 * (0.5 + 0.2) * omega_c,
                                                               rel=1e-12)
    assert f0["pa0.support.y"] == pytest.approx(5000.0, rel=1e-6)  # tangential at 0 deg
    for pin in (None, {"tangential": "20 um"}):
        s, mesh, f, freq = solve(pin_error=pin)
        sb, mesh_b, fb, freq_b = solve(pin_error=pin, shaft_bearing="1e14 N/m")
        for name in mesh:
            assert mesh[name] == pytest.approx(mesh_b[name], rel=1e-6), name
        for e in ("pa0.support.x", "pa0.support.y", "pa1.support.y"):
            assert f[e] == pytest.approx(fb[e], rel=1e-6, abs=1e-6), e
        np.testing.assert_allclose(freq, freq_b[:freq.size], rtol=1e-5)
    assert mesh["sp0"] < 0.6 * mesh["sp1"]  # the pin error unloads planet 0


def test_a_compound_planet_bearing_damping_ratio_counts_both_gears():
    """c = 2 zeta sqrt(k m), m the planet shaft's mass (0.5 + 0.2 kg) against the
    carrier's (5 kg) in series."""
    raw = compound_raw()
    raw["gears"]["pa0"]["support"]["damping_ratio"] = 0.05
    s = torquesplit.assemble(load(raw))
    c = dict(zip(s.element_names, s.damping))["pa0.support.x"]
    m = 0.7 * 5.0 / 5.7
    assert c == pytest.approx(2 * 0.05 * math.sqrt(2e8 * m), rel=1e-12)


def test_a_gear_on_a_bearing_on_a_planet_preloads_the_pin():
    """Its centrifugal load reaches the carrier's pin through the planet, and its
    softening, measured from where the carrier's rotation takes it, leaves the rigid
    rotation of carrier, sun and planets a zero mode in the turning frame (it diverged,
    -1.97 Hz at 9000 rpm, whatever the bearing).  With a bearing of 1e14 N/m the modes
    are those of the gear riding the shaft."""
    from torquesplit.modes import model_modes

    def modes(bearing):
        raw = compound_raw(shaft_bearing=bearing)
        raw["drives"]["input"]["speed"] = "9000 rpm"
        return model_modes(load(raw))

    for bearing in ("5e8 N/m", "2e9 N/m"):
        rep = modes(bearing)
        assert rep.rigid_modes == 1 and min(r.frequency for r in rep.rows) > 900.0
    stiff, rigid = modes("1e14 N/m"), modes(None)
    f_rigid = sorted(r.frequency for r in rigid.rows)
    f_stiff = sorted(r.frequency for r in stiff.rows)[:len(f_rigid)]
    np.testing.assert_allclose(f_stiff, f_rigid, rtol=1e-5)


def test_a_compound_planet_is_one_planet_in_its_load_sharing():
    """K_gamma per planet shaft, named after the gear on the pin and taken over both its
    gears' meshes (the ring gears were listed as planets of their own)."""
    from torquesplit.metrics.planetary import planet_load_sharing
    from torquesplit.quasistatic import quasi_static_load_sharing

    qs = quasi_static_load_sharing(load(compound_raw(pin_error={"tangential": "20 um"})),
                                   revolutions=0.05)
    k = planet_load_sharing(qs.metrics(), qs.kinematics)
    assert list(k.per_planet) == ["pa0", "pa1", "pa2"]
    per_mesh = qs.metrics().position_mean
    for i in range(3):
        assert k.per_planet[f"pa{i}"] == pytest.approx(max(per_mesh[f"sp{i}"],
                                                           per_mesh[f"rp{i}"]), rel=1e-12)
    assert k.per_stage["carrier"] == pytest.approx(max(k.per_planet.values()), rel=1e-12)


def test_a_gear_seated_on_a_planet_rigid_on_its_pin():
    """The other way round: the pin's gear rigid on its pin, the ring gear on a bearing
    of 1e14 N/m seated on it (the seat moves with the pin and its error; it was held by
    the housing, and the stage did not balance): as both rigid on the pin."""
    def forces(seated):
        raw = compound_raw(pin_error={"tangential": "20 um"},
                           shaft_bearing="1e14 N/m" if seated else None)
        for i in range(3):
            raw["gears"][f"pa{i}"]["dofs"] = ["theta"]
        s = torquesplit.assemble(load(raw))
        return _mesh_forces(s, static_equilibrium(s))

    rigid, seated = forces(False), forces(True)
    for name in rigid:
        assert seated[name] == pytest.approx(rigid[name], rel=2e-5), name  # (1e14 N/m)
    assert rigid["sp0"] < 0 < rigid["sp1"]  # 20 um: planet 0's teeth pull (no backlash)


def test_rigid_planets_on_a_rigid_carrier_see_its_eccentricity():
    """A carrier without translations offsets every pin by its eccentricity: planets
    rigid on their pins load as planets on bearings a million times stiffer."""
    raw = lp_raw(3)
    st = raw["planetary"][0]
    st["carrier"]["dofs"] = ["theta"]
    st["carrier"].pop("support", None)
    st["carrier"].update(eccentricity="10 um", eccentricity_phase="30 deg")
    st["sun"]["dofs"] = ["theta"]  # (a fixed sun: the offsets load the planets)
    st["sun"].pop("support", None)
    r, b = _rigid_and_stiff_pins(raw)
    for name in r:
        assert r[name] == pytest.approx(b[name], rel=1e-4), name
    assert max(r.values()) > 1.2 * min(r.values())


def test_compound_planet_kinematics_and_torques():
    """Willis with a stepped planet: carrier = sun / (1 + (80/20)(40/20)) = 100 rpm,
    planets -300 rpm; each planet shaft passes the sun mesh's torque on to its ring
    gear, F r_b = 100 N m / 3 x 40/20 = 66.67 N m on both its gears (the body table gave
    half of it: the rigid shaft's torque was left out)."""
    kin = solve_kinematics(load(compound_raw()))
    rpm = 60 / (2 * math.pi)
    assert kin.bodies["carrier"].speed * rpm == pytest.approx(100.0, rel=1e-12)
    assert kin.bodies["pa0"].speed * rpm == pytest.approx(-300.0, rel=1e-12)
    assert kin.load_torques["output"] == pytest.approx(900.0, rel=1e-8)
    for g in ("pa0", "pb0", "pa2", "pb2"):
        assert kin.bodies[g].torque == pytest.approx(200.0 / 3, rel=1e-8), g
    assert kin.bodies["sun"].torque == pytest.approx(100.0, rel=1e-8)
    assert kin.bodies["carrier"].torque == pytest.approx(900.0, rel=1e-8)
    # a held member on a rigid shaft: both carry the reaction, T_s z_r / z_s (it was
    # halved: the reaction was counted on the held body alone)
    raw = lp_raw(4)
    raw["planetary"][0]["ring"].pop("torsional_support")
    raw["bodies"] = {"housing": {"polar_inertia": "1 kg m^2",
                                 "torsional_support": {"rigid": True}}}
    raw["shafts"] = {"fix": {"connects": ["stage_ring", "housing"], "rigid": True}}
    kin = solve_kinematics(load(raw))
    for b in ("stage_ring", "housing"):
        assert kin.bodies[b].torque == pytest.approx(100.0 * ZR / ZS, rel=1e-8), b


@pytest.mark.parametrize("teeth, fits", [((20, 40, 20, 80), True), ((20, 30, 24, 74), True),
                                         ((20, 30, 26, 76), False)])
def test_compound_planets_clocked_alike(teeth, fits):
    """Identical compound planets (the gears of every planet shaft clocked alike) fit
    where (z_s z_b + z_r z_a) / (N gcd(z_a, z_b)) is whole: 60, 150, and 466.67 (refused,
    naming the ring mesh of a planet; giving the meshes' phases clocks each planet on its
    own).  Where they fit, the ring meshes of planets at psi differ by -sigma z_r psi / 2 pi
    as for simple planets, and the first planet's gears have a tooth at one angle."""
    from torquesplit.assembly.excitation import _phase_terms, mesh_phases

    raw = compound_raw(teeth=teeth)
    if not fits:
        with pytest.raises(ModelError, match=r"meshes\.rp[12].*compound planets cannot all "
                                             r"be clocked alike"):
            load(raw)
        # a phase given on the first planet's meshes clocks that planet only
        raw["meshes"]["rp0"]["phase"] = 0.3
        with pytest.raises(ModelError, match=r"meshes\.rp[12].*clocked alike"):
            load(raw)
        for i in range(3):
            raw["meshes"][f"rp{i}"]["phase"] = 0.1 * i
        load(raw)  # planets clocked each on its own
        return
    model = load(raw)
    kin = solve_kinematics(model)
    ph = mesh_phases(model, kin, strict=True)
    zs, zr = teeth[0], teeth[3]
    # -sigma z psi / 2 pi, sigma the sign of the central gear's speed in the carrier's
    # frame: the sun turns at +800 rpm there (sigma +1), the held ring at -100 rpm (-1)
    for i in (1, 2):
        for mesh, z, sigma in (("sp", zs, 1), ("rp", zr, -1)):
            gap = (ph[f"{mesh}{i}"] - ph[f"{mesh}0"]) % 1.0
            expect = (-sigma * z * i / 3) % 1.0
            assert abs((gap - expect + 0.5) % 1.0 - 0.5) < 1e-9, (mesh, i, gap, expect)
    # the tooth angle of pa0 (from sp0) and of pb0 (from rp0) agree, modulo pb's pitch

    def tooth(mesh, gear):
        z, sigma, tau, c = _phase_terms(model, kin, mesh, gear)
        return tau + 2 * math.pi * (ph[mesh] - c) / (sigma * z)

    miss = (tooth("rp0", "pb0") - tooth("sp0", "pa0")) * teeth[2] / (2 * math.pi)
    assert abs((miss + 0.5) % 1.0 - 0.5) < 1e-9


# --------------------------------------------------------------------------- bad input
def _general(**change):
    data = general_elements(lp_model(4))
    for path, value in change.items():
        node = data
        keys = path.split(".")
        for k in keys[:-1]:
            node = node[k]
        node[keys[-1]] = value
    return data


@pytest.mark.parametrize("change, where, text", [
    ({"gears.stage_planet2.place.angle": math.radians(91)}, "meshes.stage_",
     "tooth-count assembly condition"),
    ({"gears.stage_ring.kind": "spur"}, "gears.stage_ring.kind", "set kind = 'internal'"),
    ({"gears.stage_planet2.place.angle": math.radians(60)}, "gears.stage_planet2",
     "overlap"),
    ({"gears.stage_ring.support.stiffness_y": 2e8}, "gears.stage_ring.support.stiffness_y",
     "one radial stiffness"),
    ({"gears.stage_ring.torsional_support": None}, "drives", "not determined"),
    ({"loads.output.body": "stage_ring"}, "torsional_support", "is driven or loaded"),
    ({"gears.stage_planet1.support.pin_error": {"radial": 1e-5}, "gears.stage_planet1.support.on":
      None}, "gears.stage_planet1.support.pin_error", "requires|add on"),
    ({"gears.stage_planet1.support.on": None}, "could not turn",
     "'stage_planet1' turns about a fixed axis between a ring and another gear (a star "
     "gear): if a planet, seat its bearing on the carrier (support.on)"),
])
def test_bad_planetary_input_names_the_field(change, where, text):
    data = _general(**change)
    data = {k: v for k, v in data.items()}
    if "gears.stage_ring.torsional_support" in change:
        data["gears"]["stage_ring"].pop("torsional_support")
    with pytest.raises(ModelError) as exc:
        model = load(data)
        torquesplit.assemble(model)
    msg = str(exc.value)
    assert where in msg and any(t in msg for t in text.split("|")), msg
    assert len(msg.splitlines()) <= 2


@pytest.mark.parametrize("stage, where, text", [
    ({"planets": 7}, "planetary.0.planets", "assembly condition"),
    ({"planets": 6}, "planetary.0.planets", "planets overlap"),
    ({"pin_radius": "110 mm"}, "planetary.0.pin_radius", "outside the circle the planets"),
    ({"pin_radius": "50 mm"}, "planetary.0.pin_radius", "are 51.25 mm inside the circle"),
    ({"pin_radius": "101.2502 mm"}, "planetary.0.pin_radius", "are 0.2 um outside the"),
    ({"angles": ["0 deg", "90 deg"]}, "planetary.0.angles", "one angle per planet"),
    ({"angles": ["0 deg", "90 deg", "90 deg", "270 deg"]}, "planetary.0.angles",
     r"planets 2 and 3 are at the same angle \(90 deg"),
    ({"angles": ["0 deg", "90 deg", "180 deg", "360 deg"]}, "planetary.0.angles",
     r"planets 1 and 4 are at the same angle \(0 deg"),
    ({"angles": ["0 deg", "180 deg", "200 deg", "270 deg"]}, "planetary.0.angles",
     "planets overlap: planets 2 and 3, 20 deg apart"),
])
def test_bad_shorthand_names_the_field(stage, where, text):
    raw = lp_raw(4)
    raw["planetary"][0].update(stage)
    with pytest.raises(ModelError, match=f"{where}: .*{text}"):
        load(raw)


def test_ring_of_the_wrong_kind_in_the_shorthand():
    raw = lp_raw(4)
    raw["planetary"][0]["ring"]["kind"] = "spur"
    with pytest.raises(ModelError, match="planetary.0.ring.kind: the ring of a planetary stage "
                       "is an internal gear"):
        load(raw)
    raw = copy.deepcopy(lp_raw(4))
    raw["gears"] = {"stage_sun": {"teeth": 20, "module": "2 mm", "face_width": "10 mm"}}
    with pytest.raises(ModelError, match="planetary.0.name: the stage would create "
                       "gears.stage_sun"):
        load(raw)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_static_solve_and_modes_do_not_depend_on_the_order_of_lines(seed):
    """The sections of the file in another order, and every mesh's gears the other way
    round: the same static mesh forces and natural frequencies (issue 16)."""
    import random

    model = lp_model(4)
    data = general_elements(model)
    rnd = random.Random(seed)
    for section in ("gears", "bodies", "meshes"):
        items = list(data[section].items())
        rnd.shuffle(items)
        data[section] = dict(items)
    for mesh in data["meshes"].values():
        mesh["gears"] = mesh["gears"][::-1]
    shuffled = load(data)
    a, b = torquesplit.assemble(model), torquesplit.assemble(shuffled)
    fa = dict(zip(a.element_names, static_equilibrium(a).element_forces))
    fb = dict(zip(b.element_names, static_equilibrium(b).element_forces))
    for name in model.meshes:
        assert fb[name] == pytest.approx(fa[name], rel=1e-9)
    np.testing.assert_allclose(modal_analysis(b).frequencies, modal_analysis(a).frequencies,
                               rtol=1e-9)


def test_two_stage_train_from_the_same_elements():
    """Two stages in series (the first carrier drives the second sun through a shaft):
    the ratio is (1 + z_r / z_s)^2, each carrier has its own turning frame, and the
    output torque is the input's times the ratio."""
    raw = lp_raw(3)
    first = raw["planetary"][0]
    first["name"] = "s1"
    second = copy.deepcopy(first)
    second.update(name="s2", position=["0 mm", "0 mm", "-80 mm"], planets=4)
    raw["planetary"] = [first, second]
    raw["shafts"] = {"link": {"connects": ["s1_carrier", "s2_sun"],
                              "torsional_stiffness": "1e6 N m/rad"}}
    raw["drives"]["input"]["body"] = "s1_sun"
    raw["loads"]["output"]["body"] = "s2_carrier"
    model = load(raw)
    kin = solve_kinematics(model)
    ratio = (1 + ZR / ZS) ** 2
    assert kin.bodies["s1_sun"].speed / kin.bodies["s2_carrier"].speed == pytest.approx(ratio)
    assert kin.load_torques["output"] == pytest.approx(100.0 * ratio, rel=1e-9)
    assert kin.frames["s2_planet1"] == "s2_carrier" and kin.frames["s1_sun"] == "s1_carrier"
    s = torquesplit.assemble(model)
    assert s.n_gyroscopic == 2 * (6 + 7)  # x-y pairs of every translating body
    sol = modal_analysis(s, static_equilibrium(s).q)
    assert sol.rigid_modes.shape[1] == 1 and np.all(sol.frequencies > 0)


def test_ring_floating_on_a_spline_in_the_turning_frame():
    """The ring held by a spline to a held housing (radial clearance and friction): its
    speed is zero, the spline's friction load is the ring's reaction, the static state
    has no rigid drift (the turning frame's inertial terms do not hold the rigid rotation
    in the static solve), and kernel and numpy twin agree there."""
    from torquesplit.solve import rhs, rhs_numpy

    raw = lp_raw(3)
    ring = raw["planetary"][0]["ring"]
    ring.pop("torsional_support")
    ring.pop("support")
    raw["bodies"] = {"housing": {"polar_inertia": 1.0, "torsional_support": {"rigid": True}}}
    raw["splines"] = {"ring_spline": {
        "connects": ["housing", "stage_ring"], "radial_clearance": "20 um",
        "stiffness": "1e8 N/m", "pitch_radius": "160 mm",
        "torsional_stiffness": "2e7 N m/rad", "friction_coefficient": 0.1}}
    model = load(raw)
    kin = solve_kinematics(model)
    assert kin.bodies["stage_ring"].speed == 0.0
    assert kin.bodies["stage_ring"].torque == pytest.approx(100.0 * ZR / ZS, rel=1e-9)
    s = torquesplit.assemble(model)
    st = static_equilibrium(s)
    assert st.converged and st.rigid_modes.shape[1] == 1
    assert np.max(np.abs(st.q)) < 1e-2
    np.testing.assert_allclose(rhs(s, 1e-6, st.y0), rhs_numpy(s, 1e-6, st.y0),
                               rtol=1e-7, atol=1e-6)


def test_the_compound_planet_recipe_of_the_theory_doc():
    """docs/theory/planetary.md's compound-planet snippet, its shaft repeated at 120 and
    240 deg as the text says, is :func:`planetary_models.compound_raw` (the same mesh
    forces), loads as it is (one planet) and gives equal sharing with three."""
    import re
    import tomllib
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "theory" /
            "planetary.md").read_text(encoding="utf-8")
    section = text[text.index("## Compound (stepped) planets"):]
    raw = tomllib.loads(re.search(r"```toml\n(.*?)```", section, re.S).group(1))
    load(raw)  # one planet shaft alone is a model too
    for i in (1, 2):
        psi = 2 * math.pi * i / 3
        at = [f"{60 * math.cos(psi):.12f} mm", f"{60 * math.sin(psi):.12f} mm"]
        for g in ("pa", "pb"):
            spec = copy.deepcopy(raw["gears"][f"{g}0"])
            spec["position"][:2] = at
            raw["gears"][f"{g}{i}"] = spec
        raw["shafts"][f"ps{i}"] = {"connects": [f"pa{i}", f"pb{i}"], "rigid": True}
        for m, pair in (("sp", ["sun", f"pa{i}"]), ("rp", [f"pb{i}", "ring"])):
            raw["meshes"][f"{m}{i}"] = dict(raw["meshes"][f"{m}0"], gears=pair)

    def forces(data):
        s = torquesplit.assemble(load(data))
        return _mesh_forces(s, static_equilibrium(s))

    got, ref = forces(raw), forces(compound_raw())
    assert got.keys() == ref.keys()
    for name in ref:
        assert got[name] == pytest.approx(ref[name], rel=1e-9), name
    assert got["sp0"] == pytest.approx(got["sp2"], rel=1e-9)  # equal sharing
    assert got["rp1"] == pytest.approx(2 * got["sp1"], rel=1e-6)  # (40/20 base radii)


@pytest.mark.parametrize("change, words", [
    ("elastic", "'pb0' is joined to the planet 'pa0' by the elastic shaft 'ps0', so it turns "
                "about a fixed axis: make the shaft rigid (rigid = true) for a compound planet"),
    ("no shaft", "'pb1' is joined to nothing but this mesh: if it is a compound planet's "
                 "gear, join it to its planet gear with a rigid shaft"),
    ("one elastic", "'pb0' is joined to the planet 'pa0' by the elastic shaft 'ps0', so it "
                    "turns about a fixed axis: make the shaft rigid"),
])
def test_a_compound_planet_written_wrong_is_told_how(change, words):
    """(A first-hour reviewer got "check which members are held and driven" and "the
    speeds ... contradict each other around a loop".)"""
    raw = compound_raw()
    if change in ("elastic", "one elastic"):
        for i in range(3 if change == "elastic" else 1):
            raw["shafts"][f"ps{i}"] = {"connects": [f"pa{i}", f"pb{i}"],
                                       "torsional_stiffness": "1e5 N m/rad"}
    else:
        del raw["shafts"]["ps1"]
    with pytest.raises(ModelError) as info:
        load(raw)
    assert any(words in msg for _, msg in info.value.issues), info.value.issues


def test_a_planets_static_orbit_is_taken_from_its_pin():
    """A planet's floating orbit is its centre relative to its pin's nominal place: the
    bearing's deflection F / k plus the pin error (10 um tangential: y of planet 1 at
    0 deg).  It was the planet's displacement in the carrier's frame, which carries the
    pin along with the carrier's twist (12.7 um where 26 were expected; 161 um once a
    second stage joined: a first-hour reviewer), and it no longer moves with what else
    the model holds: an output shaft and inertia on the carrier leave it alone."""
    from torquesplit.quasistatic import quasi_static_load_sharing

    def orbit(extra):
        raw = lp_raw(4, pin_errors=[{"tangential": "10 um"}, {}, {}, {}])
        if extra:
            raw["bodies"] = {"out": {"polar_inertia": "1 kg m^2",
                                     "position": ["0 mm", "0 mm", "-200 mm"]}}
            raw["shafts"] = {"q": {"connects": ["stage_carrier", "out"],
                                   "torsional_stiffness": "1e4 N m/rad"}}
            raw["loads"]["output"]["body"] = "out"
        qs = quasi_static_load_sharing(load(raw), revolutions=0.02)
        f = dict(zip(qs.structure.element_names, qs.solution.element_forces[0]))
        return qs.orbits()["stage_planet1"][0], f

    (x, y), f = orbit(False)
    assert y == pytest.approx(f["stage_planet1.support.y"] / LP["k_bearing"] + 10e-6,
                              rel=1e-9)
    assert x == pytest.approx(f["stage_planet1.support.x"] / LP["k_bearing"], rel=1e-9)
    # (the planet's displacement in the carrier's frame went from 7.7 to 3870 um; then
    # the bearing force moved by 0.2 % with the carrier's static twist, which the
    # softening of an absolute planet translation turned into a tangential load)
    (x2, y2), _ = orbit(True)
    assert (x2, y2) == pytest.approx((x, y), rel=1e-9)


@pytest.mark.parametrize("bearing, where, words", [
    # the second gear's own bearing on the planet: m Omega^2 = 0.2 kg (100 rpm)^2
    ({"shaft_bearing": "10 N/m"}, "gears.pb0.support",
     "the bearing of 'pb0' on the planet 'pa0' (10 N/m) is softer than its centrifugal "
     "softening m Omega^2 = 21.9 N/m"),
    # the pin's bearing holds both gears of a rigid planet shaft: 0.7 kg (100 rpm)^2
    ({"pin": "10 N/m"}, "gears.pa0.support",
     "the planet's bearing (10 N/m along its pin's tangent) is softer than its centrifugal "
     "softening m Omega^2 = 76.8 N/m at the carrier's speed: it would fly off its pin"),
])
def test_a_bearing_softer_than_its_centrifugal_softening_is_refused(bearing, where, words):
    raw = compound_raw(shaft_bearing=bearing.get("shaft_bearing"))
    for i in range(3):
        raw["gears"][f"pa{i}"]["support"]["stiffness"] = bearing.get("pin", "2e8 N/m")
    with pytest.raises(ModelError) as info:
        torquesplit.assemble(load(raw))
    assert any(loc == where and words in msg for loc, msg in info.value.issues), \
        info.value.issues


def test_a_torque_driven_turning_train_keeps_its_speed():
    """Torques balanced by the gear ratios do not load the rigid rotation of a train with
    a turning carrier: at the static equilibrium the rigid mode's acceleration is zero to
    round-off, and a run keeps the carrier's angle.  (The split-path differential example,
    carrier at 1600 rpm, drifted by 0.004 rad in 0.27 s and 0.1 rad in 1.3 s: its planet
    bearing forces in the carrier's frame turned with the drift, 11 % in one component
    between 200 and 400 cycles, a reviewer's finding.)"""
    from torquesplit.solve.integrate import integrate
    from torquesplit.solve.reference import rhs_numpy

    s = torquesplit.assemble(torquesplit.load_model(
        torquesplit.example_path("split_path_planetary_differential")))
    st = static_equilibrium(s)
    phi = rigid_body_modes(s)[:, 0]
    n = s.n_dof
    a = rhs_numpy(s, 0.0, st.y0)[n:]
    load = np.abs(phi * s.external_force).sum()
    assert abs(phi @ (a / s.inv_mass)) < 1e-10 * load
    j = s.dof_names.index("stage_carrier.theta")
    sol = integrate(s, st.y0, (0.0, 0.25), method="rk4", steps_per_period=40,
                    history_dofs=[j])
    th = sol.history_q[:, 0]
    k = th.size // 3  # the mean angle of the last third against the first (it vibrates)
    assert abs(th[-k:].mean() - th[:k].mean()) < 1e-6


def test_a_held_carrier_keeps_the_exact_terms_of_its_pins():
    """A carrier held by a shaft to a member at a set speed (Cooley & Parker 2012's
    example, k_cu) has no rigid rotation to keep free: its planets' softening stays on
    their translations and the pin preload P R on its rotation, the exact linearisation
    of a planet preloaded by its centrifugal force in its pin (measured from the pin,
    the softening moved a mode by 1.3 % at a carrier speed of 6000 rpm where this moves
    it by 1e-2 % of the published equations' value, a reviewer).  A train that turns
    freely with its carrier has the softening measured from the pin instead."""
    from planetary_models import CP, cp_raw

    model = load(cp_raw(4, sun_speed="20000 rpm"))
    s = torquesplit.assemble(model)
    assert s.metadata["free_carriers"] == []
    om = solve_kinematics(model).bodies["st_carrier"].speed
    R, m, k = CP["module"] * (36 + 24) / 2, CP["m_p"], CP["k_p"]
    P = m * om**2 * R * k / (k - m * om**2)
    Kf = s.frame_stiffness_matrix()
    ic = s.dof_names.index("st_carrier.theta")
    rot = [i for i, nm in enumerate(s.dof_names) if nm.endswith(".theta")]
    assert Kf[ic, ic] == pytest.approx(4 * P * R, rel=1e-12)
    Kf[ic, ic] = 0.0
    assert not Kf[rot, :].any() and not Kf[:, rot].any()  # (translations only)
    planet_x = s.dof_names.index("st_planet1.x")
    assert Kf[planet_x, planet_x] == pytest.approx(-m * om**2, rel=1e-12)
    free = torquesplit.assemble(load(lp_raw(4)))
    assert free.metadata["free_carriers"] == ["stage_carrier"]
    ic = free.dof_names.index("stage_carrier.theta")
    assert np.count_nonzero(free.frame_stiffness_matrix()[ic]) > 4  # (planets coupled)
