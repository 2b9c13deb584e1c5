"""Model-level steady state, Campbell map and the CLI commands on a shipped example."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from torquesplit.cli import app
from torquesplit.examples import example_path
from torquesplit.model.io import load_model
from torquesplit.steady import campbell, steady_state
from torquesplit.steady.period import LongPeriodError

EXAMPLE = "ji_li_mill_drive"
SOLVER_TABLE = 256
"""The harmonic-balance tests run Ji & Li with 256 table points (its jumps ramps of 1/256
cycle, which 64-128 harmonics resolve): the example's own 65536 points make the jumps
sharp, and a harmonic series converges on a jump as slowly as a Fourier series on a step
(Gibbs), 1.4e-4 of shooting at the default harmonics: shooting is the method for such
tables (docs/theory/steady.md)."""


def _ji_li(points: int = SOLVER_TABLE):
    """Ji & Li's example with ``points`` table points per mesh period."""
    return _example(EXAMPLE, points)


def _example(name: str, points: int = SOLVER_TABLE):
    """A shipped example with ``points`` table points per mesh period (the solver tests'
    own resolution: what they test does not depend on it)."""
    import warnings

    from torquesplit.model.io import model_from_dict
    from torquesplit.model.overrides import apply_overrides, read_raw

    data = apply_overrides(read_raw(example_path(name)), {"analysis.table_points": points})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_model(model_from_dict(data, source=name))


def test_steady_state_of_one_stage_and_its_results():
    st = steady_state(example_path(EXAMPLE), keep="stage1", harmonics=16)
    ps = st.solution
    assert ps.converged and ps.stable and ps.periodicity_defect < 1e-3
    assert [d.element for d in st.dropped] == ["m12", "m22"]
    rows = {r.mesh: r for r in st.mesh_table()}
    for r in rows.values():
        assert r.dynamic_factor == pytest.approx(r.peak_force / r.static_force)
        assert r.peak_to_nominal == pytest.approx(r.peak_force / r.nominal_force)
        assert r.min_force <= r.mean_force <= r.peak_force
    res = st.to_results()  # every metric of a dynamic run works on it
    met = res.metrics("cycle_peak")
    assert met.settling.settled
    assert met.rows[0].peak_force == pytest.approx(rows["m11"].peak_force, rel=1e-2)


def test_default_harmonics_converge_the_dynamic_factor_to_shooting():
    """The stepped stiffness of a contact-ratio change needs many harmonics: without a
    number asked for, HB doubles them until converged and agrees with shooting (RK4, 400
    steps per cycle); a fixed 8 per cycle (the first guess) does not."""
    def factors(**kw):
        st = steady_state(_ji_li(), keep="stage1", stability=False, check=False, **kw)
        return st, np.array([r.dynamic_factor for r in st.mesh_table()])

    _, ref = factors(method="shooting", steps_per_cycle=400)
    st, hb = factors(method="hb")
    assert st.solution.harmonics >= 64
    np.testing.assert_allclose(hb, ref, rtol=1e-4)
    _, coarse = factors(harmonics=8)
    assert np.max(np.abs(coarse / ref - 1.0)) > 1e-2


def test_shooting_steps_through_table_corners_and_samples_the_peaks_there():
    """A mesh force peaks at a corner of its stiffness table, between RK4 steps: shooting
    steps through the corners (as the integrators do) and keeps the forces there, so its
    dynamic factors do not move when the steps are doubled and agree with converged
    harmonic balance; its RK4 samples alone leave the peak of m21 low."""
    def solve(**kw):
        st = steady_state(_ji_li(), keep="stage1", stability=False, check=False, **kw)
        return st, np.array([r.dynamic_factor for r in st.mesh_table()])

    st, df = solve(method="shooting")
    _, fine = solve(method="shooting", steps_per_cycle=800)
    _, hb = solve(method="hb")
    ps = st.solution
    assert ps.corner_t.size > 0 and np.all((ps.corner_t > 0) & (ps.corner_t < ps.period))
    np.testing.assert_allclose(df, fine, rtol=1e-6)
    np.testing.assert_allclose(df, hb, rtol=2e-5)
    e = list(st.structure.element_names).index("m21")
    peak = next(r.peak_force for r in st.mesh_table() if r.mesh == "m21")
    assert peak == pytest.approx(ps.corner_forces[:, e].max(), rel=1e-12)
    assert ps.forces[:, e].max() < (1 - 1e-3) * peak


