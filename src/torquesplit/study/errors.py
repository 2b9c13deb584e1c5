"""Exceptions of the study layer (all derive from :class:`torquesplit.errors.TorquesplitError`)."""

from __future__ import annotations

from ..errors import TorquesplitError


class StudyError(TorquesplitError, ValueError):
    """A study file (or study dict) is invalid, or a study cannot be resumed.

    The message is one line: ``source: field: what is wrong; what to do``.
    ``field`` is the dotted location in the study file (``grid.parameters.0.start``).
    """

    def __init__(self, field: str, message: str, source: str | None = None):
        self.field = field
        self.source = source
        self.reason = message
        where = f"{source}: " if source else ""
        where += f"{field}: " if field else ""
        super().__init__(where + message)

    def with_source(self, source: str | None) -> "StudyError":
        """The same error, naming the file it came from."""
        return StudyError(self.field, self.reason, source)


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
