"""Speed of the study layer; writes benchmarks/STUDY_RESULTS.md and STUDY_RESULTS.json.

    python benchmarks/bench_study.py              # everything, about 10 minutes on 2 cores
    python benchmarks/bench_study.py --quick      # fewer Monte Carlo cases
    python benchmarks/bench_study.py diameter     # one part: diameter, monte_carlo, memory

Not part of the test suite; nothing here asserts a threshold.  The design targets are
printed beside the measured values.

diameter     Ji & Li's drive-shaft diameter study (28 diameters, the shipped
             ``ji_li_diameter`` study) on 2 workers: with the stop-when-settled rule
             (as shipped) and at the paper's fixed 30 s; wall time of the whole
             ``Study.run`` (pool start, kernel loading, every case), the simulated time
             the rule chose, and how far its outputs are from the 30 s runs.
monte_carlo  Dong et al. 2021's model at its validation settings (1.21 s simulated,
             RK4 100 steps per face-gear mesh period) with ISO 1328 eccentricities and
             random phases on every gear: N cases on 1 and on 2 workers; speed-up,
             per-case time, the study's fixed part, the 1000-case time and speed-up
             from them; per-case overhead.
memory       peak RSS of the driver process for 200 and 2000 cases of a small model.

Per-case overhead = everything but integration, measured in the worker: model
validation, kinematics, assembly, static equilibrium, metrics, pickling, minus nothing
else (``wall_time - integration_time - compile_time`` of each case, from the store),
and, seen from the driver, the study's wall time times the workers minus the cases'
integration time, per case (pool start, kernel loading, idle workers at the end,
store commits).  'After each worker's first case' leaves out the one case per worker
that also pays the process start-up (lazy imports, loading the compiled kernels): the
per-case overhead of a long study.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import json
import math
import os
import platform
import sqlite3
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT_MD = HERE / "STUDY_RESULTS.md"
OUT_JSON = HERE / "STUDY_RESULTS.json"


def _log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _cases(folder: Path) -> list[dict]:
    with sqlite3.connect(folder / "study.sqlite") as db:
        cols = ("idx", "status", "wall_time", "integration_time", "compile_time",
                "simulated_time", "runs", "worker")
        return [dict(zip(cols, r)) for r in
                db.execute(f"SELECT {', '.join(cols)} FROM cases ORDER BY idx")]


def _first_cases(cases: list[dict]) -> set[int]:
    """Each worker's first case (its lowest index: a pool's workers take the cases in
    order), which also pays the process start-up (lazy imports, loading the compiled
    kernels, compiling the right-hand side): a fixed cost per worker, not per case."""
    first: dict = {}
    for c in cases:
        first[c["worker"]] = min(first.get(c["worker"], c["idx"]), c["idx"])
    return set(first.values())


def _overhead(cases: list[dict], wall: float, workers: int) -> dict:
    n = len(cases)
    case_wall = sum(c["wall_time"] for c in cases)
    integ = sum(c["integration_time"] for c in cases)
    comp = sum(c["compile_time"] for c in cases)
    in_worker = case_wall - integ - comp
    firsts = _first_cases(cases)
    later = [c for c in cases if c["idx"] not in firsts]
    later_wall = sum(c["wall_time"] for c in later)
    # (the right-hand side's compilation is not overhead here either: a worker compiles
    # the literal code once, in its second case when the first one's demand repays it)
    later_over = later_wall - sum(c["integration_time"] + c["compile_time"] for c in later)
    steady = later_wall / len(later) if later else case_wall / n
    return {
        "cases": n, "study_wall_s": wall, "workers": workers,
        "mean_case_wall_s": case_wall / n, "mean_integration_s": integ / n,
        "compile_s_total": comp,
        "overhead_in_worker_s_per_case": in_worker / n,
        "overhead_in_worker_fraction": in_worker / case_wall,
        "overhead_after_first_s_per_case": later_over / max(len(later), 1),
        "overhead_after_first_fraction": later_over / later_wall if later_wall else math.nan,
        "cases_after_first": len(later),
        "overhead_seen_by_driver_s_per_case": (wall * workers - integ) / n,
        "overhead_seen_by_driver_fraction": (wall * workers - integ) / (wall * workers),
        "distinct_workers": len({c["worker"] for c in cases}),
        "steady_case_wall_s": steady,
        "first_case_extra_s": sum(c["wall_time"] - steady for c in cases
                                  if c["idx"] in firsts),
    }


# ============================================================================ diameter
def diameter() -> dict:
    import numpy as np

    from torquesplit.study import Study
    from torquesplit.study.shipped import study_path

    text = study_path("ji_li_diameter").read_text()
    out: dict = {}
    for label, body in (("settle", text),
                        ("fixed_30s", text.replace("[analysis.settle]\ntolerance = 0.002\n"
                                                   "start = \"1 s\"\n", ""))):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "s.toml"
            path.write_text(body)
            st = Study(path)
            assert (label == "settle") == ("settle" in st.plan().analysis), label
            _log(f"diameter study, {label}: {st.n_cases} cases on 2 workers")
            t0 = time.perf_counter()
            ds = st.run(workers=2, out=Path(tmp) / "out", figures=False)
            wall = time.perf_counter() - t0
            cases = _cases(Path(tmp) / "out")
            res = _overhead(cases, wall, 2)
            res["simulated_time_s"] = [c["simulated_time"] for c in cases]
            res["runs_per_case"] = [c["runs"] for c in cases]
            res["status"] = sorted(set(ds["status"].values.tolist()))
            res["outputs"] = {v: ds[v].values.tolist() for v in ds.data_vars
                              if "output" in ds[v].attrs}
            res["diameter_m"] = ds["drive_shaft_diameter"].values.tolist()
            out[label] = res
            _log(f"  {wall:.1f} s")
    diffs = {}
    for name, a in out["settle"]["outputs"].items():
        b = np.asarray(out["fixed_30s"]["outputs"][name])
        diffs[name] = float(np.max(np.abs(np.asarray(a) - b)))
    out["max_abs_difference_settle_vs_30s"] = diffs
    return out


# ============================================================================ Monte Carlo
_PLAIN = r"""
import sys, time, warnings, torquesplit
warnings.simplefilter("ignore")
m = torquesplit.load_model(torquesplit.example_path("dong2021_face_gear"))
torquesplit.simulate(m, duration=0.01)
r = torquesplit.simulate(m, duration=0.3)
print(r.statistics()["wall_time_s"])
"""


def parallel_capacity() -> dict:
    """How much two plain ``simulate`` processes slow each other down on this machine
    right now (1.0 on two idle cores, 2.0 when only one core is free): the baseline for
    the worker speed-up, measured in the same run."""
    env = dict(os.environ)

    def start():
        return subprocess.Popen([sys.executable, "-c", _PLAIN], env=env,
                                stdout=subprocess.PIPE, text=True)

    alone = float(start().communicate()[0])
    a, b = start(), start()
    pair = [float(a.communicate()[0]), float(b.communicate()[0])]
    return {"alone_s": alone, "side_by_side_s": pair,
            "slowdown": sum(pair) / 2 / alone, "free_cores_estimate": 2 * alone / max(pair)}


def _literal_codes_needed(spec: dict) -> int:
    """How many distinct literal right-hand sides the study's cases need (their kernel
    models' parameter values, ``codegen._value_key``)."""
    from torquesplit import assemble, load_model
    from torquesplit.model.io import model_from_dict
    from torquesplit.model.overrides import apply_overrides
    from torquesplit.solve import codegen, kernel_data
    from torquesplit.study import Study

    plan = Study(spec).plan()
    keys = set()
    for i in range(plan.design.n_cases):
        data = apply_overrides(plan.case_data, plan.design.overrides(i))
        model = load_model(model_from_dict(data, source=plan.model_source))
        keys.add(codegen._value_key(kernel_data.kernel_model(assemble(model))))
    return len(keys)


