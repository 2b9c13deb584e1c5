"""Report figures of a dynamic run (:class:`~torquesplit.results.Results`) and of a
quasi-static sweep (:class:`~torquesplit.quasistatic.QuasiStaticResults`).

Every ``*_figure`` function takes results and returns a :class:`matplotlib.figure.Figure`
drawn with the object-oriented API on an Agg canvas: no pyplot, no global state, nothing
set at import.  :func:`write_figures` and :func:`write_static_figures` write every figure
that applies to a run.

Units on the axes: forces in kN (spectrum amplitudes in N), time in s or ms (ms when the
run is shorter than one second), frequency in Hz or kHz, displacements in micrometres,
mesh stiffness in N/um (1 N/um = 1e6 N/m).

Examples
--------
>>> import tempfile, torquesplit
>>> from torquesplit.plot import figures
>>> res = torquesplit.simulate(torquesplit.example_path("ji_li_mill_drive"), cycles=20)
>>> fig = figures.mesh_force_figure(res)
>>> fig.axes[0].get_ylabel()
'mesh force [kN]'
>>> paths = figures.write_figures(res, tempfile.mkdtemp(), formats=("png",))
>>> sorted(p.name for p in paths)[:3]
['cycle_peak_force.png', 'dynamic_factors.png', 'load_sharing_engineering.png']
"""

from __future__ import annotations

import logging
import math
import warnings
from pathlib import Path
from typing import Callable, Iterable

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator

from ..errors import FigureNotApplicableError, TorquesplitError  # noqa: F401 - re-exported
from .. import _args
from ..errors import OptionError, OptionTypeError

__all__ = [
    "FigureNotApplicableError", "figure_jobs", "write_jobs", "figure_svg",
    "mesh_force_figure", "cycle_peak_figure", "load_sharing_figure", "dynamic_factor_figure",
    "support_spectrum_figure", "orbit_figure", "mesh_stiffness_figure",
    "static_mesh_force_figure", "static_load_sharing_figure",
    "write_figures", "write_static_figures",
]

log = logging.getLogger(__name__)

#: font sizes [pt] of the figure title, panel titles, axis labels, ticks and legends
FONT = {"suptitle": 13, "title": 11, "label": 10.5, "tick": 9.5, "legend": 9}
#: width [in] of a one-column figure and height [in] of one row of panels
WIDTH, ROW_HEIGHT = 9.0, 2.9
#: colour of the nominal (equal-split static) force and of reported coefficients
REFERENCE_COLOR = "0.15"
#: a per-cycle series longer than this is drawn as ranges over runs of cycles
DENSE_CYCLES = 400
#: number of runs of cycles (bins) of a dense series
DENSE_BINS = 300
#: a quasi-static sweep over more revolutions of its slowest gear than this is drawn
#: over the one revolution that holds the group's largest value, with every revolution's
#: range at each angle as a band (Mo et al. 2017's 25 revolutions were a solid block)
FOLD_REVOLUTIONS = 2.0

_KN = 1e-3  # N -> kN
_UM = 1e6  # m -> um
_N_PER_UM = 1e-6  # N/m -> N/um

_DEFINITION_TEXT = {
    "cycle_peak": r"$N\,F_{\max,i}(k)\,/\,\Sigma_j F_{\max,j}(k)$ in each mesh cycle $k$",
    "instantaneous": r"peak in each mesh cycle of $N\,F_i(t)\,/\,\Sigma_j F_j(t)$",
    "engineering": r"peak in each mesh cycle of $N\,F_i(t)\,/\,\Sigma_j F_j(t)$",
    "mean_force": r"$N\,\bar F_i(k)\,/\,\Sigma_j \bar F_j(k)$ in each mesh cycle $k$",
}
_REPORTED_TEXT = {
    "cycle_peak": "largest over settled cycles",
    "instantaneous": "largest over settled samples",
    "engineering": "mean of settled cycle peaks",
    "mean_force": "from settled mean forces",
}




# ============================================================ dynamic run figures
def mesh_force_figure(results, *, last_cycles: float | None = None,
                      band_above: float = 30.0, bins: int = 400) -> Figure:
    """Mesh force against time, one panel per load-sharing group, the paths overlaid.

    Parameters
    ----------
    results : Results
        A dynamic run.
    last_cycles : float, optional
        Show only the last ``last_cycles`` mesh cycles of each group (each panel has its
        own time window).  Default: the whole run.
    band_above : float
        Where a panel shows more than this many mesh cycles (a waveform there is a solid
        block of colour), every panel draws each mesh as the band between its smallest
        and largest force in each mesh cycle (or in runs of whole cycles, at most
        ``bins`` per panel), from the per-cycle extremes the integrator
        streams at every step (and at the tables' corners), not from the decimated
        history, which can miss peaks between its samples.  Fewer cycles are drawn
        sample by sample from the history, with each complete cycle's streamed largest
        and smallest force as short dotted steps over it: where they stand clear of the
        line, the history is too coarse for the waveform (``samples_per_period``).
    bins : int
        Largest number of time bins of a band.

    Returns
    -------
    Figure
        The nominal (equal-split) static force of each mesh is the dashed line.
    """
    _args.results_of(results, "mesh_force_figure", ("dynamic",))
    if last_cycles is not None:
        last_cycles = _args.positive(last_cycles, "last_cycles", "last_cycles=20")
    band_above = _args.positive(band_above, "band_above", "band_above=30")
    bins = _args.whole(bins, "bins", "bins=400")
    t, forces = results.mesh_force_history()
    forces = _finite(forces)
    names, groups = results.mesh_names, results.groups
    nominal = results.nominal_forces()
    freq = _group_frequencies(results)
    c_max, c_min = (_finite(a) for a in results.complete_cycle_statistics()[:2])
    starts, cols = results.solution.cycle_start, _cycle_columns(results)
    fig, axes = _panels(len(groups), sharex=last_cycles is None)
    scale, unit = _time_unit(t)
    shown_times = {}
    for g, members in groups.items():
        keep = np.ones(t.shape, bool)
        if last_cycles is not None and t.size:
            # the end of the finite record (a diverged run stops being finite before t[-1])
            finite = np.flatnonzero(np.isfinite(forces[:, [names.index(m) for m in members]])
                                    .all(axis=1))
            t_end = t[finite[-1]] if finite.size else t[-1]
            keep = (t >= t_end - last_cycles / freq[g]) & (t <= t_end)
        shown_times[g] = keep
    # one way of drawing for the whole figure: bands where any panel is too dense
    band = any(((t[k][-1] - t[k][0]) * freq[g] if k.any() else 0.0) > band_above
               for g, k in shown_times.items())
    for ax, (g, members) in zip(axes, groups.items()):
        keep = shown_times[g]
        tk = t[keep]
        for i, m in enumerate(members):
            style = _line_style(i, len(members))
            j, col = names.index(m), cols[m]
            ok = np.isfinite(c_max[:, j]) & np.isfinite(c_min[:, j])
            t0, hi, lo = starts[ok, col], c_max[ok, j] * _KN, c_min[ok, j] * _KN
            if band:  # the streamed extremes of every cycle, in bins of whole cycles
                per_bin = max(1, math.ceil(t0.size / bins))
                idx = np.arange(t0.size) // per_bin
                tb, lo_b, _ = _bin_extremes(t0, lo, idx)
                _, _, hi_b = _bin_extremes(t0, hi, idx)
                tb = tb + 0.5 / freq[g]  # the bins' middles (t0 are cycle starts)
                # edges in the mesh's own dash; a light fill for a lone mesh only (the
                # fills of overlapping bands blend into a colour no legend entry has)
                lab = f"{m} (largest and smallest of each cycle)"
                if len(members) == 1:
                    ax.fill_between(tb * scale, lo_b, hi_b, color=style["color"],
                                    alpha=0.12, lw=0)
                ax.plot(tb * scale, hi_b, color=style["color"], lw=1.1, ls=style["ls"],
                        label=lab)
                ax.plot(tb * scale, lo_b, color=style["color"], lw=1.1, ls=style["ls"])
                continue
            ax.plot(tk * scale, forces[keep, j] * _KN, label=m, **style)
            shown = (t0 >= tk[0] - 1e-12) & (t0 + 1.0 / freq[g] <= tk[-1] + 1e-9) if (
                tk.size) else np.zeros(t0.shape, bool)
            if shown.any():  # each complete cycle's streamed extremes over it
                edges = np.stack([t0[shown], t0[shown] + 1.0 / freq[g]], axis=1) * scale
                for ext, lab in ((hi[shown], "largest"), (lo[shown], "smallest")):
                    ax.plot(edges.ravel(), np.repeat(ext, 2), color=style["color"], lw=0.8,
                            ls=":", label="largest / smallest of each cycle (streamed)"
                            if i == 0 and lab == "largest" else None)
        _nominal_lines(ax, [nominal[m] for m in members])
        window = f", last {last_cycles:g} mesh cycles" if last_cycles is not None else ""
        ax.set_title(f"{_group_label(g, members)}, mesh frequency {_hz(freq[g])}{window}",
                     fontsize=FONT["title"])
        _label(ax, f"time [{unit}]", "mesh force [kN]")
        _legend(ax)
    what = "mesh force" if last_cycles is None else "mesh force, end of the run"
    _suptitle(fig, results, what)
    return fig


