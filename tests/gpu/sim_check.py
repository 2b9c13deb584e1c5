"""Run in a subprocess with NUMBA_ENABLE_CUDASIM=1 by test_gpu_simulator.py: the CUDA
code path (device functions, thread-local arrays, kernel launch, transfers) in numba's
simulator on a tiny ensemble, compared with the CPU engine field by field.  Prints one
JSON line: {"device": ..., "cases": [[label, status, n_steps, [differing fields]], ...]}.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
sys.path[:0] = [str(here), str(here.parent), str(here.parent / "solve")]


def main() -> None:
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        raise SystemExit("set NUMBA_ENABLE_CUDASIM=1: this script runs the CUDA simulator")
    from gpu_cases import compare, engine, example_run, feature_runs

    from torquesplit.gpu.ensemble import run_ensemble

    runs = feature_runs()
    for r in runs:  # a few hundred steps each: the simulator runs Python per thread
        object.__setattr__(r, "duration", 0.0015)
    runs.append(example_run("ji_li_mill_drive", 1.0e-3))
    res = run_ensemble(runs, target="cuda", threads_per_block=2)
    out = []
    for i, (r, sol) in enumerate(zip(runs, res.solutions, strict=True)):
        ref = engine(r)
        out.append([f"case {i}", ref.status, ref.n_steps, compare(sol, ref)])
    print(json.dumps({"device": res.device, "patterns": res.patterns, "cases": out,
                      "law_binding": res.law_binding}))


if __name__ == "__main__":
    main()
