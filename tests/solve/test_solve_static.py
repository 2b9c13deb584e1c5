"""Static equilibrium: transmission error, dead zones, rigid-body modes, unbalanced loads."""

from __future__ import annotations

import math

import numpy as np
import pytest
from solve_models import J1, J2, K_MESH, R1, R2, T_IN, spur_pair

from torquesplit.assembly.structure import MESH, SPRING, build_structure
from torquesplit.errors import SolverError
from torquesplit.solve import quasi_static, static_equilibrium
from torquesplit.solve.reference import element_forces_numpy


def test_static_transmission_error_is_load_over_stiffness():
    s = spur_pair()
    st = static_equilibrium(s)
    force = T_IN / R1
    assert st.converged and st.iterations <= 2
    assert st.element_forces[0] == pytest.approx(force, rel=1e-9)
    assert st.deformations[0] == pytest.approx(force / K_MESH, rel=1e-9)
    # one rigid-body mode (the train turning), removed by zero mass-weighted motion
    assert st.rigid_modes.shape == (2, 1)
    phi = st.rigid_modes[:, 0]
    assert phi[0] / phi[1] == pytest.approx(R2 / R1, rel=1e-12)
    assert abs(phi @ (np.array([J1, J2]) * st.q)) < 1e-12 * np.max(np.abs(st.q))
    assert (np.array([J1, J2]) * phi) @ phi == pytest.approx(1.0, rel=1e-12)


def test_static_with_backlash_adds_the_gap():
    s = spur_pair(gaps=20e-6)
    st = static_equilibrium(s)
    assert st.deformations[0] == pytest.approx(20e-6 + T_IN / R1 / K_MESH, rel=1e-9)
    assert st.element_forces[0] == pytest.approx(T_IN / R1, rel=1e-9)
    assert st.in_contact[0]


def _clearance_model(stop_gap=1e-3, bearing_gap=5e-6):
    """Gear 1 floats on a bearing with radial clearance; gear 2 has a bearing and a far stop.

    DOFs th1, th2, x1, x2; the mesh line of action runs along x.
    """
    k_b1, k_b2, k_stop = 3e8, 4e8, 1e9
    els = [
        dict(name="mesh", kind=MESH, dofs=[0, 1, 2, 3], coefs=[R1, -R2, 1.0, -1.0],
             stiffness=K_MESH),
        dict(name="bearing1", kind=SPRING, dofs=[2], coefs=[1.0], stiffness=k_b1,
             gaps=bearing_gap),
        dict(name="bearing2", kind=SPRING, dofs=[3], coefs=[1.0], stiffness=k_b2),
        dict(name="stop2", kind=SPRING, dofs=[3], coefs=[1.0], stiffness=k_stop,
             gaps=stop_gap),
    ]
    s = build_structure(["g1.theta", "g2.theta", "g1.x", "g2.x"],
                        [1 / J1, 1 / J2, 1 / 2.0, 1 / 3.0], els,
                        external_force=[T_IN, -T_IN * R2 / R1, 0.0, 0.0])
    return s, (k_b1, k_b2)


def test_static_with_clearance_and_separated_stop():
    s, (k_b1, k_b2) = _clearance_model()
    st = static_equilibrium(s)
    f = T_IN / R1
    assert st.converged
    assert st.element_forces[0] == pytest.approx(f, rel=1e-9)
    # bearing 1 takes the mesh force across its clearance: x1 = -(g + f / k)
    assert st.element_forces[1] == pytest.approx(-f, rel=1e-9)
    assert st.q[2] == pytest.approx(-(5e-6 + f / k_b1), rel=1e-9)
    assert st.q[3] == pytest.approx(f / k_b2, rel=1e-9)
    assert st.element_forces[3] == 0.0
    assert st.separated == ("stop2",)
    assert list(st.in_contact) == [True, True, True, False]
    assert st.rigid_modes.shape[1] == 1
    # the state is a true equilibrium of the dynamic equations
    force, _ = element_forces_numpy(s, 0.0, st.y0)
    resid = s.external_force - s.projection_matrix().T @ force
    assert np.max(np.abs(resid)) < 1e-9 * f
    # with a stop inside the travel it engages and shares the load
    st2 = static_equilibrium(_clearance_model(stop_gap=1e-6)[0])
    assert st2.in_contact[3] and st2.separated == ()
    assert st2.element_forces[2] + st2.element_forces[3] == pytest.approx(f, rel=1e-9)


