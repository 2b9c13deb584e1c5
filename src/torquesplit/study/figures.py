"""Figures of a study, drawn from its Dataset only (no metric is recomputed here).

Matplotlib's object-oriented API on Agg canvases, no pyplot and no global state, as in
:mod:`torquesplit.plot`.

==========================  ==============================================================
design                      figures (one file per output family, PNG and SVG)
==========================  ==============================================================
grid, 1 parameter           output against the parameter, one curve per load-sharing group
                            or mesh (the papers' convention), the system value bold;
                            failed cases marked with a red x on the axis
grid, 2 parameters          one colour map per output (panels: members of a family)
grid, 3 parameters          maps over the first two, one panel per value of the third
monte_carlo                 per output: histogram; empirical CDF with its 95 % band
                            (Dvoretzky-Kiefer-Wolfowitz); running mean with its 95 %
                            interval and running 95th percentile against sample count
sensitivity                 tornado chart per output: factors ranked by Morris mu* or
                            Sobol ST, with bootstrap intervals (and S1 for Sobol)
==========================  ==============================================================

Axes carry units: parameters in the unit the study file wrote them in, forces in kN.
"""

from __future__ import annotations

import json
import logging
import math
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from . import outputs as out_mod
from .dataset import display_values

log = logging.getLogger(__name__)

WIDTH = 7.5
MAX_MEMBERS = 12
"""Curves (or map panels) per figure; further members are left out (and logged)."""
MAX_FIGURES = 40


