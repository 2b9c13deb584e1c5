"""What every command of :mod:`torquesplit.cli` shows the user besides its result.

==========================  ==============================================================
helper                      what it does
==========================  ==============================================================
:class:`Session`            the warnings of one command, in the order they were printed
:func:`warn`                print one ``warning:`` line on stderr and keep it for ``--json``
:func:`collect_warnings`    route Python warnings raised inside (the model's checks, the
                            run's cost estimate, deprecated names) to :func:`warn`
:func:`emit_json`           print a command's JSON with its ``warnings`` list
:func:`progress`            a progress bar (or a spinner for work of unknown length) on a
                            terminal, nothing elsewhere; its callback takes the fraction
                            done and, optionally, what is being done
:func:`interruptible`       Ctrl-C prints "interrupted; ..." with what was kept, exit 130
                            (:func:`exit_interrupted`, also after a command that stopped
                            on Ctrl-C with what it had)
:func:`quantity`            an option value with units; a bare number is SI (``--duration
                            3`` is 3 s), as in model files
:func:`header`              a table header with its unit in brackets, safe from rich markup
                            (``"speed [rpm]"`` would otherwise lose ``[rpm]``)
:func:`planet_sharing`      the planet load-sharing factor K_gamma of a planetary model, its
                            rows (:func:`planet_rows`, tables of ``run``, ``static``,
                            ``report``) and its ``--json`` entry (:func:`planet_sharing_dict`)
==========================  ==============================================================

No state survives a command: :func:`reset` starts each one (the app's callback calls it).
"""

from __future__ import annotations

import contextlib
import math
import sys
import warnings
from dataclasses import dataclass, field
from typing import Callable, Iterator, Optional

from rich.markup import escape

from . import _json
from .errors import ModelWarning, OptionError, clip_message, from_interrupt

MESH_UNITS = {"nominal_force": "N", "static_force": "N", "mean_force": "N",
              "min_force": "N", "peak_force": "N", "back_flank_force": "N",
              "dynamic_factor": "1", "dynamic_factor_engineering": "1",
              "peak_to_nominal": "1", "load_sharing": "1",
              "contact_loss": "1 (fraction of the time)",
              "back_contact": "1 (fraction of the time)",
              "rms_transmission_error": "m", "settle_time_s": "s"}
"""The unit of each per-mesh number of the ``--json`` outputs (``units`` key): SI, as
every JSON of the tool, where the tables print kN, % and um."""


@dataclass
class Session:
    """Warnings printed by the current command."""

    warnings: list[str] = field(default_factory=list)
    console: object = None
    err_console: object = None
    debug: bool = False
    json: bool = False
    """Whether the command was given ``--json`` (:func:`json_option`)."""
    json_printed: bool = False
    """Whether the command has printed its JSON (an error after it is not printed again)."""


_session = Session()


def session() -> Session:
    return _session


def reset(console, err_console, debug: bool = False) -> None:
    """Start a command: no warnings yet."""
    global _session
    _session = Session(console=console, err_console=err_console, debug=debug)


def warn(text: str, *, label: str = "warning") -> None:
    """Print ``warning: text`` on stderr (once per command) and keep it for ``--json``."""
    text = clip_message(str(text).strip())
    if not text or text in _session.warnings:
        return
    _session.warnings.append(text)
    con = _session.err_console
    if con is None:  # pragma: no cover - outside a command
        print(f"{label}: {text}", file=sys.stderr)
        return
    con.print(f"[yellow]{label}:[/] ", end="")
    con.print(text, markup=False, highlight=False, soft_wrap=True)


@contextlib.contextmanager
def collect_warnings() -> Iterator[None]:
    """Show every :class:`~torquesplit.errors.ModelWarning` (and deprecation notes) raised
    inside as a ``warning:`` line the moment it is raised, and keep it for ``--json``.

    Other Python warnings (numerical noise of a library) are shown the same way with
    ``--debug`` only.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("always", ModelWarning)
        warnings.simplefilter("always", FutureWarning)

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, ModelWarning):
                warn(str(message))
            elif issubclass(category, FutureWarning):
                warn(str(message), label="note")
            elif _session.debug:
                warn(f"{message} ({category.__name__} at {filename}:{lineno})")

        warnings.showwarning = show
        yield


def emit_json(data: dict, default: Callable | None = None) -> None:
    """Print ``data`` as JSON with the command's ``warnings`` list added."""
    data = dict(data)
    data["warnings"] = list(_session.warnings)
    print(_json.dumps(data, indent=2, default=default or json_default))
    _session.json_printed = True


