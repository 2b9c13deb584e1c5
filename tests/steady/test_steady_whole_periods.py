"""A steady state's table is over whole periods, at the step its meshes' cycles need."""

import math

import numpy as np
import pytest
from model_texts import write_tutorial_model

from torquesplit import example_path
from torquesplit.steady.api import steady_state
from torquesplit.steady.problem import MESH_CYCLE_STEPS


@pytest.fixture(scope="module")
def mo_star():
    """Mo et al. 2017's star reducer: three identical paths, 10 kHz meshes of constant
    stiffness, errors turning with the gears (period 0.486 s, fastest error 666.7 Hz)."""
    return steady_state(example_path("mo2017_star_reducer"), stability=False)


def test_mean_force_sharing_of_identical_paths_is_one(mo_star):
    """Over whole periods the three paths carry the same mean force (1e-12), so the
    mean-force coefficients are 1; the record repeated twice and settled part-way gave
    1.0003."""
    rows = mo_star.mesh_table("mean_force")
    means = np.array([r.mean_force for r in rows])
    np.testing.assert_allclose(means[:3], means[0], rtol=1e-12)
    for r in rows:
        assert r.load_sharing == pytest.approx(1.0, abs=1e-9), r.mesh
    met = mo_star.to_results().metrics("mean_force")
    assert met.settling.settled and met.load_sharing.system == pytest.approx(1.0, abs=1e-9)


def test_steps_resolve_the_cycles_of_a_constant_stiffness_mesh(mo_star):
    """The errors alone would set 100 steps per 666.7 Hz cycle, 6.7 per 10 kHz mesh
    cycle; the per-cycle statistics get at least MESH_CYCLE_STEPS per mesh cycle."""
    st = mo_star
    f_mesh = float(np.max(st.structure.frequency))
    cycles = f_mesh * st.solution.period
    assert cycles == pytest.approx(round(cycles)) and st.period.max_order * 100 < 10 * cycles
    assert st.solution.mesh_t.size >= MESH_CYCLE_STEPS * round(cycles)


def test_period_text_is_that_of_the_speed_solved():
    """At 2/3 of the model's speed the period and every frequency in the text scale."""
    from torquesplit.steady.period import fundamental_period

    import torquesplit

    s = torquesplit.assemble(torquesplit.load_model(example_path("ji_li_mill_drive")))
    per = fundamental_period(s)
    text = per.describe(2 / 3)
    assert f"least common period {per.period * 1.5:.6g} s" in text
    assert f"f0 = {per.frequency * 2 / 3:.6g} Hz" in text


def test_speed_with_its_unit():
    """speed='3000 rpm' and speed='50 Hz' are the same speed (rad/s as a bare number)."""
    import math

    from torquesplit.errors import OptionError
    from torquesplit.steady.api import reference_speed, speed_factor

    import torquesplit

    m = torquesplit.load_model(example_path("ji_li_mill_drive"))
    w = 100 * math.pi
    assert speed_factor(m, "3000 rpm") == pytest.approx(w / reference_speed(m), rel=1e-12)
    assert speed_factor(m, "50 Hz") == pytest.approx(speed_factor(m, w), rel=1e-12)
    with pytest.raises(OptionError, match="speed"):
        speed_factor(m, "3000 mm")


