"""Time integration: accuracy, order, contact, stability refusal, divergence, streaming."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from solve_models import J1, J2, R1, pair_frequency, spur_pair

from torquesplit.assembly.structure import SPRING
from torquesplit.errors import SolverError, StepTooLargeError
from torquesplit.solve import integrate, stable_step, static_equilibrium


def _free_pair(delta0=1e-5):
    """Unloaded, undamped pair released with a mesh deflection delta0 (no rigid motion)."""
    s = spur_pair(torque=0.0, load=0.0)
    y0 = np.array([delta0 / R1, 0.0, 0.0, 0.0])
    return s, y0


def _zero_crossing_frequency(t, x):
    """Frequency from linearly interpolated zero crossings (exact up to O(h^3))."""
    i = np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:]))
    tc = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return 0.5 * (len(tc) - 1) / (tc[-1] - tc[0])


def test_free_vibration_frequency_matches_analytic():
    s, y0 = _free_pair()
    f_n = pair_frequency()
    sol = integrate(s, y0, (0.0, 60.0 / f_n), history_dofs=())
    assert sol.success, sol.message
    assert sol.step == pytest.approx(1.0 / f_n / 100, rel=1e-6)  # natural period / 100
    f_est = _zero_crossing_frequency(sol.history_t, sol.history_forces[:, 0])
    assert f_est == pytest.approx(f_n, rel=1e-4)
    # undamped: the force amplitude is kept (RK4 damps it only at order (w h)^6)
    assert np.max(sol.history_forces[:, 0]) == pytest.approx(1e-5 * 2e8, rel=1e-4)


def _forced_linear_pair():
    return spur_pair(torque=0.0, load=0.0, damping=300.0,
                     errors=[(2e-6, 2 * math.pi * 700.0, 0.4)])


@pytest.mark.parametrize("n_period", [32, 64])
def test_rk4_error_falls_at_fourth_order(n_period):
    # smooth linear forced case (constant stiffness, sinusoidal error, damping)
    s = _forced_linear_pair()
    y0 = np.zeros(4)
    period = 1.0 / pair_frequency()
    span = 20 * period
    ref = integrate(s, y0, (0.0, span), step=period / (16 * n_period), history_elements=(),
                    history_dofs=(), track_elements=())
    errs = []
    for m in (1, 2):
        sol = integrate(s, y0, (0.0, span), step=period / (m * n_period),
                        history_elements=(), history_dofs=(), track_elements=())
        errs.append(np.max(np.abs(sol.y_final - ref.y_final) / np.max(np.abs(ref.y_final))))
    ratio = errs[0] / errs[1]
    assert 12.0 < ratio < 20.0, (errs, ratio)
    assert errs[1] > 1e-9  # far above round-off, so the ratio measures truncation error


def test_dopri_meets_tolerance_against_fine_rk4():
    s = dataclasses.replace(_forced_linear_pair(), external_force=np.zeros(2))
    y0 = np.array([1e-5 / R1, 0.0, 0.0, 0.0])
    span = 0.02
    ref = integrate(s, y0, (0.0, span), step=1.0 / pair_frequency() / 1000,
                    history_elements=(), history_dofs=(), track_elements=())
    scale = np.max(np.abs(ref.y_final))
    for rtol in (1e-6, 1e-9):
        sol = integrate(s, y0, (0.0, span), method="dopri", rtol=rtol, atol=rtol * 1e-4,
                        history_elements=(), history_dofs=())
        assert sol.success, sol.message
        err = np.max(np.abs(sol.y_final - ref.y_final)) / scale
        assert err < 100 * rtol, (rtol, err)
        assert sol.step_max <= 1.0 / 700.0 / 20 * (1 + 1e-12)  # default max_step
    # tighter tolerance costs more steps
    loose = integrate(s, y0, (0.0, span), method="dopri", rtol=1e-5)
    tight = integrate(s, y0, (0.0, span), method="dopri", rtol=1e-9)
    assert tight.n_steps > loose.n_steps
    assert tight.n_rhs >= 6 * tight.n_steps


def test_dopri_history_is_uniform_and_accurate():
    s = _forced_linear_pair()
    y0 = np.array([1e-5 / R1, 0.0, 0.0, 0.0])
    dt = 1e-5
    sol = integrate(s, y0, (0.0, 0.005), method="dopri", rtol=1e-10, atol=1e-16,
                    sample_interval=dt, full_history=True)
    np.testing.assert_allclose(sol.history_t, np.arange(501) * dt, rtol=0, atol=1e-15)
    ref = integrate(s, y0, (0.0, 0.005), step=dt / 20, record_every=20, full_history=False)
    np.testing.assert_allclose(sol.history_t, ref.history_t, atol=1e-15)
    scale = np.max(np.abs(ref.history_q))
    assert np.max(np.abs(sol.history_q - ref.history_q)) < 1e-6 * scale
    fscale = np.max(np.abs(ref.history_forces))
    assert np.max(np.abs(sol.history_forces - ref.history_forces)) < 1e-6 * fscale
    np.testing.assert_array_equal(sol.full_y[:, :2], sol.history_q)


def test_backlash_wider_than_vibration_keeps_force_exactly_zero():
    # gear 1 rings on a torsional spring to ground inside a 2 x 50 um backlash
    shaft = dict(name="shaft", kind=SPRING, dofs=[0], coefs=[1.0], stiffness=5e5)
    table = 2e8 * (1 + 0.2 * np.sin(2 * np.pi * np.arange(64) / 64))
    s = spur_pair(torque=0.0, load=0.0, gaps=50e-6, frequency=900.0, stiffness=table,
                  damping=100.0, extra=[shaft])
    y0 = np.array([2e-6 / R1, 0.0, 0.0, 0.0])  # 2 um along the line of action
    sol = integrate(s, y0, (0.0, 0.02))
    assert sol.success
    assert np.all(sol.history_forces[:, 0] == 0.0)
    assert np.all(sol.cycle_max == 0.0) and np.all(sol.cycle_min == 0.0)
    assert sol.separation_steps[0] == sol.n_samples == sol.n_steps + 1
    assert sol.back_contact_steps[0] == 0
    assert sol.separation_time[0] == pytest.approx(0.02, rel=1e-12)
    assert sol.separation_fraction[0] == pytest.approx(1.0, rel=1e-12)
    assert np.max(np.abs(sol.history_forces[:, 1])) > 0  # the shaft does vibrate
    # a fraction is at most 1, however the sum of the steps rounds (Dong et al. 2021's
    # support in back contact the whole run read 1.0000000000033538)
    over = dataclasses.replace(sol, separation_time=sol.separation_time * (1 + 1e-12),
                               back_contact_time=sol.separation_time * (1 + 1e-12))
    assert over.separation_fraction[0] == 1.0 == over.back_contact_fraction[0]


def test_backlash_contact_loss_is_counted():
    # loaded pair with a large error excitation: the mesh separates and hits its back flank
    s = spur_pair(torque=20.0, gaps=10e-6, damping=50.0, frequency=1000.0,
                  errors=[(40e-6, 2 * math.pi * pair_frequency(), 0.0)])
    st = static_equilibrium(s)
    sol = integrate(s, st.y0, (0.0, 0.02))
    assert sol.success
    assert sol.separation_steps[0] > 0
    assert sol.back_contact_steps[0] > 0
    assert np.min(sol.cycle_min) < 0  # back-flank force
    f = sol.history_forces[:, 0]
    assert np.any(f == 0.0)
    # the times split the steps where the contact changes (on the parabola through three
    # samples): at the default step, and at a tolerance where the adaptive method crowds
    # its steps at the impacts, they equal a tight adaptive run's (2.4732e-4 s
    # separated), where whole steps gave 2.45e-4 at the default step and 3.20e-4 at 200
    # steps per period
    ref = integrate(s, st.y0, (0.0, 0.02), method="dopri", rtol=1e-10)
    dp = integrate(s, st.y0, (0.0, 0.02), method="dopri", rtol=1e-8)
    assert dp.separation_steps[0] / dp.n_samples > 3 * dp.separation_fraction[0]
    for r in (sol, dp):
        assert r.separation_time[0] == pytest.approx(ref.separation_time[0], rel=5e-4)
        assert r.back_contact_time[0] == pytest.approx(ref.back_contact_time[0], rel=1e-5)


def test_step_ten_times_too_large_is_refused_with_safe_step():
    s = spur_pair()
    safe = 0.8 * stable_step(s)
    # analytic RK4 limit for an undamped mode: w h = 2 sqrt(2)
    assert stable_step(s) == pytest.approx(2 * math.sqrt(2) / (2 * math.pi * pair_frequency()),
                                           rel=1e-9)
    with pytest.raises(StepTooLargeError) as err:
        integrate(s, np.zeros(4), (0.0, 0.01), step=10 * safe)
    msg = str(err.value)
    assert f"{10 * safe:.4g} s" in msg
    assert f"{pair_frequency():.6g} Hz" in msg
    assert f"safe step is {safe:.4g} s" in msg
    assert msg.endswith("or method='dopri'.")
    assert isinstance(err.value, ValueError)
    ok = integrate(s, np.zeros(4), (0.0, 0.001), step=float(f"{safe:.4g}"))
    assert ok.success


def test_default_step_is_refined_when_unstable():
    # excitation at 10 Hz: period/100 = 1 ms is far above the stability limit (~0.1 ms)
    s = spur_pair(frequency=10.0)
    sol = integrate(s, np.zeros(4), (0.0, 0.2), history_elements=(), history_dofs=())
    assert sol.success
    assert sol.step <= 0.8 * stable_step(s)
    assert (0.1 / sol.step) == pytest.approx(round(0.1 / sol.step), abs=1e-6)


def test_divergence_reports_status_and_keeps_partial_history():
    s, y0 = _free_pair()
    safe = 0.8 * stable_step(s)
    sol = integrate(s, y0, (0.0, 1000 * 10 * safe), step=10 * safe, check_stability=False)
    assert sol.status == 1 and not sol.success
    assert "diverged" in sol.message and "g1.theta" in sol.message or "g2.theta" in sol.message
    assert sol.t_final < sol.t_span[1]
    assert 0 < len(sol.history_t) < 1001
    assert np.all(np.isfinite(sol.history_forces)) and np.all(np.isfinite(sol.history_q))
    assert sol.history_t[-1] < sol.t_final
    assert sol.n_steps == round(sol.t_final / sol.step)


def test_negative_stiffness_diverges_to_blowup():
    s = spur_pair(torque=0.0, load=0.0, stiffness=-1e6)
    sol = integrate(s, np.array([1e-6, 0, 0, 0]), (0.0, 1.0), step=1e-4, blowup=1.0)
    assert sol.status == 1
    assert "exceeds blowup" in sol.message
    assert len(sol.history_t) == sol.n_steps  # states before the blow-up are all kept
    # where the bound is set (simulate has no blowup argument; the message said "raise
    # blowup"), and the step's name as simulate and the command line take it
    assert "blowup= of torquesplit.solve.integrate" in sol.message
    assert "steps_per_period" in sol.message and "--steps-per-period" in sol.message


def test_dopri_divergence_keeps_only_valid_records():
    s = spur_pair(torque=0.0, load=0.0, stiffness=-1e6)
    sol = integrate(s, np.array([1e-6, 0, 0, 0]), (0.0, 1.0), method="dopri", blowup=1.0,
                    sample_interval=1e-3)
    assert sol.status == 1 and "exceeds blowup" in sol.message
    assert np.all(np.abs(sol.history_q) <= 1.0)
    assert sol.history_t[-1] <= sol.t_final
    assert np.max(np.abs(sol.y_final[:2])) > 1.0


def test_two_runs_identical_and_independent_of_progress():
    s = spur_pair(damping=80.0, frequency=1000.0, gaps=[1e-6, 3e-6, 2e-6],
                  stiffness=2e8 * (1 + 0.2 * np.sin(2 * np.pi * np.arange(64) / 64)),
                  errors=[(3e-6, 2 * math.pi * 77.0, 0.1)])
    y0 = static_equilibrium(s).y0
    a = integrate(s, y0, (0.0, 0.05))
    calls = []
    b = integrate(s, y0, (0.0, 0.05), progress=calls.append)
    assert len(calls) > 1
    for field in dataclasses.fields(a):
        if field.name in ("wall_time", "compile_time"):
            continue
        va, vb = getattr(a, field.name), getattr(b, field.name)
        if isinstance(va, np.ndarray):
            np.testing.assert_array_equal(va, vb, err_msg=field.name)
        else:
            assert va == vb, field.name


def test_progress_fractions_increase_to_one():
    s = spur_pair(frequency=1000.0)
    for method in ("rk4", "dopri"):
        calls = []
        sol = integrate(s, np.zeros(4), (0.0, 0.1), method=method, progress=calls.append,
                        history_elements=(), history_dofs=())
        assert sol.success
        assert len(calls) >= 10
        assert all(b > a for a, b in zip(calls, calls[1:], strict=False))
        assert calls[-1] == 1.0


def test_rigid_body_mode_does_not_drift():
    s = spur_pair(damping=100.0, frequency=2000.0,
                  stiffness=2e8 * (1 + 0.3 * np.sign(np.sin(2 * np.pi * np.arange(64) / 64))),
                  errors=[(5e-6, 2 * math.pi * 50.0, 0.0)])
    st = static_equilibrium(s)
    phi = st.rigid_modes[:, 0]
    mass = np.array([J1, J2])
    sol = integrate(s, st.y0, (0.0, 0.5), record_every=10)  # 100 000 steps
    assert sol.success
    rigid = sol.history_q @ (mass * phi)
    amplitude = np.max(np.abs(sol.history_q - st.q))
    assert np.max(np.abs(rigid)) < 1e-9 * amplitude
    # the vibration itself is real: the error excitation moves the gears
    assert amplitude > 1e-3 * np.max(np.abs(st.q))


def test_max_steps_stops_with_status_3():
    s = spur_pair(frequency=1000.0)
    for method, kw in (("rk4", {}), ("dopri", {})):
        sol = integrate(s, np.zeros(4), (0.0, 0.01), method=method, max_steps=50, **kw)
        assert sol.status == 3
        assert sol.n_steps == 50
        assert "Maximum number of steps (50)" in sol.message


def test_options_are_checked():
    s = spur_pair(frequency=1000.0)
    y0 = np.zeros(4)
    with pytest.raises(ValueError, match="do not apply"):
        integrate(s, y0, (0, 0.01), rtol=1e-6)
    with pytest.raises(ValueError, match="do not apply"):
        integrate(s, y0, (0, 0.01), method="dopri", step=1e-6)
    with pytest.raises(ValueError, match="Did you mean"):
        integrate(s, y0, (0, 0.01), history_elements=["mseh"])
    with pytest.raises(ValueError, match="unknown method"):
        integrate(s, y0, (0, 0.01), method="euler")
    with pytest.raises(ValueError, match="y0"):
        integrate(s, np.zeros(3), (0, 0.01))
    with pytest.raises(ValueError, match="no excitation frequency"):
        integrate(spur_pair(), y0, (0, 0.01), track_elements=["mesh"])
    with pytest.raises(SolverError, match="GiB"):
        integrate(s, y0, (0, 1e3), step=1e-7, check_stability=False, full_history=True)


def test_selections_by_name_and_q_only_start():
    s = spur_pair(frequency=1000.0)
    sol = integrate(s, np.array([1e-4, 0.0]), (0.0, 0.002), history_elements=["mesh"],
                    history_dofs=["g2.theta"], record_every=10)
    assert sol.history_forces.shape == (21, 1)
    assert sol.history_q.shape == (21, 1)
    np.testing.assert_allclose(sol.history_t, np.arange(21) * 1e-4, atol=1e-15)
    c = sol.cycles("mesh")
    assert c["count"][0] == 100 and np.isfinite(c["mean"][0])


def test_planned_step_is_kept_per_live_structure_only():
    """The default step of a structure is computed once while it lives, then forgotten."""
    import gc
    import importlib

    integ = importlib.import_module("torquesplit.solve.integrate")
    from torquesplit.solve.integrate import planned_step

    s = spur_pair()
    first = planned_step(s, 100, 0.1)
    assert id(s) in integ._STEPS
    assert planned_step(s, 100, 0.1) == first
    assert planned_step(s, 50, 0.1) != first  # other arguments: computed again
    key = id(s)
    del s
    gc.collect()
    assert key not in integ._STEPS


def test_a_step_set_by_stability_names_the_damping_that_sets_it():
    """A stiff friction regularisation (F_m / v of a spline) limits RK4 by stability, not
    by the highest oscillation: the reason says so and names the spline."""
    from torquesplit.assembly.structure import MESH, SPLINE, build_structure
    from torquesplit.solve.integrate import planned_step

    def pair(velocity):
        return build_structure(
            ["g1.theta", "g2.theta", "g2.x", "g2.y"], [1 / J1, 1 / J2, 0.1, 0.1],
            [dict(name="m", kind=MESH, dofs=[0, 1], coefs=[R1, 0.05], stiffness=2e8,
                  frequency=500.0),
             dict(name="sp", kind=SPLINE, x=([2], [1.0]), y=([3], [1.0]), stiffness=1e8,
                  clearance=5e-5, friction_force=1e4, velocity_scale=velocity)])

    h, why = planned_step(pair(1e-4), 100, 0.1)
    assert why.startswith("RK4 stability: a heavily damped motion")
    assert "'sp." in why and "spline_velocity_scale" in why
    h_soft, why_soft = planned_step(pair(1.0), 100, 0.1)
    assert why_soft == "excitation period" and h_soft > 10 * h


def test_chunks_after_the_first_call_the_compiled_kernel_directly(monkeypatch):
    """After the first chunk the RK4 kernel is called without numba's argument typing;
    the run is the same bit for bit as with the dispatcher for every chunk."""
    import importlib

    integ = importlib.import_module("torquesplit.solve.integrate")
    from torquesplit.solve import _kernels as kern

    s = spur_pair(gaps=5e-6)
    st = static_equilibrium(s)
    y0 = np.concatenate([st.q, np.zeros_like(st.q)])
    found = []
    real = integ._compiled

    def spy(dispatcher, args):
        fn = real(dispatcher, args)
        found.append(fn is not dispatcher)
        return fn

    monkeypatch.setattr(integ, "_compiled", spy)
    a = integrate(s, y0, (0.0, 0.05), method="rk4")
    assert found and all(found) and a.n_steps > integ.rk4_chunk(a.n_steps)  # several chunks
    monkeypatch.setattr(integ, "_compiled", lambda dispatcher, args: kern.rk4_run)
    b = integrate(s, y0, (0.0, 0.05), method="rk4")
    assert np.array_equal(a.y_final, b.y_final) and a.n_steps == b.n_steps


def test_compile_time_is_what_the_call_paid():
    """A reviewer read compile_time 31 s on every run of a process whose runs took 0.05 s:
    only the call that compiled (or loaded) the kernels reports it, later calls 0."""
    s = spur_pair(frequency=1000.0)
    y0 = static_equilibrium(s).y0
    integrate(s, y0, (0.0, 0.001))
    again = integrate(s, y0, (0.0, 0.001))
    assert again.compile_time == 0.0
