"""Small studies on the two-path split test model (each case takes milliseconds)."""

from __future__ import annotations

import copy
from pathlib import Path

from model_texts import split_model, write_model

#: short runs: 40 cycles of the slowest mesh, enough to settle this damped model
CYCLES = 40


def model_file(tmp_path: Path, extra: str = "") -> Path:
    return write_model(tmp_path, split_model(extra=extra), "split.toml")


def grid_study(model: Path, parameters: list[dict], outputs=("load_sharing.cycle_peak*",),
               **analysis) -> dict:
    return {
        "study": {"name": "test grid", "model": str(model), "outputs": list(outputs)},
        "analysis": {"cycles": CYCLES, **analysis},
        "grid": {"parameters": copy.deepcopy(parameters)},
    }


def mc_study(model: Path, samples=24, seed=7, sampling="random", stop=None,
             outputs=("load_sharing.cycle_peak",)) -> dict:
    mc = {"sampling": sampling, "seed": seed, "parameters": [
        {"path": "meshes.a1.transmission_error.constant", "distribution": "normal",
         "mean": "0 um", "std": "3 um"},
        {"path": "meshes.b2.stiffness", "distribution": "uniform",
         "low": "3e8 N/m", "high": "5e8 N/m"},
    ]}
    if stop is None:
        mc["samples"] = samples
    else:
        mc["stop"] = stop
    return {"study": {"name": "test mc", "model": str(model), "outputs": list(outputs)},
            "analysis": {"cycles": CYCLES}, "monte_carlo": mc}
