"""How far a run's reported numbers move when its step is halved: which digits to trust.

A fixed-step RK4 run is an approximation whose error falls with the step; a number is
worth the digits that do not move when the step is halved.  :func:`check_step` runs the
same simulation again at half the step the first run took (not half the step it asked
for: a stiff damping or a resolved mode may have set a finer one) and compares every
metric of :meth:`Results.metric_values <torquesplit.results.Results.metric_values>`;
:class:`StepCheck` says, per metric, how many significant digits agree.  For the
adaptive Dormand-Prince method the tolerance is tightened 32-fold instead (its local
error is fifth order in the step, so that about halves the steps).  A model whose
excitation tables have jumps (a rectangular single/double contact wave, a table that
steps where a tooth pair enters) is also checked with TABLE_REFINEMENT times its table
points: a table of n points turns each jump into a ramp one n-th of a mesh period long,
which moves peak forces as the step does (Ji & Li's stage 2: 2 % from 256 to 4096
points, where halving the step moves nothing).  :func:`check_steady` does the same for a
periodic steady state (shooting at half its RK4 step, harmonic balance with twice its
harmonics).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["StepCheck", "check_step", "check_steady", "halved_steps_per_period",
           "agreeing_digits", "held_decimals", "has_jumps", "jump_elements", "coarse_table_warning"]

TIGHTER_RTOL = 32.0
"""Dormand-Prince: the check's tolerance is the run's divided by this (~ half the step)."""
TABLE_REFINEMENT = 4
"""A model with jumps in its tables is checked with this many times its table points."""
JUMP = 0.25
"""A table has a jump where one spacing holds more than this fraction of its range."""


def has_jumps(structure) -> bool:
    """Whether a time-varying stiffness or additive-force table of ``structure`` changes
    by more than :data:`JUMP` of its range between two neighbouring points (a step the
    table resolves as a ramp of one spacing)."""
    return bool(jump_elements(structure))


def jump_elements(structure) -> list[str]:
    """Names of the elements of ``structure`` with a table that jumps (:func:`has_jumps`)."""
    jumps = np.zeros(len(structure.element_names), dtype=bool)
    for table in (structure.stiffness_table, structure.force_table):
        t = np.asarray(table, dtype=float)
        if t.ndim != 2 or t.shape[1] < 2 or t.shape[0] != jumps.shape[0]:
            continue
        jumps |= rows_that_jump(t) & (structure.frequency > 0)
    return [structure.element_names[i] for i in np.flatnonzero(jumps)]


def rows_that_jump(table) -> np.ndarray:
    """Per row of a periodic table (rows x phases): whether one spacing holds more than
    :data:`JUMP` of the row's range (a row that does not vary does not jump)."""
    t = np.atleast_2d(np.asarray(table, dtype=float))
    span = t.max(axis=1) - t.min(axis=1)
    step = np.max(np.abs(t - np.roll(t, 1, axis=1)), axis=1)
    return (span > 1e-9 * np.max(np.abs(t), axis=1)) & (step > JUMP * span)


COARSE_TABLE = 4096
"""Fewer table points than this where tables jump: :func:`coarse_table_warning`."""


def coarse_table_warning(model, structure) -> str | None:
    """A warning when tables jump and the structure's table points (``[analysis]
    table_points``) are below :data:`COARSE_TABLE`: each jump is then a ramp of 1/n of a
    cycle, and the dynamic peaks come out low (the shipped examples at 256 points: Liu et
    al. 2021's spur stage 0.6 %, Jin et al. 2019's 1 %, a planetary differential's sun
    mesh 9 %).  The default resolves jumps with 16384 points and is never warned of."""
    n = int(structure.n_table)
    names = jump_elements(structure) if n < COARSE_TABLE else []
    if not names:
        return None
    listed = ", ".join(names[:4]) + (f" and {len(names) - 4} more" if len(names) > 4 else "")
    return (f"analysis.table_points: the tables of {listed} step (a tooth pair entering or "
            f"leaving, an impact pulse); with {n} points per cycle each step is a ramp 1/{n} "
            "of a cycle long, which lowers the dynamic peaks (0.6-9 % on the shipped "
            "examples at 256); set [analysis] table_points = 16384 (no cost per step for "
            "most models) and confirm with --check-step (torquesplit.convergence.check_step in "
            "Python)")


def check_model(results):
    """The model of ``results`` (a run, or a steady state) as the check runs it, and its
    table points before and in the check: TABLE_REFINEMENT times as many where the tables
    have jumps."""
    model = results.model
    n = int(results.structure.n_table)
    if not has_jumps(results.structure):
        return model, n, n
    analysis = model.analysis.model_copy(update={"table_points": TABLE_REFINEMENT * n})
    return model.model_copy(update={"analysis": analysis}), n, TABLE_REFINEMENT * n


