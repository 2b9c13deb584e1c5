"""Model -> Structure: number the DOFs, build the diagonal mass and the element list.

Element kinds produced here (docs/theory/model.md):

==============  ==========================================  =========================
element         deformation ``V . q``                         stiffness
==============  ==========================================  =========================
mesh            ``n.(u_d - u_n) + arm_d th_d - arm_n th_n``   k(phase) table [N/m]
shaft           ``th_a - th_b``                               torsional [N m/rad]
support         ``u_i`` (one translational DOF; ``- u_seat``  bearing [N/m], clearance
                for a bearing on another body, ``on``)       per axis
radial bearing  the two translations across the axis, 2-D    the spline's radial law,
                (a support with a 'radial' clearance)         no stick, no friction
spline torsion  ``th_hub - th_float``                         torsional [N m/rad]
spline radial   ``u_hub - u_float``, radial plane, 2-D        radial law, Dong et al. 2021 eq. 6
torque harmonic ``+-th`` of a drive's or load's body          none; a force table of
                                                              the torque [N m]
==============  ==========================================  =========================

A mesh with ``friction`` also gets its friction projection W (Jin et al. 2019; forces only):
``+t`` on the driver's and ``-t`` on the driven gear's translations times the friction
force per unit load, and the friction moments per unit load on their rotations (see
:func:`torquesplit.assembly.excitation.friction_table` for the signs).

Bodies joined by a rigid shaft share one rotational DOF.  A drive in ``speed`` mode
prescribes its body's rotation: that DOF is removed.

Options (``assemble(..., options={...})``):

``spline_velocity_scale``
    Velocity scale v of the regularised Coulomb friction of the splines,
    F_m tanh(Rdot / v) [m/s]; default: the model's ``[analysis] spline_velocity_scale``
    (1e-3 m/s).  Below about v the friction is viscous (tangent F_m / v), above it
    Coulomb; the RK4 stability check accounts for the tangent F_m / v, which can shorten
    the step (see docs/theory/model.md).

``rotating_frame``
    True (default): bodies whose translations are measured in a turning carrier's frame
    get the Coriolis (gyroscopic) and centripetal terms and the centrifugal force
    (:mod:`torquesplit.assembly.rotating`).  False leaves them out: the stationary-
    carrier model of Lin & Parker 1999's natural frequencies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, OptionError, warn_user
from ..gears import line_of_action as loa
from ..gears.vectors import cross
from ..model.kinematics import Kinematics, solve_kinematics
from ..model.schema import Model
from . import excitation
from .structure import MESH, SPLINE, SPRING, Structure, build_structure

_OPTIONS = {"spline_velocity_scale", "rotating_frame"}


@dataclass(frozen=True)
class DofMap:
    """Where each body's coordinates live in the state vector."""

    theta: dict[str, tuple[int, float]]
    """body -> (DOF index or -1 if prescribed, sign relative to the DOF's axis)."""
    translation: dict[str, dict[str, int]]
    """body -> {'x': index, ...} ('x', 'y', 'z', 'loa')."""
    names: tuple[str, ...]
    axes: dict[str, dict[str, np.ndarray]]
    """body -> {'x': unit direction, ...} of each translational DOF."""
    host: dict[str, str] = field(default_factory=dict)
    """planet body without translations -> the body of its planet shaft whose translations
    it shares (the one on the pin's bearing: a compound planet's other gear); a planet
    body not listed rides its pin rigidly (:func:`planet_bearer`)."""

    def project(self, body: str, vec, sign: float = 1.0, tol: float = 0.0):
        """(DOF index, sign * vec . direction) of each of ``body``'s translations whose
        projection exceeds ``tol`` in magnitude (x, y, z give vec's components exactly)."""
        out = []
        for d, j in self.translation[body].items():
            c = float(np.dot(vec, self.axes[body][d]))
            if abs(c) > tol:
                out.append((j, sign * c))
        return out