def test_steady_out_keeps_an_existing_file_unless_forced(tmp_path):
    """`steady --out` on an existing file is refused before solving, as `run --out` is;
    --force replaces it."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    out = tmp_path / "s.nc"
    out.write_bytes(b"keep me")
    args = ["steady", "ji_li_mill_drive", "--keep", "stage1", "--no-stability", "--out",
            str(out)]
    runner = CliRunner()
    refused = runner.invoke(app, args)
    assert refused.exit_code == 2 and "--force" in refused.output
    assert out.read_bytes() == b"keep me"
    done = runner.invoke(app, args + ["--force"])
    assert done.exit_code == 0, done.output
    assert out.read_bytes() != b"keep me"


def test_resonance_map_orders_follow_the_stiffness_spectrum():
    """A rectangular single/double contact wave of duty 0.6 still has 9 % of its
    fundamental at the 7th harmonic: the map's mesh lines go that far (at most 10, at
    least 3 for a constant stiffness)."""
    from torquesplit.steady.maps import MAX_ORDERS, MIN_ORDERS, mesh_orders

    phase = np.arange(256) / 256
    wave = np.where(phase < 0.6, 1.1, 1.0)
    assert mesh_orders(wave) >= 7
    assert mesh_orders(np.ones(256)) == MIN_ORDERS
    assert mesh_orders(np.where(phase < 0.5, 1.1, 1.0) + 0 * phase) <= MAX_ORDERS
    assert mesh_orders(1.0 + 0.1 * np.cos(2 * np.pi * phase)) == MIN_ORDERS


def test_ratio_extremes_take_the_cycle_starts(mo_star, monkeypatch):
    """Mo et al. 2017's meshes have constant stiffness (continuous at their cycle starts):
    the load-sharing ratio interpolated at each start enters the per-cycle ratio
    extremes (``boundary_ratios``, as the integrator's ``ratio_starts``), which raises
    some cycle maxima above their instants' and never lowers one."""
    import torquesplit.steady.api as api

    with_starts = mo_star.to_results().solution.cycle_ratio_max
    monkeypatch.setattr(api, "boundary_ratios", lambda *a, **k: None)
    without = mo_star.to_results().solution.cycle_ratio_max
    ok = np.isfinite(with_starts) & np.isfinite(without)
    assert ok.sum() > 100
    assert np.all(with_starts[ok] >= without[ok])
    assert np.sum(with_starts[ok] > without[ok] * (1 + 1e-12)) > 10


def test_steady_says_its_results_warnings_and_leaves_out_cycles_without_samples(tmp_path):
    """A reviewer found a warning in the steady state's file that the command never
    printed (nor listed under --json), advising an option 'steady' does not have; and the
    cycles table gave a mean force of 0.0 where the cycle had no sample (blank peak)."""
    import csv
    import json

    from typer.testing import CliRunner

    from torquesplit.cli import app

    model = write_tutorial_model(tmp_path)
    out = tmp_path / "sd.csv"
    res = CliRunner().invoke(app, ["steady", str(model), "--no-stability", "--json", "--out",
                                   str(out)])
    assert res.exit_code == 0, res.output
    said = json.loads(res.stdout)["warnings"]
    # each group's and the system's numbers, as a run's --json has them (the steady
    # state's had the meshes only: an exports reviewer)
    printed = json.loads(res.stdout)
    import torquesplit.steady as steady

    met = steady.steady_state(str(model), stability=False).to_results().metrics().to_dict()
    assert printed["groups"].keys() == met["groups"].keys() and printed["groups"]
    for g, v in met["groups"].items():
        assert printed["groups"][g]["load_sharing"] == pytest.approx(v["load_sharing"])
        assert printed["groups"][g]["dynamic_factor"] == pytest.approx(v["dynamic_factor"])
    assert printed["system_load_sharing"] == pytest.approx(met["system_load_sharing"])
    waveform = [w for w in said if "saved waveform of the periodic state" in w]
    assert waveform and "--steps-per-cycle" in waveform[0]
    assert not any("--samples-per-period" in w for w in said)
    # and every warning it printed is in its files
    kept = json.loads((tmp_path / "sd_about.json").read_text())["warnings"]
    assert said and [w for w in said if w not in kept] == []
    rows = list(csv.DictReader(open(tmp_path / "sd_cycles.csv", newline="")))
    for row in rows:
        for key in [k for k in row if k.endswith("_peak_N")]:
            mean = row[key.replace("_peak_N", "_mean_N")]
            assert (row[key] == "") == (mean == ""), (row["cycle"], key)
    assert any(row["in1_peak_N"] == "" for row in rows)
    # the cycles of one period, not of every repetition of it in the record (a planetary
    # reviewer's table had 89 identical rows); the .nc keeps the whole record
    import xarray as xr

    about = json.loads((tmp_path / "sd_about.json").read_text())
    period = about["steady"]["period_s"]
    starts = [[float(v) for k, v in r.items() if k.endswith("_start_s") and v != ""]
              for r in rows]
    assert all(any(-1e-12 <= t < period for t in row) for row in starts), starts
    # every mesh's own cycles only: a row is a cycle index, which a slower mesh reaches
    # later (its cells held six repetitions of the period, an exports reviewer)
    assert all(-1e-12 <= t < period for row in starts for t in row), starts
    for row in rows:  # a mesh's cells and its settled flag are there together
        for key in [k for k in row if k.endswith("_start_s")]:
            assert (row[key] == "") == (row[key.replace("_start_s", "_settled")] == "")
    assert max(max(r) for r in starts) > 0.5 * period  # (the whole period, not a part)
    nc = CliRunner().invoke(app, ["steady", str(model), "--no-stability", "--out",
                                  str(tmp_path / "sd.nc")])
    assert nc.exit_code == 0, nc.output
    with xr.open_dataset(tmp_path / "sd.nc", engine="h5netcdf") as ds:
        assert ds.sizes["cycle"] > 3 * len(rows)
    # the table's RMS transmission error is in the summary file as in the .nc
    summary = {r["mesh"]: r for r in csv.DictReader(open(out, newline=""))}
    printed = json.loads(res.stdout)["meshes"]
    for mesh, row in summary.items():
        assert float(row["rms_transmission_error_m"]) == pytest.approx(
            printed[mesh]["rms_transmission_error"], rel=1e-12)


def test_json_output_and_file_attributes_hold_no_bare_nan(tmp_path):
    """'steady --json' printed "top_harmonic_energy": NaN, which is not JSON (node and
    MATLAB's jsondecode refuse the whole document); the file's statistics_json and
    steady_json did the same.  Non-finite numbers are null now."""
    import json

    import xarray as xr
    from typer.testing import CliRunner

    from torquesplit import _json
    from torquesplit.cli import app

    def refuse(token):
        raise ValueError(f"bare {token} in the JSON")

    out = tmp_path / "s.nc"
    res = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--keep", "stage1",
                                   "--no-stability", "--json", "--out", str(out)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout, parse_constant=refuse)
    assert "top_harmonic_energy" in json.dumps(doc)
    with xr.open_dataset(out) as ds:
        for key, text in ds.attrs.items():
            if key.endswith("_json"):
                json.loads(text, parse_constant=refuse)
    assert _json.dumps({"a": [float("nan"), np.float64("-inf"), np.array([1.0, np.nan])]}) \
        == '{"a": [null, null, [1.0, null]]}'


