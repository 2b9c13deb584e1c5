"""A transcription generated from the assembled structure (checks kernel overhead, not
assembly).

:func:`specialised_source` writes a straight-line RK4 of one model *from the engine's
own assembled structure*: one Python statement per non-zero of the equations, every
coefficient, stiffness, damping, mass and DOF index a literal, no index arrays, no
element loop, no generality.  It is compiled with numba (same flags as the engine) and
timed in the same process as the engine, so the ratio does not depend on how loaded the
machine is.  Because its equations come from the assembly, it measures the overhead of
the kernels but cannot reveal an error of the assembly; the independent baseline, the
Ji & Li equations written by hand from the paper, is ``bench_transcription.py``.

What the specialised code does per step, like the engine: classic RK4; mesh stiffness
interpolated in the same periodic tables at each distinct stage time (t, t + h/2,
t + h, the last reused by the next step); dead zones (backlash, clearance); per-mesh-
cycle max / min / sum / count of every mesh force at the start of each step; a history
row of mesh forces and states every ``record_every`` steps.  It does not do: error
sinusoids, additive force tables, tooth friction, splines, contact-loss counters,
divergence checks or chunking (models with the first four are refused).
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit


def supported(s) -> str | None:
    """None if the structure can be transcribed, else why not."""
    if s.error_amplitude.size:
        return "error sinusoids"
    if np.any(s.force_table != 0):
        return "additive force tables (impact)"
    if len(s.fr_el):
        return "tooth friction"
    if s.sp_el.size:
        return "splines"
    if np.any(np.diff(s.gap_ptr) != 1):
        return "per-cycle gap sequences"
    return None


def _lit(x: float) -> str:
    return repr(float(x))


def specialised_source(s, name: str = "specialised_rk4") -> str:
    """Python source of ``name(y, t0, h, n_steps, tab, freq, phase, cyc_max, cyc_min,
    cyc_sum, cyc_cnt, record_every, hist_t, hist_f, hist_y)`` for structure ``s``."""
    why = supported(s)
    if why:
        raise ValueError(f"cannot transcribe a structure with {why}")
    n = s.n_dof
    tv = [e for e in range(s.n_elements) if s.frequency[e] > 0]
    slot = {e: j for j, e in enumerate(tv)}
    lines = [
        f"def {name}(y, t0, h, n_steps, tab, freq, phase, cyc_max, cyc_min, cyc_sum,",
        "        cyc_cnt, record_every, hist_t, hist_f, hist_y):",
        "    n_tab = tab.shape[1]",
        "    cap = cyc_max.shape[0]",
        f"    ka = np.empty({len(tv)})",
        f"    kh = np.empty({len(tv)})",
        f"    kb = np.empty({len(tv)})",
        f"    cyc = np.empty({len(tv)}, dtype=np.int64)",
        f"    k1 = np.empty({2 * n})",
        f"    k2 = np.empty({2 * n})",
        f"    k3 = np.empty({2 * n})",
        f"    k4 = np.empty({2 * n})",
        f"    yt = np.empty({2 * n})",
        f"    fm = np.empty({len(tv)})",
        "    _excite(t0, tab, freq, phase, ka, cyc)",
        "    row = 0",
        "    for i in range(n_steps):",
        "        t = t0 + i * h",
        "        _rhs(y, ka, k1, fm)",
        "        for m in range(fm.shape[0]):",
        "            c = cyc[m]",
        "            if c >= 0 and c < cap:",
        "                if fm[m] > cyc_max[c, m]:",
        "                    cyc_max[c, m] = fm[m]",
        "                if fm[m] < cyc_min[c, m]:",
        "                    cyc_min[c, m] = fm[m]",
        "                cyc_sum[c, m] += fm[m]",
        "                cyc_cnt[c, m] += 1",
        "        if i % record_every == 0 and row < hist_t.shape[0]:",
        "            hist_t[row] = t",
        "            hist_f[row, :] = fm",
        "            hist_y[row, :] = y",
        "            row += 1",
        "        _excite(t + 0.5 * h, tab, freq, phase, kh, cyc)",
        f"        for m in range({2 * n}):",
        "            yt[m] = y[m] + 0.5 * h * k1[m]",
        "        _rhs(yt, kh, k2, fm)",
        f"        for m in range({2 * n}):",
        "            yt[m] = y[m] + 0.5 * h * k2[m]",
        "        _rhs(yt, kh, k3, fm)",
        "        _excite(t0 + (i + 1) * h, tab, freq, phase, kb, cyc)",
        f"        for m in range({2 * n}):",
        "            yt[m] = y[m] + h * k3[m]",
        "        _rhs(yt, kb, k4, fm)",
        f"        for m in range({2 * n}):",
        "            y[m] += h / 6.0 * (k1[m] + 2.0 * (k2[m] + k3[m]) + k4[m])",
        "        ka, kb = kb, ka",
        "    return row",
        "",
        "",
        "def _excite(t, tab, freq, phase, k, cyc):",
        "    n_tab = tab.shape[1]",
    ]
    for j in range(len(tv)):
        lines += [
            f"    s = freq[{j}] * t + phase[{j}]",
            "    fl = math.floor(s)",
            "    x = (s - fl) * n_tab",
            "    i0 = int(x)",
            "    if i0 >= n_tab:",
            "        i0 -= n_tab",
            "    i1 = i0 + 1 if i0 + 1 < n_tab else 0",
            f"    k[{j}] = tab[{j}, i0] + (x - int(x)) * (tab[{j}, i1] - tab[{j}, i0])",
            f"    cyc[{j}] = int(fl) + 1 if s - fl >= 1.0 - 1e-9 else int(fl)",
        ]
    lines += ["", "", "def _rhs(y, k, dy, fm):"]
    gens: dict[int, list[str]] = {i: [] for i in range(n)}
    for e in range(s.n_elements):
        idx = s.v_dof[s.v_ptr[e]:s.v_ptr[e + 1]]
        cf = s.v_coef[s.v_ptr[e]:s.v_ptr[e + 1]]
        err = s.error_constant[e]
        d = " + ".join(f"{_lit(c)} * y[{i}]" for i, c in zip(idx, cf)) or "0.0"
        r = " + ".join(f"{_lit(c)} * y[{n + i}]" for i, c in zip(idx, cf)) or "0.0"
        lines.append(f"    d{e} = {d}" + (f" - {_lit(err)}" if err else ""))
        lines.append(f"    r{e} = {r}")
        k = f"k[{slot[e]}]" if e in slot else _lit(s.stiffness_table[e, 0])
        c = _lit(s.damping[e])
        g = float(s.gap_values[s.gap_ptr[e]])
        if g > 0:
            lines += [
                f"    if d{e} > {_lit(g)}:",
                f"        f{e} = {k} * (d{e} - {_lit(g)}) + {c} * r{e}",
                f"    elif d{e} < {_lit(-g)}:",
                f"        f{e} = {k} * (d{e} + {_lit(g)}) + {c} * r{e}",
                "    else:",
                f"        f{e} = 0.0",
            ]
        else:
            lines.append(f"    f{e} = {k} * d{e} + {c} * r{e}")
        if e in slot:
            lines.append(f"    fm[{slot[e]}] = f{e}")
        for i, cc in zip(idx, cf):
            gens[int(i)].append(f"{_lit(cc)} * f{e}")
    for i in range(n):
        acc = _lit(s.external_force[i])
        if s.ground_damping[i]:
            acc += f" - {_lit(s.ground_damping[i])} * y[{n + i}]"
        if gens[i]:
            acc += " - (" + " + ".join(gens[i]) + ")"
        lines.append(f"    dy[{i}] = y[{n + i}]")
        lines.append(f"    dy[{n + i}] = {_lit(s.inv_mass[i])} * ({acc})")
    return "\n".join(lines) + "\n"


def compile_specialised(s):
    """The compiled specialised RK4 of ``s`` and its compile time [s]."""
    src = specialised_source(s)
    scope = {"np": np, "math": math}
    exec(compile(src, "<specialised rk4>", "exec"), scope)  # noqa: S102 - generated above
    flags = dict(error_model="numpy")
    scope["_excite"] = njit(**flags)(scope["_excite"])
    scope["_rhs"] = njit(**flags)(scope["_rhs"])
    fn = njit(**flags)(scope["specialised_rk4"])
    return fn, src


def _arrays(s, h, n_steps, record_every):
    tv = np.flatnonzero(s.frequency > 0)
    span = n_steps * h
    cap = int(math.ceil(span * float(s.frequency[tv].max()))) + 2 if tv.size else 1
    m = tv.size
    n_rows = n_steps // record_every + 1
    return dict(
        tab=np.ascontiguousarray(s.stiffness_table[tv]), freq=s.frequency[tv].copy(),
        phase=s.phase[tv].copy(), cyc_max=np.full((cap, m), -np.inf),
        cyc_min=np.full((cap, m), np.inf), cyc_sum=np.zeros((cap, m)),
        cyc_cnt=np.zeros((cap, m), np.int64), record_every=record_every,
        hist_t=np.empty(n_rows), hist_f=np.empty((n_rows, m)),
        hist_y=np.empty((n_rows, 2 * s.n_dof)),
    )


def compare(case, n_steps: int, repeat: int = 5, record_every: int = 100) -> dict:
    """Engine RK4 against the specialised RK4 of the same structure, interleaved runs.

    Both start from the case's static equilibrium with the engine's own step; the
    result has the best CPU µs per step of each, their ratio, and the largest relative
    difference of the final states (the two must integrate the same equations).
    """
    from torquesplit.solve.integrate import integrate

    s = case.structure
    why = supported(s)
    if why:
        return {"model": case.name, "skipped": f"the structure has {why}"}
    c0 = time.perf_counter()
    fn, src = compile_specialised(s)
    h = integrate(s, case.y0, (0.0, 1.0 / case.f_max), method="rk4",
                  steps_per_period=100).step
    y = case.y0.copy()
    fn(y, 0.0, h, 10, **_arrays(s, h, 10, record_every))  # compile
    compile_s = time.perf_counter() - c0
    best = {"engine": np.inf, "specialised": np.inf}
    y_end = {}
    for _ in range(repeat):
        t0 = time.process_time()
        sol = integrate(s, case.y0, (0.0, n_steps * h), method="rk4", steps_per_period=100,
                        record_every=record_every, rhs="generated")
        best["engine"] = min(best["engine"], (time.process_time() - t0) / sol.n_steps)
        y_end["engine"] = sol.y_final
        arr = _arrays(s, h, sol.n_steps, record_every)
        y = case.y0.copy()
        t0 = time.process_time()
        fn(y, 0.0, h, sol.n_steps, **arr)
        best["specialised"] = min(best["specialised"], (time.process_time() - t0) / sol.n_steps)
        y_end["specialised"] = y
    a, b = y_end["engine"], y_end["specialised"]
    n = s.n_dof
    # largest difference relative to each half's largest magnitude (q, then v)
    diff = float(max(np.max(np.abs(a[:n] - b[:n])) / max(np.max(np.abs(a[:n])), 1e-300),
                     np.max(np.abs(a[n:] - b[n:])) / max(np.max(np.abs(a[n:])), 1e-300)))
    return {"model": case.name, "n_dof": s.n_dof, "n_elements": s.n_elements,
            "steps": int(n_steps), "step": h,
            "engine_us": best["engine"] * 1e6, "specialised_us": best["specialised"] * 1e6,
            "ratio": best["engine"] / best["specialised"], "final_state_rel_diff": diff,
            "compile_s": compile_s, "source_lines": src.count("\n")}


if __name__ == "__main__":
    import sys

    from bench_engine import example_cases

    names = sys.argv[1:] or ["ji_li_mill_drive"]
    cases, skipped = example_cases(names)
    for c in cases:
        print(compare(c, 200_000))
