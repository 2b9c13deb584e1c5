"""``Study`` and ``run_study``: check a study, run its cases, return an xarray Dataset.

The driver loop is the same whatever runs the cases (this process, a local process
pool, a Dask cluster; see :mod:`torquesplit.study.runners`):

1. resolve the study against its model (:func:`torquesplit.study.design.resolve`):
   every check happens here, before any case runs;
2. open the store in the output folder; on resume, refuse a changed study or model and
   skip every finished case;
3. stream the remaining cases to the runner; commit each result as it arrives; report
   progress through the callback; for a Monte Carlo stopping rule, stop submitting once
   the first n samples (n a checkpoint) give a narrow enough interval;
4. build the Dataset from the store (ordered by case index, so it does not depend on
   which worker finished first), write ``results.nc`` and the figures.
"""

from __future__ import annotations

import functools
import json
import logging
import math
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import OutputError, warn_user
from .case import payload, run_case
from .design import Plan, resolve
from .errors import StudyError, StudyInterrupted
from .runners import make_runner
from .spec import read_study
from .store import STORE_NAME, Store, StoreLock

log = logging.getLogger(__name__)

RESULTS_NAME = "results.nc"


@dataclass(frozen=True)
class Words:
    """How messages name the options of a run: the keyword arguments of
    :meth:`Study.run` (:data:`API_WORDS`) or the command-line flags (:data:`CLI_WORDS`,
    used by ``torquesplit study`` and ``sweep``)."""

    out: str
    resume: str
    resume_on: str
    overwrite_on: str
    backend: str
    backend_gpu: str
    precision: str
    scheduler: str
    workers: str


API_WORDS = Words(out="out", resume="resume", resume_on="resume=True",
                  overwrite_on="overwrite=True", backend="backend", backend_gpu="backend='gpu'",
                  precision="precision", scheduler="scheduler, client and runner",
                  workers="workers")
CLI_WORDS = Words(out="--out", resume="--resume", resume_on="--resume",
                  overwrite_on="--overwrite", backend="--backend", backend_gpu="--backend gpu",
                  precision="--precision", scheduler="--scheduler", workers="--workers")


@dataclass(frozen=True)
class Progress:
    """What the progress callback is told when the cases start (``last`` None, nothing
    computed yet) and after each finished case."""

    done: int
    """Cases finished (this run and earlier runs of the same study)."""
    failed: int
    """Of which not ok (contact lost, diverged, refused, error)."""
    total: int
    """Cases in the study (Monte Carlo with a stopping rule: the current target)."""
    computed: int
    """Cases computed by this run."""
    elapsed: float
    """Seconds since this run started."""
    last: dict | None
    """The case that just finished (index, status, reason, values...); None at the start."""
    stage: str = ""
    """What the runner is doing while no case finishes (the GPU runner: setting cases up,
    compiling its kernel, running a launch); empty with a finished case."""


