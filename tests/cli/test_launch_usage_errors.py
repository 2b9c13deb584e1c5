"""Options the parser refuses get the commands' one-line ``error:`` form and, with
``--json``, the JSON document on stdout (a first-hour reviewer: ``--steps-per-period
abc`` gave a boxed panel and an empty stdout under ``--json``, unlike every other bad
option)."""

from __future__ import annotations

import json

import pytest

from torquesplit import _launch, cli_support


def _launch_with(monkeypatch, capsys, *args):
    monkeypatch.setattr("sys.argv", ["torquesplit", *args])
    monkeypatch.setattr(cli_support._session, "json", False)
    monkeypatch.setattr(cli_support._session, "json_printed", False)
    with pytest.raises(SystemExit) as exit_:
        _launch.main()
    out, err = capsys.readouterr()
    return exit_.value.code, out, err


def test_a_value_of_the_wrong_type_is_one_error_line(monkeypatch, capsys):
    code, out, err = _launch_with(monkeypatch, capsys, "run", "ji_li_mill_drive",
                                  "--steps-per-period", "abc")
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --steps-per-period: ")
    assert "'torquesplit run --help' lists the options" in lines[0]
    assert "Traceback" not in err and "╭" not in err


@pytest.mark.parametrize("args, said", [
    (("run", "ji_li_mill_drive", "--json", "--cycles", "abc"), "--cycles: "),
    (("check", "ji_li_mill_drive", "--json", "--bogus"), "No such option: --bogus"),
])
def test_with_json_the_errors_are_a_json_document_on_stdout(monkeypatch, capsys, args, said):
    code, out, err = _launch_with(monkeypatch, capsys, *args)
    assert code == 2
    doc = json.loads(out)
    assert doc["success"] is False and doc["errors"][0].startswith(said)
    assert err.startswith(f"error: {said}")


def test_a_missing_argument_names_it(monkeypatch, capsys):
    code, out, err = _launch_with(monkeypatch, capsys, "check")
    assert code == 2 and err.startswith("error: Missing argument 'MODEL'")


def test_a_good_command_exits_with_its_own_status(monkeypatch, capsys):
    code, out, _ = _launch_with(monkeypatch, capsys, "check", "ji_li_mill_drive", "--json")
    assert code == 0 and json.loads(out)["model"]
    code, _, err = _launch_with(monkeypatch, capsys, "run", "ji_li_mill_drive",
                                "--steps-per-period", "0")
    assert code == 2 and "--steps-per-period must be a whole number" in err


@pytest.mark.parametrize("typed, meant", [("--steps", "--steps-per-period"),
                                          ("--step", "--steps-per-period"),
                                          ("--cycle", "--cycles")])
def test_an_abbreviated_option_is_named_in_full(monkeypatch, capsys, typed, meant):
    """'--steps' was answered with --check-step, --max-steps, --set, not the option meant
    (a first-hour reviewer)."""
    code, _, err = _launch_with(monkeypatch, capsys, "run", "ji_li_mill_drive", typed, "50")
    assert code == 2 and err.startswith(f"error: No such option: {typed} (did you mean "
                                        f"{meant}?"), err
