"""Bad study files are refused with one line naming the field, before any case runs."""

from __future__ import annotations

import pytest
import tomli_w
from typer.testing import CliRunner

from study_helpers import grid_study, mc_study
from torquesplit.cli import app
from torquesplit.errors import TorquesplitError
from torquesplit.study import Study, StudyError

K = {"path": "meshes.a1.stiffness", "start": "2e8 N/m", "stop": "6e8 N/m", "num": 3}


def _bad_cases(model):
    two = grid_study(model, [K])
    two["monte_carlo"] = mc_study(model)["monte_carlo"]
    negative = mc_study(model)
    negative["monte_carlo"]["samples"] = -3
    typo = grid_study(model, [K])
    typo["study"]["outputz"] = ["x"]
    lone = grid_study(model, [K])
    del lone["grid"]
    lone["sensitivity"] = {"method": "sobol", "seed": 1, "parameters": [
        {"path": "meshes.a1.stiffness", "low": "2e8 N/m", "high": "6e8 N/m"}]}
    return {
        # (the count, not the raw table: "got [{'path': 'meshes...")
        "one sensitivity factor": (lone, "sensitivity.parameters",
                                   "has 1 item(s); give at least 2"),
        "unknown path": (grid_study(model, [dict(K, path="meshes.zz.stiffness")]),
                         "grid.parameters.0.path", "'meshes.zz' does not exist"),
        "unknown field": (grid_study(model, [dict(K, path="meshes.a1.stifness")]),
                          "grid.parameters.0.path", "did you mean 'stiffness'"),
        "wrong dimension": (grid_study(model, [dict(K, start="2e8 kg")]),
                            "grid.parameters.0.start", "is not a stiffness"),
        "wrong unit option": (grid_study(model, [dict(K, start=2, stop=6, unit="mm")]),
                              "grid.parameters.0.unit", "not a unit of stiffness"),
        "empty range": (grid_study(model, [dict(K, num=0)]), "grid.parameters.0.num",
                        "the range is empty"),
        "start equals stop": (grid_study(model, [dict(K, stop="2e8 N/m")]),
                              "grid.parameters.0.stop", "the range is empty"),
        "one point of two values": (grid_study(model, [dict(K, num=1)]),
                                    "grid.parameters.0.num",
                                    "1 point but start 2e8 N/m != stop 6e8 N/m; give num >= 2 "
                                    "or start = stop"),
        "one point, unit option": (grid_study(model, [dict(K, start=1, stop=2, num=1,
                                                           unit="N/mm")]),
                                   "grid.parameters.0.num", "start 1 N/mm != stop 2 N/mm"),
        "negative samples": (negative, "monte_carlo.samples", "must be at least 1"),
        "two designs": (two, "monte_carlo", "one design"),
        # (a second design missing its fields was told those first)
        "two designs, one incomplete": ({**grid_study(model, [K]), "monte_carlo": {}},
                                        "monte_carlo", "a study has one design, here grid "
                                                       "and monte_carlo"),
        "unknown output": (grid_study(model, [K], outputs=["load_sharing.engneering.*"]),
                           "study.outputs", "matches no output"),
        "unknown key": (typo, "study.outputz", "unknown field"),
        "four axes": (grid_study(model, [dict(K, path=f"meshes.{m}.stiffness")
                                         for m in ("a1", "b1", "a2", "b2")]),
                      "grid.parameters", "at most 3"),
        "plain number with unit": (grid_study(model, [{"path": "meshes.a1.damping_ratio",
                                                       "values": ["5 %"]}]),
                                   "grid.parameters.0.values.0", "plain number"),
        "invalid first case": (grid_study(model, [{"path": "meshes.a1.damping_ratio",
                                                   "values": [-0.1, 0.1]}]),
                               "grid.parameters", "case 0"),
        # ('must be a valid integer, got a number with a fractional part, got 2.5')
        "fractional count": (grid_study(model, [dict(K, num=2.5)]), "grid.parameters.0.num",
                             "must be a whole number, got 2.5"),
        # ('two parameters are named [p, p]; give each a different name' hid this)
        "one path twice": (grid_study(model, [K, K]), "grid.parameters.1",
                           "which parameter 0 also writes"),
        # a grid of 1e8 points grew to GB before its first case, silently
        "huge range": (grid_study(model, [dict(K, num=100_000_000)]),
                       "grid.parameters.0.num", "at most 1,000,000 cases"),
        "huge grid": (grid_study(model, [dict(K, num=2000), dict(K, path="meshes.b1.stiffness",
                                                              num=2000)]),
                      "grid.parameters", "2000 x 2000 = 4,000,000 cases"),
    }