def test_a_periodic_state_is_not_said_to_drift():
    """A converged periodic state of Ji & Li's drive at 20 rpm was said to have 'settled
    peaks that are not steady ... a mode still decaying' (its stage-1 peaks beat with
    stage 2 over 168 of their cycles): a periodic state repeats, nothing decays."""
    import torquesplit

    model = torquesplit.load_model("ji_li_mill_drive")
    sd = steady_state(model, speed="20 rpm", stability=False)
    res = sd.to_results()
    assert res.periodic and res.success
    assert not any("not steady" in w or "over its first half" in w for w in res.warnings())
    # the period solved is at 20 rpm (period_s); period.period is the model speed's
    rpm = float(torquesplit.steady.maps.reference_speed(model)) * torquesplit.steady.maps.RPM
    assert sd.period_s == pytest.approx(sd.period.period * rpm / 20.0, rel=1e-12)
    assert f"period {sd.period_s:.4g} s" in repr(sd)


def test_keep_takes_a_frequency_with_its_unit():
    """--keep '235.917 Hz' was refused as 'no mesh, stage or body ... or a frequency in
    Hz' although the help asks for a frequency in Hz."""
    from typer.testing import CliRunner

    from torquesplit.cli import app

    runner = CliRunner()
    args = ["steady", "ji_li_mill_drive", "--no-stability", "--json", "--keep"]
    bare = runner.invoke(app, args + ["235.917"])
    unit = runner.invoke(app, args + ["235.917 Hz"])
    assert bare.exit_code == unit.exit_code == 0, unit.output
    import json

    a, b = json.loads(bare.stdout), json.loads(unit.stdout)
    assert a["dropped_excitations"] == b["dropped_excitations"] and a["dropped_excitations"]
    assert a["meshes"] == b["meshes"]
    wrong = runner.invoke(app, args + ["235.917 mm"])
    assert wrong.exit_code == 2 and "--keep '235.917 mm'" in wrong.stderr
    assert "not a frequency" in wrong.stderr


def test_a_harmonic_balance_cut_short_is_said():
    """16 fixed harmonics of Ji & Li's stage 1 gave dynamic factors 1.6 % low (and two
    symmetric meshes different ones) with no warning; the adaptive solve has none."""
    import torquesplit

    model = torquesplit.load_model("ji_li_mill_drive")
    cut = steady_state(model, keep="stage1", method="hb", harmonics=16, adaptive=False,
                       stability=False).to_results()
    said = [w for w in cut.warnings() if "harmonic balance with 16 harmonics" in w]
    assert said and "--method shooting" in said[0]
    full = steady_state(model, keep="stage1", method="hb", stability=False).to_results()
    assert not any("harmonic balance with" in w for w in full.warnings())
    # a looser limit asked for is not contradicted (a reviewer's energy_tol=1e-4 was told
    # to let the harmonics double)
    loose = steady_state(model, keep="stage1", method="hb", harmonics=16, adaptive=False,
                         energy_tol=0.5, stability=False).to_results()
    assert not any("harmonic balance with" in w for w in loose.warnings())


