"""A QA review of the Python API's bad input: each refusal is a torquesplit error naming
what to give (pydantic's text, a ValueError of dict(), pathlib's TypeError, h5py's
FileNotFoundError and an accepted rtol=2 before)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import torquesplit
from torquesplit.errors import ModelError, OptionError, OptionTypeError, OutputError
from torquesplit.model.schema import Model

EXAMPLE = "ji_li_mill_drive"


def test_a_model_built_in_python_names_its_bad_fields():
    data = dict(model={"name": "x"}, gears={"a": {"teeth": -1}}, drives={}, loads={})
    for build in (lambda: Model(**data), lambda: Model.model_validate(data)):
        with pytest.raises(ModelError) as exc:
            build()
        said = str(exc.value)
        assert "gears.a.teeth: must be greater than 0, got -1; give a positive value" in said
        assert "pydantic" not in said


def test_changes_are_a_mapping_of_paths_or_set_texts():
    m = torquesplit.load_model(EXAMPLE, changes="meshes.m11.damping_ratio=0.08")
    assert m.meshes["m11"].damping_ratio == 0.08
    m = torquesplit.load_model(EXAMPLE, changes=["meshes.m11.damping_ratio=0.09"])
    assert m.meshes["m11"].damping_ratio == 0.09
    for bad in ({5: 1}, 3):
        with pytest.raises(OptionTypeError, match="changes must map field paths to values"):
            torquesplit.load_model(EXAMPLE, changes=bad)
        with pytest.raises(OptionTypeError, match="changes must map field paths to values"):
            m.with_changes(bad)


@pytest.mark.parametrize("call, pattern", [
    (lambda: torquesplit.load_model(None), "load_model takes a model file's path"),
    (lambda: torquesplit.run_study(None), "a study is a study file's path"),
])
def test_nothing_given_is_said_as_such(call, pattern):
    with pytest.raises(OptionTypeError, match=pattern):
        call()


def test_a_model_text_given_for_a_path_is_told_how_to_pass_it():
    from tests.model_texts import SPUR_PAIR, split_model

    for text in (SPUR_PAIR, split_model()):  # (a long one: 'File name too long' from the OS)
        with pytest.raises(OptionTypeError, match=r"got a text of \d+ characters .* "
                           r"pass tomllib\.loads\(text\)"):
            torquesplit.load_model(text)


def test_paths_that_are_not_there_or_not_folders(tmp_path):
    with pytest.raises(OutputError, match=r"nope\.nc: no such file; give the \.nc file"):
        torquesplit.load_results(tmp_path / "nope.nc")
    # and what Python code that reads a file catches (an exports review)
    with pytest.raises(FileNotFoundError, match="no such file"):
        torquesplit.load_results(tmp_path / "nope.nc")
    with pytest.raises(OutputError, match=r"no such file \(nor the folder"):
        torquesplit.load_results(tmp_path / "gone" / "nope.nc")
    res = torquesplit.simulate(EXAMPLE, cycles=3)
    model_file = tmp_path / "m.toml"
    model_file.write_text("x")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        res.write_figures(model_file)


def test_tolerances_out_of_range_are_refused():
    with pytest.raises(OptionError, match=r"rtol must be a number between 0 and 1"):
        torquesplit.simulate(EXAMPLE, method="dopri", rtol=2, cycles=2)
    from torquesplit.modes import model_modes

    with pytest.raises(OptionError, match=r"rtol must be a relative difference"):
        model_modes(EXAMPLE, rtol=math.nan)


def test_a_dopri_run_that_diverges_names_its_tolerance(tmp_path):
    """--method dopri with rtol = 0.9 diverged with advice about stiffness signs only."""
    from model_texts import SPUR_PAIR, write_model

    path = write_model(tmp_path, SPUR_PAIR.replace('damping_ratio = 0.05',
                                                   'damping_ratio = 0.05\nbacklash = "100 um"'))
    res = torquesplit.simulate(path, method="dopri", rtol=0.9, cycles=50)
    assert not res.success
    assert "diverged" in res.message and "Tighten rtol" in res.message, res.message


def test_changes_as_pairs_and_a_model_from_json_text():
    """(path, value) pairs went through dict() before: still taken.  A JSON text of a
    model is refused in torquesplit's words too."""
    m = torquesplit.load_model(EXAMPLE, changes=[("meshes.m11.damping_ratio", 0.07)])
    assert m.meshes["m11"].damping_ratio == 0.07
    with pytest.raises(ModelError, match=r"gears\.a\.teeth: must be greater than 0"):
        Model.model_validate_json('{"model": {"name": "x"}, "gears": {"a": {"teeth": -1}}, '
                                  '"drives": {}, "loads": {}}')


