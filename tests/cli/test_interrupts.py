"""Ctrl-C: one line and status 130 wherever it lands, and a speed sweep keeps its curve."""

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from torquesplit import cli_support as ux
from torquesplit.cli import app


def _chained_interrupt():
    """What numba raises when Ctrl-C lands inside compiled code (seen in 'contact')."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as inner:
            raise SystemError("_numba_unpickle returned a result with an exception set") from inner
    except SystemError as middle:
        raise SystemError("CPUDispatcher(ltca_solve) returned a result with an exception "
                          "set") from middle


def test_an_interrupt_inside_compiled_code_is_an_interrupt():
    with pytest.raises(typer.Exit) as info:
        with ux.interruptible():
            _chained_interrupt()
    assert info.value.exit_code == 130
    with pytest.raises(SystemError, match="unrelated"):  # any other SystemError is a bug
        with ux.interruptible():
            raise SystemError("unrelated")


def test_contact_refuses_more_positions_than_the_model_file_allows():
    """--positions 100000 ran for minutes without an estimate, and segfaulted on Ctrl-C."""
    res = CliRunner().invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11",
                                   "--positions", "100000"])
    assert res.exit_code == 2 and "--positions 100000 is more than 4096" in res.stderr


def _interrupt_sweep_at_point(monkeypatch, n: int) -> None:
    """Ctrl-C as the shooting continuation computes the multipliers of its n-th point."""
    from torquesplit.steady import sweep as S

    calls = {"n": 0}
    real = S.ShootingContinuation.multipliers

    def interrupt(self, x, s):
        calls["n"] += 1
        if calls["n"] == n:
            raise KeyboardInterrupt
        return real(self, x, s)

    monkeypatch.setattr(S.ShootingContinuation, "multipliers", interrupt)


def test_an_interrupted_speed_sweep_keeps_its_curve(monkeypatch):
    """Ctrl-C during 'sweep-speed' exited 130 and wrote nothing; other stops keep the curve."""
    _interrupt_sweep_at_point(monkeypatch, 3)
    from torquesplit import example_path
    from torquesplit.steady.maps import sweep_speed

    ds = sweep_speed(example_path("ji_li_mill_drive"), 300 * 0.10472, 1500 * 0.10472,
                     points=30)
    assert ds.sizes["point"] == 2 and not ds.attrs["complete"]
    assert ds.attrs["message"].startswith("interrupted (Ctrl-C) after 2 points")


def test_a_speed_sweep_interrupted_before_its_first_point_stops(monkeypatch):
    """Ctrl-C before the first point (while the kernels compiled) gave an empty curve
    whose checks then called a half-built kernel (numba's RuntimeError, a traceback), or
    exited 130 without a word: there is nothing to keep, so the interrupt propagates and
    the command says so in one line."""
    _interrupt_sweep_at_point(monkeypatch, 1)
    from torquesplit import example_path
    from torquesplit.steady.maps import sweep_speed

    with pytest.raises(KeyboardInterrupt):
        sweep_speed(example_path("ji_li_mill_drive"), 300 * 0.10472, 1500 * 0.10472,
                    points=30)
    _interrupt_sweep_at_point(monkeypatch, 1)  # (a counter of its own)
    res = CliRunner().invoke(app, ["sweep-speed", "ji_li_mill_drive", "--from", "300 rpm",
                                   "--to", "1500 rpm", "--points", "30"])
    assert res.exit_code == 130, res.output
    assert res.stderr.strip().splitlines()[-1] == "interrupted; nothing written"


def _interrupting_progress(at: float):
    def progress(fraction):
        if fraction >= at:
            raise KeyboardInterrupt
    return progress


def test_an_interrupted_run_is_a_stopped_run_inside_stop_on_interrupt():
    """'run' threw away everything on Ctrl-C ('interrupted; nothing written'); inside
    stop_on_interrupt the run ends as a stopped one that keeps what it recorded.  Outside
    it (studies) the interrupt propagates as before."""
    import torquesplit
    from torquesplit.solve.integrate import INTERRUPTED, stop_on_interrupt

    model = torquesplit.load_model("ji_li_mill_drive")
    with stop_on_interrupt():
        res = torquesplit.simulate(model, duration=0.2, progress=_interrupting_progress(0.3))
    s = res.solution
    assert s.status == INTERRUPTED and not res.success
    assert res.message.startswith("Interrupted (Ctrl-C) at t = ")
    assert 0.05 < s.t_final < 0.2 and s.history_t.size > 0 and s.history_t[-1] <= s.t_final
    with pytest.raises(KeyboardInterrupt):
        torquesplit.simulate(model, duration=0.2, progress=_interrupting_progress(0.3))


def test_the_run_command_saves_what_it_computed_when_interrupted(tmp_path, monkeypatch):
    import contextlib

    @contextlib.contextmanager
    def progress(label, quiet, total=1.0):
        yield _interrupting_progress(0.3)

    monkeypatch.setattr(ux, "progress", progress)
    out = tmp_path / "r.nc"
    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.2",
                                   "--out", str(out)])
    assert res.exit_code == 130, res.output
    assert "Interrupted (Ctrl-C)" in res.stdout and out.exists()
    # --force over an earlier run's results: those are kept, the partial ones go beside
    # them (a reliability reviewer's complete file was replaced by a partial one)
    before = out.read_bytes()
    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.2",
                                   "--out", str(out), "--force"])
    assert res.exit_code == 130, res.output
    assert out.read_bytes() == before
    assert f"this run's partial results are in {tmp_path / 'r.partial.nc'}" in " ".join(
        res.stderr.split())
    assert f"are in {tmp_path / 'r.partial.nc'}" in " ".join(res.stdout.split())
    assert (tmp_path / "r.partial.nc").is_file()


def test_an_interrupted_static_sweep_keeps_the_positions_done(tmp_path, monkeypatch):
    """'static' threw its sweep away on Ctrl-C (a minute on some examples); it now ends
    with the positions done: tables, a warning that says how many, the file, status 130."""
    import contextlib

    import xarray as xr

    @contextlib.contextmanager
    def progress(label, quiet, total=1.0):
        yield _interrupting_progress(0.5)

    monkeypatch.setattr(ux, "progress", progress)
    out = tmp_path / "s.nc"
    res = CliRunner().invoke(app, ["static", "ji_li_mill_drive", "--revolutions", "0.2",
                                   "--out", str(out)])
    assert res.exit_code == 130, res.output
    assert "quasi-static load sharing" in res.stdout and "stopped by Ctrl-C" in res.stdout
    assert f"interrupted; results kept in {out}" in res.stderr
    ds = xr.open_dataset(out)
    n = ds.sizes["time"]
    assert 0 < n and f"stopped by Ctrl-C after {n} of " in ds.attrs["warnings"]
    ds.close()


def test_a_static_sweep_interrupted_before_its_first_position_or_outside_the_context():
    import torquesplit
    from torquesplit.solve.integrate import stop_on_interrupt

    model = torquesplit.load_model("ji_li_mill_drive")
    with pytest.raises(KeyboardInterrupt):  # outside stop_on_interrupt: as before
        torquesplit.quasi_static_load_sharing(model, revolutions=0.2,
                                              progress=_interrupting_progress(0.5))
    with stop_on_interrupt(), pytest.raises(KeyboardInterrupt):  # nothing done to keep
        torquesplit.quasi_static_load_sharing(model, revolutions=0.2,
                                              progress=_interrupting_progress(0.0))
    with stop_on_interrupt():
        res = torquesplit.quasi_static_load_sharing(model, revolutions=0.2,
                                                    progress=_interrupting_progress(0.5))
    sol = res.solution
    assert sol.interrupted and 0 < sol.times.size < sol.planned
    assert sol.q.shape[0] == sol.element_forces.shape[0] == sol.times.size
    assert any("stopped by Ctrl-C" in w for w in res.warnings())


@pytest.mark.parametrize("command", ["run", "static"])
def test_a_ctrl_c_while_results_are_written_keeps_them(command, tmp_path, monkeypatch):
    """A Ctrl-C after the computation, while the results were being saved, lost them all
    ('interrupted; nothing written'): now the file is finished first."""
    import os
    import signal

    import torquesplit.quasistatic as qs
    import torquesplit.results as rs
    from model_texts import SPUR_PAIR, write_model

    cls = rs.Results if command == "run" else qs.QuasiStaticResults
    save = cls.save

    def interrupted_save(self, *a, **k):
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C lands as the file is written
        return save(self, *a, **k)

    monkeypatch.setattr(cls, "save", interrupted_save)
    # Ctrl-C as at a terminal (a background job, e.g. CI started with '&', ignores it)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    out = tmp_path / "r.csv"
    args = [command, str(write_model(tmp_path, SPUR_PAIR)), "--out", str(out), "--quiet"]
    args += ["--cycles", "30"] if command == "run" else ["--points-per-cycle", "2"]
    try:
        res = CliRunner().invoke(app, args)
        assert res.exit_code == 130, res.output
        assert f"interrupted; results kept in {out}" in res.stderr and out.exists()
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, before)


def test_finishing_before_an_interrupt_leaves_an_ignored_sigint_alone():
    """A job started with SIGINT ignored (nohup, a script's background job) became
    interruptible inside the block."""
    import signal

    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with ux.finish_before_interrupt():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_sweep_that_stopped_says_its_largest_factor_is_of_the_part_computed(monkeypatch):
    """A reviewer's sweep stopped at 9498 of 9000-11000 rpm and headed 'largest dynamic
    factor ... 1.86' where its run-up found 2.95 beyond the stop."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    _interrupt_sweep_at_point(monkeypatch, 4)
    res = CliRunner().invoke(app, ["sweep-speed", "ji_li_mill_drive", "--from", "300 rpm",
                                   "--to", "1500 rpm", "--points", "30"])
    text = " ".join(res.output.split())
    assert "over the part computed (300-" in text and "of 300 rpm-1500 rpm: the sweep stopped" \
        in text, text


def test_ctrl_c_while_the_command_line_loads_is_one_line(monkeypatch, capsys):
    """Ctrl-C in the first half second (numpy, numba, pydantic loading) printed a 30-line
    traceback from inside an import (a fuzzer); the entry point says it in one line."""
    import sys
    import types

    from torquesplit import _launch

    class Loading(types.ModuleType):
        def __getattr__(self, name):
            raise KeyboardInterrupt

    monkeypatch.setitem(sys.modules, "torquesplit.cli", Loading("torquesplit.cli"))
    with pytest.raises(SystemExit) as exc:
        _launch.main()
    assert exc.value.code == 130
    assert capsys.readouterr().err == "interrupted; nothing written\n"


@pytest.mark.parametrize("args, target", [
    (["steady", "ji_li_mill_drive", "--keep", "stage1"], "steady"),
    (["mesh", "ji_li_mill_drive", "--pair", "m11"], "mesh"),
])
def test_ctrl_c_in_steady_and_mesh_says_so(args, target, monkeypatch):
    """Both exited 130 without a word (stderr a file: a fuzzer)."""
    from typer.testing import CliRunner

    import torquesplit.gears.stiffness as stiffness
    import torquesplit.steady.api as api
    from torquesplit.cli import app

    def interrupt(*a, **k):
        raise KeyboardInterrupt

    if target == "steady":
        monkeypatch.setattr(api, "steady_state", interrupt)
    else:
        monkeypatch.setattr(stiffness, "compare_methods", interrupt)
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 130 and "interrupted; nothing written" in res.output


def test_the_entry_point_loads_nothing_heavy_before_its_guard():
    """The guard of _launch.main covers the heavy imports only if 'import torquesplit'
    itself does not make them (it loaded pydantic, numpy and numba: a code review)."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", "import sys, torquesplit._launch; print("
                          "sorted(m for m in ('pydantic', 'numpy', 'numba', 'xarray') "
                          "if m in sys.modules))"], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout


def test_python_dash_m_torquesplit_is_the_command():
    """'python -m torquesplit' said 'is a package and cannot be directly executed'."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "torquesplit", "--version"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.startswith("torquesplit ")


def test_modes_interrupted_while_saving_or_plotting_says_so(tmp_path, monkeypatch):
    """'modes' exited 130 without a word when Ctrl-C landed in its save, and 'modes
    --campbell' too, also after its map's file was written (which it did not name)."""
    import torquesplit.results.export as export
    import torquesplit.steady.plot as plot

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(export, "save_dataset", interrupted)
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--out",
                                   str(tmp_path / "m.nc")])
    assert res.exit_code == 130, res.output
    assert res.stderr.strip().splitlines()[-1] == "interrupted; nothing written"
    monkeypatch.undo()  # (the map's file is saved; its figure is interrupted)
    monkeypatch.setattr(plot, "save", interrupted)
    out = tmp_path / "c.nc"
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--campbell", "--from",
                                   "500 rpm", "--to", "3000 rpm", "--out", str(out),
                                   "--plot", str(tmp_path / "c.png")])
    assert res.exit_code == 130, res.output
    last = res.stderr.strip().splitlines()[-1]
    assert last == f"interrupted; kept {out}; the figure is incomplete" and out.exists()


