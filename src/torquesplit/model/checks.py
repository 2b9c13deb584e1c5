"""Checks a validated schema cannot express: references, topology, physics consistency.

Errors are collected (all of them, not only the first) and raised as one
:class:`~torquesplit.errors.ModelError`: the names first (every other check needs them to
resolve), then everything that needs only the names at once, then the checks that need
the kinematics (speeds, positions).  Values that look wrong but can be right are
reported as :class:`~torquesplit.errors.ModelWarning`.  Both name the field as the user
wrote it: what a ``[[planetary]]`` stage generated is named by the stage's field
(:func:`as_written`: ``planetary.0.pin_errors.1``, not ``gears.st_planet2.support...``).

``torquesplit check`` and ``torquesplit run`` share these checks, so that a model that
passes ``check`` is never refused by ``run`` for a modelling reason:

==============================  ========================================================
check                           what it refuses
==============================  ========================================================
:func:`reference_issues`        names of bodies, gears that do not exist
:func:`topology_issues`         bodies connected to nothing, trains without drive/load
:func:`mesh_compatibility_...`  modules, pressure angles, helices that cannot mesh
:func:`geometry_issues`         involute geometry (interference, centre distance)
kinematics                      loops that cannot turn, power that does not balance,
                                carriers and planets (model/epicyclic.py)
:func:`shaft_axis_issues`       shafts joining bodies that are not on a common axis
:func:`overlap_issues`          gears that do not mesh but occupy the same space
:func:`face_overlap_issues`     meshing gears whose faces do not overlap along the axis
:func:`nominal_load_issues`     meshes that carry no load (no power passes them)
:func:`balance_issues`          torques out of balance by more than
                                :data:`BALANCE_TOLERANCE` (what the static solution of
                                every run refuses)
:func:`stiffness_table_issues`  mesh stiffness tables that are not positive everywhere
:func:`planet_fit_issues`       planets whose teeth cannot mesh with sun and ring at
                                their angles (the tooth-count assembly condition)
:func:`readiness_issues`        (``deep``) the stages every run performs before it
                                integrates: assembly and the static equilibrium
==============================  ========================================================

:func:`rim_overlap_warnings` warns of a gear in the rim an internal gear is assumed to
have (no ``rim_thickness`` or ``outer_diameter`` in the file).
:func:`plausibility_warnings` flag magnitudes that are possible but usually a wrong
unit: lengths against the size of the gears, inertias and masses against the gear's
geometry, stiffness against ISO 6336, speeds and tooth loads against what gears carry;
:func:`tolerance_warnings` errors, clearances and backlash against the ISO 1328-1
tolerances of the gear (the coarsest grade, 11, and the grade the file states) and the
backlash range of ISO/TR 10064-2.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import ModelError, ModelWarning, SolverError, warn_user
from .schema import Model

#: largest net power along the train's rigid rotation, as a fraction of the input plus
#: output power, that counts as round-off; the static equilibrium of every run refuses
#: more (``torquesplit.solve.static.static_equilibrium(balance_tolerance=1e-8)``)
BALANCE_TOLERANCE = 1e-8


def check_model(model: Model, source: str | None = None, *, deep: bool = False) -> None:
    """Raise ModelError listing every problem found; warn on suspicious values.

    Parameters
    ----------
    model : Model
    source : str, optional
        Where the model came from (named in the messages).
    deep : bool
        Also run what every dynamic run does before it integrates -- the assembly of the
        equations of motion and the static equilibrium -- and report their refusals as
        model errors (:func:`readiness_issues`; ``torquesplit check`` does).
    """
    issues = reference_issues(model)
    if not issues:  # the names resolve: every check that needs only them, in one round
        mismatched = mesh_compatibility_issues(model)
        skip = {loc for loc, _ in mismatched}  # (no pair geometry for gears that cannot mesh)
        geometry = geometry_issues(model, skip)
        issues = topology_issues(model) + mismatched + geometry
        issues += support_issues(model) + modification_issues(model, skip)
        issues += error_size_issues(model)
        issues += [i for i in placement_issues(model, skip, geometry) if i not in issues]
    if issues:
        raise ModelError(as_written(model, issues), source)
    # the kinematic pass finds loops that cannot turn and power that does not balance
    from .kinematics import KinematicsError, solve_kinematics

    try:
        kin = solve_kinematics(model)
    except KinematicsError as exc:
        raise ModelError(as_written(model, exc.issues), source) from None
    issues = shaft_axis_issues(model, kin) + overlap_issues(model, kin)
    issues += face_overlap_issues(model, kin)
    on_planets = planet_drive_issues(model, kin)
    issues += nominal_load_issues(model, kin) + (on_planets or balance_issues(model, kin))
    issues += stiffness_table_issues(model, kin) + planet_fit_issues(model, kin)
    issues += stiffness_magnitude_issues(model, kin)
    notes = []
    if not issues and deep:
        issues, notes = _readiness(model, kin)
    if issues:
        raise ModelError(as_written(model, issues), source)
    warned = as_written(model, plausibility_warnings(model, kin)
                        + rim_overlap_warnings(model, kin) + notes)
    for loc, msg in warned:
        if accepted(model, loc) is not None:
            continue  # known and accepted in the file, with its reason
        warn_user(f"{source + ': ' if source else ''}{loc}: {msg}", ModelWarning)
    if deep:  # (every check ran: an entry that matches none of them accepts nothing)
        for i, a in enumerate(model.model.accepted_warnings):
            if not any(_accepts(a, loc) for loc, _ in warned):
                warn_user(
                    f"{source + ': ' if source else ''}model.accepted_warnings.{i}: "
                    f"{a.field!r} matches no warning of this model's checks; remove the "
                    f"entry, or correct its field (the field a warning names, '*' for any "
                    f"part)", ModelWarning)


def accepted(model: Model, loc: str) -> str | None:
    """The reason of the model's ``accepted_warnings`` entry that matches the warned
    field ``loc`` ('*' matches any part), or None."""
    for a in model.model.accepted_warnings:
        if _accepts(a, loc):
            return a.reason
    return None


def _accepts(entry, loc: str) -> bool:
    """Whether an ``accepted_warnings`` entry names the warned field ``loc``."""
    import fnmatch

    return fnmatch.fnmatchcase(loc, entry.field)


def as_written(model: Model, issues) -> list[tuple[str, str]]:
    """``(location, message)`` pairs with each location named as the user wrote it (a
    ``[[planetary]]`` stage's field rather than the element it generated:
    :meth:`Model.written_at`), once each (every planet of a stage gives the same)."""
    out: list[tuple[str, str]] = []
    for loc, msg in issues:
        item = (model.written_at(loc), msg)
        if item not in out:
            out.append(item)
    return out


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
                known = sorted(mates.get(name, set()))
                hint = (f"name a gear it meshes with ({', '.join(known)})" if known else
                        f"no mesh lists {name!r} in its 'gears': check the meshes")
                issues.append((loc, f"{name!r} is placed from {ref!r} but does not mesh with it; "
                               f"{hint}, or give 'position' instead"))
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        for name, item in items.items():  # a bearing's seat on another body (a planet pin)
            seat = item.support.on if item.support is not None else None
            if seat is not None:
                need(f"{kind}.{name}.support.on", seat)
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
    driven_by = {d.body: name for name, d in model.drives.items()}
    balanced = {ld.body for ld in model.loads.values() if ld.torque is None}
    for name, ld in model.loads.items():
        need(f"loads.{name}.body", ld.body)
        # every drive on a body whose balanced load takes its power: no power passes any
        # gear (a load with a given torque there is a take-off; a second drive on the
        # output body, a booster: both fine)
        if ld.torque is None and ld.body in driven_by and driven_by.keys() <= balanced:
            issues.append((f"loads.{name}.body", (
                f"{ld.body!r} is the body drives.{driven_by[ld.body]} drives: a balanced "
                f"load there takes the drive's power before it passes any gear; put the "
                f"load on the body the power leaves by (a power take-off on the input "
                f"body: give its torque)")))
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


def _adjacency(model: Model) -> dict[str, set[str]]:
    """Body -> the bodies a mesh, shaft, spline or bearing on another body joins it to."""
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
    for n in names:  # a bearing on another body (a planet on its carrier) joins them
        spec = model.gears.get(n) or model.bodies.get(n)
        on = spec.support.on if spec is not None and spec.support is not None else None
        if on in adj and on != n:
            adj[n].add(on)
            adj[on].add(n)
    return adj


def _trains(adj: dict[str, set[str]]) -> list[set[str]]:
    """The connected components of :func:`_adjacency`: the separate gear trains."""
    seen: set[str] = set()
    out = []
    for start in adj:
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
        out.append(comp)
    return out


def topology_issues(model: Model) -> list[tuple[str, str]]:
    """Every body must be connected to the drive train; a drive and a load per train."""
    issues = []
    names = model.body_names()
    adj = _adjacency(model)
    for n in names:
        if not adj[n]:
            kind = "gears" if n in model.gears else "bodies"
            issues.append((f"{kind}.{n}", "this body is connected to nothing; add a mesh or a "
                           "shaft that joins it to the gearbox, or delete it"))
    if issues:
        return issues
    # connected components: each needs a drive and a load
    for comp in _trains(adj):
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


def geometry_issues(model: Model, skip=frozenset()) -> list[tuple[str, str]]:
    """What the involute geometry refuses (too few teeth, interference...), by field.

    Runs the geometry of :mod:`torquesplit.gears.geometry` on every gear and every
    cylindrical pair before the kinematics, so that its errors name the model's fields;
    the pairs of the meshes in ``skip`` (``meshes.NAME``: gears that cannot mesh) are left
    out.
    """
    from ..gears.line_of_action import cylindrical_pair, is_conical
    from .kinematics import gear_geometry

    issues = []
    good = set()
    for name, gear in model.gears.items():
        try:
            geo = gear_geometry(gear)
            good.add(name)
        except ModelError as exc:
            for loc, msg in exc.issues:
                field = _GEOMETRY_FIELDS.get(loc.split(".")[-1])
                issues.append((f"gears.{name}" + (f".{field}" if field else ""), _teach(msg)))
            continue
        d_f = 2.0 * geo.root_radius
        if gear.gear_type != "internal" and gear.bore_diameter and gear.bore_diameter >= d_f:
            # (a reviewer's 200 mm bore in a 72 mm pinion was taken, its computed mass the
            # teeth's alone and the tooth stiffness's fillet foundation a ring of nothing)
            issues.append((f"gears.{name}.bore_diameter", (
                f"{_length_text(gear.bore_diameter)} is not smaller than the root diameter "
                f"({_length_text(d_f)}): the gear would have no body under its teeth; give "
                f"the bore of the gear's hub (or leave it out: a solid disc)")))
    for name, mesh in model.meshes.items():
        a, b = mesh.gears
        ga, gb = model.gears[a], model.gears[b]
        if not {a, b} <= good or is_conical(ga, gb) or f"meshes.{name}" in skip:
            continue
        # the pair's messages say pinion (gear1) and wheel (gear2); an internal gear is
        # put second: name the gears instead
        role = {"pinion": b, "wheel": a} if ga.gear_type == "internal" else {"pinion": a, "wheel": b}
        try:
            cylindrical_pair(ga, gb).operating_center_distance  # noqa: B018 - validates
        except ModelError as exc:
            for _, msg in exc.issues:
                msg = _ROLE.sub(lambda m: _gear_named(role[m[1]], m[2]), msg)
                issues.append((f"meshes.{name}", f"gears {a!r} and {b!r}: {_teach(msg)}"))
    return issues


def placement_issues(model: Model, skip=frozenset(), found=()) -> list[tuple[str, str]]:
    """Gears placed where they cannot mesh (the positions against the operating centre
    distance, as the kinematics checks them), in the same round as the checks above:
    meshes in ``skip`` and those of a gear whose geometry ``found`` refuses are left out
    (their message would follow from the first)."""
    from ..gears import line_of_action as loa
    from . import epicyclic as epi
    from .kinematics import _layout, _rigid_groups

    placed: list[tuple[str, str]] = []
    try:
        positions, axes, computed = _layout(model, placed)
        # carriers and planets first, as the kinematics do: a ring of the wrong kind is
        # named as such, not as a centre distance that does not fit
        layout: list[tuple[str, str]] = []
        epi.find_layout(model, positions, axes, _rigid_groups(model), layout)
    except (ValueError, ArithmeticError, KeyError):  # pragma: no cover - the kinematics say
        return []
    if layout:
        return layout
    named = {loc.split(".")[1] for loc, _ in found if loc.startswith("gears.")}
    # a gear placed from a refused one fails for its reason (said once, not again as
    # 'gears.b1.place: GearGeometry: addendum: ...' for each of its mates)
    grew = True
    while grew:
        more = {n for n, g in model.gears.items()
                if g.place is not None and g.place.from_gear in named} - named
        named |= more
        grew = bool(more)
    unplaced = {loc.split(".")[1] for loc, _ in placed}
    # a mesh whose pair geometry is refused: its placement and frame fail for that reason
    skip = set(skip) | {".".join(loc.split(".")[:2]) for loc, _ in found
                        if loc.startswith("meshes.")}
    for name in skip:  # (a gear placed from a mate it cannot mesh with has no position:
        # its placement fails for the reason the mesh's geometry gave)
        if name.startswith("meshes.") and name[7:] in model.meshes:
            named |= set(model.meshes[name[7:]].gears) & (set(computed) | unplaced)
    issues = [(loc, msg) for loc, msg in placed if loc.split(".")[1] not in named]
    for name, mesh in model.meshes.items():
        if f"meshes.{name}" in skip or named & set(mesh.gears):
            continue
        try:
            loa.contact_frame(model, name, positions, axes)
        except ValueError as exc:
            issues.append((f"meshes.{name}", str(exc)))
    return issues


#: "the pinion", "the wheel's", "its pinion", "the wheel tip" in a pair's messages
_ROLE = re.compile(r"\b(?:(?:the|its) )?(pinion|wheel)\b('s| tip| profile shift| addendum)?")


def _gear_named(name: str, tail: str | None) -> str:
    """A gear's name where a pair's message says pinion or wheel: "b1's tip", not
    "the b1 tip"."""
    if tail is None:
        return name
    return f"{name}'s" + ("" if tail == "'s" else tail)


def modification_issues(model: Model, skip=frozenset()) -> list[tuple[str, str]]:
    """Tooth modifications that do not fit the active profile of a mating pair (a relief
    longer than the active profile, tip and root relief overlapping, an end relief longer
    than half the face), and the LTCA asked of a bevel or face mesh, named by field (the
    pairs of the meshes in ``skip`` left out, as in :func:`geometry_issues`)."""
    from ..gears.contact.modifications import check_modification, modification_from_spec
    from ..gears.line_of_action import cylindrical_pair, is_conical

    issues: list[tuple[str, str]] = []
    for name, g in model.gears.items():  # (said with the meshes' LTCA, not before them)
        if g.modifications is not None and g.gear_type in ("bevel", "face"):
            issues.append((f"gears.{name}.modifications", (
                f"tooth modifications are analysed for cylindrical gears (spur, helical, "
                f"double-helical, internal), not for a {g.gear_type} gear; remove them")))
    # a gear with mates of different sizes (a planet: sun and ring) is checked against
    # each: its messages name the mate (as written: every planet of a stage the same)
    mates: dict[str, set[str]] = {}
    for mesh in model.meshes.values():
        for g, other in (mesh.gears, mesh.gears[::-1]):
            mates.setdefault(g, set()).add(model.written_at(f"gears.{other}"))
    for name, mesh in model.meshes.items():
        a, b = mesh.gears
        ga, gb = model.gears[a], model.gears[b]
        if mesh.stiffness.method == "ltca" and is_conical(ga, gb):
            issues.append((f"meshes.{name}.stiffness.method", (
                "the LTCA is implemented for cylindrical pairs (spur, helical, double-helical, "
                "internal); use a table or a constant for this bevel/face mesh")))
        if ((ga.modifications is None and gb.modifications is None) or is_conical(ga, gb)
                or f"meshes.{name}" in skip):
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
                mate = model.written_at(f"gears.{b if g == a else a}")
                found = [(loc, f"in the mesh with {mate}: {msg}" if len(mates[g]) > 1 else msg)
                         for loc, msg in exc.issues]
                issues += [i for i in found if i not in issues]
    return issues


def _teach(msg: str) -> str:
    """A message, ending with what to do if it does not already."""
    return msg if ";" in msg else f"{msg}; correct the value"


#: the start of the warning that a gear's modifications do not enter the dynamics
MODIFICATIONS_UNUSED = ("a dynamic run uses tooth modifications only through the stiffness "
                        "method 'ltca'")
#: fewest slices across the face that resolve a lead modification (crowning, end relief)
LEAD_SLICES = 5


def lead_slices_note(model: Model, mesh: str, slices: int, option: str) -> str:
    """Why ``slices`` across the face of mesh ``mesh`` leave its gears' lead modifications
    unresolved ('' when they resolve them or there are none); ``option`` names the setting
    in the remedy (``slices``, ``--slices``), so that a model file and ``contact`` say the
    same."""
    lead = [g for g in model.meshes[mesh].gears if model.gears[g].modifications is not None
            and (model.gears[g].modifications.crowning > 0
                 or model.gears[g].modifications.end_relief is not None)]
    if not lead or slices >= LEAD_SLICES:
        return ""
    return (f"{slices} slice(s) across the face cannot resolve the lead modification of "
            f"{', '.join(lead)} (crowning, end relief): the LTCA sees an unmodified lead; "
            f"give {option} >= {LEAD_SLICES} (default 40)")


#: an error, backlash or bearing clearance beyond this many modules (the whole tooth depth,
#: 2.25 m_n) takes the teeth out of mesh: refused, not warned (a reviewer's 20 m
#: eccentricity, a unit slip, ran with back-flank forces of 3e5 kN)
TOOTH_DEPTH = 2.25


def error_size_issues(model: Model) -> list[tuple[str, str]]:
    """Errors, backlash and bearing clearances deeper than the whole tooth (:data:`
    TOOTH_DEPTH` modules): the teeth would leave mesh, so the value is a unit slip."""
    issues = []

    def deeper(loc, value, module, what):
        depth = TOOTH_DEPTH * module
        if value and math.isfinite(value) and abs(value) > depth:
            issues.append((loc, f"{_length_text(abs(value))} is deeper than the whole tooth "
                                f"({TOOTH_DEPTH:g} x module = {_length_text(depth)}): the teeth "
                                f"would leave mesh; {what} are microns: check the value and "
                                f"its unit (a bare number is read in m: write '20 um')"))

    for name, g in model.gears.items():
        for field in ("eccentricity", "installation", "tooth_thickness", "pitch",
                      "bearing_runout"):
            deeper(f"gears.{name}.errors.{field}", getattr(g.errors, field), g.module,
                   "manufacturing and assembly errors")
        for field, value in _modification_amounts(f"gears.{name}", g):
            deeper(field, value, g.module, "tooth modifications")
        if g.support is not None:
            deeper(f"gears.{name}.support.clearance", g.support.clearance, g.module,
                   "bearing clearances")
            for field in ("radial", "tangential"):
                deeper(f"gears.{name}.support.pin_error.{field}",
                       getattr(g.support.pin_error, field), g.module, "pin position errors")
            seat = getattr(g.support, "on", None)
            if seat in model.bodies:  # a carrier's eccentricity, against what it holds
                deeper(f"bodies.{seat}.eccentricity", model.bodies[seat].eccentricity,
                       g.module, "carrier eccentricities")
    for name, m in model.meshes.items():
        modules = [model.gears[x].module for x in m.gears if x in model.gears]
        if modules:
            deeper(f"meshes.{name}.backlash", m.backlash.nominal + m.backlash.tolerance,
                   min(modules), "backlashes")
            for field in ("constant", "amplitude"):
                deeper(f"meshes.{name}.transmission_error.{field}",
                       getattr(m.transmission_error, field), min(modules),
                       "transmission errors")
    return list(dict.fromkeys(issues))  # (a carrier named once per planet it holds)


def support_issues(model: Model) -> list[tuple[str, str]]:
    """Translational DOFs need a support to the housing (bearing or shaft bending), or a
    spline that holds the body radially (Dong et al. 2021 floating pinion)."""
    issues = []
    on_spline = {b for sp in model.splines.values() for b in sp.connects}
    for kind, items in (("gears", model.gears), ("bodies", model.bodies)):
        for name, body in items.items():
            free = [d for d in body.dofs if d != "theta"]
            if free and body.support is None and name not in on_spline:
                written = model.written_at(f"{kind}.{name}")
                floating = (written.startswith("planetary.") and written.endswith(".sun"))
                hint = ("; a floating sun, held by its planet meshes alone: support = "
                        "{floating = true} (a stiff support holds it: 1e8 N/m takes most "
                        "of the equalising away)"
                        if floating else "")
                issues.append((f"{kind}.{name}.support", (
                    f"the translational DOFs {free} have no support; add one, e.g. "
                    f"support = {{stiffness = '1e8 N/m'}}, or remove them from 'dofs'"
                    f"{hint}")))
    return issues


#: a mesh stiffness beyond this multiple of the ISO 6336 estimate is refused: no gear is
#: that stiff (a unit slip), and against it the other compliances and a backlash fall
#: below what double precision resolves (1e20 N/m: a quasi-static sweep found every
#: tooth force 0 and "converged", the modes no elastic mode)
ISO_STIFFNESS_LIMIT = 1e6


def stiffness_magnitude_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Constant mesh stiffnesses beyond :data:`ISO_STIFFNESS_LIMIT` times the ISO 6336
    estimate (warned from 5 times)."""
    out = []
    for name, mk in kin.meshes.items():
        spec, iso = model.meshes[name].stiffness, mk.iso_stiffness
        if spec.method == "constant" and iso and spec.value / iso > ISO_STIFFNESS_LIMIT:
            out.append((f"meshes.{name}.stiffness", (
                f"{spec.value:.3g} N/m is {spec.value / iso:.2g} times the ISO 6336 estimate "
                f"c_gamma*b = {iso:.3g} N/m: no gear mesh is that stiff, and beside it the "
                f"other compliances fall below what the solvers resolve; check the value "
                f"and its unit (meshes are 1e8-1e10 N/m: write e.g. '4e8 N/m' or "
                f"'400 N/um')")))
    return out


