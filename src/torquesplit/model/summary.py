"""The kinematic and static summary printed by ``torquesplit check``."""

from __future__ import annotations

import math

import numpy as np

from .kinematics import solve_kinematics
from .schema import Model

RPM = 30 / math.pi


def summary(model: Model) -> dict:
    """A JSON-serialisable summary: speeds, torques, mesh frequencies, geometry, forces."""
    from ..assembly.excitation import stage_labels

    from .kinematics import frame_label, mass_basis

    kin = solve_kinematics(model)
    stages = stage_labels(model, kin)
    idlers = _idlers(model)
    roles = _roles(model)
    bodies = {}
    for name, b in kin.bodies.items():
        carrier = kin.planet_bodies.get(name)
        carrier = carrier if carrier and kin.bodies[carrier].speed else None  # (a star's
        # carrier is at rest: a planet's speed on its pin is its speed)
        bodies[name] = {
            "speed_rpm": b.speed * RPM,  # (absolute: in the housing's frame)
            # a planet's speed on its pin (its bearing's), relative to its carrier
            **({"carrier": carrier,
                "speed_relative_to_carrier_rpm": (b.speed - kin.bodies[carrier].speed) * RPM}
               if carrier else {}),
            "torque_Nm": b.torque,
            # (an idler passes power on: none is put in or taken out; its torque times
            # its speed read as 5.7 kW on a planet, a reviewer)
            "power_kW": 0.0 if name in idlers else b.power / 1e3,
            "mass_kg": b.mass,
            "polar_inertia_kgm2": b.polar_inertia,
            "mass_computed": b.mass_computed,
            "inertia_computed": b.inertia_computed,
            "computed_from": (mass_basis(model.gears[name]) if name in model.gears
                              and (b.mass_computed or b.inertia_computed) else None),
            "position_mm": [1e3 * float(v) for v in b.position],
            "position_computed": name in kin.positions_computed,
            "idler": name in idlers,
            "role": roles.get(name, ""),
        }
    meshes = {}
    for name, mk in kin.meshes.items():
        turning = mk.carrier if mk.carrier and kin.bodies[mk.carrier].speed else None
        meshes[name] = {
            # the frame of the driving flank, the frequency and the power: a turning
            # carrier's for the meshes of its planets (speeds relative to it)
            "frame": frame_label(turning),
            "driver": mk.driver,
            "driven": mk.driven,
            "stage": stages[name],
            "frequency_Hz": mk.frequency,
            "base_radii_mm": [1e3 * r for r in mk.base_radii],
            "pitch_radii_mm": [1e3 * r for r in mk.pitch_radii],
            "transverse_contact_ratio": _num(mk.transverse_contact_ratio),
            "overlap_contact_ratio": _num(mk.overlap_contact_ratio),
            "total_contact_ratio": _num(mk.total_contact_ratio),
            "working_pressure_angle_deg": math.degrees(mk.working_pressure_angle),
            "center_distance_mm": _num(1e3 * mk.center_distance),
            "line_of_action": [float(v) for v in mk.line_of_action],
            "torque_driver_Nm": mk.torque_driver,
            "torque_driven_Nm": mk.torque_driven,
            "tooth_force_N": mk.force,
            # its axial component on the driver (a helical mesh's thrust on the bearings)
            "axial_force_N": mk.force * abs(float(
                np.asarray(mk.line_of_action) @ _unit(kin.bodies[mk.driver].axis))),
            "power_kW": mk.power / 1e3,
            "equivalent_mass_kg": mk.equivalent_mass,
            "critical_damping_Ns_per_m": mk.critical_damping,
            "iso6336_stiffness_N_per_m": mk.iso_stiffness,
        }
    return {
        "model": model.model.name,
        "description": model.model.description,
        "reference": model.model.reference,
        "input_power_kW": kin.input_power / 1e3,
        "output_power_kW": kin.output_power / 1e3,
        "power_balance": (kin.input_power - kin.output_power) / kin.input_power,
        "drive_torques_Nm": kin.drive_torques,
        "load_torques_Nm": kin.load_torques,
        "accepted_warnings": [{"field": a.field, "reason": a.reason}
                              for a in model.model.accepted_warnings],
        "bodies": bodies,
        "meshes": meshes,
    }


def _idlers(model) -> set[str]:
    """Gears that only pass torque from one mesh to another (an idler, a simple planet):
    no drive, load, torsional support, shaft or spline on them, and two meshes or more.
    Their net torque is zero; ``torque_Nm`` is the torque of one mesh on them."""
    ends = {d.body for d in model.drives.values()} | {ld.body for ld in model.loads.values()}
    for part in (*model.shafts.values(), *model.splines.values()):
        ends.update(part.connects)
    count: dict[str, int] = {}
    for m in model.meshes.values():
        for g in m.gears:
            count[g] = count.get(g, 0) + 1
    return {name for name, g in model.gears.items() if name not in ends
            and g.torsional_support is None and count.get(name, 0) >= 2}