def test_contact_interrupted_while_writing_figures_names_its_results(tmp_path, monkeypatch):
    """'contact --out --plot' interrupted during its figures said 'nothing written'
    though its results file was complete (a reviewer)."""
    import torquesplit.plot.contact as contact

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(contact, "write_contact_figures", interrupted)
    out = tmp_path / "k.nc"
    res = CliRunner().invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11", "--out",
                                   str(out), "--plot", str(tmp_path / "figs")])
    assert res.exit_code == 130, res.output
    last = res.stderr.strip().splitlines()[-1]
    assert last == f"interrupted; results kept in {out}; figures incomplete" and out.exists()


def test_steady_interrupted_after_its_solve_says_what_it_kept(tmp_path, monkeypatch):
    """'steady --out --check-step': a Ctrl-C in the step check said 'nothing written'
    with the results file complete, and one before the save exited 130 without a word
    (a reviewer)."""
    import torquesplit.convergence as convergence
    import torquesplit.results.plausibility as plausibility

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(convergence, "check_steady", interrupted)
    out = tmp_path / "a.nc"
    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--out", str(out),
                                   "--check-step"])
    assert res.exit_code == 130, res.output
    assert res.stderr.strip().splitlines()[-1] == f"interrupted; results kept in {out}"
    monkeypatch.setattr(plausibility, "result_warnings", interrupted)
    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--out",
                                   str(tmp_path / "b.nc")])
    assert res.exit_code == 130, res.output
    assert res.stderr.strip().splitlines()[-1] == "interrupted; nothing written"


