"""Support forces of a planetary stage are in the carrier's turning frame: the spectrum's
panels and the dataset say so, and the shaft-order markers are speeds in that frame."""

from __future__ import annotations

import math
import warnings

import pytest

from planetary_models import three_planet_toml
import torquesplit
from torquesplit.model.kinematics import solve_kinematics, support_frame
from torquesplit.results.dataset import results_to_dataset

STAGE = three_planet_toml("frames")


@pytest.fixture(scope="module")
def run():
    import tomllib

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torquesplit.simulate(torquesplit.load_model(tomllib.loads(STAGE)), cycles=30)


def test_support_frame_gives_speeds_relative_to_the_carrier(run):
    kin = run.kinematics
    # sun 1500 rpm, carrier 1500 * 24 / 108 = 333.3 rpm, planets -600 rpm (housing)
    carrier, f_sun, f_frame = support_frame(kin, "st_sun")
    assert carrier == "st_carrier"
    assert f_frame == pytest.approx(1500 * 24 / 108 / 60, rel=1e-9)
    assert f_sun == pytest.approx((1500 - 1500 * 24 / 108) / 60, rel=1e-9)
    _, f_planet, _ = support_frame(kin, "st_planet1")
    assert f_planet == pytest.approx((600 + 1500 * 24 / 108) / 60, rel=1e-9)


def test_support_frame_of_a_fixed_axis_body_is_the_housing():
    model = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    kin = solve_kinematics(model)
    body = next(b for b in kin.bodies if kin.bodies[b].speed)
    carrier, f, f_frame = support_frame(kin, body)
    assert carrier is None and f_frame == 0
    assert f == pytest.approx(abs(kin.bodies[body].speed) / (2 * math.pi))


def test_the_spectrum_names_the_frame_and_marks_relative_speeds(run):
    from torquesplit.plot.figures import support_spectrum_figure

    fig = support_spectrum_figure(run, bodies=["st_sun", "st_planet1"])
    sun, planet = fig.axes[:2]
    assert "st_carrier's turning frame" in sun.get_title()
    assert "in the force's frame" in sun.get_xlabel()
    labels = sun.get_legend_handles_labels()[1]
    assert "rotation of st_sun relative to st_carrier: 19.44 Hz" in labels, labels
    assert any(lab.startswith("rotation of st_carrier (housing seen") for lab in labels)
    labels = planet.get_legend_handles_labels()[1]
    assert "rotation of st_planet1 relative to st_carrier: 15.56 Hz" in labels, labels


def test_the_dataset_says_the_frame_of_each_force(run):
    ds = results_to_dataset(run)
    frames = dict(zip(ds["element"].values, ds["element_frame"].values))
    assert frames["st_planet1.support.x"] == "turning with st_carrier"
    assert frames["st_sun.support.y"] == "turning with st_carrier"
    assert frames["st_sun_planet1"] == ""
    assert "turning carrier" in ds["element_frame"].attrs["long_name"]
