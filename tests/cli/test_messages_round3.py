"""One-line messages where a reviewer met raw ones (TOML syntax error for a .csv, a raw
FileExistsError, scipy's 'f(a) and f(b) must have different signs')."""

import pytest
from typer.testing import CliRunner

import torquesplit
from model_texts import SPUR_PAIR
from torquesplit.cli import app
from torquesplit.errors import ModelError

runner = CliRunner()

SPUR = SPUR_PAIR.replace("damping_ratio = 0.05\n", 'damping_ratio = 0.05\nbacklash = "100 um"\n')


@pytest.mark.parametrize("suffix", [".csv", ".mat"])
def test_report_of_an_export_says_it_reads_netcdf(tmp_path, suffix):
    f = tmp_path / f"r{suffix}"
    f.write_text("a,b\n1,2\n")
    res = runner.invoke(app, ["report", str(f)])
    assert res.exit_code == 2 and "'report' reads the NetCDF results" in res.stderr


def test_a_results_file_given_as_a_model_is_named_as_such(tmp_path):
    f = tmp_path / "r.nc"
    f.write_bytes(b"\x89HDF\r\n" + b"\0" * 5_000_000)
    with pytest.raises(ModelError, match="is a results file"):
        torquesplit.load_model(f)


def test_an_impossible_contact_load_is_said_in_words(tmp_path):
    """1e9 N on a mill drive's pair printed p_H = 87 GPa without a word; on a small spur
    pair scipy's 'f(a) and f(b) must have different signs'."""
    res = runner.invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11", "--load", "1e9 N",
                              "--harris", "0"])
    assert res.exit_code == 0 and "beyond what any steel flank carries" in res.stderr
    spur = tmp_path / "spur.toml"
    spur.write_text(SPUR)
    res = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--load", "1e7 N",
                              "--harris", "0"])
    # the impact is a side result: its failure no longer ends the analysis (a reviewer
    # lost the whole table to it, with a message naming an internal function)
    assert res.exit_code == 0, res.output
    assert "meshing-in impact: not computed (no corner contact" in res.stdout
    assert "check the load" in res.stdout and "TE p-p" in res.stdout


def test_a_campbell_range_without_campbell_is_refused():
    """'modes --from/--to' without --campbell ignored the range silently."""
    res = runner.invoke(app, ["modes", "ji_li_mill_drive", "--from", "300 rpm", "--to",
                              "900 rpm"])
    assert res.exit_code == 2 and "add --campbell" in res.stderr


@pytest.mark.parametrize("args, said", [
    (["--plot", "x.png"], "--plot draws the Campbell diagram; add --campbell"),
    (["--campbell", "--from", "100 rpm", "--to", "200 rpm", "--count", "2"],
     "--count limits the list of modes; the Campbell map takes every mode"),
    (["--campbell", "--from", "100 rpm", "--to", "200 rpm", "--count", "2", "--below",
      "60 Hz"], "--count and --below limit the list of modes"),
])
def test_modes_options_of_the_other_form_are_refused_not_ignored(tmp_path, args, said):
    """A reviewer's 'modes --plot x.png' wrote nothing and said nothing; --count and
    --below printed the same Campbell critical speeds as without them."""
    args = [a if a != "x.png" else str(tmp_path / a) for a in args]
    res = runner.invoke(app, ["modes", "ji_li_mill_drive", *args])
    assert res.exit_code == 2 and said in " ".join(res.stderr.split()), res.output
    assert not (tmp_path / "x.png").exists()


