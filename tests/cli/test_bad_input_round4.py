"""Smaller findings of a bad-input reviewer: a tooth count of inf was told to 'write a
plain number such as 0.05'; contact --load 'nan kN' was 'neither a force nor a torque';
run_study(workers='two') ended in a raw TypeError."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.study import StudyError


@pytest.mark.parametrize("path", ["gears.z1.teeth", "gears.z2.teeth"])
def test_a_count_that_is_not_finite_is_told_to_be_a_whole_number(path):
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive", "--set", f"{path}=inf"])
    assert res.exit_code == 2
    assert (f"{path}: must be a finite whole number, got inf; write an integer such as 20"
            in " ".join(res.output.split())), res.output
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive", "--set",
                                   "meshes.m11.damping_ratio=inf"])
    assert "write a plain number such as 0.05" in " ".join(res.output.split())


def test_a_load_that_is_not_finite_is_said_so():
    res = CliRunner().invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11", "--load",
                                   "nan kN"])
    assert res.exit_code == 2
    assert "--load 'nan kN' is not a finite number" in res.output, res.output


def test_workers_that_are_not_a_number_are_refused_by_name():
    study = {"study": {"name": "w", "model": "ji_li_mill_drive",
                       "outputs": ["load_sharing.mean_force"]},
             "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                      "values": [0.05]}]}}
    with pytest.raises(StudyError, match="workers: got 'two'"):
        torquesplit.run_study(study, workers="two")


def test_an_index_past_a_list_says_how_long_the_list_is():
    """'planetary.3' does not exist (known here: none) on a model with planetary.0."""
    study = {"study": {"name": "p", "model": "lin_parker1999_planetary",
                       "outputs": ["load_sharing.mean_force"]},
             "grid": {"parameters": [{"path": "planetary.3.sun_mesh.damping_ratio",
                                      "values": [0.05]}]}}
    with pytest.raises(StudyError) as info:
        torquesplit.Study(study).plan()
    assert "'planetary.3' does not exist in the model: its list has 1 item(s), indices 0..0" \
        in str(info.value), str(info.value)


def test_an_item_of_a_list_the_file_does_not_write_asks_for_the_whole_list():
    """--set planetary.0.angles.1=45 deg on a stage without angles said 'must be a list,
    got {'1': '45 deg'}'."""
    res = CliRunner().invoke(app, ["check", "lin_parker1999_planetary", "--set",
                                   "planetary.0.angles.1=45 deg"])
    assert res.exit_code == 2
    assert ("'planetary.0.angles' is not in the file, so it has no item 1; set the whole "
            "list: planetary.0.angles=[a, b, ...]") in " ".join(res.output.split()), res.output
