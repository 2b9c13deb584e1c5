"""The study layer's exceptions, defined with every other one in :mod:`torquesplit.errors`
(re-exported here for the study modules)."""

from __future__ import annotations

from ..errors import StudyError, StudyInterrupted

__all__ = ["StudyError", "StudyInterrupted"]
