"""The compiled LTCA kernels agree with their readable numpy twins (same inputs)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from torquesplit.gears.contact import (
    ContactModel,
    FlankModification,
    LtcaOptions,
    Misalignment,
    Relief,
    ToothModification,
)
from torquesplit.gears.contact._kernels import contact_deflection, contact_deflection_twin
from torquesplit.gears.geometry import GearGeometry, PairGeometry

A20 = math.radians(20)


def test_contact_deflection_kernel_matches_twin():
    rng = np.random.default_rng(1)
    c = (1 - 0.3 ** 2) / 206e9
    for _ in range(50):
        q, R, d1, d2 = rng.uniform(1e3, 1e6), rng.uniform(2e-3, 5e-2), rng.uniform(1e-3, 5e-3), rng.uniform(1e-3, 5e-3)
        assert contact_deflection(q, R, d1, d2, c, c, 0.3, 0.3) == pytest.approx(
            float(contact_deflection_twin(q, R, d1, d2, c, c, 0.3, 0.3)), rel=1e-13)
    assert contact_deflection(0.0, 1e-2, 2e-3, 2e-3, c, c, 0.3, 0.3) == 0.0


@pytest.mark.parametrize("double, model, coupling", [
    (False, "weber", True), (False, "linear", False), (True, "weber", True)])
def test_ltca_kernel_matches_twin(double, model, coupling):
    beta = math.radians(18)
    pair = PairGeometry(GearGeometry(21, 2.5e-3, A20, beta, 18e-3, double_helical=double),
                        GearGeometry(43, 2.5e-3, A20, -beta, 18e-3, double_helical=double))
    mod = ToothModification(FlankModification(tip_relief=Relief(12e-6, length=2e-3, shape="parabolic"),
                                              crowning=5e-6))
    cm = ContactModel(pair, (mod, None), Misalignment(lead_mismatch=6e-6),
                      LtcaOptions(positions=12, slices=8, contact_model=model, coupling=coupling))
    fast, slow = cm.solve(6000.0), cm.solve(6000.0, twin=True)
    assert fast.converged
    np.testing.assert_allclose(fast.transmission_error, slow.transmission_error, rtol=1e-9)
    np.testing.assert_allclose(fast.stiffness_tangent, slow.stiffness_tangent, rtol=1e-8)
    np.testing.assert_allclose(fast.slice_load, slow.slice_load, rtol=0, atol=1e-7 * 6000.0)
