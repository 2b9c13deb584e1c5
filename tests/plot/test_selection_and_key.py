"""The spectrum draws a support as strong as one drawn; the layout key draws shafts as
the sketch does."""

from __future__ import annotations

import pytest

import matplotlib

import torquesplit
from model_texts import split_model, write_model
from torquesplit.plot.figures import _strongest
from torquesplit.plot.layout import layout_figure

matplotlib.use("Agg")


def test_a_support_as_strong_as_a_drawn_one_is_drawn_too():
    strength = {"z1": 3704.0, "z2": 216.1, "z3": 216.1, "z4": 705.7, "z5": 705.7, "z6": 3.4}
    shown, hidden = _strongest(strength, 4)
    assert shown == ["z1", "z2", "z3", "z4", "z5"] and hidden == ["z6"]
    assert _strongest({"a": 2.0, "b": 1.0, "c": 0.5}, 2) == (["a", "b"], ["c"])


def _key_and_shafts(model):
    fig = layout_figure(model)
    ax, legend = fig.axes[0], fig.legends[0]  # (the key below the drawing)
    key = {t.get_text(): h.get_linestyle()
           for t, h in zip(legend.get_texts(), legend.legend_handles)}
    drawn = {ln.get_linestyle() for ln in ax.get_lines()
             if ln.get_linewidth() == 4.0 and len(ln.get_xdata())}
    return key, drawn


def test_layout_key_shows_shafts_as_drawn(tmp_path):
    from torquesplit.examples import example_path

    elastic, drawn = _key_and_shafts(torquesplit.load_model(example_path("ji_li_mill_drive")))
    assert "shaft, rigid" not in elastic and drawn == {elastic["shaft, elastic"]}
    rigid, drawn = _key_and_shafts(torquesplit.load_model(write_model(tmp_path,
                                                                      split_model())))
    assert "shaft, elastic" not in rigid and drawn == {rigid["shaft, rigid"]} == {"-"}
    assert elastic["shaft, elastic"] != "-"


def test_the_layout_writes_large_torques_without_an_exponent():
    """A reviewer's mill drive read 'load mill: 2e+05 N m' on its drawing."""
    import re

    import torquesplit
    from torquesplit.plot.layout import layout_svg

    svg = layout_svg(torquesplit.load_model("ji_li_mill_drive"))
    labels = re.findall(r"load \w+: [^<]*", svg) + re.findall(r"drive \w+: [^<]*", svg)
    assert labels and not any("e+" in text for text in labels), labels


def test_the_layout_drawing_keeps_its_labels_apart():
    """Fixed label offsets piled names on each other where parts sit close (17 overlapping
    pairs on Ji & Li's drive: 'm11 backlash' over 'm21' and 'z1 19 T')."""
    import itertools

    import torquesplit
    from torquesplit.plot.layout import layout_figure

    fig = layout_figure(torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive")))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for ax in fig.axes for t in ax.texts
             if t.get_text().strip()]
    assert len(boxes) > 10

    def overlap(a, b):
        return (min(a.x1, b.x1) - max(a.x0, b.x0) > 2
                and min(a.y1, b.y1) - max(a.y0, b.y0) > 2)

    assert sum(overlap(a, b) for a, b in itertools.combinations(boxes, 2)) == 0


def _overlapping_label_pairs(fig) -> int:
    import itertools

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for ax in fig.axes for t in ax.texts
             if t.get_text().strip()]

    def overlap(a, b):
        return (min(a.x1, b.x1) - max(a.x0, b.x0) > 2
                and min(a.y1, b.y1) - max(a.y0, b.y0) > 2)

    return sum(overlap(a, b) for a, b in itertools.combinations(boxes, 2))


def _labels_over_lines(fig) -> list[str]:
    """The labels that cover a drawn line of a few points (shaft, support, hatch) or a
    marker: each segment sampled every 2 points."""
    import numpy as np

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    pts = []
    for line in ax.lines:
        xy = line.get_xydata()
        if 0 < len(xy) <= 10:
            d = ax.transData.transform(xy)
            pts += list(d)
            for a, b in zip(d[:-1], d[1:]):
                pts += [a + f * (b - a) for f in np.linspace(0, 1, 2 + int(
                    np.hypot(*(b - a)) / (2 * fig.dpi / 72)))]
    pts = np.array(pts)
    out = []
    for t in ax.texts:
        if t.get_text().strip():
            b = t.get_window_extent(renderer)
            inside = ((pts[:, 0] > b.x0 + 1) & (pts[:, 0] < b.x1 - 1)
                      & (pts[:, 1] > b.y0 + 1) & (pts[:, 1] < b.y1 - 1))
            if inside.any():
                out.append(t.get_text())
    return out


