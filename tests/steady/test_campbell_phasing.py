"""Crossings that the planets' mesh phasing leaves unexcited (Parker & Lin 2004) are
marked suppressed in the resonance map, its table and the report, not counted as critical;
models without an equally spaced stage are unchanged."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit import example_path, load_model
from torquesplit.cli import app
from torquesplit.model.kinematics import solve_kinematics
from torquesplit.modes import PhasedStage, phased_stages, phasing_suppresses
from torquesplit.steady.maps import campbell

RPM = np.pi / 30


@pytest.mark.parametrize("zs, n, order, excited", [
    # z_s = 24, N = 3: every harmonic has l z_s / N whole -> rotational modes only
    (24, 3, 1, {"rotational"}), (24, 3, 2, {"rotational"}),
    # z_s = 25, N = 3: l = 1 -> (25 - 1)/3 whole: translational; l = 3 -> 75/3: rotational
    (25, 3, 1, {"translational"}), (25, 3, 3, {"rotational"}),
    # Lin & Parker's example, z_s = 42, N = 4: l = 1 -> 42/4, 41/4, 43/4: planet modes
    (42, 4, 1, {"planet"}), (42, 4, 2, {"rotational"}),
    # z_s = 21, N = 5: l = 1 -> 20/5 whole: translational; l = 2 -> 42/5, 41/5 no, 43/5 no
    (21, 5, 1, {"translational"}), (21, 5, 2, {"planet"}),
])
def test_the_rule_of_parker_and_lin_2004(zs, n, order, excited):
    st = PhasedStage(carrier="c", planets=n, sun_teeth=zs, meshes=frozenset({"m"}))
    got = {t for t in ("rotational", "translational", "planet") if st.excites(order, t)}
    assert got == excited
    assert st.excites(order, "mixed") and st.excites(order, None)
    assert phasing_suppresses([st], "m", order, "planet") == ("planet" not in excited)
    assert not phasing_suppresses([st], "other mesh", order, "planet")


def _lp(**stage):
    raw = torquesplit.model.io.read_file(example_path("lin_parker1999_planetary"))
    raw = copy.deepcopy(raw)
    raw["planetary"][0].update(stage)
    return load_model(raw)


def _stages(model):
    return phased_stages(model, solve_kinematics(model))


def test_only_equally_spaced_identical_planets_with_equal_loads_are_phased():
    (st,) = _stages(load_model(example_path("lin_parker1999_planetary")))
    assert (st.planets, st.sun_teeth, len(st.meshes)) == (4, 42, 8)
    assert _stages(_lp(pin_errors=[{"tangential": "10 um"}, {}, {}, {}])) == []
    assert len(_stages(_lp(angles=["0 deg", "90 deg", "180 deg", "270 deg"]))) == 1
    # fits (multiples of 360 deg / (z_s + z_r) = 2 deg) but not equally spaced
    assert _stages(_lp(angles=["0 deg", "82 deg", "180 deg", "270 deg"])) == []
    # no central member translates: the translational pairs are labelled planet
    raw = copy.deepcopy(torquesplit.model.io.read_file(example_path("lin_parker1999_planetary")))
    for member in ("sun", "ring", "carrier"):
        raw["planetary"][0][member]["dofs"] = ["theta"]
        raw["planetary"][0][member].pop("support", None)
    assert _stages(load_model(raw)) == []


@pytest.fixture(scope="module")
def lp_map():
    model = load_model(example_path("lin_parker1999_planetary"))
    return campbell(model, 500 * RPM, 3000 * RPM, points=21)


def test_campbell_marks_suppressed_crossings_and_does_not_count_them(lp_map):
    ds, crossings = lp_map
    mesh = [c for c in crossings if "meshes" in c]
    assert mesh and all("suppressed" in c and "mode_type" in c for c in crossings)
    st = _stages(load_model(example_path("lin_parker1999_planetary")))
    for c in mesh:
        assert c["suppressed"] == all(phasing_suppresses(st, m, c["order"], c["mode_type"],
                                                         c.get("whirl")) for m in c["meshes"])
    suppressed = [c for c in crossings if c["suppressed"]]
    excited = [c for c in crossings if not c["suppressed"]]
    assert suppressed and excited
    assert {c["mode_type"] for c in suppressed} <= {"rotational", "translational", "planet"}
    assert ds.attrs["critical_speeds_rpm"] == [c["speed_rpm"] for c in excited]
    assert ds.attrs["suppressed_speeds_rpm"] == [c["speed_rpm"] for c in suppressed]
    assert not [c for c in crossings if "meshes" not in c
                and c["suppressed"]]  # shaft orders are never suppressed


def test_a_model_without_planets_is_unchanged():
    model = load_model(example_path("ji_li_mill_drive"))
    ds, crossings = campbell(model, 200 * RPM, 1500 * RPM, points=5)
    assert crossings and not [c for c in crossings if "suppressed" in c]
    assert "suppressed_speeds_rpm" not in ds.attrs
    assert len(ds.attrs["critical_speeds_rpm"]) == len(crossings)


def test_the_campbell_table_and_json_say_which_are_suppressed():
    runner = CliRunner()
    args = ["modes", str(example_path("lin_parker1999_planetary")), "--campbell",
            "--from", "500 rpm", "--to", "3000 rpm"]
    res = runner.invoke(app, args + ["--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["suppressed_by_mesh_phasing"]
    assert not [c for c in data["critical_speeds"] if c["suppressed"]]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    assert "phasing" in res.stdout and "suppressed" in res.stdout
    assert "Parker & Lin 2004" in res.stdout
    # a constant mesh stiffness without errors has no harmonic to cancel, and the
    # phasing column gives the phasing's verdict: '0 (cancels)' beside 'excited' read as
    # a contradiction (a planetary reviewer)
    rows = [line for line in res.stdout.splitlines() if " x meshes " in line]
    assert rows and not any("(cancels)" in line for line in rows)
    assert sum("not suppressed" in line for line in rows) == len(data["critical_speeds"])
    assert not any(" excited " in line for line in rows)


def test_the_report_mode_table_marks_suppressed_orders():
    from types import SimpleNamespace

    from torquesplit.report.html import _modes

    model = load_model(example_path("lin_parker1999_planetary"))
    html = _modes(SimpleNamespace(model=model, kinematics=solve_kinematics(model)))
    assert "Parker &amp; Lin 2004" in html
    assert "(suppressed by phasing)" in html, html
    model = load_model(example_path("ji_li_mill_drive"))
    html = _modes(SimpleNamespace(model=model, kinematics=solve_kinematics(model)))
    assert "suppressed" not in html and "Parker" not in html
    # with the static state the forces' cancellation is judged: a constant stiffness
    # has no harmonic to cancel (it said 'forces cancel' on every unsuppressed order)
    # (at 1835 rpm twice the mesh frequency is near the rotational mode 9, 1970 Hz,
    # which the phasing lets through)
    from torquesplit.model.io import model_from_dict
    from torquesplit.model.overrides import apply_overrides, read_raw

    data = apply_overrides(read_raw(example_path("lin_parker1999_planetary")),
                           {"drives.input.speed": "1835 rpm"})
    res = torquesplit.simulate(load_model(model_from_dict(data, source="lp")), cycles=3)
    table = _modes(res).split("</table>")[0]
    assert "(suppressed by phasing)" in table and "(forces cancel)" not in table
    assert "2×stage_sun_planet1," in table  # (an order near a mode, not suppressed)


def test_the_campbell_figure_draws_suppressed_crossings_apart(lp_map):
    from torquesplit.steady.plot import campbell_figure

    fig = campbell_figure(lp_map[0])
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert "suppressed by mesh phasing (Parker & Lin 2004)" in labels
    assert "critical speed (a crossing)" in labels


def test_campbell_labels_that_would_overprint_share_one_text():
    """Degenerate pairs printed '6/7' over each other, coinciding harmonics '52x' (a
    reviewer's Campbell diagram)."""
    import xarray as xr

    from torquesplit.steady.plot import campbell_figure

    rpm = np.array([1000.0, 2000.0])
    ds = xr.Dataset(
        {"natural_frequency": (("speed", "mode"), [[500.0, 500.5, 900.0]] * 2),
         "excitation_frequency": (("speed", "line"), [[100.0, 200.0, 100.0, 200.0],
                                                      [500.0, 1000.0, 500.0, 1000.0]])},
        coords={"speed_rpm": ("speed", rpm), "mode": [1, 2, 3],
                "line": ["1 x mesh a", "2 x mesh a", "2 x mesh b", "4 x mesh b"]},
        attrs={"critical_speeds_rpm": [1500.0]})
    texts = [t.get_text() for t in campbell_figure(ds).axes[0].texts]
    assert "1, 2" in texts and "3" in texts
    assert "2x a = 4x b" in texts and "1x a = 2x b" in texts
    assert "1500" in texts


def test_critical_speeds_the_model_does_not_drive_are_labelled_so(lp_map):
    """The speed sweep's figure numbered every critical speed alike, those whose
    harmonic is nil (constant mesh stiffness) or cancels on the mode included (a
    reviewer): their labels say 'not driven'; a driven one's does not."""
    from torquesplit.steady.maps import driven

    ds, crossings = lp_map
    labels = ds.attrs["critical_speed_labels"]
    assert labels and all(lab.endswith("(not driven)") for lab in labels)
    ds, crossings = campbell(load_model(example_path("ji_li_mill_drive")), 100 * RPM,
                             1500 * RPM, points=21)
    critical = [c for c in crossings if not c.get("suppressed")]
    labels = ds.attrs["critical_speed_labels"]
    assert len(labels) == len(critical)
    assert [lab.endswith("(not driven)") for lab in labels] == [not driven(c)
                                                               for c in critical]
    assert 0 < sum(lab.endswith("(not driven)") for lab in labels) < len(labels)


def test_the_numerical_modal_force_agrees_with_the_phasing_rule_in_a_turning_frame():
    """Five planets, mesh stiffness varying over the cycle, the carrier's frame turning:
    every crossing of a planet mesh harmonic with a mode of a pure type is driven by the
    meshes' forces (their share on the mode, phi^H F) exactly where Parker & Lin's rule
    says it is excited, whirls included (the share took phi^T F, which measured the
    other whirl: order 2 drives the backward whirl, and was called cancelled)."""
    changes = {"planetary.0.planets": 5}
    for mesh in ("sun_mesh", "ring_mesh"):
        changes[f"planetary.0.{mesh}.stiffness"] = {"method": "constant", "value": "5e8 N/m",
                                                    "peak_to_peak": 0.3}
    model = load_model("lin_parker1999_planetary", changes=changes)
    ds, crossings = campbell(model, 300 * RPM, 3000 * RPM, points=31)
    judged = [c for c in crossings if "meshes" in c
              and c.get("mode_type") in ("rotational", "translational", "planet")
              and c.get("modal_force_share") is not None]
    whirls = {c.get("whirl") for c in judged if c["mode_type"] == "translational"}
    assert whirls == {"forward", "backward"}
    for c in judged:
        assert c["suppressed"] == (c["modal_force_share"] < 1e-6), c
    # the crossing a reviewer met near 1001 rpm: order 2 on the backward whirl, driven
    near = [c for c in judged if c["order"] == 2 and c["mode_type"] == "translational"
            and c["whirl"] == "backward" and 950 < c["speed_rpm"] < 1050]
    assert near and not near[0]["suppressed"] and near[0]["modal_force_share"] > 0.5
