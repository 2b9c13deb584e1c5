"""The GPU backend as a study runner: same store, same Dataset, same values.

The runner is :class:`torquesplit.gpu.backend.GpuRunner` with ``target="cpu"`` (the
generated CUDA source compiled for the CPU), so that these tests need no device; the
CUDA path itself is tested in the simulator and on a device (test_gpu_simulator.py,
test_gpu_device.py)."""

from __future__ import annotations

import json
import sys
import warnings

import numpy as np
import pytest

import torquesplit
from torquesplit.errors import GpuFallbackWarning, GpuUnsupportedError
from torquesplit.gpu.backend import GpuRunner, check_plan
from torquesplit.gpu.compile import cuda_available
from torquesplit.study.errors import StudyError

GRID = {"study": {"name": "gpu_grid", "model": "ji_li_mill_drive",
                  "outputs": ["load_sharing.*", "dynamic_factor*", "peak_force.*",
                              "contact_loss.*", "settle_time"]},
        "analysis": {"duration": "0.12 s"},
        "grid": {"parameters": [
            {"path": "meshes.m11.damping_ratio", "values": [0.05, 0.12]},
            {"path": "meshes.m12.backlash", "values": ["0.3 mm", "0.9 mm"]}]}}

TIMING = ("case_wall_time", "case_integration_time", "case_compile_time")


def _same(ds_a, ds_b):
    for v in ds_a.data_vars:
        if v in TIMING:
            continue
        a, b = ds_a[v].values, ds_b[v].values
        if a.dtype.kind == "f":
            assert np.array_equal(a, b, equal_nan=True), v
        else:
            assert np.array_equal(a, b), v


def test_gpu_runner_gives_the_cpu_runners_dataset(tmp_path):
    ds_cpu = torquesplit.run_study(GRID, workers=1)
    runner = GpuRunner(target="cpu", batch=3)  # two batches: 3 + 1 cases
    ds_gpu = torquesplit.Study(GRID).run(runner=runner, out=tmp_path / "g", figures=False)
    _same(ds_cpu, ds_gpu)
    assert set(ds_gpu["status"].values.ravel()) == {"ok"}
    report = json.loads(ds_gpu.attrs["gpu_backend"])
    assert report["cases"] == 4 and report["ensembles"] == 2
    assert report["sample_steps"] > 0 and report["precision"] == "fp64"
    # the store is the CPU runner's: resume finds every case finished
    again = torquesplit.Study(GRID).run(runner=GpuRunner(target="cpu"), out=tmp_path / "g",
                                        resume=True, figures=False)
    _same(ds_cpu, again)


