"""The ``torquesplit`` command line: one entry point, one sub-command per job.

Bad input prints one line per problem, ``error: FILE: FIELD: what is wrong; what to
do``, and exits with status 2; ``--debug`` shows the traceback instead.  Everything that
can be checked before a computation is: the model (``check`` runs every check ``run``
would), the numeric options, and the output path -- its folder, suffix, an existing file
(kept unless ``--force``) and another run writing it (see
:mod:`torquesplit.results.files`), so that no run computes for minutes and then cannot
save.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import warnings
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from torquesplit._table import Table

from . import cli_support as ux
from .model.checks import MODIFICATIONS_UNUSED
from .cli_support import header as _h
from .errors import (ModelError, ModelWarning, OptionError, OutputError, TorquesplitError,
                     clip_message, interrupt_name)


class _Command(typer.core.TyperCommand):
    """A command listed in --help without type noise: no ``<bool>`` on flags, no
    ``<str>`` beside an argument that already has a name (MODEL)."""

    def get_help_option(self, ctx):
        option = super().get_help_option(ctx)
        if option is not None and getattr(option, "metavar", "") is None:
            option.metavar = ""
        return option

    def get_params(self, ctx):
        params = super().get_params(ctx)
        for p in params:
            if isinstance(p, typer.core.TyperArgument):
                p.metavar = p.metavar or p.name.upper()  # STUDY_FILE, not study_file <str>
                p.display_type_rich = lambda ctx: None  # the metavar says it
            elif isinstance(p, typer.core.TyperOption) and p.is_flag and not p.metavar:
                p.metavar = ""  # a flag takes no value: no <bool>
        return params


class _Group(typer.core.TyperGroup):
    """The app's group, its --help listed like the commands'."""

    def get_help_option(self, ctx):
        option = super().get_help_option(ctx)
        if option is not None and getattr(option, "metavar", "") is None:
            option.metavar = ""
        return option


app = typer.Typer(
    cls=_Group,
    rich_markup_mode="markdown",
    add_completion=False,
    no_args_is_help=True,
    help="Dynamic load-sharing analysis of power-split gear transmissions.  Start with "
         "'torquesplit examples', then 'torquesplit check ji_li_mill_drive' and "
         "'torquesplit run ji_li_mill_drive'; docs/tutorial.md builds a model from scratch.",
)
def _width(stream) -> int | None:
    """Terminal width: the terminal's, else $COLUMNS, else 160 (pipes, files)."""
    if stream.isatty():
        return None
    try:
        return max(40, int(os.environ.get("COLUMNS", "")))
    except ValueError:
        return 160


console = Console(width=_width(sys.stdout), emoji=False)
err_console = Console(stderr=True, width=_width(sys.stderr), emoji=False)

_state = {"debug": False}


def _version(value: bool) -> None:
    if value:
        from . import __version__

        print(f"torquesplit {__version__}")
        raise typer.Exit()


@app.callback()
def _main(ctx: typer.Context,
          debug: bool = typer.Option(False, "--debug", help="Show tracebacks on errors.",
                                     metavar=""),
          version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                       help="Print the version and exit.", metavar="")):
    _state["debug"] = debug
    ux.reset(console, err_console, debug)
    # a model warning raised anywhere in the command (a cached result's replayed one
    # too) is a "warning:" line, said once, never Python's own two-line form
    ctx.with_resource(ux.collect_warnings())


def _flag(option: str, help: str):
    """An on/off option shown without a type in --help."""
    return typer.Option(False, option, help=help, metavar="")


def _fail(exc: BaseException) -> None:
    """Print ``exc`` as one ``error:`` line per problem and exit with status 2."""
    if _state["debug"]:
        raise exc
    msg = str(exc).strip() or exc.__class__.__name__
    if isinstance(exc, OSError) and not isinstance(exc, TorquesplitError):
        where = f"{exc.filename}: " if exc.filename else ""
        msg = f"{where}{exc.strerror or msg}; check the path and its permissions"
    msg = clip_message(msg)
    lines = msg.splitlines() or [msg]
    for line in lines:
        err_console.print("[bold red]error:[/] ", end="")
        err_console.print(line, markup=False, highlight=False, soft_wrap=True)
    ux.emit_json_errors(lines)
    raise typer.Exit(2)


#: what the commands catch and print as one-line errors (anything else is a bug and
#: keeps its traceback)
_EXPECTED = (TorquesplitError, ValueError, OSError)


def _option_errors() -> ux.OptionErrors:
    """A collector of this command's bad options (:class:`cli_support.OptionErrors`)."""
    return ux.OptionErrors(load=_load)


def _at_least(value, minimum, option: str, example: str) -> None:
    """Refuse a count below ``minimum`` (``--count -1``) before any computation."""
    if value is not None and value < minimum:
        raise OptionError(f"{option} must be a whole number of at least {minimum}, got "
                          f"{value}; give e.g. {option} {example}")


def _out_option(check, *args, **kwargs):
    """``check(*args, **kwargs)`` of an ``--out`` path, its problem named by the option
    (as ``run`` says it: 'error: --out: cannot save results as ...')."""
    try:
        return check(*args, **kwargs)
    except OutputError as exc:
        raise OptionError(f"--out: {exc}") from None


def _check_out(out: Optional[Path], force: bool):
    """The output plan of ``--out`` (None without it), its problems named by the option."""
    if out is None:
        return None
    from .results import files

    try:
        return files.check_output(out, overwrite=force)
    except OutputError as exc:
        raise OptionError(f"--out: {exc}") from None


def _check_method(method: Optional[str]) -> None:
    if method is not None and method not in ("rk4", "dopri"):
        raise OptionError(f"--method {method!r} is unknown; use rk4 or dopri")


def _one_run_length(duration, cycles) -> None:
    """Refuse ``--duration`` with ``--cycles``: both set the run length."""
    if duration is not None and cycles is not None:
        raise OptionError(f"--cycles {cycles} and --duration {duration} both set the run "
                          "length; give only one of them")


MAX_MESH_POINTS = 65536
"""Most samples per mesh cycle 'mesh' computes (the finest table a shipped example uses)."""


def _at_most(value, most, option: str) -> None:
    if value is not None and value > most:
        raise OptionError(f"{option} {value} is more than {most}; give at most {most}")


def _positive(value, option: str, example: str) -> None:
    if value is not None and not (value > 0 and math.isfinite(value)):
        raise OptionError(f"{option} must be a positive finite number, got {value}; give "
                          f"e.g. {option} {example}")


def _check_plots_folder(plots: Optional[Path], option: str = "--plots", names=(),
                        force: bool = True) -> None:
    """A figures folder, checked before computing: a folder (or creatable) that files can
    be written in, holding none of the figure files ``names`` unless ``force``."""
    if plots is None:
        return
    if plots.exists() and not plots.is_dir():
        raise OptionError(f"{option} {plots} is a file, not a folder; give a folder for the "
                          f"figures")
    parent = plots if plots.exists() else plots.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise OptionError(f"{option} {plots} cannot be created: {parent} is not a folder; "
                          f"give a folder for the figures")
    from .results import files

    try:
        files.check_writable_folder(parent, plots)
    except OSError as exc:
        raise OptionError(f"{option}: {exc}") from None
    existing = [] if force or not plots.is_dir() else [n for n in names
                                                       if (plots / n).exists()]
    if existing:
        more = f" and {len(existing) - 1} more figure files" if len(existing) > 1 else ""
        raise OptionError(f"{option} {plots} already holds {existing[0]}{more}; use --force "
                          f"to replace the figures, or choose another folder")


def _figure_error(exc: BaseException, option: str, target: Path, kept: str):
    """A figure that could not be written after the computation: one line saying what
    was kept (``kept``) and what to do."""
    from .errors import OutputError

    reason = getattr(exc, "strerror", None) or str(exc).strip() or type(exc).__name__
    return OutputError(f"{option} {target}: cannot write the figures ({clip_message(reason)}); "
                       f"{kept}; choose a folder you can write to")


def _kept_results(saved) -> str:
    """What a command that failed to write its figures kept."""
    return ux.kept_files(saved) or "the results are printed but not saved (no --out)"


def _check_figure_file(path: Optional[Path], option: str, force: bool = False) -> None:
    """A single figure file (``mesh --plot k.png``), checked before computing: a format
    matplotlib writes, in an existing folder that can be written, no existing file unless
    ``force``."""
    if path is None:
        return
    from .results import files

    formats = {f".{s}": s for s in ("png", "svg", "pdf", "jpg", "jpeg", "eps", "ps", "tif",
                                    "tiff", "webp")}
    try:
        files.check_output(path, formats=formats, overwrite=force, what="the figure")
    except OSError as exc:
        raise OptionError(f"{option}: {exc}") from None


def _resolve_model_path(model: str) -> Path:
    """A file path, or the name of a shipped example (an old example name gives the new
    one, with a note); a missing file named like an example is refused naming it."""
    p = Path(model)
    if p.exists():
        return p
    from .examples import current_name, example_names, example_path

    name, note = current_name(model)
    if not p.suffix and name in example_names():
        if note:
            ux.warn(note, label="note")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            return example_path(name)
    if p.parent == Path(".") and p.suffix.lower() in ("", ".toml", ".json"):
        import difflib

        names = {n.lower(): n for n in example_names()}
        close = difflib.get_close_matches(p.stem.lower(), names, n=3, cutoff=0.6)
        if close or not p.suffix:
            from .errors import ModelError

            hint = f"did you mean {' or '.join(names[c] for c in close)}? " if close else ""
            raise ModelError([("", f"no such file or example; {hint}'torquesplit examples' "
                                   f"lists the examples (current folder: {Path.cwd()})")],
                             model)
    return p


def _load(model: str, assignments: Optional[list[str]] = None, *, deep: bool = False,
          warn: bool = True, irrelevant: tuple[str, ...] = ()):
    """Read, validate and check a model; ``--set`` overrides are applied to the file's
    data first, and their errors are reported against the ``--set`` argument.

    The model's warnings are printed at once and kept for ``--json``
    (:mod:`torquesplit.cli_support`), but for those that contain a text of
    ``irrelevant`` (advice that does not apply to the command)."""
    from .errors import ModelError
    from .model.checks import check_model
    from .model.io import _located, load_model, model_from_dict

    path = _resolve_model_path(model)
    where: dict[str, str] = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        if assignments:
            from .errors import ModelError
            from .model.overrides import apply_assignments, attribute_errors, read_raw

            raw = read_raw(path)
            try:
                data, where = apply_assignments(raw, assignments)
            except ModelError as exc:  # and the file's own problems, all at once
                raise _with_file_problems(exc, raw, path, deep) from None
            try:
                m = model_from_dict(data, source=str(path))
                check_model(m, source=str(path), deep=deep)
            except ModelError as exc:  # (the file's own fields at their lines)
                own = _file_issue_locations(raw, path, deep)
                raise _located(attribute_errors(exc, where, str(path), own),
                               path) from None
        else:
            m = load_model(path, check=False)
            try:  # (the checks' problems at their lines, as the schema's)
                check_model(m, source=str(path), deep=deep)
            except ModelError as exc:
                raise _located(exc, path) from None
    from .model.overrides import attribute_warning

    for w in caught:
        if (warn and issubclass(w.category, ModelWarning)
                and not any(text in str(w.message) for text in irrelevant)):
            ux.warn(attribute_warning(str(w.message), where, str(path)))
    return m, path


def _file_problems(raw: dict, path, deep: bool):
    """The ModelError of the file as it stands, without its ``--set`` overrides; None if
    it passes; False if it cannot even be checked (the --set's error is then the one to
    say)."""
    import copy

    from .errors import ModelError
    from .model.checks import check_model
    from .model.io import model_from_dict

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            check_model(model_from_dict(copy.deepcopy(raw), source=str(path)),
                        source=str(path), deep=deep)
    except ModelError as exc:
        return exc
    except Exception:  # noqa: BLE001 - (the overrides' own error is the one to report)
        return False
    return None


