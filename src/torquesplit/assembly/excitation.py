"""Periodic excitation tables of the meshes: stiffness, phasing, backlash, errors, impact.

Each function turns the model's description of one mesh into the arrays the
:class:`~torquesplit.assembly.structure.Structure` holds, by calling the physics in
:mod:`torquesplit.gears`.  Phase 0 of a mesh cycle is when a new tooth pair enters
contact.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import ModelWarning, warn_user
from ..gears import line_of_action as loa
from ..gears.vectors import cross
from ..model.kinematics import Kinematics
from ..model.schema import Model


#: unlabelled meshes of one tooth-count pair whose nominal forces differ by more than this
#: (relative) are not parallel paths of one stage: a split and a combining stage differ
#: by the number of paths (x2, x3), parallel branches at most by their working pressure
#: angles (profile shifts, centre distances: a few per cent of cos alpha)
STAGE_FORCE_RTOL = 0.05


def tooth_pair(model: Model, mesh_name: str) -> str:
    """``"za/zb"``: the tooth counts of a mesh's gears, smaller first."""
    za, zb = sorted(model.gears[g].teeth for g in model.meshes[mesh_name].gears)
    return f"{za}/{zb}"


def stage_labels(model: Model, kin: Kinematics) -> dict[str, str]:
    """Each mesh's stage (its load-sharing group, within its path): the model's label or,
    without one, the tooth-count pair of its gears ``"za/zb"``.  Unlabelled meshes of one
    pair that carry different nominal forces are not parallel paths (a split stage and a
    combining stage of equal ratio: grouped, the combining meshes read as twice loaded):
    they become ``"za/zb-1"``, ``"za/zb-2"``... in the order the file first lists each
    force (:func:`torquesplit.model.checks.plausibility_warnings` says so)."""
    labels = {name: mesh.stage for name, mesh in model.meshes.items() if mesh.stage}
    by_pair: dict[str, list[str]] = {}
    for name, mesh in model.meshes.items():
        if not mesh.stage:
            by_pair.setdefault(tooth_pair(model, name), []).append(name)
    for pair, names in by_pair.items():
        levels: list[float] = []  # the distinct nominal forces, in file order
        which = {}
        for name in names:
            f = abs(kin.meshes[name].force)
            k = next((i for i, g in enumerate(levels)
                      if abs(f - g) <= STAGE_FORCE_RTOL * max(f, g)), None)
            if k is None:
                levels.append(f)
                k = len(levels) - 1
            which[name] = k
        for name in names:
            labels[name] = pair if len(levels) == 1 else f"{pair}-{which[name] + 1}"
    return {name: labels[name] for name in model.meshes}


# --------------------------------------------------------------------------- stiffness
#: table points per period where ``[analysis] table_points`` is not given: where a table
#: steps (a tooth pair entering or leaving, an impact pulse) a step is a ramp 1/n of a
#: period long, which lowers the dynamic peaks (0.6-9 % on the shipped examples at 256)
STEP_TABLE_POINTS = 16384
#: and where every table is smooth
SMOOTH_TABLE_POINTS = 256


SECANT_SOFT = 0.8
"""A secant LTCA stiffness below this share of the tangent one is said: the separation
the modifications open (and the Hertzian softening) counts as compliance in P/Z."""


def _warn_soft_secant(mesh_name: str, summary: dict) -> None:
    """Warn where a mesh couples its LTCA by the secant stiffness (Liu et al. 2021 eq. 5,
    k = P/Z) and that is well below the tangent dP/dZ: 20 um of tip relief took a pair
    from 741 to 455 N/um while its tangent stiffness stayed at 756, with nothing said;
    its natural frequencies come out low by the square root of that ratio."""
    if summary.get("excitation") != "secant":
        return
    ks = summary.get("stiffness_secant_mean_N_per_m", math.nan)
    kt = summary.get("stiffness_tangent_mean_N_per_m", math.nan)
    if not (ks > 0 and kt > 0 and ks < SECANT_SOFT * kt):
        return
    warn_user(
        f"meshes.{mesh_name}.stiffness: the secant LTCA stiffness P/Z ({ks / 1e6:.4g} N/um, "
        f"Liu et al. 2021 eq. 5) is {100 * (1 - ks / kt):.0f} % below the tangent dP/dZ "
        f"({kt / 1e6:.4g} N/um): the separation the modifications open counts as compliance, "
        f"so the mesh's natural frequencies come out about {100 * (1 - math.sqrt(ks / kt)):.0f}"
        f" % low; ltca.excitation = \"tangent\" (the default) keeps dP/dZ and drives the "
        f"loaded transmission error instead", ModelWarning)


