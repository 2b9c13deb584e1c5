"""Nothing lost: a killed study resumes without recomputing a finished case; a changed
study or model refuses to resume and says what changed; Ctrl-C stops cleanly."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time

import pytest
import tomli_w
import xarray as xr
from typer.testing import CliRunner

from study_helpers import grid_study, mc_study
from torquesplit.cli import app
from torquesplit.study import Study, StudyError, StudyInterrupted

GRID = [{"path": "meshes.a1.transmission_error.constant", "start": "0 um", "stop": "9 um",
         "num": 10}]


def _write(tmp_path, data, name="s.toml"):
    path = tmp_path / name
    path.write_text(tomli_w.dumps(data))
    return path


def _count(db_path) -> int:
    try:
        with sqlite3.connect(db_path, timeout=5) as db:
            return db.execute("SELECT COUNT(*) FROM cases").fetchone()[0]
    except sqlite3.Error:
        return 0


def _study_process(tmp_path, split_file, *, workers: int, done: int):
    """(study file, out folder, process) of a 10-case study run by the command line in a
    process of its own, once ``done`` cases are committed (about 0.25-0.75 s a case: at
    0.1-0.3 s two workers could finish the study between two looks at its store, a
    flaky failure on a loaded machine)."""
    path = _write(tmp_path, grid_study(split_file, GRID, cycles=5000))
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-m", "torquesplit.cli", "study", str(path),
                             "--out", str(out), "--workers", str(workers), "--quiet",
                             "--no-figures"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while _count(out / "study.sqlite") < done:
        assert proc.poll() is None, proc.stderr.read().decode()
        assert time.monotonic() < deadline, "the study did not start"
        time.sleep(0.05)
    return path, out, proc


def test_sigkill_then_resume_computes_each_case_once(tmp_path, split_file):
    # the kill lands in the middle of the study
    path, out, proc = _study_process(tmp_path, split_file, workers=1, done=3)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    first = _count(out / "study.sqlite")
    assert 3 <= first < 10, "kill the study while it runs"
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--resume",
                                   "--workers", "1", "--quiet", "--no-figures"])
    assert res.exit_code == 0, res.output
    with sqlite3.connect(out / "study.sqlite") as db:
        runs = db.execute("SELECT run, computed FROM runs ORDER BY run").fetchall()
        per_run = dict(db.execute("SELECT run, COUNT(*) FROM cases GROUP BY run").fetchall())
    assert [c for _, c in runs] == [first, 10 - first]
    assert sum(per_run.values()) == 10 and per_run[runs[0][0]] == first
    resumed = xr.open_dataset(out / "results.nc", engine="h5netcdf")
    clean = Study(path).run(workers=1)
    # (the file says which run wrote it: its provenance, which the Dataset has not)
    from torquesplit.results.files import provenance

    said = {k: resumed.attrs.pop(k) for k in provenance("", "{}")}
    assert said["software"].startswith("torquesplit") and said["model_sha256"]
    xr.testing.assert_identical(resumed.drop_vars("case_wall_time"),
                                clean.drop_vars("case_wall_time"))


def test_a_folder_of_other_results_is_not_written_over(tmp_path, split_file):
    """'study --out DIR' replaced another run's results.nc and figures in DIR, silently."""
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "other"
    out.mkdir()
    (out / "results.nc").write_bytes(b"someone else's")
    with pytest.raises(StudyError, match=r"^out: .* holds results.nc of another run"):
        Study(path).run(workers=1, out=out, figures=False)
    assert (out / "results.nc").read_bytes() == b"someone else's"
    # a spreadsheet of theirs alone too (a studies reviewer's results.csv was replaced)
    lone = tmp_path / "sheet"
    lone.mkdir()
    (lone / "results.csv").write_text("mine")
    with pytest.raises(StudyError, match=r"^out: .* holds results.csv of another run"):
        Study(path).run(workers=1, out=lone, figures=False)
    assert (lone / "results.csv").read_text() == "mine"
    (out / "figures").mkdir()
    (out / "figures" / "dynamic_factor.png").write_bytes(b"another study's figure")
    Study(path).run(workers=1, out=out, figures=False, overwrite=True)
    assert (out / "results.nc").read_bytes() != b"someone else's"
    # its figures went with it: they stayed beside the new study's, from other outputs
    assert not (out / "figures" / "dynamic_factor.png").exists()


