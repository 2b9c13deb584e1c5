"""Epicyclic kinematics: carriers, planets, held members, speeds and the nominal torques.

A **planet** is a body whose bearing sits on another body (``support.on``, the
**carrier**) off that body's axis: its centre orbits with the carrier.  Every mesh that
involves a planet is analysed in the frame of its carrier, where it is a fixed-axis mesh
(Willis): its speed ratio, line of action, mesh frequency and loaded flank follow from
the speeds *relative to the carrier*.  Members held against rotation
(``torsional_support``) have zero nominal speed.

Speeds.  One unknown per rigid group (bodies joined by rigid shafts).  Each mesh gives
``w_b - w_C = r (w_a - w_C)`` with ``r`` the geometric speed ratio of its contact frame
and ``w_C`` the speed of its carrier (0 for a fixed-axis mesh); shafts and splines
``w_b = +-w_a``; held members ``w = 0``; every drive its speed.  The linear system must
be consistent (loops that can turn) and determined (a differential needs two input
speeds, or a held member).

Nominal torques.  One unknown per mesh (the torque tau on its first gear; the second
gets ``-tau / r``, from the power balance in the carrier frame), per elastic shaft or
spline, per held member (its reaction) and per balanced load; one torque equation per
rigid group about its axis.  A carrier receives, through its pins, minus the torques of
its planets' meshes on the gears that are not its planets (the moment balance of the
planets about the carrier axis).  Parallel paths (N planets, split paths) leave the
system statically indeterminate; the nominal split is the one with the least sum of
squared tooth forces, which is the equal split wherever the paths are alike (every
planet of a symmetric stage; the branches of a symmetric split), and exactly the
kinematic split of a differential (which is determinate).  Several balanced loads
take equal power.  Each mesh's driver is the gear that gives power to the mesh in the
carrier frame; where no power passes (an unloaded mesh) the flank is not determined
and a warning says so.

Only models with a planet or a held member use this path; the others keep the
equal-power-split flow of :mod:`torquesplit.model.kinematics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelWarning, warn_user
from .schema import Model

#: a body whose centre is farther than this from its bearing seat's axis orbits with it [m]
ORBIT_TOLERANCE = 1e-7


@dataclass(frozen=True)
class EpicyclicLayout:
    """Carriers and planets of a model (positions at t = 0)."""

    carriers: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """Carrier body -> its planets (bodies whose bearing sits on it, off its axis)."""
    planet_bodies: dict[str, str] = field(default_factory=dict)
    """Body of a planet's rigid group (a planet and the gears on its shaft) -> carrier."""
    mesh_carrier: dict[str, str | None] = field(default_factory=dict)
    """Mesh -> the carrier in whose frame it is analysed (None: the housing)."""
    held: tuple[str, ...] = ()
    """Bodies with a torsional support (nominal speed zero)."""

    @property
    def active(self) -> bool:
        return bool(self.carriers) or bool(self.held)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _off_axis(p, c, a) -> float:
    d = np.asarray(p, float) - np.asarray(c, float)
    return float(np.linalg.norm(d - a * float(d @ a)))