def test_unbalanced_torques_raise_with_amount():
    s = spur_pair(load=-150.0)  # balance needs -200 N m
    with pytest.raises(SolverError) as err:
        static_equilibrium(s)
    msg = str(err.value)
    assert "do not balance" in msg
    # net load referred to the input: 100 - 150 * r1 / r2 = 25 N m
    assert "25 N m referred to 'g1.theta'" in msg
    assert isinstance(err.value, RuntimeError)


def test_dof_without_stiffness_is_a_rigid_body_mode():
    els = [dict(name="spring", kind=SPRING, dofs=[0, 1], coefs=[1.0, -1.0], stiffness=1e6),
           dict(name="ground", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=1e6),
           dict(name="dead", kind=SPRING, dofs=[2], coefs=[1.0], stiffness=0.0)]
    s = build_structure(["a.x", "b.x", "c.x"], [1.0, 1.0, 1.0], els)
    # c.x has no stiffness at all: it is a rigid-body mode, and must carry no load
    st = static_equilibrium(s)
    assert st.rigid_modes.shape[1] == 1
    assert abs(st.rigid_modes[2, 0]) == pytest.approx(1.0)


def test_quasi_static_follows_mesh_stiffness():
    table = K_MESH * (1 + 0.25 * np.cos(2 * np.pi * np.arange(64) / 64))
    s = spur_pair(stiffness=table, frequency=500.0, errors=[(1e-6, 2 * math.pi * 50, 0.0)])
    times = np.linspace(0, 0.004, 41)
    qs = quasi_static(s, times)
    assert qs.converged.all()
    np.testing.assert_allclose(qs.element_forces[:, 0], T_IN / R1, rtol=1e-9)
    for i, t in enumerate(times):
        st = static_equilibrium(s, t)
        np.testing.assert_allclose(qs.q[i], st.q, rtol=1e-9, atol=1e-15)
    k_t = np.interp((500.0 * times) % 1.0, np.arange(65) / 64, np.append(table, table[0]))
    e_t = 1e-6 * np.sin(2 * math.pi * 50 * times)
    np.testing.assert_allclose(qs.deformations[:, 0], T_IN / R1 / k_t, rtol=1e-9)
    # the error moves the gears, not the force
    delta_q = R1 * qs.q[:, 0] - R2 * qs.q[:, 1]
    np.testing.assert_allclose(delta_q - e_t, qs.deformations[:, 0], rtol=1e-9, atol=1e-18)


def test_member_held_only_by_an_open_clearance_is_regularised_and_reported():
    els = [dict(name="mesh", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=1e7),
           dict(name="loose", kind=SPRING, dofs=[1], coefs=[1.0], stiffness=1e8, gaps=1e-4,
                error_constant=2e-5)]
    s = build_structure(["a.x", "float.x"], [1.0, 1.0], els, external_force=[50.0, 0.0])
    st = static_equilibrium(s)
    assert st.converged
    assert st.separated == ("loose",)
    assert st.element_forces[1] == 0.0
    # the tiny regularising spring centres the free member in its clearance
    assert st.deformations[1] == pytest.approx(0.0, abs=1e-15)
    assert st.q[0] == pytest.approx(50.0 / 1e7, rel=1e-12)


def _spline_mass(load, stick=2e-6, clearance=1e-5, k=1e8):
    """A 2-D mass held only by a spline to ground, loaded by ``load`` (N, 2-vector)."""
    from torquesplit.assembly.structure import SPLINE

    els = [dict(name="sp", kind=SPLINE, x=([0], [-1.0]), y=([1], [-1.0]), stiffness=k,
                damping=10.0, stick_limit=stick, clearance=clearance, friction_force=50.0)]
    return build_structure(["m.x", "m.y"], [1.0, 1.0], els, external_force=load)


