"""The five seed gearboxes as model files (package data), one per paper.

==========================  ===========================================================
name                        system (paper)
==========================  ===========================================================
seed000_split_torque        two-input split-torque helicopter reducer (seed 000)
seed001_mill_drive          heavy industrial helical split drive, grinding mill (seed 001)
seed002_face_gear           face-gear dual-power split helicopter drive (seed 002)
seed003_friction_split      double-input split-torque drive, herringbone stage (seed 003)
seed004_star_reducer        two-stage external-mesh star reducer, 3 paths (seed 004)
==========================  ===========================================================
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path


def example_names() -> list[str]:
    """Names of the shipped example models."""
    files = resources.files(__name__)
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def example_path(name: str) -> Path:
    """Path of a shipped example model file."""
    name = name.removesuffix(".toml")
    path = Path(str(resources.files(__name__) / f"{name}.toml"))
    if not path.exists():
        raise FileNotFoundError(
            f"no example named {name!r}; available: {', '.join(example_names())}")
    return path


def example_info(name: str) -> dict:
    """The [model] section (name, description, reference) of an example."""
    data = tomllib.loads(example_path(name).read_text(encoding="utf-8"))
    return data.get("model", {})