def _file_issue_locations(raw: dict, path, deep: bool) -> set[str] | None:
    """Locations of the problems of the file without its ``--set`` overrides (empty: it
    passes; None: it cannot even be read as a model, so nothing is said of the cause)."""
    found = _file_problems(raw, path, deep)
    if found is False:
        return None
    return set() if found is None else {loc for loc, _ in found.issues}


def _with_file_problems(exc, raw: dict, path, deep: bool):
    """A ``--set`` that cannot be applied, with the problems of the file as it stands
    (they were said only once the --set was mended: one run per problem)."""
    from .errors import ModelError
    from .model.io import _located

    found = _file_problems(raw, path, deep)
    if not found:
        return exc
    lines = str(exc).splitlines() + str(_located(found, path)).splitlines()
    return ModelError([("", line) for line in lines])


def _model_warnings() -> list[str]:
    """The warnings printed so far by this command (the model's, at load)."""
    return list(ux.session().warnings)


# --------------------------------------------------------------------------- check
_MODEL_HELP = ("Model file (.toml/.json) or example name (see 'torquesplit examples').")
_SET_HELP = ("Override a model field for this command: PATH=VALUE, e.g. "
             "shafts.s1.diameter='250 mm' (repeat for several); it replaces a field the "
             "file gives another way (torque a drive's power).")


@app.command()
def check(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print the summary as JSON."),
    quiet: bool = _flag("--quiet", "No progress display."),
):
    """Validate a model and print its kinematic and static summary.

    Runs every check 'run' performs before it integrates (the assembly and the static
    equilibrium included), so a model that passes is refused by 'run' only for a
    numerical reason.  Values that are possible but look wrong (a unit mistake, an error
    beyond the coarsest ISO 1328 grade) are warnings naming the field.
    """
    with ux.interruptible():
        try:
            from .model.summary import summary

            with ux.progress("checking the model (assembly, static equilibrium)", quiet or
                             as_json, total=None):
                m, path = _load(model, assign, deep=True)
                s = summary(m)
        except _EXPECTED as exc:
            _fail(exc)
            return
    if as_json:
        ux.emit_json(s, _json_default)
        return
    from .model.summary import render_summary

    render_summary(s, console)


# --------------------------------------------------------------------------- run
def _definition_help() -> str:
    from .metrics.load_sharing import DYNAMIC_DEFINITIONS, DEFINITION_TEXT, DEFINITION_USE

    parts = [f"'{d}': {DEFINITION_TEXT[d]}; {DEFINITION_USE[d]}." for d in DYNAMIC_DEFINITIONS]
    return ("Load-sharing definition to report (default: the model's [analysis] "
            "load_sharing, 'mean_force' for a new model).  " + "  ".join(parts)
            + "  'static' / 'static_torque': quasi-static, run 'torquesplit static'.")


@app.command()
def run(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    duration: Optional[str] = typer.Option(
        None, "--duration", help="Simulated time, e.g. '0.5 s' (a bare number is seconds).  "
        "Default: the model's [analysis] duration or cycles, else 200 cycles of the slowest "
        "mesh.", metavar="TIME"),
    cycles: Optional[int] = typer.Option(
        None, "--cycles", help="Cycles of the slowest mesh to simulate (default as for "
        "--duration: the model's [analysis], else 200).", metavar="N"),
    method: Optional[str] = typer.Option(None, "--method", help="rk4 (fixed step) or dopri.",
                                         metavar="rk4|dopri"),
    steps_per_period: Optional[int] = typer.Option(
        None, "--steps-per-period", help="RK4 steps per shortest mesh period, or per "
        "period of a faster error sinusoid (an LTCA transmission-error harmonic; the run "
        "says so) (default: the model's [analysis] steps_per_period, else 100).",
        metavar="N"),
    max_steps: Optional[int] = typer.Option(
        None, "--max-steps", help="Refuse an RK4 run needing more steps (default 2e8).",
        metavar="N"),
    samples_per_period: Optional[int] = typer.Option(
        None, "--samples-per-period", help="History samples per shortest mesh period, for "
        "--out files, --plots figures and the bearing-force table's means (the mesh "
        "table's forces and coefficients and the bearings' peaks are streamed at every "
        "step and do not depend on it); "
        "default: every step of a run of at most 50,000, else every k-th step: 50,000 "
        "samples, or more where 20 per period need more, at most 200,000 (the bearing "
        "table's title says how many per period); a run warns when the history misses "
        "the peaks.", metavar="N"),
    definition: Optional[str] = typer.Option(None, "--definition", help=_definition_help(),
                                             metavar="NAME"),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Write results: .nc (NetCDF-4; .h5 and .netcdf are read as .nc), "
        ".mat (MATLAB) or .csv "
        "(spreadsheet files: NAME.csv a row per mesh, NAME_groups.csv a row per "
        "load-sharing group and the system, NAME_bearings.csv, NAME_elements.csv (contact "
        "loss of every element), NAME_history.csv, NAME_cycles.csv, and NAME_about.json: "
        "model, warnings, metrics, provenance).",
        metavar="FILE"),
    force: bool = _flag("--force", "Replace existing results files and figures."),
    plots: Optional[Path] = typer.Option(None, "--plots", help="Write report figures (PNG, "
                                         "SVG) into this folder.", metavar="DIR"),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print metrics, statistics and warnings as JSON."),
    quiet: bool = _flag("--quiet", "No progress bar."),
    check: bool = _flag("--check-step", "Run again at half the step (and with 4x the "
                        "table points where the excitation tables have jumps) and report how "
                        "many significant digits of every number hold.  The second run takes "
                        "twice the steps: about three times the integration time of a plain "
                        "run in all."),
):
    """Static equilibrium, then the dynamic response: load sharing and dynamic factors.

    The options and the output path are checked before anything is computed; the
    output is claimed for this run at once (a second run on the same path is refused)
    and written atomically at the end.  Ctrl-C stops the run and says what was kept.
    """
    from .results import files

    state = {"saved": [], "figures": None}
    save_failed = None

    with contextlib.ExitStack() as stack, ux.interruptible(
            lambda: ux.kept_files(state["saved"], state["figures"] is not None)):
        try:
            opts = _option_errors()
            opts(_check_method, method)
            opts(_one_run_length, duration, cycles)
            dur = opts(ux.quantity, duration, "time", "--duration")
            opts(_positive, dur, "--duration", "'0.5 s'")
            opts(_at_least, cycles, 1, "--cycles", "200")
            opts(_at_least, steps_per_period, 10, "--steps-per-period", "100")
            opts(_at_least, max_steps, 1, "--max-steps", "200000000")
            opts(_at_least, samples_per_period, 1, "--samples-per-period", "100")
            opts(_check_definition, definition)
            opts(_check_plots_folder, plots)
            plan = opts(_check_out, out, force)
            opts.raise_any(model, assign)
            # results of an earlier run that --force would replace: a run that does not
            # finish leaves them and puts its partial results beside them
            earlier = plan is not None and any(f.exists() for f in plan.files)
            if plan is not None:
                stack.enter_context(files.claim_output(plan))
            m, path = _load(model, assign)
            chosen = _run_definition(m, definition)
            if plots is not None and not force:
                from .plot.figures import RUN_FIGURES, figure_files

                _check_plots_folder(plots, names=figure_files(RUN_FIGURES, definition=chosen),
                                    force=False)
            from .simulation import simulate

            from .solve.integrate import stop_on_interrupt

            # Ctrl-C ends the run as a stopped one: what it computed is saved and reported
            with ux.collect_warnings(), stop_on_interrupt(), \
                    ux.progress("integrating", quiet or as_json) as cb:
                res = simulate(m, duration=dur, cycles=cycles, method=method,
                               steps_per_period=steps_per_period, max_steps=max_steps,
                               samples_per_period=samples_per_period, progress=cb)
            # the run is done: a Ctrl-C now waits until its results are on disk
            with ux.finish_before_interrupt():
                res.model_warnings = [w for w in _model_warnings()
                                      if w not in res.run_warnings]
                met = None
                if res.success:
                    met = res.metrics(chosen)
                    from .results.plausibility import result_warnings

                    for loc, msg in result_warnings(res, met):
                        ux.warn(f"{loc}: {msg}")
                    for text in _near_critical(res):  # (in the files' warnings too)
                        res.run_warnings.append(text)
                        ux.warn(text)
                if out is not None and earlier and not res.success:
                    state["saved"], save_failed = _save_partial_beside(res, plan, chosen)
                elif out is not None:
                    try:
                        res.save(out, overwrite=force, definition=chosen)
                        state["saved"] = list(plan.files)
                    except _EXPECTED as exc:  # (the folder went during the run, a
                        # companion file appeared): the run is kept elsewhere, said last
                        state["saved"], save_failed = _rescued(
                            lambda p: res.save(p, definition=chosen), out, exc)
            step_check, check_stopped = None, False
            if check and met is not None:
                from .convergence import check_step
                from .errors import from_interrupt

                try:
                    with ux.collect_warnings(), ux.progress("checking the step (half of it)",
                                                            quiet or as_json) as cb:
                        step_check = check_step(res, definitions=[chosen], progress=cb)
                except (KeyboardInterrupt, SystemError) as exc:
                    # the run's own tables are printed, then the stop (it said only
                    # 'results kept in', not that no check was made: a reliability
                    # reviewer)
                    if not from_interrupt(exc):
                        raise
                    check_stopped = True
        except _EXPECTED as exc:
            _fail(exc)
            return
        saved = state["saved"]
        if met is None:
            _render_stopped(res, saved, as_json)
            if save_failed is not None:
                _fail(save_failed)
            from .solve.integrate import INTERRUPTED

            raise typer.Exit(130 if res.solution.status == INTERRUPTED else 1)
        figures, failed = [], save_failed
        if plots is not None:
            state["figures"] = []
            try:
                figures = _write_run_figures(res, plots, met.definition, quiet or as_json)
            except OSError as exc:
                failed = failed or _figure_error(exc, "--plots", plots, _kept_results(saved))
            state["figures"] = None
    if failed is None:
        _print_run(m, res, met, saved, figures, step_check, plots, as_json)
    else:
        _print_run(m, res, met, saved, [], step_check, None, as_json)
        _fail(failed)
    if check_stopped:
        ux.warn(f"the step check (--check-step) was interrupted ({interrupt_name()}): the "
                f"tables are the run's, complete, their digits not checked")
        ux.exit_interrupted(ux.kept_files(saved))


def _save_partial_beside(res, plan, definition) -> tuple[list[Path], Exception | None]:
    """A run that did not finish (interrupted, diverged) where ``--force`` would replace
    an earlier run's results: those are kept, and this run's partial results go to
    ``NAME.partial.SUFFIX`` beside them, said in a warning (--force replaced a complete
    file with a partial one, which 'report' then refused: a reliability reviewer).
    Returns the files written and the error of a save that failed."""
    from .results import files

    partial = plan.path.with_name(f"{plan.path.stem}.partial{plan.path.suffix}")
    try:
        res.save(partial, overwrite=True, definition=definition)
    except _EXPECTED as exc:
        return [], exc
    kept = ", ".join(str(f) for f in plan.files if f.exists())
    ux.warn(f"the run did not finish: {kept} (an earlier run's results, which --force "
            f"would have replaced) kept; this run's partial results are in {partial}")
    return list(files.check_output(partial, overwrite=True).files), None