def test_changed_study_or_model_refuses_resume(tmp_path, split_file):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    with pytest.raises(StudyError, match=r"^out: .* already holds a study \(finished: its "
                                         r"results are in .*results\.nc\); add resume=True "
                                         r"to continue it, overwrite=True to start it again"):
        Study(path).run(workers=1, out=out)
    # done: resuming recomputes nothing
    ds = Study(path).run(workers=1, out=out, resume=True, figures=False)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [2, 0]
    assert ds.sizes["meshes.a1.transmission_error.constant"] == 2
    data["grid"]["parameters"][0]["stop"] = "12 um"
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=r"^resume: the study changed .*grid\.parameters"
                                         r"\.0\.stop: '9 um' -> '12 um'.*another out or "
                                         r"overwrite=True$"):
        Study(path).run(workers=1, out=out, resume=True)
    # another study in the folder: said so, not as the JSON of every field that differs
    name = data["study"]["name"]
    data["study"]["name"] = "another"
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=rf"^resume: .*out holds the study '{name}', not "
                                         r"'another'; start a new study with another out"):
        Study(path).run(workers=1, out=out, resume=True)
    data["study"]["name"] = name
    data["grid"]["parameters"][0]["stop"] = "9 um"
    _write(tmp_path, data)
    split_file.write_text(split_file.read_text().replace('torque = "100 N m"',
                                                         'torque = "120 N m"'))
    with pytest.raises(StudyError, match=r"model changed .*drives\.motor\.torque: 100\.0 -> "
                                         r"120\.0"):
        Study(path).run(workers=1, out=out, resume=True)
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--resume"])
    assert res.exit_code == 2 and "drives.motor.torque" in res.output
    ds = Study(path).run(workers=1, out=out, overwrite=True, figures=False)
    assert (ds["status"] == "ok").all()


def test_ctrl_c_stops_cleanly_and_resume_finishes(tmp_path, split_file):
    data = grid_study(split_file, GRID)
    out = tmp_path / "out"
    seen = []

    def interrupt_after_four(p):
        seen.append(p.done)
        if p.computed == 4:
            raise KeyboardInterrupt

    with pytest.raises(StudyInterrupted) as info:
        Study(data).run(workers=1, out=out, progress=interrupt_after_four)
    assert isinstance(info.value, KeyboardInterrupt)
    assert "4 of 10" in str(info.value) and "--resume" in str(info.value)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert db.execute("SELECT COUNT(*) FROM cases").fetchone()[0] == 4
        assert db.execute("SELECT state FROM runs").fetchone()[0] == "interrupted"
    ds = Study(data).run(workers=1, out=out, resume=True, figures=False)
    assert (ds["status"] == "ok").all() and ds.sizes[GRID[0]["path"]] == 10
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [4, 6]


def test_a_dead_worker_stops_the_study_without_losing_cases(tmp_path, split_file):
    from concurrent.futures.process import BrokenProcessPool

    def flaky(function, payloads):  # any callable is a runner
        for i, p in enumerate(payloads):
            if i == 3:
                raise BrokenProcessPool("a worker process died")
            yield function(p)

    data = grid_study(split_file, GRID)
    out = tmp_path / "out"
    with pytest.raises(StudyError, match="stopped after 3 cases: BrokenProcessPool.*with "
                                         "resume=True"):
        Study(data).run(runner=flaky, out=out)
    ds = Study(data).run(workers=1, out=out, resume=True, figures=False)
    assert (ds["status"] == "ok").all()
    with sqlite3.connect(out / "study.sqlite") as db:
        assert db.execute("SELECT state, computed FROM runs ORDER BY run").fetchall() == [
            ("failed", 3), ("finished", 7)]


def test_one_run_at_a_time_per_folder(tmp_path, split_file):
    from torquesplit.study.store import StoreLock

    out = tmp_path / "out"
    out.mkdir()
    held = StoreLock(out)  # as if another process were running the study
    try:
        with pytest.raises(StudyError, match="in use by another run of a study"):
            Study(grid_study(split_file, GRID)).run(workers=1, out=out)
    finally:
        held.release()
    ds = Study(grid_study(split_file, GRID[:1])).run(workers=1, out=out, figures=False)
    assert ds.sizes[GRID[0]["path"]] == 10


