"""The GPU backend of the study runner: ``Study.run(backend="gpu")``, ``--backend gpu``.

A runner of :mod:`torquesplit.study.runners` is a callable ``runner(function, payloads)``
that yields one result dict per case.  :class:`GpuRunner` is one: it takes the payloads
in batches (as many cases as ``batch`` and the phase tables' memory allow, set up in
chunks), sets every case up on the CPU exactly as a CPU worker would (the study's
overrides, :func:`torquesplit.simulation.prepare_run`: structure, static equilibrium as
initial state, step), compiles the first chunk's kernel while the next is set up,
integrates the batch as one ensemble (:func:`torquesplit.gpu.ensemble.run_ensemble`:
one launch where the memory allows it), and turns each case's Solution into the
same result dict as :func:`torquesplit.study.case.run_case` through the study's own
functions (``output_values``, the status and contact-loss rules of
:mod:`torquesplit.study.case`).  The driver, the store and the dataset are the CPU
runner's: nothing else changes.

The settle rule of a study (``[analysis.settle]``: run lengths T, gT, g^2 T ... until two
successive runs agree) is run in rounds: every unsettled case of the batch runs the next
length in one ensemble, exactly as :func:`torquesplit.study.case._dynamic` runs them one
after the other.

``precision="fp32"``: the first ``check_cases`` cases of the study also run in FP64, and
the largest difference of every output between the two is reported (``report``, written
to the store's metadata and the dataset's attributes by :meth:`Study.run`).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import itertools
import logging
import math
import os
import time
import warnings
from collections import OrderedDict
from typing import Callable

import numpy as np

from .._memo import hash_arrays
from ..assembly.tables import TABLES
from ..errors import OptionError, warn_user
from .layout import IdentityMemo

log = logging.getLogger(__name__)

BATCH = 16384
"""Cases set up and integrated together (the store still gets them one by one): one case
a thread, a launch must hold enough cases to occupy every multiprocessor (an H100 has
132; with 64-thread blocks 1,024 cases kept 16 of them busy), and a set-up case costs
little memory (cases share their phase tables)."""


def check_plan(plan) -> None:
    """Refuse, by name and before any case runs, a study the GPU backend cannot run."""
    from ..errors import GpuUnsupportedError

    a = plan.analysis
    if a["type"] == "static":
        raise GpuUnsupportedError(
            "quasi-static analyses ([analysis] type = \"static\")",
            "run this study with the CPU backend (backend='cpu'; on the command line, "
            "leave out --backend gpu)")
    if a.get("method") not in (None, "rk4"):
        raise GpuUnsupportedError(
            f"adaptive time stepping (method = {a['method']!r})",
            "set [analysis] method = \"rk4\", or use the CPU backend")
    if plan.model.analysis.method != "rk4" and a.get("method") is None:
        raise GpuUnsupportedError(
            f"adaptive time stepping (the model's [analysis] method = "
            f"{plan.model.analysis.method!r})",
            "set [analysis] method = \"rk4\" in the study, or use the CPU backend")
    from ..study.outputs import HISTORY_FAMILIES

    history = [n for n in plan.outputs if n.split(".")[0] in HISTORY_FAMILIES]
    if history:  # (a GPU run keeps no history: they would be NaN)
        raise GpuUnsupportedError(
            f"outputs read from the history ({', '.join(history[:3])}"
            f"{', ...' if len(history) > 3 else ''}: a GPU run keeps none)",
            "leave the bearing forces out of study.outputs, or use the CPU backend")


#: cases set up first, before the phase tables' memory a case is known
FIRST_BATCH = 64
#: host memory for the distinct phase tables of one batch [bytes]
TABLE_BUDGET = 2 * 1024**3


class GpuRunner:
    """Run a study's cases as GPU ensembles (see the module docstring).

    Parameters
    ----------
    precision : {"fp64", "fp32"}
        Arithmetic of the dynamics; FP64 equals the CPU engine.
    target : {"cuda", "cpu"}
        ``"cpu"`` runs the same generated code on the CPU (tests, no device needed).
    batch : int
        Cases per ensemble at most (fewer where their phase tables would pass
        TABLE_BUDGET).
    check_cases : int
        FP32 only: cases also run in FP64 to report the FP32 error.
    workers : int
        Processes that set the cases up on the CPU (model, assembly, static
        equilibrium: about 10-20 ms a case, the host's share of a GPU study); 1: this
        process.
    """

    def __init__(self, *, precision: str = "fp64", target: str = "cuda", batch: int = BATCH,
                 check_cases: int = 16, workers: int = 1):
        from .ensemble import PRECISIONS, TARGETS

        if precision not in PRECISIONS:
            raise OptionError(f"precision must be one of {PRECISIONS}, got {precision!r}; "
                             "use 'fp64' or 'fp32'")
        if target not in TARGETS:
            raise OptionError(f"target must be one of {TARGETS}, got {target!r}")
        if batch < 1:
            raise OptionError(f"batch must be >= 1, got {batch}; give e.g. batch=16384")
        self.precision = precision
        self.target = target
        self.batch = int(batch)
        self.check_cases = int(check_cases)
        if int(workers) < 1:
            raise OptionError(f"workers must be >= 1, got {workers}; give e.g. workers=4")
        self.workers = int(workers)
        self._pool = None
        self._tables: OrderedDict = OrderedDict()  # table sets workers sent (bounded)
        self._case_bytes = 0.0  # host memory of a case's own tables (measured per batch)
        self._compiled_ahead = False
        self._fp32_cases: set = set()  # cases whose FP32 error was measured
        #: told what the runner does between finished cases (the study's progress sets it)
        self.on_stage: Callable[[str], None] | None = None
        self.device = ""
        self.report: dict = {"backend": "gpu", "target": target, "precision": precision,
                             "cases": 0, "ensembles": 0, "launches": 0,
                             "kernel_time_s": 0.0,
                             "compile_time_s": 0.0, "setup_time_s": 0.0, "post_time_s": 0.0,
                             "prepare_time_s": 0.0, "metrics_time_s": 0.0,
                             "sample_steps": 0}

    def __repr__(self) -> str:
        return f"GpuRunner(target={self.target!r}, precision={self.precision!r})"

    @staticmethod
    def check_plan(plan) -> None:
        """Refuse, by name, a study this runner cannot run (:func:`check_plan`); a study
        asks any runner given to it as ``runner`` with a ``check_plan``."""
        check_plan(plan)

    # ----------------------------------------------------------------- runner protocol
    def __call__(self, function, payloads):
        it = iter(payloads)
        try:
            while jobs := self._gather(it):
                yield from self._run_jobs(jobs)
        finally:
            if self._pool is not None:
                self._pool.shutdown(wait=False, cancel_futures=True)
                self._pool = None
                self._tables = OrderedDict()

    def _gather(self, it) -> list["_Job"]:
        """The next launch's cases, set up for their first run.  A GPU runs the cases of
        one launch side by side (on an H200 a launch of 1,000 cases took as long a step
        as one of 64), so a launch takes as many as ``batch`` and the phase tables'
        TABLE_BUDGET allow: they are set up in chunks (FIRST_BATCH, then doubling), the
        tables' memory a case measured after each."""
        jobs: list[_Job] = []
        while len(jobs) < self._next_size():
            want = min(self._next_size() - len(jobs), max(FIRST_BATCH, len(jobs)))
            chunk = [_Job(p, self._worker()) for p in itertools.islice(it, want)]
            if not chunk:
                break
            ahead = None
            if jobs and not self._compiled_ahead:
                ahead = functools.partial(self._compile_ahead, list(jobs))
            t = time.perf_counter()
            self._prepare(chunk, True, ahead)
            self.report["prepare_time_s"] += time.perf_counter() - t
            jobs += chunk
            self._measure_tables(jobs)
            self._say(f"{len(jobs)} cases set up for the next launch")
        return jobs

    def _say(self, text: str) -> None:
        if self.on_stage is not None:
            self.on_stage(text)

    def _compile_ahead(self, jobs: list["_Job"]) -> None:
        """Compile the kernel of the cases set up so far while the workers set up the
        next ones: the launch finds it compiled where its cases vary the parameters
        these vary (a Monte Carlo's do), and the compile (about 20 s for a 14-DOF model)
        overlaps the set-up instead of following it.  Once per runner; a failure is
        left to the launch, which compiles (and reports) for itself."""
        from .ensemble import compile_ahead

        self._compiled_ahead = True
        runs = [j.run for j in jobs if j.run is not None and not j.finished]
        if not runs:
            return
        self._say("compiling the kernel while the next cases are set up (once a model "
                  "pattern: about 20 s for a 14-DOF model)")
        t = time.perf_counter()
        try:
            compile_ahead(runs, target=self.target, precision=self.precision)
        except Exception as exc:  # noqa: BLE001 - the launch compiles and reports it
            log.debug("compiling ahead failed: %r", exc)
            return
        self.report["compile_ahead_s"] = time.perf_counter() - t

    def _prepare(self, jobs: list["_Job"], first: bool, meanwhile=None) -> None:
        """Set the jobs' next runs up, in a process pool when ``workers`` > 1 (calling
        ``meanwhile()`` while the workers work)."""
        args = [(j.p, None if first else j.length) for j in jobs]
        if self.workers > 1 and len(jobs) > 1:
            if self._pool is None:
                import multiprocessing
                from concurrent.futures import ProcessPoolExecutor

                from ..study.runners import worker_start

                self._pool = ProcessPoolExecutor(
                    self.workers, mp_context=multiprocessing.get_context("spawn"),
                    initializer=worker_start)
            chunk = max(1, len(jobs) // (4 * self.workers))
            pending = self._pool.map(prepare_case, *zip(*args), [True] * len(args),
                                     chunksize=chunk)  # (submitted: the workers start)
            if meanwhile is not None:
                meanwhile()
            results = list(pending)
            self._attach_tables(results, args)
        else:
            results = [prepare_case(p, length) for p, length in args]
        for job, res in zip(jobs, results, strict=True):
            job.apply_prepared(res)

    def _attach_tables(self, results: list[dict], args: list[tuple]) -> None:
        """Give the runs that a worker sent without their phase tables (it had sent those
        tables before: earlier in this call, or in an earlier one) the tables it sent, so
        every case of one table set shares one object.  One pass in order, with every set
        of this call at hand (the bounded memory is for later calls only); a case whose
        tables never came is set up again here (correct, slower) and its set kept."""
        this_call: dict[str, tuple] = {}
        for k, res in enumerate(results):
            key = res.get("tables")
            if not key:
                continue
            kept = this_call.get(key) or self._tables.get(key)
            if res.get("tables_stripped"):
                if kept is None:
                    res = results[k] = prepare_case(*args[k])
                    if res["run"] is None:
                        continue
                    kept = tuple(getattr(res["run"].structure, f) for f in TABLES)
            elif kept is None:
                kept = tuple(getattr(res["run"].structure, f) for f in TABLES)
            this_call[key] = kept
            _remember(self._tables, key, kept)
            results[k] = {**res, "run": _with_tables(res["run"], kept)}

    # ----------------------------------------------------------------------- batches
    def _run_jobs(self, jobs: list["_Job"]):
        """Integrate set-up jobs, set up and integrate again the ones whose settle rule
        asks for a longer run, then give every job's result."""
        active = [j for j in jobs if not j.finished]
        while active:
            ready = [j for j in active if j.run is not None and not j.finished]
            if ready:
                self._integrate(ready)
            active = [j for j in active if not j.finished]
            if active:
                t = time.perf_counter()
                self._prepare(active, False)
                self.report["prepare_time_s"] += time.perf_counter() - t
        for job in jobs:
            yield job.result()

    def _measure_tables(self, jobs: list["_Job"]) -> None:
        """Host memory of the distinct phase-table sets of a batch, per case: each
        distinct set is held by the structure (the kernel model takes its arrays as they
        are) and stacked into the launch (about twice its size)."""
        sets = {}
        for j in jobs:
            if j.run is not None:
                s = j.run.structure
                sets[id(s.stiffness_table)] = sum(getattr(s, f).nbytes for f in TABLES)
        if jobs:
            self._case_bytes = 2.0 * sum(sets.values()) / len(jobs)

    def _next_size(self) -> int:
        """Cases in the next batch: the runner's ``batch``, fewer where the cases' own
        phase tables would hold more than TABLE_BUDGET (a stiffness Monte Carlo of Ji &
        Li's drive: 44 MB a case)."""
        per = self._case_bytes
        fit = int(TABLE_BUDGET // per) if per > 0 else self.batch
        return max(min(self.batch, FIRST_BATCH), min(self.batch, fit))

    def _integrate(self, jobs: list["_Job"]) -> None:
        from .ensemble import run_ensemble

        runs = [j.run for j in jobs]
        self._say(f"running {len(runs)} cases together "
                  f"{'on the GPU' if self.target == 'cuda' else '(generated code, CPU)'}")
        res = run_ensemble(runs, target=self.target, precision=self.precision)
        self._say(f"the outputs of {len(runs)} cases")
        self.device = res.device
        r = self.report
        r["device"] = res.device
        if res.law_binding:
            r["law_binding"] = res.law_binding
        if res.binding_errors:
            r["law_binding_errors"] = res.binding_errors
        r["ensembles"] += 1
        r["launches"] += res.launches
        r["cases"] += len(runs)
        r["kernel_time_s"] += res.kernel_time
        r["compile_time_s"] += res.compile_time
        r["setup_time_s"] += res.setup_time
        r["post_time_s"] += res.post_time
        r["sample_steps"] += res.sample_steps
        fp64 = None
        if self.precision == "fp32" and r.get("fp32_runs_checked", 0) < self.check_cases:
            k = min(len(runs), self.check_cases - r.get("fp32_runs_checked", 0))
            fp64 = run_ensemble(runs[:k], target=self.target, precision="fp64").solutions
        t = time.perf_counter()
        for i, (job, sol) in enumerate(zip(jobs, res.solutions, strict=True)):
            job.take(sol, res.kernel_time / len(runs), res.compile_time / len(runs))
            if fp64 is not None and i < len(fp64):
                self._fp32_error(job, sol, fp64[i])
        r["metrics_time_s"] = r.get("metrics_time_s", 0.0) + time.perf_counter() - t

    def _fp32_error(self, job, sol32, sol64) -> None:
        """Largest absolute and relative difference of every output, FP32 against FP64;
        and what a difference cannot say: runs that failed in FP32 only
        (``fp32_failed``), outputs finite in one precision only (``one_finite`` per
        output).  ``fp32_checked`` counts cases (a settle rule's rounds of a case once),
        ``fp32_runs_checked`` runs."""
        from ..results import Results
        from ..study.outputs import output_values

        def values(sol):
            res = Results(model=job.run.model, kinematics=job.run.kinematics,
                          structure=job.run.structure, static=job.run.static, solution=sol)
            if not res.success:
                return None
            return output_values(res, job.p["definitions"])

        a, b = values(sol32), values(sol64)
        r = self.report
        if a is None and b is not None:
            r["fp32_failed"] = r.get("fp32_failed", 0) + 1
        err = r.setdefault("fp32_error", {})
        for name in job.p["outputs"]:
            x, y = (a or {}).get(name, math.nan), (b or {}).get(name, math.nan)
            e = err.setdefault(name, {"abs": 0.0, "rel": 0.0, "one_finite": 0})
            if math.isfinite(x) != math.isfinite(y):
                e["one_finite"] += 1
            if not (math.isfinite(x) and math.isfinite(y)):
                continue
            e["abs"] = max(e["abs"], abs(x - y))
            e["rel"] = max(e["rel"], abs(x - y) / max(abs(y), 1e-300))
        r["fp32_runs_checked"] = r.get("fp32_runs_checked", 0) + 1
        self._fp32_cases.add(job.p["index"])
        r["fp32_checked"] = len(self._fp32_cases)

    def _worker(self) -> str:
        where = "gpu" if self.target == "cuda" else "ensemble-cpu"
        return f"{os.uname().nodename}:{os.getpid()}:{where}"


#: (TABLES, the structure's phase tables, are the bulk of a prepared run: 14 MB for Ji &
#: Li's drive; the cases of one process share equal sets, torquesplit.assembly.tables)
#: table sets a worker remembers having sent (it strips only those), and the runner keeps
#: to give back: more, so that a set recent for one worker is still there (a worker that
#: strips a set the runner no longer has costs one set-up in the runner, no error)
WORKER_SETS, RUNNER_SETS = 4, 32
_SENT: OrderedDict = OrderedDict()  # sets this worker has sent: key -> tables (recent last)
_KEYS = IdentityMemo()


def _with_tables(run, tables: tuple):
    s = dataclasses.replace(run.structure, **dict(zip(TABLES, tables, strict=True)))
    return dataclasses.replace(run, structure=s)


def _table_key(run) -> str:
    """A digest of the run's table set (computed once per set object)."""
    current = tuple(getattr(run.structure, f) for f in TABLES)

    def digest():
        return hash_arrays(hashlib.blake2b(digest_size=16), current).hexdigest()

    return _KEYS.get(current, digest)


def _remember(kept: OrderedDict, key, value=True, bound: int = RUNNER_SETS) -> None:
    kept[key] = value
    kept.move_to_end(key)
    while len(kept) > bound:
        kept.popitem(last=False)


def prepare_case(p: dict, length: float | None = None, worker: bool = False) -> dict:
    """Set up one case as :func:`torquesplit.study.case.run_case` sets it up (the study's
    overrides, validation, :func:`torquesplit.simulation.prepare_run`), in this process or
    in a pool worker: ``{run, status, reason, warnings, full, length, tables}``.  With a
    settle rule, ``length`` is the run length of this round (None: the first, which is
    computed here, with ``full``, the cap of the rule); errors become statuses, as in
    run_case.  Cases with equal phase tables share one table object (the assembly does
    it); a ``worker`` sends a set once (``tables``: its key) and then runs without it
    (``tables_stripped``; :meth:`GpuRunner._attach_tables` puts them back)."""
    from ..errors import SolverError, TorquesplitError
    from ..model.io import load_model, model_from_dict
    from ..model.overrides import apply_overrides
    from ..simulation import prepare_run
    from ..study.case import _full_duration, _one_line

    out = {"run": None, "status": "ok", "reason": "", "warnings": [], "full": None,
           "length": length}
    a = p["analysis"]
    kw = {k: a[k] for k in ("method", "steps_per_period", "rtol", "max_steps")
          if a.get(k) is not None}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            data = apply_overrides(p["model"], p["overrides"])
            model = load_model(model_from_dict(data, source=p["source"]))
            settle = a.get("settle")
            if settle is None:
                out["run"] = prepare_run(model, duration=a.get("duration"),
                                         cycles=a.get("cycles"), **kw)
            else:
                if length is None:
                    full, f_min = _full_duration(model, a)
                    out["full"] = full
                    out["length"] = length = min(settle["start"] or 50.0 / f_min, full)
                out["run"] = prepare_run(model, duration=length, **kw)
        except (TorquesplitError, SolverError, ValueError) as exc:
            out.update(status="refused", reason=_one_line(exc))
        except Exception as exc:  # noqa: BLE001 - recorded, the study goes on
            out.update(status="error", reason=f"{type(exc).__name__}: {_one_line(exc)}")
    out["warnings"] = [_one_line(w.message) for w in caught]
    if out["run"] is not None and worker:
        out["tables"] = key = _table_key(out["run"])
        current = tuple(getattr(out["run"].structure, f) for f in TABLES)
        if key in _SENT:
            empty = tuple(np.zeros((0, 0)) for _ in TABLES)
            out["run"], out["tables_stripped"] = _with_tables(out["run"], empty), True
        # held here (strongly): the next case's set-up finds the set alive and shares it,
        # and its key is not hashed again (a 14.7 MB digest a case otherwise)
        _remember(_SENT, key, current, bound=WORKER_SETS)
    return out


class _Job:
    """One case through the rounds of a batch: load, (prepare, integrate)+, result."""

    def __init__(self, p: dict, worker: str):
        self.p = p
        self.run = None
        self.finished = False
        self.status = "ok"
        self.notes: list[str] = []  # warnings, one line each
        self.t0 = time.perf_counter()
        a = p["analysis"]
        self.settle = a.get("settle")
        self.length = None
        self.full = None
        self.previous = None
        self.vals = None
        self.out = {"index": p["index"], "status": "ok", "reason": "", "values": None,
                    "wall_time": 0.0, "integration_time": 0.0, "compile_time": 0.0,
                    "simulated_time": math.nan, "runs": 0, "settled": True,
                    "worker": worker, "warnings": []}

    def _guard(self, fn):
        """Run ``fn`` as run_case runs a case: warnings recorded, errors -> status."""
        from ..errors import SolverError, TorquesplitError
        from ..study.case import _one_line

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                return fn()
            except (TorquesplitError, SolverError, ValueError) as exc:
                self._fail("refused", _one_line(exc))
            except Exception as exc:  # noqa: BLE001 - recorded, the study goes on
                self._fail("error", f"{type(exc).__name__}: {_one_line(exc)}")
            finally:
                self.notes.extend(_one_line(w.message) for w in caught)
        return None

    def _fail(self, status: str, reason: str) -> None:
        self.out.update(status=status, reason=reason,
                        values=[math.nan] * len(self.p["outputs"]))
        self.status = status
        self.finished = True

    def apply_prepared(self, res: dict) -> None:
        """The outcome of :func:`prepare_case` for this case's next run."""
        self.notes.extend(res["warnings"])
        self.run = res["run"]
        if res["status"] != "ok":
            self._fail(res["status"], res["reason"])
            return
        if res["full"] is not None:
            self.full = res["full"]
        self.length = res["length"]

    def take(self, solution, kernel_share: float, compile_share: float) -> None:
        """A finished integration of this case (as case._dynamic after simulate)."""
        self._guard(lambda: self._take(solution, kernel_share, compile_share))

    def _take(self, solution, kernel_share, compile_share) -> None:
        from ..results import Results
        from ..study.case import _close
        from ..study.outputs import output_values

        run = self.run
        res = Results(model=run.model, kinematics=run.kinematics, structure=run.structure,
                      static=run.static, solution=solution)
        out = self.out
        out["integration_time"] += kernel_share
        out["compile_time"] += compile_share
        out["simulated_time"] = solution.t_final - solution.t_span[0]
        out["runs"] += 1
        names, defs = self.p["outputs"], self.p["definitions"]
        if self.settle is None or not res.success:
            self._finish(res)
            return
        vals = output_values(res, defs)
        current = [vals.get(n, math.nan) for n in names]
        settled = res.metrics("cycle_peak").settling.settled
        if (self.previous is not None and settled
                and _close(self.previous, current, self.settle["tolerance"], names)):
            self._finish(res, vals)
            return
        if self.length >= self.full:
            out["settled"] = False
            self._finish(res, vals)
            return
        self.previous = current
        self.length = min(self.length * self.settle["growth"], self.full)

    def _finish(self, res, vals=None) -> None:
        from ..study.case import _finish
        from ..study.outputs import output_values

        self.out["values"] = _finish(res, self.p["outputs"], self.p["definitions"], self.out,
                                     output_values, vals)
        self.status = self.out["status"]
        self.finished = True

    def result(self) -> dict:
        out = self.out
        if out["values"] is None:  # never integrated (cannot happen; be explicit)
            out.update(status="error", reason="the case was not integrated",
                       values=[math.nan] * len(self.p["outputs"]))
        out["warnings"] = sorted(set(self.notes))
        out["wall_time"] = time.perf_counter() - self.t0
        return out


def fallback_message(precision: str | None) -> str:
    """Why a study asked of the GPU backend runs on the CPU runner: the warning
    :func:`make_gpu_runner` gives, and the results' ``backend_fallback``."""
    from .compile import cuda_available

    return (f"backend='gpu' (--backend gpu): {cuda_available()[1]}; the study runs on the "
            "CPU runner instead (same results, CPU speed"
            + ("; in FP64: precision 'fp32' applies to the GPU backend only"
               if precision == "fp32" else "")
            + "). Run it on a machine with an NVIDIA GPU for the GPU backend.")


def make_gpu_runner(*, precision: str = "fp64", batch: int = BATCH,
                    workers: int | None = None):
    """A :class:`GpuRunner` on the CUDA device, or — with a warning that says why — the
    CPU runner when there is none (``None``: the caller makes its usual CPU runner)."""
    from ..errors import GpuFallbackWarning
    from .compile import cuda_available

    ok, _ = cuda_available()
    if not ok:
        msg = fallback_message(precision)
        log.info(msg)
        warn_user(msg, GpuFallbackWarning)
        return None
    return GpuRunner(precision=precision, target="cuda", batch=batch,
                     workers=int(workers or os.cpu_count() or 1))


__all__ = ["GpuRunner", "check_plan", "fallback_message", "make_gpu_runner", "BATCH"]
