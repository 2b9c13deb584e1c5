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


def test_remember_content_keys_on_values_not_objects():
    import numpy as np

    from torquesplit._memo import remember_content

    calls = []

    @remember_content(kept=2)
    def total(x, scale):
        calls.append(1)
        return float(np.sum(x)) * scale

    a = np.arange(4.0)
    assert total(a, 2.0) == 12.0
    assert total(a.copy(), 2.0) == 12.0  # another object, the same content
    assert len(calls) == 1
    assert total(a, 3.0) == 18.0  # another number
    assert total(a.astype(np.float32), 2.0) == 12.0  # another dtype: another key
    assert total(a.reshape(2, 2), 2.0) == 12.0  # another shape: another key
    assert len(calls) == 4
    b = a.copy()
    b[0] = 1.0
    assert total(b, 2.0) == 14.0
    assert len(total.cache) == 2  # the oldest dropped
    total(a, 2.0)  # (dropped: computed again)
    assert len(calls) == 6
