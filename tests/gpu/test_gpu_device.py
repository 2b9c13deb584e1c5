"""Checks that need NVIDIA's tools: PTX compilation (libNVVM, no device) and runs on a
CUDA device (skipped, with the reason, where there is none)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gpu_cases import engine, example_run, feature_runs
from torquesplit.gpu.compile import cuda_available, cuda_simulated, ptx
from torquesplit.gpu.ensemble import case_arrays, run_ensemble
from torquesplit.gpu.layout import build_group
from torquesplit.gpu.source import kernel_source
from torquesplit.results import Results
from torquesplit.study.outputs import output_values

_OK, _WHY = cuda_available()
DEVICE = _OK and not cuda_simulated()
needs_device = pytest.mark.skipif(not DEVICE, reason=f"no CUDA device: {_WHY}")


def _ptx_or_skip(src, binding="njit"):
    try:
        return ptx(src, binding=binding)
    except Exception as exc:  # noqa: BLE001 - no libNVVM / CUDA toolkit here
        name = type(exc).__name__
        if "Nvvm" in name or "CudaSupport" in name or "libNVVM" in str(exc):
            pytest.skip(f"no libNVVM to compile PTX: {name}: {exc}")
        raise


@pytest.mark.parametrize("binding", ["device", "njit"])
def test_kernel_compiles_to_ptx_without_a_device(binding):
    """Both ways the CUDA kernel binds the laws compile for sm_90 (the simulator types
    nothing: a broken binding would otherwise show only on a device, behind the other)."""
    run = feature_runs()[0]
    p = case_arrays(run)
    g = build_group([p.case], [0], np.float64)
    text = _ptx_or_skip(kernel_source(g, "fp64"), binding)
    assert ".entry" in text and ".target sm_90" in text
    assert "fma.rn.f64" in text or "mul.f64" in text


def _mismatches(i, sol, ref) -> list[str]:
    """Where a device Solution differs from the engine's by more than 1e-9 (every field;
    for per-cycle fields the first differing cycle and tracked element)."""
    out = []
    if sol.status != ref.status or sol.n_steps != ref.n_steps:
        return [f"run {i}: status/steps {sol.status}/{sol.n_steps} != {ref.status}/"
                f"{ref.n_steps}"]
    for f in ("cycle_max", "cycle_min", "cycle_mean", "cycle_ratio_max", "y_final"):
        a, b = np.asarray(getattr(sol, f)), np.asarray(getattr(ref, f))
        ok = np.isfinite(b)
        if not np.array_equal(np.isfinite(a), ok):
            out.append(f"run {i}: {f} finite at other places")
            continue
        scale = np.abs(b[ok]).max() if ok.any() else 0.0
        bad = ok & ~np.isclose(np.where(ok, a, 0.0), np.where(ok, b, 0.0), rtol=1e-9,
                               atol=1e-9 * scale)
        if bad.any():
            where = tuple(int(k) for k in np.argwhere(bad)[0])
            out.append(f"run {i}: {f} differs at {bad.sum()} places, first {where}: "
                       f"{a[where]!r} != {b[where]!r}")
    return out


#: run length of the synthetic feature runs on the device: their dynamics are sensitive
#: to rounding (discontinuous spline law, grazing contacts): over 12 ms the generated
#: code compiled for the CPU with FMA contraction, the GPU's rounding class, moves one
#: of them by 30 % and the H200 moved another's last cycle peaks by up to O(1); over
#: this length the FMA build agrees to 1e-12 (test_feature_runs_are_insensitive_...).
FEATURE_LENGTH = 2e-3
#: run 0 (every feature) leaves the engine on the H200 between 1 and 2 ms (1.8e-15 at
#: 1 ms, 2.9e-3 at 2 ms, O(1) by 6 ms), where a one-ulp change of any input moves it
#: by < 1e-14 on the CPU and the generated code agrees bit for bit compiled for the CPU
#: with garbage-filled scratch, with bounds checks, with the CUDA namespace's literal
#: constants, and in numba's CUDA simulator (FMA contraction: 1.2e-15; each tanh, sqrt,
#: sin or cos moved one ulp: < 5e-15): a GPU-only
#: difference not found yet (benchmarks/GPU_RESULTS.md, agreement; element 2's first
#: back-flank contact falls in that interval).  The device test runs it over 1 ms;
#: test_run0_over_2ms_on_the_device keeps the failure in view.
RUN0_LENGTH = 1e-3


def short_feature_runs():
    import dataclasses

    runs = [dataclasses.replace(r, duration=FEATURE_LENGTH) for r in feature_runs()]
    runs[0] = dataclasses.replace(runs[0], duration=RUN0_LENGTH)
    return runs


def test_feature_runs_are_insensitive_to_rounding_over_the_device_length():
    """The premise of the device test: compiled with FMA contraction (rounding as a GPU
    rounds), the generated code agrees with the engine to 1e-12 on the feature runs at
    the device test's length, so a larger device difference is an error, not rounding."""
    import functools

    from torquesplit.gpu import compile as comp
    from torquesplit.gpu import ensemble as ens

    fma_driver = functools.partial(comp.cpu_driver, contract=True)

    runs = short_feature_runs()
    saved = ens.cpu_driver
    try:
        ens.cpu_driver = fma_driver
        res = ens.run_ensemble(runs, target="cpu")
    finally:
        ens.cpu_driver = saved
    for i, (run, sol) in enumerate(zip(runs, res.solutions, strict=True)):
        ref = engine(run)
        assert sol.status == ref.status and sol.n_steps == ref.n_steps
        for f in ("cycle_max", "y_final"):
            a, b = np.asarray(getattr(sol, f)), np.asarray(getattr(ref, f))
            ok = np.isfinite(b)
            assert np.allclose(a[ok], b[ok], rtol=1e-12, atol=1e-12 * np.abs(b[ok]).max()), (
                i, f)


@pytest.mark.gpu
@needs_device
def test_gpu_equals_the_engine_to_1e_9():
    runs = short_feature_runs() + [example_run("ji_li_mill_drive", 5e-3)]
    res = run_ensemble(runs, target="cuda")
    problems = []
    for i, (run, sol) in enumerate(zip(runs, res.solutions, strict=True)):
        problems += _mismatches(i, sol, engine(run))
    run = runs[-1]

    def values(s):
        return output_values(Results(model=run.model, kinematics=run.kinematics,
                                     structure=run.structure, static=run.static, solution=s))

    a, b = values(res.solutions[-1]), values(engine(run))
    for k in b:
        if not ((math.isnan(a[k]) and math.isnan(b[k]))
                or abs(a[k] - b[k]) <= 1e-9 * max(abs(b[k]), 1.0)):
            problems.append(f"Ji & Li output {k}: {a[k]!r} != {b[k]!r}")
    assert not problems, "\n".join(problems)


@pytest.mark.gpu
@needs_device
@pytest.mark.xfail(strict=True, reason="GPU-only difference of feature run 0 between 1 and "
                   "2 ms (benchmarks/GPU_RESULTS.md, agreement): remove this mark once found")
def test_run0_over_2ms_on_the_device():
    import dataclasses

    run = dataclasses.replace(feature_runs()[0], duration=FEATURE_LENGTH)
    sol = run_ensemble([run], target="cuda").solutions[0]
    assert _mismatches(0, sol, engine(run)) == []
