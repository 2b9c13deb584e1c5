"""Periodic steady state at one operating point: :func:`periodic_solution`.

Works on an assembled :class:`~torquesplit.assembly.structure.Structure`; the model
pipeline (model -> kinematics -> structure -> static -> periodic state -> Results) is
:func:`torquesplit.steady.steady_state`.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from torquesplit.errors import (
    ModelWarning,
    OptionError,
    SolverError,
    from_interrupt,
    warn_user,
)
from torquesplit.solve._frozen import freeze_arrays
from torquesplit.solve._kernels import MESH_KIND
from torquesplit.steady.harmonic import HarmonicBalance
from torquesplit.steady.newton import (
    floquet_hill,
    floquet_monodromy,
    matrix_free,
    solve_hb,
    solve_shooting,
)
from torquesplit.steady.period import Period
from torquesplit.steady.problem import PeriodicProblem

log = logging.getLogger(__name__)

STABILITY_TOL = 1e-6
"""A periodic state is stable when every Floquet multiplier has |mu| <= 1 + this."""
MARGINAL_TOL = 1e-5
"""... and only marginally so when the largest is within this of 1 (a mode without
damping: its multipliers sit on the unit circle, where any change can take them out)."""
MAX_HARMONICS = 2 ** 15
"""Most harmonics the harmonic balance takes (given, or reached by adaptive doubling)."""
UNDAMPED = 1e-6
"""A mode whose modal damping ratio is below this has no damping (:func:`undamped_note`)."""


def warn_undamped(structure, q) -> None:
    """Warn (a ModelWarning) of the modes without damping (:func:`undamped_note`)."""
    from torquesplit.errors import ModelWarning, warn_user

    note = undamped_note(structure, q)
    if note:
        warn_user(note, ModelWarning)


def undamped_note(structure, q) -> str:
    """A warning naming the modes without damping (modal damping ratio below
    :data:`UNDAMPED`) and the element with the largest share of each one's strain energy,
    or '': their periodic response is marginally stable and unbounded at their resonances
    (a reviewer's speed sweep crawled into one for 1100 points, to a dynamic factor of 85,
    reported as the stable maximum; split_path_planetary_differential's pinion_b support
    has no damping)."""
    from torquesplit.solve.modal import modal_analysis

    try:
        sol = modal_analysis(structure, q)
    except Exception:  # noqa: BLE001 - a note, never a reason to stop the analysis
        return ""
    idle = [i for i, (f, z) in enumerate(zip(sol.frequencies, sol.damping_ratios))
            if f > 0 and abs(z) < UNDAMPED]
    if not idle:
        return ""
    said = "; ".join(f"mode {i + 1} ({sol.frequencies[i]:.6g} Hz, "
                     f"{100 * sol.dominant_elements(i, 1)[0][1]:.0f} % of its strain energy in "
                     f"{sol.dominant_elements(i, 1)[0][0]})" for i in idle[:4])
    more = f" and {len(idle) - 4} more" if len(idle) > 4 else ""
    return (f"{len(idle)} mode(s) without damping: {said}{more}: a periodic state is at "
            f"best marginally stable (|mu| = 1) and grows without bound at their "
            f"resonances; give the elements they load a damping ratio")
HARMONICS_PER_CYCLE = 8
"""Harmonics per cycle of the fastest excitation to start from (raised until converged)."""
ENERGY_TOL = 1e-7
"""Adaptive HB stops when the highest quarter of the harmonics holds at most this share of
the velocity energy.  1e-6 left Liu et al. 2021's spur-split dynamic factors 0.4 % from
shooting (at 32 harmonics); 1e-7 brings them within 4e-4 and Ji & Li's within 6e-5
(benchmarks/STEADY_RESULTS.md)."""
MAX_SAMPLES = 1 << 16
"""Shooting keeps the state and every element's force at most this many times a period
(every k-th RK4 step, k the smallest divisor of the steps that gets there), the meshes'
forces and deformations at every step: Jin et al. 2019's full period (725,200 steps, 52
DOFs) held 2.2 GB at every step, 3.0 GB with its Results."""
MAX_TRACK_BYTES = 4 << 30
"""Shooting refuses a period whose per-step mesh forces and deformations would take more
memory than this (Ji & Li's drive at 0.001 rpm: 3.2e10 steps, a 941 GiB allocation that
failed with a traceback after the warning that it would take hours)."""
ANNOUNCE_SECONDS = 2.0
"""A shooting solve whose integration of one period is estimated to take longer is
announced before it starts, with what sets its steps: Ji & Li's drive at 1 rpm ran for
minutes without a word (its highest mode, not its slow meshes, sets the step)."""
SECONDS_PER_DOF_STEP = 25e-9
"""Rough cost of an RK4 step per DOF (benchmarks/RESULTS.md: 16-33 ns), for estimates."""
HILL_LIMIT = 800
"""Largest Hill matrix (complex, square) for Hill's method; larger: the monodromy."""
AUTO = "shooting unless harmonics or Hill's method are asked for"
"""What ``method='auto'`` does.  Since shooting steps through the tables' corners it is
the faster and the more accurate of the two on every shipped example (closer to long
time integration by one to three orders; benchmarks/STEADY_RESULTS.md), short periods
included; harmonic balance stays for a number of harmonics asked for, Hill's stability
and the speed continuation."""