def write_study_figures(ds, directory, formats=("png", "svg"), dpi: int = 130) -> list[Path]:
    """Write every figure that applies to the study Dataset ``ds``; returns the paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    design = ds.attrs["design"]
    jobs = []
    if design == "grid":
        params = [d for d in ds[_output_vars(ds)[0]].dims]
        fams = _families(ds)
        for fam, members in fams.items():
            if len(params) == 1:
                jobs.append((_safe(fam), lambda f=fam, m=members: curves_figure(ds, f, m)))
            else:
                jobs.append((f"map_{_safe(fam)}", lambda f=fam, m=members: maps_figure(ds, f, m)))
    elif design == "monte_carlo":
        for var in _output_vars(ds):
            jobs.append((f"mc_{_safe(var)}",
                         lambda v=var: monte_carlo_figure(ds, v, _confidence(ds))))
    elif design == "sensitivity":
        for var in _output_vars(ds):
            jobs.append((f"tornado_{_safe(var)}", lambda v=var: tornado_figure(ds, v)))
    if len(jobs) > MAX_FIGURES:
        log.info("%d figures apply; writing the first %d", len(jobs), MAX_FIGURES)
        jobs = jobs[:MAX_FIGURES]
    written = []
    for name, make in jobs:
        fig = make()
        for fmt in formats:
            path = directory / f"{name}.{fmt}"
            # whole or absent: a Ctrl-C while saving leaves no half-written figure
            tmp = path.with_name(f".{path.name}.tmp")
            try:
                fig.savefig(tmp, dpi=dpi, format=fmt)
                tmp.replace(path)
            finally:
                tmp.unlink(missing_ok=True)
            written.append(path)
    return written


# ============================================================================ grid
LEGEND_WIDTH = 28
"""Characters per line of a legend entry (several equal members joined by '=')."""


def curves_figure(ds, family: str, members: list[tuple[str, str]]) -> Figure:
    """A 1-parameter grid: the outputs of one family against the parameter."""
    var0 = members[0][1]
    pname = ds[var0].dims[0]
    x, xunit = display_values(ds, pname)
    fig = _figure(WIDTH, 4.2)
    ax = fig.add_subplot()
    unit, scale = _out_unit(var0)
    # a curve equal to one drawn already (the system's coefficient is its worst group's,
    # a group of one mesh is that mesh) is not drawn again, hidden under it: its name
    # joins that curve's legend entry
    drawn: list[tuple[np.ndarray, object]] = []
    for i, (member, var) in enumerate(members[:MAX_MEMBERS]):
        y = ds[var].values * scale
        same = next((line for yy, line in drawn
                     if np.allclose(y, yy, rtol=1e-12, atol=0.0, equal_nan=True)), None)
        if same is not None:  # (wrapped: the equal members ran over the axes, a reviewer)
            same.set_label(_wrap(f"{same.get_label()} = {member}", LEGEND_WIDTH))
            continue
        if member == "system":
            line, = ax.plot(x, y, color="k", lw=2.4, marker="o", ms=3, label="system",
                            zorder=5)
        else:
            line, = ax.plot(x, y, color=_color(i), lw=1.4, ls=_DASHES[i % len(_DASHES)],
                            marker="o", ms=2.5, label=member)
        drawn.append((y, line))
    _mark_failed(ax, x, ds["status"].values)
    _log_axis(ds, pname, ax.set_xscale)
    ax.set_xlabel(_wrap(f"{_param_label(ds, pname)} [{xunit}]", 70))
    ax.set_ylabel(_wrap(f"{_family_text(family)} [{unit}]", 45))
    ax.grid(True, alpha=0.3)
    ax.yaxis.get_major_formatter().set_useOffset(False)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, fontsize=8)
    _suptitle(fig, f"{_title(ds)}: {_family_text(family)}")
    return fig


def maps_figure(ds, family: str, members: list[tuple[str, str]]) -> Figure:
    """A 2- or 3-parameter grid: colour maps of one family over the first two parameters
    (a panel per member of the family; with 3 parameters, a row per value of the third
    and at most 4 members)."""
    dims = ds[members[0][1]].dims
    third = dims[2] if len(dims) == 3 else None
    if third:
        members = members[:4]
        panels = [(m, r) for r in range(min(ds.sizes[third], 6)) for m in members]
        ncols = len(members)
    else:
        members = members[:MAX_MEMBERS]
        panels = [(m, 0) for m in members]
        ncols = min(3, len(members))
    nrows = math.ceil(len(panels) / ncols)
    fig = _figure(max(WIDTH, 3.6 * ncols), 3.0 * nrows + 0.8)
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    x, xunit = display_values(ds, dims[0])
    y, yunit = display_values(ds, dims[1])
    unit, scale = _out_unit(members[0][1])
    # one colour scale for the family (every member, every value of a third parameter):
    # the same colour is the same value in every panel
    full = np.concatenate([np.ravel(ds[v].values) * scale for _, v in members])
    limits = ({"vmin": float(np.nanmin(full)), "vmax": float(np.nanmax(full))}
              if np.isfinite(full).any() else {})
    for ax, ((member, var), r) in zip(axes, panels):
        data = ds[var]
        status = ds["status"]
        title = member
        if third:
            data = data.isel({third: r})
            status = status.isel({third: r})
            tv, tu = display_values(ds, third)
            title += f", {third} = {tv[r]:.4g} {tu}"
        z = data.transpose(dims[1], dims[0]).values * scale
        mesh = ax.pcolormesh(_edges(ds, dims[0], x), _edges(ds, dims[1], y),
                             np.ma.masked_invalid(z), shading="flat", cmap="viridis", **limits)
        _log_axis(ds, dims[0], ax.set_xscale)
        _log_axis(ds, dims[1], ax.set_yscale)
        if z.size <= CELL_VALUES:  # a small grid: each cell's value in it
            _cell_values(ax, x, y, z, mesh)
        elif np.isfinite(z).all() and len(x) > 1 and len(y) > 1 and np.nanstd(z) > 0:
            lines = ax.contour(x, y, z, colors="w", linewidths=0.6, alpha=0.8)
            ax.clabel(lines, fontsize=6, fmt="%.4g")
        kind = _kind(status.transpose(dims[1], dims[0]).values)
        for k, (marker, color, label) in _MARKS.items():
            yy, xx = np.nonzero(kind == k)
            if yy.size:
                ax.plot(np.asarray(x)[xx], np.asarray(y)[yy], ls="none", marker=marker,
                        color=color, ms=6, label=label)
        bar = fig.colorbar(mesh, ax=ax, label=f"[{unit}]")  # (the quantity: the title)
        bar.formatter.set_useOffset(False)
        bar.update_ticks()
        ax.set_title(title, fontsize=9)
        # (wrapped: a parameter set on three paths ran into the next panel's label)
        ax.set_xlabel(textwrap.fill(f"{_param_label(ds, dims[0])} [{xunit}]", 40), fontsize=8)
        ax.set_ylabel(textwrap.fill(f"{_param_label(ds, dims[1])} [{yunit}]", 40), fontsize=8)
        ax.tick_params(labelsize=7)
    _suptitle(fig, f"{_title(ds)}: {_family_text(family)}")
    return fig


# ============================================================================ Monte Carlo
def monte_carlo_figure(ds, var: str, confidence: float = 0.95) -> Figure:
    """Histogram, ECDF with a DKW band, and convergence of the mean and 95th percentile."""
    unit, scale = _out_unit(var)
    y = ds[var].values * scale
    ok = np.isfinite(y)
    fig = _figure(WIDTH * 1.6, 3.8)
    ax_h, ax_c, ax_v = fig.subplots(1, 3)
    label = f"{ds[var].attrs.get('output', var)} [{unit}]"
    v = np.sort(y[ok])
    n = v.size
    if n:
        ax_h.hist(v, bins=max(5, min(40, int(math.sqrt(n)) + 1)), color=_color(0), alpha=0.8)
        ecdf = np.arange(1, n + 1) / n
        eps = math.sqrt(math.log(2 / (1 - confidence)) / (2 * n))  # Dvoretzky-Kiefer-Wolfowitz
        ax_c.step(v, ecdf, where="post", color=_color(0), label="empirical CDF")
        ax_c.fill_between(v, np.clip(ecdf - eps, 0, 1), np.clip(ecdf + eps, 0, 1),
                          step="post", color=_color(0), alpha=0.25,
                          label=f"{confidence:.0%} band (DKW)")
        seq = y[ok]  # in sample order: the convergence a stopping rule sees
        k = np.arange(1, seq.size + 1)
        mean = np.cumsum(seq) / k
        if seq.size > 1:
            from scipy import stats

            csum2 = np.cumsum(seq ** 2)
            var_run = np.maximum(csum2 / k - mean ** 2, 0) * k / np.maximum(k - 1, 1)
            t = stats.t.ppf(0.5 + confidence / 2, np.maximum(k - 1, 1))
            half = t * np.sqrt(var_run / k)
            half[0] = np.nan
            ax_v.fill_between(k, mean - half, mean + half, color=_color(0), alpha=0.25,
                              label=f"{confidence:.0%} interval of the mean")
        ax_v.plot(k, mean, color=_color(0), label="running mean")
        # a 95th percentile of fewer than 20 samples is their largest: drawn from 20 on
        if seq.size >= P95_FROM:
            p95 = [np.quantile(seq[:j], 0.95) for j in range(P95_FROM, seq.size + 1)]
            ax_v.plot(k[P95_FROM - 1:], p95, color=_color(1), ls="--",
                      label=f"running 95th percentile (from {P95_FROM} samples)")
        _stopping_band(ds, var, ax_v, scale)
    ax_h.set_xlabel(label, fontsize=8)
    ax_h.set_ylabel("cases")
    ax_h.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts: whole numbers
    ax_c.set_xlabel(label, fontsize=8)
    ax_c.set_ylabel("cumulative probability [-]")
    ax_v.set_xlabel("samples")
    ax_v.set_ylabel(label, fontsize=8)
    for ax in (ax_h, ax_c, ax_v):
        ax.grid(True, alpha=0.3)
    ax_c.legend(fontsize=7, loc="lower right")
    ax_v.legend(fontsize=7)
    note = _status_note(ds["status"].values)
    what = f"statistics over {n} of {y.size} cases" if n < y.size else f"{n} samples"
    _suptitle(fig, f"{_title(ds)}: {what}{note}")
    return fig


#: the running 95th percentile of a Monte Carlo is drawn from this many samples on
P95_FROM = 20


def _confidence(ds) -> float:
    """The stopping rule's confidence (its intervals are drawn at it), else 0.95."""
    rule = ds.attrs.get("stopping_rule")
    return float(json.loads(rule)["confidence"]) if rule else 0.95