@contextlib.contextmanager
def _literal_codes(allowed: bool, codegen):
    """Literal right-hand sides as by default (``allowed``) or none, in this process
    (the 1-worker study runs its cases here) and in the workers it starts."""
    if allowed:
        yield
        return
    before, env = codegen.LITERAL_MAX, os.environ.get("TORQUESPLIT_LITERAL_MAX")
    compiled = codegen._COMPILER._literal  # (those compiled here would still be used)
    codegen.LITERAL_MAX, codegen._COMPILER._literal = 0, {}
    os.environ["TORQUESPLIT_LITERAL_MAX"] = "0"
    try:
        yield
    finally:
        codegen.LITERAL_MAX, codegen._COMPILER._literal = before, compiled
        if env is None:
            os.environ.pop("TORQUESPLIT_LITERAL_MAX", None)
        else:
            os.environ["TORQUESPLIT_LITERAL_MAX"] = env


def _mc_spec(samples: int) -> dict:
    """The benchmark's Monte Carlo: ISO 1328 grade 6 eccentricities with random phases on
    every gear of Dong et al. 2021's model, its validation settings."""
    return {
        "study": {"name": "bench_mc", "model": "dong2021_face_gear",
                  "outputs": ["load_sharing.mean_force", "load_sharing.mean_force.I"]},
        "monte_carlo": {"sampling": "random", "seed": 1, "samples": samples,
                        "parameters": [
                            {"paths": ["gears.*.errors.eccentricity"],
                             "distribution": "iso1328", "grade": 6},
                            {"paths": ["gears.*.errors.eccentricity_phase"],
                             "distribution": "uniform", "low": "0 deg",
                             "high": "360 deg"}]},
    }


