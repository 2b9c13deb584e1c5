"""The HTML report of a run: one self-contained file to hand on.

:func:`build_report` takes a finished run (:class:`~torquesplit.results.Results`, from
:func:`torquesplit.simulate` or a results file) and returns the page as text.  Sections:

1. provenance: torquesplit version and commit, model file and its SHA-256, date, the
   results file's run id when the run comes from one;
2. warnings (the model's, the run's and the results');
3. the model: bodies, meshes, supports, shafts and splines, with units;
4. the layout drawing (:mod:`torquesplit.plot.layout`);
5. the run's settings and the per-mesh and per-group tables, with what the load-sharing
   definition measures and when to report it; for a planetary model the planet table
   (K_gamma per stage, the factor per planet);
6. figures: load sharing, dynamic factors, cycle peaks, mesh force at the end of the run,
   support-force spectrum (whatever applies);
7. natural modes, those near a mesh frequency or its harmonics marked;
8. the quasi-static load sharing for a model whose definition is ``static_torque``;
9. for the shipped examples, the comparison with the paper's published numbers.

Every figure is inline SVG (text as text, ids unique per figure); the page loads nothing
and runs no script, so it opens offline and prints as it shows.
"""

from __future__ import annotations

import datetime
import hashlib
import html
import math
from pathlib import Path

import numpy as np

#: natural modes listed
MODES_LISTED = 12
#: a results file's attributes that say which run wrote it (results.files.provenance)
PROVENANCE_KEYS = ("run_id", "created_utc", "software", "command", "working_directory",
                   "model_sha256")