def _stopping_band(ds, var, ax, scale) -> None:
    """The stopping rule's target band around its final estimate, on the watched
    output's running statistic."""
    a = ds.attrs
    if "stopping_target_met" not in a:
        return
    rule = json.loads(a["stopping_rule"])
    if ds[var].attrs.get("output") != rule["output"]:
        return
    est, target = a["stopping_estimate"] * scale, a["stopping_target"] * scale
    met = "met" if a["stopping_target_met"] else "not met"
    ax.axhspan(est - target, est + target, color=_color(2), alpha=0.2,
               label=f"stopping target +/-{target:.3g} ({a['stopping_statistic']}, {met})")
    ax.axvline(a["stopping_cases"], color=_color(2), lw=1, ls=":")
    if "stopping_lower" in a and np.isfinite(a["stopping_lower"]):  # the interval itself
        lo, hi = a["stopping_lower"] * scale, a["stopping_upper"] * scale
        ax.errorbar([a["stopping_cases"]], [est], yerr=[[est - lo], [hi - est]],
                    color=_color(2), capsize=4, lw=1.5,
                    label=f"{rule['confidence']:.0%} interval at the stop")


# ============================================================================ sensitivity
def tornado_figure(ds, var: str) -> Figure:
    """Factors ranked by importance for one output (Morris mu* or Sobol ST)."""
    key = ds.attrs["ranking"]
    # mu* in the output's unit as the axis names it (kN for a force: it drew N on an axis
    # labelled kN); Sobol indices have none
    unit, scale = _out_unit(var) if key == "mu_star" else ("-", 1.0)
    row = ds[key].sel(output=var).values * scale
    conf = ds[f"{key}_conf"].sel(output=var).values * scale
    factors = [str(f) for f in ds["factor"].values]
    order = np.argsort(np.nan_to_num(row, nan=-np.inf))  # largest at the top
    fig = _figure(WIDTH, 0.45 * len(factors) + 1.6)
    ax = fig.add_subplot()
    pos = np.arange(len(factors))
    if key == "ST":  # side by side, each bar with its own interval
        s1 = ds["S1"].sel(output=var).values
        s1_conf = ds["S1_conf"].sel(output=var).values
        ax.barh(pos + 0.2, row[order], height=0.4, xerr=conf[order], color=_color(0),
                alpha=0.85, label="ST (total)")
        ax.barh(pos - 0.2, s1[order], height=0.4, xerr=s1_conf[order], color=_color(1),
                alpha=0.85, label="S1 (first order)")
    else:
        ax.barh(pos, row[order], xerr=conf[order], color=_color(0), alpha=0.85,
                label="mu* (Morris)")
    ax.set_yticks(pos, [factors[i] for i in order], fontsize=8)
    ax.set_xlabel("mu*: mean |output change| over each factor's range [" + unit + "]"
                  if key == "mu_star" else "Sobol index [-]")
    ax.grid(True, axis="x", alpha=0.3)
    # (the whiskers were in no legend: a reviewer)
    ax.legend(fontsize=8, loc="lower right", title="whiskers: 95 % bootstrap interval",
              title_fontsize=7)
    _suptitle(fig, f"{_title(ds)}: {ds[var].attrs.get('output', var)}")
    return fig


