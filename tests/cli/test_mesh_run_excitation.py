"""An LTCA reviewer could not see the loaded transmission error e(s) a tangent-stiffness
mesh drives a run with: 'torquesplit mesh' showed k(s) only.  It now also gives what a
run sees of the mesh over a cycle at the static equilibrium: k(s), e(s) and the force
k(s) (delta - e(s)), where the error varies over the cycle."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import torquesplit
from model_texts import RELIEVED_SPUR_LTCA, write_model
from torquesplit.cli import app
from torquesplit.solve import static_equilibrium
from torquesplit.steady.maps import mesh_cycle


def test_an_ltca_mesh_shows_its_error_and_force_over_the_cycle(tmp_path):
    path = write_model(tmp_path, RELIEVED_SPUR_LTCA)
    res = CliRunner().invoke(app, ["mesh", str(path), "--pair", "m", "--json"])
    assert res.exit_code == 0, res.output
    run = json.loads(res.stdout)["run_excitation"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = torquesplit.assemble(torquesplit.load_model(path))
        cyc = mesh_cycle(s, static_equilibrium(s).q, list(s.element_names).index("m"))
    assert np.allclose(run["error_m"], cyc.error, rtol=0, atol=1e-15)
    assert np.ptp(run["error_m"]) > 1e-6  # micrometres of loaded TE
    assert np.allclose(run["static_force_N"], cyc.force)
    text = " ".join(CliRunner().invoke(app, ["mesh", str(path), "--pair", "m"]).stdout.split())
    assert "what a run sees of m over a mesh cycle" in text
    assert f"error e(s) [µm] │ {cyc.error.mean() * 1e6:#.5g}" in text, text[-1500:]
    share = np.ptp(cyc.force) / cyc.force.mean()
    assert f"peak-to-peak is {100 * share:.3g} % of its mean" in text


@pytest.mark.parametrize("as_json", [False, True])
def test_a_mesh_without_varying_error_has_no_such_table(as_json):
    res = CliRunner().invoke(app, ["mesh", "ji_li_mill_drive", "--pair", "m11"]
                             + (["--json"] if as_json else []))
    assert res.exit_code == 0, res.output
    if as_json:
        assert "run_excitation" not in json.loads(res.stdout)
    else:
        assert "what a run sees" not in res.stdout


def test_a_mesh_with_backlash_says_what_of_its_deformation_the_teeth_carry():
    """Ji & Li's m11 with a transmission-error harmonic: its static deformation 711 um
    is mostly the backlash's half-gap (the teeth carry 25 um)."""
    res = CliRunner().invoke(app, ["mesh", "ji_li_mill_drive", "--pair", "m11", "--set",
                                   'meshes.m11.transmission_error={amplitude="5 um"}',
                                   "--json"])
    assert res.exit_code == 0, res.output
    run = json.loads(res.stdout)["run_excitation"]
    carried = run["static_deflection_m"] - run["half_gap_m"]
    k = np.mean(run["stiffness_N_per_m"])
    assert run["half_gap_m"] > 0 and carried == pytest.approx(
        np.mean(run["static_force_N"]) / k, rel=0.02)
    text = " ".join(CliRunner().invoke(app, ["mesh", "ji_li_mill_drive", "--pair", "m11",
                                             "--set", 'meshes.m11.transmission_error='
                                             '{amplitude="5 um"}']).stdout.split())
    assert "of it the backlash's half-gap, which the teeth do not carry" in text
