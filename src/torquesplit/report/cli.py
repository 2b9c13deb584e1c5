"""The ``torquesplit report`` and ``torquesplit draw`` commands.

Registered on the main typer app by :mod:`torquesplit.cli` (:func:`register`).  Output
paths are checked before anything is computed and files are written atomically
(:mod:`torquesplit.results.files`); errors print one line and exit with status 2.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Optional

import typer

#: formats ``draw --out`` writes
DRAW_FORMATS = {".svg": "svg", ".png": "png", ".pdf": "pdf"}
#: formats ``report --out`` writes
REPORT_FORMATS = {".html": "html", ".htm": "html"}


def register(app, helpers) -> None:
    """Add ``draw`` and ``report`` to ``app``.

    ``helpers`` is :mod:`torquesplit.cli` (its ``_load``, ``_fail``, ``_flag``,
    ``_EXPECTED``, ``_MODEL_HELP``, ``_SET_HELP``, ``console``).
    """
    h = helpers
    from .. import cli_support as ux

    @app.command()
    def draw(
        model: str = typer.Argument(..., help=h._MODEL_HELP, metavar="MODEL"),
        out: Optional[Path] = typer.Option(None, "--out", help="Drawing file: .svg (default "
                                           "MODEL_NAME_layout.svg), .png or .pdf.",
                                           metavar="FILE"),
        force: bool = h._flag("--force", "Replace an existing file."),
        assign: Optional[list[str]] = typer.Option(None, "--set", help=h._SET_HELP,
                                                   metavar="PATH=VALUE"),
    ):
        """Draw the gearbox: pitch circles at their positions, lines of action and power
        flow of every mesh, shafts, splines, supports and clearances, names on everything,
        so that you see that the model is the gearbox you meant before running it."""
        from ..results import files

        with ux.interruptible():
            try:
                if out is not None:
                    files.check_output(out, formats=DRAW_FORMATS, overwrite=force,
                                       what="the drawing")
                m, _ = h._load(model, assign)
                target = out or Path(f"{_file_stem(m.model.name)}_layout.svg")
                plan = files.check_output(target, formats=DRAW_FORMATS, overwrite=force,
                                          what="the drawing")
                data = drawing_bytes(m, plan.format)
                files.write_atomically(plan.path, data, overwrite=force, formats=DRAW_FORMATS,
                                       what="the drawing")
            except h._EXPECTED as exc:
                h._fail(exc)
                return
        h.console.print(f"layout of {m.model.name} written to {plan.path}", highlight=False)

    @app.command()
    def report(
        source: str = typer.Argument(..., help="Model file, example name, or a results file "
                                     "(.nc) written by 'torquesplit run --out'.",
                                     metavar="MODEL|RESULTS.nc"),
        out: Optional[Path] = typer.Option(None, "--out", help="HTML file (default "
                                           "MODEL_NAME_report.html).", metavar="FILE"),
        force: bool = h._flag("--force", "Replace an existing file."),
        duration: Optional[str] = typer.Option(None, "--duration", help="For a model: "
                                               "simulated time (default the model's).",
                                               metavar="TIME"),
        cycles: Optional[int] = typer.Option(None, "--cycles", help="For a model: cycles of "
                                             "the slowest mesh.", metavar="N"),
        definition: Optional[str] = typer.Option(None, "--definition", help="Load-sharing "
                                                 "definition reported (see 'run --help').",
                                                 metavar="NAME"),
        assign: Optional[list[str]] = typer.Option(None, "--set", help=h._SET_HELP,
                                                   metavar="PATH=VALUE"),
        # (kept for scripts that pass it, out of --help: it can make no PDF)
        pdf: bool = typer.Option(False, "--pdf", hidden=True),
        quiet: bool = h._flag("--quiet", "No progress display."),
    ):
        """One self-contained HTML report to hand on: the model with units, its layout, the
        run's settings and provenance, the per-mesh table, load-sharing and dynamic-factor
        figures, natural modes, warnings and, for the shipped examples, the comparison with
        the paper.  Figures are inline SVG; the file needs no network."""
        from ..results import files

        state = {"written": None}
        with ux.interruptible(lambda: f"report kept in {state['written']}"
                              if state["written"] else ""):
            try:
                if out is not None:
                    files.check_output(out, formats=REPORT_FORMATS, overwrite=force,
                                       what="the report")
                h._check_definition(definition)
                res, path, attrs, quasi = _report_inputs(
                    h, ux, source, assign, duration, cycles, definition, quiet)
                target = out or Path(f"{_file_stem(res.model.model.name)}_report.html")
                plan = files.check_output(target, formats=REPORT_FORMATS, overwrite=force,
                                          what="the report")
                from .html import build_report

                chosen = definition or getattr(res, "saved_definition", None) or None
                with ux.progress("writing the report", quiet) as cb:
                    page = build_report(res, definition=chosen, source=path,
                                        results_attrs=attrs, quasi=quasi, progress=cb)
                files.write_atomically(plan.path, page.encode("utf-8"), overwrite=force,
                                       formats=REPORT_FORMATS, what="the report")
                state["written"] = plan.path
            except h._EXPECTED as exc:
                h._fail(exc)
                return
        h.console.print(f"report written to {plan.path}", highlight=False)
        if pdf:  # (it refused, and wrote no HTML either: an option that could never work)
            ux.warn(f"--pdf: no PDF written: torquesplit ships no HTML-to-PDF converter "
                    f"(none is pure Python); open {plan.path} in a browser and print it to "
                    f"PDF", label="note")


def drawing_bytes(model, fmt: str) -> bytes:
    """The layout drawing of ``model`` in ``fmt`` (svg, png, pdf) as bytes."""
    import io

    import matplotlib

    from ..plot.layout import layout_figure

    fig = layout_figure(model)
    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "layout"}):
        fig.savefig(buffer, format=fmt, dpi=150, bbox_inches="tight", pad_inches=0.1,
                    metadata={"Date": None} if fmt == "svg" else None)
    return buffer.getvalue()


def _file_stem(name: str) -> str:
    """A file-name-safe form of a model name."""
    import re

    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "model"
    return stem[:80]


def _report_inputs(h, ux, source, assign, duration, cycles, definition, quiet):
    """(Results, model file or None, results-file attributes or None, quasi-static sweep
    or None) for ``report SOURCE``: a results file is read back, a model is run."""
    path = Path(source)
    if path.suffix.lower() in (".mat", ".csv"):
        from ..errors import OptionError

        raise OptionError(f"{source}: 'report' reads the NetCDF results of 'torquesplit run "
                          f"--out F.nc' (the .mat and .csv exports leave out what the report "
                          f"needs); give the .nc file, or the model file to run it again")
    if path.suffix.lower() in (".nc", ".netcdf", ".h5"):
        from ..errors import OptionError
        from ..results import open_results
        from ..results.dataset import results_from_dataset
        from .html import results_attributes

        if assign or duration or cycles:
            raise OptionError("--set, --duration and --cycles apply to a model, not to a "
                              "results file; give the model file to run it again")
        if not path.is_file():
            raise OptionError(f"{source}: no such results file; give a .nc file written by "
                              f"'torquesplit run --out F.nc', or a model file")
        try:
            with ux.progress("reading the results", quiet, total=None):
                with open_results(path) as ds:
                    ds.load()
                    attrs = results_attributes(ds)
                    try:
                        res = results_from_dataset(ds)
                    except OptionError as exc:  # (another kind of file: say which one)
                        raise OptionError(f"{source}: {exc}") from None
        except (OSError, KeyError) as exc:
            raise OptionError(f"{source}: cannot read it as torquesplit results ({exc}); give "
                              f"a .nc file written by 'torquesplit run --out F.nc'") from None
        if not res.success:  # (its coefficients would be those of a part of the run)
            from ..errors import SolverError

            raise SolverError(f"{source}: the run stopped ({res.message}), so there is "
                              f"nothing to report; run the model again to the end")
        for note in res.model_warnings or []:
            ux.warn(note)
        return res, None, attrs, _quasi_if_static(res.model, ux, quiet)
    h._one_run_length(duration, cycles)
    m, model_path = h._load(source, assign)
    dur = ux.quantity(duration, "time", "--duration")
    h._positive(dur, "--duration", "'0.5 s'")
    h._at_least(cycles, 1, "--cycles", "200")
    from ..simulation import simulate

    with ux.collect_warnings(), ux.progress("integrating", quiet) as cb:
        res = simulate(m, duration=dur, cycles=cycles, progress=cb)
    res.model_warnings = [w for w in ux.session().warnings if w not in res.run_warnings]
    if not res.success:
        from ..errors import SolverError

        raise SolverError(f"the run stopped ({res.message}), so there is nothing to report; "
                          f"run 'torquesplit run {source}' to see why")
    chosen = h._run_definition(m, definition)
    from ..results.plausibility import result_warnings

    for loc, msg in result_warnings(res, res.metrics(chosen)):
        ux.warn(f"{loc}: {msg}")
    for text in h._near_critical(res):  # (as run says it, and in the report's warnings)
        res.run_warnings.append(text)
        ux.warn(text)
    return res, model_path, None, _quasi_if_static(m, ux, quiet)


def _quasi_if_static(model, ux, quiet):
    """The quasi-static sweep of a model whose definition is ``static_torque``."""
    if model.analysis.load_sharing not in ("static", "static_torque"):
        return None
    from ..errors import ModelWarning
    from ..quasistatic import quasi_static_load_sharing
    from ..results.plausibility import static_warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("ignore")
        warnings.simplefilter("always", ModelWarning)  # kept for the report, and said
        with ux.progress("quasi-static equilibria", quiet) as cb:
            quasi = quasi_static_load_sharing(model, progress=cb)
    said = list(dict.fromkeys(str(w.message) for w in caught
                              if issubclass(w.category, ModelWarning)))
    for text in said:
        ux.warn(text if "quasi-static" in text else f"quasi-static sweep: {text}")
    if said:
        quasi.kept_warnings = said + [f"{loc}: {msg}" for loc, msg in static_warnings(quasi)]
    return quasi
