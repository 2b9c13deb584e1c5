"""Ji & Li's 14-DOF bend-torsion equations of motion, written out by hand (issue 9 item 6).

Paper: Zhao Ji & Xia Li, SEW Industrial Gear (Tianjin), "Study on the vibration coupling
mechanism of a power transmission system with misaligned couplings" (the body is a
bend-torsion model of a two-stage helical split-torque grinding-mill drive; year not
printed), cited below as "Ji & Li, eq. N".

What this is for
----------------
An *independent* transcription of the equations of motion of the shipped model
``ji_li_mill_drive``: every coefficient of the paper's eq. 9 is computed here from the
model's physical parameters (masses, inertias, tooth counts, modules, angles, shaft
geometry, bearing stiffnesses, damping ratios, backlash, mesh stiffness) with the
paper's eqs. 1-13, and eq. 9 is typed in as straight-line numba code in the paper's
notation.  Nothing comes from :mod:`torquesplit.assembly` (no Structure, no projection
vectors, no assembled arrays), so a disagreement with the engine can reveal an error of
the assembly.  It is also the speed baseline of the engine (``benchmarks/``).

Inputs taken from the library, none of them part of the equations of motion:

* the transverse contact ratio of each pair (:class:`torquesplit.gears.geometry.
  PairGeometry`), which sets the duty cycle of the assumed single/double-contact
  stiffness wave;
* with a random backlash, the per-engagement sequence of Ji & Li eq. 14
  (:func:`torquesplit.gears.backlash.random_backlash`);
* for the comparison with the engine only (:func:`engine_state_signs`): the direction
  of each engine coordinate, from :func:`torquesplit.solve_kinematics`.

Where the shipped model departs from the paper, this transcription follows the model
and says so at the formula (``# model:``).  In short:

1. Eq. 12 as printed gives X1 the sign -1 in both Y11 and Y21 (and X6 the sign -1 in
   both Y12 and Y22), which contradicts eq. 9 (F11 - F21 on X1, F22 - F12 on X6): the
   two meshes of z1 push it along opposite lines of action.  Consistent with eq. 9:
   ``Y21 = (+X1 + r1 th1) - (r3 th3 + X3)`` and ``Y12 = (-X4 + r4 th4) - (r6 th6 - X6)``.
2. Normal (not transverse) mesh deflection and force, as the model does: Y_ij is the
   transverse expression of eq. 12 times cos(beta_b) (base helix angle), so the torque
   arm is r_b cos(beta_b) (eq. 9 prints r cos(beta) with the helix angle) and the
   translations get cos(beta_b) F (eq. 9 prints F).  This makes K symmetric; the paper's
   mix (arm r cos(beta) in the torques, r in Y) does not.
3. Backlash (eq. 13) acts on the normal deflection; the model gives the total 2 b.  The
   mesh damping acts only in contact (eq. 11 prints c Ydot even inside the backlash).
4. Damping from damping ratios with dimensionally consistent masses: eq. 1 with the arms
   r_b cos(beta_b) as radii, J_k J_l / (J_k a_l^2 + J_l a_k^2); eq. 4 for the support
   translations with the gear mass and k'_S (the paper's J_m J_n / (J_m + J_n) has the
   wrong dimension for a translation).  The ratios zeta are the model's assumptions.
5. The time-varying stiffness of eq. 8 (whose series does not converge) is the model's
   rectangular single/double-contact wave, 10 % peak to peak about k_bar, sampled at
   ``[analysis] table_points`` mesh phases and interpolated linearly and periodically
   (the model's definition of k(t)).  k_bar of eq. 1 is the mean of those samples.
6. No mesh errors (e_ij = 0 in eq. 12: the paper gives none).

Coordinates (Ji & Li eq. 15): ``y = [th0 .. th7, X1 .. X6]`` then the velocities in the
same order.  th_i is the vibratory rotation of body i (0 motor, 1-6 gears z1-z6, 7 mill)
positive in its own direction of rotation; X_i the translation of gear z_i along the
transverse line of action, with the directions fixed by eq. 9 and 12: X2 along n11, X3
along n21, X1 along -n11 = n21, X4 along -n12, X5 along -n22, X6 along n22 = -n12
(n_ij: the force of the driver on the driven gear).  The mesh forces F_ij are the
normal tooth forces [N], positive in drive-flank contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from torquesplit.gears.backlash import random_backlash
from torquesplit.gears.geometry import GearGeometry, PairGeometry

PAPER_DOFS = ("th0", "th1", "th2", "th3", "th4", "th5", "th6", "th7",
              "X1", "X2", "X3", "X4", "X5", "X6")
"""Ji & Li eq. 15: y0..y7 = theta0..theta7, y8..y13 = X1..X6."""
BODIES = ("motor", "z1", "z2", "z3", "z4", "z5", "z6", "mill")
"""Body of th0 .. th7 in the model file."""
GEARS = ("z1", "z2", "z3", "z4", "z5", "z6")
"""Gear of X1 .. X6 in the model file."""
MESHES = ("m11", "m21", "m12", "m22")
"""F11 (z1->z2), F21 (z1->z3), F12 (z4->z6), F22 (z5->z6): the model's mesh names."""
SHAFTS = ("input", "drive1", "drive2", "output")
"""k_T0 (motor-z1), k_T1 (z2-z4), k_T2 (z3-z5), k_T3 (z6-mill)."""