class Study:
    """A study read from a file, a dict or a :class:`~torquesplit.study.spec.StudySpec`.

    Parameters
    ----------
    source : str, Path, dict or StudySpec
        A study file (``.toml``), the name of a shipped study, or its data.
    analysis : dict, optional
        Fields that replace the study's ``[analysis]`` ones, e.g. ``{"cycles": 50}`` for
        a shorter trial of a shipped study (a run length replaces the study's:
        ``duration`` drops its ``cycles`` and the other way round).  A resume compares
        the study with them.

    Examples
    --------
    >>> import torquesplit
    >>> study = torquesplit.Study({
    ...     "study": {"name": "k", "model": "ji_li_mill_drive",
    ...               "outputs": ["load_sharing.engineering"]},
    ...     "analysis": {"cycles": 20},
    ...     "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
    ...                              "values": [0.05, 0.1]}]}})
    >>> study.n_cases
    2
    >>> ds = study.run(workers=1)
    >>> ds["load_sharing.engineering"].dims
    ('meshes.m11.damping_ratio',)
    """

    def __init__(self, source, *, analysis: dict | None = None):
        self.spec, self.folder, self.text = read_study(source, analysis)
        self.source = str(source) if isinstance(source, (str, Path)) else None
        self._plan: Plan | None = None

    def __repr__(self) -> str:
        design = next((d for d in ("grid", "monte_carlo", "sensitivity")
                       if getattr(self.spec, d, None) is not None), "?")
        model = self.spec.study.model
        model = repr(model) if isinstance(model, str) else "a model given as data"
        return (f"Study({self.name!r}: {design} on {model}"
                f"{', from ' + self.source if self.source else ''})")

    @classmethod
    def from_file(cls, path) -> "Study":
        return cls(path)

    @property
    def name(self) -> str:
        return self.spec.study.name

    def plan(self) -> Plan:
        """The study checked against its model, with every case's values (cached)."""
        if self._plan is None:
            self._plan = resolve(self.spec, self.folder, self.text, self.source)
        return self._plan

    @property
    def n_cases(self) -> int:
        """Number of cases (Monte Carlo with a stopping rule: the most it may run)."""
        return self.plan().n_cases

    @property
    def outputs(self) -> list[str]:
        """The output names the study records (patterns expanded)."""
        return self.plan().outputs

    def run(self, *, workers: int | None = None, client=None, scheduler: str | None = None,
            runner=None, out=None, resume: bool = False, overwrite: bool = False,
            progress: Callable[[Progress], None] | None = None, figures: bool = True,
            backend: str = "cpu", precision: str | None = None):
        """Run the study and return its results as an :class:`xarray.Dataset`.

        Parameters
        ----------
        workers : int, optional
            Local worker processes (default: all cores; 1 runs in this process).
        client : dask.distributed.Client, optional
            Run on this Dask cluster instead.
        scheduler : str, optional
            Or the address of a Dask scheduler (``"tcp://host:8786"``).
        runner : callable, optional
            Or any runner ``runner(function, payloads) -> iterator of results``.
        out : str or Path, optional
            Output folder: the store ``study.sqlite`` (every finished case, committed as
            it completes), ``results.nc`` and the figures.  Without it nothing is written
            and the study cannot be resumed.
        resume : bool
            Continue the study stored in ``out``: finished cases are not computed again.
        overwrite : bool
            Delete a study stored in ``out`` and start again.
        progress : callable, optional
            Called with a :class:`Progress` after each finished case.
        figures : bool
            Write the figures (PNG and SVG) into ``out``.
        backend : {"cpu", "gpu"}
            ``"gpu"``: integrate the cases as ensembles on a CUDA device, one case per
            thread (:mod:`torquesplit.gpu`; same store and Dataset, FP64 results equal to
            the CPU engine's).  Without a device: a warning, and the CPU runner.  What the
            GPU kernel does not do (quasi-static analyses, ``method = "dopri"``) is
            refused by name before any case runs.  ``workers`` are then the processes
            that set the cases up on the CPU (default: all cores).
        precision : {"fp64", "fp32"}, optional
            GPU backend only: arithmetic of the dynamics (default "fp64").  "fp32" also
            runs the first cases in FP64 and reports the largest difference of each
            output (the Dataset's ``gpu_backend`` attribute).

        Raises
        ------
        StudyError
            Bad study file, or ``out`` holds another study (the message says what
            changed) - before any case runs.
        StudyInterrupted
            On Ctrl-C, after committing every finished case (also while ``results.nc``
            and the figures are written: the run is recorded as finished only once they
            are, and ``resume=True`` writes them again).
        """

        from ..errors import ModelWarning

        for note in self.plan().notes + resume_notes(out, resume, API_WORDS):
            warn_user(note, ModelWarning)  # (before any case runs)
        return self._run(API_WORDS, workers=workers, client=client, scheduler=scheduler,
                         runner=runner, out=out, resume=resume, overwrite=overwrite,
                         progress=progress, figures=figures, backend=backend,
                         precision=precision)

    def _run(self, words: Words, *, workers, client, scheduler, runner, out, resume,
             overwrite, progress, figures, backend, precision):
        """:meth:`run`, its messages naming the options as ``words`` says."""
        if resume and overwrite:
            raise StudyError(words.overwrite_on, (
                f"{words.resume_on} continues the stored study and {words.overwrite_on} "
                f"starts it again: give one of them"))
        plan = self.plan()
        if workers is not None and (isinstance(workers, bool) or not isinstance(
                workers, (int, np.integer)) or workers < 1):
            raise StudyError(words.workers, f"got {workers!r}; give at least 1 worker (1 "
                                            "runs the cases in this process)")
        chosen = _backend_runner(plan, backend, precision, client, scheduler, runner,
                                 workers, words)
        fallback = ""
        if backend == "gpu" and chosen is None:  # (kept in the results: backend_fallback)
            from ..gpu.backend import fallback_message

            fallback = fallback_message(precision)
        store = _open_store(plan, out, resume, overwrite, words)
        try:
            try:
                runner_ = chosen or make_runner(workers, client=client, scheduler=scheduler,
                                                runner=runner)
            except KeyboardInterrupt:  # (while the workers start: a stop like any other;
                # cases that ended in an error are not done: they run again)
                done = sum(1 for r in store.cases() if r["status"] != "error")
                raise StudyInterrupted(done, plan.design.n_cases, out) from None
            run = _Driver(plan, store, runner_, progress, out, words)
            run.execute()
            try:
                report = getattr(run.runner, "report", None)
                if report is not None:
                    store.write_meta({"gpu_backend": report})
                # (a fallback left no trace in the results: only the command line said it)
                store.write_meta({"backend_fallback": fallback})
                ds = dataset_from_store(plan, store, run.n_used)
                ds.attrs.update(run.stop_report)
                if out is not None:
                    _write_outputs(ds, Path(out), figures)
            except KeyboardInterrupt:
                # the cases are all saved; resuming writes the results and figures again
                store.end_run("interrupted")
                raise StudyInterrupted(int(run.finished.sum()), run.n_used, run.out) from None
            except BaseException:
                store.end_run("failed")
                raise
            store.end_run("finished")
        finally:
            store.close()
        return ds


