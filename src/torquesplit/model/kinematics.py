"""Nominal kinematics and statics of a model: layout, speeds, power flow, torques, forces.

This is the rigid-body solution about which the dynamic model vibrates:

* layout: each gear's centre and axis (given, placed from a mating gear, or
  inherited from the body it shares a shaft with);
* per mesh: the contact frame (pitch point, radial and tangential unit vectors of each
  gear), pitch and base radii, contact ratios, the line of action as a 3-D unit vector;
* speeds propagated from the first drive through meshes and shafts; a power-split loop
  whose paths give different speeds is an error (it could not turn);
* power flow with an equal split at every branching (the nominal design split), from
  which each mesh's driver, torque and tooth force follow.

All values SI.  Angles of rotation are signed about each body's own axis.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from .._memo import remember_last
from ..errors import ModelWarning, warn_user
from ..gears import line_of_action as loa
from ..gears.geometry import GearGeometry, PairGeometry
from ..gears.vectors import cross
from ..errors import KinematicsError  # noqa: F401 - re-exported
from .schema import Gear, Model




@dataclass(frozen=True)
class BodyKinematics:
    """Nominal state of one body."""

    name: str
    position: np.ndarray
    axis: np.ndarray
    speed: float
    """Signed angular speed about the body's axis [rad/s]."""
    torque: float
    """Torque magnitude carried through the body for the equal split [N m]."""
    power: float
    """Power through the body [W]."""
    mass: float
    polar_inertia: float
    mass_computed: bool
    inertia_computed: bool


@dataclass(frozen=True)
class MeshKinematics:
    """Nominal geometry and loading of one mesh."""

    name: str
    driver: str
    driven: str
    frequency: float
    """Mesh frequency [Hz]."""
    contact_point: np.ndarray
    line_of_action: np.ndarray
    """Unit vector of the force the driver exerts on the driven gear."""
    arm_driver: float
    """(rho x n) . a of the driver [m]: torque per unit mesh force about its axis."""
    arm_driven: float
    pitch_radii: tuple[float, float]
    base_radii: tuple[float, float]
    transverse_contact_ratio: float
    overlap_contact_ratio: float
    total_contact_ratio: float
    working_pressure_angle: float
    center_distance: float
    torque_driver: float
    """Torque the mesh takes from the driver for the equal split [N m]."""
    torque_driven: float
    force: float
    """Nominal normal tooth force along the line of action [N]."""
    power: float
    equivalent_mass: float
    """J1 J2 / (J1 rb2^2 + J2 rb1^2) [kg], the mesh's torsional equivalent mass."""
    critical_damping: float
    """2 sqrt(k m_eq) with the mean mesh stiffness (one computed at assembly: its ISO 6336
    estimate) [N s/m]; 0 where neither is known."""
    iso_stiffness: float | None
    """ISO 6336-1 estimate c_gamma * b [N/m] (cylindrical pairs only)."""
    conical: bool
    geometry: PairGeometry | None = field(default=None, repr=False, compare=False)
    carrier: str | None = None
    """The carrier in whose (rotating) frame the mesh is analysed; None: the housing."""
    driver_speed: float = math.nan
    """Signed speed of the driver about its axis in the mesh's frame [rad/s]."""
    driven_speed: float = math.nan
    """Signed speed of the driven gear about its axis in the mesh's frame [rad/s]."""


@dataclass(frozen=True)
class Kinematics:
    """The rigid-body (nominal) solution of a model."""

    bodies: dict[str, BodyKinematics]
    meshes: dict[str, MeshKinematics]
    input_power: float
    output_power: float
    load_torques: dict[str, float]
    """Resisting torque magnitude of each load [N m]."""
    drive_torques: dict[str, float]
    groups: dict[str, str]
    """Body -> representative of its rigid group (bodies joined by rigid shafts)."""
    positions_computed: list[str]
    translation_axes: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    """Body -> {translational DOF: its unit direction}: the global axes for x, y, z and
    the transverse line of action of the body's meshes for 'loa'."""
    carriers: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """Carrier body -> its planets (bodies whose bearing sits on it, off its axis)."""
    planet_bodies: dict[str, str] = field(default_factory=dict)
    """Body turning with a planet (the planet and the gears on its shaft) -> carrier."""
    frames: dict[str, str] = field(default_factory=dict)
    """Body -> carrier whose rotating frame its translations are measured in (bodies not
    listed: the housing's frame)."""
    held: tuple[str, ...] = ()
    """Bodies held against rotation by a torsional support (nominal speed zero)."""
    reactions: dict[str, float] = field(default_factory=dict)
    """Held body -> reaction torque of its torsional support about its axis [N m]."""

    def __repr__(self) -> str:
        """One line (the generated repr printed every body's and mesh's arrays)."""
        return (f"<Kinematics: {len(self.bodies)} bodies, {len(self.meshes)} meshes, "
                f"input {self.input_power / 1e3:.6g} kW; .bodies, .meshes, "
                f".drive_torques, .load_torques>")

    def frame_speed(self, body: str) -> float:
        """Speed of the frame ``body``'s translations are measured in [rad/s] (signed
        about the carrier's axis; 0 for the housing)."""
        c = self.frames.get(body)
        return 0.0 if c is None else self.bodies[c].speed

    def relative_speed(self, body: str, carrier: str | None) -> float:
        """Speed of ``body`` about its own axis relative to ``carrier``'s frame."""
        w = self.bodies[body].speed
        if carrier is None:
            return w
        c = self.bodies[carrier]
        return w - float(self.bodies[body].axis @ c.axis) * c.speed