def _stage_groups(model: Model, kin) -> list[tuple[str, str]]:
    """Load-sharing groups that are probably not what the file meant: unlabelled meshes
    of one tooth-count pair split by their nominal forces (a split and a combining stage
    of equal ratio, :func:`torquesplit.assembly.excitation.stage_labels`), and a stage
    label held by one mesh that reads like the label of meshes parallel to it (the same
    tooth counts and nominal force: 'splt' beside 'split', a group of one, coefficient 1
    by definition, and its stage's group one mesh short)."""
    import difflib

    from ..assembly.excitation import STAGE_FORCE_RTOL, stage_labels, tooth_pair

    out = []
    stages = stage_labels(model, kin)
    split: dict[str, list[str]] = {}
    for name, mesh in model.meshes.items():
        if not mesh.stage and "-" in stages[name]:
            split.setdefault(stages[name].rsplit("-", 1)[0], []).append(name)
    for pair, names in split.items():
        groups = {}
        for n in names:
            groups.setdefault(stages[n], []).append(n)
        said = "; ".join(f"{g}: {', '.join(ms)} ({abs(kin.meshes[ms[0]].force) / 1e3:.4g} kN)"
                         for g, ms in groups.items())
        out.append((f"meshes.{names[0]}.stage", (
            f"meshes {', '.join(names)} have no stage label and the same tooth counts "
            f"({pair}) but different nominal forces, so they are not one stage: their "
            f"load-sharing groups are {said}. Give the meshes of each stage one `stage` "
            f"label to name the groups")))
    members: dict[str, list[str]] = {}
    for name, mesh in model.meshes.items():
        if mesh.stage:
            members.setdefault(mesh.stage, []).append(name)

    def parallel(a, b):  # the same tooth counts and nominal force: parallel paths
        fa, fb = abs(kin.meshes[a].force), abs(kin.meshes[b].force)
        return (tooth_pair(model, a) == tooth_pair(model, b)
                and abs(fa - fb) <= STAGE_FORCE_RTOL * max(fa, fb))

    for label, ms in members.items():
        if len(ms) != 1:
            continue
        like = [other for other in difflib.get_close_matches(label, list(members), n=3,
                                                             cutoff=0.6)
                if other != label and len(members[other]) > 1
                and any(parallel(m, ms[0]) for m in members[other])]
        if like:
            other = like[0]
            out.append((f"meshes.{ms[0]}.stage", (
                f"{label!r} is the stage of this mesh alone (a load-sharing group of one: "
                f"coefficient 1 by definition), while {', '.join(members[other])}, with the "
                f"same tooth counts and nominal force, are stage {other!r}: if it is one of "
                f"them, write {other!r}")))
    return out


