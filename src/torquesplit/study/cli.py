"""``torquesplit study`` and ``torquesplit sweep``: run a study from the command line.

Registered on the main ``torquesplit`` app by :mod:`torquesplit.cli`.  Progress is a rich
bar on stderr (cases done, not ok, elapsed, remaining); the summary table goes to
stdout.  Bad input: one line naming the field, exit status 2, before any case runs.
Ctrl-C: every finished case is already saved; one line says how to resume; status 130.
"""

from __future__ import annotations

import contextlib
import json
import math
import re
import warnings
from pathlib import Path
from typing import Optional

import typer

from .. import _json
from ..cli_support import LOG_EVERY, clock_text, json_option
from ..errors import OptionError

BACKEND_HELP = ("cpu (default) or gpu: integrate the cases as ensembles on a CUDA GPU, one "
                "case per thread (falls back to the CPU with a warning when there is none).")
PRECISION_HELP = ("GPU backend: fp64 (default; the CPU runner's values up to the GPU's "
                  "rounding, see docs/studies.md) or fp32 (its error against fp64 is "
                  "reported).")


def _ui():
    from .. import cli

    return cli


# --------------------------------------------------------------------------- study
def study(
    study_file: Optional[str] = typer.Argument(
        None, help="Study file (.toml) or the name of a shipped study (see --list)."),
    workers: Optional[int] = typer.Option(
        None, "--workers", help="Local worker processes (default: all cores; 1 = this process).",
        metavar="N"),
    scheduler: Optional[str] = typer.Option(
        None, "--scheduler", help="Run on a Dask cluster: the scheduler address, e.g. "
                                  "tcp://10.0.0.5:8786.",
        metavar="ADDRESS"),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Output folder: store, results.nc, figures "
                            "(default: ./study_NAME).",
        metavar="DIR"),
    resume: bool = typer.Option(False, "--resume", help="Continue the study stored in --out."),
    overwrite: bool = typer.Option(False, "--overwrite",
                                   help="Start again, deleting the study stored in --out."),
    list_studies: bool = typer.Option(False, "--list", help="List the shipped studies."),
    duration: Optional[str] = typer.Option(
        None, "--duration", help="Simulated time per case, instead of the study's.",
        metavar="TIME"),
    cycles: Optional[int] = typer.Option(
        None, "--cycles", help="Cycles of the slowest mesh per case, instead of the study's.",
        metavar="N"),
    backend: str = typer.Option(
        "cpu", "--backend", help=BACKEND_HELP, metavar="NAME"),
    precision: Optional[str] = typer.Option(
        None, "--precision", help=PRECISION_HELP, metavar="NAME"),
    no_figures: bool = typer.Option(False, "--no-figures", help="Do not write figures."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress bar."),
    as_json: bool = json_option("Print the summary as JSON."),
):
    """Run a study: a grid, a Monte Carlo or a sensitivity ranking of a model."""
    ui = _ui()
    if list_studies:
        _list()
        return
    if study_file is None:
        ui._fail(ValueError("give a study file or a shipped study name; list them with "
                            "'torquesplit study --list'"))
        return
    analysis = {k: v for k, v in (("duration", _seconds(duration)), ("cycles", cycles))
                if v is not None}
    _run(study_file, workers=workers, scheduler=scheduler, out=out, resume=resume,
         overwrite=overwrite, figures=not no_figures, quiet=quiet, as_json=as_json,
         backend=backend, precision=precision, analysis=analysis)


@contextlib.contextmanager
def _terminate_as_interrupt():
    """While a study runs, SIGTERM (a batch system's time limit, ``timeout``, ``kill``)
    stops it as Ctrl-C does: the finished cases committed, the workers shut down, one
    line saying how to resume (it died with 'leaked semaphore objects', the store's run
    left 'running' and its lock behind)."""
    import signal
    import threading

    from ..errors import HeldInterrupt

    terminated = HeldInterrupt()  # (true once a SIGTERM came)
    if threading.current_thread() is not threading.main_thread():
        yield terminated
        return

    def stop(signum, frame):
        terminated.hit = True
        from .._launch import _stop_as_interrupt  # (as every command stops on it)

        _stop_as_interrupt(signum, frame)

    before = signal.signal(signal.SIGTERM, stop)
    try:
        yield terminated
    finally:
        signal.signal(signal.SIGTERM, before)


def _seconds(duration: str | None) -> str | None:
    """``--duration`` as the study file writes it: a bare number is seconds, as ``run``
    reads it (``sweep ... --duration 0.1`` said it was not a time, and ``study`` blamed
    the study file's analysis.duration for the option)."""
    if duration is None:
        return None
    try:
        float(duration)
    except ValueError:
        return duration
    return f"{duration.strip()} s"


def _list() -> None:
    from torquesplit._table import Table

    from .shipped import study_info, study_names

    ui = _ui()
    t = Table(title="shipped studies (torquesplit study NAME)")
    t.add_column("name", style="bold")
    t.add_column("model")
    t.add_column("description")
    t.add_column("reference")
    for name in study_names():
        info = study_info(name)
        t.add_row(name, info.get("model", ""), info.get("description", ""),
                  info.get("reference", ""))
    ui.console.print(t)