def test_a_researchers_session():
    """A Python user's review: a bearing start time past the run's end took the whole
    history (start-up included) silently; the Dataset's forces could not be scaled in
    place; a quasi-static sweep's metrics('static_torque') was a TypeError; run_study
    could not shorten a shipped study."""
    import numpy as np

    res = torquesplit.simulate(EXAMPLE, cycles=30)
    end = float(res.solution.history_t[-1])
    for bad in (end + 1.0, float("nan")):
        with pytest.raises(OptionError, match="leaves no sample of the history"):
            res.bearing_forces(start_time=bad)
    ds = res.to_dataset()
    ds["element_force"] /= 1e3  # a copy: the run's own arrays stay read-only
    assert not res.solution.history_forces.flags.writeable
    t, _ = res.mesh_force_history()
    t += 1.0  # (a copy: the run's history is not moved)
    assert res.mesh_force_history()[0][0] == res.solution.history_t[0] == t[0] - 1.0
    from torquesplit.quasistatic import quasi_static_load_sharing

    qs = quasi_static_load_sharing(torquesplit.load_model("mo2017_star_reducer"),
                                   points_per_cycle=4, max_points=64)
    assert np.isfinite(qs.metrics("static_torque").system)
    with pytest.raises(OptionError, match="'static_torque' load sharing only"):
        qs.metrics("engineering")
    import inspect

    assert "analysis" in inspect.signature(torquesplit.run_study).parameters


def test_an_unknown_example_and_history_dofs_of_the_wrong_kind_are_torquesplit_errors():
    """example_path('nope') raised a bare FileNotFoundError and history_dofs=5 'int object
    is not iterable' (a fuzzer)."""
    from torquesplit.errors import NoSuchExampleError, TorquesplitError

    with pytest.raises(NoSuchExampleError, match="no example named 'nope'; use one of"):
        torquesplit.example_path("nope")
    assert issubclass(NoSuchExampleError, FileNotFoundError)  # (as it was)
    with pytest.raises(OptionTypeError, match="history_dofs must be DOF names"):
        torquesplit.simulate(EXAMPLE, cycles=5, history_dofs=5)
    with pytest.raises(TorquesplitError):
        torquesplit.simulate(EXAMPLE, cycles=5, history_dofs=[1, 2])


def test_empty_change_paths_python_wording_and_table_points_of_assemble():
    """with_changes({'': 3}) said 'unknown field' of none, changes=['x'] spoke of --set,
    assemble(n_table=0) was taken (a fuzzer)."""
    m = torquesplit.load_model(EXAMPLE)
    for path in ("", "meshes..damping_ratio"):
        with pytest.raises(ModelError, match="an empty field path, or an empty part"):
            m.with_changes({path: 3})
    with pytest.raises(OptionTypeError, match="changes: 'x' is not 'PATH=VALUE'") as exc:
        torquesplit.load_model(EXAMPLE, changes=["x"])
    assert "--set" not in str(exc.value)
    with pytest.raises(OptionError, match="n_table must be a whole number of table points"):
        torquesplit.assemble(m, n_table=0)
    assert torquesplit.assemble(m, n_table=16).n_table == 16


