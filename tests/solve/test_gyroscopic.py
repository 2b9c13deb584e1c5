"""The gyroscopic (Coriolis) term of a body's translations in a rotating frame:
generalized force -G v with G skew-symmetric (``build_structure(gyroscopic=...)``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from torquesplit.assembly.structure import build_structure
from torquesplit.solve import integrate, modal_analysis, rhs, rhs_numpy

M = 3.0  # kg
K = 4.0e6  # N/m, isotropic support
OMEGA = 2 * math.pi * 25.0  # rad/s, frame speed


def _rotating_body(softening: bool = True):
    """A body in a frame turning at OMEGA: m x'' - 2 m OMEGA y' + (k - m OMEGA^2) x = 0 and
    m y'' + 2 m OMEGA x' + (k - m OMEGA^2) y = 0 (Coriolis and centripetal terms)."""
    k = K - (M * OMEGA**2 if softening else 0.0)
    g = 2 * M * OMEGA
    return build_structure(["b.x", "b.y"], [1 / M, 1 / M],
                           [dict(name="bx", dofs=[0], coefs=[1.0], stiffness=k),
                            dict(name="by", dofs=[1], coefs=[1.0], stiffness=k)],
                           gyroscopic=[(0, 1, -g), (1, 0, g)])


def test_degenerate_pair_splits_by_twice_the_frame_speed():
    """(omega +- OMEGA)^2 = k / m with the centripetal softening: the two whirl
    frequencies are omega0 -+ OMEGA (analytic; without softening they are
    sqrt(omega0^2 + OMEGA^2) -+ OMEGA)."""
    w0 = math.sqrt(K / M)
    f = modal_analysis(_rotating_body()).frequencies
    np.testing.assert_allclose(f, [(w0 - OMEGA) / (2 * math.pi), (w0 + OMEGA) / (2 * math.pi)],
                               rtol=1e-10)
    f = modal_analysis(_rotating_body(softening=False)).frequencies
    root = math.sqrt(w0**2 + OMEGA**2)
    np.testing.assert_allclose(f, [(root - OMEGA) / (2 * math.pi),
                                   (root + OMEGA) / (2 * math.pi)], rtol=1e-10)


def test_undamped_free_vibration_conserves_energy():
    """The gyroscopic force does no work: E = (m v^2 + k_eff q^2) / 2 stays constant over
    10^5 RK4 steps (drift below 1e-9 of E)."""
    s = _rotating_body()
    k_eff = K - M * OMEGA**2
    h = 5e-6  # omega h <= 0.0066: RK4 loses (omega h)^6 / 72 ~ 1e-15 of E per step
    sol = integrate(s, [1e-4, 0.0, 0.0, 0.02], (0.0, 1e5 * h), step=h, record_every=1000)
    assert sol.success and sol.n_steps == 100_000
    q, v = sol.history_q, sol.history_v
    energy = 0.5 * M * (v**2).sum(axis=1) + 0.5 * k_eff * (q**2).sum(axis=1)
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-9
    # the motion is a real whirl: energy moves between x and y through the coupling
    assert np.ptp(q[:, 1]) > 1e-5


def test_kernel_and_twin_agree_with_the_gyroscopic_term():
    s = _rotating_body()
    y = np.array([1e-5, -2e-5, 0.3, 0.1])
    np.testing.assert_allclose(rhs(s, 0.0, y), rhs_numpy(s, 0.0, y), rtol=1e-14)
    # the coupling term by hand: a_x = (-k_eff x + 2 m OMEGA v_y) / m
    k_eff = K - M * OMEGA**2
    assert rhs(s, 0.0, y)[2] == pytest.approx((-k_eff * y[0] + 2 * M * OMEGA * y[3]) / M,
                                              rel=1e-13)


def test_bad_gyroscopic_entry_is_refused():
    with pytest.raises(ValueError, match="out of range"):
        build_structure(["a.x"], [1.0], [dict(name="k", dofs=[0], coefs=[1.0],
                                              stiffness=1.0)], gyroscopic=[(0, 3, 1.0)])


def test_frame_stiffness_term_in_every_consumer():
    """K_f (the centripetal softening as a frame stiffness, not an element): kernel and
    twin agree, the modes are those of K + K_f, and the static solve carries -K_f q."""
    from torquesplit.solve import static_equilibrium

    k = K
    s = build_structure(["b.x", "b.y"], [1 / M, 1 / M],
                        [dict(name="bx", dofs=[0], coefs=[1.0], stiffness=k),
                         dict(name="by", dofs=[1], coefs=[1.0], stiffness=k)],
                        external_force=[10.0, -4.0],
                        frame_stiffness=[(0, 0, -M * OMEGA**2), (1, 1, -M * OMEGA**2)])
    y = np.array([1e-5, -2e-5, 0.3, 0.1])
    np.testing.assert_allclose(rhs(s, 0.0, y), rhs_numpy(s, 0.0, y), rtol=1e-14)
    w = math.sqrt((k - M * OMEGA**2) / M)
    np.testing.assert_allclose(modal_analysis(s).frequencies, [w / (2 * math.pi)] * 2,
                               rtol=1e-12)
    st = static_equilibrium(s)
    np.testing.assert_allclose(st.q, [10.0 / (k - M * OMEGA**2), -4.0 / (k - M * OMEGA**2)],
                               rtol=1e-12)