# --------------------------------------------------------------------------- helpers
def gear_geometry(gear: Gear) -> GearGeometry:
    """The involute geometry of a schema gear."""
    return loa.gear_geometry(gear)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


#: default rim thickness of an internal gear from its root circle outwards, in normal
#: modules: ISO 6336-3:2006 (rim thickness factor Y_B) finds no rim influence on the tooth
#: root stress of an internal gear from s_R = 3.5 m_n up (Y_B = 1; thinner rims, down to
#: 1.75 m_n, raise it), the rim a ring gear is designed with at least (cf. AGMA 6123 on
#: ring gear rims)
RIM_THICKNESS_MODULES = 3.5


def internal_rim(gear: Gear) -> tuple[float, float, bool]:
    """(root radius, outer radius, outer radius computed) of an internal gear's rim: the
    outer radius is ``outer_diameter / 2``, or the root radius plus ``rim_thickness``
    (default :data:`RIM_THICKNESS_MODULES` normal modules)."""
    r_f = gear_geometry(gear).root_radius
    if gear.outer_diameter is not None:
        return r_f, gear.outer_diameter / 2, False
    rim = (gear.rim_thickness if gear.rim_thickness is not None
           else RIM_THICKNESS_MODULES * gear.module)
    return r_f, r_f + rim, True


def mass_basis(gear: Gear) -> str:
    """What computed mass and inertia of ``gear`` are made of, for ``check``'s table."""
    if gear.gear_type == "internal":
        r_f, r_o, _ = internal_rim(gear)
        rim = r_o - r_f
        of = (f" = {rim / gear.module:.3g} m_n" if gear.outer_diameter is None
              and gear.rim_thickness is None else "")
        return f"rim {rim * 1e3:.4g} mm{of}, d_o {2 * r_o * 1e3:.5g} mm"
    return "disc of d" + (f", bore {gear.bore_diameter * 1e3:.4g} mm"
                          if gear.bore_diameter else "")


def gear_mass_properties(gear: Gear) -> tuple[float, float, bool, bool]:
    """Mass and polar inertia, from the model or computed: a solid disc of the pitch
    diameter less the bore, or for an internal gear the annulus of its rim from the root
    circle to the outer diameter (:func:`internal_rim`; the teeth inside the root circle
    are left out, about a tenth of a ring's mass at the default rim)."""
    width = gear.face_width * (2 if gear.gear_type == "double_helical" else 1)
    if gear.gear_type == "internal":
        ri, ro, _ = internal_rim(gear)
        do, di = 2 * ro, 2 * ri
    else:
        do = 2 * gear_geometry(gear).reference_radius
        di = min(gear.bore_diameter, 0.9 * do)
    m_geo = gear.density * math.pi * (do**2 - di**2) / 4 * width
    j_geo = m_geo * (do**2 + di**2) / 8
    mass = gear.mass if gear.mass is not None else m_geo
    inertia = gear.polar_inertia if gear.polar_inertia is not None else j_geo
    return mass, inertia, gear.mass is None, gear.polar_inertia is None


def support_frame(kin, body: str) -> tuple[str | None, float | None, float]:
    """(carrier, rotation frequency of ``body`` in the frame of its support force,
    rotation frequency of that frame) [Hz]: the force on a body whose translations are
    measured in a turning carrier's frame (docs/theory/planetary.md) is in that frame,
    where the body turns at its speed relative to the carrier; (None, absolute frequency,
    0) for the housing's frame (or a carrier that does not turn); None for a body the
    kinematics do not know."""
    bodies = getattr(kin, "bodies", {})
    info = bodies.get(body)
    if info is None:
        return None, None, 0.0
    carrier = getattr(kin, "frames", {}).get(body)
    w_frame = abs(kin.frame_speed(body)) if carrier is not None else 0.0
    if carrier is None or w_frame == 0.0:
        return carrier, abs(info.speed) / (2 * math.pi), 0.0
    return (carrier, abs(kin.relative_speed(body, carrier)) / (2 * math.pi),
            w_frame / (2 * math.pi))


