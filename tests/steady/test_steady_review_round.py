"""Two reviewers' findings on the steady state: its RMS transmission error is the dynamic
TE a measurement gives (the flanks' relative displacement, errors included; it took the
elastic deflection alone, so an LTCA pair's optimum tip relief, which cuts the loaded TE
several-fold, moved it by 1 %: 4.729 against 4.698 um); a state with an undamped mode is
marginal and the mode named; a sweep stopped short says where, in rpm, and why."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import torquesplit
from model_texts import RELIEVED_SPUR_LTCA, write_model
from torquesplit.gears.contact.coupling import mesh_ltca

UNMODIFIED = (RELIEVED_SPUR_LTCA
              .replace('tip_relief = {amount = "15 um", length = "5 mm"}\n', "")
              .replace('tip_relief = {amount = "15 um", length = "5 mm", shape = "parabolic"}\n',
                       ""))


def _rms(x):
    return float(np.sqrt(np.mean((x - x.mean()) ** 2)))


@pytest.mark.parametrize("text", [RELIEVED_SPUR_LTCA, UNMODIFIED], ids=["relieved", "plain"])
def test_quasi_static_te_is_the_ltca_loaded_te(tmp_path, text):
    """At a low speed the dynamic TE is the loaded static TE of the LTCA."""
    assert text.count("tip_relief") == (2 if text is RELIEVED_SPUR_LTCA else 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(write_model(tmp_path, text))
        st = torquesplit.steady_state(model, speed="50 rpm")
    te = mesh_ltca(model, torquesplit.solve_kinematics(model), "m", 256).te
    row, = st.mesh_table()
    assert row.rms_transmission_error == pytest.approx(_rms(te), rel=0.05)


def test_tip_relief_lowers_the_dynamic_te(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rms = [torquesplit.steady_state(torquesplit.load_model(
            write_model(tmp_path, text, f"{i}.toml")), speed="200 rpm").mesh_table()[0]
            .rms_transmission_error for i, text in enumerate((UNMODIFIED, RELIEVED_SPUR_LTCA))]
    assert rms[1] < rms[0] / 3, rms


def test_a_state_with_an_undamped_mode_is_marginal_and_said(tmp_path):
    """A reviewer's steady state read 'stable, |mu| = 1.000000' with a mode without any
    damping: it is marginal, and the mode is named."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["steady", "split_path_planetary_differential",
                                   "--set", "gears.pinion_a.support.damping_ratio=0",
                                   "--set", "gears.pinion_b.support.damping_ratio=0"])
    assert res.exit_code == 0, res.output
    assert "stable, but only marginally" in res.stdout
    assert "mode(s) without damping: mode 7" in res.stderr


def test_a_stopped_sweep_says_where_in_rpm_and_why():
    from types import SimpleNamespace

    from torquesplit.steady.maps import _message_in_rpm

    w_ref = 3000 / 60 * 2 * np.pi  # 3000 rpm
    pts = [SimpleNamespace(speed=1.05, max_multiplier=0.9961)]
    msg = _message_in_rpm("stopped after 2000 points; curve kept.", w_ref, pts, 1.1, False)
    assert msg.startswith("stopped after 2000 points at 3150 rpm, short of the 3300 rpm asked")
    assert "|mu| = 0.9961" in msg and "parametric instability" in msg
    assert _message_in_rpm("tangent failed at speed factor 0.5 (x)", w_ref, pts, 1.1,
                           False) == "tangent failed at 1500 rpm (x)"


