"""Write docs/tutorial.md by running every command it shows.

    python scripts/make_tutorial.py

The tutorial builds a three-branch split drive from scratch.  Each ``$ torquesplit ...``
block below is run in a scratch folder and its output (what a terminal 140 columns wide
shows, stdout and stderr) is pasted under it: no number in the tutorial is typed by hand.
The layout drawing is copied to docs/tutorial/three_branch_layout.svg.
``tests/test_tutorial.py`` fails when the tutorial's model no longer passes ``check`` or
its printed load-sharing coefficient no longer matches a fresh run.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "tutorial.md"
FIGURES = ROOT / "docs" / "tutorial"
WIDTH = 140

MODEL = '''\
# A three-branch split drive: the input pinion drives three branch gears 120 deg apart;
# each branch gear turns a second pinion through an elastic shaft, and the three pinions
# drive the output gear, which sits on the input's axis 120 mm further along.
[model]
name = "three_branch"
description = "Three-branch locked-train split drive, 200 kW at 3000 rpm"

# ---------------------------------------------------------------- first stage
[gears.input]
teeth = 20
module = "3 mm"                     # a bare number would be metres: write the unit
face_width = "40 mm"
position = ["0 mm", "0 mm", "0 mm"]
dofs = ["x", "y", "theta"]          # floats radially on its bearings
support = { stiffness = "100 N/um", damping_ratio = 0.05 }

[gears.b1]
teeth = 40
module = "3 mm"
face_width = "40 mm"
place = { from_gear = "input", angle = "90 deg" }     # at the centre distance, 90 deg
errors = { installation = "15 um" }                     # one branch mounted off-centre

[gears.b2]
teeth = 40
module = "3 mm"
face_width = "40 mm"
place = { from_gear = "input", angle = "210 deg" }

[gears.b3]
teeth = 40
module = "3 mm"
face_width = "40 mm"
place = { from_gear = "input", angle = "330 deg" }

# ---------------------------------------------------------------- second stage
[gears.output]
teeth = 40
module = "3 mm"
face_width = "50 mm"
position = ["0 mm", "0 mm", "-120 mm"]

[gears.p1]
teeth = 20
module = "3 mm"
face_width = "50 mm"
place = { from_gear = "output", angle = "90 deg" }    # on b1's axis, 120 mm behind it

[gears.p2]
teeth = 20
module = "3 mm"
face_width = "50 mm"
place = { from_gear = "output", angle = "210 deg" }

[gears.p3]
teeth = 20
module = "3 mm"
face_width = "50 mm"
place = { from_gear = "output", angle = "330 deg" }

# ---------------------------------------------------------------- branch shafts
[shafts.s1]
connects = ["b1", "p1"]
diameter = "30 mm"
length = "120 mm"

[shafts.s2]
connects = ["b2", "p2"]
diameter = "30 mm"
length = "120 mm"

[shafts.s3]
connects = ["b3", "p3"]
diameter = "30 mm"
length = "120 mm"

# ---------------------------------------------------------------- meshes
# meshes with the same 'stage' share one flow of power: a load-sharing group
[meshes.in1]
gears = ["input", "b1"]
stiffness = { method = "iso6336" }   # single/double tooth contact from the geometry
damping_ratio = 0.05
stage = "split"

[meshes.in2]
gears = ["input", "b2"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
stage = "split"

[meshes.in3]
gears = ["input", "b3"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
stage = "split"

[meshes.out1]
gears = ["p1", "output"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
stage = "combine"

[meshes.out2]
gears = ["p2", "output"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
stage = "combine"

[meshes.out3]
gears = ["p3", "output"]
stiffness = { method = "iso6336" }
damping_ratio = 0.05
stage = "combine"

# ---------------------------------------------------------------- power
[drives.motor]
body = "input"
speed = "3000 rpm"
power = "200 kW"

[loads.machine]
body = "output"
torque = "balanced"                  # takes whatever the drive puts in

# ---------------------------------------------------------------- analysis
[analysis]
# the ISO 6336 stiffness steps where a tooth pair enters and leaves; a table of n points
# per mesh cycle makes each step a ramp 1/n of a cycle long: 16384 points resolve it, at
# no cost per step (the default where a table steps; 256 where every table is smooth)
table_points = 16384
'''

SPEED_SWEEP = ('torquesplit sweep-speed three_branch.toml --keep split --from "2400 rpm" '
               '--to "3600 rpm" --plot speed_response.svg')

SWEEP = ('torquesplit sweep three_branch.toml --vary '
         '"shafts.s1.diameter,shafts.s2.diameter,shafts.s3.diameter=25:40:4mm" '
         '--output load_sharing.mean_force')

#: the tutorial: text, and commands whose output is pasted (``$ `` lines)
TUTORIAL = f'''\
# Tutorial: a three-branch split drive from scratch

This tutorial builds a gearbox that splits its power into three branches and joins it
again, checks it, draws it, runs it, reads the table, changes a parameter, runs a small
sweep, looks for resonances over a speed range and writes a report to hand on.  Every
output below was produced by the command above it (`python scripts/make_tutorial.py`
writes this page); your numbers should be the same to the digits shown.

You need torquesplit installed (`pip install .` in the source folder) and a terminal.  All
quantities in a model file carry their units (`"3 mm"`, `"3000 rpm"`); a bare number is
read in SI units, so `module = 3` would mean 3 m.  The same holds on the command line:
`--duration 0.5` is 0.5 s.

## 1. The model file

Save this as `three_branch.toml`.  The input pinion drives three branch gears placed 120°
apart around it (`place` puts a gear at the operating centre distance from its mate, so
you give angles, not coordinates); each branch gear turns, through a 30 mm shaft, a pinion
that drives the output gear.  This is a *locked train*: the three branches are stiff
paths between the same input and output, so how the load divides depends on the branch
stiffnesses and on the errors, here a 15 µm installation error of branch 1.

```toml
{MODEL}```

Every field is described in [model-file.md](model-file.md).

## 2. Check it

`check` runs everything a run does before it integrates (geometry, kinematics, the
assembly and the static equilibrium) and prints the speeds, torques and mesh data with
their units.  Values that are possible but look wrong (a unit slip, an error beyond the
coarsest ISO 1328 grade) come out as warnings naming the field; this model has none.

$ torquesplit check three_branch.toml

`(placed)` marks positions computed from `place`; `(computed)` masses and inertias are
solid steel discs of the pitch diameter (give `mass` and `polar_inertia` when you know
better).

## 3. Draw it

$ torquesplit draw three_branch.toml --out three_branch_layout.svg

![layout of the three-branch drive](tutorial/three_branch_layout.svg)

The drawing is an oblique view: the gears' axis points out of the page, depth runs along
the diagonal.  Red arrows are the lines of action (the force each driver puts on its
driven gear), blue arrows the power flow; the grey bars are the branch shafts.  Check
that it is the gearbox you meant before running it.

## 4. Run it

$ torquesplit run three_branch.toml

The run starts from the static equilibrium at t = 0 (stiffness and errors as they are at
the start), integrates 200 cycles of the slowest mesh and
leaves out the start-up transient before computing anything.

## 5. Read the table

* **nominal F**: the tooth force of an equal split; **static F**: the force at the static
  equilibrium under the mean excitation (mean mesh stiffness, constant errors: the 15 µm
  error already shifts load onto branch 1; an eccentricity turning with its gear would
  average out), the denominator of the dynamic factor; the run itself starts from the
  equilibrium at t = 0; **mean F** and **peak F**: over the settled part of the run.
* **LSC (mean_force)**: the load-sharing coefficient, the mean force of a mesh over the
  mean of its group.  This is the number a design standard calls the mesh load factor
  K_γ (ISO 6336-1, AGMA 6123), and the one to report next to the dynamic factor: it is
  the default for a new model.  Here branch 1 carries {{{{overload}}}} % more than its share.
  Other definitions and when to use them: [load-sharing.md](load-sharing.md).
* **dynamic factor**: the settled peak over the mesh's own static force, the K_v of the
  standards.  **peak/nominal** is both together: the largest tooth force over the equal
  share.
* **load-sharing groups**: per group, the largest LSC, dynamic factor and peak/nominal of
  its meshes, and **peak/nominal (eng.)**: the mean over settled cycles of the largest
  member's per-cycle peak over the nominal force (Ji & Li's engineering dynamic load
  coefficient G_it, from their eq. 19).
* **bearing forces**: for each supported body (here `input` on its bearing, and every
  other gear), the settled mean bearing force by direction, the magnitude of that mean
  and the peak magnitude |F|; a gear with no translations sits on a rigid bearing, and
  its row (marked `(rigid bearing)`) is the sum of its meshes' forces, in the housing's
  x, y (and z: the axial thrust of helical teeth); a planetary stage's fixed ring's in its
  carrier's frame, as the planets'.  The peaks are streamed at every step and table
  corner, as the mesh table's are (next bullet); the means: a rigid bearing's is its
  meshes' mean forces (b1's is in1's), another's the mean of its history samples.  `--json` gives them
  as `bearing_forces_N`, a .nc or .mat results file (`--out`) as `bearing_mean_force`
  and `bearing_peak_force`.
{{{{drift_text}}}}
* **the history**, which results files (`--out`), figures (`--plots`) and the bearing
  table's means are made from (its peaks are taken at every step and table corner, as
  the mesh table's), holds every integration step of this run ({{{{history_samples}}}} samples):
  by default a run keeps every step up to 50,000 samples, and a longer one every k-th
  step: 50,000 samples, or more where 20 per shortest mesh period need more (at most
  200,000: fewer per period on a very long run).  This drive rings at its mesh modes
  near order {{{{order}}}} of the mesh frequency (section 5): a history of 20 samples per
  split-mesh period (`--samples-per-period 20`) misses the settled {{{{history_what}}}}
  of {{{{history_mesh}}}} by {{{{history_miss}}}} %{{{{history_of}}}}, and the run says so in a
  warning.  Even every step misses
  {{{{every_mesh}}}}'s settled peak by {{{{every_miss}}}} %, and this run's warning says
  that: the ISO stiffness steps up as a second tooth pair comes into contact, and the
  force peaks at that corner of the table, inside a step.  The integrator splits the
  step there and streams that instant into the mesh table's numbers, which never depend
  on the history; the waveform in the files holds the steps only (a finer step,
  `--steps-per-period`, brings it closer).
* **contact loss** and **back flank**: these meshes have no backlash, so they cannot lose
  contact; had their forces turned negative (the back flank loaded) the table and a
  warning would say so.

How many of those digits hold?  `--check-step` runs the model again at half the step
and says, for every number, how many significant digits stay put; the second run takes
twice the steps, so the command integrates about three times as long as a plain run.
The ISO 6336 stiffness steps between single and double tooth contact, and a table of n
points per mesh cycle (`[analysis] table_points`: 16384 here, the default where a table
steps) makes each step a ramp one n-th of a cycle long, so the check also runs with four
times the table points.  The bearing table's means come from the history, so the
check also samples it twice as often:

$ torquesplit run three_branch.toml --check-step --quiet

A number that moves in a printed digit is listed with the digits that hold.  Here the
peaks move in their second digit: the drive runs near a resonance (next paragraph),
where the peaks depend on the step and on how sharply the tables resolve the jumps (half
the step and 65536 table points move them by about 1 %).  Refine both (`--steps-per-period`, `--set
analysis.table_points=...`), and report only the digits that hold; the mean-force
coefficients move far less than the peaks: they hold {{{{lsc_digits}}}} significant digits
(`--json` gives every number's digits).

A dynamic factor of about {{{{dynamic_factor}}}} is large.  The modes show where it can come from:

$ torquesplit modes three_branch.toml --count 8

The mesh modes ({{{{mesh_modes}}}} kHz, strain energy in the meshes) sit near order
{{{{order}}}} of the {{{{f_split}}}} Hz split-stage mesh frequency, and the ISO 6336 stiffness of a
spur pair jumps by a factor of {{{{jump}}}} between single and double tooth contact: a sharp,
harmonic-rich excitation.
Tooth modifications (`stiffness.method = "ltca"` with `[gears.NAME.modifications]`)
smooth it; see the `contact` command.

The split-stage mesh frequency itself (order 1) also crosses two lower modes, on either
side of this run's 3000 rpm: the input-bearing mode ({{{{bearing_Hz}}}} Hz) at
{{{{bearing_rpm}}}} rpm, which it drives, and the branch-shaft mode ({{{{shaft_Hz}}}} Hz) at
{{{{shaft_rpm}}}} rpm, which it hardly does: the three branches mesh a third of a cycle apart,
and on a mode where the three shafts twist together their forces cancel (to
{{{{shaft_share}}}} % of their sum here, the rest from branch 1's error)
(`torquesplit modes three_branch.toml --campbell --from "2400 rpm" --to "3600 rpm"`
lists both, the second marked 'cancels').  The speed sweep of section 8 finds its largest
dynamic factor next to the first.  Near that speed the remedy is to detune the input
bearing (its stiffness, or the inertia it carries), which moves the critical speed away.

## 6. Change a parameter

`--set` changes one field for one command, without editing the file (a field the file
gives another way gives way: `--set drives.motor.torque=...` replaces a `power`,
`damping_ratio` a `damping`).  Mount branch 1 correctly:

$ torquesplit run three_branch.toml --set gears.b1.errors.installation=0

With the error gone the three branches share almost equally: every coefficient is close
to 1, the remainder coming from the three meshes' different phases.

## 7. A small sweep

The branch shafts decide how much an error matters: a stiff shaft passes the error
straight into the teeth.  `sweep` runs the model for each value of one parameter (here
the three shaft diameters together, 25 to 40 mm in 4 steps) and tabulates an output; it
keeps every finished case, so an interrupted sweep resumes where it stopped (the same
command with `--resume`; run again without it, it refuses to write over the folder):

$ {SWEEP}

Thicker shafts share worse: the usual trade-off of a locked train, where the compliance
of the branches is what evens out the errors.  The table prints six digits; the same
sweep at half the step (`--set analysis.steps_per_period=200`) moves them by up to
{{{{sweep_change}}}}, so they hold {{{{sweep_decimals}}}} decimals:
{{{{sweep_held}}}}.  Grids of several parameters, tolerance
Monte Carlo and sensitivity ranking are `torquesplit study` files: [studies.md](studies.md).

## 8. Over the speed range

Where are the resonances between 2400 and 3600 rpm, and how large is the dynamic factor
there?  `sweep-speed` follows the periodic steady state along the speed range by
continuation (shooting: one period integrated as `run` steps it, Newton on the state
that repeats, the monodromy giving stability at every point), instead of integrating
from rest at every speed.  `--keep split` keeps the excitations of the split
stage (the combine stage's stiffness variation is replaced by its mean; `torquesplit
steady three_branch.toml --keep split` lists what is dropped), so that one period is one
split-stage mesh cycle:

$ {SPEED_SWEEP}

The table gives each mesh's largest dynamic factor over the stable points of the range
and the speed where it occurs (to the spacing of the curve's points there: the peak lies
between its neighbours; more `--points` narrow it), to the digits that hold: each peak is
solved again at its
speed with half the RK4 step, and the line under the table gives both values (near a
resonance the response is steep, and the split stage's peaks hold two or three digits at
the default resolution; `--steps-per-cycle` refines it).  The combine stage's rows
leave out its own excitation (its stiffness variation was replaced by its mean, as the
line under the table says):
they are not the combine meshes' dynamic factors, which `run` or `steady` without
`--keep` give at a speed.  The figure draws the dynamic factor, the load sharing and the
RMS transmission error of every mesh against speed (dashed where the periodic state is
unstable) and numbers the critical speeds, where a natural frequency crosses a harmonic
of a mesh frequency, listing them under the plot (`torquesplit modes three_branch.toml
--campbell --from "2400 rpm" --to "3600 rpm"` lists them with the elements that carry
each mode).  The mode of the critical speed a peak sits on is the one to detune:

![dynamic factor against speed](tutorial/speed_response.svg)

`torquesplit steady` gives the full per-mesh table at one speed; `--cross-check` adds
run-up and run-down time integrations to the sweep, to see the jumps a backlash
nonlinearity can make.

## 9. Hand it on

$ torquesplit report three_branch.toml --out three_branch_report.html

The report is one HTML file with the model and its units, the drawing, the run's settings
and provenance (torquesplit version, the model file's SHA-256), the tables, the figures,
the modes and the warnings; it needs no network and prints as it shows.  `torquesplit
report` also reads a results file written by `torquesplit run --out results.nc`.

## Where next

* The shipped examples (`torquesplit examples`): start with `ji_li_mill_drive`, a 14-DOF
  grinding-mill drive that runs in seconds; `torquesplit example NAME` copies one to your
  folder.
* [model-file.md](model-file.md): every field of the model file.
* [load-sharing.md](load-sharing.md): the load-sharing definitions and which to report.
* [theory/](theory/): the physics and its sources; [validation.md](validation.md): the
  comparison with the papers.
'''


def _run(command: str, cwd: Path) -> str:
    """Run one tutorial command (``torquesplit`` is this checkout's CLI) and return what
    the terminal shows."""
    env = dict(os.environ, COLUMNS=str(WIDTH), PYTHONPATH=str(ROOT / "src"))
    shim = cwd / "bin"
    shim.mkdir(exist_ok=True)
    exe = shim / "torquesplit"
    exe.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} -m torquesplit.cli "
                   '"$@"\n')
    exe.chmod(0o755)
    py = shim / "python"
    if not py.exists():
        py.symlink_to(sys.executable)
    env["PATH"] = f"{shim}{os.pathsep}{env['PATH']}"
    proc = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=900)
    if proc.returncode != 0:
        raise SystemExit(f"tutorial command failed ({proc.returncode}): {command}\n"
                         f"{proc.stdout}{proc.stderr}")
    text = proc.stderr + proc.stdout
    text = text.replace(str(cwd) + os.sep, "").replace(str(cwd), ".")
    return "\n".join(line.rstrip() for line in text.strip("\n").splitlines())


def _numbers(work: Path) -> dict[str, str]:
    """The numbers the tutorial's text quotes, from runs of its model."""
    import json

    import numpy as np

    run = json.loads(_run("torquesplit run three_branch.toml --json 2>/dev/null", work))
    drift = [w for w in run["warnings"] if w.startswith("meshes.in1: the settled peaks")]
    if drift:  # a slowly dying mode: said in a bullet of its own
        drift = re.search(r"\(([-+]\d+(?:\.\d+)?) %\)", drift[0]).group(1).lstrip("-+")
        drift_text = (
            "* **the first warning**: in1's largest force still falls by " + drift + " % "
            "from the first settled window to the last, a lightly damped mode dying out "
            "slowly.  The dynamic factor takes the largest settled peak, so its third "
            "digit is that of the transient's tail; the periodic steady state (section 8, "
            "`torquesplit steady`) gives the value the run tends to.")
    else:
        drift_text = (
            "* **the transient** is left out: the settled part starts after the leading "
            "windows of 20 cycles whose peaks lie outside the range of the run's last "
            "half by more than 1e-4 of the peak (docs/theory/model.md), so the dynamic "
            "factor is that of the response the run tends to; the periodic steady state "
            "(section 8, `torquesplit steady`) gives it directly.")
    every = [w for w in run["warnings"]
             if w.startswith("analysis: the history keeps every RK4 step")]
    if not every:
        raise SystemExit("the tutorial's text expects a history of every step that misses "
                         "a peak at a stiffness corner (the run's warning)")
    every_kind, every_mesh, every_miss = re.search(
        r"misses the settled (peak|smallest) force of mesh (\w+) by (\d+(?:\.\d+)?) %",
        every[0]).groups()
    if every_kind != "peak":
        raise SystemExit("the tutorial's text expects the every-step history to miss a "
                         f"peak at a stiffness corner, not the {every_kind} force")
    history_samples = f"{run['statistics']['history_samples']:,}"
    coarse = json.loads(_run("torquesplit run three_branch.toml --samples-per-period 20 "
                             "--json 2>/dev/null", work))
    coarse = [w for w in coarse["warnings"] if w.startswith("analysis: the history")]
    if not coarse:
        raise SystemExit("the tutorial's text expects the coarse-history warning at 20 "
                         "samples per period")
    history_kind, history_mesh, history_miss = re.search(
        r"misses the settled (peak|smallest) force of mesh (\w+) by (\d+(?:\.\d+)?) %",
        coarse[0]).groups()
    history_what = ("peak" if history_kind == "peak" else "smallest force")
    history_of = "" if history_kind == "peak" else " of its peak"
    modes = json.loads(_run("torquesplit modes three_branch.toml --count 8 --json 2>/dev/null", work))
    campbell = json.loads(_run('torquesplit modes three_branch.toml --campbell --from '
                               '"2400 rpm" --to "3600 rpm" --json 2>/dev/null', work))
    first = {}  # first-order crossings of the split mesh (a double mode listed once)
    for c in campbell["critical_speeds"]:
        if c["order"] == 1 and "in1" in c.get("meshes", [c["source"].split()[-1]]):
            first.setdefault(round(c["speed_rpm"], 1), c)
    bearing, shaft = (first[s] for s in sorted(first)) if len(first) == 2 else (None, None)
    if not (bearing and ".support." in bearing["energy"][0][0]
            and shaft["energy"][0][0] in ("s1", "s2", "s3")):
        raise SystemExit("the tutorial's text expects two first-order crossings of the split "
                         "mesh: an input-bearing mode, then a branch-shaft mode")
    if bearing.get("stiffness_cancelled") or not shaft.get("stiffness_cancelled"):
        raise SystemExit("the tutorial's text expects the input-bearing crossing driven and "
                         "the branch-shaft crossing cancelled by the branches' phasing")
    sweep_change, sweep_decimals, sweep_held = _sweep_held(work)
    check = json.loads(_run("torquesplit run three_branch.toml --check-step --json "
                            "2>/dev/null", work))["step_check"]["metrics"]
    lsc = sorted({v["digits"] for k, v in check.items()
                  if k.startswith("load_sharing.mean_force")})
    lsc_digits = f"{lsc[0]}" if len(lsc) == 1 else f"{lsc[0]} to {lsc[-1]}"
    met = run["metrics"]
    meshes = set(met["meshes"])
    f_split = modes["mesh_frequencies_Hz"]["in1"]
    mesh_modes = [m["frequency_Hz"] for m in modes["modes"]
                  if m["strain_energy"] and max(m["strain_energy"],
                                                key=m["strain_energy"].get) in meshes]
    import torquesplit
    from torquesplit.assembly.excitation import stiffness_table
    from torquesplit.model.kinematics import solve_kinematics

    model = torquesplit.load_model(work / "three_branch.toml")
    k = np.asarray(stiffness_table(model, solve_kinematics(model), "in1", 256))
    low, high = min(mesh_modes), max(mesh_modes)
    return {
        "overload": f"{100 * (met['meshes']['in1']['load_sharing'] - 1):.1f}",
        "history_miss": history_miss, "history_what": history_what,
        "history_mesh": history_mesh, "history_of": history_of,
        "every_mesh": every_mesh,
        "every_miss": every_miss,
        "history_samples": history_samples,
        "dynamic_factor": f"{met['groups']['split']['dynamic_factor']:.1f}",
        "mesh_modes": f"{low / 1e3:.1f}–{high / 1e3:.1f}",
        "order": f"{round(low / f_split)}",
        "f_split": f"{f_split:.4g}",
        "jump": f"{k.max() / k.min():.2g}",
        "drift_text": textwrap.fill(drift_text, 90, subsequent_indent="  "),
        "bearing_Hz": f"{bearing['frequency_Hz']:.0f}",
        "bearing_rpm": f"{bearing['speed_rpm']:.0f}",
        "shaft_Hz": f"{shaft['frequency_Hz']:.0f}",
        "shaft_rpm": f"{shaft['speed_rpm']:.0f}",
        "shaft_share": f"{100 * shaft['modal_force_share']:.1f}",
        "sweep_change": sweep_change, "sweep_decimals": sweep_decimals,
        "sweep_held": sweep_held, "lsc_digits": lsc_digits,
    }


def _sweep_held(work: Path) -> tuple[str, str, str]:
    """The section 7 sweep against the same sweep at half the step: the largest change,
    the decimals every value keeps (:func:`torquesplit.convergence.agreeing_digits`), and
    the values to those decimals."""
    import json

    from torquesplit.convergence import agreeing_digits

    def values(extra: str, out: str) -> list[float]:
        got = json.loads(_run(f"{SWEEP} --json --quiet --no-figures --out {out} {extra} "
                              "2>/dev/null", work))
        return got["outputs"]["load_sharing.mean_force"]

    base = values("", "sweep_check")
    fine = values("--set analysis.steps_per_period=200", "sweep_fine")
    change = max(abs(a - b) for a, b in zip(base, fine, strict=True))
    decimals = min(agreeing_digits(a, b, 7) - 1 for a, b in zip(base, fine, strict=True))
    if not 1 <= decimals <= 5:
        raise SystemExit(f"the tutorial's sweep sentence expects 1-5 decimals that hold, "
                         f"got {decimals} (change {change:.2g})")
    held = ", ".join(f"{a:.{decimals}f}" for a in base)
    return f"{change:.1g}", str(decimals), held


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="torquesplit-tutorial-"))
    try:
        (work / "three_branch.toml").write_text(MODEL, encoding="utf-8")
        numbers = _numbers(work)
        tutorial = re.sub(r"\{\{(\w+)\}\}", lambda m: numbers[m.group(1)], TUTORIAL)
        out = []
        for line in tutorial.splitlines():
            if line.startswith("$ "):
                command = line[2:]
                shown = command
                print(f"running: {shown.splitlines()[0]}", file=sys.stderr)
                out += ["```console", f"$ {shown}", _run(command, work), "```"]
            else:
                out.append(line)
        FIGURES.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(work / "three_branch_layout.svg", FIGURES / "three_branch_layout.svg")
        shutil.copyfile(work / "speed_response.svg", FIGURES / "speed_response.svg")
        text = "\n".join(out) + "\n"
        text = re.sub(r"\n{3,}", "\n\n", text)
        DOC.write_text(text, encoding="utf-8")
        print(f"wrote {DOC} and {FIGURES / 'three_branch_layout.svg'}", file=sys.stderr)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