def find_layout(model: Model, positions, axes, groups, issues) -> EpicyclicLayout:
    """Carriers, planets and held members; appends (location, message) to ``issues``."""
    carriers: dict[str, list[str]] = {}
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        for name, spec in items.items():
            sup = spec.support
            if sup is None or sup.on is None or sup.on not in positions:
                continue
            c = sup.on
            ac = axes[c]
            if _off_axis(positions[name], positions[c], ac) <= ORBIT_TOLERANCE:
                if not sup.pin_error.is_zero:
                    issues.append((f"{kind}.{name}.support.pin_error", (
                        f"{name!r} sits on the axis of {c!r}, so its seat has no radial or "
                        f"tangential direction; remove 'pin_error' (or place {name!r} off "
                        f"{c!r}'s axis if it is a planet)")))
                continue
            if abs(abs(float(axes[name] @ ac)) - 1.0) > 1e-6:
                issues.append((f"{kind}.{name}.support.on", (
                    f"{name!r} orbits with {c!r} (its bearing sits on it off its axis) but "
                    f"its axis is not parallel to {c!r}'s; give both the same 'axis'")))
                continue
            carriers.setdefault(c, []).append(name)
    for c, planets in carriers.items():  # planets whose tips overlap cannot be assembled
        gears = [p for p in planets if p in model.gears]
        for i, p in enumerate(gears):
            for q in gears[i + 1:]:
                overlap = _tips_overlap(model, p, q, positions, axes[c])
                if overlap is not None:
                    issues.append((f"gears.{q}", (
                        f"planets {p!r} and {q!r} overlap: their centres are "
                        f"{overlap[0] * 1e3:.4f} mm apart, less than the sum of their tip "
                        f"radii {overlap[1] * 1e3:.4f} mm; place them farther apart (another "
                        f"angle), or in other planes")))
    planet_bodies: dict[str, str] = {}
    for c, planets in carriers.items():
        for p in planets:
            for b, rep in groups.items():
                if rep == groups[p]:
                    if planet_bodies.get(b, c) != c:
                        issues.append((f"gears.{b}", (
                            f"{b!r} is a planet of two carriers ({planet_bodies[b]!r} and "
                            f"{c!r}); a planet sits on one carrier")))
                    planet_bodies[b] = c
        if groups[c] in {groups[p] for p in planets}:
            issues.append((f"bodies.{c}", (
                f"the carrier {c!r} turns rigidly with its own planet; join the planet to "
                f"the carrier by its bearing only")))
    mesh_carrier: dict[str, str | None] = {}
    for name, m in model.meshes.items():
        a, b = m.gears
        ca, cb = planet_bodies.get(a), planet_bodies.get(b)
        if ca and cb and ca != cb:
            issues.append((f"meshes.{name}", (
                f"meshes planets of two carriers ({ca!r} and {cb!r}); a planet meshes with "
                f"the gears of its own stage")))
            continue
        c = ca or cb
        mesh_carrier[name] = c
        if c is None or (ca and cb):
            continue
        other = b if ca else a
        planet = a if ca else b
        ac = axes[c]
        coaxial = (abs(abs(float(axes[other] @ ac)) - 1.0) <= 1e-6
                   and _off_axis(positions[other], positions[c], ac) <= ORBIT_TOLERANCE)
        if not coaxial:
            issues.append((f"meshes.{name}", (
                f"gear {other!r} meshes with planet {planet!r} of carrier {c!r} but does not "
                f"turn about the carrier's axis; a gear meshing with a planet is a sun or "
                f"ring on that axis (place it there), or another planet on the same "
                f"carrier")))
            continue
        g_other, g_planet = model.gears[other], model.gears[planet]
        r_orbit = _off_axis(positions[planet], positions[c], ac)
        r_other = g_other.teeth * g_other.module / 2
        if g_other.gear_type != "internal" and r_other > r_orbit and \
                g_planet.gear_type != "internal" and \
                not any(loc == f"gears.{other}.kind" for loc, _ in issues):
            issues.append((f"gears.{other}.kind", (
                f"{other!r} meshes with planet {planet!r} around it (its pitch radius "
                f"{r_other * 1e3:.4g} mm exceeds the planet circle {r_orbit * 1e3:.4g} mm) "
                f"but is not an internal gear; a ring is internal: set kind = 'internal'")))
    held = []
    driven = {d.body for d in model.drives.values()} | {ld.body for ld in model.loads.values()}
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        for name, spec in items.items():
            if spec.torsional_support is None:
                continue
            held.append(name)
            for other in driven:
                if groups[other] == groups[name]:
                    issues.append((f"{kind}.{name}.torsional_support", (
                        f"holds {name!r} at zero speed, but {other!r}, which turns with it, "
                        f"is driven or loaded; remove the torsional support or the "
                        f"drive/load")))
            if name in planet_bodies:
                issues.append((f"{kind}.{name}.torsional_support", (
                    "a planet cannot be held against rotation on its pin; remove it")))
    return EpicyclicLayout(carriers={c: tuple(p) for c, p in carriers.items()},
                           planet_bodies=planet_bodies, mesh_carrier=mesh_carrier,
                           held=tuple(held))


