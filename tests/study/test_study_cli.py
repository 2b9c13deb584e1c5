"""torquesplit study / sweep on tiny studies; the shipped studies all check out."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import tomli_w
import xarray as xr
from study_helpers import grid_study, mc_study
from typer.testing import CliRunner

from torquesplit.cli import app
from torquesplit.study import Study
from torquesplit.study.cli import parse_vary
from torquesplit.study.shipped import study_names

runner = CliRunner()


def _ok(args):
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return res.stdout


def test_study_command_writes_store_results_and_figures(tmp_path, split_file):
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um", "4 um", "8 um"]}],
                      outputs=["load_sharing.cycle_peak*", "peak_force.a1"])
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(data))
    out = tmp_path / "out"
    text = _ok(["study", str(path), "--out", str(out), "--workers", "1"])
    assert "3 ok" in text and "results.nc" in text
    ds = xr.open_dataset(out / "results.nc", engine="h5netcdf")
    assert ds["load_sharing.cycle_peak"].shape == (3,)
    figs = sorted(p.name for p in (out / "figures").iterdir())
    assert "load_sharing.cycle_peak.png" in figs and "load_sharing.cycle_peak.svg" in figs
    assert "peak_force.png" in figs
    again = json.loads(_ok(["study", str(path), "--out", str(out), "--resume", "--json",
                            "--no-figures"]))
    assert again["status"] == {"ok": 3} and len(again["outputs"]["peak_force.a1"]) == 3
    # every figure file in --json: the SVGs beside the PNGs (it listed the PNGs only)
    listed = json.loads(_ok(["study", str(path), "--out", str(out), "--resume",
                             "--json"]))["figures"]
    assert sorted(Path(f).name for f in listed) == [f for f in figs
                                                    if f.endswith((".png", ".svg"))]


def test_sweep_one_liner(tmp_path, split_file):
    out = tmp_path / "sw"
    data = json.loads(_ok(["sweep", str(split_file), "--vary",
                           "meshes.a1.transmission_error.constant,"
                           "meshes.a2.transmission_error.constant=0:10:3um",
                           "--output", "load_sharing.cycle_peak", "--cycles", "40",
                           "--workers", "1", "--out", str(out), "--json", "--quiet"]))
    assert data["cases"] == 3 and data["status"] == {"ok": 3}
    assert data["coordinates"]["constant"] == pytest.approx([0.0, 5e-6, 1e-5])
    assert data["coordinate_units"] == {"constant": "m"}  # (SI: 5e-06 said no unit)
    lsc = data["outputs"]["load_sharing.cycle_peak"]
    assert lsc[0] < lsc[1] < lsc[2]
    bad = runner.invoke(app, ["sweep", str(split_file), "--vary", "meshes.a1.stiffness=1:2"])
    assert bad.exit_code == 2 and "START:STOP:NUM" in bad.output
    # an empty range: the remedy in --vary's terms (it offered 'values', a study field)
    bad = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.stiffness=5:5:3N/um"])
    assert bad.exit_code == 2 and "one value as START:START:1" in bad.output
    assert "'values'" not in bad.output
    # a resume with another range names the sweep's option, not the study field it makes
    # ('grid.parameters.0.stop: 10.0 -> 12.0', a studies reviewer)
    other = runner.invoke(app, ["sweep", str(split_file), "--vary",
                                "meshes.a1.transmission_error.constant,"
                                "meshes.a2.transmission_error.constant=0:12:3um",
                                "--output", "load_sharing.cycle_peak", "--cycles", "40",
                                "--workers", "1", "--out", str(out), "--resume", "--quiet"])
    assert other.exit_code == 2, other.output
    text = " ".join(other.stderr.split())
    assert "--vary's STOP: 10.0 -> 12.0" in text and "grid.parameters" not in text, text


def test_parse_vary():
    assert parse_vary("shafts.s.diameter=130:400:28mm") == {
        "path": "shafts.s.diameter", "start": 130.0, "stop": 400.0, "num": 28, "unit": "mm"}
    assert parse_vary("a.b=2e8 N/m:6e8 N/m:9") == {"path": "a.b", "start": "2e8 N/m",
                                                    "stop": "6e8 N/m", "num": 9}


def test_monte_carlo_summary_and_list(tmp_path, split_file):
    path = tmp_path / "mc.toml"
    path.write_text(tomli_w.dumps(mc_study(split_file, samples=8)))
    text = _ok(["study", str(path), "--out", str(tmp_path / "mc"), "--workers", "1",
                "--quiet"])
    assert "p95" in text and "8 ok" in text
    # over 8 cases p5 and p95 are interpolated between extremes: said
    assert "p5 and p95 over 8 cases" in " ".join(text.split())
    # the table's statistics in --json too (only the terminal had them, a reviewer)
    import xarray as xr

    data = json.loads(_ok(["study", str(path), "--out", str(tmp_path / "mc"), "--resume",
                           "--json", "--no-figures"]))
    st = data["statistics"]["load_sharing.cycle_peak"]
    with xr.open_dataset(tmp_path / "mc" / "results.nc", engine="h5netcdf") as ds:
        x = ds["load_sharing.cycle_peak"].values
    assert st["cases"] == 8 and st["mean"] == pytest.approx(float(np.mean(x)), rel=1e-12)
    assert st["p95"] == pytest.approx(float(np.quantile(x, 0.95)), rel=1e-12)
    assert st["std"] == pytest.approx(float(np.std(x, ddof=1)), rel=1e-12)
    figs = {p.name for p in (tmp_path / "mc" / "figures").iterdir()}
    assert "mc_load_sharing.cycle_peak.png" in figs
    listed = _ok(["study", "--list"])
    assert "ji_li_diameter" in listed and "mo_2017_errors" in listed


@pytest.mark.parametrize("name", study_names())
def test_shipped_studies_check_out(name):
    study = Study(name)
    plan = study.plan()
    assert plan.n_cases >= 6 and plan.outputs
    text = plan.study_text
    assert "seed" not in study.spec.study.reference.lower()  # cite authors, not seed numbers
    assert study.spec.study.reference and "#" in text  # every file explains itself


def test_sweep_refuses_a_bare_range_for_a_field_with_units(tmp_path, split_file):
    from torquesplit.study.cli import _refuse_bare_range

    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a1.transmission_error.constant=0:40:5", "--cycles", "40",
                              "--out", str(tmp_path / "s"), "--quiet"])
    assert res.exit_code == 2, res.output
    assert "0:40:5um" in res.output and "0 to 40 m" in res.output
    assert "Traceback" not in res.output and not (tmp_path / "s").exists()
    # with a unit, or for a plain number, the range stands
    _refuse_bare_range("x", parse_vary("meshes.a1.transmission_error.constant=0:40:5um"))
    _refuse_bare_range("x", parse_vary("meshes.a1.damping_ratio=0.05:0.1:2"))


def test_parse_vary_refuses_a_step_for_the_count():
    with pytest.raises(ValueError, match="number of points, a whole number"):
        parse_vary("meshes.a1.transmission_error.constant=0:40:2.5um")
    with pytest.raises(ValueError, match="number of points"):
        parse_vary("a.b=0:40:0um")
    for empty in ("=0:40:3um", ",=0:40:3um", " =0:40:3um"):  # (an IndexError: a fuzzer)
        with pytest.raises(ValueError, match="names no field before '='"):
            parse_vary(empty)
    # a pattern is named by itself (sweep has no --name): its last segment alone lost
    # which fields it sets; its folder writes '*' as 'all'
    assert parse_vary("gears.*.errors.eccentricity=0:40:2um")["name"] == \
        "gears.*.errors.eccentricity"
    assert parse_vary("shafts.a.diameter,shafts.b.diameter=1:2:2mm")["name"] == "diameter"
    from torquesplit.study.cli import _safe

    assert _safe("sweep_meshes.*.damping_ratio") == "sweep_meshes.all.damping_ratio"


def test_sweep_pattern_and_static_run_length_flags(tmp_path, split_file):
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "gears.*.errors.eccentricity=0:40:2", "--quiet"])
    assert res.exit_code == 2 and "0:40:2um" in res.output  # a pattern's kind is known too
    res = runner.invoke(app, ["sweep", str(split_file), "--vary",
                              "meshes.a*.transmission_error.constant=0:4:2um", "--cycles", "40",
                              "--output", "load_sharing.cycle_peak", "--workers", "1",
                              "--out", str(tmp_path / "p"), "--quiet", "--json",
                              "--no-figures"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["status"] == {"ok": 2}
    res = runner.invoke(app, ["sweep", str(split_file), "--static", "--duration", "0.5 s",
                              "--vary", "meshes.a1.transmission_error.constant=0:4:2um"])
    assert res.exit_code == 2 and "--duration" in res.output
    assert "analysis.duration" not in res.output


def test_summary_names_the_case_of_each_failure_units_and_an_empty_resume(tmp_path,
                                                                        split_file):
    """A reviewer's sweep printed three near-identical 'not ok' lines without saying which
    case each was, force columns without their unit, and '--resume' into a mistyped
    folder started the study again without a word."""
    data = grid_study(split_file, [{"path": "drives.motor.torque",
                                    "values": ["100 N m", "1e10 N m", "120 N m"]}],
                      outputs=["peak_force.a1", "load_sharing.cycle_peak"])
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(data))
    res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / "typo"),
                              "--resume", "--workers", "1", "--no-figures", "--quiet"])
    assert res.exit_code == 0, res.output
    assert "holds no study to resume: the study starts from its first case" in res.stderr
    lines = res.stdout.splitlines()
    # (with its value: 'case 1' alone was read as the first case)
    assert any(ln.strip().startswith("not ok, case 1 (drives.motor.torque = 1e+10 N m): "
                                     "Integration diverged") for ln in lines), res.stdout
    # forces in kN, as the figures draw them and the run's tables print them
    assert "peak_force.a1 [kN]" in res.stdout and "load_sharing.cycle_peak [" not in res.stdout
    import xarray as xr

    with xr.open_dataset(tmp_path / "typo" / "results.nc") as ds:
        var = next(v for v in ds.data_vars if ds[v].attrs.get("output") == "peak_force.a1")
        first = float(ds[var].values[0])
    assert f"{first * 1e-3:.6g}" in res.stdout and f"{first:.6g}" not in res.stdout
    assert "2 outputs" in res.stderr
    # a study none of whose cases gave results fails (it exited 0, a reliability
    # reviewer); its files are written all the same, and --json says so too
    data["grid"]["parameters"][0]["values"] = ["100 N m", "120 N m"]
    data["analysis"].update(method="dopri", rtol=0.9)  # (steps past the stable one)
    path.write_text(tomli_w.dumps(data))
    for extra in ([], ["--json"]):
        res = runner.invoke(app, ["study", str(path), "--out", str(tmp_path / f"all{extra}"),
                                  "--workers", "1", "--no-figures", "--quiet", *extra])
        assert res.exit_code == 1, res.output
        assert "error: no case gave results (2 diverged)" in res.stderr
        assert (tmp_path / f"all{extra}" / "results.nc").is_file()
    assert json.loads(res.stdout)["success"] is False


def test_a_sweeps_remedy_is_in_its_options(tmp_path):
    """--log over a range from 0 answered 'use spacing = "linear"', the study file's
    syntax, to a command line whose fix is to leave out --log."""
    res = runner.invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                              "meshes.m11.backlash=0:1:3mm", "--log", "--out",
                              str(tmp_path / "s")])
    assert res.exit_code == 2
    assert "a log range needs positive start and stop; leave out --log" in res.stderr
    assert "spacing" not in res.stderr


@pytest.mark.parametrize("path, said", [
    ("meshes.stage_sun_planet1.backlash", "it sets every planet's alike"),
    ("gears.stage_planet1.support.pin_error.tangential",
     "'planetary.0.pin_errors.0.tangential' (planet 1's alone: the stage's pin_errors "
     "lists one entry per planet")])
def test_a_generated_path_points_to_the_stages_own_field(path, said):
    """A planet's pin error was pointed to 'planetary.0.pin_errors.0.tangential' 'which
    sets every planet's alike': it is planet 1's alone (a reviewer)."""
    from torquesplit.study.errors import StudyError

    spec = {"study": {"name": "t", "model": "lin_parker1999_planetary",
                      "outputs": ["load_sharing.static_torque"]},
            "analysis": {"type": "static"},
            "grid": {"parameters": [{"path": path, "values": ["0 um", "10 um"]}]}}
    with pytest.raises(StudyError, match="is generated by a \\[\\[planetary\\]\\] stage") as err:
        Study(spec).plan()
    assert said in str(err.value)