def table_points(model: Model, kin: Kinematics) -> int:
    """Points per period of the excitation tables: ``[analysis] table_points``, or by
    default :data:`STEP_TABLE_POINTS` where a mesh's stiffness table steps or a mesh has
    a meshing-in impact or an LTCA stiffness, else :data:`SMOOTH_TABLE_POINTS`."""
    n = model.analysis.table_points
    if n is not None:
        return int(n)
    from ..convergence import rows_that_jump

    for name, mesh in model.meshes.items():
        if mesh.impact or mesh.stiffness.method == "ltca":
            return STEP_TABLE_POINTS
        try:
            k = stiffness_table(model, kin, name, SMOOTH_TABLE_POINTS)
        except (ValueError, KeyError):  # a table the model checks refuse, with the reason
            continue
        if rows_that_jump(k)[0]:
            return STEP_TABLE_POINTS
    return SMOOTH_TABLE_POINTS


def stiffness_table(model: Model, kin: Kinematics, mesh_name: str, n: int) -> np.ndarray:
    """k(phase) sampled at ``n`` uniform mesh phases [N/m]."""
    spec = model.meshes[mesh_name].stiffness
    phase = np.arange(n) / n
    mk = kin.meshes[mesh_name]
    if spec.method == "constant":
        return _constant_table(n, float(spec.value), float(spec.peak_to_peak),
                               float(_profile_contact_ratio(mk))).copy()  # (the caller's)
    if spec.method == "table":
        src = np.asarray(spec.phase)
        order = np.argsort(src)
        return np.interp(phase, src[order], np.asarray(spec.values)[order], period=1.0)
    if spec.method == "fourier":
        k = np.full(n, spec.mean)
        for i, a in enumerate(spec.cos, start=1):
            k += a * np.cos(2 * np.pi * i * phase)
        for i, b in enumerate(spec.sin, start=1):
            k += b * np.sin(2 * np.pi * i * phase)
        if np.any(k <= 0):
            raise ValueError(f"meshes.{mesh_name}.stiffness: the Fourier series becomes negative; "
                             f"check the coefficients against the mean")
        return k
    if spec.method == "ltca":
        from ..gears.contact.coupling import mesh_ltca

        tab = mesh_ltca(model, kin, mesh_name, n)
        _warn_soft_secant(mesh_name, tab.summary)
        return np.asarray(tab.stiffness)
    from ..gears import stiffness as gst

    if mk.geometry is None:
        raise ValueError(f"meshes.{mesh_name}.stiffness: method {spec.method!r} needs a "
                         f"cylindrical pair; give a table or a constant for bevel/face meshes")
    opts = {}
    if spec.method == "potential_energy":
        opts = dict(fillet_foundation=spec.fillet_foundation, slices=spec.slices)
    ms = gst.mesh_stiffness(mk.geometry, spec.method, n=n, **opts)
    return np.interp(phase, np.asarray(ms.phase), np.asarray(ms.stiffness), period=1.0)


@functools.lru_cache(maxsize=64, typed=True)  # (typed: n = 512.0 is not 512)
def _constant_table(n, value: float, peak_to_peak: float, contact_ratio: float):
    """The table of a "constant" stiffness (read-only), kept by its values: a model is
    checked and assembled with three of them per mesh, and a study's cases that vary
    something else share them (1 ms of a Dong et al. 2021 case's 20 ms set-up)."""
    if peak_to_peak == 0:
        k = np.full(n, value)
    else:
        k = contact_zone_wave(np.arange(n) / n, value, peak_to_peak, contact_ratio)
    k.flags.writeable = False
    return k


def _profile_contact_ratio(mk) -> float:
    eps = mk.transverse_contact_ratio
    return eps if math.isfinite(eps) else 1.5


def contact_zone_wave(phase: np.ndarray, mean: float, peak_to_peak: float, contact_ratio: float):
    """Rectangular single/double contact wave with the given mean and relative p-p.

    Over one mesh cycle ``ceil(eps) `` pairs are in contact for the fraction
    ``eps - floor(eps)`` of the cycle (starting at phase 0), ``floor(eps)`` pairs
    for the rest; the stiffness steps by ``peak_to_peak * mean`` between the two.
    """
    frac = contact_ratio - math.floor(contact_ratio)
    high = phase < frac
    dk = peak_to_peak * mean
    k_low = mean - dk * frac
    return np.where(high, k_low + dk, k_low)


