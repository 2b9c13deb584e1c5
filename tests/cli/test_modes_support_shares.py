"""A planetary reviewer: the modes table gave a rotational mode's energy in planet 1's
bearing as 'support.y' and in planet 2's as 'support.x' (the carrier frame's axes, not
the planet's), so the four equal planets of Lin & Parker's rotational mode looked
different; a degenerate pair's split between x and y depends on the solver's basis.  The
summary takes a support's components together; every component stays in the data."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from torquesplit.cli import app
from torquesplit.modes import ModeRow, model_modes


def test_a_supports_components_are_summed_and_the_rest_kept():
    r = ModeRow(mode=1, frequency=10.0, group=1, multiplicity=1, type=None,
                strain_energy={"p1.support.x": 0.1, "m": 0.3, "p1.support.y": 0.25,
                               "p2.support.loa": 0.2, "shaft.support_like.x": 0.15})
    assert r.largest_shares(3) == [("p1.support", pytest.approx(0.35)), ("m", 0.3),
                                   ("p2.support", 0.2)]
    assert r.largest_shares(9)[-1] == ("shaft.support_like.x", 0.15)  # (not a support)
    assert r.strain_energy["p1.support.x"] == 0.1


def test_the_planets_of_a_rotational_mode_share_alike():
    import torquesplit

    rep = model_modes(torquesplit.load_model(torquesplit.example_path(
        "lin_parker1999_planetary")), rotating_frame=False)
    rot = [r for r in rep.rows if r.type == "rotational"][0]
    planets = {n: v for n, v in rot.largest_shares(20) if ".support" in n and "planet" in n}
    assert len(planets) == 4, planets
    assert max(planets.values()) - min(planets.values()) < 1e-6, planets
    res = CliRunner().invoke(app, ["modes", "lin_parker1999_planetary", "--count", "6",
                                   "--no-rotating-frame"])
    assert res.exit_code == 0, res.output
    assert "support.x" not in res.stdout and "support.y" not in res.stdout, res.stdout
