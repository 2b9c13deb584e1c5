"""Single stiffness c' and mesh stiffness c_gamma by ISO 6336-1 method B, and a
time-varying shape built from the contact-line length.

Units: the standard tabulates ``q'`` in mm um/N and ``c'``, ``c_gamma`` in N/(mm um)
(newton per millimetre of face width per micrometre of deflection).  This module
returns SI: ``q'`` in m^2/N (1 mm um/N = 1e-9 m^2/N) and ``c'``, ``c_gamma`` in
N/m per metre of face width, i.e. N/m^2 (1 N/(mm um) = 1e9 N/m^2).  The ``*_iso``
properties give the standard's units for comparison with its tables.

Direction: ISO uses ``c'`` and ``c_gamma`` with loads and deviations of the transverse
plane (the tangential line load ``F_t / b`` and the transverse base-pitch deviation
``f_pb`` in ``K_H_alpha``; the reduced mass of ``K_v`` on the base circle), so they are
read here as transverse-plane stiffness per unit face width.  The waveform returned by
:func:`iso6336_stiffness` is, like every :class:`MeshStiffness`, along the normal to
the flanks: ``k_n = k_t / cos^2(beta_b)`` (normal force ``F_t / cos(beta_b)``, normal
approach ``delta_t cos(beta_b)``); for spur gears the two coincide.

Reference: ISO 6336-1:2006/2019, Calculation of load capacity of spur and helical
gears -- Part 1, clause "Tooth stiffness parameters c' and c_gamma", method B
(theoretical single stiffness from the minimum flexibility q', correction factors
C_M, C_R, C_B, mesh stiffness c_gamma = c' (0.75 eps_alpha + 0.25)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import PairGeometry
from torquesplit.gears.stiffness.phasing import contact_line_length, phase_grid, require_contact
from torquesplit.gears.stiffness.result import MeshStiffness

__all__ = [
    "ISO_C",
    "STEEL_YOUNG_MODULUS",
    "Iso6336Values",
    "minimum_flexibility",
    "basic_rack_factor",
    "blank_factor",
    "iso6336_values",
    "iso6336_mesh_stiffness_value",
    "iso6336_stiffness",
]

#: C1..C9 of the minimum flexibility q'_min, ISO 6336-1 method B (table of constants).
ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)

#: Young's modulus of steel to which ISO 6336-1 refers c' [Pa] (206 000 N/mm^2).
STEEL_YOUNG_MODULUS = 206e9

#: Theoretical correction factor C_M (ISO 6336-1 method B).
CORRECTION_FACTOR_CM = 0.8

_ISO_TO_SI_STIFFNESS = 1e9   # N/(mm um) -> N/m^2
_ISO_TO_SI_FLEXIBILITY = 1e-9  # mm um/N -> m^2/N


def minimum_flexibility(zn1: float, zn2: float, x1: float, x2: float) -> float:
    """Minimum flexibility of a tooth pair ``q'_min`` [m^2/N] (ISO 6336-1 method B).

    ``q' = C1 + C2/zn1 + C3/zn2 + C4 x1 + C5 x1/zn1 + C6 x2 + C7 x2/zn2 + C8 x1^2 + C9 x2^2``
    in mm um/N, converted to SI (x 1e-9).  ``zn`` are virtual tooth numbers
    ``z / (cos^2(beta_b) cos(beta))``; for an internal gear pass ``zn2 = inf`` and
    ``x2`` in ISO's sign convention (``-x`` of this package's convention).
    Valid per ISO for ``x1 >= x2`` and ``-0.5 <= x1 + x2 <= 2``.
    """
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = ISO_C
    inv1 = 0.0 if math.isinf(zn1) else 1.0 / zn1
    inv2 = 0.0 if math.isinf(zn2) else 1.0 / zn2
    # ISO 6336-1 method B, q'_min [mm um/N]
    q = (c1 + c2 * inv1 + c3 * inv2 + c4 * x1 + c5 * x1 * inv1 + c6 * x2 + c7 * x2 * inv2
         + c8 * x1 ** 2 + c9 * x2 ** 2)
    return q * _ISO_TO_SI_FLEXIBILITY


def basic_rack_factor(dedendum: float, normal_pressure_angle: float) -> float:
    """Basic rack factor ``C_B`` [-] of one gear (ISO 6336-1 method B).

    ``C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_Pn)]`` with the rack
    dedendum coefficient ``h_fP/m_n`` and ``alpha_Pn`` in degrees; 0.975 for the
    ISO 53 standard rack (1.25, 20 deg).  For a pair ISO uses the mean of both gears.
    """
    # ISO 6336-1 method B, C_B
    return (1.0 + 0.5 * (1.2 - dedendum)) * (1.0 - 0.02 * (20.0 - math.degrees(normal_pressure_angle)))


def blank_factor(face_width: float, web_thickness: float, rim_thickness: float, normal_module: float) -> float:
    """Gear blank factor ``C_R`` [-] (ISO 6336-1 method B); 1 for solid discs.

    ``C_R = 1 + ln(b_s / b) / (5 exp(s_R / (5 m_n)))`` with web thickness ``b_s``,
    rim thickness ``s_R``, all in metres; the standard limits ``b_s/b`` to
    [0.2, 1.2] and ``s_R/m_n`` to >= 1 (values outside are clamped, as it directs).
    """
    ratio = min(max(web_thickness / face_width, 0.2), 1.2)
    rim = max(rim_thickness / normal_module, 1.0)
    # ISO 6336-1 method B, C_R
    return 1.0 + math.log(ratio) / (5.0 * math.exp(rim / 5.0))


@dataclass(frozen=True)
class Iso6336Values:
    """ISO 6336-1 method B stiffness values of a pair, SI units.

    ``q_prime`` [m^2/N]; ``c_prime_th``, ``c_prime``, ``c_gamma`` [N/m^2] = N/m per m of
    face width; ``single_stiffness = c' b`` and ``mesh_stiffness = c_gamma b`` [N/m]
    for the total active face width ``b`` (both helices of a double-helical pair).
    These are ISO's transverse-plane values; ``*_normal`` divide by ``cos^2(beta_b)``.
    """

    q_prime: float
    c_prime_th: float
    c_prime: float
    c_gamma: float
    face_width: float
    single_stiffness: float
    mesh_stiffness: float
    transverse_contact_ratio: float
    factor_cm: float
    factor_cr: float
    factor_cb: float
    factor_material: float
    factor_load: float
    base_helix_angle: float

    @property
    def single_stiffness_normal(self) -> float:
        """``c' b / cos^2(beta_b)`` [N/m], along the normal to the flanks."""
        return self.single_stiffness / math.cos(self.base_helix_angle) ** 2

    @property
    def mesh_stiffness_normal(self) -> float:
        """``c_gamma b / cos^2(beta_b)`` [N/m], along the normal to the flanks."""
        return self.mesh_stiffness / math.cos(self.base_helix_angle) ** 2

    @property
    def q_prime_iso(self) -> float:
        """``q'`` in the standard's unit mm um/N."""
        return self.q_prime / _ISO_TO_SI_FLEXIBILITY

    @property
    def c_prime_iso(self) -> float:
        """``c'`` in the standard's unit N/(mm um)."""
        return self.c_prime / _ISO_TO_SI_STIFFNESS

    @property
    def c_gamma_iso(self) -> float:
        """``c_gamma`` in the standard's unit N/(mm um)."""
        return self.c_gamma / _ISO_TO_SI_STIFFNESS


