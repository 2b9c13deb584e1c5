"""The generated ensemble kernel compiled for the CPU equals the CPU engine.

The same source is what CUDA compiles (test_gpu_simulator.py runs it as CUDA in the
simulator; test_gpu_device.py on a device).  FP64 results are bit-identical to
:func:`torquesplit.solve.integrate.integrate`: every per-cycle statistic, contact
counter, the end state, step counts, status and message; and every study output of
every shipped example.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

import torquesplit
from gpu_cases import compare, engine, example_run, feature_runs
from torquesplit.errors import GpuUnavailableError, GpuUnsupportedError
from torquesplit.gpu.compile import cuda_available
from torquesplit.gpu.ensemble import run_ensemble
from torquesplit.results import Results
from torquesplit.study.outputs import output_values

_LENGTHS = {  # run lengths: about a hundred to a few hundred steps, table corners included
    "liu2021_split_torque_helicopter": 6e-4,
    "ji_li_mill_drive": 2e-3,
    "dong2021_face_gear": 1e-3,
    "jin2019_friction_split": 6e-4,
    "mo2017_star_reducer": 2e-3,
}
#: every shipped example (a new one is covered without editing this file)
EXAMPLES = {name: _LENGTHS.get(name, 1e-3) for name in torquesplit.example_names()}


def test_every_feature_equals_the_engine():
    runs = feature_runs()
    res = run_ensemble(runs, target="cpu")
    assert res.patterns == 2 and len(res.solutions) == 4
    for i, (run, sol) in enumerate(zip(runs, res.solutions, strict=True)):
        ref = engine(run)
        assert compare(sol, ref) == [], f"case {i}"
        assert sol.n_steps > (0 if i != 2 else -1)
    assert [s.status for s in res.solutions] == [0, 0, 1, 0]
    assert "diverged" in res.solutions[2].message
    # the two cases of one pattern really differ (per-case parameters, table sets)
    assert not np.array_equal(res.solutions[0].cycle_max, res.solutions[1].cycle_max,
                              equal_nan=True)
    assert res.sample_steps == sum(s.n_steps for s in res.solutions)
    # one case a launch (the outputs over the budget): each case's row, the same bits
    each = run_ensemble(runs, target="cpu", max_output_bytes=1)
    assert (res.launches, each.launches) == (2, 4)  # one a pattern; one a case
    assert [compare(a, b) for a, b in zip(each.solutions, res.solutions, strict=True)] == [
        []] * 4


@pytest.mark.skipif(not os.path.exists("/proc/meminfo"), reason="reads Linux's /proc/meminfo")
def test_the_output_budget_follows_the_memory_available():
    from torquesplit.gpu.ensemble import MIN_OUTPUT_BYTES, output_budget

    with open("/proc/meminfo") as f:
        avail = 1024 * int(next(ln for ln in f if ln.startswith("MemAvailable")).split()[1])
    assert MIN_OUTPUT_BYTES <= output_budget("cpu") <= max(avail // 4, MIN_OUTPUT_BYTES)
    assert output_budget("cpu") > avail // 8  # most of a quarter (the memory moves)


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_shipped_example_equals_the_engine(name):
    run = example_run(name, EXAMPLES[name])
    sol = run_ensemble([run], target="cpu").solutions[0]
    ref = engine(dict_free(run))
    assert compare(sol, ref) == []
    assert ref.n_steps > 50 and (ref.cycle_count > 0).any()

    def values(s):
        return output_values(Results(model=run.model, kinematics=run.kinematics,
                                     structure=run.structure, static=run.static,
                                     solution=s))

    from torquesplit.study.outputs import HISTORY_FAMILIES

    a, b = values(sol), values(ref)
    # the bearing forces come from the history, which a GPU run does not keep (a GPU
    # study refuses them by name: test_gpu_study)
    assert not any(k.split(".")[0] in HISTORY_FAMILIES for k in a)
    b = {k: v for k, v in b.items() if k.split(".")[0] not in HISTORY_FAMILIES}
    assert a.keys() == b.keys() and len(a) > 50
    for k in a:
        assert a[k] == b[k] or (math.isnan(a[k]) and math.isnan(b[k])), k


def dict_free(run):
    """The engine runs the same prepared run (histories are not compared)."""
    return run


def test_refuses_what_it_does_not_do():
    run = example_run("ji_li_mill_drive", 1e-3)
    from dataclasses import replace

    dopri = replace(run, integrate_kwargs={**run.integrate_kwargs, "method": "dopri"})
    with pytest.raises(GpuUnsupportedError, match="adaptive time stepping") as info:
        run_ensemble([dopri], target="cpu")
    assert "rk4" in str(info.value) and info.value.feature.startswith("adaptive")
    full = replace(run, integrate_kwargs={**run.integrate_kwargs, "full_history": True})
    with pytest.raises(GpuUnsupportedError, match="full state histories"):
        run_ensemble([full], target="cpu")
    # integrate options the kernel plans for itself were ignored without a word
    for extra, text in (({"step": 1e-6}, "step = 1e-06"), ({"blowup": 1e-9}, "blowup"),
                        ({"corners": False}, "corners = False"),
                        ({"max_steps": 10}, "max_steps = 10")):
        odd = replace(run, integrate_kwargs={**run.integrate_kwargs, **extra})
        with pytest.raises(GpuUnsupportedError, match=f"integrate options {text}"):
            run_ensemble([odd], target="cpu")
    with pytest.raises(ValueError, match="precision"):
        run_ensemble([run], target="cpu", precision="fp16")
    with pytest.raises(ValueError, match="target"):
        run_ensemble([run], target="tpu")


@pytest.mark.skipif(cuda_available()[0], reason="a CUDA device is present")
def test_no_device_is_said_clearly():
    run = example_run("ji_li_mill_drive", 1e-3)
    with pytest.raises(GpuUnavailableError, match="CPU backend") as info:
        run_ensemble([run], target="cuda")
    assert info.value.reason


def test_fp32_is_close_to_fp64_and_not_equal():
    run = example_run("ji_li_mill_drive", 2e-3)
    s64 = engine(run)
    s32 = run_ensemble([run], target="cpu", precision="fp32").solutions[0]
    assert s32.status == 0 and s32.n_steps == s64.n_steps
    m64, m32 = s64.cycle_max, s32.cycle_max
    ok = np.isfinite(m64)
    rel = np.abs(m32[ok] - m64[ok]) / np.abs(m64[ok])
    assert rel.max() < 1e-3  # single precision of the dynamics (measured ~1e-6)
    assert rel.max() > 0.0  # it really ran in single precision


def test_generator_knows_every_kernel_array_of_the_engine():
    """A field the engine's KernelModel gains is a term the generated code would miss:
    runs are refused until the generator makes it (this test fails to say so)."""
    from torquesplit.gpu.layout import KNOWN_FIELDS
    from torquesplit.solve.kernel_data import KernelModel

    assert tuple(KernelModel._fields) == KNOWN_FIELDS


def test_cases_that_share_tables_plan_the_kernel_model_of_their_own_structure():
    """The planner makes the tables' copies and corner nodes once per table object (a
    study's cases share them); a structure with the same table objects whose other
    corner inputs differ (here: an element that no longer varies) must still get exactly
    ``kernel_model`` of its own structure, field by field."""
    import dataclasses

    from torquesplit.gpu.ensemble import _kernel_model, case_arrays
    from torquesplit.solve import kernel_data as kd

    runs = feature_runs() + [example_run("ji_li_mill_drive", 1e-3)]
    s = runs[0].structure
    varied = dataclasses.replace(s, frequency=np.where(np.arange(len(s.frequency)) == 0,
                                                       0.0, s.frequency))
    shared = [r for r in runs if r.structure.stiffness_table is s.stiffness_table]
    assert len(shared) >= 2
    structures = [r.structure for r in runs] + [varied, s]
    for st in structures:  # (the engine's own, computed afresh: not its per-structure memo)
        want, got = kd.kernel_model.__wrapped__(st), _kernel_model(st)
        for f in want._fields:
            a, b = getattr(got, f), getattr(want, f)
            assert np.shape(a) == np.shape(b) and np.array_equal(a, b), f
    models = [case_arrays(r).case.model for r in shared[:2]]
    assert models[0].stiffness_table is models[1].stiffness_table


@pytest.mark.parametrize("example", ["jin2019_friction_split", "dong2021_face_gear"])
def test_the_planners_kernel_model_is_the_engines_and_goes_with_its_structure(example):
    """The kernel model takes the structure's tables as they are: a memo value that held
    one (or a view of the friction table) kept its own key alive, so a study's table
    sets were never released (tooth friction: 17 MB each).  A hit must still give the
    engine's kernel model, and neither may change the structure's tables (a spline
    component's stiffness row is zeroed in a copy)."""
    import gc

    import torquesplit
    from torquesplit.gpu import ensemble
    from torquesplit.solve import kernel_data as kd

    s = torquesplit.assemble(torquesplit.load_model(example))  # (a name is memoised)
    before = s.stiffness_table.copy()
    first, again, engine = ensemble._kernel_model(s), ensemble._kernel_model(s), \
        kd.kernel_model(s)
    for field in engine._fields:
        for m in (first, again):
            np.testing.assert_array_equal(getattr(m, field), getattr(engine, field), field)
    np.testing.assert_array_equal(s.stiffness_table, before)
    assert kd.kernel_model(s).force_table is s.force_table  # taken, not copied
    held = len(ensemble._KERNEL_TABLES)
    del s, first, again, engine, m  # (every kernel model holds the tables it takes)
    gc.collect()
    assert len(ensemble._KERNEL_TABLES) == held - 1


def test_a_memo_value_goes_with_its_arrays():
    """The planner's copies of a table set (29 MB for Ji & Li's drive) must not outlive
    the cases that use them."""
    import gc

    from torquesplit.gpu.layout import IdentityMemo

    memo = IdentityMemo()
    a, b = np.ones(3), np.zeros(3)
    assert memo.get((a, b), lambda: "v") == "v" and len(memo) == 1
    assert memo.get((a, b), lambda: "other") == "v"
    del a
    gc.collect()
    assert len(memo) == 0


def test_a_launch_copies_the_phase_tables_once_per_table_memory(monkeypatch):
    """Cases that share their table objects and differ in half-gaps (a backlash Monte
    Carlo) make one table set, its tables copied once (each case copied and hashed its
    12 MB of tables before); a case with other multi-value gap sequences makes a set of
    its own."""
    import dataclasses

    from torquesplit.gpu import layout
    from torquesplit.gpu.ensemble import case_arrays

    run = example_run("ji_li_mill_drive", 2e-3)
    s = run.structure
    runs = [dataclasses.replace(run, structure=dataclasses.replace(
        s, gap_values=s.gap_values * f)) for f in (1.0, 1.1, 1.2)]
    calls = []
    phase = layout._phase_tables
    monkeypatch.setattr(layout, "_phase_tables", lambda L, m: calls.append(1) or phase(L, m))
    cases = [case_arrays(r).case for r in runs]
    g = layout.build_group(cases, [0, 1, 2], np.float64)
    assert len(calls) == 1 and g.TK.shape[0] == 1 and g.columns[("tset",)] == ("lit", 0)
    assert sum(1 for k, v in g.columns.items() if k[0] == "G0" and v[0] == "P") > 0
    # multi-value gap sequences (the feature runs' pattern a): one set per sequence
    a, a2 = feature_runs()[:2]
    b = dataclasses.replace(a, structure=dataclasses.replace(
        a.structure, gap_values=a.structure.gap_values * 0.5))
    calls.clear()
    cs = [case_arrays(r).case for r in (a, b, a)]
    g = layout.build_group(cs, [0, 1, 2], np.float64)
    assert len(calls) == 1 and g.TK.shape[0] == 2
    assert g.PI[g.columns[("tset",)][1]].tolist() == [0, 1, 0]
