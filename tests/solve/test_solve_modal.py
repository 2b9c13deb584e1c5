"""Modal analysis and RK4 stability against closed-form results."""

from __future__ import annotations

import math

import numpy as np
import pytest
from solve_models import J1, J2, R1, R2, pair_frequency, spur_pair

from torquesplit.assembly.structure import SPRING, build_structure
from torquesplit.solve import (
    check_step,
    highest_natural_frequency,
    modal_analysis,
    stable_step,
    static_equilibrium,
)
from torquesplit.solve.stability import rk4_amplification


def _chain(m1=2.0, m2=0.5, k1=4e6, k2=1e6):
    """ground -k1- m1 -k2- m2"""
    els = [dict(name="k1", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=k1, damping=20.0),
           dict(name="k2", kind=SPRING, dofs=[0, 1], coefs=[1.0, -1.0], stiffness=k2)]
    return build_structure(["m1.x", "m2.x"], [1 / m1, 1 / m2], els)


def test_two_dof_chain_frequencies_and_modes():
    m1, m2, k1, k2 = 2.0, 0.5, 4e6, 1e6
    modes = modal_analysis(_chain(m1, m2, k1, k2))
    a = (k1 + k2) / m1 + k2 / m2
    b = k1 * k2 / (m1 * m2)
    lam = np.array([(a - math.sqrt(a * a - 4 * b)) / 2, (a + math.sqrt(a * a - 4 * b)) / 2])
    np.testing.assert_allclose(modes.frequencies, np.sqrt(lam) / (2 * math.pi), rtol=1e-12)
    assert modes.rigid_modes.shape == (2, 0)
    M = np.diag([m1, m2])
    phi = modes.mode_shapes
    np.testing.assert_allclose(phi.T @ M @ phi, np.eye(2), atol=1e-12)
    # mode shape ratio x2 / x1 = k2 / (k2 - m2 w^2)
    for i in range(2):
        assert phi[1, i] / phi[0, i] == pytest.approx(k2 / (k2 - m2 * lam[i]), rel=1e-9)
    np.testing.assert_allclose(modes.strain_energy_fraction.sum(axis=1), 1.0, rtol=1e-12)
    # strain energy 0.5 k (V phi)^2 sums to 0.5 w^2 for a mass-normalised mode
    e1 = k1 * phi[0, 0] ** 2 / lam[0]
    assert modes.strain_energy_fraction[0, 0] == pytest.approx(e1, rel=1e-9)
    # damping ratio estimate from the grounded dashpot: c phi1^2 / (2 w)
    assert modes.damping_ratios[0] == pytest.approx(20.0 * phi[0, 0] ** 2
                                                    / (2 * math.sqrt(lam[0])), rel=1e-9)


def test_spur_pair_has_one_rigid_mode_and_the_mesh_mode():
    modes = modal_analysis(spur_pair())
    assert modes.frequencies == pytest.approx([pair_frequency()], rel=1e-12)
    assert modes.rigid_modes.shape == (2, 1)
    rigid = modes.rigid_modes[:, 0]
    assert R1 * rigid[0] - R2 * rigid[1] == pytest.approx(0.0, abs=1e-12)
    assert modes.dominant_elements(0, 1) == [("mesh", 1.0)]


def test_separated_element_is_left_out_at_the_linearisation_state():
    stop = dict(name="stop", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=1e9, gaps=1.0)
    s = spur_pair(extra=[stop])
    closed = modal_analysis(s)  # every element in contact
    st = static_equilibrium(s)
    open_ = modal_analysis(s, st.q)
    assert not open_.active[1] and closed.active[1]
    assert open_.rigid_modes.shape[1] == 1 and closed.rigid_modes.shape[1] == 0
    assert open_.frequencies == pytest.approx([pair_frequency()], rel=1e-12)


def test_rk4_stability_limit_of_an_oscillator():
    s = _chain(k2=0.0)  # m1 on k1 (with a dashpot), m2 free
    lam = np.linalg.eigvals(np.array([[0, 1], [-4e6 / 2.0, -20.0 / 2.0]]))
    h = stable_step(s)
    assert np.max(np.abs(rk4_amplification(h * lam))) == pytest.approx(1.0, abs=1e-9)
    assert np.max(np.abs(rk4_amplification(1.001 * h * lam))) > 1.0
    assert check_step(s, 0.5 * h) == pytest.approx(0.8 * h)
    assert highest_natural_frequency(s) == pytest.approx(math.sqrt(2e6) / (2 * math.pi),
                                                         rel=1e-4)


def test_step_check_uses_maximum_stiffness_and_closed_gaps():
    table = 2e8 * (1 + 0.5 * np.sign(np.sin(2 * np.pi * np.arange(64) / 64)))
    s = spur_pair(stiffness=table, gaps=1e-5, frequency=1000.0)
    w_max = math.sqrt(3e8 * (R1**2 / J1 + R2**2 / J2))
    assert stable_step(s) == pytest.approx(2 * math.sqrt(2) / w_max, rel=1e-9)


