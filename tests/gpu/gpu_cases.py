"""Ensembles shared by the GPU tests (also run in the simulator subprocess)."""

from __future__ import annotations

import warnings

import numpy as np

from solve_models import random_structure_extras
from torquesplit.simulation import PreparedRun, prepare_run
from torquesplit.solve.integrate import integrate

#: Solution fields that must be identical (FP64, same arithmetic) to the engine's
FIELDS = ("cycle_start", "cycle_max", "cycle_min", "cycle_mean", "cycle_count",
          "cycle_ratio_max", "cycle_ratio_min", "separation_steps", "back_contact_steps",
          "separation_time", "back_contact_time", "y_final")
SCALARS = ("status", "n_steps", "n_rhs", "n_samples", "t_final", "step", "message")


def structure_run(s, y0, duration, groups=None) -> PreparedRun:
    """A prepared run of a bare structure (no model): what run_ensemble reads."""
    kw = dict(method="rk4", load_sharing_groups=groups)
    return PreparedRun(model=None, kinematics=None, structure=s, static=None,
                       y0=np.asarray(y0, dtype=float), duration=duration, integrate_kwargs=kw)


def engine(run):
    """The CPU engine's Solution of a prepared run (what the ensemble must equal)."""
    kw = dict(run.integrate_kwargs)
    kw.setdefault("history_elements", ())
    kw.setdefault("history_dofs", ())
    return integrate(run.structure, run.y0, (0.0, run.duration), **kw)


def feature_runs() -> list[PreparedRun]:
    """Every feature of the generated code: time-varying stiffness and additive force
    tables with corners, per-cycle half-gap sequences, dead zones, error sinusoids
    (phasor rotation and re-synchronisation), tooth friction, both spline branches, a
    gyroscopic coupling, a load-sharing group; two patterns, per-case values, one case
    that diverges."""
    a = random_structure_extras(0, gyroscopic=True)
    b = random_structure_extras(1)
    rng = np.random.default_rng(5)
    y0a = 1e-7 * rng.normal(size=2 * a.n_dof)
    groups = [["mesh0", "mesh1", "mesh2"]]
    runs = [structure_run(a, y0a, 0.012, groups)]
    # same pattern, other values: stiffness tables, masses, errors, gaps, damping
    from dataclasses import replace

    a2 = replace(a, stiffness_table=a.stiffness_table * 1.1, inv_mass=a.inv_mass * 0.9,
                 error_amplitude=a.error_amplitude * 1.5, gap_values=a.gap_values * 0.7,
                 damping=a.damping * 2.0, phase=(a.phase + 0.13) % 1.0)
    runs.append(structure_run(a2, -y0a, 0.012, groups))
    runs.append(structure_run(a, np.full(2 * a.n_dof, 2e3), 0.012, groups))  # diverges
    runs.append(structure_run(b, 1e-7 * rng.normal(size=2 * b.n_dof), 0.008))
    return runs


def example_run(name: str, duration: float) -> PreparedRun:
    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare_run(torquesplit.example_path(name), duration=duration)


def compare(sol, ref) -> list[str]:
    """Names of the fields where ``sol`` differs from ``ref`` in any bit."""
    bad = []
    for f in FIELDS:
        if not np.array_equal(getattr(sol, f), getattr(ref, f), equal_nan=True):
            bad.append(f)
    for f in SCALARS:
        if getattr(sol, f) != getattr(ref, f):
            bad.append(f)
    return bad