def _last_words(text: str, expected: str) -> bool:
    """Whether ``text`` ends with ``expected``, whatever the console's line breaks."""
    return "".join(text.split()).endswith("".join(expected.split()))


SWEEP = ["sweep-speed", "ji_li_mill_drive", "--from", "300 rpm", "--to", "1500 rpm",
         "--points", "30", "--quiet"]
SHORT_SWEEP = SWEEP[:5] + ["400 rpm", "--points", "4", "--quiet"]


def _sigint_on_call(monkeypatch, owner, name: str) -> None:
    """A real Ctrl-C (SIGINT to this process) as ``owner.name`` is first called."""
    import os
    import signal

    real, calls = getattr(owner, name), []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)
        return real(*args, **kwargs)

    monkeypatch.setattr(owner, name, interrupted)


@pytest.fixture
def terminal_sigint():
    """Ctrl-C as at a terminal (a background job, e.g. CI started with '&', ignores it)."""
    import signal

    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def test_a_sweep_interrupted_part_way_exits_130_after_keeping_its_curve(tmp_path,
                                                                       monkeypatch):
    """A sweep stopped by Ctrl-C part-way exited 1, as a sweep that failed; it now writes
    and prints the curve computed, then exits 130 naming the file."""
    _interrupt_sweep_at_point(monkeypatch, 4)
    res = CliRunner().invoke(app, SWEEP)
    assert res.exit_code == 130, res.output
    assert "interrupted (Ctrl-C) after 3 points" in " ".join(res.output.split())
    # (it said 'the curve computed is printed above', where only its maxima are)
    assert " ".join(res.stderr.split()).endswith(
        "interrupted; nothing written: the curve's 3 points are kept only by --out (their "
        "largest dynamic factors are printed above; --json prints every point)")
    _interrupt_sweep_at_point(monkeypatch, 4)
    res = CliRunner().invoke(app, SWEEP + ["--json"])
    assert res.exit_code == 130, res.output
    import json

    curve = json.loads(res.stdout)["curve"]
    assert len(curve["speed_rpm"]) == 3 and all(len(v) == 3
                                                for v in curve["dynamic_factor"].values())
    _interrupt_sweep_at_point(monkeypatch, 4)
    out = tmp_path / "curve.csv"
    res = CliRunner().invoke(app, SWEEP + ["--out", str(out)])
    assert res.exit_code == 130, res.output
    assert _last_words(res.stderr, f"interrupted; results kept in {out}, "
                       f"{tmp_path / 'curve_about.json'}")
    assert out.exists()


