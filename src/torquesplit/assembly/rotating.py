"""Rotating-frame terms of the bodies whose translations are measured in a carrier's frame.

With the carrier turning at the constant speed Omega about its unit axis a, a body of
mass m whose translations u are measured in the carrier's frame has the absolute
acceleration ``u'' + 2 Omega a x u' + Omega a x (Omega a x (r0 + u))`` (r0 its nominal
position from the axis).  Moved to the right-hand side, the equations of motion of the
lumped planetary models in the literature follow (Lin & Parker 1999 eq. 1 with Omega_c;
Cooley & Parker 2012 eq. 1)::

    M q'' + Omega G q' + (K_b + K_m - Omega^2 K_Omega) q = T

* Coriolis (gyroscopic) term, generalized force ``-G v`` with
  ``G_ij = 2 m Omega u_i . (a x u_j)`` over the body's translational DOF directions
  u_i, u_j (skew-symmetric, it does no work): for x, y DOFs about z,
  ``G_xy = -2 m Omega``, ``G_yx = +2 m Omega`` (Lin & Parker 1999, the 2 m Omega blocks
  of G);
* centripetal softening ``-m Omega^2`` on every in-plane translation (Lin & Parker 1999
  K_Omega = diag(m, m, 0) per body): entries ``-m Omega^2 V_k V_k^T`` of the frame
  stiffness matrix K_f (generalized force -K_f q), V_k the displacement along two
  orthonormal directions of the carrier's plane.  For a carrier held against turning
  with the train, the displacement is the body's own, and the planet's centrifugal
  preload P in its pin turns with the carrier: a geometric stiffness ``P R`` on the
  carrier's rotation (R the pin radius, P = m Omega^2 R k_t / (k_t - m Omega^2) the
  static load of a bearing of stiffness k_t along the pin's tangent), the exact
  linearisation of the preloaded pin.  For a carrier whose rotation is part of the
  train's rigid-body motion (:func:`free_carriers`), the displacement is measured from
  where the carrier's rotation theta_c takes the body's nominal position r0,
  u - theta_c a x r0, so that the kinematic rigid rotation (the gear ratios') is an
  exact zero-frequency mode which torques balanced by the gear ratios do not load: with
  the exact form the zero mode turns the planets by (R + delta) / R of the carrier while
  the meshes, linearised about the nominal geometry, keep the gear ratios, and balanced
  torques loaded it by about m Omega^2 / k_t (a torque-driven train's speed drifted).
  The difference between the forms is of order 2 m Omega^2 / k_t in the modes that twist
  the carrier against its planets.  The radial preload of the meshes is left out;
* centrifugal force ``m Omega^2 r0`` (outwards, constant in the carrier frame) on the
  translations of a body off the axis (the planets), an external force;
* A planet without translations sits rigidly on its pin: its mass is carried by the
  carrier (translations and ``m R^2`` on its rotation, assembly/assemble.py) and so are
  its rotating-frame terms and centrifugal force.  A gear without translations on the
  shaft of a planet that has them (a compound planet) moves with that planet: its mass
  joins the planet's in these terms.  A gear with translations on a bearing on the planet
  loads the pin through that bearing (its static share enters a held carrier's pin
  preload), which must be stiffer than that gear's softening.

The bodies' rotations need no term (planar model, all axes parallel to a).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..gears import line_of_action as loa
from ..gears.vectors import cross


def in_plane_basis(axis) -> tuple[np.ndarray, np.ndarray]:
    """Two orthonormal directions of the plane normal to ``axis`` (x, y for the z axis)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    e1 = loa.reference_direction(a, 0.0)
    return e1, cross(a, e1)