def resume_notes(out, resume: bool, words: Words) -> list[str]:
    """What a resume does beyond skipping the finished cases: start from the first case
    where the folder holds no study (a typo in the folder restarted a long study without
    a word), run again the cases that ended in an error (an exception: a bug or the
    machine, which a later run may not meet; a refusal or a divergence is the model's and
    stays)."""
    if not resume or out is None:
        return []
    path = Path(out) / STORE_NAME
    if not path.exists():
        return [f"{words.out} {out} holds no study to resume: the study starts from its "
                f"first case"]
    import contextlib
    import sqlite3

    try:  # (a URI escapes a folder's '#', '?' or '%'; closing: 'with' only commits)
        with contextlib.closing(sqlite3.connect(path.resolve().as_uri() + "?mode=ro",
                                                uri=True)) as db:
            n = db.execute("SELECT COUNT(*) FROM cases WHERE status = 'error'").fetchone()[0]
    except sqlite3.Error:  # (the store's own checks say what is wrong with it)
        return []
    if not n:
        return []
    return [f"{n} case{'s' if n > 1 else ''} of the study in {out} ended in an error (an "
            f"exception, not a refusal or a divergence of the model) and "
            f"{'are' if n > 1 else 'is'} run again"]


def stored_cases(out) -> int:
    """How many finished cases the study store in ``out`` holds (0 without one)."""
    import contextlib
    import sqlite3

    path = Path(out) / STORE_NAME
    if not path.exists():
        return 0
    try:
        with contextlib.closing(sqlite3.connect(path.resolve().as_uri() + "?mode=ro",
                                                uri=True)) as db:
            return int(db.execute("SELECT COUNT(*) FROM cases WHERE status != 'error'"
                                  ).fetchone()[0])
    except sqlite3.Error:
        return 0


def _write_outputs(ds, out: Path, figures: bool) -> None:
    """``results.nc`` and (if asked) the figures of a study whose cases are all done."""
    from .dataset import write_dataset

    write_dataset(ds, out / RESULTS_NAME)
    if figures:
        from .figures import write_study_figures

        written = write_study_figures(ds, out / "figures")
        # the figures this study wrote, which an --overwrite removes (and no others: a
        # user's own plot in figures/ went too, a studies reviewer)
        manifest = out / "figures" / FIGURE_MANIFEST
        manifest.write_text(json.dumps(sorted(Path(p).name for p in written)))


