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
