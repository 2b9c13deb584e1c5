"""Figures of a speed sweep and of a Campbell diagram (matplotlib OO API, Agg, no pyplot).

The figures consume the Datasets of :mod:`.maps` and recompute nothing.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def _figure(w, h):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


_SWEEP_AXES = {  # variable -> (axis label, scale of the stored SI value)
    "dynamic_factor": ("dynamic factor\n(peak / static force) [-]", 1.0),
    "peak_to_nominal": ("peak / nominal force [-]", 1.0),
    "load_sharing_mean_force": ("load-sharing coefficient\n(mean forces) [-]", 1.0),
    "load_sharing_instantaneous": ("load-sharing coefficient\n(largest instantaneous) [-]",
                                   1.0),
    "rms_transmission_error": ("RMS dynamic\ntransmission error [µm]", 1e6),
    "peak_force": ("peak mesh force [kN]", 1e-3),
}


def sweep_variables(ds) -> list[str]:
    """The panels of :func:`sweep_figure` by default: the dynamic factor, the load-sharing
    coefficient where some mesh shares its load with others (a coefficient that is 1
    everywhere says nothing), and the RMS transmission error."""
    out = ["dynamic_factor"]
    lsc = (ds["load_sharing_mean_force"].values if "load_sharing_mean_force" in ds
           else np.ones(1))
    if np.any(np.abs(np.nan_to_num(lsc, nan=1.0) - 1.0) > 1e-9):
        out.append("load_sharing_mean_force")
    elif "load_sharing_instantaneous" in ds:  # (equal means, unequal instants: Ji & Li's
        # stages, whose instantaneous coefficient moves with speed, had no panel)
        inst = np.nan_to_num(ds["load_sharing_instantaneous"].values, nan=1.0)
        if np.any(np.abs(inst - 1.0) > 1e-9):
            out.append("load_sharing_instantaneous")
    if "rms_transmission_error" in ds:
        out.append("rms_transmission_error")
    return out


def sweep_figure(ds, variables=None):
    """Speed response of a sweep (:func:`~torquesplit.steady.maps.sweep_speed`), one panel
    per variable (``variables``: a name or a list; default :func:`sweep_variables`), each
    mesh against speed: stable solid, unstable dashed, turning points (jump speeds)
    dotted, critical speeds (natural frequency x mesh order) as grey lines labelled in
    the top panel, run-up / run-down time integrations as markers when present."""
    if "load_sharing" in ds and "load_sharing_mean_force" not in ds:
        ds = ds.rename(load_sharing="load_sharing_mean_force")  # (an older sweep file)
    if variables is None:
        variables = sweep_variables(ds)
    elif isinstance(variables, str):
        variables = [variables]
    variables = ["load_sharing_mean_force" if v == "load_sharing" else v for v in variables]
    rpm = ds["speed_rpm"].values
    lo, hi = float(np.nanmin(rpm)), float(np.nanmax(rpm))
    groups = critical_speed_groups(ds, lo, hi)
    fig = _figure(9, 1.6 + 2.6 * len(variables) + 0.12 * len(groups))
    grid = fig.add_gridspec(len(variables) + 1, 1,
                            height_ratios=[2.6] * len(variables) + [0.1 + 0.12 * len(groups)])
    axes = [fig.add_subplot(grid[0])]
    axes += [fig.add_subplot(grid[i], sharex=axes[0]) for i in range(1, len(variables))]
    asked = ds.attrs.get("requested_speeds_rpm")
    if isinstance(asked, str):  # (a file's attribute: the list as JSON)
        import json

        asked = json.loads(asked)
    stopped = (not int(ds.attrs.get("complete", 1)) and asked is not None
               and len(asked) == 2 and rpm.size)
    for n, (ax, variable) in enumerate(zip(axes, variables)):
        _sweep_panel(ax, ds, variable)
        if stopped:  # the range asked that the sweep did not reach, said on the figure
            # (in the direction asked: a branch that turned back still heads there)
            end = float(asked[1])
            gap = sorted((float(rpm[-1]), end))
            ax.axvspan(*gap, color="0.85", alpha=0.6, lw=0,
                       label="not computed: the sweep stopped\n(see its message)"
                       if n == 0 else None)
        for f in ds.attrs.get("fold_speeds_rpm", []):
            ax.axvline(f, color="k", lw=0.8, ls=":")
        for k, (c, _) in enumerate(groups):
            ax.axvline(c, color="0.6", lw=0.6)
            if n == 0:  # a short tag above the panel (two rows where tags crowd), the
                # full labels listed under the figure
                row = k % 2 if len(groups) > 1 and _crowded(groups, k, hi - lo) else 0
                ax.annotate(str(k + 1), (c, 1.0), xycoords=ax.get_xaxis_transform(),
                            xytext=(0, 2 + 8 * row), textcoords="offset points",
                            fontsize=6, ha="center", va="bottom", color="0.35")
        label, _ = _SWEEP_AXES.get(variable, (ds[variable].attrs.get("long_name", variable),
                                              1.0))
        ax.set_ylabel(label, fontsize=8)
        _least_span(ax)
        ax.grid(alpha=0.3)
        if n < len(variables) - 1:
            ax.tick_params(labelbottom=False)
    axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1].set_xlabel("input speed [rpm]")
    notes = fig.add_subplot(grid[-1])
    notes.axis("off")
    if groups:
        tags = [f"{k + 1}: {c:.0f} rpm, {', '.join(labs)}" for k, (c, labs) in
                enumerate(groups)]
        notes.text(0.0, 1.0, "\n".join(tags), fontsize=6, va="top", ha="left",
                   transform=notes.transAxes, color="0.3")
        notes.set_title("critical speeds (natural frequency = order x excitation "
                        "frequency)", fontsize=7, loc="left")
    dropped = ds.attrs.get("dropped_excitations") or []
    if isinstance(dropped, str):  # a file's attribute: the list as JSON
        import json

        try:
            dropped = json.loads(dropped)
        except ValueError:
            dropped = [dropped]
    note = f"\nreplaced by their means: {'; '.join(dropped)}" if dropped else ""
    import textwrap

    judged = ("max_multiplier" in ds
              and bool(np.isfinite(np.asarray(ds["max_multiplier"].values, float)).any()))
    lines = ("solid stable, dashed unstable" if judged else
             "stability not computed")  # (--no-stability: no curve is judged)
    title = (f"{ds.attrs.get('model', '')}: speed response ({lines}, dotted: turning "
             f"points, grey: critical speeds)")
    # (wrapped: a long model name ran the title off the figure's left edge)
    axes[0].set_title(textwrap.fill(title, 80) + note, fontsize=9, pad=16)
    return fig


def _least_span(ax, share: float = 0.02) -> None:
    """At least ``share`` of the panel's value on its y axis, and no offset notation: a
    coefficient of 1 within rounding filled its panel with 1e-8 wiggles ('1e-8+1')."""
    lo, hi = ax.get_ylim()
    mid = 0.5 * (lo + hi)
    floor = share * abs(mid)
    if floor > 0 and hi - lo < floor:
        ax.set_ylim(mid - floor / 2, mid + floor / 2)
    ax.ticklabel_format(axis="y", useOffset=False)


def _crowded(groups, k, span) -> bool:
    """Whether tag k sits within 2 % of the range of a neighbour's."""
    c = groups[k][0]
    near = [abs(c - groups[i][0]) for i in (k - 1, k + 1) if 0 <= i < len(groups)]
    return bool(near) and min(near) < 0.02 * max(span, 1e-12)