def test_a_positive_base_pitch_deviation_brings_the_entering_pair_early(tmp_path):
    """The field said 'driver minus driven', but the analysis (rightly, for the premature
    contact the field is there for) takes f_pb > 0 as early engagement, which is driven
    minus driver: the driver's next flank lies p_b(driver) behind, the driven gear's
    p_b(driven) behind (a reviewer).  Now the description says what the code does."""
    import json

    from torquesplit.model.schema_modifications import MisalignmentSpec

    said = MisalignmentSpec.model_fields["base_pitch_deviation"].description
    assert said.startswith("Normal base pitch of the driven gear minus that of the driver")
    spur = tmp_path / "spur.toml"
    spur.write_text(SPUR_PAIR)
    impact = {}
    for f in (10, -10):
        res = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--positions", "32",
                                  "--slices", "4", "--harris", "0", "--json", "--set",
                                  f"meshes.m.misalignment.base_pitch_deviation={f} um"])
        assert res.exit_code == 0, res.output
        impact[f] = json.loads(res.stdout)["impact"]
    assert impact[10]["advance_m"] > impact[-10]["advance_m"]  # earlier, deeper approach
    assert impact[10]["corner_separation_m"] == 0.0 < impact[-10]["corner_separation_m"]


RING_DRIVES = """
[model]
name = "internal 24/60, ring drives"

[gears.pinion]
teeth = 24
module = "4 mm"
face_width = "25 mm"
position = ["0 mm", "0 mm", "0 mm"]

[gears.ring]
teeth = 60
module = "4 mm"
face_width = "25 mm"
kind = "internal"
place = {from_gear = "pinion", angle = "0 deg"}

[meshes.m]
gears = ["pinion", "ring"]
stiffness = {method = "ltca", ltca = {positions = 16}}
damping_ratio = 0.05

[drives.motor]
body = "ring"
speed = "400 rpm"
torque = "500 N m"

[loads.out]
body = "pinion"
"""


def test_contact_and_mesh_say_who_drives_and_which_stiffness_the_run_takes(tmp_path):
    """A driving ring was printed as 'pinion drives ring'; the mesh table's 'model file'
    row of an LTCA mesh did not say it is the tangent at the operating load (a reviewer)."""
    path = tmp_path / "ring.toml"
    path.write_text(RING_DRIVES)
    res = runner.invoke(app, ["contact", str(path), "--pair", "m", "--positions", "16",
                              "--slices", "4", "--harris", "0"])
    assert res.exit_code == 0, res.output
    assert "(ring drives pinion)" in res.stdout
    res = runner.invoke(app, ["mesh", str(path), "--pair", "m"])
    assert res.exit_code == 0, res.output
    assert "model file (ltca, tangent:" in res.stdout and "dP/dZ" in res.stdout  # (wrapped)


def test_the_arc_seconds_axis_names_its_gear(tmp_path):
    """The figures' right axis read 'TE of gear 2' without naming the gear."""
    from torquesplit.gears.contact.coupling import contact_model_for_mesh
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.plot.contact import te_figure

    path = tmp_path / "ring.toml"
    path.write_text(RING_DRIVES)
    model = torquesplit.load_model(path)
    cm, load, names, _ = contact_model_for_mesh(model, solve_kinematics(model), "m")
    ax = te_figure([cm.solve(load)], gear=names[1]).axes[0]
    assert ax.child_axes[0].get_ylabel() == "TE, arc seconds of ring [arc s]"


def test_an_absurd_inertia_is_named_beside_the_statics_it_breaks(tmp_path):
    """A wheel of 1e-30 kg m^2 was refused as 'make the drive and load torques consistent'
    (the load was 'balanced'); the inertia is named now, and an implausible one warned."""
    path = tmp_path / "pair.toml"
    path.write_text(SPUR_PAIR.replace('polar_inertia = "6e-4 kg m^2"',
                                      'polar_inertia = "1e-30 kg m^2"'))
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 2
    assert "gears.wheel.polar_inertia: 1e-30 kg m^2 is" in res.stderr
    assert "times that of a steel disc of this gear's size" in res.stderr
    path.write_text(SPUR_PAIR.replace('polar_inertia = "6e-4 kg m^2"',
                                      'polar_inertia = "600 kg m^2"'))  # kg mm^2 meant
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 0 and "gears.wheel.polar_inertia: 600 kg m^2 is" in res.stderr


