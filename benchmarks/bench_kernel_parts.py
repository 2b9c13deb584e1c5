"""Where an RK4 step's time goes: the kernel's building blocks timed one by one.

One RK4 step of ``_kernels.rk4_run`` calls a few kernels (when this was written: 4
``rhs_slot``, 2 ``excite_tables`` for t + h/2 and t + h, 2 error-sinusoid updates, one
``record_statistics`` and one ``bad_state``) plus the RK4 vector updates (4 loops over
2 n states); :func:`step_blocks` reads the current list from ``rk4_run``'s source.  Each
building block is called
``n_calls`` times from a small ``@njit`` driver loop and timed in CPU seconds (best of
3); the whole step is timed the same way right after (``integrate``, CPU time), and the
remainder is reported as "rest": RK4 vector arithmetic, history writes, loop overhead.

The kernels are edited while this benchmark exists, so nothing here hard-codes their
argument lists: each driver loop is generated from the kernel's own parameter names,
bound by name to the model arrays (``_kernels.MODEL_ARRAYS``) and to scratch arrays of
the usual names (``y``, ``K``, ``force``, ...).  A block whose kernel is missing or
takes an argument this file does not know is reported as skipped, not fatal.  The
``slot`` argument is passed as a variable (as ``rk4_run`` does for its slots ``a`` and
``b``), so the drivers do not get literal-specialised copies.

The kernels of tooth friction and splines (``excite_friction``, ``rhs_extra``) are
called inside ``if`` blocks, only for models that have them, so the breakdown of a model
without them leaves them out (as it leaves out the RESYNC and history branches); their
scratch arrays are in the namespace all the same.
"""

from __future__ import annotations

import inspect
import time

import numpy as np
from numba import njit

from torquesplit.solve import _kernels as kern


def step_blocks() -> list[tuple[str, int, bool]]:
    """Kernels ``rk4_run`` calls unconditionally in its step loop: (name, calls, returns).

    Read from ``rk4_run``'s own source (ast), so the list follows the kernel as it is
    edited.  Calls inside an ``if`` (the exact re-synchronisation every RESYNC steps,
    the history writes every ``record_every`` steps) are left out: they are rare.
    """
    import ast
    import textwrap

    from numba.core.registry import CPUDispatcher

    tree = ast.parse(textwrap.dedent(inspect.getsource(kern.rk4_run.py_func)))
    fn = tree.body[0]
    def n_kernel_calls(node):
        return sum(1 for c in ast.walk(node) if isinstance(c, ast.Call)
                   and isinstance(c.func, ast.Name)
                   and isinstance(getattr(kern, c.func.id, None), CPUDispatcher))

    # the step loop: the top-level for loop with the most kernel calls
    loop = max((node for node in fn.body if isinstance(node, ast.For)), key=n_kernel_calls)
    counts: dict[str, list] = {}

    def visit(stmts):
        for st in stmts:
            if isinstance(st, ast.If) and isinstance(st.test, ast.Name) and st.test.id == "gen":
                visit(st.orelse)  # the general right-hand side (rhs_slot) of `if gen:`
                continue
            if isinstance(st, ast.If):
                continue
            if isinstance(st, ast.For):
                visit(st.body)
                continue
            for node in ast.walk(st):
                if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                        and isinstance(getattr(kern, node.func.id, None), CPUDispatcher)):
                    entry = counts.setdefault(node.func.id, [0, False])
                    entry[0] += 1
                    entry[1] |= isinstance(st, ast.Assign)

    visit(loop.body)
    return [(name, n, ret) for name, (n, ret) in counts.items()]