# --------------------------------------------------------------------------- phasing
def mesh_phases(model: Model, kin: Kinematics, *, strict: bool = False) -> dict[str, float]:
    """Mesh phase at t = 0 [cycles] of every mesh: override, else from the involute
    geometry (docs/theory/planetary.md, "Mesh phasing").

    Phase 0 of a mesh cycle is the instant a new tooth pair enters contact at the
    start of active contact (where the driven gear's tip cuts the line of action, the
    driver's tip for an internal driver).  On a gear g (z teeth, base radius r_b, base
    pitch p_b = 2 pi r_b / z) a mesh X has, at t = 0::

        s_X = frac( -sigma z (tau_X - gamma) / 2 pi + eps_X (h - rho_X) / p_b )

    with tau_X the angle (about g's axis) of the point where X's line of action touches
    g's base circle, rho_X the distance from there to X's start of active contact,
    sigma the sign of g's speed in X's frame (its carrier's for a planet mesh), eps_X =
    +1 if X's contact moves away from that tangency point (g drives an external pair or
    is driven as a ring), -1 otherwise -- which also says which flank X loads -- and h
    half of g's base tooth thickness (+ external, - internal tooth: the flank's base
    point lies h from the tooth centre line, itself at the angle gamma).  Two meshes on
    the same flank of one gear (same eps) with congruent geometry differ by
    ``-sigma z (tau_2 - tau_1) / 2 pi`` (the rule of split-torque clocking); the sun and
    ring meshes of a planet are on opposite flanks and differ also by the tooth
    thickness and their own starts of contact.  The first mesh reached on each gear
    fixes its tooth angle gamma.  Bevel and face meshes (no involute pair) use the
    angle of the contact point and no flank term.

    A loop of meshes through a planet must close (the tooth-count assembly condition);
    with ``strict`` a loop that does not raises :class:`~torquesplit.errors.ModelError`.
    Meshes reached from no fixed reference start at phase 0.
    """
    on_gear: dict[str, list[str]] = {g: [] for g in model.gears}
    for name, m in model.meshes.items():
        for g in m.gears:
            on_gear[g].append(name)
    terms = {(name, g): _phase_terms(model, kin, name, g)
             for name, m in model.meshes.items() for g in m.gears}

    def phase(mesh, g, gamma):
        z, sigma, tau, c = terms[(mesh, g)]
        return (-sigma * z * (tau - gamma) / (2 * math.pi) + c) % 1.0

    def tooth_angle(mesh, g, s):
        z, sigma, tau, c = terms[(mesh, g)]
        return tau + 2 * math.pi * (s - c) / (sigma * z)

    phases: dict[str, float] = {}
    gamma: dict[str, float] = {}
    misfits: list[tuple[str, str, float]] = []
    shaft = compound_partners(model, kin)
    component: dict[str, str] = {}  # mesh -> the mesh its phasing started from
    order = [n for n, m in model.meshes.items() if m.phase is not None] + list(model.meshes)
    for start in order:
        if start in phases:
            continue
        m0 = model.meshes[start]
        phases[start] = (m0.phase or 0.0) % 1.0
        stack = [start]
        while stack:
            cur = stack.pop()
            component[cur] = start
            for g in model.meshes[cur].gears:
                if g not in gamma:
                    gamma[g] = tooth_angle(cur, g, phases[cur])
                elif model.meshes[cur].phase is None:
                    d = (phase(cur, g, gamma[g]) - phases[cur] + 0.5) % 1.0 - 0.5
                    if abs(d) > 1e-6:
                        misfits.append((cur, g, d))
                for other in on_gear[g]:
                    if other in phases:
                        continue
                    if model.meshes[other].phase is not None:
                        phases[other] = model.meshes[other].phase % 1.0
                    else:
                        phases[other] = phase(other, g, gamma[g])
                    stack.append(other)
    if shaft:
        misfits += _clock_compound_planets(model, kin, shaft, on_gear, phases, component,
                                           phase, tooth_angle)
    if strict:
        issues = []
        for mesh, g, d in misfits:
            if kin.meshes[mesh].carrier is None:
                continue  # a fixed-axis loop: the user clocks the gears (Liu et al. 2021)
            planet = next((b for b in model.meshes[mesh].gears if b in kin.planet_bodies),
                          g)
            if planet in shaft:
                issues.append((f"meshes.{mesh}", (
                    f"the compound planets cannot all be clocked alike: with the gears of "
                    f"each planet shaft clocked as on the first one, the teeth of "
                    f"{planet!r} miss by {d:+.4f} of a mesh cycle here (identical compound "
                    f"planets fit only where (z_s z_2 + z_r z_1) / (N gcd(z_1, z_2)) is a "
                    f"whole number for equal spacing, z_1 the planet gear on the sun, z_2 "
                    f"on the ring); change the tooth counts or the angles, or give the "
                    f"meshes' 'phase' (planets clocked each on its own)")))
                continue
            issues.append((f"meshes.{mesh}", (
                f"the teeth of planet {planet!r} cannot mesh here: around the loop of "
                f"meshes through it the tooth positions miss by {d:+.4f} of a mesh cycle "
                f"(the tooth-count assembly condition: a planet fits sun and ring only at "
                f"angles that are whole multiples of 360 deg / (z_s + z_r) from another "
                f"planet); move the planet to such an angle, change the tooth counts, or "
                f"give the meshes' 'phase'")))
        if issues:
            from ..errors import ModelError

            raise ModelError(issues[:1] if len(issues) > 3 else issues)
    return phases


