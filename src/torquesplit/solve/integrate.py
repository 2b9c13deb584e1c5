"""Time integration of an assembled :class:`~torquesplit.assembly.structure.Structure`.

:func:`integrate` is the readable entry point; the loops run in
:mod:`torquesplit.solve._kernels`.  A run is split into chunks of about 1.5 % of its
length; between chunks the optional ``progress`` callback is told the fraction done
(no Python call happens per step).  Chunk boundaries depend only on the run length, so
a run gives the same numbers with or without a progress callback.

Post-processing streams while integrating, so memory does not grow with the run length
except for the explicitly sized output arrays:

* per-mesh-cycle max / min / mean / count of the force of tracked elements,
* decimated histories (every ``record_every`` steps for RK4, uniform ``sample_interval``
  for Dormand-Prince, interpolated by cubic Hermite) of chosen element forces and DOFs,
* per-element counts of steps (and time) in separation and in back-side contact,
* optionally the full state at every step (RK4) or sample time (Dormand-Prince).
"""

from __future__ import annotations

import contextlib
import difflib
import logging
import math
import operator
import threading
import time
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from torquesplit._memo import remember_last
from torquesplit.assembly.structure import Structure
from torquesplit.errors import (ModelWarning, OptionError, OptionTypeError, SolverError,
                                from_interrupt, interrupt_name, warn_user)
from torquesplit.solve import _kernels as kern
from torquesplit.solve import codegen
from torquesplit.solve import kernel_data as kd
from torquesplit.solve._frozen import freeze_arrays
from torquesplit.solve.reference import element_forces_numpy, rhs_numpy
from torquesplit.solve.stability import (
    SAFETY,
    check_step,
    highest_mode,
    stability_cause,
    stable_step,
    system_eigenvalues,
)
from torquesplit.solve.vector_peaks import VectorPeaks

__all__ = ["Solution", "integrate", "planned_step", "rhs", "element_forces", "rhs_numpy",
           "element_forces_numpy", "compile_kernels", "STATUS_MESSAGES"]

log = logging.getLogger(__name__)

INTERRUPTED = 4
"""Status of a run stopped by Ctrl-C inside :func:`stop_on_interrupt` (set here, between
chunks of the kernels, never by them)."""

STATUS_MESSAGES = {
    kern.FINISHED: "finished",
    kern.DIVERGED: "diverged",
    kern.STEP_UNDERFLOW: "step size underflow",
    kern.MAX_STEPS: "maximum number of steps reached",
    INTERRUPTED: "interrupted",
}

_stop_on_interrupt = threading.local()


@contextlib.contextmanager
def stop_on_interrupt():
    """Within this context, Ctrl-C during an integration ends it as a stopped run (status
    ``INTERRUPTED``, everything recorded so far kept, as a diverged run keeps it) instead
    of raising KeyboardInterrupt: ``torquesplit run`` saves and reports what it has.
    Outside it (studies, whose workers must stop at once) the interrupt propagates."""
    before = getattr(_stop_on_interrupt, "on", False)
    _stop_on_interrupt.on = True
    try:
        yield
    finally:
        _stop_on_interrupt.on = before


def _interrupted(exc: BaseException) -> bool:
    """An interrupt to turn into a status: inside :func:`stop_on_interrupt`, a
    KeyboardInterrupt or an error chained from one (Ctrl-C inside compiled code)."""
    return bool(getattr(_stop_on_interrupt, "on", False)) and from_interrupt(exc)

_N_CHUNKS = 64  # progress granularity: about 1.5 % of the run per chunk
_MIN_CHUNK_STEPS = 16 * kern.RESYNC
_MEMORY_LIMIT = 2 * 1024**3  # bytes of output arrays before we refuse and explain
_COMPILE_TIMES: dict[str, float] = {}  # method -> seconds of its first warm-up
ACCURACY = 1.0
"""Default RK4 step: at most ACCURACY / omega_max, omega_max the highest natural angular
frequency at maximum stiffness, so that the highest mode is resolved (6.3 steps per its
period; RK4's amplitude error per step (omega h)^6 / 144 < 0.7 %) and not only stable
(omega h <= 2.2 with the 0.8 safety).  Measured on the Ji & Li drive: at the stability
limit (109 steps per mesh period) its load-sharing coefficient moved by 1.7e-3 when the
step was halved, at this limit (about 240) by less than 1e-4."""
_STEP_WARN_FACTOR = 10.0  # warn when the step is this many times the requested one
_CODEGEN_WARNED = False


# ===================================================================== result
@dataclass(frozen=True, eq=False)
class Solution:
    """Result of :func:`integrate`.  Arrays are owned by the solution and read-only.

    Cycle arrays have shape (n_cycles, n_tracked); row c is the c-th excitation cycle
    of each tracked element counted from the cycle containing ``t_span[0]``; empty
    cycles have count 0 and NaN statistics.  History arrays have one row per record.
    """

    status: int
    """0 finished, 1 diverged, 2 step size underflow (dopri), 3 maximum steps reached."""
    message: str
    """Where and why the run stopped (scipy.integrate style)."""
    success: bool
    """``status == 0``."""
    method: str
    t_span: tuple[float, float]
    t_final: float
    """Time of ``y_final`` (where the run stopped)."""
    y_final: np.ndarray
    """State [q, v] at ``t_final`` (non-finite if the run diverged there)."""
    n_steps: int
    """Accepted steps."""
    n_rejected: int
    """Rejected steps (dopri)."""
    n_rhs: int
    """Right-hand-side evaluations of the integrator (not those made to record samples)."""
    step: float | None
    """RK4 step used [s]; None for dopri."""
    step_limited_by: str
    """What set the RK4 step: the excitation period (``steps_per_period``), the highest
    mode (named, with its element), or a given step; empty for dopri."""
    step_min: float
    """Smallest accepted step [s]."""
    step_max: float
    """Largest accepted step [s]."""
    compile_time: float
    """Seconds this call spent compiling (or loading from cache) this method's kernels:
    only the first call of a method in a process, 0 afterwards."""
    wall_time: float
    """Seconds spent in this call, compile time excluded."""
    rhs: str
    """Right-hand side the kernels called: "literal", "generated" or "general" (see
    integrate)."""
    rhs_compile_time: float
    """Seconds spent generating and compiling it in this call (0 when cached)."""
    dof_names: tuple[str, ...]
    element_names: tuple[str, ...]
    tracked_elements: tuple[int, ...]
    cycle_start: np.ndarray
    """(n_cycles, n_tracked) start time of each excitation cycle [s]."""
    cycle_max: np.ndarray
    """(n_cycles, n_tracked) largest element force in the cycle [N]."""
    cycle_min: np.ndarray
    """(n_cycles, n_tracked) smallest element force in the cycle [N]."""
    cycle_mean: np.ndarray
    """(n_cycles, n_tracked) mean of the force samples in the cycle [N]."""
    cycle_count: np.ndarray
    """(n_cycles, n_tracked) number of accepted states in the cycle."""
    load_sharing_groups: tuple[tuple[int, ...], ...]
    """Element indices of each load-sharing group (see ``integrate``)."""
    cycle_ratio_max: np.ndarray
    """(n_cycles, n_tracked) largest instantaneous load-sharing ratio N f_i / sum_j f_j
    of the element's group in the cycle (NaN outside groups or without samples)."""
    cycle_ratio_min: np.ndarray
    """(n_cycles, n_tracked) smallest instantaneous ratio in the cycle."""
    history_elements: tuple[int, ...]
    history_dofs: tuple[int, ...]
    history_t: np.ndarray
    """(n_records,) [s]."""
    history_forces: np.ndarray
    """(n_records, n_history_elements) element forces [N]."""
    history_q: np.ndarray
    """(n_records, n_history_dofs) displacements [m, rad]."""
    history_v: np.ndarray
    """(n_records, n_history_dofs) velocities [m/s, rad/s]."""
    full_t: np.ndarray | None
    """Times of the full state records, or None if not asked."""
    full_y: np.ndarray | None
    """(n_records, 2 n_dof) full states, or None if not asked."""
    n_samples: int
    """Accepted states entered in the statistics and contact counters."""
    separation_steps: np.ndarray
    """(n_el,) accepted states with |delta| <= g (g > 0): contact lost."""
    back_contact_steps: np.ndarray
    """(n_el,) accepted states with delta < -g (back flank; mesh without backlash:
    delta < 0)."""
    separation_time: np.ndarray
    """(n_el,) time spent in separation [s]: each interval between two accepted states
    split where delta - g or delta + g changes sign, on the parabola through three
    states (:func:`~torquesplit.solve._kernels.record`).  Unlike ``separation_steps``
    it is not biased by adaptive steps crowding at contact events, and converges with
    the step where the contact is only grazed."""
    back_contact_time: np.ndarray
    """(n_el,) time spent in back-side contact [s], split like ``separation_time``."""
    history_peak_names: tuple[str, ...] = ()
    """Names of the force vectors whose magnitude was taken at every instant
    (``integrate``'s ``history_peaks``)."""
    history_peaks: np.ndarray | None = None
    """(n_records, n_vectors) each vector's largest magnitude [N] since the record
    before (this record included), over every (accepted) step, table corner and peak
    between them (the vertex of a parabola through three): its largest over a span of
    records does not depend on the sampling (:mod:`~torquesplit.solve.vector_peaks`).
    None without vectors or where the dense record overflowed."""

    def __post_init__(self):
        freeze_arrays(self)

    @property
    def separation_fraction(self) -> np.ndarray:
        """(n_el,) fraction of the integrated time spent in separation (at most 1: the
        sum of the step lengths rounds differently from the span)."""
        return np.minimum(self.separation_time / max(self.t_final - self.t_span[0], 1e-300),
                          1.0)

    @property
    def back_contact_fraction(self) -> np.ndarray:
        """(n_el,) fraction of the integrated time spent in back-side contact (at most 1,
        as :attr:`separation_fraction`)."""
        return np.minimum(self.back_contact_time / max(self.t_final - self.t_span[0], 1e-300),
                          1.0)

    def cycles(self, element: int | str) -> dict[str, np.ndarray]:
        """Cycle statistics of one tracked element (by index or name) as a dict."""
        e = _resolve(self.element_names, [element], "element")[0]
        if e not in self.tracked_elements:
            names = [self.element_names[i] for i in self.tracked_elements]
            raise OptionError(f"element {self.element_names[e]!r} was not tracked; tracked "
                              f"elements are {names}. Pass track_elements=[...] to integrate.")
        j = self.tracked_elements.index(e)
        return {"start": self.cycle_start[:, j], "max": self.cycle_max[:, j],
                "min": self.cycle_min[:, j], "mean": self.cycle_mean[:, j],
                "count": self.cycle_count[:, j]}


