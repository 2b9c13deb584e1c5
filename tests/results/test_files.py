"""Results files are checked before a run, claimed by one run, and complete or absent
(issue 14, item 1): kills and interrupts during the save, concurrent writers, bad
paths."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from torquesplit.errors import OutputBusyError, OutputError, OutputFormatError
from torquesplit.results import files

SRC = str(Path(files.__file__).resolve().parents[2])


def _child(tmp_path: Path, body: str) -> subprocess.Popen:
    """A Python subprocess running ``body`` (torquesplit importable), stdout piped."""
    script = tmp_path / f"child{time.monotonic_ns()}.py"
    script.write_text(textwrap.dedent(body))
    env = dict(os.environ, PYTHONPATH=SRC)
    return subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, stdin=subprocess.PIPE, text=True, env=env)


def _wait_for(proc: subprocess.Popen, word: str, seconds: float = 60.0) -> None:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if line.strip() == word:
            return
        if not line and proc.poll() is not None:
            break
    proc.kill()
    raise AssertionError(f"child did not say {word!r}: {proc.stderr.read()}")


def _visible(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir()}


# --------------------------------------------------------------------------- checks
def test_a_message_about_a_file_deep_in_folders_names_the_file(tmp_path):
    """A path over 80 characters was cut at its end: 'error: /tmp/.../a_hist... exists'
    hid which file was in the way (pytest-xdist's longer temporary folders showed it)."""
    deep = tmp_path / ("results_of_the_long_campaign_" * 3) / "run_7"
    deep.mkdir(parents=True)
    (deep / "gearbox_history.csv").write_text("x")
    assert len(str(deep / "gearbox_history.csv")) > 100
    with pytest.raises(OutputError) as info:
        files.check_output(deep / "gearbox.csv")
    msg = str(info.value)
    assert "/gearbox_history.csv exists; use --force" in msg and "..." in msg
    assert len(msg.split(" exists")[0]) <= 80


def test_checks_before_any_computation(tmp_path):
    with pytest.raises(OutputFormatError, match=r"use a \.nc, \.mat or \.csv file"):
        files.check_output(tmp_path / "r.xlsx")
    assert issubclass(OutputFormatError, ValueError)
    with pytest.raises(OutputError, match=r"folder .*nowhere does not exist; create it"):
        files.check_output(tmp_path / "nowhere" / "r.nc")
    with pytest.raises(OutputError, match=r"is a folder; give a file name in it"):
        files.check_output(tmp_path)
    (tmp_path / "r.nc").write_bytes(b"old")
    with pytest.raises(OutputError, match=r"r\.nc exists; use --force"):
        files.check_output(tmp_path / "r.nc")
    plan = files.check_output(tmp_path / "r.nc", overwrite=True)
    assert plan.files == (tmp_path / "r.nc",) and plan.format == "netcdf"
    (tmp_path / "a_history.csv").write_text("x")
    with pytest.raises(OutputError, match=r"a_history\.csv exists"):
        files.check_output(tmp_path / "a.csv")
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.nc")
        with pytest.raises(OutputError, match="not a regular file"):
            files.check_output(tmp_path / "pipe.nc", overwrite=True)


def test_unwritable_folder(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        if os.access(folder, os.W_OK):
            pytest.skip("running as a user who writes anywhere")
        with pytest.raises(OutputError, match="permission denied"):
            files.check_output(folder / "r.nc")
    finally:
        folder.chmod(0o700)


# --------------------------------------------------------------------------- atomic writes
@pytest.fixture(params=[True, False], ids=["O_TMPFILE", "named temporary"])
def tmpfile_mode(request, monkeypatch):
    if request.param and not files.USE_O_TMPFILE:
        pytest.skip("no O_TMPFILE here")
    monkeypatch.setattr(files, "USE_O_TMPFILE", request.param)
    return request.param


def test_write_replaces_only_when_asked_and_leaves_nothing_else(tmp_path, tmpfile_mode):
    target = tmp_path / "r.nc"
    files.write_atomically(target, b"first")
    with pytest.raises(OutputError, match="exists"):
        files.write_atomically(target, b"second")
    files.write_atomically(target, b"second", overwrite=True)
    assert target.read_bytes() == b"second"
    assert _visible(tmp_path) == {"r.nc"}  # no lock or temporary left


def test_a_file_that_appears_meanwhile_is_not_overwritten(tmp_path, tmpfile_mode):
    target = tmp_path / "r.nc"
    plan = files.check_output(target)
    with files.claim_output(plan) as claim:
        target.write_bytes(b"another program's")
        with pytest.raises(OutputError, match="written by another program or run meanwhile"):
            claim.write({target: b"ours"})
    assert target.read_bytes() == b"another program's"


def test_interrupt_during_the_save_keeps_the_previous_file(tmp_path, tmpfile_mode, monkeypatch):
    """Ctrl-C during the save left a file with 3 of 12 variables."""
    target = tmp_path / "r.nc"
    files.write_atomically(target, b"previous complete file")

    def half_then_interrupt(fd, data):
        os.write(fd, data[: len(data) // 2])
        raise KeyboardInterrupt

    monkeypatch.setattr(files, "_write_all", half_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        files.write_atomically(target, b"new data " * 1000, overwrite=True)
    assert target.read_bytes() == b"previous complete file"
    assert _visible(tmp_path) == {"r.nc"}


@pytest.mark.parametrize("o_tmpfile", [True, False], ids=["O_TMPFILE", "named temporary"])
def test_sigkill_during_the_save_keeps_the_previous_file(tmp_path, o_tmpfile):
    """SIGKILL during the save replaced a good file with a 96-byte unreadable stub."""
    if o_tmpfile and not files.USE_O_TMPFILE:
        pytest.skip("no O_TMPFILE here")
    target = tmp_path / "r.nc"
    files.write_atomically(target, b"previous complete file")
    proc = _child(tmp_path, f"""
        import os, sys, time
        from torquesplit.results import files
        files.USE_O_TMPFILE = {o_tmpfile}
        def half_then_wait(fd, data):  # a slow disk: half written, then the kill
            os.write(fd, data[: len(data) // 2])
            print("HALF", flush=True)
            time.sleep(600)
        files._write_all = half_then_wait
        files.write_atomically({str(target)!r}, b"new " * 10**6, overwrite=True)
    """)
    _wait_for(proc, "HALF")
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert target.read_bytes() == b"previous complete file"
    left = _visible(tmp_path) - {"r.nc"} - {p.name for p in tmp_path.glob("child*.py")}
    if o_tmpfile:
        assert left == {".r.nc.lock"}  # the unnamed temporary vanished with the process
    else:
        assert {n for n in left if n.endswith(".tmp")}, left  # a hidden temporary...
    # ... which the next writer of r.nc removes; the dead writer's lock is free
    files.write_atomically(target, b"next", overwrite=True)
    assert target.read_bytes() == b"next"
    assert _visible(tmp_path) - {p.name for p in tmp_path.glob("child*.py")} == {"r.nc"}


# --------------------------------------------------------------------------- two writers
def test_a_second_writer_is_refused_at_once_naming_the_first(tmp_path):
    target = tmp_path / "r.nc"
    holder = _child(tmp_path, f"""
        import sys
        from torquesplit.results import files
        plan = files.check_output({str(target)!r})
        with files.claim_output(plan, run_id="first-run") as claim:
            print("CLAIMED", flush=True)
            sys.stdin.readline()  # computing...
            claim.write({{plan.path: b"first"}})
        print("WROTE", flush=True)
    """)
    _wait_for(holder, "CLAIMED")
    plan = files.check_output(target)
    with pytest.raises(OutputBusyError, match=rf"is being written by another torquesplit run "
                                              rf"\(pid {holder.pid}, run first-run, since "):
        with files.claim_output(plan):
            pass
    holder.stdin.write("go\n")
    holder.stdin.flush()
    _wait_for(holder, "WROTE")
    holder.wait()
    assert target.read_bytes() == b"first"
    with pytest.raises(OutputError, match="exists"):
        files.check_output(target)


def test_a_killed_claim_holder_leaves_no_stale_lock(tmp_path):
    target = tmp_path / "r.nc"
    holder = _child(tmp_path, f"""
        import time
        from torquesplit.results import files
        with files.claim_output(files.check_output({str(target)!r})):
            print("CLAIMED", flush=True)
            time.sleep(600)
    """)
    _wait_for(holder, "CLAIMED")
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    files.write_atomically(target, b"mine")
    assert target.read_bytes() == b"mine"


def test_two_racing_writers_exactly_one_wins(tmp_path):
    target = tmp_path / "r.nc"
    go = tmp_path / "go"
    body = """
        import os, sys, time
        from torquesplit.errors import OutputError
        from torquesplit.results import files
        while not os.path.exists({go!r}):
            time.sleep(0.001)
        try:
            files.write_atomically({target!r}, b"written by " + sys.argv[0].encode())
        except OutputError as exc:
            print("REFUSED", exc, flush=True)
            sys.exit(2)
        print("WON", flush=True)
    """.format(go=str(go), target=str(target))
    writers = [_child(tmp_path, body) for _ in range(2)]
    time.sleep(0.5)
    go.write_text("")
    outs = [w.communicate(timeout=60)[0] for w in writers]
    codes = sorted(w.returncode for w in writers)
    assert codes == [0, 2], (codes, outs)
    winner = next(w for w, o in zip(writers, outs) if o.startswith("WON"))
    loser = next(o for o in outs if o.startswith("REFUSED"))
    assert ("being written by another torquesplit run" in loser or "exists" in loser
            or "meanwhile" in loser), loser
    assert target.read_bytes() == b"written by " + winner.args[1].encode()
