"""The Python API as a notebook user meets it: what the package lists, short reprs,
argument checks that name the argument (a reviewer's findings)."""

from __future__ import annotations

import warnings

import pytest

import torquesplit


@pytest.fixture(scope="module")
def model():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.load_model("ji_li_mill_drive")


def test_everything_listed_is_there_and_listed():
    for name in torquesplit.__all__:
        assert getattr(torquesplit, name) is not None, name
        assert name in dir(torquesplit), name  # (tab completion of the lazy ones too)
    assert issubclass(torquesplit.OptionError, torquesplit.TorquesplitError)
    # the classes the functions return or raise are named at the top (a reviewer had to
    # find torquesplit.results.Results, torquesplit.study.StudyError...)
    res = torquesplit.simulate("ji_li_mill_drive", cycles=5)
    assert isinstance(res, torquesplit.Results)
    assert isinstance(torquesplit.load_model("ji_li_mill_drive"), torquesplit.Model)
    for name in ("StudyError", "OutputError"):
        assert issubclass(getattr(torquesplit, name), torquesplit.TorquesplitError)


def test_the_pipeline_functions_take_what_load_model_reads(model):
    assert torquesplit.solve_kinematics("ji_li_mill_drive").input_power == \
        torquesplit.solve_kinematics(model).input_power
    assert torquesplit.assemble("ji_li_mill_drive").n_dof == torquesplit.assemble(model).n_dof