def _clock_compound_planets(model, kin, shaft, on_gear, phases, component, phase,
                            tooth_angle) -> list[tuple[str, str, float]]:
    """Phases of compound planets (:func:`mesh_phases`' second pass).  The meshes reached
    through a planet's other gear (its ring meshes) were phased apart from the first
    gear's: shifted together (a turn of that train) so that the gears of the first planet
    shaft have a tooth at one angle, unless a mesh there has a given ``phase``.  Every
    other planet shaft must then be clocked as the first (identical planets): its two
    tooth angles may differ from the first's only by whole teeth of either gear, i.e. by
    a multiple of gcd(z_1, z_2) / z_1 of the second gear's mesh cycle (not checked for a
    planet a mesh of which has a given ``phase``: the user clocks it).  Returns the
    misfits (mesh, gear, miss in cycles)."""
    def angle(g):
        return tooth_angle(on_gear[g][0], g, phases[on_gear[g][0]])

    def reach(g):  # the gears, not planets, that g meshes with: its role on the shaft
        return frozenset(o for m in on_gear[g] for o in model.meshes[m].gears
                         if o not in kin.planet_bodies)

    shafts, seen = [], set()
    for g in model.gears:
        if g in shaft and g not in seen and on_gear[g]:
            members = [g] + [o for o in shaft[g] if on_gear[o]]
            seen.update(members)
            shafts.append((kin.planet_bodies[g], members))
    misfits = []
    first: dict[str, list[str]] = {}  # carrier -> the first shaft's gears
    for carrier, members in shafts:
        ref = first.setdefault(carrier, members)
        if ref is members:  # the first shaft of this carrier: join its trains
            g0 = members[0]
            for gk in members[1:]:
                xk = on_gear[gk][0]
                start = component[xk]
                if start == component[on_gear[g0][0]] or any(
                        model.meshes[m].phase is not None
                        for m, c in component.items() if c == start):
                    continue
                shift = phase(xk, gk, angle(g0)) - phases[xk]
                for m, c in list(component.items()):
                    if c == start:
                        phases[m] = (phases[m] + shift) % 1.0
                        component[m] = component[on_gear[g0][0]]
            continue
        if any(model.meshes[m].phase is not None for g in members for m in on_gear[g]):
            continue  # the user clocks this planet (given phases)
        roles = {reach(r): r for r in ref}
        match = [(g, roles.get(reach(g))) for g in members]
        if any(r is None for _, r in match):
            continue  # not a copy of the first shaft: nothing to compare
        (g1, r1), rest = match[0], match[1:]
        for g2, r2 in rest:
            z1, z2 = model.gears[g1].teeth, model.gears[g2].teeth
            step = math.gcd(z1, z2) / z1
            d = ((angle(g2) - angle(g1)) - (angle(r2) - angle(r1))) * z2 / (2 * math.pi)
            d = (d / step + 0.5) % 1.0 - 0.5
            if abs(d) * step > 1e-6:
                misfits.append((on_gear[g2][0], g2, d * step))
    return misfits


def compound_partners(model: Model, kin: Kinematics) -> dict[str, list[str]]:
    """Gear -> the other gears of its compound planet: planet gears of one carrier joined
    by rigid shafts (they turn together; :func:`mesh_phases` clocks them alike)."""
    groups: dict[str, list[str]] = {}
    for g in model.gears:
        if g in kin.planet_bodies:
            groups.setdefault(kin.groups[g], []).append(g)
    return {g: [o for o in members if o != g]
            for members in groups.values() if len(members) > 1 for g in members}


