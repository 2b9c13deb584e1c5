"""The spectrum draws a support as strong as one drawn; the layout key draws shafts as
the sketch does."""

from __future__ import annotations

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
    ax = layout_figure(model).axes[0]
    legend = ax.get_legend()
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