def test_steady_states_equal_long_time_integration_on_shipped_examples():
    """The issue's check on shipped examples (all of them: benchmarks/STEADY_RESULTS.md,
    by scripts/steady_vs_integration.py, the same function): each mesh-force waveform
    over a period within 1e-3 of its amplitude of the last period of a long RK4 run from
    the static state, once the slowest mode has decayed.  Shooting steps as the run does,
    so it agrees far closer."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "steady_vs_integration.py"
    spec = importlib.util.spec_from_file_location("steady_vs_integration", path)
    svi = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(svi)
    for name, methods, shooting_tol, points in (
            (EXAMPLE, ("hb", "shooting"), 1e-6, SOLVER_TABLE),
            (EXAMPLE, ("shooting",), 1e-6, None),  # the example's own sharp tables
            ("dong2021_face_gear", ("shooting",), 1e-4, None)):
        r = svi.compare(name, svi.KEEP[name], methods=methods, table_points=points)
        err = {m: max(v.values()) for m, v in r["max_error_over_amplitude"].items()}
        assert r["transient_left"] < 1e-3, r
        assert max(err.values()) <= 1e-3 and err["shooting"] <= shooting_tol, (name, err)


def test_results_of_a_kept_stage_stay_bounded():
    """Dong et al. 2021 with stage I kept: the other stage's meshes turn 8 times slower and
    their dropped error sinusoids (amplitude 0) once set a 1710-cycle settle window, which
    repeated the period 54,000 times (gigabytes).  Zero-amplitude sinusoids no longer
    lengthen the window, and the record is capped at RESULT_ROWS samples."""
    from torquesplit.steady.api import RESULT_ROWS

    st = steady_state(example_path("dong2021_face_gear"), keep="I", harmonics=8,
                      stability=False, check=False)
    res = st.to_results()
    assert max(res.settle_windows(20)) == 20
    assert res.solution.n_samples <= RESULT_ROWS
    rows = st.mesh_table()
    assert all(np.isfinite(r.load_sharing) for r in rows)


def test_speed_sweep_starts_and_ends_at_the_speeds_asked_for():
    from torquesplit.steady import sweep_speed

    m = load_model(example_path(EXAMPLE))
    w = abs(m.drives["motor"].speed)
    for a, b in ((0.8 * w, 1.2 * w), (1.2 * w, 0.8 * w)):
        sp = sweep_speed(m, a, b, points=10, keep="stage1", harmonics=16,
                         stability=False)["speed"].values
        assert sp[0] == pytest.approx(a, rel=1e-12) and sp[-1] == pytest.approx(b, rel=1e-12)
        assert np.all(np.diff(sp) * np.sign(b - a) > 0)


def test_harmonics_short_of_convergence_are_said():
    """Ji & Li over the full 168-cycle period reaches the harmonic limit before the energy
    criterion: a warning says so and what to do; a converged stage says nothing."""
    import warnings

    from torquesplit.errors import ModelWarning

    with pytest.warns(ModelWarning, match="harmonic balance stopped at .*--method shooting"):
        steady_state(example_path(EXAMPLE), method="hb", stability=False, check=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        steady_state(example_path(EXAMPLE), keep="stage1", stability=False, check=False)


def test_a_long_period_is_shot_matrix_free():
    """Ji & Li's full period holds 168 stage-1 mesh cycles: the default method shoots
    matrix-free (Anderson-accelerated period maps, no monodromy), and the state it
    returns is periodic when integrated again, independently of the solver's check."""
    st = steady_state(example_path(EXAMPLE), stability=False, check=False)
    ps = st.solution
    assert ps.method == "shooting" and ps.converged and st.period.max_order == 168
    assert "Anderson-accelerated period maps" in ps.message and "Newton" not in ps.message
    p = st.problem
    y0 = np.concatenate([ps.q[0], ps.v[0]])
    steps = ps.t.size
    yT = p.integrate(y0, 0.0, ps.period, steps, every=steps, max_rows=1)[3]
    V = st.structure.projection_matrix()
    drift = np.max(np.abs(V @ (yT - y0)[:p.n])) / np.max(np.abs(V @ y0[:p.n]))
    assert drift <= 1e-9
    # (stage 2 with the example's sharp contact-wave jumps: 1.105; docs/validation.md)
    assert all(1.07 < r.dynamic_factor < 1.11 for r in st.mesh_table())


def test_long_period_is_refused_with_the_fix():
    with pytest.raises(LongPeriodError, match="keep="):
        steady_state(example_path(EXAMPLE), max_cycles=100)


def test_shooting_accepts_longer_periods_than_harmonic_balance():
    """Liu et al. 2021 repeats after 3638 cycles of its fastest mesh: too long for
    harmonic balance by default (refused before any solve, with the fix), within
    shooting's default limit (its solve is benchmarked, not run here)."""
    from torquesplit.steady.period import default_max_cycles

    with pytest.raises(LongPeriodError, match=r"3638 cycles.*keep=.*max_cycles=3638"):
        steady_state(example_path("liu2021_split_torque_helicopter"), method="hb")
    assert default_max_cycles("hb") < 3638 < default_max_cycles("auto")
    assert default_max_cycles("shooting") == default_max_cycles("auto")