@pytest.mark.parametrize("magnitude", [0.0, 50.0, 150.0, 3000.0])
def test_static_spline_is_a_radial_dead_zone(magnitude):
    k, s1, s2 = 1e8, 2e-6, 1e-5
    direction = np.array([0.6, -0.8])
    st = static_equilibrium(_spline_mass(magnitude * direction, s1, s2, k))
    assert st.converged
    rad = np.linalg.norm(st.q)
    if magnitude == 0.0:
        assert rad < 1e-15  # centred (stick zone around R = 0)
        return
    np.testing.assert_allclose(st.q / rad, direction, atol=1e-12)  # moves along the load
    if magnitude < k * s1:  # sticks: F = k R
        assert rad == pytest.approx(magnitude / k, rel=1e-12)
    else:  # slides across the clearance (friction is zero at rest): F = k (R - S2)
        assert rad == pytest.approx(s2 + magnitude / k, rel=1e-12)
    assert st.in_contact.all() and st.separated == ()
    np.testing.assert_allclose(st.element_forces, -magnitude * direction, rtol=1e-12)


def test_static_floating_member_in_its_spline_clearance_is_reported():
    # no stick limit: without load the member floats (regularised, centred)
    st = static_equilibrium(_spline_mass([0.0, 0.0], stick=0.0))
    assert st.converged and st.separated == ("sp.x", "sp.y")
    np.testing.assert_array_equal(st.element_forces, 0.0)
    assert np.linalg.norm(st.q) < 1e-15


def test_static_friction_changes_the_load_only_through_its_mean_moments():
    ph = np.arange(64) / 64
    m1 = -4e-4 + 6e-4 * np.sign(np.sin(2 * np.pi * (ph - 0.3)))  # reverses at the pitch point
    m2 = -9e-4 - 1.2e-3 * np.sign(np.sin(2 * np.pi * (ph - 0.3)))
    mesh = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[R1, -R2], stiffness=K_MESH,
                frequency=500.0, friction=dict(table=[0 * ph, m1, m2], dofs=[0, 1],
                                               coefs=[-1.0, -1.0], rows=[1, 2]))
    m1_bar, m2_bar = m1.mean(), m2.mean()
    f_lossy = T_IN / (R1 - m1_bar)  # driver: T_in = (r1 - m1) f
    lossy = build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh],
                            external_force=[T_IN, -(R2 + m2_bar) * f_lossy])
    st = static_equilibrium(lossy)
    assert st.converged
    assert st.element_forces[0] == pytest.approx(f_lossy, rel=1e-12)
    assert abs(st.rigid_acceleration[0]) < 1e-12 * T_IN / np.sqrt(J1)
    # lossless balance (as the kinematics gives it): friction decelerates the train;
    # the d'Alembert force of that deceleration shifts the force, by the mean moments only
    lossless = build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh],
                               external_force=[T_IN, -T_IN * R2 / R1])
    st2 = static_equilibrium(lossless)
    phi = st2.rigid_modes[:, 0]
    a = st2.rigid_acceleration[0]
    assert a * np.sign(phi[0]) < 0  # decelerates (phi along the rotation when phi[0] > 0)
    # J1 (a phi1) = T_in - (r1 - m1) f  and  J2 (a phi2) = -T_in r2 / r1 + (r2 + m2) f
    f = st2.element_forces[0]
    assert J1 * a * phi[0] == pytest.approx(T_IN - (R1 - m1_bar) * f, rel=1e-9)
    assert J2 * a * phi[1] == pytest.approx(-T_IN * R2 / R1 + (R2 + m2_bar) * f, rel=1e-9)
    # a load torque wildly out of balance is still refused
    wrong = build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh],
                            external_force=[T_IN, -0.5 * T_IN * R2 / R1])
    with pytest.raises(SolverError, match="do not balance"):
        static_equilibrium(wrong)
    # quasi-statics use the friction moments at each mesh position
    qs = quasi_static(lossy, [0.1 / 500.0, 0.7 / 500.0])
    assert qs.converged.all()
    assert qs.element_forces[0, 0] != pytest.approx(qs.element_forces[1, 0], rel=1e-3)


