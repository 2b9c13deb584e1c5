"""The set-up of a run, done once per structure: what a second run of the same structure
reuses (kernel arrays, eigenvalues of the step check, the compiled kernel's entry point,
the class of the generated function) and that reusing it changes no result."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from solve_models import random_structure, spur_pair

from torquesplit.solve import _kernels as kern
from torquesplit.solve import codegen, integrate, stability
from torquesplit.solve.kernel_data import kernel_model

integrate_module = sys.modules["torquesplit.solve.integrate"]


def test_kernel_model_and_eigenvalues_are_kept_per_structure():
    s, other = spur_pair(frequency=500.0), spur_pair(frequency=500.0)
    assert kernel_model(s) is kernel_model(s)
    assert kernel_model(other) is not kernel_model(s)
    lam = stability.system_eigenvalues(s)
    assert lam is stability.system_eigenvalues(s)
    with pytest.raises(ValueError):  # shared between callers: read-only
        lam[0] = 0.0
    assert stability.stable_step(s) == stability.stable_step(other)
    assert id(s) in stability.stable_step.cache and id(s) in kernel_model.cache


def test_equal_matrices_of_other_structures_share_their_eigen_problems():
    """A study's cases build a new structure each; those whose matrices are equal (errors
    and phases varied) share the step check's eigen problems, the rigid-body modes and the
    keys of the generated code; a changed stiffness does not."""
    from torquesplit.solve.static import rigid_body_modes

    s, same, stiffer = (spur_pair(frequency=500.0), spur_pair(frequency=500.0),
                        spur_pair(frequency=500.0, stiffness=4e8))
    assert stability.system_eigenvalues(same) is stability.system_eigenvalues(s)
    assert stability.system_eigenvalues(stiffer) is not stability.system_eigenvalues(s)
    assert stability.stable_step(stiffer) < stability.stable_step(same)
    assert stability.highest_mode(same) == stability.highest_mode(s)
    assert stability.highest_mode(stiffer)[0] > stability.highest_mode(s)[0]
    from torquesplit.solve import static

    phi = rigid_body_modes(s)
    kept = set(static._rigid_modes.cache)
    again = rigid_body_modes(same)
    assert set(static._rigid_modes.cache) == kept  # (no second SVD)
    assert np.array_equal(again, phi) and again is not phi and again.flags.writeable
    damped = spur_pair(frequency=500.0, damping=50.0)  # (the code reads the stiffness
    # tables at every call, a damping coefficient from its parameters or its literals)
    assert codegen._value_key(kernel_model(s)) == codegen._value_key(kernel_model(same))
    assert codegen._value_key(kernel_model(s)) != codegen._value_key(kernel_model(damped))
    assert codegen._pattern_key(kernel_model(s)) == codegen._pattern_key(kernel_model(damped))


def test_the_code_keys_keep_no_finished_run_alive():
    """The generated code's keys are kept for the last kernel model's arrays, weakly:
    a finished run's phase tables are freed with it."""
    import gc
    import weakref

    s = random_structure(2)
    km = kernel_model(s)
    key = codegen._value_key(km)
    assert codegen._value_key(km._replace()) == key  # (the same arrays: kept)
    ref = weakref.ref(km.stiffness_table)
    del s, km
    gc.collect()
    assert ref() is None


def test_generated_functions_share_one_class():
    """numba types a first-class function argument by a dispatch on its class: one class
    for every generated function (a class per call missed that dispatch's cache)."""
    a = codegen.generated_rhs(kernel_model(random_structure(0)))
    b = codegen.generated_rhs(kernel_model(random_structure(1)))
    assert a.generated and b.generated
    assert type(a.function) is type(b.function)


def test_type_key_follows_what_numba_types():
    x = np.zeros(4)
    ro = np.zeros(4)
    ro.setflags(write=False)
    key = integrate_module._type_key
    assert key(x) == key(np.ones(4))
    assert key(x) != key(ro)  # read-only arrays are typed apart
    assert key(x) != key(np.zeros(4, dtype=np.int64))
    assert key(x) != key(np.zeros((2, 2)))
    assert key(np.zeros((4, 3))[:, 0]) != key(x)  # layout
    assert key((x, 1.0)) != key((x, 1))
    # what numba may type apart for one key is not keyed: numba types it
    for untyped in ([1], np.zeros(2, dtype=[("a", "f8"), ("b", "f8")]), 2**63,
                    (x, [1.0])):
        assert key(untyped) is None
    assert integrate_module._compiled(kern.rk4_run, ([1.0],)) is kern.rk4_run


