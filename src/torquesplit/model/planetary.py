"""The ``[[planetary]]`` shorthand: one table that expands to a planetary stage.

A planetary (epicyclic) stage is made of the general elements of the model file --
gears, a carrier body, planet bearings on the carrier (``support.on``), meshes and
torsional supports -- and can be written with them alone (docs/theory/planetary.md).
This shorthand writes them for you::

    [[planetary]]
    name = "stage"              # prefix of the generated names
    planets = 4
    module = "2.25 mm"
    pressure_angle = "24.6 deg"
    face_width = "30 mm"
    sun = {teeth = 42}
    planet = {teeth = 48, mass = "0.66 kg"}
    ring = {teeth = 138, torsional_support = {stiffness = "2.1e7 N m/rad"}}
    carrier = {polar_inertia = "0.064 kg m^2"}
    planet_bearing = {stiffness = "1e8 N/m"}
    sun_mesh = {stiffness = "5e8 N/m"}
    ring_mesh = {stiffness = "5e8 N/m"}

expands to ``stage_sun``, ``stage_ring`` (internal), ``stage_planet1`` ...
(placed from the sun at the planet angles), the body ``stage_carrier`` holding the
planet bearings (``support.on = "stage_carrier"``, with the pin errors), and the meshes
``stage_sun_planet1`` ..., ``stage_ring_planet1`` ... with the stage labels
``stage-sun`` and ``stage-ring`` (their load-sharing groups).  Drives and loads name the
generated bodies.  What is checked here, with the field named: the planets fit (the
tooth-count assembly condition ``(z_s + z_r) psi / 360 deg`` whole for every planet
angle psi), they do not overlap, sun-planet and planet-ring centre distances agree, the
ring is internal, the pins sit on the planet circle.

Tooth modifications of a member (``sun.modifications``, ``planet.modifications`` -- every
planet gets it --, ``ring.modifications``) and the ``misalignment`` of ``sun_mesh`` /
``ring_mesh`` go to the generated gears and meshes, where stiffness method ``"ltca"``
uses them as for any gear and mesh (the LTCA analyses the internal ring-planet pair).

After validation the model holds the general elements only (a model written back to a
file has no ``[[planetary]]`` table).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import BeforeValidator, Field, model_validator

from .schema import (
    Angle,
    BacklashSpec,
    Count,
    Damping,
    Dof,
    FieldError,
    GearErrors,
    Inertia,
    Length,
    Mass,
    MisalignmentSpec,
    Module,
    ModificationsSpec,
    Number,
    PinDeviation,
    StiffnessSpec,
    Strict,
    Support,
    TorsionalSupport,
    Unit,
    _backlash_shorthand,
    _angle_field,
    _check_rim,
    _stiffness_shorthand,
    _unique_dofs,
    _needs_mass,
)

#: relative tolerance of the assembly condition (a whole number of teeth)
FIT_TOLERANCE = 1e-6
#: relative tolerance of pin_radius against the sun-planet centre distance (the pins are
#: the planets' nominal centres; an offset is a pin error, pin_errors.radial)
PIN_TOLERANCE = 1e-6


class PlanetaryGear(Strict):
    """The sun, the planets or the ring of a ``[[planetary]]`` stage (the module, pressure
    and helix angle are the stage's)."""

    teeth: Count = Field(gt=0, le=10_000, description="Number of teeth.")
    kind: Literal["spur", "helical", "double_helical", "internal"] | None = Field(
        None, description="Gear type; default from the stage (the ring is internal; "
        "'double_helical' is refused: the internal ring has one helix).")
    profile_shift: Number = Field(0.0, ge=-5, le=5, description="Profile shift coefficient x.")
    face_width: Length | None = Field(None, gt=0, description="Face width; default the "
                                      "stage's.")
    mass: Mass | None = Field(None, gt=0, description="Mass; from geometry if omitted.")
    polar_inertia: Inertia | None = Field(None, gt=0, description="Polar moment of inertia; "
                                          "from geometry if omitted.")
    bore_diameter: Length = Field(0.0, ge=0, description="Bore diameter used for computed "
                                  "mass and inertia (sun and planets).")
    outer_diameter: Length | None = Field(None, gt=0, description="Outer diameter of the "
                                          "ring's rim, used for computed mass and inertia "
                                          "and, given, for the overlap check; default "
                                          "the root diameter + 2 rim_thickness.")
    rim_thickness: Length | None = Field(None, gt=0, description="Rim thickness of the ring "
                                         "from its root circle outwards, used for computed "
                                         "mass and inertia and, given, for the overlap "
                                         "check; default 3.5 m_n (ISO 6336-3:2006 "
                                         "Y_B = 1 from there).")
    dofs: tuple[Dof, ...] | None = Field(None, description="Degrees of freedom; default "
                                   "['theta', 'x', 'y'] for the planets, ['theta'] else.")
    support: Support | None = Field(None, description="Support of the translational DOFs "
                                    "(sun and ring; the planets sit on 'planet_bearing').")
    torsional_support: TorsionalSupport | None = Field(
        None, description="Holds the member against rotation (a fixed ring).")
    errors: GearErrors = Field(GearErrors(), description="Manufacturing and assembly errors "
                               "(every planet gets these).")
    modifications: ModificationsSpec | None = Field(
        None, description="Tooth modification of the loaded flank, as for [gears.NAME] "
        "(every planet gets it; used by stiffness method 'ltca' of sun_mesh / ring_mesh).")

    @model_validator(mode="after")
    def _dofs(self):
        if self.dofs is not None:
            _unique_dofs(self.dofs)
        return self


class PlanetaryCarrier(Strict):
    """The carrier of a ``[[planetary]]`` stage (a body on the stage axis)."""

    polar_inertia: Inertia = Field(gt=0, description="Polar moment of inertia (with the "
                                   "pins, without the planets).")
    mass: Mass | None = Field(None, gt=0, description="Mass (needed with translational DOFs).")
    dofs: tuple[Dof, ...] = Field(("theta",), description="Degrees of freedom.")
    support: Support | None = Field(None, description="Support of the translational DOFs.")
    torsional_support: TorsionalSupport | None = Field(
        None, description="Holds the carrier against rotation (a star stage).")
    eccentricity: Length = Field(0.0, ge=0, description="Carrier eccentricity (turns with "
                                 "the carrier).")
    eccentricity_phase: Angle = Field(0.0, description="Direction of the eccentricity at "
                                      "t = 0.")

    @model_validator(mode="after")
    def _dofs(self):
        _unique_dofs(self.dofs)
        # (here, not only on the body it expands to: beside another problem of the
        # stage, which stops the expansion, it was not said)
        _needs_mass(self.dofs, self.mass)
        return self


class PlanetaryMesh(Strict):
    """The sun-planet or the ring-planet meshes of a ``[[planetary]]`` stage (every planet
    the same)."""

    stiffness: Annotated[
        StiffnessSpec, BeforeValidator(_stiffness_shorthand), Unit("stiffness")
    ] = Field(description="Mean mesh stiffness (\"5e8 N/m\"), or a [stiffness] table.")
    damping: Damping | None = Field(None, ge=0, description="Mesh damping.")
    damping_ratio: Number | None = Field(None, ge=0, description="Mesh damping as a "
                                         "fraction of critical.")
    backlash: Annotated[
        BacklashSpec, BeforeValidator(_backlash_shorthand), Unit("length")
    ] = Field(0.0, description="Total backlash (\"100 um\"; 0 = none), or a [backlash] table.")
    misalignment: MisalignmentSpec = Field(MisalignmentSpec(), description="Misalignment and "
                                           "base pitch deviation of every planet's mesh "
                                           "(stiffness method 'ltca').")
    driver: Literal["sun", "ring", "planet"] | None = Field(
        None, description="Which gear of each of these meshes drives: 'sun' (sun_mesh) or "
        "'ring' (ring_mesh), or 'planet'; from the power flow if omitted (needed only where "
        "no power passes the meshes, e.g. a stage turning as one block, which 'check' warns "
        "of).")

    @model_validator(mode="after")
    def _one(self):
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("both 'damping' and 'damping_ratio' are given; remove one of them")
        return self


def _nearest_fits(i: int, first: float, steps: float, period: float) -> str:
    """The angle(s) nearest to a planet that does not fit: both where it lies halfway
    (245 deg between 243.333 and 246.667 named only the second, a planetary reviewer)."""
    lo, hi = math.floor(steps), math.ceil(steps)
    near = ([lo, hi] if abs((steps - lo) - (hi - steps)) < 1e-6 else [round(steps)])
    text = " or ".join(f"{math.degrees(first + k * period):.10g} deg" for k in near)
    return f"the nearest for planet {i}: {text}"


class Planetary(Strict):
    """A planetary (epicyclic) stage in one table: expands to the sun, planets, ring and
    carrier, the planet bearings on the carrier and the meshes (see
    docs/theory/planetary.md).  Any member may be held by a ``torsional_support`` (ring:
    planetary; carrier: star) or driven and loaded through ``[drives]``/``[loads]`` on
    the generated names (``<name>_sun``, ``<name>_ring``, ``<name>_carrier``).  A
    floating sun, held by its planet meshes alone: ``dofs = ["theta", "x", "y"]`` with
    ``support = {floating = true}`` (a support of negligible stiffness, 1 N/m, whose
    softness is not warned)."""

    name: str = Field("planetary", pattern=r"^[A-Za-z][A-Za-z0-9_]*$", max_length=40,
                      description="Prefix of the generated names (letters, digits, _).")
    planets: Count = Field(ge=1, le=32, description="Number of planets.")
    angles: tuple[Angle, ...] | None = Field(
        None, description="Planet angles about the stage axis from the x axis (default "
        "equally spaced from 0); one per planet, in any order: planet k (and its entry of "
        "'pin_errors') is the one at the k-th angle.")
    module: Module = Field(gt=0, description=(
        "Normal module of all three gears (or their normal diametral pitch, '4 1/in')."))
    pressure_angle: Angle = Field(math.radians(20.0), description="Normal pressure angle.")
    helix_angle: Angle = Field(0.0, description="Helix angle.")
    hand: Literal["right", "left"] | None = Field(
        None, description="Hand of the sun's helix (planets opposite, ring as the planets).")
    face_width: Length = Field(gt=0, description="Face width (of one helix for "
                               "double-helical gears).")
    position: tuple[Length, Length, Length] = Field((0.0, 0.0, 0.0),
                                                    description="Centre of the stage.")
    axis: tuple[Number, Number, Number] = Field((0.0, 0.0, 1.0), description="Stage axis.")
    pin_radius: Length | None = Field(
        None, gt=0, description="Radius of the planet pins; must equal the sun-planet "
        "centre distance (to 1e-6 of it; an offset of the pins is pin_errors.radial); "
        "default that distance.")
    sun: PlanetaryGear = Field(description="The sun gear.")
    planet: PlanetaryGear = Field(description="Every planet gear.")
    ring: PlanetaryGear = Field(description="The ring gear (internal).")
    carrier: PlanetaryCarrier = Field(description="The carrier.")
    planet_bearing: Support = Field(description="Bearing of each planet on its carrier pin "
                                    "(its other end is on the carrier: leave 'on' out).")
    pin_errors: tuple[PinDeviation, ...] | None = Field(
        None, description="Pin position error of each planet: one {radial, tangential} "
        "table per planet, in planet order, e.g. [{tangential = '20 um'}, {}, {}] (pin "
        "errors are typically microns); default none.")
    sun_mesh: PlanetaryMesh = Field(description="The sun-planet meshes.")
    ring_mesh: PlanetaryMesh = Field(description="The ring-planet meshes.")

    _pressure_angle_range = _angle_field("pressure_angle", 45)
    _helix_angle_range = _angle_field("helix_angle", 60)

    @model_validator(mode="after")
    def _consistent(self):
        problems: list[tuple[str, str]] = []  # (every one is said at once)
        if self.helix_angle != 0 and self.hand is None:
            problems.append(("hand", "a helical stage needs the sun's hand; add "
                             "hand = 'right' or hand = 'left'"))
        if not math.hypot(*self.axis) > 0:
            problems.append(("axis", "the zero vector has no direction; give e.g. [0, 0, 1]"))
        n = self.planets
        if self.angles is not None and len(self.angles) != n:
            problems.append(("angles", f"gives {len(self.angles)} angles for {n} planets; "
                             f"give one angle per planet"))
        if self.pin_errors is not None and len(self.pin_errors) != n:
            problems.append(("pin_errors", f"gives {len(self.pin_errors)} errors for {n} "
                             f"planets; give one {{radial, tangential}} per planet"))
        if self.planet.support is not None:
            problems.append(("planet.support", "the planets sit on 'planet_bearing'; "
                             "remove planet.support (give its stiffness in planet_bearing)"))
        if self.planet_bearing.on is not None:
            problems.append(("planet_bearing.on", "the planet bearings sit on the stage's "
                             "carrier; remove 'on'"))
        for member in ("sun", "ring"):
            drv = getattr(self, f"{member}_mesh").driver
            if drv not in (None, member, "planet"):
                problems.append((f"{member}_mesh.driver", (
                    f"{drv!r} is not a gear of the {member}-planet meshes; give "
                    f"'{member}' or 'planet', or remove 'driver'")))
        if self.ring.kind not in (None, "internal"):
            problems.append(("ring.kind", f"the ring of a planetary stage is an internal "
                             f"gear, not {self.ring.kind!r}; remove 'kind' or write "
                             f"kind = 'internal'"))
        for member in ("sun", "planet", "ring"):
            spec = getattr(self, member)
            try:
                _check_rim(spec.outer_diameter, spec.rim_thickness, member == "ring",
                           "the ring", lambda: 2 * self._geometry(spec, True).root_radius)
            except FieldError as exc:
                problems.append((f"{member}.{exc.field}", str(exc)))
        for member in ("sun", "planet"):
            if getattr(self, member).kind == "internal":
                # ("the planet meshes outside the planets' teeth" read as nonsense)
                what = ("the sun is an external gear (the planets mesh around it)"
                        if member == "sun" else "a planet is an external gear (it meshes "
                        "with the sun and inside the ring)")
                problems.append((f"{member}.kind", f"{what}, so it cannot be internal; "
                                 f"remove 'kind' (only the ring is internal)"))
            if getattr(self, member).kind == "double_helical":
                # the ring is an internal gear, and an internal gear has one helix here
                problems.append((f"{member}.kind", (
                    "a [[planetary]] stage is spur or helical: its ring is an internal gear "
                    "with one helix, which cannot mesh with double-helical planets; use "
                    "kind = 'helical' (with the stage's helix_angle) or remove 'kind'")))
        # (these read the counts and kinds checked above: each runs where those it
        # reads are sound)
        said = {field for field, _ in problems}
        checks = [self._check_modifications]
        if not said & {"angles", "pin_errors"}:
            checks.append(self._check_error_sizes)
        if not any(f == "angles" or f.endswith((".kind", "_diameter", "_thickness"))
                   for f in said):
            checks.append(self._check_fit)
        for check in checks:
            try:
                check()
            except FieldError as exc:
                problems += [(exc.field, str(exc)), *exc.more]
        if problems:
            raise FieldError.of(problems)
        return self

    def _check_error_sizes(self) -> None:
        """Pin errors, gear errors and the carrier eccentricity of a stage larger than its
        module are refused: they are microns, and one larger than the tooth is a length
        written as a bare number (read in metres: ``tangential = 20`` is 20 m), which the
        equations would carry through to nonsense (a planet factor of -384366)."""
        if not 0 < self.module < 0.1:
            return  # a module in bare metres: _check_fit refuses it first
        fields = []
        for i, pin in enumerate(self.pin_errors or []):
            fields += [(f"pin_errors.{i}.{f}", getattr(pin, f), "pin position errors")
                       for f in ("radial", "tangential")]
        for member in ("sun", "planet", "ring"):
            e = getattr(self, member).errors
            fields += [(f"{member}.errors.{f}", getattr(e, f), "gear errors")
                       for f in ("eccentricity", "installation", "tooth_thickness", "pitch",
                                 "bearing_runout")]
        fields.append(("carrier.eccentricity", self.carrier.eccentricity,
                       "carrier eccentricities"))
        for field, value, what in fields:
            if not abs(value) > self.module:
                continue
            # what was probably meant: the same digits in microns (a bare 20 -> '20 um';
            # '20 mm' -> '20 um')
            bare = abs(value) >= 1
            digits = math.copysign(abs(value) if bare else abs(value) * 1e3, value)
            size = f"{abs(value):.6g} m" if bare else f"{abs(value) * 1e3:.6g} mm"
            raise FieldError(field, (
                f"{size} is larger than the module ({self.module * 1e3:.4g} mm), which the "
                f"equations cannot carry (the teeth would part); {what} are microns" + (
                    " and a bare number is read in metres" if bare else "") +
                f": write '{digits:g} um'"))

    def _check_modifications(self) -> None:
        """What [gears.NAME] refuses of its modifications, named as written here: a second
        helix on a gear with one helix, which every member of a stage is (see
        _consistent).  Every member is cylindrical, so every one may be modified; the
        LTCA analyses the internal ring-planet pair too."""
        for member in ("sun", "planet", "ring"):
            spec = getattr(self, member).modifications
            if spec is not None and spec.second_helix is not None:
                raise FieldError(f"{member}.modifications.second_helix", (
                    "a second helix exists on double-helical gears only, and the gears of a "
                    "[[planetary]] stage have one helix (spur or helical); remove "
                    "second_helix"))

    # ------------------------------------------------------------------ layout
    def planet_angles(self) -> list[float]:
        """Planet angles [rad] (given, or equally spaced from 0)."""
        if self.angles is not None:
            return list(self.angles)
        return [2 * math.pi * i / self.planets for i in range(self.planets)]

    def _kind(self, member: PlanetaryGear) -> str:
        if member.kind is not None:
            return member.kind
        return "helical" if self.helix_angle != 0 else "spur"

    def _geometry(self, member: PlanetaryGear, internal: bool = False):
        from ..gears.geometry import GearGeometry

        kind = "internal" if internal else self._kind(member)
        return GearGeometry(
            teeth=member.teeth, normal_module=self.module,
            normal_pressure_angle=self.pressure_angle, helix_angle=abs(self.helix_angle),
            face_width=member.face_width or self.face_width,
            profile_shift=member.profile_shift, internal=kind == "internal",
            double_helical=kind == "double_helical")

    def _closing_sun_shift(self, a_rp: float) -> float | None:
        """The sun's profile shift that makes the sun-planet operating centre distance
        ``a_rp`` (the planet-ring one), the other shifts as given; None where the shifts
        are all zero (the tooth counts are the fix) or no shift in [-1, 1.5] does it."""
        from scipy.optimize import brentq

        from ..errors import ModelError
        from ..gears.geometry import PairGeometry

        if not any(m.profile_shift for m in (self.sun, self.planet, self.ring)):
            return None
        planet = self._geometry(self.planet, internal=False)

        def gap(x):
            sun = self._geometry(self.sun.model_copy(update={"profile_shift": x}),
                                 internal=False)
            return PairGeometry(sun, planet).operating_center_distance - a_rp

        def valued(x):  # (a shift that points or undercuts the teeth has none)
            try:
                return gap(x)
            except (ModelError, ValueError):
                return None

        grid = [(x, valued(x)) for x in np.linspace(-1.0, 1.5, 26)]
        for (x0, g0), (x1, g1) in zip(grid, grid[1:]):
            if g0 is not None and g1 is not None and g0 * g1 <= 0:
                return float(brentq(gap, x0, x1, xtol=1e-7))
        return None

    def _check_fit(self) -> None:
        """Planets that do not fit: the assembly condition, overlapping planets, unequal
        centre distances, pins off the planet circle."""
        from ..errors import ModelError
        from ..gears.geometry import PairGeometry

        geo, member = {}, None
        try:
            for member in ("sun", "planet", "ring"):
                geo[member] = self._geometry(getattr(self, member), internal=member == "ring")
            member = None
            sun, planet, ring = geo["sun"], geo["planet"], geo["ring"]
            a_sp = PairGeometry(sun, planet).operating_center_distance
            a_rp = PairGeometry(planet, ring).operating_center_distance
        except ModelError as exc:
            loc, msg = exc.issues[0]
            # a gear's own geometry names its field (the stage's module, the member's
            # teeth); a pair that cannot mesh, the tooth counts
            field = {"normal_module": "module", "normal_pressure_angle": "pressure_angle",
                     "helix_angle": "helix_angle", "teeth": f"{member}.teeth",
                     "addendum": f"{member}.profile_shift"}.get(loc) if member else None
            zs, zp, zr = self.sun.teeth, self.planet.teeth, self.ring.teeth
            if field is None and loc == "gear2.teeth" and zr <= zp:
                raise FieldError("ring.teeth", (
                    f"a ring of {zr} teeth cannot hold planets of {zp}: an internal gear "
                    f"needs more teeth than its pinion, and without profile shifts the ring "
                    f"needs z_s + 2 z_p = {zs + 2 * zp}; correct the tooth counts")) from None
            if field is None:
                field = "ring.teeth" if "internal" in msg else "planet.teeth"
            fix = "tooth counts" if field.endswith(".teeth") else "value"
            raise FieldError(field, msg if ";" in msg else f"{msg}; correct the {fix}") from None
        zs, zp, zr = self.sun.teeth, self.planet.teeth, self.ring.teeth
        if abs(a_sp - a_rp) > 1e-6 * a_sp:
            shift = self._closing_sun_shift(a_rp)
            # (the stage, not one member: which count is wrong is the user's call, and
            # a --set of the sun's was blamed on the ring's line, a planetary reviewer)
            raise FieldError("", (
                f"sun {zs}, planet {zp} and ring {zr} teeth: "
                f"the planets cannot mesh with sun and ring at once: the sun-planet centre "
                f"distance is {a_sp * 1e3:.4f} mm, the planet-ring one {a_rp * 1e3:.4f} mm; "
                f"without profile shifts the ring needs z_s + 2 z_p = {zs + 2 * zp} teeth"
                + (f", and with the planet's and ring's shifts as given a sun profile_shift "
                   f"of {shift:.4f} closes the gap" if shift is not None else "")
                + ": correct the tooth counts or the profile shifts"))
        if self.pin_radius is not None and abs(self.pin_radius - a_sp) > PIN_TOLERANCE * a_sp:
            off = self.pin_radius - a_sp
            raise FieldError("pin_radius", (
                f"pins at {self.pin_radius * 1e3:.9g} mm from the axis are "
                + (f"{abs(off) * 1e6:.4g} um" if abs(off) < 1e-3 else
                   f"{abs(off) * 1e3:.6g} mm")
                + f" {'outside' if off > 0 else 'inside'} the circle "
                f"the planets mesh on (the operating sun-planet centre distance, "
                f"{a_sp * 1e3:.9g} mm; tolerance {PIN_TOLERANCE:g} of it, "
                f"{PIN_TOLERANCE * a_sp * 1e6:.2g} um): remove 'pin_radius' or write "
                f"pin_radius = '{a_sp * 1e3:.9g} mm'" + (
                    f"; give a real offset of the pins as pin_errors = [{{radial = "
                    f"'{off * 1e6:.4g} um'}}, ...]" if abs(off) <= self.module else "")))
        angles = self.planet_angles()
        where = "angles" if self.angles is not None else "planets"
        period = 2 * math.pi / (zs + zr)
        fit: list[tuple[str, str]] = []
        for i, psi in enumerate(angles[1:], start=2):
            # tooth-count assembly condition: a planet fits sun and ring at once only at
            # angles that are multiples of 360 deg / (z_s + z_r) from the first
            # (e.g. Parker & Lin 2004; Mueller, Epicyclic drive trains)
            steps = (psi - angles[0]) / period
            if abs(steps - round(steps)) > FIT_TOLERANCE * max(1.0, abs(steps)):
                hint = (f"with {self.planets} equally spaced planets (z_s + z_r) / N = "
                        f"{(zs + zr) / self.planets:.6g} must be a whole number: choose tooth "
                        f"counts with z_s + z_r divisible by {self.planets}, or give 'angles'"
                        if self.angles is None else
                        f"give angles that are multiples of 360 deg / (z_s + z_r) = "
                        f"{math.degrees(period):.6g} deg from the first planet; "
                        + _nearest_fits(i, angles[0], steps, period))
                if self.angles is not None and max(abs(a) for a in angles) > 2 * math.pi:
                    # an angle beyond a turn is a number of degrees written bare: that
                    # one message (the other angles are misread the same way)
                    raise FieldError(where, (
                        f"planet {i} does not fit: at {math.degrees(psi - angles[0]):.6g} "
                        f"deg from planet 1 it is {steps:.6g} tooth periods of sun and ring "
                        f"away (the tooth-count assembly condition); a bare number is read "
                        f"in radians: planet {i}'s angle {psi:g} is {math.degrees(psi):.6g} "
                        f"deg; write '{psi:g} deg'"))
                # (the digits the condition is decided to: '120 deg ... the nearest: 120 deg'
                # hid an angle written as 2.0944 rad, a planetary reviewer)
                fit.append((where, (
                    f"planet {i} does not fit: at {math.degrees(psi - angles[0]):.10g} deg "
                    f"from planet 1 it is {steps:.10g} tooth periods of sun and ring away, "
                    f"not a whole number to {FIT_TOLERANCE:g} (the tooth-count assembly "
                    f"condition); {hint}")))
                if self.angles is None:
                    break  # (equal spacing: one message says it for every planet)
        # (planet numbers from 1, in the order of 'angles', which may be any order)
        order = sorted((a % (2 * math.pi), i) for i, a in enumerate(angles, start=1))
        tip = planet.tip_radius
        for k in range(len(order)):
            if len(order) == 1:
                break
            (a1, i1), (a2, i2) = order[k], order[(k + 1) % len(order)]
            gap = (a2 - a1) % (2 * math.pi)
            chord = 2 * a_sp * math.sin(min(gap, 2 * math.pi) / 2)
            if chord <= 2 * tip:
                i1, i2 = sorted((i1, i2))
                fit.append((where, (
                    f"planets {i1} and {i2} are at the same angle ({math.degrees(a1):.6g} "
                    f"deg, modulo 360 deg); give each planet its own angle"
                    if chord < 1e-9 * a_sp else
                    f"planets overlap: planets {i1} and {i2}, {math.degrees(gap):.4g} deg "
                    f"apart, are {chord * 1e3:.4f} mm apart, less than the planet tip "
                    f"diameter {2 * tip * 1e3:.4f} mm; use fewer planets, smaller planets or "
                    f"wider angles")))
                break  # (one overlap said)
        if fit:
            raise FieldError.of(fit)

    # ------------------------------------------------------------------ expansion
    def names(self) -> dict[str, object]:
        """Generated names: sun, ring, carrier, planets, sun meshes, ring meshes."""
        n = self.name
        planets = [f"{n}_planet{i + 1}" for i in range(self.planets)]
        return dict(sun=f"{n}_sun", ring=f"{n}_ring", carrier=f"{n}_carrier",
                    planets=planets, sun_meshes=[f"{n}_sun_planet{i + 1}" for i in
                                                 range(self.planets)],
                    ring_meshes=[f"{n}_ring_planet{i + 1}" for i in range(self.planets)])

    def origins(self, index: int) -> dict[str, str]:
        """Where the user wrote what the expansion generates: the location of each
        generated element, and of its fields that come from elsewhere in the stage table
        -> the field of ``[[planetary]]`` number ``index`` (``gears.st_planet2`` ->
        ``planetary.0.planet``, ``gears.st_planet2.support.pin_error`` ->
        ``planetary.0.pin_errors.1``, ``gears.st_sun.module`` -> ``planetary.0.module``),
        so that messages name the field as written (:meth:`Model.written_at`)."""
        here = f"planetary.{index}"
        names = self.names()
        out: dict[str, str] = {}
        members = [("sun", names["sun"]), ("ring", names["ring"])]
        members += [("planet", p) for p in names["planets"]]
        for member, gear in members:
            loc, spec = f"gears.{gear}", getattr(self, member)
            out[loc] = f"{here}.{member}"
            for field in ("module", "pressure_angle", "helix_angle", "hand", "axis"):
                out[f"{loc}.{field}"] = f"{here}.{field}"
            if spec.face_width is None:
                out[f"{loc}.face_width"] = f"{here}.face_width"
            if member != "planet":
                out[f"{loc}.position"] = f"{here}.position"
        for i, planet in enumerate(names["planets"]):
            loc = f"gears.{planet}"
            where = f"{here}.angles.{i}" if self.angles is not None else f"{here}.planets"
            out[f"{loc}.place"] = out[f"{loc}.position"] = where
            out[f"{loc}.support"] = f"{here}.planet_bearing"
            out[f"{loc}.support.pin_error"] = f"{here}.pin_errors.{i}"
        loc = f"bodies.{names['carrier']}"
        out[loc] = f"{here}.carrier"
        out[f"{loc}.position"] = f"{here}.position"
        out[f"{loc}.axis"] = f"{here}.axis"
        for member in ("sun", "ring"):
            for mesh in names[f"{member}_meshes"]:
                out[f"meshes.{mesh}"] = f"{here}.{member}_mesh"
        return out

    def expand(self) -> tuple[dict, dict, dict]:
        """(gears, bodies, meshes) as dicts of SI values and schema objects, ready for
        the general schema sections."""
        names = self.names()
        hand_sun = self.hand
        other = {"right": "left", "left": "right", None: None}[hand_sun]

        def gear(member: PlanetaryGear, kind: str, hand, dofs, **extra) -> dict:
            d = dict(teeth=member.teeth, module=self.module,
                     pressure_angle=self.pressure_angle, helix_angle=self.helix_angle,
                     hand=hand if self.helix_angle != 0 else None, kind=kind,
                     face_width=member.face_width or self.face_width,
                     profile_shift=member.profile_shift, bore_diameter=member.bore_diameter,
                     outer_diameter=member.outer_diameter, rim_thickness=member.rim_thickness,
                     axis=self.axis, dofs=member.dofs or dofs, errors=member.errors,
                     torsional_support=member.torsional_support,
                     modifications=member.modifications)
            if member.mass is not None:
                d["mass"] = member.mass
            if member.polar_inertia is not None:
                d["polar_inertia"] = member.polar_inertia
            d.update(extra)
            return {k: v for k, v in d.items() if v is not None}

        gears = {
            names["sun"]: gear(self.sun, self._kind(self.sun), hand_sun, ["theta"],
                               position=self.position, support=self.sun.support),
            names["ring"]: gear(self.ring, "internal", other, ["theta"],
                                position=self.position, support=self.ring.support),
        }
        pins = self.pin_errors or [PinDeviation()] * self.planets
        for i, (pname, psi) in enumerate(zip(names["planets"], self.planet_angles())):
            bearing = self.planet_bearing.model_copy(update={"on": names["carrier"],
                                                             "pin_error": pins[i]})
            gears[pname] = gear(self.planet, self._kind(self.planet), other,
                                ["theta", "x", "y"],
                                place={"from_gear": names["sun"], "angle": psi},
                                support=bearing)
        c = self.carrier
        bodies = {names["carrier"]: {k: v for k, v in dict(
            polar_inertia=c.polar_inertia, mass=c.mass, position=self.position,
            axis=self.axis, dofs=c.dofs, support=c.support,
            torsional_support=c.torsional_support, eccentricity=c.eccentricity,
            eccentricity_phase=c.eccentricity_phase).items() if v is not None}}
        meshes = {}
        for member, spec, mnames in (("sun", self.sun_mesh, names["sun_meshes"]),
                                     ("ring", self.ring_mesh, names["ring_meshes"])):
            for mname, pname in zip(mnames, names["planets"]):
                d = dict(gears=(names[member], pname), stiffness=spec.stiffness,
                         backlash=spec.backlash, stage=f"{self.name}-{member}",
                         misalignment=spec.misalignment)
                if spec.damping is not None:
                    d["damping"] = spec.damping
                if spec.damping_ratio is not None:
                    d["damping_ratio"] = spec.damping_ratio
                if spec.driver is not None:
                    d["driver"] = pname if spec.driver == "planet" else names[member]
                meshes[mname] = d
        return gears, bodies, meshes


def written_at(origins: dict[str, str], loc: str) -> str:
    """``loc`` (``gears.st_planet2.modifications.crowning``) as the user wrote it
    (``planetary.0.planet.modifications.crowning``) by the longest generated prefix in
    ``origins`` (:meth:`Planetary.origins`); a location of no stage is returned as is."""
    if not origins or not loc:
        return loc
    parts = loc.split(".")
    for n in range(len(parts), 0, -1):
        head = ".".join(parts[:n])
        if head in origins:
            return origins[head] + loc[len(head):]
    return loc
