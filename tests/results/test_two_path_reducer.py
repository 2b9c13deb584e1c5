"""A reviewer's two-path split-torque spur reducer: a tensile tooth force on the working
flank is said (the mesh damping pulls as the teeth separate: -540 N on mesh a1 with
back_contact 0 and no word), its rigidly held pinions have bearing rows, and the two
stages of its locked train give the same mean-force coefficient."""

from __future__ import annotations

import warnings

import pytest

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


def test_a_body_held_rigidly_has_its_bearing_row(tmp_path):
    """The reviewer's pinions p1, p2 (rotation only, on torsion-only shafts) carried the
    largest radial loads and had no bearing row: a body with no translational DOF is held
    rigidly, its bearing carries the sum of its meshes' forces along their lines of
    action (here one mesh each, so minus its settled mean force along its line of action
    for a driver: the mesh table's, not the mean of the history's samples)."""
    import numpy as np

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(write_model(tmp_path, TWO_PATH_SPUR_REDUCER))
        res = torquesplit.simulate(model)
    start = res.metrics().settling.start_time
    rows = {b["body"]: b for b in res.bearing_forces(start)}
    assert {"p1", "p2"} <= set(rows) and rows["p1"]["held"] == "rigid"
    assert "held" not in rows["bull"]  # (a support of its own: its support's force)
    means = {r.mesh: r.mean_force for r in res.metrics().rows}
    for body, mesh in (("p1", "b1"), ("p2", "b2")):
        n = np.asarray(res.kinematics.meshes[mesh].line_of_action)
        assert res.kinematics.meshes[mesh].driver == body
        mean = -means[mesh] * n  # the force on the driver
        row = rows[body]
        assert row["directions"] == ["x", "y"]  # (spur: no axial thrust)
        np.testing.assert_allclose(row["mean"], mean[:2], rtol=1e-12)
    from torquesplit.results import bearing_bodies
    assert bearing_bodies(res.structure, model) == [b["body"] for b in res.bearing_forces()]


def test_the_stages_of_a_locked_train_share_alike_by_mean_force(tmp_path):
    """Both stages of a locked train carry the same mean path torques, so their
    mean-force coefficients (K_gamma) agree when averaged over the same span; over each
    group's own settled span they read 1.2014 and 1.2119 (the slow eccentricity drifting
    between the two starts)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate(torquesplit.load_model(
            write_model(tmp_path, TWO_PATH_SPUR_REDUCER)))
    met = res.metrics("mean_force")
    first, second = met.load_sharing.per_group["first"], met.load_sharing.per_group["second"]
    assert abs(first - second) < 1e-3, (first, second)
    assert met.settling.group_time["first"] != met.settling.group_time["second"]  # (premise)


def test_a_model_of_rotations_only_has_rigid_bearing_rows_and_mean_f_matches_k_gamma(tmp_path):
    """A code review: a model whose bodies only turn got no bearing rows at all (an early
    return), though a study accepted their names; the table's mean F was over each group's
    own span while K_gamma took the common one; a body on a rigid shaft with a supported
    one (Dong et al. 2021's O1b beside O1) is not a bearing of its own."""
    import numpy as np

    from model_texts import SPUR_PAIR
    from torquesplit.results import bearing_bodies, rigid_bearings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pair = torquesplit.load_model(write_model(tmp_path, SPUR_PAIR, "pair.toml"))
        res = torquesplit.simulate(pair, cycles=40)
        reducer = torquesplit.simulate(torquesplit.load_model(
            write_model(tmp_path, TWO_PATH_SPUR_REDUCER)))
    rows = res.bearing_forces()
    assert [r["body"] for r in rows] == bearing_bodies(res.structure, pair) == ["pinion",
                                                                                "wheel"]
    assert all(r["held"] == "rigid" for r in rows)
    met = reducer.metrics("mean_force")
    for g, members in met.load_sharing.groups.items():
        mean = np.array([next(r.mean_force for r in met.rows if r.mesh == m) for m in members])
        assert met.load_sharing.per_group[g] == pytest.approx(
            float(np.max(len(mean) * mean / mean.sum())), rel=1e-12)
    dong = torquesplit.load_model("dong2021_face_gear")
    assert "O1b" not in rigid_bearings(dong, torquesplit.solve_kinematics(dong))
