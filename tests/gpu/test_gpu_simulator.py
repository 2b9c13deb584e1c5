"""The CUDA code path under numba's CUDA simulator, in a subprocess.

``NUMBA_ENABLE_CUDASIM=1`` changes numba for the whole process it is set in, so the
simulator runs in a child process (``sim_check.py``) and the rest of the suite never
sees it.  The child runs a tiny ensemble (every feature of the generated code, two
patterns, a diverging case, and the Ji & Li drive) through the CUDA kernel — device
functions, thread-local scratch, launch, transfers — and compares every case with the
CPU engine bit for bit (the simulator does the arithmetic of the CPU)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parent / "sim_check.py"
SRC = Path(__file__).resolve().parents[2] / "src"


def test_cuda_kernel_in_the_simulator_equals_the_engine():
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env["PYTHONPATH"] = os.pathsep.join([str(SRC), env.get("PYTHONPATH", "")])
    proc = subprocess.run([sys.executable, str(SCRIPT)], env=env, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "simulator" in report["device"]
    assert report["patterns"] == 3
    assert report["law_binding"] == "device"  # the laws as CUDA device functions
    statuses = [c[1] for c in report["cases"]]
    assert statuses == [0, 0, 1, 0, 0]  # the third case diverges, as in the engine
    for label, _, n_steps, bad in report["cases"]:
        assert n_steps > 0
        assert bad == [], f"{label}: {bad} differ from the CPU engine"
