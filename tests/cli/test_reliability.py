"""The command line refuses what it cannot do before computing, writes results safely
and never prints meaningless numbers (issue 14, items 1, 4 (options), 5 and 6)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import xarray as xr
from typer.testing import CliRunner

import torquesplit
from model_texts import SPUR_PAIR, write_model
from torquesplit.cli import app

runner = CliRunner()
SRC = str(Path(torquesplit.__file__).resolve().parents[1])

#: a pair driven through a shaft of 4.4e-4 N m/rad: 2.2e5 rad of static twist
SOFT_SHAFT = SPUR_PAIR.replace(
    "[gears.pinion]", '[bodies.motor]\npolar_inertia = "0.01 kg m^2"\n\n[shafts.s]\n'
    'connects = ["motor", "pinion"]\ntorsional_stiffness = "4.4e-4 N m/rad"\n\n[gears.pinion]',
    1).replace('body = "pinion"', 'body = "motor"')


def one_line_error(res, *patterns) -> str:
    """Exit 2, only ``error:`` lines on stderr, containing every pattern."""
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    assert res.exit_code == 2, (res.exit_code, res.output)
    lines = res.stderr.strip().splitlines()
    assert lines and all(ln.startswith("error: ") for ln in lines), res.stderr
    for p in patterns:
        assert p in res.stderr, (p, res.stderr)
    return res.stderr


@pytest.fixture
def no_compute(monkeypatch):
    """Make any computation fail the test: what is refused must be refused first."""
    import torquesplit.quasistatic
    import torquesplit.simulation

    def computed(*args, **kwargs):
        raise AssertionError("the command computed before refusing")

    monkeypatch.setattr(torquesplit.simulation, "simulate", computed)
    monkeypatch.setattr(torquesplit.quasistatic, "quasi_static_load_sharing", computed)


# --------------------------------------------------------------------------- output paths
@pytest.mark.parametrize("name,pattern", [
    ("missing/r.nc", "does not exist; create it first"),
    ("r.xlsx", "use a .nc, .mat or .csv file"),
    (".", "is a folder; give a file name in it"),
])
def test_bad_out_paths_are_refused_before_the_run(tmp_path, no_compute, name, pattern):
    """A bad --out failed only after the whole simulation."""
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--out", str(tmp_path / name)])
    one_line_error(res, pattern)


def test_existing_results_are_kept_unless_force(tmp_path, no_compute):
    model = write_model(tmp_path, SPUR_PAIR)
    (tmp_path / "r.nc").write_bytes(b"earlier results")
    res = runner.invoke(app, ["run", str(model), "--out", str(tmp_path / "r.nc")])
    one_line_error(res, "r.nc exists; use --force")
    (tmp_path / "s_history.csv").write_text("earlier")
    res = runner.invoke(app, ["run", str(model), "--out", str(tmp_path / "s.csv")])
    one_line_error(res, "s_history.csv exists")
    res = runner.invoke(app, ["static", str(model), "--out", str(tmp_path / "r.nc")])
    one_line_error(res, "r.nc exists; use --force")
    assert (tmp_path / "r.nc").read_bytes() == b"earlier results"


def test_force_replaces_and_the_file_says_which_run_wrote_it(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    out = tmp_path / "r.nc"
    args = ["run", str(model), "--cycles", "5", "--quiet", "--out", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        first = dict(ds.attrs)
    assert {"run_id", "created_utc", "software", "command"} <= set(first)
    assert first["software"].startswith("torquesplit ")
    # traceable a month later: the commit that wrote it, the model's hash, the folder,
    # and a command a shell takes back whole ('35 mm' was two arguments)
    import hashlib
    import shlex

    from torquesplit.results.files import software_commit

    assert software_commit() == "" or f"(commit {software_commit()})" in first["software"]
    assert first["model_sha256"] == hashlib.sha256(first["model_json"].encode()).hexdigest()
    assert first["working_directory"] == os.getcwd()
    import sys as _sys

    argv = _sys.argv
    try:
        _sys.argv = ["torquesplit", "run", "m.toml", "--set", "shafts.s.diameter=35 mm"]
        from torquesplit.results.files import provenance

        assert shlex.split(provenance("x")["command"])[-1] == "shafts.s.diameter=35 mm"
    finally:
        _sys.argv = argv
    one_line_error(runner.invoke(app, args), "exists; use --force")
    assert runner.invoke(app, args + ["--force"]).exit_code == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["run_id"] != first["run_id"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.toml", "r.nc"]
    res = runner.invoke(app, ["static", str(model), "--points-per-cycle", "2", "--json",
                              "--out", str(tmp_path / "q.nc")])
    assert res.exit_code == 0, res.output
    with xr.open_dataset(tmp_path / "q.nc", engine="h5netcdf") as ds:
        assert ds.attrs["run_id"]


def test_a_run_on_a_path_another_run_holds_is_refused_at_once(tmp_path, no_compute):
    """Two runs on one path overwrote silently or died with BlockingIOError."""
    model = write_model(tmp_path, SPUR_PAIR)
    out = tmp_path / "r.nc"
    holder = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(f"""
            import sys
            from torquesplit.results import files
            with files.claim_output(files.check_output({str(out)!r}), run_id="the-other-run"):
                print("CLAIMED", flush=True)
                sys.stdin.readline()
        """)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
        env=dict(os.environ, PYTHONPATH=SRC))
    try:
        assert holder.stdout.readline().strip() == "CLAIMED"
        res = runner.invoke(app, ["run", str(model), "--out", str(out)])
        one_line_error(res, "is being written by another torquesplit run",
                       f"pid {holder.pid}", "run the-other-run", "choose another file")
    finally:
        holder.communicate("\n", timeout=60)


def _cli(args, **kwargs):
    return subprocess.Popen([sys.executable, "-m", "torquesplit.cli", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=SRC), **kwargs)


def test_two_concurrent_runs_on_one_path_exactly_one_wins(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    out = tmp_path / "r.nc"
    runs = [_cli(["run", str(model), "--cycles", "20", "--quiet", "--out", str(out)])
            for _ in range(2)]
    results = [(p.wait(timeout=300), *p.communicate()) for p in runs]
    codes = sorted(r[0] for r in results)
    assert codes == [0, 2], results
    loser = next(r for r in results if r[0] == 2)
    assert loser[2].startswith("error: ") and len(loser[2].strip().splitlines()) == 1
    assert ("being written by another torquesplit run" in loser[2] or "exists" in loser[2])
    with xr.open_dataset(out, engine="h5netcdf") as ds:  # complete and readable
        assert ds.attrs["run_id"] and "element_force" in ds


def test_sigkill_during_the_cli_save_keeps_the_previous_results(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    out = tmp_path / "r.nc"
    assert runner.invoke(app, ["run", str(model), "--cycles", "5", "--quiet",
                               "--out", str(out)]).exit_code == 0
    before = out.read_bytes()
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(f"""
            import os, time
            from torquesplit.results import files
            def slow_disk(fd, data):  # half of the file reaches the disk, then the kill
                os.write(fd, data[: len(data) // 2])
                print("HALF", flush=True)
                time.sleep(600)
            files._write_all = slow_disk
            from torquesplit.cli import app
            app(["run", {str(model)!r}, "--cycles", "5", "--quiet", "--force",
                 "--out", {str(out)!r}])
        """)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, PYTHONPATH=SRC))
    deadline = time.monotonic() + 120
    while proc.stdout.readline().strip() != "HALF":
        assert time.monotonic() < deadline and proc.poll() is None, proc.stderr.read()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert out.read_bytes() == before
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert "element_force" in ds
    assert not [p.name for p in tmp_path.iterdir()
                if p.name not in ("model.toml", "r.nc", ".r.nc.lock")]


# --------------------------------------------------------------------------- options
@pytest.mark.parametrize("args,pattern", [
    (["run", "M", "--cycles", "0"], "--cycles must be a whole number of at least 1, got 0"),
    (["run", "M", "--steps-per-period", "0"], "--steps-per-period must be a whole number"),
    (["run", "M", "--duration", "-1 s"], "--duration must be a positive finite number"),
    (["run", "M", "--duration", "soon"], "--duration: cannot read 'soon' as a time"),
    (["run", "M", "--method", "euler"], "--method 'euler' is unknown; use rk4 or dopri"),
    (["run", "M", "--definition", "best"], "--definition 'best' is unknown"),
    (["static", "M", "--revolutions", "0"], "--revolutions must be a positive finite number"),
    (["static", "M", "--revolutions", "nan"], "--revolutions must be a positive finite number"),
    (["static", "M", "--points-per-cycle", "-5"], "--points-per-cycle must be a whole number"),
    (["modes", "M", "--count", "-1"], "--count must be a whole number of at least 1, got -1"),
    (["mesh", "M", "--pair", "m", "--points", "0"], "--points must be a whole number"),
    (["mesh", "M", "--pair", "zz"], "--pair: no mesh named 'zz'; use one of m"),
])
def test_numeric_options_are_checked_first(tmp_path, no_compute, args, pattern):
    """--steps-per-period 0 silently used the model's value; --count -1 printed nothing."""
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, [str(model) if a == "M" else a for a in args])
    one_line_error(res, pattern)


def test_every_bad_option_and_set_argument_is_reported_at_once(tmp_path, no_compute):
    """A bad --duration hid two bad --set arguments and a bad --samples-per-period: the
    user fixed them one attempt at a time."""
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--duration", "-1 s", "--samples-per-period",
                              "0", "--set", "foo=1", "--set", "meshes.m.stiffness=50 kg"])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.startswith("error: ")]
    assert len(lines) == 4, res.output
    for pattern in ("--duration must be a positive", "--samples-per-period must be a whole",
                    "--set foo=1: foo: unknown field",
                    "--set meshes.m.stiffness=50 kg: meshes.m.stiffness"):
        assert any(pattern in ln for ln in lines), (pattern, res.output)
    res = runner.invoke(app, ["modes", str(model), "--count", "0", "--below", "-1 kHz"])
    assert [ln.split(" must")[0] for ln in res.output.splitlines()] == [
        "error: --count", "error: --below"], res.output


