"""A bad-input reviewer ran the planetary differential example for 100 s: 'Integration
diverged at t = 97.5 s ... Use a smaller step', which did not help.  The train drifted
along its rigid-body motion: a power drive against a torque load holds no speed, and a
net torque along that motion accelerates it.  The message now says so."""

from __future__ import annotations

import warnings

import torquesplit
from torquesplit.solve import static_equilibrium
from torquesplit.solve.integrate import integrate


def _run(example, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = torquesplit.assemble(torquesplit.load_model(torquesplit.example_path(example)))
        return integrate(s, static_equilibrium(s).y0, kw.pop("span"), method="rk4",
                         history_elements=(), history_dofs=(), **kw)


def test_a_drifting_train_is_said_to_drift_not_to_need_a_smaller_step():
    """The example no longer drifts (its turning frame loaded the rigid rotation by
    0.037 N m, fixed): a net torque of 0.05 N m on the carrier stands for it."""
    import dataclasses

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = torquesplit.assemble(torquesplit.load_model(torquesplit.example_path(
            "split_path_planetary_differential")))
        y0 = static_equilibrium(s).y0
    ext = s.external_force.copy()
    ext[s.dof_names.index("stage_carrier.theta")] += 0.05
    # (a small bound: the drift reaches it within 2 s instead of 97 s)
    sol = integrate(dataclasses.replace(s, external_force=ext), y0, (0.0, 4.0),
                    method="rk4", history_elements=(), history_dofs=(), blowup=0.05)
    assert sol.status == 1, sol.message  # (DIVERGED)
    assert "That is no instability" in sol.message and "rigid-body motion" in sol.message
    assert "speed_coefficient" in sol.message and "smaller step does not help" in sol.message
    assert "Use a smaller step" not in sol.message


def test_a_real_divergence_keeps_the_step_advice():
    # Ji & Li's drive at a step far beyond RK4's stability limit
    sol = _run("ji_li_mill_drive", span=(0.0, 0.05), step=2e-4, check_stability=False)
    assert sol.status == 1, sol.message  # (DIVERGED)
    assert "Use a smaller step" in sol.message and "no instability" not in sol.message