def frame_label(carrier: str | None) -> str:
    """A force's frame in words: ``"housing"``, or ``"turning with NAME"`` for axes fixed
    to the turning carrier NAME (it read "carrier NAME (turning)": "carrier stage_carrier
    (turning)" on a sun's bearing to the housing, a reviewer)."""
    return f"turning with {carrier}" if carrier else "housing"


def bearing_frame(kin, body: str) -> str:
    """The frame a body's bearing force is written in (:func:`frame_label`): the housing,
    or a turning carrier for a body whose translations are measured in its frame
    (:func:`support_frame`)."""
    carrier, _, turning = support_frame(kin, body)
    return frame_label(carrier if turning else None)


# --------------------------------------------------------------------------- solver
def kinematics_at(kin: Kinematics, factor: float) -> Kinematics:
    """``kin`` at ``factor`` times every speed with the torques held (a speed change at
    constant load, as the steady state at another speed and a speed sweep take it): body
    and mesh speeds, powers and mesh frequencies scaled; forces and torques unchanged."""
    if factor == 1.0:
        return kin
    from dataclasses import replace

    bodies = {n: replace(b, speed=b.speed * factor, power=b.power * factor)
              for n, b in kin.bodies.items()}
    meshes = {n: replace(m, frequency=m.frequency * factor, power=m.power * factor,
                         driver_speed=m.driver_speed * factor,
                         driven_speed=m.driven_speed * factor)
              for n, m in kin.meshes.items()}
    return replace(kin, bodies=bodies, meshes=meshes, input_power=kin.input_power * factor,
                   output_power=kin.output_power * factor)


def solve_kinematics(model) -> Kinematics:
    """Layout, speeds, power flow, torques and forces of the nominal equal split.

    ``model``: a :class:`Model`, or what :func:`~torquesplit.load_model` reads (a file, a
    shipped example's name, a dict).  The result is kept while the model lives (models
    and kinematics are frozen): loading a model checks it through its kinematics, and
    the run set up next needs them again.  A model changed in place after loading is
    refused (:meth:`Model.changed_in_place`)."""
    if not isinstance(model, Model):
        from .io import load_model

        model = load_model(model)
    if model.changed_in_place():
        from ..errors import ModelError

        raise ModelError([("", (
            "the model was changed in place after it was loaded (an entry of one of its "
            "sections replaced, added or deleted): that change is not checked, and results "
            "kept for the model would not see it; make it with model.with_changes({'PATH': "
            "value}) or load_model(source, changes={...})"))])
    return _kinematics(model)


@remember_last
def _kinematics(model: Model) -> Kinematics:
    return _solve_kinematics(model)


