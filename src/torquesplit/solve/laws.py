"""Element laws: every force law of the model, defined once, with its derivatives.

Each law is a small scalar function compiled by numba with ``inline="always"``: the
compiled kernels inline it where they use it, and every other consumer calls the very
same function — the integrators (:mod:`torquesplit.solve._kernels`), the straight-line
right-hand side generated for a model (:mod:`torquesplit.solve.codegen` links the law's
own compiled code, see :func:`spring_force_c` and :func:`spline_force_c`), static and
quasi-static Newton
(:mod:`torquesplit.solve.static`), the modal linearisation
(:mod:`torquesplit.solve.modal`) and the numpy twin of the tests
(:mod:`torquesplit.solve.reference`).  Python callers use the batch evaluators at the
end of this module (compiled loops over arrays of elements).

=====================  ==========================================================
law                    what it is
=====================  ==========================================================
:func:`dead_zone`      deformation carried through a dead zone of half-width g
                       (backlash, bearing clearance), its slope and energy
:func:`spring_force`   mesh, shaft, support: f = k h(d; g) + c r, damping only in
                       contact; df/dd, df/dr
:func:`spline_radial`  radial law of a floating spline coupling (Dong et al. 2021
                       eq. 6): stick, float with regularised Coulomb friction,
                       contact; dF/dR, dF/dRdot, elastic energy, region
:func:`spline_force`   the radial law as a 2-D force on the relative displacement
                       (dx, dy); :func:`spline_tangent` its Jacobians with respect
                       to (dx, dy) and the rates (rx, ry)
:func:`positive_part`  tooth friction acts on the loaded flank only: max(f, 0)
:func:`table_phase`    position in a periodic table sampled over one excitation
                       period (stiffness, impact force, friction tables)
:func:`lerp`           linear interpolation between two table samples
:func:`stat_cycle`     statistics cycle index of a mesh phase
=====================  ==========================================================

Derivatives are analytic; ``tests/solve/test_laws.py`` checks each law against a hand
case and its derivatives against finite differences.  The velocity-dependent
gyroscopic (Coriolis) coupling of bodies in a rotating frame is linear (a constant
skew-symmetric matrix, ``Structure.gyroscopic_matrix``) and needs no law here.

Units: SI (m, m/s, N, N/m, N s/m).  Flags: ``error_model="numpy"``, no fastmath, so
that every consumer rounds exactly alike (the generated code is bit for bit the general
kernel).
"""

from __future__ import annotations

import math

import numpy as np
from numba import cfunc, njit, types

from torquesplit._jit_cache import track_imports

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

__all__ = [
    "STICK", "FLOAT", "CONTACT", "CYCLE_EPS",
    "dead_zone", "spring_force", "spline_radial", "spline_force", "spline_tangent",
    "positive_part",
    "table_phase", "lerp", "stat_cycle",
    "spring_forces", "dead_zones", "spline_forces", "periodic_values",
    "spring_force_c",
]

#: regions of the spline law (also the static solver's contact states of a spline)
STICK, FLOAT, CONTACT = 2, 3, 4

CYCLE_EPS = 1e-9
"""Cycle index of the statistics: floor(s), plus one when frac(s) >= 1 - CYCLE_EPS, so a
sample at a cycle boundary whose phase s = f t + phase rounds just below the integer
(e.g. 31.99999999999999) counts in the cycle it starts.  Tables and the half-gap
sequence still use floor(s)."""

_law = njit(inline="always", error_model="numpy")


# ===================================================================== elastic laws
@_law
def dead_zone(d, g):
    """Deformation ``h`` carried by an element with a dead zone, ``dh/dd`` and the
    elastic energy per unit stiffness ``u`` (so that ``k h = d(k u)/dd``).

    ``g > 0`` is the half-width of the dead zone (half the backlash of a mesh, Ji & Li
    eq. 13 and Dong et al. 2021 eq. 7; the radial clearance of a bearing): ``h = d - g``
    above it, ``d + g`` below it, 0 inside.  ``g <= 0``: no dead zone, ``h = d``.
    """
    if g > 0.0:
        if d > g:
            h = d - g
            return h, 1.0, 0.5 * h * h
        if d < -g:
            h = d + g
            return h, 1.0, 0.5 * h * h
        return 0.0, 0.0, 0.0
    return d, 1.0, 0.5 * d * d


