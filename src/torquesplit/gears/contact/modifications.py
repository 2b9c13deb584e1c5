"""Tooth modifications and misalignment as initial separations of the flanks.

A modification removes material from a flank; an amount is measured along the normal
to the flank, in metres, positive = material removed.  The initial separation of a
potential contact point is the sum of what both flanks have lost there, plus the
separation the misalignment and errors of the pair open (Liu et al. 2021 eq. 22
superposes the modification surface along the flank normal; Dong et al. 2021 §5 adds
the separations ``b`` to the geometric transmission error).

Profile coordinates (transverse plane, one gear)
------------------------------------------------
``rho`` is the roll length: the distance of the contact point from the gear's
base-circle tangent point on the line of action (``rho = r_b tan(alpha)``, radius
``r = sqrt(r_b^2 + rho^2)``, roll angle ``rho / r_b``).  On its flank each gear has an
*active profile* between its start of active profile (SAP, the lowest point that
touches the mate) and the point that touches the mate's SAP (its tip for standard
pairs).  Tip relief grows towards the tip end, root relief towards the SAP end.

Relief curves (Liu et al. 2021 eq. 20 with exponent ``c``)::

    xi(t) = C t^c,      t = (distance into the relief zone) / (zone length) in [0, 1]

``linear`` is c = 1, ``parabolic`` c = 2, ``power`` any c > 0.  The zone is given by
its roll length along the line of action (``length``, ISO 21771 L_Ca), by the diameter
where it starts (``start_diameter``), by the roll angle where it starts
(``start_roll_angle``) or by its radial height (``height``, Liu et al. 2021 Fig. 9:
the modification lengths y3, y4 of the rotation-projection surface, eq. 21, are
radial).  ``t`` is measured in the coordinate the zone is given in (roll length for
``length`` and ``start_roll_angle``, radius for ``start_diameter`` and ``height``).

Lead coordinates (one helix)
----------------------------
``y`` runs across the face of one helix from 0 (the end where a tooth pair enters
contact, see :mod:`torquesplit.gears.stiffness.phasing`) to ``b``, the common face
width of the pair.  Both gears' lead modifications are laid out over this common
face, centred.  Crowning ``C_b (2y/b - 1)^2`` (amount at each end); end relief
``C_I ((L_I - y)/L_I)^c`` over ``y < L_I`` and mirrored at ``y > b - L_I``; helix
slope ``f (y/b - 1/2)``.  A double-helical gear carries the same modification on both
helices unless ``second_helix`` is given; the second helix's ``y`` also starts at its
entry end, which is mirrored, so equal modifications are mirror-symmetric.

Pair separations (:class:`Misalignment`)
----------------------------------------
``lead_mismatch`` f: combined helix-slope deviation of both gears over one helix,
``f (y/b - 1/2)`` in each helix.  ``shaft_misalignment`` theta: tilt of the axes
against each other in the plane of action; at axial position ``z`` (measured from the
middle of the gear) the flanks separate by ``theta z cos(beta_b)`` along the normal --
continuous across both helices of a double-helical gear (the central groove is not
modelled).  ``base_pitch_deviation`` f_pb = p_bn(driven) - p_bn(driver): the
equivalent base-circle mismatch, a separation ``f_pb (s - s_mid) / p_bt`` linear along
the path, so that each newer tooth pair is ``f_pb`` closer (premature contact at
engagement for f_pb > 0: the driver's next flank, p_bn(driver) behind its current one,
meets the driven gear's next flank, p_bn(driven) behind, that much early) while the
analysis stays mesh-periodic.

Units: metres, radians.  Everything here is plain numpy (it runs once per analysis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from torquesplit.errors import ModelError

__all__ = [
    "Relief",
    "EndRelief",
    "FlankModification",
    "ToothModification",
    "Misalignment",
    "liu2021_topological",
    "FlankCoordinates",
    "flank_coordinates",
    "profile_separation",
    "lead_separation",
]

_SHAPES = {"linear": 1.0, "parabolic": 2.0}


def _num(value, unit: str = "") -> str:
    """A number for a message without float noise ("-5e-06 m", not -4.9999999999999996e-06)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"{value:.6g}" + (f" {unit}" if unit else "")
    return repr(value)


def _exponent(shape: str, exponent: float, where: str) -> float:
    if shape in _SHAPES:
        return _SHAPES[shape]
    if shape == "power":
        if not (exponent > 0 and math.isfinite(exponent)):
            raise ModelError([(f"{where}.exponent", f"must be a positive number, got "
                                                    f"{_num(exponent)}; give e.g. 2 for a "
                                                    "parabola")])
        return float(exponent)
    raise ModelError([(f"{where}.shape", f"unknown shape {shape!r}; use 'linear', 'parabolic' "
                                         "or 'power'")])