# ============================================================================ helpers
_DASHES = ("-", (0, (5, 2)), (0, (5, 2, 1, 2)), (0, (1.5, 1.5)))


def _figure(width, height) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _color(i: int) -> str:
    return f"C{i % 10}"


def _output_vars(ds) -> list[str]:
    return [v for v in ds.data_vars if "output" in ds[v].attrs]


def _families(ds) -> dict[str, list[tuple[str, str]]]:
    fams: dict[str, list[tuple[str, str]]] = {}
    for var in _output_vars(ds):
        fam, member = out_mod.family(ds[var].attrs["output"])
        fams.setdefault(fam, []).append((member, var))
    for fam, members in fams.items():  # the system value first
        members.sort(key=lambda m: m[0] != "system")
        if len(members) > MAX_MEMBERS:
            log.info("family %s: %d members, showing %d", fam, len(members), MAX_MEMBERS)
    return fams


def _out_unit(var_or_name: str) -> tuple[str, float]:
    unit = out_mod.output_unit(var_or_name)
    if unit == "N":
        return "kN", 1e-3
    return ("-" if unit == "1" else unit), 1.0


#: a grid of at most this many cells prints each cell's value in it (no contours: drawn
#: between the cells' centres, they crossed flat cells and missed the jumps between them)
CELL_VALUES = 64


