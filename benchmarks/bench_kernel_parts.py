"""Where an RK4 step's time goes: the marginal cost of each part of the step, in situ.

An isolated building block timed in its own loop misses what matters in the real step
(inlining, registers, the memory traffic of its neighbours).  Here each part is instead
*removed* from a copy of ``solve/_kernels.py`` and the whole RK4 step is timed without
it; the difference to the unpatched copy is the part's marginal cost per step.  The
parts: the four right-hand-side evaluations (the generated code), the excitation at
t + h/2 and t + h, the statistics (per-cycle extremes, means, the load-sharing ratios,
contact counters) and the divergence check; what is left is the RK4 vector arithmetic,
the loop, the history and corner bookkeeping.  A removal that no longer matches the
kernel's source is reported as skipped, not fatal.

The run is the one ``simulate`` makes of the example (its step, tracked meshes and
load-sharing groups), with ``rhs="generated"``, plain steps (``corners=False``) and no
history.  Every copy is compiled in ONE fresh process (without numba's cache) and the
copies are timed in turn, ``rounds`` times, each round starting with the next copy; the
best CPU time of each is kept.  (Timing each copy in its own process, as this benchmark
first did, compared processes whose speed differs by tens of per cent on a shared
machine: parts summed to 180 % of the step.)  Runnable alone:
``python benchmarks/bench_kernel_parts.py [EXAMPLE]``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KERNELS = ROOT / "src" / "torquesplit" / "solve" / "_kernels.py"

# part -> (what to remove, what to put instead); a part whose text is not found is skipped
REMOVALS = {
    "right-hand side (4 calls)": [("        rhs_fn(a[A_SELF], a[A_Y] + row * np.uint64(iy)", None)],
    "excitation (t + h/2, t + h)": [
        ("            excite(t_end if last else t_mid, sb if last else s_half,\n"
         "                   src_end if last else src_half, m, w)\n", "            pass\n")],
    "statistics (record)": [("        record(t, a, F_MAIN, m, w, r, counters)\n", "")],
    "  of it: parabola vertices (force_instant)": [
        ("        g2 = regime(defl[i_f, el], G[slot, el])\n        if smooth:\n",
         "        g2 = 0\n        if False:\n")],
    "  of it: ratio at cycle starts (ratio_starts)": [
        ("        ratio_starts(t, slot, i_f, m, w, r)\n", "        pass\n")],
    "  of it: cycle means (force_instant)": [
        ("        if not first:\n            if c == c1 + 1:",
         "        if False:\n            if c == c1 + 1:")],
    "  of it: instantaneous ratio (ratio_sample)": [
        ("    ratio_sample(slot, i_f, w, r)\n", "")],
    "  of it: contact counters": [("    for j in range(watch_el.shape[0]):\n",
                                   "    for j in range(0):\n")],
    "divergence check": [("        bad = bad_state(Y_STATE, w)\n", "        bad = -1\n")],
}
BASE = "whole step"

_RUN = r"""
import json, sys, time, warnings, importlib.util
warnings.simplefilter("ignore")
sys.path.insert(0, {src!r})
import torquesplit as ts
import torquesplit.solve.integrate
from torquesplit.simulation import prepare_run
I = sys.modules["torquesplit.solve.integrate"]
variants = json.loads({variants!r})
mods = {{}}
for k, (name, path) in enumerate(variants):
    spec = importlib.util.spec_from_file_location(f"torquesplit.solve._kernels_part{{k}}", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mods[name] = mod
run = prepare_run(ts.load_model(ts.example_path({example!r})))
s, y0 = run.structure, run.y0
kw = dict(run.integrate_kwargs, history_elements=(), history_dofs=(), corners=False,
          rhs="generated", progress=None)
kw.pop("sample_interval", None)
h = I.planned_step(s, kw.pop("steps_per_period", None), run.duration)[0]  # simulate's
kw["step"] = h
for name, mod in mods.items():  # compile every copy before any timing
    I.kern = mod
    I.integrate(s, y0, (0.0, 100 * h), **kw)
best = {{name: float("inf") for name in mods}}
names = list(mods)
for rnd in range({rounds}):
    for name in names[rnd % len(names):] + names[:rnd % len(names)]:
        I.kern = mods[name]
        t0 = time.process_time()
        sol = I.integrate(s, y0, (0.0, {steps} * h), **kw)
        best[name] = min(best[name], (time.process_time() - t0) / sol.n_steps * 1e9)
print(json.dumps({{"ns_per_step": best, "n_dof": s.n_dof, "n_elements": s.n_elements,
                  "step": h, "groups": len(kw["load_sharing_groups"] or ())}}))
"""


def _patched(source: str, removals) -> str | None:
    for old, new in removals:
        if old not in source:
            return None
        if new is None:  # the generated call spans lines: drop it up to its closing ")"
            i0 = source.index(old)
            i1 = source.index("np.int64(slot * w.F.shape[1]))", i0) + len(
                "np.int64(slot * w.F.shape[1]))")
            source = source[:i0] + "        pass" + source[i1:]
        else:
            source = source.replace(old, new)
    return source


def _time_all(sources: dict, steps: int, rounds: int, example: str) -> dict:
    """Best CPU ns per step of every source, all compiled in one fresh process (no
    numba cache) and timed in turn, ``rounds`` times (each round starting one later)."""
    with tempfile.TemporaryDirectory() as tmp:
        variants = []
        for k, (name, source) in enumerate(sources.items()):
            path = Path(tmp) / f"_kernels_part{k}.py"
            path.write_text(source.replace("cache=True, ", ""), encoding="utf-8")
            variants.append((name, str(path)))
        code = _RUN.format(src=str(ROOT / "src"), variants=json.dumps(variants),
                           steps=steps, rounds=rounds, example=example)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=1800, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def breakdown(steps: int = 200_000, rounds: int = 7, example: str = "ji_li_mill_drive") -> dict:
    """Marginal ns per step of each part (see the module docstring) and of the whole."""
    source = KERNELS.read_text(encoding="utf-8")
    sources, skipped = {BASE: source}, {}
    for name, removals in REMOVALS.items():
        patched = _patched(source, removals)
        if patched is None:
            skipped[name] = "its text is no longer in _kernels.py"
        else:
            sources[name] = patched
    res = _time_all(sources, steps, rounds, example)
    ns = res["ns_per_step"]
    base = ns[BASE]
    parts = {name: {"ns_per_step": base - ns[name], "share": (base - ns[name]) / base}
             for name in sources if name != BASE}
    rest = base - sum(p["ns_per_step"] for k, p in parts.items() if not k.startswith("  of it"))
    parts["rest (RK4 vectors, loop, bookkeeping)"] = {"ns_per_step": rest,
                                                       "share": rest / base}
    return {"example": example, "step_ns": base, "n_dof": res["n_dof"],
            "n_elements": res["n_elements"], "step": res["step"], "groups": res["groups"],
            "steps": steps, "rounds": rounds, "parts": parts, "skipped": skipped}


if __name__ == "__main__":
    name = sys.argv[1] if len(sys.argv) > 1 else "ji_li_mill_drive"
    res = breakdown(example=name)
    print(f"{name}, {res['step_ns']:.0f} ns per RK4 step of {res['step']:.3g} s "
          f"({res['groups']} load-sharing groups, best of {res['rounds']} rounds):")
    for k, v in res["parts"].items():
        print(f"  {k:40s} {v['ns_per_step']:7.1f} ns  {100 * v['share']:5.1f} %")
