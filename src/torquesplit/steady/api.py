"""Model-level periodic steady state: :func:`steady_state` and :class:`SteadyState`.

The pipeline is that of :func:`torquesplit.simulate` with the time integration replaced
by a periodic solver: model -> kinematics -> structure -> static equilibrium ->
fundamental period (or the kept excitations) -> periodic state.  The periodic state
converts to a :class:`torquesplit.results.Results` (:meth:`SteadyState.to_results`)
whose "run" is the periodic state repeated over a few periods, so every metric, plot
and export of a dynamic run works on it unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit import _args
from torquesplit.errors import OptionError, SolverError, collect_model_warnings, warn_user
from torquesplit.solve.kernel_data import continuous_start
from torquesplit.steady.period import (
    base_frequency,
    default_max_cycles,
    fundamental_period,
    keep_excitations,
)
from torquesplit.steady.problem import PeriodicProblem, periodic_problem
from torquesplit.steady.solution import ENERGY_TOL, PeriodicSolution, periodic_solution

__all__ = ["steady_state", "SteadyState", "MeshSteady", "speed_factor", "reference_speed"]


@dataclass(frozen=True)
class MeshSteady:
    """One line of the per-mesh table of a periodic state (forces in N)."""

    mesh: str
    group: str
    nominal_force: float
    """Equal-split static tooth force (kinematics)."""
    static_force: float
    """The mesh's own static force (static equilibrium)."""
    mean_force: float
    min_force: float
    peak_force: float
    dynamic_factor: float
    """peak / the mesh's own static force."""
    peak_to_nominal: float
    """peak / the equal-split nominal force."""
    load_sharing: float
    rms_transmission_error: float
    """RMS about its mean of the dynamic transmission error along the line of action
    [m]: the relative displacement of the flanks ``V q``, elastic deflection and the
    errors (tooth modifications through the LTCA, eccentricities, transmission errors)
    together, as a transmission-error measurement gives it."""
    contact_loss: float
    """Fraction of the period with the teeth apart."""


def reference_speed(model) -> float:
    """|speed| of the model's first drive [rad/s]: the speed factor 1."""
    drives = list(model.drives.values())
    if not drives:
        raise SolverError("the model has no drive, so it has no speed; add a [drives] entry.")
    return abs(float(drives[0].speed))


def speed_factor(model, speed) -> float:
    """Speed factor of an input speed: rad/s, or a string with its unit ('3000 rpm',
    '50 Hz': revolutions per second); None: 1."""
    if speed is None:
        return 1.0
    from torquesplit.model.units import parse_quantity

    try:
        value = parse_quantity(speed, "speed")
    except ValueError as exc:
        raise OptionError(f"speed: {exc}") from None
    s = value / reference_speed(model)
    if not (s > 0 and math.isfinite(s)):  # (a negative speed was turned round silently)
        raise OptionError(f"speed {speed!r} is not a positive finite speed (its direction "
                          f"is the model's); give e.g. speed='3000 rpm' or speed=314.16 "
                          f"(rad/s).")
    _warn_far_speed(model, speed, value, s)
    return s


def _warn_far_speed(model, speed, value: float, s: float) -> None:
    """Warn where a speed is far from the model's input speed in the way a unit slip
    makes it: written in Hz and over 10 times (or under a tenth of) it (Hz is the unit of
    every frequency the tool prints: a mesh frequency pasted as a speed ran Ji & Li's
    drive at 44,700 rpm without a word), or a bare number (rad/s) over 5 times or under a
    fifth of it (745 meant as rpm is 9.5 times 745 rpm).  The command line says a bare
    number's unit itself."""
    rpm = 30.0 / math.pi
    at = (f"{s:.3g} times the model's input speed "
          f"({reference_speed(model) * rpm:.6g} rpm)")
    if isinstance(speed, str):
        if "hz" not in speed.lower() or 0.1 <= s <= 10.0:
            return
        text = (f"speed {speed!r} is {value / (2 * math.pi):.6g} revolutions per second = "
                f"{value * rpm:,.6g} rpm, {at}; a speed in Hz counts revolutions per "
                f"second: give it in rpm if a frequency was meant")
    elif 0.2 <= s <= 5.0:
        return
    else:
        text = (f"speed {speed!r} is read in rad/s = {value * rpm:,.6g} rpm, {at}; give "
                f"speed='{speed:g} rpm' if rpm were meant")
    from torquesplit.errors import ModelWarning

    warn_user(text, ModelWarning)


def _check_options(*, steps_per_cycle, tol, stability, energy_tol, method="auto",
                   harmonics=None, max_cycles=None) -> None:
    """The solver options of :func:`steady_state`, refused by name before any work:
    steps_per_cycle=0 and -3 ran, tol=-1 ran 3.6 s to 'NOT converged', stability='foo'
    was taken (a reviewer)."""
    import numbers

    if steps_per_cycle is not None and (
            isinstance(steps_per_cycle, bool) or not isinstance(steps_per_cycle, numbers.Real)
            or not float(steps_per_cycle).is_integer() or steps_per_cycle < 10):
        raise OptionError(f"steps_per_cycle must be a whole number >= 10, got "
                          f"{steps_per_cycle!r}; give e.g. steps_per_cycle=100")
    for name, value in (("tol", tol), ("energy_tol", energy_tol)):
        if value is not None and (isinstance(value, bool) or not isinstance(
                value, numbers.Real) or not 0 < value < 1):
            raise OptionError(f"{name} must be a small positive number, got {value!r}; "
                              f"leave it out for the default")
    from torquesplit.steady.solution import check_method

    check_method(method)
    if harmonics is not None and (isinstance(harmonics, bool) or not isinstance(
            harmonics, numbers.Integral) or harmonics < 1):
        raise OptionError(f"harmonics must be a whole number >= 1, got {harmonics!r}; e.g. "
                          f"harmonics=16 per excitation cycle")
    from torquesplit.steady.solution import MAX_HARMONICS

    if harmonics is not None and harmonics > MAX_HARMONICS:  # (1e6 on a 1-DOF model took
        # 3 million samples and 13 s; a larger model runs out of memory)
        raise OptionError(f"harmonics {harmonics} is more than {MAX_HARMONICS}, the most the "
                          f"harmonic balance takes (the adaptive doubling's limit); a period "
                          f"needing more is solved by shooting (method='shooting')")
    if harmonics is not None and method == "shooting":  # (ignored without a word)
        raise OptionError(f"harmonics={harmonics} sets the harmonic balance; "
                          f"method='shooting' integrates in time and takes none: leave one "
                          f"of them out (method='hb', or no harmonics)")
    if not (max_cycles is None or max_cycles == "auto" or (
            isinstance(max_cycles, numbers.Integral) and not isinstance(max_cycles, bool)
            and max_cycles >= 1)):
        raise OptionError(f"max_cycles must be a whole number >= 1, 'auto' or None, got "
                          f"{max_cycles!r}")
    if not (isinstance(stability, bool) or stability in ("hill", "monodromy")):
        raise OptionError(f"stability must be True, False, 'hill' or 'monodromy', got "
                          f"{stability!r}")