def _phase_terms(model: Model, kin: Kinematics, mesh_name: str, gear: str):
    """(z, sigma, tau, c) of gear ``gear`` in mesh ``mesh_name`` for :func:`mesh_phases`:
    c = eps (h - rho_start) / p_b [cycles]."""
    mk = kin.meshes[mesh_name]
    body = kin.bodies[gear]
    axis = body.axis / np.linalg.norm(body.axis)
    e1 = loa.reference_direction(axis, 0.0)
    e2 = cross(axis, e1)
    z = model.gears[gear].teeth
    w = mk.driver_speed if gear == mk.driver else mk.driven_speed
    sigma = 1.0 if w > 0 else -1.0

    def angle(v):
        v = v - axis * float(v @ axis)
        return math.atan2(float(v @ e2), float(v @ e1))

    geo = mk.geometry
    if geo is None:  # bevel / face: the contact point's angle, no flank term
        return z, sigma, angle(mk.contact_point - body.position), 0.0
    n = np.asarray(mk.line_of_action, dtype=float)
    n_t = n - axis * float(n @ axis)
    n_t = n_t / np.linalg.norm(n_t)
    rel = mk.contact_point - body.position
    rel = rel - axis * float(rel @ axis)
    tangency = rel - float(rel @ n_t) * n_t  # foot of the perpendicular from the centre
    tau = angle(tangency)
    ga = model.gears[model.meshes[mesh_name].gears[0]]
    pair_first = model.meshes[mesh_name].gears[0 if ga.gear_type != "internal" else 1]
    index = 1 if gear == pair_first else 2  # gear 1 of the PairGeometry is the pinion
    gg = geo.gear1 if index == 1 else geo.gear2
    p1, p2, _, _ = geo._tangent_lengths
    first_drives = mk.driver == pair_first
    s_start = geo.path_start if first_drives else geo.path_end
    s_dot = 1.0 if first_drives else -1.0  # direction of travel along s
    if index == 1:
        rho, d_rho = p1 + s_start, 1.0
    elif geo.is_internal:
        rho, d_rho = p2 + s_start, 1.0
    else:
        rho, d_rho = p2 - s_start, -1.0
    eps = s_dot * d_rho
    if gg.internal:
        # half base thickness of an internal tooth: (pi/2 - 2 x tan(alpha_n)) / z at the
        # reference circle, thinner by inv(alpha_t) at the base circle
        alpha_t = gg.transverse_pressure_angle
        psi = ((math.pi / 2 - 2.0 * gg.profile_shift * math.tan(gg.normal_pressure_angle))
               / gg.teeth - (math.tan(alpha_t) - alpha_t))
        h = -gg.base_radius * psi
    else:
        h = gg.base_radius * gg.base_half_angle
    p_b = 2 * math.pi * gg.base_radius / gg.teeth
    return z, sigma, tau, eps * (h - rho) / p_b


# --------------------------------------------------------------------------- backlash
def half_backlash_sequence(model: Model, kin: Kinematics, mesh_name: str) -> np.ndarray:
    """Half backlash per engagement [m]: constant, or random per Ji & Li eq. 14.

    The model gives the total backlash 2b; the dead zone of the mesh element has the
    half-width b (Ji & Li eq. 13, Dong et al. 2021 eq. 7).  A random sequence is drawn per
    engagement within ``nominal +/- tolerance`` and repeats after lcm(z1, z2) cycles.
    """
    spec = model.meshes[mesh_name].backlash
    if spec.distribution == "constant" or spec.tolerance == 0:
        return np.array([spec.nominal / 2])
    from ..gears import backlash as gbl

    za, zb = (model.gears[g].teeth for g in model.meshes[mesh_name].gears)
    lower = max(spec.nominal - spec.tolerance, 0.0)
    upper = spec.nominal + spec.tolerance
    period = 1.0 / kin.meshes[mesh_name].frequency
    if spec.distribution == "normal":
        seq = gbl.random_backlash(lower, upper, za, zb, period, spec.seed).values
    else:
        n = gbl.hunting_period_cycles(za, zb)
        seq = np.random.default_rng(spec.seed).uniform(lower, upper, n)
    return np.asarray(seq) / 2