def test_python_api_names_its_arguments_the_cli_its_flags(tmp_path, split_file):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    for kwargs, words in [({"out": out}, "resume=True"),
                          ({"precision": "fp32"}, "backend='gpu' or leave precision out"),
                          ({"backend": "gpu", "scheduler": "tcp://127.0.0.1:1"},
                           "leave out scheduler, client and runner"),
                          ({"workers": 0}, "workers: got 0; give at least 1 worker")]:
        with pytest.raises(StudyError, match=words) as info:
            Study(path).run(**kwargs)
        assert "--" not in str(info.value)
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--quiet"])
    assert res.exit_code == 2
    assert "--out: " in res.output and "add --resume to continue it, --overwrite" in res.output
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--quiet",
                                   "--precision", "fp32"])
    assert res.exit_code == 2 and "add --backend gpu or leave --precision out" in res.output


def _stop_while_writing_figures(monkeypatch):
    """Ctrl-C after the first figure of the study is written (every case done)."""
    from torquesplit.study import figures

    real = figures.write_study_figures

    def interrupted(ds, directory, **kwargs):
        real(ds, directory, formats=("png",))
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "write_study_figures", interrupted)


def _runs(out):
    with sqlite3.connect(out / "study.sqlite") as db:
        return db.execute("SELECT state, computed FROM runs ORDER BY run").fetchall()


def test_ctrl_c_while_writing_figures_is_a_stop_and_resume_writes_them(tmp_path, split_file,
                                                                        monkeypatch):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 3
    out = tmp_path / "out"
    with monkeypatch.context() as m:
        _stop_while_writing_figures(m)
        with pytest.raises(StudyInterrupted) as info:
            Study(data).run(workers=1, out=out)
    assert "3 of 3" in str(info.value) and "resume=True" in str(info.value)
    assert _runs(out) == [("interrupted", 3)]  # not finished: the figures are not all there
    assert not list((out / "figures").glob("*.svg"))
    Study(data).run(workers=1, out=out, resume=True)
    assert _runs(out) == [("interrupted", 3), ("finished", 0)]
    assert list((out / "figures").glob("*.svg")) and (out / "results.nc").exists()


def test_cli_says_how_to_resume_after_ctrl_c_while_writing_figures(tmp_path, split_file,
                                                                   monkeypatch):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    args = ["study", str(path), "--out", str(out), "--workers", "1", "--quiet"]
    with monkeypatch.context() as m:
        _stop_while_writing_figures(m)
        res = CliRunner().invoke(app, args)
    assert res.exit_code == 130
    assert "stopped: 2 of 2 cases done and saved in" in res.output
    assert "figures not all written; to finish, run the same command with --resume" in res.output
    assert _runs(out) == [("interrupted", 2)]
    res = CliRunner().invoke(app, args + ["--resume"])
    assert res.exit_code == 0, res.output

    # without figures the message names results.nc only (it said 'and figures')
    from torquesplit.study import dataset

    def stopped(ds, path):
        raise KeyboardInterrupt

    out2 = tmp_path / "out2"
    args2 = ["study", str(path), "--out", str(out2), "--workers", "1", "--quiet",
             "--no-figures"]
    with monkeypatch.context() as m:
        m.setattr(dataset, "write_dataset", stopped)
        res = CliRunner().invoke(app, args2)
    assert res.exit_code == 130
    assert "saved in" in res.output and "results.nc not all written; to finish" in res.output
    assert _runs(out)[-1] == ("finished", 0) and list((out / "figures").glob("*.svg"))


def test_a_figure_is_whole_or_absent(tmp_path, split_file, monkeypatch):
    from matplotlib.figure import Figure

    from torquesplit.study.figures import write_study_figures

    ds = Study(grid_study(split_file, GRID[:1])).run(workers=1)

    def half_then_stop(self, fname, **kwargs):
        with open(fname, "wb") as f:
            f.write(b"half a figure")
        raise KeyboardInterrupt

    monkeypatch.setattr(Figure, "savefig", half_then_stop)
    with pytest.raises(KeyboardInterrupt):
        write_study_figures(ds, tmp_path / "figures")
    assert list((tmp_path / "figures").iterdir()) == []