def test_campbell_crossings_at_hand_computed_speeds():
    """Two-stage drive: stage 1 meshes z1 (motor shaft) at f = z1 n1, so a mode at f_n
    is crossed by harmonic h of that mesh at n1 = f_n / (h z1) rev/s."""
    m = load_model(example_path(EXAMPLE))
    z1 = m.gears["z1"].teeth
    w_model = abs(m.drives["motor"].speed)
    ds, crossings = campbell(m, 0.5 * w_model, 1.5 * w_model, orders=2)
    fn = ds["natural_frequency"].values[0]
    hand = []
    for i, f in enumerate(fn):
        for h in (1, 2):
            w = 2 * math.pi * f / (h * z1)
            if 0.5 * w_model <= w <= 1.5 * w_model:
                hand.append((i + 1, h, w * 60 / (2 * math.pi)))
    got = [(c["mode"], c["order"], c["speed_rpm"]) for c in crossings
           if c.get("meshes") == ["m11", "m21"]]
    assert len(got) == len(hand) > 0
    for (mo, h, rpm), (mo2, h2, rpm2) in zip(sorted(hand), sorted(got), strict=True):
        assert (mo, h) == (mo2, h2) and rpm2 == pytest.approx(rpm, rel=1e-9)
    assert all(abs(sum(v for _, v in c["energy"])) <= 1 + 1e-9 for c in crossings)