class Eom(NamedTuple):
    """The constant coefficients of Ji & Li eq. 9 (SI), in the paper's symbols.

    a_i = r_i cos(beta_b) is the torque arm of gear i (model: normal force, see the
    module docstring), cb1 / cb2 the cosine of the base helix angle of stage 1 / 2.
    """

    J0: float
    J1: float
    J2: float
    J3: float
    J4: float
    J5: float
    J6: float
    J7: float
    m1: float
    m2: float
    m3: float
    m4: float
    m5: float
    m6: float
    r1: float
    r2: float
    r3: float
    r4: float
    r5: float
    r6: float
    cb1: float
    cb2: float
    a1: float
    a2: float
    a3: float
    a4: float
    a5: float
    a6: float
    kT0: float
    kT1: float
    kT2: float
    kT3: float
    cT0: float
    cT1: float
    cT2: float
    cT3: float
    kS1: float  # k'_S of eq. 10: shaft bending in series with the bearing
    kS2: float
    kS3: float
    kS4: float
    kS5: float
    kS6: float
    cS1: float
    cS2: float
    cS3: float
    cS4: float
    cS5: float
    cS6: float
    cv11: float
    cv21: float
    cv12: float
    cv22: float
    T1: float  # input torque on the motor [N m]
    T0: float  # load torque on the mill [N m]


@dataclass(frozen=True)
class Seed001:
    """Everything the transcription needs: eq. 9's coefficients and the excitation.

    ``table`` (4, n): k_vij(phase) at phases i/n; ``frequency`` and ``phase`` give the
    mesh phase s = f t + phase [cycles]; half backlash b_ij of engagement floor(s) is
    ``half_backlash[ptr[j] + floor(s) mod (ptr[j+1] - ptr[j])]``.
    """

    eom: Eom
    table: np.ndarray
    k_mean: np.ndarray
    frequency: np.ndarray
    phase: np.ndarray
    backlash_ptr: np.ndarray
    half_backlash: np.ndarray
    omega: np.ndarray
    """(8,) speed of each body [rad/s], positive (each th_i counts in its own sense)."""
    directions: dict
    """gear -> unit vector (global frame) along which its X_i counts."""
    static_force: np.ndarray
    """(4,) nominal normal tooth force of each mesh for the equal split [N]."""


# =================================================================== parameters
def _alpha_t(gear) -> float:
    """Transverse pressure angle tan(alpha_t) = tan(alpha_n) / cos(beta) (ISO 21771)."""
    return math.atan(math.tan(gear.pressure_angle) / math.cos(gear.helix_angle))


def _base_radius(gear) -> float:
    """r_b = z m_n cos(alpha_t) / (2 cos(beta)) [m] (Table 1's base radii, from the model)."""
    return gear.teeth * gear.module * math.cos(_alpha_t(gear)) / (2 * math.cos(gear.helix_angle))


def _base_helix(gear) -> float:
    """tan(beta_b) = tan(beta) cos(alpha_t) (ISO 21771)."""
    return math.atan(math.tan(gear.helix_angle) * math.cos(_alpha_t(gear)))


def _working_pressure_angle(g1, g2) -> float:
    """inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2) (ISO 21771)."""
    at = _alpha_t(g1)
    target = math.tan(at) - at + 2 * math.tan(g1.pressure_angle) * (
        g1.profile_shift + g2.profile_shift) / (g1.teeth + g2.teeth)
    a = at
    for _ in range(50):  # Newton on tan(a) - a = target
        step = (math.tan(a) - a - target) / math.tan(a) ** 2
        a -= step
        if abs(step) < 1e-16:
            break
    return a


def _bending_stiffness(shaft) -> float:
    """k_S = 6 E I l / (a b (l^2 - a^2 - b^2)), I = pi d^4 / 64 [N/m]."""
    l = shaft.span
    a = shaft.position
    b = l - a
    inertia = math.pi * shaft.diameter**4 / 64  # Ji & Li eq. 7
    # Ji & Li eq. 6 (eq. 5 as printed lacks the 1/l of the simply supported beam's
    # deflection under the load, F a b (l^2 - a^2 - b^2) / (6 E I l); eq. 6 has it)
    return 6 * shaft.youngs_modulus * inertia * l / (a * b * (l**2 - a**2 - b**2))


def _stiffness_wave(n: int, mean: float, peak_to_peak: float, contact_ratio: float):
    """Model: rectangular single/double-contact wave of relative peak-to-peak
    ``peak_to_peak`` about ``mean`` at the phases i/n, phase 0 = a pair enters contact.

    ceil(eps) pairs carry the load for the fraction eps - floor(eps) of the cycle
    (stiffness k_low + dk), floor(eps) pairs for the rest (k_low); the mean is ``mean``.
    Replaces Ji & Li eq. 8, whose series sum_i sin(i w t + phi) does not converge.
    """
    frac = contact_ratio - math.floor(contact_ratio)
    dk = peak_to_peak * mean
    k_low = mean - dk * frac
    phase = np.arange(n) / n
    return np.where(phase < frac, k_low + dk, k_low)


def _geometry(gear) -> GearGeometry:
    return GearGeometry(teeth=gear.teeth, normal_module=gear.module,
                        normal_pressure_angle=gear.pressure_angle,
                        helix_angle=abs(gear.helix_angle), face_width=gear.face_width,
                        profile_shift=gear.profile_shift)


