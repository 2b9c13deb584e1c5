"""Liu et al. 2021's reducer (49 DOF) at the paper's resolution: a default run's integration.

The design target: at most 3 s of integration on one core for the run the paper describes
(step 1/100 of the bevel mesh period, 2000 double-helical mesh cycles; the example's
``[analysis]``, i.e. ``torquesplit run liu2021_split_torque_helicopter``).  Timed is what
``simulate`` reports as the integration's wall time (``Solution.wall_time``: the kernels'
run, the outputs streamed as a default run streams them; without the static equilibrium,
the assembly and the one-time generation of the literal right-hand side, which a first
run adds, reported apart) and the process CPU time of the whole ``simulate`` call, best of
``repeat`` runs after one that compiles or loads everything.  Runnable alone:
``python benchmarks/bench_paper_run.py``.
"""

from __future__ import annotations

import time

MODEL = "liu2021_split_torque_helicopter"


def measure(repeat: int = 2) -> dict:
    """Best integration wall time and best CPU time of the example's default run."""
    import warnings

    import torquesplit

    model = torquesplit.load_model(torquesplit.example_path(MODEL))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        first = torquesplit.simulate(model)  # compiles or loads the kernels and the code
        best_wall, best_cpu = float("inf"), float("inf")
        for _ in range(repeat):
            c0 = time.process_time()
            res = torquesplit.simulate(model)
            best_cpu = min(best_cpu, time.process_time() - c0)
            best_wall = min(best_wall, res.solution.wall_time)
    sol = res.solution
    return {"model": MODEL, "steps": int(sol.n_steps),
            "simulated": float(sol.t_final - sol.t_span[0]), "rhs": str(sol.rhs),
            "integration_s": best_wall, "simulate_cpu_s": best_cpu,
            "first_rhs_compile_s": float(first.solution.rhs_compile_time),
            "us_per_step": 1e6 * best_wall / max(int(sol.n_steps), 1), "repeat": repeat}


if __name__ == "__main__":
    r = measure()
    print(f"{r['model']}: {r['steps']:,} steps ({r['rhs']}), integration "
          f"{r['integration_s']:.3f} s ({r['us_per_step']:.3f} us/step), whole simulate CPU "
          f"{r['simulate_cpu_s']:.3f} s")