# ============================================================ one evaluation
def rhs(structure: Structure, t: float, y) -> np.ndarray:
    """dy/dt at (t, y) evaluated by the compiled kernel (twin: :func:`rhs_numpy`)."""
    dy, _, _ = _evaluate(structure, t, y)
    return dy


def element_forces(structure: Structure, t: float, y):
    """Element forces and deformations at (t, y) from the compiled kernel: ``(f, delta)``."""
    _, force, defl = _evaluate(structure, t, y)
    return force, defl


def _evaluate(structure, t, y, model=None, code=None):
    """(dy/dt, element forces, deformations) at (t, y) from the compiled kernel: the
    general one, or ``code`` (a :class:`codegen.GeneratedRhs`)."""
    y = np.array(y, dtype=np.float64, order="C", copy=True)
    if y.shape != (2 * structure.n_dof,):
        raise OptionError(f"state must have shape ({2 * structure.n_dof},) = [q, v], "
                          f"got {y.shape}.")
    m = kd.kernel_model(structure) if model is None else model
    code = codegen.general_rhs() if code is None else code
    w = kd.make_work(m, code.parameters)
    w.Y[kd.Y_STATE] = y
    kern.evaluate(float(t), m, w, code.function, code.generated)
    return (w.Y[kd.Y_K1].copy(), w.F[kd.F_MAIN].copy(), w.D[kd.F_MAIN].copy())


# ============================================================== compilation
def compile_kernels(methods: Sequence[str] = ("rk4", "dopri")) -> float:
    """Compile (or load from numba's cache) the kernels of ``methods`` once per process.

    Each method's kernels are warmed up on first need, so a first RK4 run (the default)
    does not wait for the Dormand-Prince kernel too.  Returns the seconds the first
    warm-up of these methods took (the same numbers afterwards).  The "dopri" warm-up
    also compiles ``evaluate`` (its starting step, :func:`rhs`, :func:`element_forces`).
    """
    unknown = sorted(set(methods) - {"rk4", "dopri"})
    if unknown:
        raise OptionError(f"unknown method(s) {unknown}; use 'rk4' or 'dopri'.")
    for method in methods:
        if method in _COMPILE_TIMES:
            continue
        from torquesplit.assembly.structure import MESH, SPLINE, build_structure

        _COMPILE_TIMES[method] = 0.0  # guard: the warm-up below calls integrate()
        t_start = time.perf_counter()
        s = build_structure(
            ["a.theta", "b.theta", "b.x", "b.y"], [1.0, 1.0, 1.0, 1.0],
            [dict(name="m", kind=MESH, dofs=[0, 1, 2], coefs=[1.0, -1.0, 0.1],
                  stiffness=[1.0, 2.0], frequency=1.0, gaps=[0.0, 0.1], damping=0.01,
                  errors=[(0.01, 1.0, 0.0)], force=[0.0, 0.1],
                  friction=dict(table=[[0.1, -0.1], [0.01, 0.0], [0.0, -0.01]],
                                dofs=[0, 1, 3], coefs=[-1.0, -1.0, 1.0], rows=[1, 2, 0])),
             dict(name="sp", kind=SPLINE, x=([2], [-1.0]), y=([3], [-1.0]), stiffness=1.0,
                  damping=0.01, stick_limit=0.001, clearance=0.01, friction_force=0.01,
                  velocity_scale=0.1)],
            n_table=4,
        )
        y0 = np.zeros(8)
        # a Ctrl-C while compiling stops the caller: inside stop_on_interrupt it ended the
        # warm-up run as an interrupted run of its own, and the caller's run went on to its
        # end (a first `torquesplit run` ignored it)
        before = getattr(_stop_on_interrupt, "on", False)
        _stop_on_interrupt.on = False
        try:
            if method == "rk4":
                integrate(s, y0, (0.0, 0.05), method="rk4", step=0.01, full_history=True)
            else:
                integrate(s, y0, (0.0, 0.05), method="dopri", full_history=True)
                rhs(s, 0.0, y0)
        except BaseException:
            del _COMPILE_TIMES[method]  # (not compiled: the next call compiles again)
            raise
        finally:
            _stop_on_interrupt.on = before
        _COMPILE_TIMES[method] = time.perf_counter() - t_start
    return sum(_COMPILE_TIMES[m] for m in methods)


# ================================================================= helpers
def _resolve(names: Sequence[str], selection, what: str) -> list[int]:
    out = []
    for item in selection:
        if isinstance(item, str):
            if item not in names:
                close = difflib.get_close_matches(item, names, n=3)
                hint = f" Did you mean {close}?" if close else ""
                raise OptionError(f"unknown {what} {item!r}.{hint} Use one of the names in "
                                  f"structure.{what}_names or an index.")
            out.append(names.index(item))
        else:
            try:  # (an integer: 1.7 or True is not an index)
                if isinstance(item, bool | np.bool_):
                    raise TypeError
                i = operator.index(item)
            except TypeError:
                raise OptionTypeError(f"each {what} is a name or an integer index, got "
                                      f"{item!r}; use one of structure.{what}_names or "
                                      "its index.") from None
            if not 0 <= i < len(names):
                raise OptionError(f"{what} index {i} is out of range 0..{len(names) - 1}; "
                                  f"use an index or a name from structure.{what}_names.")
            out.append(i)
    return out


def _excitation_periods(structure: Structure) -> np.ndarray:
    f = structure.frequency[structure.frequency > 0]
    om = np.abs(structure.error_omega)
    om = om[om > 0]
    return np.concatenate([1.0 / f, 2 * math.pi / om])