def test_line_search_lands_on_a_kink_at_the_root():
    """phi' with a kink at its root: bisection over the kinks finds it in a few
    evaluations (regula falsi alone converges linearly there, ~20 evaluations)."""
    from torquesplit.solve.static import _line_search

    root = 0.3
    calls = []

    def dphi(a):
        calls.append(a)
        d = (2.0 if a < root else 10.0) * (a - root)
        return d, abs(d) + 1.0

    kinks = np.array([-0.5, 0.1, root, 0.7, 2.0])  # some outside (0, 1)
    assert _line_search(dphi, dphi(0.0)[0], kinks) == root
    assert len(calls) <= 4
    calls.clear()
    alpha = _line_search(dphi, dphi(0.0)[0])  # without the kinks: the same root, slowly
    assert alpha == pytest.approx(root, abs=1e-9)
    assert len(calls) > 10


def test_line_search_kinks_of_a_spline_are_its_radii():
    """The kinks along a line are where |d + alpha v| reaches the spline's clearance."""
    from torquesplit.solve.static import _StaticProblem

    from torquesplit.assembly.structure import SPLINE

    s = build_structure(["a.x", "a.y"], [1.0, 1.0], [dict(
        name="sp", kind=SPLINE, x=([0], [1.0]), y=([1], [1.0]), stiffness=1e8,
        clearance=1e-4, stick_limit=2e-5)])
    p = _StaticProblem(s, 1e-9, 1e-8)
    delta = np.array([0.0, 0.0])
    vdq = np.array([3e-4, 4e-4])  # |v| = 5e-4: radius 1e-4 at 0.2, 2e-5 at 0.04
    kinks = np.sort(p._kinks(delta, vdq, np.zeros(2)))
    np.testing.assert_allclose(kinks[kinks > 0], [0.04, 0.2], rtol=1e-12)


def test_newton_stuck_on_a_kink_gives_up_before_its_budget(monkeypatch):
    """A line search that returns no step (as on a spline's stick limit without
    regularisation) ends the Newton iteration, unconverged, after _STALL_STEPS solves,
    not after the whole budget (Dong et al. 2021: 4 such positions in a 200-position
    quasi-static sweep took 38 % of its line-search evaluations)."""
    from torquesplit.solve import static

    s, _ = _clearance_model()
    p = static._StaticProblem(s, 1e-9, 1e-8)
    L = p.loads(None)
    monkeypatch.setattr(static, "_line_search", lambda *args: 0.0)
    q, solves, ok = p.newton(np.zeros(s.n_dof), L, L.f_eff, p.reg, 200)
    assert not ok and solves == static._STALL_STEPS
    assert np.array_equal(q, np.zeros(s.n_dof))


@pytest.mark.parametrize("reg", [1e-9, "per element"])
def test_the_line_searchs_compiled_forces_are_the_newton_forces_bit_for_bit(reg):
    """With splines, the line search's forces come from one compiled pass
    (static._line_forces); Newton's (with tangents) from numpy.  Both the same laws and
    regularisation: equal to the last bit, in every region of the spline law (stick,
    float, contact), for a scalar and a per-element regularisation."""
    from torquesplit.assembly.structure import SPLINE
    from torquesplit.solve.static import _StaticProblem

    els = [dict(name="sp", kind=SPLINE, x=([0], [1.0]), y=([1], [1.0]), stiffness=1e8,
                clearance=1e-4, stick_limit=2e-5, friction_force=50.0, velocity_scale=1e-3),
           dict(name="mesh", kind=MESH, dofs=[0, 2], coefs=[1.0, -R1], stiffness=K_MESH,
                gaps=5e-6)]
    s = build_structure(["a.x", "a.y", "b.theta"], [1.0, 1.0, 1 / J1], els)
    p = _StaticProblem(s, 1e-9, 1e-8)
    L = p.loads(None)
    r = np.linspace(1e-9, 1e-8, s.n_elements) if reg == "per element" else reg
    rng = np.random.default_rng(3)
    for scale in (1e-5, 5e-5, 3e-4):  # stick, between, beyond the clearance
        for _ in range(20):
            q = rng.normal(scale=scale, size=s.n_dof)
            assert np.array_equal(p.force(q, L, r), p.forces(q, L, r)[1])