class SteadyState:
    """A periodic steady state of a model and everything needed to interpret it."""

    def __init__(self, *, model, kinematics, structure, static, period, solution,
                 dropped, problem, options=None, notes=()):
        self.model = model
        #: the ModelWarnings given while it was solved (kept with its results)
        self.notes = list(notes)
        self._critical: list[str] | None = None
        #: the arguments of :func:`steady_state` that chose the problem (keep, speed,
        #: max_cycles), so that it can be solved again (e.g. finer: convergence.check_steady)
        self.options = dict(options or {})
        self.kinematics = kinematics
        self.structure = structure
        #: the static equilibrium at the speed solved (a turning carrier's centrifugal
        #: loads are that speed's)
        self.static = static
        #: the excitations kept and their orders, at the model's own speed: its
        #: ``period.period`` is the model speed's; the period solved, at the speed asked,
        #: is :attr:`period_s` (``solution.period``)
        self.period = period
        self.solution: PeriodicSolution = solution
        self.dropped = dropped
        self.problem: PeriodicProblem = problem
        # the model at the speed solved (torques held): what the metrics, the exports
        # and the critical speeds of this state read; ``kinematics`` and ``structure``
        # are the model's own speed's, which the solver scales (``solution.speed``)
        from torquesplit.model.kinematics import kinematics_at

        factor = solution.speed
        #: :attr:`kinematics` at the speed solved
        self.kinematics_at = kinematics_at(kinematics, factor)
        #: :attr:`structure` at the speed solved (:meth:`PeriodicProblem.structure_at`)
        self.structure_at = problem.structure_at(factor)

    @property
    def period_s(self) -> float:
        """The period of this steady state [s], at the speed it was solved at (the same
        as ``solution.period``; ``period.period`` is the model's own speed's)."""
        return self.solution.period

    def __repr__(self) -> str:
        from .maps import RPM, reference_speed

        sol = self.solution
        # (the speed solved at, in rpm: a speed factor alone did not say 700 rpm was asked)
        rpm = reference_speed(self.model) * sol.speed * RPM
        return (f"SteadyState({self.model.model.name!r}: {sol.method} at {rpm:.6g} rpm "
                f"(speed factor {sol.speed:.6g}), period "
                f"{self.period_s:.4g} s, "
                f"{'converged' if sol.converged else 'NOT converged'})")

    @property
    def success(self) -> bool:
        return self.solution.converged

    @property
    def mesh_names(self) -> list[str]:
        return list(self.model.meshes)

    def samples(self, per_cycle: int = 64, n: int | None = None):
        """(t, forces, deformations) over one period: HB at ``n`` equally spaced times
        (default: at least ``per_cycle`` per cycle of the fastest excitation; q and v by
        trigonometric interpolation, the forces from the model's laws at those times);
        shooting at its samples (every ``sample_every``-th RK4 step; the meshes at every
        step: :meth:`mesh_series`)."""
        per_cycle = _args.whole(per_cycle, "per_cycle", "per_cycle=64", minimum=2)
        if n is not None:
            n = _args.whole(n, "n", "n=256", minimum=2)
        ps = self.solution
        if ps.method != "hb":
            return ps.t, ps.forces, ps.deformations
        from torquesplit.steady.harmonic import HarmonicBalance

        n_need = per_cycle * max(self.period.max_order, 1)
        N = max(len(ps.t), 1 << int(math.ceil(math.log2(max(n_need, 2))))) if n is None \
            else int(n)
        if N == len(ps.t):
            return ps.t, ps.forces, ps.deformations
        every = int(math.ceil((2 * ps.harmonics + 2) / N))  # enough samples for the series
        hb = HarmonicBalance(self.problem, ps.harmonics, N * every)
        x = ps.coefficients
        q, v, _ = hb.waveforms(x, ps.speed)
        _, lam = hb.split(x)
        t = hb.times(ps.speed)
        Y = hb._states(q, v, lam)[::every]
        t = t[::every]
        _, F, D = self.problem.accelerations(t, Y, ps.speed)
        return t, F, D

    def mesh_series(self, elements=None):
        """(t, forces, deformations) of the elements ``elements`` (indices or element
        names such as mesh names; default every mesh, in the model file's order) over
        one period at their finest: every RK4 step for meshes (shooting keeps the other
        elements every ``sample_every`` steps only), the samples otherwise."""
        names = list(self.structure.element_names)
        if elements is None:  # (a Python API reviewer's call without it: a TypeError)
            elements = list(self.model.meshes)
        elif isinstance(elements, (str, int, np.integer)):  # one element ('m11' was read
            elements = [elements]  # letter by letter: "unknown element 'm'", a reviewer)
        try:
            elements = [names.index(e) if isinstance(e, str) else int(e) for e in elements]
        except ValueError:
            unknown = [e for e in elements if isinstance(e, str) and e not in names]
            raise OptionError(f"unknown element {unknown[0]!r}; the elements are "
                              f"{names}") from None
        ps = self.solution
        cols = {int(e): j for j, e in enumerate(ps.mesh_elements)}
        if ps.method != "hb" and ps.mesh_t.size and all(int(e) in cols for e in elements):
            idx = [cols[int(e)] for e in elements]
            if idx == list(range(len(cols))):  # all of them, in order: no copy
                return ps.mesh_t, ps.mesh_forces, ps.mesh_deformations
            return ps.mesh_t, ps.mesh_forces[:, idx], ps.mesh_deformations[:, idx]
        t, F, D = self.samples()
        return t, F[:, list(elements)], D[:, list(elements)]

    def save(self, path, *, overwrite: bool = False, periods: int | None = None):
        """Save the periodic state as ``torquesplit steady --out`` does (its record as a
        run's, :meth:`to_results`, with the steady-state attributes): ``.nc``, ``.mat`` or
        ``.csv``.  Returns the path written."""
        return self.to_results(periods).save(path, overwrite=overwrite)

    def to_results(self, periods: int | None = None):
        """The periodic state as :class:`~torquesplit.results.Results` (the state
        repeated over ``periods`` periods: default enough for 4 settle windows), whose
        metrics take every complete cycle of whole periods (``Results.periodic``)."""
        from torquesplit.results import Results

        kin, s = self.kinematics_at, self.structure_at  # (at the speed solved)
        shell = Results(model=self.model, kinematics=kin, structure=s, static=self.static,
                        solution=None)
        sol = _as_solution(self, shell, periods)
        res = Results(model=self.model, kinematics=kin, structure=s,
                      static=self.static, solution=sol, periodic=True,
                      period=self.solution.period)
        res.steady = self
        # what was said while solving, and the critical speeds near this one, as a run
        # keeps them: its files and report carry them
        res.run_warnings = self.notes + (self.critical_notes() if self.solution.converged
                                         else [])
        return res

    def critical_notes(self) -> list[str]:
        """``"location: message"`` of each critical speed near the one solved, as
        ``run`` warns of them at its own (computed once)."""
        if self._critical is None:
            from torquesplit.steady.maps import near_critical_notes

            # (the modes at the speed solved; the excitation lines per unit speed are
            # the model's own)
            self._critical = near_critical_notes(
                self.model, self.problem.structure_at(self.solution.speed, frequencies=False),
                self.static.q, self.kinematics,
                speed=self.solution.speed * reference_speed(self.model))
        return self._critical

    def summary(self, rows=None, results=None) -> dict:
        """What ``torquesplit steady`` prints, as a dict (its ``--json`` and the
        ``steady_json`` attribute of a saved steady state): method, period, residuals,
        stability, the excitations replaced by their means, and the per-mesh table
        (``rows``: :meth:`mesh_table`, computed when not given, from ``results`` when
        given: the :meth:`to_results` already at hand)."""
        from torquesplit.results import default_definition

        ps = self.solution
        mu = ps.multipliers
        results = self.to_results() if results is None else results
        rows = self.mesh_table(results=results) if rows is None else rows
        # each group's and the system's numbers, as a run's --json has them (a steady
        # state's had the meshes only: an exports reviewer)
        met = results.metrics().to_dict()
        return {
            "model": self.model.model.name, "method": ps.method, "converged": ps.converged,
            "message": ps.message, "period_s": ps.period, "fundamental_Hz": ps.frequency,
            "period": self.period.describe(ps.frequency / self.period.frequency),
            "harmonics": ps.harmonics, "residual": ps.residual,
            "time_residual": ps.time_residual, "periodicity_defect": ps.periodicity_defect,
            "top_harmonic_energy": ps.top_harmonic_energy,
            "stable": ps.stable, "stability_method": ps.stability_method,
            "largest_multiplier": float(abs(mu[0])) if mu is not None and mu.size else None,
            "dropped_excitations": self.dropped_text(),
            # which coefficient 'load_sharing' is (sweep_speed's is mean_force's)
            "load_sharing_definition": default_definition(self.model),
            "meshes": {r.mesh: {k: v for k, v in r.__dict__.items() if k != "mesh"}
                       for r in rows},
            "groups": met["groups"], "system_load_sharing": met["system_load_sharing"],
        }

    def dropped_text(self) -> list[str]:
        """The excitations ``keep`` replaced by their means, in words, at this state's
        speed."""
        ps = self.solution
        return [d.describe(ps.frequency / self.period.frequency) for d in self.dropped]

    def mesh_table(self, definition: str | None = None, results=None) -> list[MeshSteady]:
        """Per-mesh static, mean, min and peak force, dynamic factors, load sharing
        (``definition``: the model's by default), RMS transmission error, contact loss;
        ``results``: this state's :meth:`to_results` if already made."""
        res = self.to_results() if results is None else results
        met = res.metrics(definition)
        names = self.structure.element_names
        t, F, D = self.mesh_series([names.index(r.mesh) for r in met.rows])
        Fc = self.solution.corner_forces  # instants at table corners (shooting)
        if Fc.shape[0] == 0:
            Fc = np.zeros((0, self.structure.n_elements))
        T = self.solution.period
        tc = self.solution.corner_t[:Fc.shape[0]]
        ws, wc = period_weights(t, tc, T)
        kinks = (self.problem.corner_times(0.0, T, self.solution.speed)
                 if self.solution.method != "hb" else np.zeros(0))
        out = []
        for j, r in enumerate(met.rows):
            e = names.index(r.mesh)
            f, d = F[:, j], D[:, j]
            te = d + self.problem.line_errors([e], t, self.solution.speed)[:, 0]  # V q
            vmax, vmin = np.full(1, -np.inf), np.full(1, np.inf)
            if self.solution.method != "hb":  # (a truncated series rings between samples)
                t_c, f_c, d_c = corner_columns(self.solution, e)
                s = self.structure_at  # (the gap sequences at the speed solved)
                vmax, vmin = between_samples(t, f, d, half_gaps(s, e, t), T,
                                             t_c, f_c, d_c, half_gaps(s, e, t_c),
                                             kinks=kinks)
            peak = float(max(f.max(), Fc[:, e].max(initial=-np.inf), vmax.max()))
            least = float(min(f.min(), Fc[:, e].min(initial=np.inf), vmin.min()))
            mean = float((ws @ f + wc @ Fc[:, e]) / self.solution.period)
            out.append(MeshSteady(
                mesh=r.mesh, group=r.group, nominal_force=r.nominal_force,
                static_force=r.static_force, mean_force=mean,
                min_force=least, peak_force=peak,
                dynamic_factor=peak / r.static_force,
                peak_to_nominal=peak / r.nominal_force,
                load_sharing=r.load_sharing,
                rms_transmission_error=float(np.sqrt(np.mean((te - te.mean()) ** 2))),
                contact_loss=r.contact_loss))
        return out


