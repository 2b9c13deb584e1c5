"""A gear engineer's first hour (issue 13): one test per finding, each the reproduction.

Every test runs the command line on small models (a 6-gear, two-path split of
``model_texts``) so that the whole file takes seconds.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import torquesplit
from model_texts import SPUR_PAIR, split_model, write_model
from torquesplit.cli import app

runner = CliRunner()
SRC = str(Path(torquesplit.__file__).resolve().parents[1])

#: the two-path split with a mesh-frequency error on a1 large enough to push its teeth
#: into tension: no backlash, so a1 is in double-flank contact part of each cycle
TENSION = split_model(error_a='0 um", amplitude = "150 um')
#: the same with backlash on every mesh: the teeth separate instead (contact loss)
RATTLE = TENSION.replace('stage = "split"\n', 'stage = "split"\nbacklash = "40 um"\n')


def one_line_error(res, *patterns) -> str:
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    assert res.exit_code == 2, (res.exit_code, res.output)
    lines = res.stderr.strip().splitlines()
    errors = [ln for ln in lines if ln.startswith("error: ")]
    assert len(errors) == 1 and all(ln.startswith(("error: ", "warning: ", "note: "))
                                    for ln in lines), res.stderr
    for p in patterns:
        assert p in res.stderr, (p, res.stderr)
    return res.stderr


def warnings_of(res) -> list[str]:
    return [ln[len("warning: "):] for ln in res.stderr.splitlines()
            if ln.startswith("warning: ")]


@pytest.fixture
def no_compute(monkeypatch):
    """Any computation fails the test: what is refused must be refused first."""
    import torquesplit.quasistatic
    import torquesplit.simulation

    def computed(*args, **kwargs):
        raise AssertionError("the command computed before refusing")

    monkeypatch.setattr(torquesplit.simulation, "simulate", computed)
    monkeypatch.setattr(torquesplit.quasistatic, "quasi_static_load_sharing", computed)


@pytest.fixture(scope="module")
def tension_run(tmp_path_factory):
    """``run TENSION --json --out r.nc``: stdout, stderr and the results file."""
    d = tmp_path_factory.mktemp("tension")
    model = write_model(d, TENSION)
    res = runner.invoke(app, ["run", str(model), "--cycles", "60", "--json", "--out",
                              str(d / "r.nc")])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), res.stderr, d / "r.nc", model


# =========================================================================== finding 1
def test_zero_backlash_mesh_reports_double_flank_contact_everywhere(tension_run):
    """Tensile tooth force with 'contact loss 0.00 %' and no word."""
    data, stderr, nc, model = tension_run
    a1 = data["metrics"]["meshes"]["a1"]
    assert a1["double_flank"] is True and a1["contact_loss"] == 0.0
    assert a1["back_contact"] > 0.01 and a1["back_flank_force"] > 0
    # the largest back-flank force of the run (its transient included) is at least the
    # settled part's
    assert a1["min_force"] < 0 and a1["back_flank_force"] >= -a1["min_force"]
    said = [w for w in data["warnings"] if w.startswith("meshes.a1: double-flank contact")]
    assert len(said) == 1 and "meshes.a1.backlash" in said[0]
    assert said[0] in stderr  # the terminal too
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert said[0] in ds.attrs["warnings"]
        assert json.loads(ds.attrs["warnings_json"]) == data["warnings"]
        j = list(ds["mesh"].values).index("a1")
        assert float(ds["back_flank_force"][j]) == pytest.approx(a1["back_flank_force"])
        assert int(ds["double_flank"][j]) == 1
        # the mesh table's forces are variables of the file too (not only in metrics_json)
        for name in ("mean_force", "peak_force", "min_force", "dynamic_factor_engineering"):
            assert float(ds[name][j]) == pytest.approx(a1[name]), name
    table = runner.invoke(app, ["run", str(model), "--cycles", "60"])
    row = next(ln for ln in table.stdout.splitlines() if ln.lstrip("│ ").startswith("a1 "))
    cells = [c.strip() for c in row.split("│")]
    assert cells[-3] == "no backlash" and cells[-2].endswith(" kN"), row


def test_backlash_mesh_reports_contact_loss_in_json_and_file(tmp_path):
    """'run FACE_GEAR --json' dropped the contact-loss warning."""
    model = write_model(tmp_path, RATTLE)
    res = runner.invoke(app, ["run", str(model), "--cycles", "60", "--json",
                              "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    loss = [w for w in data["warnings"] if "contact loss" in w]
    assert loss and loss[0].startswith("meshes.a1: contact loss")
    assert data["metrics"]["meshes"]["a1"]["contact_loss"] > 0
    with xr.open_dataset(tmp_path / "r.nc", engine="h5netcdf") as ds:
        assert loss[0] in ds.attrs["warnings"]


def test_a_20_mm_installation_error_is_flagged_before_and_after_the_run(tmp_path):
    """A 20 mm installation error (typo for 20 um) passed check; run printed -123 kN.
    Deeper than the whole tooth (4.5 mm here) it is refused; one between the module and
    the tooth depth is flagged before and after the run."""
    deep = split_model().replace("[gears.b2]", '[gears.a.errors]\ninstallation = "20 mm"\n\n'
                                               "[gears.b2]")
    for command in ("check", "run"):
        refused = runner.invoke(app, [command, str(write_model(tmp_path, deep, "deep.toml"))])
        assert refused.exit_code == 2 and "gears.a.errors.installation: 20 mm is deeper " \
            "than the whole tooth" in refused.output, refused.output
    text = deep.replace('installation = "20 mm"', 'installation = "3 mm"')
    model = write_model(tmp_path, text)
    check = runner.invoke(app, ["check", str(model)])
    assert check.exit_code == 0, check.output
    said = [w for w in warnings_of(check) if "gears.a.errors.installation" in w]
    assert any("3 mm is larger than the module" in w for w in said)
    assert any("ISO 1328-1 runout tolerance" in w and "coarsest grade, 11" in w for w in said)
    res = runner.invoke(app, ["run", str(model), "--cycles", "30", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert any(w.startswith("meshes.") and "the static force is -" in w
               for w in data["warnings"]), data["warnings"]
    assert any("gears.a.errors.installation" in w for w in data["warnings"])


def test_errors_beyond_the_stated_grade_and_odd_backlash_are_flagged(tmp_path):
    text = split_model().replace(
        "[gears.b2]", '[gears.a.errors]\neccentricity = "30 um"\ngrade = 5\n\n[gears.b2]')
    text = text.replace('stage = "combine"\n', 'stage = "combine"\nbacklash = "3 mm"\n', 1)
    res = runner.invoke(app, ["check", str(write_model(tmp_path, text))])
    assert res.exit_code == 0, res.output
    said = warnings_of(res)
    assert any(w.startswith(f"{tmp_path}") and "gears.a.errors.eccentricity" in w
               and "grade 5" in w for w in said), said
    assert any("meshes.a2.backlash" in w and "ISO/TR 10064-2" in w for w in said), said
    quiet = runner.invoke(app, ["check", str(write_model(tmp_path, split_model(), "ok.toml"))])
    assert not warnings_of(quiet), quiet.stderr  # a sound model: no warning at all
    # an installation error is the bore's, which the gear's grade does not bound (a
    # reviewer's 20 um on an 845 mm centre distance was flagged against grade 5's F_rT)
    bore = split_model().replace(
        "[gears.b2]", '[gears.a.errors]\ninstallation = "20 um"\ngrade = 3\n\n[gears.b2]')
    res = runner.invoke(app, ["check", str(write_model(tmp_path, bore, "bore.toml"))])
    assert res.exit_code == 0 and not warnings_of(res), res.stderr


def test_a_pitch_error_is_checked_as_the_total_cumulative_deviation_it_models(tmp_path):
    """The dynamics take ``pitch`` as F_p (a once-per-revolution harmonic of F_p/2), but
    the check compared it with the single pitch tolerance f_pT, about 3x smaller: a
    pitch error of a grade-6 gear was flagged as coarser than its grade."""
    from torquesplit.gears import grades

    model = torquesplit.load_model(write_model(tmp_path, split_model(), "m.toml"))
    g = model.gears["a"]
    d = g.teeth * g.module / math.cos(g.helix_angle)
    f_pt = grades.single_pitch_tolerance(6, g.module, d)
    big_f_pt = grades.total_cumulative_pitch_tolerance(6, g.module, d)
    assert big_f_pt > 2 * f_pt
    value = f"{0.5 * (f_pt + big_f_pt) * 1e6:.3f} um"  # above f_pT, within F_pT
    text = split_model().replace(
        "[gears.b2]", f'[gears.a.errors]\npitch = "{value}"\ngrade = 6\n\n[gears.b2]')
    res = runner.invoke(app, ["check", str(write_model(tmp_path, text))])
    assert res.exit_code == 0 and not warnings_of(res), res.stderr
    text = text.replace(value, f"{2 * big_f_pt * 1e6:.3f} um")
    res = runner.invoke(app, ["check", str(write_model(tmp_path, text))])
    assert any("gears.a.errors.pitch" in w and "F_pT" in w for w in warnings_of(res)), res.stderr


def test_a_position_off_the_operating_centre_distance_is_said_to_be_ignored(tmp_path):
    """A wheel 50 um off the 60 mm centre distance (within the 0.1 % the layout accepts)
    changed nothing and said nothing; 2 um (typed rounding) stays quiet."""
    for offset, said in ((50, True), (2, False)):
        text = SPUR_PAIR.replace('place = {from_gear = "pinion", angle = "0 deg"}',
                                 f'position = ["{60 + offset * 1e-3:.6f} mm", "0 mm", "0 mm"]')
        res = runner.invoke(app, ["check", str(write_model(tmp_path, text, f"o{offset}.toml"))])
        assert res.exit_code == 0, res.output
        hits = [w for w in warnings_of(res) if "off their operating centre distance" in w]
        assert bool(hits) == said, res.stderr
        if said:
            assert "meshes.m" in hits[0] and f"+{offset} um" in hits[0]


def test_a_dynamic_factor_above_three_points_to_modes(tension_run):
    data, stderr, nc, model = tension_run
    over = [m for m, r in data["metrics"]["meshes"].items() if r["dynamic_factor"] > 3]
    said = [w for w in data["warnings"] if "near a resonance" in w]
    assert over and sorted(w.split(":")[0] for w in said) == sorted(f"meshes.{m}" for m in over)
    assert all("torquesplit modes" in w for w in said)


@pytest.mark.parametrize("extra,pattern", [
    ('position = ["50 mm", "0 mm", "0 mm"]', "off their common axis"),
    ('axis = [1.0, 0.0, 0.0]', "axes are not parallel"),
])
def test_check_refuses_a_shaft_between_bodies_off_a_common_axis(tmp_path, extra, pattern):
    text = SPUR_PAIR.replace(
        "[gears.pinion]", f'[bodies.motor]\npolar_inertia = "0.01 kg m^2"\n{extra}\n\n'
        '[shafts.s]\nconnects = ["motor", "pinion"]\ntorsional_stiffness = "1e5 N m/rad"\n\n'
        '[gears.pinion]', 1).replace('body = "pinion"', 'body = "motor"')
    one_line_error(runner.invoke(app, ["check", str(write_model(tmp_path, text))]),
                   "shafts.s:", pattern)
    same = text.replace(extra, 'position = ["0 mm", "0 mm", "-80 mm"]')  # on the axis: fine
    assert runner.invoke(app, ["check", str(write_model(tmp_path, same, "ok.toml"))]
                         ).exit_code == 0


# =========================================================================== finding 2
@pytest.mark.parametrize("args,pattern", [
    (["run", "."], "is a folder, not a model file"),
    (["check", "DIR.toml"], "is a folder, not a model file"),
    (["check", "BIN.toml"], "is not valid UTF-8 text"),
    (["run", "M", "--out", "missing_dir/x.nc"], "does not exist; create it first"),
    (["run", "M", "--plots", "FILE"], "is a file, not a folder"),
    (["run", "M", "--out", "x.xlsx"], "use a .nc, .mat or .csv file"),
    (["static", "M", "--out", "s.xlsx"], "use a .nc, .mat or .csv file"),
    (["report", "M", "--out", "r.pdf"], "use a .html or .htm file"),
    (["draw", "M", "--out", "missing_dir/l.svg"], "does not exist; create it first"),
    (["mesh", "M", "--pair", "m", "--plot", "k.xlsx"], "--plot:"),
    (["modes", "M", "--campbell", "--from", "100", "--to", "200", "--plot", "none/c.png"],
     "does not exist"),
])
def test_no_traceback_and_output_paths_checked_before_computing(tmp_path, no_compute, args,
                                                                pattern):
    (tmp_path / "DIR.toml").mkdir()
    (tmp_path / "BIN.toml").write_bytes(bytes(range(256)))
    (tmp_path / "FILE").write_text("a file")
    model = write_model(tmp_path, SPUR_PAIR)
    swap = {"M": str(model), "DIR.toml": str(tmp_path / "DIR.toml"),
            "BIN.toml": str(tmp_path / "BIN.toml"), "FILE": str(tmp_path / "FILE")}
    args = [swap.get(a, str(tmp_path / a) if "/" in a or a.startswith(("x.", "s.", "r.",
                                                                        "k.")) else a)
            for a in args]
    one_line_error(runner.invoke(app, args), pattern)


def test_csv_results_name_every_file_written(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--cycles", "5", "--out",
                              str(tmp_path / "x.csv")])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())
    for name in ("x.csv", "x_groups.csv", "x_history.csv", "x_cycles.csv", "x_bearings.csv",
                 "x_elements.csv", "x_about.json"):
        assert (tmp_path / name).exists()
        assert name in text
    data = json.loads(runner.invoke(app, ["run", str(model), "--cycles", "5", "--json",
                                          "--force", "--out", str(tmp_path / "x.csv")]).stdout)
    assert sorted(Path(f).name for f in data["results_files"]) == [
        "x.csv", "x_about.json", "x_bearings.csv", "x_cycles.csv", "x_elements.csv",
        "x_groups.csv", "x_history.csv"]


def test_ctrl_c_says_nothing_was_written(tmp_path, monkeypatch):
    integrate = sys.modules["torquesplit.solve.integrate"]

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(integrate, "integrate", interrupted)
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 130
    assert res.stderr.strip().splitlines()[-1] == "interrupted; nothing written"
    assert not (tmp_path / "r.nc").exists() and "Traceback" not in res.output


def test_ctrl_c_after_saving_says_what_was_kept(tmp_path, monkeypatch):
    import torquesplit.plot.figures as figures

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "write_jobs", interrupted)
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--cycles", "5", "--out",
                              str(tmp_path / "r.nc"), "--plots", str(tmp_path / "figs")])
    assert res.exit_code == 130
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("interrupted; results kept in ") and "r.nc" in last
    assert "figures incomplete" in last and (tmp_path / "r.nc").exists()


def test_ctrl_c_while_static_figures_are_written_says_they_are_incomplete(tmp_path,
                                                                          monkeypatch):
    """'static --plots' said 'results kept in s.nc' with the figure folder empty."""
    import torquesplit.plot.figures as figures

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "write_jobs", interrupted)
    res = runner.invoke(app, ["static", "ji_li_mill_drive", "--revolutions", "0.05", "--out",
                              str(tmp_path / "s.nc"), "--plots", str(tmp_path / "figs")])
    assert res.exit_code == 130, res.output
    last = res.stderr.strip().splitlines()[-1]
    assert last == f"interrupted; results kept in {tmp_path / 's.nc'}; figures incomplete"


def test_a_real_sigint_stops_a_run_and_keeps_what_it_computed(tmp_path):
    """Ctrl-C during the integration ends the run as a stopped one: its partial results
    are written (with their status) and said; nothing is lost, no traceback."""
    from torquesplit.solve.integrate import compile_kernels

    # the kernels in numba's cache first: a Ctrl-C while the run compiles them stops it
    # with nothing computed (tests/solve/test_run_setup.py), which is not this test's case
    compile_kernels(("rk4",))
    model = write_model(tmp_path, SPUR_PAIR)
    out = tmp_path / "r.nc"
    proc = subprocess.Popen([sys.executable, "-m", "torquesplit.cli", "run", str(model),
                             "--cycles", "3000000", "--max-steps", "1000000000", "--out",
                             str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ, PYTHONPATH=SRC),
                            # Ctrl-C as a terminal delivers it, even where the test runner
                            # itself runs with SIGINT ignored (a background job: nohup ... &)
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while not (tmp_path / ".r.nc.lock").exists():  # claimed: the run has started
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.1)
    time.sleep(2.0)
    proc.send_signal(signal.SIGINT)
    stdout, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "stopped: Interrupted (Ctrl-C) at t = " in stdout, (stdout, err)
    assert "the partial results (with their status) are in" in " ".join(stdout.split())
    assert "Traceback" not in err and out.exists()
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["message"].startswith("Interrupted (Ctrl-C)") and ds.attrs["status"] == 4


# =========================================================================== finding 3
def test_examples_have_names_users_know_and_old_names_still_work(tmp_path):
    listing = runner.invoke(app, ["examples"])
    assert listing.exit_code == 0
    for name in ("liu2021_split_torque_helicopter", "ji_li_mill_drive", "dong2021_face_gear",
                 "jin2019_friction_split", "mo2017_star_reducer"):
        assert name in listing.stdout
    assert "(start here)" in listing.stdout
    table = listing.stdout.split("The earlier names")[0]
    assert "seed0" not in table
    res = runner.invoke(app, ["example", "seed001_mill_drive", "--dir", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "ji_li_mill_drive.toml").exists()
    assert "note: the example name 'seed001_mill_drive' is deprecated" in res.stderr
    check = runner.invoke(app, ["check", "seed004_star_reducer", "--json"])
    assert check.exit_code == 0, check.output
    data = json.loads(check.stdout)
    assert data["model"] == "mo2017_star_reducer"
    assert any("deprecated" in w for w in data["warnings"])
    with pytest.warns(FutureWarning, match="use 'dong2021_face_gear'"):
        assert torquesplit.example_path("seed002_face_gear").name == "dong2021_face_gear.toml"


def test_public_functions_are_named_for_the_physics():
    from torquesplit.gears import errors

    kw = dict(eccentricity_i=1e-5, phase_i=0.1, omega_i=10.0, installation_i=2e-6,
              installation_phase_i=0.2, eccentricity_j=3e-6, phase_j=0.3, omega_j=5.0,
              installation_j=0.0, installation_phase_j=0.0, sign=1.0)
    new = errors.eccentricity_installation_error_sum_form(line_offset=0.4, **kw)
    with pytest.warns(FutureWarning, match="eccentricity_installation_error_sum_form"):
        old = errors.seed000_mesh_error(line_offset=0.4, **kw)
    assert old.constant == new.constant
    np.testing.assert_array_equal(old.phases, new.phases)
    assert not [n for n in errors.__all__ if n.startswith("seed")]


#: nothing left out of the check (the validation page, its template and its data use the
#: papers' names too)
USER_DOCS_EXEMPT: set[str] = set()


def _help_texts() -> dict[str, str]:
    out = {"torquesplit --help": runner.invoke(app, ["--help"]).stdout}
    import typer.main

    group = typer.main.get_command(app)
    for name in group.commands:
        out[f"torquesplit {name} --help"] = runner.invoke(app, [name, "--help"]).stdout
    return out


def test_no_user_facing_text_says_seed_0():
    """Users never read 'seed 000': CLI help, schema descriptions, example files, docs."""
    pattern = re.compile(r"seed ?0\d\d|seed0\d\d", re.IGNORECASE)
    hits = []
    for where, text in _help_texts().items():
        hits += [f"{where}: {m.group()}" for m in pattern.finditer(text)]
    from torquesplit.model import schema

    for name in dir(schema):
        cls = getattr(schema, name)
        for field_name, info in getattr(cls, "model_fields", {}).items():
            if info.description and pattern.search(info.description):
                hits.append(f"schema {name}.{field_name}")
        if isinstance(cls, type) and cls.__doc__ and hasattr(cls, "model_fields") \
                and pattern.search(cls.__doc__):
            hits.append(f"schema {name} docstring")
    examples = Path(torquesplit.__file__).parent / "examples"
    root = Path(__file__).resolve().parents[2]   # the checkout (the package may be installed)
    files = list(examples.rglob("*.toml"))
    files += [f for f in (root / "docs").rglob("*") if f.is_file()
              and f.name not in USER_DOCS_EXEMPT]
    files += [root / "README.md"]
    for f in files:
        for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
            if pattern.search(line) and "seed000_split_torque" not in line:
                hits.append(f"{f}:{i}")
    assert not hits, hits


# =========================================================================== finding 4
def test_run_help_lists_every_definition_and_when_to_report_it():
    text = " ".join(runner.invoke(app, ["run", "--help"]).stdout.split())
    text = re.sub(r"[│╭╮╰╯─]", " ", text)
    text = " ".join(text.split())
    for d in ("cycle_peak", "instantaneous", "engineering", "mean_force", "static_torque"):
        assert d in text
    assert "K_gamma" in text and "torquesplit static" in text


def test_a_new_model_reports_the_design_standard_definition(tmp_path):
    model = write_model(tmp_path, split_model(error_a="3 um"))
    res = runner.invoke(app, ["run", str(model), "--cycles", "30"])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())
    assert "load sharing: mean_force" in text and "K_gamma" in text
    assert "do not multiply it by a dynamic factor" not in text
    data = json.loads(runner.invoke(app, ["run", str(model), "--cycles", "30", "--json",
                                          "--definition", "cycle_peak"]).stdout)
    assert data["metrics"]["definition"] == "cycle_peak"
    rows = data["metrics"]["meshes"].values()
    assert all(r["dynamic_factor"] >= 1.0 for r in rows)  # the K_v sense: >= 1 in contact


@pytest.mark.parametrize("name", ["static", "static_torque"])
def test_definition_static_points_to_the_static_command(tmp_path, no_compute, name):
    model = write_model(tmp_path, SPUR_PAIR)
    one_line_error(runner.invoke(app, ["run", str(model), "--definition", name]),
                   "run `torquesplit static MODEL`")


def test_a_static_torque_model_runs_dynamically_with_a_note(tmp_path):
    model = write_model(tmp_path, split_model(extra='[analysis]\nload_sharing = '
                                                    '"static_torque"\n'))
    res = runner.invoke(app, ["run", str(model), "--cycles", "20", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["metrics"]["definition"] == "mean_force"
    assert any("quasi-static definition of 'torquesplit static'" in w
               for w in data["warnings"])


# =========================================================================== finding 5
def test_static_reports_progress():
    from torquesplit.quasistatic import quasi_static_load_sharing

    seen = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(torquesplit.example_path("mo2017_star_reducer"))
    quasi_static_load_sharing(model, points_per_cycle=1, progress=seen.append)
    assert len(seen) >= 10 and seen == sorted(seen) and 0.9 <= seen[-1] < 1.0


def test_a_long_run_is_announced_before_it_starts(tmp_path, monkeypatch):
    """'--duration "1 h"' ran silently into 750 MB."""
    integrate = sys.modules["torquesplit.solve.integrate"]

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(integrate, "integrate", interrupted)
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--duration", "1 h", "--max-steps",
                              "10000000000"])
    assert res.exit_code == 130
    said = " ".join(warnings_of(res))
    assert re.search(r"this run takes [\d,]+ RK4 steps", said)
    assert re.search(r"about [\d.]+ (min|s) of integration and [\d,]+ MB of results", said)


def test_figures_say_what_they_are_doing():
    import tempfile

    from torquesplit.plot.figures import write_jobs

    seen = []
    made = []

    def job(name):
        return name, lambda: made.append(name) or _tiny_figure()

    write_jobs([job("a"), job("b")], tempfile.mkdtemp(), ("svg",),
               progress=lambda i, n, what: seen.append((i, n, what)))
    assert seen == [(0, 2, "a"), (1, 2, "b"), (2, 2, "done")] and made == ["a", "b"]


def _tiny_figure():
    from torquesplit.plot.figures import _figure

    fig = _figure(3, 2)
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], label="a line")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))  # outside the axes
    return fig


def test_saved_figures_never_clip_their_legends(tmp_path):
    """Legends placed right of the axes were cut off at the figure edge."""
    from matplotlib.image import imread

    from torquesplit.plot.figures import save_figure

    fig = _tiny_figure()
    path, = save_figure(fig, [tmp_path / "f.png"], dpi=100)
    legend = fig.axes[0].get_legend().get_window_extent()
    width_px = imread(path).shape[1]
    assert width_px >= legend.x1 - fig.bbox.x0  # the legend's right edge is inside
    assert width_px > 3 * 100  # wider than the 3 in figure: it was cropped to the content


# =========================================================================== finding 6
def test_check_tables_carry_their_units(tmp_path):
    model = write_model(tmp_path, split_model())
    text = runner.invoke(app, ["check", str(model)]).stdout
    for unit in ("speed [rpm]", "mass [kg]", "J [kg m²]", "position [mm]", "r_b [mm]",
                 "torque [N m]", "f_mesh [Hz]", "F_n [kN]"):
        assert unit in text, unit


def test_placed_gears_are_flagged_as_computed_positions(tmp_path):
    data = json.loads(runner.invoke(app, ["check", str(write_model(tmp_path, split_model())),
                                          "--json"]).stdout)
    flags = {b: v["position_computed"] for b, v in data["bodies"].items()}
    assert flags["a"] and flags["b"]  # placed from the pinion
    assert not flags["pinion"] and not flags["out"]  # positions given in the file


def test_static_orbits_in_micrometres_and_mesh_stiffness_in_n_per_um(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    mesh = runner.invoke(app, ["mesh", str(model), "--pair", "m"]).stdout
    assert "mean [N/µm]" in mesh and "N/(mm µm)" in mesh
    floating = split_model().replace(
        'position = ["0 mm", "0 mm", "0 mm"]\n',
        'position = ["0 mm", "0 mm", "0 mm"]\ndofs = ["x", "y", "theta"]\nsupport = '
        '{stiffness = "2e8 N/m"}\n', 1)
    static = runner.invoke(app, ["static", str(write_model(tmp_path, floating, "f.toml")),
                                 "--points-per-cycle", "2"])
    assert static.exit_code == 0, static.output
    assert "x range [µm]" in static.stdout and "max F [kN]" in static.stdout


def test_bare_numbers_on_the_command_line_are_si(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    data = json.loads(runner.invoke(app, ["run", str(model), "--duration", "0.02",
                                          "--json"]).stdout)
    assert data["statistics"]["simulated_time_s"] == pytest.approx(0.02)


def test_a_bare_module_says_it_is_metres(tmp_path):
    """'module = 3' is 3 m; the messages say that a bare number is SI."""
    text = SPUR_PAIR.replace('module = "2 mm"', "module = 3")
    res = runner.invoke(app, ["check", str(write_model(tmp_path, text))])
    assert res.exit_code == 2 and "Traceback" not in res.output
    # (one cause at two places: one line naming both)
    assert "gears.pinion.module, gears.wheel.module: 3 m is implausibly large; a bare number " \
           "is read in metres: write '3 mm'" in res.stderr
    text = SPUR_PAIR.replace('face_width = "20 mm"', "face_width = 20", 1)
    res = runner.invoke(app, ["check", str(write_model(tmp_path, text, "w.toml"))])
    said = [w for w in warnings_of(res) if "gears.pinion.face_width" in w]
    assert said, res.output


# =========================================================================== finding 11
def test_version_and_clean_flags():
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0 and res.stdout.strip() == f"torquesplit {torquesplit.__version__}"
    for command in ("run", "check", "static", "report", "draw", "modes"):
        text = runner.invoke(app, [command, "--help"]).stdout
        assert "<bool>" not in text and "<str>" not in text and "<path>" not in text, command


def test_every_json_output_has_a_warnings_list(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    for args in (["check", str(model)], ["modes", str(model)],
                 ["static", str(model), "--points-per-cycle", "2"],
                 ["mesh", str(model), "--pair", "m"]):
        res = runner.invoke(app, [*args, "--json"])
        assert res.exit_code == 0, res.output
        assert isinstance(json.loads(res.stdout)["warnings"], list), args


def test_results_metrics_leave_out_the_cut_off_cycles(tmp_path):
    """A spike at the very end of the load-sharing trace became the reported value."""
    res = torquesplit.simulate(torquesplit.load_model(write_model(tmp_path, TENSION)),
                               cycles=40)
    s = res.solution
    cols = res._mesh_columns
    complete = res.complete_cycles
    finite = np.isfinite(s.cycle_max[:, cols])
    assert (finite & ~complete).any()  # the run does cut cycles
    for definition in ("cycle_peak", "mean_force", "instantaneous"):
        per_cycle = res.metrics(definition).load_sharing.per_cycle
        for j, m in enumerate(res.mesh_names):
            assert np.all(np.isnan(per_cycle[m][~complete[:, j]]))


def test_check_gives_a_helical_meshs_axial_force_and_a_spur_table_stays_narrow(tmp_path):
    """The axial thrust of a helical mesh was nowhere (a reviewer's mill drive: 19.8 kN on
    its input pinion, F_n sin(beta_b))."""
    import math

    res = runner.invoke(app, ["check", "ji_li_mill_drive", "--json"])
    data = json.loads(res.stdout)
    m = data["meshes"]["m11"]
    kin = torquesplit.solve_kinematics("ji_li_mill_drive")
    beta_b = math.asin(abs(kin.meshes["m11"].line_of_action[2]))
    assert m["axial_force_N"] == pytest.approx(m["tooth_force_N"] * math.sin(beta_b), rel=1e-9)
    assert 0.15 < m["axial_force_N"] / m["tooth_force_N"] < 0.25  # (beta_b about 11 deg)
    assert "F_a [kN]" in runner.invoke(app, ["check", "ji_li_mill_drive"]).stdout
    spur = runner.invoke(app, ["check", str(write_model(tmp_path, split_model()))])
    assert "F_a" not in spur.stdout