@_law
def spring_force(k, c, d, r, g):
    """Force of a mesh, shaft or support element and its derivatives.

    ``f = k h(d; g) + c r`` with ``h`` the :func:`dead_zone`; the damping acts only
    while the element is in contact (docs/theory/model.md).  ``k`` stiffness [N/m], ``c``
    damping [N s/m], ``d`` deformation [m], ``r`` its rate [m/s], ``g`` half-gap [m].
    Returns ``(f, df/dd, df/dr)``.  The additive impact force of a mesh is added by the
    caller.
    """
    h, dh, _ = dead_zone(d, g)
    return k * h + c * r * dh, k * dh, c * dh


@_law
def spline_radial(radius, rate, k, c, stick_limit, clearance, friction_force, velocity):
    """Radial force of a floating spline coupling (Dong et al. 2021 eq. 6).

    ``radius`` R = |relative displacement| [m], ``rate`` dR/dt [m/s]:

    * R < S1 (stick): ``F = k R + c Rdot``;
    * S1 <= R <= S2 (floating in the clearance): ``F = F_m tanh(Rdot / v)``, the
      Coulomb friction of the teeth regularised over the velocity scale v;
    * R > S2 (contact): ``F = k (R - S2) + c Rdot + F_m tanh(Rdot / v)``.

    Returns ``(F, dF/dR, dF/dRdot, U, region)``: U the elastic energy (continuous in R;
    friction has none) and region STICK, FLOAT or CONTACT.
    """
    if radius < stick_limit:
        return (k * radius + c * rate, k, c, 0.5 * k * radius * radius, STICK)
    th = math.tanh(rate / velocity)
    fr = friction_force * th
    dfr = friction_force * (1.0 - th * th) / velocity
    u0 = 0.5 * k * stick_limit * stick_limit
    if radius <= clearance:
        return fr, 0.0, dfr, u0, FLOAT
    o = radius - clearance
    return k * o + c * rate + fr, k, c + dfr, u0 + 0.5 * k * o * o, CONTACT


@_law
def spline_force(dx, dy, rx, ry, k, c, stick_limit, clearance, friction_force, velocity):
    """The spline's radial law as a force on its relative displacement (dx, dy).

    ``(f_x, f_y) = F(R, Rdot) (dx, dy) / R`` with ``R = |d|`` and ``Rdot = d.d'/R``
    (:func:`spline_radial`); 0 at R = 0.  Its derivatives are
    :func:`spline_tangent` (apart, so that the integrators compute only the force).
    """
    rad = math.sqrt(dx * dx + dy * dy)
    if rad > 0.0:
        rdot = (dx * rx + dy * ry) / rad
        f = spline_radial(rad, rdot, k, c, stick_limit, clearance, friction_force,
                          velocity)[0]
        return f * dx / rad, f * dy / rad
    return 0.0, 0.0


@_law
def spline_tangent(dx, dy, rx, ry, k, c, stick_limit, clearance, friction_force, velocity):
    """Derivatives of :func:`spline_force`: ``(jxx, jxy, jyx, jyy, cxx, cxy, cyx, cyy, U,
    region)``, the Jacobian of the force with respect to (dx, dy) (j) and to the rates
    (rx, ry) (c), the elastic energy and the region of :func:`spline_radial`.  At R = 0
    the Jacobians are the isotropic tangents of the region next to the origin (stick if
    S1 > 0, floating if S2 > 0, else contact)."""
    rad = math.sqrt(dx * dx + dy * dy)
    if rad > 0.0:
        rdot = (dx * rx + dy * ry) / rad
        f, f_r, f_rd, u, region = spline_radial(rad, rdot, k, c, stick_limit, clearance,
                                                friction_force, velocity)
        nx = dx / rad
        ny = dy / rad
        gx = (rx - rdot * nx) / rad  # d Rdot / d(dx)
        gy = (ry - rdot * ny) / rad
        s = f / rad  # tangential stiffness of a radial force
        return (f_r * nx * nx + f_rd * nx * gx + s * (1.0 - nx * nx),
                f_r * nx * ny + f_rd * nx * gy - s * nx * ny,
                f_r * ny * nx + f_rd * ny * gx - s * ny * nx,
                f_r * ny * ny + f_rd * ny * gy + s * (1.0 - ny * ny),
                f_rd * nx * nx, f_rd * nx * ny, f_rd * ny * nx, f_rd * ny * ny, u, region)
    fric = friction_force / velocity
    if stick_limit > 0.0:
        slope, damp, region = k, c, STICK
    elif clearance > 0.0:
        slope, damp, region = 0.0, fric, FLOAT
    else:
        slope, damp, region = k, c + fric, CONTACT
    return slope, 0.0, 0.0, slope, damp, 0.0, 0.0, damp, 0.0, region