def steady_state(model, *, method: str = "auto", harmonics: int | None = None,
                 samples: int | None = None, keep=None, speed: float | str | None = None,
                 max_cycles: int | None | str = "auto", stability: bool | str = True,
                 adaptive: bool | None = None, energy_tol: float = ENERGY_TOL,
                 tol: float | None = None, steps_per_cycle: int | None = None,
                 check: bool = True, initial=None, progress=None) -> SteadyState:
    """Periodic steady state of a model at one speed.

    Parameters
    ----------
    model : Model, str or Path
    method : {"auto", "hb", "shooting"}
        Harmonic balance with alternating frequency-time evaluation, or shooting (Newton
        on the period map, stepping through the tables' corners; robust for contact loss
        and impacts; matrix-free on long periods).  ``"auto"`` (default): shooting, the
        faster and more accurate on every shipped example, unless ``harmonics`` or
        Hill's stability is asked for (then harmonic balance).
    harmonics : int, optional
        HB harmonics of the fundamental frequency.  Default: 8 per cycle of the fastest
        excitation to start with, raised (``adaptive``) until the highest quarter of the
        harmonics holds less than ``energy_tol`` of the velocity energy
        (:func:`~torquesplit.steady.solution.converged_hb`).  The stepped stiffness of a
        contact-ratio change needs many: on Ji & Li's drive 8 per cycle leave the dynamic
        factor 0.03 low; the adaptive rule stops at 512, within 1e-4 of shooting.
    adaptive : bool, optional
        Raise the harmonics until converged as above; default True when ``harmonics``
        is not given, False when it is (a fixed number asked for).
    samples : int, optional
        HB time samples per period (default: a power of two >= 4 H + 2).
    keep : str or float, optional
        Keep only the excitations periodic with this base (a stage label, a mesh or body
        name, or a frequency in Hz at ``speed``); the others are replaced by their means and listed
        in ``SteadyState.dropped``.  Default: every excitation, over their least common
        period (refused when longer than ``max_cycles`` cycles of the fastest one).
    max_cycles : int, None or "auto"
        Longest period accepted, in cycles of the fastest excitation; None: no limit;
        "auto" (default): 1000 for harmonic balance, 10,000 for shooting and "auto"
        (:func:`~torquesplit.steady.period.default_max_cycles`).
    speed : float or str, optional
        Input speed of the first drive: rad/s, or a string with its unit ('3000 rpm',
        '50 Hz' = 50 revolutions per second) (default the model's).  Torques are kept
        (a speed change at constant load); excitation tables are functions of the mesh
        phase and stay.
    stability : bool or "hill" or "monodromy"
        Floquet multipliers (Hill's method for small HB systems, else the monodromy).
    tol : float, optional
        Newton tolerance (HB: 1e-10 of the largest acceleration; shooting: 1e-9 of the
        largest deformation).
    steps_per_cycle : int, optional
        RK4 steps per cycle of the fastest excitation for shooting and the checks
        (default 100, refined for the highest mode).
    check : bool
        HB: integrate one period from the solution and report the periodicity defect.
    initial : array_like, optional
        A starting guess (e.g. a neighbouring speed's solution): the state [q, v] at the
        start of the period (2 n values in the structure's DOF order, SI), or for
        ``method="hb"`` also a solution's harmonic coefficients; anything else is
        refused.  Default: the static equilibrium.
    progress : callable, optional
        ``progress(None, what)`` is called as the solver moves on (settling, each Newton
        step with its defect, the harmonics tried, the Floquet multipliers): what a long
        run is doing, e.g. for the command line's spinner.

    Returns
    -------
    SteadyState

    Raises
    ------
    SteadyInterrupted
        Ctrl-C while the stability was computed, after the state converged: a
        KeyboardInterrupt whose ``steady`` holds the state, its stability "interrupted".
    """
    from torquesplit.model.io import load_model

    _check_options(steps_per_cycle=steps_per_cycle, tol=tol, stability=stability,
                   energy_tol=energy_tol, method=method, harmonics=harmonics,
                   max_cycles=max_cycles)
    if not hasattr(model, "meshes"):
        model = load_model(model)
    with collect_model_warnings() as notes:
        return _steady_state(model, method=method, harmonics=harmonics, samples=samples,
                             keep=keep, speed=speed, max_cycles=max_cycles,
                             stability=stability, adaptive=adaptive, energy_tol=energy_tol,
                             tol=tol, steps_per_cycle=steps_per_cycle, check=check,
                             initial=initial, progress=progress, notes=notes)


