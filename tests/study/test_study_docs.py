"""docs/studies.md: its complete study examples check out against the shipped models."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from torquesplit.study import Study
from torquesplit.study.shipped import study_names

DOC = Path(__file__).resolve().parents[2] / "docs" / "studies.md"


def _blocks():
    text = DOC.read_text(encoding="utf-8")
    return [b for b in re.findall(r"```toml\n(.*?)```", text, re.S)]


def test_complete_examples_check_out():
    complete = [b for b in _blocks() if b.lstrip().startswith("[study]")]
    assert complete
    for block in complete:
        assert Study(tomllib.loads(block)).n_cases > 0


def test_fragments_are_valid_toml():
    for block in _blocks():
        tomllib.loads(block)


@pytest.mark.parametrize("name", study_names())
def test_every_shipped_study_is_documented(name):
    assert f"`{name}`" in DOC.read_text(encoding="utf-8")