def _backend_runner(plan: Plan, backend: str, precision, client, scheduler, runner,
                    workers=None, words: Words = API_WORDS):
    """The GPU runner for ``backend="gpu"`` (None: use the CPU runners), after refusing
    options that do not go together and, by name, what the GPU kernel does not do."""
    w = words
    if backend not in ("cpu", "gpu"):
        raise StudyError(w.backend, f"unknown backend {backend!r}; use 'cpu' or 'gpu'")
    if backend == "cpu":
        if precision is not None:
            raise StudyError(w.precision, f"applies to the GPU backend only; add "
                                          f"{w.backend_gpu} or leave {w.precision} out")
        # a runner given as such refuses, by name, what it cannot run (a GpuRunner passed
        # as ``runner`` ran a static study as a dynamic one, its outputs NaN and "ok")
        check = getattr(runner, "check_plan", None)
        if callable(check):
            check(plan)
        return None
    if precision not in (None, "fp64", "fp32"):
        raise StudyError(w.precision, f"unknown precision {precision!r}; use 'fp64' or "
                                      f"'fp32'")
    if client is not None or scheduler is not None or runner is not None:
        raise StudyError(w.backend, "the GPU backend runs the cases on this machine's GPU; "
                                    f"leave out {w.scheduler}")
    from ..gpu.backend import check_plan, make_gpu_runner

    check_plan(plan)
    return make_gpu_runner(precision=precision or "fp64", workers=workers)


def run_study(spec, *, analysis: dict | None = None, workers: int | None = None,
              client=None, scheduler: str | None = None, runner=None, out=None,
              resume: bool = False, overwrite: bool = False,
              progress: Callable[[Progress], None] | None = None, figures: bool = True,
              backend: str = "cpu", precision: str | None = None):
    """Run a study (file, name of a shipped study, dict or spec) and return its Dataset;
    ``analysis`` as :class:`Study` takes it (``{"cycles": 30}``: a shorter trial of a
    shipped study), the other arguments as :meth:`Study.run` (written out: a misspelt
    ``worker=2`` is refused by Python naming it, and ``help(run_study)`` lists them)."""
    return Study(spec, analysis=analysis).run(
        workers=workers, client=client, scheduler=scheduler, runner=runner, out=out,
        resume=resume, overwrite=overwrite, progress=progress, figures=figures,
        backend=backend, precision=precision)


def load_results(out):
    """The results Dataset of a finished study folder (``results.nc``)."""
    import xarray as xr

    from ..errors import OutputError

    where = Path(out)
    if where.is_file():
        raise OutputError(f"{out}: a file, not a study's folder; a run's results file opens "
                          f"with torquesplit.load_results({str(out)!r}), any torquesplit "
                          f".nc file with torquesplit.open_results")
    if not (where / RESULTS_NAME).is_file():
        why = ("no such folder" if not where.is_dir() else
               f"no {RESULTS_NAME} in it: the study has not finished (run it again with "
               f"resume=True, or --resume)" if (where / STORE_NAME).is_file() else
               f"not a study's folder (no {STORE_NAME})")
        raise OutputError(f"{out}: {why}")
    return xr.open_dataset(where / RESULTS_NAME, engine="h5netcdf")


# ============================================================================ store
def _provenance(plan: Plan) -> dict:
    from .. import __version__

    d = plan.design
    return {
        "format": 1, "study_name": plan.spec.study.name, "study_source": plan.source,
        "study_text": plan.study_text, "study": plan.spec.canonical(),
        "study_hash": plan.study_hash, "model_source": plan.model_source,
        "model": plan.model_dict, "model_hash": plan.model_hash,
        "torquesplit_version": __version__, "design": d.kind, "n_cases": d.n_cases,
        "outputs": plan.outputs, "parameters": [p.name for p in d.parameters],
        "created": time.time(),
    }


