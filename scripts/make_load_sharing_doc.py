"""Write docs/load-sharing.md: what each load-sharing definition measures, when to report
it, and the numbers of every definition for the same runs.

    python scripts/make_load_sharing_doc.py

The table of numbers comes from runs of shipped examples made here (their own
``[analysis]`` settings); the per-definition text from
``torquesplit.metrics.load_sharing`` (``DEFINITION_TEXT``, ``DEFINITION_USE``), the same
text the run table and ``run --help`` print.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import torquesplit  # noqa: E402
from torquesplit.convergence import agreeing_digits, check_step  # noqa: E402
from torquesplit.metrics.load_sharing import (  # noqa: E402
    DEFINITION_TEXT, DEFINITION_USE, DYNAMIC_DEFINITIONS, STANDARD_DEFINITION)

DOC = ROOT / "docs" / "load-sharing.md"
#: examples run for the table (small ones: the script runs in about a minute)
EXAMPLES = ("ji_li_mill_drive", "dong2021_face_gear")

HEAD = """\
# Load sharing: which number to report

A power-split gearbox divides its torque between parallel paths; the load-sharing
coefficient (LSC) of a mesh says how much more than its equal share it carries.  In a
group of N parallel meshes (the meshes with the same `stage` and `path` labels in the
model file) each definition forms `N X_i / sum_j X_j` of some quantity X of mesh i, so an
equal split gives 1 for every mesh.  Only the ratio of mean forces (`mean_force`) sums to
N over a group; the others take each mesh's largest ratio over time (or over cycle
peaks), so in a dynamic run every mesh can exceed 1 at some instant and their sum
exceeds N.  The table at the end shows system values: for Ji & Li's symmetric drive the
mean-force coefficient is 1, while the peak-based ones are above 1 because each of its two
split meshes is above its share at some instants.  The papers torquesplit reproduces use
four different X, and for the same run they give different numbers (the table at the end
shows by how much).  Choose with `--definition` (`run`, `report`) or `[analysis]
load_sharing` in the model file; every table says which it shows.

## The definitions

| definition | what it measures | when to report it |
|---|---|---|
"""

ARGUMENT = f"""
`static_torque` (Mo et al. 2017 eqs. 14-15) is the sharing of quasi-static equilibria
over the mesh positions, computed by `torquesplit static`; `run` refuses it with that
pointer, and a model whose default it is reports `{STANDARD_DEFINITION}` when run.

## The default for a new model: `{STANDARD_DEFINITION}`