def test_cli_steady_sweep_and_campbell(tmp_path):
    r = CliRunner().invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--harmonics", "16",
                                 "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["converged"] and out["harmonics"] == 16 and out["stable"]
    assert set(out["meshes"]) == {"m11", "m21", "m12", "m22"}
    r = CliRunner().invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--no-stability"])
    assert r.exit_code == 0 and "stability: not computed (--no-stability)" in r.output
    r = CliRunner().invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--no-stability",
                                 "--json"])
    assert json.loads(r.stdout)["stable"] is None
    r = CliRunner().invoke(app, ["sweep-speed", EXAMPLE, "--keep", "stage1", "--from",
                                 "700 rpm", "--to", "790 rpm", "--points", "4",
                                 "--harmonics", "8", "--no-stability", "--plot",
                                 str(tmp_path / "s.png"), "--out", str(tmp_path / "s.nc"),
                                 "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["complete"] and out["points"] >= 4 and (tmp_path / "s.png").exists()
    assert out["figure_files"] == [str(tmp_path / "s.png")]  # (written without a word)
    r = CliRunner().invoke(app, ["sweep-speed", EXAMPLE, "--keep", "stage1", "--from",
                                 "-700 rpm", "--to", "-700 rpm"])
    assert r.exit_code == 2 and "--from must be a positive speed" in r.output
    assert "--to must be a positive speed" in r.output  # (both at once)
    r = CliRunner().invoke(app, ["sweep-speed", EXAMPLE, "--keep", "stage1", "--from",
                                 "700 rpm", "--to", "700 rpm"])
    assert r.exit_code == 2 and "two different positive speeds" in r.output
    r = CliRunner().invoke(app, ["sweep-speed", EXAMPLE, "--from", "700 rpm", "--to",
                                 "800 rpm", "--points", "0", "--steps-per-cycle", "1"])
    assert r.exit_code == 2 and "--points must be a whole number >= 1" in r.output
    assert "--steps-per-cycle must be at least 10" in r.output
    r = CliRunner().invoke(app, ["modes", EXAMPLE, "--campbell", "--from", "300 rpm",
                                 "--to", "1200 rpm", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["critical_speeds"]
    r = CliRunner().invoke(app, ["steady", EXAMPLE, "--max-cycles", "10"])
    assert r.exit_code == 2 and "keep" in r.output


def test_cli_steady_converges_its_harmonics_unless_told_not_to():
    harmonics = {}
    for flags in ([], ["--fixed"]):
        r = CliRunner().invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--json",
                                     "--method", "hb", *flags])
        assert r.exit_code == 0, r.output
        data = json.loads(r.stdout)
        harmonics[tuple(flags)] = data["harmonics"]
        cut = [w for w in data["warnings"] if "harmonic balance with" in w]
        assert bool(cut) == bool(flags), cut  # the fixed 8 are too few, and it is said
    assert harmonics[()] >= 64 and harmonics[("--fixed",)] == 8
    # nothing varies in time: the steady state is the static one, and the message says so
    r = CliRunner().invoke(app, ["steady", "lin_parker1999_star"])
    assert r.exit_code == 2 and "torquesplit static" in r.output
    assert "Traceback" not in r.output


def test_coinciding_critical_speeds_share_one_line_in_the_sweep_figure():
    """A degenerate pair of modes crosses a mesh order at one speed: one line, both
    labels in one block (they were printed over each other)."""
    import xarray as xr

    from torquesplit.steady.plot import critical_speed_groups, sweep_figure

    rpm = np.linspace(2400.0, 3600.0, 5)
    ds = xr.Dataset(
        {"speed_rpm": ("point", rpm), "stable": ("point", np.ones(5, bool)),
         "dynamic_factor": (("point", "mesh"), np.ones((5, 1)))},
        coords={"mesh": ["m1"]},
        attrs={"model": "t", "critical_speeds_rpm": [2640.0, 2641.0, 3430.0, 5000.0],
               "critical_speed_labels": ["mode 2 x 2 m1", "mode 3 x 2 m1", "mode 4 x 1 m1",
                                         "outside"]})
    groups = critical_speed_groups(ds, 2400.0, 3600.0)
    assert [labs for _, labs in groups] == [["mode 2 x 2 m1", "mode 3 x 2 m1"],
                                            ["mode 4 x 1 m1"]]
    assert groups[0][0] == pytest.approx(2640.5)
    fig = sweep_figure(ds)
    tags = [t.get_text() for t in fig.axes[0].texts]
    assert tags == ["1", "2"]  # one tag per line, above the top panel
    listed = "".join(t.get_text() for t in fig.axes[-1].texts).splitlines()
    assert listed == ["1: 2640 rpm, mode 2 x 2 m1, mode 3 x 2 m1", "2: 3430 rpm, mode 4 x 1 m1"]


def test_a_long_period_keeps_every_step_of_the_meshes_and_samples_the_rest(monkeypatch):
    """A period of more than MAX_SAMPLES steps: the state and every element's force are
    kept every k-th step (k divides the steps), the meshes at every step, so the mesh
    table and the Results metrics are those of the run that keeps every step, and the
    kept samples are its rows (the deformations as the right-hand side gives them)."""
    import torquesplit.steady.solution as sol

    def solve():
        return steady_state(example_path(EXAMPLE), stability=False, check=False)

    full = solve()
    monkeypatch.setattr(sol, "MAX_SAMPLES", 1000)
    lean = solve()
    a, b = full.solution, lean.solution
    steps = a.t.size
    k = b.sample_every
    assert a.sample_every == 1 and k > 1 and steps % k == 0 and b.t.size == steps // k
    assert f"kept every {k} steps" in b.message and "kept every" not in a.message
    np.testing.assert_array_equal(b.t, a.t[::k])
    np.testing.assert_array_equal(b.forces, a.forces[::k])
    np.testing.assert_array_equal(b.mesh_forces, a.mesh_forces)
    assert b.mesh_t.size == steps and b.mesh_forces.shape[1] == len(full.mesh_names)
    _, _, D = full.problem.accelerations(a.t, np.hstack([a.q, a.v]))
    np.testing.assert_allclose(a.deformations, D, rtol=0, atol=1e-15 * np.abs(D).max())
    assert full.mesh_table() == lean.mesh_table()
    ma, mb = full.to_results().metrics(), lean.to_results().metrics()
    for ra, rb in zip(ma.rows, mb.rows, strict=True):
        assert (ra.peak_force, ra.min_force, ra.mean_force, ra.load_sharing,
                ra.contact_loss) == (rb.peak_force, rb.min_force, rb.mean_force,
                                     rb.load_sharing, rb.contact_loss)


def test_the_monodromy_is_the_derivative_of_the_cornered_period_map():
    """The variational equations step through the stiffness tables' corners in the
    sub-steps of the period map shooting solves for: the state they carry is that map's
    to the bit, and the monodromy equals its central differences (to their own error,
    about 1e-8 here; stepping over the corners left 1e-5 to 4e-5)."""
    st = steady_state(example_path(EXAMPLE), keep="stage1", method="shooting",
                      stability=False, check=False)
    p, ps = st.problem, st.solution
    steps, T, y0 = ps.t.size, ps.period, ps.y0
    assert ps.corner_t.size > 0

    def period_map(y):
        return p.integrate(y, 0.0, T, steps, every=steps, max_rows=1)[3]

    yT, Phi = p.integrate_variational(y0, 0.0, T, steps)
    np.testing.assert_array_equal(yT, period_map(y0))
    rng = np.random.default_rng(0)
    for _ in range(4):
        v = rng.normal(size=y0.size) * (np.abs(y0) + 1e-12)
        fd = (period_map(y0 + 1e-6 * v) - period_map(y0 - 1e-6 * v)) / 2e-6
        assert np.linalg.norm(fd - Phi @ v) <= 1e-6 * np.linalg.norm(fd)


def test_newton_picard_step_on_a_period_over_which_every_mode_decays():
    """Liu et al. 2021's full period (3638 bevel cycles): every mode of the linearised
    model keeps less than PICARD_RHO of itself over it, so after the first matrix-free
    Newton step the second is taken on the products already made (Newton-Picard): fewer
    products, the same periodic state.  Ji & Li's slow load-characteristic mode (0.88
    over its period) rules the step out there.  The default (Anderson-accelerated period
    maps) needs no more maps than plain Newton and about as many as Newton-Picard (8, 8
    and 7 here)."""
    from torquesplit.steady.newton import _slow_modes, solve_shooting

    ji = steady_state(example_path(EXAMPLE), stability=False, check=False)
    assert _slow_modes(ji.problem, ji.solution.period) > 0
    st = steady_state(_example("liu2021_split_torque_helicopter"), stability=False,
                      check=False, max_cycles=5000, tol=1e-2)  # the problem, cheaply
    p, ps = st.problem, st.solution
    assert _slow_modes(p, ps.period) == 0 and st.period.max_order > 3000
    steps = ps.mesh_t.size
    y0 = p.settled_start(np.concatenate([st.static.q, np.zeros(p.n)]), ps.period, steps,
                         1.0, st.period.max_order)
    runs = [solve_shooting(p, y0, steps, monodromy=False, newton_picard=npk,
                           anderson=False) for npk in (True, False)]
    (ya, _, a), (yb, _, b) = runs
    assert a.converged and b.converged and a.products < b.products
    V = st.structure.projection_matrix()
    assert np.max(np.abs(V @ (ya - yb)[:p.n])) <= 1e-8 * np.max(np.abs(V @ yb[:p.n]))
    # the default, Anderson-accelerated maps: the same state in fewer period maps than
    # either Newton (a defect map per step and one per product)
    yc, _, c = solve_shooting(p, y0, steps, monodromy=False)
    assert c.converged and c.anderson == c.iterations and c.products == 0
    assert c.anderson <= b.iterations + 1 + b.products
    assert c.anderson <= a.iterations + 1 + a.products + 2
    assert np.max(np.abs(V @ (yc - yb)[:p.n])) <= 1e-8 * np.max(np.abs(V @ yb[:p.n]))


def test_progress_says_what_a_long_steady_state_is_doing():
    """The progress callback hears each phase: every period map of the matrix-free
    (Anderson-accelerated) iteration with its defect, the monodromy; for harmonic
    balance the harmonics tried and the Floquet multipliers."""
    heard = []
    st = steady_state(example_path(EXAMPLE), stability=True, check=False,
                      progress=lambda fraction, what: heard.append((fraction, what)))
    texts = [w for _, w in heard]
    assert all(f is None for f, _ in heard)
    maps = [t for t in texts if "Anderson step" in t]
    assert texts[:len(maps)] == maps and len(maps) == st.solution.iterations
    assert f"{st.solution.residual:.1e}" in maps[-1]
    assert len(texts) == len(maps) + 1 and "monodromy" in texts[-1]
    heard.clear()
    steady_state(example_path(EXAMPLE), keep="stage1", harmonics=16,
                 progress=lambda fraction, what: heard.append(what))
    assert heard[0] == "harmonic balance, 16 harmonics" and "Floquet multipliers" in heard


def test_period_weights_by_hand():
    """Trapezoid weights with a corner instant as a breakpoint sum to the period."""
    from torquesplit.steady.api import period_weights

    ws, wc = period_weights([0.0, 0.25, 0.5, 0.75], [0.6], 1.0)
    assert np.allclose(ws, [0.25, 0.25, 0.175, 0.2]) and np.allclose(wc, [0.125])
    assert math.isclose(ws.sum() + wc.sum(), 1.0)


def test_mean_forces_converge_with_the_step_through_impact_pulses():
    """Liu et al. 2021's spur split stage (meshing-in impact pulses and steep stiffness
    ramps, narrower than a step): the mean mesh forces by the trapezoid rule with the
    table corners as breakpoints move by < 5e-4 from 100 to 200 steps per cycle (3e-4
    on one mesh since the spur pairs' ISO stiffness has ISO's mean c_gamma), and agree
    with 800 to 1e-4; the plain mean of the step samples moved by 5e-3 (first order).  The step check reports the same.  (At the example's own 16384 table points
    the pulses are sharper still and 100 steps per cycle move them 3e-4.)"""
    from torquesplit.convergence import check_steady

    path = _example("liu2021_split_torque_helicopter")
    runs = {spc: steady_state(path, keep="spur_split", stability=False,
                              steps_per_cycle=spc) for spc in (100, 200, 800)}
    mean = {spc: np.array([r.mean_force for r in st.mesh_table()])
            for spc, st in runs.items()}
    assert np.max(np.abs(mean[100] / mean[200] - 1)) < 5e-4
    assert np.max(np.abs(mean[200] / mean[800] - 1)) < 1e-4
    plain = runs[100].solution.mesh_forces.mean(axis=0)
    assert np.max(np.abs(plain / mean[800] - 1)) > 2e-3  # what the rectangle rule gave
    check = check_steady(runs[100])
    assert check.step == pytest.approx(2 * check.halved_step)
    assert all(check.digits(k) >= 3 for k in check.values if k.startswith("mean_force"))


def test_steady_check_step_on_the_command_line():
    """``steady --check-step`` solves again at half the step and says how many digits
    hold; ``--steps-per-cycle`` sets the step (and is checked)."""
    runner = CliRunner()
    out = runner.invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--check-step",
                              "--no-stability"])
    assert out.exit_code == 0, out.output
    assert "step check, the same state at half the step" in out.output
    data = json.loads(runner.invoke(app, ["steady", EXAMPLE, "--keep", "stage1", "--json",
                                          "--check-step", "--steps-per-cycle", "200",
                                          "--no-stability"]).output)
    check = data["step_check"]
    assert check["method"] == "shooting"
    assert check["step"] == pytest.approx(2 * check["halved_step"])
    # the example's contact waves have jumps: the check refines its tables too
    assert check["check_table_points"] == 4 * check["table_points"] == 4 * 65536
    assert check["step"] <= data["period_s"] / 200 * (1 + 1e-9)  # at least 200 per cycle
    assert all(v["digits"] >= 4 for k, v in check["metrics"].items()
               if k.startswith(("dynamic_factor", "mean_force")))
    bad = runner.invoke(app, ["steady", EXAMPLE, "--steps-per-cycle", "3"])
    assert bad.exit_code != 0 and "--steps-per-cycle" in bad.output