def _run(source, *, workers, scheduler, out, resume, overwrite, figures, quiet, as_json,
         name_hint: str | None = None, backend: str = "cpu", precision: str | None = None,
         flag: str | None = None, analysis: dict | None = None):
    """Run a study from the command line; ``flag``: the option that wrote its only grid
    parameter ('--vary'), named in errors instead of the study field; ``analysis``: the
    ``[analysis]`` fields given as options (``--duration``, ``--cycles``)."""
    from ..errors import TorquesplitError
    from .core import CLI_WORDS
    from .errors import StudyInterrupted

    ui = _ui()
    terminated = False  # (a SIGTERM while the cases run: _terminate_as_interrupt)
    try:
        st = _study_with(source, analysis)
        plan = st.plan()
        if out is None:
            out = Path(f"study_{_safe(name_hint or st.name)}")
        if workers is not None and workers < 1:
            raise OptionError(f"--workers {workers}: give at least 1")
        if not as_json:
            ui.err_console.print(
                f"[bold]{st.name}[/]: {plan.n_cases} cases ({plan.design.kind}, "
                f"{plan.analysis['type']}), {_count(len(plan.outputs), 'output')} -> {out}",
                highlight=False)
        from .core import resume_notes, stored_cases

        for note in plan.notes:  # cases known invalid before any runs
            ui.ux.warn(_sweep_note(note, flag) if flag else note)
        for note in resume_notes(out, resume, CLI_WORDS):
            ui.ux.warn(note)
        kept = stored_cases(out) if resume else 0
        if kept and not as_json:  # (a resume went straight to 'cases 3/6' without a word)
            # (before the stored study is compared with this one: 'kept', then a refusal
            # of a changed --cycles, read as a contradiction, a studies reviewer)
            ui.err_console.print(f"resuming: {kept} finished case{'s' if kept > 1 else ''} "
                                 f"stored in {out}, kept if the study is unchanged",
                                 highlight=False)
        with warnings.catch_warnings():
            if backend == "gpu":  # no device: say so in one line, not as a Python warning
                from ..errors import GpuFallbackWarning
                from ..gpu.backend import check_plan
                from ..gpu.compile import cuda_available, cuda_simulated

                # what the GPU backend refuses, before a note that it would fall back
                # (the two read as a contradiction, a GPU reviewer)
                check_plan(plan)
                ok, why = cuda_available()
                if not ok:
                    ui.err_console.print(
                        f"[yellow]--backend gpu:[/] {why}; running on the CPU runner "
                        "(same results, CPU speed"
                        + ("; in FP64: --precision fp32 applies to the GPU backend only"
                           if precision == "fp32" else "") + ")", highlight=False)
                elif cuda_simulated():
                    ui.err_console.print(
                        "[yellow]--backend gpu:[/] numba's CUDA simulator "
                        "(NUMBA_ENABLE_CUDASIM=1 is set): the same results at Python speed; "
                        "unset it to run on the GPU", highlight=False)
                warnings.simplefilter("ignore", GpuFallbackWarning)
            # the messages name the flags (--resume), not Study.run's arguments
            with _terminate_as_interrupt() as terminated:
                ds = _with_bar(lambda cb: st._run(CLI_WORDS, workers=workers, client=None,
                                                  scheduler=scheduler, runner=None, out=out,
                                                  resume=resume, overwrite=overwrite,
                                                  progress=cb, figures=figures,
                                                  backend=backend, precision=precision),
                               plan.n_cases, quiet or as_json)
    except StudyInterrupted as exc:
        # every case done: stopped while results.nc and the figures were written
        unwritten = ((f"; results.nc{' and figures' if figures else ''} not all written")
                     if exc.done >= exc.total else "")
        again = ("the same command with --resume in place of --overwrite" if overwrite
                 else "the same command with --resume")
        from ..errors import interrupt_name

        # (a SIGHUP stops it as Ctrl-C does, and exits 129: torquesplit._launch)
        cause = "SIGTERM" if terminated else interrupt_name()
        why = f" ({cause})" if cause != "Ctrl-C" else ""
        ui.err_console.print(f"[yellow]stopped{why}:[/] ", end="")
        ui.err_console.print(f"{exc.done} of {exc.total} cases done and saved in {out}"
                             f"{unwritten}; to finish, run {again}",
                             markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(143 if terminated else 130)
    except (TorquesplitError, ValueError, OSError) as exc:
        from .errors import StudyError

        if flag and isinstance(exc, StudyError):  # the sweep's words, not the study's
            exc = StudyError.of([(_sweep_option(f, flag), _sweep_words(m))
                                 for f, m in exc.problems])
        ui._fail(exc)
        return
    _summary(ds, Path(out), as_json, figures)


def _study_with(source, analysis: dict | None):
    """The study of ``source`` with the run length of ``--duration``/``--cycles``
    (checked first, their errors naming the option)."""
    from .core import Study
    from .errors import StudyError

    if not analysis:
        return Study(source)
    ui = _ui()
    ui._one_run_length(analysis.get("duration"), analysis.get("cycles"))
    flag = "--duration" if "duration" in analysis else "--cycles"
    if "duration" in analysis:
        ui._positive(ui.ux.quantity(analysis["duration"], "time", flag), flag, "'0.5 s'")
    else:
        ui._at_least(analysis["cycles"], 1, flag, "200")
    st = Study(source)
    if st.spec.analysis.type == "static":
        raise OptionError(f"{flag} sets the length of a dynamic run; the study "
                          f"'{st.name}' is quasi-static (analysis type = 'static', which "
                          f"turns the gears through whole revolutions): leave {flag} out")
    try:
        return Study(source, analysis=analysis)
    except StudyError as exc:  # (not expected: the values are checked above)
        raise StudyError.of([(flag if f.startswith("analysis.") else f, m)
                             for f, m in exc.problems]) from None


#: a study field -> the ``sweep`` option that wrote it
_SWEEP_OPTIONS = (("study.outputs", "--output"), ("analysis.duration", "--duration"),
                  ("analysis.cycles", "--cycles"), ("analysis.settle", "--settle"),
                  ("set", "--set"), ("study.model", "MODEL"))


def _sweep_option(field: str, flag: str) -> str:
    """The option of ``sweep`` that wrote study field ``field`` (its only grid parameter
    is ``flag``'s); the field itself where no option wrote it."""
    if field == "grid.parameters":  # (a case of the only parameter)
        return flag
    if field.startswith("grid.parameters.0"):
        sub = field[len("grid.parameters.0"):].lstrip(".")
        return flag + (f" ({sub})" if sub else "")
    for prefix, option in _SWEEP_OPTIONS:
        if field == prefix or field.startswith(prefix + "."):
            return option
    return field


#: a study file's remedy -> the sweep's (its message spoke study-file syntax to a command
#: line: 'use spacing = "linear"' where the fix is to leave out --log)
_SWEEP_WORDS = (('use spacing = "linear"', "leave out --log"),
                # (the study file's key, where the sweep's unit follows the count)
                ("given for a plain-number field; remove 'unit'",
                 "given for a plain-number field; write no unit after the count"),
                # (--vary takes a range only: one value is START:START:1)
                ("give a different stop, or 'values'",
                 "give a different STOP, or one value as START:START:1"))


def _sweep_words(message: str) -> str:
    """A study message's remedy in the sweep's options (:data:`_SWEEP_WORDS`; a study
    file's ``unit = "um"`` is the unit after the count of --vary)."""
    for study, sweep in _SWEEP_WORDS:
        message = message.replace(study, sweep)
    # a changed sweep's resume named the study fields it is built of (a reviewer:
    # 'grid.parameters.0.stop: 300.0 -> 350.0')
    message = re.sub(r"\bgrid\.parameters\.0\.(start|stop|num)\b",
                     lambda m: f"--vary's {m.group(1).upper()}", message)
    message = re.sub(r"\bgrid\.parameters\.0\.(unit|paths?|values)\b", "--vary", message)
    message = re.sub(r"\banalysis\.(duration|cycles)\b", r"--\1", message)
    return re.sub(r'write e\.g\. unit = "([^"]+)"',
                  r"write the unit after the count, e.g. START:STOP:NUM\1", message)


def _sweep_note(note: str, flag: str) -> str:
    """A plan's note ("field: message") in the sweep's words, as its errors
    (:func:`_sweep_option`)."""
    field, sep, message = note.partition(": ")
    return f"{_sweep_option(field, flag)}{sep}{_sweep_words(message)}" if sep else note


def _eta_column():
    """The time left as the mean rate of this session's finished cases gives it (cases
    per second over the time since the bar started: the workers' parallelism included),
    counting down between completions.  rich's own column took the speed of the last few
    completions: two workers finishing together read as 'ETA 0:00:04' with 95 s left,
    frozen until the next case (a reviewer)."""
    import time

    from rich.progress import ProgressColumn
    from rich.text import Text

    class Eta(ProgressColumn):
        def render(self, task):
            finish = task.fields.get("finish")
            if finish is None:
                return Text("-:--:--", style="progress.remaining")
            return Text(clock_text(finish - time.monotonic()), style="progress.remaining")

    return Eta()


def eta_finish(start: tuple[float, int], now: float, done: int, total: int):
    """When the study will finish (monotonic seconds) at the mean rate since ``start``
    (time, cases done then: a resumed study's earlier cases do not count); None before a
    case of this session has finished."""
    t0, done0 = start
    if done <= done0 or now <= t0:
        return None
    return now + (total - done) * (now - t0) / (done - done0)


def progress_lines(write, clock=None):
    """A study's progress as plain lines for a log (stderr not a terminal: a batch job, a
    cluster, nohup), where a bar draws nothing until the end: one when the first case
    finishes, then at most every LOG_EVERY seconds, and the last.  ``write(text)``."""
    import time

    clock = clock or time.monotonic
    state = {"start": None, "last": None, "stage": None}

    def cb(p):
        now = clock()
        if state["start"] is None:
            state["start"] = (now, p.done)
            return
        if getattr(p, "stage", ""):  # what a runner does between cases (the GPU runner's)
            if state["stage"] is None or now - state["stage"] >= LOG_EVERY:
                state["stage"] = now
                write(f"{p.stage} ({clock_text(now - state['start'][0])} elapsed)")
            return
        due = state["last"] is None or now - state["last"] >= LOG_EVERY or p.done >= p.total
        if not due or p.done <= state["start"][1]:
            return
        state["last"] = now
        finish = eta_finish(state["start"], now, p.done, p.total)
        left = "" if finish is None or p.done >= p.total else \
            f", about {clock_text(finish - now)} left"
        write(f"cases {p.done}/{p.total} ({p.failed} not ok), "
              f"{clock_text(now - state['start'][0])} elapsed{left}")

    return cb


def _with_bar(job, total: int, quiet: bool):
    if quiet:
        return job(None)
    import time

    if not getattr(_ui().err_console, "is_terminal", False):
        con = _ui().err_console
        return job(progress_lines(lambda text: con.print(text, highlight=False,
                                                          markup=False)))

    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                               TimeElapsedColumn)

    ui = _ui()
    bar = Progress(TextColumn("cases"), BarColumn(), MofNCompleteColumn(),
                   TextColumn("[red]{task.fields[failed]} not ok"), TimeElapsedColumn(),
                   TextColumn("ETA"), _eta_column(),
                   TextColumn("{task.fields[stage]}", style="dim", markup=False),
                   console=ui.err_console, transient=False)
    # the bar shows from the first report: a study refused before it starts (its folder
    # holds another study) draws no empty bar above the error
    task, start = [], []

    def cb(p):
        now = time.monotonic()
        if not task:
            bar.start()
            task.append(bar.add_task("study", total=total, failed=0, finish=None,
                                     stage=""))
            start.append((now, p.done))
        bar.update(task[0], completed=p.done, total=p.total, failed=p.failed,
                   finish=eta_finish(start[0], now, p.done, p.total),
                   stage=getattr(p, "stage", ""))

    try:
        return job(cb)
    finally:
        if task:
            bar.stop()


