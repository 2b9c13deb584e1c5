"""The run-length arguments of ``simulate`` and ``prepare_run``: refused with one message
naming the argument (never a bare TypeError or ZeroDivisionError), a time string read."""

from __future__ import annotations

import pytest

import torquesplit
from torquesplit.errors import OptionError
from torquesplit.simulation import prepare_run

BAD = [
    ({"duration": 0.005, "cycles": 30}, r"duration=0\.005 and cycles=30 .*only one of them"),
    ({"duration": "5 xx"}, r"^duration: cannot read '5 xx' as a time"),
    ({"duration": "5 m"}, r"^duration: '5 m' is not a time"),
    ({"duration": -1.0}, r"^duration must be a positive time, got -1\.0"),
    ({"duration": "0 s"}, r"^duration must be a positive time"),
    ({"duration": [1]}, r"^duration: got \[1\]"),
    ({"cycles": 2.5}, r"^cycles must be a whole number >= 1, got 2\.5; give e\.g\. cycles=200$"),
    ({"cycles": "3"}, r"^cycles must be a whole number"),
    ({"cycles": -3}, r"^cycles must be a whole number >= 1, got -3; give e\.g\. cycles=200$"),
    ({"cycles": 0}, r"^cycles must be a whole number >= 1, got 0"),
    ({"samples_per_period": 0}, r"^samples_per_period must be a whole number >= 1, got 0"),
    ({"samples_per_period": 0.5}, r"^samples_per_period must be a whole number"),
    # 0 fell back to the model's 100 and 2.5 was cut to 2, silently
    ({"steps_per_period": 0}, r"^steps_per_period must be a whole number >= 10, got 0"),
    ({"steps_per_period": 2.5}, r"^steps_per_period must be a whole number >= 10, got 2\.5"),
    ({"steps_per_period": 3}, r"^steps_per_period must be a whole number >= 10, got 3"),
    # (a reviewer: '100' was told "a whole number >= 1", the minimum being 10)
    ({"steps_per_period": "100"}, r"^steps_per_period must be a whole number >= 10, got '100'"),
]


@pytest.mark.parametrize("function", [torquesplit.simulate, prepare_run])
@pytest.mark.parametrize("kwargs, message", BAD)
def test_bad_run_length_is_refused_naming_the_argument(spur_pair, function, kwargs, message):
    with pytest.raises(OptionError, match=message) as info:
        function(spur_pair, **kwargs)
    assert "--" not in str(info.value)  # the Python API names its own arguments


@pytest.mark.parametrize("kwargs, message", [
    ({"window": 0}, r"^window must be a whole number of cycles >= 2, got 0"),
    ({"window": 2.5}, r"^window must be a whole number"),
    ({"tolerance": 0}, r"^tolerance must be a fraction between 0 and 1, got 0"),
    ({"tolerance": -1}, r"^tolerance must be a fraction"),
])
def test_metrics_settle_arguments_are_checked(spur_pair, kwargs, message):
    """window=0 was clamped to 2 and tolerance=-1 gave metrics from half the run, both
    without a word."""
    res = torquesplit.simulate(spur_pair, cycles=30)
    with pytest.raises(ValueError, match=message):
        res.metrics(**kwargs)
    assert res.metrics(window=20.0, tolerance=0.02).load_sharing.system > 0


@pytest.mark.parametrize("kwargs, message", [
    ({"max_points": 0}, r"^max_points must be a whole number >= 1, got 0"),
    ({"max_points": -1}, r"^max_points must be"),
    ({"points_per_cycle": 0}, r"^points_per_cycle must be a whole number >= 1, got 0"),
    ({"points_per_cycle": 2.5}, r"^points_per_cycle must be"),
    ({"revolutions": "2"}, r"^revolutions must be a positive number, got '2'"),
    ({"revolutions": -1}, r"^revolutions must be a positive number"),
])
def test_quasi_static_arguments_are_checked(spur_pair, kwargs, message):
    """max_points=0 divided by zero, -1 gave an empty sweep, points_per_cycle=0 16
    positions silently, a string revolutions a TypeError."""
    with pytest.raises(ValueError, match=message):
        torquesplit.quasi_static_load_sharing(spur_pair, **kwargs)


def test_duration_string_and_whole_float_cycles_are_read(spur_pair):
    run = prepare_run(spur_pair, duration="5 ms")
    assert run.duration == pytest.approx(0.005)
    f_min = min(m.frequency for m in run.kinematics.meshes.values())
    assert prepare_run(spur_pair, cycles=3.0).duration == pytest.approx(3 / f_min)
    res = torquesplit.simulate(spur_pair, duration="2 ms")
    assert res.success and res.solution.t_final == pytest.approx(0.002)


def test_the_default_history_keeps_every_step_of_a_short_run_and_a_budget_of_a_long_one():
    """20 samples per period by default missed the peaks of short runs whose every step
    costs nothing to keep; a long run keeps AUTO_HISTORY_RECORDS, never fewer than
    MIN_SAMPLES_PER_PERIOD a period."""
    from torquesplit.simulation import (AUTO_HISTORY_RECORDS, MIN_SAMPLES_PER_PERIOD,
                                        history_interval)

    f_max = 1000.0
    short = history_interval(0.1, f_max, None)
    assert short == pytest.approx(0.1 / AUTO_HISTORY_RECORDS)  # below any usual step
    long = history_interval(1e3, f_max, None)
    assert long == pytest.approx(1.0 / (MIN_SAMPLES_PER_PERIOD * f_max))
    middle = history_interval(1.0, f_max, None)  # 50 a period: the budget
    assert 1.0 / middle == pytest.approx(AUTO_HISTORY_RECORDS)
    assert history_interval(1e3, f_max, 7) == pytest.approx(1.0 / 7e3)


