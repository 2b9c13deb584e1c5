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


def _ptx_or_skip(src):
    try:
        return ptx(src)
    except Exception as exc:  # noqa: BLE001 - no libNVVM / CUDA toolkit here
        name = type(exc).__name__
        if "Nvvm" in name or "CudaSupport" in name or "libNVVM" in str(exc):
            pytest.skip(f"no libNVVM to compile PTX: {name}: {exc}")
        raise


def test_kernel_compiles_to_ptx_without_a_device():
    run = feature_runs()[0]
    p = case_arrays(run)
    g = build_group([p.case], [0], np.float64)
    text = _ptx_or_skip(kernel_source(g, "fp64"))
    assert ".entry" in text and ".target sm_90" in text
    assert "fma.rn.f64" in text or "mul.f64" in text


@pytest.mark.gpu
@needs_device
def test_gpu_equals_the_engine_to_1e_9():
    runs = feature_runs() + [example_run("ji_li_mill_drive", 5e-3)]
    res = run_ensemble(runs, target="cuda")
    for run, sol in zip(runs, res.solutions, strict=True):
        ref = engine(run)
        assert sol.status == ref.status and sol.n_steps == ref.n_steps
        for f in ("cycle_max", "cycle_min", "cycle_mean", "cycle_ratio_max", "y_final"):
            a, b = getattr(sol, f), getattr(ref, f)
            ok = np.isfinite(b)
            assert np.array_equal(np.isfinite(a), ok), f
            assert np.allclose(a[ok], b[ok], rtol=1e-9, atol=1e-9 * np.abs(b[ok]).max()), f
    run = runs[-1]

    def values(s):
        return output_values(Results(model=run.model, kinematics=run.kinematics,
                                     structure=run.structure, static=run.static, solution=s))

    a, b = values(res.solutions[-1]), values(engine(run))
    for k in b:
        assert (math.isnan(a[k]) and math.isnan(b[k])) or abs(a[k] - b[k]) <= 1e-9 * max(
            abs(b[k]), 1.0), k