def _summary(ds, out: Path, as_json: bool, figures: bool) -> None:
    import numpy as np
    from rich.markup import escape

    from .dataset import ranking, warning_groups
    from .outputs import output_definitions

    ui = _ui()
    status = ds["status"].values.ravel()
    groups = warning_groups(ds)
    n_warned = (int((ds["warning_count"].values.ravel() > 0).sum())
                if "warning_count" in ds else 0)
    counts = {s: int((status == s).sum()) for s in sorted(set(status.tolist()))}
    # a study none of whose cases gave outputs failed (it exited 0, a reliability
    # reviewer: a script took 'cases: 4 diverged' for success)
    failed = status.size > 0 and not any(counts.get(s) for s in ("ok", "contact_lost"))
    out_vars = [v for v in ds.data_vars if "output" in ds[v].attrs]
    # (each figure's PNG and SVG: --json listed the PNGs only, a reviewer)
    figs = sorted(str(p) for x in ("*.png", "*.svg")
                  for p in (out / "figures").glob(x)) if figures else []
    if as_json:
        coords = [c for c in ds.coords if c not in ("output", "factor")
                  and ds[c].dtype.kind == "f"]
        data = {"success": not failed,
                "study": ds.attrs["study_name"], "design": ds.attrs["design"],
                "cases": int(status.size), "status": counts,
                "results_file": str(out / "results.nc"),
                "results_files": [str(out / f"results.{x}") for x in ("nc", "csv", "mat")],
                "figures": figs,
                "coordinates": {c: [float(x) for x in np.ravel(ds[c].values)]
                                for c in coords},
                # (SI, as the outputs: a reviewer read 5e-05 without a unit)
                "coordinate_units": {c: ds[c].attrs.get("units", "") for c in coords},
                "outputs": {ds[v].attrs["output"]: [_num(x) for x in ds[v].values.ravel()]
                            for v in out_vars},
                # each list runs over these dimensions, the last fastest (C order)
                "output_dimensions": list(ds[out_vars[0]].dims) if out_vars else [],
                "output_units": {ds[v].attrs["output"]: ds[v].attrs.get("units", "")
                                 for v in out_vars},
                "definitions": output_definitions([ds[v].attrs["output"] for v in out_vars]),
                "reasons": sorted({r for r in ds["reason"].values.ravel().tolist() if r}),
                "cases_warned": n_warned,
                "warnings": [{"text": g["text"], "cases": g["cases"]} for g in groups]}
        if "stopping_target_met" in ds.attrs:
            data["stopping_rule"] = {k[len("stopping_"):]: ds.attrs[k] for k in ds.attrs
                                     if k.startswith("stopping_") and k != "stopping_rule"}
            data["stopping_rule"]["target_met"] = bool(data["stopping_rule"]["target_met"])
            # which output, and in what unit its estimate and widths are (a reviewer read
            # bare numbers in N)
            watched = json.loads(ds.attrs.get("stopping_rule", "{}")).get("output")
            if watched:
                from .dataset import variable_name

                var = variable_name(watched)
                data["stopping_rule"].update(
                    output=watched,
                    units=ds[var].attrs.get("units", "") if var in ds else "")
        if ds.attrs["design"] == "monte_carlo":  # (the terminal's table: not in --json)
            data["statistics"] = {ds[v].attrs["output"]: sample_statistics(ds[v].values)
                                  for v in out_vars}
        if ds.attrs["design"] == "sensitivity":
            data["ranking"] = {ds[v].attrs["output"]: ranking(ds, ds[v].attrs["output"])
                               for v in out_vars}
            data["sensitivity_warnings"] = json.loads(ds.attrs.get("sensitivity_warnings",
                                                                    "[]"))
        print(_json.dumps(data, indent=2))
        _fail_if_no_results(failed, counts)
        return
    from torquesplit._table import Table

    design = ds.attrs["design"]
    if design == "grid" and status.size <= MAX_TABLE_CASES:
        for title, columns in _grid_tables(ds, out_vars):
            ui.console.print(_grid_table(ds, title, columns))
    elif design == "grid":  # never Monte Carlo statistics over grid points
        ui.console.print(f"{ds.attrs['study_name']}: a grid of {status.size} cases "
                         f"({' x '.join(str(n) for n in ds[out_vars[0]].shape)}), too many "
                         f"to print; the values are in {out / 'results.nc'} and the figures",
                         highlight=False)
    elif design == "sensitivity":
        ui.console.print(_sensitivity_table(ds, out_vars))
        used_var = next((u for u in ("samples_used", "trajectories_used") if u in ds), None)
        if used_var is not None:
            total = int(ds[used_var].attrs["total"])
            fewest = int(ds[used_var].values.min())
            if fewest < total:
                unit = "trajectory" if used_var.startswith("traj") else "base row"
                ui.console.print(f"indices over {fewest} of {total} "
                                 f"{used_var.split('_')[0]} at the fewest (a failed case "
                                 f"drops its {unit})", highlight=False)
        for note in json.loads(ds.attrs.get("sensitivity_warnings", "[]")):
            ui.console.print(f"warning: {note}", markup=False, highlight=False)
    else:
        used = {v: int(np.isfinite(ds[v].values).sum()) for v in out_vars}
        fewer = sorted({u for u in used.values() if u < status.size})
        title = f"{ds.attrs['study_name']}: {status.size} cases"
        if len(fewer) == 1 and all(u == fewer[0] for u in used.values()):
            title = f"{ds.attrs['study_name']}: statistics over {fewer[0]} of {status.size} cases"
        t = Table(title=title)
        cols = ["output", "mean", "std", "min", "p5", "p95", "max"]
        if len(fewer) and "over" not in title:
            cols.append("cases")
        for col in cols:
            t.add_column(col, justify="left" if col == "output" else "right")
        for v in out_vars:
            suffix, scale = _shown(ds[v])
            st = sample_statistics(ds[v].values)
            count = [f"{st['cases']} of {status.size}"] if "cases" in cols else []
            if not st["cases"]:
                t.add_row(escape(v + suffix), *["-"] * 6, *count)
                continue
            t.add_row(escape(v + suffix), *[f"{st[k] * scale:.6g}" for k in cols[1:7]],
                      *count)
        ui.console.print(t)
        if 0 < min(used.values()) < 20:  # (a 5 % tail of fewer than 20 is an end value)
            ui.console.print(f"p5 and p95 over {min(used.values())} cases at the fewest are "
                             f"interpolated between the extreme values: 20 or more give "
                             f"them a tail to stand for", highlight=False)
        if fewer:
            ui.console.print(f"statistics over the cases with a finite value only: "
                             f"{min(used.values())} of {status.size} at the fewest",
                             highlight=False)
        lost = int((status == "contact_lost").sum())
        if lost:  # (kept: a separating mesh is a result; but not one to average unawares)
            rule = " and the stopping rule" if "stopping_target_met" in ds.attrs else ""
            ui.console.print(
                f"{lost} of these {status.size} cases lost contact (status contact_lost): "
                f"their values are in the statistics{rule}, computed on a mesh that "
                f"separated (select status == 'ok' in results.nc to leave them out)",
                markup=False, highlight=False)
    # what the columns are (the run's table has this legend; the study's had only names)
    for line in output_definitions([ds[v].attrs["output"] for v in out_vars]):
        ui.console.print(line, markup=False, highlight=False, soft_wrap=True)
    ui.console.print("cases: " + ", ".join(f"{n} {s}" for s, n in counts.items()))
    line = stopping_line(ds)
    if line:
        ui.console.print(line, markup=False, highlight=False)
    # each reason with the cases it is of (three near-identical lines said nothing of
    # which case each was)
    of_reason: dict[str, list[int]] = {}
    for k, (r, s) in enumerate(zip(ds["reason"].values.ravel().tolist(), status)):
        if s != "ok":
            of_reason.setdefault(r, []).append(k)
    for r, cases in list(of_reason.items())[:5]:
        ui.console.print(f"  not ok, {_cases_with_values(ds, cases)}: {r}", markup=False,
                         highlight=False, soft_wrap=True)
    if len(of_reason) > 5:
        ui.console.print(f"  ... and {len(of_reason) - 5} more reasons (variable 'reason' "
                         f"of results.nc)", highlight=False)
    if n_warned:
        ui.console.print(f"[yellow]{n_warned} of {status.size} cases warned[/] (variable "
                         f"'warnings' of results.nc has each case's):", highlight=False)
        for g in groups[:5]:
            ui.console.print(f"  {_cases_with_values(ds, g['cases'])}: {g['text']}",
                             markup=False, highlight=False, soft_wrap=True)
        if len(groups) > 5:
            ui.console.print(f"  ... and {len(groups) - 5} more kinds of warning",
                             highlight=False)
    ui.console.print(f"results: {out / 'results.nc'} (and .csv, .mat); store: "
                     f"{out / 'study.sqlite'}"
                     + (f"; {_count(sum(f.endswith('.png') for f in figs), 'figure')} in "
                        f"{out / 'figures'} (PNG and SVG)" if figs else ""))
    _fail_if_no_results(failed, counts)


