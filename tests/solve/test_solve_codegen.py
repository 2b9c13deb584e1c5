"""The generated right-hand side (solve/codegen.py) against the general kernel rhs_slot:
bit for bit, in the kernels and through integrate."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from solve_models import random_structure, random_structure_extras, spur_pair

import torquesplit
from torquesplit.solve import codegen, integrate
from torquesplit.solve.kernel_data import kernel_model

integrate_module = sys.modules["torquesplit.solve.integrate"]


def _call(code, s, t, y):
    """dy/dt, forces and deformations at (t, y) through the kernels' one stage
    evaluation, with the generated code or the general kernel (``code``)."""
    return integrate_module._evaluate(s, t, y, code=code)


def _extras_gyro(seed):
    return random_structure_extras(seed, gyroscopic=True)


@pytest.mark.parametrize("make, seed", [(random_structure, 0), (random_structure, 1),
                                        (random_structure_extras, 2), (_extras_gyro, 4)])
def test_generated_rhs_is_rhs_slot_bit_for_bit(make, seed):
    """Every branch: elements inside and outside their dead zones (gaps 1-2 um against
    deflections of a few um), errors, additive forces, spline components (zero
    stiffness in this kernel), at several times."""
    s = make(seed)
    model = kernel_model(s)
    gen, general = codegen.generated_rhs(model), codegen.general_rhs()
    assert gen.generated and not general.generated and gen.lines > 0
    rng = np.random.default_rng(seed)
    n = s.n_dof
    in_zone = set()
    for t in (0.0, 1.7e-3, 0.0413, 3.2):
        g = torquesplit.solve.excitation_numpy(s, t).half_gap
        for _ in range(25):
            y = np.concatenate([rng.normal(scale=3e-6, size=n), rng.normal(scale=1e-3, size=n)])
            dy_g, f_g, d_g = _call(gen, s, t, y)
            dy_s, f_s, d_s = _call(general, s, t, y)
            np.testing.assert_array_equal(dy_g, dy_s)
            np.testing.assert_array_equal(f_g, f_s)
            np.testing.assert_array_equal(d_g, d_s)
            in_zone |= set(np.flatnonzero((np.abs(d_s) <= g) & (g > 0)).tolist())
    assert in_zone, "no state fell inside a dead zone: the test would miss that branch"


@pytest.mark.parametrize("kind, seed", [("generated", 3), ("literal", 5)])
@pytest.mark.parametrize("method", ["rk4", "dopri"])
def test_integrate_compiled_equals_general(method, kind, seed):
    """The generated code (the pattern's, and the literal one with the model's values
    compiled in) against the general kernel, through integrate."""
    s = random_structure_extras(seed, gyroscopic=True)
    y0 = np.zeros(2 * s.n_dof)
    kw = dict(method=method, full_history=True)
    if method == "rk4":
        kw["step"] = 2e-6
    a = integrate(s, y0, (0.0, 0.004), rhs=kind, **kw)
    b = integrate(s, y0, (0.0, 0.004), rhs="general", **kw)
    assert (a.rhs, b.rhs) == (kind, "general")
    assert a.success and b.success and a.n_steps == b.n_steps > 100
    for name in ("y_final", "cycle_max", "cycle_min", "cycle_mean", "history_forces",
                 "history_q", "full_y", "separation_steps", "back_contact_steps"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_seed001_example_runs_the_generated_code_with_the_same_results():
    model = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    runs = [torquesplit.simulate(model, duration=0.05, rhs=kind) for kind in ("generated",
                                                                             "general")]
    a, b = (r.solution for r in runs)
    assert (a.rhs, b.rhs) == ("generated", "general")
    np.testing.assert_array_equal(a.y_final, b.y_final)
    np.testing.assert_array_equal(a.cycle_max, b.cycle_max)


def test_compiled_code_is_reused_for_the_same_pattern():
    """Values differ (stiffness, torque), sparsity does not: one compilation."""
    s1, s2 = spur_pair(stiffness=3.1e8, torque=71.0), spur_pair(stiffness=4.7e8, torque=13.0)
    g1, g2 = (codegen.generated_rhs(kernel_model(s)) for s in (s1, s2))
    assert g2.compile_time == 0.0
    assert g1.function.__wrapper_address__() == g2.function.__wrapper_address__()
    assert not np.array_equal(g1.parameters, g2.parameters)
    y0 = np.zeros(2 * s2.n_dof)
    a = integrate(s2, y0, (0.0, 1e-3), rhs="generated")
    b = integrate(s2, y0, (0.0, 1e-3), rhs="general")
    np.testing.assert_array_equal(a.y_final, b.y_final)


def test_bad_rhs_option_is_refused():
    s = spur_pair()
    with pytest.raises(ValueError, match="rhs must be 'auto', 'generated', 'literal' or "
                                         "'general'"):
        integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-3), rhs="fast")


def test_generation_failure_falls_back_to_the_general_kernel(monkeypatch):
    def broken(model, literal=False):
        raise RuntimeError("no compiler here")

    monkeypatch.setattr(codegen, "generated_rhs", broken)
    monkeypatch.setattr(integrate_module, "_CODEGEN_WARNED", False)
    s = spur_pair()
    with pytest.warns(RuntimeWarning, match="no compiler here.*general kernel"):
        sol = integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-3), rhs="generated")
    assert sol.success and sol.rhs == "general"


def test_auto_generates_only_when_the_run_repays_the_compilation():
    """A pattern no other test compiles: short runs keep the general kernel, long ones
    generate, and once compiled the pattern is always used."""
    s = random_structure(7)
    model = kernel_model(s)
    assert not codegen.worth_generating(model, 1e3)
    assert codegen.worth_generating(model, 1e9)
    y0 = np.zeros(2 * s.n_dof)
    short = integrate(s, y0, (0.0, 1e-4), step=1e-6)  # 100 steps
    assert short.rhs == "general"
    codegen.generated_rhs(model)
    assert codegen.worth_generating(model, 1e3)
    again = integrate(s, y0, (0.0, 1e-4), step=1e-6)
    assert again.rhs == "generated"
    np.testing.assert_array_equal(short.y_final, again.y_final)


def test_threads_compiling_and_running_at_once_agree():
    """Four threads generate (distinct patterns and one shared) and integrate at once:
    the compiler is serialised and every result equals the general kernel's."""
    from concurrent.futures import ThreadPoolExecutor

    structures = [random_structure(20 + k % 3) for k in range(4)]

    def run(s):
        y0 = np.zeros(2 * s.n_dof)
        a = integrate(s, y0, (0.0, 2e-4), step=1e-6, rhs="generated")
        b = integrate(s, y0, (0.0, 2e-4), step=1e-6, rhs="general")
        return a.rhs, np.array_equal(a.y_final, b.y_final)

    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(run, structures))
    assert results == [("generated", True)] * 4


