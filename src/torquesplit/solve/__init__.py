"""Numerical core: time integration, static equilibrium and modes of a Structure.

Every analysis here takes an assembled :class:`torquesplit.assembly.structure.Structure`
(immutable flat arrays) and returns a frozen result object with read-only arrays;
nothing is modified.  Lifetime: compiled kernels are built once per process (and cached
on disk by numba); a Structure once per model or study case; results once per call.

==================  ===================================================================
Module              What it does
==================  ===================================================================
``integrate``       :func:`integrate` - fixed-step RK4 or adaptive Dormand-Prince 5(4)
                    in compiled chunks with a progress callback; streaming per-mesh-cycle
                    statistics, decimated histories, contact-loss counters;
                    :class:`Solution` with scipy-style status and message.
``stability``       :func:`check_step` / :func:`stable_step` - RK4 stability of a step
                    from the eigenvalues at maximum stiffness; the error explains the
                    highest natural frequency and a safe step.
``static``          :func:`static_equilibrium`, :func:`quasi_static` - Newton with exact
                    line search on the strain energy with backlash / clearance / spline
                    dead zones, tooth friction iterated as a load; rigid-body modes
                    removed by mass-weighted constraints; unbalanced torques reported.
``modal``           :func:`modal_analysis` - natural frequencies, mass-normalised modes,
                    modal strain energy per element, rigid-body modes apart.
``reference``       Readable numpy twins of the kernels (:func:`rhs_numpy`, ...), used by
                    tests and as the scipy baseline.
``_kernels``        Every numba ``@njit(cache=True)`` loop, each naming its twin.
``_frozen``         Makes the arrays of the frozen result objects read-only.
==================  ===================================================================

Conventions
-----------
* SI units throughout: m, rad, N, N m, kg, kg m^2, s; frequencies in Hz, angular
  frequencies in rad/s.
* State vector ``y = [q, v]``: the ``n_dof`` displacements in the order of
  ``structure.dof_names``, then the velocities in the same order.  Rotational DOFs
  are the vibratory angle measured from the nominal rigid rotation.
* Element ``e``: deformation ``delta = V_e.q - e_e(t)``, force ``f_e = k_e(t) h(delta)
  + c_e rate + p_e(t)`` (positive = compression of the mesh / spring), generalized
  force ``-V_e f_e``; a mesh with tooth friction adds ``-W_e(phase) max(f_e, 0)``; the
  two component elements of a spline carry the x and y components of its radial force.
  Element and DOF selections accept indices or names.
* Excitation cycle ``c`` of an element: ``floor(f t + phase)`` (counted one up within
  1e-9 below the next integer, so a sample on a cycle boundary belongs to the cycle it
  starts) minus its value at the start of the run; per-cycle arrays have one row per
  cycle, one column per element.
* Solver status codes: 0 finished, 1 diverged, 2 step size underflow, 3 maximum
  steps reached.  A stopped run is a result, not an exception.
"""

from torquesplit.solve.integrate import (
    Solution,
    compile_kernels,
    element_forces,
    integrate,
    rhs,
)
from torquesplit.solve.modal import ModalSolution, modal_analysis
from torquesplit.solve.reference import element_forces_numpy, excitation_numpy, rhs_numpy
from torquesplit.solve.stability import check_step, highest_natural_frequency, stable_step
from torquesplit.solve.static import (
    QuasiStaticSolution,
    StaticSolution,
    quasi_static,
    rigid_body_modes,
    static_equilibrium,
)

__all__ = [
    "Solution",
    "integrate",
    "rhs",
    "element_forces",
    "compile_kernels",
    "check_step",
    "stable_step",
    "highest_natural_frequency",
    "StaticSolution",
    "QuasiStaticSolution",
    "static_equilibrium",
    "quasi_static",
    "rigid_body_modes",
    "ModalSolution",
    "modal_analysis",
    "rhs_numpy",
    "element_forces_numpy",
    "excitation_numpy",
]
