"""Campbell diagram of a turning carrier after a modal review: shaft orders in the
carrier's frame, whirl-selective mesh phasing and a readable figure."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

import torquesplit
from torquesplit import example_path, load_model
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.steady.maps import campbell

RPM = math.pi / 30

# a 3-planet 43/47/137 stage after Lin & Parker 1999 (ring held, sun in, carrier out)
LP3 = """
[model]
name = "lp3"
[[planetary]]
name = "stage"
planets = 3
module = "2.25 mm"
pressure_angle = "24.6 deg"
face_width = "30 mm"
[planetary.sun]
teeth = 43
mass = "0.4 kg"
polar_inertia = "0.39 kg * (42.9614 mm)**2"
dofs = ["theta", "x", "y"]
support = {stiffness = "1e8 N/m"}
[planetary.planet]
teeth = 47
mass = "0.66 kg"
polar_inertia = "0.61 kg * (49.0987 mm)**2"
[planetary.ring]
teeth = 137
mass = "2.35 kg"
polar_inertia = "3.00 kg * (141.1589 mm)**2"
dofs = ["theta", "x", "y"]
support = {stiffness = "1e8 N/m"}
torsional_support = {stiffness = "1e9 N/m * (141.1589 mm)**2"}
[planetary.carrier]
mass = "5.43 kg"
polar_inertia = "6.29 kg * (101.25 mm)**2"
dofs = ["theta", "x", "y"]
support = {stiffness = "1e8 N/m"}
[planetary.planet_bearing]
stiffness = "1e8 N/m"
[planetary.sun_mesh]
stiffness = {method = "constant", value = "5e8 N/m", peak_to_peak = 0.2}
damping_ratio = 0.005
[planetary.ring_mesh]
stiffness = {method = "constant", value = "5e8 N/m", peak_to_peak = 0.2}
damping_ratio = 0.005
[drives.input]
body = "stage_sun"
speed = "1000 rpm"
torque = "100 N m"
[loads.output]
body = "stage_carrier"
"""


def _lp3(fixed: str = "ring"):
    """The stage with the ring held (sun input), or the sun held (ring input): the sun
    turns relative to the carrier with, or against, the carrier's rotation."""
    import tomllib

    raw = tomllib.loads(LP3)
    if fixed == "sun":
        st = raw["planetary"][0]
        st["sun"]["torsional_support"] = {"stiffness": "1e9 N/m * (42.9614 mm)**2"}
        st["ring"].pop("torsional_support")
        raw["drives"]["input"]["body"] = "stage_ring"
    return load_model(raw)


def _lp_with_eccentricities():
    raw = copy.deepcopy(torquesplit.model.io.read_file(example_path("lin_parker1999_planetary")))
    for member in ("sun", "planet"):
        raw["planetary"][0][member]["errors"] = {"eccentricity": "10 um"}
    return load_model(raw)


def test_shaft_order_lines_are_the_speeds_relative_to_a_turning_carrier():
    """The eccentricities of sun and planets are applied at their speeds relative to the
    carrier, where the natural frequencies are computed; the lines were drawn at the
    absolute speeds (16.7 and 7.3 Hz for 12.8 and 11.2 Hz at 1000 rpm)."""
    from torquesplit.assembly import excitation

    model = _lp_with_eccentricities()
    kin = solve_kinematics(model)
    ds, _ = campbell(model, 1000 * RPM, 1100 * RPM, points=2)
    lines = {str(k): float(f) for k, f in zip(ds["line"].values,
                                                ds["excitation_frequency"].values[0])}
    sp = {b: kin.bodies[b].speed for b in ("stage_sun", "stage_planet1", "stage_carrier")}
    sun = "1 x rotation of stage_sun relative to stage_carrier"
    planet = "1 x rotation of stage_planet1 relative to stage_carrier"
    assert lines[sun] == pytest.approx(abs(sp["stage_sun"] - sp["stage_carrier"]) / 2 / math.pi)
    assert lines[planet] == pytest.approx(
        abs(sp["stage_planet1"] - sp["stage_carrier"]) / 2 / math.pi)
    _, sines = excitation.mesh_errors(model, kin, "stage_sun_planet1")
    applied = sorted({round(om / 2 / math.pi, 6) for _, om, _ in sines})
    assert applied == pytest.approx(sorted([lines[sun], lines[planet]]), rel=1e-6)
    assert not [k for k in lines if "rotation of stage_carrier" in k]  # still in its frame


