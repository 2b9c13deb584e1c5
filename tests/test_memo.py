"""remember_last: one result per live frozen object, warnings given on every call."""

from __future__ import annotations

import gc
import warnings

import pytest

from torquesplit._memo import remember_last


class _Frozen:
    pass


def test_the_last_result_is_kept_and_its_warnings_repeat():
    calls = []

    @remember_last
    def work(obj, k):
        calls.append(k)
        warnings.warn(f"note {k}", UserWarning)
        return [k]

    a, b = _Frozen(), _Frozen()
    with pytest.warns(UserWarning, match="note 1"):
        first = work(a, 1)
    with pytest.warns(UserWarning, match="note 1"):
        assert work(a, 1) is first
    assert calls == [1]
    with pytest.warns(UserWarning, match="note 2"):
        work(a, 2)  # other arguments
    with pytest.warns(UserWarning, match="note 2"):
        work(b, 2)  # another object
    assert calls == [1, 2, 2]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        del a, b
        gc.collect()
        c = _Frozen()
        work(c, 2)  # a new object, even at a reused address, is computed afresh
    assert calls == [1, 2, 2, 2]


def test_an_error_is_not_kept():
    calls = []

    @remember_last
    def fails(obj):
        calls.append(1)
        raise ValueError("no")

    x = _Frozen()
    for _ in range(2):
        with pytest.raises(ValueError):
            fails(x)
    assert len(calls) == 2
