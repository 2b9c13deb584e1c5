"""Planetary test models: the Lin & Parker 1999 example and its variants, as data."""

from __future__ import annotations

import copy
import math
import tomllib
import warnings

import torquesplit
from torquesplit.model.io import model_from_dict, model_to_dict
from torquesplit.model.reader import read_model_file

#: Lin & Parker 1999 Table 1 (the example system), SI
LP = dict(m_s=0.4, m_r=2.35, m_c=5.43, m_p=0.66, i_s=0.39, i_r=3.00, i_c=6.29, i_p=0.61,
          k_mesh=5e8, k_bearing=1e8, k_ru=1e9, alpha=math.radians(24.6))


def lp_raw(planets: int = 4, **stage) -> dict:
    """The raw data of the shipped Lin & Parker example, ``planets`` planets, with
    ``stage`` overriding fields of its [[planetary]] table."""
    data = read_model_file(torquesplit.example_path("lin_parker1999_planetary"))
    data = copy.deepcopy(data)
    data["planetary"][0]["planets"] = planets
    data["planetary"][0].update(stage)
    return data


def load(data: dict, check: bool = True):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = model_from_dict(data)
        return torquesplit.load_model(model, check=check)


def lp_model(planets: int = 4, **stage):
    return load(lp_raw(planets, **stage))


def general_elements(model) -> dict:
    """The model written with the general sections only (no [[planetary]] table)."""
    return model_to_dict(model)


#: Cooley & Parker 2012 Table 1 (the example of the rotating-carrier analysis), SI; the
#: torsional stiffnesses act on u = r theta.  Tooth counts and module are ours (not in
#: the paper; the lumped model does not depend on them): 36 / 24 / 84, 2 mm, 20 deg.
CP = dict(m_s=3.0, m_r=7.64, m_c=12.0, m_p=1.86, i_s=1.75, i_r=8.09, i_c=6.80, i_p=1.25,
          k_mesh=100e6, k_s=20e6, k_r=100e6, k_c=50e6, k_p=10e6, k_su=20e6, k_ru=100e6,
          k_cu=100e6, alpha=math.radians(20.0), teeth=(36, 24, 84), module=2e-3)


def cp_raw(planets: int = 4, sun_speed: str = "100 rpm") -> dict:
    """Cooley & Parker 2012's example as a model: the sun's torsional stiffness k_su is a
    shaft to an input held at its speed (a speed drive removes its rotation), the
    carrier's k_cu a shaft to an output inertia of 1e6 kg m^2 (ground for the stage's
    modes: it adds one mode near 0.1 Hz), the ring held by k_ru."""
    zs, zp, zr = CP["teeth"]
    m, a = CP["module"], CP["alpha"]

    def rb(z):
        return m * z / 2 * math.cos(a)

    ac = m * (zs + zp) / 2
    p = CP
    return {
        "model": {"name": "cooley_parker2012"},
        "planetary": [{
            "name": "st", "planets": planets, "module": m, "pressure_angle": "20 deg",
            "face_width": "20 mm",
            "sun": {"teeth": zs, "mass": p["m_s"], "polar_inertia": p["i_s"] * rb(zs) ** 2,
                    "dofs": ["theta", "x", "y"], "support": {"stiffness": p["k_s"]}},
            "planet": {"teeth": zp, "mass": p["m_p"], "polar_inertia": p["i_p"] * rb(zp) ** 2},
            "ring": {"teeth": zr, "mass": p["m_r"], "polar_inertia": p["i_r"] * rb(zr) ** 2,
                     "dofs": ["theta", "x", "y"], "support": {"stiffness": p["k_r"]},
                     "torsional_support": {"stiffness": p["k_ru"] * rb(zr) ** 2}},
            "carrier": {"mass": p["m_c"], "polar_inertia": p["i_c"] * ac**2,
                        "dofs": ["theta", "x", "y"], "support": {"stiffness": p["k_c"]}},
            "planet_bearing": {"stiffness": p["k_p"]},
            "sun_mesh": {"stiffness": p["k_mesh"]}, "ring_mesh": {"stiffness": p["k_mesh"]},
        }],
        "bodies": {"input": {"polar_inertia": 1.0}, "output": {"polar_inertia": 1e6}},
        "shafts": {
            "sun_shaft": {"connects": ["input", "st_sun"],
                          "torsional_stiffness": p["k_su"] * rb(zs) ** 2},
            "carrier_shaft": {"connects": ["st_carrier", "output"],
                              "torsional_stiffness": p["k_cu"] * ac**2}},
        "drives": {"in": {"body": "input", "speed": sun_speed, "torque": "10 N m",
                          "mode": "speed"}},
        "loads": {"out": {"body": "output"}},
    }


#: a small planetary stage (3 planets, 21/24/69 teeth, sun in, carrier out, ring held)
#: whose meshes use the LTCA with few positions and slices (fast): the stage of the
#: tooth-modification tests
SMALL_LTCA_STAGE = """\
[model]
name = "small planetary, LTCA meshes"

[[planetary]]
name = "st"
planets = 3
module = "2 mm"
face_width = "20 mm"
sun = {teeth = 21}
planet = {teeth = 24}
ring = {teeth = 69, torsional_support = {stiffness = "1e7 N m/rad"}}
carrier = {polar_inertia = "0.05 kg m^2"}
planet_bearing = {stiffness = "1e8 N/m"}
sun_mesh = {stiffness = {method = "ltca", slices = 4, ltca = {positions = 16}}}
ring_mesh = {stiffness = {method = "ltca", slices = 4, ltca = {positions = 16}}}

[drives.input]
body = "st_sun"
speed = "1000 rpm"
torque = "100 N m"

[loads.output]
body = "st_carrier"
"""