def _natural_period_min(structure: Structure) -> float:
    lam = system_eigenvalues(structure)
    w = float(np.max(np.abs(lam))) if lam.size else 0.0
    return 2 * math.pi / w if w > 0 else math.inf


def _default_atol(structure: Structure, rtol: float) -> np.ndarray:
    """Absolute tolerance per state: rtol x a typical displacement / velocity of each DOF.

    Typical element deformation = max(load / stiffness, half-gap or spline clearance,
    error amplitude), the load being the largest external force or torque carried by any
    element; each DOF's scale is the smallest deformation scale of its elements divided
    by its projection coefficient.  Velocities scale with the highest excitation (or natural) frequency.
    """
    s = structure
    n = s.n_dof
    k_ref = s.stiffness_table.max(axis=1)
    load = 0.0
    for e in range(s.n_elements):
        for j in range(s.v_ptr[e], s.v_ptr[e + 1]):
            c = abs(s.v_coef[j])
            if c > 0:
                load = max(load, abs(s.external_force[s.v_dof[j]]) / c)
    load = max(load, float(np.max(np.abs(s.force_table), initial=0.0)))
    q_scale = np.full(n, np.inf)
    clearance = np.zeros(s.n_elements)  # spline components: their radial clearance
    for (ex, ey), par in zip(s.sp_el, s.sp_par, strict=True):
        clearance[[ex, ey]] = par[3]
    for e in range(s.n_elements):
        gaps = np.append(s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]], clearance[e])
        amp = abs(s.error_constant[e]) + np.sum(np.abs(
            s.error_amplitude[s.error_ptr[e]:s.error_ptr[e + 1]]))
        d = max(load / k_ref[e] if k_ref[e] > 0 else 0.0, float(np.max(gaps)), amp)
        if d <= 0:
            continue
        for j in range(s.v_ptr[e], s.v_ptr[e + 1]):
            c = abs(s.v_coef[j])
            if c > 0:
                q_scale[s.v_dof[j]] = min(q_scale[s.v_dof[j]], d / c)
    finite = np.isfinite(q_scale)
    q_scale[~finite] = np.max(q_scale[finite]) if finite.any() else 1e-6
    periods = _excitation_periods(s)
    period = float(periods.min()) if periods.size else _natural_period_min(s)
    omega = 2 * math.pi / period if math.isfinite(period) else 1.0
    return rtol * np.concatenate([q_scale, q_scale * omega])