def rotating_frame_terms(kin, dmap, ext: np.ndarray, pin_stiffness=None,
                         free_carriers=()):
    """Frame-stiffness and gyroscopic entries of every body measured in a turning
    carrier's frame; adds the centrifugal forces to ``ext`` in place.

    ``pin_stiffness(body, direction)`` gives the stiffness of a planet's bearing along
    a unit direction (for the pin-preload term, and to refuse a bearing softer than the
    centrifugal softening).  ``free_carriers``: the carriers whose rotation is part of a
    rigid-body motion of the train (:func:`free_carriers`), whose softening is measured
    from the pin's rigid rotation; the others' is absolute, with the pin preload.
    Returns ``(frame_stiffness, gyroscopic)``, lists of ``(i, j, value)`` for
    :func:`~torquesplit.assembly.structure.build_structure`: the inertial terms are not
    elements (they carry no force of their own), so they cost one multiply-add per entry.
    """
    frame: list[tuple[int, int, float]] = []
    gyro: list[tuple[int, int, float]] = []
    preload: dict[str, list] = {}  # carrier -> [its rotation DOF, sign, stiffness]
    # planets rigid on their pins (no translations) move with their carrier
    rigid_pins: dict[str, list[str]] = {}
    # gears without translations on the shaft of a planet that has them (a compound
    # planet) move with that planet (``dmap.host``)
    hosted: dict[str, list[str]] = {}
    for p, c in kin.planet_bodies.items():
        if p in dmap.host:
            hosted.setdefault(dmap.host[p], []).append(p)
        elif not dmap.translation.get(p):
            rigid_pins.setdefault(c, []).append(p)
    for body in dmap.translation:  # the model's order: a reproducible element list
        carrier = kin.frames.get(body)
        tr = dmap.translation[body]
        if carrier is None or not tr:
            continue
        cb = kin.bodies[carrier]
        omega = float(cb.speed)
        if omega == 0.0:
            continue
        a = cb.axis / np.linalg.norm(cb.axis)
        m = kin.bodies[body].mass + sum(kin.bodies[p].mass for p in hosted.get(body, []))
        if body == carrier:
            m += sum(kin.bodies[p].mass for p in rigid_pins.get(body, []))
        dirs = {d: dmap.axes[body][d] for d in tr}
        # Coriolis: G_ij = 2 m Omega u_i . (a x u_j)   (Lin & Parker 1999 G)
        for di, i in tr.items():
            for dj, j in tr.items():
                g = 2.0 * m * omega * float(dirs[di] @ cross(a, dirs[dj]))
                if abs(g) > 1e-14 * 2.0 * m * abs(omega):
                    gyro.append((i, j, g))
        # centripetal softening -m Omega^2 in the carrier's plane (Lin & Parker 1999
        # K_Omega): -m Omega^2 (V_k V_k^T) for the projection V_k of each in-plane
        # direction; for a carrier that turns with the train's rigid-body motion, of the
        # displacement from where its rotation theta_c takes the body's nominal position
        # r0 (theta_c a x r0): that rotation only shifts the nominal one, and the
        # centrifugal forces turn with it
        r_nom = kin.bodies[body].position - cb.position
        r_nom = r_nom - a * float(r_nom @ a)
        idx_c, s_c = dmap.theta.get(carrier, (-1, 1.0))
        turn = (cross(a, r_nom) if body != carrier and idx_c >= 0 and carrier in free_carriers
                else None)
        for e in in_plane_basis(a):
            rows = dmap.project(body, e, 1.0, tol=1e-15)
            if turn is not None and abs(float(e @ turn)) > 0.0:
                rows = [*rows, (idx_c, -s_c * float(e @ turn))]
            for i, ci in rows:
                for j, cj in rows:
                    frame.append((i, j, -m * omega**2 * ci * cj))
        # centrifugal force of the nominal position, m Omega^2 r0 outwards (for a carrier,
        # that of the planets rigid on its pins)
        carried = [(b, kin.bodies[b].mass) for b in [body] + hosted.get(body, [])] \
            if body != carrier else [(p, kin.bodies[p].mass) for p in rigid_pins.get(body, [])]
        for b, mb in carried:
            r = kin.bodies[b].position - cb.position
            r0 = r - a * float(r @ a)
            if float(np.linalg.norm(r0)) > 0.0:
                for j, c in dmap.project(body, mb * omega**2 * r0, 1.0, tol=0.0):
                    ext[j] += c
        # a planet's bearing must be stiffer than the centrifugal softening of what it
        # holds (the planet, and a gear on a bearing on it: statically a softening
        # s_i = k_i m_i Omega^2 / (k_i - m_i Omega^2)), or its static preload has no bound
        if body in kin.planet_bodies and body != carrier and pin_stiffness is not None:
            big_r = float(np.linalg.norm(r_nom))
            tangent = cross(a, r_nom / big_r) if big_r > 0 else None
            k_t = pin_stiffness(body, tangent) if big_r > 0 else None
            if k_t is not None:
                soft, load = m * omega**2, m * omega**2 * big_r
                for b, k_i in getattr(pin_stiffness, "seated", lambda *_: [])(body, tangent):
                    soft_i = kin.bodies[b].mass * omega**2
                    _stiffer_than_spin(f"gears.{b}.support", f"the bearing of {b!r} on the "
                                       f"planet {body!r} ({k_i:.3g} N/m)", k_i, soft_i, "")
                    s_i = k_i * soft_i / (k_i - soft_i)
                    r_i = kin.bodies[b].position - cb.position
                    soft += s_i
                    load += s_i * float(np.linalg.norm(r_i - a * float(r_i @ a)))
                _stiffer_than_spin(f"gears.{body}.support", f"the planet's bearing "
                                   f"({k_t:.3g} N/m along its pin's tangent)", k_t, soft,
                                   ": it would fly off its pin")
                if idx_c >= 0 and carrier not in free_carriers:
                    # the pin preload P R, P = k_t delta the bearing's static load (delta =
                    # load / (k_t - soft); one planet body: m Omega^2 R k_t / (k_t -
                    # m Omega^2)): when the carrier turns by theta the preload turns too
                    preload.setdefault(carrier, [idx_c, s_c, 0.0])[2] += \
                        big_r * k_t * load / (k_t - soft)
    # the pin preloads of all the planets of a held carrier, on its rotation
    for idx, s_c, k in preload.values():
        frame.append((idx, idx, k * s_c * s_c))
    return frame, gyro