def _solve_kinematics(model: Model) -> Kinematics:
    issues: list[tuple[str, str]] = []
    groups = _rigid_groups(model)
    positions, axes, computed = _layout(model, issues)
    if issues:
        raise KinematicsError(issues)
    from . import epicyclic as epi

    # carriers and planets first: a ring of the wrong kind is named as such, not as a
    # centre distance that does not fit
    layout = epi.find_layout(model, positions, axes, groups, issues)
    if issues:
        raise KinematicsError(issues)

    frames = {}
    for name, mesh in model.meshes.items():
        try:
            frames[name] = loa.contact_frame(model, name, positions, axes)
        except ValueError as exc:
            issues.append((f"meshes.{name}", str(exc)))
    if issues:
        raise KinematicsError(issues)
    nominal = None
    trans_frames: dict[str, str] = {}
    if layout.active:
        # carriers, planets or held members: speeds and torques from the linear
        # equations of model/epicyclic.py (Willis in every carrier's frame)
        speeds = epi.solve_speeds(model, axes, frames, groups, layout, issues)
        if issues:
            raise KinematicsError(issues)
        nominal = epi.solve_torques(model, axes, frames, groups, speeds, layout, issues)
        if issues or nominal is None:
            raise KinematicsError(issues)
        trans_frames = epi.translation_frames(model, layout, positions, axes, speeds, issues)
        if issues:
            raise KinematicsError(issues)
        drivers, edge_power = nominal.drivers, nominal.mesh_power
        drive_torques, load_torques = nominal.drive_torques, nominal.load_torques
        power = {b: nominal.body_torque[b] * abs(speeds[b]) for b in model.body_names()}
        p_in = sum(drive_torques[n] * abs(d.speed) for n, d in model.drives.items())
        p_out = sum(load_torques[n] * abs(speeds[ld.body]) for n, ld in model.loads.items())
    else:
        speeds = _propagate_speeds(model, axes, frames, issues)
        if issues:
            raise KinematicsError(issues)

        power, edge_power, drivers, drive_torques, load_torques, p_in, p_out = _power_flow(
            model, speeds, groups, issues
        )
        if issues:
            raise KinematicsError(issues)

    bodies = {}
    for name in model.body_names():
        if name in model.gears:
            mass, inertia, mc, ic = gear_mass_properties(model.gears[name])
        else:
            b = model.bodies[name]
            mass, inertia, mc, ic = (b.mass or 0.0), b.polar_inertia, False, False
        w = speeds[name]
        p = power.get(name, 0.0)
        torque = nominal.body_torque[name] if nominal is not None else p / abs(w)
        bodies[name] = BodyKinematics(
            name=name, position=positions[name], axis=axes[name], speed=w,
            torque=torque, power=p, mass=mass, polar_inertia=inertia,
            mass_computed=mc, inertia_computed=ic,
        )

    meshes = {}
    for name, mesh in model.meshes.items():
        driver, driven = drivers[name]
        fr = frames[name]
        carrier = layout.mesh_carrier.get(name)
        # speeds in the mesh's frame (its carrier's; the housing's for fixed axes)
        rel = {g: epi.relative_speed(g, carrier, speeds, axes) for g in (driver, driven)}
        n_vec, arm_d, arm_n = loa.line_of_action(model, name, fr, driver, rel)
        za = model.gears[driver].teeth
        freq = abs(rel[driver]) * za / (2 * math.pi)
        if not freq > 0:
            # a gear joined to nothing but this mesh (a compound planet's second gear
            # without its shaft) turns with whatever it meshes: say so
            ends = {b for part in (*model.shafts.values(), *model.splines.values())
                    for b in part.connects}
            ends |= {d.body for d in model.drives.values()} | {
                ld.body for ld in model.loads.values()}
            alone = [g for g in (driver, driven) if g not in ends
                     and sum(g in m.gears for m in model.meshes.values()) == 1]
            hint = (f"; {alone[0]!r} is joined to nothing but this mesh: if it is a compound "
                    f"planet's gear, join it to its planet gear with a rigid shaft"
                    if alone else "")
            hint += epi.elastic_shaft_hint(model, layout.planet_bodies, (driver, driven), 1)
            issues.append((f"meshes.{name}", (
                f"the gears of this mesh do not turn against each other (speed "
                f"{rel[driver] * 30 / math.pi:.6g} rpm in its frame), so it has no mesh "
                f"cycle; check which members are held and driven" + hint)))
            continue
        p_mesh = edge_power[name]
        if nominal is not None:
            first = model.meshes[name].gears[0]
            t_first, t_second = nominal.mesh_torque[name], nominal.mesh_torque_second[name]
            t_drv, t_dvn = (abs(t_first), abs(t_second)) if driver == first else \
                (abs(t_second), abs(t_first))
        else:
            t_drv = p_mesh / abs(speeds[driver])
            t_dvn = p_mesh / abs(speeds[driven])
        force = t_drv / abs(arm_d)
        # inertia of the rigid group each gear belongs to (compound gears)
        ja, jb = (sum(bodies[b].polar_inertia for b in bodies if groups[b] == groups[g])
                  for g in (driver, driven))
        # equivalent mass of the mesh, m = J1 J2 / (J1 r2^2 + J2 r1^2), with the arms
        # as the effective base radii (Ji & Li eq. 1 corrected)
        den = ja * arm_n**2 + jb * arm_d**2
        m_eq = ja * jb / den if den > 0 else 0.0
        spec = mesh.stiffness
        i0, i1 = (0, 1) if mesh.gears[0] == driver else (1, 0)
        geo = fr.pair_geometry
        iso = None
        if geo is not None:
            iso = _iso_estimate(geo)
        # (a stiffness computed at assembly, ISO 6336, potential energy or LTCA: its ISO
        # estimate; 'check --json' gave 0 N s/m for a damping ratio of 0.06)
        k_mean = _mean_stiffness(spec) or iso
        crit = 2 * math.sqrt(k_mean * m_eq) if k_mean else 0.0
        meshes[name] = MeshKinematics(
            name=name, driver=driver, driven=driven, frequency=freq,
            contact_point=fr.contact_point, line_of_action=n_vec,
            arm_driver=arm_d, arm_driven=arm_n,
            pitch_radii=(fr.pitch_radii[i0], fr.pitch_radii[i1]),
            base_radii=(fr.base_radii[i0], fr.base_radii[i1]),
            transverse_contact_ratio=fr.transverse_contact_ratio,
            overlap_contact_ratio=fr.overlap_contact_ratio,
            total_contact_ratio=fr.transverse_contact_ratio + fr.overlap_contact_ratio,
            working_pressure_angle=fr.working_pressure_angle,
            center_distance=fr.center_distance,
            torque_driver=t_drv, torque_driven=t_dvn, force=force, power=p_mesh,
            equivalent_mass=m_eq, critical_damping=crit, iso_stiffness=iso,
            conical=fr.conical, geometry=geo, carrier=carrier,
            driver_speed=rel[driver], driven_speed=rel[driven],
        )
    if issues:
        raise KinematicsError(issues)
    trans_axes = _translation_axes(model, bodies, meshes, issues)
    if issues:
        raise KinematicsError(issues)
    return Kinematics(
        bodies=bodies, meshes=meshes, input_power=p_in, output_power=p_out,
        load_torques=load_torques, drive_torques=drive_torques, groups=groups,
        positions_computed=computed, translation_axes=trans_axes,
        carriers=dict(layout.carriers), planet_bodies=dict(layout.planet_bodies),
        frames=trans_frames, held=layout.held,
        reactions=dict(nominal.reactions) if nominal is not None else {},
    )


