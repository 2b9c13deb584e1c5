"""Gear and assembly errors as displacement excitations along the line of action.

Every error of a mesh is returned as a :class:`LineOfActionDeviation`: a constant plus a
sum of sinusoids ``a_k sin(omega_k t + phi_k)`` (amplitudes in m, angular
frequencies in rad/s >= 0, phases in rad).  The assembler adds them per mesh and
uses ``evaluate`` and ``rate`` (e(t), de/dt) in the element deformation
``delta = V^T q - e(t)``.

Sign convention (physical functions)
------------------------------------
``n`` is the unit vector of the line of action, oriented along the force that
gear 1 exerts on gear 2.  A positive error opens the mesh (material missing,
separation), so ``delta = V^T q - e``.  A rigid offset eps_i of gear i's tooth
ring centre acts on the mesh exactly like a displacement of that gear's centre,
hence ``e = -(eps_1 - eps_2) . n``.  Directions are polar angles from the global
+x axis, counter-clockwise positive; a gear's signed angular velocity is positive
counter-clockwise.

The papers' printed forms
-------------------------
:func:`eccentricity_installation_error_sum_form` (both gears' terms added: Liu, Fang,
Jia et al. 2021 eqs. 1-2) and :func:`eccentricity_installation_error_difference_form`
(the gears' terms subtracted: Dong, Zhang, Zhao & Duan 2021 eq. 11) reproduce the
papers' expressions literally, for comparison and for the example models.  Their
differences from the physical form are listed in their docstrings and in
docs/theory/excitations.md.  (Their earlier names, ``seed000_mesh_error`` and
``seed002_mesh_error``, still work, with a FutureWarning.)

Sources: Liu et al. 2021 eqs. 1-2; Dong et al. 2021 eq. 11; Mo, Ma, Jin et al. 2017
section 4 (tooth thickness, pitch, bearing errors as equivalent linear/angular meshing
errors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from torquesplit.errors import ModelError

__all__ = [
    "LineOfActionDeviation",
    "CentreDeviation",
    "rotating_offset_on_line",
    "fixed_offset_on_line",
    "centre_errors_on_line",
    "eccentricity_installation_error_sum_form",
    "eccentricity_installation_error_difference_form",
    "tooth_thickness_error",
    "cumulative_pitch_error",
    "pitch_error_from_deviations",
    "bearing_runout_error",
]


def _wrap(phase):
    return (np.asarray(phase, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


@dataclass(frozen=True)
class LineOfActionDeviation:
    """e(t) = constant + sum_k amplitudes[k] * sin(omegas[k] t + phases[k])  [m].

    Normalised on construction: omegas >= 0 and amplitudes > 0 (signs moved into
    the phases), phases wrapped to [-pi, pi), zero-frequency terms folded into the
    constant, zero-amplitude terms dropped.

    Examples
    --------
    >>> e = LineOfActionDeviation(1e-6, [2e-6], [10.0], [0.0])
    >>> round(float(e.evaluate(0.0)), 12), round(float(e.rate(0.0)), 12)
    (1e-06, 2e-05)
    """

    constant: float = 0.0
    amplitudes: np.ndarray = field(default_factory=lambda: np.zeros(0))
    omegas: np.ndarray = field(default_factory=lambda: np.zeros(0))
    phases: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        if np.size(self.amplitudes) == 0 and np.size(self.omegas) == 0 \
                and np.size(self.phases) == 0:  # a constant (most terms of a model)
            object.__setattr__(self, "constant", float(self.constant) + 0.0)  # as below
            for name in ("amplitudes", "omegas", "phases"):
                object.__setattr__(self, name, np.zeros(0))
            return
        a = np.array(self.amplitudes, dtype=float, ndmin=1)  # (copies)
        w = np.array(self.omegas, dtype=float, ndmin=1)
        p = np.array(self.phases, dtype=float, ndmin=1)
        if not (a.shape == w.shape == p.shape) or a.ndim != 1:
            raise ModelError(
                "LineOfActionDeviation: amplitudes, omegas and phases must be 1-D and of equal "
                f"length (got {a.shape}, {w.shape}, {p.shape})."
            )
        if a.size and w.min() > 0.0 and a.min() > 0.0:  # nothing to move or drop (the
            # terms of a sum or a scaling of normalised ones): the steps below would leave
            # every value as it is but the phases (the errors of Dong et al. 2021's ten meshes:
            # 1.8 -> 1.3 ms)
            object.__setattr__(self, "constant", float(self.constant) + 0.0)
            object.__setattr__(self, "amplitudes", a)
            object.__setattr__(self, "omegas", w)
            object.__setattr__(self, "phases", _wrap(p))
            return
        # a sin(-|w| t + p) = a sin(|w| t - p + pi)
        neg_w = w < 0
        w[neg_w] = -w[neg_w]
        p[neg_w] = np.pi - p[neg_w]
        # -a sin(x) = a sin(x + pi)
        neg_a = a < 0
        a[neg_a] = -a[neg_a]
        p[neg_a] = p[neg_a] + np.pi
        # zero-frequency terms are constants; zero-amplitude terms are dropped
        zero = w == 0.0
        const = float(self.constant) + float(np.sum(a[zero] * np.sin(p[zero])))
        keep = ~zero & (a != 0.0)
        object.__setattr__(self, "constant", const)
        object.__setattr__(self, "amplitudes", a[keep])
        object.__setattr__(self, "omegas", w[keep])
        object.__setattr__(self, "phases", _wrap(p[keep]))

    # --- evaluation -----------------------------------------------------
    def evaluate(self, t):
        """e(t) [m] for scalar or array ``t`` [s]."""
        t = np.asarray(t, dtype=float)
        arg = np.multiply.outer(t, self.omegas) + self.phases
        return self.constant + np.sum(self.amplitudes * np.sin(arg), axis=-1)

    def rate(self, t):
        """de/dt [m/s]."""
        t = np.asarray(t, dtype=float)
        arg = np.multiply.outer(t, self.omegas) + self.phases
        return np.sum(self.amplitudes * self.omegas * np.cos(arg), axis=-1)

    # --- algebra --------------------------------------------------------
    def __add__(self, other: "LineOfActionDeviation") -> "LineOfActionDeviation":
        if not isinstance(other, LineOfActionDeviation):
            return NotImplemented
        return LineOfActionDeviation(
            self.constant + other.constant,
            np.concatenate([self.amplitudes, other.amplitudes]),
            np.concatenate([self.omegas, other.omegas]),
            np.concatenate([self.phases, other.phases]),
        )

    def __neg__(self) -> "LineOfActionDeviation":
        return self.scaled(-1.0)

    def scaled(self, factor: float) -> "LineOfActionDeviation":
        """factor * e(t)."""
        return LineOfActionDeviation(self.constant * factor, self.amplitudes * factor, self.omegas, self.phases)

    def angular(self, base_radius: float) -> "LineOfActionDeviation":
        """Equivalent angular meshing error e / r_b [rad] (Mo et al. 2017 section 4.1)."""
        if base_radius <= 0:
            raise ModelError("LineOfActionDeviation.angular: base_radius must be positive (m).")
        return self.scaled(1.0 / base_radius)

    def combined(self, rtol: float = 1e-12) -> "LineOfActionDeviation":
        """Merge terms of equal frequency into one (phasor sum); drop zero amplitudes."""
        if self.omegas.size == 0:
            return self
        order = np.argsort(self.omegas)
        w, a, p = self.omegas[order], self.amplitudes[order], self.phases[order]
        out_w, out_z = [], []
        for wk, ak, pk in zip(w, a, p):
            z = ak * np.exp(1j * pk)
            if out_w and abs(wk - out_w[-1]) <= rtol * max(wk, 1.0):
                out_z[-1] += z
            else:
                out_w.append(wk)
                out_z.append(z)
        out_z = np.array(out_z)
        keep = np.abs(out_z) > 0.0
        return LineOfActionDeviation(
            self.constant, np.abs(out_z)[keep], np.array(out_w)[keep], np.angle(out_z)[keep]
        )


# --------------------------------------------------------------------------- #
# physical projections
# --------------------------------------------------------------------------- #
def rotating_offset_on_line(amplitude, phase, omega, line_angle) -> LineOfActionDeviation:
    """Projection on the line of action of an offset that rotates with its gear.

    The offset vector E (cos(Omega t + phi), sin(Omega t + phi)) projected on
    n = (cos zeta, sin zeta) is E cos(Omega t + phi - zeta)
    = E sin(Omega t + phi - zeta + pi/2).       # Liu et al. 2021 eqs. 1-2, Dong et al. 2021 eq. 11

    ``phase`` phi is the offset direction at t = 0 (polar angle), ``omega`` Omega
    the gear's signed angular velocity (CCW > 0), ``line_angle`` zeta the polar
    angle of n.  This is the signed displacement along n, not yet the mesh error;
    see :func:`centre_errors_on_line` for the sign of e.
    """
    return LineOfActionDeviation(0.0, [amplitude], [omega], [phase - line_angle + np.pi / 2])


def fixed_offset_on_line(amplitude, direction, line_angle) -> LineOfActionDeviation:
    """Projection A cos(gamma - zeta) of a fixed (installation) offset on n."""
    return LineOfActionDeviation(float(amplitude * math.cos(direction - line_angle)))


@dataclass(frozen=True)
class CentreDeviation:
    """Tooth-ring centre errors of one gear, SI.

    eccentricity : E [m], offset of the tooth ring from the rotation axis; it
        rotates with the gear.  (Geometric eccentricity = half the radial runout.)
    eccentricity_phase : its polar angle at t = 0 [rad].
    installation : A [m], offset of the rotation axis from its nominal position;
        fixed in space.
    installation_direction : its polar angle [rad].
    omega : signed angular velocity of the gear [rad/s], CCW > 0.
    """

    eccentricity: float = 0.0
    eccentricity_phase: float = 0.0
    installation: float = 0.0
    installation_direction: float = 0.0
    omega: float = 0.0

    def on_line(self, line_angle: float) -> LineOfActionDeviation:
        """Displacement of this gear's teeth along n (before the mesh sign)."""
        return rotating_offset_on_line(
            self.eccentricity, self.eccentricity_phase, self.omega, line_angle
        ) + fixed_offset_on_line(self.installation, self.installation_direction, line_angle)


