"""Speed of the periodic steady state and of speed sweeps (issue 12 targets).

    PYTHONPATH=src python benchmarks/bench_steady.py [--points 200] [--check 10]

* steady state of seed 001 (Ji & Li) at its speed: full period (168 mesh cycles) and one
  stage's excitations; seed 000 (Liu et al. 2021) with the spur-split stage kept (its full
  period holds 7918 cycles of the fastest mesh and is refused);
* a speed sweep of seed 001 (stage 1 kept, +-20 % speed, ``--points`` points) by
  continuation against stepping RK4 from the static state to a settled state at
  ``--check`` of those speeds (extrapolated to all points), with the dynamic factor of
  both at the checked speeds.
Times are wall seconds after compilation (a warm-up call first), best of 2.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np

from torquesplit.examples import example_path
from torquesplit.model.io import load_model
from torquesplit.steady import steady_state, sweep_speed


def best(f, n=2):
    out, t = None, np.inf
    for _ in range(n):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return out, t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--check", type=int, default=10)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    r = {}
    s1 = example_path("ji_li_mill_drive")
    steady_state(s1, keep="stage1", harmonics=8)  # compile
    for label, kw in (("seed001_full_period", {}), ("seed001_stage1", {"keep": "stage1"})):
        st, t = best(lambda kw=kw: steady_state(s1, stability=False, check=False, **kw))
        r[label] = dict(seconds=t, solver_seconds=st.solution.wall_time,
                        harmonics=st.solution.harmonics, converged=st.solution.converged)
    s0 = example_path("liu2021_split_torque_helicopter")
    st, t = best(lambda: steady_state(s0, keep="spur_split", stability=False, check=False), 1)
    r["seed000_spur_split"] = dict(seconds=t, solver_seconds=st.solution.wall_time,
                                   harmonics=st.solution.harmonics,
                                   converged=st.solution.converged)
    # sweep vs stepping
    m = load_model(s1)
    w = abs(m.drives["motor"].speed)
    t0 = time.perf_counter()
    ds = sweep_speed(m, 0.8 * w, 1.2 * w, points=args.points, keep="stage1", harmonics=8,
                     stability=False, max_step=0.4 * w / (args.points - 1))
    t_sweep = time.perf_counter() - t0
    from torquesplit.steady.maps import _prepare
    from torquesplit.steady.problem import PeriodicProblem
    from torquesplit.steady.sweep import stepped_sweep

    model, kin, s, _, per, static = _prepare(m, "stage1", 1000)
    p = PeriodicProblem(s, per.frequency)
    idx = np.linspace(0, ds.sizes["point"] - 1, args.check).astype(int)
    speeds = ds["speed"].values[idx] / w
    names = list(s.element_names)
    track = [names.index(x) for x in model.meshes]
    t0 = time.perf_counter()
    peaks = []
    for sp in speeds:  # each speed from the static state (no carried-over state)
        pk, _ = stepped_sweep(p, per, static.q, [sp], settle_periods=2000, track=track)
        peaks.append(pk[0])
    t_ti = (time.perf_counter() - t0) / len(speeds) * ds.sizes["point"]
    static_f = np.array([static.element_forces[e] for e in track])
    df_ti = np.array(peaks) / static_f
    df_hb = ds["dynamic_factor"].values[idx]
    r["sweep_seed001_stage1"] = dict(
        points=int(ds.sizes["point"]), hb_continuation_seconds=t_sweep,
        time_integration_seconds_extrapolated=t_ti, speed_up=t_ti / t_sweep,
        max_dynamic_factor_difference=float(np.max(np.abs(df_ti - df_hb))),
        settle_periods=2000)
    print(json.dumps(r, indent=1))


if __name__ == "__main__":
    main()
