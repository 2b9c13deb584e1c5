"""One case of a study: the function every worker runs.

:func:`run_case` takes a plain, picklable payload (base model data, the case's
overrides, analysis settings, output names) and returns a plain dict: it can run in this
process, in a process pool or on a Dask worker, unchanged.  It never raises for a bad
case: a model the overrides make invalid is *refused*, a run that blows up *diverged*,
a run whose teeth separate *contact_lost* (outputs kept); anything unexpected is an
*error* with the exception's text.  Only Ctrl-C (KeyboardInterrupt) passes through.

Kernel reuse: a worker process compiles (or loads from numba's on-disk cache) the
integrator kernels once, on its first case, and the generated right-hand side once per
sparsity pattern (:mod:`torquesplit.solve.codegen` keeps them per process); every later
case of the same pattern reuses both.  ``compile_time`` in the result says what a case
paid for that (the first case of a worker only).
"""

from __future__ import annotations

import gc
import math
import os
import time
import warnings

from ..errors import CaseWarning, warn_user

STATUSES = ("ok", "contact_lost", "diverged", "refused", "error")
"""Case statuses, from best to worst."""



def payload(index: int, plan, overrides: dict) -> dict:
    """The picklable description of case ``index`` of a plan."""
    return {"index": int(index), "model": plan.case_data, "source": plan.model_source,
            "overrides": overrides, "analysis": plan.analysis, "outputs": plan.outputs,
            "definitions": plan.definitions}