def cycle_peak_figure(results, *, dense_above: int = DENSE_CYCLES) -> Figure:
    """Peak mesh force of every complete mesh cycle against the cycle's start time.

    One panel per load-sharing group; the nominal static force is dashed, the start of
    the group's settled part (the settle criterion of :meth:`Results.metrics`, which works on
    these peaks) is the dotted vertical line and the transient before it is shaded.  The
    cycle cut off by the end of the run is not drawn (its peak is that of part of a
    cycle).  More than ``dense_above`` cycles are drawn as the range of the peaks over
    runs of cycles with their mean (:func:`_dense_line`).
    """
    _args.results_of(results, "cycle_peak_figure", ("dynamic",))
    dense_above = _args.whole(dense_above, "dense_above", f"dense_above={DENSE_CYCLES}")
    s = results.solution
    groups = results.groups
    nominal = results.nominal_forces()
    settling = results.metrics().settling
    peaks = results.complete_cycle_statistics()[0]
    col = {m: j for j, m in enumerate(results.mesh_names)}
    cols = _cycle_columns(results)
    fig, axes = _panels(len(groups), sharex=True)
    scale, unit = _time_unit(s.history_t if s.history_t.size else s.cycle_start.ravel())
    for ax, (g, members) in zip(axes, groups.items()):
        for i, m in enumerate(members):
            start, peak = s.cycle_start[:, cols[m]], _finite(peaks[:, col[m]])
            ok = np.isfinite(peak)
            _dense_line(ax, start[ok] * scale, peak[ok] * _KN, m,
                        _line_style(i, len(members)), dense_above)
        _nominal_lines(ax, [nominal[m] for m in members])
        # the group's own settle time: its metrics start there
        _mark_settled(ax, settling.group_time.get(g, settling.start_time) * scale,
                      s.t_span[0] * scale, unit)
        ax.set_title(_group_label(g, members), fontsize=FONT["title"])
        _label(ax, f"cycle start time [{unit}]", "peak force in cycle [kN]")
        _legend(ax)
    _suptitle(fig, results, "peak mesh force of each mesh cycle")
    return fig


def load_sharing_figure(results, definition: str | None = None, *,
                        dense_above: int = DENSE_CYCLES, zoom_cycles: int = 40) -> Figure:
    """Load-sharing coefficient of each mesh cycle against time, by ``definition``.

    Parameters
    ----------
    results : Results
        A dynamic run.
    definition : str, optional
        One of :data:`torquesplit.metrics.load_sharing.DEFINITIONS`; default the model's
        ``[analysis] load_sharing``.  ``cycle_peak`` and ``mean_force`` use the per-cycle
        peak or mean forces; the sample-based definitions (``instantaneous``,
        ``engineering``, ``static_torque``) show the peak in each mesh cycle of the
        instantaneous coefficient.

    dense_above : int
        A run of more cycles than this is drawn in two columns: the whole run as the
        range of the coefficient over runs of cycles with its mean, and the last
        ``zoom_cycles`` cycles one by one.

    Returns
    -------
    Figure
        One panel per group of two or more meshes.  The dashed line is the group's
        reported coefficient (``results.metrics(definition).load_sharing.per_group``),
        the dotted vertical line the start of the group's settled part.
    """
    _args.results_of(results, "load_sharing_figure", ("dynamic",))
    dense_above = _args.whole(dense_above, "dense_above", f"dense_above={DENSE_CYCLES}")
    zoom_cycles = _args.whole(zoom_cycles, "zoom_cycles", "zoom_cycles=40")
    met = results.metrics(definition)
    definition = met.definition
    groups = {g: ms for g, ms in results.groups.items() if len(ms) > 1}
    if not groups:
        raise FigureNotApplicableError(
            "every load-sharing group has a single mesh, so every coefficient is 1; give "
            "parallel meshes the same 'stage' (and 'path') label in the model file to group "
            "them")
    s = results.solution
    settle = met.settling.start_time
    # the metric's own per-cycle data: the figure shows what the number is made of
    cycle_t, coef = met.load_sharing.cycle_time, met.load_sharing.per_cycle
    dense = any(np.isfinite(coef[m]).sum() > dense_above for ms in groups.values()
                for m in ms)
    if dense:  # whole run as ranges (left), the last cycles one by one (right)
        fig = _figure(WIDTH * 1.45, ROW_HEIGHT * len(groups) + 0.9)
        grid = fig.subplots(len(groups), 2, squeeze=False,
                            gridspec_kw={"width_ratios": [2.2, 1.0]})
        axes, zooms = list(grid[:, 0]), list(grid[:, 1])
    else:
        fig, axes = _panels(len(groups), sharex=True)
        zooms = [None] * len(groups)
    scale, unit = _time_unit(s.history_t if s.history_t.size else s.cycle_start.ravel())
    for ax, zoom, (g, members) in zip(axes, zooms, groups.items()):
        reported = met.load_sharing.per_group[g]
        per = 1
        for i, m in enumerate(members):
            style = _line_style(i, len(members))
            ok = np.isfinite(coef[m])
            if zoom is None:
                ax.plot(cycle_t[m] * scale, coef[m], label=m, **style)
                continue
            per = _dense_line(ax, cycle_t[m][ok] * scale, coef[m][ok], m, style, 0)
            last = np.flatnonzero(ok)[-zoom_cycles:]
            zoom.plot(cycle_t[m][last] * scale, coef[m][last], label=m, marker=".",
                      ms=4, **style)
        for a in (ax, zoom) if zoom is not None else (ax,):
            a.axhline(1.0, color="0.6", lw=0.8)
            a.axhline(reported, color=REFERENCE_COLOR, ls="--", lw=1.2,
                      label=f"reported {reported:.6g}\n({_REPORTED_TEXT[definition]})")
        # the group's own settle time: its coefficients start there
        _mark_settled(ax, met.settling.group_time.get(g, settle) * scale,
                      s.t_span[0] * scale, unit)
        whole = (f", whole run: mean of {per} cycles, band their range" if per > 1
                 else ", whole run")
        ax.set_title(_group_label(g, members) + (whole if zoom is not None else ""),
                     fontsize=FONT["title"])
        _label(ax, f"time [{unit}]", "load-sharing coefficient [-]")
        if zoom is None:
            _legend(ax)
            continue
        zoom.set_title(f"last {zoom_cycles} cycles, one by one", fontsize=FONT["title"])
        _label(zoom, f"time [{unit}]", "load-sharing coefficient [-]")
        zoom.set_ylim(ax.get_ylim())
        _legend(zoom)
    _suptitle(fig, results, f"load-sharing coefficient, definition '{definition}'\n"
                            f"{_DEFINITION_TEXT[definition]}{_unsettled(met)}")
    return fig