def _steady_state(model, *, method, harmonics, samples, keep, speed, max_cycles, stability,
                  adaptive, energy_tol, tol, steps_per_cycle, check, initial, progress,
                  notes) -> SteadyState:
    """:func:`steady_state` of a loaded model; ``notes``: the list its warnings go to."""
    from torquesplit.assembly.assemble import assemble
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.solve.static import static_equilibrium

    kin = solve_kinematics(model)
    full = assemble(model, kin)
    dropped = []
    structure = full
    factor = speed_factor(model, speed)
    keep_asked = keep
    if isinstance(keep, (int, float)) and not isinstance(keep, bool):
        # a frequency at the speed asked for; the structure's are at the model's speed
        # (a reviewer's --keep 5350.67 at 16052 rpm was read at the file's 3000 rpm)
        keep = keep / factor
    if keep is not None:
        structure, dropped = keep_excitations(full, base_frequency(full, keep, kin))
    if max_cycles == "auto":
        max_cycles = default_max_cycles(method)
    per = fundamental_period(structure, max_cycles=max_cycles)
    if keep is not None:
        base = base_frequency(full, keep, kin)
        per = _at_base(per, base)
    static = static_equilibrium(structure)
    if not np.all(np.isfinite(static.q)):
        raise SolverError("the static equilibrium failed, so the periodic state has no start; "
                          "check the clearances and supports (see the run command).")
    from torquesplit.model.checks import refuse_out_of_mesh

    refuse_out_of_mesh(model, structure, static.q, warn=True)
    if per.frequency <= 0:
        raise SolverError("the model has no time-varying excitation (constant mesh stiffness, "
                          "no errors or tables), so its steady state is the static "
                          "equilibrium: run `torquesplit static` (or static_equilibrium) "
                          "instead, or give a mesh a stiffness variation or an error.")
    if adaptive is None:
        adaptive = harmonics is None
    from torquesplit.steady.solution import warn_undamped

    problem = periodic_problem(model, kin, structure, per.frequency)
    at_speed = structure
    if factor != 1.0 and structure.metadata.get("rotating_frame"):
        # a turning carrier's centrifugal loads at the speed asked: the equilibrium the
        # state starts from and its static forces (the dynamic factors) are that speed's
        at_speed = problem.structure_at(factor, frequencies=False)
        static = static_equilibrium(at_speed)
        if not np.all(np.isfinite(static.q)):
            raise SolverError(f"the static equilibrium at {factor:.6g} times the model's "
                              f"speed failed (the carrier's centrifugal loads), so the "
                              f"periodic state has no start; check the planet bearings.")
    warn_undamped(at_speed, static.q)  # (the modes at that speed, a reviewer)
    sol = periodic_solution(structure, per, method=method, harmonics=harmonics,
                            samples=samples, speed=factor, q_static=static.q, initial=initial,
                            tol=tol, adaptive=adaptive, energy_tol=energy_tol,
                            stability=stability, steps_per_cycle=steps_per_cycle,
                            check=check, problem=problem, progress=progress)
    state = SteadyState(model=model, kinematics=kin, structure=structure, static=static,
                        period=per, solution=sol, dropped=dropped, problem=problem,
                        options=dict(keep=keep_asked, speed=speed, max_cycles=max_cycles,
                                     energy_tol=energy_tol), notes=notes)
    if sol.stability_method == "interrupted":  # Ctrl-C in the stability: stop, with it
        from torquesplit.errors import SteadyInterrupted

        raise SteadyInterrupted(state)
    return state