def _sweep_panel(ax, ds, variable):
    """One variable of a sweep per mesh, and its run-up / run-down markers."""
    rpm = ds["speed_rpm"].values
    from torquesplit.steady.maps import counted_points

    stable = counted_points(ds)
    _, scale = _SWEEP_AXES.get(variable, ("", 1.0))
    drawn = []  # (values, first line): a curve equal to one drawn joins its label
    # equal: to 1e-6 of the panel's largest value, far below what a figure shows (at
    # 1e-9 relative, identical planets' curves split on their round-off, a planetary
    # reviewer's legend listed two of three ring meshes apart from the third)
    values = ds[variable].values * scale
    tol = 1e-6 * float(np.nanmax(np.abs(values))) if np.isfinite(values).any() else 0.0
    for j, mesh in enumerate(ds["mesh"].values):
        y = values[:, j]
        same = next((ln for yy, ln in drawn
                     if np.allclose(y, yy, rtol=0.0, atol=tol, equal_nan=True)), None)
        if same is not None:  # (identical planets: eight entries over one line)
            same.set_label(f"{same.get_label()}, {mesh}")
            continue
        line = None
        first = None
        # one polyline per run of stable (or unstable) segments: a dash pattern drawn
        # segment by segment restarts at every point and looks solid
        seg = [bool(stable[k] and stable[k + 1]) for k in range(len(rpm) - 1)]
        k = 0
        while k < len(seg):
            e = k
            while e + 1 < len(seg) and seg[e + 1] == seg[k]:
                e += 1
            # one colour per mesh in every panel (a curve equal to one drawn is left out:
            # with the cycle's next colour, a lower panel's m12 took m21's)
            (line,) = ax.plot(rpm[k:e + 2], y[k:e + 2], "-" if seg[k] else "--",
                              color=LINE_COLOURS[j % len(LINE_COLOURS)],
                              label=str(mesh) if k == 0 else None, lw=1.3)
            first = first or line
            k = e + 1
        if first is not None:
            drawn.append((y, first))
        colour = line.get_color() if line is not None else None
        if j == 0 and "instability" in ds:  # where the response is not on the curve
            from torquesplit.steady.sweep import flag_runs

            runs = flag_runs(ds["instability"].values == "period doubling")
            for k, (a, b) in enumerate(runs):  # (to midway to the stable neighbours)
                lo = 0.5 * (rpm[a - 1] + rpm[a]) if a > 0 else rpm[a]
                hi = 0.5 * (rpm[b] + rpm[b + 1]) if b + 1 < len(rpm) else rpm[b]
                ax.axvspan(lo, hi, color="tab:red", alpha=0.08, lw=0,
                           label="period doubling (the response is\nnot on this curve)"
                           if k == 0 else None)
        check = f"run_up_{variable}"
        if check in ds:
            ax.plot(ds["check_speed_rpm"].values, ds[check].values[:, j] * scale, "^", ms=4,
                    color=colour, alpha=0.7,
                    label="run-up (time integration)" if j == 0 else None)
            ax.plot(ds["check_speed_rpm"].values,
                    ds[f"run_down_{variable}"].values[:, j] * scale, "v", ms=4, color=colour,
                    alpha=0.7, label="run-down (time integration)" if j == 0 else None)


