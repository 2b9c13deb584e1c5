"""Speed benchmark of the torquesplit engine; writes benchmarks/RESULTS.md.

    python benchmarks/run.py            # full run (a few minutes on 2 cores)
    python benchmarks/run.py --quick    # fewer steps, 1-million-step memory run

Every comparison is a ratio against a baseline measured in the same run, never an
absolute threshold; the design targets are printed beside the measured values.  See
benchmarks/README.md for what each number means.  Not part of the test suite.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_baseline
import bench_compile
import bench_engine
import bench_memory

TARGETS = {
    "us_per_step": 1.0,  # Ji & Li mill drive, microseconds per RK4 step
    "speedup": 1000.0,  # engine / scipy baseline, simulated seconds per wall second
    "compile": 20.0,  # first (cold) compilation, seconds
    "memory": 300.0,  # MB (MiB) for a 10-million-step run
    "hand_ratio": 1.2,  # engine / hand transcription of Ji & Li, CPU time per step
    "hand_ratio_general": 1.5,  # the same with rhs="general"
    "paper_run": 3.0,  # s of integration, Liu et al. 2021 at the paper's resolution
}
SEED001 = "ji_li_mill_drive"


def _log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _settings(quick: bool) -> dict:
    if quick:
        return {"engine_steps": 50_000, "memory_steps": 1_000_000, "scipy_periods": 5,
                    "numpy_rk4_steps": 50, "scipy_budget": 20.0, "kernel_calls": 200_000}
    return {"engine_steps": 200_000, "memory_steps": 10_000_000, "scipy_periods": 20,
                "numpy_rk4_steps": 200, "scipy_budget": 25.0, "kernel_calls": 1_000_000}


# ======================================================================== run
def run(quick: bool, repeat: int, skip_compile: bool = False) -> dict:
    cfg = _settings(quick)
    t_start = time.perf_counter()
    res = {"quick": quick, "repeat": repeat, "cfg": cfg, "machine": _machine(),
               "load_start": _loadavg()}

    from torquesplit.solve.integrate import compile_kernels

    _log("loading kernels (numba cache)")
    compile_kernels()

    _log("assembling the shipped examples and the generated split models")
    examples, res["skipped"] = bench_engine.example_cases()
    for name, why in res["skipped"].items():
        _log(f"  skipped {name}: {why}")
    splits = bench_engine.split_cases((2, 4, 8, 16))
    cases = examples + splits

    _log(f"engine: {cfg['engine_steps']} RK4 steps per model, best of {repeat}")
    res["engine"] = []
    for c in cases:
        r = bench_engine.time_rk4(c, cfg["engine_steps"], repeat)
        _log(f"  {c.name}: {r['us_per_step']:.2f} us/step (cpu {r['cpu_us_per_step']:.2f})")
        res["engine"].append(r)
    eng = {r["model"]: r for r in res["engine"]}

    _log("engine against the hand transcription of Ji & Li's equations")
    import bench_transcription

    res["transcription"] = bench_transcription.compare(cfg["engine_steps"], max(9, repeat))
    tr = res["transcription"]
    _log(f"  engine {tr['engine_us']:.3f} / general {tr['general_us']:.3f} / hand "
         f"{tr['hand_us']:.3f} us/step")

    _log("Liu et al. 2021's reducer at the paper's resolution (the example's default run)")
    import bench_paper_run

    res["paper_run"] = bench_paper_run.measure(2)
    _log(f"  integration {res['paper_run']['integration_s']:.2f} s")

    _log("engine against a transcription generated from the assembled structure "
         "(compiles ~10-20 s)")
    import bench_specialised

    res["specialised"] = bench_specialised.compare(
        next(c for c in cases if c.name == SEED001), cfg["engine_steps"], max(3, repeat))

    _log("engine dopri (rtol 1e-6) over a tenth of that simulated time")
    res["dopri"] = [bench_engine.time_dopri(c, 0.1 * eng[c.name]["simulated"], 1e-6, repeat)
                    for c in cases]

    _log(f"scipy RK45 baselines over {cfg['scipy_periods']} shortest mesh periods")
    res["scipy"], res["scipy_cached"], res["numpy_rk4"], res["cached_check"] = [], [], [], []
    for c in cases:
        a = bench_baseline.time_scipy(c, cfg["scipy_periods"], budget=cfg["scipy_budget"])
        b = bench_baseline.time_scipy(c, cfg["scipy_periods"], cached=True,
                                      budget=cfg["scipy_budget"])
        n = bench_baseline.time_numpy_rk4(c, eng[c.name]["step"], cfg["numpy_rk4_steps"])
        res["scipy"].append(a)
        res["scipy_cached"].append(b)
        res["numpy_rk4"].append(n)
        res["cached_check"].append(bench_baseline.check_cached_rhs(c))
        _log(f"  {c.name}: scipy {a['sim_per_wall']:.3g} sim s/s ({a['n_rhs']} rhs), "
             f"cached-V {b['sim_per_wall']:.3g}, numpy RK4 {n['us_per_step']:.0f} us/step")

    _log("where a step goes (Ji & Li): parts removed one by one, timed in one process")
    import bench_kernel_parts

    res["parts"] = bench_kernel_parts.breakdown(cfg["engine_steps"], 3 if quick else 7)

    _log(f"memory: {cfg['memory_steps']:,} steps of the Ji & Li mill drive in a fresh process")
    res["memory"] = bench_memory.measure(cfg["memory_steps"], 100)

    if skip_compile:
        res["compile"] = None
    else:
        _log("compile time: cold (twice) and cached, in fresh processes (takes ~1-2 min)")
        res["compile"] = bench_compile.measure()

    res["load_end"] = _loadavg()
    res["elapsed"] = time.perf_counter() - t_start
    return res


# ===================================================================== report
def _machine() -> dict:
    import numba
    import numpy
    import scipy

    import torquesplit

    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE,
                                capture_output=True, text=True, check=False).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "src"], cwd=HERE.parent,
                               capture_output=True, text=True, check=False).stdout.strip()
    except OSError:
        commit, dirty = "?", ""
    kern_file = HERE.parent / "src" / "torquesplit" / "solve" / "_kernels.py"
    try:
        import hashlib

        kern_sha = hashlib.sha256(kern_file.read_bytes()).hexdigest()[:10]
        kern_dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", str(kern_file)],
                                    cwd=HERE.parent, check=False).returncode != 0
    except OSError:
        kern_sha, kern_dirty = "?", False
    cpu = platform.processor() or ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "date": _dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z"),
        "platform": platform.platform(), "cpu": cpu, "cpu_count": os.cpu_count(),
        "python": platform.python_version(), "numba": numba.__version__,
        "numpy": numpy.__version__, "scipy": scipy.__version__,
        "torquesplit": torquesplit.__version__, "commit": commit,
        "src_dirty": len(dirty.splitlines()) if dirty else 0,
        "kernels_sha": kern_sha, "kernels_modified": kern_dirty,
    }


def _loadavg():
    try:
        return os.getloadavg()
    except OSError:
        return (math.nan,) * 3


def _f(x, digits=3) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, int):
        return f"{x:,}"
    if x == 0:
        return "0"
    mag = abs(x)
    if mag >= 1e5 or mag < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{max(digits - 1 - math.floor(math.log10(mag)), 0)}f}"


def _table(header, rows) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def _ok(passed: bool | None) -> str:
    return "-" if passed is None else ("met" if passed else "**not met**")


def report(res: dict) -> str:
    m, cfg = res["machine"], res["cfg"]
    eng = {r["model"]: r for r in res["engine"]}
    dop = {r["model"]: r for r in res["dopri"]}
    sci = {r["model"]: r for r in res["scipy"]}
    scc = {r["model"]: r for r in res["scipy_cached"]}
    nrk = {r["model"]: r for r in res["numpy_rk4"]}
    mem, comp = res["memory"], res["compile"]
    e001 = eng[SEED001]
    speed001 = e001["sim_per_wall"] / sci[SEED001]["sim_per_wall"]
    speed_min = min(eng[k]["sim_per_wall"] / sci[k]["sim_per_wall"] for k in eng)
    mode = ("**--quick** (fewer steps; the memory run is 1 million steps, not 10 million)"
            if res["quick"] else "full")
    L = []
    L.append("# torquesplit speed benchmark results\n")
    L.append(f"Produced by `python benchmarks/run.py{' --quick' if res['quick'] else ''}` "
             f"(mode: {mode}) in {res['elapsed'] / 60:.1f} min. Regenerate with the same "
             "command; see `benchmarks/README.md` for what each number means.\n")
    L.append(_table(["machine", ""], [
        ["date", m["date"]], ["platform", m["platform"]], ["CPU", m["cpu"]],
        ["cpu count", m["cpu_count"]], ["Python", m["python"]], ["numba", m["numba"]],
        ["numpy", m["numpy"]], ["scipy", m["scipy"]],
        ["torquesplit", f"{m['torquesplit']} (commit {m['commit']}"
         + (f", {m['src_dirty']} uncommitted file(s) under src/)" if m["src_dirty"] else ")")],
        ["solve/_kernels.py measured", f"sha256 {m['kernels_sha']}"
         + (" (uncommitted changes against HEAD)" if m["kernels_modified"] else " (as in HEAD)")],
        ["load average (1/5/15 min) at start", " / ".join(f"{x:.2f}" for x in res["load_start"])],
        ["load average at end", " / ".join(f"{x:.2f}" for x in res["load_end"])],
    ]))
    L.append("\nWall-clock numbers are the best of "
             f"{res['repeat']} runs. The CPU column is process CPU time (the kernels are "
             "single-threaded): when other processes load the machine (load average above "
             "the cpu count) it is the better estimate of an idle core.\n")

    # ---------------------------------------------------------------- targets
    L.append("## Design targets\n")
    rows = [
        ["µs per RK4 step, Ji & Li mill drive", f"<= {TARGETS['us_per_step']:g}",
         f"{_f(e001['us_per_step'])} (CPU {_f(e001['cpu_us_per_step'])})",
         _ok(e001["us_per_step"] <= TARGETS["us_per_step"])],
        ["speed-up over the scipy baseline (simulated s per wall s), Ji & Li mill drive",
         f">= {TARGETS['speedup']:g}x", f"{_f(speed001)}x",
         _ok(speed001 >= TARGETS["speedup"])],
        ["speed-up over the scipy baseline, smallest over all models",
         f">= {TARGETS['speedup']:g}x", f"{_f(speed_min)}x",
         _ok(speed_min >= TARGETS["speedup"])],
    ]
    if comp:
        cold = comp["cold"]
        runs = comp.get("cold_runs", [cold])
        each = (f", best of {len(runs)} fresh caches: "
                + " / ".join(f"{_f(d['compile'])}" for d in runs) + " s") if len(runs) > 1 else ""
        rows.append(["first (cold) compilation: the kernels of a first default (RK4) run",
                     f"< {TARGETS['compile']:g} s",
                     f"{_f(cold['compile'])} s (CPU {_f(cold['compile_cpu'])} s{each}); the "
                     f"Dormand-Prince kernels add {_f(cold.get('compile_dopri', float('nan')))} s "
                     f"on the first adaptive run",
                     _ok(cold["compile"] < TARGETS["compile"])])
    n_mem = mem["n_steps"]
    rows.append([f"peak memory, {n_mem:,}-step Ji & Li mill drive run (peak RSS during the run)",
                 f"< {TARGETS['memory']:g} MB"
                 + ("" if n_mem >= 10_000_000 else " (for 10 million steps)"),
                 (f"{_f(mem['rss_peak'])} MiB (run itself: +{_f(mem['rss_delta'])} MiB RSS, "
                 f"tracemalloc peak {_f(mem['tracemalloc_peak'])} MiB)"),
                 _ok(mem["rss_peak"] < TARGETS["memory"]) if n_mem >= 10_000_000 else
                 "- (quick mode)"])
    sp = res.get("specialised") or {}
    ht = res.get("transcription") or {}
    if "ratio" in ht:
        rows[1:1] = [
            ["engine / hand transcription of Ji & Li's equations (CPU time per "
             f"RK4 step, same run; the engine's right-hand side as a default run of the "
             f"example takes it: {ht.get('default_rhs', 'generated')})",
             f"<= {TARGETS['hand_ratio']:g}",
             f"{_f(ht['ratio'])} ({_f(ht['engine_us'])} / {_f(ht['hand_us'])} µs)"
             + (f"; the pattern's generated code (short runs, a study's cases): "
                f"{_f(ht['ratio_pattern'])}" if "ratio_pattern" in ht else ""),
             _ok(ht["ratio"] <= TARGETS["hand_ratio"])],
            ["engine with `rhs=\"general\"` / hand transcription of Ji & Li's equations",
             f"<= {TARGETS['hand_ratio_general']:g}",
             f"{_f(ht['ratio_general'])} ({_f(ht['general_us'])} / {_f(ht['hand_us'])} µs)",
             _ok(ht["ratio_general"] <= TARGETS["hand_ratio_general"])]]
    pr = res.get("paper_run")
    if pr:
        rows.insert(1, [
            f"integration of Liu et al. 2021's reducer (49 DOFs) at the paper's resolution "
            f"(the example's default run: {pr['steps']:,} RK4 steps, {_f(pr['simulated'])} s "
            f"simulated; `bench_paper_run.py`)",
            f"<= {TARGETS['paper_run']:g} s",
            f"{_f(pr['integration_s'])} s ({_f(pr['us_per_step'])} µs/step, {pr['rhs']} "
            f"rhs; the whole `simulate` call {_f(pr['simulate_cpu_s'])} s CPU"
            + (f"; a first run adds {_f(pr['first_rhs_compile_s'])} s generating its "
               f"right-hand side" if pr["first_rhs_compile_s"] >= 0.01 else "") + ")",
            _ok(pr["integration_s"] <= TARGETS["paper_run"])])
    L.append(_table(["quantity", "target", "measured", "status"], rows))

    # ---------------------------------------------------------------- engine
    L.append("\n## Engine: `integrate(method='rk4')`\n")
    L.append(f"{cfg['engine_steps']:,} RK4 steps per model from the static equilibrium, "
             "100 steps per shortest mesh period (or the finer stable step `integrate` "
             "chooses itself, see 'steps/period'), streaming outputs as in `simulate` "
             "(cycle statistics of every mesh, the bearings' force peaks, history of every "
             "element and DOF every 100 steps).\n")
    if res["skipped"]:
        L.append("Shipped examples left out because they do not load in this checkout "
                 "(src/ is edited concurrently):\n")
        L.extend(f"* `{k}`: {v}" for k, v in res["skipped"].items())
        L.append("")
    L.append("The right-hand side is the model's generated code (`solve/codegen.py`, "
             "what the default `rhs=\"auto\"` takes for a run of this length; 'rhs' says "
             "which ran); 'literal µs/step' is the same run with `rhs=\"literal\"` (the "
             "model's values compiled into that code as constants: what \"auto\" takes "
             "for runs long enough to repay that compilation, e.g. the examples' "
             "default runs; bit for bit the same results), 'general µs/step' with "
             "`rhs=\"general\"` (the kernel's element loop), the three alternated.\n")
    rows = []
    for r in res["engine"]:
        rows.append([r["model"], r["n_dof"], r["n_elements"], _f(r["f_max"], 4),
                     _f(r["steps_per_period"], 4), _f(r["step"]), f"{r['n_steps']:,}",
                     f"**{_f(r['us_per_step'])}**", _f(r["cpu_us_per_step"]),
                     r["rhs"],
                     (_f(r["literal_us_per_step"]) if r.get("literal_rhs") == "literal"
                      else f"- (ran {r.get('literal_rhs')})"),
                     (f"{_f(r['literal_us_per_step'] / r['us_per_step'])}x"
                      if r.get("literal_rhs") == "literal" else "-"),
                     _f(r["general_us_per_step"]),
                     f"{_f(r['general_us_per_step'] / r['us_per_step'])}x",
                     _f(r["us_per_step"] * 1e3 / r["n_dof"]),
                     _f(r["sim_per_wall"]),
                     ("ok" if r["success"] else r["message"])
                     + ("" if r["static_converged"] else
                        " (static equilibrium did not converge: started from its last "
                        "iterate)")])
    L.append(_table(["model", "DOFs", "elements", "f_mesh max [Hz]", "steps/period",
                     "step [s]", "steps", "µs/step", "CPU µs/step", "rhs",
                     "literal µs/step", "literal / generated", "general µs/step",
                     "general / generated", "ns/step/DOF",
                     "simulated s per wall s", "status"], rows))

    # ---------------------------------------------------------------- scipy
    L.append("\n## Engine against the scipy baseline (simulated seconds per wall second)\n")
    L.append(f"Baseline: `scipy.integrate.solve_ivp(method='RK45', rtol=1e-6)` with "
             f"`torquesplit.solve.reference.rhs_numpy` on the same assembled structure and "
             f"initial state, over {cfg['scipy_periods']} shortest mesh periods (atol: the "
             f"engine's own per-state default). 'cached V' is the same right-hand side with "
             f"the projection matrix built once (`bench_baseline.cached_rhs`; it leaves "
             f"out splines and tooth friction, and equals `rhs_numpy` to a relative "
             f"{_f(max(c for c in res['cached_check'] if c < 1e-9), 2)} on the models "
             f"without them; differences: "
             + ", ".join(f"{r['model']} {_f(c, 2)}" for r, c in zip(res["engine"],
                                                                  res["cached_check"])
                         if c >= 1e-9)
             + "). 'engine dopri' is `integrate(method="
             "'dopri', rtol=1e-6)` over a tenth of the engine RK4 run's simulated time: "
             "the same algorithm family as RK45 (*max steps*: it stopped at its step limit "
             "and is reported over the part it did). Ratio = engine / baseline. The "
             "baseline moves with `rhs_numpy`'s own speed: it builds the projection matrix "
             "at every call, with one `np.add.at` since commit bfd2d66 (Ji & Li: 102 µs a "
             "call at 1aecc2e, 72 µs after), so the ratios fell by about a third then "
             "(1169x to about 800x for Ji & Li) with the engine no slower.\n")
    rows = []
    for k in eng:
        a, b, d = sci[k], scc[k], dop[k]
        n_per = a["n_steps"] / cfg["scipy_periods"] if a["n_steps"] else None
        rows.append([k, _f(a["sim_per_wall"]) + ("" if a["complete"] else " (partial)"),
                     a["n_rhs"], _f(n_per), _f(a["rhs_us"], 3),
                     _f(b["sim_per_wall"]), _f(eng[k]["sim_per_wall"]),
                     f"**{_f(eng[k]['sim_per_wall'] / a['sim_per_wall'])}x**",
                     f"{_f(eng[k]['sim_per_wall'] / b['sim_per_wall'])}x",
                     _f(d["sim_per_wall"]) + ("" if d["success"] else " (max steps)"),
                     f"{_f(d['sim_per_wall'] / a['sim_per_wall'])}x"])
    L.append(_table(["model", "scipy sim s/wall s", "scipy rhs calls",
                     "scipy steps/period", "µs per rhs_numpy call", "scipy cached-V sim s/wall s",
                     "engine RK4 sim s/wall s", "RK4 / scipy", "RK4 / scipy cached-V",
                     "engine dopri sim s/wall s", "dopri / scipy"], rows))

    if "ratio" in ht:
        L.append("\n## Engine against the hand transcription of Ji & Li's equations\n")
        L.append("`tests/validation/transcription_ji_li.py` writes the paper's 14-DOF "
                 "eq. 9 by hand as numba code from the model's physical parameters, without "
                 "the assembler (`tests/validation/test_ji_li_transcription.py`: it agrees "
                 "with the engine to 1e-9). `bench_transcription.py` runs it and the engine "
                 "(literal, generated and general right-hand side) over the same steps from "
                 "the same "
                 "state, each streaming the per-cycle statistics of the four mesh forces "
                 f"(the engine without a history), alternated, best CPU time of each over "
                 f"{ht.get('repeat', 3)} rounds. The cost "
                 "per step is the difference between runs of 2 n and n steps over n; what is "
                 "left is the fixed cost of a call (for the engine, the Python set-up of "
                 "`integrate`: its work and record arrays and the outputs; the kernel "
                 "arrays, the step check's eigenvalues and the kernels' entry point are kept "
                 "per structure from its first run).\n")
        L.append(_table(["quantity", "value"], [
            ["steps (n) / step", f"{ht['steps']:,} / {_f(ht['step'])} s"],
            [f"engine ({ht.get('default_rhs', 'generated')} rhs: a default run's) CPU "
             "µs/step", _f(ht["engine_us"])],
            ["engine (`rhs=\"generated\"`, the pattern's code) CPU µs/step",
             _f(ht.get("pattern_us", math.nan))],
            ["engine (`rhs=\"general\"`) CPU µs/step", _f(ht["general_us"])],
            ["hand transcription CPU µs/step", _f(ht["hand_us"])],
            ["fixed cost of a call: engine / generated / general / hand [ms]",
             " / ".join(_f(ht.get(k, math.nan)) for k in ("engine_call_ms", "pattern_call_ms",
                                                        "general_call_ms", "hand_call_ms"))],
            ["ratio engine / hand", f"**{_f(ht['ratio'])}** (target <= "
             f"{TARGETS['hand_ratio']:g})"],
            ["ratio generated / hand", _f(ht.get("ratio_pattern", math.nan))],
            ["ratio general / hand", f"**{_f(ht['ratio_general'])}** (target <= "
             f"{TARGETS['hand_ratio_general']:g})"],
            ["final states, largest difference (per kind, over its largest value)",
             _f(ht["final_state_rel_diff"], 2)],
        ]))

    if "ratio" in sp:
        L.append("\n## Engine against a transcription generated from the assembled structure "
                 "(checks kernel overhead, not assembly; Ji & Li mill drive)\n")
        L.append("`bench_specialised.py` writes the engine's own assembled Ji & Li structure "
                 "out as straight-line numba code: one statement per non-zero, every "
                 "coefficient and index a literal, the same stiffness tables, dead zones, "
                 "per-cycle statistics and history, no error sinusoids/friction/splines/"
                 "contact counters/divergence checks. Being generated from the assembly, it "
                 "measures the kernel's overhead but cannot reveal an assembly error; the "
                 "hand transcription above is the independent baseline. Both run the same "
                 "steps from the same state, alternated, best CPU time of each.\n")
        L.append(_table(["quantity", "value"], [
            ["DOFs / elements", f"{sp['n_dof']} / {sp['n_elements']}"],
            ["steps", f"{sp['steps']:,}"],
            ["engine CPU µs/step", _f(sp["engine_us"])],
            ["generated transcription CPU µs/step", _f(sp["specialised_us"])],
            ["ratio engine / generated transcription", f"**{_f(sp['ratio'])}**"],
            ["final states, largest relative difference", _f(sp["final_state_rel_diff"], 2)],
            ["generated code: lines / numba compile time",
             f"{sp['source_lines']} / {_f(sp['compile_s'])} s"],
        ]))

    L.append("\n## Engine against a numpy RK4 loop (per step)\n")
    L.append(f"Baseline: `torquesplit.solve.reference.rk4_numpy` (classic RK4, a Python "
             f"call to `rhs_numpy` per stage), {cfg['numpy_rk4_steps']} steps of the same "
             f"step size as the engine run.\n")
    rows = [[k, _f(nrk[k]["us_per_step"]), _f(eng[k]["us_per_step"]),
             f"**{_f(nrk[k]['us_per_step'] / eng[k]['us_per_step'])}x**"] for k in eng]
    L.append(_table(["model", "numpy RK4 µs/step", "engine µs/step", "ratio"], rows))

    # ---------------------------------------------------------------- kernel parts
    p = res["parts"]
    L.append(f"\n## Where a Ji & Li RK4 step goes ({p['n_dof']} DOFs, {p['n_elements']} "
             f"elements, {_f(p['step_ns'] / 1e3)} µs per step)\n")
    L.append("Marginal cost of each part: the step timed with that part removed from a copy "
             "of `_kernels.py`, against the unpatched copy (`bench_kernel_parts.py`): the "
             f"run `simulate` makes of the example (its step, {p.get('groups', '?')} "
             "load-sharing groups), generated right-hand side, plain steps, no history; "
             "every copy compiled in one process and timed in turn, best CPU time of "
             f"{p.get('rounds', '?')} rounds.  A removal also lets the compiler drop the "
             "work that only fed the removed part: without the right-hand-side calls the "
             "RK4 trial states go too, so that row holds them and 'rest' is what no part "
             "needs (the loop and its bookkeeping; the parts need not add up exactly).\n")
    rows = [[k, _f(v["ns_per_step"]), f"{100 * v['share']:.0f} %"]
            for k, v in p["parts"].items()]
    L.append(_table(["part", "ns/step", "share"], rows))
    if p["skipped"]:
        L.append("\nNot measured: " + "; ".join(f"{k} ({v})" for k, v in p["skipped"].items()))

    # ---------------------------------------------------------------- compile
    if comp:
        L.append("\n## Compile time (fresh processes, temporary `NUMBA_CACHE_DIR`)\n")
        runs = comp.get("cold_runs", [])
        if len(runs) > 1:
            L.append(f"Cold: the fastest of {len(runs)} processes, each with a new empty "
                     "cache (RK4 / then Dormand-Prince, s: "
                     + "; ".join(f"{_f(d['compile'])} / {_f(d['compile_dopri'])}" for d in runs)
                     + "); cached: a process that loads the last one's cache.\n")
        rows = []
        for label, d in (("cold (empty cache)", comp["cold"]), ("cached", comp["cached"])):
            rows.append([label, _f(d["import"]), f"**{_f(d['compile'])}**",
                         _f(d["compile_cpu"]), _f(d.get("compile_dopri", float("nan"))),
                         _f(d["first_run"]), _f(d["total"])])
        L.append(_table(["process", "import [s]", "compile_kernels(('rk4',)) [s]", "its CPU [s]",
                         "then compile_kernels(('dopri',)) [s]",
                         "assemble + 1000 steps Ji & Li [s]", "total [s]"], rows))
        L.append("\nnumba's compile timers per kernel in the cold process (inclusive of the "
                 "kernels each one calls, so they do not add up; 'signatures' is how many "
                 "specialisations were compiled):\n")
        rows = [[k, v["n_signatures"], _f(v["compile"]), _f(v["llvm"])]
                for k, v in sorted(comp["cold"]["kernels"].items(),
                                   key=lambda kv: -kv[1]["compile"])]
        L.append(_table(["kernel", "signatures", "compile [s]", "of which LLVM [s]"], rows))

    # ---------------------------------------------------------------- memory
    L.append(f"\n## Memory: {mem['n_steps']:,}-step Ji & Li mill drive run"
             + ("" if mem["n_steps"] >= 10_000_000 else
                " (quick mode: 1 million steps, not 10 million)") + "\n")
    L.append(f"Fresh process, `integrate(method='rk4', record_every={mem['record_every']})`: "
             f"{mem['n_records']:,} history records of every element and DOF, "
             f"{mem['n_cycles']:,} mesh cycles of statistics, {_f(mem['simulated'])} s "
             "simulated.\n")
    L.append(_table(["quantity", "value"], [
        ["wall time [s]", _f(mem["wall"])],
        ["µs/step (CPU µs/step)", f"{_f(mem['us_per_step'])} ({_f(mem['cpu_us_per_step'])})"],
        ["RSS before the run (interpreter, numpy, numba, kernels) [MiB]", _f(mem["rss_before"])],
        ["peak RSS during the run [MiB]", f"**{_f(mem['rss_peak'])}**"],
        ["peak RSS of the whole process (incl. loading the kernels) [MiB]",
         _f(mem["process_maxrss"])],
        ["peak RSS added by the run [MiB]", _f(mem["rss_delta"])],
        ["tracemalloc peak during the run [MiB]", _f(mem["tracemalloc_peak"])],
        ["arrays held by the returned Solution [MiB]", _f(mem["outputs"])],
    ]))
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true",
                   help="fewer steps everywhere; 1 million steps for the memory run")
    p.add_argument("--repeat", type=int, default=2, help="timed runs per case (best kept)")
    p.add_argument("--skip-compile", action="store_true",
                   help="skip the compile-time measurement (one to two minutes)")
    p.add_argument("--output", type=Path, default=HERE / "RESULTS.md",
                   help="markdown file to write (default benchmarks/RESULTS.md)")
    p.add_argument("--render", action="store_true",
                   help="measure nothing: re-render the markdown from its RESULTS.json")
    a = p.parse_args(argv)
    if a.render:
        import json

        res = json.loads(a.output.with_suffix(".json").read_text(encoding="utf-8"))
        a.output.write_text(report(res), encoding="utf-8")
        _log(f"rendered {a.output} from {a.output.with_suffix('.json').name}")
        return 0
    res = run(a.quick, max(1, a.repeat), a.skip_compile)
    text = report(res)
    a.output.write_text(text, encoding="utf-8")
    json_path = a.output.with_suffix(".json")
    import json

    json_path.write_text(json.dumps(res, indent=1, default=_jsonable), encoding="utf-8")
    print(text)
    _log(f"wrote {a.output} and {json_path.name} in {res['elapsed'] / 60:.1f} min")
    return 0


def _jsonable(x):
    try:
        import numpy as np

        if isinstance(x, np.generic):
            return x.item()
        if isinstance(x, np.ndarray):
            return x.tolist()
    except ImportError:
        pass
    return str(x)


if __name__ == "__main__":
    raise SystemExit(main())
