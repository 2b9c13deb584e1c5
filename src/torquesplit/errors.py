"""Exceptions of torquesplit.

One base class; each subclass also derives from the matching built-in so that
``except ValueError`` (or ``except OSError`` for files) keeps working.  Every message
ends with what to do.  The CLI prints each line of the message as ``error: ...`` and
exits with status 2; ``--debug`` shows the traceback instead.

Messages quote values from the user's files, which can be anything: they quote at most
:data:`QUOTE_LIMIT` characters of a value, and :func:`clip_message` cuts whatever long
text still reaches a message, so that an error never echoes a 100 KB string whole.
"""

from __future__ import annotations

import contextlib
import contextvars
import re
from collections.abc import Iterator

#: longest quoted value (in characters) a message repeats from the input
QUOTE_LIMIT = 80

#: longest message line; longer lines keep their start and their end (the fix)
LINE_LIMIT = 1000

_LONG_WORD = re.compile(r"\S{%d,}" % (2 * QUOTE_LIMIT + 1))


def clip_text(text: str, limit: int = QUOTE_LIMIT) -> str:
    """``text`` shortened to ``limit`` characters, the cut marked with ``...``.

    Examples
    --------
    >>> clip_text("x" * 100, 10)
    'xxxxxxx...'
    """
    return text if len(text) <= limit else text[: max(limit - 3, 0)] + "..."


def clip_path(path, limit: int = QUOTE_LIMIT) -> str:
    """A path shortened to ``limit`` characters with the file's name kept whole (a
    message about a file must name it): the folders are cut, the cut marked ``...``.  A
    name that is itself too long keeps its end (its suffix and extension).

    Examples
    --------
    >>> clip_path("/tmp/" + "d" * 100 + "/run_history.csv", 40)
    '/tmp/dddddddddddddddd.../run_history.csv'
    >>> clip_path("/tmp/" + "n" * 100 + "_history.csv", 24)
    '...nnnnnnnnn_history.csv'
    """
    text = str(path)
    if len(text) <= limit:
        return text
    name = text.replace("\\", "/").rsplit("/", 1)[-1]
    if len(name) + 8 > limit:
        return "..." + text[len(text) - max(limit - 3, 1):]
    return text[: limit - len(name) - 4] + ".../" + name


