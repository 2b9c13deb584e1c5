"""The model-file schema: what a gearbox description may contain.

A model file is TOML (or JSON) with the sections ``[model]``, ``[gears.NAME]``,
``[bodies.NAME]``, ``[shafts.NAME]``, ``[meshes.NAME]``, ``[splines.NAME]``,
``[drives.NAME]``, ``[loads.NAME]`` and ``[analysis]``.  Every physical quantity is
read through :func:`torquesplit.model.units.parse_quantity`: a string with units
(``"50 um"``) or a bare number in the field's SI unit.  After validation every value
is SI float64.  Unknown fields are errors (a typo must not be silently ignored).

``docs/model-file.md`` is generated from this module (``python -m
torquesplit.model.docs``) and a test checks that it is up to date.
"""

from __future__ import annotations

import math
import re
import typing
from typing import Annotated, Literal

from pydantic import (BaseModel, BeforeValidator, ConfigDict, Field, PrivateAttr,
                      ValidationError, field_validator, model_validator)
from pydantic import Strict as StrictType

from ..errors import FieldError, ModelError  # noqa: F401 - FieldError re-exported
from .units import KINDS, parse_module, parse_quantity


class Unit:
    """Annotation marker: the field is a physical quantity of this kind.

    On a table field (mesh ``stiffness``, ``backlash``) it marks the shorthand: a single
    quantity of this kind stands for the table.
    """

    def __init__(self, kind: str):
        self.kind = kind
        self.si = KINDS[kind][0]

    def __repr__(self) -> str:  # pragma: no cover - debugging aid
        return f"Unit({self.kind!r})"


def Q(kind: str):
    """A float field that accepts a quantity with units of ``kind`` (stored in SI)."""
    return Annotated[float, BeforeValidator(lambda v: parse_quantity(v, kind)), Unit(kind)]


def _not_a_bool(what: str, example: str):
    """A validator refusing true/false where a number is meant (pydantic reads true as 1)."""

    def check(v):
        if isinstance(v, bool):
            raise ValueError(f"must be {what}, got {str(v).lower()} (true/false is not a "
                             f"number); write {example}")
        return v

    return BeforeValidator(check)


_PERCENT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(?:%|percent)\s*$")


def _plain_number():
    """A validator for a dimensionless number: true/false refused, and a percentage
    ('10 %', '10 percent') read as its fraction (a damping ratio of "10 %" was refused)."""
    refuse_bool = _not_a_bool("a number", "a plain number such as 0.05").func

    def check(v):
        v = refuse_bool(v)
        if isinstance(v, str):
            m = _PERCENT.match(v)
            if m:
                return float(m.group(1)) / 100.0
        return v

    return BeforeValidator(check)


Number = Annotated[float, _plain_number()]
"""A plain (dimensionless) number, or a percentage ('5 %' is 0.05); true/false are
refused."""
Count = Annotated[int, _not_a_bool("a whole number", "an integer such as 20")]
"""A whole number; true/false are refused."""
Flag = Annotated[bool, StrictType()]
"""true or false only (not 0/1, not "yes")."""

Length = Q("length")
Module = Annotated[float, BeforeValidator(parse_module), Unit("length")]
"""A normal module, or a diametral pitch read as its module (:func:`~torquesplit.model.
units.parse_module`)."""
Angle = Q("angle")
Mass = Q("mass")
Inertia = Q("inertia")
Density = Q("density")
Stiffness = Q("stiffness")
TorsionalStiffness = Q("torsional_stiffness")
Damping = Q("damping")
TorsionalDamping = Q("torsional_damping")
Pressure = Q("pressure")
Speed = Q("speed")
Power = Q("power")
Torque = Q("torque")
Time = Q("time")
Viscosity = Q("viscosity")
Frequency = Q("frequency")

Dof = Literal["x", "y", "z", "loa", "theta"]
"""Body DOFs: translations along the global x, y, z; 'loa' a single translation along
the (transverse) line of action of the gear's meshes, as in lumped torsion-translation
models (Ji & Li eq. 9); 'theta' the rotation about the body's axis."""


def list_item(tp):
    """The item type of a list field, else None: ``list[X]`` or ``tuple[X, ...]`` (the
    model's lists are tuples, so that a validated model cannot be changed in place, see
    :meth:`Model.changed_in_place`)."""
    args = typing.get_args(tp)
    if typing.get_origin(tp) is list:
        return args[0]
    if typing.get_origin(tp) is tuple and len(args) == 2 and args[1] is Ellipsis:
        return args[0]
    return None


class Strict(BaseModel):
    """Base of every schema section: unknown fields are errors, numbers must be finite."""

    model_config = ConfigDict(extra="forbid", validate_default=True, frozen=True,
                              allow_inf_nan=False)

    def __setattr__(self, name: str, value) -> None:
        """A model is frozen: setting a field is refused in torquesplit's words (pydantic's
        'Instance is frozen' ValidationError was not a torquesplit error), pointing to
        ``with_changes``."""
        if name.startswith("_"):  # (private state: the source data kept for changes)
            return super().__setattr__(name, value)
        from ..errors import OptionTypeError

        raise OptionTypeError(f"a model is frozen: {type(self).__name__}.{name} cannot be "
                              f"set; make a changed copy with model.with_changes({{PATH: "
                              f"value}}), PATH the field's path as in the file (e.g. "
                              f"'meshes.m1.damping_ratio')")




def _angle_field(name: str, upper_deg: float):
    """A field validator of an angle within +/- ``upper_deg`` (a field's own check runs
    with the section's other field checks: a unit error elsewhere in a [[planetary]]
    stage hid it until the next attempt)."""

    def check(cls, v):
        return _check_angle(v, name, upper_deg)

    return field_validator(name)(classmethod(check))


def _check_angle(v: float, name: str, upper_deg: float) -> float:
    """``v`` [rad], or a ValueError saying what the value read as and what to write."""
    if not (-math.radians(upper_deg) <= v <= math.radians(upper_deg)):
        # a number a user types bare (20, 14.5) is round and would be a valid angle in
        # degrees; '60 deg' arrives as 1.0472 rad, for which that hint read as nonsense
        bare = abs(v) <= upper_deg and abs(100 * v - round(100 * v)) < 1e-6
        hint = (f"a bare number is read in radians: if you meant {v:g} degrees, write "
                f"'{v:g} deg'" if bare else
                f"check the value ({name.replace('_', ' ')}s lie within +/-{upper_deg:g} deg)")
        raise ValueError(f"{v:g} rad ({math.degrees(v):g} deg) is outside "
                         f"+/-{upper_deg:g} deg; {hint}")
    return v


# tooth modifications, misalignment and LTCA options live in their own module; imported
# here, after the base classes above, which it uses
from .schema_modifications import LtcaSpec, MisalignmentSpec, ModificationsSpec  # noqa: E402