# --------------------------------------------------------------------------- errors
def mesh_errors(model: Model, kin: Kinematics, mesh_name: str):
    """Constant error and sinusoids (amplitude, omega, phase) along the line of action.

    A positive error opens the mesh (delta = V q - e).  Centre offsets of the driver
    (eccentricity, installation, bearing run-out) enter as ``-eps_d . n``, those of the
    driven gear as ``+eps_n . n`` (Liu et al. 2021 eqs. 1-2 and Dong et al. 2021 eq. 11 in physical
    form, see gears/errors.py); tooth thickness and pitch errors of either gear open
    the mesh (Mo et al. 2017 §4).  In-plane offsets are projected on the 3-D line of action
    through its component in the gear's plane.
    """
    from ..gears import errors as gerr

    mesh = model.meshes[mesh_name]
    mk = kin.meshes[mesh_name]
    te = mesh.transmission_error
    total = gerr.LineOfActionDeviation(te.constant)
    if te.amplitude:
        total = total + gerr.LineOfActionDeviation(0.0, [te.amplitude],
                                               [2 * math.pi * mk.frequency], [te.phase])
    n = mk.line_of_action
    for g in mesh.gears:
        ge = model.gears[g].errors
        if not any((ge.eccentricity, ge.installation, ge.tooth_thickness, ge.pitch,
                    ge.bearing_runout)):
            continue
        body = kin.bodies[g]
        axis = body.axis
        e1 = loa.reference_direction(axis, 0.0)
        e2 = cross(axis, e1)
        n1, n2 = float(n @ e1), float(n @ e2)
        scale = math.hypot(n1, n2)  # in-plane part of the line of action
        zeta = math.atan2(n2, n1)
        # errors turn with the gear relative to the mesh's frame (a planet mesh's carrier)
        w = mk.driver_speed if g == mk.driver else mk.driven_speed
        centre = gerr.CentreDeviation(
            eccentricity=ge.eccentricity * scale, eccentricity_phase=ge.eccentricity_phase,
            installation=ge.installation * scale, installation_direction=ge.installation_phase,
            omega=w).on_line(zeta)
        if ge.bearing_runout:
            centre = centre + gerr.bearing_runout_error(ge.bearing_runout * scale,
                                                        ge.bearing_runout_phase, w, zeta)
        sign = -1.0 if g == mk.driver else 1.0
        total = total + centre.scaled(sign)
        alpha = mk.working_pressure_angle
        if ge.tooth_thickness:
            total = total + gerr.tooth_thickness_error(ge.tooth_thickness, alpha)
        if ge.pitch:
            total = total + gerr.cumulative_pitch_error(ge.pitch, 0.0, abs(w), alpha)
    if mesh.stiffness.method == "ltca":
        # loaded transmission-error excitation of the LTCA (gears/contact/coupling.py)
        from ..gears.contact.coupling import mesh_ltca, error_harmonics

        tab = mesh_ltca(model, kin, mesh_name, table_points(model, kin))
        c0, harm = error_harmonics(tab.error, mk.frequency, mesh_phases(model, kin)[mesh_name],
                                   int(tab.summary.get("error_harmonics", 16)))
        if harm:
            amp, om, ph = zip(*harm)
            total = total + gerr.LineOfActionDeviation(c0, list(amp), list(om), list(ph))
        else:
            total = total + gerr.LineOfActionDeviation(c0)
    sines = [(float(a), float(om), float(ph))
             for a, om, ph in zip(total.amplitudes, total.omegas, total.phases)]
    return float(total.constant), sines


# --------------------------------------------------------------------------- impact
#: stiffness methods whose tables start (phase 0) where a new tooth pair enters contact
ENTRY_PHASED = ("iso6336", "potential_energy")