def test_resume_accepts_a_changed_description(tmp_path, split_file):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    data["study"]["description"] = "now with a better description"
    data["study"]["reference"] = "a paper"
    _write(tmp_path, data)
    ds = Study(path).run(workers=1, out=out, resume=True, figures=False)
    assert ds.attrs["description"] == "now with a better description"
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [2, 0]
    data["study"]["name"] = "another name"  # not wording only: still refused
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=r"holds the study 'test grid', not 'another name'"):
        Study(path).run(workers=1, out=out, resume=True)


@pytest.mark.parametrize("sampling", ["random", "sobol"])
def test_a_monte_carlo_is_extended_by_a_resume_with_more_samples(tmp_path, split_file,
                                                                 sampling):
    """Sample i is the same whatever the number drawn (random, Sobol): a resume with more
    samples, or a tighter stopping rule, reuses the stored cases (a reviewer tightening
    half_width was refused and had to recompute all); the results equal a study run at
    that size from the start.  A Latin hypercube's points depend on its size: refused."""
    data = mc_study(split_file, samples=4, sampling=sampling)
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    data["monte_carlo"]["samples"] = 8
    _write(tmp_path, data)
    ds = Study(path).run(workers=1, out=out, resume=True, figures=False)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [4, 4]
    fresh = Study(_write(tmp_path, data, "fresh.toml")).run(workers=1, figures=False)
    assert ds.sizes["sample"] == 8
    timing = [v for v in fresh.data_vars if "time" in v and "simulated" not in v]
    xr.testing.assert_equal(ds.drop_vars(timing).reset_coords(drop=True),
                            fresh.drop_vars(timing).reset_coords(drop=True))
    # and the stored study is now the extended one: a third resume computes nothing
    Study(path).run(workers=1, out=out, resume=True, figures=False)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [4, 4, 0]
    data["monte_carlo"]["seed"] = 8  # other samples: still a change
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=r"monte_carlo\.seed"):
        Study(path).run(workers=1, out=out, resume=True)


def test_a_latin_hypercube_is_not_extended_by_a_resume(tmp_path, split_file):
    data = mc_study(split_file, samples=4, sampling="latin_hypercube")
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    data["monte_carlo"]["samples"] = 8
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=r"monte_carlo\.samples"):
        Study(path).run(workers=1, out=out, resume=True)


def test_resume_compares_values_not_their_writing(tmp_path, split_file):
    """'9 um' written '0.009 mm' was refused as a changed study; another value is."""
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    data["grid"]["parameters"][0]["stop"] = "0.009 mm"
    _write(tmp_path, data)
    Study(path).run(workers=1, out=out, resume=True, figures=False)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [2, 0]
    data["grid"]["parameters"][0]["stop"] = "0.008 mm"
    _write(tmp_path, data)
    with pytest.raises(StudyError, match="the study changed"):
        Study(path).run(workers=1, out=out, resume=True)


def test_resume_and_overwrite_together_are_refused(tmp_path, split_file):
    """--resume --overwrite reset the store and recomputed the finished cases."""
    from study_helpers import grid_study
    from torquesplit.errors import StudyError
    from torquesplit.study import Study

    study = Study(grid_study(split_file, [{"path": "meshes.a1.damping_ratio",
                                           "values": [0.05, 0.06]}], cycles=5))
    with pytest.raises(StudyError, match="resume=True continues the stored study and "
                                         "overwrite=True starts it again"):
        study.run(out=tmp_path / "o", resume=True, overwrite=True)
    assert not (tmp_path / "o").exists()


def test_a_study_folder_that_is_a_file_is_refused(tmp_path, split_file):
    from study_helpers import grid_study
    from torquesplit.errors import StudyError
    from torquesplit.study import Study

    f = tmp_path / "taken.toml"
    f.write_text("x = 1\n")
    study = Study(grid_study(split_file, [{"path": "meshes.a1.damping_ratio",
                                           "values": [0.05, 0.06]}], cycles=5))
    with pytest.raises(StudyError, match="is a file; a study writes a folder"):
        study.run(out=f)


