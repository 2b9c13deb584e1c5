"""Timing of the compiled engine, :func:`torquesplit.solve.integrate.integrate`.

Every case is a :class:`Case`: an assembled structure and its static equilibrium (the
initial state :func:`torquesplit.simulate` uses).  :func:`time_rk4` runs a fixed number
of RK4 steps at 100 steps per shortest mesh period (or the smaller stable step that
``integrate`` picks itself, see ``steps_per_period`` in the result) with the streaming
outputs ``simulate`` uses (per-cycle statistics of every mesh, the bearings' force peaks,
history every 100 steps);
:func:`time_dopri` runs the engine's adaptive Dormand-Prince for comparison with scipy.

Wall times use ``time.perf_counter``; CPU times ``time.process_time`` (the kernels are
single-threaded, so CPU time is what the run would take on an idle core).  The best of
``repeat`` runs is kept.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

STEPS_PER_PERIOD = 100
RECORD_EVERY = 100


@dataclass(frozen=True)
class Case:
    """One benchmark model, assembled once (lifetime: the whole benchmark run)."""

    name: str
    structure: object
    y0: np.ndarray
    f_max: float
    """Highest mesh frequency [Hz]."""
    static_converged: bool = True
    """False: the static iteration cycled; y0 is its last iterate (timings still valid)."""
    history_peaks: dict | None = None
    """The bearing table's force vectors that ``simulate`` streams (``integrate``'s
    ``history_peaks``)."""

    @property
    def n_dof(self) -> int:
        return self.structure.n_dof

    @property
    def n_elements(self) -> int:
        return self.structure.n_elements


def make_case(name: str, model) -> Case:
    """Assemble ``model`` and start from its static equilibrium."""
    import torquesplit
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.results import bearing_vectors
    from torquesplit.solve.static import static_equilibrium

    s = torquesplit.assemble(model)
    st = static_equilibrium(s)
    return Case(name=name, structure=s, y0=st.y0, f_max=float(s.frequency.max()),
                static_converged=bool(st.converged),
                history_peaks=bearing_vectors(s.element_names, model,
                                              solve_kinematics(model)))


def example_cases(names=None) -> tuple[list[Case], dict[str, str]]:
    """The shipped examples (``torquesplit.example_names()``) that load, as cases.

    Returns ``(cases, skipped)``; ``skipped`` maps the name of an example that does not
    load, assemble or reach static equilibrium (src/ is edited concurrently) to the
    first line of its error, so the benchmark reports it instead of stopping.
    """
    import torquesplit

    cases, skipped = [], {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", torquesplit.ModelWarning)
        for name in names or torquesplit.example_names():
            try:
                model = torquesplit.load_model(torquesplit.example_path(name))
                cases.append(make_case(name, model))
            except Exception as exc:  # noqa: BLE001 - reported in RESULTS.md
                skipped[name] = f"{type(exc).__name__}: {str(exc).splitlines()[0]}"
    return cases, skipped


def split_cases(branches=(2, 4, 8, 16)) -> list[Case]:
    """The generated N-branch split models of :mod:`models`."""
    from models import split_model

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", torquesplit.ModelWarning)
        return [make_case(f"split N={n}", split_model(n)) for n in branches]


def rk4_step(case: Case) -> float:
    """The RK4 step ``integrate`` uses at 100 steps per shortest mesh period [s].

    ``integrate`` refines the step by itself if 1/(100 f_max) is beyond 0.8 x the RK4
    stability limit of the structure; this returns the step it actually takes.
    """
    from torquesplit.solve.integrate import integrate

    sol = integrate(case.structure, case.y0, (0.0, 1.0 / case.f_max), method="rk4",
                    steps_per_period=STEPS_PER_PERIOD)
    return float(sol.step)  # a whole number of steps per period, so n_steps stay exact


def time_rk4(case: Case, n_steps: int, repeat: int = 2) -> dict:
    """Best of ``repeat`` runs of ``n_steps`` RK4 steps; us/step and simulated s per wall s.

    The engine's generated right-hand side (the pattern's code: what ``rhs="auto"`` takes
    for a run of this length), the literal code (``rhs="literal"``: the model's values
    compiled in, what "auto" takes for runs long enough to repay that) and the general
    kernel (``rhs="general"``) are run alternately, so their ratios are not skewed by the
    machine getting busier or quieter; the main figures are the generated code's.
    """
    from torquesplit.solve.integrate import integrate

    h = rk4_step(case)
    span = n_steps * h
    best: dict[str, dict] = {}
    for _ in range(repeat):
        for kind in ("generated", "literal", "general"):
            w0, c0 = time.perf_counter(), time.process_time()
            sol = integrate(case.structure, case.y0, (0.0, span), method="rk4",
                            steps_per_period=STEPS_PER_PERIOD, record_every=RECORD_EVERY,
                            history_peaks=case.history_peaks, rhs=kind)
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            if kind not in best or wall < best[kind]["wall"]:
                best[kind] = {"wall": wall, "cpu": cpu, "sol": sol}
    sol, gen, lit = best["generated"]["sol"], best["general"], best["literal"]
    return {
        "model": case.name, "static_converged": case.static_converged, "n_dof": case.n_dof,
        "n_elements": case.n_elements, "f_max": case.f_max,
        "step": float(sol.step), "steps_per_period": 1.0 / (case.f_max * sol.step),
        "n_steps": sol.n_steps, "simulated": sol.t_final, "success": sol.success,
        "message": sol.message, "rhs": sol.rhs, "rhs_compile_s": sol.rhs_compile_time,
        "wall": best["generated"]["wall"], "cpu": best["generated"]["cpu"],
        "us_per_step": best["generated"]["wall"] / sol.n_steps * 1e6,
        "cpu_us_per_step": best["generated"]["cpu"] / sol.n_steps * 1e6,
        "sim_per_wall": sol.t_final / best["generated"]["wall"],
        "general_us_per_step": gen["wall"] / gen["sol"].n_steps * 1e6,
        "general_cpu_us_per_step": gen["cpu"] / gen["sol"].n_steps * 1e6,
        "literal_us_per_step": lit["wall"] / lit["sol"].n_steps * 1e6,
        "literal_cpu_us_per_step": lit["cpu"] / lit["sol"].n_steps * 1e6,
        "literal_rhs": lit["sol"].rhs,
    }


def time_dopri(case: Case, duration: float, rtol: float = 1e-6, repeat: int = 2) -> dict:
    """Best of ``repeat`` runs of the engine's Dormand-Prince over ``duration`` seconds."""
    from torquesplit.solve.integrate import integrate

    best = None
    for _ in range(repeat):
        w0 = time.perf_counter()
        sol = integrate(case.structure, case.y0, (0.0, duration), method="dopri", rtol=rtol)
        wall = time.perf_counter() - w0
        if best is None or wall < best[0]:
            best = (wall, sol)
    wall, sol = best
    return {"model": case.name, "wall": wall, "n_steps": sol.n_steps, "n_rhs": sol.n_rhs,
                "n_rejected": sol.n_rejected, "simulated": sol.t_final, "success": sol.success,
                "sim_per_wall": sol.t_final / wall}