def critical_speed_groups(ds, lo: float, hi: float, merge: float = 0.025):
    """Critical speeds of ``ds`` inside [lo, hi] rpm as (speed, labels): crossings closer
    than ``merge`` of the range (a degenerate pair of modes, two orders meeting; 2.5 %:
    about the width of a label at the figure's size) share one
    line and one label block instead of printing over each other."""
    crit = sorted((float(c), str(lab)) for c, lab in zip(
        ds.attrs.get("critical_speeds_rpm", []), ds.attrs.get("critical_speed_labels", []),
        strict=False) if lo <= c <= hi)
    groups: list[tuple[list[float], list[str]]] = []
    for c, lab in crit:
        if groups and c - groups[-1][0][-1] <= merge * max(hi - lo, 1e-12):
            groups[-1][0].append(c)
            if lab not in groups[-1][1]:
                groups[-1][1].append(lab)
        else:
            groups.append(([c], [lab]))
    return [(float(np.mean(cs)), labs) for cs, labs in groups]


def campbell_figure(ds):
    """Natural frequencies and excitation lines against speed; crossings marked.

    Labels that would print over each other share one text: modes of equal frequency
    ('6, 7': a degenerate pair), excitation lines that end at the same frequency ('10x in1
    = 20x out1': coinciding harmonics).  Critical speeds are grey dotted lines with their
    speeds (staggered in rows; one too close to the others in every row is left
    unlabelled), the model's operating speed a solid line; the legend sits under the
    axes, clear of the lines' labels.  Where the slowest mesh's orders end below
    :data:`ZOOM_SHARE` of the highest line (a two-stage drive: the stage-2 orders and the
    first modes shared the bottom tenth of the axis), a second panel below shows them."""
    import textwrap

    fmax = float(np.nanmax(ds["excitation_frequency"].values))
    zoom = _zoom_top(ds, fmax * 1.05)
    if zoom is None:
        fig = _figure(9, 6.5)
        ax = fig.add_subplot()
        axes = [ax]
    else:
        fig = _figure(9, 9.5)
        ax, low = fig.subplots(2, 1, sharex=True, gridspec_kw=dict(height_ratios=[3, 2]))
        axes = [ax, low]
    rows = _campbell_panel(ax, ds, fmax * 1.05, labelled=True, floor=zoom or 0.0)
    if zoom is not None:
        _campbell_panel(low, ds, zoom, labelled=False)
        ax.set_xlabel("")  # (the speed axis is the panel's below)
        low.set_title(f"below {zoom:.4g} Hz: the slower meshes' orders and the lowest "
                      f"modes", fontsize=8, loc="left")
    name = textwrap.shorten(str(ds.attrs.get("model", "")), 90, placeholder="...")
    ax.set_title(f"{name}: Campbell diagram\nsolid: natural frequencies (numbered); dashed: "
                 "excitation orders; dotted: critical speeds [rpm]", fontsize=9,
                 pad=6 + 26 * max(rows, 1))
    under = axes[-1]
    ncol = 2 if len(ax.get_legend_handles_labels()[1]) > 3 else 1
    handles, labels = ax.get_legend_handles_labels()
    under.legend(handles, labels, fontsize=7, loc="upper center",
                 bbox_to_anchor=(0.5, -0.1 if zoom is None else -0.17), ncol=ncol,
                 frameon=False)
    return fig