# =================================================================== integrate
def integrate(
    structure: Structure,
    y0,
    t_span,
    *,
    method: str = "rk4",
    step: float | None = None,
    steps_per_period: int | None = None,
    rtol: float | None = None,
    atol=None,
    max_step: float | None = None,
    max_steps: int | None = None,
    track_elements=None,
    load_sharing_groups=None,
    load_sharing_min_total=None,
    n_cycles_cap: int | None = None,
    history_elements=None,
    history_dofs=None,
    history_peaks=None,
    record_every: int | None = None,
    sample_interval: float | None = None,
    full_history: bool = False,
    check_stability: bool | None = None,
    blowup: float = 1.0e3,
    progress: Callable[[float], None] | None = None,
    rhs: str = "auto",
    corners: bool = True,
) -> Solution:
    """Integrate the equations of motion of ``structure`` from ``y0`` over ``t_span``.

    Parameters
    ----------
    structure : Structure
        Assembled system.
    y0 : array_like
        Initial state ``[q, v]`` (2 n_dof) or displacements ``q`` only (velocities 0).
        Start from :func:`torquesplit.solve.static.static_equilibrium` to skip start-up
        transients.
    t_span : (float, float)
        Start and end time [s].
    method : {"rk4", "dopri"}
        Classic fixed-step Runge-Kutta 4, or adaptive Dormand-Prince 5(4).
    step : float, optional (rk4)
        Time step [s].  Default: shortest excitation period / ``steps_per_period`` (or
        shortest natural period / ``steps_per_period`` without excitation), refined to
        a whole number of steps per period where the highest mode needs it (see
        :data:`ACCURACY`: resolved, and stable with a 0.8 margin); ``Solution.
        step_limited_by`` says which, and a step more than 10 times shorter than asked
        is warned about with the element that causes it.  Reduced slightly if
        needed so that a whole number of steps spans ``t_span`` (see ``Solution.step``).
    steps_per_period : int, optional (rk4)
        Default 100.
    rtol : float, optional (dopri)
        Relative tolerance, default 1e-6.
    atol : float or array_like, optional (dopri)
        Absolute tolerance, scalar or per state (2 n_dof).  Default: ``rtol`` x a
        typical displacement of each DOF (load / stiffness, gaps, errors) and the
        matching velocity.
    max_step : float, optional (dopri)
        Largest step [s].  Default: shortest excitation period / 20.
    max_steps : int, optional
        Stop with status 3 after this many accepted steps.  Default: no limit for rk4;
        for dopri 10 x the steps at ``max_step`` (at least 100 000).
    track_elements : sequence of int or str, optional
        Elements whose force is summarised per excitation cycle (all must have an
        excitation frequency > 0).  Default: every element with frequency > 0.
    load_sharing_groups : sequence of sequences of int or str, optional
        Groups of tracked elements that share one flow of power: the instantaneous
        ratio N f_i / sum_j f_j of each member (Ji & Li eq. 18) is formed at every step
        and its per-cycle largest and smallest values streamed
        (``Solution.cycle_ratio_max`` / ``cycle_ratio_min``).  Default: none.
    load_sharing_min_total : sequence of float, optional
        Per group, the total force [N] below which no ratio is formed (an instant when the
        group carries almost nothing, e.g. every mesh of it out of contact: the ratio of
        nearly nothing is not load sharing).  Default: any positive total.
    n_cycles_cap : int, optional
        Rows of the cycle arrays.  Default: enough for the whole run.
    history_elements, history_dofs : sequence of int or str, optional
        Elements (forces) and DOFs (q and v) kept in the decimated history.
        Default: all of them.  Pass ``()`` to keep none.
    history_peaks : mapping of str to sequence of (int or str, (3,) array_like), optional
        Force vectors whose magnitude is taken at every instant: name -> terms
        (element, direction), the vector being the sum of each element's force times its
        direction (a bearing's force from its x and y support elements, or a body's from
        its meshes' lines of action).  Each one's largest magnitude between history
        records, over every (accepted) step, corner and peak between steps, is
        ``Solution.history_peaks``: its peak over a span does not depend on the
        sampling.  Default: none.  Ignored without a history.
    record_every : int, optional (rk4)
        History every ``record_every`` steps, default 1.
    sample_interval : float, optional
        History sampling interval [s].  dopri: uniform times by cubic Hermite
        interpolation, default ``max_step``; rk4: rounded to a whole number of steps.
    full_history : bool
        Also keep the full state at every step (rk4) or sample time (dopri).
    check_stability : bool, optional (rk4)
        Refuse an unstable step with :class:`~torquesplit.errors.StepTooLargeError`
        (default True).
    blowup : float
        Stop with status 1 when any |q| exceeds this [m or rad].
    progress : callable, optional
        ``progress(fraction_done)``, called between chunks of the run.
    rhs : {"auto", "generated", "literal", "general"}
        Right-hand side the kernels call.  "generated": this structure's equations as
        straight-line machine code (:mod:`torquesplit.solve.codegen`, compiled in
        0.05 s for 14 DOFs to seconds for 400, cached per sparsity pattern; bit for bit
        the general kernel's results, about twice as fast per step).  "literal": the
        same code with this model's values as constants (compiled per set of values;
        another 4-25 % off a step, the same results; once ``codegen.LITERAL_MAX`` of
        them were compiled in the process (16; environment variable
        ``TORQUESPLIT_LITERAL_MAX``), "generated").  "general": the kernel's
        element loop.  "auto" (default): generated when the run is long enough to repay
        the compilation (:func:`codegen.worth_generating`) or the pattern is already
        compiled, literal when the run is long enough to repay that compilation too
        (:func:`codegen.worth_literal`).  If the code cannot be generated (e.g. an
        llvmlite without the new pass manager) the run uses "general" with a warning;
        ``Solution.rhs`` says which one ran.

    corners : bool
        Where a table (stiffness wave, impact force, per-cycle backlash) has a corner
        (``kernel_data.CORNER_TOL``): RK4 steps through it in sub-steps that end on it,
        so that no step straddles a kink of the right-hand side (which would cost RK4
        its order), and both methods sample the forces there for the per-cycle
        extremes.  False: plain fixed steps and step samples only (to compare with
        another fixed-step RK4 code, step for step).

    Returns
    -------
    Solution
        Never raises for a diverging run: status and message say where and why it
        stopped, and everything recorded before stays valid.  Status 1: a state became
        non-finite or |q| > ``blowup``; 2 (dopri): the step fell below
        max(1e-12 x span, 10 eps |t|); 3: ``max_steps`` reached.

    Notes
    -----
    ``compile_time`` is what this call paid: the first call of a method in a process
    compiles its kernels (or loads them from numba's on-disk cache) through a tiny
    warm-up run; every later call reports 0.  ``wall_time`` excludes it.

    Examples
    --------
    >>> from torquesplit.assembly.structure import MESH, build_structure
    >>> s = build_structure(["g1.theta", "g2.theta"], [1 / 0.01, 1 / 0.04],
    ...     [dict(name="mesh", kind=MESH, dofs=[0, 1], coefs=[0.05, -0.1],
    ...           stiffness=2e8, frequency=1000.0)],
    ...     external_force=[100.0, -200.0])
    >>> sol = integrate(s, [0.0] * 4, (0.0, 0.01))
    >>> sol.success, sol.n_steps
    (True, 1000)
    """
    rk4 = _check_options(method, progress, record_every, sample_interval,
                         rk4_only=dict(step=step, steps_per_period=steps_per_period,
                                       record_every=record_every,
                                       check_stability=check_stability),
                         dopri_only=dict(rtol=rtol, atol=atol, max_step=max_step))
    methods = ("rk4",) if rk4 else ("dopri",)
    # what this call paid: a later call of the same method in the process pays nothing
    compile_time = 0.0 if methods[0] in _COMPILE_TIMES else compile_kernels(methods)
    t_call = time.perf_counter()
    s = structure
    t0, t_end = (float(x) for x in t_span)
    span = t_end - t0
    if not (math.isfinite(span) and span > 0):
        raise OptionError(f"t_span must be (start, end) with end > start, got {t_span!r}.")
    y = _initial_state(s, y0)
    model = kd.kernel_model(s)
    full_model = model  # (plain steps drop the corners, not what they say of the force)
    if not corners:
        model = model._replace(corner_node=np.zeros(0, dtype=np.int64),
                               corner_ptr=np.zeros_like(model.corner_ptr))
    sel = _select(s, t0, span, track_elements, n_cycles_cap, history_elements, history_dofs,
                  load_sharing_groups)
    if rk4:
        plan = _plan_rk4(s, span, step, steps_per_period, check_stability, record_every,
                         sample_interval, full_history, max_steps)
    else:
        plan = _plan_dopri(s, span, rtol, atol, max_step, sample_interval, full_history,
                           max_steps)
    # right-hand-side evaluations the run will need (dopri: at least 6 per largest step)
    n_rhs_planned = 4 * min(plan.n_steps, plan.limit_steps) if rk4 else 6 * span / plan.h_max
    rhs_code = _rhs_code(rhs, model, n_rhs_planned)
    n_hist = plan.n_hist if (sel.hist_el or sel.hist_dof or (full_history and not rk4)) else 0
    need = kd.record_bytes(sel.n_cycles_cap, len(sel.track), n_hist, len(sel.hist_el),
                           len(sel.hist_dof), plan.n_full, s.n_dof)
    if need > _MEMORY_LIMIT:
        raise SolverError(
            f"the requested outputs need {need / 1024**3:.1f} GiB; record less: raise "
            "record_every / sample_interval, list fewer history_elements and "
            "history_dofs, drop full_history, or lower n_cycles_cap.")
    if load_sharing_min_total is not None and len(load_sharing_min_total) != len(sel.groups):
        raise OptionError("load_sharing_min_total needs one value per load-sharing group.")
    vectors = _vectors(s, history_peaks)
    peaks = (VectorPeaks.build(vectors, n_hist, t0,
                               plan.every * plan.h if rk4 else plan.dt_sample,
                               np.flatnonzero(np.diff(model.corner_ptr)))
             if vectors and n_hist else None)
    rec = kd.make_record(sel.track, sel.track_base, sel.n_cycles_cap, sel.groups,
                         s.n_elements, sel.hist_el, sel.hist_dof, n_hist, plan.n_full,
                         s.n_dof, load_sharing_min_total,
                         [kd.continuous_start(full_model.corner_ptr, full_model.corner_node, e)
                          for e in sel.track],
                         dense=peaks.layout if peaks is not None else None,
                         n_dense=_dense_rows(model, plan) if peaks is not None else 0)
    work = kd.make_work(model, rhs_code.parameters)
    work.Y[kd.Y_STATE] = y
    counters = np.zeros(kern.N_COUNTERS, dtype=np.int64)
    clock = np.zeros(kern.N_CLOCK)
    clock[kern.F_T] = t0
    blowup = float(blowup)

    if rk4:
        try:
            _run_rk4(t0, plan, blowup, model, work, rec, rhs_code, counters, clock, progress,
                     peaks)
        finally:  # (what the last chunk recorded, whatever stopped it)
            if peaks is not None:
                peaks.drain(rec)
        step_min = step_max = plan.h
    else:
        clock[kern.F_H] = min(_initial_step(s, y, t0, t_end, plan.rtol, plan.atol, model),
                              plan.h_max)
        counters[kern.I_RHS] = 2  # the two evaluations of the starting-step estimate
        try:
            _run_dopri(t0, t_end, plan, blowup, model, work, rec, rhs_code, counters, clock,
                       progress, peaks)
        finally:
            if peaks is not None:
                peaks.drain(rec)
        accepted = counters[kern.I_STEPS] > 0
        step_min = float(clock[kern.F_HMIN]) if accepted else math.nan
        step_max = float(clock[kern.F_HMAX]) if accepted else math.nan
    y = work.Y[kd.Y_STATE].copy()
    return _solution(s, sel, plan, rec, counters, clock, y, method=method, t_span=(t0, t_end),
                     blowup=blowup, step_min=step_min, step_max=step_max,
                     compile_time=compile_time, wall_time=time.perf_counter() - t_call,
                     rhs_name=("literal" if rhs_code.literal else "generated")
                     if rhs_code.generated else "general",
                     rhs_compile_time=rhs_code.compile_time, full_history=full_history,
                     peaks=peaks if peaks is not None and not peaks.lost(rec) else None)


def _solution(s, sel, plan, rec, counters, clock, y, *, method, t_span, blowup, step_min,
              step_max, compile_time, wall_time, rhs_name, rhs_compile_time,
              full_history, peaks=None) -> Solution:
    """The :class:`Solution` of a finished run from its output arrays (``rec``, a
    :class:`~.kernel_data.Record`), counters, clock and end state ``y``: the one place
    that turns a run's raw outputs into a Solution (the GPU ensemble backend,
    :mod:`torquesplit.gpu`, hands its per-case outputs to it too)."""
    t0, t_end = t_span
    rk4 = method == "rk4"
    status = int(counters[kern.I_STATUS])
    t_final = float(clock[kern.F_T])
    cycles = _cycle_summary(rec, s, sel)
    n_rec = int(counters[kern.I_HIST])
    n_full_rec = int(counters[kern.I_FULL])
    return Solution(
        status=status,
        message=_message(status, s, y, t_final, t_end, counters, clock, blowup,
                         plan.limit_steps, method, plan.rtol),
        success=status == kern.FINISHED,
        method=method,
        t_span=(t0, t_end),
        t_final=t_final,
        y_final=y,
        n_steps=int(counters[kern.I_STEPS]),
        n_rejected=int(counters[kern.I_REJECTED]),
        n_rhs=int(counters[kern.I_RHS]),
        step=plan.h if rk4 else None,
        step_limited_by=plan.limited_by,
        step_min=step_min,
        step_max=step_max,
        compile_time=compile_time,
        wall_time=wall_time,
        rhs=rhs_name,
        rhs_compile_time=rhs_compile_time,
        dof_names=tuple(s.dof_names),
        element_names=tuple(s.element_names),
        tracked_elements=tuple(sel.track),
        load_sharing_groups=tuple(tuple(sel.track[c] for c in g) for g in sel.groups),
        **cycles,
        history_elements=tuple(sel.hist_el),
        history_dofs=tuple(sel.hist_dof),
        history_t=_rows(rec.hist_t, n_rec),
        history_forces=_rows(rec.hist_f, n_rec),
        history_q=_rows(rec.hist_q, n_rec),
        history_v=_rows(rec.hist_v, n_rec),
        full_t=_rows(rec.full_t, n_full_rec) if full_history else None,
        full_y=_rows(rec.full_y, n_full_rec) if full_history else None,
        n_samples=int(counters[kern.I_SAMPLES]),
        separation_steps=rec.sep_count,
        back_contact_steps=rec.back_count,
        separation_time=rec.sep_time,
        back_contact_time=rec.back_time,
        history_peak_names=peaks.names if peaks is not None else (),
        history_peaks=peaks.magnitudes(n_rec) if peaks is not None else None,
    )