def test_a_sweep_interrupted_in_the_check_of_its_peaks_exits_130(monkeypatch):
    """Ctrl-C in the check of the peaks' digits (inside compiled code: a SystemError
    chained from the interrupt) printed the table and exited 0, as a finished check."""
    import torquesplit.steady.api as api

    def interrupted(*args, **kwargs):
        _chained_interrupt()

    monkeypatch.setattr(api, "steady_state", interrupted)
    res = CliRunner().invoke(app, SHORT_SWEEP)
    assert res.exit_code == 130, res.output
    text = " ".join(res.output.split())
    assert "the check of the peaks' digits was interrupted" in text
    assert "largest dynamic factor over the stable points" in text


def test_a_ctrl_c_as_the_sweep_finishes_its_curve_keeps_the_curve(monkeypatch,
                                                                  terminal_sigint):
    """A Ctrl-C after the continuation, while the curve's metrics were computed, lost the
    whole curve ('interrupted; nothing written'); it now waits for the curve's metrics,
    and one in the cross-check keeps the curve without it."""
    from torquesplit import example_path
    from torquesplit.steady import maps

    _sigint_on_call(monkeypatch, maps, "shooting_point_metrics")
    ds = maps.sweep_speed(example_path("ji_li_mill_drive"), 300 * 0.10472, 400 * 0.10472,
                          points=4, cross_check=True)
    assert ds.attrs["complete"] and "check_speed_rpm" not in ds.coords
    assert ds.attrs["message"].startswith(
        "interrupted (Ctrl-C) once the curve's %d points were computed; the curve is kept "
        "(the cross-check not run)" % ds.sizes["point"])
    assert ds.sizes["point"] >= 3 and np.isfinite(ds["dynamic_factor"].values).all()
    monkeypatch.undo()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(maps, "stepped_sweep", interrupted)
    ds = maps.sweep_speed(example_path("ji_li_mill_drive"), 300 * 0.10472, 400 * 0.10472,
                          points=4, cross_check=True)
    assert ds.attrs["message"].startswith("interrupted (Ctrl-C) in the run-up and run-down")
    assert ds.attrs["complete"] and "run_up_dynamic_factor" not in ds