# --------------------------------------------------------------------------- supports
class ShaftBending(Strict):
    """Lateral stiffness of a gear on a simply supported shaft (Ji & Li eqs. 5-7, 10)."""

    diameter: Length = Field(gt=0, description="Shaft diameter at the gear.")
    span: Length = Field(gt=0, description="Distance between the two bearings.")
    position: Length = Field(
        gt=0, description="Distance from the first bearing to the gear (0 < position < span)."
    )
    youngs_modulus: Pressure = Field(206e9, gt=0, description="Young's modulus of the shaft.")
    bearing_stiffness: Stiffness | None = Field(
        None, gt=0, description=(
            "Radial stiffness of the bearings as the gear sees them, one k_C in series with "
            "the shaft (Ji & Li eq. 10: k = k_S k_C / (k_S + k_C)).  Not the stiffness of "
            "each bearing: two bearings k_1, k_2 at a and b from the gear (l = a + b) give "
            "k_C = l^2 / (b^2 / k_1 + a^2 / k_2), twice k_1 = k_2 at mid-span."))

    @model_validator(mode="after")
    def _inside(self):
        if self.position >= self.span:
            raise FieldError("position", (
                f"{self.position:g} m must lie between the bearings (span {self.span:g} m); "
                f"correct 'position' or 'span'"))
        return self


class PinDeviation(Strict):
    """Position error of a bearing seat on the body that carries it (a planet pin on its
    carrier; Bodas & Kahraman 2004, Ligata et al. 2008)."""

    radial: Length = Field(0.0, description="Along the line from the seat body's axis to "
                           "the nominal pin centre, positive outwards.")
    tangential: Length = Field(0.0, description="Perpendicular to it in the seat body's "
                               "plane, positive in the seat body's positive sense of "
                               "rotation (counter-clockwise about its axis).")

    @property
    def is_zero(self) -> bool:
        return self.radial == 0.0 and self.tangential == 0.0


class TorsionalSupport(Strict):
    """Holds a member against rotation (a fixed ring gear, the fixed carrier of a star
    stage): its nominal speed is zero and the support takes the reaction torque, through
    a torsional spring to the housing (Lin & Parker 1999 k_ru) or rigidly."""

    stiffness: TorsionalStiffness | None = Field(
        None, gt=0, description="Torsional stiffness to the housing (e.g. '6e6 N m/rad')."
    )
    damping: TorsionalDamping | None = Field(None, ge=0, description="Torsional damping.")
    damping_ratio: Number | None = Field(
        None, ge=0, description="Damping as a fraction of critical, c = 2 zeta sqrt(k J).")
    rigid: Flag = Field(False, description="Hold the member rigidly (its rotation is "
                        "removed from the DOFs) instead of through a spring.")

    @model_validator(mode="after")
    def _one(self):
        if self.rigid and self.stiffness is not None:
            raise ValueError("both 'rigid' and 'stiffness' are given; remove one of them")
        if not self.rigid and self.stiffness is None:
            raise ValueError("the torsional support has no stiffness; give 'stiffness' "
                             "(e.g. '6e6 N m/rad') or rigid = true")
        if self.rigid and (self.damping is not None or self.damping_ratio is not None):
            raise ValueError("a rigid torsional support has no damping; remove 'damping' "
                             "and 'damping_ratio' or give a 'stiffness' instead of rigid")
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("both 'damping' and 'damping_ratio' are given; remove one of them")
        return self


#: the stiffness of a floating member's support when none is given [N/m]: negligible
#: beside any mesh (1e8-1e10 N/m), enough to keep a static solve regular
FLOATING_STIFFNESS = 1.0


class Support(Strict):
    """Support of a body's translations: a bearing or shaft bending, to the housing or
    (``on``) to another body (a planet on its carrier pin, a gear on a moving frame)."""

    stiffness: Stiffness | None = Field(
        None, gt=0, description="Radial stiffness (x and y) of the body's whole support: "
        "all its bearings together (two bearings of 1e9 N/m side by side: 2e9 N/m)."
    )
    stiffness_y: Stiffness | None = Field(
        None, gt=0, description="Stiffness in y when it differs from x (defaults to 'stiffness')."
    )
    axial_stiffness: Stiffness | None = Field(
        None, gt=0, description="Axial stiffness (z); defaults to the radial stiffness."
    )
    shaft: ShaftBending | None = Field(
        None, description="Compute the radial stiffness from the shaft instead (Ji & Li)."
    )
    damping: Damping | None = Field(None, ge=0, description="Viscous damping of the support.")
    damping_ratio: Number | None = Field(
        None, ge=0, description="Damping as a fraction of critical, c = 2 zeta sqrt(k m)."
    )
    clearance: Length = Field(
        0.0, ge=0, description="Clearance of the bearing (half the diametral play): no "
        "force until the body has moved this far; 0 = none. Its shape: 'clearance_shape'."
    )
    clearance_shape: Literal["radial", "per_axis"] = Field(
        "radial", description="'radial': a circular clearance of the two translations "
        "across the body's axis, in contact when their resultant exceeds it (a bearing's "
        "radial play; the same in every orientation of the axes; damped on the radial "
        "rate only, as a spline); 'per_axis': a dead zone "
        "on each translational DOF on its own (Dong et al. 2021 eq. 7: a square clearance, "
        "larger along the diagonals). A single translation (e.g. 'loa') or the axial one: "
        "the two are the same.")
    on: str | None = Field(
        None, description="Body the bearing sits on (its translations carry the bearing's "
        "other end: a planet pin on its carrier, a moving housing); default: the fixed "
        "housing."
    )
    pin_error: PinDeviation = Field(
        PinDeviation(), description="Position error of the seat (planet pin) on the body "
        "named by 'on' (radial: outwards from its axis; tangential: in its positive sense "
        "of rotation); requires 'on'.  A pin ahead in the direction the planet's loads push "
        "it unloads that planet: with the carrier as output, a positive tangential error "
        "on a carrier turning positively.")
    floating: bool = Field(
        False, description="The body floats by design, held by its meshes alone (a "
        "floating sun): the support only keeps the equilibrium regular and its softness "
        "is not warned; 'stiffness' may then be left out (1 N/m).")

    @model_validator(mode="before")
    @classmethod
    def _floating_stiffness(cls, data):
        # a floating member's support: negligible unless given (the recipe wrote
        # stiffness = '1 N/m' and accepted a warning on every command, a reviewer)
        if (isinstance(data, dict) and data.get("floating") is True
                and data.get("stiffness") is None and data.get("shaft") is None):
            data = {**data, "stiffness": FLOATING_STIFFNESS}
        return data

    @model_validator(mode="after")
    def _one_stiffness(self):
        if self.stiffness is None and self.shaft is None:
            raise ValueError("the support has no stiffness; give 'stiffness' (e.g. '1e8 N/m') "
                             "or a 'shaft' bending description")
        if self.stiffness is not None and self.shaft is not None:
            raise ValueError("both 'stiffness' and 'shaft' are given; remove one of them")
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("both 'damping' and 'damping_ratio' are given; remove one of them")
        if self.floating and self.shaft is not None:
            raise FieldError("floating", "a floating member is held by its meshes, not by "
                             "a shaft's bending; remove 'shaft' (or 'floating')")
        if self.on is None and not self.pin_error.is_zero:
            raise FieldError("pin_error", (
                "a pin position error is the error of the seat on the body named by 'on' "
                "(a planet pin on its carrier); add on = \"carrier\" (your carrier's name), "
                "or give an offset of a housing bore as the gear's errors.installation"))
        return self


