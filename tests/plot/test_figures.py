"""Report figures: written, labelled with units, and drawing the run's own numbers."""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys

import numpy as np
import pytest

import torquesplit
from torquesplit.plot import figures as F
from torquesplit.quasistatic import quasi_static_load_sharing
from torquesplit.results import Results
from torquesplit.solve.reference import excitation_numpy

from model_texts import split_model, write_model

UNIT = re.compile(r"\[[^\]]+\]$")  # "force [kN]", "coefficient [-]"
SPLIT_F = 1000.0  # mesh frequency of the split stage [Hz] (20 teeth at 3000 rpm)


def _model_text() -> str:
    """The two-path split with a floating, supported pinion, a time-varying stiffness on
    the split stage and a 3 um error on mesh a1 (so the paths do not share equally)."""
    text = split_model(error_a="3 um")
    text = text.replace(
        'position = ["0 mm", "0 mm", "0 mm"]\n',
        'position = ["0 mm", "0 mm", "0 mm"]\ndofs = ["x", "y", "theta"]\n\n'
        '[gears.pinion.support]\nstiffness = "2e8 N/m"\ndamping_ratio = 0.05\n', 1)
    text = text.replace(
        'stiffness = "4e8 N/m"\ndamping_ratio = 0.05\nstage = "split"',
        'stiffness = {method = "constant", value = "4e8 N/m", peak_to_peak = 0.3}\n'
        'damping_ratio = 0.05\nstage = "split"')
    assert "[gears.pinion.support]" in text and "peak_to_peak" in text
    return text


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    return torquesplit.load_model(write_model(tmp_path_factory.mktemp("plot"), _model_text()))


@pytest.fixture(scope="module")
def run(model):
    res = torquesplit.simulate(model, cycles=40, history_dofs=["pinion.x", "pinion.y"])
    assert res.success
    return res


@pytest.fixture(scope="module")
def static(model):
    return quasi_static_load_sharing(model)


def _with_history(res, column_values: dict[str, np.ndarray]) -> Results:
    """The same run with some element force histories replaced (by element name), and
    their per-cycle extremes with the replacement's (the figures draw both)."""
    s = res.solution
    forces = s.history_forces.copy()
    c_max, c_min = s.cycle_max.copy(), s.cycle_min.copy()
    el = res.structure.element_names
    names = [el[e] for e in s.history_elements]
    tracked = list(s.tracked_elements)
    for name, values in column_values.items():
        forces[:, names.index(name)] = values
        if el.index(name) in tracked:
            c = tracked.index(el.index(name))
            c_max[:, c] = np.where(np.isfinite(c_max[:, c]), np.max(values), np.nan)
            c_min[:, c] = np.where(np.isfinite(c_min[:, c]), np.min(values), np.nan)
    return Results(model=res.model, kinematics=res.kinematics, structure=res.structure,
                   static=res.static, solution=dataclasses.replace(
                       s, history_forces=forces, cycle_max=c_max, cycle_min=c_min))


def _panel(fig, title_start: str):
    return next(ax for ax in fig.axes if ax.get_title().startswith(title_start))


def _line(ax, label: str):
    return next(ln for ln in ax.get_lines() if ln.get_label() == label)


def _assert_labelled(fig, model_name: str):
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert visible
    for ax in visible:
        assert UNIT.search(ax.get_xlabel()), ax.get_xlabel()
        assert UNIT.search(ax.get_ylabel()), ax.get_ylabel()
        assert ax.get_title()
    assert fig.get_suptitle().startswith(model_name)


# ----------------------------------------------------------------------------- files
def test_write_figures_writes_every_applicable_figure(run, tmp_path):
    paths = F.write_figures(run, tmp_path / "out", formats=("png",), dpi=50,
                            definition="cycle_peak", prefix="case1_")
    names = sorted(p.name for p in paths)
    assert names == sorted(f"case1_{n}.png" for n in (
        "mesh_force", "mesh_force_end", "cycle_peak_force", "load_sharing_cycle_peak",
        "dynamic_factors", "support_force_spectrum", "orbits", "mesh_stiffness"))
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_write_static_figures_svg(static, tmp_path):
    paths = F.write_static_figures(static, tmp_path, formats="svg")
    assert sorted(p.name for p in paths) == [
        "mesh_stiffness.svg", "static_load_sharing.svg", "static_mesh_force.svg",
        "static_orbits.svg"]
    for p in paths:
        text = p.read_text(encoding="utf-8")
        assert "<svg" in text and "two-path split" in text