def _open_store(plan: Plan, out, resume: bool, overwrite: bool,
                words: Words = API_WORDS) -> Store:
    if out is None:
        if resume:
            raise StudyError(words.out, "resume needs the output folder of the earlier run; "
                                        "give out=DIR")
        store = Store(":memory:")
        store.write_meta(_provenance(plan))
        return store
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise StudyError(words.out, f"{out} is a file; a study writes a folder (its store, "
                                    f"results and figures): give a folder name")
    out.mkdir(parents=True, exist_ok=True)
    try:
        lock = StoreLock(out)
    except BlockingIOError as exc:
        raise StudyError(words.out, f"{out} is in use by another run of a study ({exc}); "
                                    f"wait for it to finish or stop it, or choose another "
                                    f"folder") from None
    try:
        store = _open_folder(plan, out, resume, overwrite, words)
    except BaseException:
        lock.release()
        raise
    store.lock = lock
    return store


#: in a study's figures folder: the names of the figures the study wrote
FIGURE_MANIFEST = ".torquesplit_figures.json"


def _study_figures(folder: Path) -> list[Path]:
    """The figures an earlier study wrote into ``folder``: those its manifest names, or
    (a folder of a version that wrote none) every PNG and SVG there."""
    manifest = folder / FIGURE_MANIFEST
    try:
        names = json.loads(manifest.read_text())
        return [folder / Path(str(n)).name for n in names] + [manifest]
    except (OSError, ValueError, TypeError):
        return [*folder.glob("*.png"), *folder.glob("*.svg")]


def _open_folder(plan: Plan, out: Path, resume: bool, overwrite: bool,
                 words: Words) -> Store:
    path = out / STORE_NAME
    if path.exists() and overwrite:
        for suffix in ("", "-wal", "-shm"):
            Path(str(path) + suffix).unlink(missing_ok=True)
    if overwrite:  # the earlier study's figures go with it (they stayed beside the new)
        for figure in _study_figures(out / "figures"):
            figure.unlink(missing_ok=True)
    exists = path.exists()
    if exists and not resume:
        done = (f" (finished: its results are in {out / RESULTS_NAME})"
                if (out / RESULTS_NAME).exists() else "")
        raise StudyError(words.out, f"{out} already holds a study{done}; add "
                                    f"{words.resume_on} to continue it, {words.overwrite_on} "
                                    f"to start it again, or choose another folder")
    # a folder of other results (no study store): what this study writes would replace them
    # (its .csv and .mat too: a spreadsheet's results.csv was replaced without a word, a
    # studies reviewer)
    written = [out / RESULTS_NAME] + [out / RESULTS_NAME.replace(".nc", x) for x in (
        ".csv", ".mat", "_sensitivity.csv")] + [out / "figures"]
    theirs = [f for f in written if f.exists()]
    if not exists and theirs and not overwrite:
        raise StudyError(words.out, f"{out} holds {theirs[0].name} of another run, which this "
                                    f"study would replace; choose another folder or add "
                                    f"{words.overwrite_on}")
    store = Store(path)
    if store.is_new():
        store.write_meta(_provenance(plan))
        return store
    meta = store.meta()
    try:
        _check_same(plan, meta, out, words)
    except StudyError:
        store.close()
        raise
    if meta.get("study_hash") != plan.study_hash:  # a change a resume accepts: recorded
        store.write_meta({**_provenance(plan), "created": meta.get("created")})
    return store


def _check_same(plan: Plan, meta: dict, out: Path, words: Words = API_WORDS) -> None:
    from .. import __version__

    w = words
    again = f"start a new study with another {w.out} or {w.overwrite_on}"
    if (meta.get("study_hash") != plan.study_hash
            and _values(_results_part(meta.get("study", {})))
            != _values(_results_part(plan.spec.canonical()))):
        stored = (meta.get("study") or {}).get("study", {}).get("name")
        if stored is not None and stored != plan.spec.study.name:  # another study: said
            # so, not as the JSON of every field that differs (a studies reviewer)
            raise StudyError(w.resume, f"{out} holds the study {stored!r}, not "
                                       f"{plan.spec.study.name!r}; {again}")
        changes = _diff(meta.get("study", {}), plan.spec.canonical())
        raise StudyError(w.resume, f"the study changed since {out} was started "
                                   f"({changes}); undo the change, or {again}")
    if meta.get("model_hash") != plan.model_hash:
        changes = _diff(meta.get("model", {}), plan.model_dict)
        raise StudyError(w.resume, f"the model changed since {out} was started "
                                   f"({changes}); undo the change, or {again}")
    if meta.get("torquesplit_version") != __version__:
        raise StudyError(w.resume, f"{out} was computed with torquesplit "
                                   f"{meta.get('torquesplit_version')}, this is {__version__}; "
                                   f"finish it with that version or start a new study")