def test_second_run_uses_the_entry_point_and_gives_the_same_result(monkeypatch):
    s = spur_pair(frequency=800.0, damping=50.0)
    kw = dict(method="rk4", steps_per_period=50)
    monkeypatch.setattr(integrate_module, "_ENTRIES", {})
    first = integrate(s, np.zeros(4), (0.0, 0.01), **kw)
    args_key = [k for k in integrate_module._ENTRIES if k[0] is kern.rk4_run]
    assert args_key, "the RK4 kernel's entry point was not kept after a run"
    found = []
    real = integrate_module._compiled
    monkeypatch.setattr(integrate_module, "_compiled",
                        lambda d, a: found.append(real(d, a)) or found[-1])
    second = integrate(s, np.zeros(4), (0.0, 0.01), **kw)
    assert found and all(f is not kern.rk4_run for f in found)  # the entry point ran
    np.testing.assert_array_equal(first.y_final, second.y_final)
    np.testing.assert_array_equal(first.cycle_max, second.cycle_max)


def test_the_code_keys_of_a_model_with_a_plain_field_are_computed_not_kept():
    km = kernel_model(random_structure(3))
    key = codegen._pattern_key(km)
    plain = km._replace(tv_tab=[0])  # (a list: no weak reference)
    assert codegen._pattern_key(plain) == key
    assert codegen._LAST_KEYS.keys is None


def test_scratch_arrays_start_on_a_cache_line_with_numpys_values():
    """Every scratch array of a run starts on a 64-byte boundary (numpy gives 16: the
    step's speed depended on the allocation's luck), with the values, shapes and dtypes
    the unaligned construction gives, and the addresses the generated code reads."""
    from torquesplit.solve import kernel_data as kd

    m = kernel_model(spur_pair())
    par = np.arange(3.0)
    w = kd.make_work(m, par)
    real = kd.aligned
    try:
        kd.aligned = lambda a: a
        plain = kd.make_work(m, par)
    finally:
        kd.aligned = real
    for name, a, b in zip(kd.Work._fields, w, plain):
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype and a.shape == b.shape, name
            assert name == "addr" or np.array_equal(a, b), name  # (addresses differ)
            assert a.flags.c_contiguous and a.flags.writeable, name
            if a is not par and a.nbytes:
                assert a.ctypes.data % kd.ALIGN == 0, name
    assert w.par is par
    assert w.addr[kd.A_Y] == w.Y.ctypes.data and w.addr[kd.A_K] == w.K.ctypes.data
    assert w.addr[kd.A_SELF] == w.addr.ctypes.data


def test_ctrl_c_while_the_kernels_compile_stops_the_caller(monkeypatch):
    """A Ctrl-C that lands while the first run compiles its kernels stops that run: the
    warm-up inside :func:`compile_kernels` ended as an interrupted run of its own, and a
    first ``torquesplit run`` went on to its end.  The method counts as not compiled."""
    import importlib

    mod = importlib.import_module("torquesplit.solve.integrate")
    monkeypatch.setattr(mod, "_COMPILE_TIMES", {})

    def interrupt(*args):  # Ctrl-C inside the kernel's first call: while it compiles
        raise KeyboardInterrupt

    monkeypatch.setattr(mod, "_compiled", lambda function, args: interrupt)
    s = spur_pair()
    with mod.stop_on_interrupt(), pytest.raises(KeyboardInterrupt):
        integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-3), step=1e-5)
    assert "rk4" not in mod._COMPILE_TIMES
    # a run's own interrupt (kernels compiled) still ends it as a stopped run
    mod._COMPILE_TIMES["rk4"] = 0.0
    with mod.stop_on_interrupt():
        sol = integrate(s, np.zeros(2 * s.n_dof), (0.0, 1e-3), step=1e-5)
    assert sol.status == mod.INTERRUPTED and not sol.success