def _at_base(per, base):
    """The period of kept excitations, stated over the base (1 / base)."""
    from torquesplit.steady.period import Period

    if per.frequency <= 0:
        return Period(base, (), ())
    k = per.frequency / base
    if abs(k - round(k)) > 1e-9 * k or round(k) < 1:
        raise SolverError(f"the kept excitations are not periodic with {base:.6g} Hz; "
                          f"choose another base (keep=...).")
    return Period(base, per.sources, tuple(int(o * round(k)) for o in per.orders))


# --------------------------------------------------------------------------- Results
RESULT_ROWS = 1 << 18
"""Largest number of time samples of a steady state's Results record (its per-cycle
statistics and history), before the samples per period are reduced."""


def period_weights(t, corners, period):
    """Trapezoid-rule weights [s] of the sample times ``t`` and the corner instants
    ``corners`` (both in [0, period)) over one period, the corners as breakpoints: each
    instant carries half of the interval to each neighbour (periodically), so that the
    weights sum to the period.  Returns (weights of t, weights of corners)."""
    t = np.asarray(t, dtype=float)
    every = np.concatenate([t, np.asarray(corners, dtype=float)])
    order = np.argsort(every, kind="stable")
    ts = every[order]
    after = np.diff(np.concatenate([ts, ts[:1] + period]))  # interval to the next instant
    w = np.empty_like(ts)
    w[order] = 0.5 * (after + np.roll(after, 1))
    return w[:t.size], w[t.size:]


def corner_columns(ps, e):
    """(times, forces, deformations) of element ``e`` at the corner instants of a
    periodic solution (empty for harmonic balance)."""
    n = ps.corner_forces.shape[0]
    if n == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    d = (ps.corner_deformations[:, e] if ps.corner_deformations.shape[0] == n
         else np.zeros(n))
    return ps.corner_t[:n], ps.corner_forces[:, e], d


def half_gaps(structure, e, t):
    """Half-gap of element ``e`` at the times ``t`` (a per-cycle backlash sequence
    indexed by the element's cycle, as the integrators take it)."""
    s = structure
    gaps = s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]
    if gaps.size == 1:
        return np.full(np.shape(t), gaps[0])
    cyc = np.floor(s.frequency[e] * np.asarray(t) + s.phase[e]).astype(np.int64) % gaps.size
    return gaps[cyc]