def clip_message(message: str) -> str:
    """A message with every unbroken run of text over twice :data:`QUOTE_LIMIT`
    characters cut to that limit (its length noted), and each line at most
    :data:`LINE_LIMIT` characters long (its end, which says what to do, is kept).

    The code that quotes a value shortens it first (``units._short``); this is the
    safety net for values that reach a message some other way (a 100 KB name).

    Examples
    --------
    >>> clip_message("cannot read " + "1" * 10_000 + " as a length; write a number")[-60:]
    '1111111111... (10000 characters) as a length; write a number'
    """
    lines = []
    for line in message.split("\n"):
        line = _LONG_WORD.sub(lambda m: clip_text(m.group(), QUOTE_LIMIT)
                              + f" ({len(m.group())} characters)", line)
        if len(line) > LINE_LIMIT:
            line = line[: LINE_LIMIT // 2] + " ... " + line[-(LINE_LIMIT // 2 - 5):]
        lines.append(line)
    return "\n".join(lines)


class TorquesplitError(Exception):
    """Base class of every error raised on purpose by torquesplit."""


_PAIR_PREFIX = re.compile(r"^gears '[^']*' and '[^']*': ")
"""A mesh issue's prefix naming its pair (the location names the mesh too)."""


#: messages about a field itself, said once per field (never one line for several)
_OWN_PROBLEMS = ("required field is missing", "an item is missing")


class ModelError(TorquesplitError, ValueError):
    """A model file or model object is invalid.

    ``issues`` holds one entry per problem: ``(location, message)``, where location
    is the field path in the file (``meshes.m1.backlash``).  ``source`` names where the
    model came from: the file, or a ``--set`` argument.  Quoted values are shortened
    (:func:`clip_message`).
    """

    def __init__(self, issues, source: str | None = None, lines=None):
        if isinstance(issues, str):
            issues = [("", issues)]
        #: field path -> line of the source file (:func:`torquesplit.model.locate.
        #: key_lines`), where the source is a file: 'drive.toml:42: gears.a.module: ...'
        self.lines = lines
        self.issues = []
        seen = set()
        for loc, msg in issues:  # one problem found twice at one place is said once
            loc, msg = clip_text(str(loc), 2 * QUOTE_LIMIT), clip_message(str(msg))
            key = (loc, _PAIR_PREFIX.sub("", msg) if loc else msg)
            if key not in seen:
                seen.add(key)
                self.issues.append((loc, msg))
        self.source = source
        # one cause at several places (a profile shift that breaks every mesh of a gear
        # and the placement of its mates): one line naming the places
        # (not a field's own problem, which is no common cause: two missing fields in
        # two tables were one line with the first one's line number, a reviewer)
        groups: dict = {}
        for loc, msg in self.issues:
            core = _PAIR_PREFIX.sub("", msg) if loc else msg
            key = (core, loc if core.startswith(_OWN_PROBLEMS) else None)
            groups.setdefault(key, []).append((loc, msg))
        def where(loc: str) -> str:
            if not source:
                return ""
            line = None
            if lines and loc:
                from .model.locate import line_of

                line = line_of(lines, loc)
            return clip_text(source, 2 * QUOTE_LIMIT) + (f":{line}" if line else "") + ": "

        text = []
        for (core, _), members in groups.items():
            if len(members) == 1:
                loc, msg = members[0]
                text.append(where(loc) + (f"{loc}: " if loc else "") + msg)
                continue
            named = [loc for loc, _ in members if loc]
            first = named[0] if named else ""
            if len(named) > 10:
                named = named[:9] + [f"{len(named) - 9} more"]
            text.append(where(first) + (f"{', '.join(named)}: " if named else "") + core)
        super().__init__("\n".join(text))

    def located(self, text: str) -> "ModelError":
        """This error with the line of each field in ``text``, its source file's TOML
        (unchanged where the text cannot be scanned)."""
        from .model.locate import key_lines

        try:
            lines = key_lines(text)
        except Exception:  # noqa: BLE001 - a locator for messages: never hide the error
            return self
        return ModelError(self.issues, self.source, lines=lines)


class OptionError(TorquesplitError, ValueError):
    """A command-line option or function argument out of its range (``--count -1``)."""


class OptionTypeError(OptionError, TypeError):
    """A function argument of the wrong kind (a ``progress`` that is not callable)."""


class NoSuchExampleError(OptionError, FileNotFoundError):
    """No shipped example of that name (still a ``FileNotFoundError``, as it was)."""

    def __str__(self) -> str:  # (as OutputError: no "[Errno ...]")
        return str(self.args[0]) if self.args else ""


class OutputError(TorquesplitError, OSError):
    """Results cannot be written where asked: no such folder, a folder, a file that
    exists (and overwriting was not asked for), another run writing it, a full disk."""

    def __str__(self) -> str:  # OSError would print "[Errno ...]" for two arguments
        return str(self.args[0]) if self.args else ""


class MissingFileError(OutputError, FileNotFoundError):
    """A file to read is not there (``load_results('nope.nc')``): an
    :class:`OutputError` as every path problem is, and a :class:`FileNotFoundError`,
    which is what Python code that reads files catches (an exports review)."""


class OutputFormatError(OutputError, ValueError):
    """The output file's suffix names no format torquesplit writes (``.xlsx``)."""


class OutputBusyError(OutputError):
    """Another run holds the output path: exactly one of two writers may write it."""


class SolverError(TorquesplitError, RuntimeError):
    """A numerical analysis could not be carried out as asked."""


class StepTooLargeError(SolverError, ValueError):
    """The requested time step lies outside the integrator's stability region."""


class PeriodError(SolverError):
    """No common period of the excitations can be formed (frequencies without a rational
    ratio): a periodic steady state does not exist as asked."""


class LongPeriodError(PeriodError):
    """The common period holds too many cycles of the fastest excitation."""


class StudyError(TorquesplitError, ValueError):
    """A study file (or study dict) is invalid, or a study cannot be resumed.

    The message is one line: ``source: field: what is wrong; what to do``.
    ``field`` is the dotted location in the study file (``grid.parameters.0.start``).
    """

    def __init__(self, field: str, message: str, source: str | None = None, *,
                 more: list[tuple[str, str]] = ()):
        self.field = field
        self.source = source
        self.reason = message
        self.problems = [(field, message), *more]
        """Every problem found, ``(field, message)``: a bad study file is refused with all
        of them at once, one line each (the first is ``field`` and ``reason``)."""
        where = f"{source}: " if source else ""
        super().__init__("\n".join(where + (f"{f}: " if f else "") + m
                                   for f, m in self.problems))

    @classmethod
    def of(cls, problems: list[tuple[str, str]], source: str | None = None) -> "StudyError":
        """One error holding every problem of ``problems`` (in their order, each once)."""
        unique = list(dict.fromkeys(problems))
        return cls(*unique[0], source, more=unique[1:])

    def with_source(self, source: str | None) -> "StudyError":
        """The same error, naming the file it came from."""
        return StudyError.of(self.problems, source)


class SteadyInterrupted(TorquesplitError, KeyboardInterrupt):
    """A steady state was stopped (Ctrl-C) while its stability was computed, after the
    periodic state had converged: ``steady`` is that state
    (:class:`~torquesplit.steady.SteadyState`, its stability "interrupted").

    Also a :class:`KeyboardInterrupt`, so code that stops on Ctrl-C keeps doing so.
    """

    def __init__(self, steady):
        self.steady = steady
        super().__init__("stopped while the Floquet multipliers were computed; the "
                         "converged periodic state is kept (the exception's 'steady'), "
                         "its stability not computed")


class StudyInterrupted(TorquesplitError, KeyboardInterrupt):
    """A study was stopped (Ctrl-C) after committing the cases that had finished.

    Also a :class:`KeyboardInterrupt`, so code that stops on Ctrl-C keeps doing so.
    """

    def __init__(self, done: int, total: int, out: str | None):
        self.done = done
        self.total = total
        self.out = out
        again = (f"run the same command with --resume (or Study.run(out={out!r}, resume=True))"
                 if out else "give an output folder (out=...) to make a study resumable")
        super().__init__(f"study stopped after {done} of {total} cases, every finished case "
                         f"is saved; to finish it, {again}")


class FieldError(TorquesplitError, ValueError):
    """A check across fields of a model-file section that failed on one field.

    Raised inside a section's validator; :mod:`torquesplit.model.io` appends ``field``
    to the section's location, so that the message names ``gears.g1.hand``, not
    ``gears.g1`` (a ValueError, as pydantic validators require)."""

    def __init__(self, field: str, message: str, *, more: list[tuple[str, str]] = ()):
        super().__init__(message)
        self.field = field
        self.more = list(more)
        """Further problems of the same section, ``(field, message)``: a validator may
        raise only one error, and every problem is said at once."""

    @classmethod
    def of(cls, problems: list[tuple[str, str]]) -> "FieldError":
        """One error holding every problem of ``problems`` (the first as its own)."""
        return cls(*problems[0], more=problems[1:])


class KinematicsError(TorquesplitError, ValueError):
    """The layout or the power flow cannot be solved; carries ``issues``, a list of
    ``(location, message)``, which the model loader turns into a :class:`ModelError`."""

    def __init__(self, issues):
        self.issues = issues
        super().__init__("; ".join(f"{a}: {b}" for a, b in issues))


class FigureNotApplicableError(TorquesplitError, ValueError):
    """The results hold nothing this figure can show (no supports, no floating body...)."""


class GpuUnsupportedError(TorquesplitError, ValueError):
    """The GPU ensemble backend (:mod:`torquesplit.gpu`) does not do something a run
    needs: refused by name rather than computed differently from the CPU engine.
    ``feature`` names it."""

    def __init__(self, feature: str, fix: str):
        self.feature = feature
        super().__init__(f"the GPU backend does not support {feature} yet; {fix}")


class GpuUnavailableError(TorquesplitError, RuntimeError):
    """No CUDA device can run the GPU ensemble backend (``reason`` says why)."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"no CUDA device to run on: {reason}; run on a machine with an "
                         "NVIDIA GPU and its driver, or use the CPU backend "
                         "(backend='cpu', the default)")


class GpuFallbackWarning(UserWarning):
    """``backend="gpu"`` was asked for but no CUDA device is present: the study runs on
    the CPU runner instead (same results, CPU speed)."""


class ModelWarning(UserWarning):
    """A value that looks wrong but can be right (damping above critical, ...)."""


class CaseWarning(UserWarning):
    """A study case's run plausibility warning (too short to tell whether it settled,
    unsettled, resonance...): raised as a warning so that every runner that records a
    case's warnings (``study.case.run_case``, the GPU backend) records it."""