def dynamic_factor_figure(results, definition: str | None = None, *,
                          resonance: float | None = None) -> Figure:
    """Dynamic factor and peak / nominal force of every mesh, as bars by group.

    The dynamic factor (settled peak / the mesh's own static force, the K_v sense) and
    peak / nominal (settled peak / equal-split nominal force: load sharing and dynamics
    together, Ji & Li eq. 19) come from ``results.metrics(definition).rows``; the grey
    line is 1, the red dotted line the factor above which a run is reported as near a
    resonance (:data:`torquesplit.results.plausibility.RESONANCE_FACTOR`; ``resonance``,
    a positive factor, moves it).
    """
    _args.results_of(results, "dynamic_factor_figure", ("dynamic",))
    from ..results.plausibility import RESONANCE_FACTOR

    met = results.metrics(definition)
    limit = (RESONANCE_FACTOR if resonance is None
             else _args.positive(resonance, "resonance", "resonance=3.0"))
    rows = met.rows
    order = [r for g in met.load_sharing.groups for r in rows if r.group == g]
    fig = _figure(WIDTH, 3.4 + 0.12 * len(order))
    ax = fig.add_subplot()
    x = np.arange(len(order))
    dyn = np.array([r.dynamic_factor for r in order], float)
    ptn = np.array([r.peak_to_nominal for r in order], float)
    bars = [ax.bar(x - 0.2, np.nan_to_num(dyn), 0.4, color=_color(0),
                   label="dynamic factor\n(peak / own static force)"),
            ax.bar(x + 0.2, np.nan_to_num(ptn), 0.4, color=_color(1),
                   label="peak / nominal\n(peak / equal-split force)")]
    # each value on its bar: from 0, 1.076 and 1.105 looked the same (a reviewer)
    if len(order) <= 12:  # (upright beyond 4 meshes: side by side they ran into each
        # other, '1.0001.000')
        for b in bars:
            ax.bar_label(b, fmt="%.3f", fontsize=FONT["tick"] - 1, padding=1,
                         rotation=0 if len(order) <= 4 else 90)
    ax.axhline(1.0, color="0.5", lw=0.9)
    top = float(np.nanmax(np.concatenate([dyn, ptn, [1.0]])))
    y_top = max((1.15 if len(order) <= 4 else 1.3) * top, 1.2)
    if top > 0.6 * limit:  # (and the axis reaches it: its legend entry named a line
        # above the axis, a first-hour reviewer)
        y_top = max(y_top, 1.05 * limit)
        ax.axhline(limit, color="tab:red", ls=":", lw=1.3,
                   label=f"dynamic factor {limit:g}: a run above it is\nreported as near a "
                         f"resonance (torquesplit modes)")
    ax.set_xticks(x, [f"{r.mesh}\n{r.group}" for r in order], rotation=0 if len(order) <= 6
                  else 60, ha="center" if len(order) <= 6 else "right")
    ax.set_xlim(-0.6, len(order) - 0.4)
    ax.set_ylim(0, y_top)
    ax.set_title("per mesh, over the settled part", fontsize=FONT["title"])
    _label(ax, "mesh, load-sharing group [-]", "factor [-]")
    _legend(ax)
    _suptitle(fig, results, f"dynamic factors{_unsettled(met)}")
    return fig


