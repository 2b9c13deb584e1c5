"""The Python API takes what the command line takes: a shipped example by its name."""

import pytest

import torquesplit
from torquesplit.errors import ModelError


def test_an_example_loads_by_name_as_on_the_command_line(tmp_path, monkeypatch):
    by_name = torquesplit.load_model("ji_li_mill_drive")
    by_path = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    assert by_name == by_path
    # a file of that name in the current folder is the file, not the example
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ji_li_mill_drive").write_text("not a model")
    with pytest.raises(ModelError):
        torquesplit.load_model("ji_li_mill_drive")
    with pytest.raises(ModelError, match="no such file"):
        torquesplit.load_model("no_such_example")


def test_a_run_says_what_it_is():
    res = torquesplit.simulate(torquesplit.load_model("ji_li_mill_drive"), duration=0.02)
    text = repr(res)
    assert text.startswith("<Results of 'ji_li_mill_drive': dynamic run, 0.02 s simulated, "
                           "4 meshes, ok;") and ".metrics()" in text


def test_the_assembled_structure_and_the_kinematics_say_what_they_are_in_one_line():
    """Their generated reprs printed every array (about 6 000 characters each for this
    14-DOF drive) where a notebook user asked what they hold."""
    model = torquesplit.load_model("ji_li_mill_drive")
    s, kin = torquesplit.assemble(model), torquesplit.solve_kinematics(model)
    assert repr(s) == ("<Structure: 14 DOFs, 14 elements (4 meshes, 10 springs), 4 "
                       "time-varying; .dof_names, .element_names, .projection_matrix()>")
    assert repr(kin).startswith(f"<Kinematics: {len(kin.bodies)} bodies, 4 meshes, input ")
    assert len(repr(kin)) < 120
