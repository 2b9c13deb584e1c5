"""Figure of mesh stiffness against mesh phase (for ``torquesplit mesh``)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["plot_mesh_stiffness"]


def plot_mesh_stiffness(comparison, path, *, cycles: int = 2, title: str | None = None) -> Path:
    """Plot mesh-stiffness waveforms and save the figure to ``path``.

    Parameters
    ----------
    comparison : MethodComparison, MeshStiffness or sequence of MeshStiffness
        What to draw.  For a :class:`~torquesplit.gears.stiffness.MethodComparison`
        the ISO 6336-1 mean mesh stiffness along the flank normal, ``c_gamma b /
        cos^2 beta_b`` (as ``torquesplit mesh`` prints it), is drawn as a dashed line.
    path : str or Path
        Output file; the format follows the suffix (``.png``, ``.pdf``, ``.svg``).
        Stiffness is drawn in N/µm (= 1e6 N/m), as ``torquesplit mesh`` prints it.
    cycles : int
        Number of mesh cycles to draw (the waveform repeats).
    title : str, optional
        Figure title.

    Returns
    -------
    Path
        The written file.
    """
    import numpy as np
    from matplotlib.figure import Figure  # no pyplot: no global backend or state

    from torquesplit.gears.stiffness import MeshStiffness

    if isinstance(comparison, MeshStiffness):
        labels, results, iso = [comparison.method], [comparison], None
    elif hasattr(comparison, "results") and hasattr(comparison, "labels"):
        labels, results, iso = list(comparison.labels), list(comparison.results), comparison.iso_mesh_stiffness
    else:
        results = list(comparison)  # type: Sequence[MeshStiffness]
        labels, iso = [r.method for r in results], None

    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.add_subplot()
    # distinct dashes and widths, the first drawn widest: curves that coincide (a
    # constant method on the ISO value) stay visible under each other
    dashes = ["-", "--", "-.", ":", (0, (5, 1, 1, 1)), (0, (3, 1))]
    for i, (lab, r) in enumerate(zip(labels, results)):
        ph = np.concatenate([r.phase + c for c in range(cycles)] + [np.array([float(cycles)])])
        k = np.concatenate([r.stiffness] * cycles + [r.stiffness[:1]])
        ax.step(ph, k / 1e6, where="post", ls=dashes[i % len(dashes)],
                lw=max(0.9, 2.6 - 0.5 * i), zorder=2 + i,
                label=f"{lab} (mean {r.mean / 1e6:.5g} N/µm)")
    if iso is not None:
        ax.axhline(iso / 1e6, color="k", linestyle=(0, (8, 4)), linewidth=0.8, zorder=10,
                   label=f"ISO 6336-1 $c_\\gamma b / \\cos^2\\beta_b$ = {iso / 1e6:.5g} N/µm "
                         f"(normal to the flanks, along the line of action as the curves)")
    ax.set_xlabel("mesh phase [mesh cycles]")
    ax.set_ylabel("mesh stiffness along the line of action [N/µm]")
    ax.set_xlim(0, cycles)
    ax.grid(True, alpha=0.3)
    # two columns only where the labels fit beside each other (a long LTCA label ran
    # off both edges of the figure: a reviewer)
    longest = max((len(t.get_label()) for t in ax.get_lines()), default=0)
    fig.legend(loc="outside lower center", ncols=2 if longest <= 48 else 1,
               fontsize="small")
    if title:
        ax.set_title(title)
    path = Path(path)
    fig.savefig(path, dpi=150)
    return path
