"""The papers' studies as study files (package data), one file per figure or section.

``torquesplit study --list`` lists them; ``torquesplit study NAME`` runs one.  Each file
names its paper, figure and the ranges it takes from the text, and says where a range is
not printed and had to be assumed.
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path


def study_names() -> list[str]:
    """Names of the shipped study files."""
    files = resources.files(__name__)
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def study_path(name: str) -> Path:
    """Path of a shipped study file."""
    name = name.removesuffix(".toml")
    path = Path(str(resources.files(__name__) / f"{name}.toml"))
    if not path.exists():
        raise FileNotFoundError(
            f"no shipped study named {name!r}; available: {', '.join(study_names())}")
    return path


def study_info(name: str) -> dict:
    """The [study] table (name, description, reference, model) of a shipped study."""
    data = tomllib.loads(study_path(name).read_text(encoding="utf-8"))
    return data.get("study", {})