@pytest.mark.parametrize("name", ["ji_li_mill_drive", "liu2021_split_torque_helicopter",
                                  "split_path_planetary_differential"])
def test_layout_labels_stay_off_each_other_and_the_drawn_lines(name):
    """A reviewer's drawings had names written over shafts, supports and bodies (114
    labels over lines on the shipped examples, 9 on Ji & Li's: 'z6' on its support,
    'load mill' on the output shaft): labels now avoid the drawn lines and markers too,
    with a leader line when moved away from their part."""
    import torquesplit
    from torquesplit.plot.layout import layout_figure

    fig = layout_figure(torquesplit.load_model(torquesplit.example_path(name)))
    assert _overlapping_label_pairs(fig) == 0
    assert _labels_over_lines(fig) == []


def test_the_layout_of_a_planetary_stage_shows_its_carrier_ring_hold_and_pin_errors():
    """A reviewer's drawing of a planetary stage had no carrier, no sign that the ring
    is held, no pin error, and the drive's label on the sun's."""
    model = torquesplit.load_model("lin_parker1999_planetary", changes={
        "planetary.0.pin_errors": [{"radial": "0 um", "tangential": "0 um"},
                                   {"radial": "20 um", "tangential": "-5 um"}]
        + [{"radial": "0 um", "tangential": "0 um"}] * 2})
    fig = layout_figure(model)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.texts]
    hold = [t for t in texts if "held in rotation" in t]
    assert hold == ["stage_ring held in rotation by 1.99e+07 N m/rad"], hold
    assert sum("pin error 20 µm radial, -5 µm tangential" in t for t in texts) == 1
    key = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "pin circle of stage_carrier (planet bearings: dotted)" in key
    radius = 0.5 * (model.gears["stage_sun"].teeth + model.gears["stage_planet1"].teeth)
    circles = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"
               and len(ln.get_xdata()) > 50]
    r = [max(abs(ln.get_xdata())) for ln in circles]  # [mm], centred on the carrier
    module = model.gears["stage_sun"].module * 1e3
    assert any(abs(x - radius * module) < 0.02 * radius * module for x in r), (r, radius)
    assert _overlapping_label_pairs(fig) <= 1
    star = torquesplit.load_model("lin_parker1999_star")
    texts = [t.get_text() for t in layout_figure(star).axes[0].texts]
    assert "stage_carrier held in rotation rigidly" in texts


def test_many_supports_of_few_kinds_are_lettered_with_their_values_in_the_key():
    """Dong et al. 2021's drawing piled eight two-line support labels on its gears."""
    model = torquesplit.load_model("dong2021_face_gear")
    fig = layout_figure(model)
    ax = fig.axes[0]
    key = [t.get_text() for t in fig.legends[0].get_texts()]
    lettered = [k for k in key if k.startswith("support ") and k[9:11] == ": "]
    assert len(lettered) >= 2 and lettered[0].startswith("support A: ")
    labels = [t.get_text() for t in ax.texts if t.get_text().startswith("support")]
    assert labels and all(len(t) == len("support A") for t in labels), labels
    assert _overlapping_label_pairs(fig) <= 2  # (11 before)


def test_a_support_is_drawn_clear_of_the_other_gears(tmp_path):
    """A reviewer's idler i1 (above the input pinion) had its support line drawn down
    through the input gear: it goes the first way that crosses no other gear."""

    from model_texts import TWO_PATH_SPUR_REDUCER
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.plot import layout as L

    model = torquesplit.load_model(write_model(tmp_path, TWO_PATH_SPUR_REDUCER))
    kin = solve_kinematics(model)
    proj = L._Projection(L._main_axis(model, kin))
    centre = L._drawing_centres(model, kin, proj)
    radius = {n: mk_r for mk in kin.meshes.values()
              for n, mk_r in zip((mk.driver, mk.driven), mk.pitch_radii)}
    drop = 0.18 * max(radius.values()) * 1e3 + radius["i1"] * 1e3
    c = proj(centre["i1"])
    way = L._support_direction(c, drop, "i1", centre, radius, proj)
    assert tuple(way) != (0.0, -1.0)  # (down crosses the input gear)
    start, end = c + way * radius["i1"] * 1e3, c + way * drop
    for g in ("input", "i2", "bull", "p1", "p2"):
        assert L._segment_distance(proj(centre[g]), start, end) > radius[g] * 1e3, g
    assert L._support_direction(proj(centre["bull"]), drop, "bull", centre, radius,
                                proj).tolist() == [0.0, -1.0]  # (nothing below it)