def _tips_overlap(model, p, q, positions, axis):
    """(centre distance, sum of tip radii) of two planets in overlapping planes whose tip
    circles intersect, else None."""
    from ..gears import line_of_action as loa
    from ..errors import ModelError

    try:
        rp = loa.gear_geometry(model.gears[p]).tip_radius
        rq = loa.gear_geometry(model.gears[q]).tip_radius
    except (ModelError, ValueError):  # reported by the geometry checks
        return None
    d = np.asarray(positions[q], float) - np.asarray(positions[p], float)
    axial = abs(float(d @ axis))
    width = 0.5 * (model.gears[p].face_width + model.gears[q].face_width)
    radial = float(np.linalg.norm(d - axis * float(d @ axis)))
    if axial < width and radial < rp + rq:
        return radial, rp + rq
    return None


# --------------------------------------------------------------------------- speeds
def _reps(groups) -> list[str]:
    out = []
    for rep in groups.values():
        if rep not in out:
            out.append(rep)
    return out


def _sign(axes, body, rep) -> float:
    return 1.0 if float(axes[body] @ axes[rep]) > 0 else -1.0


def elastic_shaft_hint(model: Model, planet_bodies, gears, most: int) -> str:
    """The errors' note on each of ``gears`` (at most ``most``) that an elastic shaft joins
    to a planet: it is no planet gear, so it turns about a fixed axis (only a rigid shaft
    makes a compound planet); '' if none."""
    found = []
    for sname, sh in model.shafts.items():
        a, b = sh.connects
        for g, p in ((a, b), (b, a)):
            if not sh.rigid and g in gears and g not in planet_bodies and p in planet_bodies:
                found.append(f"; {g!r} is joined to the planet {p!r} by the elastic shaft "
                             f"{sname!r}, so it turns about a fixed axis: make the shaft "
                             f"rigid (rigid = true) for a compound planet")
                break
    return "".join(found[:most])