def _rescued(save, out, exc) -> tuple[list[Path], Exception]:
    """A finished run whose results file cannot be written (checked at the start, the
    folder went or a companion file appeared during the run): saved as ``NAME_rescued.nc``
    in the current folder (else the temporary one) instead, and the error to report after
    the tables, naming where the results are.  A run of hours is never lost to a path."""
    import tempfile

    from .errors import OutputError

    stem = Path(str(out)).stem or "results"
    try:
        here = [Path.cwd()]
    except OSError:  # (the folder that went may be the current one)
        here = []
    for folder in [*here, Path(tempfile.gettempdir())]:
        path = next(p for p in (folder / f"{stem}_rescued{'' if k == 1 else f'_{k}'}.nc"
                                for k in range(1, 10**6)) if not p.exists())
        try:
            save(path)
        except _EXPECTED:
            continue
        return [path], OutputError(f"{clip_message(str(exc))}; the results were saved to "
                                   f"{path} instead")
    return [], exc


def _near_critical(res) -> list[str]:
    """``run``'s word on a critical speed next to the model's, from the run's own
    structure and static equilibrium."""
    from .steady.maps import near_critical_notes

    return near_critical_notes(res.model, res.structure, res.static.q, res.kinematics)


def _print_run(m, res, met, saved, figures, step_check, plots, as_json) -> None:
    """A finished run's tables (or JSON).  A model with a planetary stage adds the planet
    table (K_gamma per stage, the factor per planet) and the JSON key
    ``planet_load_sharing``; a model without planets has neither."""
    planets = ux.planet_sharing(met.load_sharing, res.kinematics)
    if as_json:
        metrics = met.to_dict()
        rows = list(metrics["meshes"].values())
        ux.emit_json({"model": m.model.name, "success": res.success,
                      "metrics": metrics,
                      **({"planet_load_sharing": ux.planet_sharing_dict(planets)}
                         if planets else {}),
                      "statistics": res.statistics(),
                      "bearing_forces_N": res.bearing_forces(met.settling.start_time,
                                                             metrics=met),
                      "results_file": str(saved[0]) if saved else None,
                      "results_files": [str(f) for f in saved],
                      "figures": [str(f) for f in figures],
                      **({"step_check": step_check.to_dict()} if step_check else {}),
                      # SI, of exactly the keys the rows have (it listed an RMS
                      # transmission error that a run does not give, a reviewer)
                      "units": {**{k: u for k, u in ux.MESH_UNITS.items()
                                   if k == "settle_time_s" or any(k in r for r in rows)},
                                **({"planet_load_sharing": "1"} if planets else {})}},
                     _json_default)
    else:
        _render_run(res, met, saved, planets)
        if step_check is not None:
            ux.render_step_check(step_check)
        if figures:
            console.print(f"{len(figures)} figure files written to {plots}")


def _run_definition(model, definition: Optional[str]) -> str:
    """The definition a run reports: the option, else the model's, else (for a model
    whose definition is the quasi-static 'static_torque') the standard one, with a note."""
    from .metrics.load_sharing import STANDARD_DEFINITION

    if definition:
        return definition
    chosen = model.analysis.load_sharing
    if chosen in ("static", "static_torque"):
        ux.warn(f"the model's load_sharing is '{chosen}', the quasi-static definition of "
                f"'torquesplit static'; this dynamic run reports '{STANDARD_DEFINITION}' "
                f"(choose another with --definition)", label="note")
        return STANDARD_DEFINITION
    return chosen


def _write_run_figures(res, plots: Path, definition: str, quiet: bool) -> list:
    """Write the run's figures with a progress display naming each one."""
    from .plot.figures import figure_jobs, write_jobs

    jobs = figure_jobs(res, definition=definition)
    with ux.progress("writing figures", quiet) as cb:
        return write_jobs(jobs, plots, ("png", "svg"),
                          progress=lambda i, n, name: cb(i / n, name))


def _check_definition(definition: Optional[str]) -> None:
    if definition is None:
        return
    from .metrics.load_sharing import DYNAMIC_DEFINITIONS

    if definition in ("static", "static_torque"):
        raise OptionError("--definition static (static_torque) is the load sharing of "
                          "quasi-static equilibria (Mo et al. 2017), not of a dynamic run; "
                          "run `torquesplit static MODEL` for it")
    if definition not in DYNAMIC_DEFINITIONS:
        raise OptionError(f"--definition {definition!r} is unknown; use one of "
                          f"{', '.join(DYNAMIC_DEFINITIONS)} (or `torquesplit static` for "
                          f"static_torque)")


def _likely_cause(res) -> Optional[str]:
    """Why a run that stopped early most likely stopped, from its static equilibrium.

    A static deflection of a tenth of the integrator's limit (``blowup``, 1000 m or rad)
    means a stiffness far too small for the load (often a unit): the vibration about it
    crosses the limit, and the integrator's advice (a smaller step) does not help.
    """
    import numpy as np

    from .model.checks import integrator_blowup

    q = np.asarray(res.static.q, dtype=float)
    names = list(res.structure.dof_names)
    if q.size == 0:
        return None
    if not np.all(np.isfinite(q)):
        return ("the static equilibrium is not finite: a stiffness or an inertia of extreme "
                "size (see the warnings of 'torquesplit check'); check the values and units")
    j = int(np.argmax(np.abs(q)))
    if abs(q[j]) >= 0.1 * integrator_blowup():
        unit = "rad" if names[j].endswith(".theta") else "m"
        return (f"the static deflection of '{names[j]}' is {abs(q[j]):.3g} {unit}: a "
                f"stiffness is far too small for the load; check the stiffness values and "
                f"their units (shafts, supports, meshes), not the step")
    return None


def _render_stopped(res, saved, as_json: bool) -> None:
    """A run that did not finish: its status and the likely cause, never coefficients of
    a partial run (they would read as results)."""
    cause = _likely_cause(res)
    st = res.statistics()
    if as_json:
        ux.emit_json({"model": res.model.model.name, "success": False,
                      "status": st["status"], "message": res.message,
                      "likely_cause": cause, "metrics": None, "statistics": st,
                      "results_file": str(saved[0]) if saved else None,
                      "results_files": [str(f) for f in saved], "figures": []},
                     _json_default)
        return
    console.print(f"[bold]{res.model.model.name}[/]: [bold red]stopped[/]: {res.message}",
                  highlight=False)
    requested = res.solution.t_span[1] - res.solution.t_span[0]
    console.print(f"{st['steps']} steps ({st['method']}); simulated "
                  f"{st['simulated_time_s']:.4g} s of {requested:.4g} s", highlight=False)
    if cause:
        console.print(f"likely cause: {cause}", highlight=False)
    console.print("no load-sharing or dynamic-factor table: the run did not finish, and "
                  "coefficients of a partial run are not results"
                  + (f"; the partial results (with their status) are in "
                     f"{', '.join(str(f) for f in saved)}" if saved
                     else "; save the partial results with --out to inspect them"),
                  highlight=False)


_json_default = ux.json_default


def _generation_lines():
    """An optimisation's progress as lines where stderr is not a terminal (a batch job,
    nohup: the bar draws nothing there), at most one per LOG_EVERY seconds and the last;
    None on a terminal (the bar)."""
    import time

    from .cli_support import LOG_EVERY, clock_text

    con = ux._session.err_console
    if con is None or getattr(con, "is_terminal", False):
        return None
    t0, last = time.monotonic(), [None]

    def cb(generation, total):
        now = time.monotonic()
        if last[0] is not None and now - last[0] < LOG_EVERY and generation < total:
            return
        last[0] = now
        con.print(f"generation {generation}/{total}, {clock_text(now - t0)} elapsed",
                  highlight=False, markup=False)

    return cb


def _with_progress(job, quiet: bool, label: str = "working"):
    """Run job(callback) with a progress bar on stderr (callback: fraction done)."""
    with ux.progress(label, quiet) as cb:
        return job(None if quiet else (lambda f: cb(f)))


def _render_run(res, met, saved, planets=None) -> None:
    from .metrics.load_sharing import DEFINITION_TEXT, DEFINITION_USE

    st = res.statistics()
    console.print(f"[bold]{res.model.model.name}[/]: {res.message}", highlight=False)
    console.print(
        f"{st['steps']:,} steps ({st['method']}), {st['microseconds_per_step']:.3g} µs/step, "
        f"integration {st['wall_time_s']:.3g} s, compile/load {st['compile_time_s']:.3g} s "
        f"(+{st['rhs_compile_time_s']:.2g} s for the {st['rhs']} right-hand side); "
        f"transient discarded: {met.settle_times_text()}"
        + ("" if met.settling.settled else " (not settled: see the warnings)"), highlight=False)
    from .solve.integrate import EXCITATION_PERIOD

    why = st.get("step_limited_by") or ""
    if why and why != EXCITATION_PERIOD:  # a finer step than asked: say what set it
        console.print(f"step {st['step_s']:.3g} s, set by {why}", highlight=False,
                      markup=False)
    console.print(run_table(met))
    console.print(group_table(met))
    if planets is not None:
        _print_planets(planets, res.kinematics)
    bearings = res.bearing_forces(met.settling.start_time, metrics=met)
    if bearings:
        console.print(bearing_table(bearings, res))
    unknown = [g for g, v in met.load_sharing.per_group.items() if not math.isfinite(v)]
    console.print(f"system load-sharing coefficient ({met.definition}): "
                  f"[bold]{met.load_sharing.system:.4f}[/]"
                  + (f" (group {', '.join(unknown)} has none: the largest of the groups' "
                     f"is not known; a longer run, --duration, gives it)" if unknown else ""),
                  highlight=False)
    console.print(
        f"LSC ({met.definition}): {DEFINITION_TEXT[met.definition]}; "
        f"{DEFINITION_USE[met.definition]}.  Static F: the static equilibrium under the "
        f"mean excitation (mean mesh stiffness, constant errors; an eccentricity or runout "
        f"turning with its gear averages out), not the t = 0 state the run starts from.  "
        f"Dynamic factor = settled peak / the mesh's own "
        f"static force (K_v sense, >= 1 in contact); peak/nominal = settled peak / "
        f"equal-split nominal force (Ji & Li eq. 19) = load sharing and dynamics together.  "
        f"Contact loss: share of the whole run (start-up included) with the drive flanks "
        f"apart (a mesh with no backlash cannot lose contact: it is in double-flank "
        f"contact); back flank: share of the whole run with the deflection reversed (the "
        f"back flank engaged: the net force, damping included, can still push), and the "
        f"largest settled back-flank (tensile) force.  Groups: dynamic factor and "
        f"peak/nominal are the largest of the group's meshes; peak/nominal (eng.) = mean "
        f"over settled cycles of the largest member's per-cycle peak / nominal force (Ji & "
        f"Li eq. 19, engineering coefficient G_it)."
        + (f"  Bearing forces: {_bearing_source(bearings)}." if bearings else "")
        + _thrust_note(bearings, res),
        markup=False, highlight=False)
    if saved:
        console.print("results written to " + ", ".join(str(f) for f in saved),
                      highlight=False)


def _thrust_note(bearings: list[dict], res) -> str:
    """Which bearing rows leave out their gear's helical thrust: a body without an axial
    DOF carries its meshes' axial forces nowhere (a first-hour user's 231 kN of thrust on
    a bull gear appeared in no output)."""
    import numpy as np

    kin, model = res.kinematics, res.model
    left = []
    for r in bearings:
        gear = model.gears.get(r["body"])
        if gear is None or not set(gear.dofs) - {"theta"} <= {"x", "y"}:
            continue  # (a 'loa' DOF moves along the line of action, thrust included)
        if r.get("held") == "rigid":  # (its row is the sum of its mesh forces: thrust in z)
            continue
        axis = np.asarray(kin.bodies[r["body"]].axis, float)
        axis /= np.linalg.norm(axis)
        thrust = sum(mk.force * abs(float(np.asarray(mk.line_of_action) @ axis))
                     for mk in kin.meshes.values() if r["body"] in (mk.driver, mk.driven))
        if thrust > 1e-6 * max(mk.force for mk in kin.meshes.values()):
            left.append(r["body"])
    if not left:
        return ""
    return (f"  Axial thrust: {', '.join(left)} ha{'s' if len(left) == 1 else 've'} no "
            f"axial DOF, so the helical meshes' axial forces (F_a of `torquesplit check`) are "
            f"in none of these bearing forces; add 'z' to their dofs (with an "
            f"axial_stiffness) to have them.")