def test_progress_is_told_when_the_cases_start_and_a_refused_sweep_draws_no_bar(
        tmp_path, split_file):
    """The bar now shows from the first report, so a study refused before it starts (its
    folder holds another study) drew an empty 'cases 0/3' bar above its error; the first
    report comes before the first case (which may compile for 20 s)."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    seen = []
    out = tmp_path / "out"
    Study(grid_study(split_file, GRID)).run(workers=1, out=out, figures=False,
                                            progress=lambda p: seen.append((p.computed, p.last)))
    assert seen[0] == (0, None) and seen[-1][0] == 10
    res = CliRunner().invoke(app, ["sweep", str(split_file), "--vary",
                                   "meshes.a1.stiffness=2e8:4e8:3 N/m", "--out", str(out)])
    assert res.exit_code == 2 and "already holds a study" in res.stderr
    assert "cases" not in res.stderr.replace("cases (grid", ""), res.stderr


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_exit_when_their_driver_is_killed(tmp_path, split_file):
    """A reviewer killed a 2-worker study's driver with SIGKILL: its workers waited for
    work forever (228 MB each), until killed by hand.  They exit with it now."""
    from pathlib import Path

    def children(pid):
        out = []
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except (OSError, IndexError):
                continue
            if int(fields[1]) == pid:
                out.append(int(stat.parent.name))
        return out

    _, _, proc = _study_process(tmp_path, split_file, workers=2, done=1)
    workers = children(proc.pid)
    assert workers, "a 2-worker study has worker processes"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    # (a worker holds the GIL while it compiles, which a cold numba cache makes many
    # seconds: its watching thread exits it after that; 20 s was flaky on a loaded CI)
    deadline = time.monotonic() + 60
    alive = workers
    while alive and time.monotonic() < deadline:
        time.sleep(0.1)
        alive = [w for w in alive if Path(f"/proc/{w}").exists()
                 and " Z " not in Path(f"/proc/{w}/stat").read_text()]
    for w in alive:  # (leave nothing behind, then fail)
        os.kill(w, signal.SIGKILL)
    assert not alive, f"workers {alive} outlived their driver"


def test_resume_runs_again_the_cases_that_ended_in_an_error(tmp_path, split_file):
    """A case that ended in an exception (a bug, the machine: here a file changed under a
    running study) was kept as 'error' by every resume, and only --overwrite (which drops
    the good cases too) ran it again.  Refused and diverged cases are the model's: kept."""
    data = grid_study(split_file, GRID)
    out = tmp_path / "out"

    def one_error(function, payloads):
        for p in payloads:
            r = function(p)
            if r["index"] == 2:
                r = dict(r, status="error", reason="NameError: a stand-in",
                         values=[float("nan")] * len(r["values"]))
            yield r

    first = Study(data).run(runner=one_error, out=out, figures=False)
    assert list(first["status"].values).count("error") == 1
    ran = []

    def recording(function, payloads):
        for p in payloads:
            ran.append(p["index"])
            yield function(p)

    with pytest.warns(UserWarning, match=r"1 case of the study in .* ended in an error .* "
                                         r"is run again"):
        ds = Study(data).run(runner=recording, out=out, resume=True, figures=False)
    assert ran == [2]
    assert (ds["status"] == "ok").all()
    clean = Study(data).run(workers=1, figures=False)
    for name in Study(data).outputs:
        xr.testing.assert_equal(ds[name], clean[name])


def test_ctrl_c_while_the_workers_start_is_a_stop_with_the_hint(tmp_path, split_file,
                                                               monkeypatch):
    """A Ctrl-C during the worker start-up left exit 130 without the resume hint."""
    import torquesplit.study.core as core

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(core, "make_runner", interrupted)
    out = tmp_path / "out"
    with pytest.raises(StudyInterrupted, match="0 of 10 cases.*resume"):
        Study(grid_study(split_file, GRID)).run(workers=2, out=out)
    monkeypatch.undo()
    ds = Study(grid_study(split_file, GRID)).run(workers=1, out=out, resume=True,
                                                 figures=False)
    assert (ds["status"] == "ok").all()