def build(model) -> Seed001:
    """The transcription's coefficients for a model of the seed 001 topology (SI).

    The model must be the shipped ``ji_li_mill_drive`` or a variant of it (other
    values, same bodies, shafts, meshes and layout); anything else is refused.
    """
    g = model.gears
    _check_layout(model)

    # ---------------------------------------------------------------- inertia, Table 1
    J = [model.bodies["motor"].polar_inertia] + [g[n].polar_inertia for n in GEARS] + [
        model.bodies["mill"].polar_inertia]
    m = [g[n].mass for n in GEARS]
    r = [_base_radius(g[n]) for n in GEARS]
    cb1 = math.cos(_base_helix(g["z1"]))  # stage 1 (z1, z2, z3)
    cb2 = math.cos(_base_helix(g["z4"]))  # stage 2 (z4, z5, z6)
    cb = [cb1, cb1, cb1, cb2, cb2, cb2]
    arm = [ri * ci for ri, ci in zip(r, cb)]  # model: normal force, arm r_b cos(beta_b)

    # ---------------------------------------------------------------- speeds, torques
    drive = model.drives["motor"]
    w1 = abs(drive.speed)
    z = {n: g[n].teeth for n in GEARS}
    w2 = w1 * z["z1"] / z["z2"]  # z2, z3 and, on the drive shafts, z4, z5
    w6 = w2 * z["z4"] / z["z6"]  # z6 and the mill
    omega = np.array([w1, w1, w2, w2, w2, w2, w6, w6])
    T1 = drive.power / w1  # torque drive: the motor's torque (constant, eq. 9)
    T0 = drive.power / w6  # "balanced" load: all of the input power (eq. 9's -T0)

    # ---------------------------------------------------------------- shafts
    kT, cT = [], []
    ends = {"input": (0, 1), "drive1": (2, 4), "drive2": (3, 5), "output": (6, 7)}
    for name in SHAFTS:
        sh = model.shafts[name]
        # Ji & Li eq. 3: k_T = G pi d^4 / (32 l_b)
        k = sh.shear_modulus * math.pi * sh.diameter**4 / (32 * sh.length)
        jm, jn = (J[i] for i in ends[name])
        # Ji & Li eq. 2: c_T = 2 zeta_T sqrt(k_T J_m J_n / (J_m + J_n))
        kT.append(k)
        cT.append(2 * sh.damping_ratio * math.sqrt(k * jm * jn / (jm + jn)))

    # ---------------------------------------------------------------- supports
    kS, cS = [], []
    for i, name in enumerate(GEARS):
        sup = g[name].support
        k_shaft = _bending_stiffness(sup.shaft)
        k_c = sup.shaft.bearing_stiffness
        k = k_shaft * k_c / (k_shaft + k_c)  # Ji & Li eq. 10
        kS.append(k)
        # Ji & Li eq. 4, model: with the gear's mass (dimensionally consistent)
        cS.append(2 * sup.damping_ratio * math.sqrt(k * m[i]))

    # ---------------------------------------------------------------- meshes
    n_tab = model.analysis.table_points
    pairs = {"m11": (1, 2), "m21": (1, 3), "m12": (4, 6), "m22": (5, 6)}  # body indices
    tables, k_mean, cv, seqs, freq = [], [], [], [], []
    for name in MESHES:
        mesh = model.meshes[name]
        d, n = pairs[name]
        gd, gn = g[GEARS[d - 1]], g[GEARS[n - 1]]
        spec = mesh.stiffness
        eps = PairGeometry(_geometry(gd), _geometry(gn)).transverse_contact_ratio
        tab = _stiffness_wave(n_tab, spec.value, spec.peak_to_peak, eps)
        kbar = float(np.mean(tab))
        ad, an = arm[d - 1], arm[n - 1]
        jd, jn = J[d], J[n]
        # Ji & Li eq. 1, model: radii = the arms, J_k J_l / (J_k a_l^2 + J_l a_k^2)
        cv.append(2 * mesh.damping_ratio * math.sqrt(kbar * jd * jn / (jd * an**2 + jn * ad**2)))
        tables.append(tab)
        k_mean.append(kbar)
        f = omega[d] * gd.teeth / (2 * math.pi)  # mesh frequency [Hz]
        freq.append(f)
        bl = mesh.backlash  # model: the total backlash 2 b; eq. 13 takes b
        if bl.distribution == "constant" or bl.tolerance == 0:
            seqs.append(np.array([bl.nominal / 2]))
        elif bl.distribution == "normal":
            # Ji & Li eq. 14: one value per engagement, normal within the band, repeated
            lo, hi = max(bl.nominal - bl.tolerance, 0.0), bl.nominal + bl.tolerance
            seq = random_backlash(lo, hi, gd.teeth, gn.teeth, 1.0 / f, bl.seed).values
            seqs.append(np.asarray(seq) / 2)
        else:
            raise ValueError(f"meshes.{name}.backlash: distribution {bl.distribution!r} is "
                             "not in the paper; use 'constant' or 'normal'")

    # mesh phases at t = 0 (the model's clocking rule): two meshes on one gear whose
    # contact points lie at angles th_a, th_b about its axis are offset by
    # -z sgn(w) (th_b - th_a) / 2 pi cycles (a tooth reaches the second contact that much
    # later).  z1 and z6 both turn positively.  The stages are not geared to each other
    # (elastic drive shafts): F11 and F12 start at phase 0 (the model's convention).
    p4, p5, p6 = (np.array(g[n].position) for n in ("z4", "z5", "z6"))
    d21 = g["z3"].place.angle - g["z2"].place.angle  # z3's contact after z2's, on z1
    d22 = math.atan2((p5 - p6)[1], (p5 - p6)[0]) - math.atan2((p4 - p6)[1], (p4 - p6)[0])
    phase = np.array([0.0, (-z["z1"] * d21 / (2 * math.pi)) % 1.0,
                      0.0, (-z["z6"] * d22 / (2 * math.pi)) % 1.0])

    eom = Eom(*J, *m, *r, cb1, cb2, *arm, *kT, *cT, *kS, *cS, *cv, T1, T0)
    lengths = [len(s) for s in seqs]
    ptr = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    # nominal normal force: the torque of each branch (equal split) over the arm
    static = np.array([T1 / 2 / arm[0], T1 / 2 / arm[0],
                       T1 / 2 * w1 / w2 / arm[3], T1 / 2 * w1 / w2 / arm[4]])
    return Seed001(eom=eom, table=np.ascontiguousarray(tables), k_mean=np.array(k_mean),
                   frequency=np.array(freq), phase=phase, backlash_ptr=ptr,
                   half_backlash=np.concatenate(seqs), omega=omega,
                   directions=_directions(model), static_force=static)