def impact_force_table(model: Model, kin: Kinematics, mesh_name: str, n: int):
    """Meshing-in impact force over one mesh cycle [N], or None (Liu et al. 2021 eqs. 6-10).

    The loaded deflection that brings the new pair early is that of the pairs in contact
    just before it enters (Liu et al. 2021 eq. 7: the loaded transmission error of the
    pair in mesh): the force over the stiffness table's value at the end of the cycle
    (phase 0 is the entry; a spur pair's single-pair stiffness).  Inputs the paper leaves
    open: the single-pair stiffness at the engagement point is the mean mesh stiffness
    divided by the transverse contact ratio (linear contact law, n = 1); the pulse is a
    half sine (see gears/impact.py).
    """
    mesh = model.meshes[mesh_name]
    if not mesh.impact:
        return None
    if mesh.stiffness.method == "ltca":
        # meshing-in impact from the loaded geometry (gears/contact/impact.py)
        from ..gears.contact.coupling import mesh_ltca

        return np.asarray(mesh_ltca(model, kin, mesh_name, n).impact_force)
    from ..gears import impact as gim

    mk = kin.meshes[mesh_name]
    geo = mk.geometry
    if geo is None:
        raise ValueError(f"meshes.{mesh_name}.impact: meshing-in impact needs a cylindrical "
                         f"pair; set impact = false for bevel and face meshes")
    table = stiffness_table(model, kin, mesh_name, n)
    k_mean = float(np.mean(table))
    driver_first = model.gears[mk.driver].gear_type != "internal" and (
        geo.gear1.teeth == model.gears[mk.driver].teeth)
    g_drv, g_dvn = (geo.gear1, geo.gear2) if driver_first else (geo.gear2, geo.gear1)
    imp = gim.meshing_in_impact(
        base_radius_driving=mk.base_radii[0], base_radius_driven=mk.base_radii[1],
        tip_radius_driven=g_dvn.tip_radius, centre_distance=mk.center_distance,
        base_pitch=geo.base_pitch, omega_driving=abs(mk.driver_speed),
        # just before the entry where the table's phase 0 is the entry (ISO 6336, the
        # potential-energy method); a table or series written by hand has its own phase
        normal_load=mk.force,
        loaded_stiffness=float(table[-1]) if mesh.stiffness.method in ENTRY_PHASED else k_mean,
        inertia_driving=kin.bodies[mk.driver].polar_inertia,
        inertia_driven=kin.bodies[mk.driven].polar_inertia,
        impact_stiffness=k_mean / max(mk.transverse_contact_ratio, 1.0),
    )
    if imp.pulse_samples(n) < gim.MIN_PULSE_SAMPLES:  # said in the model's words
        warn_user(f"meshes.{mesh_name}.impact: the meshing-in impact pulse spans "
                  f"{imp.pulse_samples(n):.1f} of the {n} table points per mesh cycle, "
                  f"too few to resolve its peak; set [analysis] table_points to at least "
                  f"{imp.phases_needed()}", ModelWarning)
    _, force = imp.table(n, warn=False)
    return np.asarray(force)


# --------------------------------------------------------------------------- friction
def friction_direction(kin: Kinematics, mesh_name: str) -> np.ndarray:
    """Unit rolling direction t of a mesh [-] (global frame): perpendicular to the line of
    action in the driver's transverse plane, pointing where the driver's surface moves at
    the contact (the entrainment direction of both flanks).

    Tooth friction on the driven gear is ``ff f t`` (ff > 0 after the pitch point, where
    the driver's flank slides ahead of the driven one, i.e. along the driver's sliding
    velocity), on the driver ``-ff f t`` (see :func:`friction_table`).
    """
    mk = kin.meshes[mesh_name]
    drv = kin.bodies[mk.driver]
    a = drv.axis / np.linalg.norm(drv.axis)
    n = np.asarray(mk.line_of_action, dtype=float)
    n_t = n - a * float(n @ a)
    n_t = n_t / np.linalg.norm(n_t)
    t = cross(a, n_t)
    v = mk.driver_speed * cross(a, mk.contact_point - drv.position)
    if float(t @ v) < 0.0:
        t = -t
    t[np.abs(t) < 1e-15] = 0.0
    return t


