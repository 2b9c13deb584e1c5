"""The numbers each paper publishes, beside the metric of a run that compares with them.

Used by the HTML report (``torquesplit report``) for the shipped examples: each entry
names the quantity, the paper's value, and the flat metric names
(:meth:`torquesplit.results.Metrics.values`) whose largest value is ours.  Where a paper
prints no numbers (its results are figures only) the entry says so.  Why the numbers
differ -- the inputs each paper leaves out -- is written in the example model files.

Quasi-static entries (``analysis = "static"``) compare with ``torquesplit static``
(:func:`torquesplit.quasistatic.quasi_static_load_sharing`); their keys are
``load_sharing.static_torque`` plus ``.<group>`` or ``.<mesh>``.  Modal entries
(``analysis = "modes"``) compare with the natural frequencies of the model at rest
(:func:`modal_values`); their keys are ``mode.<type>.<k>``: the k-th distinct frequency
of that mode type (a degenerate pair counts once), ascending, rigid-body modes left out.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Published:
    """One published number."""

    quantity: str
    paper: float
    keys: tuple[str, ...]
    """Flat metric names; ours is the largest of them."""
    analysis: str = "dynamic"
    """``"dynamic"`` (a run), ``"static"`` (the quasi-static sweep) or ``"modes"`` (the
    natural frequencies, :func:`modal_values`)."""
    where: str = ""
    """Where the paper gives it."""


#: example name -> (note, published numbers)
PUBLISHED: dict[str, tuple[str, tuple[Published, ...]]] = {
    "liu2021_split_torque_helicopter": (
        "Liu et al. 2021, section 5.2, with meshing-in impact, left input path; the dynamic "
        "load factor of the paper is the largest dynamic force over the nominal static "
        "force, our peak/nominal.", (
            Published("load sharing, spur split stage (cycle peak, eqs. 17-19)", 1.06332,
                      ("load_sharing.cycle_peak.left/spur_split",), where="section 5.2"),
            Published("load sharing, double-helical stage (cycle peak)", 1.09603,
                      ("load_sharing.cycle_peak.left/dh_combine",), where="section 5.2"),
            Published("dynamic load factor, spur split stage", 1.42443,
                      ("peak_to_nominal.left/spur_split",), where="section 5.2"),
            Published("dynamic load factor, double-helical stage", 1.20669,
                      ("peak_to_nominal.left/dh_combine",), where="section 5.2"),
        )),
    "dong2021_face_gear": (
        "Dong et al. 2021, section 6.1 baseline (mean-force coefficients, eq. 12).", (
            Published("load sharing, face-gear stage I (mean force)", 1.0383,
                      ("load_sharing.mean_force.I",), where="section 6.1"),
            Published("load sharing, herringbone stage II (mean force)", 1.0860,
                      ("load_sharing.mean_force.O2/II_pinion_idler",
                       "load_sharing.mean_force.O3/II_pinion_idler",
                       "load_sharing.mean_force.O2/II_idler_output",
                       "load_sharing.mean_force.O3/II_idler_output"), where="section 6.1"),
        )),
    "mo2017_star_reducer": (
        "Mo et al. 2017, quasi-static load sharing with 6 um errors on every gear "
        "(eqs. 14-15); compare with 'torquesplit static'.", (
            Published("system load-sharing coefficient (static torque, eq. 15)", 1.0619,
                      ("load_sharing.static_torque",), analysis="static",
                      where="text on Figure 5"),
            Published("largest stage-1 path coefficient", 1.0619,
                      ("load_sharing.static_torque.stage1",), analysis="static",
                      where="text on Figure 5"),
        )),
    "lin_parker1999_planetary": (
        "Lin & Parker 1999, Table 1 system with four planets: natural frequencies of the "
        "planetary at rest (stationary carrier), by mode type; a translational frequency "
        "is a degenerate pair, a planet mode has multiplicity N - 3.", tuple(
            Published(f"{kind} mode {k + 1} [Hz]", f, (f"mode.{kind}.{k + 1}",),
                      analysis="modes",
                      where="natural frequencies, N = 4 (J. Lin's thesis, Table C.1)")
            for kind, values in (
                ("rotational", (1536.6, 1970.6, 2625.7, 7773.6, 13071.1)),
                ("translational", (727.0, 1091.0, 1892.8, 2342.5, 7189.9, 10437.6)),
                ("planet", (1808.2, 5963.8, 6981.7)))
            for k, f in enumerate(values))),
    "ji_li_mill_drive": (
        "Ji & Li print no numerical results (their coefficients are in figures only); the "
        "paper's trends are discussed in the model file's comments.", ()),
    "jin2019_friction_split": (
        "Jin et al. 2019 print no numerical results (figures only); the model file's "
        "comments list the trends it reproduces.", ()),
}


def modal_values(report) -> dict[str, float]:
    """``mode.<type>.<k>`` -> the k-th distinct natural frequency [Hz] of that type in a
    :class:`torquesplit.modes.ModalReport` (one per degenerate group, ascending, the
    rigid-body modes left out)."""
    out: dict[str, float] = {}
    seen: set[int] = set()
    count: dict[str, int] = {}
    for r in sorted(report.rows, key=lambda r: r.frequency):
        if r.group in seen or not r.frequency > 0 or r.type is None:
            continue
        seen.add(r.group)
        count[r.type] = count.get(r.type, 0) + 1
        out[f"mode.{r.type}.{count[r.type]}"] = float(r.frequency)
    return out


def published_for(model_name: str) -> tuple[str, tuple[Published, ...]] | None:
    """The published numbers of a shipped example (by its model name), or None."""
    from . import RENAMED

    return PUBLISHED.get(RENAMED.get(model_name, model_name))