#: a second panel shows the slowest mesh's orders where they end below this share of the
#: highest excitation line
ZOOM_SHARE = 0.2


def _zoom_top(ds, top: float) -> float | None:
    """The top [Hz] of the low panel: a little above where the slowest mesh's orders end
    at the highest speed, or None where they take more than ZOOM_SHARE of the axis."""
    ends: dict[str, float] = {}
    for j, lab in enumerate(ds["line"].values):
        order, _, source = str(lab).partition(" x ")
        if source.startswith("mesh"):
            f = float(ds["excitation_frequency"].values[-1, j])
            ends[source] = max(ends.get(source, 0.0), f)
    if len(ends) < 2:
        return None
    slow = min(ends.values())
    return 1.1 * slow if 0 < 1.1 * slow < ZOOM_SHARE * top else None


def _campbell_panel(ax, ds, top: float, *, labelled: bool, floor: float = 0.0) -> int:
    """One panel of the Campbell diagram from 0 to ``top`` Hz: natural frequencies with
    their numbers, excitation lines with their orders, critical speeds (their speeds
    printed above the axes where ``labelled``), the operating speed.  Order labels below
    ``floor`` are left to the panel below (they stacked over each other and the modes'
    numbers), and a line that leaves the panel in its first quarter is not labelled (its
    label sat outside the axes).  Returns the rows of critical-speed labels."""
    rpm = ds["speed_rpm"].values
    near = 0.02 * top  # two mode labels closer than this (in Hz) would overlap
    ends: list[tuple[float, list[str]]] = []
    for m in range(ds.sizes["mode"]):
        fn = ds["natural_frequency"].values[:, m]
        ax.plot(rpm, fn, color="k", lw=0.8)
        if np.isfinite(fn[-1]) and 0 < fn[-1] <= top:  # mode number at its end
            _merge_label(ends, float(fn[-1]), f"{int(ds['mode'].values[m])}", near)
    for f, labels in ends:
        ax.annotate(", ".join(labels), (rpm[-1], f), fontsize=7, xytext=(3, 0),
                    textcoords="offset points", va="center")
    # one colour per source (a mesh or a group of meshes of one frequency: its orders
    # 1..k, labelled inside the axes at their ends; a shaft), one legend entry each
    sources: dict[str, list[tuple[int, int]]] = {}
    for j, lab in enumerate(ds["line"].values):
        order, _, source = str(lab).partition(" x ")
        sources.setdefault(source, []).append((j, int(order)))
    several = sum(len(m) > 1 for m in sources.values()) > 1
    # a label's height in Hz: order labels closer than this are thinned (one source) or
    # stacked with a leader line (lines of different sources)
    height = top * 9.0 / (ax.figure.get_figheight() * 72 * ax.get_position().height)
    tops: list[tuple[float, float, list[str], str]] = []  # (x, y, labels, colour)
    for k, (source, members) in enumerate(sources.items()):
        colour = LINE_COLOURS[k % len(LINE_COLOURS)]
        orders = [o for _, o in members]
        label = source if orders == [1] else f"{source} x {min(orders)}..{max(orders)}"
        short = _short(source) if several else ""
        ends = []
        for i, (j, order) in enumerate(members):
            fe = ds["excitation_frequency"].values[:, j]
            ax.plot(rpm, fe, lw=0.8, ls="--", color=colour, label=label if i == 0 else None)
            inside = np.flatnonzero(fe <= top)
            if len(members) > 1 and inside.size:  # the order at the line's last point
                x_end, y_end = float(rpm[inside[-1]]), float(fe[inside[-1]])
                if (y_end >= floor and x_end >= rpm[0] + 0.25 * (rpm[-1] - rpm[0])):
                    ends.append((x_end, y_end, f"{order}x {short}".strip()))
        for x, y, text in _thinned(ends, height):
            # '=' only for lines that coincide (a harmonic of one mesh on another's)
            same = next((t for t in tops if abs(t[0] - x) < 1e-9 * max(abs(x), 1.0)
                         and abs(t[1] - y) <= COINCIDE * max(abs(y), 1e-12)), None)
            if same is None:
                tops.append((x, y, [text], colour))
            else:
                same[2].append(text)
    for x, y, at, labels, colour in _stacked(tops, height):  # right-aligned at the line's
        ax.annotate(" = ".join(labels), (x, y), xytext=(x, at), textcoords="data",
                    fontsize=7, color=colour, ha="right", va="bottom",
                    bbox=dict(fc="white", ec="none", alpha=0.8, pad=0.3),
                    arrowprops=(dict(arrowstyle="-", color=colour, lw=0.4) if at > y + 1e-9
                                else None))
    rows = _critical_labels(ax, sorted(ds.attrs.get("critical_speeds_rpm", [])),
                            float(rpm.min()), float(rpm.max()), labelled=labelled)
    # crossings that the planets' mesh phasing leaves unexcited (Parker & Lin 2004)
    for i, c in enumerate(ds.attrs.get("suppressed_speeds_rpm", [])):
        ax.axvline(c, color="0.75", lw=0.5, ls="-.",
                   label="suppressed by mesh phasing (Parker & Lin 2004)" if i == 0 else None)
    op = ds.attrs.get("model_speed_rpm")
    if op is not None and float(rpm.min()) <= float(op) <= float(rpm.max()):
        ax.axvline(float(op), color="C3", lw=1.4, alpha=0.7,
                   label=f"operating speed (the model's drive): {float(op):.5g} rpm")
    ax.set_ylim(0, top)
    ax.set_xlim(float(rpm.min()), float(rpm.max()))
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    return rows


