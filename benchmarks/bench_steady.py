"""Speed of the periodic steady state and of speed sweeps; writes benchmarks/STEADY_RESULTS.md
and STEADY_RESULTS.json.

    python benchmarks/bench_steady.py [--points 200] [--check 10] [--harmonics H]
    python benchmarks/bench_steady.py --render      # the .md again from the .json

* steady state at one speed (defaults, stability and the periodicity check off but in one
  row): Ji & Li's mill drive over its full period (168 mesh cycles of stage 1: shooting,
  and harmonic balance asked for) and with stage 1's excitations kept; Liu et al. 2021
  with the spur-split stage kept and over its full period (3638 cycles of its fastest
  excitation), also with Floquet stability; Jin et al. 2019 over its full period.  Wall
  time of ``steady_state`` from the model file, after a warm-up call (compilation), best
  of 2 (Jin et al. 2019 and Liu et al. 2021 with stability: 1); accuracy
  against shooting at 1600 RK4 steps per cycle, whose own change at 800 is reported
  beside it (not over the full periods).
* a 200-point speed sweep of Liu et al. 2021 (spur split kept, Floquet stability on);
* a speed sweep of Ji & Li's drive (stage 1 kept, +-20 % speed, ``--points`` points) by
  harmonic-balance continuation against stepping RK4 from the static state to a settled
  state (2000 periods) at ``--check`` of those speeds, extrapolated to all points.  The
  dynamic factor of each is compared at the checked speeds; the RK4 reference is run at
  its default 100 steps per mesh cycle and at 400 (its peaks sampled finely enough to be
  the accurate one), and the continuation at its harmonics (by default those the library
  converges to at the first speed) and twice as many (how far the truncation still moves
  it).  Every call as a user makes it: defaults unless stated.

Not part of the test suite; nothing here asserts a threshold.  The design targets are
printed beside the measured values.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT_MD = HERE / "STEADY_RESULTS.md"
OUT_JSON = HERE / "STEADY_RESULTS.json"
SETTLE_PERIODS = 2000


def best(f, n=2):
    out, t = None, np.inf
    for _ in range(n):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return out, t


REF_STEPS = (800, 1600)
"""RK4 steps per cycle of the fastest excitation of the shooting reference, and half of
them (how far the reference itself still moves)."""


def _kept_mib(ps) -> float:
    """MiB of the arrays a periodic solution keeps (samples, corners, mesh series)."""
    return sum(a.nbytes for a in vars(ps).values() if isinstance(a, np.ndarray)) / 2**20


def one_speed() -> dict:
    from torquesplit.examples import example_path
    from torquesplit.steady import steady_state

    def factors(st):
        return np.array([row.dynamic_factor for row in st.mesh_table()])

    r = {}
    s1 = example_path("ji_li_mill_drive")
    s0 = example_path("liu2021_split_torque_helicopter")
    steady_state(s1, keep="stage1", harmonics=8)  # compile
    steady_state(s1, keep="stage1", method="shooting", stability=False)
    refs = {}
    s2 = example_path("jin2019_friction_split")
    for label, path, kw in (("ji_li_full_period", s1, {}),
                            ("ji_li_full_period_hb", s1, {"method": "hb"}),
                            ("ji_li_stage1", s1, {"keep": "stage1"}),
                            ("liu2021_spur_split", s0, {"keep": "spur_split"}),
                            ("liu2021_full_period", s0, {}),
                            ("liu2021_full_period_stability", s0, {"stability": True}),
                            ("jin2019_full_period", s2, {})):
        long = "full_period" in label and not label.startswith("ji_li")
        st, t = best(lambda path=path, kw=kw: steady_state(
            path, check=False, **({"stability": False} | kw)),
            2 if label in ("liu2021_full_period", ) or not long else 1)
        kept = _kept_mib(st.solution)
        if long:  # a reference 16 times finer over thousands of cycles: not run
            ps = st.solution
            r[label] = dict(seconds=t, solver_seconds=ps.wall_time, method=ps.method,
                            kept_mib=kept,
                            harmonics=ps.harmonics, converged=bool(ps.converged),
                            message=ps.message, cycles=st.period.max_order,
                            max_dynamic_factor_relative_difference_to_shooting=None)
            continue
        # the accuracy: shooting (RK4, REF_STEPS per cycle) on the same kept excitations
        key = (path, kw.get("keep"))
        if key not in refs:
            half, ref = (factors(steady_state(path, method="shooting", steps_per_cycle=spc,
                                              stability=False, check=False,
                                              keep=kw.get("keep")))
                         for spc in REF_STEPS)
            refs[key] = ref, float(np.max(np.abs(half / ref - 1.0)))
        ref, ref_moves = refs[key]
        ps = st.solution
        r[label] = dict(seconds=t, solver_seconds=ps.wall_time, method=ps.method,
                        kept_mib=kept, harmonics=ps.harmonics, converged=bool(ps.converged),
                        message=ps.message, reference_steps_per_cycle=REF_STEPS[1],
                        reference_change_at_half_the_steps=ref_moves,
                        max_dynamic_factor_relative_difference_to_shooting=float(
                            np.max(np.abs(factors(st) / ref - 1.0))))
    return r


def sweep(points: int, check: int, harmonics: int) -> dict:
    from torquesplit.examples import example_path
    from torquesplit.model.io import load_model
    from torquesplit.steady import sweep_speed
    from torquesplit.steady.maps import _prepare
    from torquesplit.steady.problem import PeriodicProblem
    from torquesplit.steady.sweep import stepped_sweep

    m = load_model(example_path("ji_li_mill_drive"))
    w = abs(m.drives["motor"].speed)

    def continuation(**kw):
        return sweep_speed(m, 0.8 * w, 1.2 * w, points=points, keep="stage1",
                           stability=False, max_step=0.4 * w / (points - 1), **kw)

    def at(ds, sp):  # dynamic factors of a sweep at speeds sp [rad/s] (per mesh)
        return np.array([np.interp(sp, ds["speed"].values, ds["dynamic_factor"].values[:, j])
                         for j in range(ds.sizes["mesh"])]).T

    continuation()  # compile
    ds, t_sweep = best(lambda: continuation(), 1)  # the default: shooting
    # its own steps doubled (samples: RK4 steps per period, one mesh cycle here)
    fine = continuation(steps_per_cycle=2 * int(ds.attrs["samples"]))
    hb_kw = {} if harmonics is None else {"harmonics": harmonics}
    continuation(method="hb", **hb_kw)
    ds_hb, t_hb = best(lambda: continuation(method="hb", **hb_kw), 1)
    h = int(ds_hb.attrs["harmonics"])
    ds_hb2 = continuation(method="hb", harmonics=2 * h)
    model, _, s, _, per, static = _prepare(m, "stage1", 1000)
    p = PeriodicProblem(s, per.frequency)
    idx = np.linspace(0, ds.sizes["point"] - 1, check).astype(int)
    sp_rad = ds["speed"].values[idx]
    speeds = sp_rad / w
    names = list(s.element_names)
    track = [names.index(x) for x in model.meshes]
    static_f = np.array([static.element_forces[e] for e in track])
    df = ds["dynamic_factor"].values[idx]

    def rel(a, b):
        return float(np.max(np.abs(a / b - 1.0)))

    out = dict(points=int(ds.sizes["point"]), method=ds.attrs["method"],
               continuation_seconds=t_sweep, settle_periods=SETTLE_PERIODS,
               steps_doubled_dynamic_factor_relative_change=rel(at(fine, sp_rad), df),
               hb_points=int(ds_hb.sizes["point"]), harmonics=h,
               harmonics_default=harmonics is None, hb_continuation_seconds=t_hb,
               hb_dynamic_factor_relative_difference=rel(at(ds_hb, sp_rad), df),
               hb_truncation_dynamic_factor_relative_change=rel(at(ds_hb2, sp_rad),
                                                                at(ds_hb, sp_rad)),
               stepping={})
    for spc in (None, 400):
        stepped_sweep(p, per, static.q, [speeds[0]], settle_periods=5, track=track,
                      steps_per_cycle=spc)  # compile
        t0 = time.perf_counter()
        peaks = []
        for sp in speeds:  # each speed from the static state (no carried-over state)
            pk, _ = stepped_sweep(p, per, static.q, [sp], settle_periods=SETTLE_PERIODS,
                                  track=track, steps_per_cycle=spc)
            peaks.append(pk[0])
        t_ti = (time.perf_counter() - t0) / len(speeds) * ds.sizes["point"]
        df_ti = np.array(peaks) / static_f
        out["stepping"][str(spc or 100)] = dict(
            seconds_extrapolated=t_ti, speed_up=t_ti / t_sweep,
            max_dynamic_factor_relative_difference=rel(df_ti, df))
    return out


def liu_sweep(points: int) -> dict:
    """Liu et al. 2021 (spur split kept), +-20 % speed, with Floquet stability (default)."""
    from torquesplit.examples import example_path
    from torquesplit.model.io import load_model
    from torquesplit.steady import sweep_speed

    m = load_model(example_path("liu2021_split_torque_helicopter"))
    w = abs(next(iter(m.drives.values())).speed)
    sweep_speed(m, 0.8 * w, 1.2 * w, points=5, keep="spur_split")  # compile
    ds, t = best(lambda: sweep_speed(m, 0.8 * w, 1.2 * w, points=points, keep="spur_split",
                                     max_step=0.4 * w / (points - 1)), 1)
    return dict(points=int(ds.sizes["point"]), harmonics=int(ds.attrs["harmonics"]),
                method=ds.attrs["method"], seconds=t, complete=bool(ds.attrs["complete"]),
                unstable_points=int((~ds["stable"].values).sum()))


def waveforms() -> list:
    """Every shipped example's steady state (one stage kept where the full period is long)
    against the last period of a long time integration (scripts/steady_vs_integration.py)."""
    import importlib.util

    from torquesplit.examples import example_names

    spec = importlib.util.spec_from_file_location(
        "steady_vs_integration", HERE.parent / "scripts" / "steady_vs_integration.py")
    svi = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(svi)
    return [svi.compare(name, svi.KEEP.get(name)) for name in example_names()]


def _machine() -> dict:
    sys.path.insert(0, str(HERE))
    from bench_study import _machine as machine
    return machine()


def report(res: dict) -> str:
    m = res["machine"]
    o, s = res["one_speed"], res["sweep"]
    lines = ["# Periodic steady state speed (benchmarks/bench_steady.py)", "",
             f"{m['date']}, {m['platform']}, {m['cpu_count']} cpus, Python {m['python']}, "
             f"numba {m['numba']}, torquesplit {m['torquesplit']} (commit {m['commit']}); "
             f"load average at start {m['load_average'][0]:.2f}.  Wall times after "
             "compilation (a warm-up call first).", "",
             "## One speed (`steady_state` from the model file, best of 2; Jin et al. 2019's "
             "full period and Liu et al. 2021's with stability: 1)", "",
             "Defaults (method 'auto': shooting, matrix-free on a long period, unless "
             "harmonics are asked for) "
             "unless the method column says 'hb (asked)'; stability (unless the row says "
             "otherwise: the monodromy's columns on as many threads as the CPUs) and the "
             "periodicity check off.  Accuracy: the largest relative difference of a "
             "mesh's dynamic factor to "
             f"shooting with {REF_STEPS[1]} RK4 steps per cycle of the fastest excitation on "
             f"the same excitations; 'reference moves' is how far that reference's own "
             f"dynamic factors move at {REF_STEPS[0]} steps per cycle (not run over the "
             f"full periods of thousands of cycles: '-').  'Arrays kept': the solution's "
             f"samples, corner instants and per-step mesh series (a long period keeps the "
             f"meshes at every RK4 step, the rest at up to 65,536 steps).  The design targets "
             f"name none for Jin et al. 2019.", "",
             "| model | excitations | method | harmonics | wall [s] | of which solver [s] | "
             "arrays kept [MiB] | dynamic factor vs reference | reference moves | target | "
             "status |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    rows = (("Ji & Li mill drive", "all (full period)", "ji_li_full_period", 0.2),
            ("Ji & Li mill drive", "all (full period)", "ji_li_full_period_hb", 0.2),
            ("Ji & Li mill drive", "stage 1 kept", "ji_li_stage1", 0.2),
            ("Liu et al. 2021", "spur split kept", "liu2021_spur_split", 2.0),
            ("Liu et al. 2021", "all (full period)", "liu2021_full_period", 2.0),
            ("Liu et al. 2021", "all (full period), Floquet stability on (the CLI's "
             "default)", "liu2021_full_period_stability", None),
            ("Jin et al. 2019", "all (full period)", "jin2019_full_period", None))
    for name, kept, key, target in rows:
        if key not in o:
            continue
        r = o[key]
        ok = ("-" if target is None else "ok" if r["seconds"] < target and r["converged"]
              else "**not met**")
        meth = r.get("method", "hb") + (" (asked)" if key.endswith("_hb") else "")
        if key.endswith("_hb"):  # not the default: for comparison, no target
            target, ok = None, "-"
        ref = r.get("reference_change_at_half_the_steps")
        acc = r["max_dynamic_factor_relative_difference_to_shooting"]
        if "cycles" in r:
            kept = f"{kept}, {r['cycles']} cycles"
        mib = f"{r['kept_mib']:.3g}" if "kept_mib" in r else "-"
        lines.append(f"| {name} | {kept} | {meth} | {r['harmonics'] or '-'} | "
                     f"**{r['seconds']:.3f}** | {r['solver_seconds']:.3f} | {mib} | "
                     f"{'-' if acc is None else f'{acc:.1e}'} | "
                     f"{'-' if ref is None else f'{ref:.1e}'} | "
                     f"{'-' if target is None else f'< {target:g} s'} | {ok} |")
    st100, st400 = s["stepping"]["100"], s["stepping"]["400"]
    lines += ["", f"## Speed sweep, Ji & Li mill drive, stage 1 kept, +-20 % speed, "
              f"{s['points']} points", "",
              f"The default continuation ({s.get('method', 'harmonic balance')}; stability "
              f"off) against RK4 stepped from the static state for {s['settle_periods']} "
              "periods at each speed (timed at 10 speeds, extrapolated to every point), "
              "dynamic factors compared at those 10 speeds.  Doubling the continuation's "
              "steps per cycle moves its dynamic factors by at most "
              f"{s.get('steps_doubled_dynamic_factor_relative_change', math.nan):.1e}.  "
              f"Harmonic-balance continuation for comparison: {s['hb_points']} points, "
              f"{s['harmonics']} harmonics per mesh cycle "
              f"({'chosen by the library' if s.get('harmonics_default') else 'asked for'}), "
              f"**{s['hb_continuation_seconds']:.2f} s**, dynamic factors within "
              f"{s.get('hb_dynamic_factor_relative_difference', math.nan):.1e} of the "
              "default's; doubling its harmonics moves them by "
              f"{s['hb_truncation_dynamic_factor_relative_change']:.1e}.", "",
              "| RK4 steps per mesh cycle | stepping [s] | continuation [s] | speed-up | "
              "largest relative dynamic-factor difference | target | status |",
              "|---|---|---|---|---|---|---|"]
    t_cont = s.get("continuation_seconds", s.get("hb_continuation_seconds"))
    for spc, r in (("100 (default)", st100), ("400", st400)):
        ok = "ok" if r["speed_up"] >= 20 else "**not met**"
        lines.append(f"| {spc} | {r['seconds_extrapolated']:.1f} | {t_cont:.2f} | "
                     f"**{r['speed_up']:.0f}x** | "
                     f"{r['max_dynamic_factor_relative_difference']:.1e} | >= 20x | {ok} |")
    lines.append("")
    if "liu2021_sweep" in res:
        lw = res["liu2021_sweep"]
        ok = "ok" if lw["seconds"] < 120 and lw["complete"] else "**not met**"
        how = (f"{lw['harmonics']} harmonics" if lw.get("harmonics")
               else lw.get("method", "shooting"))
        lines += [f"Liu et al. 2021, spur split kept, +-20 % speed, {lw['points']} points, "
                  f"{how}, Floquet stability at every point: "
                  f"**{lw['seconds']:.1f} s** (target < 120 s on 2 cores: {ok}; "
                  f"{lw['unstable_points']} unstable points).", ""]
    if "waveforms" in res:
        lines += _waveform_table(res["waveforms"])
    return "\n".join(lines)


def _waveform_table(rows: list) -> list:
    out = ["## Against long time integration, every shipped example", "",
           "The largest difference of each mesh-force waveform over one period between the "
           "steady state and the last period of `integrate` (RK4, the same step, from the "
           "static state after the settling time shown), over the waveform's peak-to-peak "
           "amplitude; the largest over the meshes.  Defaults otherwise (harmonic balance: "
           "its harmonics converged by the library).  'Transient left': the largest Floquet "
           "multiplier of the shooting solution to the power of the periods the long run "
           "settled, the share of its start that the slowest mode still holds (the long run "
           "is no reference where it is not small).  Target 1e-3 where the response is "
           "periodic (`scripts/steady_vs_integration.py`).", "",
           "| example | excitations | settled [s] | transient left | HB harmonics | HB | "
           "shooting | status |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "skipped" in r:
            out.append(f"| {r['example']} | - | - | - | - | - | - | skipped: "
                       f"{r['skipped']} |")
            continue
        err = {k: max(v.values()) for k, v in r["max_error_over_amplitude"].items()}
        left = r.get("transient_left", 0.0)
        ok = ("ok" if max(err.values()) <= 1e-3 else
              "long run not settled" if left > 1e-3 else
              "shooting ok, HB **not met**" if err.get("shooting", 1.0) <= 1e-3 else
              "**not met**")
        again = (f" (re-measured {r['remeasured']})" if r.get("remeasured") else "")
        out.append(f"| {r['example']} | {r['keep'] or 'all'} | {r['settle_s']:.3g} | "
                   f"{left:.1e} | {r.get('harmonics') or '-'} | "
                   + " | ".join(f"{err[m]:.1e}" if m in err else "-"
                                for m in ("hb", "shooting")) + f" | {ok}{again} |")
    out.append("")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--check", type=int, default=10)
    ap.add_argument("--harmonics", type=int, default=None,
                    help="HB harmonics per mesh cycle of the sweep (default: the library's "
                         "choice, converged at the first speed)")
    ap.add_argument("--render", action="store_true", help="rewrite the .md from the .json")
    args = ap.parse_args(argv)
    if args.render:
        OUT_MD.write_text(report(json.loads(OUT_JSON.read_text())))
        return 0
    warnings.simplefilter("ignore")
    res = {"machine": _machine(), "one_speed": one_speed(),
           "sweep": sweep(args.points, args.check, args.harmonics),
           "liu2021_sweep": liu_sweep(args.points), "waveforms": waveforms()}
    OUT_JSON.write_text(json.dumps(res, indent=1) + "\n")
    OUT_MD.write_text(report(res))
    print(report(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
