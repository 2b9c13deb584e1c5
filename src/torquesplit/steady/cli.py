"""The ``steady`` and ``sweep-speed`` commands, and the Campbell part of ``modes``.

Registered on the main typer app by :mod:`torquesplit.cli` (:func:`register`).  Errors
print one line and exit with status 2 (the main CLI's ``_fail``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Optional

import typer
from torquesplit._table import Table
from torquesplit.cli_support import MESH_UNITS, OptionErrors, json_option
from torquesplit.errors import OptionError, interrupt_name

RPM = 60.0 / (2 * math.pi)


def _speed(text, what):
    """A speed option: '1200 rpm'; a bare number is rad/s (SI, as in model files)."""
    from torquesplit.cli_support import quantity

    return quantity(text, "speed", what)


def _speed_argument(text):
    """--speed for :func:`steady_state`: its text, whose unit the library judges (a speed
    in Hz far from the model's is said); a bare number with its unit written out, rad/s
    (the option has said so already: the library's bare-number warning would repeat it)."""
    if text is None:
        return None
    try:
        return f"{float(text)!r} rad/s"
    except ValueError:
        return text


def _speed_text(text) -> str:
    """An option's speed as given, with its unit: a bare number is rad/s."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        return str(text)
    return f"{value:g} rad/s ({value * RPM:.6g} rpm)"


def _check_out(path, formats=None, force=False):
    """Check an output path before computing (folder, suffix, an existing file: kept
    unless --force)."""
    from torquesplit.results import files

    if path is not None:
        from torquesplit.cli import _out_option

        _out_option(files.check_output, path, formats=formats, overwrite=force)


def _emit(data, json_default):
    from torquesplit.cli_support import emit_json

    emit_json(data, json_default)


def _h(text):
    from torquesplit.cli_support import header

    return header(text)


_API_TO_FLAGS = ((re.compile(r"keep='([^']*)'"), r"--keep \1"),
                 (re.compile(r"max_cycles=(\d+)"), r"--max-cycles \1"),
                 (re.compile(r"harmonics=(\d+)"), r"--harmonics \1"),
                 (re.compile(r"speed='([^']*)'"), r"--speed '\1'"),
                 (re.compile(r"method='(\w+)'"), r"--method \1"))


def _in_flags(exc):
    """The solver's message with its Python keywords (keep='stage1', max_cycles=4000) as
    the command's flags (--keep stage1, --max-cycles 4000); the same exception type."""
    from torquesplit.errors import TorquesplitError

    text = str(exc)
    new = text
    for pattern, flag in _API_TO_FLAGS:
        new = pattern.sub(flag, new)
    if new == text or not isinstance(exc, TorquesplitError):
        return exc
    try:
        return type(exc)(new)
    except TypeError:  # an error class with other arguments: the original
        return exc


#: what an unstable periodic state means for its numbers, by how it loses stability
_INSTABILITY = {
    "period doubling": "period doubling: a Floquet multiplier below -1, so the response "
                       "near this speed is an orbit of twice the period or longer with "
                       "other forces, not this one; 'torquesplit run' gives it, and "
                       "'steady' with --keep half the fundamental frequency solves for the "
                       "orbit of two periods",
    "fold": "a real Floquet multiplier above 1 (a fold: the middle of a jump): the "
            "response is on another branch; 'torquesplit sweep-speed' shows both",
    "torus": "a complex pair of Floquet multipliers outside the unit circle: the response "
             "is quasi-periodic, not this orbit; 'torquesplit run' gives it",
}


def _check_method(method: str) -> None:
    if method not in ("auto", "hb", "shooting"):
        raise OptionError(f"--method {method!r} is unknown; use auto, hb or shooting")


def _check_steps_per_cycle(steps_per_cycle) -> None:
    if steps_per_cycle is not None and steps_per_cycle < 10:
        raise OptionError(f"--steps-per-cycle must be at least 10 (e.g. 200), got "
                          f"{steps_per_cycle}")


def _check_count(value, option: str, example: str) -> None:
    if value is not None and value < 1:
        raise OptionError(f"{option} must be a whole number >= 1 (e.g. {example}), got {value}")


def _check_positive_speed(text, option: str, example: str):
    """The speed of an option [rad/s] (None if not given), refused unless positive."""
    if text is None:
        return None
    value = _speed(text, option)
    if not value > 0:
        raise OptionError(f"{option} must be a positive speed, e.g. {example}; got {text!r}")
    return value


def _keep(keep):
    """--keep: a name, or a frequency (a bare number in Hz, or a number with its unit)."""
    if keep is None:
        return None
    try:
        return float(keep)
    except ValueError:
        pass
    if re.match(r"\s*[-+]?(\d|\.\d)", keep):  # a number with a unit: a frequency
        from torquesplit.model.units import parse_quantity

        try:
            return parse_quantity(keep, "frequency")
        except ValueError as exc:
            raise OptionError(f"--keep {keep!r}: {exc}") from None
    return keep


def _harmonics_need_hb(harmonics, method: str) -> None:
    """--harmonics sets the harmonic balance: refused with --method shooting (it was
    ignored without a word)."""
    if harmonics is not None and method == "shooting":
        raise OptionError(f"--harmonics {harmonics} sets the harmonic balance; --method "
                          f"shooting integrates in time and takes none: leave one of them "
                          f"out (--method hb, or no --harmonics)")


def register(app, load, fail, console, err_console, json_default, set_help=""):
    """Add the commands to ``app`` (helpers of :mod:`torquesplit.cli` passed in; ``load``
    takes the model argument and the ``--set`` assignments)."""
    from torquesplit.errors import TorquesplitError, from_interrupt

    @app.command()
    def steady(
        model: str = typer.Argument(..., help="Model file (.toml/.json) or example name."),
        method: str = typer.Option(
            "auto", "--method", help="hb (harmonic balance), shooting, or auto: shooting unless "
            "--harmonics is given."),
        harmonics: Optional[int] = typer.Option(
            None, "--harmonics", help="HB harmonics of the fundamental (default: 8 per cycle "
            "of the fastest excitation, doubled until converged)."),
        adaptive: Optional[bool] = typer.Option(
            None, "--adaptive/--fixed", help="Double the harmonics until the top quarter holds "
            "< 1e-7 of the velocity energy (default unless --harmonics is given)."),
        keep: Optional[str] = typer.Option(
            None, "--keep", help="Keep only the excitations periodic with this stage, mesh, "
            "body or frequency [Hz, at --speed]; the others by their means."),
        speed: Optional[str] = typer.Option(
            None, "--speed", help="Input speed, e.g. '1200 rpm' (default the model's); the "
            "loads keep the model's torques (run --set drives.NAME.speed=... keeps its "
            "power instead)."),
        max_cycles: Optional[int] = typer.Option(
            None, "--max-cycles", help="Longest period accepted, in cycles of the fastest "
            "excitation (default 1000 for hb, 10000 for shooting and auto)."),
        stability: bool = typer.Option(
            True, "--stability/--no-stability", help="Floquet multipliers of the periodic "
            "state. Over a period of thousands of cycles the monodromy (2n variational "
            "columns) can take most of the run."),
        out: Optional[Path] = typer.Option(None, "--out", help="Write results (.nc, .mat, .csv)."),
        force: bool = typer.Option(False, "--force", help="Replace an existing --out file."),
        as_json: bool = json_option("Print the results as JSON."),
        steps_per_cycle: Optional[int] = typer.Option(
            None, "--steps-per-cycle", help="Shooting: RK4 steps per cycle of the fastest "
            "excitation (default 100, refined for the highest mode).", metavar="N"),
        check: bool = typer.Option(
            False, "--check-step", help="Solve again at half the RK4 step (harmonic "
            "balance: twice the harmonics) and report how many significant digits of "
            "every number hold."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress display."),
        assign: Optional[list[str]] = typer.Option(None, "--set", help=set_help,
                                                   metavar="PATH=VALUE"),
    ):
        """Periodic steady state at one speed: per-mesh table, residual, harmonics, stability."""
        try:
            opts = OptionErrors(load)
            opts(_check_method, method)
            opts(_check_steps_per_cycle, steps_per_cycle)
            for value, option, example in ((max_cycles, "--max-cycles", "10000"),
                                           (harmonics, "--harmonics", "16")):
                opts(_check_count, value, option, example)
            opts(_check_positive_speed, speed, "--speed", "'3000 rpm'")
            opts(_check_out, out, force=force)
            opts(_harmonics_need_hb, harmonics, method)
            opts.raise_any(model, assign)
            from torquesplit.steady.api import steady_state

            m, _ = load(model, assign)
            from torquesplit.cli_support import collect_warnings, interruptible, progress

            # (Ctrl-C exited 130 without a word)
            from torquesplit.errors import SteadyInterrupted

            stopped = False  # (Ctrl-C in the stability: the converged state is kept)
            with interruptible(), collect_warnings(), progress(
                    "periodic steady state", as_json or quiet, total=None) as update:
                try:
                    # (a speed with its unit as text, so that the unit is judged)
                    st = steady_state(m, method=method, harmonics=harmonics,
                                      adaptive=adaptive, keep=_keep(keep),
                                      speed=_speed_argument(speed),
                                      max_cycles="auto" if max_cycles is None else max_cycles,
                                      stability=stability, steps_per_cycle=steps_per_cycle,
                                      progress=update)
                except SteadyInterrupted as exc:
                    st, stopped, check = exc.steady, True, False  # (no step check either)
            # (a Ctrl-C after the solve exited 130 without a word, and during the step
            # check said 'nothing written' with the results file complete: a reviewer)
            from torquesplit.cli_support import kept_files

            saved = None
            with interruptible(lambda: kept_files(saved)):
                res = st.to_results()
                if st.solution.converged:  # what the results say, as 'run' prints it
                    from torquesplit.cli_support import warn
                    from torquesplit.results.plausibility import result_warnings

                    for loc, msg in result_warnings(res, res.metrics()):
                        warn(f"{loc}: {msg}")
                    for note in st.critical_notes():  # (as 'run' says it, at this speed)
                        warn(note)
                if speed is not None:  # (run at a --set speed keeps the power: forces 14 % apart
                    # at 3425 rpm on the tutorial's drive, neither saying which it held)
                    from torquesplit.cli_support import warn

                    warn("--speed: the loads keep the model's torques (forces as at its own "
                         "speed; 'run --set drives.NAME.speed=...' keeps its power instead)",
                         label="note")
                rows = st.mesh_table(results=res)
                if out is not None:  # (every file named where the save is reported; a Ctrl-C
                    # waits for it, then names it)
                    from torquesplit.cli_support import finish_before_interrupt
                    from torquesplit.results.files import RESULT_FORMATS, companion_files

                    with finish_before_interrupt():
                        path = res.save(out, overwrite=force)
                        saved = list(companion_files(path,
                                                     RESULT_FORMATS[path.suffix.lower()]))
                step_check = None
                if check:
                    from torquesplit.convergence import check_steady

                    with collect_warnings(), progress(
                            "checking the resolution", as_json or quiet, total=None) as update:
                        step_check = check_steady(st, progress=update)
        except (TorquesplitError, ValueError, OSError) as exc:
            fail(_in_flags(exc))
            return
        ps = st.solution
        mu = ps.multipliers
        from torquesplit.cli_support import warn
        from torquesplit.steady.sweep import instability

        # (an orbit of a fraction of the period asked for: its multipliers are powers of
        # the shorter orbit's, which do not tell how that one loses stability)
        kind = instability(mu) if ps.converged and ps.repeats_within == 1 else ""
        if not ps.converged:
            warn(f"the periodic state did not converge ({ps.message}): its numbers are "
                 f"those of the last iterate; try --method hb, more --steps-per-cycle, or "
                 f"'torquesplit run' (contact loss makes shooting harder to converge"
                 f"{_friction_hint(m)})")
        elif kind and as_json:
            warn(_INSTABILITY[kind])
        # the period found at the model's speeds, told at the speed solved
        period_text = st.period.describe(ps.frequency / st.period.frequency)
        from torquesplit.cli_support import planet_sharing, planet_sharing_dict

        # a planetary stage: K_gamma over the period, as 'run' gives it
        planets = (planet_sharing(res.metrics().load_sharing, st.kinematics)
                   if ps.converged else None)
        info = {
            **st.summary(rows, results=res), "instability": kind or None,
            **({"planet_load_sharing": planet_sharing_dict(planets)} if planets else {}),
            **({} if ps.converged else {"stable": None}),
            "results_file": str(saved[0]) if saved else None,
            "results_files": [str(f) for f in saved or []],
            **({"step_check": step_check.to_dict()} if step_check else {}),
            # SI (the table prints kN and µm), of exactly the keys the rows have
            "units": {k: u for k, u in MESH_UNITS.items()
                      if any(k in r.__dict__ for r in rows)},
        }
        if as_json:
            _emit(info, json_default)
        else:
            console.print(f"[bold]{m.model.name}[/]: {ps.message}")
            console.print(period_text)
            if st.dropped:
                console.print("kept excitations periodic with the base; replaced by their "
                              "means: " + "; ".join(st.dropped_text())
                              + ": the rows of those meshes leave out their own excitation",
                              highlight=False)
            if ps.method == "hb":  # three independent checks
                console.print(
                    f"residual {ps.residual:.2e}, time-domain: midpoint residual "
                    f"{ps.time_residual:.2e}, one-period integration defect "
                    f"{ps.periodicity_defect:.2e}"
                    + (f"; harmonics {ps.harmonics} (top-quarter energy "
                       f"{ps.top_harmonic_energy:.1e})" if ps.harmonics else ""))
            else:  # (shooting's residual is its one-period defect: one number, said once)
                console.print(f"one-period integration defect {ps.residual:.2e} (the "
                              f"shooting residual: the state after one period against the "
                              f"start, over the largest deformation)", highlight=False)
            if not ps.converged:
                console.print("stability: not meaningful (the periodic state did not "
                              "converge; the table is the last iterate's)")
            elif mu is not None:
                state = ("stable, but only marginally (a multiplier on the unit circle: a "
                         "mode without damping, see the warning; any change can make it "
                         "unstable)" if ps.marginal else "stable" if ps.stable else "UNSTABLE")
                console.print(f"stability ({ps.stability_method}): {state}, largest Floquet "
                              f"multiplier |mu| = {abs(mu[0]):.6g}", highlight=False)
                if kind:
                    console.print(f"[yellow]{_INSTABILITY[kind]}[/]"
                                  + (f" (--keep {ps.frequency / 2:.9g})"
                                     if kind == "period doubling" else ""), highlight=False)
            elif not stability:
                console.print("stability: not computed (--no-stability)")
            elif ps.stability_method == "interrupted":
                console.print(f"stability: not computed (interrupted by {interrupt_name()} "
                              f"while the Floquet multipliers were computed)")
            t = Table(title="meshes (periodic steady state)" if ps.converged else
                      "meshes: NOT CONVERGED (the last Newton iterate, not a periodic "
                      "state)")
            chosen = m.analysis.load_sharing  # mesh_table()'s (Results.default_definition)
            chosen = "mean_force" if chosen == "static_torque" else chosen
            # the columns and digits of run's mesh table (6 digits here did not hold: the
            # sun and ring mean forces of one planet differed in the 5th, equally loaded
            # planets' factors in the 5th decimal; the JSON and the files keep them all)
            for col in ("mesh", "group", "nominal F\n[kN]", "static F\n[kN]",
                        "mean F\n[kN]", "peak F\n[kN]", "dynamic\nfactor",
                        "peak/\nnominal", f"LSC\n({chosen})", "RMS TE\n[µm]",
                        "contact\nloss"):
                t.add_column(_h(col), justify="left" if col in ("mesh", "group") else "right")
            def cell(x, fmt):  # (an undefined number, as the JSON's null: no 'inf')
                return format(x, fmt) if math.isfinite(x) else "-"

            for r in rows:
                t.add_row(r.mesh, r.group, cell(r.nominal_force / 1e3, "#.5g"),
                          cell(r.static_force / 1e3, "#.5g"),
                          cell(r.mean_force / 1e3, "#.5g"), cell(r.peak_force / 1e3, "#.5g"),
                          cell(r.dynamic_factor, ".4f"), cell(r.peak_to_nominal, ".4f"),
                          cell(r.load_sharing, ".4f"),
                          cell(1e6 * r.rms_transmission_error, "#.4g"),
                          cell(100 * r.contact_loss, ".2f") + " %")
            console.print(t)
            if planets:
                from torquesplit.cli_support import planet_table, planet_text

                console.print(planet_table(planets, st.kinematics))
                console.print(planet_text(planets), markup=False, highlight=False)
            console.print("RMS TE: root mean square over the period of the dynamic "
                          "transmission error about its mean, along the line of action: the "
                          "relative displacement of the flanks, elastic deflection and "
                          "errors (tooth modifications, eccentricities) together, as a "
                          "transmission-error measurement gives it", highlight=False)
            if step_check is not None:
                from torquesplit.cli_support import render_step_check

                render_step_check(step_check, printed=6,
                                  refine="--harmonics" if ps.method == "hb" else
                                  "--steps-per-cycle")
            if saved:
                console.print("results written to " + ", ".join(str(f) for f in saved),
                              highlight=False)
        if stopped:  # the state printed and written, then the command stops as asked
            from torquesplit.cli_support import exit_interrupted

            exit_interrupted(kept_files(saved) or "the periodic state is printed above; "
                                                  "nothing written")
        if not ps.converged:
            raise typer.Exit(1)

    @app.command("sweep-speed")
    def sweep_speed_cmd(
        model: str = typer.Argument(..., help="Model file (.toml/.json) or example name."),
        start: str = typer.Option(..., "--from", help="First speed, e.g. '500 rpm' (the "
                                  "loads keep the model's torques at every speed)."),
        stop: str = typer.Option(..., "--to", help="Last speed, e.g. '3000 rpm'."),
        points: int = typer.Option(
            50, "--points", help="Points over the range to start from: the step is the "
            "range / (points - 1), grows to at most twice that where the response is "
            "smooth and shrinks where it changes fast, so the curve has at least about half "
            "this many points; a peak narrower than the step is "
            "missed: give more, or --max-step, for narrow resonances."),
        method: str = typer.Option(
            "auto", "--method", help="shooting (one monodromy per point), hb (harmonic "
            "balance), or auto: shooting unless --harmonics is given."),
        harmonics: Optional[int] = typer.Option(
            None, "--harmonics", help="HB harmonics (default: as 'steady' chooses them at the "
            "first speed, then kept along the curve)."),
        keep: Optional[str] = typer.Option(None, "--keep", help="As for 'steady' (a frequency "
                                           "in Hz is at the model file's speed)."),
        max_cycles: int = typer.Option(
            1000, "--max-cycles", help="Longest period accepted, in cycles of the fastest "
            "excitation (default 1000 for every method; 'steady' accepts 10000 for "
            "shooting and auto)."),
        no_stability: bool = typer.Option(False, "--no-stability",
                                          help="Skip the Floquet multipliers."),
        cross_check: bool = typer.Option(False, "--cross-check",
                                         help="Also run-up and run-down time integrations."),
        max_step: Optional[str] = typer.Option(
            None, "--max-step", help="Largest continuation step in speed, e.g. '5 rpm' "
            "(default: twice the initial spacing).", metavar="SPEED"),
        steps_per_cycle: Optional[int] = typer.Option(
            None, "--steps-per-cycle", help="Shooting: RK4 steps per cycle of the fastest "
            "excitation (default 100, refined for the highest mode).", metavar="N"),
        out: Optional[Path] = typer.Option(None, "--out", help="Write the curves: .nc, .mat or "
                                           ".csv (a row per speed)."),
        plot: Optional[Path] = typer.Option(None, "--plot", help="Write the figure (.png, .svg, "
                                            ".pdf or another format matplotlib writes)."),
        force: bool = typer.Option(False, "--force", help="Replace existing --out / --plot "
                                   "files."),
        as_json: bool = json_option("Print a summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress display."),
        assign: Optional[list[str]] = typer.Option(None, "--set", help=set_help,
                                                   metavar="PATH=VALUE"),
    ):
        """Speed response by continuation: dynamic factor, load sharing, RMS TE vs speed."""
        try:
            from torquesplit.results.export import check_dataset_output
            from torquesplit.steady.maps import sweep_speed

            opts = OptionErrors(load)
            opts(_check_method, method)
            opts(_check_steps_per_cycle, steps_per_cycle)
            opts(_check_count, points, "--points", "50")
            opts(_check_count, harmonics, "--harmonics", "16")
            opts(_harmonics_need_hb, harmonics, method)
            opts(_check_count, max_cycles, "--max-cycles", "1000")
            for text, option in ((start, "--from"), (stop, "--to")):
                opts(_check_positive_speed, text, option, "'1000 rpm'")
            step = opts(_check_positive_speed, max_step, "--max-step", "'5 rpm'")
            if out is not None:  # (the CSV tables: per speed, per run-up/-down speed)
                from torquesplit.cli import _out_option

                opts(_out_option, check_dataset_output, out, ("point", "check"),
                     overwrite=force)
            if plot is not None:
                from torquesplit import cli as ui  # (every figure option takes the same)

                opts(ui._check_figure_file, plot, "--plot", force)
            opts.raise_any(model, assign)
            m, _ = load(model, assign)
            from torquesplit.cli_support import (
                collect_warnings,
                exit_interrupted,
                finish_before_interrupt,
                interruptible,
                kept_files,
                progress,
            )

            # (Ctrl-C before the first point exited 130 without a word)
            with interruptible(), collect_warnings(), progress("speed sweep",
                                                              as_json or quiet, total=None):
                ds = sweep_speed(m, _speed(start, "--from"), _speed(stop, "--to"),
                                 points=points, harmonics=harmonics, keep=_keep(keep),
                                 max_cycles=max_cycles, stability=not no_stability,
                                 cross_check=cross_check, method=method, max_step=step,
                                 steps_per_cycle=steps_per_cycle)
        except (TorquesplitError, ValueError, OSError) as exc:
            fail(_in_flags(exc))
            return
        # (Ctrl-C: the curve is kept. A sweep stopped part-way exited 1 as any stop, not
        # 130; one in the check of the peaks' digits exited 0)
        interrupted = str(ds.attrs["message"]).startswith("interrupted")
        saved, failed, plotted = None, None, []

        def kept() -> str:
            # (it said 'the curve computed is printed above', where only its largest
            # dynamic factors are, a reliability reviewer; --json holds the points)
            return kept_files([*(saved or []), *plotted]) or (
                f"nothing written: the curve's {int(ds.sizes['point'])} points are kept only "
                f"by --out (their largest dynamic factors are printed above"
                f"{'' if as_json else '; --json prints every point'})")

        try:  # a file that cannot be written: the curves are still printed, then the error
            with finish_before_interrupt():  # (a Ctrl-C: the files are finished, the curve
                # printed, then the command stops)
                if out is not None:
                    from torquesplit.results.export import dataset_files

                    saved = dataset_files(ds, _save(_with_model(ds, m), out, force))
                if plot is not None:
                    from torquesplit.steady.plot import save, sweep_figure

                    plotted = [save(sweep_figure(ds), plot)]
        except (TorquesplitError, OSError) as exc:
            failed = exc
        except KeyboardInterrupt:
            interrupted = True
        largest = sweep_maxima(ds)
        held = {}
        try:  # (Ctrl-C here keeps the curve: it is printed without the check; a sweep
            # already interrupted is not made to wait for it)
            if not interrupted:
                with collect_warnings(), progress("checking the peaks' digits",
                                                  as_json or quiet, total=None):
                    held = peak_resolution(m, ds, largest, keep=_keep(keep),
                                           max_cycles=max_cycles)
        except (KeyboardInterrupt, SystemError) as exc:
            if not from_interrupt(exc):
                raise
            interrupted = True
            err_console.print("[yellow]warning:[/] the check of the peaks' digits was "
                              f"interrupted ({interrupt_name()}): the largest dynamic "
                              "factors are printed unchecked")
        summary = {
            "model": ds.attrs["model"], "points": int(ds.sizes["point"]),
            # the curve itself (a script had only its maxima without a file)
            "curve": {"speed_rpm": ds["speed_rpm"].values.tolist(),
                      "dynamic_factor": {str(k): ds["dynamic_factor"].sel(mesh=k).values
                                         .tolist() for k in ds["mesh"].values}},
            "complete": bool(ds.attrs["complete"]), "message": ds.attrs["message"],
            "fold_speeds_rpm": ds.attrs["fold_speeds_rpm"],
            "critical_speeds_rpm": ds.attrs["critical_speeds_rpm"],
            "max_dynamic_factor": {k: v["stable"][0] for k, v in largest.items()},
            "max_dynamic_factor_speed_rpm": {k: v["stable"][1] for k, v in largest.items()},
            "max_dynamic_factor_of": "the stable points of the branch (unstable ones are "
                                     "not observable)",
            # the same at its speed with twice the resolution, and the digits that hold
            "max_dynamic_factor_at_half_step": {k: v["halved"] for k, v in held.items()},
            "max_dynamic_factor_digits": {k: v["digits"] for k, v in held.items()},
            "unstable_points": (int((~ds["stable"].values).sum()) if "stable" in ds
                                else None),
            "marginal_points": _marginal(ds),
            "unresolved_peaks": unresolved_peaks(ds),
            "period_doubling_rpm": (_runs(ds, ds["instability"].values == "period doubling")
                                    if "instability" in ds else []),
            "max_contact_loss": _largest_loss(ds),
            "wall_time_s": ds.attrs["wall_time_s"],
            "results_file": str(saved[0]) if saved else None,
            "results_files": [str(f) for f in saved or []],
            "figure_files": [str(f) for f in plotted],
            # (the sweep's load sharing: these two, whatever the model's definition)
            "load_sharing_definitions": ["mean_force", "instantaneous"],
        }
        chosen = m.analysis.load_sharing
        other = (f"load sharing over speed: the mean-force coefficient (Dong et al. 2021 eq. "
                 f"12, 'load_sharing_mean_force' in the files) and the largest instantaneous ratio (Ji "
                 f"& Li eq. 18); the model's definition {chosen!r} is not computed by the "
                 f"sweep: 'torquesplit steady --speed S' gives it at a speed"
                 if chosen not in (None, "mean_force", "instantaneous", "static",
                                   "static_torque") else None)
        checked = cross_check and "run_up_dynamic_factor" in ds  # (not when interrupted)
        if checked:
            for key in ("run_up", "run_down"):
                summary[f"{key}_max_dynamic_factor"] = {k: v[key][0]
                                                        for k, v in largest.items()}
                summary[f"{key}_max_dynamic_factor_speed_rpm"] = {
                    k: v[key][1] for k, v in largest.items()}
        if as_json:
            _emit(summary, json_default)
        else:
            console.print(f"[bold]{summary['model']}[/]: {summary['points']} points, "
                          f"{ds.attrs['message']} ({summary['wall_time_s']:.3g} s)")
            if summary["fold_speeds_rpm"]:
                console.print("turning points (jump speeds): " + ", ".join(
                    f"{f:.5g} rpm ({k})" for f, k in zip(summary["fold_speeds_rpm"],
                                                        ds.attrs["fold_kinds"], strict=True)))
            rpm = ds["speed_rpm"].values
            # (a sweep that stopped part-way: its largest factor is of the part computed,
            # and a reviewer read 1.86 where the run-up found 2.95 beyond the stop)
            part = ("" if ds.attrs["complete"] or not rpm.size else
                    f", over the part computed ({np.nanmin(rpm):.5g}-{np.nanmax(rpm):.5g} rpm"
                    f" of {_speed_text(start)}-{_speed_text(stop)}: the sweep stopped)")
            t = Table(title=("largest dynamic factor of the sweep (stability not computed)"
                             if no_stability else
                             "largest dynamic factor over the stable points of the sweep")
                          + part + (" and the time integrations" if checked else ""))
            cols = ["mesh", "dynamic factor\n(peak/static)", "at [rpm]"]
            cols += ["run-up DF", "at [rpm]", "run-down DF", "at [rpm]"] if checked else []
            for col in cols:
                t.add_column(_h(col))
            for k, v in largest.items():
                cells = [k] + [c for key in ("stable", "run_up", "run_down")
                               if key in v for c in (f"{v[key][0]:.5f}", f"{v[key][1]:.6g}")]
                if k in held:  # (to the digits that hold: 2.9 where 2.89820 was computed)
                    cells[1] = _held_text(v["stable"][0], held[k]["digits"])
                if "stable" in v:  # (a point of the curve: its speed to the points' spacing)
                    cells[2] = _speed_at_text(v["stable"][1], rpm)
                t.add_row(*cells)
            console.print(t)
            if held:
                console.print(
                    "DF to the digits that hold when the peak is solved again at its speed "
                    "with twice the resolution (half the RK4 step, or twice the harmonics; "
                    "the files keep every digit): " + ", ".join(
                        f"{k} {largest[k]['stable'][0]:.5f} -> {h['halved']:.5f}"
                        for k, h in held.items()), highlight=False)
            dropped = ds.attrs.get("dropped_excitations") or []
            if dropped:
                console.print("kept excitations periodic with the base; replaced by their "
                              "means: " + "; ".join(dropped) + ": the rows of those meshes "
                              "leave out their own excitation (run 'steady' without --keep "
                              "at a speed for their full response)", highlight=False)
            if no_stability:
                console.print("stability: not computed (--no-stability): every point is "
                              "taken, an unstable one too")
            else:
                console.print(f"unstable points: {summary['unstable_points']} (dashed in the "
                              f"figure; left out of the largest dynamic factor)")
                if summary["marginal_points"]:
                    console.print(
                        f"[yellow]marginally stable points: {summary['marginal_points']}[/] "
                        f"(a Floquet multiplier on the unit circle: a mode without damping, "
                        f"see the warning); their dynamic factors are those of an undamped "
                        f"resonance, not a design value", highlight=False)
            for a, b in summary["period_doubling_rpm"]:
                where = f"at {a:.6g}" if a == b else f"between {a:.6g} and {b:.6g}"
                console.print(f"[yellow]period doubling[/] {where} rpm (a "
                              f"Floquet multiplier below -1): the response there is not on "
                              f"this curve but an orbit of twice the period or longer, with "
                              f"other forces; 'torquesplit run' at those speeds gives it")
            coarse = unresolved_peaks(ds)
            if coarse:  # (the curve's points may straddle its peak)
                console.print(f"[yellow]peaks not resolved:[/] {', '.join(coarse)}: the "
                              f"largest dynamic factor can lie between the points; give "
                              f"more --points (or a smaller --max-step) around it",
                              highlight=False)
            lost = {k: v for k, v in summary["max_contact_loss"].items() if v[0] > 0}
            if lost:
                console.print("contact loss on the stable points: " + ", ".join(
                    f"{k} up to {100 * v[0]:.3g} % of the period (at {v[1]:.6g} rpm)"
                    for k, v in lost.items()), highlight=False)
            if other:
                console.print(other, highlight=False)
            if saved or plotted:  # (the figure was written without a word)
                console.print("results written to " + ", ".join(
                    str(f) for f in [*(saved or []), *plotted]), highlight=False)
        if failed is not None:
            fail(failed)
            return
        if interrupted:
            exit_interrupted(kept())
        if not ds.attrs["complete"]:
            err_console.print(f"[yellow]warning:[/] {ds.attrs['message']}")
            raise typer.Exit(1)


import numpy as np  # noqa: E402  (used by the commands above)


def _speed_at_text(at: float, rpm) -> str:
    """The speed of a curve's largest point, to the spacing of the points beside it (the
    peak lies somewhere between them: a reviewer saw 2615.38 rpm become 2615.01 with
    more points): '2615 ± 2'."""
    import math

    speeds = np.unique(np.asarray(rpm, dtype=float)[np.isfinite(rpm)])
    i = int(np.argmin(np.abs(speeds - at)))
    gaps = [abs(speeds[j] - speeds[i]) for j in (i - 1, i + 1) if 0 <= j < speeds.size]
    if not gaps or max(gaps) <= 0.0:
        return f"{at:.6g}"
    width = max(gaps)
    places = max(0, -math.floor(math.log10(width)))
    return f"{at:.{places}f} ± {width:.{places}f}"


def _held_text(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant digits (at most 6), trailing zeros kept ('2.9',
    '1.0800'); fewer than 2 that hold: 3 digits marked unresolved (the heading says the
    digits printed hold)."""
    import math

    if digits < 2:
        return f"{value:#.3g} (unresolved)"
    d = min(6, digits)
    places = max(0, d - 1 - math.floor(math.log10(abs(value)))) if value else d - 1
    return f"{value:.{places}f}"


def _marginal(ds) -> int:
    """Stable points whose largest Floquet multiplier is within MARGINAL_TOL of 1."""
    from torquesplit.steady.solution import MARGINAL_TOL

    if "max_multiplier" not in ds:
        return 0
    mu = np.asarray(ds["max_multiplier"].values, float)
    from torquesplit.steady.maps import counted_points

    stable = counted_points(ds)
    return int((stable & (mu >= 1 - MARGINAL_TOL)).sum())


def _runs(ds, flag) -> list[list[float]]:
    """[first, last] speed [rpm] of each run of consecutive points where ``flag``."""
    from torquesplit.steady.sweep import flag_runs

    rpm = np.asarray(ds["speed_rpm"].values, float)
    return [[float(rpm[a]), float(rpm[b])] for a, b in flag_runs(flag)]


def _largest_loss(ds) -> dict[str, list[float]]:
    """Per mesh, the largest contact-loss fraction over the stable points and its speed
    [rpm] ([0, None] without one)."""
    from torquesplit.steady.maps import counted_points

    stable = counted_points(ds)
    rpm = np.asarray(ds["speed_rpm"].values, float)[stable]
    out = {}
    for j, k in enumerate(ds["mesh"].values):
        loss = np.asarray(ds["contact_loss"].values[:, j], float)[stable]
        i = int(np.argmax(loss)) if loss.size else -1
        out[str(k)] = [float(loss[i]), float(rpm[i])] if i >= 0 else [0.0, None]
    return out


#: a sweep's largest dynamic factor whose neighbouring points are lower by more than this
#: share of its dynamic increment (DF - 1) is said to be unresolved (:func:`unresolved_peaks`)
PEAK_RESOLUTION = 0.02


def unresolved_peaks(ds) -> list[str]:
    """Meshes whose largest stable dynamic factor is an interior point with both
    neighbours lower by more than :data:`PEAK_RESOLUTION` of its dynamic increment: the
    true peak can lie between the points (a reviewer's 8-point sweep put the peak at
    585.7 rpm, 1.09915, its neighbours 5.6 % of the increment lower; 77 points gave
    609.7 rpm, 1.10207), as '<mesh> (<share> % ... at <rpm>)'."""
    out = []
    from torquesplit.steady.maps import counted_points

    stable = counted_points(ds)
    rpm = np.asarray(ds["speed_rpm"].values, float)
    for j, k in enumerate(ds["mesh"].values):
        df = np.where(stable, np.asarray(ds["dynamic_factor"].values[:, j], float), np.nan)
        if not np.isfinite(df).any():
            continue
        i = int(np.nanargmax(df))
        if i == 0 or i == df.size - 1 or not (stable[i - 1] and stable[i + 1]):
            continue  # (at an end of the range, or next to an unstable point)
        increment = df[i] - 1.0 if df[i] > 1.0 else df[i]
        drop = (df[i] - max(df[i - 1], df[i + 1])) / increment
        if drop > PEAK_RESOLUTION:
            out.append(f"{k} (its neighbours {100 * drop:.2g} % of the dynamic increment "
                       f"lower, at {rpm[i]:.6g} rpm)")
    return out


def peak_resolution(model, ds, largest, keep=None, max_cycles=None) -> dict[str, dict]:
    """Per mesh, its largest stable dynamic factor of the sweep solved again at that
    speed with twice the sweep's resolution (shooting: half its RK4 step; harmonic
    balance: twice its harmonics; TABLE_REFINEMENT times the table points where the
    tables jump, as ``--check-step`` does): ``{"halved": value, "digits": significant
    digits of the sweep's value that it confirms}``.  The tutorial's sweep printed
    2.89820 where steady, at the same speed, gave 2.90252 with its own step and 2.89433
    at a quarter of it: 6 digits of which 2 hold.  A solve that fails leaves its meshes
    out."""
    import math
    from types import SimpleNamespace

    from torquesplit.assembly.assemble import assemble
    from torquesplit.convergence import agreeing_digits, check_model
    from torquesplit.errors import TorquesplitError, from_interrupt
    from torquesplit.steady.api import steady_state

    try:
        fine_model, _, _ = check_model(SimpleNamespace(model=model,
                                                       structure=assemble(model)))
    except Exception as exc:  # noqa: BLE001 - a side check: the curve stands without it
        if from_interrupt(exc):  # (Ctrl-C inside compiled code: a SystemError, not a failure)
            raise
        return {}
    by_speed: dict[float, list[str]] = {}
    for mesh, row in largest.items():
        value, rpm = row["stable"]
        if math.isfinite(value) and math.isfinite(rpm):
            by_speed.setdefault(rpm, []).append(mesh)
    shooting = int(ds.attrs.get("harmonics", 0)) == 0
    out = {}
    for rpm, meshes in by_speed.items():
        common = dict(speed=f"{rpm!r} rpm", keep=keep, stability=False, check=False,
                      max_cycles=max_cycles if max_cycles is not None else "auto")
        try:
            if shooting:
                spc = 2 * int(ds.attrs["samples"]) / int(
                    ds.attrs.get("excitation_cycles_per_period", 1))
                fine = steady_state(fine_model, method="shooting",
                                    steps_per_cycle=math.ceil(spc), **common)
            else:
                fine = steady_state(fine_model, method="hb", adaptive=False,
                                    harmonics=2 * int(ds.attrs["harmonics"]), **common)
        except (TorquesplitError, ValueError, ArithmeticError, RuntimeError):
            continue
        if not fine.solution.converged:
            continue
        rows = {r.mesh: float(r.dynamic_factor) for r in fine.mesh_table()}
        for mesh in meshes:
            value = largest[mesh]["stable"][0]
            out[mesh] = {"halved": rows[mesh], "digits": agreeing_digits(value, rows[mesh])}
    return out


def sweep_maxima(ds) -> dict[str, dict[str, tuple[float, float]]]:
    """Per mesh, the largest dynamic factor and its speed [rpm] over the stable points of
    a speed sweep (``"stable"``; an unstable periodic state is never observed, so its
    peak is not a result) and, where present, over the run-up and run-down time
    integrations of ``--cross-check`` (``"run_up"``, ``"run_down"``).  NaN where there is
    no such point."""
    out = {}
    from torquesplit.steady.maps import counted_points

    stable = counted_points(ds)
    rpm = np.asarray(ds["speed_rpm"].values, float)

    def peak(values, speeds):
        values = np.where(np.isfinite(values), values, -np.inf)
        if not values.size or not np.isfinite(values.max()):
            return (math.nan, math.nan)
        i = int(np.argmax(values))
        return (float(values[i]), float(speeds[i]))

    for j, k in enumerate(ds["mesh"].values):
        df = np.asarray(ds["dynamic_factor"].values[:, j], float)
        row = {"stable": peak(df[stable], rpm[stable])}
        for key in ("run_up", "run_down"):
            if f"{key}_dynamic_factor" in ds:
                row[key] = peak(np.asarray(ds[f"{key}_dynamic_factor"].values[:, j], float),
                                np.asarray(ds["check_speed_rpm"].values, float))
        out[str(k)] = row
    return out


def _with_model(ds, model):
    """The Dataset with its model and this command's warnings (results.export)."""
    from torquesplit.cli_support import session
    from torquesplit.results.export import with_model

    return with_model(ds, model, session().warnings)


def _save(ds, path, overwrite=False):
    """Write by suffix, atomically (complete or absent; torquesplit.results.export)."""
    from torquesplit.results.export import save_dataset

    return save_dataset(ds, path, overwrite=overwrite)


def _friction_hint(model) -> str:
    """Where the model's splines have friction: that it is the likely cause of a steady
    state that does not converge (its regularised Coulomb law is stiff and nearly
    non-smooth over one period; a reviewer's quill-shaft drive converged in one Newton
    step without it), and what to do."""
    rubbing = [n for n, sp in model.splines.items() if sp.friction_coefficient > 0]
    if not rubbing:
        return ""
    names = ", ".join(f"splines.{n}.friction_coefficient" for n in rubbing)
    return (f", and so does spline friction ({names}): its Coulomb law, regularised over "
            f"analysis.spline_velocity_scale, stick-slips; 'torquesplit run' integrates it "
            f"as it is, and --set {names.split(', ')[0]}=0 shows what it changes")


def campbell_command(m, start, stop, plot, as_json, console, json_default, out=None,
                     force=False, orders=None):
    """``modes --campbell``: the resonance map and the critical speeds (the map written
    to ``out`` if given; mesh orders 1..``orders``, None: as the stiffness tables
    excite them)."""
    from torquesplit.cli_support import interruptible
    from torquesplit.steady.maps import campbell

    from torquesplit.errors import TorquesplitError

    written, failed = [], None
    # (Ctrl-C exited 130 without a word, and after the map's file, without naming it)
    with interruptible(lambda: f"kept {', '.join(str(w) for w in written)}"
                       + ("; the figure is incomplete" if plot is not None
                          and plot not in written else "") if written else ""):
        ds, crossings = campbell(m, _speed(start, "--from"), _speed(stop, "--to"),
                                 orders=orders)
        try:  # a file that cannot be written: the map is still printed, then the error
            if out is not None:
                from torquesplit.results.export import dataset_files

                written += dataset_files(ds, _save(_with_model(ds, m), out, force))
            if plot is not None:
                from torquesplit.steady.plot import campbell_figure, save

                save(campbell_figure(ds), plot)
                written.append(plot)
        except (TorquesplitError, OSError) as exc:
            failed = exc
    from torquesplit.steady.maps import mode_kind, split_suppressed

    critical, suppressed = split_suppressed(crossings)
    if as_json:
        out = {"critical_speeds": critical,
               "natural_frequencies_Hz": ds["natural_frequency"].values[0].tolist(),
               # a turning carrier's frequencies change with speed: those at --from
               "natural_frequencies_at_speed_rpm": float(ds["speed_rpm"].values[0])}
        if suppressed:
            out["suppressed_by_mesh_phasing"] = suppressed
        if ds.attrs.get("orders_left_out"):
            out["orders_left_out"] = list(ds.attrs["orders_left_out"])
        out["files"] = [str(w) for w in written]
        _emit(out, json_default)
        if failed is not None:
            raise failed
        return
    phased = any("suppressed" in c for c in crossings)
    lo, hi = (_speed_text(x) for x in (start, stop))
    if _speed(start, "--from") > _speed(stop, "--to"):  # (--from above --to: it echoed
        lo, hi = hi, lo  # 'between 3600rpm and 2400rpm')
    from torquesplit.steady.maps import DRIVING_HARMONIC, driven

    n_driven = sum(driven(c, DRIVING_HARMONIC) for c in critical)
    t = Table(title=f"critical speeds between {lo} and {hi}" + (
        f" ({len(critical)} critical; {len(suppressed)} crossings that the planets' mesh "
        f"phasing leaves unexcited, Parker & Lin 2004, or of a stage's meshes with a mode "
        f"in which no stage member moves (type 'other'), marked 'suppressed')" if phased
        else "") + f"; {n_driven} of {len(critical)} driven by at least "
        f"{100 * DRIVING_HARMONIC:g} % (the mesh force harmonic, or a shaft order's k "
        f"harmonic or error; one whose meshes' forces cancel on the mode, marked 'cancels', "
        f"drives none)"
        # ('21 of 21 driven ...: the others only by ...' named others there were none of)
        + (": the others only by what the model leaves out" if n_driven < len(critical)
           else ""))
    # without errors on any line the force harmonic is the stiffness harmonic: the two
    # columns that split it are shown only where there are errors to split off
    split = any(c.get("error_share") is not None for c in crossings)
    cols = ["speed [rpm]", "mode", "f [Hz]", "excitation", "force harmonic [%]"]
    cols += ["k harmonic [%]", "error [%]"] if split else []
    cols += ["mode type", "phasing"] if phased else []
    for col in cols + ["strain energy (largest shares)"]:
        t.add_column(_h(col))
    for c in crossings:
        # (the phasing's verdict, not the excitation's: 'excited' beside a harmonic of
        # 0 read as a contradiction, a planetary reviewer)
        extra = ([mode_kind(c) if c.get("mode_type") else "-",
                  "suppressed" if c["suppressed"] else "not suppressed"]
                 if phased else [])
        k_h, err = c.get("stiffness_harmonic"), c.get("error_share")
        f_h = c.get("force_harmonic")
        # (a harmonic whose meshes' forces cancel on the mode drives nothing there; a
        # harmonic of 0 has nothing to cancel: constant mesh stiffness without errors
        # printed '0 (cancels)')
        there = max(f_h or 0.0, k_h or 0.0) > 0.0
        cancels = " (cancels)" if c.get("stiffness_cancelled") and there else ""
        t.add_row(f"{c['speed_rpm']:#.6g}", str(c["mode"]), f"{c['frequency_Hz']:#.6g}",
                  f"{c['order']} x {c['source']}",
                  "-" if f_h is None else f"{100 * f_h:.3g}{cancels}",
                  *(["-" if k_h is None else f"{100 * k_h:.3g}{cancels}",
                     "-" if err is None else f"{100 * err:.3g} ({c['error_mesh']})"]
                    if split else []), *extra,
                  ", ".join(f"{n} {100 * v:.0f} %" for n, v in c["energy"]))
    console.print(t)
    console.print("force harmonic: the amplitude of that order of the static mesh force "
                  "k(s) (delta - e(s)) over its mean, the stiffness variation and the "
                  "transmission error together (what drives a mesh line; tip relief makes "
                  "the two cancel; a shaft order has none: '-')" + (
                      "; k harmonic: that of the mesh stiffness alone over its mean; error: "
                      "the force amplitude k e of the model's errors at that frequency "
                      "(transmission error, eccentricity) over the mesh's nominal force, the "
                      "largest and its mesh ('-': no error there)" if split else ""),
                  highlight=False)
    for line in ds.attrs.get("orders_left_out", []):
        console.print(f"note: {line}", highlight=False)
    for w in written:
        console.print(f"wrote {w}", highlight=False)
    if failed is not None:
        raise failed