def _label_slips(model: Model) -> list[tuple[str, str]]:
    """Stage and path labels that differ only in spacing, case or punctuation: each
    label is a load-sharing group of its own ('stage 1' beside 'stage1' split a stage
    into two groups of one mesh, each sharing 1.00000, without a word)."""
    out = []
    for field in ("stage", "path"):
        labels: dict[str, list[str]] = {}
        for name, m in model.meshes.items():
            label = getattr(m, field)
            if label is not None:
                labels.setdefault(label, []).append(name)
        by_key: dict[str, list[str]] = {}
        for label in labels:
            by_key.setdefault(re.sub(r"[\W_]+", "", label).lower(), []).append(label)
        for same in by_key.values():
            if len(same) < 2:
                continue
            few = min(same, key=lambda lab: len(labels[lab]))
            others = ", ".join(repr(lab) for lab in same if lab != few)
            out.append((f"meshes.{labels[few][0]}.{field}", (
                f"{few!r} differs from {others} only in spacing, case or punctuation; each "
                f"{field} label is a load-sharing group of its own, so these meshes form "
                f"{len(same)} groups: write the same label")))
    return out


#: the error amplitudes of a gear (``errors.grade`` bounds them, sets none)
GEAR_ERROR_FIELDS = ("eccentricity", "installation", "tooth_thickness", "pitch",
                     "bearing_runout")

#: a support deflecting more than this fraction of its gear's module under the nominal
#: tooth forces, or a shaft twisting more than MAX_NOMINAL_TWIST [rad] under the torque
#: it carries, is warned: a unit slip (the shipped examples: at most 0.023 modules and
#: 0.015 rad, but for one printed as the paper gives it and accepted in its file)
MAX_NOMINAL_DEFLECTION = 0.5
MAX_NOMINAL_TWIST = 0.2
#: a support this many times softer than its gear's meshes (ISO 6336 estimate) is warned:
#: the member floats (shipped floating members: 0.16 of their meshes)
MIN_SUPPORT_MESH_RATIO = 1e-4


#: a support said to float (``floating = true``) this stiff beside its gear's meshes holds
#: the gear: it does not float (warned)
FLOATING_HOLD_RATIO = 1e-2


def _floating_text(k: float, mesh: float) -> str:
    return (f"{k:.3g} N/m is {mesh / k:.3g} times softer than the gear's meshes (ISO 6336 "
            f"about {mesh:.3g} N/m): the gear floats, held by its meshes alone; if that is "
            f"meant (a floating sun), say so with floating = true in the support, else "
            f"check the value and its unit (bearings are about 1e8-1e10 N/m; a bare number "
            f"is read in N/m)")


def compliance_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Supports and shafts so soft that they cannot carry the nominal load: a stiffness
    in the wrong unit (2000 N/mm for 2000 N/um) passes every other check, and in a
    locked train the soft branch merely sheds its load (its static deflection stays
    small), so the load sharing comes out absurd without a word.  Each is measured
    against the nominal (equal-split) forces: a support by its deflection under the
    resultant of its gear's nominal tooth forces, and by its stiffness beside the gear's
    meshes; a shaft by its twist under the torque it carries."""
    out = []
    for name, gear in model.gears.items():
        sup, bk = gear.support, kin.bodies.get(name)
        if (sup is None or sup.stiffness is None or bk is None
                or not set(gear.dofs) - {"theta"}):  # (no translation: nothing deflects)
            continue
        k = min(v for v in (sup.stiffness, sup.stiffness_y) if v is not None)
        resultant, mesh_k = np.zeros(3), []
        for mk in kin.meshes.values():
            if name in (mk.driver, mk.driven):
                sign = -1.0 if name == mk.driver else 1.0
                resultant += sign * mk.force * np.asarray(mk.line_of_action, float)
                mesh_k.append(mk.iso_stiffness or 0.0)
        axis = np.asarray(bk.axis, float)
        radial = float(np.linalg.norm(resultant - resultant.dot(axis) * axis))
        loc = f"gears.{name}.support.stiffness"
        floats = bool(mesh_k) and max(mesh_k) > 0 and k < MIN_SUPPORT_MESH_RATIO * max(mesh_k)
        # (held in one direction is held: the stiffer of stiffness and stiffness_y)
        k_held = max(v for v in (sup.stiffness, sup.stiffness_y) if v is not None)
        if sup.floating and mesh_k and k_held >= FLOATING_HOLD_RATIO * max(mesh_k):
            # (a --set of floating = true merges into a table that gives a stiffness: the
            # member stayed on its bearing without a word, a planetary reviewer)
            fields = " and ".join(f for f, v in (("stiffness", sup.stiffness),
                                                 ("stiffness_y", sup.stiffness_y))
                                  if v is not None)
            loc_y = model.written_at(f"gears.{name}.support.stiffness_y")
            sets = " and ".join(f"{at}=1 N/m" for at, v in (
                (model.written_at(loc), sup.stiffness), (loc_y, sup.stiffness_y))
                if v is not None)
            out.append((f"gears.{name}.support.floating", (
                f"floating = true, but the support's stiffness {k_held:.3g} N/m is "
                f"{k_held / max(mesh_k):.2g} of the gear's meshes' (ISO 6336 about "
                f"{max(mesh_k):.3g} N/m): the support holds the gear, which does not float; "
                f"for a floating member leave {fields} out (1 N/m is taken; a --set of "
                f"the support merges into the file's table, so set {sets} too), else "
                f"remove 'floating'")))
            continue
        if sup.floating:  # (said to float: its softness is meant)
            if len(mesh_k) >= 3:
                continue  # (centred by its meshes)
            floats = False  # (fewer cannot centre it: a resultant still deflects it)
        # (the texts name no gear: the planets of a [[planetary]] stage, which share one
        # written field, are then said once)
        if floats and len(mesh_k) >= 3:
            # three meshes or more can centre it (a sun among unequally spaced planets has
            # a resultant, and was told of a unit slip for the support the floating-sun
            # recipe writes, a planetary reviewer): it floats, as meant or not
            out.append((loc, _floating_text(k, max(mesh_k))))
        elif radial / k > MAX_NOMINAL_DEFLECTION * gear.module:
            out.append((loc, (
                f"{k:.3g} N/m would deflect {_length_text(radial / k)} under the gear's "
                f"nominal tooth forces ({radial / 1e3:.4g} kN), more than half its module: "
                f"check the value and its unit (bearings are about 1e8-1e10 N/m: write e.g. "
                f"'2000 N/um'; a bare number is read in N/m)")))
        elif floats:
            out.append((loc, _floating_text(k, max(mesh_k))))
    for name, sh in model.shafts.items():
        k = sh.torsional_stiffness
        if sh.rigid or k is None or not k > 0:
            continue  # (one from the diameter and length: those are checked for size)
        torque = min((abs(kin.bodies[b].torque) for b in sh.connects if b in kin.bodies),
                     default=0.0)
        if torque / k > MAX_NOMINAL_TWIST:
            out.append((f"shafts.{name}.torsional_stiffness", (
                f"{k:.3g} N m/rad twists {torque / k:.3g} rad ({math.degrees(torque / k):.3g} "
                f"deg) under the {torque:.4g} N m it carries: check the value and its unit "
                f"(a bare number is read in N m/rad; 'N mm/rad' is 1000 times softer)")))
    return out


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
    out += _friction_drift(model) + _label_slips(model) + _stage_groups(model, kin)
    out += _locked_speed_drives(model)
    out += _mass_magnitudes(model)
    out += _centre_distance_offsets(model, kin)
    out += _face_overlap_warnings(model, kin)
    pairs: dict[frozenset, str] = {}
    for name, m in model.meshes.items():
        key = frozenset(m.gears)
        if key in pairs and len(key) == 2:
            first = pairs[key]
            out.append((f"meshes.{name}", (
                f"joins the same gears as meshes.{first} ({', '.join(m.gears)}): the two "
                f"meshes act in parallel and double the mesh stiffness and load; remove one "
                f"(a double-helical pair is one mesh of double-helical gears)")))
        pairs.setdefault(key, name)
    ltca_gears = {g for m in model.meshes.values() if m.stiffness.method == "ltca" for g in m.gears}
    for name, gear in model.gears.items():
        if gear.modifications is not None and name not in ltca_gears:
            loc = f"gears.{name}.modifications"
            meshes = "its meshes"
            if model.written_at(loc).startswith("planetary."):  # planetary.0.sun.modif...
                _, k, member = model.written_at(loc).split(".")[:3]
                meshes = (f"planetary.{k}.{member}_mesh" if member != "planet" else
                          f"planetary.{k}.sun_mesh and/or planetary.{k}.ring_mesh")
            out.append((loc, MODIFICATIONS_UNUSED + ", and no mesh of this gear uses it "
                             "('torquesplit contact' analyses them either way); set "
                             f"stiffness.method = 'ltca' on {meshes} or remove the "
                             f"modifications"))
        elif (gear.modifications is not None
              and not model.written_at(f"gears.{name}").startswith("planetary.")):
            # (a designer's modified pinion in an LTCA mesh and a non-LTCA one: the second
            # ran unmodified without a word; a planet's sun and ring meshes, which take
            # their flanks' modifications, are a stage's choice)
            plain = [m for m, mesh in model.meshes.items()
                     if name in mesh.gears and mesh.stiffness.method != "ltca"]
            if plain:
                out.append((f"gears.{name}.modifications", (
                    MODIFICATIONS_UNUSED + f": meshes {', '.join(plain)} of this gear do not "
                    f"use it (they run as unmodified); set stiffness.method = 'ltca' on them "
                    f"too, or accept it")))
    for name, m in model.meshes.items():
        if m.stiffness.method == "ltca":
            note = lead_slices_note(model, name, m.stiffness.slices, "slices")
            if note:
                out.append((f"meshes.{name}.stiffness.slices", note))
            # (a reviewer's stagger and axial_float on a spur pair were taken silently)
            kinds = {model.gears[g].gear_type for g in m.gears}
            lt = m.stiffness.ltca
            for field, given in (("stagger", lt.stagger != 0.0), ("axial_float", lt.axial_float)):
                if given and "double_helical" not in kinds:
                    out.append((f"meshes.{name}.stiffness.ltca.{field}", (
                        f"applies to a double-helical pair only (its second helix); this "
                        f"pair's gears are {' and '.join(sorted(kinds))}, so it changes "
                        f"nothing: remove it")))
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
        if (spec.method == "constant" and iso and not (0.2 < spec.value / iso < 5)
                and spec.value / iso <= ISO_STIFFNESS_LIMIT):
            out.append((f"meshes.{name}.stiffness",
                        f"{spec.value:.3g} N/m is {spec.value / iso:.2g} times the ISO 6336 "
                        f"estimate c_gamma*b = {iso:.3g} N/m (b the face width); check the "
                        f"value, the gears' face_width and their units"))
    rigid = [(loc, msg.replace("a shaft joins bodies on one axis", "a rigid join locks "
                               "their rotations but not the motion of one about the other's "
                               "centre"))
             for loc, msg in shaft_axis_issues(model, kin, rigid=True)]
    return (out + rigid + magnitude_warnings(model, kin) + compliance_warnings(model, kin)
            + tolerance_warnings(model, kin))


#: a shaft's two bodies may be this far off their common axis [m] (plus SHAFT_AXIS_RELATIVE
#: of their distance) and their axes this far from parallel [rad]
SHAFT_AXIS_OFFSET = 1e-4
SHAFT_AXIS_RELATIVE = 1e-3
SHAFT_AXIS_ANGLE = 1e-3


def shaft_axis_issues(model: Model, kin, *, rigid: bool = False) -> list[tuple[str, str]]:
    """An elastic shaft transmits torque about one axis: the bodies it joins must turn
    about parallel axes and sit on that common axis.  A body whose position the file
    leaves out (a motor or a load inertia) is taken to be on the axis.

    ``rigid=True`` checks the rigid joins instead (``rigid = true``: the bodies turn as
    one, as a gear bolted to a carrier may), which :func:`plausibility_warnings` reports
    as warnings."""
    issues = []
    for name, s in model.shafts.items():
        if bool(s.rigid) != rigid:
            continue
        a, b = s.connects
        if a not in kin.bodies or b not in kin.bodies:
            continue
        ba, bb = kin.bodies[a], kin.bodies[b]
        ua, ub = np.asarray(ba.axis, float), np.asarray(bb.axis, float)
        angle = math.acos(min(1.0, abs(float(np.dot(ua, ub)))))
        if angle > SHAFT_AXIS_ANGLE:
            issues.append((f"shafts.{name}", (
                f"joins {a!r} and {b!r}, whose axes are {math.degrees(angle):.3g} deg apart; "
                f"a shaft turns both bodies about one axis: give them the same 'axis', or "
                f"connect them by a mesh (bevel gears) instead")))
            continue
        if not (_position_given(model, a) and _position_given(model, b)):
            continue
        d = np.asarray(bb.position, float) - np.asarray(ba.position, float)
        off = float(np.linalg.norm(d - np.dot(d, ua) * ua))
        if off > SHAFT_AXIS_OFFSET + SHAFT_AXIS_RELATIVE * float(np.linalg.norm(d)):
            issues.append((f"shafts.{name}", (
                f"joins {a!r} at {_mm(ba.position)} and {b!r} at {_mm(bb.position)}, "
                f"{off * 1e3:.4g} mm off their common axis; a shaft joins bodies on one "
                f"axis: correct the positions (or 'place'), or connect them otherwise")))
    return issues


#: gears whose tooth regions overlap by less than this [m] are taken to touch, not overlap
OVERLAP_TOLERANCE = 1e-6


def overlap_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Gears that do not mesh with each other but whose bodies would occupy the same
    space: parallel axes, face widths that overlap along the axis, and regions that
    intersect in the plane (a placement angle or a position typed wrong).

    An external gear's region is its tip disc; an internal gear's the annulus from its
    tip circle to the outside of its rim where the file gives the rim (``outer_diameter``
    or ``rim_thickness``), else to its root circle (:func:`rim_overlap_warnings` warns
    of a gear in the rim assumed then), so that a planet inside its ring is fine, while
    a gear reaching past a ring's tip circle into its teeth or rim is not.  Meshing
    pairs (their centre distance is the mesh's), gears on one shaft line (shafts and
    splines; ``shaft_axis_issues`` checks those) and bevel and face gears are left out,
    and so are gears whose plane the file does not state (see
    :func:`_axially_located`).  Positions are those at t = 0."""
    return [_overlap_issue(model, a, b, d)
            for a, b, d, refused in _overlapping_pairs(model, kin) if refused]