def test_a_frozen_model_says_how_to_change_it_and_reprs_say_what_a_user_asked():
    """Setting a field raised pydantic's 'Instance is frozen' ValidationError (not a
    torquesplit error); a steady state's repr gave a speed factor, not the 700 rpm asked;
    Metrics printed 1.0000286 as 'stage2 1' (a notebook user)."""
    m = torquesplit.load_model(EXAMPLE)
    with pytest.raises(OptionTypeError, match=r"a model is frozen: Gear\.teeth cannot be set; "
                                              r"make a changed copy with model\.with_changes"):
        m.gears["z1"].teeth = 41
    assert m.gears["z1"].teeth != 41
    from torquesplit.steady.api import steady_state

    ss = steady_state(m, keep="stage1", speed="700 rpm", stability=False, check=False)
    assert "at 700 rpm (speed factor 0.9395" in repr(ss)
    res = torquesplit.simulate(EXAMPLE, cycles=30)
    text = repr(res.metrics())
    assert "stage2 1.0000" in text or "stage2 1.000" in text, text


def test_a_mistyped_example_name_is_told_the_example_in_python():
    """The command line suggested it; load_model said 'no such file' (a notebook user)."""
    with pytest.raises(ModelError, match=r"no such file or example; did you mean "
                                         r"'ji_li_mill_drive'\?"):
        torquesplit.load_model("ji_li_mil_drive")


def test_modes_steady_states_and_static_sweeps_save_as_their_commands_do(tmp_path):
    """A notebook user found no save for ModalReport or SteadyState (the commands' --out)
    and no write_figures for a quasi-static sweep (static --plots)."""
    import xarray as xr

    from torquesplit.steady.api import steady_state

    m = torquesplit.load_model(EXAMPLE)
    rep = torquesplit.model_modes(m)
    path = rep.save(tmp_path / "modes.nc")
    ds = xr.load_dataset(path)
    assert ds["frequency"].values.tolist() == [r.frequency for r in rep.rows]
    with pytest.raises(OutputError, match="exists"):
        rep.save(tmp_path / "modes.nc")
    st = steady_state(m, keep="stage1", speed="700 rpm", stability=False, check=False)
    saved = torquesplit.load_results(st.save(tmp_path / "steady.nc"))
    assert saved.saved_steady and saved.metrics().load_sharing.system == pytest.approx(
        st.to_results().metrics().load_sharing.system, rel=1e-12)
    qs = torquesplit.quasi_static_load_sharing(m, points_per_cycle=8, revolutions=1)
    figures = qs.write_figures(tmp_path / "figs", formats=("png",))
    assert figures and all(f.exists() and f.suffix == ".png" for f in figures)


@pytest.fixture(scope="module")
def short_run():
    return torquesplit.simulate(EXAMPLE, cycles=20)