def test_a_ctrl_c_while_the_sweep_is_written_finishes_its_files(tmp_path, monkeypatch,
                                                               terminal_sigint):
    """A Ctrl-C while the curve's files were written left them half-written and said
    nothing of them."""
    import torquesplit.steady.plot as plot

    _sigint_on_call(monkeypatch, plot, "sweep_figure")
    out, fig = tmp_path / "curve.nc", tmp_path / "curve.png"
    res = CliRunner().invoke(app, SHORT_SWEEP + ["--out", str(out), "--plot", str(fig)])
    assert res.exit_code == 130, res.output
    assert _last_words(res.stderr, f"interrupted; results kept in {out}, {fig}")
    assert out.exists() and fig.stat().st_size > 1000


def test_an_interrupted_sweep_with_a_cross_check_keeps_its_curve(monkeypatch):
    """With --cross-check, a Ctrl-C part-way through the continuation still ran the whole
    run-up and run-down (minutes), and one in the cross-check ended in a traceback
    (KeyError 'run_up'), exit 1, with the files written but not named (a reviewer)."""
    from torquesplit.steady import maps

    called = []
    real = maps.stepped_sweep

    def counted(*args, **kwargs):
        called.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(maps, "stepped_sweep", counted)
    _interrupt_sweep_at_point(monkeypatch, 3)
    res = CliRunner().invoke(app, SWEEP + ["--cross-check"])
    assert res.exit_code == 130, res.output
    assert not called
    monkeypatch.undo()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(maps, "stepped_sweep", interrupted)
    res = CliRunner().invoke(app, SHORT_SWEEP + ["--cross-check"])
    assert res.exit_code == 130, res.output
    text = " ".join(res.output.split())
    assert "interrupted (Ctrl-C) in the run-up and run-down cross-check" in text
    assert "largest dynamic factor" in text and "run-up DF" not in text