def _check_layout(model):
    """Refuse a model that is not the seed 001 model this file transcribes (topology,
    layout and the kinds of laws it writes out)."""
    want = dict(gears=set(GEARS), bodies={"motor", "mill"}, meshes=set(MESHES),
                shafts=set(SHAFTS))
    for what, names in want.items():
        if set(getattr(model, what)) != names:
            raise ValueError(f"the transcription is of Ji & Li's drive: {what} must be "
                             f"{sorted(names)}, got {sorted(getattr(model, what))}")
    for n in GEARS + ("motor", "mill"):
        spec = model.gears.get(n) or model.bodies[n]
        if tuple(spec.axis) != (0.0, 0.0, 1.0):
            raise ValueError(f"{n}: the transcription's layout has every axis along +z")
    for name, (a, b) in {"m11": ("z1", "z2"), "m21": ("z1", "z3"), "m12": ("z4", "z6"),
                         "m22": ("z5", "z6")}.items():
        if tuple(model.meshes[name].gears) != (a, b):
            raise ValueError(f"meshes.{name} must join {a} and {b}")
    if model.drives["motor"].speed <= 0 or model.drives["motor"].mode != "torque":
        raise ValueError("the motor must be a torque drive turning positively about +z")
    load = model.loads["mill"]
    if load.torque is not None or load.speed_coefficient != 0:
        raise ValueError("the mill's load must be the constant balanced torque of eq. 9")
    # what eq. 9 has no term for (or this file computes differently) must be absent
    for n in GEARS:
        sup = model.gears[n].support
        if (sup.stiffness is not None or sup.shaft is None or sup.damping is not None
                or sup.clearance or sup.shaft.bearing_stiffness is None):
            raise ValueError(f"gears.{n}.support: the transcription needs shaft bending + "
                             "bearing (eqs. 6, 10), a damping ratio and no clearance")
        ge = model.gears[n].errors
        if any((ge.eccentricity, ge.installation, ge.tooth_thickness, ge.pitch,
                ge.bearing_runout)):
            raise ValueError(f"gears.{n}.errors: e_ij of eq. 12 is 0 in the transcription")
    for name in MESHES:
        mesh = model.meshes[name]
        te = mesh.transmission_error
        if (mesh.stiffness.method != "constant" or mesh.damping is not None
                or mesh.phase is not None or mesh.impact or mesh.friction is not None
                or te.constant or te.amplitude):
            raise ValueError(f"meshes.{name}: the transcription has a constant-method "
                             "stiffness wave, a damping ratio, no phase override, no "
                             "errors, impact or friction")
    for name in SHAFTS:
        sh = model.shafts[name]
        if sh.rigid or sh.torsional_stiffness is not None or sh.damping is not None or (
                sh.inner_diameter):
            raise ValueError(f"shafts.{name}: the transcription needs a solid elastic "
                             "shaft (eq. 3) with a damping ratio (eq. 2)")


def _directions(model) -> dict:
    """Unit direction (global frame) of each X_i: the transverse lines of action.

    n_t of a mesh: cos(alpha_wt) e_t + sin(alpha_wt) e_r with e_r from the driver's centre
    towards the driven gear's and e_t = sgn(w_d) a x e_r where the driver's flank moves.
    z2 / z3 sit at the 'place' angles from z1; z4, z5, z6 at their positions.
    """
    g = model.gears
    zhat = np.array([0.0, 0.0, 1.0])

    def n_t(er, s_driver, alpha):
        er = er / np.linalg.norm(er)
        return math.cos(alpha) * s_driver * np.cross(zhat, er) + math.sin(alpha) * er

    a1 = _working_pressure_angle(g["z1"], g["z2"])
    a2 = _working_pressure_angle(g["z4"], g["z6"])
    e12 = np.array([math.cos(g["z2"].place.angle), math.sin(g["z2"].place.angle), 0.0])
    e13 = np.array([math.cos(g["z3"].place.angle), math.sin(g["z3"].place.angle), 0.0])
    p4, p5, p6 = (np.array(g[n].position) for n in ("z4", "z5", "z6"))
    n11 = n_t(e12, +1.0, a1)  # z1 turns positively
    n21 = n_t(e13, +1.0, a1)
    n12 = n_t((p6 - p4) * [1, 1, 0], -1.0, a2)  # z4, z5 turn negatively
    n22 = n_t((p6 - p5) * [1, 1, 0], -1.0, a2)
    # eq. 9 puts F11 - F21 on X1 and F22 - F12 on X6: the lines must be opposite
    if np.linalg.norm(n11 + n21) > 1e-9 or np.linalg.norm(n12 + n22) > 1e-9:
        raise ValueError("the two meshes of z1 (and of z6) must push along opposite lines "
                         "of action (branches at 180 deg), as eq. 9 assumes")
    return {"z1": -n11, "z2": n11, "z3": n21, "z4": -n12, "z5": -n22, "z6": n22}


