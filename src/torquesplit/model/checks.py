"""Checks a validated schema cannot express: references, topology, physics consistency.

Errors are collected (all of them, not only the first) and raised as one
:class:`~torquesplit.errors.ModelError`.  Values that look wrong but can be right are
reported as :class:`~torquesplit.errors.ModelWarning`.
"""

from __future__ import annotations

import math
import re
import warnings

from ..errors import ModelError, ModelWarning
from .schema import Model


def check_model(model: Model, source: str | None = None) -> None:
    """Raise ModelError listing every problem found; warn on suspicious values."""
    issues = reference_issues(model)
    if not issues:
        issues = topology_issues(model)
    if not issues:
        issues = mesh_compatibility_issues(model)
    if not issues:
        issues = geometry_issues(model) + support_issues(model) + modification_issues(model)
    if issues:
        raise ModelError(issues, source)
    # the kinematic pass finds loops that cannot turn and power that does not balance
    from .kinematics import KinematicsError, solve_kinematics

    try:
        kin = solve_kinematics(model)
    except KinematicsError as exc:
        raise ModelError(exc.issues, source) from None
    for loc, msg in plausibility_warnings(model, kin):
        warnings.warn(f"{source + ': ' if source else ''}{loc}: {msg}", ModelWarning, stacklevel=3)


def reference_issues(model: Model) -> list[tuple[str, str]]:
    """Names that refer to bodies which do not exist, duplicated names."""
    issues = []
    bodies = set(model.body_names())
    for name in set(model.gears) & set(model.bodies):
        issues.append((f"bodies.{name}", f"name {name!r} is used by a gear too; rename one"))

    def need(loc, name):
        if name not in bodies:
            issues.append((loc, f"body {name!r} does not exist; {_one_of(bodies, 'bodies')}"))

    mates: dict[str, set[str]] = {}
    for m in model.meshes.values():
        mates.setdefault(m.gears[0], set()).add(m.gears[1])
        mates.setdefault(m.gears[1], set()).add(m.gears[0])
    for name, g in model.gears.items():
        if g.place is not None:
            ref, loc = g.place.from_gear, f"gears.{name}.place.from_gear"
            if ref not in model.gears:
                issues.append((loc, f"gear {ref!r} does not exist; {_one_of(model.gears, 'gears')}"))
            elif ref not in mates.get(name, set()):
                issues.append((loc, f"{name!r} is placed from {ref!r} but does not mesh with it; "
                               f"name a gear it meshes with: {sorted(mates.get(name, set()))}, "
                               f"or give 'position' instead"))
    for name, s in model.shafts.items():
        for b in s.connects:
            need(f"shafts.{name}.connects", b)
        if s.connects[0] == s.connects[1]:
            issues.append((f"shafts.{name}.connects", "a shaft must join two different "
                           "bodies; name two different bodies in 'connects'"))
    for name, s in model.splines.items():
        for b in s.connects:
            need(f"splines.{name}.connects", b)
    for name, m in model.meshes.items():
        for g in m.gears:
            if g not in model.gears:
                issues.append((f"meshes.{name}.gears",
                               f"gear {g!r} does not exist; {_one_of(model.gears, 'gears')}"))
    for name, d in model.drives.items():
        need(f"drives.{name}.body", d.body)
    for name, ld in model.loads.items():
        need(f"loads.{name}.body", ld.body)
    if not model.drives:
        issues.append(("drives", "the model has no drive; add a [drives.NAME] section"))
    if not model.loads:
        issues.append(("loads", "the model has no load; add a [loads.NAME] section"))
    return issues


def _one_of(names, what: str) -> str:
    """'use one of the gears [...]', or 'add a [gears.NAME] section first' if there is none."""
    if names:
        return f"use one of the {what} {sorted(names)}"
    sections = "[gears.NAME] or [bodies.NAME]" if what == "bodies" else f"[{what}.NAME]"
    return f"add a {sections} section first"


def topology_issues(model: Model) -> list[tuple[str, str]]:
    """Every body must be connected to the drive train; a drive and a load per train."""
    issues = []
    names = model.body_names()
    adj: dict[str, set[str]] = {n: set() for n in names}
    for m in model.meshes.values():
        a, b = m.gears
        adj[a].add(b)
        adj[b].add(a)
    for s in list(model.shafts.values()) + list(model.splines.values()):
        a, b = s.connects
        adj[a].add(b)
        adj[b].add(a)
    for n in names:
        if not adj[n]:
            kind = "gears" if n in model.gears else "bodies"
            issues.append((f"{kind}.{n}", "this body is connected to nothing; add a mesh or a "
                           "shaft that joins it to the gearbox, or delete it"))
    if issues:
        return issues
    # connected components: each needs a drive and a load
    seen: set[str] = set()
    for start in names:
        if start in seen:
            continue
        comp = {start}
        stack = [start]
        while stack:
            for nb in adj[stack.pop()]:
                if nb not in comp:
                    comp.add(nb)
                    stack.append(nb)
        seen |= comp
        has_drive = any(d.body in comp for d in model.drives.values())
        has_load = any(ld.body in comp for ld in model.loads.values())
        if len(comp) < len(names) or not (has_drive and has_load):
            if not has_drive or not has_load:
                missing = "drive" if not has_drive else "load"
                issues.append(("", f"bodies {sorted(comp)} form a separate gear train without a "
                               f"{missing}; connect them to the rest or add a {missing}"))
    return issues


