"""Run each paper's study on its example model and collect the numbers the paper
reports, for docs/validation.md.

    python scripts/validate.py [liu2021 ji_li ...] [--quick]
    python scripts/render_docs.py      # then docs/validation.md from the numbers

Writes docs/validation_results.json (one entry per paper, with the commit and the
machine it ran on) and prints a summary.  The settings are the papers' where they give
them (see each example's [analysis] section and the comments in the model files);
nothing is tuned to a published number.  Every dynamic run is repeated with half the
step (and 4x the table points where the tables have jumps, as ``--check-step`` does): the
largest change of any reported metric is stored beside it (``halved``), so a
number is only published with the evidence that it does not move.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import torquesplit
from torquesplit.convergence import check_model, halved_steps_per_period
from torquesplit.errors import ModelWarning
from torquesplit.model.io import model_from_dict
from torquesplit.model.overrides import apply_overrides, read_raw
from torquesplit.quasistatic import quasi_static_load_sharing

OUT = Path(__file__).resolve().parents[1] / "docs" / "validation_results.json"


def _model(name: str, overrides: dict | None = None):
    data = read_raw(torquesplit.example_path(name))
    if overrides:
        data = apply_overrides(data, overrides)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return torquesplit.load_model(model_from_dict(data, source=name))


def _run(model, **kwargs) -> dict:
    t0 = time.perf_counter()
    res = torquesplit.simulate(model, **kwargs)
    wall = time.perf_counter() - t0
    values = res.metric_values()
    out = {"wall_time_s": wall, "statistics": res.statistics(), "values": values,
           "settled": bool(res.metrics().settling.settled),
           "warnings": res.warnings()}  # (as the command line prints them)
    for definition in ("cycle_peak", "engineering", "mean_force"):
        out[definition] = res.metrics(definition).to_dict()
    # the same run with half the step it took (not half the step it asked for: a stiff
    # damping may have set a finer one), and 4x the table points where the tables have
    # jumps (as --check-step does): how far every reported number moves
    kwargs.pop("steps_per_period", None)
    spp = halved_steps_per_period(res)
    check, n, n_check = check_model(res)
    half = torquesplit.simulate(check, steps_per_period=spp, **kwargs).metric_values()
    change = {k: abs(half[k] - v) for k, v in values.items()
              if k in half and math.isfinite(v) and math.isfinite(half[k])
              and k.startswith(("load_sharing", "dynamic_factor", "peak_to_nominal"))}
    worst = max(change, key=change.get) if change else ""
    mean = [v for k, v in change.items() if k.startswith("load_sharing.mean_force")]
    out["halved"] = {"steps_per_period": spp, "table_points": n, "check_table_points": n_check,
                     "max_change": change.get(worst, 0.0),
                     "worst": worst, "change": change,
                     # (the halved run's own values: a number whose rounding flips has a
                     # last digit that does not hold, however small the change)
                     "value": {k: half[k] for k in change},
                     "max_change_mean_force": max(mean, default=0.0)}
    return out


def _provenance() -> dict:
    """Which code and machine produced the numbers."""
    import platform
    import subprocess

    root = Path(__file__).resolve().parents[1]

    def git(*args):
        try:
            return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True,
                                  check=True).stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            return ""

    dirty = bool(git("status", "--porcelain", "--untracked-files=no", "src"))
    return {"commit": git("rev-parse", "--short", "HEAD") + (" (with uncommitted changes "
                                                             "in src)" if dirty else ""),
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "torquesplit": torquesplit.__version__, "python": platform.python_version(),
            "machine": platform.machine(), "cpu_count": __import__("os").cpu_count()}


def liu2021(quick: bool) -> dict:
    """Per-cycle peak LSC and DLF of the left path, with and without meshing-in impact."""
    cycles = 200 if quick else None  # None: the example's [analysis] (2000 third-stage cycles)
    names = [m for m in read_raw(torquesplit.example_path("liu2021_split_torque_helicopter"))["meshes"]]
    results = {}
    for label, impact in (("no_impact", False), ("impact", True)):
        over = {f"meshes.{m}.impact": impact for m in names if not m.endswith("12")}
        results[label] = _run(_model("liu2021_split_torque_helicopter", over), cycles=cycles)
    # the natural frequencies next to the double-helical input stage's mesh frequency
    # (the text says which modes its high dynamic factors sit near)
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.modes import model_modes

    model = _model("liu2021_split_torque_helicopter")
    f_mesh = solve_kinematics(model).meshes["L34"].frequency
    freqs = np.array([r.frequency for r in model_modes(model).rows])
    results["modes_near_L34"] = {
        "mesh_frequency": float(f_mesh),
        "below": float(freqs[freqs < f_mesh].max()) if (freqs < f_mesh).any() else None,
        "above": float(freqs[freqs > f_mesh].min()) if (freqs > f_mesh).any() else None,
        "group_below_from": (float(freqs[near].min()) if (
            near := (freqs < f_mesh) & (freqs > 0.8 * f_mesh)).any() else None),
    }
    return results


def ji_li(quick: bool) -> dict:
    """g1t, g2t, G1t, G2t at drive-shaft diameters 200, 250 and 300 mm."""
    out = {}
    for d in ("200 mm", "250 mm", "300 mm"):
        over = {"shafts.drive1.diameter": d, "shafts.drive2.diameter": d}
        for g in ("z2", "z3", "z4", "z5"):
            over[f"gears.{g}.support.shaft.diameter"] = d
        kwargs = {"duration": 3.0} if quick else {}
        out[d] = _run(_model("ji_li_mill_drive", over), **kwargs)
    return out


def dong2021(quick: bool) -> dict:
    """Omega_I, Omega_II and every Omega_ij (mean-force definition, Dong et al. 2021 eq. 12),
    and how the mean-force coefficients drift: over each half of the settled part, and
    over a run twice as long (the run does not settle)."""
    from torquesplit.results.plausibility import mean_force_halves

    out = {"baseline": _run(_model("dong2021_face_gear"), cycles=100 if quick else None)}
    res = torquesplit.simulate(_model("dong2021_face_gear"), cycles=100 if quick else None)
    met = res.metrics("mean_force")
    halves = mean_force_halves(res, met)
    # the group whose halves differ most: the one the run's warning names
    g = max(halves, key=lambda k: abs(halves[k][1] - halves[k][0]))
    longer = torquesplit.simulate(_model("dong2021_face_gear"),
                                  **({"cycles": 200} if quick else {"duration": 2.4}))
    long_met = longer.metrics("mean_force")
    out["drift"] = {"group": g, "whole": met.load_sharing.per_group[g],
                    "first": halves[g][0], "second": halves[g][1],
                    "change": abs(halves[g][1] - halves[g][0]),
                    "stage1_change": max((abs(b - a) for k, (a, b) in halves.items()
                                          if k.endswith("_I") or "/I_" in k or k == "I"),
                                         default=float("nan")),
                    "long_duration_s": longer.solution.t_final - longer.solution.t_span[0],
                    "long_settled": bool(long_met.settling.settled),
                    "long_state": ("settled" if long_met.settling.settled
                                   else "still not settled"),
                    "long": long_met.load_sharing.per_group[g]}
    # how far a change at the last digit of one input moves the coefficients: the
    # response is sensitive to it (impacts in the clearances), so differences between
    # study cases below this are noise (a reviewer: 1 ulp of a spline clearance moved
    # Omega_II in its 4th decimal)
    base_c = float(np.nextafter(_model("dong2021_face_gear").splines["spline4"].radial_clearance,
                                1.0))
    nudged = torquesplit.simulate(
        _model("dong2021_face_gear", {"splines.spline4.radial_clearance": base_c}),
        cycles=100 if quick else None).metrics("mean_force").load_sharing.per_group
    out["ulp"] = {"what": "splines.spline4.radial_clearance, one ulp larger",
                  "change": max(abs(nudged[k] - met.load_sharing.per_group[k])
                                for k in nudged),
                  "group": max(nudged, key=lambda k: abs(nudged[k]
                                                         - met.load_sharing.per_group[k]))}
    out["settings"] = _dong2021_settings(quick)
    return out


# (spline_velocity_scale [mm/s], steps per stage-I mesh period): the reference first, the
# settings the example used until 2026-11-29 second, then coarser and finer neighbours of
# the example's (5 mm/s, 50)
DONG_SETTINGS = ((1, 800), (1, 100), (1, 400), (2, 100), (5, 100), (5, 50), (5, 35),
                 (10, 50))


def _dong2021_settings(quick: bool) -> dict:
    """The numerical settings of the Dong et al. 2021 example against a fine reference:
    each setting's step, wall time and largest change of a mean-force coefficient (eq.
    12) from the reference run; and how fast the splines slide radially at the
    example's settings (the regularised friction acts as a radial damping below its
    velocity scale)."""
    from torquesplit.assembly.structure import SPLINE

    kwargs = {"cycles": 100} if quick else {}
    rows, ref = {}, None
    for v, spp in DONG_SETTINGS:
        model = _model("dong2021_face_gear", {"analysis.spline_velocity_scale": v * 1e-3})
        t0 = time.perf_counter()
        res = torquesplit.simulate(model, steps_per_period=spp, **kwargs)
        wall = time.perf_counter() - t0
        coef = res.metrics("mean_force").load_sharing.per_group
        ref = ref or coef
        worst = max(coef, key=lambda k: abs(coef[k] - ref[k]))
        rows[f"v{v}_n{spp}"] = {"velocity_scale_mm_s": v, "steps_per_period": spp,
                                "step_s": res.solution.step, "wall_time_s": wall,
                                "steps": int(res.solution.n_steps),
                                "max_change": abs(coef[worst] - ref[worst]),
                                "worst": worst, "values": coef}
    # radial sliding speed of each spline over the second half of a run at the
    # example's settings, sampled 20 times a stage-I mesh period
    model = _model("dong2021_face_gear")
    names = list(torquesplit.assemble(model).dof_names)
    res = torquesplit.simulate(model, samples_per_period=20, history_dofs=names, **kwargs)
    s, sol = res.structure, res.solution
    p = s.projection_matrix()
    half = sol.history_q.shape[0] // 2
    q, v = sol.history_q[half:], sol.history_v[half:]
    scale = model.analysis.spline_velocity_scale
    slide = {}
    comps = [e for e, k in enumerate(s.element_kind) if k == SPLINE]
    for a, b in zip(comps[::2], comps[1::2], strict=True):
        dx, dy, rx, ry = q @ p[a], q @ p[b], v @ p[a], v @ p[b]
        r = np.hypot(dx, dy)
        speed = np.abs(dx * rx + dy * ry) / np.maximum(r, 1e-30)
        slide[s.element_names[a].split(".")[0]] = {
            "median_mm_s": float(np.median(speed)) * 1e3,
            "p99_mm_s": float(np.percentile(speed, 99)) * 1e3,
            "below_scale": float(np.mean(speed < scale)),
            "radius_um": float(np.median(r)) * 1e6}
    far = max(rows, key=lambda k: rows[k]["max_change"])
    return {"rows": rows, "velocity_scale_mm_s": scale * 1e3, "sliding": slide,
            "largest_change": rows[far]["max_change"], "largest_at": far}


def jin2019(quick: bool) -> dict:
    """Mesh forces with tooth friction for RMS roughness 0.3, 0.6 and 0.9 um."""
    data = read_raw(torquesplit.example_path("jin2019_friction_split"))
    from torquesplit.assembly.excitation import friction_table

    out = {}
    for s in ("0.3 um", "0.6 um", "0.9 um"):
        over = {f"meshes.{m}.friction": {"roughness": s}
                for m, v in data["meshes"].items() if v.get("friction")}
        model = _model("jin2019_friction_split", over)
        out[s] = _run(model, cycles=100 if quick else None)
        # friction force over one mesh cycle at the nominal load (the tables the
        # dynamic model uses), a spur split mesh and a herringbone mesh of the right path
        kin = torquesplit.solve_kinematics(model)
        for mesh in ("Rp1s", "RB1h"):
            force = friction_table(model, kin, mesh, 256)[0] * kin.meshes[mesh].force
            out[s][f"friction_{mesh}_N"] = [float(force.min()), float(force.max())]
    return out


def mo2017(quick: bool) -> dict:
    """Quasi-static star load-sharing coefficients and the suns' floating orbits, over
    the errors' common period (the default sweep), and how far the coefficients move
    when the positions are doubled."""
    ppc = 2 if quick else 32
    t0 = time.perf_counter()
    res = quasi_static_load_sharing(_model("mo2017_star_reducer"), points_per_cycle=ppc)
    met = res.metrics()
    wall = time.perf_counter() - t0
    fine = quasi_static_load_sharing(_model("mo2017_star_reducer"), points_per_cycle=2 * ppc,
                                     max_points=10**6).metrics()
    kin = res.kinematics
    slowest = min(abs(v) for mk in kin.meshes.values()
                  for v in (mk.driver_speed, mk.driven_speed) if v)
    span = float(res.times[-1] + (res.times[1] - res.times[0]))
    orbits = {b: {"x_um": [1e6 * float(o[:, 0].min()), 1e6 * float(o[:, 0].max())],
                  "y_um": [1e6 * float(o[:, 1].min()), 1e6 * float(o[:, 1].max())]}
              for b, o in res.orbits().items() if b in ("s1", "s2")}
    return {"per_mesh": met.per_mesh, "per_group": met.per_group, "system": met.system,
            "orbits": orbits, "positions": int(res.times.size),
            "points_per_cycle": ppc, "revolutions": span * slowest / (2 * math.pi),
            "wall_time_s": wall,
            "doubled_positions_change": max(abs(fine.per_mesh[m] - v)
                                            for m, v in met.per_mesh.items()),
            "converged": bool(res.solution.converged.all())}


def kinematics(quick: bool) -> dict:
    """The exact (non-dynamic) quantities each paper prints: contact ratio, speeds,
    torques, mesh frequencies, from the shipped models' kinematics."""
    rpm = 3.141592653589793 / 30

    def kin(name):
        return torquesplit.solve_kinematics(_model(name))

    k0, k1, k2, k4 = (kin(n) for n in ("liu2021_split_torque_helicopter", "ji_li_mill_drive",
                                       "dong2021_face_gear", "mo2017_star_reducer"))
    return {
        "liu2021": {"contact_ratio_dh": k0.meshes["L78"].total_contact_ratio,
                    "speed_spur_pinion_rpm": abs(k0.bodies["L3"].speed) / rpm,
                    "speed_dh_pinion_rpm": abs(k0.bodies["L7"].speed) / rpm,
                    "design_load_Nm": k0.meshes["L78"].torque_driven},
        "ji_li": {"f_mesh1_Hz": k1.meshes["m11"].frequency,
                    "f_mesh2_Hz": k1.meshes["m12"].frequency},
        "dong2021": {"input_torque_Nm": k2.drive_torques["engine"],
                    "idler_torque_Nm": k2.bodies["O6"].torque},
        "mo2017": {"input_torque_Nm": k4.drive_torques["turbine"],
                    "path_torque_Nm": k4.meshes["s1p11"].torque_driver,
                    "star_shaft_torque_Nm": k4.bodies["p11"].torque,
                    "output_torque_Nm": k4.load_torques["output"]},
    }


STUDIES = {"kinematics": kinematics, "liu2021": liu2021, "ji_li": ji_li, "dong2021": dong2021, "jin2019": jin2019,
           "mo2017": mo2017}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("papers", nargs="*", default=list(STUDIES))
    ap.add_argument("--quick", action="store_true", help="shorter runs (smoke test)")
    args = ap.parse_args(argv)
    old = json.loads(OUT.read_text()) if OUT.exists() else {}
    old["provenance"] = _provenance()
    for seed in args.papers:
        t0 = time.perf_counter()
        try:
            old[seed] = STUDIES[seed](args.quick)
        except torquesplit.TorquesplitError as exc:
            old[seed] = {"error": str(exc)}
        old[seed + "_wall_time_s"] = time.perf_counter() - t0
        print(f"{seed}: done in {time.perf_counter() - t0:.1f} s", flush=True)
        OUT.write_text(json.dumps(old, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