def number_dofs(model: Model, kin: Kinematics) -> tuple[DofMap, np.ndarray]:
    """DOF numbering and the diagonal mass (inverse mass returned)."""
    names: list[str] = []
    mass: list[float] = []
    theta: dict[str, tuple[int, float]] = {}
    trans: dict[str, dict[str, int]] = {}
    prescribed = {kin.groups[d.body] for d in model.drives.values() if d.mode == "speed"}
    # a member held rigidly (torsional_support.rigid) loses its rotation like a speed drive
    for body in kin.held:
        spec = model.gears.get(body) or model.bodies[body]
        if spec.torsional_support.rigid:
            prescribed.add(kin.groups[body])
    group_index: dict[str, int] = {}
    for body in model.body_names():
        spec = model.gears.get(body) or model.bodies[body]
        bk = kin.bodies[body]
        rep = kin.groups[body]
        sign = 1.0 if float(kin.bodies[rep].axis @ bk.axis) > 0 else -1.0
        if "theta" in spec.dofs or rep != body:
            if rep in prescribed:
                theta[body] = (-1, sign)
            else:
                if rep not in group_index:
                    group_index[rep] = len(names)
                    names.append(f"{rep}.theta")
                    mass.append(0.0)
                idx = group_index[rep]
                mass[idx] += bk.polar_inertia
                theta[body] = (idx, sign)
        trans[body] = {}
        for d in ("x", "y", "z", "loa"):
            if d in spec.dofs:
                trans[body][d] = len(names)
                names.append(f"{body}.{d}")
                mass.append(bk.mass)
    # a planet without translations on the shaft of one that has them (a compound
    # planet's other gear) moves with that one; else it sits rigidly on its pin: its mass
    # moves with the carrier's translations and, at the pin radius R, with its rotation
    # (m R^2)
    host: dict[str, str] = {}
    for body, carrier in kin.planet_bodies.items():
        if trans[body] or body not in kin.bodies:
            continue
        mp = kin.bodies[body].mass
        bearer = planet_bearer(model, kin, body)
        if bearer is not None and trans[bearer]:
            host[body] = bearer
            for j in trans[bearer].values():
                mass[j] += mp
            continue
        for j in trans.get(carrier, {}).values():
            mass[j] += mp
        idx, _ = theta.get(carrier, (-1, 1.0))
        if idx >= 0:
            mass[idx] += mp * orbit_radius(kin, body, carrier) ** 2
    m = np.asarray(mass)
    with np.errstate(divide="ignore", over="ignore"):
        inv = 1.0 / m
    if np.any(m <= 0) or not np.all(np.isfinite(inv)):
        bad = [names[i] for i in np.flatnonzero(m <= 0)]
        raise ModelError([("", f"DOFs {bad} have no mass or inertia; give 'mass'/'polar_inertia'")])
    axes = {b: dict(kin.translation_axes.get(b, {})) for b in trans}
    return DofMap(theta=theta, translation=trans, names=tuple(names), axes=axes,
                  host=host), inv


def assemble(model: Model, kin: Kinematics | None = None, *, n_table: int | None = None,
             options: dict | None = None) -> Structure:
    """Assemble the equations of motion of ``model`` (see module docstring; a
    :class:`Model` or what :func:`~torquesplit.load_model` reads); a refusal names the
    field as the user wrote it (a ``[[planetary]]`` stage's, not the element it
    generated), as ``torquesplit check`` does."""
    if n_table is not None and not (isinstance(n_table, (int, np.integer))
                                    and not isinstance(n_table, bool) and n_table >= 16):
        from ..errors import OptionError

        # (0 was taken: tables of no phase)
        raise OptionError(f"n_table must be a whole number of table points >= 16, got "
                          f"{n_table!r}; give e.g. n_table=256 (or leave it out: the "
                          f"model's analysis.table_points)")
    if not isinstance(model, Model):
        from ..model.io import load_model

        model = load_model(model)
    try:
        return _assemble(model, kin, n_table=n_table, options=options)
    except ModelError as exc:
        from ..model.checks import as_written

        raise ModelError(as_written(model, exc.issues), exc.source) from None