def json_option(help: str):
    """The ``--json`` option of a command: it also makes the command's errors JSON
    (:func:`emit_json_errors`)."""
    import typer

    def remember(value: bool) -> bool:
        _session.json = bool(value)
        return value

    return typer.Option(False, "--json", help=help, metavar="", callback=remember)


def emit_json_errors(lines: list[str]) -> None:
    """A command run with ``--json`` that fails prints its errors as JSON on stdout too
    (``success`` false, ``errors``, ``warnings``), unless it has printed its JSON already:
    a script that reads stdout gets a document either way."""
    if not _session.json or _session.json_printed:
        return
    emit_json({"success": False, "errors": lines})


def json_default(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    try:
        return float(x)
    except Exception:
        return str(x)


@contextlib.contextmanager
def progress(label: str, quiet: bool = False, *, total: Optional[float] = 1.0):
    """A transient progress bar on stderr while the block runs (a terminal only).

    Yields a callback ``update(fraction, what=None)``; with ``total=None`` the bar is a
    spinner (work of unknown length) and ``fraction`` is ignored.  A non-terminal stderr
    (a batch job's log, nohup), where a bar draws nothing: a line at most every
    :data:`LOG_EVERY` seconds once that long has passed (a long run printed nothing
    for its whole length: a reliability reviewer).  ``quiet``: nothing.
    """
    con = _session.err_console
    if quiet or con is None:
        yield lambda fraction=None, what=None: None
        return
    if not getattr(con, "is_terminal", False):
        yield _progress_lines(con, label, total)
        return
    from rich.progress import (BarColumn, Progress, SpinnerColumn, TextColumn,
                               TimeElapsedColumn, TimeRemainingColumn)

    columns = ([SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn()]
               if total is None else
               [TextColumn("{task.description}"), BarColumn(),
                TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn()])
    columns.append(_compile_hint_column())
    with Progress(*columns, console=con, transient=True) as bar:
        task = bar.add_task(label, total=total)

        def update(fraction=None, what=None):
            kwargs = {}
            if fraction is not None and total is not None:
                kwargs["completed"] = fraction * total
            if what:
                kwargs["description"] = f"{label}: {what}"
            bar.update(task, **kwargs)

        yield update


#: seconds between the progress lines of a command whose stderr is not a terminal
LOG_EVERY = 30.0


def _progress_lines(con, label: str, total, clock=None):
    """:func:`progress`'s callback for a log: ``label: 45 %, 0:01:30 elapsed`` (with a
    ``total``) at most every :data:`LOG_EVERY` seconds, the first after that long."""
    import time

    clock = clock or time.monotonic
    t0 = clock()
    last = [t0]

    def update(fraction=None, what=None):
        now = clock()
        if now - last[0] < LOG_EVERY:
            return
        last[0] = now
        done = (f"{100 * fraction:.0f} %, " if fraction is not None and total is not None
                else "")
        con.print(f"{label}{': ' + what if what else ''}: {done}{clock_text(now - t0)} "
                  f"elapsed", highlight=False, markup=False)

    return update


def clock_text(seconds: float) -> str:
    """``H:MM:SS`` of a duration (progress lines)."""
    s = int(round(max(0.0, seconds)))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


#: seconds without progress after which a bar says that a first run compiles
COMPILE_HINT_AFTER = 4.0


def _compile_hint_column():
    from rich.progress import ProgressColumn
    from rich.text import Text

    class CompileHint(ProgressColumn):
        """A bar that has not moved for a few seconds says why it may not: the first run
        on a machine compiles the numba kernels (about 15 s; cached for later runs)."""

        def render(self, task):
            if task.completed == 0 and (task.elapsed or 0.0) > COMPILE_HINT_AFTER:
                return Text("(a first run also compiles the kernels: about 15 s, once)",
                            style="dim")
            return Text("")

    return CompileHint()


@contextlib.contextmanager
def interruptible(kept: Callable[[], str] | None = None) -> Iterator[None]:
    """Turn Ctrl-C into one line, ``interrupted; <what was kept>``, and exit status 130.

    ``kept()`` says what is on disk ("nothing written" when it returns an empty text).
    """
    try:
        yield
    except (KeyboardInterrupt, SystemError) as exc:
        # a Ctrl-C that lands inside compiled code comes back as a SystemError ("returned
        # a result with an exception set") whose context is the interrupt
        if isinstance(exc, SystemError) and not from_interrupt(exc):
            raise
        what = ""
        try:
            what = kept() if kept is not None else ""
        except Exception:  # pragma: no cover - never hide the interrupt
            what = ""
        exit_interrupted(what)


@contextlib.contextmanager
def finish_before_interrupt() -> Iterator[None]:
    """Within this block a Ctrl-C waits: the block (metrics and the results files of a
    finished computation) runs to its end, then the interrupt is raised, so that what was
    computed is on disk when :func:`interruptible` says what was kept.  A second Ctrl-C
    interrupts at once (:func:`torquesplit.errors.held_interrupt`)."""
    from .errors import held_interrupt

    with held_interrupt() as ctrl_c:
        yield
    if ctrl_c.hit:
        raise KeyboardInterrupt


def kept_files(files, figures_incomplete: bool = False) -> str:
    """What an interrupted command kept, for :func:`interruptible` and
    :func:`exit_interrupted`: ``"results kept in a.nc[; figures incomplete]"``, or ""
    (said as "nothing written") when no file was written."""
    if not files:
        return ""
    return ("results kept in " + ", ".join(str(f) for f in files)
            + ("; figures incomplete" if figures_incomplete else ""))


def exit_interrupted(what: str = "") -> None:
    """Print ``interrupted; <what was kept>`` on stderr and exit with status 130 (also
    after a command that stopped on Ctrl-C and reported what it had computed)."""
    import typer

    con = _session.err_console
    text = f"interrupted; {what or 'nothing written'}"
    if con is None:  # pragma: no cover
        print(text, file=sys.stderr)
    else:
        con.print(text, markup=False, highlight=False)
    raise typer.Exit(130) from None


def quantity(text: Optional[str], kind: str, option: str) -> Optional[float]:
    """An option value in SI: ``"0.5 s"``, ``"3000 rpm"``; a bare number is already SI
    (``--duration 3`` is 3 s), as in model files."""
    from .model.units import KINDS, parse_quantity

    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        try:
            return parse_quantity(text, kind)
        except ValueError as exc:
            raise OptionError(f"{option}: {exc}") from None
    if not math.isfinite(value):
        raise OptionError(f"{option} {text!r} is not a finite number; give e.g. {option} "
                          f"'{KINDS[kind][1]}'")
    if kind == "speed" and value != 0.0:  # engineers write speeds in rpm
        from .model.units import rad_s_text

        warn(f"{option} {text}: a bare number is a speed in rad/s ({rad_s_text(value)}); "
             f"write '{text} rpm' for rpm")
    return value


def header(text: str) -> str:
    """A table header safe from rich markup (``[rpm]`` is not a style tag)."""
    return escape(text)


PRINTED_DIGITS = 5
"""Significant digits the run tables print (1.0800, 12.036 kN)."""


class OptionErrors:
    """Every bad option of one command line, reported together: each check runs through
    this collector (``value = opts(check, *args)``: None where it failed) and
    :meth:`raise_any` raises one :class:`~torquesplit.errors.OptionError` with a line per
    problem, the model file's and ``--set`` problems added, instead of one problem per
    attempt.  ``load(model, assign, warn=False)`` reads a model as the command does."""

    def __init__(self, load=None) -> None:
        self.messages: list[str] = []
        self.load = load

    def __call__(self, check, *args, **kwargs):
        from torquesplit.errors import OptionError, OutputError

        try:
            return check(*args, **kwargs)
        except (OptionError, OutputError) as exc:  # (an --out path that cannot be written)
            self.messages.append(str(exc))
            return None

    def raise_any(self, model: str | None = None, assign=None) -> None:
        """Raise what was collected (nothing when every option is good), with the
        problems of ``model`` and its ``--set`` arguments, read without warnings."""
        from torquesplit.errors import OptionError, TorquesplitError

        if not self.messages:
            return
        if model is not None and self.load is not None:
            try:
                self.load(model, assign, warn=False)
            except (TorquesplitError, ValueError, OSError) as exc:
                self.messages.append(str(exc).strip())
        raise OptionError("\n".join(self.messages))


def render_step_check(check, rows: int = 12, printed: int = PRINTED_DIGITS,
                      refine: str = "--steps-per-period") -> None:
    """How many significant digits of the numbers hold at half the step (harmonic
    balance: twice the harmonics): a summary and the least converged numbers (those
    holding fewer than the ``printed`` digits of the tables)."""
    from torquesplit._table import Table

    console = session().console
    table = check.rows()
    short = [r for r in table if r[4] < printed]
    if check.method == "hb":
        what, was = "twice the harmonics", f"{check.step:.0f} -> {check.halved_step:.0f}"
    elif check.method == "dopri":
        what = f"a {check.step / check.halved_step:.0f}-fold tighter tolerance"
        was = f"rtol {check.step:.3g} -> {check.halved_step:.3g}"
    else:
        what, was = "half the step", f"{check.step:.3g} s -> {check.halved_step:.3g} s"
    if check.check_table_points > check.table_points:  # tables with jumps: finer too
        what += " and finer tables"
        was += (f"; {check.table_points} -> {check.check_table_points} table points: "
                f"the tables have jumps")
        refine = f"{refine} and [analysis] table_points"
    if check.check_history_samples > check.history_samples > 0:  # the bearing table's
        what += " and history"
        was += (f"; {check.history_samples:.3g} -> {check.check_history_samples:.3g} "
                f"history samples per period: the bearing forces")
        if any(r[0].startswith("bearing_mean_force") for r in short):
            refine = f"{refine}; the bearing means: --samples-per-period"
    console.print(
        f"step check, the same {'run' if check.method in ('rk4', 'dopri') else 'state'} at "
        f"{what} ({was}): "
        + (f"all {len(table)} numbers hold the {printed} significant digits printed"
           if not short else
           f"{len(table) - len(short)} of {len(table)} numbers hold the {printed} "
           f"significant digits printed; these hold fewer (trust only those digits, or "
           f"refine: {refine}):"), highlight=False, markup=False)
    if not short:
        return
    t = Table()
    for col in ("number", "unit", "value", "checked", "digits that hold"):
        t.add_column(col, justify="left" if col in ("number", "unit") else "right")
    for name, a, b, _, d in short[:rows]:
        # in the units of the tables above: forces in kN, transmission errors in µm
        head = name.split(".")[0]
        scale, unit = ((1e-3, "kN") if head.endswith("_force") else
                       (1e6, "µm") if head.endswith("transmission_error") else
                       (1.0, "s") if head.endswith("_time") else (1.0, ""))
        t.add_row(name, unit, f"{a * scale:.6g}", f"{b * scale:.6g}", str(d))
    console.print(t)
    if len(short) > rows:
        console.print(f"... and {len(short) - rows} more (--json lists every number)",
                      highlight=False)


#: what the planet table's numbers are (the line under it in ``run``, ``static``, ``report``)
PLANET_TEXT = ("K_gamma of a stage: its largest planet load over the mean planet load (the "
               "mesh-load factor of AGMA 6123 / ISO 6336-1), the largest load-sharing "
               "coefficient of its sun and ring mesh groups; a planet's factor: the largest "
               "coefficient of its meshes")
#: the planet table's columns (the factor's takes the definition)
PLANET_HEADER = ("carrier", "planet", "mesh groups", "factor ({definition})")
#: what a quasi-static sweep's planet table shows (K_gamma from the position-averaged
#: loads; the instantaneous peak in a column of its own)
PLANET_TEXT_STATIC = (
    "K_gamma of a stage: its largest planet load over the mean planet load, each planet's "
    "load averaged over the mesh positions (the mesh-load factor of AGMA 6123 / ISO "
    "6336-1), the largest over its sun and ring mesh groups; a planet's factor: the "
    "largest of its meshes; 'peak instantaneous ratio': the largest ratio at one mesh "
    "position (Mo et al. 2017), not K_gamma (it exceeds 1 for sequentially phased planets "
    "with equal mean loads)")


#: the line under the planet table of a peak-based definition, whose stage value is not
#: K_gamma (``{definition}``: the definition)
PLANET_TEXT_PEAK = (
    "planet load-sharing coefficient of a stage: the largest {definition} coefficient of "
    "its sun and ring mesh groups, peak forces with the dynamics in them; a planet's "
    "factor: the largest coefficient of its meshes.  K_gamma (the mesh-load factor of AGMA "
    "6123 / ISO 6336-1, a ratio of mean loads) is the stage value of --definition "
    "mean_force")


def is_k_gamma(k) -> bool:
    """Whether the stage value of ``k`` is the standards' K_gamma: the mean-force
    coefficient of a run, or a quasi-static sweep's (position-averaged loads); a
    peak-based definition's is that definition's planet coefficient."""
    return k.definition == "mean_force" or bool(k.peak_per_stage)


def planet_header(k) -> list[str]:
    """The planet table's columns for ``k``: a quasi-static one has the peak apart."""
    head = [h.format(definition=k.definition) for h in PLANET_HEADER]
    if k.peak_per_stage:
        head[3] = "K_gamma / factor (position-averaged loads)"
        head.append("peak instantaneous ratio")
    return head


def planet_text(k) -> str:
    """The line under the planet table."""
    if not is_k_gamma(k):
        return PLANET_TEXT_PEAK.format(definition=k.definition) + "."
    return (PLANET_TEXT_STATIC if k.peak_per_stage else PLANET_TEXT) + f" ({k.definition})."


def planet_sharing(load_sharing, kinematics):
    """K_gamma of every planetary stage of a load-sharing result
    (:func:`torquesplit.metrics.planetary.planet_load_sharing`, any definition), or None
    for a model without planets."""
    from .metrics.planetary import planet_load_sharing

    k = planet_load_sharing(load_sharing, kinematics)
    return k if k.per_stage else None


def planet_table(k, kinematics):
    """The planet table (K_gamma per stage, the factor per planet) as a rich Table."""
    from torquesplit._table import Table

    t = Table(title=f"planets (load sharing: {k.definition})")
    for i, col in enumerate(planet_header(k)):
        t.add_column(header(col), justify="right" if i >= 3 else "left")
    for row in planet_rows(k, kinematics):
        t.add_row(*row)
    return t


def planet_rows(k, kinematics) -> list[list[str]]:
    """Rows of the planet table: per stage (carrier) its K_gamma (a peak-based
    definition: its planet load-sharing coefficient) and the groups it is taken over,
    then each of its planets' factor."""
    rows = []
    peak = bool(k.peak_per_stage)
    label = ("K_gamma (stage)" if is_k_gamma(k)
             else f"planet load-sharing coefficient ({k.definition})")
    for carrier, value in k.per_stage.items():
        rows.append([carrier, label, ", ".join(k.groups[carrier]), f"{value:.4f}"]
                    + ([f"{k.peak_per_stage[carrier]:.4f}"] if peak else []))
        for planet in kinematics.carriers.get(carrier, ()):
            if planet in k.per_planet:
                rows.append(["", planet, "", f"{k.per_planet[planet]:.4f}"]
                            + ([f"{k.peak_per_planet[planet]:.4f}"] if peak else []))
    return rows


def planet_sharing_dict(k) -> dict:
    """The ``--json`` entry ``planet_load_sharing`` of a planetary model (commands leave
    the key out for a model without planets): the definition, K_gamma per stage (carrier),
    the factor per planet and the mesh groups of each stage."""
    # a quasi-static sweep's stage value is K_gamma of the position-averaged loads, and
    # its definition's own (the static torque ratio, peak over positions) is apart: the
    # 'definition' names what per_stage holds (it said static_torque over K_gamma)
    out = {"definition": "K_gamma" if k.peak_per_stage else k.definition,
           "per_stage": dict(k.per_stage),
           "per_planet": dict(k.per_planet), "groups": {c: list(g) for c, g in k.groups.items()}}
    if k.peak_per_stage:
        out["per_stage_basis"] = "loads averaged over the mesh positions (AGMA 6123 / ISO 6336-1)"
        out["peak_instantaneous_ratio"] = {"definition": k.definition,
                                           "per_stage": dict(k.peak_per_stage),
                                           "per_planet": dict(k.peak_per_planet)}
    return out