def test_reprs_are_one_short_line(model):
    quasi = torquesplit.quasi_static_load_sharing(model, revolutions=0.05)
    run = torquesplit.simulate(model, cycles=20)
    objects = [model, torquesplit.model_modes(model), quasi, run.metrics(), quasi.metrics(),
               torquesplit.steady_state(model, method="hb"),
               torquesplit.Study({"study": {"name": "k", "model": "ji_li_mill_drive",
                                            "outputs": ["load_sharing.engineering"]},
                                  "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                                           "values": [0.05, 0.1]}]}})]
    for obj in objects:
        text = repr(obj)
        assert len(text) < 160 and "\n" not in text and " at 0x" not in text, text
        assert type(obj).__name__ in text


def test_mode_numbers_and_counts_are_checked(model):
    report = torquesplit.model_modes(model)
    assert report.shape(1) and report.shape(len(report.solution.frequencies))
    # an argument out of range is an OptionError: a TorquesplitError (one except clause
    # for the package's own errors) and a ValueError
    for bad in (0, -1, 99, 1.5):
        with pytest.raises(torquesplit.OptionError, match="1-based"):
            report.shape(bad)
    for bad in (0, -1):
        with pytest.raises(torquesplit.OptionError, match="count must be"):
            torquesplit.model_modes(model, count=bad)
    with pytest.raises(torquesplit.OptionError, match="below must be a positive frequency"):
        torquesplit.model_modes(model, below=-5.0)  # ('1 kHz' is read with its unit)
    with pytest.raises(torquesplit.OptionError, match="below '1 kg' is not a frequency"):
        torquesplit.model_modes(model, below="1 kg")


def test_bad_arguments_raise_the_packages_own_error(model):
    """A reviewer met ValueError from some functions and SolverError from others for the
    same kind of mistake: an argument out of range is an OptionError everywhere."""
    run = torquesplit.simulate(model, cycles=10)
    calls = [lambda: torquesplit.simulate(model, cycles=10, steps_per_period=0),
             lambda: torquesplit.simulate(model, cycles=10, method="euler"),
             lambda: run.metrics(window=1),
             lambda: run.metrics("no_such_definition"),
             lambda: torquesplit.quasi_static_load_sharing(model, revolutions=-1),
             lambda: torquesplit.steady_state(model, method="hb").mesh_series(["m99"]),
             # checked before the period search (a LongPeriodError of another model)
             lambda: torquesplit.steady_state(model, method="newton"),
             lambda: torquesplit.steady_state(model, harmonics=0),
             lambda: torquesplit.steady_state(model, speed="3000 mm"),
             lambda: torquesplit.sweep_speed(model, "600 rpm", "800 rpm", points=0),
             lambda: torquesplit.simulate(model, cycles=10, max_steps=0),
             lambda: run.bearing_forces("x"),
             lambda: run.write_figures("figs", formats=("xlsx",)),
             lambda: run.metrics("static_torque"),  # (a quasi-static definition)
             lambda: torquesplit.assemble(model, options={"x": 1}),
             lambda: torquesplit.steady_state(model, keep="zz"),
             lambda: torquesplit.steady_state(model, method="hb", keep="stage1", samples=-3),
             lambda: torquesplit.steady_state(model, max_cycles=0),
             lambda: torquesplit.sweep_speed(model, "600 rpm", "800 rpm", max_step=-1)]
    for call in calls:
        with pytest.raises(torquesplit.OptionError):
            call()
    # a wrong kind of argument is also a TypeError
    with pytest.raises(torquesplit.OptionTypeError):
        torquesplit.simulate(model, cycles=10, progress="yes")
    # what the message says: the quasi-static definition's own command; options of the
    # other method refused, not ignored (rtol was silently dropped by rk4)
    with pytest.raises(torquesplit.OptionError, match="torquesplit static"):
        run.metrics("static_torque")
    with pytest.raises(torquesplit.OptionError, match=r"\['rtol'\] do not apply to "
                       r"method='rk4'"):
        torquesplit.simulate(model, cycles=10, method="rk4", rtol=1e-6)
    with pytest.raises(torquesplit.OptionError, match=r"\['steps_per_period', 'max_steps'\] "
                       r"do not apply to method='dopri'"):
        torquesplit.simulate(model, cycles=10, method="dopri", steps_per_period=100,
                             max_steps=10)


def test_speeds_with_units_and_series_by_name(model):
    """sweep_speed and campbell took only rad/s (a reviewer's '2400 rpm' failed with
    'could not convert string to float'); mesh_series took only element indices."""
    rpm = 3.141592653589793 / 30
    by_text = torquesplit.campbell(model, "600 rpm", "800 rpm")[1]
    by_number = torquesplit.campbell(model, 600 * rpm, 800 * rpm)[1]
    assert [c["speed_rpm"] for c in by_text] == [c["speed_rpm"] for c in by_number]
    with pytest.raises(torquesplit.OptionError, match="start: '600 kg' is not a speed"):
        torquesplit.campbell(model, "600 kg", "800 rpm")
    st = torquesplit.steady_state(model, method="hb")
    names = list(st.structure.element_names)
    t_name, f_name, _ = st.mesh_series(["m11", "m21"])
    t_index, f_index, _ = st.mesh_series([names.index("m11"), names.index("m21")])
    assert (f_name == f_index).all() and (t_name == t_index).all()
    with pytest.raises(torquesplit.OptionError, match="unknown element 'm99'"):
        st.mesh_series(["m99"])


def test_warnings_name_the_callers_line(model):
    """A warning raised a few calls below the function the user called was attributed to
    a line of torquesplit's own (simulation.py:131), not to the user's script."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.simulate(model, cycles=5, samples_per_period=10**6)
        line = __import__("inspect").currentframe().f_lineno - 1
    said = [w for w in caught if "asks for more samples" in str(w.message)]
    assert len(said) == 1
    assert (said[0].filename, said[0].lineno) == (__file__, line)


def test_tab_completion_lists_the_library_and_modes_take_a_limit_with_its_unit():
    """dir(torquesplit) listed 'annotations' (a __future__ feature); dir(torquesplit.plot)
    listed none of its figure functions; model_modes(below='1 kHz') was refused while
    simulate(duration='5 ms') reads its unit."""
    import torquesplit.plot

    assert "annotations" not in dir(torquesplit)
    assert set(torquesplit.plot.__all__) <= set(dir(torquesplit.plot))
    a = torquesplit.model_modes("ji_li_mill_drive", below="1 kHz")
    b = torquesplit.model_modes("ji_li_mill_drive", below=1000.0)
    assert [r.frequency for r in a.rows] == [r.frequency for r in b.rows] and a.rows
    with pytest.raises(torquesplit.errors.OptionError, match="below"):
        torquesplit.model_modes("ji_li_mill_drive", below="1 kg")


def test_every_result_is_saved_by_one_function_with_its_model(model, tmp_path):
    """An exports reviewer: sweep_speed returned a bare Dataset (whose to_netcdf('x.csv')
    wrote NetCDF under a .csv name), campbell a tuple, a contact analysis had no save,
    and the modes saved from Python named no model.  torquesplit.save writes each by
    suffix, as its command does, with the model the file came from."""
    import scipy.io
    import xarray as xr

    from torquesplit.model.io import model_to_json

    results = {
        "modes": torquesplit.model_modes(model, count=4),
        "contact": torquesplit.contact_analysis(model, "m11", positions=16, slices=4),
        "sweep": torquesplit.sweep_speed(model, "740 rpm", "745 rpm", points=2,
                                         stability=False),
        "campbell": torquesplit.campbell(model, "0 rpm", "800 rpm", points=3),
    }
    for name in ("sweep", "campbell"):  # (each variable says what it is, for a file's reader)
        ds = results[name][0] if name == "campbell" else results[name]
        bare = [v for v in [*ds.data_vars, *(c for c in ds.coords if c not in ds.dims)]
                if "long_name" not in ds[v].attrs]
        assert bare == [], (name, bare)
    for name, result in results.items():
        for suffix in (".nc", ".mat", ".csv"):
            assert torquesplit.save(result, tmp_path / f"{name}{suffix}") == \
                tmp_path / f"{name}{suffix}"
        with xr.open_dataset(tmp_path / f"{name}.nc") as ds:
            assert ds.attrs["model_json"] == model_to_json(model), name
            assert ds.attrs["model_sha256"], name
        assert scipy.io.loadmat(tmp_path / f"{name}.mat")["model_json"][0] == \
            model_to_json(model), name
        assert (tmp_path / f"{name}.csv").read_bytes()[:1] != b"\x89"  # (not HDF5)
    with pytest.raises(torquesplit.OutputError, match="exists"):
        torquesplit.save(results["modes"], tmp_path / "modes.nc")
    with pytest.raises(torquesplit.OptionError, match="not a dict"):
        torquesplit.save({}, tmp_path / "x.nc")