def _namespace(case) -> dict:
    """Every argument a building block may take, by the kernels' own names."""
    from torquesplit.solve.integrate import _model_arrays

    s = case.structure
    ns = dict(zip(kern.MODEL_ARRAYS, _model_arrays(s)))
    n, ne = s.n_dof, s.n_elements
    n_sin = ns["error_omega"].shape[0]
    h = 1.0 / (100.0 * case.f_max)
    ns.update(
        y=case.y0.copy(), dy=np.empty(2 * n), yt=np.empty(2 * n), genf=np.empty(n),
        force=np.empty(ne), defl=np.empty(ne), ftmp=np.empty(ne), dtmp=np.empty(ne),
        K=np.empty((3, ne)), P=np.empty((3, ne)), G=np.empty((3, ne)),
        E=np.empty((3, ne)), ED=np.empty((3, ne)), CY=np.zeros((3, ne), np.int64),
        S=np.zeros((3, n_sin)), C=np.ones((3, n_sin)),
        FR=np.zeros((3, ns["friction_table"].shape[0])),
        cos_rot=np.cos(ns["error_omega"] * h / 2), sin_rot=np.sin(ns["error_omega"] * h / 2),
        gap_cyc=np.full(ne, getattr(kern, "_NO_CYCLE", -(2**62)), np.int64),
        gap_val=np.zeros(ne),
        slot=np.int64(1), src=np.int64(0), dst=np.int64(1), blowup=1e9,
        counters=np.zeros(kern.N_COUNTERS, np.int64),
    )
    track = np.flatnonzero(s.frequency > 0).astype(np.int64)
    cap = 4
    ns.update(track_el=track, track_base=np.zeros(track.size, np.int64),
              cyc_max=np.full((cap, track.size), -np.inf),
              cyc_min=np.full((cap, track.size), np.inf),
              cyc_sum=np.zeros((cap, track.size)),
              cyc_cnt=np.zeros((cap, track.size), np.int64),
              sep_count=np.zeros(ne, np.int64), back_count=np.zeros(ne, np.int64),
              sep_time=np.zeros(ne), back_time=np.zeros(ne), weight=h, h=h,
              has_force=np.ones(ne, np.bool_), watch_el=np.arange(ne, dtype=np.int64),
              n_watch=np.int64(ne))
    flags = getattr(kern, "scratch_flags", None)  # per-call element flags, if the kernel has them
    if flags is not None:
        params = list(inspect.signature(flags.py_func).parameters)
        if all(p in ns for p in params):
            ns["n_watch"] = np.int64(flags(*(ns[p] for p in params)))
    init = getattr(kern, "init_slots", None)
    if init is not None:
        params = list(inspect.signature(init.py_func).parameters)
        if all(p in ns for p in params):
            init(*(ns[p] for p in params))
    return ns, h


def _driver(fn_name: str, returns: bool, ns: dict):
    """A compiled loop calling ``_kernels.<fn_name>`` n_calls times, and its arguments.

    The state ``y`` is nudged before each call and an output (``dy`` or the return
    value) is accumulated after it, so that the call cannot be hoisted out of the loop.
    """
    fn = getattr(kern, fn_name, None)
    if fn is None:
        return None, f"no kernel named {fn_name}"
    params = list(inspect.signature(fn.py_func).parameters)
    unknown = [p for p in params if p not in ns and p != "t"]
    if unknown:
        return None, f"unknown argument(s) {unknown}"
    loop_params = [p for p in params if p != "t"]
    call = ", ".join("_i * _h" if p == "t" else p for p in params)
    pre = "y[0] += 1e-300" if "y" in params else ""
    if returns:
        post = "acc += _r"
    elif "dy" in params:
        post = "acc += dy[dy.shape[0] - 1]"
    elif "K" in params and "slot" in params:
        post = "acc += K[slot, 0]"
    else:
        post = ""
    returns = "_r = " if returns else ""
    src = (f"def _loop(_n, _h, {', '.join(loop_params)}):\n"
           f"    acc = 0.0\n"
           f"    for _i in range(_n):\n"
           f"        {pre or 'pass'}\n"
           f"        {returns}kern.{fn_name}({call})\n"
           f"        {post or 'pass'}\n"
           f"    return acc\n")
    scope = {"kern": kern}
    exec(compile(src, f"<driver {fn_name}>", "exec"), scope)  # noqa: S102 - generated above
    return (njit(cache=False)(scope["_loop"]), [ns[p] for p in loop_params]), None


