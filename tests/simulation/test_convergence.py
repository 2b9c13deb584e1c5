"""The step check: a run again at half the step it took, and the digits that hold."""

from __future__ import annotations

import json
import math
import warnings

import pytest
from typer.testing import CliRunner

import torquesplit
from model_texts import SPUR_PAIR, write_model
from torquesplit.cli import app
from torquesplit.convergence import (
    StepCheck,
    agreeing_digits,
    bearing_values,
    check_step,
    halved_steps_per_period,
    has_jumps,
)
from torquesplit.errors import ModelWarning
from torquesplit.model.io import load_model, model_from_dict
from torquesplit.model.overrides import apply_overrides, read_raw


@pytest.mark.parametrize("a, b, digits", [
    (6.7389, 6.7394, 4),      # 6.739: an error of 5e-4 is within half a unit of the 4th
    (6.7389, 6.7389, 15),
    (1.0, 2.0, 0),
    (123.45, 123.40, 3),      # within half a unit of the 4th digit, but 123.5 vs 123.4
    (123.45, 123.39, 3),
    (-0.0012341, -0.0012342, 4),
    # a reviewer: "5 digits hold" where the 5th printed digit moves (1.1049 vs 1.1050)
    (1.104934, 1.104970, 4),
    (0.99996, 1.00004, 3),    # 1.000 both (a's places: 3)
    (1234.5, 1236.1, 2),      # 1230 vs 1240 at 3 digits
    (0.0, 1e-9, 0),
    (1.0, math.nan, 0),
])
def test_agreeing_digits_by_hand(a, b, digits):
    assert agreeing_digits(a, b) == digits


def test_step_check_rows_least_converged_first():
    c = StepCheck(values={"x": 1.0, "y": 2.0, "z": 3.0, "w": math.nan},
                  halved={"x": 1.0, "y": 2.1, "z": 3.001}, method="rk4", step=2e-6,
                  halved_step=1e-6)
    rows = c.rows()
    assert [r[0] for r in rows] == ["y", "z", "x"]  # w: not finite in both, left out
    assert rows[0][3] == pytest.approx(0.1 / 2.1) and c.digits("z") == 3
    assert json.loads(json.dumps(c.to_dict()))["metrics"]["y"]["digits"] == 1


def _stiff_pair(tmp_path):
    """A spur pair so stiff that its highest mode, not the 100 steps per mesh period
    asked for, sets the RK4 step."""
    data = apply_overrides(read_raw(write_model(tmp_path, SPUR_PAIR, "pair.toml")),
                           {"meshes.m.stiffness": "4e10 N/m"})
    with pytest.warns(ModelWarning, match="ISO 6336 estimate"):  # stiff on purpose
        return load_model(model_from_dict(data, source="stiff pair"))


def test_the_check_halves_the_step_the_run_took_not_the_one_it_asked_for(tmp_path):
    """Where something else than the steps asked for set the step, doubling the steps
    asked for leaves it almost unchanged; the check takes half the step the run took."""
    model = _stiff_pair(tmp_path)
    res = torquesplit.simulate(model, cycles=10)
    h = res.solution.step
    assert res.solution.step_limited_by.startswith("the highest mode")
    doubled = torquesplit.simulate(model, cycles=10, steps_per_period=200).solution.step
    assert doubled > 0.6 * h  # what the old check did: not half the step
    spp = halved_steps_per_period(res)
    check = check_step(res)
    assert check.step == h and 0.45 * h <= check.halved_step <= 0.5 * h * (1 + 1e-9)
    assert spp > 200
    # every metric, and the bearing table's numbers
    assert set(check.values) == set(res.metric_values()) | set(bearing_values(res))
    assert any(k.startswith("bearing_peak_force.") for k in check.values)
    assert all(d >= 2 for *_, d in check.rows())  # a smooth run: the numbers converge


def test_the_check_of_an_adaptive_run_tightens_its_tolerance(tmp_path):
    path = write_model(tmp_path, SPUR_PAIR, "pair.toml")
    res = torquesplit.simulate(path, cycles=10, method="dopri", rtol=1e-6)
    check = check_step(res, rtol=1e-6)
    assert check.method == "dopri" and check.halved_step == pytest.approx(1e-6 / 32)
    assert set(check.values) == set(check.halved) and check.rows()


def test_run_check_step_on_the_command_line(tmp_path):
    """``run --check-step`` says how many digits hold, on the terminal and in the JSON."""
    path = write_model(tmp_path, SPUR_PAIR, "pair.toml")
    runner = CliRunner()
    out = runner.invoke(app, ["run", str(path), "--cycles", "20", "--check-step", "--quiet"])
    assert out.exit_code == 0, out.output
    assert "step check, the same run at half the step" in out.output
    res = runner.invoke(app, ["run", str(path), "--cycles", "20", "--check-step", "--json"])
    data = json.loads(res.output[res.output.index("{"):])
    check = data["step_check"]
    assert check["method"] == "rk4" and check["halved_step"] < 0.51 * check["step"]
    assert "dynamic_factor.m" in check["metrics"]
    assert all("digits" in v for v in check["metrics"].values())
    plain = runner.invoke(app, ["run", str(path), "--cycles", "20", "--json"]).output
    plain = json.loads(plain[plain.index("{"):])  # after the warnings (stderr mixed in)
    assert "step_check" not in plain