def run_table(met) -> Table:
    """The per-mesh table of a run (forces in kN)."""
    t = Table(title=f"meshes (load sharing: {met.definition})")
    cols = ("mesh", "group", "nominal F\n[kN]", "static F\n[kN]", "mean F\n[kN]",
            "peak F\n[kN]", "dynamic\nfactor", "peak/\nnominal", f"LSC\n({met.definition})",
            "contact\nloss", "back flank\n(time, force)")
    for col in cols:
        t.add_column(_h(col), justify="left" if col in ("mesh", "group") else "right")
    for r in met.rows:
        back = f"{100 * r.back_contact:.2f} %"
        if r.back_flank_force > 0:  # (settled; a transient's is in the warnings)
            back += f", {r.back_flank_force / 1e3:.4g} kN"
        loss = "no backlash" if r.double_flank else f"{100 * r.contact_loss:.2f} %"
        t.add_row(r.mesh, r.group, f"{r.nominal_force / 1e3:#.5g}", f"{r.static_force / 1e3:#.5g}",
                  f"{r.mean_force / 1e3:#.5g}", f"{r.peak_force / 1e3:#.5g}",
                  f"{r.dynamic_factor:.4f}", f"{r.peak_to_nominal:.4f}",
                  f"{r.load_sharing:.4f}", loss, back)
    return t


def bearing_table(bearings: list[dict], res) -> Table:
    """The supported bodies' bearing forces over the settled part (kN), from the run's
    history (:meth:`Results.bearing_forces`)."""
    per = ("every step" if res.history_keeps_every_step() else
           f"{res.history_samples_per_period():.3g} samples per shortest mesh period")
    streamed = all(r.get("peak_streamed") for r in bearings)
    b = Table(title=f"bearing forces (settled; {'peaks at every step, means ' if streamed else ''}"
                    f"from the history, {per})")
    # the force on the body's bearing, by direction of the frame it is written in: a
    # planet's (and any body's of a turning carrier's model) turns with the carrier
    frames = [r["frame"] for r in bearings]
    turning = any(f != "housing" for f in frames)
    cols = ["body", "mean force by direction\n[kN]", "|mean|\n[kN]", "peak |F|\n[kN]"]
    for col in cols + (["directions in"] if turning else []):
        b.add_column(_h(col), justify="left" if col in ("body", "directions in") else "right")
    from .results import bearing_round_off

    tiny = bearing_round_off(bearings)  # (round-off, written 0)

    def kn(v):
        return f"{(0.0 if abs(v) <= tiny else v) / 1e3:#.5g}"

    for r, frame in zip(bearings, frames):
        means = ", ".join(f"{d} {kn(v)}" for d, v in zip(r["directions"], r["mean"]))
        body = (f"{r['body']} (spline {r['via']})" if r.get("via") else
                f"{r['body']} (rigid bearing)" if r.get("held") == "rigid" else r["body"])
        b.add_row(body, means, kn(r["mean_magnitude"]), kn(r["peak_magnitude"]),
                  *([frame] if turning else []))
    spin = _centrifugal_loads(res.kinematics, [r["body"] for r in bearings])
    if spin:  # (4.49 kN on a planet's bearing with 0.59 kN tooth forces: a reviewer)
        b.caption = f"the planets' mean forces include their centrifugal force m Ω_c² r: {spin}"
        b.caption_justify = "left"
    return b


def _bearing_source(bearings: list[dict]) -> str:
    """Where the bearing table's numbers come from, for its note."""
    if all(r.get("peak_streamed") for r in bearings):
        return ("peak |F| streamed at every step (corners and the peaks between steps "
                "included, as the mesh forces'); means from the history's samples "
                "(--samples-per-period)")
    return ("from the history, not streamed, so a peak between its samples is missed "
            "(--samples-per-period; --check-step checks them at twice the sampling)")


def _centrifugal_loads(kin, bodies) -> str:
    """``"stage_planet1 4.4897 kN, ..."``: the centrifugal force m Omega_c^2 r of each
    planet among ``bodies`` whose carrier turns (one value where they are all equal)."""
    from .assembly.assemble import orbit_radius

    out = {}
    for body in bodies:
        carrier = kin.planet_bodies.get(body)
        if carrier is None or not kin.bodies[carrier].speed:
            continue
        out[body] = (kin.bodies[body].mass * kin.bodies[carrier].speed ** 2
                     * orbit_radius(kin, body, carrier))
    if not out:
        return ""
    if max(out.values()) - min(out.values()) <= 1e-9 * max(out.values()):
        return f"{next(iter(out.values())) / 1e3:#.5g} kN each"
    return ", ".join(f"{b} {v / 1e3:#.5g} kN" for b, v in out.items())


def group_table(met) -> Table:
    g = Table(title="load-sharing groups")
    for col in ("group", "meshes", f"LSC\n({met.definition})", "dynamic\nfactor",
                "peak/\nnominal", "peak/nominal\n(eng.)"):
        g.add_column(_h(col), justify="left" if col in ("group", "meshes") else "right")
    d = met.dynamic_factors
    for name, members in met.load_sharing.groups.items():
        g.add_row(name, ", ".join(members), f"{met.load_sharing.per_group[name]:.4f}",
                  f"{d.per_group_dynamic_factor[name]:.4f}",
                  f"{d.per_group_peak_to_nominal[name]:.4f}",
                  f"{d.per_group_peak_to_nominal_engineering[name]:.4f}")
    return g


def _print_planets(planets, kinematics) -> None:
    """The planet table (K_gamma per stage, the factor per planet) and what it shows."""
    console.print(ux.planet_table(planets, kinematics))
    console.print(ux.planet_text(planets), markup=False, highlight=False)


# --------------------------------------------------------------------------- static
@app.command()
def static(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    revolutions: Optional[float] = typer.Option(
        None, "--revolutions", help="Revolutions of the slowest gear (default: whole "
        "periods of the errors and tables, at least one revolution).", metavar="N"),
    points_per_cycle: int = typer.Option(32, "--points-per-cycle",
                                         help="Positions per cycle of the fastest "
                                         "excitation (raised to a multiple of the meshes' "
                                         "phase offsets, e.g. 96 for three planets 1/3 of a "
                                         "cycle apart, so that each samples the same "
                                         "phases).", metavar="N"),
    max_points: int = typer.Option(20000, "--max-points", help="Most positions of the sweep "
                                   "(a longer common period of the errors thins them, and "
                                   "says so).", metavar="N"),
    out: Optional[Path] = typer.Option(
        None, "--out", metavar="FILE",
        help="Write results: .nc (NetCDF), .mat (MATLAB) or .csv (NAME.csv per mesh, "
             "NAME_groups.csv per group and the system, NAME_history.csv per position, "
             "NAME_about.json)."),
    force: bool = _flag("--force", "Replace an existing results file and figures."),
    plots: Optional[Path] = typer.Option(None, "--plots", help="Write report figures (PNG, "
                                         "SVG) into this folder.", metavar="DIR"),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print the results and warnings as JSON."),
    quiet: bool = _flag("--quiet", "No progress bar."),
):
    """Quasi-static load sharing: the equilibrium at each mesh position, with the errors
    and clearances at that position (Mo et al. 2017); floating orbits in µm."""
    from .results import files
    from .results.export import check_dataset_output

    state = {"saved": None, "figures": False}
    with contextlib.ExitStack() as stack, ux.interruptible(
            lambda: ux.kept_files(state["saved"], state["figures"])):
        try:
            opts = _option_errors()
            opts(_positive, revolutions, "--revolutions", "1")
            opts(_at_least, points_per_cycle, 1, "--points-per-cycle", "32")
            opts(_at_least, max_points, 16, "--max-points", "50000")
            if plots is not None:
                from .plot.figures import STATIC_FIGURES, figure_files

                opts(_check_plots_folder, plots, names=figure_files(STATIC_FIGURES),
                     force=force)
            opts.raise_any(model, assign)
            if out is not None:
                # (the CSV tables: per mesh, per position, per group, per planet of a
                # stage)
                plan = _out_option(check_dataset_output, out,
                                   ("mesh", "time", "group", "planet_entity"),
                                   overwrite=force)
                stack.enter_context(files.claim_output(plan))
            m, _ = _load(model, assign)
            from .quasistatic import quasi_static_load_sharing
            from .results.plausibility import static_warnings
            from .solve.integrate import stop_on_interrupt

            # Ctrl-C ends the sweep with the positions done: saved and reported as such
            with ux.collect_warnings(), stop_on_interrupt(), \
                    ux.progress("quasi-static equilibria", quiet or as_json) as cb:
                res = quasi_static_load_sharing(m, revolutions=revolutions,
                                                points_per_cycle=points_per_cycle,
                                                max_points=max_points, progress=cb)
            for loc, msg in static_warnings(res):
                ux.warn(f"{loc}: {msg}")
            res.kept_warnings = list(ux.session().warnings)
        except _EXPECTED as exc:
            _fail(exc)
            return
        failed = None
        try:  # a file that cannot be written: the results are still printed, then the error
            with ux.finish_before_interrupt():  # (a Ctrl-C now waits for the file)
                if out is not None:  # (every file named where the save is reported)
                    from .results.export import dataset_files

                    state["saved"] = dataset_files(res.to_dataset(),
                                                   res.save(out, overwrite=force))
        except _EXPECTED as exc:
            failed = exc
        saved = state["saved"]
        met = res.metrics()
        orbits = res.orbits()
        figures = []
        if plots is not None:
            from .plot import write_static_figures

            state["figures"] = True  # (a Ctrl-C now: "figures incomplete", as run says)
            try:
                with ux.progress("writing figures", quiet or as_json, total=None):
                    figures = write_static_figures(res, plots)
            except OSError as exc:
                failed = failed or _figure_error(exc, "--plots", plots,
                                                 _kept_results(saved or []))
            state["figures"] = False
    _print_static(m, res, met, orbits, saved, figures, plots, as_json)
    if failed is not None:
        _fail(failed)
    elif res.solution.interrupted:
        ux.exit_interrupted(ux.kept_files(saved))


