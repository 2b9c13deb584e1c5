"""Shared fixtures."""

from __future__ import annotations

import os

# the CLI's tables are as wide as $COLUMNS where output is no terminal (160 without it):
# the tests read them at that width whatever the shell (or pytest-xdist, which exports
# COLUMNS=80 to its workers) says
os.environ["COLUMNS"] = "160"

import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

import torquesplit  # noqa: E402
from model_texts import SPUR_PAIR, split_model, write_model  # noqa: E402

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
