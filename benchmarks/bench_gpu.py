"""The GPU ensemble backend (torquesplit.gpu); writes benchmarks/GPU_RESULTS.json / .md.

    python benchmarks/bench_gpu.py              # everything that this machine can run
    python benchmarks/bench_gpu.py --quick      # 1,000-case Monte Carlo, 100 Liu et al. 2021 cases
    python benchmarks/bench_gpu.py layout       # one part: layout, monte_carlo, liu2021

Not part of the test suite; nothing here asserts a threshold.  The design targets are
printed beside the measured values.  Parts that need a CUDA device are recorded as not
run, with the reason, where there is none (never estimated).

layout       Needs no device, only NVIDIA's compilers (libNVVM, ptxas): for every shipped
             example, FP64 and FP32, the kernel's PTX compile time and what ptxas
             allocates for one thread (registers, spill stores/loads, stack): how far
             one-case-per-thread stays in registers as the DOF count grows.
monte_carlo  Device: Ji & Li's drive (14 DOF), a Monte Carlo over the backlash of its
             four meshes and their damping ratios, 10 s simulated per case (the
             design target's 10,000-case study; --quick 1,000), ``Study.run(backend="gpu")`` end
             to end (CPU set-up of every case incl. its static equilibrium, kernel,
             metrics, store), the kernel time alone, sample-steps per second, the FP32
             run with its error; the CPU study runner on 2 workers on a subsample of the
             same study, extrapolated per case, for the ratio.
liu2021      Device: Liu et al. 2021's reducer (49 DOF) at the paper's resolution, random
             eccentricity phases on every gear, 1,000 cases (--quick 100).
setup        Needs no device: the host's share of a GPU study, per case, on one core --
             the cases of the monte_carlo and liu2021 studies set up as the GPU runner
             sets them up (overrides, model validation and checks, kinematics, assembly,
             static equilibrium: ``gpu.backend.prepare_case``; then the engine's step and
             cycle planning: ``gpu.ensemble.case_arrays``), 64 cases each.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT_JSON = HERE / "GPU_RESULTS.json"
OUT_MD = HERE / "GPU_RESULTS.md"
EXAMPLES = ("ji_li_mill_drive", "mo2017_star_reducer", "dong2021_face_gear",
            "liu2021_split_torque_helicopter", "jin2019_friction_split")


def _log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _device() -> tuple[bool, str]:
    from torquesplit.gpu.compile import cuda_available, cuda_simulated

    ok, why = cuda_available()
    if ok and cuda_simulated():
        return False, "numba's CUDA simulator is on (NUMBA_ENABLE_CUDASIM=1): no timings"
    return ok, why


# ------------------------------------------------------------------------- layout
def layout() -> dict:
    import numpy as np

    import torquesplit
    from torquesplit.gpu.compile import ptx
    from torquesplit.gpu.ensemble import case_arrays
    from torquesplit.gpu.layout import build_group
    from torquesplit.gpu.source import kernel_source
    from torquesplit.simulation import prepare_run

    ptxas = shutil.which("ptxas")
    out = {}
    for name in EXAMPLES:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = prepare_run(torquesplit.example_path(name), duration=1e-3)
        p = case_arrays(run)
        for prec in ("fp64", "fp32"):
            g = build_group([p.case], [0], np.float32 if prec == "fp32" else np.float64)
            src = kernel_source(g, prec)
            row = {"dof": run.structure.n_dof, "elements": run.structure.n_elements,
                   "source_lines": src.n_lines}
            t = time.perf_counter()
            try:
                text = ptx(src)
            except Exception as exc:  # noqa: BLE001 - no libNVVM here
                row["ptx"] = f"not compiled: {type(exc).__name__}: {exc}"[:300]
                out[f"{name}/{prec}"] = row
                continue
            row["ptx_compile_s"] = round(time.perf_counter() - t, 2)
            row["ptx_local_accesses"] = len(re.findall(r"\b(?:ld|st)\.local", text))
            if ptxas:
                with tempfile.TemporaryDirectory() as tmp:
                    f = Path(tmp) / "k.ptx"
                    f.write_text(text)
                    r = subprocess.run([ptxas, "-arch=sm_90", "-v", str(f), "-o",
                                        str(Path(tmp) / "k.cubin")], capture_output=True,
                                       text=True)
                info = r.stderr
                m = re.search(r"Used (\d+) registers", info)
                s = re.search(r"(\d+) bytes spill stores, (\d+) bytes spill loads", info)
                k = re.search(r"(\d+) bytes stack frame", info)
                row.update(registers=int(m.group(1)) if m else None,
                           spill_store_bytes=int(s.group(1)) if s else None,
                           spill_load_bytes=int(s.group(2)) if s else None,
                           stack_bytes=int(k.group(1)) if k else None)
            else:
                row["ptxas"] = "ptxas not found: no register counts"
            out[f"{name}/{prec}"] = row
            _log(f"layout {name} {prec}: {row}")
    return out


# -------------------------------------------------------------------- studies
MC_SPEC = {
    "study": {"name": "gpu_bench_ji_li_mc", "model": "ji_li_mill_drive",
              "outputs": ["load_sharing.engineering*", "peak_to_nominal_engineering.*",
                          "dynamic_factor", "contact_loss.*"]},
    "analysis": {"duration": "10 s"},
    "monte_carlo": {"samples": 10000, "seed": 1, "sampling": "random"},
}


def _mc_spec(n: int) -> dict:
    spec = json.loads(json.dumps(MC_SPEC))
    spec["monte_carlo"]["samples"] = n
    spec["monte_carlo"]["parameters"] = [
        {"paths": ["meshes.*.backlash"], "distribution": "uniform", "low": "1.044 mm",
         "high": "1.702 mm"},
        {"paths": ["meshes.*.damping_ratio"], "distribution": "uniform", "low": 0.05,
         "high": 0.15}]
    return spec


def _timed_study(spec, **kw) -> tuple[float, object]:
    import torquesplit

    t = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        ds = torquesplit.Study(spec).run(out=Path(tmp) / "s", figures=False, **kw)
    return time.perf_counter() - t, ds


def _study_part(spec, cpu_cases: int) -> dict:
    import numpy as np

    n = spec["monte_carlo"]["samples"]
    res = {"cases": n}
    wall, ds = _timed_study(spec, backend="gpu")
    rep = json.loads(ds.attrs["gpu_backend"])
    res["gpu_fp64"] = {"end_to_end_s": wall, **rep,
                       "sample_steps_per_s_kernel": rep["sample_steps"] / rep["kernel_time_s"]}
    _log(f"gpu fp64: {json.dumps(res['gpu_fp64'], default=str)}")  # kept if stopped later
    wall32, ds32 = _timed_study(spec, backend="gpu", precision="fp32")
    rep32 = json.loads(ds32.attrs["gpu_backend"])
    res["gpu_fp32"] = {"end_to_end_s": wall32, **rep32}
    _log(f"gpu fp32: {json.dumps(res['gpu_fp32'], default=str)}")
    sub = json.loads(json.dumps(spec))
    sub["monte_carlo"]["samples"] = cpu_cases
    cwall, cds = _timed_study(sub, workers=2)
    res["cpu_2_workers"] = {"cases": cpu_cases, "wall_s": cwall,
                            "per_case_s": cwall / cpu_cases,
                            # the cases' own times on their workers (no pool start-up):
                            # the 2-core runner's throughput on a long study
                            "case_wall_sum_s": float(cds["case_wall_time"].sum())}
    _log(f"cpu: {json.dumps(res['cpu_2_workers'])}")
    # same cases, same values: the CPU subsample against the GPU's first cases
    diffs = []
    for v in cds.data_vars:
        if v.startswith(("load_sharing", "peak_to", "dynamic", "contact")):
            a = np.asarray(cds[v].values, float)
            b = np.asarray(ds[v].values[:cpu_cases], float)
            ok = np.isfinite(a) & np.isfinite(b)
            if ok.any():
                diffs.append(float(np.max(np.abs(a[ok] - b[ok]) / np.maximum(np.abs(a[ok]),
                                                                             1e-300))))
    res["fp64_max_rel_difference_to_cpu"] = max(diffs) if diffs else None
    res["ratio_to_cpu_runner_end_to_end"] = (res["cpu_2_workers"]["per_case_s"] * n) / wall
    res["ratio_to_cpu_case_throughput"] = (
        res["cpu_2_workers"]["case_wall_sum_s"] / 2 / cpu_cases * n) / wall
    return res


def monte_carlo(quick: bool) -> dict:
    ok, why = _device()
    if not ok:
        return {"run": False, "reason": why}
    return {"run": True, **_study_part(_mc_spec(1000 if quick else 10000), 10 if quick else 20)}


def liu2021(quick: bool) -> dict:
    ok, why = _device()
    if not ok:
        return {"run": False, "reason": why}
    n = 100 if quick else 1000
    spec = {"study": {"name": "gpu_bench_liu", "model": "liu2021_split_torque_helicopter",
                      "outputs": ["load_sharing.cycle_peak*", "dynamic_factor"]},
            "analysis": {"type": "run"},
            "monte_carlo": {"samples": n, "seed": 2, "sampling": "random",
                            "parameters": [{"paths": ["gears.*.errors.eccentricity_phase"],
                                            "distribution": "uniform", "low": "0 deg",
                                            "high": "360 deg"}]}}
    return {"run": True, **_study_part(spec, 4)}


def agreement() -> dict:
    """Where the FP64 GPU run leaves the CPU engine's, on the device test's synthetic
    feature run 0 (every feature: gyroscopic coupling, tooth friction, splines,
    multi-value half-gaps, error sinusoids), which an H200 moved by 2.9e-3 between 1 and
    2 ms (GPU_RESULTS.md).  Without a device: run 0 at 2 ms with each
    input moved by one ulp (how far rounding alone moves it).  On a device: run 0 at
    1..12 ms and run 1 (its pattern, other values) at 12 ms in one ensemble (one
    compile), run 0 ending at every step from 1 to 2 ms (one launch: the first step
    whose end state differs, and its states), then run 0 at 12 ms with one feature
    switched off at a time (a compile each), each logged as it finishes.  Per run: the
    largest relative difference of the end state and of the cycle peaks."""
    import dataclasses

    import numpy as np

    sys.path[:0] = [str(HERE.parent / "tests" / "gpu"), str(HERE.parent / "tests" / "solve")]
    from gpu_cases import engine, feature_runs

    from torquesplit.gpu import ensemble as ens

    def diff(sol, ref, fields=("y_final", "cycle_max")):
        out = {}
        for f in fields:
            a, b = np.asarray(getattr(sol, f)), np.asarray(getattr(ref, f))
            m = np.isfinite(a) & np.isfinite(b)
            out[f] = (float(np.abs(a[m] - b[m]).max() / max(np.abs(b[m]).max(), 1e-300))
                      if m.any() else None)
        return out

    runs = feature_runs()
    r0 = dataclasses.replace(runs[0], duration=2e-3)
    ref0 = engine(r0)
    s0 = r0.structure
    ulp = {}
    rng = np.random.default_rng(0)
    y0 = np.nextafter(r0.y0, np.where(rng.random(np.shape(r0.y0)) < 0.5, -np.inf, np.inf))
    end = ("y_final",)  # (a moved frequency may track another number of cycles)
    ulp["y0"] = diff(engine(dataclasses.replace(r0, y0=y0)), ref0, end)["y_final"]
    for f in ("inv_mass", "damping", "stiffness_table", "phase", "frequency",
              "error_omega", "gap_values", "sp_par"):
        v = np.asarray(getattr(s0, f))
        moved = np.nextafter(v, np.inf * np.sign(v + (v == 0))).astype(v.dtype)
        run = dataclasses.replace(r0, structure=dataclasses.replace(s0, **{f: moved}))
        ulp[f] = diff(engine(run), ref0, end)["y_final"]
    out = {"ulp_sensitivity_run0_2ms": ulp}  # (the rows of an earlier run stay)
    _log(f"agreement: one ulp, run 0 at 2 ms: {ulp}")
    ok, why = _device()
    if not ok:
        return {"run": False, "reason": why, **out}
    lengths = (1, 1.25, 1.5, 1.75, 2, 3, 4, 6, 8, 10, 12)  # one kernel: one compile
    batch = [dataclasses.replace(runs[0], duration=ms * 1e-3) for ms in lengths]
    batch.append(dataclasses.replace(runs[1], duration=12e-3))
    names = [f"run0_{ms:g}ms" for ms in lengths] + ["run1_12ms"]
    rows = {}
    try:
        sols = ens.run_ensemble(batch, target="cuda").solutions
        rows = {n: diff(sol, engine(r)) for n, sol, r in zip(names, sols, batch, strict=True)}
    except Exception as exc:  # noqa: BLE001 - recorded
        rows = {"error": f"{exc!r}"[:300]}
    out["by_length"] = rows
    _log(f"agreement by length: {rows}")
    # step by step from 1 to 2 ms (one launch): the first step whose end state differs
    h = engine(batch[0]).step
    steps = list(range(int(round(1e-3 / h)), int(round(2e-3 / h)) + 1))
    fine = [dataclasses.replace(runs[0], duration=k * h) for k in steps]
    first = {"step": h, "found": None}
    try:
        sols = ens.run_ensemble(fine, target="cuda").solutions
        for k, sol, r in zip(steps, sols, fine, strict=True):
            ref = engine(r)
            dy = np.abs(np.asarray(sol.y_final) - np.asarray(ref.y_final))
            if dy.max() > 1e-12 * np.abs(ref.y_final).max():
                first["found"] = {"steps": k, "t": k * h, "worst_states": np.argsort(
                    dy)[::-1][:4].tolist(), "relative": float(dy.max() / np.abs(
                        ref.y_final).max()), "n_steps": [sol.n_steps, ref.n_steps]}
                break
    except Exception as exc:  # noqa: BLE001 - recorded
        first["error"] = f"{exc!r}"[:300]
    out["first_differing_step_1_to_2ms"] = first
    _log(f"agreement, first differing step: {first}")
    r12 = batch[-2]
    s12 = r12.structure
    sp = np.array(s12.sp_par, dtype=float).reshape(-1, 6)
    off = {"gyroscopic": {"gy_coef": np.zeros_like(s12.gy_coef)},
           "tooth_friction": {"friction_table": np.zeros_like(s12.friction_table)},
           "error_sinusoids": {"error_amplitude": np.zeros_like(s12.error_amplitude)},
           "spline_friction": {"sp_par": np.where(np.arange(6) == 4, 0.0, sp).reshape(
               np.shape(s12.sp_par))}}
    out["feature_off_run0_12ms"] = features = {}
    for name, change in off.items():
        run = dataclasses.replace(r12, structure=dataclasses.replace(s12, **change))
        try:
            features[name] = diff(ens.run_ensemble([run], target="cuda").solutions[0],
                                  engine(run))
        except Exception as exc:  # noqa: BLE001 - recorded
            features[name] = {"error": f"{exc!r}"[:300]}
        _log(f"agreement without {name}: {features[name]}")
    return {"run": True, **out}


def setup() -> dict:
    """Host set-up per case (no device needed), one core."""
    import numpy as np

    import torquesplit
    from torquesplit.gpu.backend import prepare_case
    from torquesplit.gpu.ensemble import case_arrays
    from torquesplit.gpu.layout import build_group, group_cases
    from torquesplit.gpu.source import kernel_source
    from torquesplit.study.case import payload

    liu = {"study": {"name": "gpu_bench_liu", "model": "liu2021_split_torque_helicopter",
                     "outputs": ["load_sharing.cycle_peak*", "dynamic_factor"]},
           "analysis": {"type": "run"},
           "monte_carlo": {"samples": 64, "seed": 2, "sampling": "random",
                           "parameters": [{"paths": ["gears.*.errors.eccentricity_phase"],
                                           "distribution": "uniform", "low": "0 deg",
                                           "high": "360 deg"}]}}
    out = {}
    for name, spec in (("ji_li_monte_carlo", _mc_spec(64)), ("liu2021", liu)):
        plan = torquesplit.Study(spec).plan()
        ps = [payload(i, plan, plan.design.overrides(i)) for i in range(64)]
        prepare_case(ps[0])  # warm: imports, kernels
        t = time.perf_counter()
        runs = [prepare_case(p)["run"] for p in ps]
        t_prep = (time.perf_counter() - t) / len(ps)
        t = time.perf_counter()
        cases = [case_arrays(r).case for r in runs]
        t_plan = (time.perf_counter() - t) / len(ps)
        t = time.perf_counter()
        for idx in group_cases(cases).values():
            kernel_source(build_group(cases, idx, np.float64), "fp64")
        t_launch = (time.perf_counter() - t) / len(ps)
        out[name] = {"cases": len(ps), "prepare_ms": 1e3 * t_prep, "plan_ms": 1e3 * t_plan,
                     "launch_arrays_ms": 1e3 * t_launch, "dof": runs[0].structure.n_dof}
        _log(f"  {name}: {1e3 * (t_prep + t_plan + t_launch):.1f} ms a case")
    return out


# --------------------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("parts", nargs="*",
                    default=["layout", "setup", "monte_carlo", "liu2021"])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    ok, why = _device()
    # parts not run this time keep their last results (``part_dates`` says when each ran)
    result = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    result.update({"date": _dt.datetime.now().isoformat(timespec="seconds"),
                   "host": platform.node(), "cpus": os.cpu_count(),
                   "load_average": os.getloadavg(), "device": why if ok else None,
                   "device_missing_reason": None if ok else why, "quick": args.quick})
    for part in args.parts:
        _log(f"{part} ...")
        if part == "layout":
            result["layout"] = layout()
        elif part == "monte_carlo":
            result["monte_carlo"] = _stamped(monte_carlo(args.quick))
        elif part == "liu2021":
            result["liu2021"] = _stamped(liu2021(args.quick))
        elif part == "setup":
            result["setup"] = setup()
        elif part == "agreement":  # a device session's rows recorded by hand stay
            kept = {k: v for k, v in result.get("agreement", {}).items()
                    if k == "device_session"}
            result["agreement"] = {**kept, **_stamped(agreement())}
        else:
            ap.error(f"unknown part {part!r}")
        result.setdefault("part_dates", {})[part] = _dt.datetime.now().isoformat(
            timespec="seconds")
    OUT_JSON.write_text(json.dumps(result, indent=1, default=str) + "\n")
    OUT_MD.write_text(_markdown(result))
    print(_markdown(result))
    return 0


def _stamped(part: dict) -> dict:
    """A device part's results with where and when they were measured."""
    if part.get("run"):
        part.update(device=_device()[1], host=f"{platform.node()} ({os.cpu_count()} CPUs)",
                    measured=_dt.datetime.now().isoformat(timespec="seconds"))
    return part


