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
