"""Run the papers' shipped studies and put their curves beside what the papers state.

    python scripts/study_validation.py                 # run (resumable) and write the docs
    python scripts/study_validation.py --no-run        # only rewrite the docs from results
    python scripts/study_validation.py ji_li_diameter  # some studies only

Results go to ``--results`` (default ``study_results/``, one folder per study, resumable
with the same command).  Writes ``docs/studies_validation.json`` (every number) and
``docs/studies_validation.md`` (tables, the paper's statements, the comparison).  The
numbers in the Markdown come from the JSON, never typed by hand; the paper's statements
below are quoted from the text (figures are missing from the extracted papers).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = ROOT / "docs" / "studies_validation.json"
OUT_MD = ROOT / "docs" / "studies_validation.md"

# What each paper states about the study's curve (quoted or closely paraphrased from the
# text; Fig. numbers are the papers').
PAPER = {
    "ji_li_diameter": [
        "Fig. 23: the g_it-d relation (i = 1, 2) fits a fourth-order polynomial, R^2 >= "
        "0.998; below d = 150 mm the load distribution coefficient changes slowly; within a "
        "certain range, reducing d effectively improves the load sharing.",
        "Fig. 24: for d < 280 mm the engineering dynamic load coefficient fluctuates "
        "significantly (primary and secondary bend-torsion resonances).",
        "No value of g_it or G_it is printed.",
    ],
    "ji_li_inertia": [
        "Fig. 26: as J2 decreases, the G2t-d curve shifts to the left and its peaks "
        "decrease; at d of about 285 mm, reducing J2 by 6 % keeps G2 within 1.05.",
    ],
    "dong_2021_installation_error": [
        "Fig. 12a-b, 0-50 um: Omega_I 1.0003-1.0049, Omega_II 1.0001-1.1605; installation "
        "errors matter little for stage I and much for stage II.",
    ],
    "dong_2021_eccentricity_error": [
        "Fig. 12c-d, 0-50 um: Omega_I 1.0005-1.0125, Omega_II 1.0005-1.1160.",
    ],
    "dong_2021_backlash_stage1": [
        "Fig. 13: with growing one-stage backlash Omega_I falls 1.121 -> 1.016; Omega_II "
        "changes little, 1.088 -> 1.075 (backlash range not printed).",
    ],
    "dong_2021_backlash_stage2": [
        "Fig. 13: with growing two-stage backlash Omega_II falls 1.268 -> 1.021; Omega_I "
        "1.045 -> 1.035 (backlash range not printed).",
    ],
    "dong_2021_support_clearance": [
        "Fig. 14: one-stage support clearance: Omega_I 1.0402 -> 1.0341, Omega_II 1.0870 -> "
        "1.0842; two-stage support clearance: Omega_I 1.0408 -> 1.0297, Omega_II 1.0879 -> "
        "1.0801 (clearance range not printed): small influence.",
    ],
    "dong_2021_spline_clearance": [
        "Fig. 15, 0-450 um: Omega_I stays 1.0383; Omega_II 1.0921 -> 1.012, stable at 1.012 "
        "once both pinions float fully (beyond 0.382 mm).",
    ],
    "dong_2021_io_shaft_stiffness": [
        "Fig. 16, (0.5-10) x 10^7 N mm/rad: the input and output shafts have almost no "
        "influence on the load sharing.",
    ],
    "dong_2021_quill_stiffness": [
        "Fig. 17, (0.5-10) x 10^6 N mm/rad: the coefficients grow with the connecting-shaft "
        "stiffness, more in stage II than in stage I.",
    ],
    "dong_2021_support_stiffness": [
        "Fig. 18: with the support stiffness factor falling 0.5 -> 0.05, Omega_II rises "
        "1.0763 -> 1.2714, Omega_I only 1.0381 -> 1.0397.",
    ],
    "dong_2021_sensitivity": [
        "Abstract and section 6: two-stage backlash and two-stage errors are the most "
        "sensitive factors; support clearance has little influence; torsional stiffness "
        "matters little for stage I but much for stage II; support stiffness acts mainly on "
        "stage II.",
    ],
    "mo_2017_errors": [
        "Section 6, every error 6 um: path coefficients 1.0179, 1.0136, 1.0619; system "
        "1.0619.",
    ],
    "mo_2017_tolerance_monte_carlo": [
        "Not in the paper: a tolerance study built on its error case (ISO 1328 grade-5 "
        "eccentricities, random phases).",
    ],
}


# What our curve shows and why it differs (qualitative: every number is in the tables,
# which come from the runs).
OURS = {
    "ji_li_diameter": (
        "Flat: the example is symmetric and error-free (the paper prints no error values, "
        "only grade 5) and uses the constant mid-band backlash, so both branches carry the "
        "same load whatever the shaft compliance; g1t > 1 comes only from the half-cycle "
        "phase shift of the two stage-1 meshes, and G2t moves by a few tenths of a per cent "
        "where the drive-shaft modes cross the stage-2 excitation.  Shaft compliance "
        "redistributes load only when the branches are excited differently - in the paper "
        "by the random per-engagement backlash of eq. 14, which taken literally opens the "
        "meshes (docs/validation.md).  The paper's trend is neither reproduced nor "
        "contradicted."),
    "ji_li_inertia": (
        "No visible effect of J2, for the reason given for the diameter study: nothing in "
        "the symmetric example makes the branches differ."),
    "dong_2021_installation_error": (
        "No effect: the example gives every installation error the same direction (0 deg; "
        "the paper prints no phases), so the constant line-of-action offsets are the same on "
        "both branches of each split and cancel in the locked loop.  The paper's growth "
        "needs directions that differ between branches, which it does not print."),
    "dong_2021_eccentricity_error": (
        "Omega_II grows with the eccentricity, as in the paper, to a similar size; Omega_I "
        "stays at the value set by the unequal connecting-shaft stiffnesses printed in "
        "Table 2 (k_24 != k_35, docs/validation.md), which no error changes."),
    "dong_2021_backlash_stage1": (
        "Almost no effect, unlike the paper: with the example's assumed damping the face-gear "
        "meshes stay in contact nearly all the time, so their backlash is rarely reached."),
    "dong_2021_backlash_stage2": (
        "Almost no effect, unlike the paper, although the herringbone meshes lose contact "
        "for a few per cent of the time: the mean-force coefficient (eq. 12) averages over "
        "the separations."),
    "dong_2021_support_clearance": (
        "The one-stage clearance has almost no influence, as in the paper.  The two-stage "
        "clearance (idlers and output gear) raises Omega_II strongly here, where the paper "
        "reports a small decrease: with the example's stiff bearings the clearance is the "
        "largest compliance of the idler supports, and clearances that open differently on "
        "the two branches shift load between them."),
    "dong_2021_spline_clearance": (
        "The paper's trend: Omega_II falls as the clearance lets the pinions float, and "
        "flattens near 1 once they float freely; Omega_I does not change (at the value set "
        "by the quill stiffnesses)."),
    "dong_2021_io_shaft_stiffness": (
        "Almost no influence, as in the paper."),
    "dong_2021_quill_stiffness": (
        "Omega_I follows the ratio of the two connecting-shaft stiffnesses: equal to 1 "
        "where k_24 equals the printed k_35, growing on both sides of it.  Omega_II falls "
        "slowly as k_24 grows, opposite to the paper."),
    "dong_2021_support_stiffness": (
        "The paper's trend: Omega_II grows as the supports soften, most below a factor 0.5, "
        "while Omega_I does not change; the growth is smaller than the paper's."),
    "dong_2021_sensitivity": (
        "The stage-II coefficients are driven first by the spline and support clearances "
        "and the eccentricity errors (stage I: below; the quill-stiffness study shows how "
        "Omega_I follows the ratio of the two connecting-shaft stiffnesses).  The "
        "paper names the two-stage backlash and errors; here the backlash ranks low (see "
        "the backlash studies).  The system coefficient is the largest group's, which in "
        "this model is stage I except where a stage-II group exceeds it, so it reacts only "
        "to large changes."),
    "mo_2017_errors": (
        "The coefficients grow linearly with the error magnitude from exactly 1 without "
        "errors; at the paper's 6 um they are of the paper's size but not its values, "
        "because the paper's mapping of each error onto the meshes (its section 4, with "
        "the figures) is lost (docs/validation.md)."),
    "mo_2017_tolerance_monte_carlo": (
        "With grade-5 eccentricities in random directions the system coefficient spreads "
        "over about a per cent around its mean; the stopping rule ended the sampling "
        "when the mean was known to +/-0.001."),
}

#: a case's warning that the top of the page (the Dong et al. 2021 runs) already says:
#: the run did not settle (its windows shrink below a revolution at the example's run
#: length: too short to tell; else the transient did not die out)
UNSETTLED = ("analysis: the transient did not die out",
             "analysis: the run is too short to tell whether the response has settled")


def _other_warnings(ds) -> list[list[str]]:
    """Each case's warnings but the unsettled-run note (said once, above)."""
    return [[line for line in str(w).split("\n")
             if line and not line.startswith(UNSETTLED)]
            for w in ds["warnings"].values.ravel().tolist()]


