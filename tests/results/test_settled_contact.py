"""The settled table leaves the start-up transient out; the warnings say what it held."""

import re
from pathlib import Path

import numpy as np
import pytest

import torquesplit
from torquesplit.results.plausibility import result_warnings

TUTORIAL = Path(__file__).resolve().parents[2] / "docs" / "tutorial.md"


@pytest.fixture(scope="module")
def three_branch_run(tmp_path_factory):
    """The tutorial's three-branch drive, 0.05 s: mesh out2 (no backlash) is pulled onto
    its back flank in the first cycles after the start from static equilibrium only."""
    text = re.search(r"```toml\n(.*?)```", TUTORIAL.read_text(), re.S).group(1)
    path = tmp_path_factory.mktemp("tutorial") / "three_branch.toml"
    path.write_text(text)
    return torquesplit.simulate(torquesplit.load_model(path), duration=0.05)


def test_back_flank_force_is_that_of_the_settled_cycles(three_branch_run):
    res = three_branch_run
    met = res.metrics()
    c_min = res.complete_cycle_statistics()[1]
    j = res.mesh_names.index("out2")
    assert np.nanmin(c_min[:, j]) < -50.0  # tension in the transient
    row = next(r for r in met.rows if r.mesh == "out2")
    assert row.min_force > 0.0
    assert row.back_flank_force == 0.0
    said = dict(result_warnings(res, met))
    assert "in the start-up transient only" in said["meshes.out2"]
    assert "81.4 N" in said["meshes.out2"]  # the transient's, named as such


def test_a_run_too_short_for_its_windows_says_so(three_branch_run):
    met = three_branch_run.metrics()
    assert not met.settling.settled
    said = dict(result_warnings(three_branch_run, met))
    assert "too short to tell whether the response has settled" in said["analysis"]
