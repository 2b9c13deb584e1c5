"""Periodic steady state (harmonic balance and shooting) against long time integration.

For each shipped example (or the ones named on the command line): the periodic state at
the model's speed by harmonic balance and by shooting, and a long RK4 run of the same
structure (``torquesplit.solve.integrate``, started from the static equilibrium) whose
last period is compared with them.  Prints the largest difference of each mesh force
waveform over the period, relative to the waveform's peak-to-peak amplitude.

    python scripts/steady_vs_integration.py [example ...] [--keep STAGE] [--periods P]
"""

from __future__ import annotations

import argparse
import json
import math
import time
import warnings

import numpy as np

from torquesplit.examples import example_names, example_path
from torquesplit.solve.integrate import integrate
from torquesplit.steady.api import steady_state

KEEP = {  # one stage's excitations: a period of one mesh cycle (the full periods are long)
    "liu2021_split_torque_helicopter": "spur_split",
    "ji_li_mill_drive": "stage1",
    "dong2021_face_gear": "I",
    "jin2019_friction_split": "confluence",
}


def compare(name, keep=None, settle_s=None, harmonics=None, steps_per_cycle=None):
    out = {"example": name, "keep": keep}
    t0 = time.perf_counter()
    hb = steady_state(example_path(name), keep=keep, harmonics=harmonics,
                      stability=False, steps_per_cycle=steps_per_cycle)
    out["hb_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    sh = steady_state(example_path(name), keep=keep, method="shooting", stability=False,
                      steps_per_cycle=steps_per_cycle)
    out["shooting_s"] = time.perf_counter() - t0
    s = hb.structure
    T = hb.solution.period
    names = list(s.element_names)
    meshes = [names.index(m) for m in hb.mesh_names]
    steps = hb.problem.rk4_steps(T, steps_per_cycle, hb.period.max_order)
    if settle_s is None:
        settle_s = 2.0
    n_per = max(1, int(math.ceil(settle_s / T)))
    y0 = hb.static.y0
    t0 = time.perf_counter()
    a = integrate(s, y0, (0.0, n_per * T), step=T / steps, history_elements=(),
                  history_dofs=(), track_elements=meshes)
    b = integrate(s, a.y_final, (n_per * T, (n_per + 1) * T), step=T / steps,
                  history_elements=meshes, history_dofs=(), track_elements=meshes)
    out["integration_s"] = time.perf_counter() - t0
    out["settle_periods"] = n_per
    tt = b.history_t - n_per * T
    F_ti = b.history_forces
    res = {}
    for label, st in (("hb", hb), ("shooting", sh)):
        t, F, _ = st.samples(n=steps)
        errs = {}
        for j, e in enumerate(meshes):
            f = np.interp(tt, t, F[:, e], period=T)
            amp = float(np.ptp(F_ti[:, j]))
            errs[hb.mesh_names[j]] = float(np.max(np.abs(f - F_ti[:, j]))) / max(amp, 1e-300)
        res[label] = errs
    out["max_error_over_amplitude"] = res
    out["hb_message"] = hb.solution.message
    out["shooting_message"] = sh.solution.message
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("examples", nargs="*")
    ap.add_argument("--settle", type=float, default=None, help="seconds integrated first")
    ap.add_argument("--harmonics", type=int, default=None)
    ap.add_argument("--steps-per-cycle", type=int, default=None)
    ap.add_argument("--full", action="store_true", help="every excitation (full period)")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    for name in args.examples or example_names():
        keep = None if args.full else KEEP.get(name)
        r = compare(name, keep, args.settle, args.harmonics, args.steps_per_cycle)
        print(json.dumps(r, indent=1))


if __name__ == "__main__":
    main()