# ============================================================ integrate: parts
def _check_options(method, progress, record_every, sample_interval, *, rk4_only,
                   dopri_only) -> bool:
    """Refuse unknown methods and options that the chosen method would ignore."""
    if method not in ("rk4", "dopri"):
        raise OptionError(f"unknown method {method!r}; use method='rk4' (fixed step) or "
                          "method='dopri' (adaptive Dormand-Prince 5(4)).")
    rk4 = method == "rk4"
    ignored = rk4_only if not rk4 else dopri_only
    wrong = [name for name, val in ignored.items() if val is not None]
    if wrong:
        raise OptionError(f"option(s) {wrong} do not apply to method={method!r}; remove them "
                          f"or choose the other method.")
    if record_every is not None and sample_interval is not None:
        raise OptionError("give either record_every or sample_interval, not both.")
    if progress is not None and not callable(progress):
        raise OptionTypeError("progress must be a callable taking the fraction done, e.g. "
                              "progress=lambda f: print(f'{f:.0%}').")
    return rk4


def _initial_state(s: Structure, y0) -> np.ndarray:
    n = s.n_dof
    y = np.array(y0, dtype=np.float64, order="C", copy=True).ravel()
    if y.shape == (n,):
        y = np.concatenate([y, np.zeros(n)])
    if y.shape != (2 * n,):
        raise OptionError(f"y0 must hold {2 * n} values [q, v] or {n} values q, got shape "
                          f"{np.shape(y0)}.")
    if not np.all(np.isfinite(y)):
        raise OptionError("y0 contains NaN or inf; start from finite displacements and "
                          "velocities, e.g. static_equilibrium(structure).y0.")
    return y


def _vectors(s: Structure, history_peaks) -> dict[str, list[tuple[int, np.ndarray]]]:
    """``integrate``'s ``history_peaks`` checked: name -> [(element index, direction)]."""
    if history_peaks is None:
        return {}
    if not hasattr(history_peaks, "items"):
        raise OptionTypeError(f"history_peaks must map a name to (element, direction) "
                              f"terms, e.g. {{'b1': [('b1.support.x', (1, 0, 0))]}}, got "
                              f"{history_peaks!r}")
    out = {}
    for name, terms in history_peaks.items():
        bad = OptionError(f"history_peaks[{name!r}] needs one or more terms (element, "
                          f"direction), each direction three finite numbers (x, y, z), "
                          f"got {terms!r}")
        try:
            els, dirs = zip(*terms)
            dirs = [np.asarray(d, dtype=float).reshape(-1) for d in dirs]
        except (TypeError, ValueError):
            raise bad from None
        if any(d.shape != (3,) or not np.all(np.isfinite(d)) for d in dirs):
            raise bad
        if not all(np.any(d) for d in dirs):
            raise OptionError(f"history_peaks[{name!r}]: a direction of (0, 0, 0) adds "
                              "nothing; give each term its element's axis or line of "
                              "action, e.g. (1, 0, 0).")
        out[str(name)] = list(zip(_resolve(s.element_names, els, "element"), dirs,
                                  strict=True))
    return out


DENSE_CHUNK = 256 * kern.RESYNC
"""Most RK4 steps in a chunk of a run with a dense record (16,384): its buffer stays
about a megabyte, where a chunk of a 10-million-step run (1/64 of it) held 10 MB and
took the benchmark's run over its memory limit."""


def _dense_rows(model, plan) -> int:
    """Rows of the dense record for one chunk of an RK4 run: its steps and at most the
    table corners that can fall inside them (per element, its corners per cycle at its
    mesh frequency), with half as many again to spare.  A Dormand-Prince run returns
    when its record is half full: twice :data:`DENSE_CHUNK` rows and the most a step can
    add (its end and the corners in the largest step).  A record that still fills up
    counts what it lost and the run keeps no peaks (the history's then stand)."""
    n_corners = np.diff(model.corner_ptr)
    per_second = float(np.sum(n_corners * np.abs(model.frequency)))
    if not math.isnan(plan.dt_sample):  # (Dormand-Prince)
        per_step = 1 + math.ceil(1.5 * plan.h_max * per_second) + int(np.sum(n_corners > 0))
        return 2 * (DENSE_CHUNK + per_step) + 16
    steps = min(rk4_chunk(plan.limit_steps), DENSE_CHUNK) + 1
    return steps + math.ceil(1.5 * steps * plan.h * per_second) + 16


@dataclass(frozen=True)
class _Selection:
    track: list[int]
    track_base: np.ndarray  # floor(f t0 + phase) of each tracked element
    n_cycles_cap: int
    hist_el: list[int]
    hist_dof: list[int]
    groups: list[list[int]]  # load-sharing groups as lists of tracked columns


def _select(s, t0, span, track_elements, n_cycles_cap, history_elements,
            history_dofs, load_sharing_groups) -> _Selection:
    if track_elements is None:
        track = [e for e in range(s.n_elements) if s.frequency[e] > 0]
    else:
        track = _resolve(s.element_names, track_elements, "element")
        static_ones = [s.element_names[e] for e in track if not s.frequency[e] > 0]
        if static_ones:
            raise OptionError(f"elements {static_ones} have no excitation frequency, so they "
                              "have no mesh cycles to track; leave them out of track_elements.")
    # same floating-point expressions as the kernel's cycle index at t0
    base = np.array([_cycle_index(s.frequency[e] * t0 + s.phase[e]) for e in track],
                    dtype=np.int64)
    if n_cycles_cap is None:
        f_max = max((float(s.frequency[e]) for e in track), default=0.0)
        cap = int(math.ceil(f_max * span)) + 2 if track else 0
    else:
        cap = int(n_cycles_cap)
        if cap < 0:
            raise OptionError("n_cycles_cap must be >= 0.")
    hist_el = list(range(s.n_elements)) if history_elements is None else _resolve(
        s.element_names, history_elements, "element")
    hist_dof = list(range(s.n_dof)) if history_dofs is None else _resolve(
        s.dof_names, history_dofs, "dof")
    groups = []
    for members in load_sharing_groups or ():
        idx = _resolve(s.element_names, members, "element")
        loose = [s.element_names[e] for e in idx if e not in track]
        if loose or len(set(idx)) != len(idx) or not idx:
            raise OptionError(f"load-sharing group {list(members)!r} must list distinct "
                              f"tracked elements; not tracked: {loose}. Track them "
                              f"(track_elements) or leave them out of the group.")
        groups.append([track.index(e) for e in idx])
    return _Selection(track, base, cap, hist_el, hist_dof, groups)


@dataclass(frozen=True)
class _Plan:
    limit_steps: int  # accepted steps before status MAX_STEPS
    n_hist: int  # rows of the history arrays
    n_full: int  # rows of the full-state arrays
    h: float = math.nan  # rk4 step
    n_steps: int = 0  # rk4 steps spanning t_span
    every: int = 1  # rk4 history decimation
    rtol: float = math.nan  # dopri
    atol: np.ndarray | None = None
    h_max: float = math.nan
    h_min: float = math.nan
    dt_sample: float = math.nan
    limited_by: str = ""  # rk4: what set the step