def test_one_launch_holds_every_case_the_table_budget_allows(monkeypatch):
    """Cases are set up in chunks (FIRST_BATCH, then doubling) and launched together: a
    GPU runs a launch's cases side by side, so a study of shared tables is one launch
    (it was a first launch of FIRST_BATCH and then more); where the tables' memory a
    case leaves room for FIRST_BATCH cases only, launches of FIRST_BATCH."""
    from torquesplit.gpu import backend

    spec = {**GRID, "analysis": {"duration": "0.05 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.04, 0.06, 0.08, 0.1, 0.12]}]}}
    monkeypatch.setattr(backend, "FIRST_BATCH", 2)
    chunks = []
    prepare = GpuRunner._prepare

    def counted(self, jobs, first, meanwhile=None):
        chunks.append((len(jobs), first))
        return prepare(self, jobs, first, meanwhile)

    monkeypatch.setattr(GpuRunner, "_prepare", counted)
    one = GpuRunner(target="cpu")
    ds_one = torquesplit.Study(spec).run(runner=one)
    assert chunks == [(2, True), (2, True), (1, True)]
    assert one.report["ensembles"] == 1 and one.report["cases"] == 5
    assert one.report["launches"] == 1
    monkeypatch.setattr(backend, "TABLE_BUDGET", 0)  # room for FIRST_BATCH cases only
    chunks.clear()
    small = GpuRunner(target="cpu")
    _same(ds_one, torquesplit.Study(spec).run(runner=small))
    assert chunks == [(2, True), (2, True), (1, True)]
    assert small.report["ensembles"] == 3


def test_settle_rule_runs_in_rounds_as_the_cpu_runner():
    spec = {**GRID, "analysis": {"duration": "0.3 s",
                                 "settle": {"tolerance": 0.2, "start": "0.08 s"}}}
    spec["grid"] = {"parameters": [{"path": "meshes.m11.damping_ratio",
                                    "values": [0.05, 0.12]}]}
    ds_cpu = torquesplit.run_study(spec, workers=1)
    runner = GpuRunner(target="cpu")
    ds_gpu = torquesplit.Study(spec).run(runner=runner)
    _same(ds_cpu, ds_gpu)
    # rounds: 0.08 s, 0.16 s, then the cap 0.3 s, every case in each round's ensemble
    assert runner.report["ensembles"] == 3 and runner.report["cases"] == 6
    assert (ds_gpu["simulated_time"].values == 0.3).all()


def test_fp32_reports_its_error_per_output():
    # (a settle rule: each case runs in rounds, each round's run checked against FP64)
    spec = {**GRID, "analysis": {"duration": "0.3 s",
                                 "settle": {"tolerance": 0.2, "start": "0.08 s"}},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.05, 0.12]}]}}
    runner = GpuRunner(target="cpu", precision="fp32", check_cases=4)
    ds = torquesplit.Study(spec).run(runner=runner)
    err = json.loads(ds.attrs["gpu_backend"])["fp32_error"]
    assert set(err) <= set(ds.attrs["outputs"] and json.loads(ds.attrs["outputs"]))
    assert "load_sharing.engineering" in err and len(err) > 10
    # (the settle time moves by whole windows where FP32's rounding, ~1e-3 of a peak,
    # exceeds the settle rule's start tolerance, 1e-4 of it: not a continuous output)
    worst = max(e["rel"] for k, e in err.items() if k != "settle_time")
    assert 0.0 < worst < 1e-2
    # what a difference cannot say is counted: outputs finite in one precision only,
    # runs that failed in FP32 only; cases counted once over the settle rule's rounds
    assert all(e["one_finite"] == 0 for e in err.values())
    report = json.loads(ds.attrs["gpu_backend"])
    assert report.get("fp32_failed", 0) == 0
    assert report["fp32_checked"] == 2 and report["fp32_runs_checked"] == 4


def test_refused_by_name_before_any_case_runs():
    static = {"study": {"name": "s", "model": "mo2017_star_reducer",
                        "outputs": ["load_sharing.static_torque"]},
              "analysis": {"type": "static", "points_per_cycle": 2},
              "grid": {"parameters": [{"path": "gears.s1.errors.eccentricity",
                                       "values": ["1 um", "2 um"]}]}}
    with pytest.raises(GpuUnsupportedError, match="quasi-static"):
        torquesplit.Study(static).run(backend="gpu")
    dopri = {**GRID, "analysis": {"duration": "0.05 s", "method": "dopri"}}
    with pytest.raises(GpuUnsupportedError, match="adaptive time stepping"):
        check_plan(torquesplit.Study(dopri).plan())
    bearings = {**GRID, "study": {**GRID["study"], "outputs": ["bearing_peak_force.*"]}}
    with pytest.raises(GpuUnsupportedError, match="read from the history.*keeps none"):
        check_plan(torquesplit.Study(bearings).plan())
    # a GPU runner given as the study's runner refuses the same (it ran a static study
    # as a dynamic one, its outputs NaN and "ok")
    with pytest.raises(GpuUnsupportedError, match="quasi-static"):
        torquesplit.Study(static).run(runner=GpuRunner(target="cpu"))
    with pytest.raises(GpuUnsupportedError, match="read from the history"):
        torquesplit.Study(bearings).run(runner=GpuRunner(target="cpu"))
    with pytest.raises(StudyError, match="GPU backend only"):
        torquesplit.Study(GRID).run(precision="fp32")
    with pytest.raises(StudyError, match="unknown backend"):
        torquesplit.Study(GRID).run(backend="tpu")
    with pytest.raises(StudyError, match="scheduler"):
        torquesplit.Study(GRID).run(backend="gpu", scheduler="tcp://127.0.0.1:1")