def _mc_warm_up() -> None:
    """An untimed one-case study: what only the first study of a process pays (the
    driver's imports of the study layer and the store, the model's first set-up) would
    otherwise sit in the first timed run alone."""
    from torquesplit.study import Study

    with tempfile.TemporaryDirectory() as tmp:
        Study(_mc_spec(1)).run(workers=1, out=Path(tmp), figures=False)


def _mc_run(workers: int, literal: bool, count: int) -> dict:
    """One timed Monte Carlo study of ``count`` cases on ``workers`` workers (its own
    pool): wall time, per-case overhead, the fixed part and the 1000-case estimate."""
    from torquesplit.solve import codegen
    from torquesplit.study import Study

    with tempfile.TemporaryDirectory() as tmp, _literal_codes(literal, codegen):
        _log(f"Monte Carlo, Dong et al. 2021 model: {count} cases on {workers} "
             f"worker(s)" + (", literal code" if literal else ", pattern's code"))
        t0 = time.perf_counter()
        Study(_mc_spec(count)).run(workers=workers, out=Path(tmp), figures=False)
        wall = time.perf_counter() - t0
        cases = _cases(Path(tmp))
    res = _overhead(cases, wall, workers)
    busy = sum(c["wall_time"] for c in cases) / workers
    res["fixed_s"] = wall - busy
    # each worker's first case once, the others at the steady case time (equal to the
    # run's wall time at its own size)
    res["cases_1000_s"] = res["fixed_s"] + (
        1000 * res["steady_case_wall_s"] + res["first_case_extra_s"]) / workers
    res["cases_1000_scaled_mean_s"] = res["fixed_s"] + 1000 * busy / count
    _log(f"  {wall:.1f} s")
    return res


def monte_carlo_1000(n: int = 1000) -> dict:
    """The same Monte Carlo measured at its target size, 1000 cases, on 2 workers and
    then on 1 (about 12 + 22 minutes here; run apart: ``bench_study.py
    monte_carlo_1000``), with the machine's parallel capacity before and after."""
    out: dict = {"capacity_before": parallel_capacity()}
    _mc_warm_up()
    for workers in (2, 1):
        out[f"workers_{workers}"] = _mc_run(workers, True, n)
    out["capacity_after"] = parallel_capacity()
    out["speedup_1_to_2"] = out["workers_1"]["study_wall_s"] / out["workers_2"]["study_wall_s"]
    return out