@remember_last
def _default_step(s: Structure, span: float, spp: int, check: bool):
    """Default RK4 step: (h, what limited it, steps per excitation period).

    Kept per live structure (a Structure is frozen): a run's set-up estimates its cost
    with it and the integrator plans with it, and each costs two eigenvalue problems."""
    return _step_for(s, span, spp, check)


_STEPS = _default_step.cache  # id(structure) -> its last step (entries leave with it)


def shortest_excitation_period(s: Structure) -> float:
    """The period that ``steps_per_period`` divides [s]: the shortest of the meshes' and
    the error sinusoids' (inf where nothing is excited)."""
    periods = _excitation_periods(s)
    return float(periods.min()) if periods.size else math.inf


def _step_for(s: Structure, span: float, spp: int, check: bool):
    period = shortest_excitation_period(s)
    if not math.isfinite(period):
        period = _natural_period_min(s)
    if not math.isfinite(period):  # nothing oscillates: 1000 steps
        period = span * spp / 1000.0
    h = period / spp
    f_hi, element = highest_mode(s)
    h_lim = ACCURACY / (2 * math.pi * f_hi) if f_hi > 0 else math.inf
    h_stable = SAFETY * stable_step(s) if check else math.inf
    if h <= min(h_lim, h_stable):
        return h, _error_sets_step(s, period, spp) or EXCITATION_PERIOD, spp
    per = math.ceil(period / min(h_lim, h_stable))  # a whole number of steps per period
    if h_lim <= h_stable:
        why = (f"the highest mode, {f_hi:.6g} Hz (mostly element '{element}'), needs "
               f"{per} steps per excitation period instead of {spp}")
    else:  # stability, not accuracy: often a stiff damping (a spline's friction)
        why = (f"RK4 stability: {stability_cause(s)}, needs {per} steps per excitation "
               f"period instead of {spp}")
    log.info("RK4 step limited: %s", why)
    return period / per, why, per


def _error_sets_step(s: Structure, period: float, spp: int) -> str | None:
    """What it is, where an error sinusoid faster than every mesh (an LTCA transmission
    -error harmonic) sets the excitation period: the step is then many times shorter
    than ``spp`` per mesh period, which a user otherwise sees only as a slow run."""
    om = np.abs(s.error_omega)
    f_mesh = float(s.frequency.max(initial=0.0))
    if not om.size or not 2 * math.pi / om.max() < (1.0 / f_mesh if f_mesh > 0 else math.inf):
        return None
    j = int(np.argmax(om))
    e = int(np.searchsorted(s.error_ptr, j, side="right") - 1)
    f = om[j] / (2 * math.pi)
    what = f"the {f:.6g} Hz error sinusoid of element '{s.element_names[e]}'"
    if s.frequency[e] > 0:
        order = f / s.frequency[e]
        what += (f" (order {order:.3g} of its mesh frequency: a transmission-error "
                 f"harmonic)")
    per_mesh = spp / (period * f_mesh) if f_mesh > 0 else math.nan
    return (f"{what}, {spp} steps per its period ({per_mesh:.4g} per shortest mesh "
            f"period); fewer (--steps-per-period, checked by --check-step; in Python "
            f"steps_per_period=, checked by torquesplit.convergence.check_step) make the run "
            f"shorter")


EXCITATION_PERIOD = "excitation period"
"""What sets the RK4 step when ``steps_per_period`` does (``step_limited_by``); else the
highest mode, RK4 stability or an error sinusoid, in words."""


def finer_step_advice(structure: Structure, limited_by: str, step: float) -> str:
    """How to ask for a finer RK4 step, in words to put in brackets after "a finer
    step": ``--steps-per-period`` where the excitation period sets the step; where
    something else does (the highest mode, stability), that only a number above the
    steps per period that makes refines it (the plain advice sent users to an option
    that changed nothing below that number)."""
    plain = "--steps-per-period; steps_per_period= in Python"
    if not limited_by or limited_by == EXCITATION_PERIOD or not step > 0:
        return plain
    per = shortest_excitation_period(structure) / step
    if not math.isfinite(per) or ", needs " not in limited_by:  # (an error sinusoid's
        return plain  # period, a given step: --steps-per-period refines it as it says)
    cause = limited_by.split(", needs ")[0]  # (what _step_for says, less its numbers)
    return (f"a --steps-per-period above {round(per)}, steps_per_period= in Python: the "
            f"step is set here by {cause}, at {round(per)} steps per shortest excitation "
            f"period")


def planned_step(structure: Structure, steps_per_period: int | None = None,
                 span: float = 1.0) -> tuple[float, str]:
    """The RK4 step :func:`integrate` would take by default and what sets it (the
    excitation period or the highest mode), without integrating: for cost estimates."""
    spp = 100 if steps_per_period is None else int(steps_per_period)
    h, why, _ = _default_step(structure, float(span), spp, True)
    return h, why


def whole_steps(span: float, h: float) -> tuple[int, float]:
    """``(n, step)``: the fixed RK4 steps that span ``span`` [s] with steps of at most
    about ``h`` (h is kept when it already divides the span)."""
    n_float = span / h
    n_steps = int(round(n_float))
    if n_steps < 1 or abs(n_float - n_steps) > 1e-9 * n_float:
        n_steps = max(1, int(math.ceil(n_float)))
    if abs(n_steps * h - span) > 1e-12 * span:
        h = span / n_steps
    return n_steps, h


def _plan_rk4(s, span, step, steps_per_period, check_stability, record_every,
              sample_interval, full_history, max_steps) -> _Plan:
    spp = 100 if steps_per_period is None else int(steps_per_period)
    if spp < 1:
        raise OptionError("steps_per_period must be >= 1.")
    check = True if check_stability is None else bool(check_stability)
    limited_by = EXCITATION_PERIOD
    if step is None:
        h, limited_by, per = _default_step(s, span, spp, check)
        if per > _STEP_WARN_FACTOR * spp:
            warn_user(
                f"the RK4 step is {per / spp:.3g} times shorter than {spp} steps per "
                f"excitation period: {limited_by}; the run takes "
                f"{math.ceil(span / h):,} steps. Check that element's stiffness and unit "
                f"(and the inertias it joins): a stiffness this high is usually a slip of "
                f"units; an adaptive method (dopri) is explicit too and needs as short a "
                f"step, so it does not help.", ModelWarning)
    else:
        h = float(step)
        if check:
            check_step(s, h)
        elif not (h > 0 and math.isfinite(h)):
            raise OptionError(f"step must be a positive number of seconds, got {step!r}.")
    n_steps, h = whole_steps(span, h)
    if sample_interval is not None:
        every = max(1, int(round(float(sample_interval) / h)))
    else:
        every = 1 if record_every is None else int(record_every)
        if every < 1:
            raise OptionError("record_every must be >= 1.")
    limit = n_steps if max_steps is None else min(n_steps, int(max_steps))
    return _Plan(limit_steps=limit, n_hist=n_steps // every + 1,
                 n_full=n_steps + 1 if full_history else 0, h=h, n_steps=n_steps,
                 every=every, limited_by=limited_by if step is None else "given step")


def _plan_dopri(s, span, rtol, atol, max_step, sample_interval, full_history,
                max_steps) -> _Plan:
    rtol = 1e-6 if rtol is None else float(rtol)
    if not rtol > 0:
        raise OptionError("rtol must be > 0, e.g. rtol=1e-6.")
    if atol is None:
        atol = _default_atol(s, rtol)
    else:
        atol = np.ascontiguousarray(np.broadcast_to(np.asarray(atol, dtype=np.float64),
                                                    (2 * s.n_dof,))).copy()
        if not np.all(atol > 0):
            raise OptionError("atol must be > 0 (scalar or one value per state [q, v]).")
    periods = _excitation_periods(s)
    if max_step is None:
        h_max = float(periods.min()) / 20.0 if periods.size else span
    else:
        h_max = float(max_step)
        if not h_max > 0:
            raise OptionError("max_step must be > 0.")
    if sample_interval is None:
        dt = h_max if (periods.size or max_step is not None) else span / 1000.0
    else:
        dt = float(sample_interval)
        if not dt > 0:
            raise OptionError("sample_interval must be > 0.")
    n_hist = int(math.floor(span / dt * (1 + 1e-12))) + 1
    limit = max(100_000, int(10 * span / h_max)) if max_steps is None else int(max_steps)
    return _Plan(limit_steps=limit, n_hist=n_hist, n_full=n_hist if full_history else 0,
                 rtol=rtol, atol=atol, h_max=h_max, h_min=1e-12 * span, dt_sample=dt)