def test_sigterm_and_sighup_are_ctrl_c_with_their_own_exit_code():
    """The handler: the SIGINT handler in force is called (a block that holds Ctrl-C
    holds these too), the messages name the signal, the exit code is the shell's."""
    import os
    import signal

    from torquesplit import _launch
    from torquesplit.errors import STOP_SIGNAL, held_interrupt, interrupt_name

    before = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)}
    try:
        for s in before:
            signal.signal(s, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)  # (a terminal's)
        _launch._handle_stop_signals()
        assert interrupt_name() == "Ctrl-C" and _launch._exit_code(130) == 130
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGHUP)
        assert interrupt_name() == "SIGHUP" and _launch._exit_code(130) == 129
        assert _launch._exit_code(1) == 1
        with held_interrupt() as held:  # held, as a Ctrl-C is
            os.kill(os.getpid(), signal.SIGTERM)
        assert held.hit and _launch._exit_code(130) == 143
        # a background job ignores SIGINT: SIGTERM stops it all the same
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGTERM)
        with held_interrupt() as held:  # and waits while a file is finished
            os.kill(os.getpid(), signal.SIGTERM)
        assert held.hit
        with pytest.raises(KeyboardInterrupt), held_interrupt():  # a second one: at once
            os.kill(os.getpid(), signal.SIGTERM)
            os.kill(os.getpid(), signal.SIGTERM)
        signal.signal(signal.SIGHUP, signal.SIG_IGN)  # (nohup's choice is left alone)
        _launch._handle_stop_signals()
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
    finally:
        STOP_SIGNAL[0] = 0  # (this process's later tests: no signal came)
        for s, h in before.items():
            signal.signal(s, h)