@dataclass(frozen=True)
class Relief:
    """Tip or root relief of one flank (SI).

    Give the amount and exactly one of ``length`` (roll length along the line of
    action), ``start_diameter``, ``start_roll_angle`` or ``height`` (radial).

    Examples
    --------
    >>> Relief(20e-6, length=2e-3).exponent
    1.0
    """

    amount: float
    length: float | None = None
    start_diameter: float | None = None
    start_roll_angle: float | None = None
    height: float | None = None
    shape: str = "linear"
    exponent: float = 2.0

    def __post_init__(self):
        if self.shape in _SHAPES:  # the exponent actually used
            object.__setattr__(self, "exponent", _SHAPES[self.shape])

    def check(self, where: str) -> None:
        """Raise ModelError (location ``where.field``) if the relief is ill-defined."""
        if not (self.amount >= 0 and math.isfinite(self.amount)):
            raise ModelError([(f"{where}.amount", f"must be a non-negative length, got "
                                                  f"{_num(self.amount, 'm')}; give e.g. '20 um'")])
        given = [n for n in ("length", "start_diameter", "start_roll_angle", "height")
                 if getattr(self, n) is not None]
        if len(given) != 1:
            raise ModelError([(where, f"needs exactly one of length, start_diameter, "
                                      f"start_roll_angle, height (got {given or 'none'}); give one")])
        v = getattr(self, given[0])
        if not (v > 0 and math.isfinite(v)):
            unit = "rad" if given[0] == "start_roll_angle" else "m"
            raise ModelError([(f"{where}.{given[0]}", f"must be positive, got {_num(v, unit)}; "
                                                      "correct the value")])
        _exponent(self.shape, self.exponent, where)

    @property
    def c(self) -> float:
        """Exponent of the relief curve [-]."""
        return _exponent(self.shape, self.exponent, "relief")


@dataclass(frozen=True)
class EndRelief:
    """Lead end relief at both ends of the face (SI): amount, length, curve."""

    amount: float
    length: float
    shape: str = "linear"
    exponent: float = 2.0

    def __post_init__(self):
        if self.shape in _SHAPES:
            object.__setattr__(self, "exponent", _SHAPES[self.shape])

    def check(self, where: str, face_width: float | None = None) -> None:
        if not (self.amount >= 0 and math.isfinite(self.amount)):
            raise ModelError([(f"{where}.amount", f"must be a non-negative length, got "
                                                  f"{_num(self.amount, 'm')}; give e.g. '10 um'")])
        if not (self.length > 0 and math.isfinite(self.length)):
            raise ModelError([(f"{where}.length", f"must be positive, got "
                                                  f"{_num(self.length, 'm')}; "
                                                  "correct the value")])
        if face_width is not None and 2.0 * self.length > face_width * (1 + 1e-12):
            raise ModelError([(f"{where}.length", (
                f"{self.length * 1e3:.4g} mm at both ends exceeds the face width "
                f"{face_width * 1e3:.4g} mm of one helix; reduce it to at most "
                f"{face_width * 5e2:.4g} mm"))])
        _exponent(self.shape, self.exponent, where)


@dataclass(frozen=True)
class FlankModification:
    """Profile and lead modification of the loaded flank of one helix (SI)."""

    tip_relief: Relief | None = None
    root_relief: Relief | None = None
    crowning: float = 0.0
    end_relief: EndRelief | None = None
    helix_slope: float = 0.0

    @property
    def is_zero(self) -> bool:
        return (self.tip_relief is None and self.root_relief is None and self.crowning == 0.0
                and self.end_relief is None and self.helix_slope == 0.0)


@dataclass(frozen=True)
class ToothModification:
    """Modification of one gear: the flank of the (first) helix, and optionally a
    different one for the second helix of a double-helical gear."""

    flank: FlankModification = field(default_factory=FlankModification)
    second_helix: FlankModification | None = None

    def helix(self, index: int) -> FlankModification:
        """The flank modification of helix 0 or 1."""
        if index == 1 and self.second_helix is not None:
            return self.second_helix
        return self.flank

    @property
    def is_zero(self) -> bool:
        return self.flank.is_zero and (self.second_helix is None or self.second_helix.is_zero)