@pytest.mark.parametrize("case", list(_bad_cases("m.toml")))
def test_bad_study_refused_with_one_line(case, split_file):
    data, field, words = _bad_cases(split_file)[case]
    with pytest.raises(StudyError) as info:
        Study(data).plan()
    msg = str(info.value)
    assert "\n" not in msg
    assert f"{field}:" in msg, msg
    assert words in msg, msg
    assert isinstance(info.value, (TorquesplitError, ValueError))


def test_cli_refuses_bad_file_before_any_case(tmp_path, split_file):
    data = grid_study(split_file, [dict(K, start="2e8 kg")])
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(data))
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--quiet"])
    assert res.exit_code == 2
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "grid.parameters.0.start" in lines[0] and "bad.toml" in lines[0]
    assert not (out / "study.sqlite").exists()


def test_every_problem_of_a_study_file_is_said_at_once(tmp_path, split_file):
    """A reviewer fixed a study file with eight mistakes in eight attempts (one line
    each).  The file's structure is checked first, all of it; then, against the model,
    every parameter, the outputs and the analysis, all at once; the sweep names its
    options for them."""
    data = grid_study(split_file, [dict(K, path="meshes.a1.stifness"),
                                   dict(K, path="meshes.b1.stiffness", start="2e8 kg"),
                                   dict(K, path="meshes.a2.stiffness", num=0)],
                      outputs=["load_sharing.engneering.*"])
    data["study"]["descripton"] = "typo"
    data["analysis"]["steps_per_period"] = 0
    with pytest.raises(StudyError) as info:
        Study(data).plan()
    fields = [f for f, _ in info.value.problems]
    assert fields == ["study.descripton", "analysis.steps_per_period",
                      "grid.parameters.2.num"], fields
    assert str(info.value).count("\n") == 2
    del data["study"]["descripton"]
    data["analysis"]["steps_per_period"] = 100
    data["grid"]["parameters"][2]["num"] = 3
    data["analysis"].pop("cycles", None)
    data["analysis"]["duration"] = "-1 s"
    data["analysis"]["settle"] = {"start": "1 kg"}  # (said with the duration, not after)
    with pytest.raises(StudyError) as info:
        Study(data).plan()
    fields = [f for f, _ in info.value.problems]
    assert fields == ["analysis.duration", "analysis.settle.start", "study.outputs",
                      "grid.parameters.0.path", "grid.parameters.1.start"], fields
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(data))
    res = CliRunner().invoke(app, ["study", str(path), "--quiet"])
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert res.exit_code == 2 and len(lines) == 5 and all(
        ln.startswith(f"error: {path}: ") for ln in lines), res.output
    res = CliRunner().invoke(app, ["sweep", str(split_file), "--vary",
                                   "meshes.a1.stifness=2e8:6e8:3 N/m", "--output", "nope",
                                   "--duration", "-1 s", "--quiet"])
    assert res.exit_code == 2
    assert [":".join(ln.split(":")[:2]) for ln in res.output.splitlines() if ln.strip()] == [
        "error: --duration", "error: --output", "error: --vary (path)"], res.output


