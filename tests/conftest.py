"""Shared fixtures."""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

import torquesplit
from model_texts import SPUR_PAIR, split_model, write_model

# property-based tests draw the same examples on every run (a CI failure reproduces);
# HYPOTHESIS_PROFILE=explore searches afresh
settings.register_profile("ci", derandomize=True, database=None, deadline=None,
                          print_blob=True)
settings.register_profile("explore", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture
def spur_pair(tmp_path):
    return torquesplit.load_model(write_model(tmp_path, SPUR_PAIR))


@pytest.fixture
def split(tmp_path):
    return torquesplit.load_model(write_model(tmp_path, split_model()))
