"""Periodic steady state, speed sweeps with continuation, and resonance maps.

=================  ===================================================================
module             what it does
=================  ===================================================================
``period``         least common period of the excitations in exact rational arithmetic
                   (:func:`fundamental_period`), refusing long or impossible periods
                   with the fix; :func:`keep_excitations` keeps one stage's / shaft's
                   excitations (the others by their means)
``problem``        :class:`PeriodicProblem`: a structure with its kernel bundles, rigid
                   modes (mean fixed; friction load carried) and speed scaling
``_kernels``       compiled loops on the integrators' ``excite``/``_stage`` and the
                   laws' derivatives: sampled right-hand side, law slopes, matrix-free
                   Jacobian, RK4 with variational equations
``harmonic``       harmonic balance with alternating frequency-time evaluation, its
                   Jacobian (matrix-free, harmonic-by-harmonic preconditioner, GMRES)
``newton``         Newton for HB and shooting (matrix-free Newton-Krylov on long
                   periods); Floquet multipliers (monodromy, Hill)
``solution``       :func:`periodic_solution` on a structure: :class:`PeriodicSolution`
``api``            :func:`steady_state` on a model: :class:`SteadyState` (per-mesh
                   table, conversion to :class:`torquesplit.results.Results`)
``sweep``          pseudo-arclength continuation in speed of the shooting (default) or
                   HB equations, folds, stepped run-up / run-down time-integration
                   cross-check
``maps``           :func:`sweep_speed` and :func:`campbell` (xarray Datasets)
``plot``           figures of a sweep and of a Campbell diagram
``cli``            the ``steady`` and ``sweep-speed`` commands
=================  ===================================================================

Conventions: SI inside (m, rad, N, s; frequencies in Hz, speeds in rad/s, rpm only in
coordinates named ``*_rpm``).  A *speed factor* is the input speed over the model's
(first drive's) speed; excitation frequencies scale with it, torques and the tables
(functions of the mesh phase) do not.  HB unknowns per DOF: a_0, a_1, b_1, ..., a_H,
b_H of q(t) = a_0 + sum a_k cos(k w t) + b_k sin(k w t), w = 2 pi f0.
Dynamic factors: ``dynamic_factor`` = peak / the mesh's own static force,
``peak_to_nominal`` = peak / the equal-split nominal force.
"""

from torquesplit.steady.api import MeshSteady, SteadyState, steady_state
from torquesplit.steady.maps import campbell, sweep_speed
from torquesplit.steady.period import (
    LongPeriodError,
    Period,
    PeriodError,
    fundamental_period,
    keep_excitations,
)
from torquesplit.steady.problem import PeriodicProblem
from torquesplit.steady.solution import PeriodicSolution, periodic_solution

__all__ = ["steady_state", "SteadyState", "MeshSteady", "sweep_speed", "campbell",
           "fundamental_period", "keep_excitations", "Period", "PeriodError",
           "LongPeriodError", "PeriodicProblem", "PeriodicSolution", "periodic_solution"]