def _cycle_summary(rec: kd.Record, s: Structure, sel: _Selection) -> dict:
    """Cycle arrays trimmed to the cycles reached; NaN where a cycle has no sample.

    Works in place on the kernel's buffers (the sums become means), so the summary
    costs no second copy of them.
    """
    cnt_all = rec.cyc_cnt
    used = np.flatnonzero(cnt_all.any(axis=1))
    n_cyc = int(used[-1]) + 1 if used.size else 0
    empty = cnt_all == 0
    for buf in (rec.cyc_max, rec.cyc_min):
        buf[empty] = np.nan
    for buf in (rec.rat_max, rec.rat_min):
        buf[~np.isfinite(buf)] = np.nan
    # the time integral over the cycle's time: its mean force (NaN without samples)
    timed = ~empty & (rec.cyc_wt > 0.0)
    np.divide(rec.cyc_sum, rec.cyc_wt, out=rec.cyc_sum, where=timed)
    rec.cyc_sum[~timed] = np.nan
    tr = np.array(sel.track, dtype=np.int64)
    rows = np.arange(n_cyc)[:, None]
    start = (sel.track_base[None, :] + rows - s.phase[tr][None, :]) \
        / s.frequency[tr][None, :] if tr.size else np.zeros((n_cyc, 0))
    # a slower mesh's rows past its last cycle are no cycles: no start time (the rows
    # run to the fastest mesh's count; their starts lay far beyond the run's end)
    if tr.size:
        start[_rows(cnt_all, n_cyc) == 0] = np.nan
    return dict(cycle_start=start, cycle_max=_rows(rec.cyc_max, n_cyc),
                cycle_min=_rows(rec.cyc_min, n_cyc), cycle_mean=_rows(rec.cyc_sum, n_cyc),
                cycle_count=_rows(cnt_all, n_cyc),
                cycle_ratio_max=_rows(rec.rat_max, n_cyc),
                cycle_ratio_min=_rows(rec.rat_min, n_cyc))


def _cycle_index(s: float) -> int:
    """Statistics cycle index of mesh phase s (as ``_kernels.excite_tables``)."""
    fl = math.floor(s)
    return fl + 1 if s - fl >= 1.0 - kern.CYCLE_EPS else fl


def _rows(buf: np.ndarray, n: int) -> np.ndarray:
    """The first n rows of an output buffer (the solution owns the buffer).

    A view when nearly all of it is used (no second copy of a large output), else a
    copy, so that a mostly unused buffer (a run that stopped early) is freed.
    """
    return buf[:n] if n >= 0.9 * buf.shape[0] else buf[:n].copy()


RHS_KINDS = ("auto", "generated", "literal", "general")


def _rhs_code(kind: str, model, n_rhs: float, literal: bool = True) -> codegen.GeneratedRhs:
    """The right-hand side the kernels call (see ``integrate(rhs=...)``); ``literal``
    False where the caller changes the parameters after the code was chosen (the
    steady-state solvers, whose turning frame's terms follow the speed)."""
    if kind not in RHS_KINDS:
        raise OptionError(f"rhs must be 'auto', 'generated', 'literal' or 'general', got "
                          f"{kind!r}.")
    if kind == "general" or (kind == "auto" and not codegen.worth_generating(model, n_rhs)):
        return codegen.general_rhs()
    if kind == "literal" and not literal:
        raise OptionError("rhs='literal' writes the model's values into the code, but "
                          "this solver keeps them where it can change them (a turning "
                          "carrier's frame terms follow the speed): use rhs='generated' "
                          "(the same results).")
    # literal code: when asked for, or when it repays its compilation ("auto"); beyond
    # codegen.LITERAL_MAX per process, the pattern's code (the same results)
    use_literal = literal and (
        (kind == "literal" and codegen._COMPILER.literal_available(model))
        or (kind == "auto" and codegen.worth_literal(model, n_rhs)))
    if literal and kind == "auto" and not use_literal:
        codegen.note_pattern_run(model, n_rhs)  # (the next run of these values may)
    try:
        return codegen.generated_rhs(model, use_literal)
    except Exception as exc:  # noqa: BLE001 - any failure falls back, with a warning
        global _CODEGEN_WARNED
        if not _CODEGEN_WARNED:
            _CODEGEN_WARNED = True
            warn_user(f"could not compile this model's right-hand side ({type(exc).__name__}: "
                          f"{exc}); using the general kernel (same results, about half the "
                          f"speed).", RuntimeWarning)
        return codegen.general_rhs()


