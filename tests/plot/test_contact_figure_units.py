"""The contact figures write µm, as the tables of ``torquesplit contact`` do, and leave
the Harris map out when there is none (``--harris 0``)."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest

import torquesplit
from torquesplit.plot import contact as C


@pytest.fixture(scope="module")
def ltca():
    """Two loads of a coarse LTCA of the Lin & Parker sun-planet mesh, and a Harris map."""
    from torquesplit.gears.contact.coupling import _options, contact_model_for_mesh
    from torquesplit.model.kinematics import solve_kinematics

    m = torquesplit.load_model(torquesplit.example_path("lin_parker1999_planetary"))
    kin = solve_kinematics(m)
    opts = replace(_options(m.meshes["stage_sun_planet1"].stiffness), positions=16, slices=8)
    cm, load, _, _ = contact_model_for_mesh(m, kin, "stage_sun_planet1", options=opts)
    results = [cm.solve(f) for f in (0.5 * load, load)]
    return results, cm.harris_map(np.array([0.5, 1.0]) * load)


def _texts(fig) -> list[str]:
    """Every text of a figure: titles, axis labels, legend entries."""
    out = [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]
    return [t for t in out if t]


@pytest.mark.parametrize("make", ["te", "harris", "stiffness"])
def test_contact_figures_write_micrometres_as_the_tables_do(ltca, make):
    results, hm = ltca
    fig = {"te": lambda: C.te_figure(results), "harris": lambda: C.harris_figure(hm),
           "stiffness": lambda: C.stiffness_figure(results[-1])}[make]()
    texts = _texts(fig)
    assert any("µm" in t for t in texts), texts
    assert not [t for t in texts if re.search(r"\bum\b|N/um", t)], texts


def test_no_harris_map_no_harris_figure(ltca, tmp_path):
    results, _ = ltca
    paths = C.write_contact_figures(results, None, tmp_path)
    assert sorted(p.name for p in paths) == sorted(C.contact_figure_files(harris=False))
    assert "contact_harris.png" not in C.contact_figure_files(harris=False)
    assert not (tmp_path / "contact_harris.png").exists()
