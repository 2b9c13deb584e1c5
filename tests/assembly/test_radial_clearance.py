"""A bearing's radial clearance is circular: the same gearbox turned about its axis gives
the same forces (a dead zone on x and on y apart, Dong et al. 2021 eq. 7, is a square
clearance, larger along the diagonals: 'per_axis')."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from model_texts import PAIR_4MM

import torquesplit
from torquesplit.solve.static import static_equilibrium

K = 1e8  # bearing stiffness [N/m]
C = 20e-6  # clearance [m]


def _pair(angle_deg: float, shape: str = "radial", ripple: float = 0.0, **support):
    """The 4 mm pair with the wheel placed at ``angle_deg`` about the pinion, the pinion
    on a bearing with a clearance (x, y translations); ``ripple``: the mesh stiffness's
    relative peak-to-peak variation."""
    extra = "".join(f", {k} = {v!r}".replace("'", '"') for k, v in support.items())
    text = PAIR_4MM.replace('stiffness = "4e8 N/m"', 'stiffness = {method = "constant", '
                            f'value = "4e8 N/m", peak_to_peak = {ripple}}}')
    text = text.replace('place = {from_gear = "pinion", angle = "0 deg"}',
                            f'place = {{from_gear = "pinion", angle = "{angle_deg} deg"}}')
    text = text.replace('mass = "2 kg"', f'''mass = "2 kg"
dofs = ["x", "y", "theta"]
support = {{stiffness = "{K:g} N/m", clearance = "{C * 1e6:g} um", clearance_shape = "{shape}"{extra}}}''')
    return torquesplit.load_model(tomllib.loads(text))


def _pinion_offset(model):
    s = torquesplit.assemble(model)
    q = static_equilibrium(s).q
    names = list(s.dof_names)
    return np.array([q[names.index("pinion.x")], q[names.index("pinion.y")]]), s


def test_the_static_offset_is_the_clearance_plus_f_over_k_in_every_orientation():
    radii = []
    for angle in (0.0, 37.0, 90.0, 135.0):
        model = _pair(angle)
        d, _ = _pinion_offset(model)
        force = torquesplit.solve_kinematics(model).meshes["m"].force
        # the mesh force pushes the pinion through its clearance: |d| = c + F / k
        assert np.hypot(*d) == pytest.approx(C + force / K, rel=1e-9)
        radii.append(np.hypot(*d))
    assert np.ptp(radii) < 1e-12


def test_the_square_clearance_of_per_axis_depends_on_the_orientation():
    """What the reviewer saw: the same pair turned by 45 deg moved by another amount (at
    20 deg the tooth force lies along y, at 65 deg along a diagonal of the square)."""
    a, _ = _pinion_offset(_pair(20.0, "per_axis"))
    b, _ = _pinion_offset(_pair(65.0, "per_axis"))
    assert np.hypot(*b) - np.hypot(*a) > 0.3 * C


def test_a_run_is_the_same_in_every_orientation():
    """The dynamic path (the bearing as the kernels' radial law) turned by 45 deg: the
    same mesh-force swing and bearing force (a stiffness ripple drives the vibration)."""
    out = []
    for angle in (20.0, 65.0):
        res = torquesplit.simulate(_pair(angle, ripple=0.4, damping_ratio=0.05), cycles=60)
        s = res.solution
        swing = np.nanmax(s.cycle_max[-20:, 0]) - np.nanmin(s.cycle_min[-20:, 0])
        bearing = next(b for b in res.bearing_forces() if b["body"] == "pinion")
        out.append((swing, bearing["peak_magnitude"]))
    assert out[0][0] > 1e3
    np.testing.assert_allclose(out[0], out[1], rtol=1e-6)


def test_a_radial_clearance_with_two_stiffnesses_is_refused():
    with pytest.raises(torquesplit.ModelError, match="clearance_shape.*one stiffness across"):
        torquesplit.assemble(_pair(0.0, stiffness_y="2e8 N/m"))


def test_the_bearing_elements_keep_their_names_and_an_eccentricity_still_counts():
    model = _pair(0.0)
    s = torquesplit.assemble(model)
    assert {"pinion.support.x", "pinion.support.y"} <= set(s.element_names)
    assert s.n_splines == 1
    assert math.isclose(s.sp_par[0, 3], C)


def test_planets_floating_in_pin_clearances_of_a_turning_carrier():
    """The open clearance's regularising spring (1e-9 k) was below the planet's centripetal
    softening m Omega^2: Newton ran a planet 9 m off its pin and called it converged (a
    reviewer's Lin & Parker 1999 stage with 20 um pin clearances at 1000 rpm).  The pin
    forces are the equilibrium's: as without clearance, but for the planet resting 20 um
    off its pin's centre along the pin force, where the centrifugal force m Omega^2 r,
    radial from the axis, leans by 20 um / R and adds m Omega^2 x 20 um along it."""
    import warnings

    from torquesplit.model.overrides import read_raw, set_parameter

    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    forces = []
    for clearance in ("0 um", "20 um"):
        data = set_parameter(raw, "planetary.0.planet_bearing.clearance", clearance)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = torquesplit.assemble(torquesplit.load_model(data))
        st = static_equilibrium(s)
        f = dict(zip(s.element_names, st.element_forces))
        forces.append(np.hypot(f["stage_planet1.support.x"], f["stage_planet1.support.y"]))
        assert np.max(np.abs(st.q)) < 1e-3
    kin = torquesplit.solve_kinematics(torquesplit.load_model(data))
    m_omega2 = kin.bodies["stage_planet1"].mass * kin.bodies["stage_carrier"].speed ** 2
    assert forces[1] - forces[0] == pytest.approx(m_omega2 * 20e-6, rel=0.02)
    assert forces[0] > 100.0


def test_the_modes_damping_of_a_radial_bearing_is_the_laws():
    """`modes` damped both components of a radial bearing (c I) while the law damps only
    the radial rate (c n n^T): its damping ratios were up to 3x the state-space ones (a
    reviewer's idler).  Here against the eigenvalues of the kernels' own linearisation at
    the static equilibrium."""
    from torquesplit.solve.modal import modal_analysis
    from torquesplit.steady.problem import PeriodicProblem

    s = torquesplit.assemble(_pair(20.0, damping_ratio=0.05))
    q = static_equilibrium(s).q
    modal = modal_analysis(s, q)
    p = PeriodicProblem(s, 1000.0)
    y = np.concatenate([q, np.zeros_like(q)])[None, :]
    lin = p.linearise(np.zeros(1), y)
    aq, av = p.mean_jacobian(lin)
    n = s.n_dof
    A = np.block([[np.zeros((n, n)), np.eye(n)], [aq, av]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 1e-3 * np.abs(lam).max()]
    exact = sorted(zip(np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)))
    f = [x for x in modal.frequencies if x > 0]
    assert len(f) == len(exact)
    for (fe, ze), fm, zm in zip(exact, f, modal.damping_ratios[-len(f):]):
        assert fm == pytest.approx(fe, rel=2e-3)
        assert zm == pytest.approx(ze, rel=0.05, abs=2e-4)


def test_the_turning_frames_regularisation_leaves_the_forces_in_contact_alone():
    """A reviewer's case against a first version of the fix above (one larger factor for
    every dead zone, kept while any member floats): the sun-planet forces of a stage
    with backlash dropped from 581.9 to 419.8 N when an unloaded body floated in a
    bearing clearance elsewhere.  The forces in contact are now those without it."""
    import json
    import warnings

    from torquesplit.model.io import model_to_json

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = json.loads(model_to_json(torquesplit.load_model("lin_parker1999_planetary")))
    for mesh in base["meshes"].values():
        mesh["backlash"] = {"nominal": 2e-4}
    out = []
    for clearance in (0.0, 2e-5):
        raw = json.loads(json.dumps(base))
        raw.setdefault("bodies", {})["idle"] = {
            "polar_inertia": "0.001 kg m^2", "mass": "1 kg", "dofs": ["theta", "x", "y"],
            "position": ["0 mm", "0 mm", "-200 mm"],
            "support": {"stiffness": 1e7, "clearance": clearance}}
        raw.setdefault("shafts", {})["sidle"] = {"connects": ["stage_sun", "idle"],
                                                 "torsional_stiffness": 1e4}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = torquesplit.assemble(torquesplit.load_model(raw))
        st = static_equilibrium(s)
        out.append(st.element_forces[s.element_names.index("stage_sun_planet1")])
    assert out[0] > 500.0 and out[1] == pytest.approx(out[0], rel=1e-9)


def test_an_unloaded_planet_of_a_turning_carrier_keeps_its_moment_balance():
    """With backlash, a pin error that unloads two planets of a Lin & Parker 1999 stage at
    speed: the regularising spring on their open meshes, scaled for a planet floating in
    its pin clearance although the pins have none, carried 14 N on the sun meshes at
    3000 rpm, so F_sun != F_ring on a planet (K_gamma 2.789 for the speed-independent
    2.761, a reviewer's active-set solution)."""
    import warnings

    from torquesplit.model.overrides import read_raw, set_parameter

    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    for path, value in (("planetary.0.sun.dofs", ["theta"]),
                        ("planetary.0.pin_errors", [{"tangential": "-60 um"}, {}, {}, {}]),
                        ("planetary.0.sun_mesh.backlash", "300 um"),
                        ("planetary.0.ring_mesh.backlash", "300 um")):
        raw = set_parameter(raw, path, value)
    shares = []
    for speed in ("10 rpm", "3000 rpm"):
        data = set_parameter(raw, "drives.input.speed", speed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = torquesplit.assemble(torquesplit.load_model(data))
        f = dict(zip(s.element_names, static_equilibrium(s).element_forces))
        sun = np.array([f[f"stage_sun_planet{i}"] for i in range(1, 5)])
        ring = np.array([f[f"stage_ring_planet{i}"] for i in range(1, 5)])
        # (4e-6 left at 3000 rpm: the rigid mode's multiplier carries a load of the
        # frame's inertial stiffness, K_f phi != 0, a separate matter)
        np.testing.assert_allclose(sun, ring, rtol=2e-5, atol=2e-5 * sun.max())
        assert sun[1] == sun[3] == 0.0  # the unloaded planets carry nothing
        shares.append(sun.max() / sun.mean())
    assert shares[1] == pytest.approx(shares[0], rel=1e-3)