def test_without_llvmlite_compilation_runs_fall_back_to_the_general_kernel(monkeypatch):
    """An llvmlite that cannot compile the generated code (e.g. without the new pass
    manager): the general kernel needs nothing of it, so every run still works, with one
    warning, and gives the same numbers."""
    def no_compiler(*args, **kwargs):
        raise AttributeError("module 'llvmlite.binding' has no attribute 'create_pass_builder'")

    monkeypatch.setattr(codegen._COMPILER, "compile", no_compiler)
    monkeypatch.setattr(codegen._COMPILER, "_cache", {})
    monkeypatch.setattr(integrate_module, "_CODEGEN_WARNED", False)
    s = random_structure(31)
    y0 = np.zeros(2 * s.n_dof)
    with pytest.warns(RuntimeWarning, match="create_pass_builder.*general kernel"):
        sol = integrate(s, y0, (0.0, 2e-4), step=1e-6, rhs="generated")
    assert sol.success and sol.rhs == "general"
    ref = integrate(s, y0, (0.0, 2e-4), step=1e-6, rhs="general")
    np.testing.assert_array_equal(sol.y_final, ref.y_final)


# ------------------------------------------------------------------ literal code
@pytest.mark.parametrize("make, seed", [(random_structure, 0), (random_structure_extras, 2),
                                        (_extras_gyro, 4)])
def test_literal_code_is_rhs_slot_bit_for_bit(make, seed):
    """The model's values as constants of the code (LLVM folds only what is exact)."""
    s = make(seed)
    model = kernel_model(s)
    lit, general = codegen.generated_rhs(model, literal=True), codegen.general_rhs()
    assert lit.literal and lit.generated
    ir, _ = codegen.rhs_ir(model, literal=True)
    assert "%par" not in ir.split("define void @rhs(")[0].split("entry:", 1)[1], \
        "the literal code still loads parameters"
    rng = np.random.default_rng(seed)
    n = s.n_dof
    for t in (0.0, 0.0413, 3.2):
        for _ in range(20):
            y = np.concatenate([rng.normal(scale=3e-6, size=n), rng.normal(scale=1e-3, size=n)])
            for a, b in zip(_call(lit, s, t, y), _call(general, s, t, y)):
                np.testing.assert_array_equal(a, b)


def test_literal_code_is_per_set_of_values():
    """Same pattern, other values of its parameters (the torque: external_force): another
    literal code; the same parameters again, or other excitation values only (the
    stiffness: the tables K, read at every call): the cached one."""
    s1, s2 = spur_pair(stiffness=3.3e8, torque=17.0), spur_pair(stiffness=3.3e8, torque=29.0)
    m1, m2 = kernel_model(s1), kernel_model(s2)
    a1, a2 = codegen.generated_rhs(m1, literal=True), codegen.generated_rhs(m2, literal=True)
    assert a1.function.__wrapper_address__() != a2.function.__wrapper_address__()
    again = codegen.generated_rhs(kernel_model(spur_pair(stiffness=5.1e8, torque=17.0)),
                                  literal=True)
    assert again.compile_time == 0.0
    assert again.function.__wrapper_address__() == a1.function.__wrapper_address__()
    y0 = np.zeros(2 * s2.n_dof)
    runs = {kind: integrate(s2, y0, (0.0, 1e-3), rhs=kind) for kind in ("literal", "general")}
    assert runs["literal"].rhs == "literal"
    np.testing.assert_array_equal(runs["literal"].y_final, runs["general"].y_final)


