"""A closed session's SIGHUP reaches a study's whole process group: the driver stops as
on Ctrl-C (tests/cli/test_interrupts.py), its helpers must not die first."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

CHILD = """
import signal
from multiprocessing import resource_tracker
from torquesplit.study.runners import start_helpers
signal.signal(signal.SIGHUP, signal.SIG_DFL)  # (as in a terminal; nohup ignores it)
start_helpers()
status = open(f"/proc/{resource_tracker._resource_tracker._pid}/status").read()
ignored = int(next(l for l in status.splitlines() if l.startswith("SigIgn:")).split()[1], 16)
print(bool(ignored >> (signal.SIGHUP - 1) & 1), signal.getsignal(signal.SIGHUP) == signal.SIG_DFL)
"""


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc (Linux)")
def test_the_pools_resource_tracker_ignores_sighup_and_the_driver_does_not():
    """A tracker killed by the group's SIGHUP left four tracebacks of leaked semaphores
    under the study's 'stopped' line; the driver keeps its own handling of SIGHUP."""
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["True", "True"], out.stdout + out.stderr


def test_a_ctrl_c_a_case_swallowed_still_stops_a_serial_study():
    """Ctrl-C landing inside compiled code came out of a case as another error (numba's
    '_get_wrapper_address() missing ... sig'); the case recorded it and the study ran on
    to exit 0 (a reliability reviewer, once in 22 tries).  The serial runner notes the
    signal itself: the case's result is dropped and the study stops."""
    import os
    import signal

    from torquesplit.study.runners import SerialRunner

    def case(i):
        if i == 1:
            try:
                os.kill(os.getpid(), signal.SIGINT)
            except KeyboardInterrupt:  # what run_case's 'except Exception' made of it
                return {"index": i, "status": "error"}
        return {"index": i, "status": "ok"}

    got = []
    before = signal.signal(signal.SIGINT, signal.default_int_handler)  # (a terminal's:
    try:  # a background job, CI's, ignores SIGINT)
        with pytest.raises(KeyboardInterrupt):
            for r in SerialRunner()(case, range(4)):
                got.append(r)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
    finally:
        signal.signal(signal.SIGINT, before)
    assert got == [{"index": 0, "status": "ok"}]
    assert [r["index"] for r in SerialRunner()(lambda i: {"index": i}, range(3))] == [0, 1, 2]
