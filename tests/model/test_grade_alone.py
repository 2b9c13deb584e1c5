"""A grade with no error values is said to give no error (a first-hour review: errors =
{grade = 6} on every gear ran error-free, load sharing 1.0000, without a word)."""

from __future__ import annotations

import warnings

import torquesplit
from torquesplit.model.checks import tolerance_warnings
from torquesplit.model.kinematics import solve_kinematics

from .model_fixtures import pair_dict


def _grade_notes(data) -> list[tuple[str, str]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model(data)
    return [(loc, msg) for loc, msg in tolerance_warnings(m, solve_kinematics(m))
            if loc.endswith(".errors.grade") and "alone" in msg]


def test_a_grade_alone_is_said_once_naming_every_gear():
    data = pair_dict()
    for g in data["gears"].values():
        g["errors"] = {"grade": 6}
    (loc, msg), = _grade_notes(data)
    assert loc == "gears.pinion.errors.grade" and "pinion, wheel no error" in msg


def test_a_grade_beside_an_error_is_not_said():
    data = pair_dict()
    data["gears"]["pinion"]["errors"] = {"grade": 6, "eccentricity": "5 um"}
    assert _grade_notes(data) == []
