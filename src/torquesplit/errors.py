"""Exceptions of torquesplit.

One base class; each subclass also derives from the matching built-in so that
``except ValueError`` keeps working.  Every message ends with what to do.
The CLI prints the message on one line and exits with status 2.
"""

from __future__ import annotations


class TorquesplitError(Exception):
    """Base class of every error raised on purpose by torquesplit."""


class ModelError(TorquesplitError, ValueError):
    """A model file or model object is invalid.

    ``issues`` holds one entry per problem: ``(location, message)``, where location
    is the field path in the file (``meshes.m1.backlash``).
    """

    def __init__(self, issues, source: str | None = None):
        if isinstance(issues, str):
            issues = [("", issues)]
        self.issues = list(issues)
        self.source = source
        lines = []
        for loc, msg in self.issues:
            where = f"{source}: " if source else ""
            where += f"{loc}: " if loc else ""
            lines.append(where + msg)
        super().__init__("\n".join(lines))


class SolverError(TorquesplitError, RuntimeError):
    """A numerical analysis could not be carried out as asked."""


class StepTooLargeError(SolverError, ValueError):
    """The requested time step lies outside the integrator's stability region."""


class ModelWarning(UserWarning):
    """A value that looks wrong but can be right (damping above critical, ...)."""