#: fields of [study] that do not change any case: a resume accepts a change of them
WORDING = ("description", "reference")
#: fields of [monte_carlo] that say how many samples, not which: with random or Sobol
#: sampling sample i is the same whatever their number, so a resume may extend (or end)
#: the sample with another count or stopping rule (a reviewer tightening half_width had to
#: recompute everything)
EXTENT = ("samples", "stop")
PREFIX_SAMPLINGS = ("random", "sobol")


def _results_part(study: dict) -> dict:
    """A canonical study without the fields that only describe it (:data:`WORDING`) or,
    for a Monte Carlo whose samples are a prefix of a longer draw, its extent
    (:data:`EXTENT`)."""
    out = dict(study)
    if isinstance(out.get("study"), dict):
        out["study"] = {k: v for k, v in out["study"].items() if k not in WORDING}
    mc = out.get("monte_carlo")
    if isinstance(mc, dict) and mc.get("sampling", "random") in PREFIX_SAMPLINGS:
        out["monte_carlo"] = {k: v for k, v in mc.items() if k not in EXTENT}
    return out


def _values(obj):
    """``obj`` with every quantity text ("30 s", "9 um") replaced by its value in base
    units and its dimension, so that a resume compares values: "30 s" and "30000 ms" are
    the same study (they were refused as a change).  Only text that starts like a number
    is read as a quantity (a name such as "m" is not a metre)."""
    if isinstance(obj, dict):
        return {k: _values(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_values(v) for v in obj]
    if isinstance(obj, str) and re.match(r"\s*[-+]?(\d|\.\d)", obj):
        from ..model.units import registry

        try:
            q = registry().Quantity(obj).to_base_units()
        except Exception:  # noqa: BLE001 - not a quantity (pint raises many kinds): as text
            return obj
        return (float(f"{float(q.magnitude):.12g}"), str(q.dimensionality))
    return obj


def _diff(old, new, prefix: str = "", limit: int = 3) -> str:
    found: list[str] = []

    def walk(a, b, path):
        if len(found) > limit:
            return
        if isinstance(a, dict) and isinstance(b, dict):
            for k in sorted(set(a) | set(b), key=str):
                walk(a.get(k, "<absent>"), b.get(k, "<absent>"), f"{path}.{k}" if path else k)
        elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
            for i, (x, y) in enumerate(zip(a, b)):
                walk(x, y, f"{path}.{i}")
        elif a != b:
            found.append(f"{path}: {_short(a)} -> {_short(b)}")

    walk(old, new, prefix)
    more = " ..." if len(found) > limit else ""
    return "; ".join(found[:limit]) + more if found else "details differ"


def _short(x) -> str:
    text = json.dumps(x) if not isinstance(x, str) else repr(x)
    return text if len(text) <= 40 else text[:37] + "..."


# ============================================================================ driver
class _Driver:
    def __init__(self, plan: Plan, store: Store, runner, progress, out,
                 words: Words = API_WORDS):
        self.plan = plan
        self.store = store
        self.runner = runner
        self.progress = progress
        self.out = None if out is None else str(out)
        self.words = words
        d = plan.design
        self.total = d.n_cases
        self.n_used = d.n_cases
        stop = plan.spec.monte_carlo.stop if plan.spec.monte_carlo is not None else None
        self.stop = stop
        self.stop_at: int | None = None
        self.stop_report: dict = {}
        """The stopping rule's outcome (Dataset attributes), once it stopped."""
        self._checked: int | None = None
        self.watch = np.full(d.n_cases, np.nan) if stop else None
        self.finished = np.zeros(d.n_cases, dtype=bool)
        self.failed = 0
        self.computed = 0

    def execute(self) -> None:
        plan, store = self.plan, self.store
        for r in store.cases():
            if r["status"] != "error":  # (an error is run again: resume_notes)
                self._note(r)
        if self.stop is not None:
            self._check_stop()
        n_done = int(self.finished.sum())
        log.info("study %s: %d cases, %d already finished", plan.spec.study.name,
                 self.total, n_done)
        store.start_run(repr(self.runner), int(getattr(self.runner, "workers", 0) or 0))
        t0 = time.perf_counter()
        results = None
        state = "interrupted"
        try:
            # (inside: a Ctrl-C while the workers start is a stop like any other, with the
            # store's run closed and the hint to resume)
            if self.progress is not None and hasattr(self.runner, "on_stage"):
                self.runner.on_stage = functools.partial(self._stage, t0)
            results = self.runner(run_case, self._payloads())
            # the cases start: a progress bar shows at once (a first case compiles)
            if self.progress is not None:
                self.progress(Progress(int(self.finished[: self._target()].sum()),
                                       self.failed, self._target(), 0, 0.0, None))
            for r in results:
                store.put(r)
                self.computed += 1
                self._note(r)
                if self.stop is not None:
                    self._check_stop()
                if self.progress is not None:
                    self.progress(Progress(int(self.finished[: self._target()].sum()),
                                           self.failed, self._target(), self.computed,
                                           time.perf_counter() - t0, r))
            state = "cases done"  # Study.run marks it finished once the outputs are written
        except KeyboardInterrupt:
            raise StudyInterrupted(int(self.finished.sum()), self._target(), self.out) from None
        except OutputError:  # the store cannot be written: its message says what to do
            state = "failed"
            raise
        except (OSError, RuntimeError) as exc:  # a worker process died, a cluster went away
            state = "failed"
            again = (f"run it again with {self.words.resume_on}" if self.out else
                     "give an output folder to keep finished cases")
            if type(exc).__name__ == "BrokenProcessPool" and _unguarded_script():
                again = ("worker processes start by running your script "
                         f"{_unguarded_script()!r} from the top, study call and all: put "
                         "the code that runs the study under `if __name__ == \"__main__\":`"
                         f" (or use workers=1), then {again}")
            raise StudyError("", f"the study stopped after {int(self.finished.sum())} cases: "
                                 f"{type(exc).__name__}: {exc}; every finished case is "
                                 f"saved, {again}") from exc
        finally:
            close = getattr(results, "close", None) if results is not None else None
            if close is not None:
                close()
            if state != "cases done":
                store.end_run(state)
        if self.stop is not None:
            self.n_used = self.stop_at if self.stop_at is not None else self.total
        missing = int((~self.finished[: self.n_used]).sum())
        if missing:  # a runner that dropped cases (should not happen)
            log.warning("%d cases of the study have no result", missing)

    def _target(self) -> int:
        return self.stop_at if self.stop_at is not None else self.total

    def _payloads(self):
        d = self.plan.design
        for i in range(d.n_cases):
            if self.stop_at is not None and i >= self.stop_at:
                return
            if not self.finished[i]:
                yield payload(i, self.plan, d.overrides(i))

    def _stage(self, t0: float, text: str) -> None:
        """The runner's report of what it is doing between finished cases."""
        self.progress(Progress(int(self.finished[: self._target()].sum()), self.failed,
                               self._target(), self.computed, time.perf_counter() - t0,
                               None, stage=text))

    def _note(self, r: dict) -> None:
        i = int(r["index"])
        if i >= self.finished.size:
            return
        self.finished[i] = True
        if r["status"] != "ok":
            self.failed += 1
        if self.watch is not None:
            j = self.plan.outputs.index(self.stop.output)
            self.watch[i] = r["values"][j]

    # -------------------------------------------------------------- stopping rule
    def _check_stop(self) -> None:
        """Decide at checkpoints n = min_samples + k batch, once samples 0..n-1 are all
        finished: the decision depends only on those n values (not on timing)."""
        s = self.stop
        while self.stop_at is None:
            n = self._next_checkpoint()
            if n is None or not self.finished[:n].all():
                return
            half, stat, lower, upper = confidence_interval(self.watch[:n], s.statistic,
                                                           s.confidence)
            target = s.half_width * (abs(stat) if s.relative else 1.0)
            finite = int(np.isfinite(self.watch[:n]).sum())
            log.info("stopping rule at n = %d: %s = %.6g +/- %.3g (target %.3g)", n,
                     s.statistic, stat, half, target)
            if finite < n:  # failed cases have no value: the interval is over the others
                log.warning("stopping rule at n = %d: %s over %d of %d cases (%d without a "
                            "finite value left out)", n, s.statistic, finite, n, n - finite)
            if half <= target or n >= s.max_samples:
                self.stop_at = n
                self.stop_report = {
                    "stopping_statistic": s.statistic, "stopping_estimate": float(stat),
                    "stopping_half_width": float(half), "stopping_target": float(target),
                    "stopping_lower": float(lower), "stopping_upper": float(upper),
                    "stopping_target_met": int(half <= target), "stopping_cases": int(n),
                    "stopping_finite_cases": finite}
                return
            self._checked = n

    def _next_checkpoint(self) -> int | None:
        s = self.stop
        last = self._checked
        n = s.min_samples if last is None else last + s.batch
        if last is not None and last >= s.max_samples:
            return None
        return min(n, s.max_samples)


def confidence_interval(values, statistic: str, confidence: float):
    """``(half_width, statistic, lower, upper)``: the confidence interval of the mean
    (Student t, symmetric) or of the 95th percentile over the finite ``values``.

    The percentile's interval is distribution-free: the order statistics x_(l), x_(u)
    (0-based) cover the q-quantile with probability F(u) - F(l), F the Binomial(n, q)
    distribution function (B = the samples below the quantile); l is the largest rank
    with F(l) <= alpha/2, u the smallest with F(u) >= 1 - alpha/2, so the coverage is at
    least ``confidence``; where u is the largest sample (or would pass it), the interval
    ends there (u = n - 1) and l is the largest rank that keeps the coverage (finite
    from 59 samples at 95 %).  It is not centred on the estimate: the half-width is half its
    length."""
    from scipy import stats

    x = np.sort(np.asarray(values, dtype=float))
    x = x[np.isfinite(x)]
    n = x.size
    if n < 2:
        return math.inf, math.nan, -math.inf, math.inf
    if statistic == "mean":
        m = float(x.mean())
        h = float(stats.t.ppf(0.5 + confidence / 2, n - 1) * x.std(ddof=1) / math.sqrt(n))
        return h, m, m - h, m + h
    q = 0.95
    est = float(np.quantile(x, q))
    alpha = 1 - confidence
    F = stats.binom.cdf(np.arange(n), n, q)  # F[k] = P(B <= k)
    u = int(np.searchsorted(F, 1 - alpha / 2 - 1e-12))
    if u >= n - 1:  # the interval ends at the largest sample: l as high as coverage allows
        u = n - 1
        ok = np.flatnonzero(F[u] - F >= confidence - 1e-12)
        lo = int(ok[-1]) if ok.size else -1
    else:
        below = np.flatnonzero(F <= alpha / 2 + 1e-12)
        lo = int(below[-1]) if below.size else -1
    if lo < 0:
        return math.inf, est, -math.inf, float(x[u])
    return float((x[u] - x[lo]) / 2), est, float(x[lo]), float(x[u])


def confidence_half_width(values, statistic: str, confidence: float) -> tuple[float, float]:
    """Half-width and statistic of :func:`confidence_interval`."""
    half, est, _, _ = confidence_interval(values, statistic, confidence)
    return half, est


# ============================================================================ dataset
def dataset_from_store(plan: Plan, store: Store, n_used: int | None = None):
    """The study's Dataset from the finished cases in ``store`` (see
    :func:`torquesplit.study.dataset.build_dataset`)."""
    from .dataset import build_dataset

    n = plan.n_cases if n_used is None else n_used
    return build_dataset(plan, store.cases(below=n), n, store.meta())


def _unguarded_script() -> str:
    """The script run as ``__main__`` when it is a file without an ``if __name__ ==
    "__main__"`` guard (its worker processes re-run it: a study or a file write at its
    top level then fails in every worker), else ''."""
    import sys

    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None) or ""
    if not path.endswith(".py"):
        return ""
    try:  # a script with the guard broke the pool some other way (memory, a crash)
        guarded = "__main__" in Path(path).read_text(errors="replace")
    except OSError:
        guarded = False
    return "" if guarded else path