@_law
def positive_part(f):
    """Tooth friction acts on the loaded flank only (Jin et al. 2019): ``max(f, 0)``
    and its derivative."""
    if f > 0.0:
        return f, 1.0
    return 0.0, 0.0


# ===================================================================== excitation
@_law
def table_phase(s, n):
    """Where phase ``s`` [cycles] falls in a periodic table of ``n`` samples over one
    period: ``(i0, i1, w, fl)`` with the value ``lerp(table[i0], table[i1], w)`` and
    ``fl = floor(s)``."""
    fl = math.floor(s)
    x = (s - fl) * n
    i0 = int(x)
    w = x - i0
    if i0 >= n:  # s - fl rounded up to 1.0
        i0 -= n
    i1 = i0 + 1
    if i1 == n:
        i1 = 0
    return i0, i1, w, fl


@_law
def lerp(a0, a1, w):
    """``a0 + w (a1 - a0)``: linear interpolation between two table samples."""
    return a0 + w * (a1 - a0)


@_law
def stat_cycle(s, fl):
    """Statistics cycle index of phase ``s`` with ``fl = floor(s)`` (see CYCLE_EPS)."""
    c = np.int64(fl)
    if s - fl >= 1.0 - CYCLE_EPS:
        return c + 1
    return c


# ========================================================= batch evaluators (Python)
@_law
def negative_share(a, b, c):
    """The fraction of [0, 1] where q(u) = a + (b - a) u + c u (u - 1) is negative: the
    parabola from ``a`` (u = 0) to ``b`` (u = 1) that sags ``c`` / 4 below its chord
    at u = 1/2 (``c`` = 0: the chord).  Not an element law: the contact times'
    (``_kernels.record``), here to be compiled for the GPU as the laws are.  Twin:
    ``reference.negative_share_numpy``."""
    if c == 0.0:
        if a < 0.0:
            return 1.0 if b < 0.0 else a / (a - b)
        return b / (b - a) if b < 0.0 else 0.0
    lin = b - a - c  # q = c u^2 + lin u + a
    disc = lin * lin - 4.0 * c * a
    if disc <= 0.0:  # (no real roots: the sign of c throughout)
        return 1.0 if c < 0.0 else 0.0
    qq = -0.5 * (lin + math.copysign(math.sqrt(disc), lin))
    r1 = qq / c
    r2 = a / qq
    if r1 > r2:
        r1, r2 = r2, r1
    # (no min / max here: numba-cuda's builtin min of two floats does not compile)
    if r1 < 0.0:
        r1 = 0.0
    if r2 > 1.0:
        r2 = 1.0
    inside = r2 - r1 if r2 > r1 else 0.0  # where q has the sign of -c
    return inside if c > 0.0 else 1.0 - inside


@_law
def may_cross(a, b, c):
    """Whether q of :func:`negative_share` can change sign on [0, 1]: the parabola lies
    within |c| / 4 of its chord.  On the safe side (whatever the sign of c), and
    without a branch on that sign: a sag of round-off, of either sign, made one of the
    kernels' branches a coin toss (2.3 ns a mesh and step)."""
    s = 0.25 * abs(c)
    return ((a < 0.0) != (b < 0.0)) | (s >= abs(a)) | (s >= abs(b))



@_law
def contact_shares(lo0, lo1, hi1, lo, hi, state, k_sag, k_ratio):
    """The shares of the interval between two samples spent in back-side contact and
    separated: delta + g goes ``lo0``, ``lo1``, ``lo`` over the last three samples (the
    parabola through them, ``k_sag`` ((lo - lo1) - (lo1 - lo0) ``k_ratio``) its sag
    over the interval), delta - g from ``hi1`` to ``hi`` on the same parabola; ``state``
    the sample's (0 contact, 1 separated, 2 back side).  The split
    (:func:`negative_share`) only where a sign can change (:func:`may_cross`; delta - g
    <= delta + g, so in contact delta - g alone can change sign first, in back-side
    contact delta + g alone).  The contact times of ``_kernels.record`` and of the GPU
    ensemble kernel.  Twin: ``reference.contact_times_numpy``."""
    sag = k_sag * ((lo - lo1) - (lo1 - lo0) * k_ratio)
    if state == 0:
        cross = may_cross(hi1, hi, sag)
    elif state == 2:
        cross = may_cross(lo1, lo, sag)
    else:
        cross = may_cross(lo1, lo, sag) | may_cross(hi1, hi, sag)
    if cross:
        f_back = negative_share(lo1, lo, sag)
        f_sep = negative_share(hi1, hi, sag) - f_back
        return f_back, f_sep if f_sep > 0.0 else 0.0
    if state == 2:  # (one state throughout the interval)
        return 1.0, 0.0
    if state == 1:
        return 0.0, 1.0
    return 0.0, 0.0