def test_study_run_length_from_the_command_line(tmp_path, split_file):
    """--cycles / --duration replace the study file's run length; a resume compares the
    study with them (another length is a change, named), and the stored study text says
    what the command line replaced."""
    data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                    "values": ["0 um", "4 um"]}], outputs=["peak_force.a1"])
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(data))
    out = tmp_path / "out"
    common = ["study", str(path), "--out", str(out), "--workers", "1", "--no-figures",
              "--quiet"]
    _ok([*common, "--duration", "20 ms"])
    ds = xr.open_dataset(out / "results.nc", engine="h5netcdf")
    assert ds["simulated_time"].values == pytest.approx([0.02, 0.02])
    assert "replaced when the study was run: duration = '20 ms'" in ds.attrs["study_toml"]
    import json

    assert json.loads(ds.attrs["analysis_settings"])["duration"] == pytest.approx(0.02)
    ds.close()
    _ok([*common, "--duration", "20ms", "--resume"])  # the same length, written otherwise
    other = runner.invoke(app, [*common, "--cycles", "7", "--resume"])
    assert other.exit_code == 2, other.output
    assert "the study changed" in other.output and "analysis.cycles" in other.output
    for args, words in (
            (["--duration", "-1 s"], "--duration must be a positive"),
            (["--duration", "3 kg"], "is not a time"),
            (["--cycles", "0"], "--cycles must be a whole number of at least 1"),
            (["--cycles", "5", "--duration", "1 s"], "both set the run length")):
        res = runner.invoke(app, ["study", str(path), *args])
        assert res.exit_code == 2 and words in res.output, res.output
    res = runner.invoke(app, ["study", "mo_2017_errors", "--cycles", "5"])
    assert res.exit_code == 2 and "quasi-static" in res.output, res.output