def _fail_if_no_results(failed: bool, counts: dict) -> None:
    """Exit 1, as a failed run does, where no case gave outputs (the reasons are
    printed above; what was computed stays in the store and the results files)."""
    if failed:
        ui = _ui()
        ui.err_console.print(
            "[red]error:[/] no case gave results ("
            + ", ".join(f"{n} {s}" for s, n in counts.items())
            + "): see the reasons above; fix the cause and run the study again",
            highlight=False)
        raise typer.Exit(1)


def _cases_with_values(ds, cases: list[int]) -> str:
    """'case 2' of a one-parameter grid with its value: 'case 2 (d = 35 mm)' (a reviewer
    counted a sweep's cases from 1 and read the warning as another diameter's)."""
    from .dataset import case_ranges, display_values

    text = case_ranges(cases)
    dims = ds["status"].dims
    if ds.attrs.get("design") != "grid" or len(dims) != 1 or len(cases) > 4:
        return text
    values, unit = display_values(ds, dims[0])
    shown = ", ".join(f"{values[i]:.6g}" for i in cases)
    return f"{text} ({dims[0]} = {shown}{'' if unit == '-' else ' ' + unit})"


def sample_statistics(values) -> dict:
    """A Monte Carlo output's statistics over its cases with a finite value (SI):
    ``cases``, ``mean``, ``std`` (sample, ddof 1), ``min``, ``p5``, ``p95``, ``max``
    (NaN where there is none)."""
    import numpy as np

    x = np.asarray(values, dtype=float).ravel()
    x = x[np.isfinite(x)]
    if not x.size:
        return {"cases": 0, **{k: math.nan for k in ("mean", "std", "min", "p5", "p95",
                                                    "max")}}
    return {"cases": int(x.size), "mean": float(x.mean()),
            "std": float(x.std(ddof=1)) if x.size > 1 else 0.0, "min": float(x.min()),
            "p5": float(np.quantile(x, 0.05)), "p95": float(np.quantile(x, 0.95)),
            "max": float(x.max())}