def _assemble(model: Model, kin: Kinematics | None, *, n_table: int | None,
              options: dict | None) -> Structure:
    kin = kin or solve_kinematics(model)
    n_table = n_table or excitation.table_points(model, kin)
    options = dict(options or {})
    unknown = sorted(set(options) - _OPTIONS)
    if unknown:
        raise OptionError(f"unknown assembly option(s) {unknown}; known: {sorted(_OPTIONS)}")
    v_reg = float(options.get("spline_velocity_scale", model.analysis.spline_velocity_scale))
    rotating = options.get("rotating_frame", True)
    if not isinstance(rotating, bool):
        raise OptionError(f"rotating_frame must be true or false, got {rotating!r}")
    if not (v_reg > 0 and math.isfinite(v_reg)):
        raise OptionError(f"spline_velocity_scale must be a positive speed in m/s, got "
                          f"{v_reg!r}")
    dmap, inv_mass = number_dofs(model, kin)
    n_dof = len(dmap.names)
    elements: list[dict] = []
    ext = np.zeros(n_dof)
    ground = np.zeros(n_dof)
    meta_meshes = {}

    phases = excitation.mesh_phases(model, kin, strict=True)
    stages = excitation.stage_labels(model, kin)

    # ---- meshes
    for name, mesh in model.meshes.items():
        mk = kin.meshes[name]
        dofs, coefs = [], []
        for body, sgn, arm in ((mk.driver, 1.0, mk.arm_driver), (mk.driven, -1.0, mk.arm_driven)):
            idx, s = dmap.theta.get(body, (-1, 1.0))
            if idx >= 0:
                dofs.append(idx)
                coefs.append(sgn * arm * s)
            for j, c in centre_projection(kin, dmap, body, mk.line_of_action, sgn):
                dofs.append(j)
                coefs.append(c)
        table = excitation.stiffness_table(model, kin, name, n_table)
        k_mean = float(np.mean(table))
        if mesh.damping is not None:
            c = mesh.damping
        elif mesh.damping_ratio is not None:
            # c = 2 zeta sqrt(k m_eq), m_eq = J1 J2 / (J1 r2^2 + J2 r1^2) (Ji & Li eq. 1, corrected)
            c = 2 * mesh.damping_ratio * math.sqrt(k_mean * mk.equivalent_mass)
        else:
            c = 0.0
        gaps = excitation.half_backlash_sequence(model, kin, name)
        err_const, sines = excitation.mesh_errors(model, kin, name)
        for body, sgn in ((mk.driver, 1.0), (mk.driven, -1.0)):
            # a planet rigid on its pin is displaced by the pin's position error: its
            # centre's part of V q (sgn u . n) misses it, so it is an error, e -= sgn u . n
            # (as a centre offset in excitation.mesh_errors)
            off = _rigid_pin_offset(model, kin, dmap, body)
            if off is not None:
                n = mk.line_of_action
                err_const -= sgn * float(off[0] @ n)
                sines = sines + [(-sgn * float(a @ n), om, ph) for a, om, ph in off[1]
                                 if abs(float(a @ n)) > 0.0]
        el = dict(
            name=name, kind=MESH, dofs=dofs, coefs=coefs, stiffness=table,
            frequency=mk.frequency, phase=phases[name], damping=c, gaps=gaps,
            error_constant=err_const, errors=sines,
        )
        force = excitation.impact_force_table(model, kin, name, n_table)
        if force is not None:
            el["force"] = force
        if mesh.friction is not None:
            el["friction"] = _friction_projection(model, kin, dmap, name, n_table)
        elements.append(el)
        meta_meshes[name] = dict(stage=stages[name], path=mesh.path,
                                 driver=mk.driver, driven=mk.driven,
                                 static_force=mk.force, frequency=mk.frequency)

    # ---- shafts
    for name, shaft in model.shafts.items():
        if shaft.rigid:
            continue
        a, b = shaft.connects
        ia, sa = dmap.theta[a]
        ib, sb = dmap.theta[b]
        r = 1.0 if float(kin.bodies[a].axis @ kin.bodies[b].axis) > 0 else -1.0
        dofs, coefs = [], []
        if ia >= 0:
            dofs.append(ia)
            coefs.append(sa)
        if ib >= 0:
            dofs.append(ib)
            coefs.append(-r * sb)
        k = shaft.torsional_stiffness
        if k is None:
            # Ji & Li eq. 3: k_T = G pi d^4 / (32 l) (hollow: d^4 - d_i^4)
            k = shaft.shear_modulus * math.pi * (shaft.diameter**4 - shaft.inner_diameter**4) / (
                32 * shaft.length)
        ja, jb = kin.bodies[a].polar_inertia, kin.bodies[b].polar_inertia
        if shaft.damping is not None:
            c = shaft.damping
        elif shaft.damping_ratio is not None:
            c = 2 * shaft.damping_ratio * math.sqrt(k * ja * jb / (ja + jb))
        else:
            c = 0.0
        if dofs:
            elements.append(dict(name=name, kind=SPRING, dofs=dofs, coefs=coefs, stiffness=k,
                                 damping=c))

    # ---- supports
    spline_members = {b for sp in model.splines.values() for b in sp.connects}
    for body in model.body_names():
        spec = model.gears.get(body) or model.bodies[body]
        tr = dmap.translation[body]
        if not tr:
            continue
        sup = spec.support
        if sup is None and body in spline_members:
            continue  # held radially by its spline (Dong et al. 2021 floating pinion)
        if sup is None:
            raise ModelError([(f"{'gears' if body in model.gears else 'bodies'}.{body}.support",
                               f"DOFs {sorted(tr)} have no support; add a support with a "
                               f"stiffness, or remove them from 'dofs'")])
        k_rad = support_stiffness(
            sup, f"{'gears' if body in model.gears else 'bodies'}.{body}.support")
        # diagonal support stiffness in the global axes, projected on each DOF's
        # direction u: k = kx ux^2 + ky uy^2 + kz uz^2 (x, y, z: the value itself)
        k_xyz = np.array([k_rad, sup.stiffness_y or k_rad, sup.axial_stiffness or k_rad])
        where = f"{'gears' if body in model.gears else 'bodies'}.{body}.support"
        on = _bearing_seat(model, dmap, body, sup.on, where,
                           orbits=body in kin.planet_bodies)
        if on is None and kin.frame_speed(body) != 0.0 and sup.stiffness_y is not None \
                and sup.stiffness is not None and sup.stiffness_y != sup.stiffness:
            raise ModelError([(f"{where}.stiffness_y", (
                f"{body!r} is measured in the frame of the turning carrier "
                f"{kin.frames[body]!r}, where a bearing to the housing with different x and "
                f"y stiffness turns; give it one radial stiffness (remove 'stiffness_y')"))])
        # (with the gears that share its translations: a compound planet's other gear)
        m = kin.bodies[body].mass + sum(kin.bodies[p].mass for p, h in dmap.host.items()
                                        if h == body)
        if on is not None:  # equivalent mass of the two bodies for the damping ratio
            m_on = kin.bodies[on].mass
            m = m * m_on / (m + m_on) if m_on > 0 else m
        seat_arm, pin_offset = _seat_geometry(kin, body, on, sup, where)
        ecc_const, ecc_sines = _eccentricity(model, kin, body)
        if on is not None and not dmap.translation[on]:
            # a seat body without translations (a carrier on rigid bearings): its
            # eccentricity moves the pins it carries; a planet rigid on its pin (the
            # seat of a compound planet's other gear) is displaced by its pin's offset
            seat_const, seat_sines = _eccentricity(model, kin, on)
            rigid = _rigid_pin_offset(model, kin, dmap, on)
            if rigid is not None:
                seat_const = seat_const + rigid[0]
                seat_sines = seat_sines + rigid[1]
            pin_offset = pin_offset + seat_const
            ecc_sines = ecc_sines + seat_sines
        # a radial clearance joins the two translations across the body's axis into one
        # circular law (the spline's, without stick or friction); the others stay apart
        pair = _radial_pair(sup, dmap.axes[body], kin.bodies[body].axis)
        if (sup.clearance > 0 and sup.clearance_shape == "radial" and not pair
                and sum(1 for d in tr if d != "loa") >= 2):
            from ..errors import ModelWarning

            warn_user(
                f"{where}.clearance_shape: 'radial' needs two translations across the "
                f"body's axis ('x', 'y' for an axis along z, ...); this body's "
                f"{sorted(tr)} are not, so its clearance acts per axis (a square dead "
                f"zone); give the body an axis along x, y or z, or clearance_shape = "
                f"'per_axis' to say so", ModelWarning)
        radial = {}
        for d, j in tr.items():
            u = dmap.axes[body][d]
            k = float(k_xyz @ u ** 2)
            if sup.damping is not None:
                c = sup.damping
            elif sup.damping_ratio is not None:
                c = 2 * sup.damping_ratio * math.sqrt(k * m)
            else:
                c = 0.0
            # deformation: the body's displacement along u, less that of the seat (a
            # bearing between two bodies: the same law, its other end on the seat,
            # which moves with the seat body's translations and, for a pin off its
            # axis, its rotation: theta_C (a_C x r) . u)
            dofs, coefs = [j], [1.0]
            if on is not None:
                # (a seat without translations of its own moves as its centre does: a
                # planet rigid on its pin with the carrier, a compound planet's gear
                # with its shaft partner)
                for jj, cc in centre_projection(kin, dmap, on, u, -1.0, tol=1e-15):
                    dofs.append(jj)
                    coefs.append(cc)
                idx_on, s_on = dmap.theta.get(on, (-1, 1.0))
                arm = float(seat_arm @ u)
                if idx_on >= 0 and abs(arm) > 1e-15:
                    dofs.append(idx_on)
                    coefs.append(-s_on * arm)
            # the seat's position error (pin error) and the body's eccentricity: the
            # bearing is unloaded when the body is displaced by them
            err = float(pin_offset @ u) + float(ecc_const @ u)
            sines = [(float(a @ u), om, ph) for a, om, ph in ecc_sines
                     if abs(float(a @ u)) > 0.0]
            if d in pair:
                radial[d] = dict(dofs=dofs, coefs=coefs, stiffness=k, damping=c,
                                 error_constant=err, errors=sines)
                continue
            elements.append(dict(name=f"{body}.support.{d}", kind=SPRING, dofs=dofs,
                                 coefs=coefs, stiffness=k, damping=c, gaps=sup.clearance,
                                 error_constant=err, errors=sines))
        if radial:
            a, b = (radial[d] for d in pair)
            if not (math.isclose(a["stiffness"], b["stiffness"], rel_tol=1e-9)
                    and math.isclose(a["damping"], b["damping"], rel_tol=1e-9, abs_tol=1e-12)):
                raise ModelError([(f"{where}.clearance_shape", (
                    f"a radial clearance needs one stiffness across the axis, but "
                    f"{pair[0]!r} has {a['stiffness']:.4g} N/m and {pair[1]!r} "
                    f"{b['stiffness']:.4g} N/m (stiffness_y or axial_stiffness); give them "
                    f"equal, or clearance_shape = 'per_axis'"))])
            elements.append(dict(
                name=f"{body}.support", kind=SPLINE, component_names=pair,
                x=(a["dofs"], a["coefs"]), y=(b["dofs"], b["coefs"]),
                stiffness=a["stiffness"], damping=a["damping"], stick_limit=0.0,
                clearance=sup.clearance, friction_force=0.0, velocity_scale=v_reg,
                error_constant_x=a["error_constant"], errors_x=a["errors"],
                error_constant_y=b["error_constant"], errors_y=b["errors"]))

    # ---- splines: torsion spring + 2-D radial element (Dong et al. 2021 eq. 6)
    for name, sp in model.splines.items():
        hub, flo = sp.connects
        ih, sh = dmap.theta[hub]
        if_, sf = dmap.theta[flo]
        dofs, coefs = [], []
        if ih >= 0:
            dofs.append(ih)
            coefs.append(sh)
        if if_ >= 0:
            dofs.append(if_)
            coefs.append(-sf)
        if dofs:  # its dead zone: half the circumferential backlash, as an angle
            elements.append(dict(name=f"{name}.torsion", kind=SPRING, dofs=dofs, coefs=coefs,
                                 stiffness=sp.torsional_stiffness,
                                 gaps=0.5 * sp.backlash / sp.pitch_radius))
        # the radial plane: normal to the floating member's axis (global x, y for an
        # axis along z); the law is isotropic, so any orthonormal pair of directions does
        axis = kin.bodies[flo].axis / np.linalg.norm(kin.bodies[flo].axis)
        e1 = loa.reference_direction(axis, 0.0)
        e2 = cross(axis, e1)
        if e2[np.argmax(np.abs(e2))] < 0:
            e2 = -e2
        rows = {}
        for comp, e in (("x", e1), ("y", e2)):
            rdofs, rcoefs = [], []
            for body, sgn in ((hub, 1.0), (flo, -1.0)):
                for j, c in dmap.project(body, e, sgn, tol=1e-15):
                    rdofs.append(j)
                    rcoefs.append(c)
            rows[comp] = (rdofs, rcoefs)
        if rows["x"][0] or rows["y"][0]:
            # friction force F_m = mu T / r_p, T the nominal torque through the spline
            # (carried by the floating member)
            f_m = sp.friction_coefficient * kin.bodies[flo].torque / sp.pitch_radius
            elements.append(dict(name=f"{name}.radial", kind=SPLINE, x=rows["x"], y=rows["y"],
                                 stiffness=sp.stiffness, damping=sp.damping,
                                 stick_limit=sp.stick_limit, clearance=sp.radial_clearance,
                                 friction_force=f_m, velocity_scale=v_reg))

    # ---- torsional supports to the housing (held members: a fixed ring, a star carrier)
    for body in kin.held:
        spec = model.gears.get(body) or model.bodies[body]
        ts = spec.torsional_support
        idx, s_t = dmap.theta[body]
        if ts.rigid or idx < 0:
            continue
        k = ts.stiffness
        if ts.damping is not None:
            c = ts.damping
        elif ts.damping_ratio is not None:
            c = 2 * ts.damping_ratio * math.sqrt(k / inv_mass[idx])
        else:
            c = 0.0
        elements.append(dict(name=f"{body}.torsional_support", kind=SPRING, dofs=[idx],
                             coefs=[s_t], stiffness=k, damping=c))

    # ---- rotating frames: Coriolis, centripetal softening, centrifugal force
    gyroscopic, frame_stiffness = [], []
    free: frozenset = frozenset()
    if rotating and kin.frames:
        from .rotating import free_carriers, rotating_frame_terms

        free = free_carriers(kin, dmap, elements, inv_mass)
        frame_stiffness, gyroscopic = rotating_frame_terms(
            kin, dmap, ext, pin_stiffness(model, kin), free_carriers=free)

    # ---- drives and loads (and their torque fluctuations: elements of an additive force)
    fixed_frequency: list[str] = []
    for name, d in model.drives.items():
        idx, s = dmap.theta[d.body]
        if idx >= 0 and d.mode == "torque":
            ext[idx] += s * math.copysign(kin.drive_torques[name], d.speed)
            ground[idx] += d.speed_coefficient  # (its slip: T falls as it speeds up)
        elements += _fluctuations(f"drives.{name}", d.fluctuation, idx,
                                  -s * math.copysign(1.0, d.speed), abs(d.speed), n_table,
                                  fixed_frequency)
    for name, ld in model.loads.items():
        idx, s = dmap.theta[ld.body]
        w = kin.bodies[ld.body].speed
        if idx >= 0:
            ext[idx] -= s * math.copysign(kin.load_torques[name], w)
            ground[idx] += ld.speed_coefficient
        elements += _fluctuations(f"loads.{name}", ld.fluctuation, idx,
                                  s * math.copysign(1.0, w), abs(w), n_table, fixed_frequency)

    meta = dict(
        model_name=model.model.name,
        meshes=meta_meshes,
        dof_map=dmap,
        mesh_names=list(model.meshes),
        friction_meshes=[n for n, m in model.meshes.items() if m.friction is not None],
        splines=list(model.splines),
        carriers={c: list(p) for c, p in kin.carriers.items()},
        planet_bodies=dict(kin.planet_bodies),
        frames=dict(kin.frames),
        rotating_frame=bool(rotating and gyroscopic),
        # (carriers turning with the train's rigid-body motion: assembly.rotating)
        free_carriers=sorted(free),
        fixed_frequency_elements=fixed_frequency,
        torque_fluctuation_elements=[el["name"] for el in elements
                                     if ".fluctuation" in el["name"]],
    )
    from .tables import share_tables

    return share_tables(build_structure(dmap.names, inv_mass, elements, external_force=ext,
                                        ground_damping=ground, gyroscopic=gyroscopic,
                                        frame_stiffness=frame_stiffness, n_table=n_table,
                                        metadata=meta))


