"""Speed of the loaded tooth contact analysis (design targets printed beside).

    python benchmarks/bench_ltca.py [--repeat 3] [--output benchmarks/LTCA_RESULTS.md]

Cases: a single-helical pair (64 positions x 40 slices, one load; a 10-load Harris map)
and the double-helical pair of Liu et al. 2021 (64 x 40 x 2 helices), unmodified and
with the paper's modification.  Timings are the best of ``--repeat`` runs after one warm
call (numba compiled or loaded from its cache; the first-call time is reported apart).
Not part of the test suite; nothing here asserts a threshold.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TARGETS = {"single_load_s": 0.5, "harris_10_s": 3.0, "nsga2_s": 300.0}


def _best(fn, repeat):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run(repeat: int) -> dict:
    t0 = time.perf_counter()
    from torquesplit.gears.contact import (
        ContactModel,
        FlankModification,
        LtcaOptions,
        Relief,
        ToothModification,
        liu2021_topological,
    )
    from torquesplit.gears.geometry import GearGeometry, PairGeometry

    deg = math.pi / 180
    helical = PairGeometry(GearGeometry(23, 3e-3, 20 * deg, 20 * deg, 40e-3),
                           GearGeometry(61, 3e-3, 20 * deg, -20 * deg, 40e-3))
    g = dict(normal_module=3.965e-3, normal_pressure_angle=20 * deg, helix_angle=30 * deg,
             face_width=50e-3, double_helical=True)
    dh = PairGeometry(GearGeometry(23, **g), GearGeometry(215, **g))
    relief = ToothModification(FlankModification(tip_relief=Relief(15e-6, length=3e-3), crowning=8e-6))
    liu = ToothModification(liu2021_topological(23e-6, 35e-6, 2.30e-3, 2.01e-3, 13e-6, 8.19e-3, 50e-3))
    opts = LtcaOptions(positions=64, slices=40)
    cases = {
        "helical 23/61, unmodified": (helical, (None, None), 15e3),
        "helical 23/61, tip relief + crowning": (helical, (relief, relief), 15e3),
        "double-helical 23/215 (Liu 2021), unmodified": (dh, (None, None), 43.69e3),
        "double-helical 23/215 (Liu 2021), modified": (dh, (liu, None), 43.69e3),
    }
    first = None
    rows = []
    for name, (pair, mods, load) in cases.items():
        t1 = time.perf_counter()
        cm = ContactModel(pair, mods, options=opts)
        build = time.perf_counter() - t1
        t1 = time.perf_counter()
        res = cm.solve(load)
        if first is None:
            first = time.perf_counter() - t1 + build
        single = _best(lambda: cm.solve(load), repeat)
        loads = np.linspace(0.1, 1.5, 10) * load
        harris = _best(lambda: cm.harris_map(loads), max(1, repeat // 2))
        build_best = _best(lambda: ContactModel(pair, mods, options=opts), repeat)
        rows.append({"case": name, "shape": list(cm.shape), "build_s": build_best,
                     "single_load_s": single, "harris_10_s": harris,
                     "converged": res.converged,
                     "active_set_iterations_max": int(res.iterations.max())})
    return {"rows": rows, "first_call_s": first, "import_s": None,
            "total_s": time.perf_counter() - t0, "machine": platform.platform(),
            "cpus": os.cpu_count(), "load_average": os.getloadavg()[0], "python": sys.version.split()[0],
            "targets": TARGETS}


def run_nsga(workers: int) -> dict:
    """The shipped optimisation of Liu et al. 2021's modification (population 40 x 50
    generations, LTCA 64 x 40 x 2 helices), timed from scratch (no stored evaluations)."""
    import tempfile
    from importlib import resources

    from torquesplit.optimize import optimize, read_spec
    from dataclasses import replace

    path = Path(str(resources.files("torquesplit.examples") / "optimize"
                    / "liu2021_dh_modification.toml"))
    with tempfile.TemporaryDirectory() as tmp:
        spec = replace(read_spec(path), store=Path(tmp) / "evals.jsonl", workers=workers)
        t0 = time.perf_counter()
        res = optimize(spec)
        wall = time.perf_counter() - t0
    return {"nsga2_s": wall, "evaluations": res.evaluations, "computed": res.computed,
            "pareto_size": int(len(res.F)), "workers": workers,
            "best_F": [float(v) for v in res.F[res.chosen]]}


def markdown(res: dict) -> str:
    lines = ["# LTCA benchmark", "",
             f"{res['machine']}, {res['cpus']} cpus, load average {res['load_average']:.2f} at the "
             f"start, Python {res['python']}.  First call (compilation or numba cache load, plus "
             f"the first model build): {res['first_call_s']:.2f} s.", "",
             "| case | positions x helices x pairs x slices | build [s] | one load [s] "
             f"(target < {TARGETS['single_load_s']}) | 10-load Harris map [s] (target < "
             f"{TARGETS['harris_10_s']}) |", "|---|---|---|---|---|"]
    for r in res["rows"]:
        lines.append(f"| {r['case']} | {' x '.join(map(str, r['shape']))} | {r['build_s']:.3f} | "
                     f"{r['single_load_s']:.3f} | {r['harris_10_s']:.3f} |")
    lines.append("")
    if res.get("nsga"):
        n = res["nsga"]
        lines.append(f"NSGA-II of the shipped example (liu2021_dh_modification.toml: population 40, "
                     f"50 generations, LTCA 64 x 40 x 2 helices per evaluation): "
                     f"{n['nsga2_s']:.0f} s with {n['workers']} workers (target < "
                     f"{TARGETS['nsga2_s']:.0f} s), {n['computed']} designs computed of "
                     f"{n['evaluations']} evaluated, {n['pareto_size']} on the front.")
        lines.append("")
    lines.append("'build' is the load-independent part (geometry, compliance tables, separations); "
                 "'one load' the contact solution at every position (Hertz fixed point and "
                 "active set); the Harris map reuses one build.")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--output", type=Path, default=HERE / "LTCA_RESULTS.md")
    ap.add_argument("--nsga", action="store_true", help="also time the shipped NSGA-II example")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    res = run(args.repeat)
    if args.nsga:
        res["nsga"] = run_nsga(args.workers)
    md = markdown(res)
    args.output.write_text(md)
    args.output.with_suffix(".json").write_text(json.dumps(res, indent=1))
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