def _sensitivity_table(ds, out_vars):
    """The factors of each output, most important first, with their indices and 95 %
    bootstrap half-widths: Sobol's total and first-order indices, or Morris' mu* (+/- its
    interval), mu (its sign: the direction of the effect) and sigma (interaction or
    nonlinearity); a reviewer's summary gave the ranking's one number per factor only."""
    import numpy as np
    from rich.markup import escape

    from torquesplit._table import Table

    from .dataset import ranking

    morris = ds.attrs["ranking"] == "mu_star"  # (in the output's unit; Sobol's are 1)
    t = Table(title=f"{ds.attrs['study_name']}: factors ranked by {ds.attrs['ranking']} "
                    f"(most important first; +/-: 95 % bootstrap half-width)")
    cols = (["output", "factor", "mu*", "mu", "sigma"] if morris else
            ["output", "factor", "ST (total)", "S1 (first order)"])
    for col in cols:
        t.add_column(col, justify="left" if col in ("output", "factor") else "right")
    factors = list(ds["factor"].values)
    for v in out_vars:
        name = ds[v].attrs["output"]
        rank = ranking(ds, name)
        # (escaped: Rich reads " [kN]" as markup and drops it)
        suffix, scale = _shown(ds[v]) if morris else ("", 1.0)
        if not any(np.isfinite(x) for _, x in rank):
            t.add_row(escape(v + suffix), "none: no index could be computed (each "
                      "trajectory or base row lost a case: see the cases' status)",
                      *[""] * (len(cols) - 2))
            continue
        row = ds.sel(output=v)
        for k, (factor, _) in enumerate(rank):
            f = factors.index(factor)
            val = lambda key: float(row[key].values[f])  # noqa: E731
            if morris:
                cells = [f"{val('mu_star') * scale:.3g} +/- {val('mu_star_conf') * scale:.2g}",
                         f"{val('mu') * scale:.3g}", f"{val('sigma') * scale:.3g}"]
            else:
                cells = [f"{val('ST'):.3g} +/- {val('ST_conf'):.2g}",
                         f"{val('S1'):.3g} +/- {val('S1_conf'):.2g}"]
            t.add_row(escape(v + suffix) if k == 0 else "", escape(str(factor)), *cells)
    return t