def _bearing_seat(model: Model, dmap: DofMap, body: str, on: str | None,
                  where: str, orbits: bool = False) -> str | None:
    """The body a bearing sits on (None: the housing), checked.  A planet (``orbits``)
    may sit on a carrier without translations: its pin moves with the carrier's
    rotation."""
    if on is None:
        return None
    if on == body:
        raise ModelError([(f"{where}.on", f"a bearing cannot sit on its own body {body!r}; "
                           "name another body (e.g. the carrier) or leave 'on' out for the "
                           "housing")])
    if on not in dmap.translation:
        raise ModelError([(f"{where}.on", f"unknown body {on!r}; use one of "
                           f"{sorted(dmap.translation)}")])
    if not dmap.translation[on] and not orbits:
        raise ModelError([(f"{where}.on", f"body {on!r} has no translational DOFs, so a "
                           "bearing on it is a bearing on the housing; give it x/y DOFs or "
                           "leave 'on' out")])
    return on


def orbit_radius(kin: Kinematics, body: str, carrier: str) -> float:
    """Distance of ``body``'s nominal centre from ``carrier``'s axis [m]."""
    c = kin.bodies[carrier]
    a = c.axis / np.linalg.norm(c.axis)
    r = kin.bodies[body].position - c.position
    return float(np.linalg.norm(r - a * float(r @ a)))


