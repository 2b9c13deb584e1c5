"""``simulate``: the dynamic pipeline model -> structure -> static -> integration -> Results.

Each stage is its own object (PyBaMM style, without a god class): the model and its
kinematics, the assembled :class:`~torquesplit.assembly.structure.Structure`, the
static equilibrium used as initial state, the integrator's
:class:`~torquesplit.solve.integrate.Solution`; :class:`~torquesplit.results.Results`
holds them and computes the metrics on demand.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._memo import remember_last
from .assembly.structure import history_elements
from .errors import ModelWarning, OptionError, SolverError, collect_model_warnings, warn_user
from .model.io import load_model
from .model.kinematics import solve_kinematics

#: largest number of decimated history records kept by default
MAX_HISTORY_RECORDS = 200_000
#: the default history (``samples_per_period=None``) keeps every RK4 step while the run
#: has at most this many, else every k-th step (at most this many samples), but never
#: fewer than :data:`MIN_SAMPLES_PER_PERIOD` per shortest mesh period
AUTO_HISTORY_RECORDS = 50_000
MIN_SAMPLES_PER_PERIOD = 20

#: set while a caller runs for the streamed metrics only (a study's case), whose sparse
#: history is its own choice: no warning that the history is coarse (a reviewer's study
#: warned it in every case of 120 s runs, and writes no waveforms)
_HISTORY_UNUSED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "torquesplit_history_unused", default=False)


@contextlib.contextmanager
def history_unused():
    """Runs in this block keep a history nobody reads: its coarseness is not warned."""
    token = _HISTORY_UNUSED.set(True)
    try:
        yield
    finally:
        _HISTORY_UNUSED.reset(token)


_SETTLING_JUDGED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "settling_judged", default=False)


@contextlib.contextmanager
def settling_judged():
    """Runs in this block do not warn that they are too short or unsettled: the caller
    judges the run it keeps (a study's stop-when-settled rule runs short trial runs
    first, whose warnings became its case's)."""
    token = _SETTLING_JUDGED.set(True)
    try:
        yield
    finally:
        _SETTLING_JUDGED.reset(token)


#: fewest RK4 steps per excitation period a run takes (the model file's bound)
MIN_STEPS_PER_PERIOD = 10
#: default step budget of a run (about 1-5 minutes of integration on one core)
MAX_STEPS = 200_000_000
#: runs longer than this many steps are announced with a warning (cost estimate)
ANNOUNCE_STEPS = 20_000_000
#: fraction of a group's nominal load below which no instantaneous load-sharing ratio is
#: formed (an instant when every mesh of the group is nearly unloaded)
GROUP_MIN_LOAD = 0.01


def simulate(
    model,
    *,
    duration: float | None = None,
    cycles: int | None = None,
    method: str | None = None,
    steps_per_period: int | None = None,
    rtol: float | None = None,
    samples_per_period: int | None = None,
    history_dofs=None,
    full_history: bool = False,
    progress: Callable[[float], None] | None = None,
    rhs: str = "auto",
    max_steps: int | None = None,
):
    """Dynamic response of a model, started from its static equilibrium at t = 0
    (:func:`starting_equilibria`).

    Parameters
    ----------
    model : Model, str or Path
        A validated model or a model file.
    duration : float or str, optional
        Simulated time: seconds, or a string with a time unit (``"5 ms"``).  Default:
        ``cycles`` if given, else the model's ``[analysis]``.
    cycles : int, optional
        Number of cycles of the slowest mesh to simulate: a whole number >= 1 (``3.0``
        is read as 3; ``2.5`` is refused).  Give ``duration`` or ``cycles``, not both
        (an :class:`~torquesplit.errors.OptionError`).  Neither: the model's
        ``[analysis]`` duration or cycles, else 200 cycles.
    method : {"rk4", "dopri"}, optional
        Integrator; default from ``[analysis]``.
    steps_per_period : int, optional
        RK4 steps per shortest excitation period (the shortest mesh period, or a faster
        error sinusoid's), a whole number >= 10; default the model's ``[analysis]
        steps_per_period`` (itself 100 unless set, as in the papers).
    samples_per_period : int, optional
        History samples per shortest mesh period, >= 1 (plots, exports and the bearing
        forces' means: every mesh metric and the bearings' peaks are computed from
        quantities streamed at every step).
        Default: every RK4 step while the run has at most
        :data:`AUTO_HISTORY_RECORDS`, else every k-th step (at most that many samples;
        Dormand-Prince: that many evenly over the run), never fewer than
        :data:`MIN_SAMPLES_PER_PERIOD` per period.
    history_dofs : list of str, optional
        DOF names (``"gear.x"``) whose displacement and velocity histories to keep.
    full_history : bool
        Keep every state (memory grows with the run length).
    progress : callable, optional
        Called with the completed fraction (0..1) during the integration.
    max_steps : int, optional
        Refuse (before integrating) an RK4 run that needs more steps than this, with the
        reason (usually one stiff element or a tiny inertia setting the step); default
        :data:`MAX_STEPS`.  Runs above :data:`ANNOUNCE_STEPS` steps get a cost warning.
    rhs : {"auto", "generated", "literal", "general"}
        Right-hand side of the kernels: the model's equations compiled as straight-line
        code (with its values as constants: "literal"), or the general element loop, or
        (default) the compiled code when the run is long enough to repay its
        compilation; same results bit for bit (see
        :func:`torquesplit.solve.integrate.integrate`).

    Returns
    -------
    Results

    Examples
    --------
    >>> import torquesplit
    >>> res = torquesplit.simulate(torquesplit.example_path("ji_li_mill_drive"), cycles=20)
    >>> res.success
    True
    """
    duration, cycles, samples_per_period = check_run_length(duration, cycles,
                                                             samples_per_period)
    if not hasattr(model, "meshes"):
        model = load_model(model)
    with warnings.catch_warnings(), collect_model_warnings() as notes:
        # every ModelWarning of the run is shown (unless the caller's filters say
        # otherwise) and kept with the results whatever the filters, so that files and
        # reports carry it
        warnings.simplefilter("always", ModelWarning, append=True)
        res = _simulate(model, duration=duration, cycles=cycles, method=method,
                        steps_per_period=steps_per_period, rtol=rtol,
                        samples_per_period=samples_per_period, history_dofs=history_dofs,
                        full_history=full_history, progress=progress, rhs=rhs,
                        max_steps=max_steps)
        _warn_unsettled(res)
    res.run_warnings = notes
    return res


def _warn_unsettled(res) -> None:
    """Say, as a :class:`ModelWarning`, that the run is too short to tell whether it
    settled, or did not settle: its metrics are then of a part of a transient, which a
    Python user heard of only by reading ``res.warnings()`` (the command line prints
    it).  The same text as there, which lists it once."""
    if not res.success or _SETTLING_JUDGED.get():
        return
    from .results.plausibility import settling

    try:
        met = res.metrics()
    except (ValueError, ArithmeticError):  # pragma: no cover - said by res.warnings()
        return
    for loc, msg in settling(res, met):
        warn_user(f"{loc}: {msg}", ModelWarning)


def _simulate(model, *, duration, cycles, method, steps_per_period, rtol,
              samples_per_period, history_dofs, full_history, progress, rhs, max_steps):
    """:func:`simulate` on a loaded model, its warnings not yet collected."""
    from .results import Results
    from .solve.integrate import integrate

    run = prepare_run(model, duration=duration, cycles=cycles, method=method,
                      steps_per_period=steps_per_period, rtol=rtol,
                      samples_per_period=samples_per_period, history_dofs=history_dofs,
                      full_history=full_history, progress=progress, rhs=rhs,
                      max_steps=max_steps)
    solution = integrate(run.structure, run.y0, (0.0, run.duration), **run.integrate_kwargs)
    return Results(model=run.model, kinematics=run.kinematics, structure=run.structure,
                   static=run.static, solution=solution)


def check_run_length(duration, cycles, samples_per_period=None):
    """The run-length arguments of :func:`simulate` and :func:`prepare_run`, checked:
    ``(duration in s or None, cycles or None, samples_per_period)``.

    ``duration``: a positive number of seconds or a time string (``"5 ms"``); ``cycles``
    and ``samples_per_period``: whole numbers >= 1 (``3.0`` is read as 3, ``2.5`` is
    refused; ``None``: the default history); ``duration`` and ``cycles`` together are
    refused (a run has one length).

    Examples
    --------
    >>> check_run_length("5 ms", None, 40)
    (0.005, None, 40)
    """
    from .errors import OptionError

    if duration is not None and cycles is not None:
        raise OptionError(f"duration={duration!r} and cycles={cycles!r} both set the run "
                          "length; give only one of them")
    if duration is not None:
        duration = _positive_time(duration)
    if cycles is not None:
        cycles = _whole(cycles, "cycles", "cycles=200")
    if samples_per_period is not None:
        samples_per_period = _whole(samples_per_period, "samples_per_period",
                                    "samples_per_period=100")
    return duration, cycles, samples_per_period


def _positive_time(value) -> float:
    """``duration`` in seconds: a number (seconds) or a string with a time unit."""
    from .errors import OptionError
    from .model.units import parse_quantity

    hint = "give e.g. duration=0.5 (seconds) or duration='500 ms'"
    try:
        x = parse_quantity(value, "time")
    except ValueError as exc:
        raise OptionError(f"duration: {exc}") from None
    if not x > 0:  # parse_quantity refuses inf and nan
        raise OptionError(f"duration must be a positive time, got {value!r}; {hint}")
    return x


def _whole(value, name: str, example: str) -> int:
    """A whole-number argument >= 1 (a float with a whole value is accepted)."""
    from ._args import whole

    return whole(value, name, example)


@dataclass(frozen=True)
class PreparedRun:
    """Everything :func:`simulate` sets up before integrating: the stages up to the
    static equilibrium and the arguments of
    :func:`~torquesplit.solve.integrate.integrate`.  Other executors of the same run (the
    GPU ensemble backend, :mod:`torquesplit.gpu`) start from it, so that a run means the
    same thing whichever engine integrates it."""

    model: object
    kinematics: object
    structure: object
    static: object
    y0: np.ndarray
    """Initial state [q, v]: the static equilibrium at t = 0 (stiffness, errors and gaps
    as they are at the start), at the rigid-body speed (v = 0)."""
    duration: float
    """Simulated time [s] (the run spans (0, duration))."""
    integrate_kwargs: dict
    """Keyword arguments of ``integrate`` (method, tracked elements, groups, ...)."""
    start: str = "t0"
    """Which equilibrium ``y0`` is: "t0" (at t = 0) or "mean" (the mean-stiffness one,
    used where the t = 0 solve did not converge)."""


def _set_up(model):
    """:func:`_kept_set_up`, after refusing a model changed in place since it was kept."""
    if model.changed_in_place():
        solve_kinematics(model)  # (raises the ModelError that says what to do)
    return _kept_set_up(model)


@remember_last
def _kept_set_up(model):
    """Kinematics, structure, static equilibrium (mean stiffness: the nominal forces) and
    the starting equilibrium of a model (kept while the model lives: a study case run
    until settled sets the same model up for each run length)."""
    from .assembly.assemble import assemble

    kin = solve_kinematics(model)
    structure = assemble(model, kin)
    return (kin, structure) + starting_equilibria(structure)


def starting_equilibria(structure):
    """The mean-stiffness static equilibrium and the one a run starts from.

    The start is the equilibrium under the excitation at t = 0 (each mesh's stiffness at
    its phase, the errors' values, the gaps of the current engagement): started from the
    mean-stiffness one, a run first swings about the instantaneous equilibrium by the
    difference (a spur pair with a 20 um eccentricity: first-cycle peak 33 % above the
    steady one, 0.2 % from the t = 0 equilibrium), a start-up transient that costs settle
    time and is counted in the start-up contact loss.  Where the t = 0 solve fails, the
    start is the mean-stiffness equilibrium, and a warning says so (one that does not
    converge exactly, a member floating in its clearance, is the regularised solution:
    a valid start, and :func:`prepare_run` says so).  Returns ``(static, start,
    which)``: two :class:`~torquesplit.solve.static.StaticSolution` and ``"t0"`` or
    ``"mean"``.
    """
    from .solve.static import static_equilibrium

    static = static_equilibrium(structure)
    try:  # (Newton from the mean equilibrium: Dong et al. 2021 5 steps, not 22)
        at0 = static_equilibrium(structure, 0.0, initial=static.q)
        # (not converged exactly but finite: the regularised solution, a valid start, as
        # prepare_run says)
        why = "" if np.all(np.isfinite(at0.q)) else "it has no finite solution"
    except (SolverError, ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        at0, why = None, f"it failed ({exc})"
    if not why:
        return static, at0, "t0"
    if np.all(np.isfinite(static.q)):
        warn_user(f"the static equilibrium at t = 0 could not start the run ({why}); it "
                      "starts from the mean-stiffness equilibrium, so its first cycles hold "
                      "a start-up swing that the settled metrics leave out", ModelWarning)
    return static, static, "mean"


def prepare_run(
    model,
    *,
    duration: float | None = None,
    cycles: int | None = None,
    method: str | None = None,
    steps_per_period: int | None = None,
    rtol: float | None = None,
    samples_per_period: int | None = None,
    history_dofs=None,
    full_history: bool = False,
    progress: Callable[[float], None] | None = None,
    rhs: str = "auto",
    max_steps: int | None = None,
) -> PreparedRun:
    """The set-up of :func:`simulate` (same parameters) without the integration: model,
    kinematics, structure, static equilibrium, initial state, run length and the
    arguments of ``integrate``; refuses what ``simulate`` refuses, warns as it warns."""
    duration, cycles, samples_per_period = check_run_length(duration, cycles,
                                                             samples_per_period)
    if not hasattr(model, "meshes"):
        model = load_model(model)
    an = model.analysis
    kin, structure, static, begin, start = _set_up(model)
    if not np.all(np.isfinite(static.q)):
        raise SolverError(
            "the static equilibrium failed; check the clearances and the supports "
            "(a body free to move inside its clearance needs a support or a spring)")
    from .model.checks import refuse_out_of_mesh

    refuse_out_of_mesh(model, structure, static.q)  # (as check does: a model that passes runs)
    if not begin.converged:  # (the state the run starts from)
        # e.g. a member floating inside its clearance with no net load: its position is
        # not determined; the regularised solution is a valid starting state
        warn_user(
            "the static equilibrium did not converge exactly (members free inside their "
            f"clearances: {', '.join(begin.separated) or 'none reported'}); the dynamic run "
            "starts from the regularised solution", ModelWarning)
    from .convergence import coarse_table_warning

    coarse = coarse_table_warning(model, structure)
    if coarse:
        warn_user(coarse, ModelWarning)
    mesh_names = list(model.meshes)
    freqs = np.array([kin.meshes[m].frequency for m in mesh_names])
    f_min, f_max = float(freqs.min()), float(freqs.max())
    method = method or an.method
    # options that the chosen method would ignore are refused, not ignored
    wrong = ([name for name, v in (("rtol", rtol),) if v is not None] if method == "rk4" else
             [name for name, v in (("steps_per_period", steps_per_period),
                                   ("max_steps", max_steps)) if v is not None])
    if wrong:
        from .errors import OptionError

        raise OptionError(f"option(s) {wrong} do not apply to method={method!r}; remove "
                          "them or choose the other method")
    if rtol is not None and not (isinstance(rtol, (int, float)) and not isinstance(rtol, bool)
                                 and 0 < rtol < 1):
        from .errors import OptionError

        raise OptionError(f"rtol must be a number between 0 and 1 (as [analysis] rtol), got "
                          f"{rtol!r}; give e.g. rtol=1e-6")
    if steps_per_period is None:
        steps_per_period = an.steps_per_period
    else:  # as the model file takes it (0 fell back to the model's, 2.5 was cut to 2)
        from ._args import whole

        steps_per_period = whole(steps_per_period, "steps_per_period",
                                 "steps_per_period=100", minimum=MIN_STEPS_PER_PERIOD)
    if duration is None:
        if cycles is not None:
            duration = cycles / f_min
        elif an.duration is not None:
            duration = an.duration
        else:
            duration = (an.cycles or 200) / f_min
    if duration <= 0 or not math.isfinite(duration):  # e.g. from the model's [analysis]
        raise SolverError(f"the run length must be positive, got {duration!r} s; give a "
                          "positive duration or cycles")
    y0 = np.concatenate([begin.q, np.zeros_like(begin.q)])

    names = structure.element_names
    track = [names.index(m) for m in mesh_names]
    hist_el = history_elements(structure, mesh_names)
    # one DOF name, not its letters ("unknown dof 'z'" for "z1.theta")
    if history_dofs is not None and not isinstance(history_dofs, str) and hasattr(
            history_dofs, "__iter__"):
        history_dofs = list(history_dofs)  # (a set, an array of names, a generator)
    if not (history_dofs is None or isinstance(history_dofs, str) or (
            isinstance(history_dofs, list) and all(isinstance(d, (str, np.str_))
                                                   for d in history_dofs))):
        from .errors import OptionTypeError

        # (5 raised "TypeError: 'int' object is not iterable")
        raise OptionTypeError(f"history_dofs must be DOF names, e.g. ['z1.theta', 'z1.x'] "
                              f"(structure.dof_names lists them), got {history_dofs!r}")
    hist_dofs = [history_dofs] if isinstance(history_dofs, str) else list(history_dofs or [])
    planned = step = None
    if method == "rk4":  # (the fixed step: the history's default and the cost use it)
        from .solve.integrate import planned_step, whole_steps

        planned = planned_step(structure, steps_per_period, duration)
        step = whole_steps(duration, planned[0])[1]
    sample_interval = history_interval(duration, f_max, samples_per_period, step)
    asked = 1.0 / (sample_interval * f_max)
    # the history keeps at most every RK4 step: a finer rate asked for is the step's
    # (a warning named the record cap and 4.05e3 per period where 400 were kept)
    finer = bool(step) and sample_interval < step * (1 - 1e-9)
    n_records = duration / (max(sample_interval, step) if finer else sample_interval)
    if n_records > MAX_HISTORY_RECORDS:
        sample_interval = duration / MAX_HISTORY_RECORDS
    elif finer and samples_per_period is not None:
        from .solve.integrate import finer_step_advice

        hint = finer_step_advice(structure, planned[1], planned[0])
        warn_user(
            f"analysis: samples_per_period={samples_per_period} asks for more samples than "
            f"the run takes steps: the history keeps every RK4 step, "
            f"{1.0 / (step * f_max):.4g} per shortest mesh period; a finer history needs "
            f"a finer step ({hint})", ModelWarning)
    # only a sampling the user asked for is worth a warning: the default one is a choice
    # of the library, and what it kept is in the bearing table's title and the files'
    # history_samples_per_period (a default run of Liu et al. 2021 warned)
    if (n_records > MAX_HISTORY_RECORDS and samples_per_period is not None
            and not _HISTORY_UNUSED.get()):
        warn_user(
            f"analysis: the history holds at most {MAX_HISTORY_RECORDS:,} samples, so this "
            f"run keeps {1.0 / (sample_interval * f_max):.3g} per shortest mesh period "
            f"instead of {asked:.3g}: the files' waveforms and the bearing table "
            f"are that coarse (the mesh table is streamed at every step); for fine "
            f"waveforms run a shorter span", ModelWarning)
    from .metrics.load_sharing import group_meshes

    mesh_groups = list(group_meshes(structure.metadata["meshes"]).values())
    groups = [[names.index(m) for m in ms] for ms in mesh_groups]
    # no load-sharing ratio while a group carries less than 1 % of its nominal load
    min_total = [GROUP_MIN_LOAD * sum(abs(kin.meshes[m].force) for m in ms)
                 for ms in mesh_groups]
    from .results import bearing_vectors

    kwargs = dict(
        method=method, track_elements=track, load_sharing_groups=groups,
        load_sharing_min_total=min_total,
        history_elements=hist_el, history_dofs=hist_dofs, full_history=full_history,
        # the bearing table's peaks, streamed at every step (not the history's samples);
        # none where the history is not read (a study without bearing outputs)
        history_peaks=None if _HISTORY_UNUSED.get() else bearing_vectors(names, model, kin),
        progress=progress, rhs=rhs,
        # the history is sampled in time, so its size never depends on the step
        sample_interval=sample_interval,
    )
    if method == "rk4":
        kwargs["steps_per_period"] = steps_per_period
        _check_cost(structure, duration, planned,
                    MAX_STEPS if max_steps is None else int(max_steps),
                    n_meshes=len(mesh_names), f_max=f_max, n_history=len(hist_el))
    else:
        kwargs["rtol"] = rtol or an.rtol
    return PreparedRun(model=model, kinematics=kin, structure=structure, static=static,
                       y0=y0, duration=float(duration), integrate_kwargs=kwargs, start=start)


def history_interval(duration: float, f_max: float, samples_per_period: int | None,
                     step: float | None = None) -> float:
    """Time between history samples [s]: ``samples_per_period`` per shortest mesh period
    (``f_max`` its frequency), or by default :data:`AUTO_HISTORY_RECORDS` over the run
    but at least :data:`MIN_SAMPLES_PER_PERIOD` a period.  An interval shorter than the
    RK4 step keeps every step (the history is sampled in time, so its size never depends
    on the step); given the fixed ``step``, the default is a whole number of steps, so
    that the budget holds (rounding 1.2 steps to 1 kept 20 % more)."""
    if samples_per_period is not None:
        return 1.0 / (samples_per_period * f_max)
    coarsest = 1.0 / (MIN_SAMPLES_PER_PERIOD * f_max)
    if step:
        every = math.ceil(duration / step / AUTO_HISTORY_RECORDS * (1 - 1e-12))
        return min(max(every, 1) * step, coarsest)
    return min(coarsest, duration / AUTO_HISTORY_RECORDS)


#: runs estimated to take longer than this [s] or to keep more than ANNOUNCE_BYTES of
#: results are announced with a warning before they start
ANNOUNCE_SECONDS = 20.0
ANNOUNCE_BYTES = 500 * 1024**2


def _check_cost(structure, duration: float, planned: tuple[float, str], max_steps: int, *,
                n_meshes: int = 0, f_max: float = 0.0, n_history: int = 0) -> None:
    """Refuse an RK4 run beyond the step budget, announce a long one (the cost known
    before integrating: the step is fixed) with its time and memory; ``planned`` is
    :func:`~torquesplit.solve.integrate.planned_step`'s ``(step, what sets it)``."""
    if max_steps < 1:
        raise OptionError(f"max_steps must be >= 1, got {max_steps}; give e.g. "
                          f"max_steps=10_000_000")
    h, why = planned
    n_steps = math.ceil(duration / h)
    # about 60 ns per DOF and step with the generated right-hand side (benchmarks/)
    seconds = n_steps * 6e-8 * max(structure.n_dof, 1)
    if n_steps > max_steps:
        raise SolverError(
            f"this run needs {n_steps:,} RK4 steps of {h:.3g} s ({why}), more than "
            f"max_steps = {max_steps:,} (about {seconds / 60:.3g} min); check the stiffness "
            "and inertias named there and their units, shorten the duration, or raise "
            "max_steps (--max-steps; a study's [analysis] max_steps)")
    # per-cycle statistics (6 arrays per tracked mesh) and the decimated history
    memory = 8 * (6 * (f_max * duration + 2) * n_meshes
                  + MAX_HISTORY_RECORDS * (1 + n_history))
    if n_steps > ANNOUNCE_STEPS or seconds > ANNOUNCE_SECONDS or memory > ANNOUNCE_BYTES:
        took = f"{seconds / 60:.2g} min" if seconds >= 60 else f"{seconds:.2g} s"
        warn_user(f"this run takes {n_steps:,} RK4 steps of {h:.3g} s ({why}): about "
                      f"{took} of integration and {memory / 1024**2:,.0f} MB of results; "
                      f"shorten the run (duration or cycles) for a quicker look", ModelWarning)