def run_case(p: dict) -> dict:
    """Run one case; returns ``{index, status, reason, values, wall_time,
    integration_time, compile_time, simulated_time, runs, settled, worker, warnings}``."""
    from ..errors import SolverError, TorquesplitError
    from ..model.io import load_model, model_from_dict
    from ..model.overrides import apply_overrides

    t0 = time.perf_counter()
    out = {"index": p["index"], "status": "ok", "reason": "", "values": None,
           "wall_time": 0.0, "integration_time": 0.0, "compile_time": 0.0,
           "simulated_time": math.nan, "runs": 0, "settled": True,
           "worker": f"{os.uname().nodename}:{os.getpid()}", "warnings": []}
    nan = [math.nan] * len(p["outputs"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            data = apply_overrides(p["model"], p["overrides"])
            # (kept uncopied: the data shares all but its overridden paths with the
            # plan's, and nothing changes either in place: set_parameter copies the path
            # it changes, with_changes too)
            model = load_model(model_from_dict(data, source=p["source"], share_source=True))
            if p["analysis"]["type"] == "static":
                values = _static(model, p, out)
            else:
                values = _dynamic(model, p, out)
            out["values"] = values
        except (TorquesplitError, SolverError, ValueError) as exc:
            out.update(status="refused", reason=_one_line(exc), values=nan)
        except Exception as exc:  # a bug, a memory error...: record it, keep the study going
            out.update(status="error", reason=f"{type(exc).__name__}: {_one_line(exc)}",
                       values=nan)
    # the model's warnings (unit slips...) and the run's (too short, unsettled...)
    out["warnings"] = sorted({_one_line(w.message) for w in caught})
    global FREEZE_HEAP
    if FREEZE_HEAP:  # (after the first case: its imports and kernels are there now)
        FREEZE_HEAP = False
        gc.collect()  # (the first case's garbage: frozen, it would never be freed)
        gc.freeze()
    out["wall_time"] = time.perf_counter() - t0
    return out


FREEZE_HEAP = False
"""Set in a local pool's worker processes (:func:`.runners.worker_start`): after its
first case, the worker moves every object it holds then (modules, compiled kernels,
the model) out of the garbage collector's reach (:func:`gc.freeze`), so that the full
collections of later cases do not walk them again (4 ms of a Dong et al. 2021 case's
40 ms overhead)."""


def _warn(pairs) -> None:
    for loc, msg in pairs:
        warn_user(f"{loc}: {msg}", CaseWarning)


def _one_line(exc) -> str:
    return " | ".join(s.strip() for s in str(exc).splitlines() if s.strip())


def _static(model, p, out) -> list[float]:
    from ..quasistatic import quasi_static_load_sharing
    from .outputs import output_values

    a = p["analysis"]
    t = time.perf_counter()
    res = quasi_static_load_sharing(model, revolutions=a["revolutions"],
                                    points_per_cycle=a["points_per_cycle"],
                                    **({"max_points": a["max_points"]}
                                       if a.get("max_points") else {}))
    out["integration_time"] = time.perf_counter() - t
    out["runs"] = 1
    conv = res.solution.converged
    if not conv.all():
        out["status"] = "diverged"
        out["reason"] = (f"the quasi-static equilibrium did not converge at "
                         f"{int((~conv).sum())} of {conv.size} mesh positions")
    from ..results.plausibility import static_warnings

    _warn(static_warnings(res))
    vals = output_values(res)
    return [vals.get(n, math.nan) for n in p["outputs"]]


def _dynamic(model, p, out) -> list[float]:
    import contextlib
    import functools

    from ..simulation import MIN_SAMPLES_PER_PERIOD, history_unused, settling_judged, simulate
    from .outputs import output_values

    a = p["analysis"]
    names, defs = p["outputs"], p["definitions"]
    kw = {k: a[k] for k in ("method", "steps_per_period", "rtol", "max_steps")
          if a.get(k) is not None}
    # only the bearing forces come from the history: without them the sparse one of
    # earlier versions (the default keeps every step of a short run, 30 % of a small
    # model's step time); with them the run's default, so that they are the run's table's
    from .outputs import HISTORY_FAMILIES

    quiet = contextlib.nullcontext()
    bearings = any(n.split(".")[0] in HISTORY_FAMILIES for n in names)
    if not bearings:
        kw["samples_per_period"] = MIN_SAMPLES_PER_PERIOD
        quiet = history_unused()  # (its coarseness is the study's choice, unread)
    values = functools.partial(output_values, bearings=bearings)  # (unread: not computed)
    # (the kept run's settling is warned by _finish: not that of the settle rule's
    # shorter trial runs)
    with quiet, settling_judged():
        return _dynamic_runs(model, a, names, defs, kw, out, simulate, values)


def _dynamic_runs(model, a, names, defs, kw, out, simulate, output_values) -> list[float]:
    """The case's run (or, with ``analysis.settle``, its runs of growing length)."""
    settle = a.get("settle")
    if settle is None:
        res = simulate(model, duration=a.get("duration"), cycles=a.get("cycles"), **kw)
        _account(res, out)
        return _finish(res, names, defs, out, output_values)
    # stop-when-settled: lengths T, gT, g^2 T ... until two successive runs agree
    full, f_min = _full_duration(model, a)
    length = min(settle["start"] or 50.0 / f_min, full)
    previous = None
    while True:
        res = simulate(model, duration=length, **kw)
        _account(res, out)
        if not res.success:
            return _finish(res, names, defs, out, output_values)
        vals = output_values(res, defs)
        current = [vals.get(n, math.nan) for n in names]
        settled = res.metrics("cycle_peak").settling.settled  # the same for every definition
        if previous is not None and settled and _close(previous, current, settle["tolerance"],
                                                       names):
            break
        if length >= full:
            out["settled"] = False
            break
        previous = current
        length = min(length * settle["growth"], full)
    return _finish(res, names, defs, out, output_values, vals)


def _full_duration(model, a) -> tuple[float, float]:
    """The run length without the settle rule (cap of the rule) and the slowest mesh
    frequency, as :func:`torquesplit.simulate` chooses them."""
    from ..model.kinematics import solve_kinematics

    kin = solve_kinematics(model)
    f_min = min(kin.meshes[m].frequency for m in model.meshes)
    if a.get("duration") is not None:
        return a["duration"], f_min
    if a.get("cycles") is not None:
        return a["cycles"] / f_min, f_min
    an = model.analysis
    if an.duration is not None:
        return an.duration, f_min
    return (an.cycles or 200) / f_min, f_min


def _close(a, b, tol, names=None) -> bool:
    """Two runs' outputs agree within the relative ``tol``; with ``names``, outputs
    that change with the run length by nature (``settle_time``:
    :data:`~torquesplit.study.outputs.NOT_CONVERGING`) are not compared."""
    from .outputs import NOT_CONVERGING

    for j, (x, y) in enumerate(zip(a, b, strict=True)):
        if names is not None and names[j] in NOT_CONVERGING:
            continue
        if math.isnan(x) and math.isnan(y):
            continue
        if not abs(x - y) <= tol * max(abs(x), abs(y)):
            return False
    return True


def _account(res, out) -> None:
    st = res.statistics()
    # (the run's wall time includes the generation of its right-hand side, counted as
    # compilation: wall - integration - compilation was short by it)
    out["integration_time"] += st["wall_time_s"] - st["rhs_compile_time_s"]
    out["compile_time"] += st["rhs_compile_time_s"] + st["compile_time_s"]  # (first: only)
    out["simulated_time"] = st["simulated_time_s"]
    out["runs"] += 1


def _finish(res, names, defs, out, output_values, vals=None) -> list[float]:
    if not res.success:
        out["status"] = "diverged"
        out["reason"] = _one_line(res.message)
        return [math.nan] * len(names)
    if vals is None:
        vals = output_values(res, defs)
    met = res.metrics("cycle_peak")  # settling and contact loss: the same for every definition
    if not out["settled"] and out["runs"] == 1:  # (the rule's first run was its cap:
        # 'still changed' claimed a comparison that never was, a studies reviewer)
        _warn([("analysis.settle", f"the rule's first run is already the longest "
                                   f"({out['simulated_time']:.4g} s): one run, nothing to "
                                   f"compare it with; give a shorter settle start or a "
                                   f"longer run (duration or cycles)")])
    elif not out["settled"]:  # only the settle rule, at its cap, has cleared it before
        _warn([("analysis.settle", f"the outputs still changed by more than the rule's "
                                   f"tolerance at the longest run ({out['simulated_time']:.4g} "
                                   f"s); raise the run length (duration or cycles) or the "
                                   f"tolerance")])
    out["settled"] = out["settled"] and met.settling.settled
    from ..results.plausibility import contact_lost, result_warnings

    _warn(result_warnings(res, met, history=False))  # (no output is from the history)
    lost = [(r.mesh, r.contact_loss) for r in met.rows if contact_lost(r)]
    if lost:
        out["status"] = "contact_lost"
        out["reason"] = "contact lost in " + ", ".join(
            f"{m} ({_percent(f)} of the time)" for m, f in lost)
    return [vals.get(n, math.nan) for n in names]


def _percent(f: float) -> str:
    """A share as a percentage with two significant digits, never in exponent form
    ('100 %', '12 %', '0.34 %'; '.2g' wrote 100 % as '1e+02 %')."""
    import numpy as np

    p = 100.0 * f
    if p >= 10:
        return f"{p:.0f} %"
    return np.format_float_positional(float(f"{p:.2g}"), trim="-") + " %"