def free_carriers(kin, dmap, elements, inv_mass) -> frozenset:
    """The turning carriers whose rotation is part of a rigid-body motion of the train
    (the null space of the stiff elements' projections, :mod:`assembly.structure`
    element dicts): a train driven and loaded by torques turns freely, with its carrier.
    Their planets' softening is measured from the pin's rigid rotation, so that this
    motion, the gear ratios', stays free of load; a carrier held (a shaft to a member at
    a set speed) keeps the exact terms of its pins."""
    from ..solve.static import rigid_modes_of

    turning = [c for c in kin.carriers if kin.bodies[c].speed
               and dmap.theta.get(c, (-1, 1.0))[0] >= 0]
    if not turning:
        return frozenset()
    rows = []
    for el in elements:
        parts = ([el["x"], el["y"]] if "x" in el and "y" in el else
                 [(el["dofs"], el["coefs"])] if np.any(np.asarray(el.get("stiffness", 0.0))
                                                       != 0.0) else [])
        for dofs, coefs in parts:
            row = np.zeros(len(inv_mass))
            np.add.at(row, np.asarray(dofs, dtype=np.int64), np.asarray(coefs, dtype=float))
            rows.append(row)
    phi = rigid_modes_of(np.array(rows).reshape(len(rows), len(inv_mass)), inv_mass)
    if phi.shape[1] == 0:
        return frozenset()
    big = float(np.abs(phi).max())
    return frozenset(c for c in turning
                     if float(np.abs(phi[dmap.theta[c][0]]).max()) > 1e-9 * big)


def _stiffer_than_spin(where: str, bearing: str, k: float, soft: float, then: str) -> None:
    """Refuse a bearing ``k`` not stiffer than the centrifugal softening ``soft`` =
    m Omega^2 of what it holds (the static preload would be unbounded)."""
    if not k > soft:
        raise ModelError([(where, (
            f"{bearing} is softer than its centrifugal softening m Omega^2 = {soft:.3g} N/m "
            f"at the carrier's speed{then}; give a stiffer bearing or a lower speed"))])


class FrameTermsAt:
    """The rotating-frame terms of ``structure`` at ``factor`` times the model's speeds
    (a speed sweep at constant load), called as ``terms(factor) -> (gy_coef, fs_coef,
    external_force)`` in the structure's own order.  Coriolis scales with the carrier's
    speed, centripetal softening and centrifugal force with its square, a held carrier's
    pin preload as m Omega^2 R k_t / (k_t - m Omega^2): recomputed, not scaled (and the
    bearings checked against the softening at that speed).  The drive and
    load torques stay the file's (the model's own centrifugal forces are taken out of the
    structure's external forces once, here)."""

    def __init__(self, model, kin, structure):
        from .assemble import pin_stiffness

        self.kin = kin
        self.structure = structure
        self.dmap = structure.metadata["dof_map"]
        self.stiff = pin_stiffness(model, kin)
        self.free = frozenset(structure.metadata.get("free_carriers", ()))
        own = np.zeros(structure.n_dof)
        rotating_frame_terms(kin, self.dmap, own, self.stiff, self.free)
        self.loads = structure.external_force - own  # (without the centrifugal forces)
        self._kept: dict[float, tuple] = {}  # (a solver and its statics ask per speed)

    def __call__(self, factor: float):
        key = float(factor)
        if key not in self._kept:
            if len(self._kept) > 8:
                self._kept.clear()
            self._kept[key] = self._terms(key)
        return self._kept[key]

    def _terms(self, factor: float):
        from ..model.kinematics import kinematics_at

        s = self.structure
        scaled = kinematics_at(self.kin, factor)
        ext = np.zeros(s.n_dof)
        try:
            frame, gyro = rotating_frame_terms(scaled, self.dmap, ext, self.stiff, self.free)
        except ModelError as exc:  # (a sweep keeps its curve on a SolverError)
            from ..errors import SolverError

            raise SolverError(f"at {factor:.6g} times the model's speed: "
                              f"{'; '.join(m for _, m in exc.issues)}") from None
        from .structure import merged_entries

        frame, gyro = merged_entries(frame), merged_entries(gyro)  # (as the structure's)
        if (len(gyro) != s.gy_coef.size or len(frame) != s.fs_coef.size
                or [j for _, j, _ in gyro] != s.gy_idx.tolist()
                or [j for _, j, _ in frame] != s.fs_idx.tolist()):
            raise ValueError("the rotating-frame terms at another speed do not have the "
                             "structure's pattern (was it assembled with "
                             "rotating_frame=False?)")
        return (np.array([g for _, _, g in gyro]), np.array([k for _, _, k in frame]),
                self.loads + ext)
