"""Parameter overrides (``--set``, studies): a new model dict, the original untouched."""

from __future__ import annotations

import copy

import pytest

from torquesplit.errors import ModelError
from torquesplit.model.overrides import apply_overrides, set_parameter


def _data():
    return {"gears": {"z1": {"teeth": 19, "errors": {"eccentricity": "5 um"}},
                      "z2": {"teeth": 60}},
            "shafts": {"s1": {"axis": [0.0, 0.0, 1.0]}}}


def test_overrides_leave_the_original_untouched_and_copy_only_their_path():
    data = _data()
    before = copy.deepcopy(data)
    out = apply_overrides(data, {"gears.z1.errors.eccentricity": "8 um",
                                 "shafts.s1.axis.2": -1.0})
    assert data == before
    assert out["gears"]["z1"]["errors"]["eccentricity"] == "8 um"
    assert out["shafts"]["s1"]["axis"] == [0.0, 0.0, -1.0]
    assert out["gears"]["z2"] is data["gears"]["z2"]  # untouched tables are shared
    assert out["gears"]["z1"] is not data["gears"]["z1"]


@pytest.mark.parametrize("path", ["gears.z9.teeth", "gears.z1.teeth.x", "shafts.s1.axis.7"])
def test_a_bad_path_is_named(path):
    with pytest.raises(ModelError) as err:
        set_parameter(_data(), path, 1)
    assert path in str(err.value)


def test_a_list_item_in_brackets_is_told_the_dotted_index():
    """'position[0]' was an 'unknown field' of the gear."""
    with pytest.raises(ModelError, match=r"not brackets; write shafts\.s1\.axis\.2"):
        set_parameter(_data(), "shafts.s1.axis[2]", -1.0)


def test_a_field_set_replaces_the_files_other_way_of_saying_it():
    """``--set drives.motor.torque=...`` on a drive given a power was refused with "remove
    one of them", which the command line cannot do (a first-hour reviewer).  The example
    then loads with the torque set, and its other fields stay."""
    import torquesplit
    from torquesplit.model.overrides import read_raw

    raw = read_raw(torquesplit.example_path("ji_li_mill_drive"))
    assert "power" in raw["drives"]["motor"]
    model = torquesplit.load_model(apply_overrides(raw, {"drives.motor.torque": "32 kN m"}))
    assert model.drives["motor"].torque == pytest.approx(32e3)
    assert model.drives["motor"].power is None
    support = apply_overrides(raw, {"gears.z1.support.damping": "1e3 N s/m"})
    assert support["gears"]["z1"]["support"]["damping"] == "1e3 N s/m"
    assert "damping_ratio" not in support["gears"]["z1"]["support"]
    assert "shaft" in support["gears"]["z1"]["support"]  # (not an alternative of damping)
    assert raw["gears"]["z1"]["support"]["damping_ratio"] == 0.065  # the original untouched


@pytest.mark.parametrize("table, path, value, gone, kept", [
    ({"stiffness": "1 N/m", "damping": 1.0}, "rigid", True, ("stiffness", "damping"), ()),
    ({"stiffness": "1 N/m", "damping": 1.0}, "rigid", False, (), ("stiffness", "damping")),
    ({"rigid": True, "diameter": "1 m"}, "torsional_stiffness", "1 N m/rad",
     ("rigid", "diameter"), ()),
    ({"torsional_stiffness": "1 N m/rad", "shear_modulus": 1.0}, "length", "1 m",
     ("torsional_stiffness",), ("shear_modulus",)),
    ({"shaft": {"length": "1 m"}}, "stiffness", "1 N/m", ("shaft",), ()),
    ({"position": [0, 0, 0]}, "place", {"at": "x"}, ("position",), ()),
])
def test_each_alternative_gives_way_and_nothing_else(table, path, value, gone, kept):
    out = set_parameter({"t": {"a": table}}, f"t.a.{path}", value)["t"]["a"]
    assert out[path] == value
    assert not set(gone) & set(out)
    assert set(kept) <= set(out)


def test_a_table_set_whole_gives_way_too_and_two_ways_at_once_are_refused():
    """A code reviewer: --set shafts.s='{torsional_stiffness=...}' merged into a shaft that
    keeps its diameter and length (refused again: 'remove one of them'); --set power and
    --set torque of one drive kept the torque alone without a word."""
    from torquesplit.model.overrides import apply_assignments

    d = {"shafts": {"s": {"diameter": "1 m", "length": "2 m", "shear_modulus": 1.0}}}
    assert set_parameter(d, "shafts.s", {"torsional_stiffness": 1e6})["shafts"]["s"] == {
        "shear_modulus": 1.0, "torsional_stiffness": 1e6}
    drive = {"drives": {"m": {"power": "1 kW"}}}
    with pytest.raises(ModelError, match=r"--set drives\.m\.torque=10: sets what --set "
                                         r"drives\.m\.power=5e3 sets, another way"):
        apply_assignments(drive, ["drives.m.power=5e3", "drives.m.torque=10"])
    with pytest.raises(ModelError, match=r"drives\.m\.torque: sets what drives\.m\.power "
                                         r"sets, another way"):
        apply_overrides(drive, {"drives.m.power": 5e3, "drives.m.torque": 10})
    # one field of each of two tables is no clash
    assert apply_overrides({"drives": {"a": {}, "b": {}}},
                           {"drives.a.power": 1, "drives.b.torque": 2}) == {
        "drives": {"a": {"power": 1}, "b": {"torque": 2}}}