_COLLECTORS: contextvars.ContextVar[tuple[list, ...]] = contextvars.ContextVar(
    "torquesplit_model_warnings", default=())


@contextlib.contextmanager
def collect_model_warnings(pause: bool = False):
    """Keep the text of every :class:`ModelWarning` given inside the block in the list
    it yields, whatever the caller's warning filters (a run's record keeps the warnings
    a caller silenced: ``simulate`` under ``warnings.simplefilter("ignore")`` lost
    them).  ``pause``: the block's warnings are kept by no enclosing collector (a cached
    result records its warnings and gives them again, see :mod:`torquesplit._memo`)."""
    notes: list[str] = []
    token = _COLLECTORS.set(() if pause else _COLLECTORS.get() + (notes,))
    try:
        yield notes
    finally:
        _COLLECTORS.reset(token)


def note_warning(message, category: type[Warning] | None = None) -> None:
    """Enter a warning about to be given in the open :func:`collect_model_warnings`."""
    if category is None:
        category = type(message) if isinstance(message, Warning) else UserWarning
    if issubclass(category, ModelWarning):
        for notes in _COLLECTORS.get():
            notes.append(str(message))


def warn_user(message, category: type[Warning] | None = None) -> None:
    """``warnings.warn`` attributed to the line that called into torquesplit (a script's
    line, a notebook's cell): the caller of the outermost torquesplit frame on the stack,
    however deep in the library the warning arose (a fixed ``stacklevel`` named a line of
    torquesplit's own, ``simulation.py:131``; the first frame outside the package would
    name scipy's or numba's where they call back into it).  Where every frame is the
    package's (``python -m torquesplit``), its outermost frame."""
    import os
    import sys
    import warnings

    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame, level, outermost = sys._getframe(1), 2, 2
    while frame is not None:
        if os.path.abspath(frame.f_code.co_filename).startswith(package):
            outermost = level
        frame, level = frame.f_back, level + 1
    level = outermost + 1 if outermost + 1 < level else outermost
    note_warning(message, category)
    if category is None:
        warnings.warn(message, stacklevel=level)
    else:
        warnings.warn(message, category, stacklevel=level)


