"""The ``torquesplit`` command's entry point: Ctrl-C while the command line loads (numpy,
numba, pydantic: about half a second) exits with one line and status 130, as it does
later, not with a traceback from inside an import (a fuzzer's 30-line pydantic one)."""

from __future__ import annotations

import sys


def main() -> None:
    try:
        from torquesplit.cli import app
    except KeyboardInterrupt:
        sys.stderr.write("interrupted; nothing written\n")
        raise SystemExit(130) from None
    app()