def test_study_analysis_replaced_in_python(split_file):
    """Study(..., analysis=...): a run length replaces the study's other one."""
    data = grid_study(split_file, [{"path": "meshes.a1.stiffness", "values": [4e8]}])
    assert data["analysis"]["cycles"]
    st = Study(data, analysis={"duration": "5 ms"})
    assert st.spec.analysis.cycles is None and st.spec.analysis.duration == "5 ms"
    assert Study(data).spec.analysis.cycles == data["analysis"]["cycles"]  # data untouched
    again = Study(st.spec, analysis={"cycles": 9})
    assert again.spec.analysis.cycles == 9 and again.spec.analysis.duration is None


def test_an_analysis_field_given_beside_a_study_file_is_named_as_given():
    """A code review: Study(static study, analysis={'cycles': 50}) blamed the study file
    for a field it does not hold."""
    from torquesplit.study import StudyError

    with pytest.raises(StudyError, match=r"^analysis\['cycles'\] \(given with the study "
                                         r"mo_2017_errors\.toml\): does not apply"):
        Study("mo_2017_errors", analysis={"cycles": 50})


def test_the_eta_is_the_mean_rate_of_this_sessions_cases():
    """Two workers finishing together read as 'ETA 0:00:04' with 95 s left (rich's
    column took the last completions' speed); a resumed study's stored cases do not make
    the rate."""
    import time

    from rich.progress import Progress

    from torquesplit.study.cli import _eta_column, eta_finish

    assert eta_finish((100.0, 0), 100.0, 0, 15) is None
    # 2 of 15 done in 27 s: 13 more at 13.5 s each
    assert eta_finish((100.0, 0), 127.0, 2, 15) == pytest.approx(127.0 + 13 * 13.5)
    # resumed with 10 stored: 2 new in 20 s, 3 left at 10 s each
    assert eta_finish((0.0, 10), 20.0, 12, 15) == pytest.approx(50.0)
    col = _eta_column()
    with Progress() as bar:
        task = bar.add_task("x", total=3, finish=time.monotonic() + 95.4)
        assert str(col.render(bar.tasks[task])) in ("0:01:35", "0:01:34")
        bar.update(task, finish=None)
        assert str(col.render(bar.tasks[task])) == "-:--:--"


