"""Default load-sharing groups and the stage labels that probably do not say what the
file meant (a first-hour reviewer: the tutorial's three-branch drive without its `stage`
lines put the split and the combining meshes, both 20/40, in one group and reported a
system coefficient of 1.354 where the drive shares to 1.015, without a word)."""

from __future__ import annotations

import tomllib

import pytest
from model_texts import tutorial_model

import torquesplit
from torquesplit.assembly.excitation import stage_labels
from torquesplit.errors import ModelWarning
from torquesplit.metrics.load_sharing import group_meshes
from torquesplit.model.kinematics import solve_kinematics



def _three_branch() -> dict:
    """The tutorial's model: input 20 t -> b1..b3 40 t (split), p1..p3 20 t -> output 40 t
    (combine): both stages are 20/40."""
    text = tutorial_model()
    return tomllib.loads(text)


def _load(data: dict):
    with pytest.warns(ModelWarning) as caught:
        model = torquesplit.load_model(data)
    return model, [str(w.message) for w in caught]


def test_unlabelled_meshes_of_one_ratio_split_by_their_nominal_force():
    data = _three_branch()
    labelled = {n: m["stage"] for n, m in data["meshes"].items()}
    assert set(labelled.values()) == {"split", "combine"}
    for mesh in data["meshes"].values():
        del mesh["stage"]
    model, said = _load(data)
    kin = solve_kinematics(model)
    stages = stage_labels(model, kin)
    groups = group_meshes({n: {"stage": s, "path": None} for n, s in stages.items()})
    # the same meshes together as with the file's labels, named by pair and force level
    assert sorted(map(sorted, groups.values())) == sorted(
        sorted(n for n in labelled if labelled[n] == lab) for lab in ("split", "combine"))
    assert set(groups) == {"20/40-1", "20/40-2"}
    assert {stages[n] for n in labelled if labelled[n] == "split"} == {"20/40-1"}
    # the assembled structure and the summary use the same groups
    meta = torquesplit.assemble(model).metadata["meshes"]
    assert {n: m["stage"] for n, m in meta.items()} == stages
    assert [w for w in said if "no stage label and the same tooth counts (20/40) but "
            "different nominal forces" in w and "20/40-1: in1, in2, in3" in w]


def test_unlabelled_meshes_of_equal_force_keep_the_pair_as_their_group():
    data = _three_branch()
    for name, mesh in data["meshes"].items():
        if mesh["stage"] == "split":
            del mesh["stage"]
    model = torquesplit.load_model(data)
    stages = stage_labels(model, solve_kinematics(model))
    assert {stages[n] for n in ("in1", "in2", "in3")} == {"20/40"}
    assert {stages[n] for n in ("out1", "out2", "out3")} == {"combine"}


def test_a_one_mesh_stage_that_reads_like_its_neighbours_is_named():
    data = _three_branch()
    data["meshes"]["in2"]["stage"] = "splt"
    _, said = _load(data)
    assert [w for w in said if w.startswith("meshes.in2.stage: 'splt' is the stage of this "
                                            "mesh alone") and "write 'split'" in w]


def test_a_single_mesh_final_stage_is_not_a_typo():
    """'stage1' (a split of two meshes) beside 'stage2' (one mesh of another ratio) is a
    gearbox, not a slip: no warning."""
    data = _three_branch()
    for name, mesh in data["meshes"].items():
        mesh["stage"] = "stage1" if mesh["stage"] == "split" else f"stage2{name}"
    data["meshes"]["out1"]["stage"] = "stage2"
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(data)
    assert not [w for w in caught if "is the stage of this mesh alone" in str(w.message)]