# ============================================================ matrices (numpy)
def mesh_rows(e: Eom) -> np.ndarray:
    """(4, 14) dY_ij/dq of Ji & Li eq. 12 (consistent signs, normal: times cos(beta_b))."""
    Y = np.zeros((4, 14))
    th = {i: i for i in range(8)}
    X = {i: 7 + i for i in range(1, 7)}
    # Y11 = cb1 [(-X1 + r1 th1) - (r2 th2 + X2)]
    Y[0, X[1]], Y[0, th[1]], Y[0, th[2]], Y[0, X[2]] = -e.cb1, e.a1, -e.a2, -e.cb1
    # Y21 = cb1 [(+X1 + r1 th1) - (r3 th3 + X3)]   (eq. 12 prints -X1)
    Y[1, X[1]], Y[1, th[1]], Y[1, th[3]], Y[1, X[3]] = e.cb1, e.a1, -e.a3, -e.cb1
    # Y12 = cb2 [(-X4 + r4 th4) - (r6 th6 - X6)]   (eq. 12 prints + X6)
    Y[2, X[4]], Y[2, th[4]], Y[2, th[6]], Y[2, X[6]] = -e.cb2, e.a4, -e.a6, e.cb2
    # Y22 = cb2 [(-X5 + r5 th5) - (r6 th6 + X6)]
    Y[3, X[5]], Y[3, th[5]], Y[3, th[6]], Y[3, X[6]] = -e.cb2, e.a5, -e.a6, -e.cb2
    return Y


def matrices(p: Seed001):
    """M, C, K (mean mesh stiffness, all meshes in contact) and F of Ji & Li eq. 9.

    Returns ``(M, C, K, F, Fb)``: M q'' + C q' + K q = F + Fb while every mesh is in
    drive-flank contact, Fb = sum_ij k_bar_ij b_ij dY_ij/dq the shift of the dead zone
    (eq. 13: k (Y - b)), with the mean half backlash of each mesh.
    """
    e = p.eom
    M = np.diag([e.J0, e.J1, e.J2, e.J3, e.J4, e.J5, e.J6, e.J7,
                 e.m1, e.m2, e.m3, e.m4, e.m5, e.m6])
    K = np.zeros((14, 14))
    C = np.zeros((14, 14))
    # torsion shafts of eq. 9: k_T (th_m - th_n) on th_m, the opposite on th_n
    for (i, j), k, c in zip(((0, 1), (2, 4), (3, 5), (6, 7)),
                            (e.kT0, e.kT1, e.kT2, e.kT3), (e.cT0, e.cT1, e.cT2, e.cT3)):
        for a, b, s in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[a, b] += s * k
            C[a, b] += s * c
    # supports of eq. 9: k'_Si X_i, c_Si X_i'
    for i, (k, c) in enumerate(zip((e.kS1, e.kS2, e.kS3, e.kS4, e.kS5, e.kS6),
                                   (e.cS1, e.cS2, e.cS3, e.cS4, e.cS5, e.cS6))):
        K[8 + i, 8 + i] += k
        C[8 + i, 8 + i] += c
    # meshes: the generalised force of F_ij is -F_ij dY_ij/dq (eq. 9's r F cos(beta),
    # F11 - F21 on X1, ...), with F = k Y + c Y' (eq. 11) in contact
    Y = mesh_rows(e)
    cv = np.array([e.cv11, e.cv21, e.cv12, e.cv22])
    K += Y.T @ (p.k_mean[:, None] * Y)
    C += Y.T @ (cv[:, None] * Y)
    F = np.zeros(14)
    F[0], F[7] = e.T1, -e.T0
    Fb = Y.T @ (p.k_mean * mean_half_backlash(p))
    return M, C, K, F, Fb


def mean_half_backlash(p: Seed001) -> np.ndarray:
    """(4,) mean b_ij over the engagements (the static solution's dead zone)."""
    return np.array([p.half_backlash[p.backlash_ptr[j]:p.backlash_ptr[j + 1]].mean()
                     for j in range(4)])


def rigid_mode(p: Seed001) -> np.ndarray:
    """The torsional rigid-body mode of eq. 9: th_i proportional to w_i, X = 0."""
    return np.concatenate([p.omega / p.omega[0], np.zeros(6)])


def static_equilibrium(p: Seed001) -> np.ndarray:
    """q with K q = F + Fb (mean stiffness, drive flanks in contact) and zero
    mass-weighted motion along the rigid mode (the engine's normalisation)."""
    M, _, K, F, Fb = matrices(p)
    r = M @ rigid_mode(p)
    A = np.block([[K, r[:, None]], [r[None, :], np.zeros((1, 1))]])
    sol = np.linalg.solve(A, np.concatenate([F + Fb, [0.0]]))
    q = sol[:14]
    if np.any(mesh_rows(p.eom) @ q <= mean_half_backlash(p)):
        raise ValueError("a mesh is not in drive-flank contact at the static solution")
    return q


def natural_frequencies(p: Seed001) -> np.ndarray:
    """Elastic natural frequencies [Hz] of M q'' + K q = 0 (mean stiffness, in contact);
    the rigid mode (eigenvalue below 1e-10 of the largest) is left out."""
    M, _, K, _, _ = matrices(p)
    d = 1.0 / np.sqrt(np.diag(M))
    lam = np.linalg.eigvalsh(d[:, None] * K * d[None, :])
    lam = lam[np.abs(lam) > 1e-10 * np.abs(lam).max()]
    return np.sqrt(lam) / (2 * math.pi)


# ================================================================ compiled code
CYCLE_EPS = 1e-9
"""A sample whose mesh phase s lies within CYCLE_EPS below an integer counts in the cycle
it starts (s = f t + phase rounds to 31.999999999999996 on a cycle boundary)."""


@njit(cache=True, error_model="numpy", inline="always")
def mesh_force(Y, dY, k, c, b):
    """F = k f(Y) + c Y' in contact, 0 inside the backlash (Ji & Li eqs. 11, 13)."""
    if Y > b:
        return k * (Y - b) + c * dY
    if Y < -b:
        return k * (Y + b) + c * dY
    return 0.0  # model: no damping force without contact