#: excitation lines' colours: matplotlib's cycle without C3, the operating speed's red
LINE_COLOURS = tuple(f"C{i}" for i in range(10) if i != 3)
#: two order lines' ends printed as one label ("1x m11 = 8x m12") within this fraction
COINCIDE = 1e-3

#: a critical speed's label [points]: rotated text of this size, and the least gap
#: between two labels of one row
CRITICAL_FONT, CRITICAL_GAP, CRITICAL_ROWS = 7, 9.0, 3
#: critical speeds within this fraction of a labelled one get no label of their own
CRITICAL_SAME = 5e-3


def _critical_labels(ax, crit, lo, hi, *, labelled: bool = True) -> int:
    """Draw the critical speeds ``crit`` [rpm] as dotted lines, their speeds above the
    axes in up to CRITICAL_ROWS rows (a label goes to the first row where it clears the
    last one by CRITICAL_GAP points; none is printed where no row has room; only the lines
    where not ``labelled``: a second panel).  Returns the rows used."""
    width_pt = ax.figure.get_figwidth() * 72 * 0.8  # about the axes' width
    last: list[float] = []
    said: list[float] = []  # crossings within CRITICAL_SAME of a labelled one (a
    for i, c in enumerate(crit):  # degenerate pair of modes, two lines of one
        ax.axvline(c, color="0.35", lw=0.6, ls=":",  # frequency): one label
                   label="critical speed (a crossing)" if i == 0 and labelled else None)
        if not labelled:
            continue
        if any(abs(c - p) <= CRITICAL_SAME * abs(p) for p in said):
            continue
        said.append(c)
        x = (c - lo) / max(hi - lo, 1e-12) * width_pt
        row = next((r for r, p in enumerate(last) if x - p >= CRITICAL_GAP), None)
        if row is None and len(last) < CRITICAL_ROWS:
            row = len(last)
            last.append(x)
        if row is None:
            continue
        last[row] = x
        ax.annotate(f"{c:.0f}", (c, 1.0), xycoords=ax.get_xaxis_transform(),
                    fontsize=CRITICAL_FONT, rotation=90, ha="center", va="bottom",
                    color="0.35", xytext=(0, 2 + 26 * row), textcoords="offset points")
    return len(last)