# --------------------------------------------------------------------------- errors
class GearErrors(Strict):
    """Manufacturing and assembly errors of one gear (Liu et al. 2021 eqs. 1-2, Dong et al. 2021 eq. 11)."""

    eccentricity: Length = Field(0.0, ge=0, description="Eccentricity amplitude (rotates with the gear).")
    eccentricity_phase: Angle = Field(0.0, description=(
        "Angular position of the eccentricity at t = 0, from the x axis of the gear's "
        "frame; it turns with the gear."))
    installation: Length = Field(0.0, ge=0, description="Installation (mounting) error amplitude.")
    installation_phase: Angle = Field(0.0, description=(
        "Direction of the installation error: a fixed offset of the gear's centre, at this "
        "angle from the x axis of its frame (it does not turn with the gear)."))
    tooth_thickness: Length = Field(0.0, description="Tooth thickness error (Mo et al. 2017 §4).")
    pitch: Length = Field(0.0, ge=0, description=(
        "Total cumulative pitch deviation F_p (peak-to-peak over a revolution, on the "
        "reference circle), modelled by its once-per-revolution harmonic of amplitude "
        "F_p/2 (Mo et al. 2017 §4.1); checked against the tolerance F_pT of ISO 1328-1."))
    bearing_runout: Length = Field(0.0, ge=0, description="Bearing run-out amplitude (Mo et al. 2017 §4).")
    bearing_runout_phase: Angle = Field(0.0, description="Phase of the bearing run-out.")
    grade: Count | None = Field(
        None, ge=1, le=11, description="ISO 1328-1:2013 accuracy grade (1 to 11), used for "
        "tolerance sampling and the checks of the errors against it."
    )


# --------------------------------------------------------------------------- bodies
class Placement(Strict):
    """Place a gear at the operating centre distance from a mating gear."""

    from_gear: str = Field(description="Name of the gear this one meshes with.")
    angle: Angle = Field(
        description="Direction of the centre line, measured in the mating gear's plane "
        "from its x axis (counter-clockwise about the mating gear's axis)."
    )


def _check_rim(outer_diameter, rim_thickness, internal: bool, what: str,
               root_diameter=None) -> None:
    """The rim of an internal gear: outer_diameter or rim_thickness, not both, only on an
    internal gear (an external gear's mass is a disc less its bore_diameter), and outside
    the root circle (``root_diameter`` a callable, called only when needed)."""
    for field, value in (("outer_diameter", outer_diameter), ("rim_thickness", rim_thickness)):
        if value is not None and not internal:
            raise FieldError(field, (
                f"{field} gives the rim of an internal gear ({what}); an external gear's "
                f"computed mass is a disc less its bore_diameter: remove {field}"))
    if outer_diameter is not None and rim_thickness is not None:
        raise FieldError("rim_thickness", "outer_diameter and rim_thickness both give the "
                         "rim; remove one of them")
    if outer_diameter is not None and root_diameter is not None:
        try:
            d_f = root_diameter()
        except (ValueError, ArithmeticError):  # the geometry's own check names it
            return
        if outer_diameter <= d_f:
            raise FieldError("outer_diameter", (
                f"{outer_diameter * 1e3:.6g} mm is not outside the root circle of the internal "
                f"gear (d_f = {d_f * 1e3:.6g} mm): the rim lies from the root circle outwards; "
                f"give a larger outer diameter, or rim_thickness"))


class Gear(Strict):
    """A gear: one rigid body with involute teeth."""

    teeth: Count = Field(gt=0, le=10_000, description="Number of teeth.")
    module: Module = Field(gt=0, description=(
        "Normal module, or the normal diametral pitch as teeth per length ('4 1/in': a "
        "module of 6.35 mm)."))
    pressure_angle: Angle = Field(math.radians(20.0), description="Normal pressure angle.")
    helix_angle: Angle = Field(0.0, description="Helix angle (spiral angle for bevel gears).")
    hand: Literal["right", "left"] | None = Field(
        None, description="Hand of the helix or spiral; required when the helix angle is not 0."
    )
    kind: Literal["spur", "helical", "double_helical", "bevel", "face", "internal"] | None = Field(
        None, description="Gear type; default spur, or helical when a helix angle is given."
    )
    face_width: Length = Field(gt=0, description="Face width (of one helix for double-helical).")
    profile_shift: Number = Field(0.0, ge=-5, le=5, description="Profile shift coefficient x.")
    cone_angle: Angle | None = Field(
        None, description="Pitch cone angle of a bevel gear (default from the shaft angle)."
    )
    mass: Mass | None = Field(None, gt=0, description="Mass; from geometry and density if omitted.")
    polar_inertia: Inertia | None = Field(
        None, gt=0, description="Polar moment of inertia; from geometry and density if omitted."
    )
    bore_diameter: Length = Field(0.0, ge=0, description="Bore diameter used for computed mass/inertia.")
    outer_diameter: Length | None = Field(None, gt=0, description=(
        "Outer diameter of an internal gear's rim, used for computed mass/inertia (the rim "
        "from the root circle outwards) and, given, for the overlap check; default the "
        "root diameter + 2 rim_thickness."))
    rim_thickness: Length | None = Field(None, gt=0, description=(
        "Rim thickness of an internal gear from its root circle outwards, used for computed "
        "mass/inertia and, given, for the overlap check (a gear in the assumed rim is "
        "warned of); default 3.5 m_n (the rim above which ISO 6336-3:2006's rim "
        "thickness factor Y_B of an internal gear is 1)."))
    density: Density = Field(7850.0, gt=0, description="Material density.")
    youngs_modulus: Pressure = Field(206e9, gt=0, description="Young's modulus of the gear material.")
    poisson_ratio: Number = Field(0.3, gt=0, lt=0.5, description="Poisson's ratio.")
    position: tuple[Length, Length, Length] | None = Field(
        None, description="Centre coordinates [x, y, z]."
    )
    place: Placement | None = Field(None, description="Position from a mating gear and an angle.")
    axis: tuple[Number, Number, Number] = Field(
        (0.0, 0.0, 1.0), description="Rotation axis direction.")
    dofs: tuple[Dof, ...] = Field(("theta",), description=(
        "Degrees of freedom: 'theta' rotation; 'x', 'y', 'z' translations along the global "
        "axes; or 'loa', one translation along the line of action of the gear's meshes "
        "(Ji & Li eq. 9; its meshes must push it along parallel lines)."))
    support: Support | None = Field(None, description="Support of the translational DOFs.")
    torsional_support: TorsionalSupport | None = Field(
        None, description="Holds the gear against rotation (a fixed ring or sun gear): "
        "its nominal speed is zero.")
    errors: GearErrors = Field(GearErrors(), description="Eccentricity, installation, ... errors.")
    modifications: ModificationsSpec | None = Field(
        None, description="Tooth modification of the loaded flank (used by stiffness method "
        "'ltca').")

    _pressure_angle_range = _angle_field("pressure_angle", 45)
    _helix_angle_range = _angle_field("helix_angle", 60)

    @model_validator(mode="after")
    def _consistent(self):
        if self.modifications is not None:  # (on a bevel or face gear: checks.py, with
            # the model's other problems)
            if self.modifications.second_helix is not None and self.gear_type != "double_helical":
                raise FieldError("modifications.second_helix", (
                    "a second helix exists on double-helical gears only; remove second_helix "
                    "or set kind = 'double_helical'"))
        if self.helix_angle != 0 and self.hand is None:
            raise FieldError("hand", "a gear with a helix angle needs a hand; add "
                             "hand = 'right' or hand = 'left'")
        if self.position is not None and self.place is not None:
            raise ValueError("both 'position' and 'place' are given; remove one of them")
        _check_rim(self.outer_diameter, self.rim_thickness, self.gear_type == "internal",
                   "kind = 'internal'", self._root_diameter)
        _check_axis(self.axis)
        _unique_dofs(self.dofs)
        return self

    def _root_diameter(self) -> float:
        from ..gears import line_of_action as loa

        return 2 * loa.gear_geometry(self).root_radius

    @property
    def gear_type(self) -> str:
        if self.kind is not None:
            return self.kind
        return "helical" if self.helix_angle != 0 else "spur"