LOA_PARALLEL_TOL = 1e-6
"""Largest sine of the angle between the transverse lines of action of two meshes that
share one 'loa' translation."""


def _translation_axes(model: Model, bodies, meshes, issues) -> dict[str, dict[str, np.ndarray]]:
    """Unit direction of every translational DOF of every body.

    x, y, z are the global axes.  'loa' (Ji & Li eq. 9: one translation X_i per gear
    "along the tangent of the meshing pair") is the line of action of the gear's meshes
    projected on its transverse plane; every mesh of the gear must have that direction
    (up to sign: e.g. two branches at 180 deg about an input pinion), else the gear
    needs x and y.
    """
    out: dict[str, dict[str, np.ndarray]] = {}
    for body in model.body_names():
        spec = model.gears.get(body) or model.bodies[body]
        kind = "gears" if body in model.gears else "bodies"
        dirs: dict[str, np.ndarray] = {}
        for d in spec.dofs:
            if d in ("x", "y", "z"):
                dirs[d] = np.eye(3)["xyz".index(d)]
            elif d == "loa":
                u = _loa_direction(body, bodies[body].axis, meshes, f"{kind}.{body}.dofs", issues)
                if u is not None:
                    dirs[d] = u
        out[body] = dirs
    return out


def _loa_direction(body, axis, meshes, loc, issues) -> np.ndarray | None:
    a = _unit(axis)
    mine = [m for m in meshes.values() if body in (m.driver, m.driven)]
    if not mine:
        issues.append((loc, "'loa' is a translation along the line of action of the body's "
                            "meshes, and it has none; use 'x' and 'y' instead"))
        return None
    u = None
    for m in mine:
        n = m.line_of_action
        t = n - (n @ a) * a
        if np.linalg.norm(t) < 1e-9:
            issues.append((loc, f"mesh {m.name!r} pushes {body!r} along its axis only; 'loa' "
                                f"has no transverse direction to follow: use 'x' and 'y'"))
            return None
        t = t / np.linalg.norm(t)
        if u is None:
            u, first = t, m.name
            continue
        sine = float(np.linalg.norm(cross(u, t)))
        if sine > LOA_PARALLEL_TOL:
            angle = math.degrees(math.asin(min(1.0, sine)))
            issues.append((loc, (
                f"meshes {first!r} and {m.name!r} push {body!r} along lines of action "
                f"{angle:.3g} deg apart; one 'loa' translation carries only parallel lines "
                f"(e.g. branches at 180 deg): use 'x' and 'y' instead")))
            return None
    return u


def _iso_estimate(geo) -> float | None:
    """ISO 6336-1 c_gamma * b of a cylindrical pair [N/m] (None if not applicable)."""
    try:
        from ..gears.stiffness import iso6336_mesh_stiffness_value
    except ImportError:
        return None
    try:
        return float(iso6336_mesh_stiffness_value(geo))
    except ValueError:
        return None


def _mean_stiffness(spec) -> float | None:
    if spec.method == "constant":
        return spec.value
    if spec.method == "table":
        return float(np.mean(spec.values))
    if spec.method == "fourier":
        return spec.mean
    return None


def _rigid_groups(model: Model) -> dict[str, str]:
    parent = {n: n for n in model.body_names()}

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for s in model.shafts.values():
        if s.rigid:
            a, b = (find(x) for x in s.connects)
            if a != b:
                parent[b] = a
    return {n: find(n) for n in parent}