def _short(source: str) -> str:
    """A short tag of an excitation source for a line's label."""
    text = source.removeprefix("meshes ").removeprefix("mesh ")
    return text if len(text) <= 18 else text[:16] + "..."


def _thinned(ends: list, height: float) -> list:
    """One source's order labels ``(x, y, text)`` at its lines' ends, every one whose end
    clears the last kept by ``height`` (the lowest and the highest order always: the
    legend gives the range), so that dense low orders do not print over each other."""
    ends = sorted(ends, key=lambda e: (e[0], e[1]))
    kept: list = []
    for e in ends:
        if not kept or e[0] != kept[-1][0] or e[1] - kept[-1][1] >= height:
            kept.append(e)
    if ends and kept[-1] is not ends[-1]:  # the highest order replaces the last kept
        kept[-1 if len(kept) > 1 else len(kept):] = [ends[-1]]
    return kept


def _stacked(tops: list, near: float) -> list:
    """The order labels ``(x, y, texts, colour)`` with a text height each: labels that end
    at one speed are stacked upwards at least ``near`` apart (a leader line joins a
    moved one to its line), not printed over each other."""
    out = []
    for x in sorted({t[0] for t in tops}):
        column = sorted((t for t in tops if t[0] == x), key=lambda t: t[1])
        at = -math.inf
        for _, y, texts, colour in column:
            at = max(y, at + near)
            out.append((x, y, at, texts, colour))
    return out


def _merge_label(ends: list, y: float, text: str, near: float) -> None:
    """Add ``text`` at height ``y`` to the label within ``near`` of it, or a new one."""
    for f, labels in ends:
        if abs(f - y) <= near:
            labels.append(text)
            return
    ends.append((y, [text]))


def save(fig, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    return path