def small_ltca_raw(**modifications) -> dict:
    """:data:`SMALL_LTCA_STAGE` as data; ``sun=``, ``planet=``, ``ring=`` give those
    members' ``modifications``."""
    data = tomllib.loads(SMALL_LTCA_STAGE)
    for member, spec in modifications.items():
        data["planetary"][0][member]["modifications"] = copy.deepcopy(spec)
    return data


def three_planet_toml(name: str, *, teeth=(24, 30, 84), face_width: str = "40 mm",
                      floating_sun: bool = True, mesh: str = '"5e8 N/m"',
                      damping_ratio: float | None = 0.05,
                      carrier: str = 'polar_inertia = "0.5 kg m^2"', extra: str = "") -> str:
    """A small 3-planet ``[[planetary]]`` stage named ``st`` (module 3 mm, ring held, sun
    driven at 1500 rpm / 100 kW, carrier loaded) as model-file text: ``teeth`` of sun,
    planet and ring; a sun floating on 1e8 N/m bearings or turning only; ``mesh`` the
    TOML of both meshes' stiffness; ``extra`` more lines of the stage table."""
    sun = f"teeth = {teeth[0]}"
    if floating_sun:
        sun += ', dofs = ["theta", "x", "y"], support = {stiffness = "1e8 N/m"}'
    damp = "" if damping_ratio is None else f", damping_ratio = {damping_ratio}"
    return f"""
[model]
name = "{name}"

[[planetary]]
name = "st"
planets = 3
module = "3 mm"
{extra}face_width = "{face_width}"
sun = {{{sun}}}
planet = {{teeth = {teeth[1]}}}
ring = {{teeth = {teeth[2]}, torsional_support = {{rigid = true}}}}
carrier = {{{carrier}}}
planet_bearing = {{stiffness = "5e8 N/m"}}
sun_mesh = {{stiffness = {mesh}{damp}}}
ring_mesh = {{stiffness = {mesh}{damp}}}

[drives.motor]
body = "st_sun"
speed = "1500 rpm"
power = "100 kW"

[loads.out]
body = "st_carrier"
"""


def compound_raw(pin_error: dict | None = None, shaft_bearing: str | None = None,
                 teeth: tuple = (20, 40, 20, 80)) -> dict:
    """Three compound (stepped) planets from the general elements: on each planet shaft
    ``pa`` (40 teeth, on the carrier's pin bearing) meshes the sun (20), ``pb`` (20, 30 mm
    behind it) the ring (80, held); module 2 mm, pins at 60 mm, sun driven at 900 rpm /
    100 N m (Willis: 1 + (80/20)(40/20) = 9, carrier 900 N m).  ``pin_error`` of planet
    0's bearing; ``shaft_bearing``: ``pb`` gets its own translations on a bearing on
    ``pa`` of that stiffness instead of riding the shaft (the same shaft, elastic);
    ``teeth`` of sun, pa, pb and ring (z_s + z_pa = z_r - z_pb: the pins at that many
    mm)."""
    zs, za, zb, zr = teeth
    radius = zs + za  # [mm] = m (z_s + z_a) / 2 with m = 2 mm

    def gear(z_teeth, z, **more):
        return dict(teeth=z_teeth, module="2 mm", face_width="20 mm",
                    position=["0 mm", "0 mm", f"{z} mm"], **more)

    gears = {"sun": gear(zs, 0, mass="1 kg", polar_inertia="0.001 kg m^2"),
             "ring": gear(zr, -30, kind="internal", torsional_support={"rigid": True})}
    meshes, shafts = {}, {}
    for i in range(3):
        psi = 2 * math.pi * i / 3
        at = [f"{radius * math.cos(psi):.12f} mm", f"{radius * math.sin(psi):.12f} mm"]
        pin = {"stiffness": "2e8 N/m", "on": "carrier"}
        if i == 0 and pin_error:
            pin["pin_error"] = pin_error
        gears[f"pa{i}"] = gear(za, 0, mass="0.5 kg", polar_inertia="0.0005 kg m^2",
                               dofs=["theta", "x", "y"], support=pin)
        gears[f"pa{i}"]["position"][:2] = at
        gears[f"pb{i}"] = gear(zb, -30, mass="0.2 kg", polar_inertia="0.0001 kg m^2")
        gears[f"pb{i}"]["position"][:2] = at
        if shaft_bearing:
            gears[f"pb{i}"].update(dofs=["theta", "x", "y"],
                                   support={"stiffness": shaft_bearing, "on": f"pa{i}"})
        shafts[f"ps{i}"] = {"connects": [f"pa{i}", f"pb{i}"], "rigid": True}
        meshes[f"sp{i}"] = {"gears": ["sun", f"pa{i}"], "stiffness": "4e8 N/m",
                            "damping_ratio": 0.05, "stage": "sun"}
        meshes[f"rp{i}"] = {"gears": [f"pb{i}", "ring"], "stiffness": "4e8 N/m",
                            "damping_ratio": 0.05, "stage": "ring"}
    return {"model": {"name": "compound"}, "gears": gears,
            "bodies": {"carrier": {"polar_inertia": "0.05 kg m^2", "mass": "5 kg",
                                   "position": ["0 mm", "0 mm", "-15 mm"]}},
            "shafts": shafts, "meshes": meshes,
            "drives": {"input": {"body": "sun", "speed": "900 rpm", "torque": "100 N m"}},
            "loads": {"output": {"body": "carrier"}}}