def _print_static(m, res, met, orbits, saved, figures, plots, as_json) -> None:
    """A quasi-static sweep's tables (or JSON); the planet table and JSON key
    ``planet_load_sharing`` (static_torque) as in ``run``, for a planetary model only."""
    forces = res.mesh_forces()
    planets = ux.planet_sharing(met, res.kinematics)
    if as_json:
        ux.emit_json({
            "model": m.model.name, "positions": int(res.times.size),
            "converged": bool(res.solution.converged.all()),
            "load_sharing": {"definition": "static_torque", "per_mesh": met.per_mesh,
                             "per_group": met.per_group, "system": met.system,
                             "groups": met.groups},
            **({"planet_load_sharing": ux.planet_sharing_dict(planets)} if planets else {}),
            "mesh_force_N": {name: {"min": float(forces[:, j].min()),
                                    "mean": float(forces[:, j].mean()),
                                    "max": float(forces[:, j].max())}
                             for j, name in enumerate(res.mesh_names)},
            "orbits_um": {b: {"x_range": [1e6 * float(o[:, 0].min()), 1e6 * float(o[:, 0].max())],
                              "y_range": [1e6 * float(o[:, 1].min()), 1e6 * float(o[:, 1].max())]}
                          for b, o in orbits.items()},
            "results_file": str(saved[0]) if saved else None,
            "results_files": [str(f) for f in saved or []],
            "figures": [str(f) for f in figures],
        }, _json_default)
        return
    stopped = (f" (stopped by Ctrl-C: {res.times.size} of {res.solution.planned})"
               if res.solution.interrupted else "")
    console.print(f"[bold]{m.model.name}[/]: {res.times.size} mesh positions{stopped}, "
                  f"{'all converged' if res.solution.converged.all() else 'NOT all converged'}",
                  highlight=False)
    t = Table(title="quasi-static load sharing (static torque ratio, largest over positions)")
    for col in ("mesh", "min F [kN]", "mean F [kN]", "max F [kN]", "LSC (static_torque)"):
        t.add_column(_h(col), justify="left" if col == "mesh" else "right")
    for j, name in enumerate(res.mesh_names):
        t.add_row(name, f"{forces[:, j].min() / 1e3:#.5g}", f"{forces[:, j].mean() / 1e3:#.5g}",
                  f"{forces[:, j].max() / 1e3:#.5g}", f"{met.per_mesh[name]:.5f}")
    console.print(t)
    for g, v in met.per_group.items():
        console.print(f"group {g}: {v:.5f}", highlight=False)
    if planets is not None:
        _print_planets(planets, res.kinematics)
    console.print(f"system load-sharing coefficient (static_torque): [bold]{met.system:.5f}[/]")
    if orbits:
        from .model.kinematics import frame_label

        kin = res.kinematics
        frames = {b: frame_label(c if (c := kin.frames.get(b)) and kin.bodies[c].speed
                                 else None) for b in orbits}
        turning = any(f != "housing" for f in frames.values())  # (as the bearing table)
        o = Table(title="floating orbits (centre displacement from its nominal position)")
        for col in ("body", "x range [µm]", "y range [µm]") + (("directions in",) if turning
                                                                 else ()):
            o.add_column(_h(col))

        def um(v):  # (rounded; no '-0.000')
            return f"{round(1e6 * v, 3) + 0.0:.3f}"

        for b, xy in orbits.items():
            o.add_row(b, f"{um(xy[:, 0].min())} .. {um(xy[:, 0].max())}",
                      f"{um(xy[:, 1].min())} .. {um(xy[:, 1].max())}",
                      *([frames[b]] if turning else []))
        console.print(o)
    if saved:
        console.print("results written to " + ", ".join(str(f) for f in saved),
                      highlight=False)
    if figures:
        console.print(f"{len(figures)} figure files written to {plots}", highlight=False)


# --------------------------------------------------------------------------- mesh
@app.command()
def mesh(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    pair: str = typer.Option(..., "--pair", help="Name of the mesh to inspect.", metavar="MESH"),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Save k(phase) of every method "
                                        "(.png, .svg or .pdf).", metavar="FILE"),
    force: bool = _flag("--force", "Replace an existing --plot file."),
    points: int = typer.Option(256, "--points", help="Samples per mesh cycle.", metavar="N"),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print the comparison as JSON."),
):
    """Mesh stiffness k(phase) of one mesh by every applicable method, with the ISO value
    (N/µm along the line of action, in the table and in the --plot figure); for a mesh
    whose error varies over the cycle (an LTCA's loaded transmission error), what a run
    sees of it: k(s), e(s) and the static force."""
    try:
        opts = _option_errors()
        opts(_at_least, points, 16, "--points", "256")
        # (a fuzzer's 100,000,000 was killed for memory without a word; 3,000,000 took
        # 18 GB: the methods keep several arrays per sample)
        opts(_at_most, points, MAX_MESH_POINTS, "--points")
        opts(_check_figure_file, plot, "--plot", force)
        opts.raise_any(model, assign)
        # (the advice to use the modifications in a dynamic run through 'ltca' is not
        # for the command that analyses them)
        m, _ = _load(model, assign, irrelevant=(MODIFICATIONS_UNUSED,))
        if pair not in m.meshes:
            raise OptionError(f"--pair: no mesh named {pair!r}; use one of "
                              f"{', '.join(m.meshes)}")
        # (the contact analysis's warnings, e.g. of a secant stiffness: a raw Python
        # warning and none in --json, an LTCA reviewer)
        with ux.collect_warnings():
            from .assembly.excitation import stiffness_table
            from .gears.stiffness import compare_methods
            from .gears.stiffness.result import MeshStiffness
            from .model.kinematics import solve_kinematics

            kin = solve_kinematics(m)
            mk = kin.meshes[pair]
            if mk.geometry is None:
                raise OptionError(f"mesh {pair!r} is a bevel/face mesh: only its model-file "
                                  f"stiffness applies (no involute stiffness methods); choose a "
                                  f"cylindrical mesh")
            spec = m.meshes[pair].stiffness
            label = spec.method
            if spec.method == "ltca":  # which stiffness of the contact analysis the run takes
                label = (f"ltca, {spec.ltca.excitation}: "
                         + ("dP/dZ" if spec.ltca.excitation == "tangent" else "P/Z")
                         + " at the operating load")
            model_k = MeshStiffness.from_samples(stiffness_table(m, kin, pair, points),
                                                 method=f"model file ({label})")
            g = m.gears[mk.driver]
            row = "model file" if spec.method != "ltca" else f"model file ({label})"
            with ux.interruptible():  # (Ctrl-C exited 130 without a word)
                cmp = compare_methods(mk.geometry, points, young_modulus=g.youngs_modulus,
                                      poisson_ratio=g.poisson_ratio, extra={row: model_k})
                cycle = _run_excitation(m, pair)
    except _EXPECTED as exc:
        _fail(exc)
        return
    failed = None
    if plot is not None:
        from .plot.mesh import plot_mesh_stiffness

        try:
            plot_mesh_stiffness(cmp, plot,
                                title=f"{m.model.name}: stiffness of mesh {pair} by method")
        except OSError as exc:
            failed = _figure_error(exc, "--plot", plot, "the table is printed, nothing saved")
            plot = None
    _print_mesh(pair, cmp, plot, as_json, cycle)
    if failed is not None:
        _fail(failed)


def _run_excitation(m, pair):
    """What a run of ``m`` sees of mesh ``pair`` over a mesh cycle at the static
    equilibrium (:func:`torquesplit.steady.maps.mesh_cycle`), where its error varies over
    the cycle (an LTCA's loaded transmission error, a transmission-error harmonic); else
    None.  (An LTCA reviewer could not see the e(s) a tangent-stiffness mesh is driven
    by.)"""
    import numpy as np

    from .assembly.assemble import assemble
    from .solve.static import static_equilibrium
    from .steady.maps import mesh_cycle

    spec = m.meshes[pair]
    te = getattr(spec, "transmission_error", None)
    if spec.stiffness.method != "ltca" and not (te is not None and te.amplitude > 0):
        return None
    s = assemble(m)
    cycle = mesh_cycle(s, static_equilibrium(s).q, list(s.element_names).index(pair))
    return cycle if cycle is not None and np.ptp(cycle.error) > 0 else None


def _print_mesh(pair, cmp, plot, as_json, cycle=None) -> None:
    """The mesh-stiffness comparison (or JSON), and what a run sees of the mesh over a
    cycle where its error varies (``cycle``, :func:`_run_excitation`)."""
    if as_json:
        out = {"mesh": pair, "methods": cmp.rows(), "units": "N/m",
               "iso_c_prime_N_per_mm_um": cmp.iso.c_prime_iso,
               "iso_c_gamma_N_per_mm_um": cmp.iso.c_gamma_iso,
               "iso_mesh_stiffness_N_per_m": cmp.iso_mesh_stiffness,
               "plot": str(plot) if plot else None}
        if cycle is not None:
            out["run_excitation"] = {
                "phase": cycle.phase, "stiffness_N_per_m": cycle.stiffness,
                "error_m": cycle.error, "static_deflection_m": cycle.deflection,
                "half_gap_m": cycle.half_gap,
                "static_force_N": cycle.force,
                "description": "over one mesh cycle at the static equilibrium: k(s), the "
                               "error e(s) along the line of action and the force "
                               "k(s) (delta - e(s)) a run is driven by"}
        ux.emit_json(out, _json_default)
        return
    t = Table(title=f"mesh stiffness of {pair} along the line of action")
    for col in ("method", "mean [N/µm]", "min [N/µm]", "max [N/µm]", "peak-peak [N/µm]",
                "mean / ISO"):
        t.add_column(_h(col), justify="left" if col == "method" else "right")
    for r in cmp.rows():
        t.add_row(r["method"], f"{r['mean'] / 1e6:#.5g}", f"{r['minimum'] / 1e6:#.5g}",
                  f"{r['maximum'] / 1e6:#.5g}", f"{r['peak_to_peak'] / 1e6:#.5g}",
                  f"{r['mean_over_iso']:.3f}")
    console.print(t)
    console.print(f"ISO 6336-1: c' = {cmp.iso.c_prime_iso:.3f} N/(mm µm), c_gamma = "
                  f"{cmp.iso.c_gamma_iso:.3f} N/(mm µm) (transverse), c_gamma b / "
                  f"cos² β_b = {cmp.iso_mesh_stiffness / 1e6:.5g} N/µm along the flank "
                  f"normal, as the table (1 N/µm = 1e6 N/m = 1 N/(mm µm) per mm of face)",
                  highlight=False)
    if cycle is not None:
        _print_run_excitation(pair, cycle)
    if plot is not None:
        console.print(f"plot written to {plot}")


def _print_run_excitation(pair, cycle) -> None:
    """The table of what a run sees of a mesh over its cycle (:func:`_run_excitation`)."""
    import numpy as np
    from rich.markup import escape

    t = Table(title=f"what a run sees of {pair} over a mesh cycle, at the static "
                    f"equilibrium")
    for col in ("quantity", "mean", "min", "max", "peak-peak", "1st harmonic"):
        t.add_column(_h(col), justify="left" if col == "quantity" else "right")
    for name, v, scale in (("stiffness k(s) [N/µm]", cycle.stiffness, 1e-6),
                           ("error e(s) [µm]", cycle.error, 1e6),
                           ("force k(s) (delta - e(s)) [kN]", cycle.force, 1e-3)):
        first = 2.0 * abs(np.fft.rfft(v)[1]) / v.size
        t.add_row(escape(name), *(f"{x * scale:#.5g}" for x in (v.mean(), v.min(), v.max(),
                                                         np.ptp(v), first)))
    console.print(t)
    mean = float(cycle.force.mean())
    share = np.ptp(cycle.force) / mean if mean > 0 else math.nan
    gap = (f" ({cycle.half_gap * 1e6:.4g} µm of it the backlash's half-gap, which the "
           f"teeth do not carry)" if cycle.half_gap > 0 else "")
    console.print(f"delta = {cycle.deflection * 1e6:.4g} µm, the mesh's static "
                  f"deformation{gap}; "
                  f"e(s): the errors that repeat every mesh cycle (the LTCA's loaded "
                  f"transmission error, the model's transmission-error harmonics) along the "
                  f"line of action; the force's peak-to-peak is {100 * share:.3g} % of its "
                  f"mean (the stiffness variation and the error together: tip relief makes "
                  f"them cancel; 'torquesplit modes --campbell' rates each order); --json "
                  f"gives the curves", highlight=False)