#: a mode within this fraction of a mesh frequency (or of its 2nd or 3rd harmonic) is
#: marked as a possible resonance
NEAR_FRACTION = 0.1

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;
margin:2em auto;max-width:1150px;color:#222;line-height:1.4;padding:0 1em}
h1{font-size:1.6em;margin-bottom:.2em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;
margin-top:1.8em}table{border-collapse:collapse;margin:.6em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}.warn{background:#fff6e0;
border-left:4px solid #e0a000;padding:.5em 1em}.warn li{margin:.3em 0}
figure{margin:1em 0;page-break-inside:avoid}figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#555}.note{color:#555;font-size:.9em}
.bad{color:#b00000;font-weight:bold}code{background:#f3f3f3;padding:0 .2em}
"""


def _e(text) -> str:
    return html.escape(str(text), quote=True)


def _table(header: list[str], rows: list[list], left: int = 1) -> str:
    """An HTML table; the first ``left`` columns are text (left-aligned)."""
    th = "".join(f'<th class="{"l" if i < left else ""}">{_e(h)}</th>'
                 for i, h in enumerate(header))
    body = []
    for row in rows:
        cells = "".join(f'<td class="{"l" if i < left else ""}">{_e(c)}</td>'
                        for i, c in enumerate(row))
        body.append(f"<tr>{cells}</tr>")
    return f"<table><thead><tr>{th}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _g(x, digits: int = 5) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


def model_hash(source: Path | None, model_json: str) -> tuple[str, str]:
    """(what was hashed, SHA-256): the model file's bytes, else the model's JSON."""
    if source is not None and source.is_file() and source.suffix.lower() in (".toml", ".json"):
        return str(source), hashlib.sha256(source.read_bytes()).hexdigest()
    return "the model embedded in the results (JSON)", hashlib.sha256(
        model_json.encode("utf-8")).hexdigest()


# --------------------------------------------------------------------------- sections
def _provenance(res, source: Path | None, results_attrs: dict | None) -> str:
    from .. import __version__

    what, digest = model_hash(source, res.model_json())
    # the model's own identity too, the same from its file and from its results file
    canonical = hashlib.sha256(res.model_json().encode("utf-8")).hexdigest()
    from ..results.files import software_commit

    commit = software_commit() or "not a git checkout"
    rows = [["torquesplit writing this report", f"{__version__}, commit {commit}"],
            ["model", res.model.model.name],
            ["model file", what], ["model SHA-256", digest],
            ["model SHA-256 (its data, SI JSON: the same from the file and its results)",
             canonical],
            ["report written (UTC)", datetime.datetime.now(datetime.timezone.utc)
             .isoformat(timespec="seconds")]]
    if results_attrs:
        for key in PROVENANCE_KEYS:
            if results_attrs.get(key):
                rows.append([f"results file: {key}", results_attrs[key]])
    info = res.model.model
    head = f"<p>{_e(info.description)}</p>" if info.description else ""
    if info.reference:
        head += f'<p class="note">Reference: {_e(info.reference)}</p>'
    return head + _table(["", "value"], rows, left=2)


def _warnings(notes: list[str]) -> str:
    if not notes:
        return '<p class="note">No warnings: every check of the model and of the results ' \
               "passed.</p>"
    items = "".join(f"<li>{_e(w)}</li>" for w in notes)
    return f'<div class="warn"><ul>{items}</ul></div>'


def _model_tables(res) -> str:
    from ..model.summary import summary

    m = res.model
    s = summary(m)
    out = []
    rows = []
    for name, b in s["bodies"].items():
        rows.append([name, "gear" if name in m.gears else "body", _g(b["speed_rpm"], 6),
                     _g(b["torque_Nm"], 6),
                     (_g(b["mass_kg"]) + (" *" if b["mass_computed"] else "")
                      if b["mass_kg"] else "–"),  # (a body that only turns needs no mass)
                     _g(b["polar_inertia_kgm2"]) + (" *" if b["inertia_computed"] else ""),
                     "(" + ", ".join(f"{round(v, 3) + 0.0:.5g}" for v in b["position_mm"])
                     + ")"])
    starred = any("*" in str(c) for row in rows for c in row)
    out.append("<h3>Bodies</h3>" + _table(
        ["body", "kind", "speed [rpm]", "torque [N m]", "mass [kg]", "J [kg m²]",
         "position [mm]"], rows, left=2)
        + ('<p class="note">* computed from the gear\'s geometry (solid steel disc of the '
           "pitch diameter).</p>" if starred else ""))
    st = res.structure
    rows = []
    for name, mk in s["meshes"].items():
        mesh = m.meshes[name]
        e = st.element_names.index(name)
        table = st.stiffness_table[e] if st.stiffness_table.shape[1] else np.full(1, math.nan)
        k = float(np.mean(table))
        # what the run uses: the time-varying wave's size (a "constant" method with a
        # peak_to_peak is a rectangular wave), and the damping assumed
        ptp = float(np.ptp(table)) / k if k > 0 else math.nan
        zeta = (_g(mesh.damping_ratio, 3) if mesh.damping_ratio is not None else
                f"{_g(mesh.damping, 4)} N s/m" if mesh.damping is not None else
                "0 (undamped)")  # (neither given: no damping; '-' read as unknown)
        rows.append([name, f"{mk['driver']} → {mk['driven']}", mk["stage"],
                     _g(mk["frequency_Hz"], 6),
                     "/".join(f"{r:.2f}" for r in mk["pitch_radii_mm"]),
                     _g(mk["total_contact_ratio"], 4), mesh.stiffness.method,
                     _g(k / 1e6), f"{100 * ptp:.3g}" if ptp > 1e-12 else "0", zeta,
                     _g(mesh.backlash.nominal * 1e6, 4), _g(mk["tooth_force_N"] / 1e3, 5)])
    out.append("<h3>Meshes</h3>" + _table(
        ["mesh", "driver → driven", "stage", "f_mesh [Hz]", "pitch radii [mm]",
         "contact ratio", "stiffness method", "mean stiffness [N/µm]",
         "stiffness peak-to-peak [% of mean]", "damping ratio", "backlash [µm]",
         "nominal F_n [kN]"],
        rows, left=3))
    rows = []
    for kind, items in (("gear", m.gears), ("body", m.bodies)):
        for name, body in items.items():
            sup = body.support
            if sup is None:
                continue
            # a shaft's bending stiffness with the value the model computed from it
            assembled = [float(np.mean(st.stiffness_table[i]))
                         for i, n in enumerate(st.element_names)
                         if n.startswith(f"{name}.support.")]
            k = (f"{sup.stiffness / 1e6:.4g}" if sup.stiffness else
                 f"{assembled[0] / 1e6:.4g} (shaft bending)"
                 if sup.shaft is not None and assembled else
                 "shaft bending" if sup.shaft is not None else "-")
            rows.append([name, kind, ", ".join(d for d in body.dofs if d != "theta") or "-",
                         k, _g(sup.damping_ratio, 3) if sup.damping_ratio is not None else
                         f"{_g(sup.damping, 4)} N s/m" if sup.damping is not None else
                         "0 (undamped)",
                         _g(sup.clearance * 1e6, 4)])
    if rows:
        out.append("<h3>Supports</h3>" + _table(
            ["body", "kind", "translations", "stiffness [N/µm]", "damping ratio",
             "clearance [µm]"], rows, left=3))
    rows = []
    for name, sh in m.shafts.items():
        # every elastic shaft by its stiffness (the split between paths follows from them),
        # one given by its geometry with the stiffness the model computed from it
        k = (float(np.mean(st.stiffness_table[st.element_names.index(name)]))
             if name in st.element_names else math.nan)
        geometry = (f" (d = {_g((sh.diameter or 0) * 1e3)} mm, "
                    f"l = {_g((sh.length or 0) * 1e3)} mm)" if not sh.torsional_stiffness
                    else "")
        rows.append([name, " – ".join(sh.connects),
                     "rigid" if sh.rigid else f"{_g(k, 5)}{geometry}"])
    if rows:
        out.append("<h3>Shafts</h3>" + _table(
            ["shaft", "joins", "torsional stiffness [N m/rad]"], rows, left=3))
    rows = _error_rows(m)
    if rows:
        out.append("<h3>Errors</h3>" + _table(
            ["where", "error", "amplitude [µm]", "phase [deg]"], rows, left=2))
    rows = [[name, " – ".join(sp.connects), _g(sp.radial_clearance * 1e6, 4),
             _g(sp.pitch_radius * 1e3, 4), _g(sp.friction_coefficient, 3)]
            for name, sp in m.splines.items()]
    if rows:
        out.append("<h3>Splines</h3>" + _table(
            ["spline", "joins (hub – floating)", "radial clearance [µm]", "pitch radius [mm]",
             "friction coefficient"], rows, left=2))
    return "".join(out)


def _error_rows(m) -> list[list[str]]:
    """Every non-zero error of the model: the gears' (eccentricity, installation, tooth
    thickness, pitch, bearing run-out), their pins' and the meshes' transmission errors
    (a reviewer's 20 µm eccentricity appeared nowhere in the report)."""
    rows = []
    for name, g in m.gears.items():
        e = g.errors
        for field, phase in (("eccentricity", e.eccentricity_phase),
                             ("installation", e.installation_phase),
                             ("tooth_thickness", None), ("pitch", None),
                             ("bearing_runout", e.bearing_runout_phase)):
            value = getattr(e, field)
            if value:
                rows.append([f"gear {name}", field.replace("_", " "), _g(value * 1e6, 4),
                             "–" if phase is None else _g(math.degrees(phase), 4)])
        pin = getattr(g.support, "pin_error", None) if g.support is not None else None
        if pin is not None and not pin.is_zero:
            for field in ("radial", "tangential"):
                if getattr(pin, field):
                    rows.append([f"gear {name}", f"pin position, {field}",
                                 _g(getattr(pin, field) * 1e6, 4), "–"])
    for name, body in m.bodies.items():  # (a carrier's eccentricity)
        if getattr(body, "eccentricity", 0.0):
            rows.append([f"body {name}", "eccentricity", _g(body.eccentricity * 1e6, 4),
                         _g(math.degrees(body.eccentricity_phase), 4)])
    for name, mesh in m.meshes.items():
        te = mesh.transmission_error
        if te.constant:
            rows.append([f"mesh {name}", "transmission error, constant",
                         _g(te.constant * 1e6, 4), "–"])
        if te.amplitude:
            rows.append([f"mesh {name}", "transmission error at mesh frequency",
                         _g(te.amplitude * 1e6, 4), _g(math.degrees(te.phase), 4)])
    return rows


def _run_section(res, met) -> str:
    from ..metrics.load_sharing import DEFINITION_TEXT, DEFINITION_USE

    st = res.statistics()
    settings = [["method", st["method"]], ["simulated time [s]", _g(st["simulated_time_s"], 6)],
                ["steps", f"{st['steps']:,}"],
                ["step [s]", _g(st["step_s"], 4) if st["step_s"] else "adaptive"],
                ["transient discarded", met.settle_times_text()
                 + ("" if met.settling.settled else " (not settled: see the warnings)")],
                ["load-sharing definition", met.definition],
                ["status", res.message]]
    rows = []
    for r in met.rows:
        back = f"{100 * r.back_contact:.2f} %"
        if r.back_flank_force > 0:  # settled (a transient's is in the warnings)
            back += f", up to {r.back_flank_force / 1e3:.4g} kN"
        rows.append([r.mesh, r.group, _g(r.nominal_force / 1e3), _g(r.static_force / 1e3),
                     _g(r.mean_force / 1e3), _g(r.peak_force / 1e3), f"{r.dynamic_factor:.4f}",
                     f"{r.peak_to_nominal:.4f}", f"{r.load_sharing:.4f}",
                     "no backlash (double-flank)" if r.double_flank
                     else f"{100 * r.contact_loss:.2f} %", back])
    per_mesh = _table(["mesh", "group", "nominal F [kN]", "static F [kN]", "mean F [kN]",
                       "peak F [kN]", "dynamic factor", "peak/nominal",
                       f"LSC ({met.definition})", "contact loss", "back flank"], rows, left=2)
    d = met.dynamic_factors
    eng = d.per_group_peak_to_nominal_engineering
    groups = _table(
        ["group", "meshes", f"LSC ({met.definition})", "dynamic factor", "peak/nominal",
         "peak/nominal (eng., G_it)"],
        [[g, ", ".join(ms), f"{met.load_sharing.per_group[g]:.4f}",
          f"{d.per_group_dynamic_factor[g]:.4f}", f"{d.per_group_peak_to_nominal[g]:.4f}",
          f"{eng[g]:.4f}" if g in eng else "-"]
         for g, ms in met.load_sharing.groups.items()], left=2)
    what = (f"<p><b>Load sharing ({_e(met.definition)})</b>: "
            f"{_e(DEFINITION_TEXT[met.definition])}; {_e(DEFINITION_USE[met.definition])}. "
            "<b>Dynamic factor</b>: settled peak / the mesh's own static force (K_v sense, "
            "&ge; 1 in contact). <b>Peak/nominal</b>: settled peak / equal-split nominal "
            "force (Ji &amp; Li eq. 19), load sharing and dynamics together. "
            "<b>Contact loss</b>: share of the whole run (start-up included) with the drive "
            "flanks apart. <b>Back flank</b>: share of the whole run in back-flank contact, "
            "and the largest settled back-flank force. In the group table, dynamic factor "
            "and peak/nominal are the largest of the group's meshes; peak/nominal (eng.) "
            "is the mean over the settled cycles of the largest member's cycle peak over "
            "the nominal force (Ji &amp; Li eq. 19, G_it). "
            f"System load-sharing coefficient: <b>{met.load_sharing.system:.4f}</b>.</p>")
    return (_table(["setting", "value"], settings, left=2) + what + "<h3>Per mesh</h3>"
            + per_mesh + "<h3>Per load-sharing group</h3>" + groups
            + _planets(met.load_sharing, res.kinematics)
            + _bearings(res.bearing_forces(met.settling.start_time, metrics=met),
                        res))


def _bearings(bearings: list[dict], res) -> str:
    """The bearing table the run prints (kN; round-off, :func:`~torquesplit.results.
    bearing_round_off`, written 0), or nothing for a model without supports."""
    from ..results import bearing_round_off

    if not bearings:
        return ""
    tiny = bearing_round_off(bearings)

    def kn(v):
        return "0" if abs(v) <= tiny else _g(v / 1e3)

    per = ("every step" if res.history_keeps_every_step() else
           f"{res.history_samples_per_period():.3g} samples per shortest mesh period")
    peak = ("peak |F| streamed at every step (corners and the peaks between steps "
            "included)" if all(b.get("peak_streamed") for b in bearings) else
            f"peak |F| from the history ({per}): a peak between its samples is missed")
    rows = [[b["body"] + (f" (spline {b['via']})" if b.get("via") else
                          " (rigid bearing)" if b.get("held") == "rigid" else ""),
             ", ".join(f"{d} {kn(v)}" for d, v in zip(b["directions"], b["mean"])),
             kn(b["mean_magnitude"]), kn(b["peak_magnitude"])] for b in bearings]
    header = ["body", "mean force by direction [kN]", "|mean| [kN]", "peak |F| [kN]"]
    if any(b["frame"] != "housing" for b in bearings):  # a planet's turns with its carrier
        header.append("directions in")
        rows = [r + [b["frame"]] for r, b in zip(rows, bearings)]
    return ("<h3>Bearing forces</h3>" + _table(header, rows, left=2)
            + f'<p class="note">The force each body puts on its bearing over the settled '
              f"part: {peak}; a rigid bearing's mean is its meshes' mean forces (their "
              f"streamed time integrals), another's the mean of the history's samples "
              f"({per}).</p>")


def _planets(load_sharing, kinematics) -> str:
    """The planet table (K_gamma per stage, the factor per planet) of a planetary model;
    nothing for a model without planets."""
    from ..cli_support import planet_header, planet_rows, planet_sharing, planet_text

    k = planet_sharing(load_sharing, kinematics)
    if k is None:
        return ""
    return ("<h3>Planets</h3>" + _table(planet_header(k), planet_rows(k, kinematics), left=3)
            + f'<p class="note">{_e(planet_text(k))}</p>')


def _figure(fig_svg: str, caption: str) -> str:
    return f"<figure>{fig_svg}<figcaption>{_e(caption)}</figcaption></figure>"


def _figures(res, definition: str) -> str:
    from ..plot import figures as F

    jobs = [
        ("load_sharing", lambda: F.load_sharing_figure(res, definition),
         "Load-sharing coefficient of each mesh cycle; dashed: the reported value."),
        ("dynamic_factors", lambda: F.dynamic_factor_figure(res, definition),
         "Dynamic factor (peak / own static force) and peak / nominal force of every mesh."),
        ("cycle_peaks", lambda: F.cycle_peak_figure(res),
         "Peak mesh force of each mesh cycle; shaded: the transient left out."),
        ("mesh_force_end", lambda: F.mesh_force_figure(res, last_cycles=5),
         "Mesh force over the last five mesh cycles of each group."),
        ("support_spectrum", lambda: F.support_spectrum_figure(res),
         "Support-force spectrum of the strongest supports; dotted: mesh orders."),
    ]
    out = []
    for salt, make, caption in jobs:
        try:
            fig = make()
        except F.FigureNotApplicableError:
            continue
        out.append(_figure(F.figure_svg(fig, salt), caption))
    return "".join(out)


def _modes(res) -> str:
    from ..modes import model_modes

    try:
        rep = model_modes(res.model, count=MODES_LISTED)
    except Exception as exc:  # noqa: BLE001 - the report goes on without its modes
        return f'<p class="note">Natural modes not computed: {_e(exc)}</p>'
    from ..modes import phased_stages, phasing_suppresses

    from ..steady.maps import mesh_orders

    mesh_f = {n: mk.frequency for n, mk in res.kinematics.meshes.items()}
    # the orders each mesh's stiffness table excites (a rectangular contact wave reaches
    # the 7th and beyond; a smooth one the 3rd)
    structure = getattr(res, "structure", None)
    names = list(structure.element_names) if structure is not None else []
    top = {n: mesh_orders(structure.stiffness_table[names.index(n)]) if n in names
           else 3 for n in mesh_f}
    typed = any(r.type for r in rep.rows)
    whirls = any(r.whirl for r in rep.rows)
    # a mesh order that the planets' mesh phasing leaves unexcited for the mode's type
    # (Parker & Lin 2004) is listed as suppressed, not as a possible resonance
    stages = phased_stages(res.model, res.kinematics)
    from ..steady.maps import CANCELLED, _modal_force_share, mesh_groups

    group_of = {m: g for g in mesh_groups(res.kinematics).values() for m in g}
    q = getattr(getattr(res, "static", None), "q", None)

    def cancels(name: str, k: int, mode: int) -> bool:
        """The meshes of that frequency exert no force of harmonic k on the mode (their
        phases cancel it: steady.maps._modal_force_share); not where they have no such
        harmonic at all (constant stiffness, no error: nothing to cancel)."""
        if structure is None or q is None:
            return False
        share = _modal_force_share(structure, q, rep.solution.mode_shapes[:, mode - 1],
                                   group_of.get(name, [name]), k)
        return share is not None and share < CANCELLED

    rows = []
    for r in rep.rows:
        f = float(r.frequency)
        near = [f"{k}×{name}" + (" (suppressed by phasing)" if phasing_suppresses(
                    stages, name, k, r.type, r.whirl) else " (forces cancel)"
                    if cancels(name, k, r.mode) else "")
                for name, fm in mesh_f.items() for k in range(1, top[name] + 1)
                if abs(f - k * fm) <= NEAR_FRACTION * k * fm]
        energy = ", ".join(f"{n} {100 * v:.0f} %" for n, v in r.largest_shares(3))
        rows.append([str(r.mode), _g(f, 6), str(r.multiplicity)]
                    + ([r.type or ""] if typed else [])
                    + ([r.whirl or ""] if whirls else [])
                    + [f"{r.damping_ratio:.3g}" if np.isfinite(r.damping_ratio) else "-",
                       energy, ", ".join(sorted(set(near))) or "-"])
    header = (["mode", "f [Hz]", "mult."] + (["type"] if typed else [])
              + (["whirl"] if whirls else []) + ["ζ (modal estimate)",
                 "strain energy of the group (largest shares)",
                 f"within {NEAR_FRACTION:.0%} of a mesh order its table excites"])
    # what the table leaves out, said (the mode that sets the step can be above it)
    freqs = np.asarray(rep.solution.frequencies, dtype=float)  # (ascending)
    shown = max((r.mode for r in rep.rows), default=0)
    more = (f" {freqs.size - shown} higher mode(s), {_g(freqs[shown], 4)} to "
            f"{_g(freqs[-1], 4)} Hz, are not listed (<code>torquesplit modes MODEL "
            f"--count {freqs.size}</code> lists them)."
            if freqs.size > shown else "")
    carriers = {c: res.kinematics.bodies[c].speed * 30 / np.pi
                for c in res.kinematics.carriers}
    turning = ("" if not any(carriers.values()) else
               " Modes at the model's speed: " + _e(", ".join(
                   f"carrier {c} turning at {v:.5g} rpm" for c, v in carriers.items()))
               + (" (in its frame: a degenerate pair of the stationary carrier splits into "
                  "forward and backward whirl)" if rep.rotating_frame else "") + ".")
    return (_table(header, rows, left=1)
            + f'<p class="note">{rep.rigid_modes} rigid-body mode(s) left out.{more}'
              f"{turning} Mesh "
              "frequencies: " + _e(", ".join(f"{k} {v:.5g} Hz" for k, v in mesh_f.items()))
            + ". A mesh order marked (forces cancel) drives nothing there: the meshes of "
              "that frequency, by their phases, exert no force of that harmonic on the mode."
            + (" With equally spaced planets, mesh harmonic l excites the rotational "
                     "modes only when l z_s / N is an integer, the translational modes only "
                     "when (l z_s ± 1) / N is, the planet modes otherwise (Parker &amp; Lin "
                     "2004); the other orders are marked suppressed." if stages else "")
            + "</p>")


def _static_section(quasi) -> str:
    from ..plot import figures as F

    met = quasi.metrics()
    forces = quasi.mesh_forces()
    rows = [[m, _g(forces[:, j].min() / 1e3), _g(forces[:, j].mean() / 1e3),
             _g(forces[:, j].max() / 1e3), f"{met.per_mesh[m]:.5f}"]
            for j, m in enumerate(quasi.mesh_names)]
    out = (f"<p>{quasi.times.size} mesh positions; system coefficient "
           f"<b>{met.system:.5f}</b> (static torque ratio, largest over the positions, Mo "
           f"et al. 2017 eqs. 14-15).</p>"
           + _table(["mesh", "min F [kN]", "mean F [kN]", "max F [kN]", "LSC (static_torque)"],
                    rows)
           + _planets(met, quasi.kinematics))
    try:
        span = float(quasi.times[-1] - quasi.times[0]) if quasi.times.size else 0.0
        out += _figure(F.figure_svg(F.static_load_sharing_figure(quasi), "static_ls"),
                       f"Quasi-static load sharing over the sweep ({quasi.times.size} "
                       f"positions over {span:.4g} s of the rated speed).")
    except F.FigureNotApplicableError:
        pass
    return out


def _comparison(res, quasi) -> str:
    from ..examples.published import modal_values, published_for

    entry = published_for(res.model.model.name)
    if entry is None:
        return ""
    note, items = entry
    if not items:
        return f"<h2>Comparison with the paper</h2><p>{_e(note)}</p>"
    values: dict[str, float] = {}
    defs = sorted({k.split(".")[1] for p in items for k in p.keys
                   if k.startswith("load_sharing.") and p.analysis == "dynamic"})
    try:
        values.update(res.metric_values(defs or None))
    except (ValueError, ArithmeticError):
        pass
    if quasi is not None:
        met = quasi.metrics()
        values["load_sharing.static_torque"] = met.system
        values.update({f"load_sharing.static_torque.{g}": v for g, v in met.per_group.items()})
        values.update({f"load_sharing.static_torque.{m}": v for m, v in met.per_mesh.items()})
    if any(p.analysis == "modes" for p in items):  # the papers' modal analyses: at rest
        from ..modes import model_modes

        values.update(modal_values(model_modes(res.model, rotating_frame=False)))
    rows = []
    for p in items:
        ours = [values[k] for k in p.keys if k in values and math.isfinite(values[k])]
        if not ours:
            rows.append([p.quantity, p.where, _g(p.paper, 6), "not computed", "-"])
            continue
        v = max(ours)
        digits = 2 if p.analysis == "modes" else 1
        off = round(100 * (v - p.paper) / p.paper, digits) + 0.0  # (never "-0.00 %")
        # which analysis 'this run' is: a quasi-static entry is the static sweep's, not
        # the dynamic run's (a reviewer read Mo et al. 2017's 1.04811 as the run's)
        what = {"static": " (quasi-static sweep)", "modes": " (modes at rest)"}.get(
            p.analysis, "")
        rows.append([p.quantity + what, p.where, _g(p.paper, 6), _g(v, 6),
                     f"{off:+.{digits}f} %"])
    return ("<h2>Comparison with the paper</h2>" + f"<p>{_e(note)}</p>"
            + _table(["quantity", "where", "paper", "this run", "difference"], rows, left=2)
            + '<p class="note">The papers leave out inputs their dynamic results depend on '
              "(masses, bearing stiffnesses, damping, error phases); the example model states "
              "the values it assumes, and its comments say why the numbers differ.</p>")


# --------------------------------------------------------------------------- page
def build_report(res, *, definition: str | None = None, source: Path | None = None,
                 results_attrs: dict | None = None, quasi=None,
                 progress=None) -> str:
    """The report of a finished run as one self-contained HTML page.

    Parameters
    ----------
    res : Results
        A finished dynamic run.
    definition : str, optional
        Load-sharing definition (default: the run's).
    source : Path, optional
        The model file (its SHA-256 goes in the provenance).
    results_attrs : dict, optional
        Attributes of the results file the run was read from (run id, time, command).
    quasi : QuasiStaticResults, optional
        A quasi-static sweep of the same model, reported in its own section.
    progress : callable, optional
        Called with ``(fraction, what)`` as the sections are built.
    """
    from ..plot.layout import layout_svg

    def step(fraction, what):
        if progress is not None:
            progress(fraction, what)

    met = res.metrics(definition)
    name = res.model.model.name
    parts = [f"<h1>{_e(name)}: dynamic load sharing</h1>",
             _provenance(res, source, results_attrs)]
    step(0.05, "warnings")
    # the quasi-static sweep's too (its positions thinned: the report said "No warnings")
    notes = res.warnings(met.definition) + (
        [w if "quasi-static" in w else f"quasi-static sweep: {w}"
         for w in quasi.warnings()] if quasi is not None else [])
    parts += ["<h2>Warnings</h2>", _warnings(notes)]
    step(0.1, "model")
    parts += ["<h2>Model</h2>", _model_tables(res)]
    step(0.2, "layout")
    parts += ["<h2>Layout</h2>", _figure(layout_svg(res.model, res.kinematics, salt="layout"),
                                         "Pitch circles at their positions; red: lines of "
                                         "action, blue: power flow.")]
    step(0.3, "results")
    parts += ["<h2>Run and results</h2>", _run_section(res, met)]
    step(0.35, "figures")
    parts += ["<h2>Figures</h2>", _figures(res, met.definition)]
    step(0.8, "natural modes")
    parts += ["<h2>Natural modes</h2>", _modes(res)]
    if quasi is not None:
        step(0.85, "quasi-static load sharing")
        parts += ["<h2>Quasi-static load sharing</h2>", _static_section(quasi)]
    step(0.9, "comparison with the paper")
    parts.append(_comparison(res, quasi))
    body = "\n".join(parts)
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{_e(name)}: torquesplit report</title>"
            "<meta name=\"generator\" content=\"torquesplit\">"
            f"<style>{_CSS}</style></head><body>\n{body}\n"
            "<p class=\"note\">Written by torquesplit. Figures are inline SVG; this page "
            "loads nothing from the network.</p></body></html>\n")


def results_attributes(ds) -> dict:
    """The provenance attributes of a results Dataset (for :func:`build_report`)."""
    return {k: ds.attrs.get(k) for k in PROVENANCE_KEYS if ds.attrs.get(k)}


def report_json_summary(res, definition: str | None = None) -> dict:
    """A small JSON summary of what the report shows (``report --json``)."""
    met = res.metrics(definition)
    return {"model": res.model.model.name, "definition": met.definition,
            "system_load_sharing": met.load_sharing.system}


__all__ = ["build_report", "model_hash", "results_attributes", "report_json_summary"]