@dataclass(frozen=True)
class Misalignment:
    """Separations the pair opens (SI): see the module docstring."""

    lead_mismatch: float = 0.0
    shaft_misalignment: float = 0.0
    base_pitch_deviation: float = 0.0


def liu2021_topological(y1: float, y2: float, y3: float, y4: float, y5: float, y6: float,
                        face_width: float, exponent: float = 2.0) -> FlankModification:
    """The topological modification of Liu, Fang, Jia et al. 2021 (§4, Fig. 9, eq. 20).

    Profile and lead modification each made of two curves ``C ((s - s_i)/(s_j - s_i))^c``
    and a straight unmodified part (eq. 20, c = 2 for the paper's "quadratic parabolas"):

    * ``y1`` root relief amount over the radial height ``y3`` above the start of active
      profile (the paper's effective tooth height H is read as the active profile);
    * ``y2`` tip relief amount over the radial height ``y4`` below the tip;
    * ``y5`` end relief amount at both face ends, over ``(b - y6) / 2`` each, ``y6``
      being the unmodified length in the middle of the face.

    Parameters
    ----------
    y1 .. y6 : float
        [m].
    face_width : float
        Face width ``L`` of one helix [m] (needed to turn y6 into the end relief length).
    exponent : float
        Index ``c`` of the modification curve.

    Examples
    --------
    >>> m = liu2021_topological(23e-6, 35e-6, 2.30e-3, 2.01e-3, 13e-6, 8.19e-3, 50e-3)
    >>> round(m.end_relief.length * 1e3, 3)
    20.905
    """
    if not (0 < y6 < face_width):
        raise ModelError([("topological.y6", (
            f"the unmodified length {y6 * 1e3:.4g} mm must lie between 0 and the face width "
            f"{face_width * 1e3:.4g} mm of one helix; correct y6"))])
    shape = dict(shape="power", exponent=float(exponent))
    return FlankModification(
        root_relief=Relief(y1, height=y3, **shape) if y1 > 0 else None,
        tip_relief=Relief(y2, height=y4, **shape) if y2 > 0 else None,
        end_relief=EndRelief(y5, 0.5 * (face_width - y6), **shape) if y5 > 0 else None,
    )


# ----------------------------------------------------------------------- coordinates
@dataclass(frozen=True)
class FlankCoordinates:
    """Where the active profile of one gear of a pair lies (SI).

    ``rho_sap``/``rho_tip``: roll lengths at the SAP end and at the tip end of the
    active profile; ``r_sap``/``r_tip`` the radii there; ``base_radius``; ``sign`` = +1
    if roll length grows from SAP to tip (external gears), -1 for a ring gear.
    """

    base_radius: float
    rho_sap: float
    rho_tip: float
    r_sap: float
    r_tip: float
    sign: float

    @property
    def active_length(self) -> float:
        """Roll length of the active profile [m]."""
        return abs(self.rho_tip - self.rho_sap)

    @property
    def active_height(self) -> float:
        """Radial height of the active profile [m]."""
        return abs(self.r_tip - self.r_sap)

    def radius(self, rho):
        return np.sqrt(self.base_radius ** 2 + np.asarray(rho, dtype=float) ** 2)


def flank_coordinates(pair, gear: int) -> FlankCoordinates:
    """Active-profile coordinates of gear 1 (pinion) or gear 2 of a PairGeometry."""
    rb = (pair.gear1 if gear == 1 else pair.gear2).base_radius
    r_start, r_end = pair.roll_distances(np.array([pair.path_start, pair.path_end]))
    if gear == 1:
        sap, tip, sign = float(r_start[0]), float(r_start[1]), 1.0
    else:
        # gear 2's tip touches the pinion's SAP (path start)
        sap, tip = float(r_end[1]), float(r_end[0])
        sign = 1.0 if tip > sap else -1.0
    return FlankCoordinates(rb, sap, tip, math.hypot(rb, sap), math.hypot(rb, tip), sign)