def test_sweep_speed_says_which_load_sharing_it_gives():
    """Over speed the coefficient is the mean-force one whatever the model asks for; a
    reviewer read Ji & Li's 1.0000 there against 1.0656 (engineering) from 'steady'."""
    import json

    from typer.testing import CliRunner

    from torquesplit.cli import app

    args = ["sweep-speed", "ji_li_mill_drive", "--from", "740 rpm", "--to", "750 rpm",
            "--points", "3", "--keep", "stage1", "--no-stability"]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    text = " ".join(r.stdout.split())
    assert "the model's definition 'engineering' is not computed by the sweep" in text
    data = json.loads(CliRunner().invoke(app, args + ["--json"]).stdout)
    assert data["load_sharing_definitions"] == ["mean_force", "instantaneous"]


def test_a_sweep_panel_of_a_nearly_constant_coefficient_is_not_all_noise():
    """A coefficient of 1 within 1e-8 filled its panel with rounding wiggles ('1e-8+1')."""
    from matplotlib.figure import Figure

    from torquesplit.steady.plot import _least_span

    ax = Figure().add_subplot()
    ax.plot([400, 500, 600], [1.0, 1.0 + 6e-10, 1.0 - 3e-10])
    _least_span(ax)
    lo, hi = ax.get_ylim()
    assert hi - lo == pytest.approx(0.02) and lo < 1.0 < hi
    assert not ax.yaxis.get_major_formatter().get_useOffset()
    wide = Figure().add_subplot()
    wide.plot([0, 1], [1.0, 1.5])
    before = wide.get_ylim()
    _least_span(wide)
    assert wide.get_ylim() == before


def test_a_speed_in_hz_far_from_the_models_is_said():
    """'--speed 745 Hz' (a frequency pasted as a speed) ran Ji & Li's drive at 44,700 rpm
    with no word; a speed in Hz near the model's is taken quietly."""
    import warnings

    import torquesplit
    from torquesplit.errors import ModelWarning
    from torquesplit.steady.api import speed_factor

    m = torquesplit.load_model("ji_li_mill_drive")
    with pytest.warns(ModelWarning, match=r"'745 Hz' is 745 revolutions per second = "
                                          r"44,700 rpm, 60 times"):
        assert speed_factor(m, "745 Hz") == pytest.approx(60.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        speed_factor(m, "12.4 Hz")
        speed_factor(m, "7450 rpm")
    # a bare number in Python is rad/s: 745 meant as rpm runs 9.5 times too fast
    with pytest.warns(ModelWarning, match=r"speed 745 is read in rad/s = 7,114.2\d rpm, "
                                          r"9.55 times .* speed='745 rpm'"):
        speed_factor(m, 745)
    with pytest.raises(torquesplit.errors.OptionError, match="not a positive finite"):
        speed_factor(m, -78.0)  # (its absolute value ran, silently)
    # the command line says a bare number's unit once (the library repeated it)
    from typer.testing import CliRunner

    from torquesplit.cli import app

    r = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--speed", "7.8",
                                 "--keep", "stage1", "--no-stability"])
    assert r.exit_code == 0, r.output
    said = [ln for ln in r.stderr.splitlines() if ln.startswith("warning:")]
    assert len([ln for ln in said if "rad/s" in ln]) == 1, said


def test_every_file_a_save_writes_is_named(tmp_path):
    """'results written to x.csv' named one of the six files a steady state's CSV set
    writes (and modes one of three)."""
    import json

    from typer.testing import CliRunner

    from torquesplit.cli import app

    out = tmp_path / "s.csv"
    r = CliRunner().invoke(app, ["steady", "ji_li_mill_drive", "--keep", "stage1",
                                 "--no-stability", "--json", "--out", str(out)])
    data = json.loads(r.stdout)
    listed = data["results_files"]
    # every number of a mesh has its unit (the table prints kN and µm, the JSON SI)
    assert set(data["units"]) == set(data["meshes"]["m11"]) - {"group"}
    assert data["units"]["rms_transmission_error"] == "m"
    assert sorted(listed) == sorted(str(p) for p in tmp_path.iterdir()) and len(listed) == 7
    r = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--out", str(tmp_path / "m.csv")])
    said = " ".join(r.stdout.split())
    for name in ("m.csv", "m_dof.csv", "m_about.json"):
        assert (tmp_path / name).exists() and str(tmp_path / name) in said