@pytest.mark.parametrize("call, error, pattern", [
    (lambda r: torquesplit.plot.mesh_force_figure("run.nc"), OptionTypeError,
     r"^mesh_force_figure takes the Results of a dynamic run \(torquesplit\.simulate\), "
     r"got str 'run\.nc'$"),
    (lambda r: torquesplit.plot.static_load_sharing_figure(r), OptionTypeError,
     r"^static_load_sharing_figure takes the results of "
     r"torquesplit\.quasi_static_load_sharing, got Results"),
    (lambda r: torquesplit.plot.orbit_figure(None), OptionTypeError,
     r"takes the Results of a dynamic run .* or the results of torquesplit\.quasi_static"),
    (lambda r: torquesplit.plot.mesh_force_figure(r, last_cycles=-1), OptionError,
     r"^last_cycles must be a positive number, got -1; give e\.g\. last_cycles=20$"),
    (lambda r: torquesplit.plot.mesh_force_figure(r, bins=0), OptionError,
     r"^bins must be a whole number >= 1, got 0"),
    (lambda r: torquesplit.plot.cycle_peak_figure(r, dense_above=2.5), OptionError,
     r"^dense_above must be a whole number >= 1, got 2\.5"),
    (lambda r: torquesplit.plot.load_sharing_figure(r, zoom_cycles=0), OptionError,
     r"^zoom_cycles must be"),
    (lambda r: torquesplit.plot.support_spectrum_figure(r, orders=-1), OptionError,
     r"^orders must be a whole number >= 0, got -1"),
    (lambda r: torquesplit.plot.support_spectrum_figure(r, dynamic_range=0), OptionError,
     r"^dynamic_range must be a positive number, got 0"),
    (lambda r: torquesplit.plot.mesh_stiffness_figure(r, points_per_cycle=1), OptionError,
     r"^points_per_cycle must be a whole number >= 2, got 1"),
    (lambda r: torquesplit.plot.mesh_stiffness_figure(r, cycles=math.inf), OptionError,
     r"^cycles must be a positive number, got inf"),
    (lambda r: r.settle_windows(0), OptionError,
     r"^minimum must be a whole number >= 2, got 0; give e\.g\. minimum=20$"),
    # (a Python API reviewer: an AttributeError, a TypeError and a ValueError from inside
    # the figures, and a group typo that gave the overall start without a word)
    (lambda r: torquesplit.plot.write_figures(r.model, "never"), OptionTypeError,
     r"^write_figures takes the Results of a dynamic run"),
    (lambda r: torquesplit.plot.dynamic_factor_figure(r, resonance="abc"), OptionError,
     r"^resonance must be a positive number, got 'abc'"),
    (lambda r: torquesplit.plot.support_spectrum_figure(r, start_time="abc"), OptionError,
     r"^start_time must be a finite number, got 'abc'; give e\.g\. start_time=0\.5"),
    (lambda r: r.history_start(group="bogus"), OptionError,
     r"^no load-sharing group 'bogus'; the groups are stage1, stage2$"),
])
def test_figures_and_results_refuse_what_they_cannot_draw_or_count(short_run, call, error,
                                                                   pattern):
    """A string, another kind of results or a count of 0 ended in an AttributeError from
    inside the figure, or was accepted (last_cycles=-1 drew the whole run)."""
    import torquesplit.plot  # noqa: F401

    with pytest.raises(error, match=pattern):
        call(short_run)


def test_campbell_and_steady_samples_refuse_counts_below_their_minimum():
    """count=0 sliced every frequency away, count=-1 dropped the highest silently."""
    from torquesplit.steady import campbell

    for count in (0, -1, 2.5):
        with pytest.raises(OptionError, match=r"^count must be a whole number >= 1"):
            campbell(torquesplit.load_model(EXAMPLE), "0 rpm", "3000 rpm", count=count)
    with pytest.raises(OptionError, match=r"^points must be a whole number >= 2, got 1"):
        campbell(torquesplit.load_model(EXAMPLE), "0 rpm", "3000 rpm", points=1)
    st = torquesplit.steady_state(EXAMPLE, keep="stage1", harmonics=4)
    for kw, pattern in (({"per_cycle": -1}, r"^per_cycle must be a whole number >= 2"),
                        ({"n": 0}, r"^n must be a whole number >= 2, got 0")):
        with pytest.raises(OptionError, match=pattern):
            st.samples(**kw)
    assert len(st.samples(n=8)[0]) == 8


def test_a_folder_that_exists_but_takes_no_files_is_said_so():
    """/proc: 'the folder /proc is not writable (No such file or directory)', of a folder
    that is there (an exports review)."""
    from torquesplit.results.files import check_writable_folder

    if not Path("/proc").is_dir():
        pytest.skip("no /proc on this system")
    with pytest.raises(OutputError) as err:
        check_writable_folder("/proc", "/proc/x.nc")
    assert "No such file" not in str(err.value)
    assert "/proc is not writable" in str(err.value)