def support_spectrum_figure(results, *, start_time: float | None = None, orders: int = 4,
                            max_frequency: float | None = None, log: bool = True,
                            dynamic_range: float = 1e-4,
                            bodies: Iterable[str] | None = None, max_panels: int = 4,
                            content_range: float = 1e-2, max_points: int = 3000,
                            common_scale: bool = True) -> Figure:
    """Amplitude spectrum of the support (bearing) force histories, mesh orders marked.

    Parameters
    ----------
    results : Results
        A dynamic run (support forces are recorded by :func:`torquesplit.simulate`).
    start_time : float, optional
        Analyse the history from this time [s]; default the settled start of
        ``results.metrics()`` (the transient would smear the spectrum).
    orders : int
        Number of harmonics of each mesh frequency to mark.
    max_frequency : float, optional
        Upper end of the frequency axis [Hz].  Default: the band that holds the content,
        up to a little above the highest line stronger than ``content_range`` times the
        largest (at most ``orders + 0.5`` times the highest mesh frequency and the Nyquist
        frequency).
    log : bool
        Logarithmic amplitude axis spanning ``dynamic_range`` below the largest line
        (mesh orders usually sit far below the shaft-rate lines of eccentricities).
    dynamic_range : float
        Smallest amplitude shown on a log axis, relative to the largest.
    bodies : iterable of str, optional
        Supported bodies to show, one panel each.  Default: the ``max_panels`` bodies
        with the largest spectral line, and any as large as the smallest of them (up to
        twice ``max_panels``); the title names those not drawn (``bodies=`` shows any of
        them).
    max_panels : int
        Largest number of panels drawn by default.
    content_range : float
        Lines weaker than this fraction of the largest do not widen the band shown.
    max_points : int
        A panel's spectrum is reduced to about this many points by keeping the largest
        amplitude of each run of frequency bins (every line keeps its height).
    common_scale : bool
        One amplitude axis for all panels (default), so that the bearings can be compared
        at a glance; ``False`` scales each panel to its own largest line.

    Returns
    -------
    Figure
        Single-sided amplitude spectrum [N] of the force minus its mean, Hann window
        (amplitude-corrected, so a sinusoid of amplitude A shows a peak of about A); the
        legend gives each direction's mean force and largest line.  Dotted: orders of
        each mesh frequency; dash-dot grey: rotation frequency of the supported body.
    """
    _args.results_of(results, "support_spectrum_figure", ("dynamic",))
    orders = _args.whole(orders, "orders", "orders=4", minimum=0)
    max_panels = _args.whole(max_panels, "max_panels", "max_panels=4")
    max_points = _args.whole(max_points, "max_points", "max_points=3000")
    if max_frequency is not None:
        max_frequency = _args.positive(max_frequency, "max_frequency", "max_frequency=5000 (Hz)")
    dynamic_range = _args.positive(dynamic_range, "dynamic_range", "dynamic_range=1e-4")
    content_range = _args.positive(content_range, "content_range", "content_range=1e-2")
    s = results.solution
    supports = results.support_columns()
    via = results.bearing_via()
    chosen = bodies is not None
    if chosen:
        wanted = [bodies] if isinstance(bodies, str) else list(bodies)  # (one name)
        unknown = [b for b in wanted if b not in supports]
        if unknown:
            raise FigureNotApplicableError(
                f"no support force history of {', '.join(unknown)}; choose among "
                f"{', '.join(supports) or '(none)'}")
        supports = {b: supports[b] for b in wanted}
    if not supports:
        raise FigureNotApplicableError(
            "the run recorded no support force; give a gear a [gears.<name>.support] table "
            "(with translational dofs) to get bearing forces")
    t = s.history_t
    t0 = results.history_start() if start_time is None else _args.number(
        start_time, "start_time", "start_time=0.5 (s)")
    keep = t >= t0
    if keep.sum() < 16:
        raise FigureNotApplicableError(
            f"only {int(keep.sum())} history samples after t = {t0:.4g} s; simulate more "
            f"cycles or give an earlier start_time")
    tk = t[keep]
    dt = float(np.median(np.diff(tk)))
    uniform = np.allclose(np.diff(tk), dt, rtol=1e-6, atol=0.0)
    mesh_f = _distinct_mesh_frequencies(results)
    # a whole number of periods of the slowest mesh: its orders fall on frequency bins
    # (no scalloping loss of their amplitudes)
    n = int((tk[-1] - tk[0]) / dt + 0.5) + 1
    periods = math.floor((n * dt) * min(mesh_f) + 1e-6)
    if periods >= 1:
        n = min(n, max(16, int(round(periods / min(mesh_f) / dt))))
    grid = tk[0] + dt * np.arange(n)
    if uniform:
        keep = np.flatnonzero(keep)[:n]
        tk = t[keep]
    freq = np.fft.rfftfreq(grid.size, dt)
    window = np.hanning(grid.size)
    # every spectrum first: the band shown and the bodies drawn depend on all of them
    spectra: dict[str, list] = {}
    strength: dict[str, float] = {}
    for body, dirs in supports.items():
        lines, size = [], 0.0
        for direction, col, sign in dirs:
            x = sign * _finite(s.history_forces[keep, col])
            if not uniform:
                x = np.interp(grid, tk, x)
            mean = float(np.nanmean(x))
            amp = 2.0 * np.abs(np.fft.rfft(np.nan_to_num(x - mean) * window)) / window.sum()
            amp[0] = 0.0
            lines.append((direction, mean, amp))
            size = max(size, float(np.nanmax(np.abs(x))))
        spectra[body] = lines
        strength[body] = max(float(a.max()) for _, _, a in lines)
        # (judged above the window's leakage of the lowest bins, as the legend's line)
        if max(float(a[3:].max(initial=0.0)) for _, _, a in lines) <= QUIET_SHARE * max(
                size, 1.0):
            strength[body] = 0.0  # rounding noise only
    f_cap = min(freq[-1], (orders + 0.5) * max(mesh_f))
    if max_frequency:
        f_top = min(float(max_frequency), freq[-1])
    else:
        largest = max(strength.values())
        tops = [freq[np.flatnonzero(a > content_range * largest)[-1]]
                for lines in spectra.values() for _, _, a in lines
                if largest > 0 and (a > content_range * largest).any()]
        content = max(tops) if tops else f_cap
        f_top = min(f_cap, max(1.25 * content, 1.5 * min(mesh_f)))
    shown, hidden = _strongest(strength, max_panels) if not chosen else (list(supports), [])
    fscale, funit = (1e-3, "kHz") if f_top >= 1e4 else (1.0, "Hz")
    show = freq <= f_top
    ncols = 1 if len(shown) <= max(4, max_panels) else 2
    fig, axes = _panels(len(shown), ncols=ncols, sharex=True, row_height=2.6)
    overall = max((float(a[show].max()) for b in shown if strength[b] > 0.0
                   for _, _, a in spectra[b]), default=0.0)
    for n_panel, (ax, body) in enumerate(zip(axes, shown)):
        lines = spectra[body]
        own = max(float(a[show].max()) for _, _, a in lines)
        largest = overall if common_scale and overall > 0.0 else own
        quiet = strength[body] == 0.0
        floor = largest * dynamic_range
        for i, (direction, mean, amp) in enumerate(lines):
            f_show, a_show = _peak_pool(freq[show], amp[show], max_points)
            y = np.maximum(a_show, 0.1 * floor) if log and not quiet else a_show
            style = _spike_style(i, len(lines))
            ax.plot(f_show * fscale, y, zorder=3, gid=f"{body}.support.{direction}", **style)
            # the largest line above the window's leakage of the lowest bins (an unsettled
            # drift put it at the first bin, 35.7 Hz on a reviewer's run: no line)
            above = f_show >= 2.5 * (freq[1] - freq[0]) if freq.size > 1 else f_show >= 0
            peak = int(np.flatnonzero(above)[np.argmax(a_show[above])]) if above.any() \
                else int(np.argmax(a_show))
            # the top of each strong line marked, so coinciding lines of x, y, z all show
            tops = _spectral_lines(y, 0.01 * own) if not quiet else np.zeros(0, int)
            ax.plot(f_show[tops] * fscale, y[tops], ls="none", marker=_MARKERS[i % 3],
                    ms=5, mfc="none", mew=1.2, color=style["color"], zorder=4,
                    # (a panel of rounding noise: its 1e-14 N numbers are not forces)
                    label=f"{direction}: rounding noise only" if quiet else
                          f"{direction}: mean {_force_text(mean)},\n"
                          f"largest {_force_text(a_show[peak])} at {_hz(f_show[peak])}")
        for j, (f, label) in enumerate(mesh_f.items()):
            for k in range(1, orders + 1):
                if k * f <= f_top:
                    ax.axvline(k * f * fscale, color=_order_color(j), ls=":", lw=1.2, zorder=1,
                               label=f"{_short_text(label)} mesh: {_hz(f)} x 1..{orders}"
                               if k == 1 and n_panel == 0 else None)
        # shaft orders in the frame of the force: a body measured in a turning carrier's
        # frame (planet bearings, and sun and ring with that carrier) turns at its speed
        # relative to the carrier there, and a load fixed in the housing turns at the
        # carrier's speed
        from ..model.kinematics import support_frame

        frame, f_rot, f_frame = support_frame(results.kinematics, body)
        if f_rot is not None and 0 < f_rot <= f_top:
            ax.axvline(f_rot * fscale, color="0.45", ls="-.", lw=1.0, zorder=1,
                       label=f"rotation of {body}" + (
                           f" relative to {frame}" if f_frame else "") + f": {_hz(f_rot)}")
        if f_frame and f_frame <= f_top:
            ax.axvline(f_frame * fscale, color="0.3", ls=(0, (5, 2, 1, 2, 1, 2)), lw=1.0,
                       zorder=1, label=f"rotation of {frame} (housing seen from its "
                       f"frame): {_hz(f_frame)}")
        ax.set_xlim(0, f_top * fscale)
        if quiet:  # do not blow rounding noise up to full scale
            ax.set_ylim(0, 1)
            ax.text(0.5, 0.5, "no dynamic content (rounding noise only)", ha="center",
                    va="center", transform=ax.transAxes, fontsize=FONT["label"])
        elif log:
            ax.set_yscale("log")
            ax.set_ylim(floor, 2.0 * largest)
            ax.yaxis.set_minor_locator(NullLocator())  # decades only: readable, fast
        else:
            ax.set_ylim(0, 1.08 * largest)
        held = f"spline {via[body]} of {body}" if body in via else f"support of {body}"
        ax.set_title(f"{held} ({_frame_text(results.kinematics, body)})",
                     fontsize=FONT["title"])
        _label(ax, f"frequency [{funit}]" + (" in the force's frame" if f_frame else ""),
               "force amplitude [N]")
        _legend(ax)
    span = grid.size * dt
    least = min((strength[b] for b in shown), default=0.0)
    smaller = [b for b in hidden if strength[b] < (1.0 - 1e-3) * least]
    others = [b for b in hidden if b not in smaller]
    more = ((f"\nnot drawn (smaller forces): {', '.join(smaller)}" if smaller else "")
            + (f"\nnot drawn ({len(shown)} panels at most; in Python bodies= chooses "
               f"them): "
               f"{', '.join(others)}" if others else ""))
    # a decimated history folds what is above its Nyquist frequency back into the band
    # (a 708 Hz harmonic drawn at 472 Hz from 5 samples per period)
    alias = ("" if results.history_keeps_every_step() else
             f"\nfrom a history of {results.history_samples_per_period():.3g} samples per "
             f"shortest mesh period: content above {_hz(0.5 / dt)} folds back "
             f"(--samples-per-period)")
    _suptitle(fig, results, f"support force spectrum\n{grid[0]:.4g} s ≤ t < "
                            f"{grid[0] + span:.4g} s, resolution {1 / span:.3g} Hz"
                            f"{alias}{more}")
    return fig


QUIET_SHARE = 1e-6
"""A support force whose largest spectral line is below this share of the force has no
dynamic content (a planetary's 1 mN against 1 kN was drawn on a log axis as a spectrum)."""


def _strongest(strength: dict[str, float], max_panels: int,
               tie: float = 1e-3) -> tuple[list[str], list[str]]:
    """``(shown, hidden)`` bodies, both in model order: the ``max_panels`` with the largest
    line, and any as large as the smallest of those (within ``tie``, relative: a
    symmetric twin is drawn, not called weaker)."""
    if len(strength) <= max_panels:
        return list(strength), []
    ranked = sorted(strength, key=lambda b: -strength[b])
    cut = strength[ranked[max_panels - 1]]
    keep = set(ranked[:max_panels])
    if cut > 0.0:
        keep |= {b for b in ranked[max_panels:2 * max_panels]
                 if strength[b] >= (1.0 - tie) * cut}
    return [b for b in strength if b in keep], [b for b in strength if b not in keep]


def _peak_pool(freq: np.ndarray, amp: np.ndarray, max_points: int):
    """At most about ``max_points`` points: the largest amplitude of each run of bins
    (with its frequency), so that every spectral line keeps its height."""
    if freq.size <= max_points:
        return freq, amp
    step = math.ceil(freq.size / max_points)
    n = freq.size // step * step
    blocks = amp[:n].reshape(-1, step)
    k = blocks.argmax(axis=1) + np.arange(blocks.shape[0]) * step
    k = np.append(k, np.arange(n, freq.size))
    return freq[k], amp[k]