def centre_errors_on_line(line_angle: float, gear_1: CentreDeviation, gear_2: CentreDeviation) -> LineOfActionDeviation:
    """Mesh error from eccentricity and installation errors of both gears.

    e(t) = -(eps_1(t) - eps_2(t)) . n, n at polar angle ``line_angle`` (force of
    gear 1 on gear 2).  Eccentricity terms vary at each gear's rotation frequency,
    installation terms are constant (as in Liu et al. 2021 eqs. 1-2 and Dong et al. 2021 eq. 11).
    A common offset of both gears cancels, as it must.

    Examples
    --------
    >>> g1 = CentreDeviation(eccentricity=8e-6, omega=800.0)
    >>> g2 = CentreDeviation(eccentricity=12e-6, omega=-254.0)
    >>> e = centre_errors_on_line(0.3, g1, g2)
    >>> sorted(e.omegas.round(1).tolist())
    [254.0, 800.0]
    """
    return gear_2.on_line(line_angle) + (-gear_1.on_line(line_angle))


# --------------------------------------------------------------------------- #
# the papers' printed forms
# --------------------------------------------------------------------------- #
def eccentricity_installation_error_sum_form(
    *,
    eccentricity_i: float,
    phase_i: float,
    omega_i: float,
    installation_i: float,
    installation_phase_i: float,
    eccentricity_j: float,
    phase_j: float,
    omega_j: float,
    installation_j: float,
    installation_phase_j: float,
    line_offset: float,
    sign: float = 1.0,
) -> LineOfActionDeviation:
    """Mesh error of eccentricity and installation errors with both gears' terms added:
    Liu, Fang, Jia et al. 2021 eqs. 1-2 exactly as printed.

    e = sign * [ E_i sin(-w_i t - lambda_i + c) + A_i sin(-mu_i + c)
               + E_j sin(-w_j t - lambda_j + c) + A_j sin(-mu_j + c) ]

    with c = ``line_offset``: gamma + alpha_ts and sign = +1 for the spur pairs 34,
    35 (eq. 1, eq. 2 first line); gamma - alpha_th and sign = -1 for the
    double-helical pairs 68, 78 (eq. 2).

    Remarks (see docs/theory/excitations.md):
    - Both gears enter with the same sign.  The mesh error depends on the
      difference of the two centre offsets, so a rigid shift of both gears would
      here produce a non-zero error; with the phases free this equals the
      physical form with lambda_j, mu_j shifted by pi (a phase-convention
      difference, not a different model).
    - Both eccentricities use -w t although mating external gears turn in
      opposite senses; equivalent to the physical form only if w_j is signed.
    - The installation terms are constant: installation errors do not rotate.
    """
    c = line_offset
    terms = LineOfActionDeviation(
        installation_i * math.sin(-installation_phase_i + c)
        + installation_j * math.sin(-installation_phase_j + c),  # Liu et al. 2021 eq. 1 A terms
        [eccentricity_i, eccentricity_j],
        [-omega_i, -omega_j],
        [-phase_i + c, -phase_j + c],  # Liu et al. 2021 eq. 1 E terms
    )
    return terms.scaled(sign)