def _layout(model: Model, issues) -> tuple[dict, dict, list[str]]:
    """Centre and unit axis of every body."""
    positions: dict[str, np.ndarray] = {}
    axes: dict[str, np.ndarray] = {}
    computed: list[str] = []
    for name, b in model.bodies.items():
        positions[name] = np.asarray(b.position, dtype=float)
        axes[name] = _unit(b.axis)
    for name, g in model.gears.items():
        axes[name] = _unit(g.axis)
        if g.position is not None:
            positions[name] = np.asarray(g.position, dtype=float)
    # place gears relative to mating gears / coaxial bodies until nothing changes
    mates: dict[str, list[str]] = {n: [] for n in model.gears}
    for m in model.meshes.values():
        a, b = m.gears
        mates[a].append(b)
        mates[b].append(a)
    coaxial: dict[str, list[str]] = {n: [] for n in model.body_names()}
    for s in list(model.shafts.values()) + list(model.splines.values()):
        a, b = s.connects
        coaxial[a].append(b)
        coaxial[b].append(a)
    pending = [n for n in model.gears if n not in positions]
    auto_count: dict[str, int] = {}
    progress = True
    while pending and progress:
        progress = False
        for name in list(pending):
            g = model.gears[name]
            if g.place is not None:
                ref = g.place.from_gear
                if ref in positions:
                    try:
                        positions[name] = loa.placed_position(
                            model, name, ref, positions[ref], axes[ref], g.place.angle)
                    except ValueError as exc:
                        issues.append((f"gears.{name}.place", str(exc)))
                        positions[name] = positions[ref].copy()
                    computed.append(name)  # placed: computed from the mating gear
                    pending.remove(name)
                    progress = True
                continue
            co = [b for b in coaxial[name] if b in positions]
            if co:
                positions[name] = positions[co[0]].copy()
                computed.append(name)
                pending.remove(name)
                progress = True
                continue
            mt = [b for b in mates[name] if b in positions]
            if mt:
                ref = mt[0]
                k = auto_count.get(ref, 0)
                auto_count[ref] = k + 1
                try:
                    positions[name] = loa.placed_position(
                        model, name, ref, positions[ref], axes[ref], math.pi * k)
                except ValueError:
                    # crossed axes: a bevel gear's frame follows from the axes alone;
                    # a face gear needs an explicit position (see gears/line_of_action.py)
                    positions[name] = positions[ref].copy()
                computed.append(name)
                pending.remove(name)
                progress = True
        if pending and not progress:
            # nothing anchored: put the first pending gear at the origin
            first = pending.pop(0)
            positions[first] = np.zeros(3)
            computed.append(first)
            progress = True
    for name in model.bodies:
        positions.setdefault(name, np.zeros(3))
    return positions, axes, computed


def _propagate_speeds(model: Model, axes, frames, issues) -> dict[str, float]:
    """Signed speed of every body from the first drive; loops must be consistent."""
    adj: dict[str, list[tuple[str, float, str]]] = {n: [] for n in model.body_names()}
    for name, m in model.meshes.items():
        a, b = m.gears
        r = frames[name].speed_ratio  # omega_b = r * omega_a
        adj[a].append((b, r, f"meshes.{name}"))
        adj[b].append((a, 1.0 / r, f"meshes.{name}"))
    for kind, items in (("shafts", model.shafts), ("splines", model.splines)):
        for name, s in items.items():
            a, b = s.connects
            dot = float(axes[a] @ axes[b])
            if abs(abs(dot) - 1) > 1e-6:
                issues.append((f"{kind}.{name}", f"joins {a!r} and {b!r} whose axes are not "
                               f"parallel; give both bodies the same 'axis'"))
                continue
            r = 1.0 if dot > 0 else -1.0
            adj[a].append((b, r, f"{kind}.{name}"))
            adj[b].append((a, r, f"{kind}.{name}"))
    if issues:
        return {}
    first = next(iter(model.drives.values()))
    speeds = {first.body: first.speed}
    queue = deque([first.body])
    while queue:
        a = queue.popleft()
        for b, r, via in adj[a]:
            w = speeds[a] * r
            if b not in speeds:
                speeds[b] = w
                queue.append(b)
            elif not math.isclose(speeds[b], w, rel_tol=1e-9, abs_tol=1e-12):
                issues.append((via, (
                    f"the gears could not turn: body {b!r} would run at "
                    f"{speeds[b] * 30 / math.pi:.6g} rpm by one path and {w * 30 / math.pi:.6g} rpm "
                    f"by another; a power-split loop needs the same ratio on every path "
                    f"(check tooth counts and axis directions)")))
                return speeds
    for name, d in model.drives.items():
        w = speeds.get(d.body)
        if w is not None and not math.isclose(w, d.speed, rel_tol=1e-6):
            issues.append((f"drives.{name}.speed", (
                f"{d.speed * 30 / math.pi:.6g} rpm contradicts the {w * 30 / math.pi:.6g} rpm that "
                f"the gear ratios give from drive {next(iter(model.drives))!r}; "
                f"make the drive speeds consistent (mind the sign, which follows the axis)")))
    return speeds