def _rectangular_pair(tmp_path, points: int):
    """The spur pair with a rectangular single/double contact wave (jumps) of ``points``
    table points."""
    data = apply_overrides(read_raw(write_model(tmp_path, SPUR_PAIR, "pair.toml")), {
        "meshes.m.stiffness": {"method": "constant", "value": "4e8 N/m",
                               "peak_to_peak": 0.4},
        "analysis": {"table_points": points}})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return load_model(model_from_dict(data, source="rectangular pair"))


def test_tables_with_jumps_are_checked_with_finer_tables(tmp_path):
    """A jump of the stiffness becomes a ramp one table spacing long: the check refines
    the tables of such a model too (4x), and its numbers then move with the tables, not
    only with the step; a smooth model keeps its tables."""
    res = torquesplit.simulate(_rectangular_pair(tmp_path, 64), cycles=30)
    assert has_jumps(res.structure)
    check = check_step(res, definitions=["cycle_peak"])
    assert (check.table_points, check.check_table_points) == (64, 256)
    finer = torquesplit.simulate(_rectangular_pair(tmp_path, 256), cycles=30,
                                 steps_per_period=halved_steps_per_period(res))
    assert {k: v for k, v in check.halved.items()
            if not k.startswith("bearing_")} == finer.metric_values(["cycle_peak"])
    assert check.digits("dynamic_factor.m") < 4  # the 64-point ramps cost digits
    smooth = torquesplit.simulate(write_model(tmp_path, SPUR_PAIR, "pair.toml"), cycles=10)
    assert not has_jumps(smooth.structure)
    plain = check_step(smooth)
    assert plain.check_table_points == plain.table_points


def test_coarse_tables_with_jumps_are_warned_of(tmp_path):
    """Tables that jump, at fewer than COARSE_TABLE points, lower the peaks: the run warns,
    naming the meshes and the field; at 4096 points, or with smooth tables, it does not."""
    from torquesplit.convergence import COARSE_TABLE, jump_elements
    from torquesplit.simulation import prepare_run

    def said(model):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ModelWarning)
            prepare_run(model, cycles=5)
        return [str(w.message) for w in caught if "table_points" in str(w.message)]

    coarse = _rectangular_pair(tmp_path, 256)
    (msg,) = said(coarse)
    assert msg.startswith("analysis.table_points: the tables of m step")
    assert "with 256 points per cycle each step is a ramp 1/256" in msg
    assert "set [analysis] table_points = 16384" in msg
    assert jump_elements(prepare_run(coarse, cycles=5).structure) == ["m"]
    assert said(_rectangular_pair(tmp_path, COARSE_TABLE)) == []
    assert said(write_model(tmp_path, SPUR_PAIR, "pair.toml")) == []


def test_check_warns_of_coarse_tables_as_a_run_does(tmp_path):
    iso = SPUR_PAIR.replace('stiffness = "4e8 N/m"', 'stiffness = {method = "iso6336"}')
    coarse = iso + "\n[analysis]\ntable_points = 256\n"
    out = CliRunner().invoke(app, ["check", str(write_model(tmp_path, coarse, "iso.toml"))])
    assert out.exit_code == 0, out.output
    text = " ".join(out.output.split())
    assert "analysis.table_points: the tables of m step" in text
    fine = iso + "\n[analysis]\ntable_points = 4096\n"
    out = CliRunner().invoke(app, ["check", str(write_model(tmp_path, fine, "fine.toml"))])
    assert out.exit_code == 0 and "table_points" not in out.output
    # by default a stepping table gets 16384 points: nothing to warn of
    out = CliRunner().invoke(app, ["check", str(write_model(tmp_path, iso, "default.toml"))])
    assert out.exit_code == 0 and "table_points" not in out.output


def test_the_default_table_points_resolve_steps_and_spare_smooth_tables(tmp_path):
    """At the former default of 256 points every ISO 6336 spur model warned that its
    peaks come out low; the default now takes 16384 where a table steps, 256 elsewhere."""
    from torquesplit.assembly.excitation import (SMOOTH_TABLE_POINTS, STEP_TABLE_POINTS,
                                                 table_points)
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.simulation import prepare_run

    iso = SPUR_PAIR.replace('stiffness = "4e8 N/m"', 'stiffness = {method = "iso6336"}')
    for text, expected in ((iso, STEP_TABLE_POINTS), (SPUR_PAIR, SMOOTH_TABLE_POINTS)):
        model = torquesplit.load_model(write_model(tmp_path, text, "m.toml"))
        assert model.analysis.table_points is None
        assert table_points(model, solve_kinematics(model)) == expected
        assert prepare_run(model, cycles=5).structure.n_table == expected
    model = torquesplit.load_model(write_model(tmp_path, iso + "\n[analysis]\ntable_points = 512\n",
                                               "m.toml"))
    assert table_points(model, solve_kinematics(model)) == 512


