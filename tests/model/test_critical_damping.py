"""The critical damping of a mesh whose stiffness is computed at assembly (an industrial
reviewer's iso6336 meshes)."""

from __future__ import annotations

import math
import tomllib
import warnings

import pytest

import torquesplit as ts
from torquesplit.model.kinematics import solve_kinematics
from tests.model_texts import SPUR_PAIR


def test_a_computed_mesh_stiffness_has_a_critical_damping_from_its_iso_estimate():
    """'check --json' gave 0 N s/m as the critical damping of every iso6336 mesh, and the
    'damping above critical' check was skipped for them (the same review)."""
    text = SPUR_PAIR.replace('stiffness = "4e8 N/m"', 'stiffness = {method = "iso6336"}')
    mk = solve_kinematics(ts.load_model(tomllib.loads(text))).meshes["m"]
    assert mk.iso_stiffness > 0
    assert mk.critical_damping == pytest.approx(2 * math.sqrt(mk.iso_stiffness *
                                                              mk.equivalent_mass), rel=1e-12)
    over = text.replace("damping_ratio = 0.05", f'damping = "{2 * mk.critical_damping} N s/m"')
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        ts.load_model(tomllib.loads(over))
    assert any("times critical for this mesh" in str(w.message) for w in seen)