def test_sigterm_stops_a_run_as_ctrl_c_does(tmp_path):
    """A batch system's time limit (SIGTERM) or a closed ssh session (SIGHUP) killed a
    run with nothing written and its output's lock left behind (a reliability
    reviewer): they now stop it as Ctrl-C does, its partial results kept, with the
    shell's code of the signal."""
    import signal
    import subprocess
    import sys

    import xarray as xr

    out = tmp_path / "h.nc"
    command = [sys.executable, "-m", "torquesplit", "run", "ji_li_mill_drive"]
    # (the kernels compiled or loaded first: the signal is to land in the integration)
    subprocess.run(command + ["--duration", "0.01", "--quiet"], capture_output=True,
                   check=True, cwd=tmp_path)
    proc = subprocess.Popen(  # (a run of minutes: the signal comes long before its end)
        [sys.executable, "-m", "torquesplit", "run", "ji_li_mill_drive", "--set",
         "analysis.duration=1200", "--samples-per-period", "2", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    err = []
    for line in proc.stderr:  # the run's size, said just before it integrates
        err.append(line)
        if "this run takes" in line:
            break
    import time

    time.sleep(5.0)  # (set-up after that line: about a second)
    proc.send_signal(signal.SIGTERM)
    stdout, rest = proc.communicate(timeout=120)
    assert proc.returncode == 143, "".join(err) + rest + stdout
    assert "Interrupted (SIGTERM) at t =" in stdout, "".join(err) + rest + stdout
    assert not list(tmp_path.glob(".*.lock"))
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["message"].startswith("Interrupted (SIGTERM)")


def test_steady_interrupted_in_its_stability_keeps_the_converged_state(tmp_path,
                                                                      monkeypatch):
    """Ctrl-C while the Floquet multipliers were computed threw the converged periodic
    state away ('interrupted; nothing written', after the stability's seconds: a
    reliability reviewer).  The state is printed and written, its stability 'not
    computed', and the command stops with 130; Python gets a KeyboardInterrupt that
    holds it."""
    import torquesplit
    import torquesplit.steady.solution as solution
    from torquesplit.errors import SteadyInterrupted

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(solution, "floquet_monodromy", interrupted)
    out = tmp_path / "s.nc"
    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--out", str(out)])
    assert res.exit_code == 130, res.output
    assert "stability: not computed (interrupted by Ctrl-C while the Floquet multipliers " \
           "were computed)" in " ".join(res.stdout.split())
    assert "meshes (periodic steady state)" in res.stdout and out.exists()
    assert res.stderr.strip().splitlines()[-1] == f"interrupted; results kept in {out}"
    with pytest.raises(SteadyInterrupted) as stopped:
        torquesplit.steady_state("ji_li_mill_drive")
    assert isinstance(stopped.value, KeyboardInterrupt)
    st = stopped.value.steady
    assert st.solution.converged and st.solution.multipliers is None
    assert st.solution.stability_method == "interrupted"


def test_a_run_whose_step_check_is_interrupted_prints_its_tables_and_says_so(tmp_path,
                                                                            monkeypatch):
    """Ctrl-C in the second run of --check-step said only 'interrupted; results kept in
    cs.nc' (a reliability reviewer): the run's tables are printed, and that its digits
    were not checked."""
    import torquesplit.convergence as convergence

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(convergence, "check_step", interrupted)
    out = tmp_path / "cs.nc"
    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.3",
                                   "--check-step", "--out", str(out)])
    assert res.exit_code == 130, res.output
    assert "load sharing" in res.stdout and out.exists()
    said = " ".join(res.stderr.split())
    assert "warning: the step check (--check-step) was interrupted (Ctrl-C): the tables " \
           "are the run's, complete, their digits not checked" in said
    assert said.endswith(f"interrupted; results kept in {out}")


def test_a_long_command_logs_its_progress_where_no_bar_draws():
    """A run piped or in a batch job printed nothing for its whole length (a reliability
    reviewer): a line at most every LOG_EVERY seconds, the first after that long."""
    import io

    from rich.console import Console

    buf = io.StringIO()
    con = Console(file=buf, force_terminal=False, width=200)
    now = [0.0]
    update = ux._progress_lines(con, "integrating", 1.0, clock=lambda: now[0])
    for t, f in ((1.0, 0.01), (ux.LOG_EVERY - 1, 0.2), (ux.LOG_EVERY + 1, 0.31),
                 (ux.LOG_EVERY + 5, 0.35), (2 * ux.LOG_EVERY + 2, 0.62)):
        now[0] = t
        update(f)
    assert buf.getvalue().splitlines() == [
        f"integrating: 31 %, 0:00:{int(ux.LOG_EVERY) + 1} elapsed",
        f"integrating: 62 %, 0:01:0{2 * int(ux.LOG_EVERY) + 2 - 60} elapsed"]
    spin = ux._progress_lines(con, "steady state", None, clock=lambda: now[0])
    now[0] += ux.LOG_EVERY
    spin(None, "Newton")
    assert buf.getvalue().splitlines()[-1] == "steady state: Newton: 0:00:30 elapsed"