def friction_table(model: Model, kin: Kinematics, mesh_name: str, n: int) -> np.ndarray:
    """Tooth friction per unit normal mesh load over one mesh cycle (Jin et al. 2019), (3, n).

    Rows: the friction force on the driven gear along the rolling direction t of
    :func:`friction_direction` [-] (the driver gets the opposite force), and the friction
    moments on the driver and on the driven gear [m], each positive in that gear's own
    direction of rotation.  Phase 0 is the instant a new tooth pair enters contact (as the
    stiffness tables).

    This is :func:`torquesplit.gears.friction.mesh_friction_table` with gear 1 = the
    driver (its tangency point N1 is the origin of the contact positions, so contact
    travels from ``contact_start`` to ``contact_end`` > ``contact_start``); its sign
    conventions then read: force on gear 2 = sign(u1 - u2) mu F (negative in the approach,
    before the pitch point, positive in the recess), moment_1 = -force rho1 (aids the
    driver in the approach), moment_2 = +force rho2 (opposes the driven gear in the
    approach); the friction power moment_1 |w1| + moment_2 |w2| = -mu F |u1 - u2| <= 0.
    Model ``"constant"``: the same kinematics (pairs, slices, load shared in proportion to
    the contact length) with a constant coefficient, reversing at the pitch point.
    Double-helical pairs: one helix at half the load (the ratios per unit load are those
    of the whole mesh).
    """
    from ..errors import ModelError
    from ..gears import friction as gfr

    spec = model.meshes[mesh_name].friction
    mk = kin.meshes[mesh_name]
    geo = mk.geometry
    loc = f"meshes.{mesh_name}.friction"
    if mk.conical or geo is None:
        raise ModelError([(loc, "tooth friction is implemented for cylindrical (spur, helical, "
                                "double-helical) pairs; remove 'friction' from this bevel/face "
                                "mesh")])
    if geo.is_internal:
        raise ModelError([(loc, "tooth friction is implemented for external pairs; remove "
                                "'friction' from this internal mesh")])
    mesh = model.meshes[mesh_name]
    p1, p2, _, _ = geo._tangent_lengths
    if mk.driver == mesh.gears[0]:  # PairGeometry gear 1 (the pinion) drives
        rb = (geo.gear1.base_radius, geo.gear2.base_radius)
        start, end = p1 + geo.path_start, p1 + geo.path_end
    else:  # the wheel drives: measure from its tangency point T2
        rb = (geo.gear2.base_radius, geo.gear1.base_radius)
        start, end = p2 - geo.path_end, p2 - geo.path_start
    g_drv, g_dvn = model.gears[mk.driver], model.gears[mk.driven]
    omega = abs(mk.driver_speed)
    load = mk.force / 2.0 if geo.double_helical else mk.force
    common = dict(base_radius_1=rb[0], base_radius_2=rb[1],
                  centre_distance=geo.operating_center_distance, contact_start=start,
                  contact_end=end, base_pitch=geo.base_pitch,
                  base_helix_angle=geo.base_helix_angle, face_width=geo.face_width)
    if spec.model == "xu2007":
        tab = gfr.mesh_friction_table(
            omega_1=omega, normal_load=load, viscosity=spec.viscosity,
            roughness=spec.roughness,
            youngs_modulus=(g_drv.youngs_modulus, g_dvn.youngs_modulus),
            poisson_ratio=(g_drv.poisson_ratio, g_dvn.poisson_ratio),
            n_phases=n, n_slices=spec.slices, **common)
        return np.vstack([tab.force_per_load, tab.moment_1_per_load, tab.moment_2_per_load])
    return constant_friction_table(coefficient=spec.coefficient, n=n, n_slices=spec.slices,
                                   **common)


def constant_friction_table(*, coefficient, base_radius_1, base_radius_2, centre_distance,
                            contact_start, contact_end, base_pitch, base_helix_angle,
                            face_width, n, n_slices) -> np.ndarray:
    """(3, n) friction force and moments per unit normal load with a constant coefficient.

    Gear 1 drives; the kinematics are those of
    :func:`torquesplit.gears.friction.mesh_friction_table` (tooth pairs one base pitch
    apart, helical teeth cut into slices shifted by z tan(beta_b), load shared in
    proportion to the contact length in contact), with mu constant and the direction
    lambda = sign(u1 - u2) reversing at the pitch point.
    """
    line = float(np.sqrt(centre_distance**2 - (base_radius_1 + base_radius_2) ** 2))
    path = contact_end - contact_start
    helical = base_helix_angle != 0.0
    m = n_slices if helical else 1
    tan_bb = math.tan(abs(base_helix_angle))
    n_pairs = int(np.ceil(path / base_pitch + face_width * tan_bb / base_pitch)) + 1
    phase = np.arange(n) / n
    z = (np.arange(m) + 0.5) * face_width / m
    travel = ((phase[:, None, None] + np.arange(n_pairs)[None, :, None]) * base_pitch
              - z[None, None, :] * tan_bb)
    inside = (travel >= 0.0) & (travel <= path)
    share = inside / inside.sum(axis=(1, 2), keepdims=True)
    s = contact_start + travel
    rho1, rho2 = s, line - s
    omega_ratio = base_radius_1 / base_radius_2  # w2 / w1
    lam = np.where(inside, np.sign(rho1 - omega_ratio * rho2), 0.0)
    f = lam * coefficient * share
    return np.vstack([f.sum(axis=(1, 2)), (-f * rho1).sum(axis=(1, 2)),
                      (f * rho2).sum(axis=(1, 2))])