def between_samples(t, f, d, g, period, corners=(), fc=(), dc=(), gc=(), periodic=True,
                    kinks=None):
    """The extremes between the instants of one record: for each sample at the times
    ``t`` (force ``f``, deformation ``d``, half-gap ``g``), the vertex of the parabola
    through it and its neighbours among all instants (the samples and the corner
    instants ``corners`` with ``fc``, ``dc``, ``gc``) where it is their largest
    (``vmax``) or smallest (``vmin``), is no corner (a sample within ``MERGE`` steps of
    one of ``kinks``, every corner time, default ``corners``, is that corner: the RK4
    kernels record no instant of their own there) and the three share one contact
    regime; -inf / +inf elsewhere.
    ``periodic``: the record is one period (its ends neighbours).  The integrators'
    ``_kernels.force_instant`` over a record."""
    from torquesplit.solve._kernels import MERGE

    t = np.asarray(t, dtype=float)
    n = t.size
    tt = np.concatenate([t, np.asarray(corners, dtype=float)])
    ff = np.concatenate([f, np.asarray(fc, dtype=float)])
    dd = np.concatenate([d, np.asarray(dc, dtype=float)])
    gg = np.concatenate([g, np.asarray(gc, dtype=float)])
    kink = np.arange(tt.size) >= n
    c = np.sort(np.asarray(tt[n:] if kinks is None else kinks, dtype=float))
    if c.size and n > 1:  # samples on a corner
        h = float(np.min(np.diff(t)))
        k = np.clip(np.searchsorted(c, t), 1, c.size - 1) if c.size > 1 else np.zeros(n, int)
        near = np.minimum(np.abs(t - c[k]), np.abs(t - c[np.maximum(k - 1, 0)]))
        if periodic:
            near = np.minimum(near, np.minimum(np.abs(t + period - c[0]),
                                               np.abs(t - period - c[-1])))
        kink[:n] = near <= MERGE * h * (1 + 1e-9)
    order = np.argsort(tt, kind="stable")
    ts, fs, ks = tt[order], ff[order], kink[order]
    reg = np.where(gg > 0, np.where(dd > gg, 1, np.where(dd < -gg, -1, 0)), 1)[order]
    if periodic:
        tp = np.concatenate([ts[-1:] - period, ts[:-1]])
        tn = np.concatenate([ts[1:], ts[:1] + period])
        f0, f2, r0, r2 = np.roll(fs, 1), np.roll(fs, -1), np.roll(reg, 1), np.roll(reg, -1)
        ends = np.zeros(ts.size, dtype=bool)
    else:
        tp = np.concatenate([ts[:1], ts[:-1]])
        tn = np.concatenate([ts[1:], ts[-1:]])
        f0 = np.concatenate([fs[:1], fs[:-1]])
        f2 = np.concatenate([fs[1:], fs[-1:]])
        r0 = np.concatenate([reg[:1], reg[:-1]])
        r2 = np.concatenate([reg[1:], reg[-1:]])
        ends = np.zeros(ts.size, dtype=bool)
        ends[[0, -1]] = True
    ok = (~ks & ~ends & (reg != 0) & (r0 == reg) & (r2 == reg)
          & ~((fs == f0) & (fs == f2)))
    with np.errstate(divide="ignore", invalid="ignore"):
        d1 = (fs - f0) / (ts - tp)
        d2 = (f2 - fs) / (tn - ts)
        a = (d2 - d1) / (tn - tp)
        sl = (d1 * (tn - ts) + d2 * (ts - tp)) / (tn - tp)
        v = np.where(a == 0.0, fs, fs - sl * sl / (4.0 * a))
    top = (fs >= f0) & (fs >= f2)
    vmax = np.where(ok & top & np.isfinite(v), v, -np.inf)
    vmin = np.where(ok & ~top & (fs <= f0) & (fs <= f2) & np.isfinite(v), v, np.inf)
    back = np.empty_like(order)
    back[order] = np.arange(order.size)
    return vmax[back[:n]], vmin[back[:n]]


def cycle_integrals(t, f, cycles, n, start, period):
    """Time integral of ``f`` and the time in each of ``n`` cycles, from its values at
    the increasing instants ``t`` in cycles ``cycles`` (cycle c begins at start + c
    period): the trapezoid rule, an interval that holds the start of a cycle split there
    (the linear interpolant on each side), past a skipped cycle half to each end's cycle;
    cycles outside [0, n) left out.  The integrator's ``_kernels.force_instant`` over a
    record."""
    ta, tb, fa, fb = t[:-1], t[1:], f[:-1], f[1:]
    ca, cb = cycles[:-1], cycles[1:]
    span = tb - ta
    split = cb == ca + 1
    th = np.where(split & (span > 0),
                  np.clip((start + cb * period - ta) / np.where(span > 0, span, 1.0), 0, 1),
                  1.0)
    fm = fa + th * (fb - fa)
    da = np.where(split, th * span, 0.5 * span)
    db = span - da
    ia = np.where(split, 0.5 * da * (fa + fm), da * fa)
    ib = np.where(split, 0.5 * db * (fm + fb), db * fb)
    total = np.zeros(n)
    time = np.zeros(n)
    for c, integral, dt in ((ca, ia, da), (cb, ib, db)):
        ok = (c >= 0) & (c < n)
        total += np.bincount(c[ok], weights=integral[ok], minlength=n)[:n]
        time += np.bincount(c[ok], weights=dt[ok], minlength=n)[:n]
    return total, time


def cycle_start_points(t, start, period, n):
    """The cycle starts ``start + k period`` (k = 1 .. n - 1) that lie within the instants
    ``t`` (in time order): (k, i, th), each start at ``t[i] + th (t[i + 1] - t[i])``
    (on an instant, that instant)."""
    k = np.arange(1, n)
    tb = start + k * period
    i = np.searchsorted(t, tb, side="right") - 1
    inside = (i >= 0) & (i < t.size - 1)
    k, tb, i = k[inside], tb[inside], i[inside]
    th = np.clip((tb - t[i]) / np.where(t[i + 1] > t[i], t[i + 1] - t[i], 1.0), 0.0, 1.0)
    return k, i, th


def boundary_extremes(t, f, start, period, mx, mn):
    """Enter in ``mx`` / ``mn`` (per cycle, cycle k from ``start + k period``) the force
    interpolated at every cycle start between the instants ``t`` (in time order, forces
    ``f``; on an instant, its force), in both cycles it divides: as
    ``_kernels.force_instant`` does for an element whose force is continuous there."""
    k, i, th = cycle_start_points(t, start, period, mx.shape[0])
    fb = f[i] + th * (f[i + 1] - f[i])
    for c in (k - 1, k):
        np.maximum.at(mx, c, fb)
        np.minimum.at(mn, c, fb)


def boundary_ratios(t, forces, member, start, period, least, mx, mn):
    """Enter in ``mx`` / ``mn`` the load-sharing ratio N f_j / sum_i f_i of group member
    ``member`` (column of ``forces`` (n_instants, N) at the instants ``t``) at each of
    its cycle starts, from every member's force interpolated there (its positive part:
    the load the teeth carry), where the total exceeds ``least``: as
    ``_kernels.ratio_starts`` does."""
    k, i, th = cycle_start_points(t, start, period, mx.shape[0])
    fb = np.maximum(forces[i] + th[:, None] * (forces[i + 1] - forces[i]), 0.0)  # no tension
    total = fb.sum(axis=1)
    keep = total > least
    r = forces.shape[1] * fb[keep, member] / total[keep]
    for c in (k[keep] - 1, k[keep]):
        np.maximum.at(mx, c, r)
        np.minimum.at(mn, c, r)