def eccentricity_installation_error_difference_form(
    *,
    eccentricity_i: float,
    phase_i: float,
    omega_i: float,
    installation_i: float,
    installation_phase_i: float,
    eccentricity_j: float,
    phase_j: float,
    omega_j: float,
    installation_j: float,
    installation_phase_j: float,
    line_angle: float,
    sign: float = 1.0,
) -> LineOfActionDeviation:
    """Mesh error of eccentricity and installation errors with the gears' terms
    subtracted: Dong, Zhang, Zhao & Duan 2021 eq. 11 exactly as printed.

    e = sign * [ E_i sin(-w_i t + eta_i + a_ij) - E_j sin(-w_j t + eta_j + a_ij)
               + A_i sin(delta_i + a_ij) - A_j sin(delta_j + a_ij) ]

    sign = +1 for pairs 12, 46, 58, 610, 810 and -1 for 13, 47, 59, 710, 910;
    a_ij = ``line_angle`` is the angle alpha_Iij or alpha_IIij of Dong et al. 2021 eq. 10
    (e.g. pi/2 - alpha_n + gamma_IIij).

    Interpretation: with n = (cos a, sin a) as in Dong et al. 2021 eq. 10, E sin(psi + a)
    is the projection on n of an offset (E sin psi, E cos psi), i.e. with psi
    measured from the +y axis towards +x; psi = -w t + eta rotates
    counter-clockwise.  The two gears enter with opposite signs (a difference of
    centre offsets, physically consistent) but, if w_i, w_j are magnitudes, both
    eccentricities rotate counter-clockwise although mating external gears turn in
    opposite senses (pass w_j < 0 to correct this).  Installation terms are constant.
    """
    a = line_angle
    terms = LineOfActionDeviation(
        installation_i * math.sin(installation_phase_i + a)
        - installation_j * math.sin(installation_phase_j + a),  # Dong et al. 2021 eq. 11 A terms
        [eccentricity_i, -eccentricity_j],
        [-omega_i, -omega_j],
        [phase_i + a, phase_j + a],  # Dong et al. 2021 eq. 11 E terms
    )
    return terms.scaled(sign)