def _zone(relief: Relief, fc: FlankCoordinates, tip: bool, where: str):
    """(coordinate function, start value, zone length) of a relief zone.

    The coordinate grows from the relief start towards the tip (tip relief) or the SAP
    (root relief); the relief is ``amount * clip(t, 0, 1)^c`` with
    ``t = (coord(rho) - start) / zone length``.
    """
    end_rho = fc.rho_tip if tip else fc.rho_sap
    other_rho = fc.rho_sap if tip else fc.rho_tip
    # +1 if rho grows towards the relieved end
    d = 1.0 if end_rho > other_rho else -1.0
    if relief.length is not None or relief.start_roll_angle is not None:
        if relief.length is not None:
            length = relief.length
        else:
            start_rho = relief.start_roll_angle * fc.base_radius
            length = d * (end_rho - start_rho)
            if not (0 < length):
                raise ModelError([(f"{where}.start_roll_angle", (
                    f"{math.degrees(relief.start_roll_angle):.4g} deg lies beyond the "
                    f"{'tip' if tip else 'start of active profile'} (roll angle "
                    f"{math.degrees(end_rho / fc.base_radius):.4g} deg); give a roll angle inside "
                    f"the active profile ({math.degrees(min(fc.rho_sap, fc.rho_tip) / fc.base_radius):.4g}"
                    f"-{math.degrees(max(fc.rho_sap, fc.rho_tip) / fc.base_radius):.4g} deg)"))])
        if length > fc.active_length * (1 + 1e-9):
            key = "length" if relief.length is not None else "start_roll_angle"
            raise ModelError([(f"{where}.{key}", (
                f"the relief zone ({length * 1e3:.4g} mm of roll length) is longer than the "
                f"active profile ({fc.active_length * 1e3:.4g} mm); reduce it"))])
        start = d * end_rho - length

        def coord(rho, d=d):
            return d * np.asarray(rho, dtype=float)

        return coord, start, length, length
    # radial coordinates
    end_r = fc.r_tip if tip else fc.r_sap
    other_r = fc.r_sap if tip else fc.r_tip
    dr = 1.0 if end_r > other_r else -1.0
    if relief.height is not None:
        height = relief.height
        key = "height"
    else:
        height = dr * (end_r - 0.5 * relief.start_diameter)
        key = "start_diameter"
        if not (height > 0):
            raise ModelError([(f"{where}.start_diameter", (
                f"{relief.start_diameter * 1e3:.5g} mm lies beyond the "
                f"{'tip' if tip else 'start of active profile'} (diameter {2e3 * end_r:.5g} mm); "
                f"give a diameter between {2e3 * min(fc.r_sap, fc.r_tip):.5g} and "
                f"{2e3 * max(fc.r_sap, fc.r_tip):.5g} mm"))])
    if height > fc.active_height * (1 + 1e-9):
        if key == "start_diameter":  # (the range the diameter may take, as beyond the tip:
            # a start below the active profile got the height message, an LTCA reviewer)
            other = "start of active profile" if tip else "tip"
            raise ModelError([(f"{where}.start_diameter", (
                f"{relief.start_diameter * 1e3:.5g} mm lies beyond the {other} (diameter "
                f"{2e3 * other_r:.5g} mm): the relief zone would be longer than the active "
                f"profile; give a diameter between {2e3 * min(fc.r_sap, fc.r_tip):.5g} and "
                f"{2e3 * max(fc.r_sap, fc.r_tip):.5g} mm"))])
        raise ModelError([(f"{where}.{key}", (
            f"the relief zone ({height * 1e3:.4g} mm radial height) is longer than the active "
            f"profile ({fc.active_height * 1e3:.4g} mm high); reduce it"))])
    start = dr * end_r - height

    def coord_r(rho, dr=dr, rb=fc.base_radius):
        return dr * np.sqrt(rb * rb + np.asarray(rho, dtype=float) ** 2)

    # zone length in roll-length terms (for the overlap check)
    r0 = dr * start
    rho0 = math.sqrt(max(r0 * r0 - fc.base_radius ** 2, 0.0))
    return coord_r, start, height, abs(end_rho - rho0)


def profile_separation(mod: FlankModification, fc: FlankCoordinates, rho, where: str = "modifications"):
    """Material removed by the profile modification at roll lengths ``rho`` [m].

    Raises ModelError naming ``where.tip_relief.length`` etc. if a relief zone is longer
    than the active profile or tip and root relief overlap.
    """
    rho = np.asarray(rho, dtype=float)
    out = np.zeros_like(rho)
    roll_lengths = []
    for name, relief, tip in (("tip_relief", mod.tip_relief, True),
                              ("root_relief", mod.root_relief, False)):
        if relief is None:
            continue
        relief.check(f"{where}.{name}")
        coord, start, length, roll_len = _zone(relief, fc, tip, f"{where}.{name}")
        roll_lengths.append((name, relief, roll_len))
        t = np.clip((coord(rho) - start) / length, 0.0, 1.0)
        out = out + relief.amount * t ** relief.c   # Liu et al. 2021 eq. 20
    if len(roll_lengths) == 2 and roll_lengths[0][2] + roll_lengths[1][2] > fc.active_length * (1 + 1e-9):
        raise ModelError([(f"{where}.tip_relief", (
            f"tip relief ({roll_lengths[0][2] * 1e3:.4g} mm) and root relief "
            f"({roll_lengths[1][2] * 1e3:.4g} mm of roll length) overlap on the active profile "
            f"({fc.active_length * 1e3:.4g} mm); shorten one of them"))])
    return out