class Body(Strict):
    """A rigid body that is not a gear: prime mover, load inertia, carrier."""

    polar_inertia: Inertia = Field(gt=0, description="Polar moment of inertia.")
    mass: Mass | None = Field(None, gt=0, description="Mass (needed with translational DOFs).")
    position: tuple[Length, Length, Length] = Field((0.0, 0.0, 0.0), description="Centre.")
    axis: tuple[Number, Number, Number] = Field((0.0, 0.0, 1.0), description="Rotation axis.")
    dofs: tuple[Dof, ...] = Field(("theta",), description=(
        "Degrees of freedom: 'theta' rotation; 'x', 'y', 'z' translations along the global "
        "axes; or 'loa', one translation along the line of action of the gear's meshes "
        "(Ji & Li eq. 9; its meshes must push it along parallel lines)."))
    support: Support | None = Field(None, description="Support of the translational DOFs.")
    torsional_support: TorsionalSupport | None = Field(
        None, description="Holds the body against rotation (the fixed carrier of a star "
        "stage): its nominal speed is zero.")
    eccentricity: Length = Field(
        0.0, ge=0, description="Offset of the body's centre (its planet pins) from its "
        "bearing axis, turning with the body (carrier eccentricity).")
    eccentricity_phase: Angle = Field(0.0, description="Direction of the eccentricity at "
                                      "t = 0, from the x axis about the body's axis.")

    @model_validator(mode="after")
    def _consistent(self):
        _check_axis(self.axis)
        _unique_dofs(self.dofs)
        _needs_mass(self.dofs, self.mass)
        return self


def _needs_mass(dofs, mass) -> None:
    """A body with translational DOFs has a mass."""
    if any(d != "theta" for d in dofs) and mass is None:
        raise FieldError("mass", "a body with translational DOFs needs a mass; add "
                         "mass = '12.5 kg' (your value), or remove x, y, z, loa from 'dofs'")


def _unique_dofs(dofs):
    if len(set(dofs)) != len(dofs):
        raise FieldError("dofs", f"{dofs} lists a DOF twice; list each DOF once")
    if "loa" in dofs and ("x" in dofs or "y" in dofs):
        raise FieldError("dofs", f"{dofs} combines 'loa' with 'x'/'y': 'loa' is the one "
                         f"translation along the line of action, x and y are both in-plane "
                         f"translations; keep either 'loa' or 'x' and 'y'")
    if "theta" not in dofs:
        raise FieldError("dofs", f"{dofs} has no 'theta': every body turns about its axis; "
                         f"add 'theta' to 'dofs'")


def _check_axis(axis):
    if not math.hypot(*axis) > 0:
        raise FieldError("axis", "the zero vector has no direction; give a direction such as "
                         "[0, 0, 1]")


# --------------------------------------------------------------------------- connections
class Shaft(Strict):
    """A torsional connection between two bodies on a common axis.  The shaft is massless:
    put its polar inertia into the bodies it joins (half into each is the usual lumping)."""

    connects: tuple[str, str] = Field(description="The two bodies the shaft joins.")
    rigid: Flag = Field(False, description="Join the bodies rigidly (one rotational DOF).")
    torsional_stiffness: TorsionalStiffness | None = Field(
        None, gt=0, description="Torsional stiffness; or give diameter and length."
    )
    diameter: Length | None = Field(None, gt=0, description="Outer diameter (Ji & Li eq. 3).")
    inner_diameter: Length = Field(0.0, ge=0, description="Bore of a hollow shaft.")
    length: Length | None = Field(None, gt=0, description="Length between the two bodies.")
    shear_modulus: Pressure = Field(79.3e9, gt=0, description="Shear modulus of the shaft.")
    damping: TorsionalDamping | None = Field(None, ge=0, description=(
        "Torsional damping (neither this nor damping_ratio: the shaft is undamped)."))
    damping_ratio: Number | None = Field(
        None, ge=0, description=(
            "Torsional damping as a fraction of critical of this shaft between its two end "
            "inertias alone, c = 2 zeta sqrt(k J_a J_b / (J_a + J_b)); a mode of the whole "
            "train gets less of it (the 'modes' table gives each mode's damping ratio)."))

    @model_validator(mode="after")
    def _stiffness(self):
        if self.rigid:
            return self
        if self.torsional_stiffness is None and (self.diameter is None or self.length is None):
            raise ValueError(
                "the shaft has no stiffness; give 'torsional_stiffness' (e.g. '2.5e6 N m/rad'), "
                "or 'diameter' and 'length', or rigid = true"
            )
        if self.torsional_stiffness is not None and (self.diameter is not None
                                                     or self.length is not None):
            given = [f for f in ("diameter", "length") if getattr(self, f) is not None]
            raise FieldError("torsional_stiffness", (
                f"both 'torsional_stiffness' and {' and '.join(repr(f) for f in given)} are "
                f"given: the stiffness would be used and the dimensions ignored (a change of "
                f"diameter would change nothing); remove one of them"))
        if self.diameter is not None and self.inner_diameter >= self.diameter:
            raise FieldError("inner_diameter", "must be smaller than 'diameter'; correct one "
                             "of them")
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("both 'damping' and 'damping_ratio' are given; remove one of them")
        return self