def cycle_extremes(values, cycles, n, extra_cycles=None, extra=None):
    """Per-cycle max and min (arrays of ``n``; -inf / inf where a cycle has none) of
    ``values`` in cycles ``cycles`` (non-decreasing: the samples of a cycle form one run)
    and of the instants ``extra`` in ``extra_cycles`` (any order); NaN values (a group
    carrying no load) left out."""
    mx = np.full(n, -np.inf)
    mn = np.full(n, np.inf)
    for v, c, runs in ((values, cycles, True), (extra, extra_cycles, False)):
        if v is None:
            continue
        ok = ~np.isnan(v)
        v, c = v[ok], c[ok]
        if not v.size:
            continue
        if runs:  # a reduction per run instead of a scatter per sample
            starts = np.concatenate([[0], np.flatnonzero(np.diff(c)) + 1])
            c, vmax, vmin = c[starts], np.maximum.reduceat(v, starts), np.minimum.reduceat(
                v, starts)
            mx[c] = np.maximum(mx[c], vmax)
            mn[c] = np.minimum(mn[c], vmin)
        else:
            np.maximum.at(mx, c, v)
            np.minimum.at(mn, c, v)
    return mx, mn


def _check_record_size(periods: int, samples: int, columns: int) -> None:
    """Refuse a repeated record far beyond :data:`RESULT_ROWS` (a speed far outside the
    model's: a reviewer's 1e9 rpm asked for 22 GiB and was killed)."""
    rows = periods * samples
    if rows > 64 * RESULT_ROWS:
        raise SolverError(
            f"the periodic state would be repeated over {periods:,} periods of {samples:,} "
            f"samples ({rows * 8 * max(columns, 1) / 2**30:.3g} GiB) to cover the settle "
            f"windows of its slowest excitation: the speed is far from the model's, or an "
            f"excitation is much slower than the meshes; check --speed, or leave the slow "
            f"excitation out (--keep)")


