"""The engine against the hand transcription of Ji & Li's equations of motion.

``tests/validation/transcription_ji_li.py`` writes the paper's 14-DOF eq. 9 by hand
as numba code from the model's physical parameters, without the assembler (the test
beside it shows that it agrees with the engine to 1e-9).  Here it is the speed
baseline: the design targets ask for the engine within 1.2 times of it per RK4 step
and the general element loop (``rhs="general"``) within 1.5 times.  "The engine" is the
right-hand side a default run of the example takes (``torquesplit run ji_li_mill_drive``,
30 s simulated: ``rhs="auto"`` chooses the literal code, the model's values compiled in as
constants; checked below and reported as ``default_rhs``); the pattern's generated code
(``rhs="generated"``, what short runs and the cases of a long study take) is timed too.

Same run, same work: both integrate the same steps of the model's step (400 per stage-1
mesh period) from the engine's static equilibrium and stream the per-mesh-cycle max,
min, sum and count of the four mesh forces; the engine is called as a user would call
``integrate`` but without a history (``history_elements=()``, ``history_dofs=()``),
which the transcription does not keep either.  What the engine does on top: contact-loss
counters, a divergence check per step, chunking.  The cost per step is the difference
between runs of 2 n and n steps, divided by n: the Python set-up of an ``integrate``
call (kernel arrays, a step stability check, the right-hand side's look-up, argument
typing: about 10 ms) is reported apart, as the fixed cost of a call (it was 16 % of a
200,000-step run, which the earlier per-step figure included).  Runs are alternated
(engine generated, engine general, transcription) and the best process-CPU time of each
is kept, so the ratios do not depend on how loaded the machine is.  Runnable alone:
``python benchmarks/bench_transcription.py [steps]``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

MODEL = "ji_li_mill_drive"


def _case():
    import torquesplit
    from torquesplit.solve import static_equilibrium
    from validation import transcription_ji_li as tr

    model = torquesplit.load_model(torquesplit.example_path(MODEL))
    s = torquesplit.assemble(model)
    p = tr.build(model)
    index, sign = tr.engine_state_signs(model, s.dof_names)
    y0 = static_equilibrium(s).y0
    h = 1.0 / (model.analysis.steps_per_period * float(p.frequency[0]))
    return tr, s, p, index, sign, y0, h


def _default_rhs(structure) -> str:
    """The right-hand side ``rhs="auto"`` takes for a default run of the example (with
    the pattern's code compiled, as it is after any run of it)."""
    import torquesplit
    from torquesplit.solve import codegen, kernel_data
    from torquesplit.solve.integrate import planned_step, whole_steps

    model = torquesplit.load_model(torquesplit.example_path(MODEL))
    span = model.analysis.duration
    n = whole_steps(span, planned_step(structure, model.analysis.steps_per_period, span)[0])[0]
    return "literal" if codegen.worth_literal(kernel_data.kernel_model(structure), 4 * n) \
        else "generated"


def compare(n_steps: int = 200_000, repeat: int = 3) -> dict:
    """CPU µs per RK4 step of the engine (generated, general) and of the hand
    transcription (the difference of the best times of 2 n and n steps, over n), the
    fixed cost of a call, their ratios, and the scaled difference of the final states."""
    from torquesplit.solve import integrate

    tr, s, p, index, sign, y0, h = _case()
    span = n_steps * h
    # plain fixed steps like the transcription (the engine's default also steps through
    # the corners of the stiffness waves, a few per cent more work: timed apart below)
    quiet = dict(method="rk4", step=h, history_elements=(), history_dofs=(), corners=False)
    c0 = time.perf_counter()
    tr.integrate(p, tr.from_engine(y0, index, sign), h, 10)  # compile or load the cache
    compile_s = time.perf_counter() - c0
    kinds = ("literal", "generated", "general")
    for rhs in kinds:  # compile / load everything outside the timing
        integrate(s, y0, (0.0, 64 * h), rhs=rhs, **quiet)
    # best CPU time of each kind for n (1) and 2 n (2) steps
    best = {(k, x): np.inf for k in kinds + ("hand",) for x in (1, 2)}
    final = {}
    y_start = tr.from_engine(y0, index, sign)
    for _ in range(repeat):
        for x in (1, 2):
            for rhs in kinds:
                t0 = time.process_time()
                sol = integrate(s, y0, (0.0, x * span), rhs=rhs, **quiet)
                best[rhs, x] = min(best[rhs, x], time.process_time() - t0)
                if sol.n_steps != x * n_steps:
                    raise RuntimeError(f"integrate took {sol.n_steps} steps, not {x * n_steps}")
                if sol.rhs != rhs:
                    raise RuntimeError(f"integrate ran {sol.rhs!r} where {rhs!r} was asked")
                if x == 1 and rhs != "general":
                    final[rhs] = tr.from_engine(sol.y_final, index, sign)
            t0 = time.process_time()
            run = tr.integrate(p, y_start, sol.step, x * n_steps)
            best["hand", x] = min(best["hand", x], time.process_time() - t0)
            if x == 1:
                final["hand"] = run.y_final
    per_step = {k: (best[k, 2] - best[k, 1]) / n_steps for k in kinds + ("hand",)}
    per_call = {k: best[k, 1] - n_steps * per_step[k] for k in per_step}
    if not np.array_equal(final["literal"], final["generated"]):
        raise RuntimeError("the literal and the generated code ended in different states")
    # largest difference of the final states, per kind (th, X, w, V) over its largest value
    a, b = final["literal"], final["hand"]
    diff = max(float(np.max(np.abs(a[k] - b[k])) / np.max(np.abs(a[k])))
               for k in (slice(0, 8), slice(8, 14), slice(14, 22), slice(22, 28)))
    return {"model": MODEL, "steps": int(n_steps), "step": float(sol.step), "repeat": repeat,
            "default_rhs": _default_rhs(s),
            "engine_us": per_step["literal"] * 1e6, "general_us": per_step["general"] * 1e6,
            "pattern_us": per_step["generated"] * 1e6, "hand_us": per_step["hand"] * 1e6,
            "ratio": per_step["literal"] / per_step["hand"],
            "ratio_pattern": per_step["generated"] / per_step["hand"],
            "ratio_general": per_step["general"] / per_step["hand"],
            "engine_call_ms": per_call["literal"] * 1e3,
            "pattern_call_ms": per_call["generated"] * 1e3,
            "general_call_ms": per_call["general"] * 1e3,
            "hand_call_ms": per_call["hand"] * 1e3,
            "final_state_rel_diff": diff, "hand_compile_s": compile_s}


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200_000
    r = compare(n, repeat=9)
    print(f"Ji & Li mill drive, CPU time per RK4 step of {r['step']:.4g} s (runs of "
          f"{2 * r['steps']:,} less {r['steps']:,} steps, best of 9):")
    print(f"  engine, literal rhs   : {r['engine_us']:.3f} µs/step "
          f"({r['ratio']:.2f}x the transcription; target <= 1.2; a default run takes "
          f"{r['default_rhs']!r})")
    print(f"  engine, generated rhs : {r['pattern_us']:.3f} µs/step "
          f"({r['ratio_pattern']:.2f}x)")
    print(f"  engine, general rhs   : {r['general_us']:.3f} µs/step "
          f"({r['ratio_general']:.2f}x; target <= 1.5)")
    print(f"  hand transcription    : {r['hand_us']:.3f} µs/step")
    print(f"  fixed cost of a call  : engine {r['engine_call_ms']:.1f} ms, general "
          f"{r['general_call_ms']:.1f} ms, transcription {r['hand_call_ms']:.2f} ms")
    print(f"  final states differ by {r['final_state_rel_diff']:.1e} (scaled)")