def test_errors_of_a_json_command_are_json_too(tmp_path, no_compute):
    """A script reading ``run --json`` got an empty stdout on a bad option: the errors
    were plain text on stderr only.  They are on stderr still, and a JSON document with
    ``success`` false and every error is on stdout, for each command that has --json."""
    model = write_model(tmp_path, SPUR_PAIR)
    for args in (["run", str(model), "--duration", "-1 s", "--set", "foo=1"],
                 ["static", str(model), "--max-points", "0"],
                 ["modes", str(model), "--count", "0"],
                 ["study", str(tmp_path / "none.toml")],
                 ["steady", str(model), "--harmonics", "0"]):
        res = runner.invoke(app, args + ["--json"])
        assert res.exit_code == 2, (args, res.output)
        doc = json.loads(res.stdout)
        errors = [ln[len("error: "):] for ln in res.stderr.strip().splitlines()]
        assert doc["success"] is False and doc["errors"] == errors and errors, args
        assert doc["warnings"] == []
        plain = runner.invoke(app, args)
        assert plain.exit_code == 2 and plain.stdout == "", args


def test_plots_must_be_a_folder(tmp_path, no_compute):
    model = write_model(tmp_path, SPUR_PAIR)
    (tmp_path / "figs").write_text("a file")
    res = runner.invoke(app, ["run", str(model), "--plots", str(tmp_path / "figs")])
    one_line_error(res, "is a file, not a folder")