def monte_carlo(n: int, n_pattern: int | None = None) -> dict:
    """The Dong et al. 2021 Monte Carlo at ``n`` cases on 1 and 2 workers.

    A study's wall time is a fixed part (pool start, the store, idle workers at the end)
    plus its cases, which the workers run side by side: fixed = wall - (sum of the cases'
    wall times) / workers, from the same run.  A worker's first case also carries its
    process start-up (imports, kernel loading, compiling the right-hand side): once per
    worker in any study, so the 1000-case time is that fixed part plus, per worker, the
    first cases' extra time and 1000 cases at the steady case time (the mean of the
    others), and the 1000-case speed-up is the ratio of those.  At n cases that sum is
    the measured wall time.  (Scaling the mean case time instead counts the start-ups
    1000 / n times: from 16 cases it predicted 49.5 s for 64 cases on 2 workers, which
    took 47.5 s; scaling the small study's wall time also counts its fixed part 1000 / n
    times; a line through two study sizes was tried and, on this VM, differencing two
    noisy wall times gave negative fixed parts.)  Every timed study starts its own pool,
    after an untimed one-case study.

    The cases run the literal right-hand side ("auto"'s choice for runs this long): the
    study varies errors only, which the code reads at every call, so one literal code
    serves every case (counted over the cases: ``literal_codes``; a process compiles at
    most 16, ``codegen.LITERAL_MAX``).  One more 1-worker run with
    ``TORQUESPLIT_LITERAL_MAX=0`` (the pattern's code, ``n_pattern`` cases) shows what it
    gains."""
    out: dict = {"capacity_before": parallel_capacity()}
    _mc_warm_up()
    out["literal_codes"] = _literal_codes_needed(_mc_spec(n))
    n_pattern = min(n, 16) if n_pattern is None else n_pattern
    for workers, literal, count in ((1, True, n), (2, True, n), (1, False, n_pattern)):
        out[f"workers_{workers}" + ("" if literal else "_pattern")] = _mc_run(
            workers, literal, count)
    out["capacity_after"] = parallel_capacity()
    w1, w2 = out["workers_1"], out["workers_2"]
    out["speedup_1_to_2"] = w1["study_wall_s"] / w2["study_wall_s"]
    out["speedup_1_to_2_at_1000"] = w1["cases_1000_s"] / w2["cases_1000_s"]
    out["extrapolated_1000_cases_2_workers_s"] = w2["cases_1000_s"]
    out["scaled_1000_cases_2_workers_s"] = 1000 * w2["study_wall_s"] / n
    return out


# ============================================================================ memory
_MEMORY_CHILD = r"""
import json, resource, sys, tempfile
sys.path[:0] = sys.argv[3:]
from model_texts import split_model, write_model
from torquesplit.study import Study
n = int(sys.argv[1])
tmp = tempfile.mkdtemp()
model = write_model(__import__('pathlib').Path(tmp), split_model())
study = {"study": {"name": "mem", "model": str(model), "outputs": ["load_sharing.cycle_peak*"]},
         "analysis": {"cycles": 20},
         "monte_carlo": {"seed": 1, "samples": n, "parameters": [
             {"path": "meshes.a1.transmission_error.constant", "distribution": "uniform",
              "low": "0 um", "high": "5 um"}]}}
def rss():
    for line in open('/proc/self/status'):
        if line.startswith('VmRSS'):
            return int(line.split()[1]) / 1024
st = Study(study); st.plan()
before = rss()
st.run(workers=2, out=sys.argv[2], figures=False)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"cases": n, "rss_before_MiB": before, "rss_after_MiB": rss(),
                  "peak_rss_MiB": peak}))
"""


def memory() -> dict:
    repo = HERE.parent
    paths = [str(repo / "tests"), str(repo / "src")]
    out = {}
    for n in (200, 2000):
        _log(f"driver memory: {n} cases")
        with tempfile.TemporaryDirectory() as tmp:
            res = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, str(n), tmp, *paths],
                                 capture_output=True, text=True, check=True)
        out[str(n)] = json.loads(res.stdout.strip().splitlines()[-1])
    return out


# ============================================================================ report
def _machine() -> dict:
    import numba
    import numpy

    import torquesplit

    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE,
                                capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = "?"
    return {"date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "platform": platform.platform(), "cpu_count": os.cpu_count(),
            "python": platform.python_version(), "numba": numba.__version__,
            "numpy": numpy.__version__, "torquesplit": torquesplit.__version__,
            "commit": commit, "load_average": os.getloadavg()}


