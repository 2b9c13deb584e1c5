"""The in-process runner keeps the collector off the process's old objects during a
study, and gives them back however the study ends."""

from __future__ import annotations

import gc

import pytest

from torquesplit.study.runners import SerialRunner


@pytest.fixture(autouse=True)
def _nothing_frozen():
    gc.unfreeze()
    yield
    gc.unfreeze()


def test_the_heap_is_frozen_after_the_first_case_and_given_back_at_the_end():
    counts = []

    def case(p):
        counts.append(gc.get_freeze_count())
        return p * 2

    assert list(SerialRunner()(case, range(3))) == [0, 2, 4]
    assert counts[0] == 0 and counts[1] > 0 and counts[2] >= counts[1]
    assert gc.get_freeze_count() == 0


def test_a_study_that_stops_or_fails_gives_the_heap_back():
    it = SerialRunner()(lambda p: p, range(5))
    assert next(it) == 0 and next(it) == 1
    assert gc.get_freeze_count() > 0
    it.close()  # (the driver's Ctrl-C or error)
    assert gc.get_freeze_count() == 0

    def failing(p):
        if p == 2:
            raise RuntimeError("a bug")
        return p

    with pytest.raises(RuntimeError):
        list(SerialRunner()(failing, range(4)))
    assert gc.get_freeze_count() == 0


def test_a_process_that_froze_objects_itself_is_left_alone():
    gc.freeze()
    mine = gc.get_freeze_count()
    counts = []
    list(SerialRunner()(lambda p: counts.append(gc.get_freeze_count()), range(3)))
    assert counts == [mine] * 3 and gc.get_freeze_count() == mine
