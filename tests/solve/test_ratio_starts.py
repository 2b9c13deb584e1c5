"""The instantaneous load-sharing ratio at cycle starts (``_kernels.ratio_starts``): the
ratio of the group's forces interpolated at each cycle start enters both cycles' max and
min, as the force does (``_kernels.force_instant``), so that the per-cycle ratio peaks of
the instantaneous and engineering coefficients (Ji & Li eq. 18) converge at second order
where the ratio rises or falls through a cycle start."""

from __future__ import annotations

import numpy as np

from torquesplit.assembly.structure import MESH, build_structure
from torquesplit.solve import integrate, static_equilibrium
from torquesplit.solve.reference import cycle_ratio_numpy

R1, R2 = 0.05, 0.10  # m
F_MESH = 1000.0  # Hz
PHASES = (0.37, 0.81)


def _two_branch(stiffness=2e8, table=None):
    """A pinion driving two gears (one group of two meshes, 1 kHz, phases 0.37 and
    0.81): constant stiffness (``table`` None) and a slow 60 Hz error on the first
    mesh, so the two share unevenly and their ratio rises or falls through most cycle
    starts, which fall between the steps."""
    k = np.full(64, stiffness) if table is None else table
    meshes = [dict(name=f"m{i}", kind=MESH, dofs=[0, i + 1], coefs=[R1, -R2], stiffness=k,
                   damping=2000.0, frequency=F_MESH, phase=PHASES[i],
                   errors=[(20e-6, 2 * np.pi * 60, 0.0)] if i == 0 else [])
              for i in range(2)]
    return build_structure(["p.theta", "a.theta", "b.theta"], [100.0, 25.0, 25.0], meshes,
                           external_force=[200.0, -200.0, -200.0], n_table=64)


def _run(s, spp, duration=0.03, **kw):
    y0 = static_equilibrium(s).y0
    return integrate(s, y0, (0.0, duration), steps_per_period=spp, record_every=1,
                     load_sharing_groups=[["m0", "m1"]], history_elements=["m0", "m1"], **kw)


def test_cycle_ratio_extremes_equal_the_twin():
    """Every per-cycle ratio max and min equals the twin's from the recorded forces at
    every step, cycle starts included (and differs from the step samples' alone)."""
    s = _two_branch()
    sol = _run(s, 97)
    assert sol.success
    n = sol.cycle_ratio_max.shape[0]
    f, ph = np.full(2, F_MESH), np.array(PHASES)
    rmax, rmin = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0, n,
                                   continuous_start=[True, True])
    np.testing.assert_allclose(sol.cycle_ratio_max, rmax, rtol=1e-13)
    np.testing.assert_allclose(sol.cycle_ratio_min, rmin, rtol=1e-13)
    plain_max, _ = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0, n)
    assert np.sum(rmax[2:-2] > plain_max[2:-2] + 1e-9) > 10


def test_cycle_ratio_peaks_at_cycle_starts_converge_with_the_step():
    """From 97 to 388 steps per cycle the per-cycle ratio peaks move far less than those
    of the step samples alone (first order: up to the ratio's slope times a step).
    Measured against 776 steps: 7.2e-6, 1.4e-6, 6.8e-7 at 97, 194, 388 steps per cycle
    (the samples alone: 1.9e-4, 8.1e-5, 2.7e-5); what is left is the ratio's peaks
    inside the cycles, taken at the instants (second order)."""
    s = _two_branch()
    f, ph = np.full(2, F_MESH), np.array(PHASES)

    def peaks(spp):
        sol = _run(s, spp)
        plain = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0,
                                  sol.cycle_ratio_max.shape[0])[0]
        return sol.cycle_ratio_max[5:25], plain[5:25]

    (coarse, coarse_plain), (fine, fine_plain) = peaks(97), peaks(388)
    moved = np.max(np.abs(coarse - fine))
    moved_plain = np.max(np.abs(coarse_plain - fine_plain))
    assert moved_plain > 1e-4 and moved < moved_plain / 15, (moved, moved_plain)


def test_no_ratio_at_cycle_starts_where_the_force_jumps():
    """A table with a corner at node 0 (the force jumps where a cycle begins): the ratio
    interpolated across the jump is no value of either cycle, so only the instants'
    ratios enter (as for the force extremes).  Without corner instants (corners=False)
    the extremes are then exactly the step samples'."""
    table = np.where(np.arange(64) < 32, 2.4e8, 1.6e8)  # steps at nodes 0 and 32
    s = _two_branch(table=table)
    sol = _run(s, 97, duration=0.01, corners=False)
    n = sol.cycle_ratio_max.shape[0]
    f, ph = np.full(2, F_MESH), np.array(PHASES)
    plain = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0, n)
    np.testing.assert_allclose(sol.cycle_ratio_max, plain[0], rtol=1e-13)
    np.testing.assert_allclose(sol.cycle_ratio_min, plain[1], rtol=1e-13)
    across = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0, n,
                               continuous_start=[True, True])
    assert not np.allclose(across[0], plain[0], rtol=1e-9)


def test_the_ratio_is_of_the_loads_the_teeth_carry():
    """A mesh that separates (backlash, a large error) can show a negative force while
    its damping force exceeds the elastic one: the ratio takes the positive parts, so no
    member exceeds N = 2 (and the engine equals the twin, which clips too)."""
    meshes = []
    for i in range(2):
        meshes.append(dict(name=f"m{i}", kind=MESH, dofs=[0, i + 1], coefs=[R1, -R2],
                           stiffness=np.full(64, 2e8), damping=2e4, frequency=F_MESH,
                           phase=PHASES[i], gaps=5e-6,
                           errors=[(60e-6, 2 * np.pi * 800, 0.0)] if i == 0 else []))
    s = build_structure(["p.theta", "a.theta", "b.theta"], [100.0, 25.0, 25.0], meshes,
                        external_force=[200.0, -200.0, -200.0], n_table=64)
    sol = _run(s, 97)
    assert sol.success and np.nanmin(sol.history_forces) < 0.0  # tension while separating
    n = sol.cycle_ratio_max.shape[0]
    f, ph = np.full(2, F_MESH), np.array(PHASES)
    rmax, rmin = cycle_ratio_numpy(sol.history_t, sol.history_forces, f, ph, 0.0, n,
                                   continuous_start=[True, True])
    np.testing.assert_allclose(sol.cycle_ratio_max, rmax, rtol=1e-13)
    np.testing.assert_allclose(sol.cycle_ratio_min, rmin, rtol=1e-13)
    finite = np.isfinite(sol.cycle_ratio_max)
    assert finite.sum() > 10 and np.all(sol.cycle_ratio_max[finite] <= 2.0)
    assert np.any(sol.cycle_ratio_max[finite] == 2.0)  # one mesh carrying all