def test_a_study_logged_to_a_file_says_its_progress_in_lines():
    """Where stderr is not a terminal (a batch job, nohup) the bar drew nothing until the
    end: a study of hours said nothing.  Lines: the first finished case, then at most
    every LOG_EVERY seconds, and the last."""
    from types import SimpleNamespace as P

    from torquesplit.study.cli import LOG_EVERY, progress_lines

    now = [0.0]
    lines = []
    cb = progress_lines(lines.append, clock=lambda: now[0])
    cb(P(done=0, total=10, failed=0))  # the study starts
    for t, done in ((5.0, 1), (10.0, 2), (5.0 + LOG_EVERY, 5), (40.0, 6), (100.0, 10)):
        now[0] = t
        cb(P(done=done, total=10, failed=1 if done > 4 else 0))
    assert lines == ["cases 1/10 (0 not ok), 0:00:05 elapsed, about 0:00:45 left",
                     f"cases 5/10 (1 not ok), 0:00:{5 + int(LOG_EVERY)} elapsed, about "
                     f"0:00:{5 + int(LOG_EVERY)} left",
                     "cases 10/10 (1 not ok), 0:01:40 elapsed"]


def test_a_logged_study_says_what_the_gpu_runner_does_between_cases():
    """A GPU study finishes no case until a launch ends (set-up, compile and kernel of
    thousands of cases): its stages are lines too, at most every LOG_EVERY seconds."""
    from types import SimpleNamespace as P

    from torquesplit.study.cli import LOG_EVERY, progress_lines

    now = [0.0]
    lines = []
    cb = progress_lines(lines.append, clock=lambda: now[0])
    cb(P(done=0, total=10, failed=0, stage=""))
    for t, stage in ((1.0, "64 cases set up"), (2.0, "compiling"), (3.0 + LOG_EVERY, "run")):
        now[0] = t
        cb(P(done=0, total=10, failed=0, stage=stage))
    now[0] = 100.0
    cb(P(done=10, total=10, failed=0, stage=""))
    assert lines == ["64 cases set up (0:00:01 elapsed)",
                     f"run (0:00:{3 + int(LOG_EVERY)} elapsed)",
                     "cases 10/10 (0 not ok), 0:01:40 elapsed"]


def test_a_bare_duration_is_seconds_for_study_and_sweep_as_for_run():
    """``run --duration 0.05`` reads seconds; ``sweep``/``study`` said '0.1' was not a
    time, and ``study`` blamed the study file's analysis.duration for the option."""
    from torquesplit.study.cli import _seconds, _study_with

    assert _seconds("0.1") == "0.1 s" and _seconds(" 2e-3 ") == "2e-3 s"
    assert _seconds("5 ms") == "5 ms" and _seconds(None) is None
    st = _study_with("ji_li_diameter", {"duration": _seconds("0.1")})
    assert st.spec.analysis.duration == "0.1 s"  # (it raised: not a time)