def test_a_file_of_another_kind_is_named_in_the_refusal(tmp_path):
    """'report s.nc' of a quasi-static file said 'not a torquesplit results file of a
    dynamic run' without the file's name (an exports review)."""
    model = torquesplit.load_model(EXAMPLE)
    static = torquesplit.quasi_static_load_sharing(model, revolutions=0.01).save(
        tmp_path / "static.nc")
    with pytest.raises(ValueError, match=r"static\.nc: not a torquesplit results file"):
        torquesplit.load_results(static)


def test_writing_figures_prints_no_font_lookup(caplog):
    """A font cache without the STIX fonts made every math label print 'findfont: Font
    family ['STIXGeneral'] not found' on the report's stderr (a reviewer)."""
    import logging
    import secrets

    import matplotlib
    from matplotlib.figure import Figure

    from torquesplit.plot.figures import figure_svg

    missing = f"NoSuchFont{secrets.token_hex(4)}"  # (findfont caches what it found)
    lookup = logging.getLogger("matplotlib.font_manager")
    with caplog.at_level(logging.WARNING, logger="matplotlib.font_manager"), \
            matplotlib.rc_context({"font.family": [missing]}):
        fig = Figure()
        fig.suptitle(r"$K_\gamma$ of the sun")
        svg = figure_svg(fig, "t")
        assert not [r for r in caplog.records if r.name == "matplotlib.font_manager"]
        from matplotlib.font_manager import FontProperties, findfont

        findfont(FontProperties(family=[missing + "b"]))  # (said outside a save)
    assert [r for r in caplog.records if r.name == "matplotlib.font_manager"]
    assert "<svg" in svg and lookup.level == logging.NOTSET


def test_a_run_too_short_to_settle_is_said_in_python():
    """The command line printed 'the run is too short to tell whether the response has
    settled'; ``simulate`` in Python said nothing (only ``res.warnings()`` had it), and
    the metrics of a few cycles of a start-up read as any others."""
    from torquesplit.errors import ModelWarning

    with pytest.warns(ModelWarning, match="too short to tell whether the response has "
                                          "settled") as said:
        res = torquesplit.simulate(EXAMPLE, cycles=3)
    text = [str(w.message) for w in said if "too short" in str(w.message)]
    assert len(text) == 1 and text[0] in res.warnings()
    assert sum("too short" in w for w in res.warnings()) == 1  # (said once there)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        long = torquesplit.simulate(EXAMPLE, cycles=60)  # (settled: nothing said)
    assert long.metrics().settling.settled


def test_run_study_takes_what_study_run_takes_by_name():
    """``run_study(spec, **kwargs)`` hid its arguments from help() and completion."""
    import inspect

    from torquesplit.study import Study, run_study

    ours = inspect.signature(run_study).parameters
    theirs = inspect.signature(Study.run).parameters
    assert [p for p in ours if p not in ("spec", "analysis")] == [
        p for p in theirs if p != "self"]
    assert all(ours[p].default == theirs[p].default for p in theirs if p != "self")
    with pytest.raises(TypeError, match="worker"):
        run_study("nope.toml", worker=2)


def test_a_quasi_static_sweep_shorter_than_the_common_period_is_said():
    """A studies reviewer's one revolution of Mo et al. 2017's errors (which repeat every
    25 revolutions of the slowest gear) gave 1.045 where the whole period gives 1.048,
    without a word."""
    import warnings

    from torquesplit.errors import ModelWarning

    def said(revolutions):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            torquesplit.quasi_static_load_sharing("mo2017_star_reducer",
                                                  revolutions=revolutions,
                                                  points_per_cycle=1, max_points=16)
        return [str(w.message) for w in caught if issubclass(w.category, ModelWarning)
                and "common period" in str(w.message)]

    (text,) = said(1)
    assert "revolutions = 1 covers part of the excitations' common period, 25 " in text
    assert said(25) == [] and said(50) == []