def solve_speeds(model: Model, axes, frames, groups, layout: EpicyclicLayout,
                 issues) -> dict[str, float]:
    """Signed speed of every body about its own axis [rad/s] (see module docstring)."""
    reps = _reps(groups)
    col = {r: j for j, r in enumerate(reps)}
    rows, rhs, where = [], [], []

    def row():
        return np.zeros(len(reps))

    for b, rep in groups.items():
        if rep != b and abs(abs(float(axes[b] @ axes[rep])) - 1.0) > 1e-6:
            issues.append((f"{'gears' if b in model.gears else 'bodies'}.{b}.axis", (
                f"turns rigidly with {rep!r} but its axis is not parallel to {rep!r}'s; give "
                f"both the same 'axis'")))
    for name, m in model.meshes.items():
        a, b = m.gears
        r = frames[name].speed_ratio  # omega_b,rel = r omega_a,rel
        v = row()
        v[col[groups[b]]] += _sign(axes, b, groups[b])
        v[col[groups[a]]] -= r * _sign(axes, a, groups[a])
        c = layout.mesh_carrier.get(name)
        if c is not None:
            # relative speeds: w - (a_gear . a_C) w_C
            v[col[groups[c]]] += (-float(axes[b] @ axes[c]) + r * float(axes[a] @ axes[c])) \
                * _sign(axes, c, groups[c])
        rows.append(v)
        rhs.append(0.0)
        where.append(f"meshes.{name}")
    for kind, items in (("shafts", model.shafts), ("splines", model.splines)):
        for name, s in items.items():
            a, b = s.connects
            dot = float(axes[a] @ axes[b])
            if abs(abs(dot) - 1) > 1e-6:
                issues.append((f"{kind}.{name}", f"joins {a!r} and {b!r} whose axes are not "
                               f"parallel; give both bodies the same 'axis'"))
                continue
            if groups[a] == groups[b]:
                continue
            v = row()
            v[col[groups[b]]] += _sign(axes, b, groups[b])
            v[col[groups[a]]] -= (1.0 if dot > 0 else -1.0) * _sign(axes, a, groups[a])
            rows.append(v)
            rhs.append(0.0)
            where.append(f"{kind}.{name}")
    for h in layout.held:
        v = row()
        v[col[groups[h]]] = 1.0
        rows.append(v)
        rhs.append(0.0)
        kind = "gears" if h in model.gears else "bodies"
        where.append(f"{kind}.{h}.torsional_support")
    for name, d in model.drives.items():
        v = row()
        v[col[groups[d.body]]] = _sign(axes, d.body, groups[d.body])
        rows.append(v)
        rhs.append(d.speed)
        where.append(f"drives.{name}.speed")
    if issues:
        return {}
    A = np.array(rows)
    y = np.array(rhs)
    scale = max(float(np.max(np.abs(y))), 1e-300)
    w, *_ = np.linalg.lstsq(A, y, rcond=None)
    sv = np.linalg.svd(A, compute_uv=False)
    rank = int(np.sum(sv > 1e-10 * sv[0])) if sv.size else 0
    resid = A @ w - y
    if np.max(np.abs(resid)) > 1e-9 * scale:
        k = int(np.argmax(np.abs(resid)))
        # gears between a ring and another gear that turn about fixed axes: star gears,
        # or planets whose bearings were meant to sit on a carrier
        ring_mates = {g for m in model.meshes.values() for g in m.gears
                      if any(model.gears[o].gear_type == "internal" for o in m.gears if o != g)}
        fixed = [g for g in ring_mates if g not in layout.planet_bodies
                 and model.gears[g].gear_type != "internal"
                 and sum(g in m.gears for m in model.meshes.values()) >= 2]
        hint = (f"; {', '.join(repr(g) for g in sorted(fixed)[:3])} "
                f"{'turn' if len(fixed) > 1 else 'turns'} about a fixed axis between a ring "
                f"and another gear (a star gear): if a planet, seat its bearing on the "
                f"carrier (support.on)" if fixed else "")
        # a ring's mate joined to a planet by an elastic shaft turns about a fixed axis
        # too: only a rigid shaft makes it a compound planet's gear
        hint += elastic_shaft_hint(model, layout.planet_bodies, ring_mates, 3)
        issues.append((where[k], (
            "the gears could not turn: the speeds the meshes, shafts, held members and "
            "drives impose contradict each other around a loop through here (a power-split "
            "loop needs the same ratio on every path, a differential at most as many given "
            "speeds as it has inputs); check tooth counts, axis directions, which members "
            "are held (torsional_support) and the drive speeds" + hint)))
        return {}
    if rank < len(reps):
        _, _, vt = np.linalg.svd(A)
        free = vt[-1]
        # the central members first: planets spin fastest in such a motion, but it is a
        # ring or carrier that nothing holds
        planets = {g for g, gear in model.gears.items()
                   if gear.support is not None and gear.support.on}
        turning = [j for j in np.argsort(-np.abs(free)) if abs(free[j]) > 1e-6]
        central = [reps[j] for j in turning if reps[j] not in planets]
        moving = (central or [reps[j] for j in turning])[:4]
        with_planets = " (with the planets)" if central and len(central) < len(turning) else ""
        issues.append(("drives", (
            f"the speeds are not determined: {', '.join(map(repr, moving))}{with_planets} "
            f"can turn freely against the rest (a differential with one input); hold a member with "
            f"torsional_support (e.g. the ring of a planetary, the carrier of a star stage) "
            f"or give a second drive")))
        return {}
    # held members stand exactly still; round-off of the solve is cleared
    w[np.abs(w) <= 1e-12 * max(float(np.max(np.abs(w))), 1e-300)] = 0.0
    for h in layout.held:
        w[col[groups[h]]] = 0.0
    return {b: _sign(axes, b, groups[b]) * float(w[col[groups[b]]]) for b in groups}


def relative_speed(body: str, carrier: str | None, speeds, axes) -> float:
    """Speed of ``body`` about its axis relative to ``carrier``'s frame [rad/s]."""
    if carrier is None:
        return speeds[body]
    return speeds[body] - float(axes[body] @ axes[carrier]) * speeds[carrier]


# --------------------------------------------------------------------------- torques
@dataclass
class NominalTorques:
    """The nominal static torques of an epicyclic model."""

    mesh_torque: dict[str, float]
    """Mesh -> torque on its first gear about that gear's axis [N m]."""
    mesh_torque_second: dict[str, float]
    """Mesh -> torque on its second gear [N m]."""
    drivers: dict[str, tuple[str, str]]
    mesh_power: dict[str, float]
    """Power through each mesh in its carrier's frame [W]."""
    body_torque: dict[str, float]
    """Torque carried through each body (half the sum of the magnitudes acting on it)."""
    drive_torques: dict[str, float]
    load_torques: dict[str, float]
    reactions: dict[str, float]
    """Held body -> reaction torque of its support about its axis [N m]."""