def planet_bearer(model: Model, kin: Kinematics, body: str) -> str | None:
    """The body on the carrier's pin of the planet shaft ``body`` is on: the member of
    its rigid group (``body`` itself for a simple planet) whose bearing sits on the
    carrier (``support.on``), one with translations first; None for a body that is no
    planet.  Its bearing, pin and pin error are the whole planet shaft's."""
    carrier = kin.planet_bodies.get(body)
    if carrier is None:
        return None
    rep = kin.groups[body]
    on_pin = []
    for b in model.body_names():
        spec = model.gears.get(b) or model.bodies[b]
        if kin.groups[b] == rep and spec.support is not None and spec.support.on == carrier:
            on_pin.append((not any(d in spec.dofs for d in ("x", "y", "z", "loa")), b))
    return min(on_pin)[1] if on_pin else None


def centre_projection(kin: Kinematics, dmap: DofMap, body: str, vec, sign: float = 1.0,
                      tol: float = 0.0):
    """(DOF, coefficient) of the displacement of ``body``'s centre along ``vec``: its
    own translations; those of the body it shares them with (``dmap.host``: a compound
    planet's gear without translations); or -- a planet without translations, rigid on
    its pin -- those of its carrier and the carrier's rotation,
    ``theta_C (a_C x r) . vec``."""
    if body in dmap.host:
        return dmap.project(dmap.host[body], vec, sign, tol)
    if dmap.translation.get(body) or body not in kin.planet_bodies:
        return dmap.project(body, vec, sign, tol)
    carrier = kin.planet_bodies[body]
    c = kin.bodies[carrier]
    a = c.axis / np.linalg.norm(c.axis)
    r = kin.bodies[body].position - c.position
    r = r - a * float(r @ a)
    out = list(dmap.project(carrier, vec, sign, tol))
    idx, s_c = dmap.theta.get(carrier, (-1, 1.0))
    arm = float(cross(a, r) @ np.asarray(vec, dtype=float))
    if idx >= 0 and abs(arm) > tol:
        out.append((idx, sign * s_c * arm))
    return out