def lead_separation(mod: FlankModification, y, face_width: float, where: str = "modifications"):
    """Material removed by the lead modification at face positions ``y`` [m] of one helix."""
    y = np.asarray(y, dtype=float)
    b = float(face_width)
    out = np.zeros_like(y)
    if mod.crowning:
        if mod.crowning < 0:
            raise ModelError([(f"{where}.crowning", f"must not be negative, got "
                                                    f"{_num(mod.crowning, 'm')}; give zero or a "
                                                    "positive amount")])
        out = out + mod.crowning * (2.0 * y / b - 1.0) ** 2
    if mod.end_relief is not None:
        er = mod.end_relief
        er.check(f"{where}.end_relief", b)
        c = _exponent(er.shape, er.exponent, f"{where}.end_relief")
        t0 = np.clip((er.length - y) / er.length, 0.0, 1.0)
        t1 = np.clip((y - (b - er.length)) / er.length, 0.0, 1.0)
        out = out + er.amount * (t0 ** c + t1 ** c)   # Liu et al. 2021 eq. 20, lead direction
    if mod.helix_slope:
        out = out + mod.helix_slope * (y / b - 0.5)
    return out


def check_modification(mod: ToothModification, pair, gear: int, where: str) -> None:
    """Evaluate the modification on the active profile of ``pair`` once, so that a relief
    longer than the active profile (or an overlap) raises a ModelError at ``where``."""
    fc = flank_coordinates(pair, gear)
    rho = np.linspace(min(fc.rho_sap, fc.rho_tip), max(fc.rho_sap, fc.rho_tip), 5)
    for h, flank in enumerate((mod.flank, mod.second_helix)):
        if flank is None:
            continue
        loc = where if h == 0 else f"{where}.second_helix"
        profile_separation(flank, fc, rho, loc)
        lead_separation(flank, np.linspace(0, pair.face_width, 5), pair.face_width, loc)


# ------------------------------------------------------------------ from the model file
def _relief_from_spec(spec) -> Relief | None:
    if spec is None:
        return None
    return Relief(spec.amount, length=spec.length, start_diameter=spec.start_diameter,
                  start_roll_angle=spec.start_roll_angle, height=spec.height,
                  shape=spec.shape, exponent=spec.exponent)


def flank_from_spec(spec, face_width: float, where: str = "modifications") -> FlankModification:
    """A :class:`FlankModification` from a model-file flank section (duck-typed: any
    object with the fields of ``torquesplit.model.schema_modifications.FlankSpec``)."""
    end = None
    if spec.end_relief is not None:
        e = spec.end_relief
        end = EndRelief(e.amount, e.length, shape=e.shape, exponent=e.exponent)
    mod = FlankModification(tip_relief=_relief_from_spec(spec.tip_relief),
                            root_relief=_relief_from_spec(spec.root_relief),
                            crowning=float(spec.crowning), end_relief=end,
                            helix_slope=float(spec.helix_slope))
    topo = getattr(spec, "topological", None)
    if topo is not None:
        try:
            preset = liu2021_topological(topo.y1, topo.y2, topo.y3, topo.y4, topo.y5, topo.y6,
                                         face_width, topo.exponent)
        except ModelError as exc:
            raise ModelError([(f"{where}.{loc}", msg) for loc, msg in exc.issues]) from None
        mod = replace(mod, tip_relief=preset.tip_relief, root_relief=preset.root_relief,
                      end_relief=preset.end_relief)
    return mod


def modification_from_spec(spec, face_width: float,
                           where: str = "modifications") -> ToothModification | None:
    """A :class:`ToothModification` from a gear's ``modifications`` section (or None)."""
    if spec is None:
        return None
    second = getattr(spec, "second_helix", None)
    return ToothModification(
        flank=flank_from_spec(spec, face_width, where),
        second_helix=None if second is None else flank_from_spec(second, face_width,
                                                                 f"{where}.second_helix"))


def misalignment_from_spec(spec) -> Misalignment:
    """A :class:`Misalignment` from a mesh's ``misalignment`` section."""
    if spec is None:
        return Misalignment()
    return Misalignment(float(spec.lead_mismatch), float(spec.shaft_misalignment),
                        float(spec.base_pitch_deviation))