def seed000_mesh_error(**kwargs) -> LineOfActionDeviation:
    """Deprecated name of :func:`eccentricity_installation_error_sum_form`."""
    import warnings

    warnings.warn("seed000_mesh_error is deprecated; use "
                  "eccentricity_installation_error_sum_form", FutureWarning, stacklevel=2)
    return eccentricity_installation_error_sum_form(**kwargs)


def seed002_mesh_error(**kwargs) -> LineOfActionDeviation:
    """Deprecated name of :func:`eccentricity_installation_error_difference_form`."""
    import warnings

    warnings.warn("seed002_mesh_error is deprecated; use "
                  "eccentricity_installation_error_difference_form", FutureWarning,
                  stacklevel=2)
    return eccentricity_installation_error_difference_form(**kwargs)


# --------------------------------------------------------------------------- #
# Mo et al. 2017: tooth thickness, pitch and bearing errors
# --------------------------------------------------------------------------- #
def tooth_thickness_error(thickness_deviation: float, pressure_angle: float) -> LineOfActionDeviation:
    """Constant mesh error of a tooth thickness deviation (Mo et al. 2017 section 4.1).

    A deviation Delta s of the circular tooth thickness, measured on a circle of
    pressure angle alpha (the reference circle: alpha_t), moves each flank by
    Delta s / 2 along that circle, i.e. turns it by Delta s / (2 r); along the line
    of action this is r_b Delta s / (2 r) = (Delta s / 2) cos alpha.  A thinner tooth
    (Delta s < 0) opens the mesh:  e = -(Delta s / 2) cos alpha.  Angular equivalent
    (Mo et al. 2017): e / r_b.
    """
    return LineOfActionDeviation(-0.5 * thickness_deviation * math.cos(pressure_angle))