# --------------------------------------------------------------------------- contact
@app.command()
def contact(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    pair: str = typer.Option(..., "--pair", help="Name of the mesh to analyse.", metavar="MESH"),
    load: Optional[list[str]] = typer.Option(
        None, "--load", help="Load: a normal force ('40 kN') or a torque ('17500 N m', on the "
        "gear named by --on); repeat for several.  Default: the operating load."),
    on: Optional[list[str]] = typer.Option(
        None, "--on", help="Gear a torque --load acts on (default the driven gear): once for "
        "every --load, or once per --load, in their order."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write the figures (PNG) into "
                                        "this folder.", metavar="DIR"),
    force: bool = _flag("--force", "Replace an existing --out file and the figures in the "
                                   "--plot folder."),
    positions: Optional[int] = typer.Option(None, "--positions", help="Mesh positions per cycle.",
                                            metavar="N"),
    slices: Optional[int] = typer.Option(None, "--slices", help="Slices across the face.",
                                         metavar="N"),
    harris: int = typer.Option(10, "--harris", help="Loads of the Harris map (0.1 to 1.5 times "
                               "the largest load); 0 for none.", metavar="N"),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print the results as JSON."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the results: .nc, .mat "
                                       "or .csv (tables per load, per mesh position with a "
                                       "column per load, and the Harris map).",
                                       metavar="FILE"),
):
    """Loaded tooth contact analysis of one mesh: transmission error, stiffness, load
    distribution, contact pressure, Harris map, meshing-in impact."""
    state = {"written": [], "figures": False}  # (what an interrupt keeps: a reviewer's
    # Ctrl-C during the figures said 'nothing written' with the results file complete)
    with ux.interruptible(lambda: ux.kept_files(state["written"], state["figures"])):
        _contact(model, pair, load, on, plot, force, positions, slices, harris, assign,
                 as_json, out, state)


MAX_FLANK_PRESSURE = 4e9
"""Hertz pressure [Pa] no steel flank carries (case-hardened gears: about 1.5 GPa
allowable, 3 GPa static limit): above it a contact load is a slip of units."""


CONTACT_TABLES = ("load_case", "position", "harris_load")
"""Row dimensions of ``contact --out``'s CSV tables (:mod:`torquesplit.gears.contact.export`)."""


def _contact(model, pair, load, on, plot, force, positions, slices, harris, assign,
             as_json, out=None, state=None) -> None:
    from .results.export import check_dataset_output

    try:
        opts = _option_errors()
        if out is not None:
            opts(_out_option, check_dataset_output, out,
                 CONTACT_TABLES if harris > 0 else CONTACT_TABLES[:2], overwrite=force)
        if plot is not None:
            from .plot.contact import contact_figure_files

            opts(_check_plots_folder, plot, "--plot", names=contact_figure_files(harris > 0),
                 force=force)
        from .model.schema_modifications import MAX_POSITIONS, MIN_POSITIONS

        # the limits of the model file's fields (stiffness.ltca.positions, .slices)
        opts(_at_least, positions, MIN_POSITIONS, "--positions", "64")
        opts(_at_least, slices, 1, "--slices", "40")
        for value, option, most in ((positions, "--positions", MAX_POSITIONS),
                                    (slices, "--slices", 400)):
            opts(_at_most, value, most, option)
        opts(_at_least, harris, 0, "--harris", "10")
        for text in load or []:  # (each with the other options and the model's problems)
            opts(_check_load_text, text)
        ons = opts(_gear_per_load, on, load)
        opts.raise_any(model, assign)
        # (the advice to use the modifications in a dynamic run through 'ltca' is not
        # for the command that analyses them)
        m, _ = _load(model, assign, irrelevant=(MODIFICATIONS_UNUSED,))
        if pair not in m.meshes:
            raise TorquesplitError(f"no mesh named {pair!r}; name one of {', '.join(m.meshes)}")
        from .gears.contact.coupling import contact_model_for_mesh, _options
        from .gears.contact.impact import loaded_meshing_in
        from .model.kinematics import solve_kinematics
        from .model.units import parse_quantity

        kin = solve_kinematics(m)
        spec = m.meshes[pair].stiffness
        opts = _options(spec)
        if positions is not None or slices is not None:
            from dataclasses import replace

            from .model.checks import lead_slices_note

            opts = replace(opts, positions=positions or opts.positions,
                           slices=slices or opts.slices)
            note = lead_slices_note(m, pair, opts.slices, "--slices") if slices else ""
            if note:  # (as the model file's slices warns)
                ux.warn(f"--slices {slices}: {note}")
        cm, op_load, names, reverse = contact_model_for_mesh(m, kin, pair, options=opts)
        loads = [_contact_load(text, m, kin, pair, names, gear, cm, parse_quantity)
                 for text, gear in zip(load or [], ons)] or [op_load]
        import numpy as np

        with ux.progress("loaded tooth contact analysis", as_json, total=None):
            results = [cm.solve(f).require_converged(f"meshes.{pair}") for f in loads]
            top = max(loads)
            hm = cm.harris_map(np.linspace(0.1, 1.5, harris) * top) if harris > 0 else None
        op = max(results, key=lambda r: r.load)
        shares = op.helix_load.mean(axis=0) / op.load
        if cm.helices == 2 and not opts.axial_float and shares.max() > 0.525:
            ux.warn(f"meshes.{pair}: the helices carry {100 * shares[0]:.0f} % and "
                    f"{100 * shares[1]:.0f} % of the load with both members held axially; "
                    f"if one member floats (as double-helical drives usually do), set "
                    f"stiffness.ltca.axial_float = true: the helices then share equally",
                    label="note")
        for r in results:  # beyond any steel flank: the elastic LTCA says nothing there
            p_h = float(r.max_pressure.max())
            if p_h > MAX_FLANK_PRESSURE:
                ux.warn(f"meshes.{pair}: at {r.load / 1e3:.4g} kN the largest Hertz pressure "
                        f"is {p_h / 1e6:.4g} MPa, beyond what any steel flank carries "
                        f"({MAX_FLANK_PRESSURE / 1e6:.0f} MPa); the linear-elastic contact "
                        f"analysis is not valid there: check the load and its unit")
        impact, impact_note = None, None
        if cm.pair.is_internal:  # (reverse: a ring that drives, internal too)
            impact_note = _INTERNAL_IMPACT
        elif not reverse:
            mk = kin.meshes[pair]
            drv, dvn = kin.bodies[mk.driver], kin.bodies[mk.driven]
            try:  # a side result: the contact analysis stands without it
                impact = loaded_meshing_in(op, omega_driving=abs(drv.speed),
                                           inertia_driving=drv.polar_inertia,
                                           inertia_driven=dvn.polar_inertia)
            except ModelError as exc:
                impact_note = f"meshing-in impact: not computed ({exc.issues[0][1]})"
        if impact_note is not None and as_json:  # the table prints it under the table
            ux.warn(impact_note, label="note")
    except _EXPECTED as exc:
        _fail(exc)
        return
    figures, written, failed = [], [], None
    given = [f"{text} on {gear or kin.meshes[pair].driven}" if not _is_force(text) else text
             for text, gear in zip(load or [], ons)] or None
    if out is not None:  # (a file that cannot be written: the tables are still printed)
        from .gears.contact.export import contact_dataset
        from .results.export import dataset_files, save_dataset, with_model

        try:
            ds = with_model(contact_dataset(results, operating_load=op_load, harris=hm,
                                            impact=impact, given=given, mesh=pair,
                                            gears=names), m)
            written = dataset_files(ds, save_dataset(ds, out, overwrite=force))
            if state is not None:
                state["written"] = written
        except TorquesplitError as exc:
            failed = exc
        except OSError as exc:
            failed = OutputError(f"--out {out}: cannot write the results "
                                 f"({clip_message(exc.strerror or str(exc))}); the tables "
                                 f"are printed; choose a folder you can write to")
    if plot is not None:
        from .plot.contact import write_contact_figures

        if state is not None:
            state["figures"] = True
        try:
            figures = write_contact_figures(results, hm, plot, operating=op,
                                            operating_load=op_load,
                                            title=f"{m.model.name} {pair}", gear=names[1])
        except OSError as exc:
            failed = _figure_error(exc, "--plot", plot, "the tables are printed" + (
                ", the results written" if written else ", nothing saved"))
        if state is not None:
            state["figures"] = False
    _print_contact(m, pair, names, op_load, cm, results, hm, impact, op, figures, plot,
                   as_json, reverse, impact_note, given, written)
    if failed is not None:
        _fail(failed)


def _print_contact(m, pair, names, op_load, cm, results, hm, impact, op, figures, plot,
                   as_json, reverse=False, impact_note=None, given=None, written=()) -> None:
    """The loaded tooth contact analysis (or JSON); ``reverse``: the second gear (a ring)
    drives; ``impact_note``: why there is no meshing-in impact; ``given``: each load as
    the command line gave it ('680 N m on wheel'); ``written``: the --out files."""
    rows = [r.summary() for r in results]
    if given is not None:  # (what each load was given as, '680 N m on wheel')
        rows = [{"given_as": g, **row} for row, g in zip(rows, given)]
    if as_json:  # the curves over the mesh cycle too (the scalars alone could not be
        # compared with another LTCA: a reviewer)
        phase = [float(x) for x in cm.phase]
        rows = [{**row, "phase": phase, "te_m": [float(x) for x in r.transmission_error],
                 "stiffness_secant_N_per_m": [float(x) for x in r.stiffness_secant],
                 "stiffness_tangent_N_per_m": [float(x) for x in r.stiffness_tangent]}
                for r, row in zip(results, rows)]
        ux.emit_json({
            "mesh": pair, "gears": list(names), "operating_load_N": op_load,
            "positions": int(cm.phase.size), "slices": int(cm.y.size), "loads": rows,
            "harris": None if hm is None else {
                "load_N": hm.loads.tolist(), "te_peak_to_peak_m": hm.te_peak_to_peak.tolist(),
                "te_peak_to_peak_arcsec": hm.te_peak_to_peak_arcsec.tolist(),
                "mean_stiffness_N_per_m": hm.mean_stiffness.tolist(),
                "contact_ratio": hm.contact_ratio.tolist()},
            "impact": None if impact is None else {
                "peak_force_N": impact.peak_force, "advance_m": impact.advance,
                "corner_separation_m": impact.corner_separation},
            "figures": [str(f) for f in figures],
            "files": [str(f) for f in written]}, _json_default)
        return
    driver, driven = (names[1], names[0]) if reverse else (names[0], names[1])
    console.print(f"[bold]{m.model.name}[/]: LTCA of mesh {pair} ({driver} drives {driven}), "
                  f"{cm.phase.size} positions x {cm.y.size} slices"
                  + (" x 2 helices" if cm.helices == 2 else "")
                  + f"; operating normal load {op_load / 1e3:.5g} kN")
    # the angular transmission error is that of the driven gear (LTCA gear 2; Liu et al.
    # 2021 eq. 3: Z / (r_b2 cos beta_b))
    arcsec = f"TE p-p [arc s of {names[1]}]"
    t = Table(title="loaded tooth contact analysis (normal direction)")
    given = [""] * len(results) if given is None else given
    for col in (["given as"] if any(given) else []) + [
            "load [kN]", "TE mean [µm]", "TE p-p [µm]", arcsec, "k secant [N/µm]",
            "k tangent [N/µm]", "p_H max [MPa]", "contact ratio", "K_Hβ"]:
        t.add_column(_h(col), justify="right")
    for r, row, g in zip(results, rows, given):
        t.add_row(*([g] if any(given) else []), f"{r.load / 1e3:#.5g}",
                  f"{row['te_mean_m'] * 1e6:#.4g}",
                  f"{row['te_peak_to_peak_m'] * 1e6:#.4g}", f"{row['te_peak_to_peak_arcsec']:#.4g}",
                  f"{row['stiffness_secant_mean_N_per_m'] / 1e6:#.5g}",
                  f"{row['stiffness_tangent_mean_N_per_m'] / 1e6:#.5g}",
                  f"{row['max_hertz_pressure_Pa'] / 1e6:#.5g}",
                  f"{row['actual_contact_ratio']:.3f}", f"{row['face_load_factor']:.3f}")
    console.print(t)
    if hm is not None:
        h = Table(title="Harris map")
        for col in ("load [kN]", "TE p-p [µm]", arcsec, "contact ratio"):
            h.add_column(_h(col), justify="right")
        for f, pp, pa, cr in zip(hm.loads, hm.te_peak_to_peak, hm.te_peak_to_peak_arcsec,
                                 hm.contact_ratio):
            h.add_row(f"{f / 1e3:#.4g}", f"{pp * 1e6:#.4g}", f"{pa:#.4g}", f"{cr:.3f}")
        console.print(h)
    if impact is not None:
        console.print(f"meshing-in impact at {op.load / 1e3:.5g} kN: {impact.peak_force:.5g} N "
                      f"(premature approach {impact.advance * 1e6:.3g} µm, relief where it enters "
                      f"{impact.corner_separation * 1e6:.3g} µm)", highlight=False)
    elif impact_note is not None:
        console.print(impact_note, highlight=False, markup=False)
    console.print("contact ratio: mean number of loaded tooth pairs over the --positions "
                  "sampled in a mesh cycle, within the theoretical path of contact: the "
                  "geometric ratio to within one position's share (1/positions), so it can "
                  "exceed it slightly (contact beyond the tips, which a heavy load brings "
                  "early, is not modelled; the meshing-in line gives that premature "
                  "approach)", highlight=False)
    if figures:
        console.print(f"{len(figures)} figures written to {plot}")
    for f in written:
        console.print(f"wrote {f}", highlight=False)


