"""Critical speeds of a model whose natural frequencies move with speed (turning carrier)."""

import numpy as np
import pytest

from torquesplit import example_path, load_model
from torquesplit.solve.modal import modal_analysis
from torquesplit.steady.maps import _prepare, _structure_at, campbell
from torquesplit.steady.api import reference_speed


def test_crossings_are_those_of_the_speed_dependent_frequencies():
    """Lin & Parker 1999's planetary stage, carrier turning: each crossing lies on the
    mode's frequency at the crossing's own speed (the modes at the model's speed were off
    by their change with speed, ~0.2 % here), and on its excitation line."""
    model = load_model(example_path("lin_parker1999_planetary"))
    ds, crossings = campbell(model, 500 * np.pi / 30, 3000 * np.pi / 30, points=41)
    assert crossings
    _, _, s, _, _, static = _prepare(model, None, None)
    assert s.n_gyroscopic
    w_ref = reference_speed(model)
    lines = {(str(lab).partition(" x ")[2], int(str(lab).partition(" x ")[0])): j
             for j, lab in enumerate(ds["line"].values)}
    for c in crossings[:4]:
        w = c["speed_rpm"] * np.pi / 30
        f_here = modal_analysis(_structure_at(model, w / w_ref), static.q).frequencies
        assert c["frequency_Hz"] == pytest.approx(f_here[c["mode"] - 1], rel=1e-12)
        j = lines[(c["source"], c["order"])]
        line = np.interp(w, ds["speed"].values, ds["excitation_frequency"].values[:, j])
        assert c["frequency_Hz"] == pytest.approx(line, rel=2e-4)