def _pair_moduli(young_modulus) -> tuple[float, float]:
    if young_modulus is None:
        return STEEL_YOUNG_MODULUS, STEEL_YOUNG_MODULUS
    if np.ndim(young_modulus) == 0:
        return float(young_modulus), float(young_modulus)
    e1, e2 = young_modulus
    return float(e1), float(e2)


def iso6336_values(pair: PairGeometry, *, blank_factor: float = 1.0, young_modulus=None,
                   line_load: float | None = None) -> Iso6336Values:
    """ISO 6336-1 method B single stiffness ``c'`` and mesh stiffness ``c_gamma``.

    Parameters
    ----------
    pair : PairGeometry
    blank_factor : float
        ``C_R`` [-]; 1 for solid gear blanks (see :func:`blank_factor`).
    young_modulus : float or (float, float), optional
        Young's moduli [Pa]; default steel/steel.  Other materials scale ``c'`` by
        ``E / E_steel`` with ``E = 2 E1 E2 / (E1 + E2)`` (ISO 6336-1).
    line_load : float, optional
        ``F_t K_A / b`` [N/m].  Below 100 N/mm (1e5 N/m) ISO reduces ``c'`` by
        ``(F_t K_A / b / 100 N/mm)^0.25``; None means at or above that load.

    Returns
    -------
    Iso6336Values
        ``c' = c'_th C_M C_R C_B cos(beta)`` with ``c'_th = 1/q'``, and
        ``c_gamma = c' (0.75 eps_alpha + 0.25)``, in N/m^2.
    """
    g1, g2 = pair.gear1, pair.gear2
    x2_iso = -g2.profile_shift if g2.internal else g2.profile_shift
    q = minimum_flexibility(g1.virtual_teeth, g2.virtual_teeth, g1.profile_shift, x2_iso)
    if q <= 0:
        raise ModelError([("profile_shift", "ISO 6336-1 q' is not positive for these profile shifts; "
                                            "they lie outside the formula's range")])
    c_th = 1.0 / q  # ISO 6336-1 method B: c'_th = 1 / q'_min
    # ISO 6336-1 method B: C_B of the pair = mean of both gears' basic rack factors
    cb = 0.5 * (basic_rack_factor(g1.dedendum, g1.normal_pressure_angle)
                + basic_rack_factor(g2.dedendum, g2.normal_pressure_angle))
    e1, e2 = _pair_moduli(young_modulus)
    f_mat = (2.0 * e1 * e2 / (e1 + e2)) / STEEL_YOUNG_MODULUS  # ISO 6336-1: c' ~ E / E_steel
    f_load = 1.0
    if line_load is not None:
        if line_load <= 0:
            raise ModelError([("line_load", "must be a positive line load F_t K_A / b in N/m")])
        f_load = min(1.0, (line_load / 1e5) ** 0.25)  # ISO 6336-1: (F_t K_A / b / 100)^0.25 below 100 N/mm
    # ISO 6336-1 method B: c' = c'_th C_M C_R C_B cos(beta)
    c_prime = c_th * CORRECTION_FACTOR_CM * blank_factor * cb * math.cos(g1.beta) * f_mat * f_load
    eps_a = pair.transverse_contact_ratio
    c_gamma = c_prime * (0.75 * eps_a + 0.25)  # ISO 6336-1: c_gamma_alpha = c' (0.75 eps_alpha + 0.25)
    b = pair.total_face_width
    return Iso6336Values(
        q_prime=q, c_prime_th=c_th, c_prime=c_prime, c_gamma=c_gamma, face_width=b,
        single_stiffness=c_prime * b, mesh_stiffness=c_gamma * b,
        transverse_contact_ratio=eps_a, factor_cm=CORRECTION_FACTOR_CM, factor_cr=blank_factor,
        factor_cb=cb, factor_material=f_mat, factor_load=f_load,
        base_helix_angle=pair.base_helix_angle,
    )