def _roles(model) -> dict[str, str]:
    """What a body's torque is (the torques are magnitudes: a reviewer could not tell the
    input of a star stage from its output and its reaction): ``input`` where a drive
    acts, ``output`` where a load does, ``reaction`` where a torsional support holds it."""
    out = {d.body: "input" for d in model.drives.values()}
    out.update({ld.body: "output" for ld in model.loads.values()})
    for items in (model.gears, getattr(model, "bodies", {})):
        for name, item in items.items():
            if getattr(item, "torsional_support", None) is not None and name not in out:
                out[name] = "reaction"
    return out


def _num(x):
    return None if x is None or not math.isfinite(x) else float(x)


def render_summary(s: dict, console) -> None:
    """Print the summary as rich tables (units in every header)."""
    from rich.markup import escape
    from torquesplit._table import Table

    console.print(f"[bold]{escape(s['model'])}[/]  {escape(s['description'])}")
    if s["reference"]:
        console.print(f"[dim]{escape(s['reference'])}[/]")
    # (in - out) / in: round-off printed as '0' (it read 'balance -1.37e-16' without a
    # unit, an LTCA reviewer)
    pb = s["power_balance"]
    balance = "0" if abs(pb) < 1e-9 else f"{100 * pb:.2g} %"
    console.print(
        f"input {s['input_power_kW']:.6g} kW, output {s['output_power_kW']:.6g} kW, "
        f"balance (input - output) / input: {balance}", highlight=False)
    planets = any("speed_relative_to_carrier_rpm" in b for b in s["bodies"].values())
    t = Table(title="bodies ((computed): from the gear's geometry; (placed): from its mates"
                    + ("; speeds absolute, a planet's on its pin beside it)" if planets
                       else ")"))
    for col in ("body", "speed [rpm]", "torque [N m]", "mass [kg]", "J [kg m²]",
                "position [mm]"):
        t.add_column(escape(col), justify="right" if col not in ("body", "position [mm]")
                     else "left")
    for name, b in s["bodies"].items():
        speed = f"{b['speed_rpm']:.6g}" + (
            f" ({b['speed_relative_to_carrier_rpm']:.6g} on its pin)"
            if "speed_relative_to_carrier_rpm" in b else "")
        basis = f": {b['computed_from']}" if (b.get("computed_from") or "").startswith("rim") \
            else ""
        mark = lambda flag, note="": f" (computed{note})" if flag else ""  # noqa: E731
        pos = "(" + ", ".join(f"{round(v, 4) + 0.0:.6g}" for v in b["position_mm"]) + ")"
        torque = f"{b['torque_Nm']:.6g}" + (" per mesh (idler: net 0)" if b.get("idler")
                                             else f" ({b['role']})" if b.get("role") else "")
        t.add_row(name, speed, torque,
                  (f"{b['mass_kg']:.5g}{mark(b['mass_computed'], basis)}" if b["mass_kg"]
                   else "-"),  # (a body that only turns needs no mass)
                  f"{b['polar_inertia_kgm2']:.5g}{mark(b['inertia_computed'])}",
                  pos + (" (placed)" if b["position_computed"] else ""))
    console.print(t)
    t = Table(title="meshes (eps: transverse, overlap and total contact ratios; LOA n: unit "
                    "line of action)")
    # the axial force only where a mesh has one (helical): spur gearboxes keep the width
    axial = any(m["axial_force_N"] > 1e-9 * m["tooth_force_N"] for m in s["meshes"].values())
    for col in ("mesh", "driver->driven", "stage", "f_mesh [Hz]", "r_b [mm]", "eps_a", "eps_b",
                "eps_g", "LOA n", "T_driver [N m]", "F_n [kN]") + (("F_a [kN]",) if axial
                                                                   else ()):
        t.add_column(escape(col), justify="left" if col in ("mesh", "driver->driven", "stage",
                                                            "LOA n") else "right")
    turning = sorted({m["frame"] for m in s["meshes"].values()} - {"housing"})
    for name, m in s["meshes"].items():
        fmt = lambda x: "-" if x is None else f"{x:.4f}"  # noqa: E731
        mark = " *" if m["frame"] != "housing" else ""
        t.add_row(name, f"{m['driver']}->{m['driven']}{mark}", m["stage"],
                  f"{m['frequency_Hz']:.6g}",
                  "/".join(f"{r:.2f}" for r in m["base_radii_mm"]),
                  fmt(m["transverse_contact_ratio"]), fmt(m["overlap_contact_ratio"]),
                  fmt(m["total_contact_ratio"]),
                  "(" + ", ".join(f"{v:+.3f}" for v in m["line_of_action"]) + ")",
                  f"{m['torque_driver_Nm']:.6g}", f"{m['tooth_force_N'] / 1e3:.5g}",
                  *([f"{m['axial_force_N'] / 1e3:.5g}"] if axial else []))
    console.print(t)
    if turning:  # (a sun read as an output: its mesh's driver is the planet there)
        console.print(
            f"* in the frame {', '.join(turning)}: the driving flank and the mesh "
            f"frequency are those the teeth see, with speeds relative to the carrier (the "
            f"bodies table's speeds and torques give the power flow in the housing's frame)",
            highlight=False)
    for a in s.get("accepted_warnings", ()):  # (the file's own, with its reason)
        console.print(f"accepted warning: {escape(a['field'])} ({escape(a['reason'])})",
                      highlight=False)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)