def drive_input_torques(model: Model, speeds, issues) -> dict[str, float]:
    """Each drive's input torque magnitude [N m]: its own (torque, or power / speed), and
    for a 'speed' drive given neither, the power that the loads' given torques take (less
    the other drives'), at its speed.  Such a drive needs every load's torque: a
    'balanced' load beside it is an issue (appended to ``issues``)."""
    out = {n: d.input_torque for n, d in model.drives.items()}
    open_ = [n for n, t in out.items() if t is None]
    if not open_:
        return out
    balanced = [n for n, ld in model.loads.items() if ld.torque is None]
    if len(open_) > 1:
        issues.append((f"drives.{open_[1]}", (
            f"the 'speed' drives {open_} have neither power nor torque, so the loads' power "
            f"cannot be split between them; give all but one of them a power or torque")))
        return out
    if balanced:
        issues.append((f"loads.{balanced[0]}.torque", (
            f"the 'speed' drive {open_[0]!r} has neither power nor torque, so it puts in "
            f"what the loads take, but this load is 'balanced' (it takes what the drives put "
            f"in); give this load's torque, or the drive's power or torque")))
        return out
    p_loads = sum(ld.torque * abs(speeds[ld.body]) for ld in model.loads.values())
    p_other = sum(t * abs(model.drives[n].speed) for n, t in out.items() if t is not None)
    name = open_[0]
    if not p_loads > p_other:
        left = ("nothing is left for this 'speed' drive" if p_loads == p_other else
                f"this 'speed' drive would have to take {(p_other - p_loads) / 1e3:.6g} kW "
                f"out (a brake or generator holding its speed), but a drive only puts power "
                f"in and a load has no speed")
        issues.append((f"drives.{name}", (
            f"the other drives put in {p_other / 1e3:.6g} kW and the loads take "
            f"{p_loads / 1e3:.6g} kW: {left}; correct the loads' torques, or give this "
            f"drive's power or torque")))
        return out
    out[name] = (p_loads - p_other) / abs(model.drives[name].speed)
    return out


_FLAT = 1e-9
"""Fall of the flow potential below which an edge carries no nominal power (round-off)."""


def _potential(g_adj, high: str, low: str) -> dict[str, float]:
    """The potential of :func:`_power_flow` for one drive and one load: 1 at the drive's
    group ``high``, 0 at the load's ``low``, harmonic at every other group (the mean of its
    neighbours': unit conductance per edge).  A dead end takes its neighbour's value."""
    names = list(g_adj)
    for g in (high, low):
        if g not in g_adj:
            names.append(g)
    free = [g for g in names if g not in (high, low)]
    x = {high: 1.0, low: 0.0}
    if free:
        col = {g: i for i, g in enumerate(free)}
        lap = np.zeros((len(free), len(free)))
        rhs = np.zeros(len(free))
        for g in free:
            i = col[g]
            for _, h in g_adj.get(g, []):
                lap[i, i] += 1.0
                if h in col:
                    lap[i, col[h]] -= 1.0
                else:
                    rhs[i] += x[h]
        # lstsq: a part joined to neither is singular (the topology check refuses it)
        sol = np.linalg.lstsq(lap, rhs, rcond=None)[0]
        x.update({g: float(sol[col[g]]) for g in free})
    return x


