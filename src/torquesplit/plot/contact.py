"""Figures of a loaded tooth contact analysis (``torquesplit contact --plot``).

Each function takes LTCA results (:class:`~torquesplit.gears.contact.LtcaResult`,
:class:`~torquesplit.gears.contact.HarrisMap`) and returns a
:class:`matplotlib.figure.Figure`; :func:`write_contact_figures` writes them all.

==============================  ==============================================================
function                        shows
==============================  ==============================================================
``te_figure``                   loaded static transmission error over two mesh cycles at
                                several loads, µm along the flank normal (left axis) and arc
                                seconds of gear 2 (right axis, Liu et al. 2021 eq. 3)
``harris_figure``               Harris map: TE peak-to-peak against load (µm and arc s), with
                                the actual contact ratio
``load_distribution_figure``    load per unit contact-line length on the face (2-D map of the
                                flank: face position against roll length of gear 1) at
                                several positions, and the envelope over the cycle
``stiffness_figure``            secant and tangent mesh stiffness against mesh phase
``pressure_figure``             maximum Hertz pressure against mesh phase, and the tooth-pair
                                load sharing
==============================  ==============================================================

Units on the axes and in the legends: µm, arc seconds, N/mm, N/µm (= 1e6 N/m), MPa, mm, kN
(µm, as in the tables of ``torquesplit contact``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["te_figure", "harris_figure", "load_distribution_figure", "stiffness_figure",
           "pressure_figure", "write_contact_figures"]


def _figure(width=7.5, height=4.8):
    from matplotlib.figure import Figure  # no pyplot: no global backend or state

    return Figure(figsize=(width, height), layout="constrained")


def _cycles(phase, values, cycles=2):
    ph = np.concatenate([phase + c for c in range(cycles)] + [np.array([float(cycles)])])
    v = np.concatenate([values] * cycles + [values[:1]])
    return ph, v


def _pair_tracks(phase, loads, cycles: int = 2) -> list:
    """Each physical tooth pair's load over ``cycles`` mesh cycles, ``(phase, load)``.

    ``loads`` (M positions, K pairs) numbers the pairs in contact at a position; after a
    mesh cycle every pair has moved one place on (the next pair takes its number), so the
    pair of column k continues in column k + s, s = +1 or -1: the shift whose columns
    join without a jump.  Numbering by column would swap the curves at each cycle."""
    m, k = loads.shape
    jump = {s: sum(abs(loads[-1, c] - loads[0, c + s]) for c in range(k) if 0 <= c + s < k)
            for s in (1, -1)}
    shift = min(jump, key=jump.get) if k > 1 else 0
    zero = np.zeros(m)
    tracks = []
    for first in range(-abs(shift) * cycles, k + abs(shift) * cycles):
        cols = [first + c * shift for c in range(cycles)]
        parts = [loads[:, c] if 0 <= c < k else zero for c in cols]
        v = np.concatenate(parts)
        if not v.max() > 0:
            continue
        last = cols[-1] + shift  # the value at the end: the next cycle's first sample
        end = loads[:1, last] if 0 <= last < k else np.zeros(1)
        tracks.append((np.concatenate([phase + c for c in range(cycles)] + [[float(cycles)]]),
                       np.concatenate([v, end])))
    return tracks


def _arcsec_axis(ax, result, gear: str | None = None):
    """Right axis in arc seconds of gear 2 (named ``gear``) for a left axis in µm
    (normal)."""
    from torquesplit.gears.contact.ltca import ARCSEC_PER_RAD

    f = float(result.model.te_angle(1e-6)) * ARCSEC_PER_RAD      # arcsec per µm
    sec = ax.secondary_yaxis("right", functions=(lambda u: u * f, lambda a: a / f))
    sec.set_ylabel(f"TE, arc seconds of {gear or 'gear 2'} [arc s]")
    return sec


def te_figure(results: Sequence, title: str | None = None, gear: str | None = None):
    """Loaded static transmission error against mesh phase at each load (the right axis
    in arc seconds of gear 2, named ``gear``)."""
    fig = _figure()
    ax = fig.add_subplot()
    for r in sorted(results, key=lambda r: r.load):
        ph, z = _cycles(r.phase, r.transmission_error * 1e6)
        ax.plot(ph, z, label=f"{r.load / 1e3:.4g} kN: p-p {r.te_peak_to_peak * 1e6:.3g} µm "
                             f"= {r.te_peak_to_peak_arcsec:.3g} arc s")
    ax.set_xlabel("mesh phase [mesh cycles]")
    ax.set_ylabel("loaded transmission error, flank normal [µm]")
    ax.set_xlim(0, 2)
    ax.grid(True, alpha=0.3)
    _arcsec_axis(ax, results[0], gear)
    fig.legend(loc="outside lower center", ncols=2, fontsize="small")
    ax.set_title(title or "loaded static transmission error")
    return fig


def harris_figure(harris, title: str | None = None, design_load: float | None = None,
                  gear: str | None = None):
    """Transmission error peak-to-peak against load (Harris map; arc seconds of gear 2,
    named ``gear``)."""
    fig = _figure()
    ax = fig.add_subplot()
    loads = harris.loads / 1e3
    ax.plot(loads, harris.te_peak_to_peak * 1e6, "o-", label="TE peak-to-peak")
    ax.set_xlabel("normal load [kN]")
    ax.set_ylabel("TE peak-to-peak, flank normal [µm]")
    ax.grid(True, alpha=0.3)
    _arcsec_axis(ax, harris.results[0], gear)
    if design_load is not None:
        ax.axvline(design_load / 1e3, color="k", linestyle="--", linewidth=1.0,
                   label=f"operating load {design_load / 1e3:.4g} kN")
    ax2 = ax.twinx()
    ax2.spines["right"].set_position(("outward", 55))
    ax2.plot(loads, harris.contact_ratio, "s:", color="tab:green",
             label="loaded contact ratio (mean loaded tooth pairs)")
    ax2.set_ylabel("loaded contact ratio (within the path of contact) [-]",
                   color="tab:green")
    cr = np.asarray(harris.contact_ratio, dtype=float)
    if cr.size and np.ptp(cr) < 0.02:  # (flat: a zoomed axis spread a constant over it)
        ax2.set_ylim(cr.mean() - 0.25, cr.mean() + 0.25)
    fig.legend(loc="outside lower center", ncols=3, fontsize="small")
    ax.set_title(title or "Harris map")
    return fig


def _flank_points(result, m=None):
    """(face position [mm], roll length of gear 1 [mm], line load [N/mm]) of loaded
    points; both helices of a double-helical pair side by side (helix 2 mirrored)."""
    cm = result.model
    b = cm.pair.face_width
    rho1, _ = cm.pair.roll_distances(cm.s)
    q = result.line_load
    sel = result.slice_load > 1e-9 * result.load
    if m is not None:
        mask = np.zeros_like(sel)
        mask[m] = sel[m]
        sel = mask
    idx = np.nonzero(sel)
    h = idx[1]
    y = cm.y[idx[3]]
    x = np.where(h == 0, y, 2.0 * b + 0.1 * b - y)
    return x * 1e3, rho1[idx] * 1e3, q[idx] / 1e3


def load_distribution_figure(result, positions: int = 4, title: str | None = None):
    """Load per unit length on the flank of gear 1 at several positions and over the cycle."""
    cm = result.model
    M = cm.phase.size
    picks = np.unique(np.linspace(0, M, positions, endpoint=False).astype(int))
    fig = _figure(9.0, 6.0)
    axes = fig.subplots(2, (len(picks) + 2) // 2, squeeze=False).ravel()
    vmax = float(result.line_load.max() / 1e3) or 1.0
    x, r, q = _flank_points(result)
    sc = axes[0].scatter(x, r, c=q, s=6, cmap="viridis", vmin=0, vmax=vmax)
    axes[0].set_title("all positions (envelope)", fontsize="small")
    for ax, m in zip(axes[1:], picks):
        x, r, q = _flank_points(result, int(m))
        ax.scatter(x, r, c=q, s=10, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(f"phase {cm.phase[m]:.3f}", fontsize="small")
    fc_lo = min(cm.pair.roll_distances(np.array([cm.pair.path_start, cm.pair.path_end]))[0]) * 1e3
    fc_hi = max(cm.pair.roll_distances(np.array([cm.pair.path_start, cm.pair.path_end]))[0]) * 1e3
    width = (2.1 if cm.helices == 2 else 1.0) * cm.pair.face_width * 1e3
    pad_x, pad_r = 0.02 * width, 0.02 * (fc_hi - fc_lo)  # (markers on the limits: whole)
    for ax in axes[:len(picks) + 1]:
        ax.set_xlim(-pad_x, width + pad_x)
        ax.set_ylim(fc_lo - pad_r, fc_hi + pad_r)
        ax.set_xlabel("face position [mm]")
        ax.set_ylabel("roll length, gear 1 [mm]")
        ax.grid(True, alpha=0.2)
    for ax in axes[len(picks) + 1:]:
        ax.set_visible(False)
    fig.colorbar(sc, ax=axes.tolist(), label="load per unit length [N/mm]")
    fig.suptitle(title or f"load distribution at {result.load / 1e3:.4g} kN")
    return fig


def stiffness_figure(result, title: str | None = None):
    """Secant and tangent mesh stiffness against mesh phase."""
    fig = _figure()
    ax = fig.add_subplot()
    for label, k in (("secant P/Z", result.stiffness_secant), ("tangent dP/dZ", result.stiffness_tangent)):
        ph, v = _cycles(result.phase, k / 1e6)
        ax.plot(ph, v, label=f"{label} (mean {k.mean() / 1e6:.4g} N/µm)")
    ax.set_xlabel("mesh phase [mesh cycles]")
    ax.set_ylabel("mesh stiffness [N/µm]")
    ax.set_xlim(0, 2)
    ax.grid(True, alpha=0.3)
    fig.legend(loc="outside lower center", ncols=2, fontsize="small")
    ax.set_title(title or f"LTCA mesh stiffness at {result.load / 1e3:.4g} kN")
    return fig


def pressure_figure(result, title: str | None = None):
    """Maximum Hertz pressure and tooth-pair loads against mesh phase."""
    fig = _figure(7.5, 6.0)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ph, p = _cycles(result.phase, result.max_pressure / 1e6)
    ax1.plot(ph, p)
    ax1.set_ylabel("max Hertz pressure [MPa]")
    ax1.grid(True, alpha=0.3)
    loads = result.pair_load.sum(axis=1)            # (M, K) both helices
    for j, (ph, v) in enumerate(_pair_tracks(np.asarray(result.phase), loads / 1e3)):
        ax2.plot(ph, v, label=f"tooth pair {j + 1}")
    ax2.set_xlabel("mesh phase [mesh cycles]")
    ax2.set_ylabel("tooth-pair load [kN]")
    ax2.set_xlim(0, 2)
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize="small", ncols=4, loc="upper center", bbox_to_anchor=(0.5, -0.18))
    fig.suptitle(title or f"contact pressure and load sharing at {result.load / 1e3:.4g} kN")
    return fig


#: the figures ``write_contact_figures`` writes, each as ``contact_NAME.png``
CONTACT_FIGURES = ("te", "harris", "load_distribution", "stiffness", "pressure")


def contact_figure_files(harris: bool = True) -> list[str]:
    """The file names :func:`write_contact_figures` writes (``harris=False``: without a
    Harris map)."""
    return [f"contact_{n}.png" for n in CONTACT_FIGURES if harris or n != "harris"]


def write_contact_figures(results: Sequence, harris, directory, *, operating=None,
                          operating_load: float | None = None, title: str = "",
                          gear: str | None = None) -> list[Path]:
    """Write every figure as PNG into ``directory``; returns the paths.

    ``operating`` is the result drawn in the single-load figures (default the largest
    load); ``operating_load`` [N] is marked on the Harris map; ``harris=None`` (``contact
    --harris 0``) writes no Harris map; ``gear`` names gear 2, whose arc seconds the
    transmission-error axes give.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    op = operating or max(results, key=lambda r: r.load)
    prefix = f"{title}: " if title else ""
    figs = {
        "te": te_figure(results, f"{prefix}loaded static transmission error", gear),
        "load_distribution": load_distribution_figure(op, title=f"{prefix}load distribution at "
                                                                 f"{op.load / 1e3:.4g} kN"),
        "stiffness": stiffness_figure(op, f"{prefix}mesh stiffness at {op.load / 1e3:.4g} kN"),
        "pressure": pressure_figure(op, f"{prefix}contact pressure at {op.load / 1e3:.4g} kN"),
    }
    if harris is not None:
        figs["harris"] = harris_figure(
            harris, f"{prefix}Harris map",
            design_load=op.load if operating_load is None else operating_load, gear=gear)
    paths = []
    for name in (n for n in CONTACT_FIGURES if n in figs):
        fig, path = figs[name], directory / f"contact_{name}.png"
        fig.savefig(path, dpi=120)
        paths.append(path)
    return paths