def dong_run_length() -> str:
    """Said once, above the studies of the Dong et al. 2021 example: its run does not
    settle (the numbers from docs/validation_results.json, ``scripts/validate.py``)."""
    dong = json.loads((ROOT / "docs" / "validation_results.json").read_text())["dong2021"]
    d, ulp = dong["drift"], dong["ulp"]
    return (
        "**The Dong et al. 2021 studies** (`dong_2021_*`) run every case for the example's "
        "1.21 s, which does not settle: `torquesplit run dong2021_face_gear` warns that the "
        "run is too short to tell whether the response has settled (fewer than four "
        "windows of a gear revolution) and that the "
        f"mean-force coefficient of its group "
        f"{d['group']} is {d['whole']:.2f} over the part used, {d['first']:.2f} over its "
        f"first half and {d['second']:.2f} over its second ({d['long']:.2f} with "
        f"`--duration \"2.4 s\"`; two decimals: at half the step each moves in its third; "
        f"docs/validation.md).  Their stage-II coefficients "
        f"(Omega_II) therefore depend on the run length by about {d['change']:.1f}; stage I "
        f"(Omega_I) does not drift ({d['stage1_change']:.1g}).  The differences between cases "
        "are differences at this one run length: a stage-II trend or ranking smaller than "
        "that drift may not survive a longer run.  The response is also sensitive to the "
        "last digit of its inputs (impacts in the clearances): a spline clearance one "
        f"rounding unit larger moves a mean-force coefficient by {ulp['change']:.1g} "
        f"({ulp['group']}), so differences between cases smaller than that are noise.")