def test_the_largest_dynamic_factor_of_a_sweep_is_that_of_its_stable_points():
    """A softening branch: continuation passes a fold and runs down the unstable middle
    branch, whose dynamic factor exceeded every stable one; 'sweep-speed' reported it
    as the sweep's largest (a reviewer's spur pair with backlash: 2.507 at 7624 rpm, on
    a point its own dataset marks unstable).  Time integrations of --cross-check are
    reported beside it."""
    import xarray as xr

    from torquesplit.steady.cli import sweep_maxima

    rpm = np.array([7000.0, 7500.0, 8000.0, 7800.0, 7600.0])
    df = np.array([[1.5], [2.0], [2.3], [2.4], [2.6]])
    ds = xr.Dataset(
        {"stable": ("point", np.array([True, True, True, False, False])),
         "dynamic_factor": (("point", "mesh"), df),
         "run_up_dynamic_factor": (("check", "mesh"), np.array([[1.4], [3.7]])),
         "run_down_dynamic_factor": (("check", "mesh"), np.array([[3.9], [2.0]]))},
        coords={"speed_rpm": ("point", rpm), "mesh": ["m"],
                "check_speed_rpm": ("check", np.array([7000.0, 8000.0]))})
    got = sweep_maxima(ds)["m"]
    assert got["stable"] == (2.3, 8000.0)
    assert got["run_up"] == (3.7, 8000.0) and got["run_down"] == (3.9, 7000.0)
    ds["stable"][:] = False
    assert all(math.isnan(v) for v in sweep_maxima(ds)["m"]["stable"])


