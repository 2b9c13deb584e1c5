"""Fixtures of the study tests."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from study_helpers import model_file  # noqa: E402


@pytest.fixture
def split_file(tmp_path):
    return model_file(tmp_path)