_batch = njit(cache=True, error_model="numpy")


@_batch
def spring_forces(k, c, d, r, g, f, df_dd, df_dr):
    """:func:`spring_force` of every element (arrays of equal length; outputs filled)."""
    for e in range(k.shape[0]):
        f[e], df_dd[e], df_dr[e] = spring_force(k[e], c[e], d[e], r[e], g[e])


@_batch
def dead_zones(d, g, h, dh, u):
    """:func:`dead_zone` of every element (outputs filled)."""
    for e in range(d.shape[0]):
        h[e], dh[e], u[e] = dead_zone(d[e], g[e])


@_batch
def spline_forces(dx, dy, rx, ry, par, out):
    """:func:`spline_force` and :func:`spline_tangent` of every spline: ``par`` (n, 6)
    rows (k, c, S1, S2, F_m, v) as ``Structure.sp_par``; ``out`` (n, 12) gets fx, fy and
    the ten values of the tangent in order."""
    for j in range(dx.shape[0]):
        out[j, 0], out[j, 1] = spline_force(dx[j], dy[j], rx[j], ry[j], par[j, 0], par[j, 1],
                                            par[j, 2], par[j, 3], par[j, 4], par[j, 5])
        (out[j, 2], out[j, 3], out[j, 4], out[j, 5], out[j, 6], out[j, 7], out[j, 8],
         out[j, 9], out[j, 10], region) = spline_tangent(
             dx[j], dy[j], rx[j], ry[j], par[j, 0], par[j, 1], par[j, 2], par[j, 3],
             par[j, 4], par[j, 5])
        out[j, 11] = region


@_batch
def periodic_values(table, phase, out):
    """Row e of ``table`` interpolated at phase ``phase[e]`` [cycles] (as the kernels)."""
    n = table.shape[1]
    for e in range(table.shape[0]):
        i0, i1, w, _ = table_phase(phase[e], n)
        out[e] = lerp(table[e, i0], table[e, i1], w)


# ================================================= the law as C code (codegen links it)
_SPRING_FORCE_C = None


def spring_force_c():
    """:func:`spring_force`'s force compiled by numba with a C signature
    ``double(double k, double c, double d, double r, double g)`` (compiled on first use,
    about 0.1 s).  The generated right-hand side links its LLVM code
    (``spring_force_c().inspect_llvm()``), so it runs the law's own instructions.  Not
    cached on disk: a cfunc loaded from numba's cache carries object code, not the IR to
    link."""
    global _SPRING_FORCE_C
    if _SPRING_FORCE_C is None:
        sig = types.float64(types.float64, types.float64, types.float64, types.float64,
                            types.float64)
        _SPRING_FORCE_C = cfunc(sig, error_model="numpy")(_spring_force_scalar)
    return _SPRING_FORCE_C


def _spring_force_scalar(k, c, d, r, g):
    return spring_force(k, c, d, r, g)[0]


_SPLINE_FORCE_C = None


def spline_force_c():
    """:func:`spline_force` compiled by numba with a C signature ``void(double dx, dy,
    rx, ry, k, c, S1, S2, F_m, v, double *out)`` (out[0], out[1] = f_x, f_y), linked into
    the generated right-hand side of a model with splines as :func:`spring_force_c` is
    (compiled on first use)."""
    global _SPLINE_FORCE_C
    if _SPLINE_FORCE_C is None:
        sig = types.void(*([types.float64] * 10), types.CPointer(types.float64))
        _SPLINE_FORCE_C = cfunc(sig, error_model="numpy")(_spline_force_scalar)
    return _SPLINE_FORCE_C


def _spline_force_scalar(dx, dy, rx, ry, k, c, stick_limit, clearance, friction_force,
                         velocity, out):
    fx, fy = spline_force(dx, dy, rx, ry, k, c, stick_limit, clearance, friction_force,
                          velocity)
    out[0] = fx
    out[1] = fy