def test_the_step_check_does_not_warn_of_its_own_table_points(tmp_path):
    """The check runs at 4x the user's table points (1024 here, still coarse): the user's
    run warned of 256; the check's run is no setting of theirs and says nothing."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate(_rectangular_pair(tmp_path, 256), cycles=10)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check = check_step(res)
    assert check.check_table_points == 1024
    assert not [w for w in caught if "table_points" in str(w.message)]


def test_the_step_check_table_gives_forces_in_kn_as_the_run_table(capsys):
    """The run's mesh table prints forces in kN; its step check listed them in N."""
    from rich.console import Console

    from torquesplit.cli_support import render_step_check, reset
    from torquesplit.convergence import StepCheck

    reset(Console(width=120), Console(stderr=True))
    check = StepCheck(values={"peak_force.m": 13084.9, "dynamic_factor.m": 1.71193,
                              "rms_transmission_error.m": 1.12926e-06},
                      halved={"peak_force.m": 13253.0, "dynamic_factor.m": 1.73392,
                              "rms_transmission_error.m": 1.2e-06},
                      method="rk4", step=1e-5, halved_step=5e-6)
    render_step_check(check)
    out = capsys.readouterr().out
    force = next(ln for ln in out.splitlines() if "peak_force.m" in ln)
    assert "kN" in force and "13.0849" in force and "13.253" in force
    factor = next(ln for ln in out.splitlines() if "dynamic_factor.m" in ln)
    assert "kN" not in factor and "1.71193" in factor
    # the steady table's transmission error in µm, as its mesh table prints it
    te = next(ln for ln in out.splitlines() if "rms_transmission_error.m" in ln)
    assert "µm" in te and "1.12926" in te and "e-06" not in te


def test_an_error_harmonic_that_sets_the_step_is_said_and_the_check_halves_it(tmp_path):
    """An LTCA mesh's transmission-error series reaches mesh order 14 here: 100 steps per
    period of that harmonic made the run 14 times longer than a user who asked for 100
    per mesh period expected, with nothing said; and the step check asked for twice the
    steps per *mesh* period the run took, per harmonic period: a step 28 times finer."""
    from model_texts import RELIEVED_SPUR_LTCA

    model = torquesplit.load_model(write_model(tmp_path, RELIEVED_SPUR_LTCA, "ltca.toml"))
    res = torquesplit.simulate(model, cycles=5)
    s, f_mesh = res.solution, res.kinematics.meshes["m"].frequency
    why = s.step_limited_by
    assert "error sinusoid of element 'm'" in why and "transmission-error harmonic" in why
    order = round(float(max(abs(res.structure.error_omega))) / (2 * math.pi * f_mesh))
    assert order > 1 and f"order {order} of its mesh frequency" in why
    assert f"{100 * order} per shortest mesh period" in why
    assert s.step == pytest.approx(1 / (100 * order * f_mesh), rel=1e-9)
    halved = torquesplit.simulate(model, cycles=5,
                                  steps_per_period=halved_steps_per_period(res))
    assert halved.solution.step == pytest.approx(s.step / 2, rel=1e-9)


def test_the_step_check_checks_the_bearing_table_at_twice_its_sampling():
    """The bearing table's means come from the history, so the check halved the step and
    left their sampling unchecked, and the table's numbers were not compared at all (its
    peaks, from the history too then, moved by 0.4 % at 66 samples per period on the
    differential).  The rerun now samples twice as often and the table's numbers are
    compared, those at round-off left out; the peaks, streamed at every step, move as
    the mesh forces do (the differential runs near a critical speed)."""
    res = torquesplit.simulate(torquesplit.example_path("split_path_planetary_differential"))
    chk = check_step(res, definitions=["mean_force"])
    assert chk.history_samples > 20
    assert chk.check_history_samples == pytest.approx(2 * chk.history_samples, rel=0.02)
    assert chk.values["bearing_peak_force.pinion_b"] == pytest.approx(
        max(b["peak_magnitude"] for b in res.bearing_forces() if b["body"] == "pinion_b"))
    rel = {n: r for n, _, _, r, _ in chk.rows()}
    assert max(r for n, r in rel.items() if n.startswith("bearing_peak_force.")) < 1e-4
    assert max(r for n, r in rel.items() if n.startswith("bearing_")) < 1e-4
    assert chk.digits("bearing_mean_force.stage_planet1") >= 4
    assert not any(k.endswith(".stage_sun") for k in chk.values)  # (0: round-off)
    assert chk.to_dict()["check_history_samples_per_period"] == chk.check_history_samples
    out = CliRunner().invoke(app, ["run", "split_path_planetary_differential", "--quiet",
                                   "--check-step"])
    text = " ".join(out.output.split())
    assert out.exit_code == 0, out.output
    assert "history samples per period: the bearing forces" in text
    assert "the bearing means: --samples-per-period" in text