def test_a_fixed_axis_train_keeps_its_absolute_shaft_orders():
    model = load_model(example_path("ji_li_mill_drive"))
    kin = solve_kinematics(model)
    ds, _ = campbell(model, 200 * RPM, 300 * RPM, points=2)
    w = ds["speed"].values[0] / torquesplit.steady.maps.reference_speed(model)
    for name, f in zip(ds["line"].values, ds["excitation_frequency"].values[0]):
        if "rotation of" in str(name):
            assert "relative" not in str(name)
            body = str(name).split("rotation of ")[1]
            assert f == pytest.approx(abs(kin.bodies[body].speed) * w / 2 / math.pi)


@pytest.mark.parametrize("fixed", ["ring", "sun"])
def test_a_mesh_harmonic_drives_one_whirl_of_each_split_pair(fixed):
    """The modal force phi^H F of harmonic l of the phased mesh stiffness on each whirl of
    the split translational pairs: the whirl the rule keeps gets all of it, the other
    none (Parker & Lin 2004's (l z_s -+ 1) / N, by the sense of the sun's rotation
    relative to the carrier: forward with a held ring, backward with a held sun)."""
    from torquesplit.modes import model_modes, phased_stages
    from torquesplit.solve.static import static_equilibrium

    model = _lp3(fixed)
    kin = solve_kinematics(model)
    (stage,) = phased_stages(model, kin)
    assert stage.sun_sense == (1 if fixed == "ring" else -1)
    rep = model_modes(model)
    st = torquesplit.assemble(model)
    d0 = st.projection_matrix() @ static_equilibrium(st).q - st.error_constant
    tab = np.fft.rfft(st.stiffness_table, axis=1) / st.stiffness_table.shape[1]
    pairs = [r for r in rep.rows if r.type == "translational"][:4]  # two split pairs
    assert [r.whirl for r in pairs] == ["forward", "backward"] * 2
    for order in (1, 2):  # 43 - 1 and 86 + 1 are multiples of 3
        amp = np.where(st.frequency > 0, 2 * tab[:, order] * np.exp(2j * np.pi * order
                                                                     * st.phase), 0)
        force = -(st.projection_matrix().T @ (amp * d0))
        modal = [abs(rep.solution.mode_shapes[:, r.mode - 1].conj() @ force) for r in pairs]
        driven = "forward" if (order == 1) == (fixed == "ring") else "backward"
        for r in pairs:
            assert stage.excites(order, "translational", r.whirl) == (r.whirl == driven)
        for fw, bw in ((modal[0], modal[1]), (modal[2], modal[3])):
            small, large = (bw, fw) if driven == "forward" else (fw, bw)
            assert small < 1e-6 * large


def test_the_campbell_lists_one_whirl_of_a_pair_as_excited():
    """It marked both whirls of a split pair as excited by a mesh harmonic."""
    from torquesplit.steady.maps import mode_kind

    ds, crossings = campbell(_lp3(), 500 * RPM, 1500 * RPM, points=11)
    trans = [c for c in crossings if c.get("mode_type") == "translational"
             and c["source"].startswith("mesh")]
    assert trans and all(c["whirl"] in ("forward", "backward") for c in trans)
    for c in trans:
        lz = c["order"] * 43
        assert c["suppressed"] == (lz % 3 != (1 if c["whirl"] == "forward" else 2)), c
    excited = {(c["order"], c["whirl"]) for c in trans if not c["suppressed"]}
    assert (1, "forward") in excited and (1, "backward") not in excited
    assert (2, "backward") in excited and (2, "forward") not in excited
    assert any("backward whirl mode: suppressed" in lab
               for lab in ds.attrs["suppressed_speed_labels"])
    assert mode_kind(trans[0]).startswith("translational, ")


