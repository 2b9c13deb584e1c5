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
