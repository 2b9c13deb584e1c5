"""Speed of planetary stages: the cost of the rotating-frame terms per RK4 step.

Runnable alone (``python benchmarks/bench_planetary.py [--quick]``); writes
``benchmarks/PLANETARY_RESULTS.md`` and ``.json``.  Cases, each run with the engine's
default (generated) right-hand side and the general kernel, best of ``--repeat``:

* the Lin & Parker 1999 example with 3 and 4 planets (18 and 21 DOFs: x, y, theta of sun,
  ring, carrier and every planet), with the turning carrier's frame (Coriolis matrix,
  centripetal springs, pin preload) and without it (``rotating_frame=False``: the same
  model in a stationary frame) -- their ratio is the cost of the rotating-frame terms;
* the generated 2- and 4-branch split models of ``models.py`` (20 and 32 DOFs), the
  split models the design targets compare ns per DOF per step with;
* the shipped examples of the five power-split papers (14 to 52 DOFs), run the same way,
  for the same comparison with the split gearboxes users model.

Design targets: ns per DOF per step of the planetary no worse than the split
models'; rotating-frame terms < 15 % per step.  Nothing is asserted; the ratios are
printed beside the targets.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))


SPLIT_EXAMPLES = ("ji_li_mill_drive", "liu2021_split_torque_helicopter", "dong2021_face_gear",
                  "jin2019_friction_split", "mo2017_star_reducer")
"""The shipped examples of the five power-split papers."""


def _planetary_case(planets: int, rotating: bool):
    import copy

    import torquesplit
    from bench_engine import Case
    from torquesplit.model.reader import read_model_file
    from torquesplit.solve.static import static_equilibrium

    data = copy.deepcopy(read_model_file(torquesplit.example_path("lin_parker1999_planetary")))
    data["planetary"][0]["planets"] = planets
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", torquesplit.ModelWarning)
        model = torquesplit.load_model(data)
    from torquesplit.assembly.assemble import assemble

    s = assemble(model, options={"rotating_frame": rotating})
    st = static_equilibrium(s)
    label = f"Lin & Parker 1999, N={planets}, " + ("turning frame" if rotating else
                                                    "stationary frame")
    return Case(name=label, structure=s, y0=st.y0, f_max=float(s.frequency.max()),
                static_converged=bool(st.converged))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="50,000 steps instead of 400,000")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--output", type=Path, default=HERE / "PLANETARY_RESULTS.md")
    args = ap.parse_args(argv)
    from bench_engine import example_cases, split_cases, time_rk4

    import torquesplit

    n_steps = 50_000 if args.quick else 400_000
    t0 = time.time()
    load0 = os.getloadavg()
    cases = []
    for planets in (3, 4):
        for rotating in (True, False):
            cases.append(_planetary_case(planets, rotating))
    cases += split_cases((2, 4))
    shipped, skipped = example_cases(SPLIT_EXAMPLES)
    cases += shipped
    rows = []
    for case in cases:
        print(f"timing {case.name} ...", file=sys.stderr)
        row = time_rk4(case, n_steps, repeat=args.repeat)
        # the right-hand side's work is a product with the element projections: a
        # planetary mesh couples x, y and theta of two bodies (6 entries), a torsional
        # split mesh two angles
        row["nnz_projection"] = int((case.structure.projection_matrix() != 0).sum())
        row["time_varying_tables"] = int(
            (case.structure.stiffness_table.max(axis=1)
             > case.structure.stiffness_table.min(axis=1)).sum())
        rows.append(row)
    load1 = os.getloadavg()
    by = {r["model"]: r for r in rows}
    ratios = {}
    for planets in (3, 4):
        turning = by[f"Lin & Parker 1999, N={planets}, turning frame"]
        still = by[f"Lin & Parker 1999, N={planets}, stationary frame"]
        ratios[planets] = {
            "wall": turning["us_per_step"] / still["us_per_step"],
            "cpu": turning["cpu_us_per_step"] / still["cpu_us_per_step"],
            "general_wall": turning["general_us_per_step"] / still["general_us_per_step"]}
    split_ns = min(r["cpu_us_per_step"] / r["n_dof"] * 1e3 for r in rows
                   if r["model"].startswith("split"))
    split_nnz = min(r["cpu_us_per_step"] / r["nnz_projection"] * 1e3 for r in rows
                    if r["model"].startswith("split"))
    papers = [r for r in rows if r["model"] in SPLIT_EXAMPLES]
    paper_ns = min((r["cpu_us_per_step"] / r["n_dof"] * 1e3, r["model"]) for r in papers) \
        if papers else None
    lines = ["# Planetary stages: speed of the rotating-frame terms", "",
             f"Produced by `python benchmarks/bench_planetary.py{' --quick' if args.quick else ''}`"
             f" in {time.time() - t0:.0f} s; {n_steps:,} RK4 steps per case, 100 per mesh "
             f"period, best of {args.repeat}; load average {load0[0]:.2f} at start, "
             f"{load1[0]:.2f} at end (2 cores shared: the CPU columns are the steadier).",
             f"torquesplit {getattr(torquesplit, '__version__', '')}",
             "", "'projection non-zeros' counts the entries of the element projections "
             "V (the right-hand side's work is f = V^T k(V q)): a planetary mesh couples x, "
             "y and theta of two bodies, a torsional split mesh two angles.  'tables' counts "
             "the elements with a time-varying stiffness (Lin & Parker's benchmark has "
             "constant mesh stiffness).", "",
             "| model | DOFs | elements | projection non-zeros | tables | gyroscopic entries "
             "| µs/step | CPU µs/step | ns/step/DOF (CPU) | ns/step per non-zero (CPU) | "
             "general µs/step | rhs |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, r in zip(cases, rows):
        lines.append(
            f"| {r['model']} | {r['n_dof']} | {r['n_elements']} | {r['nnz_projection']} | "
            f"{r['time_varying_tables']} | "
            f"{case.structure.n_gyroscopic} | {r['us_per_step']:.3g} | "
            f"{r['cpu_us_per_step']:.3g} | {r['cpu_us_per_step'] / r['n_dof'] * 1e3:.3g} | "
            f"{r['cpu_us_per_step'] / r['nnz_projection'] * 1e3:.3g} | "
            f"{r['general_us_per_step']:.3g} | {r['rhs']} |")
    lines += ["", "## Design targets", "", "| quantity | target | measured |", "|---|---|---|"]
    for planets, rr in ratios.items():
        lines.append(f"| rotating-frame terms, cost per step, N = {planets} (turning / "
                     f"stationary frame) | < 1.15 | {rr['cpu']:.3f} (CPU), {rr['wall']:.3f} "
                     f"(wall); general kernel {rr['general_wall']:.3f} |")
    for planets in (3, 4):
        r = by[f"Lin & Parker 1999, N={planets}, turning frame"]
        lines.append(f"| ns per DOF per step, N = {planets} turning frame, against the best "
                     f"split model ({split_ns:.3g}) | no worse | "
                     f"{r['cpu_us_per_step'] / r['n_dof'] * 1e3:.3g} |")
    for planets in (3, 4):
        if paper_ns is None:
            break
        r = by[f"Lin & Parker 1999, N={planets}, turning frame"]
        lines.append(f"| ns per DOF per step, N = {planets} turning frame, against the best "
                     f"shipped power-split example ({paper_ns[1]}, {paper_ns[0]:.3g}) | no "
                     f"worse | {r['cpu_us_per_step'] / r['n_dof'] * 1e3:.3g} |")
    for planets in (3, 4):
        r = by[f"Lin & Parker 1999, N={planets}, turning frame"]
        lines.append(f"| ns per projection non-zero per step, N = {planets} turning frame, "
                     f"against the best split model ({split_nnz:.3g}) | no worse (per unit of "
                     f"right-hand-side work) | "
                     f"{r['cpu_us_per_step'] / r['nnz_projection'] * 1e3:.3g} |")
    if skipped:
        lines += ["", "Not measured: " + "; ".join(f"{k} ({v})" for k, v in skipped.items())]
    text = "\n".join(lines) + "\n"
    args.output.write_text(text, encoding="utf-8")
    args.output.with_suffix(".json").write_text(json.dumps(
        {"rows": [{k: v for k, v in r.items() if k != "sol"} for r in rows],
         "rotating_frame_cost": ratios, "load_average": [load0, load1]}, indent=2,
        default=float), encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
