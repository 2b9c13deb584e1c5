"""Where an RK4 step's time goes: the marginal cost of each part of the step, in situ.

An isolated building block timed in its own loop misses what matters in the real step
(inlining, registers, the memory traffic of its neighbours).  Here each part is instead
*removed* from a copy of ``solve/_kernels.py`` (a patched source, compiled in a fresh
process without numba's cache), and the whole RK4 step of the Ji & Li drive is timed
without it; the difference to the unpatched copy is the part's marginal cost per step.
The parts: the four right-hand-side evaluations (the generated code), the excitation at
t + h/2 and t + h, the statistics (per-cycle extremes, the load-sharing ratio, contact
counters) and the divergence check; what is left is the RK4 vector arithmetic, the loop,
the history and corner bookkeeping.  A removal that no longer matches the kernel's source
is reported as skipped, not fatal.  Every run: ``rhs="generated"``, plain steps
(``corners=False``), no history, best CPU time of ``repeat``.  Runnable alone:
``python benchmarks/bench_kernel_parts.py``.
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
    "right-hand side (4 calls)": [("        rhs_fn(a[A_Y] + row * np.uint64(iy)", None)],
    "excitation (t + h/2, t + h)": [
        ("            excite(t_end if last else t_mid, sb if last else s_half,\n"
         "                   src_end if last else src_half, m, w)\n", "            pass\n")],
    "statistics (record)": [("        record(t, a, F_MAIN, 0.0 if last else h, m, w, r, counters)\n",
                             "")],
    "  of it: parabola vertices (peak_sample)": [
        ("        peak_sample(t, kink, slot, i_f, w, r)\n", "")],
    "  of it: ratio at cycle starts (ratio_starts)": [
        ("        ratio_starts(t, slot, i_f, m, w, r)\n", "")],
    "  of it: cycle means (mean_sample)": [
        ("        mean_sample(t, slot, i_f, m, w, r)\n    ratio_sample", "    ratio_sample")],
    "  of it: instantaneous ratio (ratio_sample)": [
        ("        mean_sample(t, slot, i_f, m, w, r)\n    ratio_sample(slot, i_f, w, r)\n",
         "        mean_sample(t, slot, i_f, m, w, r)\n")],
    "divergence check": [("        bad = bad_state(Y_STATE, blowup, w)\n", "        bad = -1\n")],
}

_RUN = r"""
import json, sys, time, warnings, importlib.util
warnings.simplefilter("ignore")
sys.path.insert(0, {src!r})
import torquesplit as ts
import torquesplit.solve.integrate
spec = importlib.util.spec_from_file_location("torquesplit.solve._kernels_part", {path!r})
mod = importlib.util.module_from_spec(spec); spec.loader.exec_module(mod)
I = sys.modules["torquesplit.solve.integrate"]
I.kern = mod
from torquesplit.solve import static_equilibrium
s = ts.assemble(ts.load_model(ts.example_path({example!r})))
y0 = static_equilibrium(s).y0
f = float(s.frequency[s.frequency > 0].max())
h = 1.0 / (400 * f)
kw = dict(method="rk4", step=h, history_elements=(), history_dofs=(), corners=False,
          rhs="generated")
I.integrate(s, y0, (0, 100 * h), **kw)
best = 1e9
for _ in range({repeat}):
    t0 = time.process_time()
    sol = I.integrate(s, y0, (0, {steps} * h), **kw)
    best = min(best, (time.process_time() - t0) / sol.n_steps)
print(json.dumps({{"ns_per_step": best * 1e9, "n_dof": s.n_dof, "n_elements": s.n_elements}}))
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


def _time(source: str, steps: int, repeat: int, example: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "_kernels_part.py"
        path.write_text(source.replace("cache=True, ", ""), encoding="utf-8")
        code = _RUN.format(src=str(ROOT / "src"), path=str(path), steps=steps, repeat=repeat,
                           example=example)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=900, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def breakdown(steps: int = 200_000, repeat: int = 3, example: str = "ji_li_mill_drive") -> dict:
    """Marginal ns per step of each part (see the module docstring) and of the whole."""
    source = KERNELS.read_text(encoding="utf-8")
    base = _time(source, steps, repeat, example)
    parts, skipped = {}, {}
    for name, removals in REMOVALS.items():
        patched = _patched(source, removals)
        if patched is None:
            skipped[name] = "its text is no longer in _kernels.py"
            continue
        without = _time(patched, steps, repeat, example)["ns_per_step"]
        cost = base["ns_per_step"] - without
        parts[name] = {"ns_per_step": cost, "share": cost / base["ns_per_step"]}
    rest = base["ns_per_step"] - sum(p["ns_per_step"] for k, p in parts.items()
                                     if not k.startswith("  of it"))
    parts["rest (RK4 vectors, loop, bookkeeping)"] = {
        "ns_per_step": rest, "share": rest / base["ns_per_step"]}
    return {"step_ns": base["ns_per_step"], "n_dof": base["n_dof"],
            "n_elements": base["n_elements"], "parts": parts, "skipped": skipped}


if __name__ == "__main__":
    name = sys.argv[1] if len(sys.argv) > 1 else "ji_li_mill_drive"
    res = breakdown(example=name)
    print(f"{name}, {res['step_ns']:.0f} ns per RK4 step:")
    for k, v in res["parts"].items():
        print(f"  {k:40s} {v['ns_per_step']:7.1f} ns  {100 * v['share']:5.1f} %")