def orbit_figure(results, *, bodies: Iterable[str] | None = None) -> Figure:
    """Floating orbit (x-y path of the centre) of every body with x and y DOFs [um].

    Works on a :class:`~torquesplit.quasistatic.QuasiStaticResults` (its
    :meth:`orbits`) and on a dynamic run whose ``history_dofs`` include ``<body>.x`` and
    ``<body>.y``.  Equal aspect, displacements from the nominal centre; each panel is
    zoomed on its orbit: ``+`` marks the nominal centre when it is near the orbit, else the
    panel title gives the mean offset from it.  The circle is the start.
    """
    _args.results_of(results, "orbit_figure", ("dynamic", "static"))
    orbits = _orbits(results)
    if bodies is not None:
        wanted = [bodies] if isinstance(bodies, str) else list(bodies)  # (one name)
        unknown = [b for b in wanted if b not in orbits]
        if unknown:
            raise FigureNotApplicableError(
                f"no x-y orbit of {', '.join(unknown)}; choose among "
                f"{', '.join(orbits) or '(none)'}")
        orbits = {b: orbits[b] for b in wanted}
    if not orbits:
        raise FigureNotApplicableError(
            "no body has recorded x and y displacements; give floating members "
            "dofs = [\"x\", \"y\", \"theta\"] and, for a dynamic run, "
            "simulate(..., history_dofs=[\"<body>.x\", \"<body>.y\"])")
    n = len(orbits)
    ncols = min(n, 4)
    nrows = math.ceil(n / ncols)
    fig = _figure(width=max(6.5, 3.4 * ncols + 0.4), height=3.5 * nrows + 0.7)
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    # a body that moves a million times less than the one that moves most is rounding (a
    # held sun's 1e-14 um drew offset tick labels): drawn as no motion
    largest = max(float(np.nanmax(np.abs(_finite(xy) * _UM), initial=0.0))
                  for xy in orbits.values())
    for ax, (body, xy) in zip(axes, orbits.items()):
        xy = _finite(xy) * _UM
        ax.plot(xy[:, 0], xy[:, 1], color=_color(0), lw=1.0)
        ax.plot(xy[:1, 0], xy[:1, 1], "o", color=_color(0), ms=5, mfc="none")
        lo, hi = np.nanmin(xy, axis=0), np.nanmax(xy, axis=0)
        reach = max(float(np.max(hi - lo)), 1e-12)
        title = body
        if float(np.nanmax(np.abs(xy), initial=0.0)) < 1e-6 * largest:
            half = 0.5 * largest
            ax.set_xlim(-half, half)
            ax.set_ylim(-half, half)
            ax.plot([0.0], [0.0], "+", color=REFERENCE_COLOR, ms=10, mew=1.5)
            ax.set_title(f"{body}\n(no motion: below {1e-6 * largest:.1g} µm)",
                         fontsize=FONT["title"])
            ax.set_aspect("equal", adjustable="box")
            _label(ax, "x [µm]", "y [µm]")
            continue
        if np.all(lo - reach <= 0.0) and np.all(hi + reach >= 0.0):
            ax.plot([0.0], [0.0], "+", color=REFERENCE_COLOR, ms=10, mew=1.5)
        else:
            mean = np.nanmean(xy, axis=0)
            title += f"\nmean offset ({mean[0]:.3g}, {mean[1]:.3g}) µm"
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(title, fontsize=FONT["title"])
        _label(ax, "x [µm]", "y [µm]")
    kind = "quasi-static" if hasattr(results, "orbits") else "dynamic"
    from ..model.kinematics import support_frame

    frames = {carrier for carrier, _, turning in
              (support_frame(results.kinematics, b) for b in orbits) if turning}
    frame = (f"x, y in {', '.join(sorted(frames))}'s turning frame for the bodies measured "
             f"in it, else the housing's" if frames else "x, y in the housing frame")
    _suptitle(fig, results, f"floating orbits ({kind}): the path of each centre about its "
                            f"nominal position\n(+ the nominal centre, o the start; {frame})")
    return fig


def mesh_stiffness_figure(results, *, cycles: float = 2.0, points_per_cycle: int = 400
                          ) -> Figure:
    """Mesh stiffness k(t) over ``cycles`` mesh cycles, one panel per group.

    The assembled stiffness tables are drawn as the integrator reads them (linear
    periodic interpolation at the mesh phase ``f t + phase``), so the relative phasing
    of parallel meshes shows.  Works on dynamic and quasi-static results.
    """
    _args.results_of(results, "mesh_stiffness_figure", ("dynamic", "static"))
    cycles = _args.positive(cycles, "cycles", "cycles=2")
    points_per_cycle = _args.whole(points_per_cycle, "points_per_cycle", "points_per_cycle=400",
                             minimum=2)
    st = results.structure
    el = st.element_names
    groups = _groups(results)
    x = np.linspace(0.0, cycles, int(points_per_cycle * cycles) + 1)
    fig, axes = _panels(len(groups), sharex=True, row_height=2.5)
    for ax, (g, members) in zip(axes, groups.items()):
        for i, m in enumerate(members):
            e = el.index(m)
            ax.plot(x, _stiffness_at_phase(st.stiffness_table[e], x + st.phase[e])
                    * _N_PER_UM, **_line_style(i, len(members)),
                    label=f"{m} (mean {st.stiffness_table[e].mean() * _N_PER_UM:.5g} N/µm)")
        ax.set_xlim(0, cycles)
        ax.set_title(_group_label(g, members), fontsize=FONT["title"])
        _label(ax, "time [mesh cycles]", "mesh stiffness [N/µm]")
        _legend(ax)
    _suptitle(fig, results, "mesh stiffness")
    return fig


# ============================================================ quasi-static figures
def static_mesh_force_figure(results) -> Figure:
    """Quasi-static mesh force against mesh position, one panel per group (over many
    revolutions: one revolution and every revolution's range, :func:`_revolution`)."""
    _args.results_of(results, "static_mesh_force_figure", ("static",))
    angle, xlabel = _positions(results)
    forces = _finite(_static_forces(results))
    names, groups = results.mesh_names, _groups(results)
    nominal = {m: results.kinematics.meshes[m].force for m in names}
    fig, axes = _panels(len(groups), sharex=True)
    folded = []
    for ax, (g, members) in zip(axes, groups.items()):
        ys = [forces[:, names.index(m)] * _KN for m in members]
        x, keep, text = _revolution(angle, ys, xlabel)
        for i, (m, y) in enumerate(zip(members, ys)):
            _folded_line(ax, angle, x, keep, y, m, _line_style(i, len(members)))
        _nominal_lines(ax, [nominal[m] for m in members])
        ax.set_xlim(*((x[0], x[-1]) if keep is None else (0.0, 360.0)))
        ax.set_title(_group_label(g, members), fontsize=FONT["title"])
        _label(ax, text, "mesh force [kN]")
        _legend(ax)
        folded.append(text != xlabel)
    _suptitle(fig, results, f"quasi-static mesh force{_fold_note(folded)}"
                            f"{_unconverged_note(results)}")
    return fig


def static_load_sharing_figure(results) -> Figure:
    """Static torque ratio ``N F_i / sum_j F_j`` (Mo et al. 2017 eq. 14) against position
    (over many revolutions: the one that holds the largest ratio, and every
    revolution's range, :func:`_revolution`).

    The dashed line is the group's reported value (largest over the positions,
    Mo et al. 2017 eq. 15: ``results.metrics().per_group``).
    """
    _args.results_of(results, "static_load_sharing_figure", ("static",))
    angle, xlabel = _positions(results)
    groups = {g: ms for g, ms in _groups(results).items() if len(ms) > 1}
    if not groups:
        raise FigureNotApplicableError(
            "every load-sharing group has a single mesh; give parallel meshes the same "
            "'stage' (and 'path') label in the model file to group them")
    met = results.metrics()
    fig, axes = _panels(len(groups), sharex=True)
    folded = []
    for ax, (g, members) in zip(axes, groups.items()):
        ys = [_finite(met.per_cycle[m]) for m in members]  # the metric's own ratios
        x, keep, text = _revolution(angle, ys, xlabel)
        for i, (m, y) in enumerate(zip(members, ys)):
            _folded_line(ax, angle, x, keep, y, m, _line_style(i, len(members)))
        ax.axhline(1.0, color="0.6", lw=0.8)
        ax.axhline(met.per_group[g], color=REFERENCE_COLOR, ls="--", lw=1.2,
                   label=f"reported {met.per_group[g]:.6g}\n(largest over positions)")
        ax.set_xlim(*((x[0], x[-1]) if keep is None else (0.0, 360.0)))
        ax.set_title(_group_label(g, members), fontsize=FONT["title"])
        _label(ax, text, "static torque ratio [-]")
        _legend(ax)
        folded.append(text != xlabel)
    _suptitle(fig, results, "quasi-static load sharing, "
                            r"$N\,F_i\,/\,\Sigma_j F_j$ at each position"
                            f"{_fold_note(folded)}{_unconverged_note(results)}")
    return fig


