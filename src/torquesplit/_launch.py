"""The ``torquesplit`` command's entry point: Ctrl-C while the command line loads (numpy,
numba, pydantic: about half a second) exits with one line and status 130, as it does
later, not with a traceback from inside an import (a fuzzer's 30-line pydantic one); an
option the parser refuses (``--steps-per-period abc``, an unknown option, a missing
argument) gets the commands' own ``error:`` line, and with ``--json`` their JSON
document on stdout, not a boxed panel and an empty stdout."""

from __future__ import annotations

import importlib
import re
import sys


def _exception_classes(name: str) -> tuple[type, ...]:
    """The parser's exception class ``name`` from click and from the copy of click that
    newer typer releases carry (``typer._click``), whichever exist."""
    found = []
    for module in ("typer._click.exceptions", "click.exceptions"):
        try:
            cls = getattr(importlib.import_module(module), name, None)
        except ImportError:
            continue
        if cls is not None and cls not in found:
            found.append(cls)
    return tuple(found)


def _options_starting(exc) -> list[str]:
    """The command's options that an unknown option abbreviates (``--steps`` for
    ``--steps-per-period``), which the parser's close-match list leaves out (a
    first-hour reviewer was offered --check-step, --max-steps, --set)."""
    name = getattr(exc, "option_name", None)
    ctx = getattr(exc, "ctx", None)
    command = getattr(ctx, "command", None)
    if not name or not name.startswith("--") or command is None:
        return []
    opts = {o for param in getattr(command, "params", ()) for o in getattr(param, "opts", ())}
    return sorted(o for o in opts if o.startswith(name) and o != name)


def usage_error_lines(exc) -> list[str]:
    """A parser's usage error as the lines the commands print: what is wrong, then what
    to run for help."""
    message = exc.format_message() if hasattr(exc, "format_message") else str(exc)
    longer = _options_starting(exc)
    if longer:
        near = sorted(set(getattr(exc, "possibilities", None) or ()) - set(longer))
        message = (f"No such option: {exc.option_name} (did you mean "
                   f"{' or '.join(longer)}?"
                   + (f" Close ones: {', '.join(near)}" if near else "") + ")")
    # "Invalid value for '--cycles': ..." in the commands' own form "--cycles: ..."
    message = re.sub(r"^Invalid value for '([^']+)': ", r"\1: ", message.strip())
    lines = [line.strip() for line in message.splitlines() if line.strip()]
    lines = lines or [type(exc).__name__]
    ctx = getattr(exc, "ctx", None)
    if ctx is not None:
        lines[-1] = f"{lines[-1].rstrip('.')}; '{ctx.command_path} --help' lists the options"
    return lines


def _stop_as_interrupt(signum, frame) -> None:
    """SIGTERM (a batch system's time limit, ``kill``, ``docker stop``) and SIGHUP (a
    closed terminal or ssh session) stop the command as Ctrl-C does: what it computed is
    kept, its files finished (a run's SIGTERM left no file and a lock behind, a
    reliability reviewer).  The SIGINT handler in force is called, so that a block that
    holds Ctrl-C (:func:`torquesplit.errors.held_interrupt`) holds these too; where SIGINT
    is ignored (a job started in the background) they raise KeyboardInterrupt
    themselves."""
    import signal

    from torquesplit.errors import HOLDING, STOP_SIGNAL

    STOP_SIGNAL[0] = signum
    handler = signal.getsignal(signal.SIGINT)
    if callable(handler):
        handler(signal.SIGINT, frame)
    elif HOLDING and not HOLDING[-1].hit:  # (SIGINT ignored, a file being finished)
        HOLDING[-1].hit = True
    else:  # (SIGINT ignored: a background job's, where SIGTERM is the way to stop it)
        raise KeyboardInterrupt


def _handle_stop_signals() -> None:
    """Install :func:`_stop_as_interrupt` for SIGTERM and SIGHUP where Python's defaults
    are (not where the caller chose to ignore them: ``nohup`` ignores SIGHUP)."""
    import signal

    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)  # (no SIGHUP on Windows)
        if sig is not None and signal.getsignal(sig) == signal.SIG_DFL:
            signal.signal(sig, _stop_as_interrupt)


def _exit_code(code: int) -> int:
    """An interrupted command's 130 as the shell's code of the signal that came
    (128 + its number: 143 for SIGTERM, 129 for SIGHUP)."""
    from torquesplit.errors import STOP_SIGNAL

    return 128 + STOP_SIGNAL[0] if code == 130 and STOP_SIGNAL[0] else code


def main() -> None:
    _handle_stop_signals()
    try:
        from torquesplit.cli import app
    except KeyboardInterrupt:
        sys.stderr.write("interrupted; nothing written\n")
        raise SystemExit(_exit_code(130)) from None
    usage = _exception_classes("UsageError")
    no_args = _exception_classes("NoArgsIsHelpError")
    abort = _exception_classes("Abort")
    try:
        code = app(standalone_mode=False, prog_name="torquesplit")
    except no_args as exc:  # a bare group or command: its help, as the parser shows it
        try:
            from typer import rich_utils

            rich_utils.rich_format_error(exc)
        except (ImportError, AttributeError):
            exc.show()
        raise SystemExit(exc.exit_code) from None
    except usage as exc:
        lines = usage_error_lines(exc)
        for line in lines:
            sys.stderr.write(f"error: {line}\n")
        if "--json" in sys.argv[1:]:
            from torquesplit import cli_support

            cli_support._session.json = True
            cli_support.emit_json_errors(lines)
        raise SystemExit(2) from None
    except abort:
        sys.stderr.write("interrupted\n")
        raise SystemExit(_exit_code(130)) from None
    except SystemExit as exc:  # (typer.Exit(130) of a command stopped by a signal)
        raise SystemExit(_exit_code(exc.code) if isinstance(exc.code, int) else
                         exc.code) from None
    raise SystemExit(_exit_code(code) if isinstance(code, int) else 0)
