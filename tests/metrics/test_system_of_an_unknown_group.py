"""A Python API reviewer: a 0.1 s run of Ji & Li's drive gave stage 2 no whole cycle (its
coefficient NaN) and the system 1.00003, stage 1's, as if it were the largest; Python's
max() skipped the NaN or not depending on the groups' order."""

from __future__ import annotations

import math
import warnings

import torquesplit
from torquesplit.metrics.load_sharing import _system


def test_the_system_is_unknown_while_a_group_is():
    assert math.isnan(_system({"a": 1.02, "b": math.nan}))
    assert math.isnan(_system({"b": math.nan, "a": 1.02}))
    assert _system({"a": 1.02, "b": 1.05}) == 1.05
    assert math.isnan(_system({}))


def test_a_run_too_short_for_a_stage_has_no_system_value():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate("ji_li_mill_drive", duration=0.1)
        ls = res.metrics("mean_force").load_sharing
    assert math.isfinite(ls.per_group["stage1"]) and math.isnan(ls.per_group["stage2"])
    assert math.isnan(ls.system)
    assert math.isnan(res.to_dataset("mean_force")["load_sharing_system"].item())


def test_the_run_says_why_the_system_has_none():
    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["run", "ji_li_mill_drive", "--duration", "0.1 s",
                                   "--set", "analysis.load_sharing=mean_force", "--quiet"])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())
    assert ("system load-sharing coefficient (mean_force): nan (group stage2 has none"
            in text), text[-2000:]


def test_a_quasi_static_sweeps_metrics_read_as_a_runs():
    """A Python API reviewer: res.metrics().load_sharing worked on a run and broke on a
    quasi-static sweep, whose metrics() is the load sharing itself."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        qs = torquesplit.quasi_static_load_sharing("mo2017_star_reducer", revolutions=0.05,
                                                   points_per_cycle=4)
    met = qs.metrics()
    assert met.load_sharing is met and met.load_sharing.system == met.system > 1.0
