"""Compile time of the kernels, cold (empty numba cache) and cached, in fresh processes.

:func:`measure` runs this file as a child process with ``NUMBA_CACHE_DIR`` set to a new
temporary directory: twice with an empty cache, where the child compiles every kernel
(cold compile; the faster is kept), then once loading the last one's cache.  The
project's own cache (``src/torquesplit/solve/__pycache__``) is neither used nor touched.

Each child prints one JSON line with, in seconds:

* ``import``  -- ``import torquesplit.solve.integrate`` (numpy, numba, the kernel module);
* ``compile`` -- ``compile_kernels(("rk4",))``: the kernels of the default method, what
  a first ``torquesplit run`` waits for (the number ``Solution.compile_time`` reports);
* ``compile_cpu`` -- CPU seconds of that compilation (less than the wall time when other
  processes load the machine);
* ``compile_dopri`` -- then ``compile_kernels(("dopri",))``: the Dormand-Prince kernels,
  compiled on the first adaptive run; ``compile + compile_dopri`` is every kernel;
* ``kernels`` -- numba's own compile timers per kernel (inclusive of its callees);
* ``first_run`` -- then assembling the Ji & Li mill drive and integrating 1000 RK4 steps;
* ``total`` -- wall time from the start of the child to the end of that first run
  (the interpreter start-up itself excluded).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _child() -> None:
    t0 = time.perf_counter()
    import warnings

    from torquesplit.solve.integrate import compile_kernels, integrate

    t1 = time.perf_counter()
    c1 = time.process_time()
    compile_time = compile_kernels(("rk4",))
    t2 = time.perf_counter()
    compile_cpu = time.process_time() - c1
    compile_dopri = compile_kernels(("dopri",))
    t_dopri_end = time.perf_counter()
    import torquesplit
    from torquesplit.solve.static import static_equilibrium

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", torquesplit.ModelWarning)
        model = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    s = torquesplit.assemble(model)
    st = static_equilibrium(s)
    h = 1.0 / (100 * s.frequency.max())
    integrate(s, st.y0, (0.0, 1000 * h), method="rk4", steps_per_period=100,
                    record_every=100)
    t3 = time.perf_counter()
    from numba.core import config

    print(json.dumps({"import_": t1 - t0, "compile": t2 - t1, "compile_cpu": compile_cpu,
                          "compile_dopri": compile_dopri,
                          "compile_reported": compile_time, "first_run": t3 - t_dopri_end,
                          "total": t3 - t0,
                          "cache_dir": config.CACHE_DIR, "kernels": _kernel_timers()}))


def _kernel_timers() -> dict:
    """Per kernel: numba's compile timers (inclusive of the kernels it calls), seconds.

    ``compiler_lock`` is the whole compilation, ``llvm_lock`` its LLVM part; both are 0
    for a kernel loaded from the cache.
    """
    from numba.core.registry import CPUDispatcher

    from torquesplit.solve import _kernels

    out = {}
    for name, obj in vars(_kernels).items():
        if isinstance(obj, CPUDispatcher):
            tot = llvm = 0.0
            for cres in obj.overloads.values():
                timers = (cres.metadata or {}).get("timers", {})
                tot += timers.get("compiler_lock", 0.0)
                llvm += timers.get("llvm_lock", 0.0)
            out[name] = {"n_signatures": len(obj.overloads), "compile": tot, "llvm": llvm}
    return out


def run_child(cache_dir: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child"],
                         env=env, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"compile-time child failed:\n{out.stderr}")
    data = json.loads(out.stdout.strip().splitlines()[-1])
    data["import"] = data.pop("import_")
    return data


def measure(repeat: int = 2) -> dict:
    """{"cold": {...}, "cached": {...}, "cold_runs": [...]}: ``repeat`` cold children,
    each with a new empty cache (the one with the fastest RK4 compilation is "cold", as
    the other benchmarks keep their best run: on a shared 2-core VM one cold compilation
    varies by 10-20 %), then a child that loads the last child's cache."""
    runs = []
    with tempfile.TemporaryDirectory(prefix="torquesplit-numba-cache-") as tmp:
        for i in range(max(1, repeat)):
            cache = Path(tmp) / f"cold{i}"
            runs.append(run_child(str(cache)))
        n_files = sum(1 for _ in cache.rglob("*.nbi"))
        cached = run_child(str(cache))
    best = min(runs, key=lambda d: d["compile"])
    return {"cold": best, "cached": cached, "cache_index_files": n_files,
            "cold_runs": [{k: d[k] for k in ("compile", "compile_cpu", "compile_dopri")}
                          for d in runs]}


if __name__ == "__main__":
    if "--child" in sys.argv:
        _child()
    else:
        print(json.dumps(measure(), indent=2))
