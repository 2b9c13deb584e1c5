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

from study_helpers import grid_study
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


def test_sigkill_then_resume_computes_each_case_once(tmp_path, split_file):
    # 2000 cycles: about 0.1-0.3 s a case, so the kill lands in the middle of the study
    data = grid_study(split_file, GRID, cycles=2000)
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-m", "torquesplit.cli", "study", str(path),
                             "--out", str(out), "--workers", "1", "--quiet", "--no-figures"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while _count(out / "study.sqlite") < 3:
        assert proc.poll() is None, proc.stderr.read().decode()
        assert time.monotonic() < deadline, "the study did not start"
        time.sleep(0.05)
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
    xr.testing.assert_identical(resumed.drop_vars("case_wall_time"),
                                clean.drop_vars("case_wall_time"))


def test_changed_study_or_model_refuses_resume(tmp_path, split_file):
    data = grid_study(split_file, GRID[:1])
    data["grid"]["parameters"][0]["num"] = 2
    path = _write(tmp_path, data)
    out = tmp_path / "out"
    Study(path).run(workers=1, out=out, figures=False)
    with pytest.raises(StudyError, match="already holds a study; add --resume"):
        Study(path).run(workers=1, out=out)
    # done: resuming recomputes nothing
    ds = Study(path).run(workers=1, out=out, resume=True, figures=False)
    with sqlite3.connect(out / "study.sqlite") as db:
        assert [c for (c,) in db.execute("SELECT computed FROM runs ORDER BY run")] == [2, 0]
    assert ds.sizes["meshes.a1.transmission_error.constant"] == 2
    data["grid"]["parameters"][0]["stop"] = "12 um"
    _write(tmp_path, data)
    with pytest.raises(StudyError, match=r"study file changed .*grid\.parameters\.0\.stop: "
                                         r"'9 um' -> '12 um'"):
        Study(path).run(workers=1, out=out, resume=True)
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
    with pytest.raises(StudyError, match="stopped after 3 cases: BrokenProcessPool.*--resume"):
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