#: the line ``contact`` prints (and ``--json`` lists in its warnings) for an internal mesh
_INTERNAL_IMPACT = ("meshing-in impact: not computed for internal gears (the corner-contact "
                    "model of Liu et al. 2021 eqs. 6-10 is that of an external pair)")


def _check_load_text(text: str) -> None:
    """A --load value is a positive force or torque (checked before the model is read)."""
    from .model.units import parse_quantity

    for kind in ("force", "torque"):
        try:
            value = parse_quantity(text, kind)
        except ValueError as exc:
            if "not a finite number" in str(exc):  # (not: 'neither a force nor a torque')
                raise OptionError(f"--load {text!r} is not a finite number; give e.g. "
                                  f"'40 kN' or '17500 N m'") from None
            continue
        if not (value > 0):
            raise OptionError(f"--load {text!r} must be positive; give e.g. '40 kN'")
        return
    raise OptionError(f"--load {text!r} is neither a force nor a torque; write e.g. '40 kN' "
                      f"or '17500 N m'")


def _is_force(text: str) -> bool:
    from .model.units import parse_quantity

    try:
        parse_quantity(text, "force")
        return True
    except ValueError:
        return False


def _gear_per_load(on, load) -> list:
    """The gear of each --load (None: the default): one --on for all, or one per --load
    (a repeated --on was silently the last one's, for every load)."""
    load, on = list(load or []), list(on or [])
    if len(on) > 1 and len(on) != len(load):
        raise OptionError(f"--on is given {len(on)} times for {len(load)} --load values: give "
                          f"it once (for every load) or once per --load, in their order")
    if on and not load:
        raise OptionError("--on names the gear a torque --load acts on; give the --load too")
    if on and all(_is_force(text) for text in load):  # (it was ignored without a word)
        raise OptionError("--on names the gear a torque --load acts on, and every --load is "
                          "a force (along the line of action, on neither gear); leave --on "
                          "out, or give the load as a torque ('680 N m')")
    return on * len(load) if len(on) == 1 else on or [None] * len(load)


def _contact_load(text, model, kin, pair, names, on, cm, parse_quantity) -> float:
    """A --load value (checked by :func:`_check_load_text`) as a normal force [N]: a force
    as given, a torque on a gear divided by its base radius times cos(beta_b)."""
    if _is_force(text):
        return parse_quantity(text, "force")
    value = parse_quantity(text, "torque")
    gear = on or kin.meshes[pair].driven
    if gear not in names:
        raise TorquesplitError(f"--on {gear!r} is not a gear of mesh {pair!r}; name one of "
                               f"{', '.join(names)}")
    g = cm.pair.gear1 if gear == names[0] else cm.pair.gear2
    return value / (g.base_radius * cm.normal_factor)


# --------------------------------------------------------------------------- optimize
@app.command()
def optimize(
    spec: str = typer.Argument(..., help="Optimisation file (.toml), or the name of a shipped "
                               "one (liu2021_dh_modification).", metavar="SPEC"),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for pareto.csv, pareto.png "
                                       "and chosen.toml (default: SPEC_results in the current "
                                       "folder).", metavar="DIR"),
    workers: Optional[int] = typer.Option(None, "--workers", help="Processes (overrides the "
                                          "file).", metavar="N"),
    generations: Optional[int] = typer.Option(None, "--generations", help="Generations.",
                                              metavar="N"),
    population: Optional[int] = typer.Option(None, "--population", help="Population size.",
                                             metavar="N"),
    seed: Optional[int] = typer.Option(None, "--seed", help="Random seed.", metavar="N"),
    scheduler: Optional[str] = typer.Option(
        None, "--scheduler", help="Dask scheduler address: the evaluations run on that "
        "cluster (as a study's).", metavar="ADDRESS"),
    force: bool = _flag("--force", "Replace the pareto.csv, pareto.png and chosen.toml of an "
                        "earlier optimisation in --out."),
    as_json: bool = ux.json_option("Print the Pareto front as JSON."),
):
    """Optimise model parameters (NSGA-II or any pymoo algorithm) on LTCA or dynamic outputs;
    evaluations are stored as they finish, so an interrupted run resumes.  The file's
    format, its outputs and results: docs/optimization.md ('torquesplit example
    liu2021_dh_modification' copies the shipped one)."""
    from .optimize import optimize as run_optimization

    path = Path(spec)
    if not path.exists():
        from .examples import current_name, optimization_path

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            shipped = optimization_path(spec)
        if shipped is not None:
            note = current_name(spec, {"seed000_dh_modification": "liu2021_dh_modification"})[1]
            if note:
                ux.warn(note, label="note")
            path = shipped
    target = out or (Path.cwd() / f"{path.stem}_results")
    with ux.interruptible(lambda: "evaluations done so far are kept in the store: run the "
                          "same command again to resume"), ux.collect_warnings():
        try:
            _check_plots_folder(target, "--out")
            old = [f for f in ("pareto.csv", "chosen.toml", "pareto.png")
                   if (target / f).exists()]
            if old and not force:
                from .errors import OutputError

                raise OutputError(f"--out {target} holds the {old[0]} of an earlier "
                                  f"optimisation; add --force to replace it, or choose "
                                  f"another folder")
            res = _with_progress(lambda cb: run_optimization(
                path, workers=workers, generations=generations, population=population,
                seed=seed, scheduler=scheduler,
                progress=(None if as_json else _generation_lines()) or (
                    None if cb is None else (lambda g, n: cb(g / max(n + 1, 1))))),
                as_json, "optimising")
            files = res.write(target)
        except _EXPECTED as exc:
            _fail(exc)
            return
    names = [v.path for v in res.spec.variables]
    objs = [o.output for o in res.spec.objectives]
    values = res.objective_values()
    if as_json:
        ux.emit_json({"pareto": [{"x": dict(zip(names, map(float, x))),
                                  "objectives": dict(zip(objs, map(float, f))),
                                  "warnings": list(res.design_notes(i))}
                                 for i, (x, f) in enumerate(zip(res.X, values))],
                      "x_units": "SI",
                      "objectives_relative_to": {o.output: o.relative_to
                                                 for o in res.spec.objectives},
                      "chosen": int(res.chosen), "baseline": res.baseline,
                      "baseline_warnings": list(res.baseline_notes),
                      "baseline_not_worse": res.baseline_not_worse,
                      "evaluations": res.evaluations, "computed": res.computed,
                      "store": None if res.spec.store is None else str(res.spec.store),
                      "files": [str(f) for f in files]}, _json_default)
        return
    from .optimize import output_unit

    t = Table(title=f"Pareto front ({res.spec.algorithm}, {res.evaluations} evaluations, "
                    f"{res.computed} computed)")
    for col in ("", *[v.label(v.path.split(".")[-1]) for v in res.spec.variables],
                *res.objective_labels()):
        t.add_column(_h(col), justify="right")
    for i, (x, f) in enumerate(zip(res.X, values)):
        t.add_row(f"{i + 1}{' *' if i == res.chosen else ''}",
                  *[f"{v.shown(a):.4g}" for v, a in zip(res.spec.variables, x)],
                  *[f"{v:.4g}" for v in f])
    console.print(t)
    relative = [o.output for o in res.spec.objectives if o.relative_to]
    if relative:
        console.print("baseline (the model without the variables): " + ", ".join(
            f"{o} = {res.baseline[o]:.5g}" + (f" {output_unit(o)}" if output_unit(o) else "")
            for o in relative), highlight=False)
    flagged = [i for i in range(len(res.X)) if res.design_notes(i)]
    for i in flagged[:3] if res.chosen not in flagged else [res.chosen]:
        ux.warn(f"design {i + 1}{' (*)' if i == res.chosen else ''} of the front: "
                f"{res.design_notes(i)[0]}")
    if flagged:
        console.print(f"{len(flagged)} of {len(res.X)} designs of the front have warnings "
                      f"(the 'warnings' column of pareto.csv)", highlight=False)
    if res.baseline_notes:
        ux.warn(f"the baseline model: {res.baseline_notes[0]}")
    if res.baseline_not_worse:
        ux.warn("the chosen design is no better than the baseline (the model without the "
                "variables) in any objective: widen the variables' bounds, add generations, "
                "or keep the baseline")
    console.print(f"chosen design (*) written to {target / 'chosen.toml'}; front in "
                  f"{target / 'pareto.csv'}", highlight=False)
    if res.spec.store is not None:
        console.print(f"evaluations stored in {res.spec.store} (the same command run from "
                      f"this folder resumes from it)", highlight=False)