def _revolution(angle: np.ndarray, ys, xlabel: str):
    """Where a sweep spans more than :data:`FOLD_REVOLUTIONS` revolutions: the positions
    of the revolution that holds the largest of ``ys`` (a mask), their angle within it
    [deg] and the axis label that says which; else every position, as it is."""
    span = float(angle[-1] - angle[0]) if angle.size else 0.0
    if span <= FOLD_REVOLUTIONS * 360.0:
        return angle, None, xlabel
    turn = np.floor((angle - angle[0]) / 360.0 + 1e-9)
    stacked = np.array(ys, dtype=float)
    if not np.isfinite(stacked).any():
        return angle, None, xlabel
    k = turn[np.nanargmax(stacked, axis=1)[np.nanargmax(np.nanmax(stacked, axis=1))]]
    keep = turn == k
    x = angle[keep] - angle[0] - 360.0 * k
    n = int(turn[-1]) + (1 if angle[-1] - angle[0] - 360.0 * turn[-1] > 1e-6 else 0)
    return x, keep, xlabel.replace(
        " [deg]", f" in revolution {int(k) + 1} of {n} (it holds the largest value) [deg]")


def _folded_line(ax, angle, x, keep, y, label: str, style: dict) -> None:
    """``y`` over the revolution ``keep`` (:func:`_revolution`), with the range of every
    revolution at each angle as a light band (positions binned by angle within a
    revolution, as many bins as a revolution has positions); all of ``y`` when
    ``keep`` is None."""
    if keep is None:
        ax.plot(x, y, label=label, **style)
        return
    within = np.mod(angle - angle[0], 360.0)
    bins = max(int(keep.sum()), 2)
    index = np.minimum((within / 360.0 * bins).astype(int), bins - 1)
    lo = np.full(bins, np.nan)
    hi = np.full(bins, np.nan)
    ok = np.isfinite(y)
    np.fmin.at(lo, index[ok], y[ok])
    np.fmax.at(hi, index[ok], y[ok])
    centre = (np.arange(bins) + 0.5) * 360.0 / bins
    ax.fill_between(centre, lo, hi, color=style["color"], alpha=0.15, lw=0)
    ax.plot(x, y[keep], label=label, **style)


def _fold_note(folded) -> str:
    """The title's note of a figure drawn over one revolution (:func:`_revolution`)."""
    return ("\none revolution (lines) and the range of every revolution (bands)"
            if any(folded) else "")


# ============================================================ writing
def write_figures(results, directory, formats=("png", "svg"), *,
                  definition: str | None = None, last_cycles: float = 5.0,
                  prefix: str = "", dpi: int = 150) -> list[Path]:
    """Write every figure that applies to a dynamic run; return the written paths.

    Parameters
    ----------
    results : Results
        A dynamic run (for a quasi-static sweep use :func:`write_static_figures`).
    directory : str or Path
        Output directory (created if missing).
    formats : sequence of str
        File formats (suffixes) to write each figure in, e.g. ``("png", "svg", "pdf")``.
    definition : str, optional
        Load-sharing definition of the coefficient figure (default: the model's).
    last_cycles : float
        Mesh cycles shown in the end-of-run mesh-force figure.
    prefix : str
        Put in front of every file name (e.g. the case name).
    dpi : int
        Resolution of raster formats.

    Returns
    -------
    list of Path
        ``mesh_force.*`` (whole run), ``mesh_force_end.*`` (last cycles),
        ``cycle_peak_force.*``, ``load_sharing_<definition>.*`` (if a group has two or
        more meshes), ``dynamic_factors.*``, ``support_force_spectrum.*`` (if supports were recorded),
        ``orbits.*`` (if x-y histories were recorded), ``mesh_stiffness.*`` (if a mesh
        stiffness varies).
    """
    if hasattr(results, "orbits"):
        raise OptionTypeError("write_figures takes a dynamic run; for quasi-static results "
                              "call "
                        "write_static_figures(results, directory)")
    _args.results_of(results, "write_figures", ("dynamic",))  # (a Model: AttributeError)
    _check_formats(formats)
    jobs = figure_jobs(results, definition=definition, last_cycles=last_cycles)
    return write_jobs(jobs, directory, formats, prefix=prefix, dpi=dpi)


#: file names (no suffix) of every figure a dynamic run may write, in order
RUN_FIGURES = ("mesh_force", "mesh_force_end", "cycle_peak_force", "load_sharing_{definition}",
               "dynamic_factors", "support_force_spectrum", "orbits", "mesh_stiffness")
#: file names (no suffix) of every figure a quasi-static sweep may write, in order
STATIC_FIGURES = ("static_mesh_force", "static_load_sharing", "static_orbits", "mesh_stiffness")


def figure_files(names, formats=("png", "svg"), *, prefix: str = "",
                 definition: str = "") -> list[str]:
    """The file names ``write_jobs`` may write for ``names`` (:data:`RUN_FIGURES`,
    :data:`STATIC_FIGURES`): what a command checks for before it computes.

    >>> figure_files(STATIC_FIGURES[:1])
    ['static_mesh_force.png', 'static_mesh_force.svg']
    """
    return [f"{prefix}{n.format(definition=definition)}.{f.lower().lstrip('.')}"
            for n in names for f in formats]


def figure_jobs(results, *, definition: str | None = None,
                last_cycles: float = 5.0) -> list[tuple[str, Callable[[], Figure]]]:
    """``(file name, make figure)`` of every figure :func:`write_figures` writes for a
    dynamic run, in order (what :func:`write_jobs` and the HTML report draw)."""
    definition = results.metrics(definition).definition
    makers = [
        lambda: mesh_force_figure(results),
        lambda: mesh_force_figure(results, last_cycles=last_cycles),
        lambda: cycle_peak_figure(results),
        lambda: load_sharing_figure(results, definition),
        lambda: dynamic_factor_figure(results, definition),
        lambda: support_spectrum_figure(results),
        lambda: orbit_figure(results),
        lambda: mesh_stiffness_figure(results),
    ]
    jobs = [(n.format(definition=definition), make) for n, make in zip(RUN_FIGURES, makers)]
    return jobs if _stiffness_varies(results) else jobs[:-1]


def write_static_figures(results, directory, formats=("png", "svg"), *, prefix: str = "",
                         dpi: int = 150) -> list[Path]:
    """Write every figure of a quasi-static sweep; return the written paths.

    ``static_mesh_force.*``, ``static_load_sharing.*`` (if a group has two or more
    meshes), ``static_orbits.*`` (if a body floats), ``mesh_stiffness.*`` (if a mesh
    stiffness varies).  Arguments as in :func:`write_figures`.
    """
    if not hasattr(results, "orbits"):
        raise OptionTypeError("write_static_figures takes quasi-static results; for a "
                              "dynamic run "
                        "call write_figures(results, directory)")
    return _write(static_figure_jobs(results), directory, formats, prefix, dpi)


def static_figure_jobs(results) -> list[tuple[str, Callable[[], Figure]]]:
    """``(file name, make figure)`` of every figure of a quasi-static sweep."""
    makers = [
        lambda: static_mesh_force_figure(results),
        lambda: static_load_sharing_figure(results),
        lambda: orbit_figure(results),
        lambda: mesh_stiffness_figure(results),
    ]
    jobs = list(zip(STATIC_FIGURES, makers))
    return jobs if _stiffness_varies(results) else jobs[:-1]


def _check_formats(formats) -> tuple[str, ...]:
    formats = (formats,) if isinstance(formats, str) else tuple(formats)
    supported = FigureCanvasAgg.get_supported_filetypes()
    bad = [f for f in formats if f.lower().lstrip(".") not in supported]
    if bad or not formats:
        raise OptionError(f"cannot write figures as {', '.join(bad) or 'no format'}; choose "
                         f"formats among {', '.join(sorted(supported))}")
    return formats