def cell_digits(z) -> int:
    """Significant digits that tell the cells apart: two more than the ratio of their
    largest magnitude to their spread needs, 4 to 8 (a reviewer's map read '1.105' and
    '1.106' over a colour scale from 1.1051 to 1.1064)."""
    finite = np.asarray(z, dtype=float)[np.isfinite(z)]
    if finite.size < 2:
        return 4
    span, size = float(np.ptp(finite)), float(np.abs(finite).max())
    if span <= 0 or size <= 0:
        return 4
    return int(min(8, max(4, math.ceil(math.log10(size / span)) + 2)))


def _cell_values(ax, x, y, z, mesh) -> None:
    """Each cell's value at its centre, dark on light colours and light on dark ones."""
    digits = cell_digits(z)
    for (i, j), v in np.ndenumerate(z):
        if not np.isfinite(v):
            continue
        r, g, b, _ = mesh.cmap(mesh.norm(v))
        dark = 0.299 * r + 0.587 * g + 0.114 * b > 0.5
        ax.text(x[j], y[i], f"{v:.{digits}g}", ha="center", va="center", fontsize=6,
                color="k" if dark else "w")


def _edges(ds, name, values) -> np.ndarray:
    """Cell edges of a map around each parameter value: midway between neighbours, on a
    log scale for a log-spaced parameter (each value centred in its cell on a log axis)."""
    v = np.asarray(values, dtype=float)
    log = ds[name].attrs.get("spacing") == "log" and v.size and (v > 0).all()
    u = np.log(v) if log else v
    if u.size == 1:
        e = u[0] + np.array([-0.5, 0.5]) * (max(abs(u[0]), 1.0) * 0.1 if not log else 0.1)
    else:
        mid = 0.5 * (u[1:] + u[:-1])
        e = np.concatenate([[u[0] - (mid[0] - u[0])], mid, [u[-1] + (u[-1] - mid[-1])]])
    return np.exp(e) if log else e


def _log_axis(ds, name, set_scale) -> None:
    """A parameter spaced logarithmically (``spacing = "log"``) on a log axis."""
    if ds[name].attrs.get("spacing") == "log":
        set_scale("log")


def path_pattern(paths: list[str]) -> str:
    """Paths of one shape as one pattern, '*' where they differ
    (gears.*.support.shaft.bearing_stiffness); else the first and how many more."""
    parts = [p.split(".") for p in paths]
    if len(parts) > 1 and len({len(p) for p in parts}) == 1:
        return ".".join(col[0] if len(set(col)) == 1 else "*" for col in zip(*parts))
    return paths[0] + (f" and {len(paths) - 1} more" if len(paths) > 1 else "")