def test_steady_says_a_critical_speed_at_its_own_speed():
    """'run' warned of a critical speed next to its speed and 'steady' did not; at another
    speed, it judges that speed (812 rpm: 0.09 % below where order 3 of Ji & Li's stage-2
    meshes meets the mode on which the two branches move together)."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    runner = CliRunner()
    res = runner.invoke(app, ["steady", "ji_li_mill_drive", "--speed", "812 rpm"])
    assert res.exit_code == 0, res.output
    assert "the speed (812 rpm) is 0.092 % below a critical speed (812.75 rpm)" in res.stderr
    far = runner.invoke(app, ["steady", "ji_li_mill_drive", "--speed", "700 rpm"])
    assert far.exit_code == 0 and "critical speed" not in far.stderr


def test_steady_and_sweep_options_said_in_their_own_words(tmp_path):
    """--harmonics with --method shooting was ignored; a zero-width sweep range was said in
    'times the model's speed'; a reversed Campbell range was refused where the sweep takes
    one; sweep-speed refused a .jpg figure that modes --campbell writes, calling it
    'results'; shooting printed its one residual three times."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    runner = CliRunner()
    both = runner.invoke(app, ["steady", "ji_li_mill_drive", "--harmonics", "8", "--method",
                               "shooting"])
    assert both.exit_code == 2 and "--harmonics 8 sets the harmonic balance" in both.output
    flat = runner.invoke(app, ["sweep-speed", "ji_li_mill_drive", "--from", "500 rpm", "--to",
                               "500 rpm"])
    assert flat.exit_code == 2 and "the speed range 500..500 rpm must be" in flat.output
    bad = runner.invoke(app, ["sweep-speed", "ji_li_mill_drive", "--from", "500 rpm", "--to",
                              "600 rpm", "--plot", str(tmp_path / "y.xyz")])
    assert bad.exit_code == 2 and "cannot save the figure as 'y.xyz'" in bad.output
    assert ".jpg" in bad.output
    from torquesplit.steady.maps import campbell

    up = campbell("ji_li_mill_drive", "600 rpm", "800 rpm", points=3)[1]
    down = campbell("ji_li_mill_drive", "800 rpm", "600 rpm", points=3)[1]
    assert [c["speed_rpm"] for c in up] == [c["speed_rpm"] for c in down] and up
    one = runner.invoke(app, ["steady", "ji_li_mill_drive"])
    assert "one-period integration defect" in one.stdout
    assert "midpoint residual" not in one.stdout  # (shooting: the one number, once)


def test_campbell_counts_the_crossings_the_model_drives():
    """Lin & Parker's stage (constant mesh stiffness, no errors) reported '4 critical'
    without saying that nothing in the model drives them."""
    from typer.testing import CliRunner

    from torquesplit.cli import app
    from torquesplit.steady.maps import campbell, driven

    res = CliRunner().invoke(app, ["modes", "lin_parker1999_planetary", "--campbell",
                                   "--from", "100 rpm", "--to", "2000 rpm"])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())
    assert ("0 of 3 driven by at least 1 % (the mesh force harmonic, or a shaft order's k "
            "harmonic or error;") in text, text[:400]
    _, crossings = campbell("ji_li_mill_drive", "700 rpm", "800 rpm", points=3)
    assert any(driven(c) for c in crossings)  # (its 10 % stiffness wave drives some)


def test_harmonics_beyond_the_harmonic_balance_limit_are_refused():
    """--harmonics 1000000 ran 3 million samples for 13 s on one DOF (a larger model runs
    out of memory): refused above the adaptive doubling's limit."""
    from typer.testing import CliRunner

    from torquesplit.cli import app
    from torquesplit.steady.solution import MAX_HARMONICS

    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--harmonics",
                                   str(MAX_HARMONICS + 1)])
    assert res.exit_code == 2 and f"is more than {MAX_HARMONICS}" in res.output
    assert "--method shooting" in res.output, res.output


def test_a_speed_whose_period_cannot_be_held_is_refused_before_any_work():
    """A fuzzer's 0.001 rpm: a period of 3e10 RK4 steps was warned about (hours), then
    died in a 941 GiB allocation with a traceback.  Refused in one line, without the
    warning, before any integration."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--speed", "1e-3 rpm"])
    assert res.exit_code == 2, res.output
    assert "GiB" in res.output and "speed nearer the model's" in res.output
    assert "warning" not in res.output and "Traceback" not in res.output


def test_modes_below_the_lowest_says_so():
    from typer.testing import CliRunner

    from torquesplit.cli import app

    lowest = min(r.frequency for r in torquesplit.model_modes("ji_li_mill_drive").rows
                 if r.frequency > 0)  # (from the modes themselves, not the message)
    assert lowest > 1.0
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--below", "1 Hz"])
    assert res.exit_code == 0
    assert f"no mode below 1 Hz: the lowest is {lowest:.5g} Hz" in res.stdout


def test_a_harmonic_of_a_meshs_error_series_is_named_so(tmp_path):
    """'14 cycles of the error of m at 7583 Hz' read as a slow error: it is harmonic 14 of
    the mesh's (LTCA) error series; kept excitations still drop it as an error."""
    from torquesplit.steady.period import excitation_sources, keep_excitations

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(write_model(tmp_path, RELIEVED_SPUR_LTCA))
    s = torquesplit.assemble(model)
    kinds = {x.kind for x in excitation_sources(s) if "error" in x.kind}
    assert "harmonic 2 of the error" in kinds, kinds
    f_mesh = float(s.frequency.max())
    kept, dropped = keep_excitations(s, 0.7 * f_mesh)  # (harmonics 7, 14 are multiples)
    gone = [x.index for x in dropped if x.kind.startswith("harmonic")]
    assert gone and np.all(kept.error_amplitude[gone] == 0.0)
    assert np.all(s.error_amplitude[gone] != 0.0)  # (they had an amplitude)