def _write(jobs, directory, formats, prefix, dpi) -> list[Path]:
    return write_jobs(jobs, directory, formats, prefix=prefix, dpi=dpi)


def write_jobs(jobs, directory, formats=("png", "svg"), *, prefix: str = "", dpi: int = 150,
               progress: Callable[[int, int, str], None] | None = None) -> list[Path]:
    """Make each ``(name, make figure)`` of ``jobs`` and write it in every format.

    Figures that do not apply (:class:`FigureNotApplicableError`) are skipped.  Files are
    cropped to their content (``bbox_inches="tight"``): no legend or title is clipped.
    ``progress(i, n, name)`` is called before each figure.
    """
    formats = _check_formats(formats)
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():  # (a model file passed by mistake)
        from ..errors import OutputError

        raise OutputError(f"{directory} is a file, not a folder; give the folder to write the "
                          f"figures into (created if missing)")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        from ..errors import OutputError

        raise OutputError(f"cannot create the figure folder {directory} "
                          f"({exc.strerror or exc}); choose another folder") from None
    written = []
    for i, (name, make) in enumerate(jobs):
        if progress is not None:
            progress(i, len(jobs), name.replace("_", " "))
        try:
            fig = make()
        except FigureNotApplicableError as exc:
            log.info("figure %s skipped: %s", name, exc)
            continue
        written += save_figure(fig, [directory / f"{prefix}{name}.{fmt.lower().lstrip('.')}"
                                     for fmt in formats], dpi=dpi)
        log.debug("figure %s written", name)
    if progress is not None:
        progress(len(jobs), len(jobs), "done")
    return written


def save_figure(fig: Figure, paths, *, dpi: int = 150) -> list[Path]:
    """Save ``fig`` to each path (format by suffix), cropped to its content so that no
    legend or title is clipped.  The layout and the crop are computed once for all the
    formats; SVG keeps its text as text (smaller, faster, searchable)."""
    import matplotlib

    fig.draw_without_rendering()  # the layout, once
    bbox = fig.get_tightbbox().padded(0.1)
    engine = fig.get_layout_engine()
    fig.set_layout_engine("none")  # keep it: every save would lay the figure out again
    out = []
    with matplotlib.rc_context({"svg.fonttype": "none"}), _quiet_font_fallback():
        for path in paths:
            path = Path(path)
            fig.savefig(path, dpi=dpi, bbox_inches=bbox,
                        metadata={"Date": None} if path.suffix.lower() == ".svg" else None)
            out.append(path)
    fig.set_layout_engine(engine)
    return out


class _quiet_font_fallback:
    """Silence matplotlib's font lookup while a figure is written: where its font cache
    lacks the STIX fonts (a cache shared with a system matplotlib that ships without
    them), every math label printed 'findfont: Font family ['STIXGeneral'] not found.
    Falling back to DejaVu Sans' on the report's stderr (a reviewer), and the fallback
    is what is drawn anyway.  Only for the duration of the save: no handler stays."""

    def __enter__(self):
        self._logger = logging.getLogger("matplotlib.font_manager")
        self._level = self._logger.level
        self._logger.setLevel(logging.ERROR)

    def __exit__(self, *exc):
        self._logger.setLevel(self._level)
        return False


def figure_svg(fig: Figure, salt: str) -> str:
    """``fig`` as SVG text for inlining in HTML: text kept as text, ids made unique by
    ``salt`` (several figures in one page must not share clip-path or marker ids), no
    XML prologue, cropped to the content."""
    import io

    import matplotlib

    buffer = io.StringIO()
    with (matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": salt}),
          _quiet_font_fallback()):
        fig.savefig(buffer, format="svg", bbox_inches="tight", pad_inches=0.1,
                    metadata={"Date": None})
    text = buffer.getvalue()
    start = text.find("<svg")
    return text[start:] if start >= 0 else text


# ============================================================ helpers: data
def _finite(x: np.ndarray) -> np.ndarray:
    """Copy with +-inf replaced by NaN (a diverged run), so lines just stop."""
    x = np.asarray(x, dtype=float)
    return np.where(np.isfinite(x), x, np.nan)


def _groups(results) -> dict[str, list[str]]:
    from ..metrics.load_sharing import group_meshes

    return group_meshes(results.structure.metadata["meshes"])


def _group_frequencies(results) -> dict[str, float]:
    meta = results.structure.metadata["meshes"]
    return {g: float(meta[ms[0]]["frequency"]) for g, ms in _groups(results).items()}


def _distinct_mesh_frequencies(results) -> dict[float, str]:
    """Mesh frequency -> names of the groups meshing at it (equal to 1e-6 relative)."""
    out: dict[float, list[str]] = {}
    for g, f in _group_frequencies(results).items():
        for known in out:
            if math.isclose(known, f, rel_tol=1e-6):
                out[known].append(g)
                break
        else:
            out[f] = [g]
    return {f: ", ".join(gs) for f, gs in sorted(out.items())}


def _spectral_lines(amp: np.ndarray, threshold: float) -> np.ndarray:
    """Indices of local maxima of a spectrum above ``threshold``."""
    inner = np.flatnonzero((amp[1:-1] >= amp[:-2]) & (amp[1:-1] > amp[2:])) + 1
    return inner[amp[inner] > threshold]


def _frame_text(kin, body: str) -> str:
    """The frame a body's support force is given in, in words."""
    from ..model.kinematics import support_frame

    carrier, _, f_frame = support_frame(kin, body)
    if carrier is None:
        return "force in the housing frame"
    if not f_frame:
        return f"force in the housing frame: {carrier} does not turn"
    return f"force in {carrier}'s turning frame"


def _cycle_columns(results) -> dict[str, int]:
    """Mesh -> column of the solution's cycle arrays."""
    s = results.solution
    el = results.structure.element_names
    tracked = list(s.tracked_elements)
    return {m: tracked.index(el.index(m)) for m in results.mesh_names}


def _bin_extremes(t: np.ndarray, y: np.ndarray, bin_index: np.ndarray):
    """Mid time, smallest and largest value of ``y`` in each run of equal, non-decreasing
    ``bin_index``; a short (incomplete) last bin is left out."""
    edges = np.flatnonzero(np.diff(bin_index, prepend=bin_index[0] - 1))
    last = np.append(edges[1:], t.size) - 1
    count = last - edges + 1
    if count.size > 2 and count[-1] < 0.9 * np.median(count):
        edges, last = edges[:-1], last[:-1]
    with np.errstate(invalid="ignore"):
        lo = np.fmin.reduceat(y[:last[-1] + 1], edges)
        hi = np.fmax.reduceat(y[:last[-1] + 1], edges)
    return 0.5 * (t[edges] + t[last]), lo, hi