def test_a_long_shooting_solve_is_announced_before_it_starts(monkeypatch):
    """Ji & Li's drive at 1 rpm printed nothing for minutes (its highest mode sets 31.6
    million steps per period); the announcement comes before the shooting starts."""
    import torquesplit
    from torquesplit.errors import ModelWarning
    from torquesplit.steady import solution

    class Stop(Exception):
        pass

    def stop(*a, **k):
        raise Stop

    monkeypatch.setattr(solution, "solve_shooting", stop)
    model = torquesplit.load_model("ji_li_mill_drive")
    with pytest.warns(ModelWarning, match=r"takes 31,5\d\d,\d\d\d RK4 steps per period "
                                          r"\(the highest mode, 9476.6\d Hz"):
        with pytest.raises(Stop):
            steady_state(model, speed="1 rpm", stability=False)


def test_steady_and_campbell_options_are_checked_and_the_summary_names_its_definition():
    """steps_per_cycle=0 ran, tol=-1 ran to 'NOT converged', stability='foo' was taken,
    campbell(points=0) failed inside xarray; summary()'s load_sharing did not say which
    coefficient it is (sweep_speed's is another)."""
    import torquesplit
    from torquesplit.errors import OptionError
    from torquesplit.steady.maps import campbell

    model = torquesplit.load_model("ji_li_mill_drive")
    for kwargs, said in (({"steps_per_cycle": 0}, "steps_per_cycle must be a whole number"),
                         ({"tol": -1}, "tol must be a small positive number"),
                         ({"stability": "foo"}, "stability must be True, False, 'hill'")):
        with pytest.raises(OptionError, match=said):
            steady_state(model, keep="stage1", **kwargs)
    with pytest.raises(ValueError, match="points must be a whole number >= 2, got 0"):
        campbell(model, 60, 80, points=0)
    summary = steady_state(model, keep="stage1", stability=False).summary()
    assert summary["load_sharing_definition"] == "engineering"  # the model's
    res = torquesplit.simulate(model, cycles=5, history_dofs="z1.theta")
    assert res.solution.history_q.shape[1] == 1  # one DOF, not its letters


def test_a_steady_states_files_keep_the_warnings_given_while_it_was_solved(tmp_path):
    """A reviewer: 'steady' printed that its speed is next to a critical speed, its files
    held no warning, and the report of them said 'no warnings'.  Its results keep the
    warnings given while solving and the critical-speed notes, as a run's do, also when
    the caller silenced them (Ji & Li's drive at 812 rpm, next to a driven crossing)."""
    import warnings

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        st = steady_state(example_path("ji_li_mill_drive"), stability=False,
                          speed="812 rpm")
    res = st.to_results()
    critical = [w for w in res.warnings() if "below a critical speed" in w]
    assert critical and critical == st.critical_notes()
    res.save(tmp_path / "st.nc")
    assert critical[0] in torquesplit.load_results(tmp_path / "st.nc").warnings()
    # its period and stability reach MATLAB and the CSV set, and a file read back and
    # saved again keeps them and its RMS transmission errors (they were lost)
    import json

    import scipy.io
    import xarray as xr

    mat = scipy.io.loadmat(res.save(tmp_path / "st.mat"), simplify_cells=True)["steady"]
    assert mat["period_s"] == pytest.approx(st.solution.period) and mat["method"] == "shooting"
    res.save(tmp_path / "st.csv")
    about = json.loads((tmp_path / "st_about.json").read_text())["steady"]
    assert about["period_s"] == pytest.approx(st.solution.period)
    torquesplit.load_results(tmp_path / "st.nc").save(tmp_path / "again.nc")
    with xr.open_dataset(tmp_path / "st.nc") as a, xr.open_dataset(tmp_path / "again.nc") as b:
        assert set(a.data_vars) == set(b.data_vars)
        kept = {k for k in a.attrs if k.startswith("steady_") or k == "record"}
        assert kept and all(b.attrs[k] == a.attrs[k] or (a.attrs[k] != a.attrs[k] and
                                                        b.attrs[k] != b.attrs[k])  # NaN
                            for k in kept if k != "steady_json")
        np.testing.assert_array_equal(a["rms_transmission_error"], b["rms_transmission_error"])
    # (the same reviewer: the slower stage's cycle starts ran ten times past the record)
    starts = res.solution.cycle_start
    assert np.nanmax(starts) <= res.solution.t_final
    assert np.isnan(starts[:, -1]).sum() > 0.5 * starts.shape[0]  # (stage 2: 1/10 the cycles)