def _rigid_pin_offset(model: Model, kin: Kinematics, dmap: DofMap, body: str):
    """Offset of the centre of a planet rigid on its pin (no translations, its own or its
    shaft's): the position error of its pin and, on a carrier without translations, the
    carrier's eccentricity, as (constant vector, [(vector amplitude, omega, phase)]); None
    for any other body."""
    if body in dmap.host or dmap.translation.get(body) or body not in kin.planet_bodies:
        return None
    carrier = kin.planet_bodies[body]
    const, sines = np.zeros(3), []
    bearer = planet_bearer(model, kin, body)
    if bearer is not None:
        kind = "gears" if bearer in model.gears else "bodies"
        spec = model.gears.get(bearer) or model.bodies[bearer]
        const = _seat_geometry(kin, bearer, carrier, spec.support,
                               f"{kind}.{bearer}.support")[1]
    if not dmap.translation.get(carrier):
        c_const, sines = _eccentricity(model, kin, carrier)
        const = const + c_const
    return const, sines


def _seat_geometry(kin: Kinematics, body: str, on: str | None, sup, where: str):
    """(a_C x r, pin offset) of a bearing on the body ``on``: the displacement of the
    seat per unit rotation of ``on`` (r from its axis to the body's nominal centre) and
    the seat's position error (radial along r, tangential along a_C x r / |r|)."""
    zero = np.zeros(3)
    if on is None:
        return zero, zero
    c = kin.bodies[on]
    a = c.axis / np.linalg.norm(c.axis)
    r = kin.bodies[body].position - c.position
    r = r - a * float(r @ a)
    arm = cross(a, r)
    pe = sup.pin_error
    if pe.is_zero:
        return arm, zero
    rn = float(np.linalg.norm(r))
    if rn <= 0.0:  # pragma: no cover - refused by the kinematics (find_layout)
        raise ModelError([(f"{where}.pin_error", "the body sits on the seat body's axis: "
                           "its pin has no radial direction; remove 'pin_error'")])
    e_r = r / rn
    return arm, pe.radial * e_r + pe.tangential * cross(a, e_r)