@dataclass(frozen=True, eq=False)
class PeriodicSolution:
    """A periodic steady state over one period (SI; samples at ``t``)."""

    method: str
    """'hb' (harmonic balance) or 'shooting'."""
    converged: bool
    message: str
    speed: float
    """Speed factor (1 = the model's speed)."""
    frequency: float
    """Fundamental frequency at this speed [Hz]."""
    harmonics: int | None
    """Harmonics of the fundamental (HB)."""
    iterations: int
    residual: float
    """Final Newton residual: HB, largest residual harmonic over the largest
    acceleration; shooting, the periodicity defect over the largest deformation."""
    time_residual: float
    """Time-domain check: RMS of the equation residual q'' - a(t, q, q') midway between
    the HB samples over the largest acceleration (large where a table steps: the series
    cannot follow a jump of the acceleration); shooting: the same as ``residual``."""
    periodicity_defect: float
    """One period integrated by RK4 from the solution's state at t = 0 returns within
    this (largest element deformation mismatch over the largest deformation); NaN when
    not checked."""
    top_harmonic_energy: float
    """Share of the velocity energy sum m (k w)^2 |c_k|^2 in the highest quarter of the
    retained harmonics (HB; NaN for shooting)."""
    multipliers: np.ndarray | None
    """Floquet multipliers (rigid-body ones left out), by decreasing modulus."""
    stability_method: str
    """'monodromy', 'hill' or '' (not computed)."""
    t: np.ndarray
    """(N,) sample times over one period [s]: HB's samples; shooting's RK4 steps, every
    ``sample_every``-th on a long period (the meshes at every step: ``mesh_t``)."""
    q: np.ndarray
    """(N, n) displacements [m, rad]."""
    v: np.ndarray
    """(N, n) velocities."""
    forces: np.ndarray
    """(N, n_el) element forces [N]."""
    deformations: np.ndarray
    """(N, n_el) element deformations V q - e [m]."""
    rigid_load: np.ndarray
    """Per rigid mode: uniform acceleration carried (undamped mode) or steady speed
    offset (mode damped by a load characteristic)."""
    coefficients: np.ndarray | None = field(default=None)
    """HB unknowns (a_0, a_1, b_1, ... per DOF, then the rigid terms)."""
    wall_time: float = 0.0
    corner_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Shooting: the instants in (0, T) where a table of an element's excitation has a
    corner, inside the RK4 steps (which step through them, as the integrators do); HB:
    empty.  A force peak sits at a corner of a stiffness table more often than not (on
    Ji & Li's drive, stage 1 kept, the steps alone left a dynamic factor 2.4e-3 low)."""
    corner_forces: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """(len(corner_t), n_el) element forces at those instants: in the extremes, and as
    breakpoints of the means (spectra use ``t`` alone)."""
    corner_deformations: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """(len(corner_t), n_el) element deformations at those instants (contact regimes)."""
    mesh_elements: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """Shooting: indices of the mesh elements, the columns of ``mesh_forces`` (HB: empty,
    its samples ``t`` serve)."""
    mesh_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """(M,) times of ``mesh_forces``: every RK4 step of the period (``t`` holds every
    ``sample_every``-th)."""
    mesh_forces: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """(M, len(mesh_elements)) forces of the meshes at ``mesh_t``: what the peaks, means,
    per-cycle statistics and load sharing are taken from."""
    mesh_deformations: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """(M, len(mesh_elements)) their deformations (transmission error, contact loss)."""
    sample_every: int = 1
    """Shooting: ``t``, ``q``, ``v``, ``forces``, ``deformations`` are every this many RK4
    steps (1 unless the period has more than :data:`MAX_SAMPLES` steps)."""
    repeats_within: int = 1
    """k > 1: a period of k cycles of every excitation was asked for (a subharmonic,
    ``keep=``), but the orbit found repeats after one k-th of it: no such response from
    this start (its multipliers are those of the shorter orbit to the k-th power)."""

    def __post_init__(self):
        freeze_arrays(self)

    @property
    def period(self) -> float:
        return 1.0 / self.frequency

    @property
    def stable(self) -> bool | None:
        if self.multipliers is None:
            return None
        return bool(np.max(np.abs(self.multipliers), initial=0.0) <= 1 + STABILITY_TOL)

    @property
    def marginal(self) -> bool:
        """Stable, but with a multiplier within :data:`MARGINAL_TOL` of the unit circle."""
        return bool(self.stable and np.max(np.abs(self.multipliers), initial=0.0)
                    >= 1 - MARGINAL_TOL)

    @property
    def y0(self) -> np.ndarray:
        return np.concatenate([self.q[0], self.v[0]])


def initial_guess(initial, n: int, n_rigid: int | None = None) -> np.ndarray | None:
    """``steady_state(initial=...)`` checked: a state [q, v] (2 n values) or, with
    ``n_rigid`` (harmonic balance), the coefficients of another harmonic count (m n +
    n_rigid values); a guess of another size was dropped without a word (shooting) or
    failed deep inside (harmonic balance)."""
    if initial is None:
        return None
    from ..errors import OptionError

    try:
        init = np.asarray(initial, dtype=float)
    except (TypeError, ValueError):
        init = None
    sizes = f"a state [q, v] of {2 * n} values" + (
        f", or the harmonic coefficients of a solution (m x {n} + {n_rigid} values)"
        if n_rigid is not None else "")
    if (init is None or init.ndim != 1 or not np.all(np.isfinite(init)) or not (
            init.size == 2 * n or (n_rigid is not None and init.size > n_rigid
                                   and (init.size - n_rigid) % n == 0))):
        shown = getattr(init, "shape", None)
        raise OptionError(f"initial must be {sizes} (finite numbers), got "
                          f"{initial!r:.60}" + (f" of shape {shown}" if shown else ""))
    return init


def _initial_hb(hb: HarmonicBalance, q_static, initial):
    x = np.zeros(hb.size)
    u, _ = hb.split(x)
    if initial is not None:
        init = initial_guess(initial, hb.p.n, hb.p.nr)
        if init.size == 2 * hb.p.n:  # a state: mean from it
            u[0] = init[:hb.p.n]
        else:  # coefficients of another H
            return pad_coefficients(init, hb)
    elif q_static is not None:
        u[0] = q_static
    p = hb.p
    if p.nr:
        u[0] -= p.rigid @ (p.rigid.T @ (p.mass * u[0]))
    return x


def pad_coefficients(x_old, hb: HarmonicBalance, n_rigid: int | None = None):
    """HB unknowns of another harmonic count, truncated or padded with zeros."""
    n = hb.p.n
    nr = hb.p.nr if n_rigid is None else n_rigid
    m = (len(x_old) - nr) // n
    old = x_old[:m * n].reshape(m, n)
    x = np.zeros(hb.size)
    u, lam = hb.split(x)
    k = min(m, u.shape[0])
    u[:k] = old[:k]
    lam[:] = x_old[m * n:]
    return x


def top_energy(hb: HarmonicBalance, x, speed=1.0) -> float:
    """Share of the velocity energy in the highest quarter of the harmonics."""
    u, _ = hb.split(x)
    k = np.arange(1, hb.H + 1)
    e = ((u[1::2] ** 2 + u[2::2] ** 2) * hb.p.mass[None, :]).sum(axis=1) * k**2
    tot = float(e.sum())
    if tot <= 0:
        return 0.0
    return float(e[k > 0.75 * hb.H].sum() / tot)


def _stability(compute):
    """``compute()``'s (multipliers, method); a Ctrl-C while it runs gives (None,
    "interrupted"): the converged state is kept (:class:`~torquesplit.errors.
    SteadyInterrupted` then stops the caller with it), where it was thrown away after the
    stability's seconds (a reliability reviewer)."""
    try:
        return compute()
    except (KeyboardInterrupt, SystemError) as exc:
        if not from_interrupt(exc):
            raise
        return None, "interrupted"


def _announce(p, T, steps, stability) -> None:
    """Warn before a shooting solve of ``steps`` RK4 steps per period ``T``: how long
    each integration of the period is, roughly, and what sets the steps."""
    from torquesplit.solve.stability import highest_mode

    f_hi, element = highest_mode(p.structure)
    n_mode = int(math.ceil(2 * math.pi * f_hi * T)) if f_hi > 0 else 0
    why = (f"the highest mode, {f_hi:.6g} Hz (mostly element '{element}'), needs "
           f"{n_mode:,} for the period of {T:.4g} s" if n_mode >= 0.9 * steps
           else f"a period of {T:.4g} s")
    per_map = SECONDS_PER_DOF_STEP * p.structure.n_dof * steps
    more = (f"; the stability adds {2 * p.structure.n_dof} variational columns "
            f"(--no-stability skips them)" if stability else "")
    warn_user(
        f"the periodic state takes {steps:,} RK4 steps per period ({why}): about "
        f"{per_map:.2g} s per integration of the period, and the solve takes several"
        f"{more}; a speed near the model's, or 'torquesplit run', is quicker",
        ModelWarning)


def converged_hb(p, H, samples, speed, q_static, initial, tol, *, adaptive=True,
                 energy_tol=ENERGY_TOL, max_harmonics=2**15, smallest=False, say=None):
    """HB solution with H harmonics; with ``adaptive``, H raised (each solve started from
    the last) until the top quarter of the harmonics holds at most ``energy_tol`` of the
    velocity energy.  H is doubled, or after two converged solves multiplied by the power
    of two that the energy's decay so far says is needed (at most 8x a step): the series
    of a stepped stiffness converges slowly and every intermediate solve costs.  A solve
    whose Newton stalls (a residual just above ``tol`` is the usual case on larger models)
    is followed by a doubled one; after two stalls in a row the last converged solution is
    returned.  ``smallest``: after a jump of more than one doubling, half the harmonics
    are tried too and kept if they pass (worth one solve when the solution is used many
    times, as along a continuation).  Returns (HarmonicBalance, coefficients, Newton
    info, top energy)."""
    best, last, stalled, jumped = None, None, 0, False
    while True:
        if say is not None:
            say(f"harmonic balance, {H} harmonics")
        hb = HarmonicBalance(p, H, samples)
        x0 = _initial_hb(hb, q_static, initial)
        x, info = solve_hb(hb, x0, speed, tol)
        energy = top_energy(hb, x, speed)
        if info.converged:
            best, stalled = (hb, x, info, energy), 0
        else:
            stalled += 1
        if not adaptive or 2 * H > max_harmonics or stalled >= 2 or (
                info.converged and energy <= energy_tol):
            if smallest and jumped and info.converged:
                fewer = converged_hb(p, H // 2, samples, speed, q_static, x, tol,
                                     adaptive=False)
                if fewer[2].converged and fewer[3] <= energy_tol:
                    return fewer
            return best if best is not None and not info.converged else (hb, x, info, energy)
        doublings = 1
        if info.converged and last is not None and 0 < energy < last[1]:
            per_doubling = (last[1] / energy) ** (1.0 / math.log2(H / last[0]))
            if per_doubling > 1.5:
                need = math.log(energy / energy_tol) / math.log(per_doubling)
                doublings = min(3, max(1, math.ceil(need - 1e-9)))
        while doublings > 1 and H * 2**doublings > max_harmonics:
            doublings -= 1
        log.info("HB with %d harmonics: %s, to %d", H,
                 f"top-band energy {energy:.2e} > {energy_tol:.1e}" if info.converged
                 else f"Newton stalled at {info.residual:.2e}", H * 2**doublings)
        if info.converged:
            last = (H, energy)
        initial = x
        jumped = doublings > 1
        H *= 2**doublings


def sample_stride(steps: int, most: int | None = None) -> int:
    """Smallest divisor k of ``steps`` with steps / k <= ``most`` (default
    :data:`MAX_SAMPLES`): the samples stay equally spaced over the period."""
    k = max(1, -(-int(steps) // int(MAX_SAMPLES if most is None else most)))
    while steps % k:
        k += 1
    return k


METHODS = ("auto", "hb", "shooting")
"""The steady-state methods: harmonic balance, shooting, or shooting unless harmonics are
given."""


def check_method(method) -> None:
    """Refuse a steady-state method that is none of :data:`METHODS`."""
    if method not in METHODS:
        raise OptionError(f"unknown method {method!r}; use method='hb' (harmonic balance), "
                          "method='shooting' or method='auto' (shooting unless harmonics "
                          "are given).")


def periodic_solution(structure, period: Period, *, method: str = "auto", harmonics=None,
                      samples=None, speed: float = 1.0, q_static=None, initial=None,
                      tol: float | None = None, adaptive: bool = False,
                      energy_tol: float = ENERGY_TOL, max_harmonics: int = MAX_HARMONICS,
                      stability: bool | str = True, steps_per_cycle: int | None = None,
                      check: bool = True, problem: PeriodicProblem | None = None,
                      progress=None) -> PeriodicSolution:
    """Periodic steady state of ``structure`` over ``period`` (see :func:`steady_state`
    for the parameters).  ``q_static`` starts the iteration (HB: as the mean)."""
    t_start = time.perf_counter()

    def say(what: str) -> None:
        if progress is not None:
            progress(None, what)

    check_method(method)
    if period.frequency <= 0:
        raise SolverError("the structure has no time-varying excitation, so its steady state "
                          "is the static equilibrium; use static_equilibrium instead.")
    p = problem or PeriodicProblem(structure, period.frequency)
    order = max(period.max_order, 1)
    # cycles of every excitation in the period: > 1 where ``keep`` asked for a fraction
    # of their frequencies (a period-doubled response: two mesh cycles)
    sub = math.gcd(*[int(k) for k in period.orders]) if period.orders else 1
    repeats = False
    f = period.frequency * speed
    T = 1.0 / f
    steps = p.rk4_steps(T, steps_per_cycle, order)
    if method == "auto":  # see AUTO
        method = "hb" if harmonics is not None or stability == "hill" else "shooting"
    # the meshes whose forces shooting keeps at every step
    meshes = np.flatnonzero(np.asarray(p.model.element_kind) == MESH_KIND)
    if method == "shooting":
        need = 16 * (steps + 1) * meshes.size
        if need > MAX_TRACK_BYTES:
            raise SolverError(
                f"one period at this speed ({T:.4g} s) takes {steps:,} RK4 steps, whose mesh "
                f"forces need {need / 2**30:.3g} GiB (at most "
                f"{MAX_TRACK_BYTES / 2**30:.3g}) and hours of integration; choose a speed "
                f"nearer the model's, --method hb, or 'torquesplit run' for a transient at "
                f"this speed")
    if method == "shooting" and (SECONDS_PER_DOF_STEP * p.structure.n_dof * steps
                                 > ANNOUNCE_SECONDS):
        _announce(p, T, steps, stability)
    multipliers = None
    stab_method = ""
    every = 1
    if method == "hb":
        H = int(harmonics) if harmonics is not None else HARMONICS_PER_CYCLE * order
        tol = 1e-10 if tol is None else tol
        hb, x, info, energy = converged_hb(p, H, samples, speed, q_static, initial, tol,
                                           adaptive=adaptive, energy_tol=energy_tol,
                                           max_harmonics=max_harmonics, say=say)
        H = hb.H
        if adaptive and info.converged and energy > energy_tol:
            warn_user(
                f"harmonic balance stopped at {H} harmonics (the limit is {max_harmonics}) "
                f"with {energy:.1e} of the velocity energy in the top quarter, above "
                f"{energy_tol:.0e}: peak forces may be off in the last digits; use "
                f"method='shooting' (--method shooting), or keep one stage's excitations "
                f"(keep=, --keep) for a shorter period", ModelWarning)
        r, a, F, D, q, v = hb.residual_samples(x, speed)
        rm = hb.residual_samples(x, speed, shift=0.5)[0]
        t_res = float(np.sqrt(np.mean(rm**2))) / max(float(np.max(np.abs(a))), 1e-300)
        t = hb.times(speed)
        _, lam = hb.split(x)
        v = hb._states(q, v, lam)[:, p.n:]  # physical velocity (rigid speed offset included)
        defect = math.nan
        y0 = np.concatenate([q[0], v[0]])
        if check:  # one period as the integrators step it (through the tables' corners)
            yT = p.integrate(y0, 0.0, T, steps, every=steps, speed=speed, max_rows=1)[3]
            defect = _defect(p, y0, yT)
        if stability:
            say("Floquet multipliers")

            def hb_multipliers():
                if stability == "hill" or (stability is True and hill_applies(p, H, f)):
                    return floquet_hill(hb, x, speed, None if stability == "hill" else H), \
                        "hill"
                return floquet_monodromy(p, p.integrate_variational(y0, 0.0, T, steps,
                                                                    speed)[1]), "monodromy"

            multipliers, stab_method = _stability(hb_multipliers)
        msg = (f"harmonic balance, {H} harmonics of {f:.6g} Hz, {hb.N} samples: "
               + ("converged" if info.converged else "did NOT converge")
               + f" in {info.iterations} Newton steps (residual {info.residual:.2e})")
        coeffs = x
    else:
        tol = 1e-9 if tol is None else tol
        every = sample_stride(steps)

        kept = [None]

        # every defect map keeps the period's waveforms, in one set of arrays refilled
        # by each (what is kept is the last map's: the solution's, once converged)
        def record(y):
            kept[0] = p.run(y, 0.0, T, steps, every=every, speed=speed, corners=True,
                            track=meshes, out=kept[0])
            return kept[0]

        if initial is not None:
            y0 = initial_guess(initial, p.n)
        else:
            y0 = np.concatenate([q_static if q_static is not None else np.zeros(p.n),
                                 np.zeros(p.n)])
            if sub > 1:  # a subharmonic: settle onto it, off the orbit of 1/sub the period
                say(f"settling onto a response of {sub} excitation periods (up to "
                    f"{SUBHARMONIC_SETTLE} periods)")
                y0 = settle_periods(p, y0, T, steps, speed, SUBHARMONIC_SETTLE)
            elif not matrix_free(p, steps):  # (Anderson's first map is the settling)
                say(f"settling the transient ({steps:,} RK4 steps per period)")
                y0 = p.settled_start(y0, T, steps, speed, order)
        y0, Phi, info = solve_shooting(p, y0, steps, speed, tol, monodromy=bool(stability),
                                       record=record, say=say)
        if sub > 1 and steps % sub == 0:  # the orbit of the period's fraction after all?
            y_part = p.integrate(y0, 0.0, T / sub, steps // sub, every=steps // sub,
                                 speed=speed, max_rows=1)[3]
            repeats = _defect(p, y0, y_part) <= 1e-6
        run = info.run
        corner_t, corner_f, corner_d = run.corner_t, run.corner_forces, run.corner_deformations
        t, q, v = run.t[:-1], run.y[:-1, :p.n], run.y[:-1, p.n:]
        F, D = run.forces[:-1], run.deformations[:-1]
        mesh_t = np.arange(steps) * (T / steps)
        mesh_f, mesh_d = run.track_forces[:-1], run.track_deformations[:-1]
        t_res = info.residual
        defect = info.residual
        energy = math.nan
        H = None
        lam = np.zeros(p.nr)
        if stability:
            if Phi is None:  # matrix-free Newton: the monodromy at the solution
                say(f"Floquet multipliers: the monodromy, {2 * p.n} columns over "
                    f"{steps:,} RK4 steps")

            def shooting_multipliers():
                at = Phi if Phi is not None else p.integrate_variational(y0, 0.0, T, steps,
                                                                         speed)[1]
                return floquet_monodromy(p, at), "monodromy"

            multipliers, stab_method = _stability(shooting_multipliers)
        newton = info.iterations - info.anderson
        steps_taken = " and ".join(
            [f"{info.anderson} Anderson-accelerated period maps"] * bool(info.anderson)
            + [f"{newton} Newton steps"] * bool(newton or not info.anderson))
        msg = (f"shooting, {steps} RK4 steps per period of {T:.6g} s: "
               + ("converged" if info.converged else "did NOT converge")
               + f" in {steps_taken} (defect {info.residual:.2e}"
               + (f", {info.products} matrix-free monodromy products)" if info.products
                  else ")")
               + (f"; waveforms kept every {every} steps, the meshes' forces at every step"
                  if every > 1 else "")
               + (f"; the orbit repeats every 1/{sub} of the period: no response of {sub} "
                  f"excitation periods from this start" if repeats else ""))
        coeffs = None
    return PeriodicSolution(
        method=method, converged=info.converged, message=msg, speed=float(speed),
        frequency=f, harmonics=H, iterations=info.iterations, residual=info.residual,
        time_residual=t_res, periodicity_defect=defect, top_harmonic_energy=energy,
        multipliers=multipliers, stability_method=stab_method, t=np.asarray(t),
        q=np.asarray(q), v=np.asarray(v), forces=np.asarray(F), deformations=np.asarray(D),
        rigid_load=np.asarray(lam, dtype=float), coefficients=coeffs,
        wall_time=time.perf_counter() - t_start,
        sample_every=every, repeats_within=sub if repeats else 1,
        **({} if method == "hb" else dict(
            corner_t=corner_t, corner_forces=corner_f, corner_deformations=corner_d,
            mesh_elements=meshes,
            mesh_t=mesh_t, mesh_forces=mesh_f, mesh_deformations=mesh_d)))


def hill_applies(p: PeriodicProblem, H: int, frequency: float) -> bool:
    """Hill's method is used automatically when its matrix is small and its harmonics
    reach beyond the highest natural frequency (else the truncation cannot hold the
    fast modes and the monodromy is used)."""
    from torquesplit.solve.stability import highest_mode

    m2 = 2 * p.n - (p.nr + int(np.sum(~p.rigid_damped)))
    f_hi, _ = highest_mode(p.structure)
    return m2 * (2 * H + 1) <= HILL_LIMIT and H * frequency >= 1.5 * f_hi


SUBHARMONIC_SETTLE = 400
"""Most periods integrated before shooting a response of several excitation periods: an
unstable orbit of the excitation's period (period doubling, multiplier -1.08) is left
at the rate of its multiplier, and Newton from near it would find it again."""


def settle_periods(p: PeriodicProblem, y, T, steps, speed, most: int):
    """``y`` integrated period by period until one period changes the state by less than
    1e-7 of the largest deformation, or ``most`` periods."""
    for _ in range(most):
        y_next = p.integrate(y, 0.0, T, steps, every=steps, speed=speed, max_rows=1)[3]
        if not np.all(np.isfinite(y_next)):
            break
        done = _defect(p, y, y_next) <= 1e-7
        y = y_next
        if done:
            break
    return y


def _defect(p: PeriodicProblem, y0, yT) -> float:
    from torquesplit.steady.newton import rigid_subspace

    R = rigid_subspace(p)
    d = yT - y0
    d = d - R @ (R.T @ d)
    V = p.structure.projection_matrix()
    n = p.n
    scale = max(float(np.max(np.abs(V @ y0[:n]), initial=0.0)), 1e-300)
    return float(np.max(np.abs(V @ d[:n]), initial=0.0)) / scale