#: said under each of them
DONG_SECTION = ("**Run length:** the run does not settle; Omega_II depends on the run length "
                "(by how much: see the top of this page).")


def refinement(name: str) -> dict:
    """The ``[analysis]`` of a study's refined run: half the step of a dynamic study
    (twice its steps per period), twice the mesh positions per cycle of a quasi-static
    one.  Every number on the page is printed to the digits this run reproduces."""
    from torquesplit.study import Study

    plan = Study(name).plan()
    a = plan.analysis
    if a["type"] == "static":
        return {"points_per_cycle": 2 * int(a["points_per_cycle"])}
    steps = a.get("steps_per_period") or plan.model.analysis.steps_per_period
    return {"steps_per_period": 2 * int(steps)}


def _run(names, results: Path) -> None:
    from torquesplit.study import Study

    for name in names:
        for folder, analysis in ((name, None), (f"{name}{REFINED}", refinement(name))):
            t0 = time.perf_counter()
            print(f"{folder} ...", file=sys.stderr, flush=True)
            Study(name, analysis=analysis).run(out=results / folder, resume=True,
                                               figures=analysis is None)
            print(f"{folder}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)


#: the folder suffix of a study's refined run
REFINED = "_refined"


def _num(x):
    x = float(x)
    return round(x, 6) if math.isfinite(x) else None


def collect_refined(name: str, folder: Path) -> dict:
    """The refined run's numbers (:func:`refinement`), as :func:`collect` gives them."""
    entry = collect(name, folder)
    keep = ("outputs", "ranking", "status")
    return {"analysis": refinement(name), **{k: entry[k] for k in keep if k in entry}}


def collect(name: str, folder: Path) -> dict:
    """Every number of one finished study."""
    from torquesplit.study import load_results
    from torquesplit.study.dataset import display_values

    ds = load_results(folder)
    outs = [v for v in ds.data_vars if "output" in ds[v].attrs]
    entry = {"reference": ds.attrs["reference"], "description": ds.attrs["description"],
             "design": ds.attrs["design"], "analysis": ds.attrs["analysis"],
             "cases": int(ds.attrs["cases"]),
             "status": {s: int((ds["status"].values == s).sum())
                        for s in sorted(set(ds["status"].values.ravel().tolist()))},
             "reasons": sorted({r for r in ds["reason"].values.ravel().tolist() if r})[:3],
             # the cases whose run warned (a 130 mm drive shaft bends more than half a
             # module: the page said '28 ok' without a word)
             "warned": sum(1 for w in _other_warnings(ds) if w),
             "first_warning": next((w[0] for w in _other_warnings(ds) if w), ""),
             "unsettled": any(u in str(w) for w in ds["warnings"].values.ravel()
                              for u in UNSETTLED),
             "paper": PAPER.get(name, []), "ours": OURS.get(name, "")}
    if ds.attrs["design"] == "grid":
        dims = list(ds[outs[0]].dims)
        entry["parameters"] = {}
        for d in dims:
            values, unit = display_values(ds, d)
            entry["parameters"][d] = {"unit": unit, "values": [_num(v) for v in values],
                                      "paths": json.loads(ds[d].attrs["paths"])}
        entry["outputs"] = {ds[v].attrs["output"]: np.vectorize(_num, otypes=[object])(
            ds[v].values).tolist() for v in outs}
    elif ds.attrs["design"] == "monte_carlo":
        entry["outputs"] = {}
        for v in outs:
            x = ds[v].values
            x = x[np.isfinite(x)]
            entry["outputs"][ds[v].attrs["output"]] = {
                "n": int(x.size), "mean": _num(x.mean()), "std": _num(x.std(ddof=1)),
                "p5": _num(np.quantile(x, 0.05)), "p95": _num(np.quantile(x, 0.95)),
                "min": _num(x.min()), "max": _num(x.max())}
    else:
        from torquesplit.study.dataset import ranking

        entry["ranking_by"] = ds.attrs["ranking"]
        entry["ranking"] = {ds[v].attrs["output"]: [(f, _num(x)) for f, x in
                                                    ranking(ds, ds[v].attrs["output"])]
                            for v in outs}
        entry["sigma"] = {ds[v].attrs["output"]: dict(zip(
            [str(f) for f in ds["factor"].values],
            [_num(x) for x in ds["sigma"].sel(output=v).values])) for v in outs} \
            if "sigma" in ds else {}
    return entry


# ============================================================================ Markdown
def _stage_columns(entry: dict) -> list[tuple[str, list]]:
    """Columns of the table: the paper's stage-level coefficients where they exist."""
    o = entry["outputs"]
    if "load_sharing.mean_force.I" in o:  # Dong et al.: Omega_I and Omega_II
        two = [k for k in o if k.startswith("load_sharing.mean_force.") and "II_" in k]
        omega2 = np.nanmax(np.array([o[k] for k in two], dtype=float), axis=0)
        return [("Omega_I", o["load_sharing.mean_force.I"]),
                ("Omega_II (largest stage-II group)", omega2.tolist())]
    if "load_sharing.engineering.stage1" in o:  # Ji & Li
        return [(label, o[k]) for label, k in (
            ("g1t", "load_sharing.engineering.stage1"),
            ("g2t", "load_sharing.engineering.stage2"),
            ("G1t", "peak_to_nominal_engineering.stage1"),
            ("G2t", "peak_to_nominal_engineering.stage2")) if k in o]
    keys = [k for k in o if k.count(".") <= 2][:6]
    return [(k, o[k]) for k in keys]


def _dong_drift() -> float:
    """How much the Dong et al. 2021 stage-II coefficient moves with the run length."""
    data = json.loads((ROOT / "docs" / "validation_results.json").read_text())
    return float(data["dong2021"]["drift"]["change"])


def _dong_noise() -> float:
    """A Dong et al. 2021 coefficient's change under a one-rounding-unit input change."""
    data = json.loads((ROOT / "docs" / "validation_results.json").read_text())
    return float(data["dong2021"]["ulp"]["change"])


def _against_drift(entry: dict) -> str:
    """A grid's stage-II change over its range against the run-length drift: the page's
    rule (a trend smaller than the drift may not survive a longer run) applied to each
    study from its numbers, not typed beside some of them."""
    (_, omega2), = [c for c in _stage_columns(entry) if c[0].startswith("Omega_II")]
    arr = np.array(omega2, dtype=object).ravel()  # (a 2-parameter grid: its whole table)
    arr = np.array([np.nan if x is None else x for x in arr], dtype=float)
    span = float(np.nanmax(arr) - np.nanmin(arr))
    drift = _dong_drift()
    if span < drift:
        return (f"Here Omega_II spans {span:.3f} over the range, less than that drift "
                f"({drift:.2f}): this curve, flat or not, is one of this run length and may "
                f"differ in a longer run.")
    return (f"Here Omega_II spans {span:.3f} over the range, more than that drift "
            f"({drift:.2f}).")


#: decimals of the page's numbers at most
DECIMALS = 4


def _fmt(x, ref) -> str:
    """``x`` to the decimals (at most DECIMALS) that the refined run's ``ref`` reproduces
    (:func:`torquesplit.convergence.held_decimals`); '-' for a missing value."""
    from torquesplit.convergence import held_decimals

    if x is None or not math.isfinite(x):
        return "-"
    return f"{x:.{held_decimals(x, ref, DECIMALS)}f}"


def _refined_columns(entry: dict) -> dict:
    """The refined run's stage columns, by label."""
    return dict(_stage_columns({"outputs": entry["refined"]["outputs"]}))


def _nan(values) -> np.ndarray:
    return np.array([np.nan if x is None else x for x in values], dtype=float)


def markdown(data: dict) -> str:
    lines = ["# The papers' studies: our curves beside what the papers state", "",
             "<!-- Generated by `python scripts/study_validation.py` from "
             "docs/studies_validation.json. Do not edit. -->", "",
             "Each section is a shipped study (`torquesplit study NAME`, "
             "`src/torquesplit/study/shipped/NAME.toml`) run on its example model. The papers "
             "print no tables for these studies: what they state (quoted below) are ranges "
             "and trends read off missing figures. The example models assume what the papers "
             "leave out (see each model file and docs/validation.md), and nothing was tuned "
             "to a published number, so the comparison is of trend and magnitude.", "",
             f"Every study was run twice: as shipped, and refined (half the step of a "
             f"dynamic study; twice the mesh positions per cycle of a quasi-static one). "
             f"Each number is the shipped run's, printed to the decimals (at most "
             f"{DECIMALS}) that the refined run reproduces: a number with fewer decimals "
             f"than its neighbours moved with the discretisation.", ""]
    if any(name.startswith("dong_2021") for name in data):
        lines += [dong_run_length(), ""]
    for name, e in data.items():
        if name.startswith("_"):
            continue
        lines += [f"## `{name}` — {e['reference']}", "", e["description"] + ".", ""]
        status = ", ".join(f"{n} {s}" for s, n in e["status"].items())
        lines += [f"Cases: {e['cases']} ({status})."]
        if e.get("warned"):
            beside = " (besides the unsettled run)" if e.get("unsettled") else ""
            lines += [f"{e['warned']} of them warned{beside}, e.g. "
                      f"\"{e['first_warning']}\" (every case's warnings: the study's "
                      f"results, variable `warnings`); their numbers are reported as "
                      f"computed."]
        if "contact_lost" in e["status"]:
            lines += ["`contact_lost`: the run finished but some teeth separated for part of "
                      "the time (" + "; ".join(e["reasons"][:1]) + "); the coefficients are "
                      "reported."]
        lines.append("")
        lines += ["**The paper:** " + " ".join(e["paper"]), ""]
        if e["design"] == "grid":
            params = e["parameters"]
            cols = _stage_columns(e)
            fine = _refined_columns(e)
            if len(params) == 1:
                (pname, p), = params.items()
                lines += [f"| {pname} [{p['unit']}] | " + " | ".join(c for c, _ in cols) + " |",
                          "|---" * (len(cols) + 1) + "|"]
                for i, v in enumerate(p["values"]):
                    lines.append(f"| {v:.4g} | " + " | ".join(
                        _fmt(c[i], fine[label][i]) for label, c in cols) + " |")
                lines.append("")
                for label, c in cols:
                    arr, ref = _nan(c), _nan(fine[label])
                    lines.append(f"- {label}: {_fmt(arr[0], ref[0])} -> "
                                 f"{_fmt(arr[-1], ref[-1])} over the range (min "
                                 f"{_fmt(np.nanmin(arr), np.nanmin(ref))}, max "
                                 f"{_fmt(np.nanmax(arr), np.nanmax(ref))})")
            else:
                (n1, p1), (n2, p2) = list(params.items())[:2]
                for label, c in cols:
                    lines += [f"{label}, rows {n1} [{p1['unit']}], columns {n2} "
                              f"[{p2['unit']}]:", "",
                              "| | " + " | ".join(f"{v:.4g}" for v in p2["values"]) + " |",
                              "|---" * (len(p2["values"]) + 1) + "|"]
                    for i, v in enumerate(p1["values"]):
                        lines.append(f"| {v:.4g} | " + " | ".join(
                            _fmt(x, r) for x, r in zip(c[i], fine[label][i])) + " |")
                    lines.append("")
        elif e["design"] == "monte_carlo":
            lines += ["| output | n | mean | std | p5 | p95 | min | max |",
                      "|---|---|---|---|---|---|---|---|"]
            for k, s in e["outputs"].items():
                r = e["refined"]["outputs"][k]
                lines.append(f"| {k} | {s['n']} | " + " | ".join(
                    _fmt(s[q], r[q]) for q in ("mean", "std", "p5", "p95", "min", "max"))
                    + " |")
        else:
            for out, rank in e["ranking"].items():
                ref = dict(e["refined"]["ranking"][out])
                lines.append(f"- `{out}`, factors by {e['ranking_by']} (output change over "
                             f"each factor's range): " + ", ".join(
                                 f"{f} {_fmt(x, ref.get(f))}" for f, x in rank))
        if e.get("ours"):
            lines += ["", "**Ours:** " + e["ours"]]
        if name.startswith("dong_2021"):
            lines += ["", DONG_SECTION]
            if e["design"] == "grid":
                lines[-1] += "  " + _against_drift(e)
            if e["design"] == "sensitivity":
                top = max(x for out, rank in e["ranking"].items() if "II_" in out
                          or out == "load_sharing.mean_force" for _, x in rank
                          if x is not None)
                lines[-1] += (f"  The largest mu_star of the stage-II and system "
                              f"coefficients, {top:.2f}, is of the size of that drift, so "
                              f"their ranking is not resolved by these runs.")
                rank1 = e["ranking"].get("load_sharing.mean_force.I")
                if rank1:
                    f1, x1 = rank1[0]
                    noise = _dong_noise()
                    verdict = ("below the noise, so no factor moves stage I over these ranges"
                               if x1 < noise else "above the noise")
                    ref1 = dict(e["refined"]["ranking"]["load_sharing.mean_force.I"])
                    lines[-1] += (f"  Stage I (Omega_I): the largest mu_star, {f1} "
                                  f"{_fmt(x1, ref1.get(f1))}, is {verdict} ({noise:.1g}, top "
                                  f"of this page).")
        lines += ["", f"Figures: `torquesplit study {name}` writes them to "
                      f"`study_{name}/figures/`.", ""]
    notes = data.get("_notes", [])
    if notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in notes] + [""]
    return "\n".join(lines)


def main(argv=None) -> int:
    from torquesplit.study.shipped import study_names

    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", default=study_names())
    ap.add_argument("--results", type=Path, default=Path("study_results"))
    ap.add_argument("--no-run", action="store_true")
    args = ap.parse_args(argv)
    if not args.no_run:
        _run(args.names, args.results)
    data = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    for name in args.names:
        folder = args.results / name
        refined = args.results / f"{name}{REFINED}"
        if (folder / "results.nc").exists() and (refined / "results.nc").exists():
            data[name] = collect(name, folder)
            data[name]["refined"] = collect_refined(name, refined)
    data = {k: data[k] for k in [n for n in study_names() if n in data]
            + [k for k in data if k.startswith("_")]}
    OUT_JSON.write_text(json.dumps(data, indent=1))
    OUT_MD.write_text(markdown(data) + "\n")
    print(f"wrote {OUT_JSON} and {OUT_MD}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
