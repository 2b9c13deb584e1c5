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