def test_a_grid_value_that_gives_an_invalid_model_is_said_before_the_cases_run(split_file):
    """A sweep down to a negative damping ratio ran its first cases and only then
    recorded the last as refused.  The grid's extreme values are checked when the study
    is planned: said at once (the case still runs as refused, the others as usual)."""
    study = Study(grid_study(split_file, [{"path": "meshes.a1.damping_ratio",
                                           "values": [0.1, 0.05, -0.1]}]))
    notes = study.plan().notes
    assert len(notes) == 1 and "case 2 (meshes.a1.damping_ratio = -0.1)" in notes[0]
    assert "recorded as refused" in notes[0]
    with pytest.warns(UserWarning, match="case 2"):
        ds = study.run(workers=1, figures=False)
    assert ds["status"].values.tolist() == ["ok", "ok", "refused"]


def test_toml_syntax_error_names_the_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[study\nname = 1\n")
    with pytest.raises(StudyError, match="broken.toml: TOML syntax error"):
        Study(path)


def test_one_point_range_with_start_equal_to_stop_runs_that_point(split_file):
    study = Study(grid_study(split_file, [dict(K, stop="200 N/um", num=1)]))
    assert study.n_cases == 1
    assert study.plan().design.axes[0].tolist() == [2e8]


def test_model_path_relative_to_study_file(tmp_path, split_file):
    data = grid_study("split.toml", [K])
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(data))
    study = Study(path)
    assert study.n_cases == 3
    assert study.outputs[0] == "load_sharing.cycle_peak"


def test_table_field_must_be_addressed_inside(tmp_path):
    from study_helpers import model_file

    model = model_file(tmp_path / "", extra="")
    text = model.read_text().replace(
        '[meshes.a1]\ngears = ["pinion", "a"]\nstiffness = "4e8 N/m"',
        '[meshes.a1]\ngears = ["pinion", "a"]\nstiffness = {method = "constant", '
        'value = "4e8 N/m", peak_to_peak = 0.1}')
    model.write_text(text)
    with pytest.raises(StudyError, match="a table in the model.*meshes.a1.stiffness.value"):
        Study(grid_study(model, [K])).plan()
    ok = Study(grid_study(model, [dict(K, path="meshes.a1.stiffness.value")]))
    assert ok.n_cases == 3


def test_a_plan_says_what_it_will_run(split_file):
    """Study.plan() (studies.md: 'check a study without running it') printed a repr of
    many thousands of characters."""
    plan = Study(grid_study(split_file, [dict(K, num=3)])).plan()
    text = repr(plan)
    assert text.startswith("<Plan of ") and "grid over" in text and "(3 cases)" in text
    assert len(text) < 400
    two = Study(grid_study(split_file, [dict(K, num=3), dict(K, path="meshes.b2.stiffness",
                                                            num=2)])).plan()
    assert "(3 x 2 = 6 cases)" in repr(two)  # (a one-axis grid said '3 = 3 cases')


def test_a_phase_of_an_error_without_amplitude_is_said(split_file):
    """A reviewer's 'gears.i*.errors.eccentricity_phase' matched a gear without
    eccentricity too and sampled its phase unsaid: a varied phase whose amplitude is 0
    and varied by no parameter changes nothing, which the plan says."""
    data = grid_study(split_file, [{"path": "gears.a.errors.eccentricity_phase",
                                    "values": ["0 deg", "90 deg"]}])
    notes = Study(data).plan().notes
    assert notes == ["grid.parameters: gears.a.errors.eccentricity_phase changes nothing: "
                     "gears.a.errors.eccentricity is 0 in the model and no parameter varies "
                     "it; leave the phase out, or give the error an amplitude"], notes
    data["grid"]["parameters"].append({"path": "gears.a.errors.eccentricity",
                                       "values": ["0 um", "10 um"]})
    assert Study(data).plan().notes == []  # (varied: the phase matters where it is not 0)