def from_interrupt(exc: BaseException | None) -> bool:
    """Whether a KeyboardInterrupt is in the chain of causes of ``exc`` (Ctrl-C that lands
    inside numba-compiled code comes back as SystemErrors chained from it)."""
    seen = 0
    while exc is not None and seen < 50:
        if isinstance(exc, KeyboardInterrupt):
            return True
        exc = exc.__cause__ or exc.__context__
        seen += 1
    return False


class HeldInterrupt:
    """What :func:`held_interrupt` saw: ``hit`` is True when a Ctrl-C came during its block
    (the object is as true as ``hit``; a study's SIGTERM and a serial run's SIGINT are
    noted in one too)."""

    hit: bool = False

    def __bool__(self) -> bool:
        return self.hit


#: the terminating signal that stopped the command as Ctrl-C does (SIGTERM, SIGHUP:
#: ``torquesplit._launch``), 0 for none
STOP_SIGNAL = [0]
#: the :func:`held_interrupt` blocks open where SIGINT is ignored (a background job):
#: there a SIGTERM or SIGHUP waits for the innermost, as a Ctrl-C would elsewhere
HOLDING: list = []


def interrupt_name() -> str:
    """What interrupted the computation, for its messages: 'Ctrl-C', or the signal that
    stopped the command ('SIGTERM', 'SIGHUP')."""
    import signal

    return signal.Signals(STOP_SIGNAL[0]).name if STOP_SIGNAL[0] else "Ctrl-C"


@contextlib.contextmanager
def held_interrupt() -> Iterator[HeldInterrupt]:
    """Within this block a Ctrl-C waits: the block runs to its end and the object yielded
    says whether one came, so that a computation can finish what the user would lose (a
    speed sweep's curve, a results file) and then stop.  A second Ctrl-C interrupts at
    once.  Main thread only (in a thread the block runs unguarded); in a job that
    ignores SIGINT, the SIGTERM or SIGHUP that stops the command (:mod:`torquesplit.
    _launch`) is held instead."""
    import signal
    import threading

    held = HeldInterrupt()
    current = (signal.getsignal(signal.SIGINT)
               if threading.current_thread() is threading.main_thread() else None)
    if current is None:  # a thread: unguarded
        yield held
        return
    if current == signal.SIG_IGN:  # not ours to change; a SIGTERM or SIGHUP is held
        HOLDING.append(held)  # all the same (torquesplit._launch)
        try:
            yield held
        finally:
            HOLDING.remove(held)
        return

    def later(signum, frame):
        if held.hit:
            raise KeyboardInterrupt
        held.hit = True

    before = signal.signal(signal.SIGINT, later)
    try:
        yield held
    finally:
        signal.signal(signal.SIGINT, before)