def test_damping_ratios_of_a_whirling_mass_match_the_damped_eigenvalues():
    """A mass on an isotropic support seen from a frame turning at 0.3 omega_0 (Coriolis
    and centripetal terms), damped: the damping ratio of each whirl is the state-space
    -Re(lambda) / |lambda| (the estimate without the gyroscopic term was off by ~Omega /
    omega)."""
    m, k, c, spin = 2.0, 8e6, 40.0, 0.3 * math.sqrt(8e6 / 2.0)
    els = [dict(name="kx", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=k),
           dict(name="ky", kind=SPRING, dofs=[1], coefs=[1.0], stiffness=k)]
    s = build_structure(["b.x", "b.y"], [1 / m, 1 / m], els, ground_damping=[c, c],
                        gyroscopic=[(0, 1, -2 * m * spin), (1, 0, 2 * m * spin)],
                        frame_stiffness=[(0, 0, -m * spin**2), (1, 1, -m * spin**2)])
    modes = modal_analysis(s)
    A = np.zeros((4, 4))
    A[:2, 2:] = np.eye(2)
    A[2:, :2] = -(s.stiffness_matrix()) / m
    A[2:, 2:] = -(s.gyroscopic_matrix() + c * np.eye(2)) / m
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0][np.argsort(lam[lam.imag > 0].imag)]
    np.testing.assert_allclose(modes.frequencies, lam.imag / (2 * math.pi), rtol=1e-4)
    np.testing.assert_allclose(modes.damping_ratios, -lam.real / np.abs(lam), rtol=1e-4)


@pytest.mark.parametrize("dx,closed,expected", [(0.0, True, 30.0),    # closed, at rest
                                                (0.0, False, 0.0),    # floating at rest
                                                (60e-6, False, 30.0)])  # radial contact
def test_a_splines_modal_damping_leaves_its_friction_out(dx, closed, expected):
    """The module leaves spline friction out of the modes, but the damping took its
    regularised slope F_m / v (a 1e3 N friction over 1 mm/s: 1e6 N s/m, a damping ratio
    of 42 on a reviewer's quill mode): only the law's damping c remains."""
    from torquesplit.solve.modal import _spline_damping

    # k, c, stick_limit, clearance, friction_force, velocity
    par = [1e8, 30.0, 0.0, 50e-6, 1e3, 1e-3]
    c2 = _spline_damping(par, dx, 0.0, closed=closed)
    assert c2[0, 0] == pytest.approx(expected) and abs(c2[0, 1]) < 1e-12
    assert np.all(c2 <= 30.0 + 1e-9)  # never the friction's 1e6 N s/m


def test_an_undamped_mode_has_a_damping_ratio_of_zero_not_rounding():
    """'modes split_path_planetary_differential' printed zeta -3.16e-19 for two modes."""
    import numpy as np

    import torquesplit

    # (the example's pinion supports had no damping; they have now, taken off here)
    model = torquesplit.load_model("split_path_planetary_differential", changes={
        f"gears.pinion_{p}.support.damping_ratio": 0.0 for p in "ab"})
    rep = torquesplit.model_modes(model)
    zeta = np.array([r.damping_ratio for r in rep.rows])
    assert np.all(zeta >= 0.0) and np.any(zeta == 0.0)
    assert not np.any((zeta > 0) & (zeta < 1e-12))
    # and such modes are said, with the element that carries them (a steady state near
    # their resonances is at best marginal: a reviewer's sweep crawled into one)
    from torquesplit.solve.static import static_equilibrium
    from torquesplit.steady.solution import undamped_note

    s = torquesplit.assemble(model)
    note = undamped_note(s, static_equilibrium(s).q)
    assert note.startswith("2 mode(s) without damping: mode 7 (") and \
        "strain energy in pinion_b.support.x" in note, note
    damped = torquesplit.load_model("split_path_planetary_differential")
    s = torquesplit.assemble(damped)
    assert undamped_note(s, static_equilibrium(s).q) == ""


def test_a_repeated_pair_of_a_turning_carrier_shares_its_strain_energy_evenly():
    """Planet modes (multiplicity N - 3) stay repeated with the carrier turning, and the
    gyroscopic solver returned their two complex shapes mass-normalised but not
    orthogonal: the group's strain energy, summed over them, gave 30 / 28 / 17 % to
    three of five identical, equally spaced planets' bearings.  Each takes a fifth."""
    import torquesplit
    from torquesplit.modes import model_modes

    model = torquesplit.load_model("lin_parker1999_planetary", changes="planetary.0.planets=5")
    rows = [r for r in model_modes(model).rows if r.type == "planet"]
    assert len(rows) == 6 and all(r.multiplicity == 2 for r in rows)
    for r in rows:
        shares = [r.strain_energy.get(f"stage_planet{k}.support.x", 0.0)
                  + r.strain_energy.get(f"stage_planet{k}.support.y", 0.0) for k in range(1, 6)]
        assert max(shares) - min(shares) <= 1e-6 * max(shares), (r.frequency, shares)