def mesh_compatibility_issues(model: Model) -> list[tuple[str, str]]:
    """Meshing gears must share module, pressure angle and (opposite) helix."""
    issues = []
    for name, m in model.meshes.items():
        a, b = (model.gears[g] for g in m.gears)
        loc = f"meshes.{name}"
        if not math.isclose(a.module, b.module, rel_tol=1e-6):
            issues.append((loc, f"gears {m.gears[0]!r} and {m.gears[1]!r} cannot mesh: modules "
                           f"{a.module * 1e3:g} mm and {b.module * 1e3:g} mm differ; "
                           f"make them equal"))
        if not math.isclose(a.pressure_angle, b.pressure_angle, rel_tol=1e-6):
            issues.append((loc, f"gears {m.gears[0]!r} and {m.gears[1]!r} cannot mesh: pressure "
                           f"angles {math.degrees(a.pressure_angle):g} deg and "
                           f"{math.degrees(b.pressure_angle):g} deg differ; make them equal"))
        conical = {a.gear_type, b.gear_type} & {"bevel", "face"}
        if not conical and not math.isclose(abs(a.helix_angle), abs(b.helix_angle), rel_tol=1e-6,
                                            abs_tol=1e-9):
            issues.append((loc, f"gears {m.gears[0]!r} and {m.gears[1]!r} cannot mesh: helix "
                           f"angles {math.degrees(a.helix_angle):g} deg and "
                           f"{math.degrees(b.helix_angle):g} deg differ in size; make them equal"))
        internal = [a.gear_type == "internal", b.gear_type == "internal"]
        if all(internal):
            issues.append((loc, "two internal gears cannot mesh; make one of them external"))
        elif (not conical and a.helix_angle != 0 and a.hand is not None and b.hand is not None
              and not any(internal) and a.hand == b.hand
              and "double_helical" not in (a.gear_type, b.gear_type)):
            issues.append((loc, f"external helical gears {m.gears[0]!r} and {m.gears[1]!r} are both "
                           f"{a.hand}-handed; meshing external helical gears need opposite hands: "
                           f"change the 'hand' of one of them"))
    return issues


#: GearGeometry argument -> schema field of a gear
_GEOMETRY_FIELDS = {
    "teeth": "teeth", "normal_module": "module", "normal_pressure_angle": "pressure_angle",
    "helix_angle": "helix_angle", "face_width": "face_width", "addendum": "profile_shift",
    "double_helical": "kind", "internal": "kind",
}


def geometry_issues(model: Model) -> list[tuple[str, str]]:
    """What the involute geometry refuses (too few teeth, interference...), by field.

    Runs the geometry of :mod:`torquesplit.gears.geometry` on every gear and every
    cylindrical pair before the kinematics, so that its errors name the model's fields.
    """
    from ..gears.line_of_action import cylindrical_pair, is_conical
    from .kinematics import gear_geometry

    issues = []
    good = set()
    for name, gear in model.gears.items():
        try:
            gear_geometry(gear)
            good.add(name)
        except ModelError as exc:
            for loc, msg in exc.issues:
                field = _GEOMETRY_FIELDS.get(loc.split(".")[-1])
                issues.append((f"gears.{name}" + (f".{field}" if field else ""), _teach(msg)))
    for name, mesh in model.meshes.items():
        a, b = mesh.gears
        ga, gb = model.gears[a], model.gears[b]
        if not {a, b} <= good or is_conical(ga, gb):
            continue
        # the pair's messages say pinion (gear1) and wheel (gear2); an internal gear is
        # put second: name the gears instead
        role = {"pinion": b, "wheel": a} if ga.gear_type == "internal" else {"pinion": a, "wheel": b}
        try:
            cylindrical_pair(ga, gb).operating_center_distance  # noqa: B018 - validates
        except ModelError as exc:
            for _, msg in exc.issues:
                msg = re.sub(r"\b(pinion|wheel)\b", lambda m: role[m.group()], msg)
                issues.append((f"meshes.{name}", f"gears {a!r} and {b!r}: {_teach(msg)}"))
    return issues


