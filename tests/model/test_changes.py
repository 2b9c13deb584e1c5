"""Changing a model from Python: with_changes / load_model(changes=...), and a model
changed in place refused (a reviewer's edit of a loaded model's dict ran with the old
kinematics, silently)."""

from __future__ import annotations

import warnings

import pytest

import torquesplit


@pytest.fixture(scope="module")
def model():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.load_model("ji_li_mill_drive")


def test_with_changes_gives_a_new_checked_model(model):
    new = model.with_changes({"meshes.m11.damping_ratio": 0.2,
                              "shafts.drive1.diameter": "300 mm"})
    assert new.meshes["m11"].damping_ratio == 0.2 and new.shafts["drive1"].diameter == 0.3
    assert model.meshes["m11"].damping_ratio != 0.2  # the model itself is unchanged
    k_old = torquesplit.assemble(model)
    k_new = torquesplit.assemble(new)
    e = k_new.element_names.index("drive1")
    assert k_new.stiffness_table[e, 0] > k_old.stiffness_table[e, 0]
    with pytest.raises(torquesplit.ModelError, match="meshes.m11.damping_ratio"):
        model.with_changes({"meshes.m11.damping_ratio": -3})


def test_load_model_takes_changes_for_a_file_an_example_or_a_dict(model):
    by_name = torquesplit.load_model("ji_li_mill_drive",
                                     changes={"shafts.drive1.diameter": "250 mm"})
    assert by_name.shafts["drive1"].diameter == pytest.approx(0.25)
    assert torquesplit.load_model(model, changes={"drives.motor.speed": "700 rpm"}) \
        .drives["motor"].speed == pytest.approx(700 * 3.141592653589793 / 30)
    with pytest.raises(torquesplit.ModelError, match="gears.nope"):
        torquesplit.load_model("ji_li_mill_drive", changes={"gears.nope.teeth": 3})


@pytest.mark.parametrize("edit", ["replace", "delete"])
def test_a_model_changed_in_place_is_refused(edit):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("ji_li_mill_drive")
    torquesplit.solve_kinematics(m)  # (kept for the model)
    if edit == "replace":
        d = m.drives["motor"]
        m.drives["motor"] = d.model_copy(update={"speed": 2 * d.speed})
    else:
        del m.meshes["m22"]
    assert m.changed_in_place()
    with pytest.raises(torquesplit.ModelError, match="changed in place.*with_changes"):
        torquesplit.simulate(m, duration=0.01)


def test_a_model_changed_after_a_run_is_refused_by_the_next_run_and_copies_are_not():
    """simulate kept its set-up per model: a change in place after one run ran the kept
    structure (a reviewer); and a pickled or copied model is not 'changed'."""
    import copy
    import pickle

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("ji_li_mill_drive")
    torquesplit.simulate(m, duration=0.01)
    for twin in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m)):
        assert not twin.changed_in_place()
        torquesplit.solve_kinematics(twin)
    d = m.drives["motor"]
    m.drives["motor"] = d.model_copy(update={"speed": 2 * d.speed})
    with pytest.raises(torquesplit.ModelError, match="changed in place"):
        torquesplit.simulate(m, duration=0.01)


def test_with_changes_reaches_a_planetary_stages_own_fields():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("lin_parker1999_planetary")
    assert len(m.with_changes({"planetary.0.planets": 3}).meshes) == 6



def _list_fields(cls, seen=None):
    """(class, field) of every list-like field of the schema under ``cls``."""
    import typing

    import pydantic

    seen = set() if seen is None else seen
    if cls in seen:
        return []
    seen.add(cls)
    out = []
    for name, field in cls.model_fields.items():
        stack = [field.annotation]
        while stack:
            tp = stack.pop()
            if typing.get_origin(tp) in (list, set, dict) or tp in (list, set, dict):
                out.append((cls.__name__, name, str(tp)))
            stack.extend(typing.get_args(tp))
            if isinstance(tp, type) and issubclass(tp, pydantic.BaseModel):
                out.extend(_list_fields(tp, seen))
    return out


def test_nothing_inside_a_models_entry_can_change_in_place():
    """A list inside an entry changed in place was not seen (a reviewer): the entries'
    lists are tuples, so only the sections (dicts, checked above) remain mutable."""
    from torquesplit.model.schema import Model

    mutable = [f for f in _list_fields(Model) if f[0] != "Model" or f[1] not in (
        "gears", "bodies", "shafts", "meshes", "splines", "drives", "loads")]
    assert mutable == []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("lin_parker1999_planetary")
    name, gear = next((n, g) for n, g in m.gears.items() if len(g.dofs) > 1)
    with pytest.raises((TypeError, AttributeError)):
        gear.dofs.append("x")
    assert isinstance(m.model.accepted_warnings, tuple)
    # and a file's lists are still read, written back and changed by path
    again = torquesplit.load_model(torquesplit.model.io.model_to_dict(m))
    assert again.gears[name].dofs == gear.dofs
    # a generated gear is changed through its stage, and the message says so
    with pytest.raises(torquesplit.ModelError, match="generated by the .*planetary.* stage: "
                       "change 'planetary.0.sun.dofs'"):
        m.with_changes({"gears.stage_sun.dofs": ["theta"]})
    assert m.with_changes({"planetary.0.sun.dofs": ["theta"]}).gears[
        "stage_sun"].dofs == ("theta",)


def test_a_table_set_on_a_table_changes_only_the_fields_it_names():
    """A reviewer: with_changes({"gears.O1.errors": {"eccentricity": ...}}) replaced the
    whole table, silently dropping the installation error the file gives."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("dong2021_face_gear")
    before = m.gears["O1"].errors
    assert before.installation > 0
    new = m.with_changes({"gears.O1.errors": {"eccentricity": "5 um"}}).gears["O1"].errors
    assert new.eccentricity == pytest.approx(5e-6)
    assert new.installation == before.installation  # kept
    assert m.gears["O1"].errors.eccentricity == before.eccentricity  # the model unchanged


def test_a_table_that_chooses_another_method_or_is_empty_replaces_the_old_one():
    """A reviewer: after merging came in, a stiffness switched from 'ltca' to 'constant'
    kept the ltca table (refused), and errors = {} no longer cleared the errors."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("ji_li_mill_drive")
        dong = torquesplit.load_model("dong2021_face_gear")
    ltca = m.with_changes({"meshes.m11.stiffness": {"method": "ltca", "ltca": {"positions": 32}}})
    assert ltca.meshes["m11"].stiffness.ltca.positions == 32
    plain = ltca.with_changes({"meshes.m11.stiffness": {"method": "constant",
                                                        "value": "4e9 N/m"}})
    spec = plain.meshes["m11"].stiffness
    assert spec.method == "constant" and spec.value == 4e9 and spec.ltca.positions != 32
    assert dong.with_changes({"gears.O1.errors": {}}).gears["O1"].errors.installation == 0
