"""Shared fixtures."""

from __future__ import annotations

import pytest

import torquesplit
from model_texts import SPUR_PAIR, split_model, write_model


@pytest.fixture
def spur_pair(tmp_path):
    return torquesplit.load_model(write_model(tmp_path, SPUR_PAIR))


@pytest.fixture
def split(tmp_path):
    return torquesplit.load_model(write_model(tmp_path, split_model()))