@pytest.mark.skipif(cuda_available()[0], reason="a CUDA device is present")
def test_without_a_device_the_cpu_runner_runs_it_with_a_warning():
    spec = {**GRID, "analysis": {"duration": "0.03 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio", "values": [0.1]}]}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = torquesplit.Study(spec).run(backend="gpu", workers=1)
    msgs = [str(w.message) for w in caught if issubclass(w.category, GpuFallbackWarning)]
    assert msgs and "CPU runner" in msgs[0] and "no CUDA device" in msgs[0]
    assert "gpu_backend" not in ds.attrs
    # the results say so too (only the command line did)
    assert "no CUDA device" in ds.attrs["backend_fallback"]
    assert "CPU runner" in ds.attrs["backend_fallback"]
    _same(torquesplit.run_study(spec, workers=1), ds)


def test_cli_refuses_and_falls_back_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from torquesplit.cli import app

    cli = CliRunner()
    res = cli.invoke(app, ["sweep", "mo2017_star_reducer", "--static", "--vary",
                           "gears.s1.errors.eccentricity=1:2:2um", "--backend", "gpu",
                           "--quiet", "--no-figures", "--out", str(tmp_path / "s")])
    assert res.exit_code == 2
    assert "does not support quasi-static" in res.output
    # refused before a note that it would fall back (the two read as a contradiction)
    assert "running on the CPU runner" not in res.output
    res = cli.invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                           "meshes.m11.damping_ratio=0.05:0.1:2", "--duration", "0.01 s",
                           "--precision", "fp32", "--quiet", "--no-figures", "--out",
                           str(tmp_path / "p")])
    assert res.exit_code == 2 and "GPU backend only" in res.output
    if not cuda_available()[0]:
        res = cli.invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                               "meshes.m11.damping_ratio=0.05:0.1:2", "--duration", "0.01 s",
                               "--backend", "gpu", "--workers", "1", "--quiet",
                               "--no-figures", "--out", str(tmp_path / "f")])
        assert res.exit_code == 0, res.output
        assert res.output.count("running on the CPU runner") == 1
        res = cli.invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                               "meshes.m11.damping_ratio=0.05:0.1:2", "--duration", "0.01 s",
                               "--backend", "gpu", "--precision", "fp32", "--workers", "1",
                               "--quiet", "--no-figures", "--out", str(tmp_path / "f32")])
        assert res.exit_code == 0, res.output
        assert "in FP64: --precision fp32 applies to the GPU backend only" in res.output