def _shown(var) -> tuple[str, float]:
    """The unit an output is printed in, as its figure draws it (forces in kN, as the run's
    tables print them: a table in N beside a figure in kN), and the factor from SI:
    (" [kN]", 1e-3); no suffix for a ratio."""
    from .figures import _out_unit

    unit, scale = _out_unit(var.attrs["output"])
    return (f" [{unit}]" if unit not in ("", "1", "-") else ""), scale


def _count(n: int, what: str) -> str:
    """"1 output", "3 outputs"."""
    return f"{n} {what}" + ("" if n == 1 else "s")


MAX_TABLE_CASES = 60
"""A grid with more cases is not printed (the results file and figures have it)."""
MAX_TABLE_OUTPUTS = 8
"""Output columns per printed table of a grid (more outputs: more tables)."""


def _grid_tables(ds, out_vars: list[str]) -> list[tuple[str, list[tuple[str, str]]]]:
    """The tables that print a grid: one per output family (the family in the title, the
    columns its members, "system", "a1", ..., not names a narrow terminal cuts to the same
    "load_sharing.me..."), each split after :data:`MAX_TABLE_OUTPUTS` columns; one table
    of full names when each output is of another family.  Returns (title, [(column
    header, variable)])."""
    from . import outputs as out_mod

    name = ds.attrs["study_name"]
    fams: dict[str, list[tuple[str, str]]] = {}
    for v in out_vars:
        fam, member = out_mod.family(ds[v].attrs["output"])
        fams.setdefault(fam, []).append((member, v))
    if len(out_vars) <= MAX_TABLE_OUTPUTS and len(fams) == len(out_vars):
        return [(name, [(v, v) for v in out_vars])]  # one output of each family
    tables = []
    for fam, members in fams.items():
        parts = -(-len(members) // MAX_TABLE_OUTPUTS)
        for k in range(parts):
            part = f" ({k + 1} of {parts})" if parts > 1 else ""
            tables.append((f"{name}: {fam}{part}",
                           members[k * MAX_TABLE_OUTPUTS: (k + 1) * MAX_TABLE_OUTPUTS]))
    return tables


def _grid_table(ds, title: str, columns: list[tuple[str, str]]):
    """One table of a grid's cases: the parameters, the ``columns`` and the status."""
    from rich.markup import escape
    from torquesplit._table import Table

    from .dataset import display_values

    t = Table(title=escape(title))
    dims = list(ds[columns[0][1]].dims)
    shown = {}
    for d in dims:
        values, unit = display_values(ds, d)
        shown[d] = dict(zip(ds[d].values.tolist(), values.tolist()))
        # escaped: Rich would read "[um]" as markup and drop it
        t.add_column(escape(f"{d} [{unit}]"), justify="right")
    shown_unit = {v: _shown(ds[v]) for _, v in columns}
    for header, v in columns:
        t.add_column(escape(header + shown_unit[v][0]), justify="right")
    t.add_column("status")
    flat = ds.stack(case=dims)
    for k in range(flat.sizes["case"]):
        row = [f"{shown[d][float(flat[d].values[k])]:.6g}" for d in dims]
        row += [f"{float(flat[v].values[k]) * shown_unit[v][1]:.6g}" for _, v in columns]
        row.append(str(flat["status"].values[k]))
        t.add_row(*row)
    return t


def stopping_line(ds) -> str:
    """The stopping rule's outcome in one line ("" without a rule)."""
    a = ds.attrs
    if "stopping_target_met" not in a:
        return ""
    from .figures import _out_unit

    rule = json.loads(a["stopping_rule"])
    unit, k = _out_unit(rule["output"])  # (as the table above prints the output)
    unit = "" if unit == "-" else f" {unit}"
    n, finite = int(a["stopping_cases"]), int(a["stopping_finite_cases"])
    over = (f" over {finite} of {n} cases ({n - finite} without a finite value left out)"
            if finite < n else f" over {n} cases")
    outcome = ("target met" if a["stopping_target_met"] else
               f"target NOT met: max_samples = {rule['max_samples']} reached; raise it or "
               f"widen half_width")
    if "stopping_lower" in a and a["stopping_statistic"] != "mean":  # (a percentile's
        # interval is not centred on its estimate; a mean's Student-t interval is)
        interval = (f"{rule['confidence']:.0%} interval {k * a['stopping_lower']:.6g} .. "
                    f"{k * a['stopping_upper']:.6g}{unit}, half-width "
                    f"{k * a['stopping_half_width']:.3g}{unit}")
    else:
        interval = (f"+/- {k * a['stopping_half_width']:.3g}{unit} ({rule['confidence']:.0%} "
                    f"interval)")
    return (f"stopping rule: {a['stopping_statistic']} of {rule['output']} = "
            f"{k * a['stopping_estimate']:.6g}{unit}, {interval}{over}; target half-width "
            f"{k * a['stopping_target']:.3g}{unit}: {outcome}")


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _safe(name: str) -> str:
    """A folder name for a study's name (a pattern's '*' as 'all')."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name.replace("*", "all")).strip("_") or "study"


# --------------------------------------------------------------------------- sweep
_RANGE = re.compile(r"^\s*(?P<start>[^:]+?)\s*:\s*(?P<stop>[^:]+?)\s*:\s*"
                    r"(?P<num>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*"
                    r"(?P<unit>[^\d\s.].*?)?\s*$")


def parse_vary(text: str) -> dict:
    """``PATH[,PATH]=START:STOP:NUM[unit]`` -> a grid parameter table."""
    if "=" not in text:
        raise OptionError(f"--vary {text!r} is not PATH=START:STOP:NUM[unit]; write e.g. "
                         f"--vary shafts.drive1.diameter=130:400:28mm")
    paths_text, spec = (s.strip() for s in text.split("=", 1))
    m = _RANGE.match(spec)
    if not m:
        raise OptionError(f"--vary {text!r}: {spec!r} is not START:STOP:NUM[unit]; write e.g. "
                         f"130:400:28mm or '2e8 N/m:6e8 N/m:9'")
    paths = [p.strip() for p in paths_text.split(",") if p.strip()]
    if not paths:  # ('=0:40:3um': an IndexError)
        raise OptionError(f"--vary {text!r} names no field before '='; write e.g. --vary "
                         f"gears.pinion.errors.eccentricity={spec}")
    table: dict = {}
    if len(paths) == 1:
        table["path"] = paths[0]
    else:
        table["paths"] = paths
    if any(c in paths[0] for c in "*?[") and len(paths) == 1:  # a pattern: named by it
        table["name"] = paths[0]
    elif len(paths) > 1:  # several fields: by their last segment
        table["name"] = paths[0].split(".")[-1]
    num = m["num"]
    if not re.fullmatch(r"\d+", num) or int(num) < 1:
        raise OptionError(f"--vary {text!r}: the count {num!r} after the second ':' is the "
                         f"number of points, a whole number >= 1 (not a step); write e.g. "
                         f"{m['start'].strip()}:{m['stop'].strip()}:5{m['unit'] or ''}")
    table.update(start=_number(m["start"]), stop=_number(m["stop"]), num=int(num))
    if m["unit"]:
        table["unit"] = m["unit"].strip()
    return table


def _refuse_bare_range(text: str, table: dict) -> None:
    """A ``--vary`` range of bare numbers for a field with units is refused: it would be
    read in SI (``0:40:5`` for an eccentricity: 0 to 40 m)."""
    from .errors import StudyError
    from .paths import schema_field, si_unit

    if "unit" in table or isinstance(table["start"], str) or isinstance(table["stop"], str):
        return
    for path in table.get("paths") or [table["path"]]:
        try:  # a pattern's '*' stands for a key of a table of gears, meshes...: its kind
            kind = schema_field(path, "--vary").kind
        except StudyError:  # reported with the study's own words when it is resolved
            continue
        if kind is None:
            continue
        from ..model.units import KINDS

        si = si_unit(kind)
        a, b, n = table["start"], table["stop"], table["num"]
        # (a length: mm or um, as the numbers are a diameter's or a clearance's)
        units = ("mm", "um") if kind == "length" else (KINDS[kind][1].split(" ", 1)[1],)
        examples = " or ".join(f"'{a:g}:{b:g}:{n}{u}'" for u in units)
        raise OptionError(f"--vary {text!r}: {path} is a {kind.replace('_', ' ')} and the "
                         f"range has no unit (it would be read as {a:g} to {b:g} {si}); "
                         f"write the unit after the count, e.g. {examples} "
                         f"(or '{a:g}:{b:g}:{n}{si}' if {si} is meant)")


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return text.strip()


def sweep(
    model: str = typer.Argument(..., help="Model file (.toml/.json) or example name."),
    vary: list[str] = typer.Option(
        ..., "--vary", help="PATH=START:STOP:NUM[unit], e.g. shafts.drive1.diameter="
                            "130:400:28mm; several paths set together: P1,P2=...",
        metavar="PATH=RANGE"),
    output: Optional[list[str]] = typer.Option(
        None, "--output", help="Output name or pattern (repeatable); default "
                               "load_sharing.DEF.* with DEF the model's load-sharing "
                               "definition: the coefficient of every group and of every mesh "
                               "(add --output load_sharing.DEF for the system's).",
        metavar="NAME"),
    log_spacing: bool = typer.Option(False, "--log", help="Logarithmic spacing."),
    static: bool = typer.Option(False, "--static", help="Quasi-static analysis instead of a run."),
    duration: Optional[str] = typer.Option(None, "--duration", help="Simulated time per case.",
        metavar="TIME"),
    cycles: Optional[int] = typer.Option(None, "--cycles", help="Cycles of the slowest mesh.",
        metavar="N"),
    settle: Optional[float] = typer.Option(
        None, "--settle", help="Stop each run once its outputs change by less than this "
                               "relative tolerance between run lengths (e.g. 0.002).",
        metavar="TOL"),
    assign: Optional[list[str]] = typer.Option(
        None, "--set", help="Fixed model change for every case: PATH=VALUE.",
        metavar="PATH=VALUE"),
    workers: Optional[int] = typer.Option(None, "--workers", help="Local worker processes.",
        metavar="N"),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Dask scheduler address.",
        metavar="ADDRESS"),
    out: Optional[Path] = typer.Option(None, "--out", help="Output folder (default "
                                                           "./study_sweep_PATH).",
        metavar="DIR"),
    resume: bool = typer.Option(False, "--resume", help="Continue the sweep stored in --out."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Start again in --out."),
    backend: str = typer.Option(
        "cpu", "--backend", help=BACKEND_HELP, metavar="NAME"),
    precision: Optional[str] = typer.Option(
        None, "--precision", help=PRECISION_HELP, metavar="NAME"),
    no_figures: bool = typer.Option(False, "--no-figures", help="Do not write figures."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress bar."),
    as_json: bool = json_option("Print the summary as JSON."),
):
    """One-parameter grid in one line: an output against a model parameter."""
    from ..errors import TorquesplitError

    ui = _ui()
    try:
        data, name = _sweep_study(ui, model, vary, output, log_spacing, static, duration,
                                  cycles, settle, assign, workers)
    except (TorquesplitError, ValueError) as exc:
        ui._fail(exc)
        return
    _run(data, workers=workers, scheduler=scheduler, out=out, resume=resume,
         overwrite=overwrite, figures=not no_figures, quiet=quiet, as_json=as_json,
         name_hint=name, backend=backend, precision=precision, flag="--vary")


def _sweep_study(ui, model, vary, output, log_spacing, static, duration, cycles, settle,
                 assign, workers) -> tuple[dict, str]:
    """The study data of a ``sweep`` command line and its name; every bad option is
    refused at once, with the study's own problems (an unknown output, a path the model
    lacks) where the options get that far (a reviewer's bad --output hid --workers 0)."""
    from ..model.overrides import parse_assignment
    from .core import Study
    from .errors import StudyError

    opts = ui._option_errors()
    opts(ui._one_run_length, duration, cycles)
    opts(ui._at_least, workers, 1, "--workers", "2")
    param = opts(_vary_table, vary, log_spacing)
    bare = False  # (a range without its unit: its cases' values are no values to judge)
    if param is not None:
        before = len(opts.messages)
        opts(_as_option, _refuse_bare_range, vary[0], param)
        bare = len(opts.messages) > before
        opts(_set_apart, param, assign)
    opts(_static_length, static, duration, cycles, settle)
    path = ui._resolve_model_path(model)
    model_ref = str(path.resolve()) if path.exists() else model
    if output:
        outputs = list(output)
    elif static:
        outputs = ["load_sharing.static_torque.*"]
    else:
        from ..model.io import load_model

        outputs = [f"load_sharing.{_default_definition(load_model, path)}.*"]
    analysis: dict = {"type": "static" if static else "run"}
    if not static:
        for key, value in (("duration", _seconds(duration)), ("cycles", cycles)):
            if value is not None:
                analysis[key] = value
        if settle is not None:
            analysis["settle"] = {"tolerance": settle}
    # named by its path, or by the parameter's name where it sets several paths (the
    # figures' titles read 'sweep_meshes.a1.backlash_and_1_more'; the axis names them)
    name = (f"sweep_{param.get('name') or param.get('path')}" if param else
            "sweep_parameter")
    data = {"study": {"name": name, "model": model_ref, "outputs": outputs},
            "analysis": analysis, "grid": {"parameters": [param]},
            "set": dict(parse_assignment(a) for a in (assign or []))}
    if opts.messages:
        # the study's own problems beside the options' (not those of a range read in SI
        # for want of its unit: 'case 0 at 0.5 m' after 'write the unit after the count')
        if param is not None:
            try:
                Study(data).plan()
            except StudyError as exc:
                opts.messages += [f"{_sweep_option(f, '--vary')}: {_sweep_words(m)}"
                                  for f, m in exc.problems
                                  if not (bare and f.startswith("grid.parameters"))]
            except (ValueError, ArithmeticError, OSError):  # said when the options are fixed
                pass
        opts.raise_any()
    return data, name


def _as_option(check, *args):
    """``check(*args)`` with its ValueError an :class:`OptionError` (a bad option)."""
    try:
        return check(*args)
    except OptionError:
        raise
    except ValueError as exc:
        raise OptionError(str(exc)) from None


def _vary_table(vary: list[str], log_spacing: bool) -> dict:
    """The grid parameter of ``--vary`` (given once)."""
    if len(vary) != 1:
        raise OptionError("--vary is given twice: a sweep varies one parameter (several "
                          "paths set together: --vary P1,P2=START:STOP:NUM); for a grid of "
                          "two or three parameters write a study file (docs/studies.md)")
    param = _as_option(parse_vary, vary[0])
    if log_spacing:
        param["spacing"] = "log"
    return param


def _set_apart(param: dict, assign) -> None:
    varied = set(param.get("paths") or [param["path"]])
    for a in assign or []:
        if a.partition("=")[0].strip() in varied:
            raise OptionError(f"--set {a!r} sets a path that --vary varies; leave one of "
                              f"them out")


def _static_length(static: bool, duration, cycles, settle) -> None:
    if static and (duration is not None or cycles is not None or settle is not None):
        flag = ("--duration" if duration is not None else "--cycles" if cycles is not None
                else "--settle")
        raise OptionError(f"{flag} sets the length of a dynamic run; a quasi-static sweep "
                          f"(--static) turns the gears through whole revolutions: leave "
                          f"{flag} out or drop --static")


def _default_definition(load_model, path) -> str:
    d = load_model(path).analysis.load_sharing
    return d if d != "static_torque" else "cycle_peak"
