"""Reports to hand on: one self-contained HTML file per analysis, and the layout drawing.

==========  ================================================================================
module      content
==========  ================================================================================
``html``    :func:`~torquesplit.report.html.build_report` -- the report of a run (a model
            file, run now, or a results file): model summary with units, the layout
            drawing, run settings and provenance, the per-mesh table, load-sharing and
            dynamic-factor figures, natural modes, warnings, and for the shipped examples
            the comparison with the paper.  Figures are inline SVG; the page loads nothing
            from the network and runs no script.
``cli``     the ``torquesplit report`` and ``torquesplit draw`` commands (registered by
            :mod:`torquesplit.cli`)
==========  ================================================================================

The layout drawing itself is :mod:`torquesplit.plot.layout`.
"""
