"""Small structures with known answers for the steady-state tests and benchmarks."""

from __future__ import annotations

import math

from torquesplit.assembly.structure import MESH, SPRING, build_structure


def backlash_oscillator(zeta=0.05, f_mean=0.1, f_alt=0.05, alpha=0.0, half_gap=1.0,
                        n_table=256):
    """The non-dimensional spur pair of Kahraman & Singh (1990) and, with ``alpha``,
    Blankenship & Kahraman (1995): ``x'' + 2 zeta x' + (1 + alpha cos W t) h(x) = F_m
    + F_a W^2 cos W t``, h the backlash dead zone of half-width ``half_gap``, x the
    dynamic transmission error.  Built as one DOF q = x + e(t) with the static
    transmission error e = F_a cos W t on both elements (e'' gives the W^2 forcing) and
    the damping on its own element (viscous in and out of contact, as in the paper).
    At speed factor 1, W = 1 (mesh frequency 1 / 2 pi Hz = the natural frequency)."""
    f = 1.0 / (2 * math.pi)
    table = [1.0 + alpha * math.cos(2 * math.pi * i / n_table) for i in range(n_table)]
    err = [(f_alt, 1.0, math.pi / 2)]
    return build_structure(
        ["x"], [1.0],
        [dict(name="mesh", kind=MESH, dofs=[0], coefs=[1.0], stiffness=table, frequency=f,
              gaps=half_gap, errors=err),
         dict(name="damper", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=0.0,
              damping=2 * zeta, errors=err)],
        external_force=[f_mean], n_table=n_table)