def test_contact_takes_the_gear_of_each_torque_load(tmp_path):
    """'--load "680 N m" --on wheel --load "340 N m" --on pinion' took the last --on for
    both loads (the wheel's 680 N m read as 19.3 kN, twice the pinion's equal load): one
    --on per --load, in their order; each row says what it was given as."""
    import json

    spur = tmp_path / "spur.toml"
    spur.write_text(SPUR)
    m = torquesplit.load_model(spur)
    ratio = m.gears["wheel"].teeth / m.gears["pinion"].teeth  # (the same normal load)
    res = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--harris", "0", "--json",
                              "--load", f"{20 * ratio} N m", "--on", "wheel",
                              "--load", "20 N m", "--on", "pinion"])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.stdout)["loads"]
    assert rows[0]["load_N"] == pytest.approx(rows[1]["load_N"], rel=1e-12)
    assert [r["given_as"] for r in rows] == [f"{20 * ratio} N m on wheel", "20 N m on pinion"]
    bad = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--load", "20 N m",
                              "--on", "wheel", "--on", "pinion", "--on", "wheel"])
    assert bad.exit_code == 2 and "--on is given 3 times for 1 --load" in bad.output


def test_contact_takes_the_model_files_limits_and_warnings(tmp_path):
    """--positions 4 ran where the model file's ltca.positions refuses fewer than 8,
    --slices 1 was refused where the file accepts it, and --slices 2 did not warn that a
    crowned lead is not resolved, as the file's slices = 2 does."""
    from model_texts import RELIEVED_SPUR_LTCA

    spur = tmp_path / "spur.toml"
    spur.write_text(RELIEVED_SPUR_LTCA)
    few = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--positions", "4"])
    assert few.exit_code == 2 and "--positions must be a whole number of at least 8" \
        in few.output
    res = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--slices", "2",
                              "--positions", "16", "--harris", "0"])
    assert res.exit_code == 0, res.output
    assert ("warning: --slices 2: 2 slice(s) across the face cannot resolve the lead "
            "modification of pinion") in res.stderr
    one = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--slices", "1",
                              "--positions", "16", "--harris", "0"])
    assert one.exit_code == 0, one.output


def test_modifications_and_an_ltca_on_a_bevel_pair_are_refused_together(tmp_path):
    """A reviewer's bevel pair with modifications and method 'ltca' was refused for the
    modifications alone; the LTCA's refusal came only after removing them."""
    text = """
[model]
name = "bevel LTCA"
[gears.pinion]
teeth = 20
module = "3 mm"
kind = "bevel"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
modifications = {crowning = "10 um"}
[gears.wheel]
teeth = 40
module = "3 mm"
kind = "bevel"
face_width = "20 mm"
axis = [1, 0, 0]
position = ["0 mm", "0 mm", "60 mm"]
[meshes.m]
gears = ["pinion", "wheel"]
shaft_angle = "90 deg"
damping_ratio = 0.05
stiffness = {method = "ltca"}
[drives.motor]
body = "pinion"
speed = "1500 rpm"
torque = "100 N m"
[loads.out]
body = "wheel"
"""
    path = tmp_path / "bev.toml"
    path.write_text(text)
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 2
    assert "gears.pinion.modifications: tooth modifications are analysed for cylindrical" \
        in res.output and "meshes.m.stiffness.method: the LTCA is implemented for " \
        "cylindrical pairs" in res.output, res.output


def test_contact_json_carries_the_curves_over_the_mesh_cycle(tmp_path):
    """'contact --json' gave scalars only: the loaded TE curve could not be exported."""
    import json

    import numpy as np

    spur = tmp_path / "spur.toml"
    spur.write_text(SPUR)
    res = runner.invoke(app, ["contact", str(spur), "--pair", "m", "--harris", "0",
                              "--positions", "16", "--json"])
    assert res.exit_code == 0, res.output
    row, = json.loads(res.stdout)["loads"]
    assert len(row["phase"]) == len(row["te_m"]) == len(row["stiffness_tangent_N_per_m"]) == 16
    te = np.array(row["te_m"])
    assert np.ptp(te) == pytest.approx(row["te_peak_to_peak_m"], rel=1e-12)
    assert te.mean() == pytest.approx(row["te_mean_m"], rel=1e-12)