def _as_solution(st: SteadyState, shell, periods):
    """An integrate.Solution made of the periodic state repeated over a few periods."""
    from torquesplit.assembly.structure import history_elements
    from torquesplit.solve.integrate import Solution

    s = st.structure_at  # (its frequencies at the speed solved: the cycles)
    ps = st.solution
    T = ps.period
    names = list(s.element_names)
    mesh_names = st.mesh_names
    track = [names.index(m) for m in mesh_names]
    hist = history_elements(s, mesh_names)
    if periods is None:
        win = max(shell.settle_windows(20))
        per_period = min(float(s.frequency[e]) * T for e in track) if track else 1.0
        periods = max(2, int(math.ceil(4 * (win + 2) / max(per_period, 1e-300))))
    # samples per period: the solution's own (or 64 per cycle of the fastest excitation),
    # fewer when the repeated record would pass RESULT_ROWS (a slow mesh left unexcited by
    # keep= needs many periods for its cycles); exact values at those times either way
    t1, F1, D1 = st.samples()
    if periods * len(t1) > RESULT_ROWS:
        n = max(64 * max(st.period.max_order, 1),
                1 << int(math.floor(math.log2(max(RESULT_ROWS // periods, 2)))))
        if n < len(t1):
            t1, F1, D1 = st.samples(n=n)
    _check_record_size(periods, len(t1), F1.shape[1])
    t = (t1[None, :] + T * np.arange(periods)[:, None]).ravel()
    F = np.tile(F1, (periods, 1))
    # the meshes' statistics from their finest series (shooting: every RK4 step, where
    # the other elements may be kept every few steps only)
    if ps.method == "hb":
        tm, Fm, Dm = t1, F1[:, track], D1[:, track]
    else:
        tm, Fm, Dm = st.mesh_series(track)
    _check_record_size(periods, len(tm), len(track))
    tt = (tm[None, :] + T * np.arange(periods)[:, None]).ravel()
    # instants at table corners (shooting): in the per-cycle extremes, as the integrator's
    # corner events, not in sums, counts or contact time
    tc = (ps.corner_t[None, :] + T * np.arange(periods)[:, None]).ravel()
    Fc = (np.tile(ps.corner_forces[:, track], (periods, 1)) if tc.size
          else np.zeros((0, len(track))))
    n_tr = len(track)

    def cycle_of(e, times):  # the statistics cycle of element e at each time (laws.stat_cycle)
        sph = s.frequency[e] * times + s.phase[e]
        fl = np.floor(sph)
        return fl + (sph - fl >= 1 - 1e-9)

    bases = [cycle_of(e, tt[:1])[0] for e in track]

    def cycles(j, times):
        return (cycle_of(track[j], times) - bases[j]).astype(np.int64)

    cyc_n = [int(cycles(j, tt[-1:])[0]) + 1 for j in range(n_tr)]
    nc = max(cyc_n) if cyc_n else 0
    corner_idx = []
    for j in range(n_tr):
        ic = cycles(j, tc)
        keep = (ic >= 0) & (ic < cyc_n[j])
        corner_idx.append((ic[keep], keep))
    kinks = (st.problem.corner_times(0.0, T, ps.speed) if ps.method != "hb"
             else np.zeros(0))
    # every instant (steps and corners) in time order, for the cycles' time integrals
    t_all = np.concatenate([tt, tc, [periods * T]])
    order = np.argsort(t_all, kind="stable")
    t_all = t_all[order]
    cmax = np.full((nc, n_tr), np.nan)
    cmin = np.full((nc, n_tr), np.nan)
    csum = np.full((nc, n_tr), np.nan)  # (NaN: a cycle left out, as the integrator's)
    ccnt = np.zeros((nc, n_tr), dtype=np.int64)
    cstart = np.zeros((nc, n_tr))
    for j, e in enumerate(track):
        idx = cycles(j, tt)
        f = np.tile(Fm[:, j], periods)
        ic, keep = corner_idx[j]
        mx, mn = cycle_extremes(f, idx, nc, ic, Fc[keep, j])
        # the extremes between the samples, in the middle sample's cycle
        if ps.method != "hb":  # (a truncated series rings between its samples)
            t_c, f_c, d_c = corner_columns(ps, e)
            vmax, vmin = between_samples(tm, Fm[:, j], Dm[:, j], half_gaps(s, e, tm), T,
                                         t_c, f_c, d_c, half_gaps(s, e, t_c), kinks=kinks)
            inside = (idx >= 0) & (idx < nc)
            np.maximum.at(mx, idx[inside], np.tile(vmax, periods)[inside])
            np.minimum.at(mn, idx[inside], np.tile(vmin, periods)[inside])
        f_all = np.concatenate([f, Fc[:, j], f[:1]])[order]
        sm, span = cycle_integrals(t_all, f_all, cycles(j, t_all), nc,
                                   (bases[j] - s.phase[e]) / s.frequency[e],
                                   1.0 / s.frequency[e])
        if continuous_start(st.problem.model.corner_ptr, st.problem.model.corner_node, e):
            boundary_extremes(t_all, f_all, (bases[j] - s.phase[e]) / s.frequency[e],
                              1.0 / s.frequency[e], mx, mn)
        cnt = np.bincount(idx, minlength=nc)
        # the first and last cycles are partial (phase offsets): left out; a mesh whose
        # cycles divide the period keeps whole periods of them (cycles 1 .. (P - 1) n),
        # so that every mean over its cycles is a mean over whole periods
        cnt[0] = 0
        cnt[cyc_n[j] - 1:] = 0
        per = s.frequency[e] * T
        if abs(per - round(per)) < 1e-6 * max(per, 1.0) and round(per) >= 1:
            cnt[1 + (periods - 1) * int(round(per)):] = 0
        ok = cnt > 0
        cmax[ok, j] = mx[ok]
        cmin[ok, j] = mn[ok]
        csum[ok, j] = sm[ok] / span[ok]
        ccnt[:, j] = cnt
        cstart[:, j] = (bases[j] + np.arange(nc) - s.phase[e]) / s.frequency[e]
        # a slower mesh's rows past its last cycle are no cycles: no start (as the
        # integrator's; their starts ran ten times past the record's end)
        cstart[cyc_n[j]:, j] = np.nan
    # per-cycle extremes of the instantaneous load-sharing ratio N f_i / sum_j f_j of each
    # group (Ji & Li eq. 18), from the same samples (what the integrator streams)
    from torquesplit.metrics.load_sharing import group_meshes

    rmax = np.full((nc, n_tr), np.nan)
    rmin = np.full((nc, n_tr), np.nan)
    groups = []
    for members in group_meshes(s.metadata["meshes"]).values():
        cols = [mesh_names.index(m) for m in members]
        groups.append(tuple(track[c] for c in cols))
        from torquesplit.simulation import GROUP_MIN_LOAD

        least = GROUP_MIN_LOAD * sum(abs(st.kinematics.meshes[m].force) for m in members)

        def ratios(x, least=least):  # of the loads the teeth carry (no tension)
            x = np.maximum(x, 0.0)
            total = x.sum(axis=1, keepdims=True)
            with np.errstate(invalid="ignore", divide="ignore"):
                return x.shape[1] * x / np.where(total > least, total, np.nan)

        ratio = ratios(np.tile(Fm[:, cols], (periods, 1)))
        ratio_c = ratios(Fc[:, cols])
        f_all = np.concatenate([np.tile(Fm[:, cols], (periods, 1)), Fc[:, cols],
                                Fm[:1, cols]])[order]
        for i, c in enumerate(cols):
            ic, keep = corner_idx[c]
            mx, mn = cycle_extremes(ratio[:, i], cycles(c, tt), nc, ic, ratio_c[keep, i])
            e = track[c]
            if continuous_start(st.problem.model.corner_ptr, st.problem.model.corner_node, e):
                boundary_ratios(t_all, f_all, i, (bases[c] - s.phase[e]) / s.frequency[e],
                                1.0 / s.frequency[e], least, mx, mn)
            ok = ccnt[:, c] > 0
            rmax[ok, c] = mx[ok]
            rmin[ok, c] = mn[ok]
    # contact loss over the period
    sep = np.zeros(s.n_elements)
    back = np.zeros(s.n_elements)
    for e in range(s.n_elements):
        te, d = (tm, Dm[:, track.index(e)]) if e in track else (t1, D1[:, e])
        g = half_gaps(s, e, te)
        sep[e] = np.mean((g > 0) & (np.abs(d) <= g))
        back[e] = np.mean(np.where(g > 0, d < -g, (s.element_kind[e] == 1) & (d < 0)))
    span = periods * T
    return Solution(
        status=0 if ps.converged else 1, message=ps.message, success=ps.converged,
        method=ps.method, t_span=(0.0, span), t_final=span,
        y_final=np.concatenate([ps.q[0], ps.v[0]]), n_steps=len(t), n_rejected=0,
        n_rhs=0, step=None, step_limited_by="", step_min=math.nan, step_max=math.nan,
        compile_time=0.0, wall_time=ps.wall_time, rhs="general", rhs_compile_time=0.0,
        dof_names=tuple(s.dof_names), element_names=tuple(s.element_names),
        tracked_elements=tuple(track), cycle_start=cstart, cycle_max=cmax, cycle_min=cmin,
        cycle_mean=csum, cycle_count=ccnt, load_sharing_groups=tuple(groups),
        cycle_ratio_max=rmax, cycle_ratio_min=rmin,
        history_elements=tuple(hist), history_dofs=(), history_t=t,
        history_forces=F[:, hist], history_q=np.zeros((len(t), 0)),
        history_v=np.zeros((len(t), 0)), full_t=None, full_y=None, n_samples=len(t),
        separation_steps=np.round(sep * len(t)).astype(np.int64),
        back_contact_steps=np.round(back * len(t)).astype(np.int64),
        separation_time=sep * span, back_contact_time=back * span)