def test_the_default_history_of_a_fixed_step_run_keeps_its_budget():
    """60,512 steps kept 60,513 samples for a budget of 50,000 (an interval of 1.2 steps
    rounded to 1): the default is a whole number of steps now."""
    from torquesplit.simulation import AUTO_HISTORY_RECORDS, history_interval

    step, n = 2e-5, 60_512
    interval = history_interval(n * step, 100.0, None, step)
    assert interval == pytest.approx(2 * step) and n * step / interval <= AUTO_HISTORY_RECORDS
    assert history_interval(1e3 * step, 100.0, None, step) == pytest.approx(step)  # all
    # never coarser than 20 samples per shortest mesh period
    assert history_interval(1e7 * step, 100.0, None, step) == pytest.approx(1 / 2000)


def test_a_history_finer_than_the_step_is_said_as_the_step(spur_pair):
    """samples_per_period=1e6 warned that the record cap kept 4.05e3 per period, where
    the history kept every step: 400 per period (Ji & Li)."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = torquesplit.simulate(spur_pair, cycles=5, samples_per_period=10**6)
    said = [str(w.message) for w in caught if "history" in str(w.message)]
    kept = res.history_samples_per_period()
    assert len(said) == 1 and f"keeps every RK4 step, {kept:.4g} per shortest" in said[0]
    assert "at most" not in said[0]
    assert "a finer step (--steps-per-period" in said[0]  # the step is the period's here


def test_a_history_finer_than_a_step_set_by_stability_says_what_refines_it():
    """Where RK4 stability sets the step (190 steps per mesh period of Dong et al. 2021's
    model with its spline friction regularised over 1 mm/s, where 100 were asked), 'a
    finer history needs a finer step (--steps-per-period)' sent the user to an option
    that changes nothing below 190."""
    import warnings

    from torquesplit.solve.integrate import planned_step, shortest_excitation_period

    model = torquesplit.load_model("dong2021_face_gear").with_changes(
        {"analysis.spline_velocity_scale": 1e-3})
    step, why = planned_step(torquesplit.assemble(model), 100)
    per = shortest_excitation_period(torquesplit.assemble(model)) / step
    assert why != "excitation period" and per > 150  # (the premise)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        torquesplit.simulate(model, cycles=3, samples_per_period=1000, steps_per_period=100)
    said = [str(w.message) for w in caught if "asks for more samples" in str(w.message)]
    cause = why.split(", needs ")[0]
    assert cause.startswith("RK4 stability") and "steps per excitation period" not in cause
    assert len(said) == 1
    assert (f"a finer step (a --steps-per-period above {round(per)}, steps_per_period= in "
            f"Python: the step is set here by {cause}, at {round(per)} steps per shortest "
            f"excitation period)") in said[0]


def test_a_runs_record_keeps_the_warnings_its_caller_silenced():
    """A reviewer: under warnings.simplefilter("ignore") a run's ModelWarnings were
    neither shown nor kept, so its files and report lost them.  Kept whatever the
    filters, once each, also when the model's set-up is kept from an earlier run."""
    import warnings

    import torquesplit

    m = torquesplit.load_model("ji_li_mill_drive")
    kw = dict(duration=0.05, steps_per_period=20)  # (a step warning: 20 is too coarse)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        loud = torquesplit.simulate(m, **kw).run_warnings
    assert loud and [str(w.message) for w in shown
                     if issubclass(w.category, torquesplit.ModelWarning)] == loud
    for _ in range(2):  # (the second: the model's set-up kept)
        with warnings.catch_warnings(record=True) as shown:
            warnings.simplefilter("ignore")
            quiet = torquesplit.simulate(m, **kw).run_warnings
        assert quiet == loud and shown == []


def test_the_metrics_one_line_says_when_the_run_did_not_settle():
    """A reviewer: a run too short to tell whether it settled said so only in its
    warnings; the metrics' line said 'settled from ...'."""
    import warnings

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        short = torquesplit.simulate("ji_li_mill_drive", cycles=3).metrics()
    assert not short.settling.settled and short.settling.short
    assert "not settled (too short to tell" in repr(short) and "settled from" not in repr(short)


def test_a_warning_its_file_accepts_is_not_in_the_runs_warnings():
    """Mo et al. 2017's file accepts its printed mesh stiffness (far below ISO 6336) with
    a reason: `run` did not print the warning, but its files and report listed it."""
    import warnings

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = torquesplit.load_model("mo2017_star_reducer")
        kept = torquesplit.simulate(m, cycles=5).warnings()
        plain = torquesplit.simulate(m.with_changes({"model.accepted_warnings": []}),
                                     cycles=5).warnings()
    assert not any("ISO 6336" in w for w in kept)
    assert any(w.startswith("meshes.s1p11.stiffness: ") and "ISO 6336" in w for w in plain)