def test_exceptions_live_in_errors_and_no_data_class_is_named_error():
    """Every exception class of the package derives from TorquesplitError and is defined
    in torquesplit.errors (warnings too, as Warning subclasses), and no other class is
    named *Error (a pydantic model PinError read as an exception; a CaseWarning lived in
    study/case.py, an unused Interrupted in cli_support.py)."""
    import importlib
    import inspect
    import pkgutil

    import torquesplit
    from torquesplit.errors import TorquesplitError

    seen = {}
    for info in pkgutil.walk_packages(torquesplit.__path__, "torquesplit."):
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if inspect.isclass(obj) and obj.__module__.startswith("torquesplit"):
                seen[obj.__module__, obj.__qualname__] = obj
    assert len(seen) > 100  # (the package's modules were walked)
    for (module, name), cls in seen.items():
        if issubclass(cls, BaseException):
            assert module == "torquesplit.errors", (module, name)
            assert issubclass(cls, (TorquesplitError, Warning)), name
        else:
            assert not name.endswith("Error"), (module, name)


def test_argument_errors_of_the_entry_points_are_the_packages_own():
    """Bad arguments to the API's lower entry points raise OptionError (a ValueError and
    a TorquesplitError: one base to catch), not bare ValueError (an audit found 77)."""
    import numpy as np

    from torquesplit.assembly.structure import build_structure
    from torquesplit.errors import OptionError, OptionTypeError
    from torquesplit.gears.geometry import _angular_speed
    from torquesplit.gpu.backend import GpuRunner
    from torquesplit.solve import modal_analysis
    from torquesplit.study.runners import LocalPool

    s = build_structure(["a.x"], [1.0], [dict(name="k", dofs=[0], coefs=[1.0],
                                              stiffness=1.0)])
    calls = [lambda: GpuRunner(batch=0), lambda: GpuRunner(precision="fp16"),
             lambda: modal_analysis(s, np.zeros(3)),
             lambda: build_structure(["a.x"], [1.0], [], gyroscopic=[(0, 5, 1.0)]),
             lambda: LocalPool(-1)]
    for call in calls:
        with pytest.raises(OptionError):
            call()
    with pytest.raises(OptionTypeError):
        _angular_speed(1.0, 2.0)


def test_one_name_where_names_are_taken_is_that_name(short_run):
    """mesh_series('m11') said "unknown element 'm'" and bodies='z1' "no support force
    history of z, 1" (a Python API reviewer): one name is taken as one name."""
    import torquesplit.plot  # noqa: F401

    ss = torquesplit.steady_state(EXAMPLE)
    t, forces, _ = ss.mesh_series("m11")
    t2, forces2, _ = ss.mesh_series(["m11"])
    assert forces.shape == forces2.shape and (forces == forces2).all()
    fig = torquesplit.plot.support_spectrum_figure(short_run, bodies="z1")
    assert len(fig.axes) == len(torquesplit.plot.support_spectrum_figure(
        short_run, bodies=["z1"]).axes)


def test_a_scheduler_address_without_a_port_is_an_option_error(tmp_path):
    from torquesplit.study import run_study

    spec = {"study": {"name": "x", "model": EXAMPLE, "outputs": ["load_sharing.mean_force"]},
            "analysis": {"cycles": 5},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio", "values": [0.05]}]}}
    with pytest.raises(OptionError, match=r"^scheduler address 'nowhere': .*give e\.g\. "
                                          r"'tcp://host:8786'$"):
        run_study(spec, scheduler="nowhere", out=tmp_path / "x")


def test_the_per_cycle_statistics_are_named(short_run):
    """A bare 5-tuple whose meaning went by position (a Python API reviewer)."""
    stats = short_run.complete_cycle_statistics()
    assert stats._fields == ("max", "min", "mean", "count", "ratio_max")
    high, low, mean, count, ratio = stats  # (still unpacks as the five arrays)
    assert high is stats.max and count is stats.count and ratio is stats.ratio_max
    assert (stats.max >= stats.min)[stats.count > 0].all()