def _written_mesh(model: Model, mesh: str) -> tuple[str, str | None]:
    """Where mesh ``mesh`` is written (``planetary.0.sun_mesh`` for a [[planetary]]
    stage's), and the stage member its table is named after ('sun' or 'ring'; None for a
    mesh of its own)."""
    where = model.written_at(f"meshes.{mesh}")
    member = where.rpartition(".")[2].removesuffix("_mesh")
    return where, (member if where.startswith("planetary.") and member in ("sun", "ring")
                   else None)


def solve_torques(model: Model, axes, frames, groups, speeds, layout: EpicyclicLayout,
                  issues) -> NominalTorques | None:
    """Nominal torques, mesh drivers and mesh powers (see the module docstring)."""
    reps = _reps(groups)
    col = {r: j for j, r in enumerate(reps)}
    meshes = list(model.meshes)
    elastic = [(f"shafts.{n}", s) for n, s in model.shafts.items() if not s.rigid]
    elastic += [(f"splines.{n}", s) for n, s in model.splines.items()]
    elastic = [(n, s) for n, s in elastic if groups[s.connects[0]] != groups[s.connects[1]]]
    held_reps = []
    for h in layout.held:
        if groups[h] not in held_reps:
            held_reps.append(groups[h])
    balanced = [n for n, ld in model.loads.items() if ld.torque is None]
    n_x = len(meshes) + len(elastic) + len(held_reps) + len(balanced)
    A = np.zeros((len(reps), n_x))
    b = np.zeros(len(reps))
    ratio = {n: frames[n].speed_ratio for n in meshes}

    # the same sums per body (about its own axis): what a rigid shaft passes on
    bodies = list(groups)
    body_row = {name: i for i, name in enumerate(bodies)}
    A_body = np.zeros((len(bodies), n_x))
    b_body = np.zeros(len(bodies))

    def add(body, j, coef):  # coef: torque on `body` about its own axis per unit x_j
        A[col[groups[body]], j] += coef * _sign(axes, body, groups[body])
        A_body[body_row[body], j] += coef

    def known(body, torque):
        b[col[groups[body]]] -= torque * _sign(axes, body, groups[body])
        b_body[body_row[body]] -= torque

    for j, name in enumerate(meshes):
        ga, gb = model.meshes[name].gears
        add(ga, j, 1.0)
        add(gb, j, -1.0 / ratio[name])
        c = layout.mesh_carrier.get(name)
        if c is not None:
            pa, pb = ga in layout.planet_bodies, gb in layout.planet_bodies
            if pa != pb:  # planet - central gear: the pins take minus its moment
                central, coef = (gb, -1.0 / ratio[name]) if pa else (ga, 1.0)
                add(c, j, -coef * float(axes[central] @ axes[c]))
    off = len(meshes)
    for k, (name, s) in enumerate(elastic):
        a, bb = s.connects
        r = 1.0 if float(axes[a] @ axes[bb]) > 0 else -1.0
        add(a, off + k, 1.0)
        add(bb, off + k, -r)
    off += len(elastic)
    for k, rep in enumerate(held_reps):
        A[col[rep], off + k] += 1.0
    off += len(held_reps)
    from .kinematics import drive_input_torques

    drive_torques, load_torques = {}, {}
    given = drive_input_torques(model, speeds, issues)
    if issues:
        return None
    for name, d in model.drives.items():
        t = given[name]
        drive_torques[name] = t
        known(d.body, math.copysign(t, d.speed))
    for name, ld in model.loads.items():
        w = speeds[ld.body]
        if abs(w) < 1e-9:
            issues.append((f"loads.{name}.body", (
                f"{ld.body!r} does not turn (it is held or locked by the gears), so it takes "
                f"no power; load a member that turns")))
            continue
        if ld.torque is not None:
            load_torques[name] = ld.torque
            known(ld.body, -math.copysign(ld.torque, w))
    for k, name in enumerate(balanced):
        body = model.loads[name].body
        w = speeds[body]
        if abs(w) < 1e-9:
            continue
        add(body, off + k, -math.copysign(1.0, w))
    if issues:
        return None
    # several balanced loads take equal power: L_i |w_i| = L_0 |w_0|
    extra = []
    for k in range(1, len(balanced)):
        row = np.zeros(n_x)
        row[off] = abs(speeds[model.loads[balanced[0]].body])
        row[off + k] = -abs(speeds[model.loads[balanced[k]].body])
        extra.append(row)
    if extra:
        A = np.vstack([A, np.array(extra)])
        b = np.concatenate([b, np.zeros(len(extra))])
    # least squared tooth forces (torque / pitch radius) subject to equilibrium
    radii = [frames[n].pitch_radii[0] for n in meshes]
    r_ref = float(np.median(radii)) if radii else 1.0
    wts = np.full(n_x, 1e-9 / r_ref**2)
    wts[:len(meshes)] = 1.0 / np.asarray(radii) ** 2
    wts[len(meshes):len(meshes) + len(elastic)] = 1.0 / r_ref**2
    m_rows = A.shape[0]
    K = np.zeros((n_x + m_rows, n_x + m_rows))
    K[:n_x, :n_x] = np.diag(wts)
    K[:n_x, n_x:] = A.T
    K[n_x:, :n_x] = A
    rhs = np.concatenate([np.zeros(n_x), b])
    sol, *_ = np.linalg.lstsq(K, rhs, rcond=None)
    x = sol[:n_x]
    scale = max(float(np.max(np.abs(b))), 1e-300)
    resid = A @ x - b
    if np.max(np.abs(resid)) > 1e-8 * scale:
        issues.append(("loads", (
            "the drive and load torques cannot all be in equilibrium with the gear ratios "
            "(a differential fixes the ratio of its input torques, a held member takes the "
            "reaction); set a load's torque to \"balanced\" or correct the torques")))
        return None
    tau = {n: float(x[j]) for j, n in enumerate(meshes)}
    tau2 = {n: -tau[n] / ratio[n] for n in meshes}
    for k, name in enumerate(balanced):
        load_torques[name] = float(x[off + k])
    reactions = {}
    for k, rep in enumerate(held_reps):
        for h in layout.held:
            if groups[h] == rep:
                reactions[h] = float(x[len(meshes) + len(elastic) + k]) * _sign(axes, h, rep)
    # drivers from the power each mesh takes from its first gear, in its carrier's frame
    power_first = {}
    for n in meshes:
        ga = model.meshes[n].gears[0]
        c = layout.mesh_carrier.get(n)
        power_first[n] = tau[n] * relative_speed(ga, c, speeds, axes)
    p_scale = max([abs(p) for p in power_first.values()] + [1e-300])
    drivers = {}
    for n in meshes:
        m = model.meshes[n]
        ga, gb = m.gears
        p = power_first[n]
        if abs(p) <= 1e-9 * p_scale:
            drv = m.driver or ga
            if m.driver is None:
                where, member = _written_mesh(model, n)
                how = f"give driver = '{member}' or 'planet' there" if member else \
                    "give 'driver'"
                warn_user(
                    f"{where}: no power passes this mesh in the nominal load, so its "
                    f"loaded flank is not determined; {ga!r} (listed first) is taken as "
                    f"the driver: {how} to choose the flank", ModelWarning)
        else:
            drv = ga if p < 0 else gb  # negative: the mesh takes power from the first gear
            if m.driver is not None and m.driver != drv:
                _, member = _written_mesh(model, n)
                if member:
                    # (one text for every planet's mesh of the stage: said once)
                    given = member if m.driver == ga else "planet"
                    issues.append((f"meshes.{n}.driver", (
                        f"{given!r} is given as driver but power flows from the "
                        f"{'planets' if given == member else member} to the "
                        f"{given if given == member else 'planets'}; remove 'driver' or "
                        f"correct it")))
                else:
                    issues.append((f"meshes.{n}.driver", (
                        f"{m.driver!r} is given as driver but power flows from {drv!r} to "
                        f"it; remove 'driver' or correct it")))
        drivers[n] = (drv, gb if drv == ga else ga)
    body_torque = {bname: 0.0 for bname in groups}
    for n in meshes:
        ga, gb = model.meshes[n].gears
        body_torque[ga] += abs(tau[n])
        body_torque[gb] += abs(tau2[n])
        c = layout.mesh_carrier.get(n)
        if c is not None and (ga in layout.planet_bodies) != (gb in layout.planet_bodies):
            body_torque[c] += abs(tau2[n] if ga in layout.planet_bodies else tau[n])
    for k, (name, s) in enumerate(elastic):
        t = abs(float(x[len(meshes) + k]))
        body_torque[s.connects[0]] += t
        body_torque[s.connects[1]] += t
    for name, d in model.drives.items():
        body_torque[d.body] += drive_torques[name]
    for name, ld in model.loads.items():
        body_torque[ld.body] += abs(load_torques.get(name, 0.0))
    for h, r in reactions.items():
        body_torque[h] += abs(r)
    # a body on a rigid shaft (a compound planet's gear) passes the rest of its torques
    # on through the shaft: that torque balances them (exact for a body with one rigid
    # shaft), a held member's reaction among them
    net = A_body @ x - b_body
    for h, r in reactions.items():
        net[body_row[h]] += r
    size = {}
    for name in bodies:
        size[groups[name]] = size.get(groups[name], 0) + 1
    for name in bodies:
        if size[groups[name]] > 1:
            body_torque[name] += abs(float(net[body_row[name]]))
    body_torque = {k: 0.5 * v for k, v in body_torque.items()}
    return NominalTorques(mesh_torque=tau, mesh_torque_second=tau2, drivers=drivers,
                          mesh_power={n: abs(p) for n, p in power_first.items()},
                          body_torque=body_torque, drive_torques=drive_torques,
                          load_torques={k: abs(v) for k, v in load_torques.items()},
                          reactions=reactions)