# --------------------------------------------------------------------------- example
def test_example_copies_only_shipped_examples(tmp_path):
    """'example /abs/path.toml' copied any TOML file; '--dir FILE' was a traceback."""
    other = write_model(tmp_path, SPUR_PAIR, "mine.toml")
    res = runner.invoke(app, ["example", str(other), "--dir", str(tmp_path / "out")])
    one_line_error(res, "no example named", "torquesplit examples")
    assert not (tmp_path / "out" / "mine.toml").exists()
    res = runner.invoke(app, ["example", "../examples/ji_li_mill_drive"])
    one_line_error(res, "no example named")
    res = runner.invoke(app, ["example", "ji_li_mill_drive", "--dir", str(other)])
    one_line_error(res, "is a file, not a folder; give a folder")
    ok = runner.invoke(app, ["example", "ji_li_mill_drive.toml", "--dir", str(tmp_path / "d")])
    assert ok.exit_code == 0 and (tmp_path / "d" / "ji_li_mill_drive.toml").exists()
    one_line_error(runner.invoke(app, ["example", "ji_li_mill_drive", "--dir",
                                       str(tmp_path / "d")]), "exists; use --force")


# --------------------------------------------------------------------------- --set
def test_set_errors_name_the_argument_not_the_file(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--set", "meshes.m.stiffness=50 kg"])
    err = one_line_error(res, "error: --set meshes.m.stiffness=50 kg: meshes.m.stiffness: "
                              "'50 kg' is not a stiffness")
    assert str(model) not in err
    res = runner.invoke(app, ["run", str(model), "--set", "meshes.zz.damping_ratio=1"])
    one_line_error(res, "error: --set meshes.zz.damping_ratio=1: 'meshes.zz' does not exist")
    res = runner.invoke(app, ["run", str(model), "--set", "gears.wheel.module=4 mm"])
    one_line_error(res, f"{model} with --set gears.wheel.module=4 mm: meshes.m: gears "
                        f"'pinion' and 'wheel' cannot mesh: modules 2 mm and 4 mm differ")
    res = runner.invoke(app, ["run", str(model), "--set", "gears.pinion.teeth=" + "9" * 5000])
    one_line_error(res, "integer of more than 4300 digits")
    res = runner.invoke(app, ["run", str(model), "--set", "x=" + "[" * 5000])
    one_line_error(res, "nested more than")


# --------------------------------------------------------------------------- stopped runs
def test_a_diverged_run_prints_no_coefficients_but_its_likely_cause(tmp_path):
    """A diverged run printed tables of 1.00000 and advised a smaller step; the cause was
    a 2.2e5 rad static deflection."""
    model = write_model(tmp_path, SOFT_SHAFT)
    res = runner.invoke(app, ["run", str(model), "--cycles", "5", "--quiet"])
    assert res.exit_code == 1, res.output
    assert "stopped" in res.stdout and "diverged" in res.stdout
    assert "likely cause: the static deflection of 'pinion.theta' is 2.2" in res.stdout
    assert "LSC" not in res.stdout and "1.00000" not in res.stdout
    assert "no load-sharing or dynamic-factor table" in res.stdout
    res = runner.invoke(app, ["run", str(model), "--cycles", "5", "--json", "--out",
                              str(tmp_path / "partial.nc")])
    assert res.exit_code == 1
    data = json.loads(res.stdout)
    assert data["success"] is False and data["metrics"] is None
    assert "static deflection" in data["likely_cause"]
    with xr.open_dataset(tmp_path / "partial.nc", engine="h5netcdf") as ds:
        assert int(ds.attrs["status"]) != 0 and "diverged" in ds.attrs["message"]
        # the failure is among the file's warnings too (its metrics are NaN)
        assert any(w.startswith("run: ") and "diverged" in w
                   for w in json.loads(ds.attrs["warnings_json"]))
    # check refuses the model outright: no run of it can succeed
    one_line_error(runner.invoke(app, ["check", str(model)]),
                   "beyond what any run accepts", "check the stiffness values")


def test_a_run_shorter_than_a_mesh_cycle_prints_its_tables_without_a_traceback(tmp_path):
    """A run too short for a whole cycle (its settle time -inf) crashed after its tables
    on the bearing forces, and --json printed nothing (a fuzzer)."""
    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.002 s",
                                   "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["bearing_forces_N"] == [] and out["success"]
    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.002 s"])
    assert res.exit_code == 0 and "Traceback" not in res.output