def _dense_line(ax, x: np.ndarray, y: np.ndarray, label: str, style: dict,
                dense_above: int, bins: int = DENSE_BINS) -> int:
    """Draw ``y(x)`` as a line; beyond ``dense_above`` points, as the range of ``y`` over
    runs of consecutive points (light band, every extreme kept) with the run means as
    the line, so that thousands of cycles of several meshes stay readable."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.size <= dense_above or x.size < 2 * bins:
        ax.plot(x, y, label=label, **style)
        return 1
    per = math.ceil(x.size / bins)
    n = math.ceil(x.size / per) * per
    pad = n - x.size
    xb = np.append(x, np.full(pad, np.nan)).reshape(-1, per)
    yb = np.append(y, np.full(pad, np.nan)).reshape(-1, per)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        xm, lo, hi, mean = (np.nanmean(xb, axis=1), np.nanmin(yb, axis=1),
                            np.nanmax(yb, axis=1), np.nanmean(yb, axis=1))
    ax.fill_between(xm, lo, hi, color=style["color"], alpha=0.15, lw=0)
    ax.plot(xm, mean, label=f"{label} (mean of {per} cycles;\nband: their range)", **style)
    return per


def _stiffness_at_phase(table: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """The stiffness table read as the integrator reads it: the same law,
    :func:`torquesplit.solve.laws.periodic_values` (linear, periodic)."""
    from ..solve.laws import periodic_values

    phase = np.asarray(phase, dtype=float).ravel()
    rows = np.ascontiguousarray(np.broadcast_to(np.asarray(table, dtype=float),
                                                (phase.size, np.size(table))))
    out = np.empty(phase.size)
    periodic_values(rows, phase, out)
    return out


def _stiffness_varies(results) -> bool:
    st = results.structure
    rows = st.stiffness_table[[st.element_names.index(m) for m in results.mesh_names]]
    return bool(np.any(np.ptp(rows, axis=1) > 1e-9 * np.abs(rows).max(axis=1)))


def _orbits(results) -> dict[str, np.ndarray]:
    if hasattr(results, "orbits"):
        return results.orbits()
    s = results.solution
    names = [s.dof_names[i] for i in s.history_dofs]
    out = {}
    for name in names:
        body, _, axis = name.rpartition(".")
        if axis == "x" and f"{body}.y" in names:
            out[body] = s.history_q[:, [names.index(name), names.index(f"{body}.y")]]
    return out


def _static_forces(results) -> np.ndarray:
    forces = np.array(results.mesh_forces(), dtype=float)
    converged = np.asarray(getattr(results.solution, "converged", np.ones(len(forces), bool)))
    forces[~converged.astype(bool)] = np.nan
    return forces


def _positions(results) -> tuple[np.ndarray, str]:
    """Sweep positions as the rotation of the slowest gear [deg] (one revolution per
    360 deg, as :func:`torquesplit.quasistatic.quasi_static_load_sharing` sweeps)."""
    from ..quasistatic import slowest_gear

    # the sweep's own gear and frame (the housing's 'rotation' of a held ring put every
    # position at 0 deg, a planet's absolute one 674 deg a revolution)
    try:
        gear, w, carrier = slowest_gear(results.kinematics)
    except ValueError:
        return np.asarray(results.times), "time [s]"
    frame = f" relative to {carrier}" if carrier else ""
    return np.degrees(results.times * w), f"rotation of {gear}{frame} [deg]"


def _unconverged_note(results) -> str:
    conv = np.asarray(getattr(results.solution, "converged", []), bool)
    bad = int((~conv).sum())
    return f"  ({bad} unconverged positions left out)" if bad else ""


# ============================================================ helpers: drawing
def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)  # Agg canvas of this figure only; no pyplot, no global backend
    return fig


def _panels(n: int, *, ncols: int = 1, sharex: bool = False, row_height: float = ROW_HEIGHT):
    nrows = math.ceil(n / ncols)
    fig = _figure(WIDTH if ncols == 1 else WIDTH * 1.5, row_height * nrows + 0.8)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharex=sharex).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    for ax in axes[:n]:  # every panel keeps its x tick labels (and unit label)
        ax.xaxis.set_tick_params(labelbottom=True)
    return fig, list(axes[:n])


LEAST_SPAN = 0.04
"""A panel's y axis spans at least this share of its largest value (a variation below
it is drawn at that scale, not magnified to the panel's height)."""


def _label(ax, xlabel: str, ylabel: str) -> None:
    ax.set_xlabel(xlabel, fontsize=FONT["label"])
    ax.set_ylabel(ylabel, fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["tick"])
    for axis in (ax.xaxis, ax.yaxis):
        formatter = axis.get_major_formatter()
        if axis.get_scale() == "linear" and hasattr(formatter, "set_useOffset"):
            formatter.set_useOffset(False)
    ax.grid(True, alpha=0.3)
    lo, hi = ax.dataLim.intervaly
    size = max(abs(lo), abs(hi))
    if np.isfinite(size) and hi - lo <= LEAST_SPAN * size and ax.get_autoscaley_on():
        # (nearly) constant data: a window of LEAST_SPAN of the value instead of the 8th
        # significant digit at full height (a planetary's equal mesh forces drew 0.25 mN
        # of rounding over the whole panel, the nominal line apparently above them)
        pad = 0.5 * LEAST_SPAN * size if size > 0 else 1.0
        ax.set_ylim(0.5 * (lo + hi) - pad, 0.5 * (lo + hi) + pad)


def _legend(ax) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=FONT["legend"],
              frameon=False, borderaxespad=0.0)


def _unsettled(met) -> str:
    """A title's note where the run did not settle (its numbers may still change: the
    run's warnings say so, a figure in a report did not)."""
    return ("" if met.settling.settled else
            "\nthe run had not settled by its end: these numbers may still change (see the "
            "run's warnings)")


def _suptitle(fig, results, what: str) -> None:
    name = results.model.model.name
    note = "" if getattr(results, "success", True) else \
        f"\nrun stopped: {results.message}"
    # each line wrapped to the figure's width (a list of the bodies not drawn ran off
    # both edges, a reviewer): about 0.55 em a character
    import textwrap

    width = max(40, int(fig.get_figwidth() * 72 / (0.55 * float(FONT["suptitle"]))))
    text = "\n".join(textwrap.fill(line, width) or line
                     for line in f"{name}: {what}{note}".split("\n"))
    fig.suptitle(text, fontsize=FONT["suptitle"])


def _nominal_lines(ax, values) -> None:
    """One dashed line per distinct nominal (equal-split static) force of the panel."""
    drawn: list[float] = []
    for v in values:
        if any(math.isclose(v, d, rel_tol=1e-9) for d in drawn):
            continue
        drawn.append(v)
        ax.axhline(v * _KN, color=REFERENCE_COLOR, ls="--", lw=1.2,
                   label=f"nominal static\n{v * _KN:.4g} kN")


def _mark_settled(ax, settle: float, start: float, unit: str) -> None:
    """Dotted line at the settled start, the transient before it shaded."""
    ax.axvline(settle, color="0.3", ls=":", lw=1.4, label=f"settled from\n{settle:.4g} {unit}")
    if settle > start:
        ax.axvspan(start, settle, color="0.85", alpha=0.6, lw=0, label="transient")


_MARKERS = ("o", "s", "^")
_DASHES = ("-", (0, (5, 2)), (0, (5, 2, 1, 2)), (0, (1.5, 1.5)))


def _line_style(i: int, n: int) -> dict:
    """Colour and dash of line i of n overlaid: a path lying on another (equal sharing)
    still shows through the gaps of its dashes, and the paths stay apart in greyscale."""
    return {"color": _color(i), "lw": 1.4, "ls": _DASHES[i % len(_DASHES)]}


def _spike_style(i: int, n: int) -> dict:
    """Colour and width of spectrum line i of n: earlier lines wider, so that coinciding
    spectral lines show every colour."""
    return {"color": _color(i), "lw": 0.9 + 0.9 * (n - 1 - i)}


def _force_text(value: float) -> str:
    """A force in N, kN or MN by its size once rounded to 4 significant digits (999.96 N
    reads '1 kN', not '1000 N'): the spectrum's axis is in N, and '0.1924 kN' beside an
    axis at 190 N read as a mismatch.  A value that is not finite is said in N."""
    if not math.isfinite(value):
        return f"{value} N"
    for scale, unit in ((1.0, "N"), (_KN, "kN")):
        text = f"{value * scale:.4g}"
        if abs(float(text)) < 1e3:
            return f"{text} {unit}"
    return f"{value * 1e-6:.4g} MN"


def _short_text(text: str, most: int = 28) -> str:
    """A legend label cut to ``most`` characters (a group of many meshes' names)."""
    return text if len(text) <= most else text[: most - 1] + "…"


def _group_label(group: str, members) -> str:
    n = len(members)
    return f"group {group} ({n} mesh{'es' if n != 1 else ''})"


def _time_unit(t: np.ndarray) -> tuple[float, str]:
    """Milliseconds for runs shorter than one second, else seconds."""
    end = float(np.nanmax(np.abs(t))) if np.size(t) else 0.0
    return (1e3, "ms") if end < 1.0 else (1.0, "s")


def _hz(f: float) -> str:
    return f"{f / 1e3:.4g} kHz" if f >= 1e3 else f"{f:.4g} Hz"


def _color(i: int) -> str:
    return f"C{i % 10}"


def _order_color(j: int) -> str:
    return ("tab:red", "tab:purple", "tab:brown", "tab:olive", "tab:cyan")[j % 5]
