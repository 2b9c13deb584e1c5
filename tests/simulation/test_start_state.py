"""A run starts from the static equilibrium under the excitation at t = 0, not from the
mean-stiffness one: at rest there, so no start-up swing about the instantaneous
equilibrium (the eccentricity of a gear, a mesh's stiffness at its phase)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import torquesplit as ts
from torquesplit.simulation import prepare_run
from torquesplit.solve.reference import rhs_numpy
from torquesplit.solve.static import static_equilibrium

from ..model_texts import SPUR_PAIR, write_model

_AT = 'position = ["0 mm", "0 mm", "0 mm"]'
ECCENTRIC = SPUR_PAIR.replace(_AT, _AT + '''

[gears.pinion.errors]
eccentricity = "20 um"
eccentricity_phase = "90 deg"''').replace('damping_ratio = 0.05', 'damping_ratio = 0.02')


def _accelerations(structure, y):
    n = structure.n_dof
    return np.abs(rhs_numpy(structure, 0.0, y)[n:] / structure.inv_mass).max()


def test_run_starts_in_equilibrium_at_t0(tmp_path):
    run = prepare_run(write_model(tmp_path, ECCENTRIC), cycles=5)
    n = run.structure.n_dof
    assert run.start == "t0"
    np.testing.assert_array_equal(run.y0[:n], static_equilibrium(run.structure, 0.0).q)
    assert not np.any(run.y0[n:])
    # at rest: what is left of the net force at t = 0 is the mesh damping's response to
    # the error's rate (the static solve has no damping), 0.02 N m; at the mean-stiffness
    # equilibrium the eccentricity's 20 um x 4e8 N/m is unbalanced (283 N m)
    mean = np.concatenate([run.static.q, np.zeros(n)])
    assert _accelerations(run.structure, run.y0) < 1e-3 * _accelerations(run.structure,
                                                                         mean)
    # the nominal (mean-stiffness) forces are still the mean equilibrium's
    assert run.static.t is None


def test_no_start_up_swing_about_the_instantaneous_equilibrium(tmp_path):
    """The first mesh cycles follow the quasi-static force: a light damping ratio keeps a
    start-up swing alive for many cycles, so the first cycles' peak would show it."""
    res = ts.simulate(write_model(tmp_path, ECCENTRIC), cycles=40)
    peaks = res.complete_cycle_statistics()[0][:, 0]
    peaks = peaks[np.isfinite(peaks)]
    # steady response: the eccentricity turns once per 20 mesh cycles; compare the first
    # five cycles with the same phase one error period later
    first, later = peaks[:5], peaks[20:25]
    # (t = 0 start: 2.2e-3 in the first cycle, the damping of the error's rate; the
    # mean-stiffness start: 0.34)
    assert np.abs(first - later).max() < 5e-3 * np.abs(later).max()


def test_falls_back_to_the_mean_equilibrium_when_the_t0_solve_fails(tmp_path, monkeypatch):
    import torquesplit.solve.static as static_mod
    from torquesplit.errors import ModelWarning, SolverError

    real = static_mod.static_equilibrium

    def failing(structure, t=None, **kw):
        if t is not None:
            raise SolverError("a DOF has no support (made up)")
        return real(structure, t, **kw)

    monkeypatch.setattr(static_mod, "static_equilibrium", failing)
    with pytest.warns(ModelWarning, match=r"the static equilibrium at t = 0 could not start "
                                          r"the run \(it failed \(a DOF has no support"):
        run = prepare_run(write_model(tmp_path, ECCENTRIC), cycles=5)
    assert run.start == "mean"
    np.testing.assert_array_equal(run.y0[:run.structure.n_dof], run.static.q)


def test_a_t0_solve_that_does_not_converge_exactly_still_starts_the_run(tmp_path,
                                                                         monkeypatch):
    """Not converged exactly (a member floating in its clearance) is the regularised
    solution at t = 0: the run starts there, and says that it did not converge."""
    import torquesplit.solve.static as static_mod
    from torquesplit.errors import ModelWarning

    real = static_mod.static_equilibrium

    def loose(structure, t=None, **kw):
        sol = real(structure, t, **kw)
        return sol if t is None else dataclasses.replace(sol, converged=False)

    monkeypatch.setattr(static_mod, "static_equilibrium", loose)
    with pytest.warns(ModelWarning, match="did not converge exactly"):
        run = prepare_run(write_model(tmp_path, ECCENTRIC), cycles=5)
    assert run.start == "t0"
    np.testing.assert_array_equal(run.y0[:run.structure.n_dof],
                                  real(run.structure, 0.0).q)
