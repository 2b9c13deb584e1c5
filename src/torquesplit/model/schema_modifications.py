"""Model-file sections of tooth modifications, misalignment and LTCA options.

They are used by the loaded tooth contact analysis (:mod:`torquesplit.gears.contact`)
through a mesh's ``stiffness.method = "ltca"``:

* ``[gears.NAME.modifications]`` -- profile and lead modification of the loaded flank
  (tip and root relief, crowning, end relief, helix slope, or the topological
  modification of Liu, Fang, Jia et al. 2021 as ``topological``);
  ``[gears.NAME.modifications.second_helix]`` for a different second helix of a
  double-helical gear;
* ``[meshes.NAME.misalignment]`` -- lead mismatch, shaft misalignment, base pitch
  deviation of the pair;
* ``[meshes.NAME.stiffness.ltca]`` -- positions, contact model, slice coupling,
  excitation form, operating load.

Amounts are material removed along the flank normal.  See
:mod:`torquesplit.gears.contact.modifications` for the coordinates.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

# schema.py imports this module after defining its base classes (the package import
# torquesplit -> model.io -> schema always comes first)
from .schema import Angle, Count, FieldError, Flag, Length, Number, Q, Strict

Force = Q("force")

__all__ = ["ReliefSpec", "EndReliefSpec", "TopologicalSpec", "FlankSpec", "ModificationsSpec",
           "MisalignmentSpec", "LtcaSpec"]

_SHAPE_DOC = ("Relief curve: 'linear', 'parabolic' (exponent 2) or 'power' (Liu et al. 2021 "
              "eq. 20 with 'exponent').")


class ReliefSpec(Strict):
    """Tip or root relief: amount and where it starts (exactly one of length,
    start_diameter, start_roll_angle, height)."""

    amount: Length = Field(ge=0, description="Material removed at the tip (tip relief) or at the "
                           "start of active profile (root relief), along the flank normal.")
    length: Length | None = Field(None, gt=0, description="Length of the relief zone along the "
                                  "line of action (roll length, ISO 21771 L_Ca).")
    start_diameter: Length | None = Field(None, gt=0, description="Diameter at which the relief "
                                          "starts.")
    start_roll_angle: Angle | None = Field(None, gt=0, description="Roll angle at which the "
                                           "relief starts.")
    height: Length | None = Field(None, gt=0, description="Radial height of the relief zone from "
                                  "the tip (tip relief) or from the start of active profile "
                                  "(root relief), as y3, y4 of Liu et al. 2021.")
    shape: Literal["linear", "parabolic", "power"] = Field("linear", description=_SHAPE_DOC)
    exponent: Number = Field(2.0, gt=0, le=10, description="Exponent c of a 'power' relief curve.")

    @model_validator(mode="after")
    def _one_start(self):
        given = [n for n in ("length", "start_diameter", "start_roll_angle", "height")
                 if getattr(self, n) is not None]
        if not given:  # ('remove the others' where none was given, an LTCA reviewer)
            raise ValueError("says how much relief but not where it starts: add one of "
                             "length, start_diameter, start_roll_angle or height, e.g. "
                             "length = '2 mm' (along the line of action)")
        if len(given) > 1:
            raise ValueError(f"give exactly one of length, start_diameter, start_roll_angle, "
                             f"height (got {', '.join(given)}); keep one, remove the others")
        if self.exponent != 2.0 and self.shape != "power":
            raise FieldError("exponent", "applies to shape = 'power' only; set shape = 'power' "
                             "or remove 'exponent'")
        return self


class EndReliefSpec(Strict):
    """Lead end relief at both ends of the face."""

    amount: Length = Field(ge=0, description="Material removed at each face end.")
    length: Length = Field(gt=0, description="Length of the relief zone at each end, along the face.")
    shape: Literal["linear", "parabolic", "power"] = Field("linear", description=_SHAPE_DOC)
    exponent: Number = Field(2.0, gt=0, le=10, description="Exponent c of a 'power' curve.")

    @model_validator(mode="after")
    def _exponent(self):
        if self.exponent != 2.0 and self.shape != "power":
            raise FieldError("exponent", "applies to shape = 'power' only; set shape = 'power' "
                             "or remove 'exponent'")
        return self


class TopologicalSpec(Strict):
    """Topological modification of Liu, Fang, Jia et al. 2021 (§4, Fig. 9, eq. 20): root and
    tip relief and end relief, each a curve of exponent c, unmodified in the middle."""

    y1: Length = Field(ge=0, description="Root relief amount.")
    y2: Length = Field(ge=0, description="Tip relief amount.")
    y3: Length = Field(gt=0, description="Root relief height above the start of active profile.")
    y4: Length = Field(gt=0, description="Tip relief height below the tip.")
    y5: Length = Field(ge=0, description="End relief amount at both face ends.")
    y6: Length = Field(gt=0, description="Unmodified length in the middle of the face (of one helix).")
    exponent: Number = Field(2.0, gt=0, le=10, description="Index c of the modification curve "
                            "(eq. 20); 2 for the paper's quadratic parabolas.")


class FlankSpec(Strict):
    """Modification of the loaded flank (one helix)."""

    tip_relief: ReliefSpec | None = Field(None, description="Profile tip relief.")
    root_relief: ReliefSpec | None = Field(None, description="Profile root relief.")
    crowning: Length = Field(0.0, ge=0, description="Lead crowning: material removed at each face "
                             "end, parabolic over the face.")
    end_relief: EndReliefSpec | None = Field(None, description="Lead end relief at both ends.")
    helix_slope: Length = Field(0.0, description="Helix slope modification: material removed at "
                                "the far face end minus at the entry end (linear over the face).")
    topological: TopologicalSpec | None = Field(None, description="Preset: the y1..y6 "
                                                "modification of Liu et al. 2021 (instead of "
                                                "tip_relief, root_relief, end_relief).")

    @model_validator(mode="after")
    def _preset_alone(self):
        if self.topological is not None:
            clash = [n for n in ("tip_relief", "root_relief", "end_relief")
                     if getattr(self, n) is not None]
            if clash:
                raise FieldError("topological", (
                    f"the preset sets tip, root and end relief itself, and {', '.join(clash)} "
                    f"is given too; remove {' and '.join(clash)} or the preset"))
        return self


class ModificationsSpec(FlankSpec):
    """Tooth modification of a gear (loaded flank; both helices of a double-helical gear
    the same unless second_helix is given)."""

    second_helix: FlankSpec | None = Field(None, description="Different modification of the "
                                           "second helix of a double-helical gear.")


class MisalignmentSpec(Strict):
    """Separations the pair opens across the face and along the path (LTCA)."""

    lead_mismatch: Length = Field(0.0, description=(
        "Combined helix-slope deviation of both gears over the face of one helix (ISO "
        "1328-1 f_Hbeta): it acts as a helix_slope modification of that amount (same sign) "
        "on either gear; microns (write '20 um')."))
    shaft_misalignment: Angle = Field(0.0, description=(
        "Tilt of the axes against each other in the plane of action, opening the mesh "
        "across the face as a lead_mismatch of tilt x face width does; milliradians at "
        "most (write '0.5 mrad' or '0.03 deg')."))
    base_pitch_deviation: Length = Field(0.0, description=(
        "Normal base pitch of the driven gear minus that of the driver: > 0 brings each "
        "entering tooth pair that much early into contact (premature contact at the driven "
        "gear's tip, as tooth deflection does); < 0 delays it."))


#: the mesh positions an LTCA takes (``ltca.positions``, ``contact --positions``)
MIN_POSITIONS, MAX_POSITIONS = 8, 4096


class LtcaSpec(Strict):
    """Options of the loaded tooth contact analysis of a mesh (stiffness method 'ltca')."""

    positions: Count = Field(64, ge=MIN_POSITIONS, le=MAX_POSITIONS,
                             description="Mesh positions over one mesh cycle.")
    contact_model: Literal["weber", "linear"] = Field(
        "weber", description="Hertzian contact of a slice: load dependent (Weber 1949 / Johnson "
        "1985) or linear (Yang & Lin 1987, as the potential-energy method).")
    coupling: Flag = Field(True, description="Couple neighbouring slices of a tooth (Pasternak "
                           "strip); false gives independent slices.")
    excitation: Literal["tangent", "secant"] = Field(
        "tangent", description="'tangent': stiffness dP/dZ at the operating load plus the "
        "transmission-error excitation that gives the operating load at every position; "
        "'secant': stiffness P/Z (Liu et al. 2021 eq. 5) and no error excitation.")
    load: Force | None = Field(None, gt=0, description="Operating normal load of the analysis; "
                               "default the mesh's nominal normal force from the power flow.")
    stagger: Number = Field(0.0, ge=0, lt=1, description="Phase offset of the second helix of a "
                           "double-helical pair [mesh cycles].")
    axial_float: Flag = Field(False, description="Double-helical pair: one member floats "
                              "axially, so the helices carry equal loads, each with its own "
                              "approach (the transmission error is their mean); false: both "
                              "members held axially (a misalignment then loads one helix more).")
    cache: Flag = Field(True, description="Keep results on disk, keyed by a hash of the inputs.")