def test_a_record_far_beyond_its_limit_is_refused_before_it_is_allocated():
    """'steady --speed 1e9 rpm' asked for 22 GiB (killed, or a MemoryError traceback)."""
    from torquesplit.errors import SolverError
    from torquesplit.steady.api import RESULT_ROWS, _check_record_size

    _check_record_size(64, RESULT_ROWS // 64, 10)  # within: nothing said
    with pytest.raises(SolverError, match=r"29,333,334 periods of 100 samples \(21\.9 GiB\)"):
        _check_record_size(29_333_334, 100, 1)


def test_critical_speeds_between_far_apart_points_are_said():
    """A sweep to 1e9 rpm in 31 points said 'complete' and missed a resonance between two
    of its points."""
    from torquesplit.steady.maps import unresolved_critical_speeds

    speeds = np.array([1000.0, 1050.0, 1100.0, 5000.0])
    assert unresolved_critical_speeds(speeds, [1040.0, 3000.0, 9000.0]) == [3000.0]
    assert unresolved_critical_speeds(speeds, [1099.0, 4800.0]) == []


@pytest.mark.parametrize("args, said", [
    (["--max-cycles", "2"], "(--keep <stage, mesh or body>, the others by their means"),
    (["--max-cycles", "2"], "accept the long period (--max-cycles 168)"),
    (["--max-cycles", "0"], "--max-cycles must be a whole number >= 1"),
    (["--harmonics", "0"], "--harmonics must be a whole number >= 1"),
    (["--speed", "0"], "--speed must be a positive speed"),
])
def test_steady_messages_name_the_flags(args, said):
    """The command's messages said keep='...', max_cycles=168, harmonics=16 (Python)."""
    r = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", *args])
    assert r.exit_code == 2 and said in r.stderr, r.stderr
    assert "max_cycles=" not in r.stderr and "keep='" not in r.stderr


def test_a_saved_steady_state_says_what_it_is():
    """Its file omitted the RMS transmission error, the Floquet stability, the residual
    and the excitations replaced by their means, and described a 0.177 s 'run' with a
    start-up (a reviewer)."""
    st = steady_state(example_path(EXAMPLE), keep="stage1", harmonics=16)
    ds = st.to_results().to_dataset()
    info = st.summary()
    assert ds.attrs["analysis"] == "periodic steady state"
    assert ds.attrs["steady_method"] == info["method"] == "hb"
    assert ds.attrs["steady_residual"] == info["residual"]
    assert ds.attrs["dropped_excitations"] == "; ".join(info["dropped_excitations"]) != ""
    assert "repeated" in ds.attrs["record"]
    np.testing.assert_array_equal(
        ds["rms_transmission_error"].values,
        [info["meshes"][m]["rms_transmission_error"] for m in ds["mesh"].values])
    assert "start-up" not in ds["contact_loss_fraction"].attrs["long_name"]
    assert json.loads(ds.attrs["steady_json"])["period_s"] == pytest.approx(info["period_s"])
    # stability as a number a program can test (it was the text 'True') and in words
    assert ds.attrs["steady_stable"] == int(info["stable"]) and ds.attrs["steady_stable"] in (0, 1)
    assert ds.attrs["steady_stability"] == ("stable" if info["stable"] else "unstable")


def test_a_saved_steady_state_holds_one_period_and_reads_back_the_same(tmp_path):
    """Its files held every repetition of the period the record repeats (Ji & Li: 62 MB of
    CSV, one period 870 times); read back, a bearing force's mean was over part of a
    period (from a settle time inside it: 2.67 N where the period's mean is 7e-5 N)."""
    import torquesplit

    st = steady_state(example_path(EXAMPLE), keep="stage1", harmonics=16)
    res = st.to_results()
    period = st.solution.period
    t = res.solution.history_t
    assert t[-1] - t[0] > 2 * period  # (the premise: the record repeats the period)
    ds = res.to_dataset()
    first = int(np.count_nonzero(t < t[0] + period * (1 - 1e-9)))
    assert ds.sizes["time"] == first and ds.attrs["history_periods"] == 1
    np.testing.assert_array_equal(ds["element_force"].values, res.solution.history_forces[:first])
    res.save(tmp_path / "s.nc")
    res.to_csv(tmp_path / "s.csv")
    rows = (tmp_path / "s_history.csv").read_text().count("\n") - 1
    assert rows == first
    back = torquesplit.load_results(tmp_path / "s.nc")
    assert back.periodic and back.period == period
    a, b = res.metrics(), back.metrics()
    assert a.load_sharing.system == b.load_sharing.system
    # (the static forces are solved again on reading: the factors agree to rounding)
    assert b.dynamic_factors.per_group_dynamic_factor == pytest.approx(
        a.dynamic_factors.per_group_dynamic_factor, rel=1e-10)
    whole = res.bearing_forces(a.settling.start_time)
    assert whole == back.bearing_forces(b.settling.start_time)
    # what reads the history after the settle time takes the whole period of a file
    # read back (it holds one period, which ends before stage 2's settle time: the
    # spectrum figure found no sample, the coarse-history check skipped every mesh)
    from torquesplit.plot.figures import support_spectrum_figure
    from torquesplit.results.plausibility import coarse_history

    assert back.history_start() == res.history_start() == t[0]
    support_spectrum_figure(back)
    assert coarse_history(back, b) == coarse_history(res, a)
    # the mean over the first whole period, whatever the settle time
    cols = res.support_columns()
    body = whole[0]["body"]
    _, c, sign = cols[body][0]
    assert whole[0]["mean"][0] == pytest.approx(
        sign * res.solution.history_forces[:first, c].mean(), rel=1e-12, abs=1e-9)


def test_a_kept_frequency_is_that_at_the_speed_asked_for():
    """--keep 5350.67 (the mesh frequency at --speed 16052 rpm) was read at the model
    file's speed: the mesh's own stiffness was dropped and a flat DF 1.00000 printed."""
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.steady.api import reference_speed

    m = _ji_li()
    kin = solve_kinematics(m)
    f1, f2 = kin.meshes["m11"].frequency, kin.meshes["m12"].frequency
    speed = 1.5 * reference_speed(m)
    kw = dict(speed=speed, harmonics=8, stability=False, adaptive=False)
    by_stage = steady_state(m, keep="stage1", **kw)
    by_hz = steady_state(m, keep=1.5 * f1, **kw)
    assert by_hz.dropped_text() == by_stage.dropped_text()
    assert any(f"at {1.5 * f2:.6g} Hz" in t for t in by_hz.dropped_text())
    a, b = by_stage.summary()["meshes"]["m11"], by_hz.summary()["meshes"]["m11"]
    assert b["dynamic_factor"] == pytest.approx(a["dynamic_factor"], rel=1e-12)
    assert b["dynamic_factor"] > 1.001


def test_a_mesh_keeps_its_colour_in_every_panel_of_the_sweep_figure():
    """A lower panel where two meshes' curves coincide drew the next mesh in the colour
    cycle's next colour: m12's transmission error read as m21's.  And without stability
    the title claimed 'solid stable, dashed unstable'; a load sharing whose means are
    equal but instants not got no panel."""
    import xarray as xr

    from torquesplit.steady.plot import sweep_figure

    rpm = np.linspace(700.0, 790.0, 4)
    df = np.column_stack([np.linspace(1.0, 1.2, 4) + k for k in range(3)])
    te = np.column_stack([np.full(4, 1.0), np.full(4, 1.0), np.full(4, 3.0)]) * 1e-6
    inst = np.column_stack([np.linspace(1.06, 1.07, 4)] * 3)
    ds = xr.Dataset(
        {"speed_rpm": ("point", rpm), "stable": ("point", np.ones(4, bool)),
         "max_multiplier": ("point", np.full(4, np.nan)),
         "dynamic_factor": (("point", "mesh"), df),
         "load_sharing_mean_force": (("point", "mesh"), np.ones((4, 3))),
         "load_sharing_instantaneous": (("point", "mesh"), inst),
         "rms_transmission_error": (("point", "mesh"), te)},
        coords={"mesh": ["m11", "m21", "m12"]}, attrs={"model": "t"})
    fig = sweep_figure(ds)
    colours = []
    for ax in fig.axes[:3]:
        colours.append({ln.get_label().split(",")[0]: ln.get_color() for ln in ax.lines
                        if ln.get_label() and not ln.get_label().startswith("_")})
    assert colours[0]["m12"] == colours[2]["m12"] and colours[0]["m11"] == colours[2]["m11"]
    assert "m21" not in colours[2]  # (joined m11's line)
    assert "stability not computed" in fig.axes[0].get_title()
    assert "instantaneous" in fig.axes[1].get_ylabel()
    # identical planets differ in their round-off: still one curve, one legend entry (at
    # 1e-9 relative two of three were listed apart, a planetary reviewer)
    same = np.column_stack([np.linspace(1.0, 1.2, 4) * (1.0 + k * 3e-9) for k in range(3)])
    fig = sweep_figure(ds.assign(dynamic_factor=(("point", "mesh"), same)))
    labels = [ln.get_label() for ln in fig.axes[0].lines if not ln.get_label().startswith("_")]
    assert labels == ["m11, m21, m12"], labels


def test_an_older_sweep_file_keeps_its_load_sharing_panel():
    """sweep-speed's mean-force coefficient was 'load_sharing' in its files before it was
    named 'load_sharing_mean_force': an older file still plots it (a reviewer)."""
    import xarray as xr

    from torquesplit.steady.plot import sweep_figure

    rpm = np.linspace(700.0, 790.0, 4)
    ds = xr.Dataset(
        {"speed_rpm": ("point", rpm), "stable": ("point", np.ones(4, bool)),
         "max_multiplier": ("point", np.full(4, np.nan)),
         "dynamic_factor": (("point", "mesh"), np.ones((4, 2))),
         "load_sharing": (("point", "mesh"), np.array([[1.1, 0.9]] * 4))},
        coords={"mesh": ["m11", "m21"]}, attrs={"model": "t"})
    for variables in (None, "load_sharing"):
        fig = sweep_figure(ds, variables)
        labels = [ax.get_ylabel() for ax in fig.axes]
        assert any("mean forces" in lab for lab in labels), labels