class StiffnessSpec(Strict):
    """Mesh stiffness: method and its parameters (see docs/theory)."""

    method: Literal["constant", "iso6336", "potential_energy", "table", "fourier", "ltca"] = Field(
        "constant", description="How k(phase) is obtained ('ltca': loaded tooth contact analysis "
        "with the gears' modifications at the operating load)."
    )
    value: Stiffness | None = Field(None, gt=0, description="Mean mesh stiffness (constant).")
    peak_to_peak: Number = Field(
        0.0, ge=0, description="Constant method: relative peak-to-peak variation of a rectangular "
        "single/double contact wave built from the contact ratio (0 = constant)."
    )
    phase: tuple[Number, ...] | None = Field(None, description="Table: mesh phases in [0, 1).")
    values: tuple[Stiffness, ...] | None = Field(None, description="Table: stiffness at "
                                                 "each phase.")
    mean: Stiffness | None = Field(None, gt=0, description="Fourier: mean stiffness.")
    cos: tuple[Stiffness, ...] = Field((), description="Fourier: cosine coefficients a_1..a_n.")
    sin: tuple[Stiffness, ...] = Field((), description="Fourier: sine coefficients b_1..b_n.")
    fillet_foundation: Flag = Field(True, description="Potential energy and LTCA: include the "
                                    "fillet term.")
    slices: Count = Field(40, ge=1, description="Helical (and LTCA): number of slices across the "
                          "face.")
    ltca: LtcaSpec = Field(LtcaSpec(), description="Options of method 'ltca'.")

    @model_validator(mode="after")
    def _complete(self):
        m = self.method
        if m == "constant" and self.value is None:
            raise FieldError("value", "method 'constant' needs the mean stiffness; add "
                             "value = '4e8 N/m' (your value)")
        if m == "table":
            if not self.phase or not self.values or len(self.phase) != len(self.values):
                raise ValueError("method 'table' needs 'phase' and 'values' lists of equal "
                                 "length; give one stiffness per phase")
            if any(not 0 <= p < 1 for p in self.phase):
                raise FieldError("phase", f"{self.phase} has values outside [0, 1); give "
                                 "phases as fractions of one mesh cycle")
            if any(v <= 0 for v in self.values):
                raise FieldError("values", "table stiffness values must be positive; correct "
                                 "them")
        if m == "fourier" and self.mean is None:
            raise FieldError("mean", "method 'fourier' needs the mean stiffness; add "
                             "mean = '4e8 N/m' (your value)")
        # a field of another method is refused, not dropped (a reviewer's
        # {method = "iso6336", value = "1 N/m"} ran at the ISO stiffness without a word)
        # (a value other than the default: a table written back whole, as a [[planetary]]
        # stage's meshes are, repeats the defaults of every method)
        for name, methods in STIFFNESS_FIELD_METHODS.items():
            if m not in methods and getattr(self, name) != type(self).model_fields[name].default:
                raise FieldError(name, (
                    f"applies to method {' or '.join(repr(x) for x in methods)} only, the "
                    f"method is {m!r}; remove it (on the command line, --set "
                    f"meshes.NAME.stiffness.method={m} drops the old method's fields)"))
        return self


#: StiffnessSpec field -> the methods that use it (the others refuse it)
STIFFNESS_FIELD_METHODS = {
    "value": ("constant",), "peak_to_peak": ("constant",), "phase": ("table",),
    "values": ("table",), "mean": ("fourier",), "cos": ("fourier",), "sin": ("fourier",),
    "fillet_foundation": ("potential_energy", "ltca"), "slices": ("potential_energy", "ltca"),
    "ltca": ("ltca",),
}


class BacklashSpec(Strict):
    """Backlash: constant, or random per engagement (Ji & Li eq. 14)."""

    nominal: Length = Field(ge=0, description=(
        "Total normal backlash j_bn = 2b, along the line of action (the mesh deflection "
        "has a dead zone of +/- b: Ji & Li eq. 13, Dong et al. 2021 eq. 7)."))
    tolerance: Length = Field(0.0, ge=0, description="Half-width of the tolerance band.")
    distribution: Literal["constant", "normal", "uniform"] = Field(
        "constant", description="How each engagement's backlash is drawn."
    )
    seed: Count = Field(0, description="Random seed for reproducible sequences.")


class TransmissionErrorSpec(Strict):
    """An additional error along the line of action: constant plus mesh-frequency harmonic."""

    constant: Length = Field(0.0, description=(
        "Constant error along the LOA (installation). Positive opens a gap at the mesh, "
        "which unloads it: '20 um' lowers this mesh's load share, '-20 um' raises it."))
    amplitude: Length = Field(0.0, ge=0, description="Amplitude at mesh frequency.")
    phase: Angle = Field(0.0, description="Phase of the mesh-frequency error.")


class FrictionSpec(Strict):
    """Sliding friction between the teeth (Jin et al. 2019 eqs. 6, 14-18)."""

    model: Literal["xu2007", "constant"] = Field(
        "xu2007", description="Friction coefficient: EHL regression of Xu et al. (2007, Jin et al. 2019 "
        "eq. 6) or a constant.")
    coefficient: Number = Field(0.05, ge=0, le=1, description="Constant friction coefficient.")
    roughness: Length = Field(0.3e-6, gt=0, description="Composite RMS surface roughness S.")
    viscosity: Viscosity = Field(8e-3, gt=0, description="Dynamic viscosity of the oil at the "
                                 "inlet temperature.")
    slices: Count = Field(20, ge=1, le=200, description="Slices across the face (helical pairs).")


def _friction_shorthand(v):
    if v is None or v is False:
        return None
    if v is True:
        return {}
    return v


def _stiffness_shorthand(v):
    if isinstance(v, (dict, StiffnessSpec)):
        return v
    return {"method": "constant", "value": v}


def _backlash_shorthand(v):
    if isinstance(v, (dict, BacklashSpec)):
        return v
    return {"nominal": v}