def modification_issues(model: Model) -> list[tuple[str, str]]:
    """Tooth modifications that do not fit the active profile of a mating pair (a relief
    longer than the active profile, tip and root relief overlapping, an end relief longer
    than half the face), and the LTCA asked of a bevel or face mesh, named by field."""
    from ..gears.contact.modifications import check_modification, modification_from_spec
    from ..gears.line_of_action import cylindrical_pair, is_conical

    issues: list[tuple[str, str]] = []
    for name, mesh in model.meshes.items():
        a, b = mesh.gears
        ga, gb = model.gears[a], model.gears[b]
        if mesh.stiffness.method == "ltca" and is_conical(ga, gb):
            issues.append((f"meshes.{name}.stiffness.method", (
                "the LTCA is implemented for cylindrical pairs (spur, helical, double-helical, "
                "internal); use a table or a constant for this bevel/face mesh")))
        if (ga.modifications is None and gb.modifications is None) or is_conical(ga, gb):
            continue
        try:
            pair = cylindrical_pair(ga, gb)
        except ModelError:
            continue  # reported by geometry_issues
        order = (b, a) if ga.gear_type == "internal" else (a, b)
        for index, g in enumerate(order, start=1):
            spec = model.gears[g].modifications
            if spec is None:
                continue
            where = f"gears.{g}.modifications"
            try:
                check_modification(modification_from_spec(spec, pair.face_width, where), pair,
                                   index, where)
            except ModelError as exc:
                issues += [i for i in exc.issues if i not in issues]
    return issues


def _teach(msg: str) -> str:
    """A geometry message, ending with what to do if it does not already."""
    return msg if ";" in msg else f"{msg}; correct the value"


def support_issues(model: Model) -> list[tuple[str, str]]:
    """Translational DOFs need a support to the housing (bearing or shaft bending), or a
    spline that holds the body radially (seed 002 floating pinion)."""
    issues = []
    on_spline = {b for sp in model.splines.values() for b in sp.connects}
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        for name, body in items.items():
            free = [d for d in body.dofs if d != "theta"]
            if free and body.support is None and name not in on_spline:
                issues.append((f"{kind}.{name}.support", (
                    f"the translational DOFs {free} have no support; add one, e.g. "
                    f"support = {{stiffness = '1e8 N/m'}}, or remove them from 'dofs'")))
    return issues


def plausibility_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Values that can be right but usually are not."""
    out = []
    ratios = [(f"shafts.{n}.damping_ratio", s.damping_ratio) for n, s in model.shafts.items()]
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        ratios += [(f"{kind}.{n}.support.damping_ratio", b.support.damping_ratio)
                   for n, b in items.items() if b.support is not None]
    ratios += [(f"meshes.{n}.damping_ratio", m.damping_ratio) for n, m in model.meshes.items()]
    for loc, ratio in ratios:
        if ratio is not None and ratio > 1:
            out.append((loc, f"{ratio:g} is above critical damping (1); check the value "
                             f"(typical 0.02-0.1)"))
    ltca_gears = {g for m in model.meshes.values() if m.stiffness.method == "ltca" for g in m.gears}
    for name, gear in model.gears.items():
        if gear.modifications is not None and name not in ltca_gears:
            out.append((f"gears.{name}.modifications",
                        "only the stiffness method 'ltca' uses tooth modifications and no mesh of "
                        "this gear uses it; set stiffness.method = 'ltca' on its meshes or remove "
                        "the modifications"))
    for name, m in model.meshes.items():
        if m.stiffness.method != "ltca" and m.misalignment != type(m.misalignment)():
            out.append((f"meshes.{name}.misalignment",
                        "only the stiffness method 'ltca' uses the misalignment; set "
                        "stiffness.method = 'ltca' or remove it"))
    for name, mk in kin.meshes.items():
        m = model.meshes[name]
        if m.damping is not None and mk.critical_damping > 0 and m.damping > mk.critical_damping:
            out.append((f"meshes.{name}.damping",
                        f"{m.damping:g} N s/m is {m.damping / mk.critical_damping:.1f} times "
                        f"critical for this mesh; check the value (typical mesh damping ratios "
                        f"are 0.02-0.1)"))
        iso = mk.iso_stiffness
        spec = m.stiffness
        if spec.method == "constant" and iso and not (0.2 < spec.value / iso < 5):
            out.append((f"meshes.{name}.stiffness",
                        f"{spec.value:.3g} N/m is {spec.value / iso:.2g} times the ISO 6336 "
                        f"estimate c_gamma*b = {iso:.3g} N/m; check the value and its unit"))
    return out