def test_a_warm_start_finds_the_same_equilibrium_in_fewer_steps():
    """Dong et al. 2021's drive (clearances, backlash, splines) at t = 0, Newton started
    from its mean-stiffness equilibrium (as every run sets up its start): the same
    displacements and contact state, in fewer linear solves."""
    import warnings

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = torquesplit.assemble(torquesplit.load_model(
            torquesplit.example_path("dong2021_face_gear")))
    mean = static_equilibrium(s)
    cold = static_equilibrium(s, 0.0)
    warm = static_equilibrium(s, 0.0, initial=mean.q)
    assert cold.converged and warm.converged
    assert np.abs(warm.q - cold.q).max() <= 1e-12 * np.abs(cold.q).max()
    assert np.array_equal(warm.in_contact, cold.in_contact)
    assert warm.iterations < cold.iterations / 2


def test_the_mean_equilibrium_is_kept_for_its_exact_inputs_only():
    """A study case's mean-excitation solve is kept per process (Dong et al. 2021's
    Monte Carlo of eccentricities: a quarter of a case's overhead): an equal problem gets
    the kept solution, equal to a fresh solve; an eccentricity, which averages out of the
    mean excitation, keeps it; any input of the mean problem (a backlash) does not."""
    import dataclasses

    import torquesplit
    from torquesplit.solve import static as st

    model = torquesplit.load_model("dong2021_face_gear")
    first = static_equilibrium(torquesplit.assemble(model))
    again = static_equilibrium(torquesplit.assemble(model))
    assert again is first
    st._MEAN_SOLUTIONS.clear()
    fresh = static_equilibrium(torquesplit.assemble(model))
    assert fresh is not first
    for f in dataclasses.fields(fresh):
        a, b = getattr(fresh, f.name), getattr(first, f.name)
        assert (np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b), f.name
    assert not fresh.q.flags.writeable  # (what is kept cannot be changed by a caller)
    turned = model.with_changes({"gears.O4.errors.eccentricity": "7 um"})
    assert static_equilibrium(torquesplit.assemble(turned)) is fresh
    wider = model.with_changes({"meshes.m46.backlash": "30 um"})
    other = static_equilibrium(torquesplit.assemble(wider))
    assert other is not fresh and not np.array_equal(other.q, fresh.q)
    # the equilibrium at a time is never kept (its errors differ from case to case)
    at0 = static_equilibrium(torquesplit.assemble(model), 0.0, initial=fresh.q)
    assert static_equilibrium(torquesplit.assemble(model), 0.0, initial=fresh.q) is not at0


def test_a_tiny_inertia_makes_no_false_rigid_body_mode():
    """A motor inertia of 1e-12 kg m^2 beside bodies of 1e4-1e5 (a unit slip) made its
    column dominate V M^-1/2: the other constraints fell below the rank tolerance, a
    second rigid-body mode appeared, and the static check blamed the drive and load
    torques (a reliability reviewer).  The modes are those of the inertias' order of
    magnitude, mass-orthonormal and undeforming."""
    from torquesplit.solve.static import rigid_modes_of

    V = np.array([[1.0, -1.0, 0.0], [0.0, 0.1, -0.3]])  # a shaft, then a mesh
    for inertia in (1.0, 1e-12):
        inv_mass = 1.0 / np.array([inertia, 1e4, 1e5])
        phi = rigid_modes_of(V, inv_mass)
        assert phi.shape == (3, 1), inertia
        np.testing.assert_allclose(V @ phi, 0.0, atol=1e-12 * np.abs(phi).max())
        np.testing.assert_allclose(phi.T @ (phi / inv_mass[:, None]), np.eye(1), rtol=1e-12)