def _eccentricity(model: Model, kin: Kinematics, body: str):
    """A body's eccentricity (carrier eccentricity) as the offset of its centre from its
    bearing axis: (constant vector, [(vector amplitude, omega, phase), ...]) with the
    offset ``const + sum amp sin(omega t + phase)`` in the frame of the body's
    translations (constant for a carrier measured in its own frame)."""
    spec = model.bodies.get(body)
    zero = np.zeros(3)
    if spec is None or spec.eccentricity == 0.0:
        return zero, []
    bk = kin.bodies[body]
    from .rotating import in_plane_basis

    e1, e2 = in_plane_basis(bk.axis)
    eps, phi = spec.eccentricity, spec.eccentricity_phase
    w = kin.relative_speed(body, kin.frames.get(body))
    if w == 0.0:
        return eps * (math.cos(phi) * e1 + math.sin(phi) * e2), []
    # eps (cos(phi + w t) e1 + sin(phi + w t) e2), cos x = sin(x + pi/2)
    return zero, [(eps * e1, w, phi + math.pi / 2), (eps * e2, w, phi)]


def _friction_projection(model: Model, kin: Kinematics, dmap: DofMap, name: str,
                         n_table: int) -> dict:
    """Friction projection W of a mesh (build_structure's ``friction`` entry).

    Table rows (per unit normal load, :func:`excitation.friction_table`): 0 the friction
    force on the driven gear along the rolling direction t, 1 and 2 the friction moments
    on driver and driven gear, positive in their direction of rotation.  The generalized
    force is -W f: so W has +t on the driver's translations and -t on the driven gear's
    (row 0), and -s sgn(w) on each gear's rotation (rows 1, 2), s the sign of the body's
    axis against its DOF's axis and sgn(w) its sense of rotation.
    """
    mk = kin.meshes[name]
    table = excitation.friction_table(model, kin, name, n_table)
    t_dir = excitation.friction_direction(kin, name)
    dofs, coefs, rows = [], [], []
    for body, sgn, row in ((mk.driver, 1.0, 1), (mk.driven, -1.0, 2)):
        idx, s = dmap.theta.get(body, (-1, 1.0))
        if idx >= 0:
            # sense of rotation in the mesh's frame (the carrier's for a planet mesh)
            speed = mk.driver_speed if body == mk.driver else mk.driven_speed
            w = 1.0 if speed > 0 else -1.0
            dofs.append(idx)
            coefs.append(-s * w)
            rows.append(row)
        for j, c in centre_projection(kin, dmap, body, t_dir, sgn):
            dofs.append(j)
            coefs.append(c)
            rows.append(0)
    return dict(table=table, dofs=dofs, coefs=coefs, rows=rows)