def _markdown(r: dict) -> str:
    lines = ["# GPU ensemble backend: measurements", "",
             f"Generated by benchmarks/bench_gpu.py; last run {r['date']} on {r['host']} "
             f"({r['cpus']} CPUs, load {r['load_average']}), device there: "
             f"{r['device'] or 'none (' + str(r['device_missing_reason']) + ')'}. Each part "
             "keeps its last results and says where it ran.", ""]
    if r.get("part_dates"):
        lines += ["Parts last run: " + ", ".join(f"{k} {v}" for k, v in
                                                 r["part_dates"].items()) + ".", ""]
    if "layout" in r:
        lines += ["## One case per thread: what ptxas allocates (sm_90, no device needed)", "",
                  "| model/precision | DOF | source lines | PTX compile s | registers | "
                  "spill stores B | spill loads B | stack B |", "|---|---|---|---|---|---|---|---|"]
        for k, v in r["layout"].items():
            lines.append(f"| {k} | {v.get('dof')} | {v.get('source_lines')} | "
                         f"{v.get('ptx_compile_s', v.get('ptx', ''))} | {v.get('registers')} | "
                         f"{v.get('spill_store_bytes')} | {v.get('spill_load_bytes')} | "
                         f"{v.get('stack_bytes')} |")
        lines.append("")
    if "setup" in r:
        lines += ["## Host set-up per case (one CPU core, no device needed)", "",
                  "What the GPU runner does on the CPU before the kernel, per case: "
                  "overrides, model validation and checks, kinematics, assembly, static "
                  "equilibrium (prepare), then the engine's step and cycle planning (plan), "
                  "then the launch's parameter and table arrays and the kernel source "
                  "(launch).", "", "| study | DOF | cases | prepare [ms] | plan [ms] | "
                  "launch [ms] | total [ms] |", "|---|---|---|---|---|---|---|"]
        for k, v in r["setup"].items():
            la = v.get("launch_arrays_ms", float("nan"))
            lines.append(f"| {k} | {v['dof']} | {v['cases']} | {v['prepare_ms']:.1f} | "
                         f"{v['plan_ms']:.1f} | {la:.2f} | "
                         f"{v['prepare_ms'] + v['plan_ms'] + la:.1f} |")
        lines.append("")
    if r.get("device_notes"):
        lines += ["## Device sessions", ""] + [f"- {n}" for n in r["device_notes"]] + [""]
    for part, target in (("monte_carlo", "design target: 10,000 cases <= 2 s end to end, "
                                         "kernel <= 0.6 s, >= 300x the 2-core CPU runner"),
                         ("monte_carlo_10000", "the same study at the design target's "
                                               "10,000 cases, FP64 only"),
                         ("liu2021", "design target: 1,000 cases <= 60 s"),
                         ("agreement", "FP64 against the CPU engine; see agreement()")):
        if part not in r:
            continue
        v = r[part]
        lines += [f"## {part}", "", f"({target})", ""]
        if not v.get("run"):
            lines += [f"Not run: {v.get('reason')}.", ""]
            continue
        if v.get("device"):
            lines += [f"Device: {v['device']}, measured {v.get('measured', '?')} (host: "
                      f"{v.get('host', r['host'])}).", ""]
        lines += ["```json", json.dumps(v, indent=1, default=str), "```", ""]
    tpb = r.get("threads_per_block")
    if tpb:
        lines += ["## Threads per block", "", f"{tpb['study']}; {tpb['device']}, measured "
                  f"{tpb['measured']}.", "", "| precision | cases | threads/block | kernel [s] "
                  "| sample-steps/s |", "|---|---|---|---|---|"]
        lines += [f"| {x['precision']} | {x['cases']} | {x['tpb']} | {x['kernel_s']} | "
                  f"{x['sample_steps_per_s']:.3g} |" for x in tpb["rows"]]
        lines.append("")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
