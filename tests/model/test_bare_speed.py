"""A drive speed written as a bare number in a model file is read in rad/s, and said so
(a first-hour reviewer: 'speed = 3000' ran the tutorial's drive at 28,648 rpm without a
word, where --set drives.motor.speed=3000 warned)."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest
from model_texts import tutorial_model

import torquesplit
from torquesplit.errors import ModelWarning



def _file(tmp_path, speed: str) -> Path:
    text = tutorial_model()
    text, n = re.subn(r'(?m)^speed = "3000 rpm"', f"speed = {speed}", text)
    assert n == 1
    path = tmp_path / "m.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_bare_drive_speed_in_a_file_is_said_to_be_rad_per_s(tmp_path):
    path = _file(tmp_path, "3000")
    with pytest.warns(ModelWarning, match=r"drives\.motor\.speed: a bare number is a speed "
                                          r"in rad/s \(3000 rad/s = 28647\.9 rpm\); write "
                                          r"'3000 rpm' for rpm"):
        model = torquesplit.load_model(path)
    assert model.drives["motor"].speed == pytest.approx(3000.0)


@pytest.mark.parametrize("speed", ['"3000 rpm"', '"314.159 rad/s"'])
def test_a_speed_with_its_unit_is_not(tmp_path, speed):
    path = _file(tmp_path, speed)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.load_model(path)
    assert not [w for w in caught if "bare number" in str(w.message)]
