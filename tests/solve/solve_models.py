"""Tiny structures for the solver tests, built directly with build_structure.

Spur pair convention: two torsional DOFs, one mesh element with projection
coefficients (r1, -r2), so delta = r1 th1 - r2 th2 and the mesh force pushes gear 1
back (-r1 f) and gear 2 forward (+r2 f).
"""

from __future__ import annotations

import math

import numpy as np

from torquesplit.assembly.structure import MESH, SPLINE, SPRING, build_structure

J1, J2 = 0.01, 0.04  # kg m^2
R1, R2 = 0.05, 0.10  # m
K_MESH = 2.0e8  # N/m
T_IN = 100.0  # N m on gear 1; gear 2 carries -T_IN r2 / r1


def pair_frequency(k=K_MESH) -> float:
    """Natural frequency of the spur pair [Hz]."""
    return math.sqrt(k * (R1**2 / J1 + R2**2 / J2)) / (2 * math.pi)


def spur_pair(*, torque=T_IN, load=None, stiffness=K_MESH, damping=0.0, gaps=0.0,
              frequency=0.0, errors=(), phase=0.0, n_table=64, extra=()):
    """Single spur pair; ``load`` defaults to the balancing torque -torque r2 / r1."""
    load = -torque * R2 / R1 if load is None else load
    mesh = dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[R1, -R2],
                stiffness=stiffness, damping=damping, gaps=gaps, frequency=frequency,
                errors=list(errors), phase=phase)
    return build_structure(["g1.theta", "g2.theta"], [1 / J1, 1 / J2], [mesh, *extra],
                           external_force=[torque, load], n_table=n_table)


def random_structure(seed: int = 0):
    """A 5-DOF structure exercising every feature of the right-hand side."""
    rng = np.random.default_rng(seed)
    n = 5
    els = []
    ph = np.arange(32) / 32
    for i in range(4):
        dofs = rng.choice(n, size=3, replace=False)
        els.append(dict(
            name=f"mesh{i}", kind=MESH, dofs=dofs.tolist(),
            coefs=rng.normal(size=3).tolist(),
            stiffness=1e8 * (1.0 + 0.3 * np.sin(2 * np.pi * ph) + 0.1 * rng.random(32)),
            frequency=500.0 + 300 * i, phase=rng.random(), damping=100.0 * rng.random(),
            gaps=(rng.random(3) * 2e-6).tolist() if i % 2 else 1e-6,
            error_constant=1e-6 * rng.normal(),
            errors=[(1e-6 * rng.random(), 2 * math.pi * 40 * (j + 1), rng.random())
                    for j in range(2)],
            force=(50.0 * np.maximum(0, np.sin(2 * np.pi * ph)) if i == 0 else 0.0),
        ))
    for i in range(3):
        els.append(dict(name=f"spring{i}", kind=SPRING, dofs=[i, i + 1], coefs=[1.0, -1.0],
                        stiffness=1e6 * (1 + i), damping=10.0,
                        gaps=2e-6 if i == 1 else 0.0,
                        errors=[(5e-7, 300.0, 0.1)] if i == 2 else []))
    els.append(dict(name="ground", kind=SPRING, dofs=[4], coefs=[1.0], stiffness=3e7))
    return build_structure([f"b{i}.x" for i in range(n)], 1.0 / rng.uniform(0.5, 2.0, n),
                           els, external_force=rng.normal(size=n) * 10,
                           ground_damping=rng.random(n), n_table=32)


def random_structure_extras(seed: int = 0, gyroscopic: bool = False):
    """:func:`random_structure` plus tooth friction on its four meshes and two spline
    radial elements (one with a stick limit and a clearance, one with a clearance and
    errors on its components, as a bearing's radial clearance has), so
    that every branch of the spline law and of the friction scatter is reachable; with
    ``gyroscopic`` also a gyroscopic coupling of DOFs 0 and 1 (and a diagonal entry) and
    a frame stiffness on them."""
    base = random_structure(seed)
    rng = np.random.default_rng(1000 + seed)
    n = base.n_dof
    ph = np.arange(32) / 32
    els = []
    for e, name in enumerate(base.element_names):
        sl = slice(base.v_ptr[e], base.v_ptr[e + 1])
        el = dict(name=name, kind=int(base.element_kind[e]), dofs=base.v_dof[sl].tolist(),
                  coefs=base.v_coef[sl].tolist(), stiffness=base.stiffness_table[e],
                  frequency=float(base.frequency[e]), phase=float(base.phase[e]),
                  damping=float(base.damping[e]),
                  gaps=base.gap_values[base.gap_ptr[e]:base.gap_ptr[e + 1]].tolist(),
                  error_constant=float(base.error_constant[e]),
                  errors=list(zip(base.error_amplitude[base.error_ptr[e]:base.error_ptr[e + 1]],
                                  base.error_omega[base.error_ptr[e]:base.error_ptr[e + 1]],
                                  base.error_phase[base.error_ptr[e]:base.error_ptr[e + 1]],
                                  strict=True)),
                  force=base.force_table[e])
        if name.startswith("mesh"):
            table = [0.05 * np.sign(np.sin(2 * np.pi * (ph - rng.random())))
                     + 0.01 * rng.normal(size=32),
                     0.002 * rng.normal(size=32), 0.003 * rng.normal(size=32)]
            dofs = rng.choice(n, size=4, replace=False).tolist()
            el["friction"] = dict(table=table, dofs=dofs, coefs=rng.normal(size=4).tolist(),
                                  rows=[0, 1, 2, 0])
        els.append(el)
    els.append(dict(name="spA", kind=SPLINE, x=([0, 1], [1.0, -1.0]), y=([2], [-1.0]),
                    stiffness=5e7, damping=20.0, stick_limit=1e-6, clearance=3e-6,
                    friction_force=30.0, velocity_scale=1e-3))
    # spB carries errors on its components, as a bearing with a radial clearance does
    # (its seat offset and the body's eccentricity): d = V q - e in every consumer
    els.append(dict(name="spB", kind=SPLINE, x=([3], [-1.0]), y=([4], [-1.0]),
                    stiffness=2e7, damping=5.0, friction_force=10.0, velocity_scale=1e-3,
                    clearance=1e-6, error_constant_x=1.5e-6,
                    errors_y=[(1e-6, 250.0, 0.3)]))
    # gyroscopic coupling of two translations (a body in a rotating frame), so that the
    # velocity-coupling term of every right-hand side is exercised too
    gyro = [(0, 1, -35.0), (1, 0, 35.0), (3, 3, 2.0)] if gyroscopic else []
    # and a frame stiffness (centripetal softening of a body in a turning frame)
    frame = [(0, 0, -4e4), (1, 1, -4e4), (0, 1, 900.0), (1, 0, 900.0)] if gyroscopic else []
    return build_structure(base.dof_names, base.inv_mass, els,
                           external_force=base.external_force,
                           ground_damping=base.ground_damping, gyroscopic=gyro,
                           frame_stiffness=frame, n_table=32)
