"""Tooth friction with a "balanced" torque load and no speed dependence: said before the
run (the train decelerates: a reviewer found its gears 33 % below nominal speed after
0.3 s, without a word)."""

import tomllib
import warnings

import pytest

import torquesplit
from model_texts import PAIR_4MM

PAIR = PAIR_4MM.replace('damping_ratio = 0.05\n', 'damping_ratio = 0.05\n'
                        'friction = { model = "constant", coefficient = 0.1 }\n')


def _said(text):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(tomllib.loads(text))
    return [str(w.message) for w in caught]


def test_friction_with_a_balanced_load_and_no_speed_dependence_is_said():
    said = [w for w in _said(PAIR) if w.startswith("loads.out.torque:")]
    assert len(said) == 1 and "decelerates" in said[0] and "speed_coefficient" in said[0]


@pytest.mark.parametrize("fix", [
    PAIR.replace("[loads.out]\nbody = \"wheel\"",
                 "[loads.out]\nbody = \"wheel\"\nspeed_coefficient = \"0.5 N m s/rad\""),
    PAIR.replace("friction = { model = \"constant\", coefficient = 0.1 }\n", ""),
])
def test_not_said_where_the_speed_holds_or_nothing_dissipates(fix):
    assert fix != PAIR
    assert not [w for w in _said(fix) if "decelerates" in w]