def _best_cpu(fn, *args, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        c0 = time.process_time()
        fn(*args)
        best = min(best, time.process_time() - c0)
    return best


def _step_cpu_us(case, n_steps: int) -> float:
    """CPU µs of one whole RK4 step with the general right-hand side (the blocks timed
    here; integrate(rhs="general"), best of 3), measured right now."""
    from torquesplit.solve.integrate import integrate

    h = integrate(case.structure, case.y0, (0.0, 1.0 / case.f_max), method="rk4",
                  steps_per_period=100).step
    best = np.inf
    for _ in range(3):
        c0 = time.process_time()
        sol = integrate(case.structure, case.y0, (0.0, n_steps * h), method="rk4",
                        steps_per_period=100, record_every=100, rhs="general")
        best = min(best, (time.process_time() - c0) / sol.n_steps)
    return best * 1e6


def breakdown(case, n_calls: int = 1_000_000, n_steps: int = 200_000) -> dict:
    """ns per call of each building block and their share of one measured step."""
    ns, h = _namespace(case)
    y0 = ns["y"].copy()
    parts, skipped = {}, {}
    blocks = step_blocks()
    if not blocks:
        skipped["rk4_run"] = "no kernel calls found in its step loop (source layout changed?)"
    for name, per_step, returns in blocks:
        drv, why = _driver(name, returns, ns)
        if drv is None:
            skipped[name] = why
            continue
        loop, args = drv
        try:
            loop(10, h, *args)  # compile
        except Exception as exc:  # noqa: BLE001 - reported, not fatal
            skipped[name] = f"{type(exc).__name__}: {str(exc).splitlines()[0][:120]}"
            continue
        ns["y"][:] = y0
        sec = _best_cpu(loop, n_calls, h, *args)
        parts[name] = {"ns_per_call": sec / n_calls * 1e9, "calls_per_step": per_step,
                           "ns_per_step": sec / n_calls * 1e9 * per_step}
        ns["y"][:] = y0
    step_ns = _step_cpu_us(case, n_steps) * 1e3
    accounted = sum(p["ns_per_step"] for p in parts.values())
    for p in parts.values():
        p["share"] = p["ns_per_step"] / step_ns
    parts["rest (RK4 vector updates, history, loop)"] = {
        "ns_per_call": float("nan"), "calls_per_step": 1, "ns_per_step": step_ns - accounted,
        "share": (step_ns - accounted) / step_ns}
    s = case.structure
    return {"model": case.name, "n_dof": s.n_dof, "n_elements": s.n_elements,
                "nnz": int(s.v_dof.size), "n_time_varying": int((s.frequency > 0).sum()),
                "n_sinusoids": int(s.error_amplitude.size), "step_ns": step_ns, "parts": parts,
                "skipped": skipped}


def marginal_rhs_cost(case, n_steps: int = 200_000, repeat: int = 5) -> dict:
    """In-situ cost of one ``rhs_slot`` call: ``rk4_run`` with one more call, minus as is.

    The isolated driver loops above run a kernel on the same, cache-hot data with
    perfectly predictable branches, which understates what it costs inside ``rk4_run``.
    Here a copy of ``_kernels.py`` is written to a temporary directory with the step
    loop's first ``rhs_slot`` statement duplicated (it recomputes the same stage-1
    derivative into the same arrays, so the results do not change), compiled there
    (about 20 s), and swapped into ``integrate`` for the duration of the measurement.
    The difference of the best CPU times per step is the marginal cost of one call.
    """
    import ast
    import importlib.util
    import sys
    import tempfile
    from pathlib import Path

    import torquesplit.solve.integrate  # noqa: F401 - the module, not the function
    integ = sys.modules["torquesplit.solve.integrate"]

    src = Path(kern.__file__).read_text(encoding="utf-8")
    tree = ast.parse(src)
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "rk4_run")
    loops = [n for n in fn.body if isinstance(n, ast.For)]
    loop = max(loops, key=lambda n: sum(isinstance(c, ast.Call) for c in ast.walk(n)))
    # the first right-hand-side statement of the step loop: a bare rhs_slot call, or the
    # `if gen: rhs_fn(...) else: rhs_slot(...)` block (duplicated whole)
    stmt = next((st for st in loop.body if (
        isinstance(st, ast.Expr) and isinstance(st.value, ast.Call)
        and isinstance(st.value.func, ast.Name) and st.value.func.id == "rhs_slot") or (
        isinstance(st, ast.If) and isinstance(st.test, ast.Name) and st.test.id == "gen")),
        None)
    if stmt is None:
        return {"skipped": "no right-hand-side statement in rk4_run's step loop"}
    lines = src.splitlines(keepends=True)
    dup = lines[stmt.lineno - 1:stmt.end_lineno]
    patched = "".join(lines[:stmt.end_lineno] + dup + lines[stmt.end_lineno:])

    s = case.structure
    h = integ.integrate(s, case.y0, (0.0, 1.0 / case.f_max), method="rk4",
                        steps_per_period=100).step
    span = n_steps * h
    with tempfile.TemporaryDirectory(prefix="torquesplit-bench-") as tmp:
        path = Path(tmp) / "_kernels_plus_one_rhs.py"
        path.write_text(patched, encoding="utf-8")
        spec = importlib.util.spec_from_file_location("_kernels_plus_one_rhs", path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        original = integ.kern
        best = {}
        try:
            c0 = time.perf_counter()
            integ.kern = mod
            integ.integrate(s, case.y0, (0.0, 100 * h), method="rk4",
                            steps_per_period=100)  # compile the copy
            compile_s = time.perf_counter() - c0
            for _ in range(repeat):
                for label, module in (("as is", original), ("plus one", mod)):
                    integ.kern = module
                    c0 = time.process_time()
                    sol = integ.integrate(s, case.y0, (0.0, span), method="rk4",
                                          steps_per_period=100, record_every=100)
                    ns = (time.process_time() - c0) / sol.n_steps * 1e9
                    best[label] = min(best.get(label, np.inf), ns)
        finally:
            integ.kern = original
    return {"step_ns": best["as is"], "step_plus_one_ns": best["plus one"],
                "rhs_ns": best["plus one"] - best["as is"], "compile_s": compile_s,
                "calls_per_step": sum(1 for st in ast.walk(loop) if isinstance(st, ast.Call)
                                   and isinstance(st.func, ast.Name)
                                   and st.func.id == "rhs_slot")}
