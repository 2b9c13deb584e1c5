"""A dimensionless field takes a percentage: a reviewer's damping_ratio = "10 %" was
refused ("must be a number"), though pint and every engineer read it as 0.1."""

from __future__ import annotations

import pytest

import torquesplit
from torquesplit.errors import ModelError


@pytest.mark.parametrize("text, value", [("10 %", 0.1), ("2.5%", 0.025), ("5 percent", 0.05),
                                         ("0.07", 0.07)])
def test_a_percentage_is_read_as_its_fraction(text, value):
    model = torquesplit.load_model("ji_li_mill_drive")
    changed = model.with_changes({"meshes.m11.damping_ratio": text})
    assert changed.meshes["m11"].damping_ratio == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("text", ["10 %%", "% 10", "ten %", "10 ppm"])
def test_what_is_no_percentage_is_still_refused_with_the_hint(text):
    model = torquesplit.load_model("ji_li_mill_drive")
    with pytest.raises(ModelError, match=r"meshes.m11.damping_ratio: must be a number.*'5 %'"):
        model.with_changes({"meshes.m11.damping_ratio": text})