def _balanced_or_torque(v):
    if v is None or v == "balanced":
        return None
    if isinstance(v, str) and v.strip().lower().rstrip(".") in ("balance", "balanced",
                                                                 "balancing", "auto"):
        raise ValueError(f"{v!r} is not a torque; did you mean \"balanced\" (the load takes "
                         f"all the input power)? write torque = \"balanced\" or a torque "
                         f"such as \"500 N m\"")
    x = parse_quantity(v, "torque")
    if x <= 0:
        raise ValueError("the load torque must be positive (its direction follows the speed); "
                         "give its magnitude, or \"balanced\"")
    return x


class Mesh(Strict):
    """A gear mesh between two gears."""

    gears: tuple[str, str] = Field(description="The two gears in mesh.")
    driver: str | None = Field(None, description="Which gear drives; from the power flow if omitted.")
    stiffness: Annotated[
        StiffnessSpec, BeforeValidator(_stiffness_shorthand), Unit("stiffness")
    ] = Field(
        description="Mean mesh stiffness (\"4.5e9 N/m\"), or a [stiffness] table with a method."
    )
    damping: Damping | None = Field(None, ge=0, description="Mesh damping.")
    damping_ratio: Number | None = Field(
        None, ge=0, description="Mesh damping as a fraction of critical, with the equivalent mass "
        "m = J1 J2 / (J1 r2^2 + J2 r1^2)."
    )
    backlash: Annotated[
        BacklashSpec, BeforeValidator(_backlash_shorthand), Unit("length")
    ] = Field(
        0.0, description=(
            "Total backlash (\"100 um\"; 0 = none), or a [backlash] table.  The play is "
            "centred: half of it on each flank at the nominal position, so the drive flank "
            "takes load after half the backlash.  In a locked train (a split) a backlash "
            "that differs between paths therefore shifts the static load split as a timing "
            "error of half the difference would; for gears clocked at assembly (drive flanks "
            "touching) add minus half the backlash to transmission_error.constant.")
    )
    transmission_error: TransmissionErrorSpec = Field(TransmissionErrorSpec(), description="Extra LOA error.")
    phase: Number | None = Field(None, description="Mesh phase at t = 0 in cycles (overrides clocking).")
    stage: str | None = Field(None, description=(
        "Stage label: the meshes of one stage (within one path) form a load-sharing group. "
        "Without it, the tooth-count pair 'za/zb' of the mesh's gears, and where meshes "
        "of one pair carry different nominal forces (a split and a combining stage of "
        "equal ratio) 'za/zb-1', 'za/zb-2'... (the check warns)."))
    path: str | None = Field(
        None, description="Input-path label: the power source a mesh belongs to (Liu et al. 2021: "
        "left/right engine).  Meshes of one stage share load within a path; do not use it to "
        "name the parallel branches of a split.")
    shaft_angle: Angle | None = Field(None, description="Angle between the axes (bevel/face).")
    impact: Flag = Field(False, description="Add meshing-in impact (Liu et al. 2021 eqs. 6-10).")
    misalignment: MisalignmentSpec = Field(MisalignmentSpec(), description="Misalignment and "
                                           "base pitch deviation (stiffness method 'ltca').")
    friction: Annotated[FrictionSpec | None, BeforeValidator(_friction_shorthand)] = Field(
        None, description="Tooth friction (Jin et al. 2019): true for the defaults, or a [friction] "
        "table; omitted or false = none.")

    @model_validator(mode="after")
    def _consistent(self):
        if self.gears[0] == self.gears[1]:
            raise FieldError("gears", f"{self.gears[0]!r} cannot mesh with itself; name two "
                             "different gears")
        if self.driver is not None and self.driver not in self.gears:
            raise FieldError("driver", f"{self.driver!r} is not one of the mesh's gears "
                             f"{list(self.gears)}; name one of them or remove 'driver'")
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("both 'damping' and 'damping_ratio' are given; remove one of them")
        return self


class Spline(Strict):
    """A member floating on a spline: radial clearance and friction (Dong et al. 2021 eq. 6)."""

    connects: tuple[str, str] = Field(description="The hub body and the floating body.")
    radial_clearance: Length = Field(ge=0, description="Radial clearance of the spline.")
    friction_coefficient: Number = Field(0.1, ge=0, description="Coulomb friction coefficient.")
    pitch_radius: Length = Field(gt=0, description="Spline pitch radius.")
    stiffness: Stiffness = Field(gt=0, description="Radial stiffness k_w once the clearance "
                                 "closes (and below the stick limit).")
    damping: Damping = Field(0.0, ge=0, description="Radial damping c_w while in contact.")
    stick_limit: Length = Field(0.0, ge=0, description="Radial displacement S_1 below which "
                                "the spline sticks (Dong et al. 2021 eq. 6; 0 = slides at once).")
    torsional_stiffness: TorsionalStiffness = Field(gt=0, description="Torsional stiffness of the spline.")
    backlash: Length = Field(0.0, ge=0, description=(
        "Circumferential backlash of the spline's teeth at the pitch radius (total play, "
        "as a gear coupling's): the torsion spring carries no torque inside +-backlash / "
        "(2 pitch_radius) of relative rotation; 0 = none."))

    @model_validator(mode="after")
    def _limits(self):
        if self.stick_limit > self.radial_clearance:
            raise FieldError("stick_limit", "must not exceed 'radial_clearance' (S_1 <= S_2); "
                             "lower it or raise the clearance")
        return self


# --------------------------------------------------------------------------- drives
class TorqueHarmonic(Strict):
    """One harmonic of a fluctuating drive or load torque, T_a sin(2 pi f t + phase) on top
    of the nominal torque (a mill's charge, a compressor's strokes, an engine's firing):
    f an ``order`` of the body's own rotation frequency or a fixed ``frequency``."""

    amplitude: Torque = Field(gt=0, description="Torque amplitude T_a.")
    order: Number | None = Field(None, gt=0, description=(
        "Frequency as a multiple of the body's rotation frequency (e.g. 2 for twice per "
        "revolution); follows the speed in a speed sweep."))
    frequency: Frequency | None = Field(None, gt=0, description=(
        "A fixed frequency instead of an order (e.g. '50 Hz'): for runs and the steady "
        "state at the model's speed (a steady state at another speed or a speed sweep "
        "refuses it: the period would not scale with the speed)."))
    phase: Angle = Field(0.0, description="Phase at t = 0.")

    @model_validator(mode="after")
    def _one(self):
        if (self.order is None) == (self.frequency is None):
            raise ValueError("give exactly one of 'order' and 'frequency', e.g. order = 2 "
                             "(twice per revolution of the body) or frequency = '50 Hz'")
        return self


