"""A shooting speed sweep of a planetary stage reaches the end of its range.

The complement of the rigid subspace mixed displacements and velocities in some columns
(a QR of [R, I]); the continuation weights displacements and velocities apart, so a
velocity in a 'displacement' column counted omega T times too much, the arclength steps
hardly moved the speed, and the sweep stopped after 2000 points (a reviewer's 3-planet
stage, 1000-1100 rpm: stuck at 1028 rpm)."""

from __future__ import annotations

import warnings

import numpy as np
from test_turning_frame_speed import SMOOTH, _stage

import torquesplit
from torquesplit.steady.maps import sweep_speed
from torquesplit.steady.newton import complement, rigid_subspace
from torquesplit.steady.problem import PeriodicProblem


def test_the_complement_columns_are_pure_displacements_or_velocities():
    s = torquesplit.assemble(_stage("1000 rpm", SMOOTH))
    p = PeriodicProblem(s, 100.0)
    Q, R, n = complement(p), rigid_subspace(p), p.n
    assert Q.shape == (2 * n, 2 * n - R.shape[1])
    np.testing.assert_allclose(Q.T @ Q, np.eye(Q.shape[1]), atol=1e-12)
    np.testing.assert_allclose(R.T @ Q, 0.0, atol=1e-12)
    top, bottom = np.abs(Q[:n]).max(axis=0), np.abs(Q[n:]).max(axis=0)
    assert np.all(np.minimum(top, bottom) == 0.0)


def test_a_shooting_sweep_through_a_planetary_resonance_completes():
    rpm = np.pi / 30
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = sweep_speed(_stage("1000 rpm", SMOOTH), 1370 * rpm, 1380 * rpm, points=3,
                         method="shooting", stability=False)
    assert ds.attrs["complete"] == 1, ds.attrs["message"]
    assert ds.sizes["point"] < 1000
    assert ds.attrs["critical_speeds_rpm"] and 1370 < ds.attrs["critical_speeds_rpm"][0] < 1380