def test_a_sweep_peak_between_points_is_said():
    """An 8-point sweep put Ji & Li's peak at 585.7 rpm (1.09915); 77 points found it at
    609.7 rpm (1.10207): a peak whose neighbours are well below it may lie between them."""
    import xarray as xr

    from torquesplit.steady.cli import unresolved_peaks

    rpm = [500.0, 542.9, 585.7, 650.0, 714.3]
    coarse = [1.08736, 1.08936, 1.09915, 1.09361, 1.07754]
    fine = [1.0900, 1.0990, 1.09915, 1.0991, 1.0800]

    def ds(df):
        return xr.Dataset({"dynamic_factor": (("point", "mesh"), np.array(df)[:, None]),
                           "stable": ("point", np.ones(5, bool))},
                          coords={"speed_rpm": ("point", rpm), "mesh": ["m11"]})

    said = unresolved_peaks(ds(coarse))
    assert said == ["m11 (its neighbours 5.6 % of the dynamic increment lower, at 585.7 rpm)"]
    assert unresolved_peaks(ds(fine)) == []


def test_sweep_speed_takes_steady_states_option_checks():
    """A code review: sweep_speed took harmonics=1e6 and harmonics with method='shooting'
    that steady_state refuses."""
    from torquesplit.errors import OptionError
    from torquesplit.steady.maps import sweep_speed

    for kw in (dict(harmonics=10 ** 6), dict(harmonics=8, method="shooting")):
        with pytest.raises(OptionError):
            sweep_speed("ji_li_mill_drive", "700 rpm", "750 rpm", **kw)
        with pytest.raises(OptionError):
            torquesplit.steady_state("ji_li_mill_drive", **kw)


def test_a_steady_state_that_fails_names_the_spline_friction_where_there_is_some():
    """A reviewer's quill-shaft drive with a rubbing spline did not converge; the hint
    named contact loss and --method hb, not the friction (it converged in one Newton
    step without it)."""
    from torquesplit import load_model
    from torquesplit.steady.cli import _friction_hint

    dong = load_model("dong2021_face_gear")
    rubbing = [n for n, sp in dong.splines.items() if sp.friction_coefficient > 0]
    hint = _friction_hint(dong)
    assert rubbing and all(f"splines.{n}.friction_coefficient" in hint for n in rubbing)
    assert f"--set splines.{rubbing[0]}.friction_coefficient=0" in hint
    assert _friction_hint(load_model("ji_li_mill_drive")) == ""
    dry = dong.with_changes({f"splines.{n}.friction_coefficient": 0.0 for n in rubbing})
    assert _friction_hint(dry) == ""