@njit(cache=True, error_model="numpy", inline="always")
def eom(y, e, k, b, dy, F, D):
    """dy = [q', q''] of Ji & Li eq. 9 at state y; k, b: k_vij(t), b_ij(t); F: F_ij;
    D: the normal deflections Y_ij.

    Legend: th_i, w_i rotation and speed of body i (0 motor .. 7 mill); X_i, V_i
    translation and velocity of gear z_i; e the :class:`Eom` coefficients.
    """
    th0, th1, th2, th3, th4, th5, th6, th7 = y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]
    X1, X2, X3, X4, X5, X6 = y[8], y[9], y[10], y[11], y[12], y[13]
    w0, w1, w2, w3, w4, w5, w6, w7 = (y[14], y[15], y[16], y[17], y[18], y[19], y[20],
                                      y[21])
    V1, V2, V3, V4, V5, V6 = y[22], y[23], y[24], y[25], y[26], y[27]

    # Ji & Li eq. 12 (signs of X1 in Y21 and X6 in Y12 corrected, see the module
    # docstring), normal deflection: times cos(beta_b); e_ij = 0
    Y11 = e.cb1 * ((-X1 + e.r1 * th1) - (e.r2 * th2 + X2))
    Y21 = e.cb1 * ((X1 + e.r1 * th1) - (e.r3 * th3 + X3))
    Y12 = e.cb2 * ((-X4 + e.r4 * th4) - (e.r6 * th6 - X6))
    Y22 = e.cb2 * ((-X5 + e.r5 * th5) - (e.r6 * th6 + X6))
    dY11 = e.cb1 * ((-V1 + e.r1 * w1) - (e.r2 * w2 + V2))
    dY21 = e.cb1 * ((V1 + e.r1 * w1) - (e.r3 * w3 + V3))
    dY12 = e.cb2 * ((-V4 + e.r4 * w4) - (e.r6 * w6 - V6))
    dY22 = e.cb2 * ((-V5 + e.r5 * w5) - (e.r6 * w6 + V6))

    # Ji & Li eqs. 11 and 13
    F11 = mesh_force(Y11, dY11, k[0], e.cv11, b[0])
    F21 = mesh_force(Y21, dY21, k[1], e.cv21, b[1])
    F12 = mesh_force(Y12, dY12, k[2], e.cv12, b[2])
    F22 = mesh_force(Y22, dY22, k[3], e.cv22, b[3])
    D[0], D[1], D[2], D[3] = Y11, Y21, Y12, Y22

    # shaft torques k_T (th_m - th_n) + c_T (w_m - w_n) of eq. 9
    M0 = e.kT0 * (th0 - th1) + e.cT0 * (w0 - w1)
    M1 = e.kT1 * (th2 - th4) + e.cT1 * (w2 - w4)
    M2 = e.kT2 * (th3 - th5) + e.cT2 * (w3 - w5)
    M3 = e.kT3 * (th6 - th7) + e.cT3 * (w6 - w7)

    for i in range(14):
        dy[i] = y[14 + i]
    # Ji & Li eq. 9, torsion (arms a_i = r_i cos(beta_b), model)
    dy[14] = (e.T1 - M0) / e.J0
    dy[15] = (M0 - e.a1 * F11 - e.a1 * F21) / e.J1
    dy[16] = (-M1 + e.a2 * F11) / e.J2
    dy[17] = (-M2 + e.a3 * F21) / e.J3
    dy[18] = (M1 - e.a4 * F12) / e.J4
    dy[19] = (M2 - e.a5 * F22) / e.J5
    dy[20] = (-M3 + e.a6 * F12 + e.a6 * F22) / e.J6
    dy[21] = (M3 - e.T0) / e.J7
    # Ji & Li eq. 9, translations (model: the normal force's transverse part cos(beta_b) F)
    dy[22] = (e.cb1 * (F11 - F21) - e.cS1 * V1 - e.kS1 * X1) / e.m1
    dy[23] = (e.cb1 * F11 - e.cS2 * V2 - e.kS2 * X2) / e.m2
    dy[24] = (e.cb1 * F21 - e.cS3 * V3 - e.kS3 * X3) / e.m3
    dy[25] = (e.cb2 * F12 - e.cS4 * V4 - e.kS4 * X4) / e.m4
    dy[26] = (e.cb2 * F22 - e.cS5 * V5 - e.kS5 * X5) / e.m5
    dy[27] = (e.cb2 * (F22 - F12) - e.cS6 * V6 - e.kS6 * X6) / e.m6
    F[0] = F11
    F[1] = F21
    F[2] = F12
    F[3] = F22


@njit(cache=True, error_model="numpy", inline="always")
def excite(t, table, frequency, phase, bl_ptr, bl_val, k, b, cyc, bl_cyc):
    """k_vij(t), b_ij(t) and the statistics cycle of each mesh at time t.

    Mesh phase s = f t + phase; k from the table at frac(s) n (linear, periodic);
    b of engagement floor(s) (eq. 14), looked up only when the engagement changes.
    """
    n_tab = table.shape[1]
    for j in range(4):
        s = frequency[j] * t + phase[j]
        fl = math.floor(s)
        x = (s - fl) * n_tab
        i0 = int(x)
        w = x - i0
        if i0 >= n_tab:
            i0 -= n_tab
        i1 = i0 + 1 if i0 + 1 < n_tab else 0
        k[j] = table[j, i0] + w * (table[j, i1] - table[j, i0])
        c = np.int64(fl)
        cyc[j] = c + 1 if s - fl >= 1.0 - CYCLE_EPS else c
        if c != bl_cyc[j]:
            n = bl_ptr[j + 1] - bl_ptr[j]
            bl_cyc[j] = c
            b[j] = bl_val[bl_ptr[j] + (c % n + n) % n]


