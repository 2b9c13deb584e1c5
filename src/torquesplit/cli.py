"""The ``torquesplit`` command line: one entry point, one sub-command per job.

Bad input prints one line naming the file, the field and the fix, and exits with
status 2; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import json
import math
import shutil
import sys
import warnings
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.table import Table

from .errors import ModelWarning, TorquesplitError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Dynamic load-sharing analysis of power-split gear transmissions.",
)
console = Console()
err_console = Console(stderr=True)

_state = {"debug": False}


@app.callback()
def _main(debug: bool = typer.Option(False, "--debug", help="Show tracebacks on errors.")):
    _state["debug"] = debug


def _fail(exc: BaseException) -> None:
    if _state["debug"]:
        raise exc
    msg = str(exc).strip() or exc.__class__.__name__
    err_console.print(f"[bold red]error:[/] {msg}", markup=True, highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def _resolve_model_path(model: str) -> Path:
    """A file path, or the name of a shipped example."""
    p = Path(model)
    if p.exists() or p.suffix in (".toml", ".json"):
        return p
    from .examples import example_names, example_path

    if model in example_names():
        return example_path(model)
    return p


def _load(model: str):
    from .model.io import load_model

    path = _resolve_model_path(model)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        m = load_model(path)
    for w in caught:
        if issubclass(w.category, ModelWarning):
            err_console.print(f"[yellow]warning:[/] {w.message}", highlight=False, soft_wrap=True)
    return m, path


# --------------------------------------------------------------------------- check
@app.command()
def check(
    model: str = typer.Argument(..., help="Model file (.toml/.json) or example name."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
):
    """Validate a model and print its kinematic and static summary."""
    try:
        from .model.summary import summary

        m, path = _load(model)
        s = summary(m)
    except TorquesplitError as exc:
        _fail(exc)
        return
    if as_json:
        print(json.dumps(s, indent=2))
        return
    from .model.summary import render_summary

    render_summary(s, console)


# --------------------------------------------------------------------------- examples
@app.command()
def examples():
    """List the shipped example models and the papers they come from."""
    from .examples import example_info, example_names

    t = Table(title="torquesplit examples")
    t.add_column("name", style="bold")
    t.add_column("description")
    t.add_column("reference")
    for name in example_names():
        info = example_info(name)
        t.add_row(name, info.get("description", ""), info.get("reference", ""))
    console.print(t)


@app.command()
def example(
    name: str = typer.Argument(..., help="Example name (see 'torquesplit examples')."),
    directory: Path = typer.Option(Path("."), "--dir", help="Folder to write the file to."),
    force: bool = typer.Option(False, "--force", help="Overwrite an existing file."),
):
    """Write an example model file to the current folder."""
    from .examples import example_path

    try:
        src = example_path(name)
    except FileNotFoundError as exc:
        _fail(TorquesplitError(f"{exc}; run 'torquesplit examples' to list them"))
        return
    dst = directory / src.name
    if dst.exists() and not force:
        _fail(TorquesplitError(f"{dst} exists; use --force to overwrite it"))
    directory.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dst)
    console.print(f"wrote {dst}")


def main():  # pragma: no cover - console entry point
    app()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
