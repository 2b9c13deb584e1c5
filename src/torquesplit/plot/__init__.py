"""Figures for reports: matplotlib, object-oriented API on Agg canvases, no pyplot.

Nothing here is imported by the analysis pipeline; importing this package sets no
backend, style or handler.  Functions take results and return a
:class:`matplotlib.figure.Figure`, or write files and return their paths.

=============  ==========================================================================
module         content
=============  ==========================================================================
``figures``    report figures of a dynamic run (:class:`~torquesplit.results.Results`)
               and of a quasi-static sweep
               (:class:`~torquesplit.quasistatic.QuasiStaticResults`);
               :func:`~torquesplit.plot.figures.write_figures` and
               :func:`~torquesplit.plot.figures.write_static_figures` write all that apply
``mesh``       mesh stiffness against mesh phase by every stiffness method
               (``torquesplit mesh --plot``)
=============  ==========================================================================

Figures of ``figures`` (one panel per load-sharing group unless said otherwise):

==============================  ===============================================  ==========
function                        shows                                            input
==============================  ===============================================  ==========
``mesh_force_figure``           mesh force vs time, paths overlaid, nominal      dynamic
                                static force dashed (whole run or last cycles)
``cycle_peak_figure``           peak force of each mesh cycle vs cycle start,    dynamic
                                settled start marked
``load_sharing_figure``         load-sharing coefficient of each mesh cycle by   dynamic
                                a definition, reported value, settled start
``dynamic_factor_figure``       dynamic factor of each mesh cycle (peak / the    dynamic
                                mesh's static force), reported value
``support_spectrum_figure``     amplitude spectrum of each support force, mesh   dynamic
                                frequency orders marked (one panel per body)
``orbit_figure``                x-y orbit of floating bodies, equal aspect       both
``mesh_stiffness_figure``       mesh stiffness over two mesh cycles, phasing     both
``static_mesh_force_figure``    quasi-static mesh force vs rotation              static
``static_load_sharing_figure``  static torque ratio vs rotation (Mo et al. 2017)  static
==============================  ===============================================  ==========

Units on the axes: forces kN (spectrum amplitudes N), time s or ms (runs shorter than
1 s), frequency Hz or kHz, displacements µm, mesh stiffness N/µm (= 1e6 N/m),
rotation deg.  Coefficients are dimensionless ("[-]").

Every function of the table is importable from ``torquesplit.plot`` too.

Examples
--------
>>> import tempfile, torquesplit
>>> from torquesplit.plot import write_figures
>>> res = torquesplit.simulate(torquesplit.example_path("ji_li_mill_drive"), cycles=20)
>>> paths = write_figures(res, tempfile.mkdtemp(), formats=("png", "svg"))
"""

from __future__ import annotations

__all__ = [
    "write_figures", "write_static_figures", "mesh_force_figure", "cycle_peak_figure",
    "load_sharing_figure", "dynamic_factor_figure", "support_spectrum_figure",
    "orbit_figure", "mesh_stiffness_figure", "static_mesh_force_figure",
    "static_load_sharing_figure", "FigureNotApplicableError",
]


def __getattr__(name):
    # lazy: importing torquesplit.plot does not import matplotlib
    if name in __all__:
        from . import figures

        return getattr(figures, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    """The figure functions (lazy: tab completion listed none of them)."""
    return sorted(set(__all__) | {"__all__", "__doc__", "__name__"})
