"""A pair's geometry messages name the model's gears ("past b1's", not "past the b1's")."""

from __future__ import annotations

import tomllib
import warnings

import pytest
from model_fixtures import PAIR_TOML

import torquesplit
from torquesplit.errors import ModelWarning


def test_interference_message_names_the_gears_without_an_article():
    data = tomllib.loads(PAIR_TOML.replace("pinion", "s1").replace("wheel", "b1"))
    data["gears"]["s1"]["teeth"] = 4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        with pytest.raises(torquesplit.ModelError) as info:
            torquesplit.load_model(data)
    msg = next(m for loc, m in info.value.issues if loc == "meshes.m" and "interference" in m)
    assert "b1's tip reaches past s1's base-circle tangent point" in msg
    assert "increase s1's profile shift or reduce b1's addendum" in msg
    assert "the s1" not in msg and "the b1" not in msg