def agreeing_digits(a: float, b: float, most: int = 15) -> int:
    """Significant digits of ``a`` that ``b`` confirms: the largest s with
    |a - b| <= 0.5 x 10^(e - s + 1), e the decimal exponent of a, at which both also
    print the same (rounded to s digits in a's decimal places: 1.104934 and 1.104970
    differ by less than half a unit of the 5th digit, but print 1.1049 and 1.1050, so
    they agree to 4); 0 if none agree, ``most`` if they are equal.  6.7389 against
    6.7394 agree to 4 (6.739)."""
    if a == b:
        return most
    if not (math.isfinite(a) and math.isfinite(b)) or a == 0.0:
        return 0
    e = math.floor(math.log10(abs(a)))
    s = max(0, min(most, math.floor(e + 1 - math.log10(2.0 * abs(a - b)))))
    while s > 0 and _printed(a, s - 1 - e) != _printed(b, s - 1 - e):
        s -= 1
    return s


def held_decimals(value: float, checked: float | None, most: int) -> int:
    """Decimal places of ``value``, at most ``most``, that ``checked`` (the same number
    refined) reproduces by :func:`agreeing_digits`' rule; 0 where ``checked`` is missing
    or not finite.  What the generated pages print a number to."""
    if checked is None or not (math.isfinite(value) and math.isfinite(checked)):
        return 0
    if value == 0.0:
        return most if checked == 0.0 else 0
    e = math.floor(math.log10(abs(value)))
    return max(0, min(most, agreeing_digits(value, checked, max(1, e + 1 + most)) - 1 - e))


def _printed(x: float, places: int) -> float:
    """``x`` as printed to ``places`` decimal places (negative: to tens, hundreds...)."""
    if places >= 0:
        return float(f"{x:.{places}f}")
    scale = 10.0 ** -places
    return float(f"{x / scale:.0f}") * scale


@dataclass(frozen=True)
class StepCheck:
    """Every metric of a run (or steady state) and of the same at half its step."""

    values: dict
    """Metric name -> value of the run (:meth:`Results.metric_values`)."""
    halved: dict
    """The same metrics at half the step (Dormand-Prince: a 32-fold tighter tolerance)."""
    method: str
    """rk4 or dopri (a run), shooting or hb (a steady state)."""
    step: float
    """The RK4 step [s] (Dormand-Prince: the relative tolerance; harmonic balance: the
    harmonics)."""
    halved_step: float
    """The check's, in the same terms."""
    table_points: int = 0
    """Points per mesh period of the run's excitation tables (0: not recorded)."""
    check_table_points: int = 0
    """The check's (more than ``table_points`` where the tables have jumps)."""
    history_samples: float = 0.0
    """History samples per shortest mesh period of the run (0: no bearing forces
    compared), from which its bearing forces' means come."""
    check_history_samples: float = 0.0
    """The check's (twice the run's, where the steps allow)."""

    def rows(self) -> list[tuple[str, float, float, float, int]]:
        """(name, value, at half the step, relative change, agreeing significant digits)
        for every metric finite in both runs, the least converged first."""
        out = []
        for name, a in self.values.items():
            b = self.halved.get(name, math.nan)
            if not (math.isfinite(a) and math.isfinite(b)):
                continue
            rel = abs(a - b) / max(abs(a), abs(b)) if a != b else 0.0
            out.append((name, a, b, rel, agreeing_digits(a, b)))
        out.sort(key=lambda r: (r[4], -r[3], r[0]))
        return out

    def digits(self, name: str) -> int:
        """Significant digits of metric ``name`` that halving the step leaves alone."""
        return agreeing_digits(self.values[name], self.halved[name])

    def to_dict(self) -> dict:
        """Plain data (JSON): the steps and, per metric, both values, the relative change
        and the agreeing digits."""
        return {"method": self.method, "step": self.step, "halved_step": self.halved_step,
                "table_points": self.table_points,
                "check_table_points": self.check_table_points,
                "history_samples_per_period": self.history_samples,
                "check_history_samples_per_period": self.check_history_samples,
                "metrics": {n: {"value": a, "halved": b, "relative_change": r, "digits": d}
                            for n, a, b, r, d in self.rows()}}


def halved_steps_per_period(results) -> int:
    """RK4 steps per period (as ``steps_per_period`` counts them: of the shortest
    excitation, :func:`~torquesplit.solve.integrate.shortest_excitation_period`) that
    take at most half the step ``results`` took (its step may be finer than its
    ``steps_per_period`` asked, e.g. set by the RK4 stability of a stiff damping: then
    doubling the steps asked would not halve it)."""
    from .solve.integrate import shortest_excitation_period

    period = shortest_excitation_period(results.structure)
    if not math.isfinite(period):
        f_max = max(results.kinematics.meshes[m].frequency for m in results.mesh_names)
        period = 1.0 / f_max
    taken = period / results.solution.step  # steps per period the run took
    return math.ceil(2.0 * taken * (1.0 - 1e-12))