def test_writers_refuse_the_wrong_results_and_unknown_formats(run, static, tmp_path):
    with pytest.raises(TypeError, match="write_static_figures"):
        F.write_figures(static, tmp_path)
    with pytest.raises(TypeError, match="write_figures"):
        F.write_static_figures(run, tmp_path)
    with pytest.raises(ValueError, match="choose formats among"):
        F.write_figures(run, tmp_path, formats=("png", "docx"))
    assert not list(tmp_path.iterdir())  # nothing written before the check


def test_import_sets_no_backend_and_no_pyplot():
    code = ("import sys, logging; "
            "import torquesplit.plot.figures as f; "
            "print('matplotlib.pyplot' in sys.modules, "
            "bool(logging.getLogger('torquesplit.plot.figures').handlers))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "False"]


# ----------------------------------------------------------------------------- content
def test_every_axis_has_a_unit_and_the_model_is_named(run, static):
    name = run.model.model.name
    figs = [F.mesh_force_figure(run), F.mesh_force_figure(run, last_cycles=3),
            F.cycle_peak_figure(run), F.load_sharing_figure(run, "engineering"),
            F.dynamic_factor_figure(run),
            F.support_spectrum_figure(run), F.orbit_figure(run), F.mesh_stiffness_figure(run),
            F.static_mesh_force_figure(static), F.static_load_sharing_figure(static),
            F.orbit_figure(static)]
    for fig in figs:
        _assert_labelled(fig, name)
        assert fig.get_layout_engine() is not None  # laid out, nothing clipped


def test_mesh_force_lines_are_the_history(run):
    fig = F.mesh_force_figure(run, last_cycles=3)
    t, forces = run.mesh_force_history()
    assert len(fig.axes) == len(run.groups) == 2
    for g, members in run.groups.items():
        ax = _panel(fig, f"group {g}")
        assert ax.get_xlabel() == "time [ms]" and ax.get_ylabel() == "mesh force [kN]"
        f_mesh = run.structure.metadata["meshes"][members[0]]["frequency"]
        keep = t >= t[-1] - 3 / f_mesh
        for m in members:
            line = _line(ax, m)
            np.testing.assert_allclose(line.get_xdata(), t[keep] * 1e3, rtol=1e-12)
            np.testing.assert_allclose(line.get_ydata(),
                                       forces[keep, run.mesh_names.index(m)] / 1e3, rtol=1e-12)
        # each complete cycle's streamed extremes, dotted over the samples
        steps = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
        assert len(steps) == 2 * len(members)
        c_max = run.complete_cycle_statistics()[0]
        shown = {round(float(y), 9) for ln in steps for y in ln.get_ydata()}
        last = [run.mesh_names.index(m) for m in members]
        full = np.flatnonzero(np.isfinite(c_max[:, last[0]]))[-2]  # a cycle in the window
        assert round(float(c_max[full, last[0]] / 1e3), 9) in shown
        nominal = [ln for ln in ax.get_lines() if ln.get_label().startswith("nominal")]
        assert len(nominal) == 1 and nominal[0].get_linestyle() == "--"
        assert nominal[0].get_ydata()[0] == pytest.approx(run.nominal_forces()[members[0]] / 1e3)


def test_long_histories_keep_every_peak_and_trough(run):
    """The bands are the per-cycle extremes the integrator streams (every step and the
    tables' corners), not the decimated history's: a history of 20 samples per mesh
    period missed a resonant response's peaks by a third (a reviewer's model)."""
    fig = F.mesh_force_figure(run, band_above=5.0)  # 40-80 cycles per panel: bands
    t, forces = run.mesh_force_history()
    c_max, c_min = run.complete_cycle_statistics()[:2]
    for g, members in run.groups.items():
        ax = _panel(fig, f"group {g}")
        assert {f"{m} (largest and smallest of each cycle)" for m in members} <= {
            ln.get_label() for ln in ax.get_lines()}
        # overlapping bands are not filled (their blend matched no legend entry)
        assert not ax.collections or len(members) == 1
        edges = [ln for ln in ax.get_lines() if not ln.get_label().startswith("nominal")]
        assert len(edges) == 2 * len(members)
        cols = [run.mesh_names.index(m) for m in members]
        # complete cycles only: the last bin ends before the run
        f_mesh = run.structure.metadata["meshes"][members[0]]["frequency"]
        assert max(ln.get_xdata()[-1] for ln in edges) <= (t[-1] - 0.5 / f_mesh) * 1e3 + 1e-9
        top = max(ln.get_ydata().max() for ln in edges)
        bottom = min(ln.get_ydata().min() for ln in edges)
        assert top == pytest.approx(np.nanmax(c_max[:, cols]) / 1e3, rel=1e-12)
        assert bottom == pytest.approx(np.nanmin(c_min[:, cols]) / 1e3, rel=1e-12)
        body = t <= t[-1] - 1.0 / f_mesh
        assert top >= forces[body][:, cols].max() / 1e3 - 1e-12  # never below the history


def test_constant_force_gets_a_readable_window(run):
    t, forces = run.mesh_force_history()
    nominal = run.nominal_forces()  # the symmetric split without error: force = nominal
    flat = _with_history(run, {m: np.full(t.size, nominal[m]) for m in run.mesh_names})
    ax = _panel(F.mesh_force_figure(flat), "group split")
    lo, hi = ax.get_ylim()
    assert hi - lo == pytest.approx(0.04 * nominal["a1"] / 1e3, rel=0.3)  # +-2 %, not 1e-12


def test_cycle_peaks_against_cycle_start(run):
    fig = F.cycle_peak_figure(run)
    s = run.solution
    settling = run.metrics().settling
    assert len(set(settling.group_time.values())) > 1  # the groups settle apart
    # and the run's table says each group's (it printed only the latest)
    said = run.metrics().settle_times_text()
    assert all(f"{g} {t:.4g} s" in said for g, t in settling.group_time.items()), said
    for g, members in run.groups.items():
        ax = _panel(fig, f"group {g}")
        assert ax.get_xlabel() == "cycle start time [ms]"
        for m in members:
            j = run.mesh_names.index(m)
            # the cycle cut off by the end of the run is not drawn (its peak is that of
            # part of a cycle: it would show as a drop)
            ok = np.isfinite(s.cycle_max[:, j]) & run.complete_cycles[:, j]
            last = np.flatnonzero(np.isfinite(s.cycle_max[:, j]))[-1]
            assert not run.complete_cycles[last, j]  # there is a cut-off cycle to leave out
            line = _line(ax, m)
            np.testing.assert_allclose(line.get_xdata(), s.cycle_start[ok, j] * 1e3)
            np.testing.assert_allclose(line.get_ydata(), s.cycle_max[ok, j] / 1e3)
        marker = next(ln for ln in ax.get_lines() if ln.get_label().startswith("settled"))
        # the group's own settle time (its metrics start there), not the latest
        assert marker.get_xdata()[0] == pytest.approx(settling.group_time[g] * 1e3)


@pytest.mark.parametrize("definition", ["cycle_peak", "instantaneous", "mean_force"])
def test_load_sharing_lines_reproduce_the_reported_coefficient(run, definition):
    met = run.metrics(definition)
    fig = F.load_sharing_figure(run, definition)
    assert definition in fig.get_suptitle()
    for g, members in run.groups.items():
        settle_ms = met.settling.group_time[g] * 1e3
        ax = _panel(fig, f"group {g}")
        lines = [_line(ax, m) for m in members]
        # the coefficients of a group sum to its number of meshes in every cycle (a cycle
        # without samples, the last one cut by the end of the run, is NaN)
        if definition != "instantaneous":  # per-mesh cycle peaks need not coincide
            total = sum(ln.get_ydata() for ln in lines)
            total = total[np.isfinite(total)]
            assert total.size > 10
            np.testing.assert_allclose(total, len(members), rtol=1e-9)
        reported = next(ln for ln in ax.get_lines() if ln.get_label().startswith("reported"))
        assert reported.get_ydata()[0] == pytest.approx(met.load_sharing.per_group[g])
        if definition in ("cycle_peak", "instantaneous"):  # reported = largest settled
            for m, ln in zip(members, lines):
                settled = ln.get_xdata() >= settle_ms
                assert np.nanmax(ln.get_ydata()[settled]) == pytest.approx(
                    met.load_sharing.per_mesh[m], rel=1e-6)
    # the 3 um error on a1 moves load to b1
    split = _panel(fig, "group split")
    assert np.nanmean(_line(split, "b1").get_ydata()) > 1.0 > np.nanmean(
        _line(split, "a1").get_ydata())


def test_single_mesh_groups_have_no_coefficient_figure(run):
    meta = {m: dict(v, stage=m) for m, v in run.structure.metadata["meshes"].items()}
    lonely = Results(model=run.model, kinematics=run.kinematics, static=run.static,
                     solution=run.solution,
                     structure=dataclasses.replace(
                         run.structure, metadata=dict(run.structure.metadata, meshes=meta)))
    with pytest.raises(F.FigureNotApplicableError, match="same 'stage'"):
        F.load_sharing_figure(lonely)


def test_support_spectrum_finds_a_known_sinusoid(run):
    t = run.solution.history_t
    f0 = 2.0 * SPLIT_F  # second mesh order of the split stage
    fake = _with_history(run, {"pinion.support.x": 500.0 + 123.0 * np.sin(2 * np.pi * f0 * t),
                               "pinion.support.y": np.full(t.size, -40.0)})
    fig = F.support_spectrum_figure(fake, start_time=0.0, log=False)
    ax = _panel(fig, "support of pinion")
    assert ax.get_xlabel() == "frequency [Hz]" and ax.get_ylabel() == "force amplitude [N]"
    x = next(ln for ln in ax.get_lines() if ln.get_gid() == "pinion.support.x")
    freq, amp = x.get_xdata(), x.get_ydata()
    k = int(np.argmax(amp))
    # the record is trimmed to whole periods of the slowest mesh (500 Hz): every mesh
    # order lies on a frequency bin, so the Hann-windowed amplitude is the true one
    periods = 500.0 / (freq[1] - freq[0])
    assert periods == pytest.approx(round(periods), abs=1e-6) and periods >= 39
    assert freq[k] == pytest.approx(f0, rel=1e-9)
    assert amp[k] == pytest.approx(123.0, rel=1e-3)
    legend = next(ln for ln in ax.get_lines() if ln.get_label().startswith("x:"))
    # in N below 1 kN, as the axis reads ('0.123 kN' beside an axis at 123 N read as a
    # mismatch), in kN and MN above, as the run's tables print forces
    label = legend.get_label()
    assert "mean 500 N" in label and "largest 123 N at 2 kHz" in label
    assert [F._force_text(v) for v in (-0.1078, 3300.0, 2.5e6, 999.96, 999960.0,
                                       float("nan"))] == [
        "-0.1078 N", "3.3 kN", "2.5 MN", "1 kN", "1 MN", "nan N"]
    np.testing.assert_allclose(legend.get_xydata(), [[f0, amp[k]]])  # the one strong line
    y = next(ln for ln in ax.get_lines() if ln.get_gid() == "pinion.support.y")
    assert np.max(y.get_ydata()) < 1e-9  # a constant force has no spectrum
    # a slow drift (an unsettled run) leaks into the lowest bins: the largest *line* named
    # is still the mesh order, not the first bin
    span = t[-1] - t[0]
    drift = _with_history(run, {"pinion.support.x": 500.0 + 400.0 * (t - t[0]) / span
                                + 123.0 * np.sin(2 * np.pi * f0 * t),
                                "pinion.support.y": np.full(t.size, -40.0)})
    ax = _panel(F.support_spectrum_figure(drift, start_time=0.0, log=False),
                "support of pinion")
    legend = next(ln for ln in ax.get_lines() if ln.get_label().startswith("x:"))
    assert "at 2 kHz" in legend.get_label(), legend.get_label()
    # mesh orders marked: 500 Hz (combine) and 1 kHz (split) and their harmonics, over
    # the band of the content only (the 2 kHz line, a quarter above it: 2.5 kHz)
    marks = {round(ln.get_xdata()[0], 6) for ln in ax.get_lines() if ln.get_linestyle() == ":"}
    assert marks == {500.0, 1000.0, 1500.0, 2000.0}
    assert ax.get_xlim()[1] == pytest.approx(2500.0, rel=0.02)  # (+ the Hann window's spread)


def test_support_spectrum_panels_share_one_amplitude_axis(tmp_path):
    """Two bearings, one ten times stronger: one axis for both by default (so they can be
    compared), each its own with common_scale=False."""
    text = _model_text()
    out_block = text.index("[gears.out]")
    end = text.index("\n\n", out_block)
    text = (text[:end] + '\ndofs = ["x", "y", "theta"]\n\n[gears.out.support]\n'
            'stiffness = "5e8 N/m"\ndamping_ratio = 0.05' + text[end:])
    res = torquesplit.simulate(torquesplit.load_model(write_model(tmp_path, text)), cycles=20)
    t = res.solution.history_t
    f0 = 2.0 * SPLIT_F
    fake = _with_history(res, {"pinion.support.x": 1000.0 * np.sin(2 * np.pi * f0 * t),
                               "out.support.x": 100.0 * np.sin(2 * np.pi * f0 * t)})
    for common in (True, False):
        fig = F.support_spectrum_figure(fake, start_time=0.0, log=True, common_scale=common)
        tops = [_panel(fig, f"support of {b}").get_ylim()[1] for b in ("pinion", "out")]
        if common:
            assert tops[0] == tops[1]
        else:
            assert tops[0] == pytest.approx(10.0 * tops[1], rel=0.05)


def test_support_spectrum_without_supports_explains(run):
    with pytest.raises(F.FigureNotApplicableError, match="choose among pinion"):
        F.support_spectrum_figure(run, bodies=["out"])


def test_orbit_in_micrometres_with_equal_aspect(run, static):
    fig = F.orbit_figure(run)
    ax = _panel(fig, "pinion")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [µm]", "y [µm]")
    assert ax.get_aspect() == 1.0
    np.testing.assert_allclose(ax.get_lines()[0].get_xydata(),
                               run.solution.history_q * 1e6, rtol=1e-12)
    orbit = static.orbits()["pinion"] * 1e6
    ax = _panel(F.orbit_figure(static), "pinion")
    np.testing.assert_allclose(ax.get_lines()[0].get_xydata(), orbit, rtol=1e-12)


def test_mesh_stiffness_is_the_assembled_table(run):
    fig = F.mesh_stiffness_figure(run, cycles=2)
    st = run.structure
    ax = _panel(fig, "group split")
    assert ax.get_ylabel() == "mesh stiffness [N/µm]"
    for m in ("a1", "b1"):
        e = st.element_names.index(m)
        table = st.stiffness_table[e]
        assert table.max() / table.min() > 1.2  # peak_to_peak 0.3: a real waveform
        line = next(ln for ln in ax.get_lines() if ln.get_label().startswith(m))
        x, y = line.get_xdata(), line.get_ydata()
        assert x[0] == 0.0 and x[-1] == 2.0
        # k(t) as the integrator's reference twin evaluates it, at t = x / f_mesh
        expected = [excitation_numpy(st, xi / st.frequency[e]).stiffness[e] / 1e6
                    for xi in x[::7]]
        np.testing.assert_allclose(y[::7], expected, rtol=1e-9)


def test_static_figures_follow_rotation_and_report(static):
    names = static.mesh_names
    forces = static.mesh_forces()
    fig = F.static_mesh_force_figure(static)
    ax = _panel(fig, "group split")
    assert ax.get_xlabel() == "rotation of out [deg]"
    line = _line(ax, "a1")
    assert line.get_xdata()[0] == 0.0 and 300.0 < line.get_xdata()[-1] <= 360.0
    np.testing.assert_allclose(line.get_ydata(), forces[:, names.index("a1")] / 1e3)
    # positions without a converged equilibrium are left out, and the title says so
    conv = static.solution.converged.copy()
    conv[5] = False
    broken = dataclasses.replace(static, solution=dataclasses.replace(static.solution,
                                                                      converged=conv))
    fig = F.static_mesh_force_figure(broken)
    y = _line(_panel(fig, "group split"), "a1").get_ydata()
    assert np.isnan(y[5]) and np.isfinite(np.delete(y, 5)).all()
    assert "1 unconverged positions left out" in fig.get_suptitle()
    met = static.metrics()
    fig = F.static_load_sharing_figure(static)
    for g, members in met.groups.items():
        ax = _panel(fig, f"group {g}")
        for m in members:
            assert _line(ax, m).get_ydata().max() == pytest.approx(met.per_mesh[m], rel=1e-9)


def test_static_figures_over_many_revolutions_show_one_and_the_range(model):
    """Mo et al. 2017's 25 revolutions of quasi-static sharing were a solid block of
    lines.  Over more than two revolutions the figure draws the revolution that holds
    the largest value (its line peaks at the reported value) and, as a band, the range of
    every revolution at each angle (every position inside it)."""
    static = quasi_static_load_sharing(model, revolutions=4)
    met = static.metrics()
    angle = F._positions(static)[0]
    fig = F.static_load_sharing_figure(static)
    assert "range of every revolution" in fig.get_suptitle()
    for g, members in met.groups.items():
        ax = _panel(fig, f"group {g}")
        assert "in revolution" in ax.get_xlabel() and ax.get_xlim() == (0.0, 360.0)
        tops = [_line(ax, m).get_ydata().max() for m in members]
        assert max(tops) == pytest.approx(met.per_group[g], rel=1e-12)
        for m in members:
            x = _line(ax, m).get_xdata()
            assert 0.0 <= x.min() and x.max() < 360.0 and x.size < angle.size / 3
        bands = [c.get_paths()[0].vertices[:, 1] for c in ax.collections]
        assert len(bands) == len(members)
        for band, m in zip(bands, members):
            y = met.per_cycle[m]
            assert band.min() == pytest.approx(np.nanmin(y)) and \
                band.max() == pytest.approx(np.nanmax(y))
    one = F.static_mesh_force_figure(quasi_static_load_sharing(model))
    assert "revolution" not in one.get_suptitle()


def test_dynamic_factor_bars_are_the_metrics(run):
    met = run.metrics("cycle_peak")
    fig = F.dynamic_factor_figure(run, "cycle_peak")
    ax = fig.axes[0]
    bars = [p.get_height() for p in ax.patches]
    order = [r for g in met.load_sharing.groups for r in met.rows if r.group == g]
    n = len(order)
    np.testing.assert_allclose(bars[:n], [r.dynamic_factor for r in order], rtol=1e-12)
    np.testing.assert_allclose(bars[n:2 * n], [r.peak_to_nominal for r in order], rtol=1e-12)


def test_a_figure_of_many_cycles_draws_bands_in_every_panel(run):
    """80 cycles of a waveform made a solid block of colour, and one panel drew
    waveforms while the other drew bands."""
    fig = F.mesh_force_figure(run)  # the default: bands above 30 cycles in any panel
    for g, members in run.groups.items():
        ax = _panel(fig, f"group {g}")
        labels = {ln.get_label() for ln in ax.get_lines()}
        assert all(f"{m} (largest and smallest of each cycle)" in labels for m in members)


def test_a_tooth_pairs_load_is_one_continuous_curve_over_the_cycles():
    """Pairs were numbered by the LTCA's column, which passes to the next pair each mesh
    cycle: every curve jumped at phase 1 (15.2 -> 0 kN on a reviewer's helical pair)."""
    from torquesplit.plot.contact import _pair_tracks

    phase = np.arange(4) / 4.0
    life = np.arange(8) / 4.0  # a pair's load over its two cycles in contact
    loads = np.stack([life[:4], life[4:]], axis=1)  # column 0: its first cycle, 1: second
    tracks = _pair_tracks(phase, loads)
    whole = [v for ph, v in tracks if np.allclose(v[:8], life)]
    assert len(whole) == 1  # one curve follows the pair through both cycles


def test_a_held_ring_and_rounding_are_not_what_a_planetary_figure_shows():
    """A planetary's quasi-static figures drew every position at 0 deg (the x axis was
    the held ring's rotation in the housing), its equal mesh forces as 0.25 mN of
    rounding over the whole panel, and its held members' orbits as 1e-14 um with offset
    tick labels.  The axis is the sweep's own: the ring turning relative to the carrier,
    one revolution per 360 deg."""
    import torquesplit

    res = torquesplit.quasi_static_load_sharing(
        torquesplit.load_model("lin_parker1999_planetary"), revolutions=0.2,
        points_per_cycle=4)
    ax = F.static_mesh_force_figure(res).axes[0]
    assert ax.get_xlabel() == "rotation of stage_ring relative to stage_carrier [deg]"
    x = ax.get_lines()[0].get_xdata()
    assert np.ptp(x) == pytest.approx(0.2 * 360, rel=0.02)  # revolutions=0.2
    lo, hi = ax.get_ylim()
    force = ax.get_lines()[0].get_ydata().mean()
    assert hi - lo >= F.LEAST_SPAN * force * (1 - 1e-9)
    titles = [a.get_title() for a in F.orbit_figure(res).axes if a.get_visible()]
    held = [t for t in titles if "no motion" in t]
    assert {t.split("\n")[0] for t in held} == {"stage_sun", "stage_ring", "stage_carrier"}


def test_a_spectrum_of_numerical_noise_is_said_and_a_decimated_one_warns_of_folding():
    """A planetary's bearing forces of 1 kN had 1e-4 N of numerical noise drawn on a log
    axis as a spectrum; a history of a few samples per period folded a 708 Hz harmonic
    to 472 Hz with no note."""
    import torquesplit

    planets = torquesplit.simulate("lin_parker1999_planetary", cycles=60)
    fig = F.support_spectrum_figure(planets)
    assert all("no dynamic content" in " ".join(t.get_text() for t in ax.texts)
               for ax in fig.axes if ax.get_visible())
    # and its legend gives no 1e-14 N 'mean' and 'largest' of that noise
    labels = [ln.get_label() for ax in fig.axes if ax.get_visible() for ln in ax.lines]
    assert any("rounding noise only" in lab for lab in labels), labels
    assert not any("mean " in lab for lab in labels), labels
    assert "folds back" not in fig.get_suptitle()  # every step kept: nothing folds
    coarse = torquesplit.simulate("ji_li_mill_drive", cycles=60, samples_per_period=5)
    text = F.support_spectrum_figure(coarse).get_suptitle()
    assert "from a history of 5 samples per shortest mesh period: content above" in text


def test_dynamic_factor_bars_carry_their_values(run):
    """From an axis at 0, factors of 1.076 and 1.105 looked the same."""
    ax = F.dynamic_factor_figure(run).axes[0]
    met = run.metrics()
    texts = [t.get_text() for t in ax.texts]
    for r in met.rows:
        assert f"{r.dynamic_factor:.3f}" in texts and f"{r.peak_to_nominal:.3f}" in texts
    # a resonance line in the legend is on the axis too (it named a line above the axis
    # at dynamic factors near 2, a first-hour reviewer)
    top = max(max(r.dynamic_factor, r.peak_to_nominal) for r in met.rows)
    ax = F.dynamic_factor_figure(run, resonance=top / 0.7).axes[0]
    labels = [h.get_label() for h in ax.get_legend().legend_handles]
    assert any("reported as near a resonance" in lab for lab in labels), labels
    assert ax.get_ylim()[1] > top / 0.7


def test_figures_of_a_run_that_did_not_settle_say_so():
    """Dong et al. 2021 at 50 cycles warned that it had not settled; its load-sharing and
    dynamic-factor figures showed 'reported 1.3457' with no such note."""
    import torquesplit

    res = torquesplit.simulate("ji_li_mill_drive", cycles=12)
    met = res.metrics()
    assert not met.settling.settled  # (the premise: too short to tell)
    for fig in (F.load_sharing_figure(res), F.dynamic_factor_figure(res)):
        assert "had not settled by its end" in fig.get_suptitle()
    settled = torquesplit.simulate("ji_li_mill_drive", cycles=120)
    assert settled.metrics().settling.settled
    assert "had not settled" not in F.dynamic_factor_figure(settled).get_suptitle()
