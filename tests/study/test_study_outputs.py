"""output_values: every name the catalogue promises, read from the metrics themselves."""

from __future__ import annotations

import math

import pytest

import torquesplit
from torquesplit.quasistatic import quasi_static_load_sharing
from torquesplit.study.outputs import (available_outputs, definitions_needed, family,
                                       output_values, select_outputs)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    from model_texts import split_model, write_model

    path = write_model(tmp_path_factory.mktemp("m"), split_model(error_a="5 um"))
    return torquesplit.simulate(path, cycles=40)


def test_dynamic_names_and_values_come_from_the_metrics(run):
    from torquesplit.results import bearing_bodies

    vals = output_values(run)
    groups = run.groups
    # (its bodies only turn: each is held rigidly, its bearing the sum of its meshes')
    bearings = bearing_bodies(run.structure, run.model)
    assert bearings == [b["body"] for b in run.bearing_forces()] and bearings
    assert set(vals) == set(available_outputs(run.mesh_names, groups, "run",
                                              bearings=bearings))
    for d in ("cycle_peak", "instantaneous", "engineering", "mean_force"):
        met = run.metrics(d)
        assert vals[f"load_sharing.{d}"] == met.load_sharing.system
        for g in groups:
            assert vals[f"load_sharing.{d}.{g}"] == met.load_sharing.per_group[g]
        for m in run.mesh_names:
            assert vals[f"load_sharing.{d}.{m}"] == met.load_sharing.per_mesh[m]
    met = run.metrics("cycle_peak")
    rows = {r.mesh: r for r in met.rows}
    for m in run.mesh_names:
        for name in ("peak_force", "min_force", "mean_force", "static_force",
                     "nominal_force", "dynamic_factor", "dynamic_factor_engineering",
                     "peak_to_nominal", "contact_loss", "back_contact"):
            assert vals[f"{name}.{m}"] == getattr(rows[m], name), (name, m)
        lo, mean, hi = (vals[f"{k}.{m}"] for k in ("min_force", "mean_force", "peak_force"))
        assert lo <= mean * (1 + 1e-12) and mean <= hi * (1 + 1e-12) and lo < hi
    d = met.dynamic_factors
    for g in groups:
        assert vals[f"peak_to_nominal_engineering.{g}"] == \
            d.per_group_peak_to_nominal_engineering[g]
        assert vals[f"dynamic_factor.{g}"] == d.per_group_dynamic_factor[g]
    assert vals["dynamic_factor"] == max(d.per_group_dynamic_factor.values())
    assert vals["settle_time"] == met.settling.start_time
    assert vals["load_sharing.cycle_peak"] > 1.01  # the 5 um error is felt


def test_only_the_definitions_asked_for(run):
    vals = output_values(run, ["engineering"])
    assert "load_sharing.engineering" in vals and "load_sharing.cycle_peak" not in vals
    with pytest.raises(ValueError, match="unknown load-sharing definition"):
        output_values(run, ["static_torque"])


def test_quasi_static_names(tmp_path):
    from model_texts import split_model, write_model

    res = quasi_static_load_sharing(write_model(tmp_path, split_model(error_a="5 um")),
                                    points_per_cycle=2)
    vals = output_values(res)
    met = res.metrics()
    assert vals["load_sharing.static_torque"] == met.system
    groups = met.groups
    assert set(vals) == set(available_outputs(res.mesh_names, groups, "static"))
    assert all(math.isfinite(v) for v in vals.values())


def test_patterns_and_families():
    names = available_outputs(["m1", "m2"], {"s": ["m1", "m2"]}, "run")
    chosen, missing = select_outputs(["load_sharing.engineering.*", "nope.*"], names)
    assert chosen == ["load_sharing.engineering.s", "load_sharing.engineering.m1",
                      "load_sharing.engineering.m2"]
    assert missing == ["nope.*"]
    assert definitions_needed(chosen + ["peak_force.m1"]) == ["engineering"]
    assert family("load_sharing.mean_force.O2/II") == ("load_sharing.mean_force", "O2/II")
    assert family("dynamic_factor") == ("dynamic_factor", "system")


def test_the_settle_rule_does_not_wait_for_settle_time(split_file):
    """settle_time moves with the run length by nature (80 -> 160 cycles here, while the
    load sharing does not change): asking for it must not lengthen the runs."""
    from study_helpers import grid_study
    from torquesplit.study import run_study

    runs = {}
    for outs in (["load_sharing.cycle_peak"], ["load_sharing.cycle_peak", "settle_time"]):
        data = grid_study(split_file, [{"path": "meshes.a1.transmission_error.constant",
                                        "values": ["4 um"]}], outputs=outs, cycles=640,
                          settle={"tolerance": 0.002, "start": "0.16 s"})
        ds = run_study(data, workers=1)
        runs[len(outs)] = float(ds["simulated_time"].values[0])
        assert ds["settled"].values[0] == 1
        assert "analysis.settle" in ds["settled"].attrs["long_name"]
    assert runs[1] == pytest.approx(0.32) and runs[2] == runs[1]