def test_a_campbell_summary_names_no_others_where_every_crossing_is_driven(tmp_path):
    """'21 of 21 driven by at least 1 % ...: the others only by what the model leaves
    out' named others there were none of (a first-hour reviewer)."""
    import re

    from typer.testing import CliRunner

    from torquesplit.cli import app

    model = write_tutorial_model(tmp_path)
    # (around the input-bearing crossing at 2632 rpm: every crossing there is driven)
    res = CliRunner().invoke(app, ["modes", str(model), "--campbell", "--from", "2600 rpm",
                                   "--to", "2650 rpm"], terminal_width=400)
    assert res.exit_code == 0, res.output
    title = " ".join(res.stdout.split())
    found = re.search(r"; (\d+) of (\d+) driven by at least", title)
    assert found and found.group(1) == found.group(2), title
    assert "the others only by" not in title


def test_a_crossing_whose_branch_forces_nearly_cancel_is_not_driven(tmp_path):
    """The tutorial's three branches mesh a third of a cycle apart: on the mode where the
    three shafts twist together (1142 Hz, 3425 rpm) their order-1 forces cancel but for
    branch 1's 15 um error (0.8 % of their sum).  With the exact-cancellation cut-off
    (1e-6) that error made it a driven crossing of a 35.5 % harmonic, a 'resonant' warning
    of run and a critical speed of the sweep, where the steady response rises smoothly."""

    import torquesplit
    from torquesplit.steady.maps import critical_speeds, driven

    model = write_tutorial_model(tmp_path)
    m = torquesplit.load_model(model)
    res = torquesplit.simulate(m, duration=1e-3)
    rpm = math.pi / 30
    crossings = critical_speeds(res.structure, res.static.q, res.kinematics, m,
                                3400 * rpm, 3450 * rpm, None)["crossings"]
    shaft = [c for c in crossings if c["order"] == 1 and "in1" in c.get("meshes", [])]
    assert shaft and all(0 < c["modal_force_share"] < 0.02 for c in shaft)
    assert all(c["force_harmonic"] > 0.3 and not driven(c) for c in shaft)
    bearing = [c for c in critical_speeds(res.structure, res.static.q, res.kinematics, m,
                                          2600 * rpm, 2650 * rpm, None)["crossings"]
               if c["order"] == 1 and "in1" in c.get("meshes", [])]
    assert bearing and all(driven(c) for c in bearing)


@pytest.mark.parametrize("method, initial", [("shooting", "abc"), ("shooting", [1, 2, 3]),
                                             ("hb", "abc"), ("hb", [1.0, 2.0])])
def test_a_starting_guess_of_the_wrong_kind_is_refused(method, initial):
    """A wrong-size guess was dropped without a word (shooting) or failed deep inside
    with a bare ValueError (harmonic balance)."""
    import torquesplit
    from torquesplit.errors import OptionError

    m = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    kw = {"harmonics": 4} if method == "hb" else {}
    with pytest.raises(OptionError, match=r"initial must be a state \[q, v\] of 28 values"):
        torquesplit.steady_state(m, method=method, initial=initial, stability=False, **kw)


@pytest.mark.parametrize("settle", [0, -1, 2.5])
def test_sweep_speed_refuses_a_settle_period_count_below_one(settle):
    import torquesplit
    from torquesplit.errors import OptionError

    m = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    with pytest.raises(OptionError, match="settle_periods must be a whole number >= 1"):
        torquesplit.sweep_speed(m, "700 rpm", "760 rpm", points=2, cross_check=True,
                                settle_periods=settle)


def test_steady_at_another_speed_says_the_loads_keep_their_torques(tmp_path):
    """steady --speed keeps the torques where run --set ...speed keeps the power: their
    forces differed by 14 % at 3425 rpm and neither said which it held."""

    from typer.testing import CliRunner

    from torquesplit.cli import app

    model = write_tutorial_model(tmp_path)
    res = CliRunner().invoke(app, ["steady", str(model), "--keep", "split", "--speed",
                                   "3100 rpm", "--no-stability"], terminal_width=300)
    assert res.exit_code == 0, res.output
    assert "the loads keep the model's torques" in " ".join(res.stderr.split())