@njit(cache=True, error_model="numpy", inline="always")
def vertex(t0, t1, t2, f0, f1, f2):
    """Value at the vertex of the parabola through three points."""
    d1 = (f1 - f0) / (t1 - t0)
    d2 = (f2 - f1) / (t2 - t1)
    a = (d2 - d1) / (t2 - t0)
    if a == 0.0:
        return f1
    sl = (d1 * (t2 - t1) + d2 * (t1 - t0)) / (t2 - t0)
    return f1 - sl * sl / (4.0 * a)


@njit(cache=True, error_model="numpy", inline="always")
def record(t, F, D, b, cyc, base, frequency, phase, cyc_max, cyc_min, cyc_sum, cyc_wt,
           cyc_cnt, prev, pk):
    """Per-mesh-cycle max, min and count of the mesh forces, and their time integral
    (streamed): the trapezoid rule over the interval from the last sample, split where a
    mesh cycle begins.  ``prev``: the last sample's time, then its forces and cycles
    (time NaN before the first sample).  Extremes between samples: where the middle of
    the last three samples is the largest (smallest) and all three are in one contact
    regime, the vertex of the parabola through them enters the middle one's cycle.
    ``pk``: the last two samples' times, then per mesh their forces, cycles and regimes,
    then the samples so far."""
    cap = cyc_max.shape[0]
    ta = prev[0]
    span = t - ta
    entered = span >= 0.0
    for j in range(4):
        c = cyc[j] - base[j]
        f = F[j]
        if 0 <= c < cap:
            if f > cyc_max[c, j]:
                cyc_max[c, j] = f
            if f < cyc_min[c, j]:
                cyc_min[c, j] = f
            cyc_cnt[c, j] += 1
        if entered:
            fa = prev[1 + j]
            cp = np.int64(prev[5 + j])
            if c == cp + 1:
                tb = (c + base[j] - phase[j]) / frequency[j]
                th = min(max((tb - ta) / span, 0.0), 1.0) if span > 0.0 else 1.0
                fb = fa + th * (f - fa)
                da = th * span
                db = span - da
                if 0 <= cp < cap:
                    cyc_sum[cp, j] += 0.5 * da * (fa + fb)
                    cyc_wt[cp, j] += da
                if 0 <= c < cap:
                    cyc_sum[c, j] += 0.5 * db * (fb + f)
                    cyc_wt[c, j] += db
            else:
                half = 0.5 * span
                if 0 <= cp < cap:
                    cyc_sum[cp, j] += half * fa
                    cyc_wt[cp, j] += half
                if 0 <= c < cap:
                    cyc_sum[c, j] += half * f
                    cyc_wt[c, j] += half
        prev[1 + j] = f
        prev[5 + j] = c
        # the peak between samples (engine: _kernels.force_instant)
        g2 = 1.0
        if b[j] > 0.0:
            g2 = 1.0 if D[j] > b[j] else (-1.0 if D[j] < -b[j] else 0.0)
        k = 2 + 6 * j
        f0, f1, c1, g0, g1 = pk[k], pk[k + 1], np.int64(pk[k + 3]), pk[k + 4], pk[k + 5]
        if (pk[26] >= 2 and g1 != 0.0 and g0 == g1 and g2 == g1 and 0 <= c1 < cap
                and (f1 != f0 or f1 != f)):
            if f1 >= f0 and f1 >= f:
                v = vertex(pk[0], pk[1], t, f0, f1, f)
                if v > cyc_max[c1, j]:
                    cyc_max[c1, j] = v
            elif f1 <= f0 and f1 <= f:
                v = vertex(pk[0], pk[1], t, f0, f1, f)
                if v < cyc_min[c1, j]:
                    cyc_min[c1, j] = v
        pk[k], pk[k + 1] = f1, f
        pk[k + 2], pk[k + 3] = pk[k + 3], c
        pk[k + 4], pk[k + 5] = g1, g2
    pk[0], pk[1] = pk[1], t
    pk[26] += 1
    prev[0] = t


@njit(cache=True, error_model="numpy")
def rk4(y, t0, h, n_steps, e, table, frequency, phase, bl_ptr, bl_val, base,
        cyc_max, cyc_min, cyc_sum, cyc_wt, cyc_cnt, prev, pk, f_end):
    """Classic RK4 (Ji & Li eq. 17, misprinted there) over ``n_steps`` steps of ``h``.

    ``y`` (28) is advanced in place.  The mesh forces of the state at the start of every
    step, and of the final state, enter the per-cycle statistics (row = cycle - base);
    ``f_end`` gets the final mesh forces.  k and b are evaluated at t, t + h/2 and t + h,
    the t + h values reused by the next step.
    """
    ka = np.empty(4)
    kh = np.empty(4)
    kb = np.empty(4)
    b = np.empty(4)
    cyc = np.empty(4, dtype=np.int64)
    bl_cyc = np.full(4, -(2**62), dtype=np.int64)
    F = np.empty(4)
    Ft = np.empty(4)
    D = np.empty(4)
    Dt = np.empty(4)
    k1 = np.empty(28)
    k2 = np.empty(28)
    k3 = np.empty(28)
    k4 = np.empty(28)
    yt = np.empty(28)
    excite(t0, table, frequency, phase, bl_ptr, bl_val, ka, b, cyc, bl_cyc)
    for i in range(n_steps):
        eom(y, e, ka, b, k1, F, D)
        record(t0 + i * h, F, D, b, cyc, base, frequency, phase, cyc_max, cyc_min, cyc_sum,
               cyc_wt, cyc_cnt, prev, pk)
        excite(t0 + (i + 0.5) * h, table, frequency, phase, bl_ptr, bl_val, kh, b, cyc,
               bl_cyc)
        for m in range(28):
            yt[m] = y[m] + 0.5 * h * k1[m]
        eom(yt, e, kh, b, k2, Ft, Dt)
        for m in range(28):
            yt[m] = y[m] + 0.5 * h * k2[m]
        eom(yt, e, kh, b, k3, Ft, Dt)
        excite(t0 + (i + 1) * h, table, frequency, phase, bl_ptr, bl_val, kb, b, cyc,
               bl_cyc)
        for m in range(28):
            yt[m] = y[m] + h * k3[m]
        eom(yt, e, kb, b, k4, Ft, Dt)
        for m in range(28):
            y[m] += h / 6.0 * (k1[m] + 2.0 * (k2[m] + k3[m]) + k4[m])
        ka, kb = kb, ka
    eom(y, e, ka, b, k1, F, D)
    record(t0 + n_steps * h, F, D, b, cyc, base, frequency, phase, cyc_max, cyc_min,
           cyc_sum, cyc_wt, cyc_cnt, prev, pk)
    for j in range(4):
        f_end[j] = F[j]