def face_overlap(model: Model, kin) -> list[tuple[str, float, float, float, float]]:
    """``(mesh, axial offset, overlap, narrower face, wider face)`` [m] of every cylindrical
    mesh whose two faces, along the common axis, do not cover each other's narrower face:
    the teeth touch over ``overlap`` only (none where it is <= 0).  Gears whose plane the
    file does not state (:func:`_axially_located`) are left out."""
    from .kinematics import gear_geometry

    located = _axially_located(model)
    out = []
    for name, m in model.meshes.items():
        a, b = m.gears
        ga, gb = model.gears[a], model.gears[b]
        if {ga.gear_type, gb.gear_type} & {"bevel", "face"} or not {a, b} <= located \
                or a not in kin.bodies or b not in kin.bodies:
            continue
        try:
            wa, wb = gear_geometry(ga).total_face_width, gear_geometry(gb).total_face_width
        except (ModelError, ValueError, ArithmeticError):  # pragma: no cover - checked before
            continue
        axis = np.asarray(kin.bodies[a].axis, float)
        axial = float(np.dot(np.asarray(kin.bodies[b].position, float)
                             - np.asarray(kin.bodies[a].position, float), axis))
        overlap = min(wa / 2, axial + wb / 2) - max(-wa / 2, axial - wb / 2)
        if overlap < min(wa, wb) - OVERLAP_TOLERANCE:
            out.append((name, axial, overlap, min(wa, wb), max(wa, wb)))
    return out


def _face_overlap_text(model: Model, name: str, axial: float, narrow: float,
                       wide: float) -> str:
    a, b = model.meshes[name].gears
    return (f"the centres of {a} and {b} are {abs(axial) * 1e3:.4g} mm apart along their "
            f"axis, with faces {narrow * 1e3:.4g} mm and {wide * 1e3:.4g} mm wide")


def face_overlap_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Meshing gears whose faces do not overlap at all along their axis (an axial
    position typed wrong): their teeth never touch."""
    return [(f"meshes.{name}", (
        f"{_face_overlap_text(model, name, axial, narrow, wide)}: their faces do not "
        f"overlap and the teeth never touch; give both gears the same axial position "
        f"(the component of 'position' along 'axis')"))
        for name, axial, overlap, narrow, wide in face_overlap(model, kin)
        if overlap <= OVERLAP_TOLERANCE]


def _face_overlap_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Meshing gears whose faces overlap along the axis over less than the narrower
    face: the mesh stiffness and the tooth loads are those of the whole narrower face.
    A double-helical pair offset along its axis has its apexes apart, which the model
    does not represent (its overlap is not that of one face: said so instead)."""
    out = []
    for name, axial, overlap, narrow, wide in face_overlap(model, kin):
        if overlap <= OVERLAP_TOLERANCE:
            continue
        text = _face_overlap_text(model, name, axial, narrow, wide)
        if any(model.gears[g].gear_type == "double_helical" for g in model.meshes[name].gears):
            out.append((f"meshes.{name}", (
                f"{text}: the apexes of these double-helical gears do not line up, which "
                f"the model does not represent (it takes both helices in full contact); "
                f"align the gears along the axis ('position')")))
        else:
            out.append((f"meshes.{name}", (
                f"{text}: the teeth touch over {overlap * 1e3:.4g} mm only, but the mesh "
                f"stiffness is that of the whole {narrow * 1e3:.4g} mm face; align the "
                f"gears along the axis ('position'), or, if the offset is meant, give the "
                f"width in contact as the narrower gear's face_width")))
    return out


#: a pair's given positions further than this from its operating centre distance [m]
#: are said to be ignored (below it: the rounding of typed coordinates)
CENTRE_OFFSET = 10e-6


def _centre_distance_offsets(model: Model, kin) -> list[tuple[str, str]]:
    """Cylindrical pairs whose positions, as given, lie off the operating centre distance
    by more than :data:`CENTRE_OFFSET` but inside the 0.1 % the layout accepts: the mesh
    works at the operating centre distance, so the offset changes nothing (a reviewer's
    0.27 mm, more than the modelled backlash, went unnoticed)."""
    from ..gears.line_of_action import cylindrical_pair, is_conical

    out = []
    for name, m in model.meshes.items():
        a, b = m.gears
        ba, bb = kin.bodies.get(a), kin.bodies.get(b)
        if ba is None or bb is None or is_conical(model.gears[a], model.gears[b]):
            continue
        try:
            aw = cylindrical_pair(model.gears[a], model.gears[b]).operating_center_distance
        except (ModelError, ValueError, ArithmeticError, KeyError):
            continue
        d = np.asarray(bb.position, float) - np.asarray(ba.position, float)
        axis = np.asarray(ba.axis, float)
        dist = float(np.linalg.norm(d - axis * float(d @ axis)))
        if abs(dist - aw) > CENTRE_OFFSET:
            out.append((f"meshes.{name}", (
                f"the positions of {a} and {b} are {dist * 1e3:.4f} mm apart, "
                f"{(dist - aw) * 1e6:+.0f} um off their operating centre distance "
                f"{aw * 1e3:.4f} mm: the mesh works at the operating centre distance and "
                f"ignores the offset; model a centre-distance deviation as backlash "
                f"(meshes.{name}.backlash) and correct the position, or place the gear with "
                f"place = {{from_gear = ..., angle = ...}}")))
    return out