# --------------------------------------------------------------------------- modes
@app.command()
def modes(
    model: str = typer.Argument(..., help=_MODEL_HELP, metavar="MODEL"),
    count: Optional[int] = typer.Option(None, "--count", help="List at most this many modes "
                                        "(default: all; a degenerate group is kept whole).",
                                        metavar="N"),
    below: Optional[str] = typer.Option(None, "--below", help="List the modes below this "
                                        "frequency, e.g. '5 kHz' (a bare number is Hz).",
                                        metavar="FREQUENCY"),
    rotating_frame: bool = typer.Option(True, "--rotating-frame/--no-rotating-frame",
                                        help="Include the Coriolis and centripetal terms of "
                                        "a turning carrier (off: stationary carrier).",
                                        metavar=""),
    assign: Optional[list[str]] = typer.Option(None, "--set", help=_SET_HELP,
                                               metavar="PATH=VALUE"),
    as_json: bool = ux.json_option("Print the modes, with their shapes, as JSON."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the modes and shapes (with "
                                       "--campbell: the map): .nc, .mat or .csv.",
                                       metavar="FILE"),
    force: bool = _flag("--force", "Replace an existing --out or --plot file."),
    campbell: bool = _flag("--campbell", "Resonance map over --from..--to."),
    start: Optional[str] = typer.Option(None, "--from", help="Campbell: first speed, e.g. "
                                        "'500 rpm' (a bare number is rad/s).", metavar="SPEED"),
    stop: Optional[str] = typer.Option(None, "--to", help="Campbell: last speed.",
                                       metavar="SPEED"),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Campbell: write the diagram "
                                        "(.png, .svg or .pdf).", metavar="FILE"),
    orders: Optional[int] = typer.Option(None, "--orders", help="Campbell: mesh-frequency "
                                         "orders 1..N (default: those with 5 % of the "
                                         "stiffness's fundamental, 3 to 10; a note names "
                                         "strong orders left out).", metavar="N"),
    quiet: bool = _flag("--quiet", "No progress display."),
):
    """Natural modes about the static equilibrium: every mode (or those asked for), its
    multiplicity, modal damping ratio and the strain-energy shares of its group; where the
    model has a planetary stage, its type too (rotational, translational or planet: Lin &
    Parker 1999's classes, which only a cyclically symmetric stage has).

    The model is linearised about its static equilibrium with the MEAN mesh stiffness; a
    mesh (or clearance) separated at the equilibrium contributes no stiffness and no
    damping. Shafts are massless torsional springs: lump their inertia into the bodies
    they join. The damping ratio zeta is the modal (proportional-damping) approximation
    phi^H C phi / (2 omega) of the undamped mass-normalised mode (coupling of modes
    through C ignored; Coriolis term added with a turning carrier); f_d = f sqrt(1 -
    zeta^2)."""
    from .results import files
    from .results.export import check_dataset_output, save_dataset

    try:
        opts = _option_errors()
        opts(_at_least, count, 1, "--count", "20")
        opts(_at_least, orders, 1, "--orders", "15")
        opts(_check_figure_file, plot, "--plot", force)
        limit = opts(ux.quantity, below, "frequency", "--below")
        opts(_positive, limit, "--below", "'5 kHz'")
        opts.raise_any(model, assign)
        if out is not None:  # (the CSV tables: per mode and per DOF, or per speed)
            _out_option(check_dataset_output, out, ("speed", "crossing") if campbell else
                        ("mode", "dof"), overwrite=force)
        m, _ = _load(model, assign)
        if not campbell and (start is not None or stop is not None):
            raise TorquesplitError("--from and --to give the speed range of a Campbell "
                                   "diagram; add --campbell, or leave them out")
        # options of the other form would be ignored silently (a --plot without the map
        # wrote nothing and said nothing)
        if not campbell and plot is not None:
            raise TorquesplitError("--plot draws the Campbell diagram; add --campbell "
                                   "--from A --to B, or leave --plot out")
        if not campbell and orders is not None:
            raise TorquesplitError("--orders sets the excitation lines of the Campbell "
                                   "diagram; add --campbell --from A --to B, or leave "
                                   "--orders out")
        if campbell and (count is not None or below is not None):
            given = " and ".join(o for o, v in (("--count", count), ("--below", below))
                                 if v is not None)
            verb = "limit" if " and " in given else "limits"
            raise TorquesplitError(f"{given} {verb} the list of modes; the Campbell map "
                                   f"takes every mode: leave {given} out, or run 'modes' "
                                   f"without --campbell for the list")
        if campbell:
            if start is None or stop is None:
                raise TorquesplitError("--campbell needs a speed range: add --from '500 rpm' "
                                       "--to '3000 rpm'")
            from .steady.cli import campbell_command

            return campbell_command(m, start, stop, plot, as_json, console, _json_default,
                                    out=out, force=force, orders=orders)
        plan = None
        if out is not None:
            plan = _out_option(check_dataset_output, out, ("mode", "dof"), overwrite=force)
        from .model.kinematics import solve_kinematics
        from .modes import model_modes

        with ux.interruptible(), ux.progress("natural modes", quiet or as_json, total=None):
            kin = solve_kinematics(m)
            rep = model_modes(m, rotating_frame=rotating_frame, below=limit, count=count)
        saved = None
        if plan is not None:  # (Ctrl-C here exited 130 without a word; the file is
            # finished first, then the interrupt says so)
            with ux.interruptible(lambda: ux.kept_files(saved)), \
                    ux.finish_before_interrupt(), files.claim_output(plan):
                ds = rep.to_dataset()
                from .results.export import dataset_files, with_model

                saved = dataset_files(ds, save_dataset(with_model(ds, m, ux.session().warnings),
                                                       plan.path, overwrite=force))
    except _EXPECTED as exc:
        _fail(exc)
        return
    mesh_f = {n: mk.frequency for n, mk in kin.meshes.items()}
    # the carriers' speeds the modes are computed at (their frame's terms depend on it)
    carrier_rpm = {c: kin.bodies[c].speed * 30 / math.pi for c in kin.carriers}
    if as_json:
        data = rep.to_dict(shapes=True)
        data.update(mesh_frequencies_Hz=mesh_f, results_file=str(saved[0]) if saved else None,
                    results_files=[str(f) for f in saved or []])
        if carrier_rpm:
            data["carrier_speed_rpm"] = carrier_rpm
        ux.emit_json(data, _json_default)
        return
    frame = (" (turning carrier frame)" if rep.rotating_frame else "")
    console.print(f"{rep.rigid_modes} rigid-body mode(s) left out{frame}; mesh frequencies: "
                  + ", ".join(f"{k} {v:.5g} Hz" for k, v in mesh_f.items()), highlight=False)
    if carrier_rpm:
        console.print("modes at the model's speed: " + ", ".join(
            f"carrier {c} turning at {v:.5g} rpm" if v else f"carrier {c} at rest (a star "
            "stage: no rotating-frame terms)" for c, v in carrier_rpm.items())
            + ("" if not any(carrier_rpm.values()) else
               " (Coriolis and centripetal terms in: a degenerate pair splits into forward "
               "and backward whirl; --no-rotating-frame gives the modes at rest, as the "
               "planetary benchmarks publish them)" if rep.rotating_frame
               else " (its Coriolis and centripetal terms left out: --no-rotating-frame)"),
            highlight=False)
    if not rep.rows:  # (an empty table said nothing: a reviewer's --below "10 Hz")
        lowest = [f for f in rep.solution.frequencies if f > 0]
        console.print((f"no mode below {limit:.5g} Hz" if below is not None  # (a bare
                       else "no elastic mode")  # number echoed without its unit, Hz)
                      + (f": the lowest is {min(lowest):.5g} Hz" if lowest else ""),
                      highlight=False)
        return
    typed = any(r.type for r in rep.rows)
    whirls = any(r.whirl for r in rep.rows)
    t = Table(title="natural modes")
    cols = ["mode", "f [Hz]", "zeta", "f_d [Hz]", "mult."] + (["type"] if typed else []) + \
        (["whirl"] if whirls else []) + ["strain energy of the group (largest shares)"]
    for col in cols:
        t.add_column(_h(col))
    for r in rep.rows:
        energy = ", ".join(f"{n} {100 * v:.0f} %" for n, v in r.largest_shares(3))
        t.add_row(str(r.mode), f"{r.frequency:#.6g}", _ratio(r.damping_ratio),
                  f"{r.damped_frequency:#.6g}" if r.frequency > 0 else "-",
                  str(r.multiplicity), *([r.type or ""] if typed else []),
                  *([{"forward": "FW", "backward": "BW"}.get(r.whirl, "")] if whirls else []),
                  energy)
    console.print(t)
    console.print("zeta: modal damping ratio phi^H C phi / (2 omega) (proportional "
                  "approximation, coupling of modes ignored); f_d = f sqrt(1 - zeta^2)"
                  + ("; whirl: FW/BW, the central members whirl with/against the carrier's "
                     "rotation in its frame" if whirls else ""), highlight=False)
    turning = {c: v for c, v in carrier_rpm.items() if v} if rep.rotating_frame else {}
    if turning:  # (frequencies of which frame: a reviewer with an accelerometer)
        console.print(
            "f: frequencies of the equations as assembled, the translations of a stage's "
            "members measured in its turning carrier's frame: a translational mode at f "
            "there is seen at f ± the carrier's rotation frequency ("
            + ", ".join(f"{c} {abs(v) / 60:.4g} Hz" for c, v in turning.items())
            + ") in the housing's frame; mesh frequencies of a stage are relative to its "
            "carrier, as the teeth see them", highlight=False)
    if saved:
        console.print("modes written to " + ", ".join(str(f) for f in saved), highlight=False)


def _ratio(x: float) -> str:
    return f"{x:.3g}" if math.isfinite(x) else "-"


# --------------------------------------------------------------------------- examples
@app.command()
def examples():
    """List the shipped example models and the papers they come from."""
    from .examples import FIRST_EXAMPLE, RENAMED, example_info, example_names

    t = Table(title="torquesplit examples (copy one with 'torquesplit example NAME')")
    t.add_column("name", style="bold")
    t.add_column("description")
    t.add_column("reference")
    order = [FIRST_EXAMPLE] + [n for n in example_names() if n != FIRST_EXAMPLE]
    for name in order:
        info = example_info(name)
        label = name + ("\n(start here)" if name == FIRST_EXAMPLE else "")
        t.add_row(label, info.get("description", ""), info.get("reference", ""))
    console.print(t)
    from .examples import optimization_names

    console.print("Shipped optimisations (torquesplit optimize NAME; copy one with "
                  "'torquesplit example NAME'; the file format: docs/optimization.md): "
                  + ", ".join(optimization_names()), highlight=False)
    from .study.shipped import study_names

    console.print("Shipped studies, the papers' figures (torquesplit study NAME; 'torquesplit "
                  "study --list' describes them; copy one with 'torquesplit example NAME'; "
                  "the file format: docs/studies.md): " + ", ".join(study_names()),
                  highlight=False)
    console.print("The earlier names still work for old scripts but are deprecated (use "
                  "the names above; a deprecated name prints a note): "
                  + ", ".join(f"{old} -> {new}" for old, new in RENAMED.items()),
                  highlight=False)


@app.command()
def example(
    name: str = typer.Argument(..., help="Example name (see 'torquesplit examples').",
                               metavar="NAME"),
    directory: Path = typer.Option(Path("."), "--dir", help="Folder to write the file to.",
                                   metavar="DIR"),
    force: bool = _flag("--force", "Overwrite an existing file."),
):
    """Write an example model file (or a shipped study or optimisation file) to the
    current folder (or --dir)."""
    from .examples import (RENAMED_OPTIMIZATIONS, current_name, example_names, example_path,
                           optimization_names, optimization_path)
    from .results import files
    from .study.shipped import study_names, study_path

    try:
        stem, note = current_name(name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            # (a shipped name only: 'example /abs/path.toml' must not copy any file)
            ostem = current_name(name, RENAMED_OPTIMIZATIONS)[0]
            optimization = (optimization_path(ostem) if ostem in optimization_names()
                            and stem not in example_names() else None)
        if optimization is None and stem not in example_names() and name in study_names():
            optimization = study_path(name)  # (a study file: copied as it is)
        if stem not in example_names() and optimization is None:
            raise OptionError(f"no example named {name!r}; run 'torquesplit examples' to list "
                              f"them ({', '.join(example_names() + optimization_names())}; "
                              f"studies: {', '.join(study_names())})")
        if note:
            ux.warn(note, label="note")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            src = optimization or example_path(stem)
        if directory.exists() and not directory.is_dir():
            raise OptionError(f"--dir {directory} is a file, not a folder; give a folder")
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OptionError(f"--dir {directory} cannot be created ({exc.strerror}); give a "
                              f"folder you can write to") from None
        dst = files.write_atomically(directory / src.name, src.read_bytes(), overwrite=force,
                                     formats={".toml": "toml"}, what="the example")
    except _EXPECTED as exc:
        _fail(exc)
        return
    console.print(f"wrote {dst}", highlight=False)


from .steady.cli import register as _register_steady  # noqa: E402

_register_steady(app, _load, _fail, console, err_console, _json_default, set_help=_SET_HELP)

# --------------------------------------------------------------------------- studies
from .study.cli import study as _study, sweep as _sweep  # noqa: E402  (typer signatures only)

app.command("study")(_study)
app.command("sweep")(_sweep)

# --------------------------------------------------------------------------- report, draw
from .report.cli import register as _register_report  # noqa: E402

_register_report(app, sys.modules[__name__])

for _info in app.registered_commands:  # every command's --help without a type
    if _info.cls in (None, typer.core.TyperCommand):
        _info.cls = _Command


if __name__ == "__main__":  # pragma: no cover - as the installed script runs it
    from torquesplit._launch import main

    main()