def test_bearing_forces_are_study_outputs_as_the_run_table_gives_them():
    """A study could vary a support clearance (Dong et al. 2021's question) but not read
    the bearing forces that the run's table prints."""
    import numpy as np

    from torquesplit.results import bearing_bodies
    from torquesplit.study import run_study

    res = torquesplit.simulate("ji_li_mill_drive", cycles=20)
    vals = output_values(res, ["engineering"])
    table = res.bearing_forces()
    assert [b["body"] for b in table] == ["z1", "z2", "z3", "z4", "z5", "z6"]
    for b in table:
        assert vals[f"bearing_mean_force.{b['body']}"] == b["mean_magnitude"]
        assert vals[f"bearing_peak_force.{b['body']}"] == b["peak_magnitude"]
    bodies = bearing_bodies(res.structure, res.model)
    promised = available_outputs(res.mesh_names, res.groups, "run", bearings=bodies)
    assert {n for n in vals if n.startswith("bearing")} == {
        n for n in promised if n.startswith("bearing")}
    # a spline-held floating member (no support of its own) is in both as well
    dong = torquesplit.simulate("dong2021_face_gear", duration=0.002)
    assert bearing_bodies(dong.structure, dong.model) == [
        b["body"] for b in dong.bearing_forces()]
    assert any(b["via"] for b in dong.bearing_forces())
    spec = {"study": {"name": "b", "model": "ji_li_mill_drive",
                      "outputs": ["bearing_peak_force.z2", "bearing_mean_force.*"]},
            "analysis": {"cycles": 20},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.1, 0.2]}]}}  # (0.1: the model's)
    ds = run_study(spec, workers=1)
    assert list(ds["status"].values) == ["ok", "ok"]
    assert ds["bearing_peak_force.z2"].attrs["units"] == "N"
    # the first case is the run above: the same history, the same table (the cases kept a
    # sparser history than the run's: their peaks came out lower)
    for b in table:
        assert ds[f"bearing_mean_force.{b['body']}"].values[0] == b["mean_magnitude"]
    z2 = [b for b in table if b["body"] == "z2"][0]
    assert ds["bearing_peak_force.z2"].values[0] == z2["peak_magnitude"]
    assert np.all(ds["bearing_peak_force.z2"].values >= ds["bearing_mean_force.z2"].values)
    bad = {**spec, "study": {**spec["study"], "outputs": ["bearing_peak_force.z9"]}}
    from torquesplit.study import StudyError

    with pytest.raises(StudyError, match="close: bearing_peak_force"):
        run_study(bad, workers=1)


def test_a_study_without_bearing_outputs_does_not_compute_them(run, monkeypatch):
    """The bearing forces come from the history (13 of a Dong et al. 2021 case's 17 ms
    of outputs); a study that asks for none skips them, and its values are the same."""
    from torquesplit.results import Results
    from torquesplit.study import run_study

    full = output_values(run)
    lean = output_values(run, bearings=False)
    assert {n for n in full if not n.startswith("bearing")} == set(lean)
    assert all(lean[n] == full[n] or (math.isnan(lean[n]) and math.isnan(full[n]))
               for n in lean)
    calls = []
    real = Results.bearing_forces
    monkeypatch.setattr(Results, "bearing_forces",
                        lambda self, *a, **k: calls.append(1) or real(self, *a, **k))
    spec = {"study": {"name": "b", "model": "ji_li_mill_drive",
                      "outputs": ["load_sharing.engineering"]},
            "analysis": {"cycles": 20},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.1]}]}}
    ds = run_study(spec, workers=1)
    assert list(ds["status"].values) == ["ok"] and not calls
    spec["study"]["outputs"] = ["load_sharing.engineering", "bearing_mean_force.z2"]
    ds2 = run_study(spec, workers=1)
    assert calls and ds2["load_sharing.engineering"].values[0] == \
        ds["load_sharing.engineering"].values[0]


def test_a_cases_times_count_the_code_generation_once(run):
    """A run's wall time includes the generation of its right-hand side; the case counts
    it as compilation, not integration too, so that wall - integration - compilation
    (the benchmark's per-case overhead) is what the case spent outside both."""
    from types import SimpleNamespace

    from torquesplit.study.case import _account

    st = run.statistics()
    stub = SimpleNamespace(statistics=lambda: {**st, "wall_time_s": 1.0,
                                               "rhs_compile_time_s": 0.3,
                                               "compile_time_s": 0.2})
    out = {"integration_time": 0.0, "compile_time": 0.0, "runs": 0}
    _account(stub, out)
    assert out["integration_time"] == pytest.approx(0.7)
    assert out["compile_time"] == pytest.approx(0.5)
    assert st["rhs_compile_time_s"] <= st["wall_time_s"]  # (inside the run's wall time)