def iso6336_mesh_stiffness_value(pair: PairGeometry, **options) -> float:
    """ISO 6336-1 mean mesh stiffness ``c_gamma b`` of the pair along the flank normal [N/m].

    ``c_gamma b / cos^2(beta_b)`` (= ``c_gamma b`` for spur gears), the mean of
    :func:`iso6336_stiffness` with ``scale="c_gamma"``; ``options`` as
    :func:`iso6336_values`.
    """
    return iso6336_values(pair, **options).mesh_stiffness_normal


def iso6336_stiffness(pair: PairGeometry, n: int = 256, *, scale: str | None = None,
                      blank_factor: float = 1.0, young_modulus=None, line_load: float | None = None,
                      stagger: float = 0.0) -> MeshStiffness:
    """Time-varying mesh stiffness from ISO 6336-1 values and the contact-line length.

    The waveform is proportional to the total length of the contact lines in the
    field of action, ``L(phi)`` (see :func:`~.phasing.contact_line_length`):

    * ``scale="single_pair"``: every tooth pair carries ``c'`` per unit face width,
      ``k(phi) = c' cos(beta_b) L(phi) / cos^2(beta_b)``.  For spur gears this is
      ``c' b`` in single contact and ``2 c' b`` in double contact; its mean is
      ``c' eps_alpha b``.
    * ``scale="c_gamma"``: the same shape normalised so that the mean is the ISO
      mesh stiffness ``c_gamma b / cos^2(beta_b)``.

    Both are along the normal to the flanks (see the module docstring).
    * ``None`` (default): ``"c_gamma"`` for every pair.  ISO's mean mesh stiffness
      ``c_gamma = c' (0.75 eps_alpha + 0.25)`` is below ``c' eps_alpha`` (``c'`` is the
      largest single-pair stiffness; the pairs near tip and root are softer), and the
      helical pairs take it: a spur default of ``"single_pair"`` made the mean jump by
      10 % between a helix angle of 0 and 0.01 deg.

    ``stagger`` [cycles] offsets the second helix of a double-helical pair (0: the
    two helices mesh in phase).  Other options as :func:`iso6336_values`.
    Result in N/m; ``info`` holds the :class:`Iso6336Values` fields.
    """
    require_contact(pair)
    values = iso6336_values(pair, blank_factor=blank_factor, young_modulus=young_modulus,
                            line_load=line_load)
    if scale is None:
        scale = "c_gamma"
    if scale not in ("single_pair", "c_gamma"):
        raise ModelError([("scale", f"must be 'single_pair' or 'c_gamma', got {scale!r}")])
    phase = phase_grid(n)
    length = contact_line_length(pair, phase)
    if pair.double_helical:
        length = length + contact_line_length(pair, phase, offset=stagger)
    elif stagger:
        raise ModelError([("stagger", "applies to double-helical pairs only")])
    cb = math.cos(pair.base_helix_angle)
    if scale == "single_pair":
        k = values.c_prime * cb * length / cb ** 2
    else:
        k = values.mesh_stiffness_normal * length / length.mean()
    info = dict(values.__dict__)
    info.update(scale=scale, c_prime_iso=values.c_prime_iso, c_gamma_iso=values.c_gamma_iso,
                q_prime_iso=values.q_prime_iso, mesh_stiffness_normal=values.mesh_stiffness_normal,
                single_stiffness_normal=values.single_stiffness_normal)
    return MeshStiffness.from_samples(k, "iso6336", info)