def test_sigterm_stops_like_ctrl_c_and_says_how_to_resume(tmp_path, split_file):
    """A batch system's time limit (SIGTERM) ended a study with 'leaked semaphore
    objects', its run left 'running' and no word on resuming."""
    path, out, proc = _study_process(tmp_path, split_file, workers=2, done=2)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    err = err.decode()
    assert proc.returncode == 143, err
    assert "stopped (SIGTERM):" in err and "--resume" in err
    assert "leaked" not in err and "Traceback" not in err
    done = _count(out / "study.sqlite")
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--resume",
                                   "--workers", "1", "--quiet", "--no-figures"])
    assert res.exit_code == 0, res.output
    assert f"resuming: {done} finished case" in res.stderr  # (it said nothing of them)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert db.execute("SELECT COUNT(*) FROM cases").fetchone()[0] == 10
        computed = [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")]
    assert computed[-1] == 10 - done


def test_a_stop_under_overwrite_says_to_resume_in_its_place(tmp_path, split_file,
                                                           monkeypatch):
    """'run the same command with --resume' under --overwrite led to 'give one of them'."""
    import torquesplit.study.core as core

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(core, "make_runner", interrupted)
    path = _write(tmp_path, grid_study(split_file, GRID))
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(tmp_path / "out"),
                                   "--overwrite", "--workers", "2", "--quiet",
                                   "--no-figures"])
    assert res.exit_code == 130
    assert "run the same command with --resume in place of --overwrite" in " ".join(
        res.output.split())


def test_overwrite_removes_the_studys_own_figures_only(tmp_path, split_file):
    """--overwrite removed every PNG and SVG in figures/, a user's own plot there too (a
    studies reviewer): the study lists the figures it wrote, and removes those."""
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "o"
    Study(path).run(workers=1, out=out)
    ours = sorted(p.name for p in (out / "figures").glob("*.png"))
    assert ours
    (out / "figures" / "my_plot.png").write_bytes(b"mine")
    Study(path).run(workers=1, out=out, overwrite=True, figures=False)
    left = sorted(p.name for p in (out / "figures").iterdir())
    assert left == ["my_plot.png"]


def test_a_broken_or_full_store_is_one_line_that_says_what_is_kept(tmp_path, split_file,
                                                                   monkeypatch):
    """A store that is not SQLite, or that cannot be written (a full disk), ended the
    study in sqlite's traceback (a reliability reviewer); the cases committed before a
    failed write are kept, and --resume finishes the study."""
    path = _write(tmp_path, grid_study(split_file, GRID))
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "study.sqlite").write_text("garbage")
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(tmp_path / "bad"),
                                   "--resume", "--workers", "1", "--quiet"])
    assert res.exit_code == 2, res.output
    assert "study.sqlite is not a readable study store (file is not a database): move it " \
           "aside" in " ".join(res.stderr.split())
    assert "Traceback" not in res.output
    # a folder that cannot be opened, or a store another process holds, is not a broken
    # store: no advice to --overwrite (which would drop the finished cases)
    from torquesplit.errors import OutputError
    from torquesplit.study.store import Store

    with pytest.raises(OutputError, match=r"cannot open the study store .* check that its "
                                          r"folder exists") as err:
        Store(tmp_path / "missing" / "study.sqlite")
    assert "overwrite" not in str(err.value)
    held = sqlite3.connect(tmp_path / "held.sqlite", isolation_level=None)
    held.execute("BEGIN EXCLUSIVE")
    monkeypatch.setattr(sqlite3, "connect", lambda *a, **k: held.__class__(
        a[0], isolation_level=None, timeout=0.1))
    with pytest.raises(OutputError, match=r"is in use by another process \(database is "
                                          r"locked\)") as err:
        Store(tmp_path / "held.sqlite")
    assert "overwrite" not in str(err.value)
    monkeypatch.undo()
    held.close()

    from torquesplit.study import store as store_module

    real_put = store_module.Store.put
    calls = []

    def put(self, r):
        calls.append(r["index"])
        if len(calls) == 4:  # the fourth commit meets a full disk
            with self._writing():
                raise sqlite3.OperationalError("disk I/O error")
        real_put(self, r)

    monkeypatch.setattr(store_module.Store, "put", put)
    out = tmp_path / "full"
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--workers", "1",
                                   "--quiet"])
    assert res.exit_code == 2, res.output
    said = " ".join(res.stderr.split())
    assert (f"error: cannot write the study store {out / 'study.sqlite'} (disk I/O error); "
            f"the cases finished before are kept in it") in said and "--resume" in said
    assert "Traceback" not in res.output and _count(out / "study.sqlite") == 3
    monkeypatch.setattr(store_module.Store, "put", real_put)
    res = CliRunner().invoke(app, ["study", str(path), "--out", str(out), "--workers", "1",
                                   "--resume", "--quiet", "--json", "--no-figures"])
    assert res.exit_code == 0, res.output
    assert _count(out / "study.sqlite") == 10