def cumulative_pitch_error(
    total_cumulative_deviation: float, phase: float, omega: float, pressure_angle: float
) -> LineOfActionDeviation:
    """First-harmonic model of the cumulative pitch deviation (Mo et al. 2017 section 4.1).

    A total cumulative pitch deviation F_p (peak-to-peak over one revolution,
    measured along the reference circle) is modelled by its once-per-revolution
    harmonic (F_p / 2) sin(Omega t + phi); along the line of action it is scaled
    by cos(alpha).  Positive = the working flank lags (mesh opens).
    """
    return LineOfActionDeviation(
        0.0, [0.5 * total_cumulative_deviation * math.cos(pressure_angle)], [omega], [phase]
    )


def pitch_error_from_deviations(
    cumulative_deviations, omega: float, pressure_angle: float, *, tooth_number: int | None = None
) -> LineOfActionDeviation:
    """Tooth-by-tooth cumulative pitch deviations as a periodic line-of-action error.

    ``cumulative_deviations[k]`` [m] is the cumulative pitch deviation of tooth k
    (positive = the working flank lags, mesh opens), measured on the reference
    circle.  Tooth k meshes during [k T_z, (k+1) T_z) with T_z = 2 pi / (z |Omega|);
    the returned signal is the trigonometric interpolation of the sequence, sampled
    at the middle of each tooth's mesh interval: harmonics 1 .. z/2 of the gear
    rotation frequency, multiplied by cos(alpha) (Mo et al. 2017 section 4.1).  Its mean
    over a revolution is the constant.
    """
    dev = np.asarray(cumulative_deviations, dtype=float) * math.cos(pressure_angle)
    z = dev.size if tooth_number is None else int(tooth_number)
    if dev.size != z or z < 2:
        raise ModelError(
            "pitch_error_from_deviations: give one cumulative deviation per tooth "
            f"(got {dev.size} values for {z} teeth)."
        )
    w = abs(float(omega))
    if w == 0:
        raise ModelError("pitch_error_from_deviations: omega must be non-zero (rad/s).")
    coeffs = np.fft.rfft(dev) / z
    amps, omegas, phases = [], [], []
    t_mid = 0.5  # sample k sits at t = (k + 0.5) T_z
    for h in range(1, coeffs.size):
        c = coeffs[h]
        factor = 1.0 if (z % 2 == 0 and h == z // 2) else 2.0
        # term: factor*|c| cos(2 pi h k / z + arg c), k = Omega t / (2 pi / z) - 1/2
        amp = factor * abs(c)
        if amp == 0.0:
            continue
        phase = np.angle(c) - 2.0 * np.pi * h * t_mid / z + np.pi / 2
        amps.append(amp)
        omegas.append(h * w)
        phases.append(phase)
    return LineOfActionDeviation(float(coeffs[0].real), amps, omegas, phases)


def bearing_runout_error(runout: float, phase: float, omega: float, line_angle: float) -> LineOfActionDeviation:
    """Displacement along n from the radial runout of a bearing ring that rotates
    with the shaft (inner ring), Mo et al. 2017 section 4.1 "bearing manufacturing error".

    The runout (total indicator reading) is twice the eccentricity of the ring, so
    the centre offset is runout / 2 and rotates with the shaft:
    (runout / 2) cos(Omega t + phi - zeta).  A stationary (outer) ring's runout is
    a fixed offset: use :func:`fixed_offset_on_line`.  Combine into a mesh error
    like an eccentricity (:class:`CentreDeviation` or minus/plus this signal).
    """
    return rotating_offset_on_line(0.5 * runout, phase, omega, line_angle)