Design standards rate a gear by multiplying the nominal tooth load by factors, each for
one effect: ISO 6336-1 and AGMA 6123 apply the mesh load factor K_γ for the unequal
division of load between parallel paths, and the dynamic factor K_v for the dynamic
increment within a mesh.  K_γ is defined as the load of the most heavily loaded path over
the average: a ratio of loads without the dynamic increment.  The mean-force definition
is that ratio (the mean force over a settled run is the load each path carries), and
torquesplit's dynamic factor (settled peak over the mesh's own static force) is the K_v
sense.  So the two numbers torquesplit reports by default are the two factors a standard
multiplies, and their product with the nominal force is about the peak force the run
found (the run's *peak/nominal* column shows it directly).

The peak-based definitions (`cycle_peak`, `instantaneous`, `engineering`) already contain
the dynamics: multiplying them by a dynamic factor counts the dynamic increment twice.
They are the right numbers to compare with the papers that use them, and to see how the
worst cycle or instant shares, not to put into a rating calculation next to K_v.

## The dynamic factors

* **dynamic factor** = settled peak / the mesh's own static force: the K_v sense, at
  least 1 for a mesh that stays in contact; what is in the static force (the static
  load sharing) is not in it.
* **peak/nominal** = settled peak / the equal-split nominal force (Ji & Li eq. 19, G_i):
  load sharing and dynamics together, the largest tooth force relative to the design share.
* **peak/nominal (eng.)** per group: the mean over settled cycles of the largest member's
  per-cycle peak over the nominal force (Ji & Li eq. 19, engineering coefficient G_it).

In the run's group table, *dynamic factor* and *peak/nominal* are the largest over the
group's meshes.

A dynamic factor above 3 is reported as a warning: the run is near a resonance, and
`torquesplit modes` lists the natural frequencies and the elements that carry them.

## The same runs, every definition

"""


#: what the table's numbers of an example need said (after the table); DRIFT: the
#: herringbone stage's run-length drift (docs/validation_results.json, scripts/validate.py)
NOTES = """
`dong2021_face_gear` does not settle in its 1.21 s (the run warns so), and its herringbone
meshes lose contact a few per cent of the time.  Its `cycle_peak` and `instantaneous`
values of 2.0 are the largest a pair can give: one mesh of a pair carried the pair's
whole load while the other had lost contact (`instantaneous`: at some instant;
`cycle_peak`: through a whole mesh cycle).  Its system `mean_force` coefficient is the
face-gear stage's, which does not drift; the herringbone stage's mean-force coefficients
change with the run length by about DRIFT ([validation.md](validation.md)), and its
peak-based numbers are those of impacts, which rounding-level differences move by
per cents (the same code on another build of the numeric libraries moved its largest
peak/nominal by 3 %): they are printed to two digits at most.
"""

#: peak-based numbers of an example printed to at most this many digits (impacts: see NOTES)
PEAK_DIGITS = {"dong2021_face_gear": 2}
#: the mark of a number whose second printed digit moves at half the step (one holds:
#: printed to one digit, 2.613 would read "3")
ONE_DIGIT = "†"

def _held(value: float, checked: float, most: int = 5) -> str:
    """``value`` to the significant digits ``checked`` confirms, at most ``most`` (trailing
    zeros kept: 2.0000 is five digits); where only one holds, two digits and ONE_DIGIT."""
    digits = min(most, agreeing_digits(value, checked, most))
    mark = ONE_DIGIT if digits < 2 else ""
    digits = max(2, digits)
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(value)))) if value else digits
    return f"{value:.{decimals}f}{mark}"


#: the table's numbers, in its column order
KEYS = tuple(f"load_sharing.{d}" for d in DYNAMIC_DEFINITIONS) + ("dynamic_factor",
                                                                   "peak_to_nominal")


def cells(name: str, check) -> list[str]:
    """The table row of example ``name`` from its ``check_step`` result: each number to
    the digits its halved run confirms, an example's peak-based ones to PEAK_DIGITS."""
    most = {k: 5 if k == "load_sharing.mean_force" else PEAK_DIGITS.get(name, 5)
            for k in KEYS}
    return [_held(check.values[k], check.halved[k], most[k]) for k in KEYS]


def main() -> None:
    lines = [HEAD]
    for d in DYNAMIC_DEFINITIONS:
        default = " (default)" if d == STANDARD_DEFINITION else ""
        lines.append(f"| `{d}`{default} | {DEFINITION_TEXT[d]} | {DEFINITION_USE[d]} |\n")
    lines.append(ARGUMENT)
    lines.append("System load-sharing coefficient of each run by every definition, and the "
                 "largest dynamic factor (`python scripts/make_load_sharing_doc.py`; each "
                 "example with its own `[analysis]` settings), each to the digits that hold "
                 "when the run is repeated at half the step with four times the table points "
                 "(`torquesplit run --check-step`; at most 5):\n\n")
    lines.append("| example | " + " | ".join(f"`{d}`" for d in DYNAMIC_DEFINITIONS)
                 + " | dynamic factor | peak/nominal |\n")
    lines.append("|---|" + "---|" * (len(DYNAMIC_DEFINITIONS) + 2) + "\n")
    for name in EXAMPLES:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = torquesplit.simulate(torquesplit.load_model(torquesplit.example_path(name)))
            check = check_step(res, definitions=DYNAMIC_DEFINITIONS)
        lines.append(f"| `{name}` | " + " | ".join(cells(name, check)) + " |\n")
        print(f"{name} done", file=sys.stderr)
    lines.append(f"\n{ONE_DIGIT} only the first digit holds at half the step.  The "
                 "peak-based coefficients include the dynamic increment: they differ "
                 "from the mean-force one by how differently the paths respond.\n")
    import json

    drift = json.loads((ROOT / "docs" / "validation_results.json").read_text(
        encoding="utf-8"))["dong2021"]["drift"]["change"]
    lines.append(NOTES.replace("DRIFT", f"{drift:.1f}"))
    DOC.write_text("".join(lines), encoding="utf-8")
    print(f"wrote {DOC}", file=sys.stderr)


if __name__ == "__main__":
    main()