def rim_overlap_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Gears that reach into the rim an internal gear is assumed to have (the default
    :data:`~torquesplit.model.kinematics.RIM_THICKNESS_MODULES` normal modules outside its
    root circle, as its computed mass), but not into its teeth: a warning, not a
    refusal, since the file does not say how thick the rim is."""
    from .kinematics import RIM_THICKNESS_MODULES

    out = []
    for a, b, d, refused in _overlapping_pairs(model, kin):
        if refused:
            continue
        if a[1] > 0 and b[1] > 0:  # two internal gears: name those whose rim is assumed
            assumed = [n for n in (a[0], b[0]) if _rim_assumed(model.gears[n])]
            fields = " and ".join(_rim_fields(model, n) for n in assumed)
            out.append((f"gears.{b[0]}", (
                f"the rims of internal gears {a[0]} and {b[0]} (centres {d * 1e3:.4g} mm "
                f"apart) intersect where {' and '.join(assumed)}'s is assumed "
                f"({RIM_THICKNESS_MODULES:g} normal modules outside the root circle); give "
                f"{fields}, or check gears.{b[0]}.place / position")))
            continue
        (ring, _, outer), (other, _, tip) = (a, b) if a[1] > 0 else (b, a)
        out.append((f"gears.{other}", (
            f"{other} (tip radius {tip * 1e3:.4g} mm, centre {d * 1e3:.4g} mm from {ring}'s) "
            f"reaches into the rim of internal gear {ring} as assumed (outer radius "
            f"{outer * 1e3:.4g} mm, {RIM_THICKNESS_MODULES:g} normal modules outside its "
            f"root circle); give {_rim_fields(model, ring)}, or check "
            f"gears.{other}.place / position")))
    return out


def _rim_assumed(gear) -> bool:
    """An internal gear whose file gives neither ``rim_thickness`` nor ``outer_diameter``."""
    return gear.outer_diameter is None and gear.rim_thickness is None


def _rim_fields(model: Model, ring: str) -> str:
    """Where the rim of ``ring`` is given, as the user writes it (a ``[[planetary]]``
    stage's ring, or the gear's own table)."""
    at = model.written_at(f"gears.{ring}.rim_thickness")
    return f"{at} or {at.rsplit('.', 1)[0]}.outer_diameter"


def _overlapping_pairs(model: Model, kin):
    """``((name, inner, outer), (name, inner, outer), centre distance, refused)`` of every
    pair of gears of :func:`overlap_issues` whose regions intersect where the internal
    gears' rims are counted, given or assumed.  ``refused``: they intersect also with
    the assumed rims left out (an internal gear's region then ends at its root circle),
    and ``outer`` is the radius of that verdict."""
    from .kinematics import gear_geometry, internal_rim

    mates = {frozenset(m.gears) for m in model.meshes.values()}
    line = _shaft_lines(model)
    located = _axially_located(model)
    gears = []
    for name, g in model.gears.items():
        if g.gear_type in ("bevel", "face") or name not in located or name not in kin.bodies:
            continue
        try:
            geo = gear_geometry(g)
        except (ModelError, ValueError, ArithmeticError):  # pragma: no cover - checked before
            continue
        if g.gear_type == "internal":
            r_f, r_o, _ = internal_rim(g)
            inner, outers = geo.tip_radius, ((r_f if _rim_assumed(g) else r_o), r_o)
        else:
            inner, outers = 0.0, (geo.tip_radius, geo.tip_radius)
        body = kin.bodies[name]
        gears.append((name, np.asarray(body.position, float), np.asarray(body.axis, float),
                      geo.total_face_width, inner, outers))
    tol = OVERLAP_TOLERANCE

    def meet(d, ia, oa, ib, ob):  # two annuli [inner, outer] about centres d apart
        return d < oa + ob - tol and ib < oa + d - tol and ia < ob + d - tol

    pairs = []
    for i, (a, pa, ua, wa, ia, oas) in enumerate(gears):
        for b, pb, ub, wb, ib, obs in gears[i + 1:]:
            if frozenset((a, b)) in mates or line.get(a, a) == line.get(b, b):
                continue
            if math.acos(min(1.0, abs(float(np.dot(ua, ub))))) > SHAFT_AXIS_ANGLE:
                continue
            rel = pb - pa
            axial = float(np.dot(rel, ua))
            if abs(axial) >= (wa + wb) / 2 - tol:
                continue  # side by side along the axis: different planes
            d = float(np.linalg.norm(rel - axial * ua))
            d = d if d > 1e-12 else 0.0  # coaxial (round-off of the placement)
            if not meet(d, ia, oas[1], ib, obs[1]):
                continue
            k = 0 if meet(d, ia, oas[0], ib, obs[0]) else 1
            pairs.append(((a, ia, oas[k]), (b, ib, obs[k]), d, k == 0))
    return pairs


def _overlap_issue(model: Model, first, second, d: float) -> tuple[str, str]:
    """(location, message) for two overlapping gears; the one to move is the second, or
    the external gear in a ring."""
    (a, ia, oa), (b, ib, ob) = first, second
    ring = [n for n, inner in ((a, ia), (b, ib)) if inner > 0]
    move = b if len(ring) != 1 or ring[0] == a else a
    other = a if move == b else b
    if (model.written_at(f"gears.{move}").startswith("planetary.")
            and not model.written_at(f"gears.{other}").startswith("planetary.")):
        move = other  # a gear of the user's own, not one a [[planetary]] stage placed
    fix = f"check gears.{move}.place / position"
    plane = "with their faces in the same plane"
    if not ring:
        return (f"gears.{move}", f"gears {a} and {b} overlap: centre distance {d * 1e3:.4g} mm "
                                 f"< sum of tip radii {(oa + ob) * 1e3:.4g} mm {plane}; {fix}")
    if len(ring) == 1:
        r = ring[0]
        ra, rf, tip = (ia, oa, ob) if r == a else (ib, ob, oa)
        given = not _rim_assumed(model.gears[r])
        part, rim = ("teeth or rim", "outer radius of its rim") if given else ("teeth",
                                                                             "root radius")
        return (f"gears.{move}", (
            f"gears {a} and {b} overlap: {move} (tip radius {tip * 1e3:.4g} mm, centre "
            f"{d * 1e3:.4g} mm from {r}'s) reaches into the {part} of internal gear {r} "
            f"(tip radius {ra * 1e3:.4g} mm, {rim} {rf * 1e3:.4g} mm) {plane}; {fix}"))
    return (f"gears.{move}", (
        f"gears {a} and {b} overlap: these internal gears (radii "
        f"{ia * 1e3:.4g}-{oa * 1e3:.4g} mm and {ib * 1e3:.4g}-{ob * 1e3:.4g} mm, centres "
        f"{d * 1e3:.4g} mm apart) intersect {plane}; {fix}"))


def _axially_located(model: Model) -> set[str]:
    """Gears whose plane the file states: a given position, or placed (by 'place' or
    next to a mate) from such a gear.  A gear on a shaft without a position takes the
    centre of a body on that shaft (kinematics ``_layout``), so its axial position is a
    stand-in, and so is that of the gears it meshes with, directly or through other
    cylindrical meshes (a planar model that gives every position with z = 0): their
    overlaps cannot be judged."""
    gears = model.gears
    joined = {b for s in list(model.shafts.values()) + list(model.splines.values())
              for b in s.connects}
    mates: dict[str, set[str]] = {n: set() for n in gears}
    for m in model.meshes.values():
        a, b = m.gears
        if a in mates and b in mates:
            mates[a].add(b)
            mates[b].add(a)
    known = {n for n, g in gears.items() if g.position is not None}
    if not known and gears:  # nothing given: the layout anchors the first gear
        first = next(iter(gears))
        if gears[first].place is None and first not in joined:
            known.add(first)
    grew = True
    while grew:
        grew = False
        for n, g in gears.items():
            if n in known:
                continue
            if g.place is not None:
                ok = g.place.from_gear in known
            else:
                ok = g.position is None and n not in joined and bool(mates[n] & known)
            if ok:
                known.add(n)
                grew = True
    # meshing gears share a plane: a stand-in plane makes that of its whole train one
    flat = {n for n, g in gears.items() if g.gear_type not in ("bevel", "face")}
    stack = [n for n in gears if n not in known]
    while stack:
        for mate in mates.get(stack.pop(), ()):
            if mate in known and mate in flat:
                known.discard(mate)
                stack.append(mate)
    return known


def _shaft_lines(model: Model) -> dict[str, str]:
    """Body -> a representative of the bodies joined to it by shafts and splines."""
    parent = {n: n for n in model.body_names()}

    def root(n):
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for s in list(model.shafts.values()) + list(model.splines.values()):
        a, b = s.connects
        if a in parent and b in parent:
            parent[root(a)] = root(b)
    return {n: root(n) for n in parent}


def _mm(p) -> str:
    return "(" + ", ".join(f"{1e3 * float(v):.4g}" for v in p) + ") mm"


def _position_given(model: Model, name: str) -> bool:
    """The position of a body is known: a gear always (given, placed or computed from
    its mates), another body when its file gives 'position'."""
    if name in model.gears:
        return True
    return "position" in model.bodies[name].model_fields_set


#: errors beyond the tolerance of the grade a gear states, by more than this factor
#: (one grade step of ISO 1328-1), are flagged
GRADE_MARGIN = math.sqrt(2.0)
#: backlash above this many times the ISO/TR 10064-2 minimum is flagged
BACKLASH_RATIO = 10.0
#: a support clearance above this fraction of the gear's pitch diameter is flagged
#: (rolling-bearing radial clearances are a few thousandths of the bore at most)
CLEARANCE_FRACTION = 5e-3


def tolerance_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Errors, clearances and backlash against the gear's size and ISO tolerances.

    * eccentricity (a runout of twice its size), installation error and bearing runout
      against the ISO 1328-1 runout tolerance F_rT of the gear at grade 11, the coarsest,
      and (not the installation error: a housing's bore position, which the gear's grade
      does not bound) at the grade the file states (``errors.grade``, one grade step of
      margin);
    * total cumulative pitch deviation (``pitch``) against F_pT the same way;
    * a planet pin position error (as an installation error, a runout of twice its
      size) and the eccentricity of the carrier that holds the gear against F_rT of the
      gear at grade 11;
    * backlash against ten times the minimum of ISO/TR 10064-2,
      j_bn,min = 2/3 (0.06 + 0.0005 a + 0.03 m_n) mm;
    * support clearance against half a percent of the pitch diameter.
    """
    from ..gears import grades
    from .kinematics import gear_geometry

    out = []
    # (a first-hour user's errors = {grade = 6} ran error-free, LSC 1.0000, without a word)
    graded = [n for n, g in model.gears.items() if g.errors.grade is not None
              and not any(getattr(g.errors, f) for f in GEAR_ERROR_FIELDS)]
    if graded:
        out.append((f"gears.{graded[0]}.errors.grade", (
            f"a grade alone gives {', '.join(graded)} no error (the errors are all 0): the "
            f"grade checks the errors given against ISO 1328-1 and bounds a study's sampling "
            f"of them (a monte_carlo parameter with distribution 'iso1328', docs/studies.md);"
            f" give the errors (eccentricity, pitch, ...) to run with them")))
    for name, g in model.gears.items():
        e = g.errors
        try:
            d = 2 * gear_geometry(g).reference_radius
        except (ModelError, ValueError, ArithmeticError):  # pragma: no cover
            continue
        loc = f"gears.{name}"
        stated = e.grade if e.grade is not None and 1 <= e.grade <= 11 else None
        for field, value, kind, what in (
                ("eccentricity", 2 * e.eccentricity, "runout", "a runout of"),
                ("installation", 2 * e.installation, "runout", "as a runout:"),
                ("bearing_runout", e.bearing_runout, "runout", ""),
                ("pitch", e.pitch, "pitch", "")):
            if not value > 0:
                continue
            try:
                tol = (grades.runout_tolerance if kind == "runout"
                       else grades.total_cumulative_pitch_tolerance)
                coarsest = tol(11, g.module, d)
                # the gear's grade bounds the gear, not the bore that holds it: an
                # installation error gets the unit-slip check of grade 11 only
                own = tol(stated, g.module, d) if stated and field != "installation" else None
            except ModelError:
                continue  # outside the standard's scope: the size checks apply
            name_tol = ("runout tolerance F_rT" if kind == "runout"
                        else "total cumulative pitch tolerance F_pT")
            size = (f"{_length_text(value / 2)} ({what} {_length_text(value)})" if what
                    else _length_text(value))
            where = f"d = {d * 1e3:.4g} mm, m_n = {g.module * 1e3:.4g} mm"
            if value > coarsest:
                out.append((f"{loc}.errors.{field}", (
                    f"{size} is beyond the ISO 1328-1 {name_tol} of the coarsest grade, "
                    f"11 ({coarsest * 1e6:.4g} um for {where}); errors are microns: check "
                    f"the value and its unit (a bare number is read in m)")))
            elif own is not None and value > GRADE_MARGIN * own:
                out.append((f"{loc}.errors.{field}", (
                    f"{size} is more than one grade beyond the ISO 1328-1 {name_tol} of "
                    f"grade {stated}, which errors.grade states ({own * 1e6:.4g} um for "
                    f"{where}); correct the value or the grade")))
        if g.support is not None and g.support.clearance > CLEARANCE_FRACTION * d:
            out.append((f"{loc}.support.clearance", (
                f"{g.support.clearance * 1e6:.4g} um is {g.support.clearance / d * 100:.2g} % "
                f"of the pitch diameter ({d * 1e3:.4g} mm); bearing clearances are a few "
                f"thousandths of the bore at most: check the value and its unit")))
    out += _seat_tolerance_warnings(model, kin)
    for name, m in model.meshes.items():
        mk = kin.meshes.get(name)
        bl = m.backlash.nominal + m.backlash.tolerance
        if mk is None or not bl > 0 or not (mk.center_distance and
                                             math.isfinite(mk.center_distance)):
            continue
        mn = min(model.gears[x].module for x in m.gears)
        j_min = 2 / 3 * (0.06 + 0.0005 * mk.center_distance * 1e3 + 0.03 * mn * 1e3) * 1e-3
        if bl > BACKLASH_RATIO * j_min:
            out.append((f"meshes.{name}.backlash", (
                f"{bl * 1e6:.4g} um is {bl / j_min:.3g} times the minimum backlash of ISO/TR "
                f"10064-2 for this mesh ({j_min * 1e6:.3g} um at a = "
                f"{mk.center_distance * 1e3:.4g} mm, m_n = {mn * 1e3:.4g} mm); backlash is "
                f"tens to hundreds of microns: check the value and its unit")))
    return out


def _seat_tolerance_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Pin position errors of gears and eccentricities of the bodies that hold them,
    beyond F_rT of the gear at grade 11 (each moves the gear like an installation error:
    a runout of twice its size); a carrier is compared with its finest-toleranced gear."""
    from ..gears import grades
    from .kinematics import gear_geometry

    seats: dict[str, list] = {}  # field -> [value, what, tolerance, gear, d]
    for name, g in model.gears.items():
        if g.support is None:
            continue
        try:
            d = 2 * gear_geometry(g).reference_radius
            tol = grades.runout_tolerance(11, g.module, d)
        except (ModelError, ValueError, ArithmeticError):
            continue  # outside the standard's scope: the size checks apply
        fields = [(f"gears.{name}.support.pin_error.{f}", getattr(g.support.pin_error, f),
                   "pin position errors") for f in ("radial", "tangential")]
        body = model.bodies.get(g.support.on) if g.support.on else None
        if body is not None:
            fields.append((f"bodies.{g.support.on}.eccentricity", body.eccentricity,
                           "carrier eccentricities"))
        for loc, value, what in fields:
            if value and math.isfinite(value) and (loc not in seats or tol < seats[loc][2]):
                seats[loc] = [value, what, tol, name, d]
    out = []
    for loc, (value, what, tol, name, d) in seats.items():
        if 2 * abs(value) > tol:
            m_n = model.gears[name].module
            out.append((loc, (
                f"{_length_text(abs(value))} (as a runout: {_length_text(2 * abs(value))}) "
                f"is beyond the ISO 1328-1 runout tolerance F_rT of the coarsest grade, 11, "
                f"of {name} ({tol * 1e6:.4g} um for d = {d * 1e3:.4g} mm, m_n = "
                f"{m_n * 1e3:.4g} mm); {what} are microns: check the value and its unit (a "
                f"bare number is read in m)")))
    return out


#: a length more than this many times the largest gear (or less than its inverse) is
#: flagged as a probable unit mistake
SIZE_RATIO = 100.0
#: a given mass or polar inertia outside [1/r, r] times the gear's solid-disc value (an
#: inertia may include the gear's shaft: Dong et al. 2021's pinion has 22 times its disc's)
INERTIA_RATIO = 100.0
#: pitch-line speed beyond which gears do not run [m/s] (turbine gears reach ~200): a
#: speed in rpm or Hz written as a bare number (read in rad/s) usually crosses it
MAX_PITCH_SPEED = 300.0
#: tooth load per face width beyond what steel teeth carry [N/m] (10 kN/mm)
MAX_LOAD_PER_WIDTH = 1e7
#: [N/m] a nominal tooth force below this per face width is warned (the shipped examples:
#: 14.7 N/mm and more; a power in W for kW gave 0.8 N/mm)
MIN_LOAD_PER_WIDTH = 2e3
#: [rad] a shaft misalignment beyond this is warned (gear shafts tilt by mrad at most)
MAX_SHAFT_MISALIGNMENT = 0.01
#: a tooth modification amount (relief, crowning, helix slope) above this fraction of the
#: module is flagged: modifications remove a few to tens of microns (tip relief of the
#: order of the tooth deflection, 0.01-0.02 m_n for heavily loaded teeth)
MODIFICATION_MODULE_RATIO = 0.05


def magnitude_warnings(model: Model, kin) -> list[tuple[str, str]]:
    """Sizes that are possible but usually a unit mistake ("560 parsec" for a shaft).

    Lengths are compared with the gears' size (the largest pitch diameter ``D``), errors,
    clearances, pin position errors and eccentricities with the module, tooth
    modifications with :data:`MODIFICATION_MODULE_RATIO` of the module, a given mass or
    inertia with the gear's solid-disc value, speeds and tooth loads with what gears
    carry.  Each names the field.
    """
    from .kinematics import gear_geometry

    out = []
    diameters = {}
    for name, g in model.gears.items():
        try:
            diameters[name] = 2 * gear_geometry(g).reference_radius
        except (ModelError, ValueError, ArithmeticError):  # pragma: no cover - checked before
            continue
    if not diameters:
        return out
    size = max(diameters.values())
    size_text = f"the largest gear's pitch diameter ({size * 1e3:.4g} mm)"

    def against_size(loc, value, small=True):
        if value is None or value == 0 or not math.isfinite(value):
            return
        ratio = abs(value) / size
        if ratio > SIZE_RATIO or (small and ratio < 1 / (100 * SIZE_RATIO)):
            out.append((loc, f"{abs(value):.4g} m is {ratio:.3g} times {size_text}; check the "
                             f"value and its unit (a bare number is read in m)"))

    def against_module(loc, value, module, what):
        if value and math.isfinite(value) and abs(value) > module:
            out.append((loc, f"{_length_text(abs(value))} is larger than the module "
                             f"({module * 1e3:.4g} mm); {what} are microns: check the value "
                             f"and its unit (a bare number is read in m: write '20 um')"))

    for name, g in model.gears.items():
        loc = f"gears.{name}"
        if g.module > 0.1 or g.module < 5e-5:
            out.append((f"{loc}.module", f"{g.module * 1e3:.4g} mm is outside the modules "
                                         f"gears are made with (0.05-100 mm); check the value "
                                         f"and its unit (a bare number is read in m: "
                                         f"module = 3 means 3 m; write '3 mm')"))
        d = diameters.get(name)
        if 0 < g.face_width < g.module:  # (b/m is 5-40 on gears that are made)
            out.append((f"{loc}.face_width", (
                f"{_length_text(g.face_width)} is {g.face_width / g.module:.3g} times the "
                f"module ({g.module * 1e3:.4g} mm), where gears have face widths of a few "
                f"modules or more; check the value and its unit (a bare number is read in "
                f"m: write '60 mm')")))
        if d and g.face_width > 10 * d:
            out.append((f"{loc}.face_width", f"{g.face_width * 1e3:.4g} mm is "
                                             f"{g.face_width / d:.3g} times the pitch diameter "
                                             f"({d * 1e3:.4g} mm); check the value and its unit"))
        if g.position is not None:
            for axis, v in zip("xyz", g.position):
                against_size(f"{loc}.position", v, small=False)
        e = g.errors
        for field in ("eccentricity", "installation", "tooth_thickness", "pitch",
                      "bearing_runout"):
            against_module(f"{loc}.errors.{field}", getattr(e, field), g.module,
                           "manufacturing and assembly errors")
        if g.support is not None:
            against_module(f"{loc}.support.clearance", g.support.clearance, g.module,
                           "bearing clearances")
            for field in ("radial", "tangential"):
                against_module(f"{loc}.support.pin_error.{field}",
                               getattr(g.support.pin_error, field), g.module,
                               "pin position errors ([[planetary]] pin_errors)")
            if g.support.shaft is not None:
                for field in ("diameter", "span", "position"):
                    against_size(f"{loc}.support.shaft.{field}",
                                 getattr(g.support.shaft, field))
        out += _modification_warnings(loc, g)
        body = kin.bodies.get(name)
        if body is not None and d:
            m_geo, j_geo = _disc_mass_inertia(g, d)
            translates = any(dof != "theta" for dof in g.dofs)
            for field, given, ref, unit in (("mass", g.mass, m_geo, "kg"),
                                            ("polar_inertia", g.polar_inertia, j_geo, "kg m^2")):
                if given is None or not ref > 0 or (field == "mass" and not translates):
                    continue  # a mass without translations is a placeholder: not used
                ratio = given / ref
                if not 1 / INERTIA_RATIO <= ratio <= INERTIA_RATIO:
                    out.append((f"{loc}.{field}", (
                        f"{given:.4g} {unit} is {ratio:.3g} times that of a solid steel disc "
                        f"of the gear's pitch diameter and face width ({ref:.4g} {unit}); "
                        f"check the value and its unit")))
            w = abs(body.speed)
            if w * d / 2 > MAX_PITCH_SPEED:
                out.append((loc, f"runs at a pitch-line speed of {w * d / 2:.4g} m/s (the "
                                 f"fastest gears run about 200 m/s); check the drive's "
                                 f"speed and its unit (a bare number is read in rad/s: "
                                 f"write '3000 rpm' or '50 Hz')"))
    for name, b in model.bodies.items():
        against_size(f"bodies.{name}.position", max(abs(v) for v in b.position), small=False)
        # the planets on a carrier set the scale of its eccentricity, else any gear
        held = [g.module for g in model.gears.values()
                if g.support is not None and g.support.on == name]
        against_module(f"bodies.{name}.eccentricity", b.eccentricity,
                       min(held or [g.module for g in model.gears.values()]),
                       "carrier eccentricities")
    for name, sh in model.shafts.items():
        for field in ("diameter", "length"):
            against_size(f"shafts.{name}.{field}", getattr(sh, field))
    light = []  # (nominal tooth force per face width, mesh) below MIN_LOAD_PER_WIDTH
    for name, m in model.meshes.items():
        module = min(model.gears[x].module for x in m.gears)
        bl = m.backlash
        against_module(f"meshes.{name}.backlash", bl.nominal + bl.tolerance, module,
                       "backlashes")
        te = m.transmission_error
        against_module(f"meshes.{name}.transmission_error", abs(te.constant) + te.amplitude,
                       module, "transmission errors")
        # (a designer's lead_mismatch = 0.002 (2 mm) and 0.2 rad of tilt ran unwarned)
        mis = m.misalignment
        for field in ("lead_mismatch", "base_pitch_deviation"):
            value = abs(getattr(mis, field))
            if value > MODIFICATION_MODULE_RATIO * module:  # (as tooth modifications)
                out.append((f"meshes.{name}.misalignment.{field}", (
                    f"{_length_text(value)} is {value / module:.3g} times the module "
                    f"({module * 1e3:.4g} mm); lead and pitch deviations are microns (rarely "
                    f"over {MODIFICATION_MODULE_RATIO:g} m_n): check the value and its unit "
                    f"(a bare number is read in m: write '20 um')")))
        if abs(mis.shaft_misalignment) > MAX_SHAFT_MISALIGNMENT:
            out.append((f"meshes.{name}.misalignment.shaft_misalignment", (
                f"{abs(mis.shaft_misalignment) * 1e3:.3g} mrad "
                f"({math.degrees(abs(mis.shaft_misalignment)):.3g} deg) is more than gear "
                f"shafts tilt (at most a few mrad); check the value and its unit (a bare "
                f"number is read in rad: write '0.5 mrad' or '0.03 deg')")))
        mk = kin.meshes.get(name)
        if mk is not None and mk.force > 0:
            width = min(model.gears[x].face_width for x in m.gears)
            if mk.force / width > MAX_LOAD_PER_WIDTH:
                out.append((f"meshes.{name}", (
                    f"carries {mk.force / width / 1e3:.4g} N/mm of face width (steel teeth "
                    f"carry up to about 2000 N/mm); check the drive's torque or power, "
                    f"the gears' face_width and their units")))
            elif mk.force / width < MIN_LOAD_PER_WIDTH:
                light.append((mk.force / width, name))
    if light:  # (one line: every mesh of a 1000-times-too-small drive is light)
        load, name = min(light)
        others = f" (the least of {len(light)} meshes this light)" if light[1:] else ""
        out.append((f"meshes.{name}", (
            f"carries {load / 1e3:.3g} N/mm of face width{others}, where loaded gears carry "
            f"about 50-2000 N/mm: a drive's power or torque in the wrong unit? (a bare number "
            f"is read in W or N m: write '5 MW'); a light load on purpose (rattle, idling) "
            f"can be accepted")))
    for name, sp in model.splines.items():
        against_size(f"splines.{name}.pitch_radius", sp.pitch_radius)
        if sp.radial_clearance > sp.pitch_radius:
            out.append((f"splines.{name}.radial_clearance", (
                f"{sp.radial_clearance * 1e3:.4g} mm is larger than the pitch radius "
                f"({sp.pitch_radius * 1e3:.4g} mm); check the value and its unit")))
    return out


def _flanks(loc: str, gear):
    """(flank modification, its location) of a gear's helices that have one."""
    spec = gear.modifications
    if spec is None:
        return []
    return [(f, w) for f, w in ((spec, f"{loc}.modifications"),
                                (spec.second_helix, f"{loc}.modifications.second_helix"))
            if f is not None]


def _modification_amounts(loc: str, gear) -> list[tuple[str, float]]:
    """(field, amount [m]) of every tooth modification of a gear (both helices)."""
    out = []
    for flank, where in _flanks(loc, gear):
        amounts = [("crowning", flank.crowning), ("helix_slope", flank.helix_slope)]
        for name in ("tip_relief", "root_relief", "end_relief"):
            if getattr(flank, name) is not None:
                amounts.append((f"{name}.amount", getattr(flank, name).amount))
        if flank.topological is not None:
            amounts += [(f"topological.{y}", getattr(flank.topological, y))
                        for y in ("y1", "y2", "y5")]
        out += [(f"{where}.{field}", value) for field, value in amounts]
    return out


#: a tip or root relief zone shorter than this share of the module is a unit slip
#: ('6 um' for '6 mm': the relief then does nothing, and nothing was said)
RELIEF_LENGTH_MODULE_RATIO = 0.02


def _modification_warnings(loc: str, gear) -> list[tuple[str, str]]:
    """Tooth modification amounts above :data:`MODIFICATION_MODULE_RATIO` of the module,
    relief zones shorter than :data:`RELIEF_LENGTH_MODULE_RATIO` of it."""
    limit = MODIFICATION_MODULE_RATIO * gear.module
    out = []
    for field, value in _modification_amounts(loc, gear):
        if math.isfinite(value) and abs(value) > limit:
            out.append((field, (
                f"{_length_text(abs(value))} is {abs(value) / gear.module:.3g} times the "
                f"module ({gear.module * 1e3:.4g} mm); tooth modifications remove a few "
                f"to tens of microns (rarely over {MODIFICATION_MODULE_RATIO:g} m_n): "
                f"check the value and its unit (a bare number is read in m: write "
                f"'15 um')")))
    for flank, where in _flanks(loc, gear):
        for name in ("tip_relief", "root_relief"):
            relief = getattr(flank, name)
            for zone in ("length", "height"):
                value = getattr(relief, zone, None) if relief is not None else None
                if value and value < RELIEF_LENGTH_MODULE_RATIO * gear.module:
                    out.append((f"{where}.{name}.{zone}", (
                        f"{_length_text(value)} is {value / gear.module:.2g} times the module "
                        f"({gear.module * 1e3:.4g} mm): a relief zone this short does "
                        f"nothing; relief {zone}s are millimetres (about 0.3-1 m_n): check "
                        f"the value and its unit (write e.g. '3 mm')")))
    return out


def _length_text(value: float) -> str:
    """A length for a message in the unit that reads best (um, mm or m)."""
    if value >= 1.0:
        return f"{value:.4g} m"
    if value >= 1e-3:
        return f"{value * 1e3:.4g} mm"
    return f"{value * 1e6:.4g} um"


def _disc_mass_inertia(gear, d: float) -> tuple[float, float]:
    """Mass and polar inertia of a solid steel disc of pitch diameter ``d`` and the
    gear's face width (both helices of a double-helical gear), less its bore."""
    width = gear.face_width * (2 if gear.gear_type == "double_helical" else 1)
    di = min(gear.bore_diameter, 0.9 * d)
    mass = 7850.0 * math.pi * (d**2 - di**2) / 4 * width
    return mass, mass * (d**2 + di**2) / 8


# --------------------------------------------------------------------------- what run needs
def nominal_load_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Every mesh must carry a nominal load: its load-sharing coefficient and dynamic
    factor are ratios to it.  A mesh carries none when no power passes it on its way
    from a drive to a load (a load on the drive's own body, say)."""
    issues = []
    same = sorted({d.body for d in model.drives.values()}
                  & {ld.body for ld in model.loads.values()})
    for name, mk in kin.meshes.items():
        if mk.force > 0 and math.isfinite(mk.force):
            continue
        why = (f"the load acts on the driven body {same[0]!r} itself, so no power passes the "
               f"gears" if same else "no power passes it on its way from a drive to a load")
        issues.append((f"meshes.{name}", (
            f"carries no nominal load ({why}); its load sharing and dynamic factor would "
            f"divide by zero: put the loads where the power must pass the meshes, or "
            f"remove the mesh")))
    return issues


#: a gear's given mass or inertia beyond these multiples of a steel disc of its size is a
#: unit slip (kg mm^2 for kg m^2 is 1e6; a shaft or rotor counted with a gear stays below
#: 1e4, the shipped examples below 25), or a stand-in value (1e-30) that breaks the statics
MASS_RATIO = (1e-8, 1e4)


def _mass_magnitudes(model: Model) -> list[tuple[str, str]]:
    """Given masses and inertias of gears far from those of a steel disc of their size
    (a reviewer's 1e-30 kg m^2 ended in a message about unbalanced torques)."""
    from .kinematics import gear_mass_properties

    out = []
    for name, gear in model.gears.items():
        if gear.mass is None and gear.polar_inertia is None:
            continue
        try:
            m_disc, j_disc, _, _ = gear_mass_properties(
                gear.model_copy(update={"mass": None, "polar_inertia": None}))
        except (ModelError, ValueError, ZeroDivisionError):
            continue  # (the geometry checks name it)
        for field, given, disc, unit in (("mass", gear.mass, m_disc, "kg"),
                                         ("polar_inertia", gear.polar_inertia, j_disc,
                                          "kg m^2")):
            if given is None or not disc > 0:
                continue
            ratio = given / disc
            if not MASS_RATIO[0] <= ratio <= MASS_RATIO[1]:
                out.append((f"gears.{name}.{field}", (
                    f"{given:.3g} {unit} is {ratio:.3g} times that of a steel disc of this "
                    f"gear's size ({disc:.3g} {unit}); check the value and its unit")))
    return out


def _locked_speed_drives(model: Model) -> list[tuple[str, str]]:
    """Two speed drives on one gear train (:func:`_trains`): the train's speed
    is prescribed twice, so the torque between them is undetermined and the meshes between
    carry no load (a reviewer's pair: static force 0, load sharing NaN, no word)."""
    trains = _trains(_adjacency(model))
    by_train: dict[int, list[str]] = {}
    for name, d in model.drives.items():
        if d.mode == "speed":
            k = next((i for i, comp in enumerate(trains) if d.body in comp), None)
            if k is not None:
                by_train.setdefault(k, []).append(name)
    return [(f"drives.{names[1]}.mode", (
        f"drives.{names[0]} and drives.{names[1]} both prescribe the speed of one gear "
        f"train: the torque between them is undetermined and the meshes between them carry "
        f"no load; make all but one of them torque drives (mode = \"torque\")"))
        for names in by_train.values() if len(names) > 1]


def _friction_drift(model: Model) -> list[tuple[str, str]]:
    """Tooth friction with torque drives and a 'balanced' load of no speed dependence:
    the load takes the whole input power, friction takes some too, so the train slows
    down over the run (a reviewer's pair: 33 % below nominal speed after 0.3 s)."""
    friction = [n for n, m in model.meshes.items() if m.friction is not None]
    if not friction or any(d.mode != "torque" for d in model.drives.values()):
        return []
    return [(f"loads.{n}.torque", (
        f"'balanced' takes the whole input power, but the tooth friction of "
        f"{', '.join('meshes.' + m for m in friction)} dissipates some of it: the train "
        f"decelerates over the run (the mesh forces follow the nominal mesh phase and are "
        f"not affected, the speeds and the power balance are); give the load a "
        f"speed_coefficient (dT/dw, as a rotor or fan has) or drive a body at a held "
        f"speed (mode = \"speed\")"))
        for n, load in model.loads.items()
        if load.torque is None and not load.speed_coefficient]


def planet_drive_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Drives and loads on a planet of a turning carrier: its spin is relative to the
    carrier, so the power it puts in or takes is not its torque x its speed (a balanced
    load on one was told only that the power did not balance, to set it 'balanced')."""
    from .kinematics import support_frame

    issues = []
    for kind, items in (("drives", model.drives), ("loads", model.loads)):
        for name, x in items.items():
            carrier, _, turning = support_frame(kin, x.body)
            gear = model.gears.get(x.body)
            on = gear.support.on if gear is not None and gear.support is not None else None
            if carrier and turning and on == carrier:
                issues.append((f"{kind}.{name}.body", (
                    f"{x.body!r} is a planet of the turning carrier {carrier!r}: it spins "
                    f"about its pin while the pin orbits, so the power a {kind[:-1]} there "
                    f"exchanges is not its torque times its speed, and the power flow "
                    f"cannot be balanced; put the {kind[:-1]} on the sun, the ring or the "
                    f"carrier")))
    return issues


def balance_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Drive and load torques must balance to :data:`BALANCE_TOLERANCE`, the tolerance
    of the static equilibrium that starts every run.

    Applies to torque-driven models without tooth friction (with friction the loads may
    take the losses off; a prescribed speed takes any torque): those are checked by the
    static equilibrium itself (:func:`readiness_issues`).
    """
    if any(m.friction is not None for m in model.meshes.values()):
        return []
    if any(d.mode != "torque" for d in model.drives.values()):
        return []
    p_in, p_out = kin.input_power, kin.output_power
    total = abs(p_in) + abs(p_out)
    if total > 0 and abs(p_in - p_out) > BALANCE_TOLERANCE * total:
        return [("loads", (
            f"power does not balance to within {100 * BALANCE_TOLERANCE:g} % (the tolerance "
            f"of the static equilibrium that starts every run): the drives put in "
            f"{p_in:.10g} W and the loads take {p_out:.10g} W "
            f"({100 * abs(p_in - p_out) / total:.3g} % of the power through the train); set a "
            f"load's torque to \"balanced\" or correct the torques"))]
    return []


def planet_fit_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Planets whose teeth cannot mesh with their sun and ring at their angles (the
    tooth-count assembly condition, checked as the closure of the mesh phases around
    every loop through a planet: :func:`torquesplit.assembly.excitation.mesh_phases`)."""
    if not kin.carriers:
        return []
    from ..assembly.excitation import mesh_phases

    try:
        mesh_phases(model, kin, strict=True)
    except ModelError as exc:
        return list(exc.issues)
    return []


#: stiffness methods whose table is cheap to evaluate here (the others are evaluated by
#: the assembly, in :func:`readiness_issues`)
_CHEAP_STIFFNESS = ("constant", "table", "fourier")


def stiffness_table_issues(model: Model, kin) -> list[tuple[str, str]]:
    """Each mesh's stiffness table, sampled as every run samples it
    (``[analysis] table_points`` phases), must be positive and finite everywhere."""
    from ..assembly.excitation import stiffness_table, table_points

    issues = []
    n = table_points(model, kin)
    for name, mesh in model.meshes.items():
        if mesh.stiffness.method not in _CHEAP_STIFFNESS:
            continue
        loc = f"meshes.{name}.stiffness"
        try:
            with np.errstate(all="ignore"):
                k = np.asarray(stiffness_table(model, kin, name, n), dtype=float)
        except ValueError:  # the Fourier series becomes negative: said below
            k = None
        if k is not None and np.all(np.isfinite(k)) and np.all(k > 0):
            continue
        spec = mesh.stiffness
        if spec.method == "fourier":
            fix = ("make 'mean' larger than the sum of the coefficients' sizes, or correct "
                   "the coefficients")
        elif spec.method == "constant":
            fix = ("the step between single and double contact is too large: give a smaller "
                   "'peak_to_peak' (typical 0.2-0.5)")
        else:
            fix = "correct the values"
        if k is None:
            kmin = "it goes to zero or below"
        elif np.isfinite(k).any():
            kmin = f"its smallest value is {np.nanmin(k):.4g} N/m"
        else:
            kmin = "it is not a finite number"
        issues.append((loc, f"the stiffness over the mesh cycle must be positive, but "
                            f"{kmin} (at {n} phases, as a run samples it); {fix}"))
    return issues


def readiness_issues(model: Model, kin=None) -> list[tuple[str, str]]:
    """What every dynamic run does before it integrates, run here: the assembly of the
    equations of motion (every stiffness table, support and spline) and the static
    equilibrium it starts from.  Their refusals come back as (location, message).

    A static deflection beyond what the integrator accepts (its ``blowup``) is refused
    too: every run of such a model diverges at its first step.  A model that passes is
    refused by ``run`` for a numerical reason only (the step, the cost, a diverging
    integration), never for a modelling one.
    """
    return _readiness(model, kin)[0]


def _readiness(model: Model, kin=None) -> tuple[list, list]:
    """(issues, warnings) of :func:`readiness_issues`."""
    from ..assembly.assemble import assemble
    from ..solve.static import static_equilibrium
    from .kinematics import solve_kinematics

    kin = kin or solve_kinematics(model)
    try:
        with np.errstate(all="ignore"):
            structure = assemble(model, kin)
    except ModelError as exc:
        return [(loc, _teach(msg)) for loc, msg in exc.issues] or [
            ("", "cannot be assembled; check the model")], []
    except (ValueError, ArithmeticError) as exc:
        return [_located(str(exc), "the equations of motion cannot be assembled")], []
    try:
        with np.errstate(all="ignore"):
            static = static_equilibrium(structure)
    except SolverError as exc:
        loc, msg = _located(str(exc), "the static equilibrium that starts every run fails")
        # a mass or inertia off by orders of magnitude is the likelier cause: said first
        return _mass_magnitudes(model) + [(loc or "loads", msg)], []
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return (_mass_magnitudes(model)
                + [_located(str(exc), "the static equilibrium that starts every run fails")]), []
    q = np.asarray(static.q, dtype=float)
    if not np.all(np.isfinite(q)):
        return [("", "the static equilibrium that starts every run has no finite solution; "
                     "check the clearances and the supports (a body free to move inside its "
                     "clearance needs a support or a spring)")], []
    if q.size == 0:
        return [], []
    names = structure.dof_names
    j = int(np.argmax(np.abs(q)))
    body, _, dof = names[j].rpartition(".")
    loc = f"{'gears' if body in model.gears else 'bodies'}.{body}"
    unit = "rad" if dof == "theta" else "m"
    blowup = integrator_blowup()
    if abs(q[j]) > blowup:
        return [(loc, f"the static equilibrium that starts every run displaces "
                      f"'{names[j]}' by {abs(q[j]):.3g} {unit}, beyond what any run "
                      f"accepts ({blowup:g}): a stiffness is far too small for the load; "
                      f"check the stiffness values and their units (shafts, supports, "
                      f"meshes)")], []
    from ..convergence import coarse_table_warning

    coarse = coarse_table_warning(model, structure)  # (what every run warns of)
    notes = [tuple(coarse.split(": ", 1))] if coarse else []
    found = _deflections(model, structure, q)  # (as every run refuses or warns of them)
    refused = [(loc, msg) for loc, msg, out in found if out]
    if refused:
        return refused, []
    return [], notes + [(loc, msg) for loc, msg, out in found if not out]


#: a gear's whole tooth depth in normal modules (ISO 53 basic rack: addendum 1, dedendum
#: 1.25): a static translation beyond it takes the teeth out of the mesh
TOOTH_DEPTH_MODULES = 2.25


def deflection_warnings(model, structure, q) -> list[tuple[str, str]]:
    """Translations of the static equilibrium ``q`` larger than half the module of their
    gear (or 1 mm for a body without teeth), up to the whole tooth depth (beyond it,
    :func:`deflection_issues` refuses): a support or shaft stiffness far too small for the
    load, usually a unit slip ('500 N/mm' for '500 N/um': a reviewer's pinion sat 21 mm
    off its centre without a word).  One message per body, at its largest DOF."""
    return [(loc, msg) for loc, msg, refused in _deflections(model, structure, q)
            if not refused]


def deflection_issues(model, structure, q) -> list[tuple[str, str]]:
    """Gears whose static translation exceeds their whole tooth depth
    (TOOTH_DEPTH_MODULES normal modules): the teeth would be out of the mesh, so no
    number of the run would mean anything (a reviewer's supports in N/m for N/mm moved
    an idler 26 mm, and the run printed a load-sharing table)."""
    return [(loc, msg) for loc, msg, refused in _deflections(model, structure, q) if refused]


def refuse_out_of_mesh(model, structure, q, *, warn: bool = False) -> None:
    """Raise the ModelError of :func:`deflection_issues`, if any: what ``run`` and
    ``static`` do with a static equilibrium that takes a gear out of its mesh (``check``
    lists it with the other problems).  ``warn``: say it as a warning instead, for the
    linear analyses (``modes``, ``steady``, ``sweep-speed``), which a study of a
    published linear model may take beyond it (Cooley & Parker's planets at 20000 rpm
    sit 4.8 mm out in the carrier frame)."""
    issues = as_written(model, deflection_issues(model, structure, q))
    if issues and warn:
        for loc, msg in issues:
            warn_user(f"{loc}: {msg}", ModelWarning)
    elif issues:
        raise ModelError(issues)


_GLOBAL = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def _plane_translation(gear, values: dict[str, float]) -> float:
    """The size of a gear's static translation in its plane [m]: its x, y, z translations
    as one vector with the component along its axis taken out (an axial float leaves a
    helical gear in mesh; the same translation must give the same verdict whatever the
    model's orientation: a reviewer's 6 mm at 45 deg passed where along y it was
    refused), and a translation along the line of action ('loa'), in the plane."""
    u = sum((v * np.asarray(_GLOBAL[d]) for d, v in values.items() if d in _GLOBAL),
            np.zeros(3))
    axis = np.asarray(gear.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm > 0.0:
        u = u - float(np.dot(u, axis)) / norm**2 * axis
    rest = sum(v * v for d, v in values.items() if d not in _GLOBAL)
    return math.sqrt(float(np.dot(u, u)) + rest)


def _deflections(model, structure, q) -> list[tuple[str, str, bool]]:
    """(location, message, refused) of every body translated more than its limit: its
    largest translation against half the module (1 mm without teeth); a gear's
    translation in its plane (:func:`_plane_translation`) against its tooth depth
    (refused)."""
    q = np.asarray(q, dtype=float)
    worst: dict[str, tuple[float, str]] = {}
    values: dict[str, dict[str, float]] = {}
    for name, value in zip(structure.dof_names, q):
        body, _, dof = str(name).rpartition(".")
        if dof == "theta" or not np.isfinite(value):
            continue
        values.setdefault(body, {})[dof] = float(value)
        if abs(value) > worst.get(body, (0.0, ""))[0]:
            worst[body] = (abs(value), dof)
    out = []
    for body, (size, dof) in worst.items():
        gear = model.gears.get(body)
        limit, what = ((0.5 * gear.module, f"half the module ({0.5e3 * gear.module:g} mm)")
                       if gear is not None else (1e-3, "1 mm"))
        if size <= limit:
            continue
        depth = TOOTH_DEPTH_MODULES * gear.module if gear is not None else math.inf
        plane = _plane_translation(gear, values[body]) if gear is not None else 0.0
        refused = plane > depth
        subject = f"{body}.{dof} is {1e3 * size:.4g} mm"
        if refused:
            subject = f"{body} in its plane is {1e3 * plane:.4g} mm"
            what = (f"the whole depth of its teeth ({depth * 1e3:.4g} mm): they would be out "
                    f"of the mesh, and no number of a run would mean anything")
        # a body that floats on a spline: the spline's stiffness or clearance is the
        # likelier cause (a fuzzer's spline of 1 N/m was blamed on gears.O4.support, a
        # table the file does not have)
        splines = [n for n, sp in model.splines.items() if body in sp.connects]
        supported = gear is not None and gear.support is not None
        where = (f"gears.{body}.support" if supported or (gear is not None and not splines)
                 else f"splines.{splines[0]}" if splines else f"bodies.{body}")
        cause = (f"the stiffness of spline {', '.join(splines)} far too small for the "
                 f"load, or its radial clearance too large"
                 + (f" (or the stiffness of {body}'s support or shaft)" if supported
                    else "") + "; check the values and units"
                 if splines else
                 "a support or shaft stiffness far too small for the load (or one far too "
                 "large for the static solution to resolve: a length in m for mm); check "
                 "its value and unit")
        out.append((where, (
            f"the static deflection of {subject}, more than "
            f"{what}: {cause} (a unit a thousand times too small gives this: N/m written "
            f"for N/mm, N/mm for N/um)"), refused))
    return out


def integrator_blowup() -> float:
    """The displacement at which the integrator stops a run (its ``blowup`` default; also
    used by the CLI to name the likely cause of a run that stopped)."""
    import inspect

    from ..solve.integrate import integrate

    default = inspect.signature(integrate).parameters.get("blowup")
    try:
        return float(default.default)
    except (AttributeError, TypeError, ValueError):  # pragma: no cover - signature changed
        return 1e3


_LOCATED = re.compile(r"^((?:gears|bodies|shafts|meshes|splines|drives|loads|analysis)"
                      r"\.[^:\s]+): (.*)$", re.S)


def _located(text: str, what: str) -> tuple[str, str]:
    """(location, message) from an exception text that may start with 'meshes.m1...: '."""
    m = _LOCATED.match(text.strip())
    loc, msg = (m.group(1), m.group(2)) if m else ("", f"{what}: {text.strip()}")
    msg = msg.rstrip(".")
    if ";" not in msg:
        msg = re.sub(r"\. ([A-Z])", lambda m: "; " + m.group(1).lower(), msg, count=1)
    return loc, _teach(msg)