def rk4_chunk(limit_steps: int) -> int:
    """Steps per call of the RK4 kernel (a multiple of RESYNC, about 1.5 % of the run).
    A chunk starts with the exact excitation and the table corners found afresh from its
    start time (``first_corners``); the GPU ensemble kernel (:mod:`torquesplit.gpu`)
    does the same at the same steps, so that both take the same sub-steps."""
    per_chunk = math.ceil(limit_steps / _N_CHUNKS)
    return max(_MIN_CHUNK_STEPS, -(-per_chunk // kern.RESYNC) * kern.RESYNC)


_ENTRIES: dict = {}


def _type_key(a):
    """What numba's typing of argument ``a`` depends on, found without typing it, for the
    kinds of argument the kernels take: a plain (non-record) array's dtype, dimensions,
    layout, writeability and alignment; a tuple's class and its items'; a float, a bool,
    an int within int64, a generated function's class.  None for anything else (a list,
    a record array, a huge int: numba may type two such values apart), which is then
    typed by numba itself."""
    if isinstance(a, np.ndarray):
        if a.dtype.fields is not None or a.dtype.kind not in "biuf":
            return None
        f = a.flags
        return (a.dtype.str, a.ndim, f.c_contiguous, f.f_contiguous, f.writeable, f.aligned)
    if isinstance(a, tuple):
        items = tuple(_type_key(x) for x in a)
        return None if any(k is None for k in items) else (type(a), items)
    if isinstance(a, (bool, float, np.float64)):
        return type(a)
    if isinstance(a, int):
        return int if -(2**63) <= a < 2**63 else None
    if hasattr(a, "__wrapper_address__") or type(a).__name__ == "CFunc":
        return type(a)
    return None


def _compiled(dispatcher, args):
    """The compiled function that ``dispatcher(*args)`` runs, to call without numba's
    argument typing (a named tuple of 44 arrays costs about 2 ms to type, on every
    call), found by :func:`_type_key`; the dispatcher itself when it has not run with
    such arguments yet (call it, then ask again) or cannot be found."""
    items = tuple(_type_key(a) for a in args)
    if any(k is None for k in items):
        return dispatcher
    key = (dispatcher, items)
    entry = _ENTRIES.get(key)
    if entry is not None:
        return entry
    try:
        sig = tuple(dispatcher.typeof_pyval(a) for a in args)
        entry = dispatcher.overloads[sig].entry_point
    except Exception:  # noqa: BLE001 - not compiled for these yet, or any surprise
        return dispatcher
    _ENTRIES[key] = entry
    return entry


def _run_rk4(t0, plan, blowup, model, work, rec, rhs_code, counters, clock, progress,
             peaks=None):
    """Run the RK4 kernel in chunks (multiples of RESYNC steps, about 1.5 % each); with
    ``peaks`` (:class:`~.vector_peaks.VectorPeaks`) the dense record is entered and
    emptied after each chunk, of at most :data:`DENSE_CHUNK` steps."""
    chunk = rk4_chunk(plan.limit_steps)
    if peaks is not None:
        chunk = min(chunk, DENSE_CHUNK)
    done = 0
    run = None
    while done < plan.limit_steps:
        m = min(chunk, plan.limit_steps - done)
        last = done + m == plan.limit_steps
        args = (t0, plan.h, done, m, last, plan.every, blowup, model, work, rec,
                rhs_code.function, rhs_code.generated, counters, clock)
        if run is None or run is kern.rk4_run:
            run = _compiled(kern.rk4_run, args)
        try:
            run(*args)
            done += m
            if peaks is not None:
                peaks.drain(rec)
            if counters[kern.I_STATUS] != kern.FINISHED:
                return
            if progress is not None:
                progress(done / plan.n_steps)
        except (KeyboardInterrupt, SystemError) as exc:
            if not _interrupted(exc):
                raise
            counters[kern.I_STATUS] = INTERRUPTED
            return
    if plan.limit_steps < plan.n_steps:
        counters[kern.I_STATUS] = kern.MAX_STEPS


def _run_dopri(t0, t_end, plan, blowup, model, work, rec, rhs_code, counters, clock,
               progress, peaks=None):
    """Run the Dormand-Prince kernel up to successive 1/64 fractions of the span; with
    ``peaks`` (:class:`~.vector_peaks.VectorPeaks`) the kernel also returns when its
    dense record is half full, to have it entered and emptied."""
    clock[kern.F_FACOLD] = 1e-4
    clock[kern.F_HMIN] = math.inf
    clock[kern.F_HMAX] = 0.0
    span = t_end - t0
    run = None
    for k in range(1, _N_CHUNKS + 1):
        t_stop = t_end if k == _N_CHUNKS else t0 + span * k / _N_CHUNKS
        if clock[kern.F_T] >= t_stop:
            continue
        args = (t0, t_end, t_stop, plan.rtol, plan.atol, plan.h_max, plan.h_min,
                plan.limit_steps, blowup, plan.dt_sample, model, work, rec,
                rhs_code.function, rhs_code.generated, counters, clock)
        if run is None or run is kern.dopri_run:
            run = _compiled(kern.dopri_run, args)
        try:
            run(*args)
            while peaks is not None and counters[kern.I_STATUS] == kern.FINISHED:
                peaks.drain(rec)
                if clock[kern.F_T] >= t_stop:
                    break
                run(*args)
            if counters[kern.I_STATUS] != kern.FINISHED:
                return
            if progress is not None:
                progress(min(1.0, (clock[kern.F_T] - t0) / span))
        except (KeyboardInterrupt, SystemError) as exc:
            if not _interrupted(exc):
                raise
            counters[kern.I_STATUS] = INTERRUPTED
            return


def _initial_step(s, y, t0, t_end, rtol, atol, model) -> float:
    """Starting step of the adaptive method (Hairer, Norsett & Wanner, Solving ODE I,
    II.4, 'starting step size')."""
    sc = atol + rtol * np.abs(y)
    sc = np.where(sc > 0, sc, 1e-300)
    f0, _, _ = _evaluate(s, t0, y, model)
    d0 = math.sqrt(np.mean((y / sc) ** 2))
    d1 = math.sqrt(np.mean((f0 / sc) ** 2))
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end - t0)
    f1, _, _ = _evaluate(s, t0 + h0, y + h0 * f0, model)
    d2 = math.sqrt(np.mean(((f1 - f0) / sc) ** 2)) / h0
    dmax = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if dmax <= 1e-15 else (0.01 / dmax) ** (1.0 / 5.0)
    return min(100 * h0, h1, t_end - t0)


DRIFT_SHARE = 0.99
"""A diverged state whose displacement lies along the rigid-body modes by at least this
share (mass-weighted) is a drift of the whole train, not an instability (:func:`_drift`)."""


def _drift(s, y) -> str:
    """The explanation of a 'divergence' that is the train drifting along its rigid-body
    motion (a torque or power drive against a torque load: nothing holds the speed, and
    any imbalance accumulates), or "" if the state is not that.  A reviewer's 100 s run
    of a differential 'diverged' at 97 s with advice to shorten the step, which did not
    help; a load's speed_coefficient did."""
    from .static import rigid_body_modes

    n = s.n_dof
    try:
        phi = rigid_body_modes(s)
    except Exception:  # (an explanation, never a second failure)
        return ""
    if phi.shape[1] == 0:
        return ""
    m = 1.0 / np.asarray(s.inv_mass, dtype=float)
    q, v = np.asarray(y[:n], dtype=float), np.asarray(y[n:], dtype=float)
    q_rigid = phi @ (phi.T @ (m * q))
    total = float(np.sqrt(np.sum(m * q * q)))
    along = float(np.sqrt(np.sum(m * q_rigid * q_rigid)))
    if not (total > 0 and along >= DRIFT_SHARE * total):
        return ""
    v_rigid = phi @ (phi.T @ (m * v))
    j = int(np.argmax(np.abs(q_rigid) * np.sqrt(m)))
    unit = "rad/s" if s.dof_names[j].endswith("theta") else "m/s"
    return (f"That is no instability: {100 * along / total:.4g} % of the displacement "
            f"(mass-weighted) is the whole train turning together, a rigid-body motion "
            f"(at the end '{s.dof_names[j]}' {v_rigid[j]:+.3g} {unit} off its nominal "
            f"speed): nothing in the model holds its speed (a torque or power drive "
            f"against a torque load), so any imbalance accumulates: the damping's losses "
            f"of the vibration are one (drive and load torques balanced at the nominal "
            f"ratio leave no power for them). Give a "
            f"load a speed_coefficient (loads.NAME.speed_coefficient, a torque that "
            f"grows with speed, as a real load's does) or drive a member by its speed; a "
            f"smaller step does not help.")


def _message(status, s, y, t_final, t_end, counters, clock, blowup, limit_steps,
             method, rtol=math.nan) -> str:
    n = s.n_dof
    n_steps = int(counters[kern.I_STEPS])
    if status == kern.FINISHED:
        return (f"The solver successfully reached the end of the integration interval "
                f"(t = {t_final:.6g} s) in {n_steps} steps.")
    if status == kern.DIVERGED:
        i = int(counters[kern.I_BAD])
        name = s.dof_names[i % n] + (" (velocity)" if i >= n else "")
        bound = ""
        if not math.isfinite(y[i]):
            why = f"the state of DOF '{name}' is not finite ({y[i]})"
        else:
            why = f"|q| of DOF '{name}' = {abs(y[i]):.3g} exceeds blowup = {blowup:.3g}"
            # (simulate has no blowup argument: say where the bound is set)
            bound = (" A displacement this large that is real needs a larger bound "
                     "(blowup= of torquesplit.solve.integrate).")
        drift = _drift(s, y) if math.isfinite(y[i]) else ""
        if drift:  # (not a step problem: a reviewer followed the advice in vain)
            return (f"Integration diverged at t = {t_final:.6g} s (step {n_steps}): {why}. "
                    f"Everything recorded before that time is valid. {drift}")
        fix = ("Use a smaller step (steps_per_period; the command line's "
               "--steps-per-period) or method='dopri', and check stiffness signs and "
               "units and that the drive and load torques balance." if method == "rk4" else
               f"Tighten rtol (it was {rtol:.3g}: try {rtol / 10:.3g}, rtol= in Python, "
               f"--set analysis.rtol={rtol / 10:.3g} on the command line): a loose "
               f"tolerance lets the steps grow past what the stiffest mode allows; and "
               f"check stiffness signs and units and that the drive and load torques "
               f"balance.") + bound
        return (f"Integration diverged at t = {t_final:.6g} s (step {n_steps}): {why}. "
                f"Everything recorded before that time is valid. {fix}")
    if status == INTERRUPTED:
        return (f"Interrupted ({interrupt_name()}) at t = {t_final:.6g} s (step {n_steps}) "
                f"of t_end = {t_end:.6g} s. Everything recorded before that time is valid.")
    if status == kern.STEP_UNDERFLOW:
        return (f"Required step size {clock[kern.F_H]:.3g} s fell below the minimum at "
                f"t = {t_final:.6g} s (step {n_steps}); the response is too stiff or "
                f"discontinuous there for method='dopri'. Loosen rtol/atol, or use "
                f"method='rk4' with a step from check_step.")
    return (f"Maximum number of steps ({limit_steps}) reached at t = {t_final:.6g} s before "
            f"t_end = {t_end:.6g} s. Raise max_steps"
            + (" or loosen rtol/atol." if method == "dopri" else "."))
