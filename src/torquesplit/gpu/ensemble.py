"""Run many prepared dynamic runs as one ensemble: one generated kernel per pattern.

:func:`run_ensemble` takes runs set up by :func:`torquesplit.simulation.prepare_run`
(model, structure, static equilibrium as initial state, integrate arguments), plans each
one's RK4 step and tracked cycles with the CPU engine's own planning
(``integrate._plan_rk4``, ``integrate._select``), groups the runs by pattern
(:mod:`torquesplit.gpu.layout`), generates and compiles each pattern's kernel
(:mod:`torquesplit.gpu.source`, :mod:`torquesplit.gpu.compile`), runs it on the target
(``"cuda"``: one case per thread on a CUDA device or numba's simulator; ``"cpu"``: the
same source compiled with numba, case after case) and turns each case's outputs into the
engine's :class:`~torquesplit.solve.integrate.Solution` with the engine's own
``integrate._solution``.  Metrics are then computed from those Solutions by the one
metrics code (:class:`torquesplit.results.Results`), never here.

What the generated code does not do is refused up front, by name
(:class:`~torquesplit.errors.GpuUnsupportedError`): adaptive time stepping
(``method = "dopri"``), full state histories.  Decimated histories are not produced (no
study output reads them): a GPU run's Solution has empty ``history_*`` arrays.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

from torquesplit.errors import GpuUnsupportedError, OptionError
from torquesplit.solve import _kernels as kern
from torquesplit.solve import kernel_data as kd

from .compile import (LAST_BINDING, cpu_driver, cuda_available, cuda_kernel,
                      cuda_simulated)
from .layout import CaseArrays, IdentityMemo, build_group, group_cases, unknown_fields
from .source import N_STAT, kernel_source

__all__ = ["EnsembleResult", "case_arrays", "compile_ahead", "run_ensemble", "TARGETS",
           "PRECISIONS", "BLOWUP"]

TARGETS = ("cuda", "cpu")
PRECISIONS = ("fp64", "fp32")
BLOWUP = 1.0e3
"""|q| that stops a run (the default of ``integrate``, which ``simulate`` uses)."""
THREADS_PER_BLOCK = 64
MAX_OUTPUT_BYTES = 2 * 1024**3
"""Output arrays of one launch at most where the free memory cannot be read."""
MIN_OUTPUT_BYTES = 256 * 1024**2


def output_budget(target: str) -> int:
    """Bytes of output arrays one launch may hold: a quarter of the host's available
    memory (the outputs come back, and each case's Solution copies its share) and, on a
    CUDA device, half of its free memory.  Fewer, larger launches are faster: a GPU
    runs the cases of one launch side by side (Ji & Li's drive, 10 s a case: 0.53 MB
    of per-cycle statistics a case, 5.3 GB for 10,000 cases; under a fixed 2 GB and the
    runner's old first batch they were five launches, 32.4 s of kernel on an H200, 6.5 s
    a launch, where 1,000 cases in one had taken 6.4 s)."""
    budget = []
    try:
        with open("/proc/meminfo") as f:
            info = dict(line.split(":", 1) for line in f)
        budget.append(int(info["MemAvailable"].split()[0]) * 1024 // 4)
    except (OSError, KeyError, ValueError):
        pass
    if target == "cuda" and not cuda_simulated():
        try:
            from numba import cuda

            free, _ = cuda.current_context().get_memory_info()
            budget.append(int(free) // 2)
        except Exception:  # noqa: BLE001 - no context yet or no query: host bound only
            pass
    return max(MIN_OUTPUT_BYTES, min(budget)) if budget else MAX_OUTPUT_BYTES


@dataclass
class _Planned:
    case: CaseArrays
    sel: object
    plan: object


@dataclass
class EnsembleResult:
    """Solutions of an ensemble, in the order of the runs, and where the time went."""

    solutions: list
    target: str
    precision: str
    device: str
    patterns: int
    """Distinct generated kernels."""
    compile_time: float
    """Generating and compiling the kernels [s] (a cached pattern costs nothing)."""
    kernel_time: float
    """Running the kernels, transfers included [s]."""
    setup_time: float
    """Planning, grouping and parameter arrays [s]."""
    post_time: float
    """Outputs -> Solutions [s]."""
    sample_steps: int
    """Sum over the cases of the RK4 steps they took."""
    lines: list[int] = field(default_factory=list)
    """Lines of generated source per pattern."""
    law_binding: str = ""
    """How the CUDA kernel called the laws ("device" functions or "njit" callees; see
    :mod:`torquesplit.gpu.compile`); empty for the CPU target."""
    binding_errors: list[str] = field(default_factory=list)
    """Why the bindings tried before it did not compile."""
    launches: int = 0
    """Kernel launches (a pattern's cases split where their outputs pass the budget)."""


def check_supported(run) -> None:
    """Refuse, by name, what the generated kernel does not do (before anything runs)."""
    kw = run.integrate_kwargs
    method = kw.get("method", "rk4")
    if method != "rk4":
        raise GpuUnsupportedError(
            f"adaptive time stepping (method = {method!r})",
            "set [analysis] method = \"rk4\" in the study, or run it with the CPU backend")
    if kw.get("full_history"):
        raise GpuUnsupportedError("full state histories (full_history)",
                                  "leave full_history off, or use the CPU backend")
    # integrate options the kernel plans for itself (the study's step and limits): one
    # set otherwise was ignored, the runs differing from the engine's without a word
    ignored = [f"{k} = {kw[k]!r}" for k, default in _PLANNED_BY_THE_KERNEL.items()
               if k in kw and kw[k] is not None and kw[k] != default]
    if ignored:
        raise GpuUnsupportedError(
            f"integrate options {', '.join(ignored)} (the kernel takes the engine's planned "
            f"step, RK4 through the table corners and the default divergence bound)",
            "leave them out of the run's integrate_kwargs, or use the CPU backend")


#: integrate's options the GPU kernel does not take, with the value it runs with
_PLANNED_BY_THE_KERNEL = {"step": None, "max_steps": None, "max_step": None, "rtol": None,
                          "atol": None, "record_every": None, "blowup": BLOWUP,
                          "corners": True, "check_stability": None}


def case_arrays(run) -> _Planned:
    """Plan one prepared run as the CPU engine would (same step, same tracked cycles)."""
    from torquesplit.solve.integrate import _plan_rk4, _select, rk4_chunk

    check_supported(run)
    s = run.structure
    kw = run.integrate_kwargs
    model = _kernel_model(s)
    unknown = unknown_fields(model)
    if unknown:
        raise GpuUnsupportedError(
            f"the engine's kernel arrays {unknown} (a term added to the engine after the "
            f"GPU kernel generator)", "use the CPU backend until torquesplit.gpu.source "
            "generates it")
    t0, span = 0.0, float(run.duration)
    sel = _select(s, t0, span, kw.get("track_elements"), None, [], [],
                  kw.get("load_sharing_groups"))
    plan = _plan_rk4(s, span, None, kw.get("steps_per_period"), None, None,
                     kw.get("sample_interval"), False, None)
    y = np.array(run.y0, dtype=np.float64).ravel()
    if y.shape != (2 * s.n_dof,):
        y = np.concatenate([y, np.zeros(s.n_dof)])
    case = CaseArrays(model=model, y0=y, t0=t0, h=float(plan.h),
                      n_steps=int(plan.limit_steps), chunk=rk4_chunk(plan.limit_steps),
                      track=list(sel.track),
                      track_base=np.asarray(sel.track_base, dtype=np.int64),
                      cap=int(sel.n_cycles_cap), groups=[list(g) for g in sel.groups],
                      blowup=BLOWUP, group_min=_group_min(kw, len(sel.groups)))
    return _Planned(case, sel, plan)


_KERNEL_TABLES = IdentityMemo()


#: KernelModel fields computed from the structure's phase tables (corner nodes, the
#: order of the time-varying elements (those with non-constant tables first), and the
#: tables themselves: the structure's own arrays, or a copy where kernel_model changes
#: one: spline components' stiffness rows zeroed)
_FROM_TABLES = ("stiffness_table", "force_table", "friction_table", "corner_ptr",
                "corner_node", "tv_el", "tv_tab")


def _kernel_model(s):
    """``kd.kernel_model(s)``, with what it computes from the phase tables (the corner
    nodes, a copy where it changes one) made once per structure table object: the cases
    of a study share their tables (see :mod:`torquesplit.gpu.backend`), so they share
    these too, and neither the corner search, a copy nor the layout's look at them is
    repeated.  The memo keeps only what is not the structure's own memory (a table the
    kernel model takes as it is, or a view of it, would keep the structure's tables
    alive, and with them the memo's entry).  The other inputs of the corner nodes (which
    elements vary, spline components, tooth-friction rows, multi-value gaps) are
    compared, not assumed."""
    src = (s.stiffness_table, s.force_table, s.friction_table)
    gaps = [np.ptp(s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]) > 0 if
            s.gap_ptr[e + 1] > s.gap_ptr[e] else False for e in range(len(s.gap_ptr) - 1)]
    aux = b"|".join(np.ascontiguousarray(a).tobytes() for a in (
        np.asarray(s.sp_el, dtype=np.int64), s.frequency > 0.0,
        np.asarray(s.fr_el, dtype=np.int64), np.asarray(gaps, dtype=bool)))
    hit = _KERNEL_TABLES.peek(src)
    if hit is None or hit[0] != aux:
        model = kd.kernel_model(s)
        own = {f: getattr(model, f) for f in _FROM_TABLES
               if not any(np.shares_memory(getattr(model, f), a) for a in src)}
        _KERNEL_TABLES.put(src, (aux, own))
        return model
    small = {f: np.zeros(a.shape[:-1] + (1,)) for f, a in zip(
        ("stiffness_table", "force_table", "friction_table"), src, strict=True)}
    # the tables the memo does not hold: the structure's own, as kernel_model takes them
    # (the friction rows 3 per friction mesh)
    n_fm = len(s.fr_el)
    taken = {f: kd.table_array(a) for f, a in zip(
        ("stiffness_table", "force_table", "friction_table"), src, strict=True)
        if f not in hit[1]}
    if "friction_table" in taken:
        taken["friction_table"] = (taken["friction_table"].reshape(3 * n_fm, -1) if n_fm
                                   else np.zeros((0, 1)))
    return kd.kernel_model(dataclasses.replace(s, **small))._replace(**hit[1], **taken)


def _group_min(kw: dict, n_groups: int) -> np.ndarray:
    """``integrate``'s ``load_sharing_min_total`` (0 for each group when not given)."""
    g = kw.get("load_sharing_min_total")
    if g is None:
        return np.zeros(n_groups)
    if len(g) != n_groups:
        raise OptionError("load_sharing_min_total needs one value per load-sharing group.")
    return np.asarray(g, dtype=np.float64).reshape(n_groups)


def run_ensemble(runs, *, target: str = "cuda", precision: str = "fp64",
                 threads_per_block: int = THREADS_PER_BLOCK,
                 max_output_bytes: int | None = None) -> EnsembleResult:
    """Integrate prepared runs (:class:`~torquesplit.simulation.PreparedRun`) together.

    Parameters
    ----------
    runs : sequence of PreparedRun
        Each from :func:`torquesplit.simulation.prepare_run` (RK4).
    target : {"cuda", "cpu"}
        ``"cuda"``: one case per GPU thread (a CUDA device, or numba's simulator under
        ``NUMBA_ENABLE_CUDASIM=1``); ``"cpu"``: the same generated source compiled for
        the CPU, one case after the other (the reference of the tests).
    precision : {"fp64", "fp32"}
        Arithmetic of the dynamics (state, stages, element forces).  Times, mesh phases,
        error sinusoids and the statistics are float64 in both.
    threads_per_block : int
        CUDA block size.
    max_output_bytes : int, optional
        Cases are launched in batches whose output arrays stay below this (default:
        :func:`output_budget`).

    Returns
    -------
    EnsembleResult
        ``solutions[i]`` is run i's :class:`~torquesplit.solve.integrate.Solution`.

    Raises
    ------
    GpuUnsupportedError
        A run needs something the generated kernel does not do (named).
    GpuUnavailableError
        ``target="cuda"`` without a CUDA device.
    """
    from torquesplit.errors import GpuUnavailableError

    if target not in TARGETS:
        raise OptionError(f"target must be one of {TARGETS}, got {target!r}; use 'cuda' "
                         f"or 'cpu'")
    if precision not in PRECISIONS:
        raise OptionError(f"precision must be one of {PRECISIONS}, got {precision!r}; use "
                         f"'fp64' (default) or 'fp32'")
    device = "cpu (generated source, numba)"
    if target == "cuda":
        ok, device = cuda_available()
        if not ok:
            raise GpuUnavailableError(device)
    t_setup = time.perf_counter()
    planned = [case_arrays(r) for r in runs]
    setup = time.perf_counter() - t_setup
    out = EnsembleResult(solutions=[None] * len(planned), target=target,
                         precision=precision, device=device, patterns=0, compile_time=0.0,
                         kernel_time=0.0, setup_time=setup, post_time=0.0,
                         sample_steps=0)
    cases = [p.case for p in planned]
    if max_output_bytes is None:
        max_output_bytes = output_budget(target)
    dtype = np.float32 if precision == "fp32" else np.float64
    for indices in group_cases(cases).values():
        t = time.perf_counter()
        probe = build_group(cases, indices[:1], dtype)
        probe.cap_max = max(cases[i].cap for i in indices)
        sizes = kernel_source(probe, precision)
        per_case = 8 * (sizes.n_of + sizes.n_oi)
        out.setup_time += time.perf_counter() - t
        batch = max(1, min(len(indices), int(max_output_bytes // max(per_case, 1))))
        for start in range(0, len(indices), batch):
            part = indices[start:start + batch]
            t = time.perf_counter()
            g = build_group(cases, part, dtype)
            src = kernel_source(g, precision)
            out.setup_time += time.perf_counter() - t
            t = time.perf_counter()
            fn = cuda_kernel(src) if target == "cuda" else cpu_driver(src)
            out.compile_time += time.perf_counter() - t
            if target == "cuda":
                out.law_binding = LAST_BINDING.get("binding", out.law_binding)
                out.binding_errors = list(LAST_BINDING.get("failed", ()))
            out.lines.append(src.n_lines)
            t = time.perf_counter()
            OF, OI = _launch(fn, target, g, src, threads_per_block)
            out.launches += 1
            out.kernel_time += time.perf_counter() - t
            t = time.perf_counter()
            share = (out.kernel_time / max(len(part), 1))
            for k, i in enumerate(part):
                out.solutions[i] = _solution(planned[i], runs[i], g, src, OF[k], OI[k],
                                             precision, target, share)
            out.post_time += time.perf_counter() - t
        out.patterns += 1
    out.sample_steps = int(sum(s.n_steps for s in out.solutions))
    return out


def compile_ahead(runs, *, target: str = "cuda", precision: str = "fp64") -> None:
    """Compile the kernel of each pattern of ``runs`` as :func:`run_ensemble` would for
    one launch of them, without running it (kept in the compiled-kernel cache: a later
    launch whose generated source is the same, e.g. more cases of a Monte Carlo, finds
    it)."""
    cases = [case_arrays(r).case for r in runs]
    dtype = np.float32 if precision == "fp32" else np.float64
    for indices in group_cases(cases).values():
        g = build_group(cases, indices, dtype)
        src = kernel_source(g, precision)
        if target == "cuda":
            cuda_kernel(src)
            continue
        _launch(cpu_driver(src), "cpu", g, src, n_cases=0)  # (compiles at its first call)


def _launch(fn, target, g, src, threads_per_block=THREADS_PER_BLOCK, n_cases=None):
    """Run the kernel on the group's cases (``n_cases`` of them: default all; 0 runs
    none, which compiles the CPU driver); the outputs, one row a case."""
    n_c = g.n_cases if n_cases is None else n_cases
    args = (g.P, g.PT, g.PI, g.Y0, g.TK, g.TF, g.TFR, g.GS, g.CN)
    if target == "cpu":
        OF = np.empty((n_c, src.n_of))
        OI = np.empty((n_c, src.n_oi), dtype=np.int64)
        fn(n_c, *args, OF, OI)
        return OF, OI
    from numba import cuda

    d_args = [cuda.to_device(np.ascontiguousarray(a)) for a in args]
    d_of = cuda.device_array((n_c, src.n_of), dtype=np.float64)
    d_oi = cuda.device_array((n_c, src.n_oi), dtype=np.int64)
    blocks = (n_c + threads_per_block - 1) // threads_per_block
    fn[blocks, threads_per_block](n_c, *d_args, d_of, d_oi)
    cuda.synchronize()
    return d_of.copy_to_host(), d_oi.copy_to_host()


def _solution(p: _Planned, run, g, src, of, oi, precision, target, share):
    """A case's outputs as the engine's Solution (``integrate._solution``)."""
    from torquesplit.solve.integrate import _solution as make_solution

    c, sel, plan = p.case, p.sel, p.plan
    s = run.structure
    n_tr = len(sel.track)
    cap = c.cap
    rec = kd.make_record(sel.track, sel.track_base, cap, sel.groups, s.n_elements, [], [],
                         0, 0, s.n_dof, c.group_min)
    st = of[:cap * n_tr * N_STAT].reshape(cap, n_tr, N_STAT)
    rec.cyc_max[:] = st[:, :, 0]
    rec.cyc_min[:] = st[:, :, 1]
    rec.cyc_sum[:] = st[:, :, 2]
    rec.rat_max[:] = st[:, :, 3]
    rec.rat_min[:] = st[:, :, 4]
    rec.cyc_wt[:] = st[:, :, 5]
    rec.cyc_cnt[:] = oi[:cap * n_tr].reshape(cap, n_tr)
    for k, el in enumerate(g.layout.watch):
        rec.sep_time[el] = of[src.of_contact + 2 * k]
        rec.back_time[el] = of[src.of_contact + 2 * k + 1]
        rec.sep_count[el] = oi[src.oi_contact + 2 * k]
        rec.back_count[el] = oi[src.oi_contact + 2 * k + 1]
    counters = np.array(oi[src.oi_counters:src.oi_counters + kern.N_COUNTERS], dtype=np.int64)
    clock = np.zeros(kern.N_CLOCK)
    clock[kern.F_T] = of[src.of_t]
    y = np.array(of[src.of_y:src.of_y + 2 * s.n_dof], dtype=np.float64)
    label = ("gpu" if target == "cuda" else "ensemble-cpu") + (
        "-fp32" if precision == "fp32" else "")
    return make_solution(s, sel, plan, rec, counters, clock, y, method="rk4",
                         t_span=(c.t0, c.t0 + run.duration), blowup=c.blowup,
                         step_min=plan.h, step_max=plan.h, compile_time=0.0,
                         wall_time=share, rhs_name=label, rhs_compile_time=0.0,
                         full_history=False)


def sample_steps_per_second(result: EnsembleResult) -> float:
    """RK4 sample-steps per second of kernel time (cases x steps / kernel seconds)."""
    return result.sample_steps / result.kernel_time if result.kernel_time > 0 else math.nan
