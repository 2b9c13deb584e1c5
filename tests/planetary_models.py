"""Planetary test models: the Lin & Parker 1999 example and its variants, as data."""

from __future__ import annotations

import copy
import math
import warnings

import torquesplit
from torquesplit.model.io import model_from_dict, model_to_dict
from torquesplit.model.reader import read_model_file

#: Lin & Parker 1999 Table 1 (the example system), SI
LP = dict(m_s=0.4, m_r=2.35, m_c=5.43, m_p=0.66, i_s=0.39, i_r=3.00, i_c=6.29, i_p=0.61,
          k_mesh=5e8, k_bearing=1e8, k_ru=1e9, alpha=math.radians(24.6))


def lp_raw(planets: int = 4, **stage) -> dict:
    """The raw data of the shipped Lin & Parker example, ``planets`` planets, with
    ``stage`` overriding fields of its [[planetary]] table."""
    data = read_model_file(torquesplit.example_path("lin_parker1999_planetary"))
    data = copy.deepcopy(data)
    data["planetary"][0]["planets"] = planets
    data["planetary"][0].update(stage)
    return data


def load(data: dict, check: bool = True):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = model_from_dict(data)
        return torquesplit.load_model(model, check=check)


def lp_model(planets: int = 4, **stage):
    return load(lp_raw(planets, **stage))


def general_elements(model) -> dict:
    """The model written with the general sections only (no [[planetary]] table)."""
    return model_to_dict(model)