def _power_flow(model: Model, speeds, groups, issues):
    """Equal-split power flow from the drives to the loads.

    Each load takes its given torque's power (a 'balanced' load an equal share of what is
    left), and each drive feeds every load in proportion to the load's power.  The power
    of one drive to one load flows down a potential, 1 at that drive, 0 at that load and
    harmonic in between (every rigid group at the mean of its neighbours: unit
    conductance per mesh, elastic shaft or spline), and a group splits what it receives
    equally among its downhill edges.  A potential falls along every branch of a split,
    whatever the number of bodies on each (hop counts to the load gave a branch with one
    body more no power); a dead end (another drive's or load's branch, a power take-off
    on an intermediate gear) has no fall and takes nothing of that pair.  The pairs' flows
    add up on each edge, which is directed by the sum."""
    # graph of rigid groups: edges are meshes and elastic shafts/splines
    edges: list[tuple[str, str, str]] = []  # (name, body_a, body_b)
    for name, m in model.meshes.items():
        edges.append((name, *m.gears))
    for name, s in list(model.shafts.items()) + list(model.splines.items()):
        if not getattr(s, "rigid", False):
            edges.append((name, *s.connects))
    g_adj: dict[str, list[tuple[str, str]]] = {}
    ends = {}
    for name, a, b in edges:
        ga, gb = groups[a], groups[b]
        ends[name] = (ga, gb)
        g_adj.setdefault(ga, []).append((name, gb))
        g_adj.setdefault(gb, []).append((name, ga))
    # inputs
    drive_torques = {}
    p_in = 0.0
    given = drive_input_torques(model, speeds, issues)
    if issues:
        return {}, {}, {}, {}, {}, 0.0, 0.0
    drive_power = {}
    for name, d in model.drives.items():
        t = given[name]
        drive_torques[name] = t
        drive_power[name] = t * abs(d.speed)
        p_in += drive_power[name]
    # loads
    load_torques = {}
    balanced = [n for n, ld in model.loads.items() if ld.torque is None]
    fixed = {n: ld.torque for n, ld in model.loads.items() if ld.torque is not None}
    p_fixed = sum(t * abs(speeds[model.loads[n].body]) for n, t in fixed.items())
    p_rest = p_in - p_fixed
    for n, t in fixed.items():
        load_torques[n] = t
    if balanced:
        if p_rest <= 0:
            issues.append(("loads", f"the loads with a given torque take {p_fixed / 1e3:.6g} kW, "
                           f"all of the {p_in / 1e3:.6g} kW input; nothing is left for "
                           f"{balanced}; correct the torques"))
        for n in balanced:
            load_torques[n] = p_rest / len(balanced) / abs(speeds[model.loads[n].body])
    elif not math.isclose(p_fixed, p_in, rel_tol=1e-3):
        issues.append(("loads", (
            f"power does not balance: the drives put in {p_in / 1e3:.6g} kW and the loads take "
            f"{p_fixed / 1e3:.6g} kW; set a load's torque to \"balanced\" or correct the values")))
    load_power = {n: max(load_torques[n], 0.0) * abs(speeds[ld.body])
                  for n, ld in model.loads.items()}
    p_out = sum(load_torques[n] * abs(speeds[model.loads[n].body]) for n in model.loads)
    # route each drive's power to each load (in proportion to the loads' powers)
    flow: dict[str, float] = {name: 0.0 for name, _, _ in edges}  # signed, a -> b
    inflow: dict[str, float] = {}
    total = sum(load_power.values())
    for dn, d in model.drives.items():
        gd = groups[d.body]
        for ln, ld in model.loads.items():
            gl = groups[ld.body]
            share = drive_power[dn] * load_power[ln] / total if total > 0 else 0.0
            if gd == gl or not share > 0:
                continue
            potential = _potential(g_adj, gd, gl)
            at = {gd: share}
            for g in sorted(potential, key=lambda k: -potential[k]):
                p = at.pop(g, 0.0)
                outs = [(name, h) for name, h in g_adj.get(g, [])
                        if potential[h] < potential[g] - _FLAT]
                if not (p > 0 and outs):
                    continue
                for name, h in outs:
                    flow[name] += p / len(outs) * (1.0 if ends[name][0] == g else -1.0)
                    at[h] = at.get(h, 0.0) + p / len(outs)
    edge_power = {name: abs(f) for name, f in flow.items()}
    edge_dir: dict[str, tuple[str, str]] = {}
    for name, f in flow.items():
        if abs(f) > _FLAT * max(p_in, 1e-300):
            ga, gb = ends[name]
            edge_dir[name] = (ga, gb) if f > 0 else (gb, ga)
            inflow[edge_dir[name][1]] = inflow.get(edge_dir[name][1], 0.0) + abs(f)
    group_power: dict[str, float] = dict(inflow)
    for dn, d in model.drives.items():
        g = groups[d.body]
        group_power[g] = group_power.get(g, 0.0) + drive_power[dn]
    # power through each body (groups share their power)
    power = {b: group_power.get(groups[b], 0.0) for b in model.body_names()}
    drivers = {}
    for name, m in model.meshes.items():
        a, b = m.gears
        flow = edge_dir.get(name)
        if flow is None:
            # no power flows through the mesh in the nominal split (e.g. an idler loop)
            drv = m.driver or a
            if m.driver is None:
                warn_user(
                    f"meshes.{name}: no power passes this mesh in the nominal split, so its "
                    f"loaded flank is not determined; {a!r} (listed first) is taken as the "
                    f"driver: give 'driver' to choose the flank", ModelWarning)
        else:
            drv = a if groups[a] == flow[0] else b
            if m.driver is not None and m.driver != drv:
                issues.append((f"meshes.{name}.driver", (
                    f"{m.driver!r} is given as driver but power flows from {drv!r} to it; "
                    f"remove 'driver' or correct it")))
        drivers[name] = (drv, b if drv == a else a)
    return power, edge_power, drivers, drive_torques, load_torques, p_in, p_out