def _param_label(ds, name) -> str:
    paths = json.loads(ds[name].attrs.get("paths", "[]"))
    if ds[name].attrs.get("mode") == "scale":  # (it said 'factor' of nothing: a reviewer)
        if not paths:
            return f"{name} (factor)"
        # the fields themselves where few ('gears.*.polar_inertia' read as every gear's
        # for the two of gears.z[23]: a reviewer), else their pattern and count
        what = (", ".join(paths) if len(paths) <= 3
                else f"{path_pattern(paths)}, {len(paths)} fields")
        return f"{name} (factor on {what})"
    if not paths or paths == [name]:
        return name
    if len(paths) <= 3:  # (a parameter set on several paths: name them, a reviewer's
        return f"{name} ({', '.join(paths)})"  # 'backlash' did not say of which meshes)
    return f"{name} ({paths[0]} and {len(paths) - 1} more)"


#: how a case that is not ok is marked: contact lost keeps its values (plotted, marked
#: apart), any other status has none
_MARKS = {"contact_lost": ("v", "tab:orange", "teeth separate (contact lost; values kept)"),
          "failed": ("x", "tab:red", "case failed (no values)")}


def _kind(status) -> np.ndarray:
    """Per case: "ok", "contact_lost" or "failed" (diverged, refused, error, missing)."""
    s = np.asarray(status).astype(str)
    return np.where((s == "ok") | (s == "contact_lost"), s, "failed")


def _mark_failed(ax, x, status) -> None:
    """Marks on the axis under the cases that are not ok, by kind (:data:`_MARKS`)."""
    kind = _kind(status)
    for k, (marker, color, label) in _MARKS.items():
        hit = kind == k
        if hit.any():
            ax.plot(np.asarray(x)[hit], np.zeros(hit.sum()), ls="none", marker=marker,
                    color=color, ms=7, clip_on=False, transform=ax.get_xaxis_transform(),
                    label=label)


def _status_note(status) -> str:
    """' (2 of 8 cases lost contact; 1 failed)', or '' when every case is ok."""
    kind = _kind(status)
    bits = [f"{int((kind == 'contact_lost').sum())} lost contact"
            if (kind == "contact_lost").any() else "",
            f"{int((kind == 'failed').sum())} failed" if (kind == "failed").any() else ""]
    bits = [b for b in bits if b]
    return f" ({' and '.join(bits)} of {kind.size} cases)" if bits else ""


def _suptitle(fig, text: str, fontsize: float = 11.0) -> None:
    """The figure's title, wrapped to its width (a long model or study name ran off both
    edges of the figure: a reviewer's '_li_mill_drive ... (mean cycle peak / nominal
    forc')."""
    import textwrap

    per_line = max(20, int(fig.get_figwidth() * 72 / (0.55 * fontsize)))
    fig.suptitle("\n".join(textwrap.wrap(text, per_line)), fontsize=fontsize)


def _title(ds) -> str:
    """The model and the study a figure is of ("ji_li_mill_drive, study
    ji_li_diameter"): a title named only the study ("sweep_shafts.drive1.diameter")."""
    model = ds.attrs.get("model_name")
    study = ds.attrs["study_name"]
    return f"{model}, study {study}" if model else study


def _family_text(family: str) -> str:
    """ "load_sharing.engineering" -> "load-sharing coefficient (engineering)"."""
    head = family.split(".")[0]
    text = out_mod.FAMILIES.get(head, ("", family))[1]
    if head in ("load_sharing", "planet_load_sharing") and "." in family:
        text += f" ({family.split('.', 1)[1]})"
    return text


def _wrap(text: str, width: int) -> str:
    """``text`` broken into lines of about ``width`` characters at its spaces only (a
    dotted output or field name stays whole)."""
    return textwrap.fill(text, width, break_long_words=False, break_on_hyphens=False)


def _safe(name: str) -> str:
    return name.replace("/", "_").replace("|", "_").replace(" ", "_")
