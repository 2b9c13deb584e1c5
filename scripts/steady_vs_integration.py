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
SETTLE_S = {"jin2019_friction_split": 10.0, "ji_li_mill_drive": 60.0}
"""Seconds integrated before the compared period where 2 s do not settle the transient
(Ji & Li's drive: a mode damped only by the load characteristic, Floquet multiplier 0.88
over 0.71 s, decays in about 5.5 s)."""
METHODS = {"mo2017_star_reducer": ("shooting",)}
"""Its period holds 324 mesh cycles (errors at the shaft rotations): shooting only."""


def _model(name, table_points=None):
    """The example (its file), or the example with ``table_points`` per mesh period."""
    if table_points is None:
        return example_path(name)
    from torquesplit.model.io import load_model, model_from_dict
    from torquesplit.model.overrides import apply_overrides, read_raw

    data = apply_overrides(read_raw(example_path(name)),
                           {"analysis.table_points": int(table_points)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_model(model_from_dict(data, source=name))


def compare(name, keep=None, settle_s=None, harmonics=None, steps_per_cycle=None,
            methods=None, table_points=None):
    """Largest difference of each mesh-force waveform over one period between the steady
    state (by each method) and the last period of a long RK4 run from the static state,
    over the waveform's peak-to-peak amplitude.  A model without time-varying excitation
    gets ``skipped`` with the reason."""
    from torquesplit.errors import SolverError

    out = {"example": name, "keep": keep}
    methods = methods or METHODS.get(name, ("hb", "shooting"))
    states = {}
    for method in methods:
        t0 = time.perf_counter()
        try:
            states[method] = steady_state(
                _model(name, table_points), keep=keep, method=method,
                stability=method == "shooting",
                harmonics=harmonics if method == "hb" else None,
                steps_per_cycle=steps_per_cycle)
        except SolverError as exc:
            out["skipped"] = str(exc).split(":")[0]
            return out
        out[f"{method}_s"] = time.perf_counter() - t0
        out[f"{method}_message"] = states[method].solution.message
    ref = next(iter(states.values()))
    if "hb" in states:
        out["harmonics"] = states["hb"].solution.harmonics
    s = ref.structure
    T = ref.solution.period
    names = list(s.element_names)
    meshes = [names.index(m) for m in ref.mesh_names]
    steps = ref.problem.rk4_steps(T, steps_per_cycle, ref.period.max_order)
    if settle_s is None:
        settle_s = SETTLE_S.get(name, 2.0)
    n_per = max(1, int(math.ceil(settle_s / T)))
    y0 = ref.static.y0
    t0 = time.perf_counter()
    a = integrate(s, y0, (0.0, n_per * T), step=T / steps, history_elements=(),
                  history_dofs=(), track_elements=meshes)
    b = integrate(s, a.y_final, (n_per * T, (n_per + 2) * T), step=T / steps,
                  history_elements=meshes, history_dofs=(), track_elements=meshes)
    out["integration_s"] = time.perf_counter() - t0
    out["settle_periods"] = n_per + 1
    out["settle_s"] = (n_per + 1) * T
    t_all = b.history_t - (n_per + 1) * T
    last = t_all >= -1e-9 * T
    tt, F_ti = t_all[last], b.history_forces[last]
    # how far the long run itself still is from periodic: its last two periods
    prev = (t_all < -1e-9 * T) & (t_all >= -T * (1 + 1e-9))
    out["reference_drift"] = max(
        float(np.max(np.abs(np.interp(tt, t_all[prev] + T, b.history_forces[prev, j],
                                      period=T) - F_ti[:, j])))
        / max(float(np.ptp(F_ti[:, j])), 1e-300) for j in range(len(meshes)))
    if "shooting" in states:  # what the slowest mode leaves of the start after settling
        mu = states["shooting"].solution.multipliers
        out["largest_multiplier"] = float(np.max(np.abs(mu), initial=0.0))
        out["transient_left"] = out["largest_multiplier"] ** out["settle_periods"]
    res = {}
    for label, st in states.items():
        # the meshes at their finest: shooting's every RK4 step (samples() may interpolate
        # rows kept every few steps on a long period), the harmonic series at every step
        if st.solution.method == "hb":
            t, F, _ = st.samples(n=steps)
            F = F[:, meshes]
        else:
            t, F, _ = st.mesh_series(meshes)
        errs = {}
        for j, e in enumerate(meshes):
            f = np.interp(tt, t, F[:, j], period=T)
            amp = float(np.ptp(F_ti[:, j]))
            errs[ref.mesh_names[j]] = float(np.max(np.abs(f - F_ti[:, j]))) / max(amp, 1e-300)
        res[label] = errs
    out["max_error_over_amplitude"] = res
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