def translation_frames(model: Model, layout: EpicyclicLayout, positions, axes, speeds,
                       issues) -> dict[str, str]:
    """Body -> carrier in whose (rotating) frame its translations are measured.

    A carrier's frame holds the carrier, its planets and every body coupled to them by a
    mesh, a spline or a bearing that turns about the carrier's axis (sun, ring, a
    floating member); their translations couple through elements fixed in that frame.
    A body with translations coupled to two frames turning at different speeds cannot
    be expressed in either: refused (unless the carrier stands still).
    """
    frames: dict[str, str] = {}
    links: dict[str, set[str]] = {b: set() for b in model.body_names()}

    def translates(b):
        spec = model.gears.get(b) or model.bodies[b]
        return any(d != "theta" for d in spec.dofs)

    for m in model.meshes.values():
        a, b = m.gears
        links[a].add(b)
        links[b].add(a)
    for sp in model.splines.values():
        a, b = sp.connects
        links[a].add(b)
        links[b].add(a)
    for b in model.body_names():
        spec = model.gears.get(b) or model.bodies[b]
        if spec.support is not None and spec.support.on in links:
            links[b].add(spec.support.on)
            links[spec.support.on].add(b)
    for c in layout.carriers:
        ac = axes[c]
        members = {c} | {b for b, cc in layout.planet_bodies.items() if cc == c}
        stack = list(members)
        while stack:
            cur = stack.pop()
            for nb in links[cur]:
                if nb in members or not translates(nb):
                    continue
                coaxial = (abs(abs(float(axes[nb] @ ac)) - 1) <= 1e-6
                           and _off_axis(positions[nb], positions[c], ac) <= ORBIT_TOLERANCE)
                if not coaxial:
                    if abs(speeds.get(c, 0.0)) > 0 and translates(cur):
                        kind = "gears" if nb in model.gears else "bodies"
                        issues.append((f"{kind}.{nb}.dofs", (
                            f"the translations of {nb!r} are coupled to {cur!r}, whose "
                            f"translations are measured in the frame of the turning carrier "
                            f"{c!r}, but {nb!r} does not turn about the carrier's axis; "
                            f"remove 'x'/'y' from one of them (or hold the carrier)")))
                    continue
                members.add(nb)
                stack.append(nb)
        for b in members:
            if b in frames and frames[b] != c and (abs(speeds.get(c, 0.0)) > 0
                                                   or abs(speeds.get(frames[b], 0.0)) > 0):
                kind = "gears" if b in model.gears else "bodies"
                issues.append((f"{kind}.{b}.dofs", (
                    f"the translations of {b!r} are coupled to the frames of carriers "
                    f"{frames[b]!r} and {c!r}; remove 'x'/'y' from {b!r}")))
            frames[b] = c
    return {b: frames[b] for b in model.body_names() if b in frames}  # the model's order
