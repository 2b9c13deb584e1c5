"""Peak memory of a long Ji & Li mill drive run with streaming outputs, in a fresh process.

:func:`measure` runs this file as a child process (so that nothing measured earlier in
the benchmark run inflates its peak) and reads one JSON line back.  The child loads the
kernels (from numba's cache), assembles the Ji & Li mill drive, then integrates
``--steps`` RK4 steps at 100 steps per shortest mesh period with the outputs
``simulate`` streams: per-cycle statistics of every mesh, the bearings' force peaks and a
history of every element force and DOF every ``--record-every`` steps.  It reports, in MiB:

* ``tracemalloc_peak`` -- the largest Python/numpy allocation total during the
  ``integrate`` call (numpy registers its buffers with tracemalloc; numba's scratch
  arrays inside the kernel are not counted, they are a few kB);
* ``rss_before`` / ``rss_peak`` -- the process's resident set before the call and its
  peak during the call (Linux: the VmHWM mark, reset just before the call through
  /proc/self/clear_refs, so an earlier peak such as a kernel compilation does not count;
  elsewhere ``resource.getrusage(...).ru_maxrss``); ``rss_delta`` is their difference,
  what the run itself added; ``process_maxrss`` is the whole process's lifetime peak;
* ``outputs`` -- bytes of the arrays held by the returned ``Solution``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

MIB = 1024.0**2


def _rss_now_mib() -> float:
    """Current resident set from /proc (Linux); NaN elsewhere."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def _reset_peak() -> bool:
    """Reset the kernel's peak-RSS mark (VmHWM) of this process (Linux >= 4.0)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def _hwm_mib() -> float:
    """Peak resident set since the last reset (VmHWM, Linux); NaN elsewhere."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def _maxrss_mib() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / 1024.0 if sys.platform != "darwin" else r / MIB  # kB on Linux, B on macOS


def _child(n_steps: int, record_every: int) -> None:
    import time
    import tracemalloc
    import warnings

    import numpy as np

    import torquesplit
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.results import bearing_vectors
    from torquesplit.solve.integrate import compile_kernels, integrate
    from torquesplit.solve.static import static_equilibrium

    compile_kernels()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", torquesplit.ModelWarning)
        model = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    s = torquesplit.assemble(model)
    st = static_equilibrium(s)
    # the step integrate really takes over one mesh period (it refines 1/(100 f) to
    # 0.8 x the stability limit if needed): a whole number of steps per period
    h = integrate(s, st.y0, (0.0, 1.0 / s.frequency.max()), method="rk4",
                  steps_per_period=100).step
    rss_before = _rss_now_mib()
    maxrss_before = _maxrss_mib()
    hwm_setup = _hwm_mib()  # this process's peak so far: import, kernels, assembly
    hwm_reset = _reset_peak()
    tracemalloc.start()
    w0, c0 = time.perf_counter(), time.process_time()
    peaks = bearing_vectors(s.element_names, model, solve_kinematics(model))
    sol = integrate(s, st.y0, (0.0, n_steps * h), method="rk4", steps_per_period=100,
                    record_every=record_every, history_peaks=peaks)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    maxrss_after = _maxrss_mib()
    if hwm_reset:  # peak of the run itself, whatever happened before it
        rss_peak = _hwm_mib()
    else:  # ru_maxrss cannot be reset: the run's peak is only known if it set a new one
        rss_peak = maxrss_after if maxrss_after > maxrss_before else float("nan")
    outputs = sum(v.nbytes for v in vars(sol).values() if isinstance(v, np.ndarray))
    print(json.dumps({
        "n_steps": sol.n_steps, "record_every": record_every, "simulated": sol.t_final,
        "success": sol.success, "n_records": len(sol.history_t), "n_cycles": sol.cycle_max.shape[0],
        "wall": wall, "cpu": cpu, "us_per_step": wall / sol.n_steps * 1e6,
        "cpu_us_per_step": cpu / sol.n_steps * 1e6,
        "tracemalloc_peak": peak / MIB, "rss_before": rss_before, "maxrss_before": maxrss_before,
        "rss_peak": rss_peak, "rss_delta": rss_peak - rss_before, "peak_method": (
            "VmHWM reset before the run" if hwm_reset else "ru_maxrss"),
        # ru_maxrss also counts the parent's resident set at fork (Linux keeps the larger
        # of the pre- and post-exec marks), so on Linux the process peak is taken from
        # VmHWM: before the reset (set-up) and during the run
        "process_maxrss": (max(hwm_setup, rss_peak) if hwm_reset else maxrss_after),
        "outputs": outputs / MIB}))


def measure(n_steps: int, record_every: int = 100) -> dict:
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child",
                          "--steps", str(n_steps), "--record-every", str(record_every)],
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"memory child failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=10_000_000)
    p.add_argument("--record-every", type=int, default=100)
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.child:
        _child(a.steps, a.record_every)
    else:
        print(json.dumps(measure(a.steps, a.record_every), indent=2))