def test_auto_takes_literal_code_only_where_it_repays_its_compilation(monkeypatch):
    s = random_structure(8)
    model = kernel_model(s)
    codegen.generated_rhs(model)  # the pattern compiled: "auto" generates from here on
    assert not codegen.worth_literal(model, 1e3)
    assert codegen.worth_literal(model, 1e9)
    y0 = np.zeros(2 * s.n_dof)
    short = integrate(s, y0, (0.0, 1e-4), step=1e-6)
    assert short.rhs == "generated"
    monkeypatch.setattr(codegen, "_LITERAL_SAVING_S_PER_NONZERO", 1.0)  # (any run repays)
    long = integrate(s, y0, (0.0, 1e-4), step=1e-6)
    assert long.rhs == "literal"
    np.testing.assert_array_equal(short.y_final, long.y_final)


def test_runs_of_the_same_values_repay_the_literal_code_together(monkeypatch):
    """A study's cases that vary only the errors share one literal code, which one case
    alone may not repay: the second run of the same values (with the pattern's code
    before) takes it; other values do not count towards it."""
    monkeypatch.setattr(codegen._COMPILER, "_literal", {})
    monkeypatch.setattr(codegen._COMPILER, "_demand", {})
    s, other = spur_pair(torque=13.0), spur_pair(torque=31.0)
    y0 = np.zeros(2 * s.n_dof)
    n_rhs = 4 * 100  # (100 RK4 steps)
    monkeypatch.setattr(codegen, "literal_break_even", lambda model: 1.5 * n_rhs)
    codegen.generated_rhs(kernel_model(s))  # (the pattern: "auto" generates)
    runs = [integrate(x, y0, (0.0, 1e-4), step=1e-6) for x in (s, other, s, s)]
    assert [r.rhs for r in runs] == ["generated", "generated", "literal", "literal"]
    np.testing.assert_array_equal(runs[0].y_final, runs[2].y_final)
    assert codegen._COMPILER.demand(kernel_model(other)) == n_rhs
    # at most DEMAND_KEYS sets of values remembered, the oldest dropped
    monkeypatch.setattr(codegen, "DEMAND_KEYS", 1)
    codegen.note_pattern_run(kernel_model(s), 1.0)
    assert codegen._COMPILER.demand(kernel_model(other)) == 0.0


def test_literal_codes_are_capped_per_process(monkeypatch):
    """MCJIT never frees code: beyond LITERAL_MAX the runs take the pattern's code, and
    asking for a literal one by name still runs (the same results)."""
    monkeypatch.setattr(codegen._COMPILER, "_literal", {})
    monkeypatch.setattr(codegen, "LITERAL_MAX", 1)
    s1, s2 = spur_pair(torque=11.0), spur_pair(torque=23.0)  # (external_force)
    y0 = np.zeros(2 * s1.n_dof)
    assert integrate(s1, y0, (0.0, 1e-3), rhs="literal").rhs == "literal"
    assert not codegen.worth_literal(kernel_model(s2), 1e12)
    b = integrate(s2, y0, (0.0, 1e-3), rhs="literal")
    assert b.rhs == "generated"
    with pytest.raises(torquesplit.errors.SolverError, match="LITERAL_MAX"):
        codegen.generated_rhs(kernel_model(s2), literal=True)
    assert integrate(s1, y0, (0.0, 1e-3), rhs="literal").rhs == "literal"  # (cached)
    np.testing.assert_array_equal(b.y_final,
                                  integrate(s2, y0, (0.0, 1e-3), rhs="general").y_final)


def test_steady_state_refuses_literal_code():
    """The steady-state solvers change the code's parameters with the speed."""
    from torquesplit.steady.problem import PeriodicProblem

    with pytest.raises(ValueError, match="rhs='literal'.*rhs='generated'"):
        PeriodicProblem(spur_pair(), 1000.0, rhs="literal")


def test_literal_cap_from_the_environment(monkeypatch):
    monkeypatch.setenv("TORQUESPLIT_LITERAL_MAX", "0")
    assert codegen._literal_max() == 0
    monkeypatch.setenv("TORQUESPLIT_LITERAL_MAX", " 40 ")
    assert codegen._literal_max() == 40
    monkeypatch.delenv("TORQUESPLIT_LITERAL_MAX")
    assert codegen._literal_max() == 16
    for bad in ("-1", "many", "2.5"):
        monkeypatch.setenv("TORQUESPLIT_LITERAL_MAX", bad)
        with pytest.warns(RuntimeWarning, match="TORQUESPLIT_LITERAL_MAX.*not a count"):
            assert codegen._literal_max() == 16