def check_step(results, *, definitions=None, rtol: float | None = None,
               progress=None) -> StepCheck:
    """The run of ``results`` again at half its step (same model, duration and method;
    Dormand-Prince: its tolerance ``rtol``, default the model's, / TIGHTER_RTOL), and
    with TABLE_REFINEMENT times its table points where its tables have jumps
    (:func:`check_model`), every metric of the load-sharing ``definitions`` (default:
    all) compared; and with twice its history's samples per period, its bearing table
    (:func:`bearing_values`: its means come from the history, so a finer step alone left
    their sampling unchecked; its peaks are taken at every step).  Costs about twice the
    first run."""
    import warnings

    from .simulation import simulate

    sol = results.solution
    duration = sol.t_span[1] - sol.t_span[0]
    model, n, n_check = check_model(results)
    bearings = bearing_values(results)
    samples = results.history_samples_per_period() if bearings else 0.0
    finer = dict(samples_per_period=math.ceil(2.0 * samples * (1.0 - 1e-12))) if samples else {}
    with warnings.catch_warnings():
        # the check's own table points and history are no settings of the user's: the
        # run warned
        warnings.filterwarnings("ignore", message="analysis.table_points: ")
        warnings.filterwarnings("ignore", message="analysis: the history holds at most ")
        warnings.filterwarnings("ignore", message="analysis: samples_per_period=")
        if sol.method == "rk4":
            spp = halved_steps_per_period(results)
            half = simulate(model, duration=duration, method="rk4",
                            steps_per_period=spp, progress=progress, **finer)
            step, halved_step = sol.step, half.solution.step
        else:
            rtol = float(results.model.analysis.rtol if rtol is None else rtol)
            half = simulate(model, duration=duration, method=sol.method,
                            rtol=rtol / TIGHTER_RTOL, progress=progress, **finer)
            step, halved_step = rtol, rtol / TIGHTER_RTOL
    return StepCheck(values={**results.metric_values(definitions), **bearings},
                     halved={**half.metric_values(definitions),
                             **(bearing_values(half) if bearings else {})},
                     method=sol.method, step=float(step), halved_step=float(halved_step),
                     table_points=n, check_table_points=n_check, history_samples=samples,
                     check_history_samples=(half.history_samples_per_period()
                                            if bearings else 0.0))


def bearing_values(results) -> dict[str, float]:
    """The bearing table's numbers by flat name: per body, the magnitude of its settled
    mean force (``bearing_mean_force.<body>``) and its largest magnitude
    (``bearing_peak_force.<body>``) [N], leaving out those at round-off
    (:func:`~torquesplit.results.bearing_round_off`: the sun of a symmetric stage,
    whose digits are noise).  Empty for a run without a settled bearing table."""
    from .results import bearing_round_off

    try:
        rows = results.bearing_forces()
    except (ValueError, ArithmeticError):  # (no settled part: no table to check)
        return {}
    tiny = bearing_round_off(rows)
    out = {}
    for b in rows:
        for key, field in (("bearing_mean_force", "mean_magnitude"),
                           ("bearing_peak_force", "peak_magnitude")):
            if abs(b[field]) > tiny:
                out[f"{key}.{b['body']}"] = float(b[field])
    return out


def _steady_values(st) -> dict:
    """The numbers of a steady state's mesh table by flat name (``field.mesh``)."""
    fields = ("mean_force", "min_force", "peak_force", "dynamic_factor", "peak_to_nominal",
              "load_sharing", "rms_transmission_error", "contact_loss")
    return {f"{f}.{r.mesh}": float(getattr(r, f)) for r in st.mesh_table() for f in fields}


def check_steady(st, *, progress=None) -> StepCheck:
    """The periodic steady state ``st`` (:func:`torquesplit.steady.steady_state`) again
    with twice its resolution, every number of its mesh table compared: shooting at half
    the RK4 step it took (from its own periodic state, so the finer solve needs few
    maps), harmonic balance with twice the harmonics; with TABLE_REFINEMENT times the
    table points where the tables have jumps (:func:`check_model`).  ``step`` /
    ``halved_step`` are the RK4 steps [s], or the harmonics for harmonic balance."""
    from .steady.api import steady_state

    ps = st.solution
    same = dict(st.options, stability=False, check=False, progress=progress)
    model, n, n_check = check_model(st)
    if ps.method == "shooting":
        steps = ps.t.size * ps.sample_every  # the samples are every k-th step
        order = max(st.period.max_order, 1)
        fine = steady_state(model, method="shooting",
                            steps_per_cycle=math.ceil(2 * steps / order),
                            initial=np.concatenate([ps.q[0], ps.v[0]]), **same)
        fine_steps = fine.solution.t.size * fine.solution.sample_every
        step, halved = ps.period / steps, fine.solution.period / fine_steps
    else:
        fine = steady_state(model, method="hb", harmonics=2 * ps.harmonics, adaptive=False,
                            **same)
        step, halved = float(ps.harmonics), float(fine.solution.harmonics)
    return StepCheck(values=_steady_values(st), halved=_steady_values(fine), method=ps.method,
                     step=float(step), halved_step=float(halved), table_points=n,
                     check_table_points=n_check)