def test_a_sweeps_largest_dynamic_factors_are_printed_to_the_digits_that_hold():
    """The tutorial's sweep printed DF 2.89820 where steady, at that speed, gave 2.90252
    with its own step and 2.89433 at a quarter of it.  Each largest stable DF is solved
    again at its speed with half the sweep's RK4 step (an independent steady solve, not
    the continuation): the JSON gives that value and the digits of the sweep's it
    confirms, the table prints those digits."""
    import json
    import math

    from typer.testing import CliRunner

    from torquesplit import load_model
    from torquesplit.cli import app
    from torquesplit.convergence import agreeing_digits
    from torquesplit.steady.api import steady_state
    from torquesplit.steady.cli import _held_text, _speed_at_text

    args = ["sweep-speed", "ji_li_mill_drive", "--keep", "stage1", "--from", "700 rpm",
            "--to", "760 rpm", "--points", "4", "--no-stability", "--steps-per-cycle", "40"]
    r = CliRunner().invoke(app, args + ["--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    m11 = out["max_dynamic_factor"]["m11"]
    rpm = out["max_dynamic_factor_speed_rpm"]["m11"]
    half = out["max_dynamic_factor_at_half_step"]["m11"]
    assert out["max_dynamic_factor_digits"]["m11"] == agreeing_digits(m11, half)
    # the same by hand: steady at that speed with 80 steps per cycle (the Ji & Li tables
    # jump: the check takes 4x their points, as --check-step does)
    model = load_model("ji_li_mill_drive")
    n = model.analysis.table_points or 65536
    fine = load_model("ji_li_mill_drive", changes={"analysis.table_points": 4 * n})
    st = steady_state(fine, speed=f"{rpm!r} rpm", keep="stage1", steps_per_cycle=80,
                      stability=False, check=False)
    by_hand = {r.mesh: r.dynamic_factor for r in st.mesh_table()}["m11"]
    assert math.isclose(half, by_hand, rel_tol=1e-6), (half, by_hand)
    text = CliRunner().invoke(app, args).output
    row = next(line for line in text.splitlines() if line.startswith("│ m11"))
    assert _held_text(m11, out["max_dynamic_factor_digits"]["m11"]) in row
    assert "DF to the digits that hold" in text
    # the speed to the spacing of the curve's points beside it (2615.38 rpm was printed
    # where more points put the peak at 2615.01: a reviewer)
    assert " ± " in row, row
    assert _speed_at_text(2615.37566, [2613.68574, 2615.37566, 2617.03833]) == "2615 ± 2"
    assert _speed_at_text(2615.3, [2614.9, 2615.3, 2616.0]) == "2615.3 ± 0.7"
    assert _speed_at_text(700.0, [700.0, 720.0]) == "700 ± 20"
    assert _speed_at_text(700.0, [700.0]) == "700"
    assert _held_text(2.89820, 2) == "2.9" and _held_text(1.08, 5) == "1.0800"
    assert _held_text(1.15554, 9) == "1.15554"  # (at most 6)


def test_a_falling_speed_sweep_stays_in_its_range_and_names_its_fold(tmp_path):
    """--from above --to: the curve turned at a fold and ran to 958,635 rpm (no upper
    guard), and a step that overshot the end below read as 'left the range backwards'
    (a fuzzer).  A linear model sweeps down as it sweeps up."""
    import json

    from typer.testing import CliRunner

    from tests.model_texts import SPUR_PAIR
    from torquesplit.cli import app

    smooth = 'stiffness = {method = "fourier", mean = "4e8 N/m", cos = ["0.2e8 N/m"], sin = []}'
    linear = tmp_path / "linear.toml"
    linear.write_text(SPUR_PAIR.replace('stiffness = "4e8 N/m"', smooth))
    wave = 'stiffness = {method = "constant", value = "4e8 N/m", peak_to_peak = 0.2}'
    runs = {}
    for a, b in (("100 rpm", "3000 rpm"), ("3000 rpm", "100 rpm")):
        r = CliRunner().invoke(app, ["sweep-speed", str(linear), "--from", a, "--to", b,
                                     "--points", "5", "--no-stability", "--json"])
        assert r.exit_code == 0, r.output
        runs[a] = json.loads(r.stdout)
        assert runs[a]["complete"], runs[a]["message"]
    up, down = runs["100 rpm"], runs["3000 rpm"]
    assert down["max_dynamic_factor"]["m"] == pytest.approx(up["max_dynamic_factor"]["m"],
                                                            rel=2e-2)
    import re

    rattle = tmp_path / "rattle.toml"  # (inertias from the gears' geometry: lighter)
    rattle.write_text(re.sub(r'polar_inertia = "[^"]*"\n', "", SPUR_PAIR.replace(
        'stiffness = "4e8 N/m"', wave + '\nbacklash = "100 um"')))
    r = CliRunner().invoke(app, ["sweep-speed", str(rattle), "--from", "3000 rpm", "--to",
                                 "500 rpm", "--out", str(tmp_path / "d.nc")])
    import xarray as xr

    rpm = xr.load_dataset(tmp_path / "d.nc")["speed_rpm"].values
    assert rpm.max() <= 3000 + 0.5 * 2500 + 1e-6  # (it ran to 958,635 rpm)
    # a fold turns this branch back near 1563 rpm: said, with the remedy
    assert r.exit_code == 1 and "turned back at a fold near" in " ".join(r.output.split())
    assert "a sweep from the other end" in " ".join(r.output.split())