def test_a_case_the_study_makes_invalid_is_refused_as_on_the_cpu():
    spec = {"study": {"name": "bad", "model": "ji_li_mill_drive",
                      "outputs": ["load_sharing.engineering"]},
            "analysis": {"duration": "0.01 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.1, -0.5]}]}}
    ds_cpu = torquesplit.run_study(spec, workers=1)
    ds_gpu = torquesplit.Study(spec).run(runner=GpuRunner(target="cpu"))
    assert list(ds_gpu["status"].values) == ["ok", "refused"]
    assert "must not be negative" in str(ds_gpu["reason"].values[1])
    _same(ds_cpu, ds_gpu)


def test_cases_set_up_in_worker_processes_give_the_same_dataset():
    spec = {**GRID, "analysis": {"duration": "0.02 s"}}
    ds_one = torquesplit.Study(spec).run(runner=GpuRunner(target="cpu"))
    runner = GpuRunner(target="cpu", workers=2)
    ds_two = torquesplit.Study(spec).run(runner=runner)
    _same(ds_one, ds_two)
    assert runner._pool is None  # shut down when the study ends
    with pytest.raises(ValueError, match="workers"):
        GpuRunner(workers=0)


def test_the_kernel_compiles_while_workers_set_up_the_next_cases(monkeypatch):
    """With set-up workers, the kernel of the first chunk compiles while the workers
    set up the next chunk; a Monte Carlo's launch then runs the source compiled ahead
    (the same generated text), with the values of a runner that compiles at launch."""
    from torquesplit.gpu import backend, compile as comp, ensemble

    spec = {**GRID, "analysis": {"duration": "0.02 s"}}
    del spec["grid"]
    spec["monte_carlo"] = {"samples": 5, "seed": 3, "sampling": "random", "parameters": [
        {"paths": ["meshes.*.backlash"], "distribution": "uniform", "low": "0.3 mm",
         "high": "0.9 mm"},
        {"paths": ["meshes.*.damping_ratio"], "distribution": "uniform", "low": 0.05,
         "high": 0.15}]}
    monkeypatch.setattr(backend, "FIRST_BATCH", 2)
    texts = []
    driver = comp.cpu_driver
    monkeypatch.setattr(ensemble, "cpu_driver", lambda src, **kw: texts.append(src.text)
                        or driver(src, **kw))
    runner = GpuRunner(target="cpu", workers=2)
    seen = []
    ds = torquesplit.Study(spec).run(runner=runner, progress=seen.append)
    assert runner.report["compile_ahead_s"] > 0 and runner.report["ensembles"] == 1
    # the progress callback hears what the runner does before the launch's cases finish
    stages = [p.stage for p in seen if p.stage]
    assert stages == ["2 cases set up for the next launch",
                      "compiling the kernel while the next cases are set up (once a model "
                      "pattern: about 20 s for a 14-DOF model)",
                      "4 cases set up for the next launch", "5 cases set up for the next "
                      "launch", "running 5 cases together (generated code, CPU)",
                      "the outputs of 5 cases"]
    assert all(p.done == 0 for p in seen if p.stage) and seen[-1].done == 5
    assert len(texts) == 2 and texts[0] == texts[1]  # ahead (2 cases), launch (5)
    _same(torquesplit.Study(spec).run(runner=GpuRunner(target="cpu")), ds)


def test_workers_send_a_table_set_once_and_the_cases_share_it(monkeypatch):
    """Ji & Li's cases carry 14 MB of phase tables each; a pool worker sends a table set
    the first time and then runs without it, and the runner puts the one set back: every
    case then holds the same object, bit for bit the tables it would have had."""
    from collections import OrderedDict

    from torquesplit.gpu import backend
    from torquesplit.gpu.backend import TABLES, _Job, prepare_case
    from torquesplit.study.case import payload

    monkeypatch.setattr(backend, "_SENT", OrderedDict())  # this process as a fresh worker

    spec = {**GRID, "analysis": {"duration": "0.01 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.05, 0.07, 0.09, 0.11, 0.13, 0.15]}]}}
    plan = torquesplit.Study(spec).plan()
    ps = [payload(i, plan, plan.design.overrides(i)) for i in range(6)]
    runner = GpuRunner(target="cpu", workers=2)
    jobs = [_Job(p, "w") for p in ps]
    try:
        runner._prepare(jobs, True)
    finally:
        runner._pool.shutdown()
    assert len(runner._tables) == 1
    fresh = prepare_case(ps[-1])["run"].structure
    for name in TABLES:
        objs = {id(getattr(j.run.structure, name)) for j in jobs}
        assert len(objs) == 1, name
        assert np.array_equal(getattr(jobs[-1].run.structure, name), getattr(fresh, name))
    # a worker that has sent the set sends the next case without it
    first = prepare_case(ps[0], worker=True)
    again = prepare_case(ps[1], worker=True)
    assert not first.get("tables_stripped") and again["tables_stripped"]
    assert again["tables"] == first["tables"]
    assert again["run"].structure.stiffness_table.size == 0


def test_a_device_whose_toolchain_cannot_compile_falls_back_with_the_reason(monkeypatch):
    """Seen on an H200 machine: the driver sees the device, but numba-cuda cannot compile
    (its typing registry needs ``np.row_stack``, gone in numpy 2.5).  The study must fall
    back to the CPU runner naming that, not stop with a traceback in the kernel launch."""
    from types import SimpleNamespace

    from numba import cuda

    import torquesplit.gpu.compile as compile_mod
    from torquesplit.gpu.backend import make_gpu_runner

    def broken_jit(*args, **kwargs):
        raise AttributeError("module 'numpy' has no attribute 'row_stack'")

    monkeypatch.setattr(cuda, "is_available", lambda: True)
    monkeypatch.setattr(cuda, "get_current_device", lambda: SimpleNamespace(name=b"Fake GPU"))
    monkeypatch.setattr(cuda, "jit", broken_jit)
    monkeypatch.setattr(compile_mod, "_PROBE", {})
    ok, why = compile_mod.cuda_available()
    assert not ok
    assert why.startswith("Fake GPU: numba-cuda cannot compile") and "row_stack" in why
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert make_gpu_runner() is None
    msgs = [str(w.message) for w in caught if issubclass(w.category, GpuFallbackWarning)]
    assert msgs and "row_stack" in msgs[0] and "CPU runner" in msgs[0]


def test_batches_shrink_where_every_case_has_its_own_tables():
    """A stiffness Monte Carlo gives every case its own 14 MB table set (three copies on
    the host): the batch is sized to TABLE_BUDGET, after a first batch of FIRST_BATCH."""
    from torquesplit.gpu import backend
    from torquesplit.gpu.backend import FIRST_BATCH, TABLE_BUDGET

    runner = GpuRunner(target="cpu")
    assert runner._next_size() == runner.batch  # nothing measured: the full batch
    runner._case_bytes = 3 * 14.7e6 / 4  # four cases to a set
    assert runner._next_size() == int(TABLE_BUDGET // runner._case_bytes) == 194
    runner._case_bytes = 1e12
    assert runner._next_size() == FIRST_BATCH
    runner._case_bytes = 3 * 14.7e6 / 1000  # one set shared by a thousand cases
    assert runner._next_size() == runner.batch
    kept = backend.OrderedDict()
    for k in range(40):
        backend._remember(kept, f"set{k}", k)
    assert list(kept) == [f"set{k}" for k in range(40 - backend.RUNNER_SETS, 40)]
    assert backend.WORKER_SETS < backend.RUNNER_SETS  # a worker strips only what we keep


def test_stripped_cases_get_their_set_back_however_many_sets_a_batch_has(monkeypatch):
    """More distinct table sets in one batch than the runner keeps for later batches:
    every stripped case still gets the set its worker sent earlier in the batch (none is
    set up again in the runner)."""
    import dataclasses

    from torquesplit.gpu import backend

    template = backend.prepare_case(_payloads(1)[0])["run"]

    def run_with(k):
        tabs = tuple(np.full((2, 4), float(k)) for _ in backend.TABLES)
        return backend._with_tables(template, tabs)

    def boom(*a, **kw):
        raise AssertionError("a stripped case was set up again")

    monkeypatch.setattr(backend, "prepare_case", boom)
    n = backend.RUNNER_SETS + 8
    empty = tuple(np.zeros((0, 0)) for _ in backend.TABLES)
    results = ([{"run": run_with(k), "tables": f"k{k}"} for k in range(n)]
               + [{"run": backend._with_tables(template, empty), "tables": f"k{k}",
                   "tables_stripped": True} for k in range(n)])
    runner = GpuRunner(target="cpu")
    runner._attach_tables(results, [(None, None)] * len(results))
    for k in range(n):
        sent, back = results[k]["run"].structure, results[n + k]["run"].structure
        assert back.stiffness_table is sent.stiffness_table, k
    assert len(runner._tables) == backend.RUNNER_SETS
    assert dataclasses.is_dataclass(results[-1]["run"])


def test_a_worker_hashes_a_table_set_once(monkeypatch):
    """A worker holds the sets it sent: the next case with equal tables shares them, and
    their 14.7 MB digest is not computed again."""
    from collections import OrderedDict

    from torquesplit.gpu import backend

    monkeypatch.setattr(backend, "_SENT", OrderedDict())
    calls = []
    real = backend.hashlib.blake2b

    def counting(*a, **kw):  # (the backend's digests only: the static solver has its own)
        if sys._getframe(1).f_globals.get("__name__") == backend.__name__:
            calls.append(1)
        return real(*a, **kw)

    monkeypatch.setattr(backend.hashlib, "blake2b", counting)
    import gc

    stripped = []
    for p in _payloads(3):  # each result leaves the worker (nothing of it kept here)
        stripped.append(backend.prepare_case(p, worker=True).get("tables_stripped", False))
        gc.collect()
    assert len(calls) == 1
    assert stripped == [False, True, True]


def _payloads(n):
    from torquesplit.study.case import payload

    spec = {**GRID, "analysis": {"duration": "0.01 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio",
                                     "values": [0.05 + 0.01 * k for k in range(n)]}]}}
    plan = torquesplit.Study(spec).plan()
    return [payload(i, plan, plan.design.overrides(i)) for i in range(n)]