def report(res: dict) -> str:
    m = res["machine"]
    lines = ["# Study layer speed (benchmarks/bench_study.py)", "",
             f"{m['date']}, {m['platform']}, {m['cpu_count']} cpus, Python {m['python']}, "
             f"numba {m['numba']}, torquesplit {m['torquesplit']} (commit {m['commit']}); "
             f"load average at start {m['load_average'][0]:.2f}.  The numba cache was warm "
             "(kernels compiled before); each worker process still loads them and "
             "compiles the generated right-hand side once.", ""]
    if res.get("parts_run"):  # parts run apart keep their own date and commit
        lines += ["Parts last run: " + "; ".join(
            f"{part} {run['date']} (commit {run['commit']})"
            for part, run in res["parts_run"].items()) + ".", ""]
    if "diameter" in res:
        d = res["diameter"]
        s, f = d["settle"], d["fixed_30s"]
        lines += ["## Ji & Li drive-shaft diameter study (28 diameters, 2 workers)", "",
                  "| run length | study wall [s] | target | simulated per case [s] | "
                  "integration per case [s] | overhead in worker | of it after each "
                  "worker's first case | status |",
                  "|---|---|---|---|---|---|---|---|",
                  f"| settle rule (0.2 %, 1 s, x2, cap 30 s) | **{s['study_wall_s']:.1f}** | "
                  f"<= 20 | {min(s['simulated_time_s']):.0f}-{max(s['simulated_time_s']):.0f} | "
                  f"{s['mean_integration_s']:.3f} | "
                  f"{100 * s['overhead_in_worker_fraction']:.1f} % | "
                  f"{100 * s['overhead_after_first_fraction']:.1f} % | {', '.join(s['status'])} |",
                  f"| fixed 30 s (the paper's) | **{f['study_wall_s']:.1f}** | - | 30 | "
                  f"{f['mean_integration_s']:.3f} | "
                  f"{100 * f['overhead_in_worker_fraction']:.1f} % | "
                  f"{100 * f['overhead_after_first_fraction']:.1f} % | {', '.join(f['status'])} |",
                  "", "Largest difference between the settle-rule and the 30 s outputs "
                  "over the 28 diameters:", ""]
        for k, v in d["max_abs_difference_settle_vs_30s"].items():
            lines.append(f"- `{k}`: {v:.2e}")
        lines.append("")
    if "monte_carlo" in res:
        mc = res["monte_carlo"]
        w1, w2 = mc["workers_1"], mc["workers_2"]
        lines += [f"## Monte Carlo, Dong et al. 2021 model at its validation settings "
                  f"({w1['cases']} cases)", "",
                  "| workers | study wall [s] | per case [s] | integration per case [s] | "
                  "overhead in worker | of it after each worker's first case | overhead seen "
                  "by driver |", "|---|---|---|---|---|---|---|"]
        pat = mc.get("workers_1_pattern")
        for w in (w1, w2) + ((pat,) if pat else ()):
            label = f"{w['workers']}" + (f" (pattern's code, {w['cases']} cases)"
                                         if w is pat else "")
            lines.append(f"| {label} | {w['study_wall_s']:.1f} | "
                         f"{w['mean_case_wall_s']:.2f} | {w['mean_integration_s']:.2f} | "
                         f"{100 * w['overhead_in_worker_fraction']:.2f} % | "
                         f"{100 * w['overhead_after_first_fraction']:.2f} % | "
                         f"{100 * w['overhead_seen_by_driver_fraction']:.1f} % |")
        if pat:
            lines += ["", "The first two rows: the cases as a study runs them, each with the "
                      "literal right-hand side (the model's values compiled in: \"auto\"'s "
                      f"choice for runs this long); the {w1['cases']} cases need "
                      f"{mc.get('literal_codes', '?')} distinct literal code(s), as the study "
                      "varies errors only, which the code reads at every call (a process "
                      "compiles at most 16).  The last row: the same cases with the pattern's "
                      "generated code (`TORQUESPLIT_LITERAL_MAX=0`): integration "
                      f"{w1['mean_integration_s']:.2f} s a case against "
                      f"{pat['mean_integration_s']:.2f} s "
                      f"({w1['mean_integration_s'] / pat['mean_integration_s']:.2f}x)."]
        caps = [mc[k] for k in ("capacity_before", "capacity_after") if k in mc]
        if caps:
            lines += ["", "Baseline in the same run: two plain `torquesplit.simulate` processes "
                      "side by side take " + " and ".join(
                          f"{c['slowdown']:.2f}x" for c in caps) + " as long as one alone "
                      "(before and after the study; 1.0 = two free cores, 2.0 = one): the "
                      "most a 2-worker study can gain here is about " + " / ".join(
                          f"{2 / c['slowdown']:.2f}x" for c in caps) + "."]
        lines += ["", "A study's wall time = a fixed part (pool start, the store, idle "
                  "workers at the end) + its cases run side by side; fixed = wall - "
                  "(sum of the cases' wall times) / workers.  Each worker's first case "
                  "also pays the process start-up (imports, loading the kernels, "
                  "compiling the right-hand side), once per worker however many cases "
                  "follow; so 1000 cases = fixed + (the first cases' extra + 1000 steady "
                  "case times) / workers, the steady case time being the mean of the "
                  "other cases (at the measured size this sum is the measured wall "
                  "time):", "",
                  "| workers | fixed part [s] | first cases' extra [s] | steady case "
                  "[s] | 1000 cases [min] | the same at the mean case time [min] |",
                  "|---|---|---|---|---|---|"]
        for w in (w1, w2):
            lines.append(f"| {w['workers']} | {w['fixed_s']:.1f} | "
                         f"{w['first_case_extra_s']:.2f} | {w['steady_case_wall_s']:.3f} | "
                         f"{w['cases_1000_s'] / 60:.1f} | "
                         f"{w['cases_1000_scaled_mean_s'] / 60:.1f} |")
        lines += ["", f"Speed-up 1 -> 2 workers: **{mc['speedup_1_to_2_at_1000']:.2f}x** "
                  f"for 1000 cases (target >= 1.8x; **{mc['speedup_1_to_2']:.2f}x "
                  f"measured** at {w1['cases']} cases).  1000 cases on 2 workers: "
                  f"**{mc['extrapolated_1000_cases_2_workers_s'] / 60:.1f} min** (target "
                  f"<= 5 min; the {w1['cases']} cases' wall time x 1000 / {w1['cases']}, "
                  f"which counts the fixed part and the start-ups {1000 // w1['cases']} "
                  f"times: {mc['scaled_1000_cases_2_workers_s'] / 60:.1f} min).", ""]
    if "monte_carlo_1000" in res:
        m = res["monte_carlo_1000"]
        w1, w2 = m["workers_1"], m["workers_2"]
        caps = [m[k]["slowdown"] for k in ("capacity_before", "capacity_after")]
        lines += [f"## The same Monte Carlo measured at {w1['cases']} cases", "",
                  f"A separate run (`python benchmarks/bench_study.py monte_carlo_1000`, "
                  f"{m['date']}, commit {m['commit']}; two plain `simulate` processes side "
                  f"by side took {caps[0]:.2f}x / {caps[1]:.2f}x as long as one alone before "
                  f"and after it):", "",
                  "| workers | study wall [min] | per case [s] | integration per case [s] | "
                  "overhead in worker | of it after each worker's first case |",
                  "|---|---|---|---|---|---|"]
        for w in (w1, w2):
            lines.append(f"| {w['workers']} | **{w['study_wall_s'] / 60:.1f}** | "
                         f"{w['mean_case_wall_s']:.3f} | {w['mean_integration_s']:.3f} | "
                         f"{100 * w['overhead_in_worker_fraction']:.2f} % | "
                         f"{100 * w['overhead_after_first_fraction']:.2f} % |")
        lines += ["", "'Overhead in worker' counts each worker's start-up (imports, loading "
                  "the kernels) in its first case; the last column leaves that case out: the "
                  "per-case overhead of a long study.  Compiling the right-hand side is "
                  "neither integration nor overhead.", "",
                  f"Speed-up 1 -> 2 workers, measured: **{m['speedup_1_to_2']:.2f}x** "
                  f"(target >= 1.8x).  {w2['cases']} cases on 2 workers: "
                  f"**{w2['study_wall_s'] / 60:.1f} min** (target <= 5 min).", ""]
    if "memory" in res:
        lines += ["## Driver memory", "", "| cases | RSS before [MiB] | peak RSS [MiB] |",
                  "|---|---|---|"]
        for k, v in res["memory"].items():
            lines.append(f"| {k} | {v['rss_before_MiB']:.0f} | {v['peak_rss_MiB']:.0f} |")
        lines.append("")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("parts", nargs="*", default=["diameter", "monte_carlo", "memory"])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--mc-cases", type=int, default=None)
    args = ap.parse_args(argv)
    sys.path.insert(0, str(HERE.parent / "src"))
    res = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    res["machine"] = _machine()
    res.setdefault("parts_run", {}).update(
        {part: {k: res["machine"][k] for k in ("date", "commit")} for part in args.parts})
    if "diameter" in args.parts:
        res["diameter"] = diameter()
    if "monte_carlo" in args.parts:
        res["monte_carlo"] = monte_carlo(args.mc_cases or (6 if args.quick else 64))
    if "memory" in args.parts:
        res["memory"] = memory()
    if "monte_carlo_1000" in args.parts:  # (not in the default parts: about 12 minutes)
        m = _machine()
        res["monte_carlo_1000"] = {**monte_carlo_1000(), "date": m["date"],
                                   "commit": m["commit"]}
    OUT_JSON.write_text(json.dumps(res, indent=1))
    OUT_MD.write_text(report(res) + "\n")
    print(report(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