def test_a_model_file_given_as_a_study_and_a_study_given_as_a_model_are_told_so(tmp_path):
    """A reviewer gave `study` a model file: ten unknown-field errors, none of which said
    what was wrong.  Each command now says which kind of file it got and which command
    takes it."""
    import torquesplit

    model_file = torquesplit.example_path("ji_li_mill_drive")
    with pytest.raises(StudyError) as exc:
        Study(model_file)
    assert "is a model file" in str(exc.value) and "torquesplit run" in str(exc.value)
    assert "unknown field" not in str(exc.value)
    study_file = tmp_path / "s.toml"
    study_file.write_text(tomli_w.dumps({"study": {"model": str(model_file)},
                                         "grid": {"meshes.m11.backlash": [0.0]}}))
    result = CliRunner().invoke(app, ["run", str(study_file)])
    assert result.exit_code == 2
    assert "is a study file" in result.output and "torquesplit study" in result.output
    assert result.output.count("error:") == 1


def test_a_run_too_short_for_any_mesh_cycle_is_refused_before_its_cases():
    """A 2 ms sweep of Ji & Li's drive ran every case and reported them 'ok' with no
    value (half a cycle of its fastest mesh): refused when planned, naming the field."""
    spec = {"study": {"name": "short", "model": "ji_li_mill_drive",
                      "outputs": ["load_sharing.engineering"]},
            "analysis": {"duration": "2 ms"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.05, 0.1]}]}}
    with pytest.raises(StudyError, match=r"analysis\.duration: the run, 0\.002 s, holds "
                                         r"0\.472 cycle\(s\) of the fastest mesh \(m11"):
        Study(spec).plan()
    spec["analysis"]["duration"] = "9 ms"  # two cycles of m11: its outputs have values
    assert Study(spec).n_cases == 2


def test_a_value_that_is_no_number_is_one_line_without_the_validators_names(split_file):
    """A bad-input reviewer's NaN listed three problems at 'values.0.int', '.float' and
    '.str': the validator's alternatives, not fields."""
    data = grid_study(split_file, [dict(path="meshes.a1.stiffness", values=[float("nan"),
                                                                          "5e8 N/m"])])
    with pytest.raises(StudyError) as info:
        Study(data).plan()
    assert info.value.problems == [(
        "grid.parameters.0.values.0",
        "must be a finite number or a value with its unit ('5e8 N/m', '2 mm'), got nan; "
        "correct the value")], info.value.problems


def test_a_planet_count_study_says_its_outputs_are_the_base_models_meshes():
    """A bad-input reviewer's sweep over 2..6 planets had no columns for planet 5 and
    blanks for the missing ones of 2 and 3, unsaid."""
    study = {"study": {"name": "n", "model": "lin_parker1999_planetary",
                       "outputs": ["load_sharing.mean_force.*"]},
             "analysis": {"type": "run", "duration": "0.05 s"},
             "grid": {"parameters": [{"path": "planetary.0.planets", "values": [3, 5]}]}}
    notes = Study(study).plan().notes
    assert any("planetary.0.planets changes the number of planets" in n for n in notes), notes


def test_every_bad_value_of_one_parameter_is_said(split_file):
    """Only the first bad value of a parameter was said (values 1 of 3; a uniform's low,
    not its high): one run per mistake."""
    grid = grid_study(split_file, [{"path": "meshes.a1.stiffness",
                                    "values": ["2e8 N/m", "2 kg", "3 s"]}])
    with pytest.raises(StudyError) as info:
        Study(grid).plan()
    fields = [f for f, _ in info.value.problems]
    assert fields == ["grid.parameters.0.values.1", "grid.parameters.0.values.2"]
    mc = mc_study(split_file)
    mc["monte_carlo"]["parameters"][1].update(low="1 s", high="2 kg")
    with pytest.raises(StudyError) as info:
        Study(mc).plan()
    fields = [f for f, _ in info.value.problems]
    assert fields == ["monte_carlo.parameters.1.low", "monte_carlo.parameters.1.high"]