class Drive(Strict):
    """A power input: torque, power or prescribed speed at a body."""

    body: str = Field(description="The driven body.")
    speed: Speed = Field(description="Nominal speed, signed about the body's axis.")
    power: Power | None = Field(None, gt=0, description=(
        "Input power (gives the torque). A 'speed' drive may leave power and torque out: "
        "it then puts in what the loads' given torques take."))
    torque: Torque | None = Field(None, gt=0, description="Input torque magnitude.")
    mode: Literal["torque", "speed"] = Field(
        "torque", description="'torque': constant torque; 'speed': prescribed speed (DOF removed)."
    )
    fluctuation: tuple[TorqueHarmonic, ...] = Field((), description=(
        "Harmonics of the drive torque about its nominal value (a 'torque' drive only), "
        "e.g. [{amplitude = '500 N m', frequency = '100 Hz'}] (see [drives.NAME.fluctuation])."))
    speed_coefficient: TorsionalDamping = Field(0.0, ge=0, description=(
        "Slope of the drive's torque-speed characteristic, -dT/d(speed) at the nominal "
        "point (an induction motor's slip: its torque falls as it runs faster); a "
        "'torque' drive only."))

    @model_validator(mode="after")
    def _one(self):
        if self.power is not None and self.torque is not None:
            raise ValueError("both 'power' and 'torque' are given; remove one of them")
        if self.power is None and self.torque is None and self.mode != "speed":
            raise ValueError("the drive has neither 'power' nor 'torque'; add one of them, e.g. "
                             "torque = '100 N m' (or make it mode = 'speed' to put in what the "
                             "loads' torques take)")
        if abs(self.speed) < 1e-6:
            raise FieldError("speed", "must not be zero (below 1e-6 rad/s); give the nominal "
                             "speed, e.g. '3000 rpm'")
        if self.speed_coefficient and self.mode == "speed":
            raise FieldError("speed_coefficient", "a 'speed' drive holds its speed (an "
                             "infinitely stiff characteristic); give the slope to a 'torque' "
                             "drive, or remove it")
        if self.fluctuation and self.mode == "speed":
            raise FieldError("fluctuation", "a 'speed' drive holds its speed, so its torque "
                             "is what the gearbox takes; put the fluctuation on a load (or "
                             "make the drive mode = 'torque')")
        return self

    @property
    def input_torque(self) -> float | None:
        """Torque magnitude [N m]; None for a 'speed' drive given neither power nor torque
        (:func:`torquesplit.model.kinematics.drive_input_torques` finds it)."""
        if self.torque is not None:
            return self.torque
        return self.power / abs(self.speed) if self.power is not None else None


class Load(Strict):
    """A power output: a resisting torque at a body."""

    body: str = Field(description="The loaded body.")
    torque: Annotated[float | None, BeforeValidator(_balanced_or_torque), Unit("torque")] = Field(
        "balanced", description="Resisting torque magnitude, or 'balanced' to take all input power."
    )
    speed_coefficient: TorsionalDamping = Field(
        0.0, ge=0, description="dT/d(speed) of the load characteristic (removes rigid-body drift)."
    )
    fluctuation: tuple[TorqueHarmonic, ...] = Field((), description=(
        "Harmonics of the load torque about its nominal value, e.g. [{amplitude = "
        "'20 kN m', order = 2}] (see [drives.NAME.fluctuation])."))


class Analysis(Strict):
    """Default settings of the analyses (the CLI can override them)."""

    method: Literal["rk4", "dopri"] = Field("rk4", description="Time integrator.")
    steps_per_period: Count = Field(100, ge=10, description=(
        "RK4 steps per shortest excitation period: the shortest mesh period, or an error "
        "sinusoid's where one is faster (an LTCA transmission-error harmonic; the run says "
        "so)."))
    duration: Time | None = Field(None, gt=0, description=(
        "Simulated time. Without it a run lasts `cycles` cycles of the slowest mesh (200 "
        "if `cycles` is not given either)."))
    cycles: Count | None = Field(None, gt=0, description=(
        "Simulated cycles of the slowest mesh, used when `duration` is not given "
        "(default 200)."))
    rtol: Number = Field(1e-6, gt=0, lt=1, description="Relative tolerance (dopri).")
    table_points: Count | None = Field(None, ge=16, description=(
        "Samples per mesh period of excitation tables. Where a table steps (a tooth pair "
        "entering, an impact pulse) each step becomes a ramp 1/n of a period long and the "
        "peaks come out low (a run warns below 4096 then). Default: 16384 where a mesh's "
        "stiffness table steps or a mesh has an impact or an LTCA stiffness, else 256."))
    spline_velocity_scale: Number = Field(
        1e-3, gt=0, description="Radial sliding speed [m/s] over which spline friction "
        "reaches its Coulomb value (regularisation of sgn; smaller is stiffer to integrate).")
    load_sharing: Literal["mean_force", "cycle_peak", "engineering", "instantaneous",
                          "static_torque"] = Field(
        "mean_force", description="Load-sharing definition 'run' reports: 'mean_force' "
        "(ratio of mean forces, the mesh load factor K_gamma of ISO 6336-1 and AGMA 6123; "
        "the default), 'cycle_peak' (Liu et al. 2021), 'engineering' or 'instantaneous' "
        "(Ji & Li), 'static_torque' (quasi-static, Mo et al. 2017: 'torquesplit static'; "
        "'run' then reports 'mean_force')."
    )


class AcceptedWarning(Strict):
    """A plausibility warning the model's author has checked and accepts, with why."""

    field: str = Field(min_length=1, description=(
        "The warned field, as the warning names it; '*' matches any part "
        "(e.g. 'meshes.*.stiffness')."))
    reason: str = Field(min_length=1, description=(
        "Why the value is right although it looks wrong (e.g. 'the paper's values, "
        "Table 2'); required."))


class ModelInfo(Strict):
    """Name and source of the model."""

    name: str = Field(max_length=200, description=(
        "Short name of the model (at most 200 characters)."))
    description: str = Field("", description="One-line description.")
    reference: str = Field("", description="Source of the data (paper, drawing).")
    accepted_warnings: tuple[AcceptedWarning, ...] = Field((), description=(
        "Plausibility warnings of the model checks that are known and accepted, each with "
        "its reason: not repeated on every load ('check' still lists them as accepted)."))


# the [[planetary]] shorthand builds on the sections above
from .planetary import Planetary  # noqa: E402


class _ModelMeta(type(Strict)):
    """``Model(...)`` built in Python: a bad field is a ModelError naming it, as a file's
    is, not pydantic's own text and link.  (On the metaclass: pydantic calls a model's
    own ``__init__`` from inside its validation, where a ModelError would be wrapped.)"""

    def __call__(cls, *args, **data):
        try:
            return super().__call__(*args, **data)
        except ValidationError as exc:
            raise _model_error(exc, data) from None


def _model_error(exc: ValidationError, data) -> ModelError:
    """pydantic's errors of a Model as the ModelError a file's would give."""
    from .io import _format_errors

    return ModelError(_format_errors(exc, data if isinstance(data, dict) else None))


