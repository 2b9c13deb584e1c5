"""A tensile tooth force on the working flank (no back-flank contact) is said: the mesh
damping pulls while the teeth separate (a reviewer's two-path reducer read a minimum
force of -540 N on mesh a1 with back_contact 0 and no word)."""

from __future__ import annotations

import warnings

import torquesplit
from model_texts import TWO_PATH_SPUR_REDUCER, write_model
from torquesplit.results.plausibility import PULL_FLOOR, damping_pull


def test_a_damping_pull_on_the_working_flank_is_said(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(write_model(tmp_path, TWO_PATH_SPUR_REDUCER))
        res = torquesplit.simulate(model)
    met = res.metrics()
    pulled = {r.mesh: r for r in met.rows
              if r.min_force < -PULL_FLOOR * r.static_force and r.back_contact == 0}
    assert set(pulled) == {"a1"}  # (the premise: the eccentric idler's mesh separates)
    said = dict(damping_pull(res, met))
    assert list(said) == ["meshes.a1"]
    assert f"{pulled['a1'].min_force:.4g} N" in said["meshes.a1"]
    assert "working flank" in said["meshes.a1"] and "damping" in said["meshes.a1"]
    assert any(w.startswith("meshes.a1: the settled tooth force goes down to")
               for w in res.warnings())