def test_the_modes_table_and_json_give_the_whirl(tmp_path):
    import json

    from typer.testing import CliRunner

    from torquesplit.cli import app

    path = tmp_path / "lp3.toml"
    path.write_text(LP3, encoding="utf-8")
    runner = CliRunner()
    res = runner.invoke(app, ["modes", str(path), "--count", "4"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "whirl" in res.stdout and "FW" in res.stdout and "BW" in res.stdout
    res = runner.invoke(app, ["modes", str(path), "--count", "4", "--json"])
    assert [m["whirl"] for m in json.loads(res.stdout)["modes"]] == ["forward", "backward"] * 2
    res = runner.invoke(app, ["modes", str(path), "--count", "4", "--json",
                              "--no-rotating-frame"])  # degenerate pairs: no whirl
    assert {m["whirl"] for m in json.loads(res.stdout)["modes"]} == {None}


@pytest.fixture(scope="module")
def lp3_figure():
    from torquesplit.steady.plot import campbell_figure

    raw = __import__("tomllib").loads(LP3)
    raw["model"]["name"] = "a planetary stage with a rather long name " * 3
    ds, _ = campbell(load_model(raw), 500 * RPM, 3000 * RPM, points=5)
    fig = campbell_figure(ds)
    fig.canvas.draw()
    return ds, fig


def test_the_campbell_figure_fits_its_title_and_keeps_the_legend_off_the_lines(lp3_figure):
    """A reviewer's figure: the title cut off on the left, order labels under the legend,
    critical speeds printed at 5 pt, one mesh's name for eight meshes, no operating
    speed."""
    ds, fig = lp3_figure
    ax = fig.axes[0]
    width = fig.bbox.width
    title = ax.title.get_window_extent()
    assert title.x0 >= 0 and title.x1 <= width
    legend = ax.get_legend().get_window_extent()
    assert not legend.overlaps(ax.get_window_extent())
    for t in ax.texts:  # every label inside the figure, none under the legend
        box = t.get_window_extent()
        assert box.x0 >= -1 and box.x1 <= width + 1, t.get_text()
        assert not box.overlaps(legend), t.get_text()
    speeds = {f"{c:.0f}" for c in ds.attrs["critical_speeds_rpm"]}
    crit = [t for t in ax.texts if t.get_text() in speeds and t.get_rotation() == 90]
    assert crit and min(t.get_fontsize() for t in crit) >= 7
    labels = ax.get_legend_handles_labels()[1]
    assert "meshes stage_sun_planet1..3, stage_ring_planet1..3 x 1..10" in labels, labels
    assert "operating speed (the model's drive): 1000 rpm" in labels


def test_the_operating_speed_is_drawn_only_inside_the_range():
    from torquesplit.steady.plot import campbell_figure

    ds, _ = campbell(_lp3(), 1500 * RPM, 3000 * RPM, points=3)
    labels = campbell_figure(ds).axes[0].get_legend_handles_labels()[1]
    assert not [lab for lab in labels if lab.startswith("operating speed")]


def test_each_mesh_crossing_is_rated_by_its_stiffness_harmonic():
    """37 crossings up to 10x the mesh frequency, unranked (a reviewer's helical mill
    drive, whose high orders the overlap ratio all but removes): each mesh crossing now
    carries the amplitude of its order of the mesh stiffness over the mean."""
    import tomllib

    from model_texts import PAIR_4MM

    text = PAIR_4MM.replace('stiffness = "4e8 N/m"', 'stiffness = {method = "fourier", '
                            'mean = "4e8 N/m", cos = ["4e7 N/m", "1e7 N/m"]}')
    model = torquesplit.load_model(tomllib.loads(text))
    rpm = math.pi / 30
    _, crossings = campbell(model, 100 * rpm, 20000 * rpm)
    rated = {c["order"]: c["stiffness_harmonic"] for c in crossings
             if c["source"].startswith("mesh")}
    assert rated[1] == pytest.approx(0.1, rel=1e-9)
    assert rated[2] == pytest.approx(0.025, rel=1e-9)
    assert all(v < 1e-9 for k, v in rated.items() if k > 2)
    assert all("stiffness_harmonic" not in c for c in crossings
               if c["source"].startswith("rotation"))


def test_a_two_stage_drive_gets_a_panel_for_its_slower_meshes():
    """Ji & Li's stage-2 orders and its first eight modes shared the bottom tenth of the
    axis, their labels stacked over each other (a first-hour reviewer)."""
    from torquesplit.steady.plot import ZOOM_SHARE, campbell_figure

    ds, _ = campbell(load_model("ji_li_mill_drive"), 600 * RPM, 900 * RPM, points=5)
    fig = campbell_figure(ds)
    fig.canvas.draw()
    top, low = fig.axes[:2]
    assert low.get_ylim()[1] < ZOOM_SHARE * top.get_ylim()[1]
    # the slower meshes' orders, labelled, and every mode below the panel's top numbered
    texts = [t.get_text() for t in low.texts]
    assert any(t.startswith("1x m12, m22") for t in texts), texts
    below = sorted(int(m) for m, f in zip(ds["mode"].values, ds["natural_frequency"].values[-1])
                   if f < low.get_ylim()[1])
    numbered = {int(n) for t in texts for n in t.split(", ") if n.isdigit()}
    assert set(below) <= numbered, (below, numbered)
    legend = low.get_legend().get_window_extent()
    assert not legend.overlaps(low.get_window_extent())
    assert not legend.overlaps(low.xaxis.label.get_window_extent())
    # the upper panel leaves the slow orders to the lower one (their labels stacked over
    # its modes' numbers), and no order label sits left of an axes (one did, between the
    # panels, at a line that leaves the lower panel at once)
    zoom_top = low.get_ylim()[1]
    orders = [t for t in top.texts if "x m" in t.get_text()]
    assert orders and all(t.xyann[1] >= zoom_top for t in orders), \
        [(t.get_text(), t.xyann) for t in orders]
    for ax in (top, low):
        box = ax.get_window_extent()
        for t in ax.texts:
            if "x m" in t.get_text():
                assert t.get_window_extent().x1 > box.x0, t.get_text()


def test_a_single_mesh_frequency_keeps_one_panel(lp3_figure):
    _, fig = lp3_figure
    assert len(fig.axes) == 1


def test_the_campbell_files_carry_the_crossings_as_a_table(tmp_path):
    """A rotordynamics reviewer found the critical speeds only as text attributes, without
    their stiffness harmonic or whether the model drives them: a CSV export now has a
    table of them, and the .nc their variables along 'crossing'."""
    import csv

    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--campbell", "--from",
                                   "700 rpm", "--to", "820 rpm", "--out",
                                   str(tmp_path / "c.csv")])
    assert res.exit_code == 0, res.output
    rows = list(csv.DictReader(open(tmp_path / "c_crossing.csv", newline="")))
    by_speed = {round(float(r["crossing_speed_rpm"]), 1): r for r in rows}
    # order 3 of the stage-2 meshes: mode 4 (the branches' forces cancel on it) and mode 5
    assert by_speed[743.2]["crossing_driven"] == "0"  # (whole numbers as such: was "0.0")
    assert by_speed[743.2]["crossing_mode"] == "4"
    assert float(by_speed[743.2]["crossing_modal_force_share"]) < 1e-9
    assert by_speed[812.7]["crossing_driven"] == "1"
    assert by_speed[812.7]["crossing_excitation"] == "3 x meshes m12, m22"