# ================================================================= Python driver
@dataclass(frozen=True)
class Run:
    """Result of :func:`integrate`: final state and per-mesh-cycle force statistics."""

    y_final: np.ndarray
    forces_final: np.ndarray
    cycle_max: np.ndarray
    cycle_min: np.ndarray
    cycle_mean: np.ndarray
    cycle_count: np.ndarray


def cycle_index(s: float) -> int:
    """Statistics cycle of mesh phase s: floor(s), one up within CYCLE_EPS below."""
    fl = math.floor(s)
    return fl + 1 if s - fl >= 1.0 - CYCLE_EPS else fl


def arrays(p: Seed001, t0: float, h: float, n_steps: int) -> dict:
    """The arrays :func:`rk4` takes besides the state, for a run of n_steps from t0."""
    cap = int(math.ceil(n_steps * h * p.frequency.max())) + 2
    base = np.array([cycle_index(p.frequency[j] * t0 + p.phase[j]) for j in range(4)],
                    dtype=np.int64)
    return dict(e=p.eom, table=p.table, frequency=p.frequency, phase=p.phase,
                bl_ptr=p.backlash_ptr, bl_val=p.half_backlash, base=base,
                cyc_max=np.full((cap, 4), -np.inf), cyc_min=np.full((cap, 4), np.inf),
                cyc_sum=np.zeros((cap, 4)), cyc_wt=np.zeros((cap, 4)),
                cyc_cnt=np.zeros((cap, 4), dtype=np.int64),
                prev=np.concatenate([[np.nan], np.zeros(8)]), pk=np.zeros(27),
                f_end=np.empty(4))


def integrate(p: Seed001, y0, h: float, n_steps: int, t0: float = 0.0) -> Run:
    """RK4 of the transcription from ``y0`` (paper order, 28 values)."""
    y = np.array(y0, dtype=float)
    a = arrays(p, t0, h, n_steps)
    rk4(y, t0, h, n_steps, **a)
    cnt = a["cyc_cnt"]
    used = np.flatnonzero(cnt.any(axis=1))
    n = int(used[-1]) + 1 if used.size else 0
    empty = cnt[:n] == 0
    wt = a["cyc_wt"][:n]
    mean = np.where(empty | (wt <= 0), np.nan, a["cyc_sum"][:n] / np.where(wt > 0, wt, 1.0))
    mx = np.where(empty, np.nan, a["cyc_max"][:n])
    mn = np.where(empty, np.nan, a["cyc_min"][:n])
    return Run(y_final=y, forces_final=a["f_end"].copy(), cycle_max=mx, cycle_min=mn,
               cycle_mean=mean, cycle_count=cnt[:n].copy())


# ========================================================== engine coordinates
def engine_state_signs(model, dof_names) -> tuple[np.ndarray, np.ndarray]:
    """Where each paper DOF sits in the engine's state and with which sign.

    Returns ``(index, sign)`` (14 each): paper q_i = sign_i * engine q[index_i] (and the
    same for velocities).  The engine's rotation of a body is about the body's axis
    (+z here): sign = the body's sense of rotation (th_i counts in it).  The engine's
    'loa' translation of a gear is along the unit vector its kinematics reports
    (:attr:`torquesplit.model.kinematics.Kinematics.translation_axes`): sign = its dot
    product with this file's X_i direction, which must be +-1.  Nothing else of the
    engine is read.
    """
    from torquesplit import solve_kinematics

    kin = solve_kinematics(model)
    p_dirs = _directions(model)
    names = list(dof_names)
    index, sign = [], []
    senses = [1.0, 1.0, -1.0, -1.0, -1.0, -1.0, 1.0, 1.0]  # z1 +, z2..z5 -, z6 +
    for body, s in zip(BODIES, senses):
        axis = kin.bodies[body].axis
        if abs(float(axis @ np.array([0.0, 0.0, 1.0])) - 1.0) > 1e-12:
            raise ValueError(f"{body}: the engine's axis is not +z")
        index.append(names.index(f"{body}.theta"))
        sign.append(s)
    for gear in GEARS:
        dot = float(kin.translation_axes[gear]["loa"] @ p_dirs[gear])
        if abs(abs(dot) - 1.0) > 1e-9:
            raise ValueError(f"{gear}: the engine's 'loa' direction is not along X "
                             f"(cosine {dot})")
        index.append(names.index(f"{gear}.loa"))
        sign.append(math.copysign(1.0, dot))
    return np.array(index), np.array(sign)


def from_engine(y_engine, index, sign) -> np.ndarray:
    """An engine state [q, v] (or q) in the paper's order and signs."""
    y = np.asarray(y_engine, dtype=float)
    n = len(index)
    if y.shape == (n,):
        return sign * y[index]
    return np.concatenate([sign * y[:n][index], sign * y[n:][index]])
