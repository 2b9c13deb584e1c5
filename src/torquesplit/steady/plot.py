"""Figures of a speed sweep and of a Campbell diagram (matplotlib OO API, Agg, no pyplot).

The figures consume the Datasets of :mod:`.maps` and recompute nothing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _figure(w, h):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def sweep_figure(ds, variable: str = "dynamic_factor"):
    """``variable`` per mesh against speed: stable solid, unstable dashed, turning points
    (jump speeds) and critical speeds (natural frequency x mesh order) marked, run-up /
    run-down time integrations as markers when present."""
    fig = _figure(8, 4.5)
    ax = fig.add_subplot()
    rpm = ds["speed_rpm"].values
    stable = ds["stable"].values
    colors = {}
    for j, mesh in enumerate(ds["mesh"].values):
        y = ds[variable].values[:, j]
        line = None
        for k in range(len(rpm) - 1):
            st = stable[k] and stable[k + 1]
            (line,) = ax.plot(rpm[k:k + 2], y[k:k + 2], "-" if st else "--",
                              color=None if line is None else line.get_color(),
                              label=str(mesh) if k == 0 else None, lw=1.3)
        colors[mesh] = line.get_color() if line is not None else None
        check = f"run_up_{variable}"
        if check in ds:
            ax.plot(ds["check_speed_rpm"].values, ds[check].values[:, j], "^", ms=4,
                    color=colors[mesh], alpha=0.7,
                    label="run-up (time integration)" if j == 0 else None)
            ax.plot(ds["check_speed_rpm"].values, ds[f"run_down_{variable}"].values[:, j],
                    "v", ms=4, color=colors[mesh], alpha=0.7,
                    label="run-down (time integration)" if j == 0 else None)
    for f in ds.attrs.get("fold_speeds_rpm", []):
        ax.axvline(f, color="k", lw=0.8, ls=":")
    lo, hi = float(np.nanmin(rpm)), float(np.nanmax(rpm))
    for c, labels in critical_speed_groups(ds, lo, hi):
        ax.axvline(c, color="0.6", lw=0.6)
        ax.text(c, 1.0, "\n".join(labels), rotation=90, fontsize=6, va="top", ha="right",
                transform=ax.get_xaxis_transform(), color="0.4")
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel(ds[variable].attrs.get("long_name", variable))
    ax.set_title(f"{ds.attrs.get('model', '')}: {variable.replace('_', ' ')} "
                 f"(solid stable, dashed unstable, dotted: turning points)", fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    return fig


def critical_speed_groups(ds, lo: float, hi: float, merge: float = 0.005):
    """Critical speeds of ``ds`` inside [lo, hi] rpm as (speed, labels): crossings closer
    than ``merge`` of the range (a degenerate pair of modes, two orders meeting) share one
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
    """Natural frequencies and excitation lines against speed; crossings marked."""
    fig = _figure(8, 5)
    ax = fig.add_subplot()
    rpm = ds["speed_rpm"].values
    fmax = float(np.nanmax(ds["excitation_frequency"].values))
    for m in range(ds.sizes["mode"]):
        fn = ds["natural_frequency"].values[:, m]
        ax.plot(rpm, fn, color="k", lw=0.8)
        if np.isfinite(fn[-1]) and 0 < fn[-1] <= fmax * 1.05:  # mode number at its end
            ax.annotate(f"{int(ds['mode'].values[m])}", (rpm[-1], fn[-1]), fontsize=6,
                        xytext=(2, 0), textcoords="offset points", va="center")
    # one colour per source (a mesh: its orders 1..k, labelled at the top; a shaft), one
    # legend entry each
    sources: dict[str, list[tuple[int, int]]] = {}
    for j, lab in enumerate(ds["line"].values):
        order, _, source = str(lab).partition(" x ")
        sources.setdefault(source, []).append((j, int(order)))
    for k, (source, members) in enumerate(sources.items()):
        colour = f"C{k % 10}"  # matplotlib's colour cycle
        orders = [o for _, o in members]
        label = source if orders == [1] else f"{source} x {min(orders)}..{max(orders)}"
        for i, (j, order) in enumerate(members):
            fe = ds["excitation_frequency"].values[:, j]
            ax.plot(rpm, fe, lw=0.8, ls="--", color=colour, label=label if i == 0 else None)
            inside = np.flatnonzero(fe <= fmax * 1.05)
            if len(members) > 1 and inside.size:  # the order at the line's last point
                ax.annotate(f"{order}x", (rpm[inside[-1]], fe[inside[-1]]), fontsize=5,
                            color=colour, xytext=(0, 2), textcoords="offset points")
    for i, c in enumerate(ds.attrs.get("critical_speeds_rpm", [])):
        ax.axvline(c, color="r", lw=0.5, alpha=0.5,
                   label="critical speed" if i == 0 else None)
    # crossings that the planets' mesh phasing leaves unexcited (Parker & Lin 2004)
    for i, c in enumerate(ds.attrs.get("suppressed_speeds_rpm", [])):
        ax.axvline(c, color="0.6", lw=0.5, ls=":",
                   label="suppressed by mesh phasing (Parker & Lin 2004)" if i == 0 else None)
    ax.set_ylim(0, fmax * 1.05)
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(f"{ds.attrs.get('model', '')}: Campbell diagram (solid: natural "
                 f"frequencies, numbered; dashed: excitation orders)", fontsize=9)
    ax.legend(fontsize=6, loc="upper left")
    return fig


def save(fig, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    return path