class Model(Strict, metaclass=_ModelMeta):
    """A complete gearbox description (all values SI after validation)."""

    model: ModelInfo = Field(description="Name, description and source of the model.")
    gears: dict[str, Gear] = Field({}, description="Gears by name (required unless a "
                                   "[[planetary]] stage gives them).")
    bodies: dict[str, Body] = Field({}, description="Other rigid bodies by name.")
    shafts: dict[str, Shaft] = Field({}, description="Shafts by name.")
    meshes: dict[str, Mesh] = Field({}, description="Gear meshes by name (required unless a "
                                    "[[planetary]] stage gives them).")
    splines: dict[str, Spline] = Field({}, description="Splines by name.")
    drives: dict[str, Drive] = Field(description="Power inputs by name.")
    loads: dict[str, Load] = Field(description="Power outputs by name.")
    analysis: Analysis = Field(Analysis(), description="Analysis defaults.")
    planetary: tuple[Planetary, ...] = Field(
        (), description="Planetary stages in one table each ([[planetary]]); expanded to "
        "the general sections (gears, bodies, meshes) on reading.")

    _origins: dict[str, str] = PrivateAttr(default_factory=dict)
    """Generated location -> the ``[[planetary]]`` field it came from (see written_at)."""
    _identity: tuple = PrivateAttr(default=())
    """The sections' entries as validated (see :meth:`changed_in_place`)."""
    _source: dict | None = PrivateAttr(default=None)
    """The data the model was validated from (set by :func:`~torquesplit.model.io.
    model_from_dict`), for :meth:`with_changes`."""

    @classmethod
    def model_validate(cls, obj, *args, **kwargs):
        """Validate ``obj`` (a dict of sections); a bad field is a ModelError."""
        try:
            return super().model_validate(obj, *args, **kwargs)
        except ValidationError as exc:
            raise _model_error(exc, obj) from None

    @classmethod
    def model_validate_json(cls, json_data, *args, **kwargs):
        """Validate a JSON text of the sections; a bad field is a ModelError."""
        try:
            return super().model_validate_json(json_data, *args, **kwargs)
        except ValidationError as exc:
            raise _model_error(exc, None) from None

    def model_post_init(self, __context) -> None:
        self._identity = self._entries()

    def _entries(self) -> tuple:
        """Every entry of every section, by name, as the objects themselves (a copy or a
        pickle of the model keeps them paired, so it is not 'changed')."""
        return tuple((section, tuple(getattr(self, section).items()))
                     for section in ("gears", "bodies", "shafts", "meshes", "splines",
                                     "drives", "loads"))

    def changed_in_place(self) -> bool:
        """True when an entry of a section was replaced, added or deleted after the model
        was validated (the sections are plain dicts): such a change is not checked, and
        results computed before it would be reused for it.  (The entries themselves are
        frozen and their lists are tuples: nothing inside them can change.)"""
        now = self._entries()
        if len(now) != len(self._identity):
            return True
        for (_, a), (_, b) in zip(now, self._identity):
            if len(a) != len(b) or any(ka != kb or va is not vb
                                       for (ka, va), (kb, vb) in zip(a, b)):
                return True
        return False

    def with_changes(self, changes) -> "Model":
        """A new, validated and checked model with ``changes`` applied: a mapping of field
        paths to values, as ``--set`` takes them (``{"meshes.m11.damping_ratio": 0.1,
        "shafts.s1.diameter": "250 mm"}``; a bare number is SI).  The model itself is not
        changed (it is frozen)."""
        import json

        from .io import changes_mapping, load_model, model_to_json
        from .overrides import apply_overrides

        changes = changes_mapping(changes)
        # the data it was read from where kept (a [[planetary]] stage's own fields then
        # exist, as for --set), else the model itself in SI
        base = self._source if self._source is not None else json.loads(model_to_json(self))
        return load_model(apply_overrides(base, changes))

    @model_validator(mode="after")
    def _expand_planetary(self):
        """Replace each [[planetary]] table by its general elements (model/planetary.py)."""
        if not self.planetary:
            for section in ("gears", "meshes"):
                if not getattr(self, section):
                    raise FieldError(section, (
                        f"the model has no {section}; add [{section}.NAME] sections (see "
                        f"docs/model-file.md) or a [[planetary]] stage"))
            return self
        from .planetary import written_at

        gears, bodies, meshes = dict(self.gears), dict(self.bodies), dict(self.meshes)
        origins: dict[str, str] = {}
        for k, stage in enumerate(self.planetary):
            g, b, m = stage.expand()
            origins.update(stage.origins(k))
            for section, new, have in (("gears", g, gears), ("bodies", b, bodies),
                                       ("meshes", m, meshes)):
                for name, spec in new.items():
                    if name in have or name in gears or name in bodies:
                        raise FieldError(f"planetary.{k}.name", (
                            f"the stage would create {section}.{name}, which exists already; "
                            f"give the stage another 'name'"))
                    cls = {"gears": Gear, "bodies": Body, "meshes": Mesh}[section]
                    try:
                        have[name] = cls.model_validate(spec)
                    except ValidationError as exc:  # named as the stage's field
                        from .io import _format_errors

                        loc, msg = _format_errors(exc)[0]
                        where = f"{section}.{name}" + (f".{loc}" if loc else "")
                        raise FieldError(written_at(origins, where), msg) from None
        object.__setattr__(self, "gears", gears)
        object.__setattr__(self, "bodies", bodies)
        object.__setattr__(self, "meshes", meshes)
        object.__setattr__(self, "planetary", ())
        self._origins = origins
        self._identity = self._entries()  # (the expanded sections are the validated ones)
        return self

    def __eq__(self, other):
        """Field by field: where a ``[[planetary]]`` stage's elements came from
        (``_origins``, for messages only) is no part of the model, so a model written to
        a file and read back (no stage tables then) equals the model it came from."""
        if not isinstance(other, Model):
            return NotImplemented
        return self.__dict__ == other.__dict__

    __hash__ = None  # (as before: its dict fields make a model unhashable)

    def __repr__(self) -> str:
        parts = [f"{len(getattr(self, k))} {k}" for k in ("gears", "bodies", "shafts",
                                                           "meshes", "splines")
                 if getattr(self, k)]
        return f"Model({self.model.name!r}: {', '.join(parts)})"

    def written_at(self, loc: str) -> str:
        """A location (``gears.st_planet2.support.pin_error.radial``) as the user wrote
        it: the field of the ``[[planetary]]`` stage that generated it
        (``planetary.0.pin_errors.1.radial``), else ``loc`` itself."""
        from .planetary import written_at

        return written_at(self._origins, loc)

    def body_names(self) -> list[str]:
        return list(self.gears) + list(self.bodies)