def _fluctuations(where: str, harmonics, idx: int, coef: float, speed: float,
                  n_table: int, fixed: list) -> list[dict]:
    """One element per harmonic of a drive's or load's torque fluctuation: no stiffness,
    an additive force table T_a sin(2 pi s + phase) over its own period, on the body's
    rotation (``coef``: the sign that makes a positive value add to the nominal torque).
    Fixed-frequency harmonics are listed in ``fixed`` (a speed sweep does not scale
    them)."""
    if not harmonics:
        return []
    if idx < 0:
        raise ModelError([(f"{where}.fluctuation", (
            "the body has no rotation of its own (held by a 'speed' drive or rigidly): its "
            "torque cannot fluctuate; put the fluctuation on a body that turns freely"))])
    grid = np.arange(n_table) / n_table
    out = []
    for k, h in enumerate(harmonics, start=1):
        f = h.order * speed / (2 * math.pi) if h.order is not None else h.frequency
        name = f"{where}.fluctuation{k}"  # (a drive and a load may share a name)
        if h.order is None:
            fixed.append(name)
        out.append(dict(name=name, kind=SPRING, dofs=[idx], coefs=[coef], stiffness=0.0,
                        frequency=f, phase=0.0,
                        force=h.amplitude * np.sin(2 * math.pi * grid + h.phase)))
    return out


def _radial_pair(sup, axes: dict, axis) -> tuple[str, ...]:
    """The two translational DOFs across ``axis`` that a radial clearance joins (empty
    without a clearance, for 'per_axis', or unless exactly two DOFs lie across it)."""
    if not sup.clearance > 0 or sup.clearance_shape != "radial":
        return ()
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    across = tuple(d for d, u in axes.items() if abs(float(np.asarray(u) @ a)) < 1e-9)
    return across if len(across) == 2 else ()


def pin_stiffness(model, kin):
    """``f(body, direction)``: the stiffness of a planet's bearing on its carrier's pin
    along a unit direction [N/m] (None for a body not on a pin), for the pin-preload term
    of :func:`torquesplit.assembly.rotating.rotating_frame_terms` and its check against
    the centrifugal softening;
    ``f.seated(body, direction)`` the bodies on bearings on that planet, with theirs."""

    def along(sup, direction):
        k_rad = support_stiffness(sup)
        k_xyz = np.array([k_rad, sup.stiffness_y or k_rad, sup.axial_stiffness or k_rad])
        return float(k_xyz @ np.asarray(direction) ** 2)

    def stiffness(body, direction):
        spec = model.gears.get(body) or model.bodies[body]
        sup = spec.support
        if sup is None or sup.on != kin.planet_bodies.get(body):
            return None
        return along(sup, direction)

    def seated(body, direction):
        """(body, stiffness along ``direction``) of each body with translations on a
        bearing on ``body`` (a compound planet's gear on the planet on the pin)."""
        out = []
        for b in model.body_names():
            spec = model.gears.get(b) or model.bodies[b]
            if (spec.support is not None and spec.support.on == body
                    and any(d in spec.dofs for d in ("x", "y", "z", "loa"))):
                out.append((b, along(spec.support, direction)))
        return out

    stiffness.seated = seated
    return stiffness


def support_stiffness(sup, where: str = "support") -> float:
    """Radial support stiffness, from the value or from shaft bending in series.

    ``where`` names the support in the error raised when the shaft's numbers give no
    finite stiffness (e.g. a gear at 1e-300 m from a bearing)."""
    if sup.stiffness is not None:
        return sup.stiffness
    sh = sup.shaft
    a = sh.position
    b = sh.span - a
    inertia = math.pi * sh.diameter**4 / 64
    # Ji & Li eqs. 5-7: simply supported shaft, load at a from one bearing:
    # deflection y = F a^2 b^2 / (3 E I l)  =>  k_S = 3 E I l / (a^2 b^2)
    den = a**2 * b**2
    k_shaft = 3 * sh.youngs_modulus * inertia * sh.span / den if den > 0 else math.inf
    if not (math.isfinite(k_shaft) and k_shaft > 0):
        raise ModelError([(f"{where}.shaft", (
            f"the shaft bending stiffness 3 E I l / (a^2 b^2) is not a finite positive "
            f"number (gear {a:g} m and {b:g} m from the bearings, span {sh.span:g} m, "
            f"diameter {sh.diameter:g} m); place the gear between the bearings, away from "
            f"them, or give the support a 'stiffness'"))])
    if sh.bearing_stiffness is None:
        return k_shaft
    # Ji & Li eq. 10: bearing in series with the shaft, k' = k_S k_C / (k_S + k_C)
    return k_shaft * sh.bearing_stiffness / (k_shaft + sh.bearing_stiffness)
