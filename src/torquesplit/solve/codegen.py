"""A model's right-hand side as straight-line machine code, compiled in milliseconds.

The general kernel :func:`torquesplit.solve._kernels.rhs_slot` loops over the elements
and the DOFs of any structure through index arrays.  For a given structure the same
arithmetic can be written out once: one load, multiply and add per non-zero of the
projection V, no index arrays and no loops.  This module writes that code as LLVM IR
(text) from the kernels' own model arrays and compiles it with llvmlite, the compiler
numba itself uses: 0.05-0.5 s for the seed examples, against 4-22 s for the same code
written as Python and compiled by numba.  The kernels (``rk4_run``, ``dopri_run``) call it through a
numba first-class function, so they are compiled and cached once for every model.

The element force law is not written here: each element's force is a call to the
law's own compiled code, :func:`torquesplit.solve.laws.spring_force_c` (numba compiles
:func:`~torquesplit.solve.laws.spring_force` with a C signature; its LLVM module is
linked into each generated module and inlined), so the generated code and
``rhs_slot`` run the same instructions for the law, and the same sums in the same order
around it (no fused multiply-adds, no reassociation): results are bit for bit the same
(tested).  A whole RK4 step is about twice as fast with it (Ji & Li: 0.78 against
1.51 µs in the same benchmark run, benchmarks/RESULTS.md), and within 1.0-1.2 times of a
transcription generated from the assembled structure (benchmarks/bench_specialised.py:
checks kernel overhead, not assembly; the Ji & Li equations written by hand are timed
in benchmarks/bench_transcription.py).  The kernels pass it data addresses taken once per call: ``array.ctypes``
at every call would cost an atomic reference-count increment and decrement per array,
more than the arithmetic.  What it computes, for one excitation slot::

    delta_e = -E_e + sum_j V_ej q_j          (CSR order of V)
    rate_e  = -ED_e + sum_j V_ej v_j
    f_e     = spring_force(K_e, c_e, delta_e, rate_e, G_e) + P_e     (the law)
    dy      = [v, M^-1 (F_ext - C_g v - sum_e V_e f_e - G v - K_f q)]  (CSR order of
              V^T, of G, of K_f)
    splines: (f_x, f_y) = spline_force(delta_x, delta_y, rate_x, rate_y, par) on the
              two component elements of each, then dy -= M^-1 V_e f_e of both
    friction: dy -= M^-1 W_e(s) max(f_e, 0) of each friction mesh
              (both as ``rhs_extra`` does them after ``rhs_slot``)

The code depends only on the sparsity of V and G, on which elements have a dead zone, which
are spline components and which meshes have tooth friction; the values (coefficients,
damping, masses, forces) are read from a parameter vector at fixed offsets.  Compiled
code is therefore kept per pattern and reused by every model with the same pattern (a
parameter sweep compiles once).

*Literal* code (``generated_rhs(model, literal=True)``, ``integrate(rhs="literal")``, and
``"auto"``'s choice for a run long enough to repay it) writes those values into the code
as constants instead: the same instructions, but LLVM drops a product with a coefficient
of 1, negates for -1 and takes every other constant as an operand, so that a whole RK4
step takes 4-8 % less time on Ji & Li's and Liu et al. 2021's models and 20-25 % less on
Dong et al. 2021's (benchmarks/RESULTS.md).  It folds nothing that is not exact (no fast-math
flags): the results are bit for bit the same (tested).  Such code serves one set of
values (the excitation arrays, e.g. the stiffness tables, still come at every call), so
a process keeps at most ``LITERAL_MAX`` of them.

Calling convention (C)::

    void rhs(uint64 addr, uint64 y, uint64 dy, uint64 force, uint64 defl, int64 off)

``y``, ``dy``, ``force``, ``defl`` are the addresses of the float64 rows read and written
(a state row's address is base + row x stride); ``addr`` the address of the run's table
of data addresses (``Work.addr``, taken once per run), from which the code loads those
of K, G, E, ED, P (the kernels' whole (n_slot, ne) excitation arrays), ``par`` and FR
(entries ``A_K`` .. ``A_FR`` of :mod:`~torquesplit.solve.kernel_data`).  The function
reads the slot starting at flat index ``off`` = slot * ne (and row off / ne of the
friction values FR).  Six arguments, so that all of them travel in registers on x86-64
and AArch64: the twelve of an earlier version put six on the stack at every call, which
cost 3-4 % of a whole RK4 step.
"""

from __future__ import annotations

import hashlib
import os
import threading
import weakref
from dataclasses import dataclass

import numpy as np

from .._jit_cache import track_imports
from .._memo import hash_arrays
from . import kernel_data as kd
from . import laws

track_imports()  # before any @njit(cache=True): see torquesplit._jit_cache

__all__ = ["GeneratedRhs", "generated_rhs", "general_rhs", "rhs_ir", "worth_generating",
           "worth_literal", "note_pattern_run"]

ARG_NAMES = ("y", "dy", "force", "defl", "K", "G", "E", "ED", "P", "par", "FR")
"""The arrays the code works on (the body's pointer arguments, in order)."""
PASSED = ARG_NAMES[:4]
"""Those the kernels pass at every call (y, dy, force, defl); the code loads the others'
addresses from the run's address table (``Work.addr``) at these entries:"""
ADDR_INDEX = {"K": kd.A_K, "G": kd.A_G, "E": kd.A_E, "ED": kd.A_ED, "P": kd.A_P,
              "par": kd.A_PAR, "FR": kd.A_FR}
PARAMETER_ARRAYS = ("v_coef", "vt_coef", "gy_coef", "fs_coef", "damping", "external_force",
                    "ground_damping", "inv_mass", "sp_par", "fr_coef")
"""The kernel-model arrays the generated code reads through ``par`` (the rest: its
pattern, or the excitation arrays K, G, E, ED, P and FR passed at every call)."""
SLOT_ARGS = ("K", "G", "E", "ED", "P")
"""Excitation arrays (n_slot, ne), passed whole: the function reads row ``off / ne``.  The
friction table values FR (n_slot, 3 n_friction) are read in row ``off / ne`` too."""


@dataclass(frozen=True)
class GeneratedRhs:
    """A compiled right-hand side: the callable the kernels take, and its parameters."""

    function: object
    """Numba first-class function (``WrapperAddressProtocol``) of the C signature above."""
    parameters: np.ndarray
    """Parameter vector ``par`` for this model's values (empty: use the general kernel)."""
    compile_time: float
    """Seconds spent generating and compiling (0.0 when the pattern was cached)."""
    lines: int
    """Lines of LLVM IR (0 for the general kernel)."""
    literal: bool = False
    """True: the model's values are constants of the code (:func:`generated_rhs` with
    ``literal=True``), which then ignores ``parameters``; False: the code reads them
    from ``parameters`` (one compiled function for every model of the pattern)."""

    @property
    def generated(self) -> bool:
        return self.parameters.size > 0


def _arrays(model) -> dict:
    return model._asdict()


_LAWS: dict = {}


def _law_ir(kind: str = "spring") -> tuple[str, str]:
    """LLVM IR of a compiled element law and the name of its function (numba calling
    convention: ``i32 (ptr retptr, ptr excinfo, <the law's arguments>)``): ``"spring"``
    :func:`~torquesplit.solve.laws.spring_force_c` (double k, c, d, r, g; the force
    stored at retptr), ``"spline"`` :func:`~torquesplit.solve.laws.spline_force_c`
    (ten doubles and the address the two force components are written to)."""
    if kind not in _LAWS:
        cf = laws.spring_force_c() if kind == "spring" else laws.spline_force_c()
        name = cf.native_name
        ir = cf.inspect_llvm()
        inner = name[len("cfunc."):]
        if not name.startswith("cfunc.") or f"@{inner}(" not in ir:
            raise RuntimeError(f"the compiled law {name!r} has no LLVM function to link")
        _LAWS[kind] = (ir, inner)
    return _LAWS[kind]


def rhs_ir(model, literal: bool = False) -> tuple[str, list[tuple[str, int]]]:
    """LLVM IR of the right-hand side of a kernel model ``model``
    (:class:`~torquesplit.solve.kernel_data.KernelModel`) and the parameter layout: entry
    i of ``par`` is ``model.<name>`` (flattened) ``[index]`` for the i-th ``(name,
    index)``.  With ``literal`` each parameter is written as its value, a constant (its
    exact bits), instead of a load from ``par``.  The IR calls the element laws by name
    (:func:`_law_ir`); :func:`_Compiler.compile` links them in."""
    a = _arrays(model)
    flat = {name: np.ravel(a[name]) for name in PARAMETER_ARRAYS}
    n = a["inv_mass"].shape[0]
    ne = a["vr_ptr"].shape[0] - 1
    vr_ptr, vq_idx = a["vr_ptr"].astype(np.int64), a["vq_idx"].astype(np.int64)
    vt_ptr, vt_el = a["vt_ptr"].astype(np.int64), a["vt_el"].astype(np.int64)
    gy_ptr, gy_idx = a["gy_ptr"].astype(np.int64), a["gy_idx"].astype(np.int64)
    fs_ptr, fs_idx = a["fs_ptr"].astype(np.int64), a["fs_idx"].astype(np.int64)
    gap_ptr, gap_values = a["gap_ptr"], a["gap_values"]
    has_error, has_force = _error_and_force_flags(a)
    sp_el = np.asarray(a["sp_el"], dtype=np.int64).reshape(-1, 2)
    fr_el, fr_ptr = a["fr_el"].astype(np.int64), a["fr_ptr"].astype(np.int64)
    fr_dof, fr_row = a["fr_dof"].astype(np.int64), a["fr_row"].astype(np.int64)
    n_fr_rows = int(a["friction_table"].shape[0])
    spline_part = set(sp_el.ravel().tolist())
    _, law = _law_ir()
    spline_law = _law_ir("spline")[1] if sp_el.shape[0] else None
    layout: list[tuple[str, int]] = []
    body: list[str] = []
    count = 0

    def new() -> str:
        nonlocal count
        count += 1
        return f"%t{count}"

    def load(ptr: str, i: int) -> str:
        p, v = new(), new()
        if ptr in SLOT_ARGS:  # row `slot` of a (n_slot, ne) array: entry off + i
            k = new()
            body.append(f"  {k} = add i64 %off, {i}")
            i = k
        body.append(f"  {p} = getelementptr inbounds double, ptr %{ptr}, i64 {i}")
        body.append(f"  {v} = load double, ptr {p}, align 8")
        return v

    def load_friction(row: int) -> str:
        """Entry ``row`` of the friction values of this slot (row off / ne of FR)."""
        k, p, v = new(), new(), new()
        body.append(f"  {k} = add i64 %off_fr, {row}")
        body.append(f"  {p} = getelementptr inbounds double, ptr %FR, i64 {k}")
        body.append(f"  {v} = load double, ptr {p}, align 8")
        return v

    def store(ptr: str, i: int, value: str) -> None:
        p = new()
        body.append(f"  {p} = getelementptr inbounds double, ptr %{ptr}, i64 {i}")
        body.append(f"  store double {value}, ptr {p}, align 8")

    def op(opcode: str, x: str, y: str) -> str:
        v = new()
        body.append(f"  {v} = {opcode} double {x}, {y}")
        return v

    def neg(x: str) -> str:
        v = new()
        body.append(f"  {v} = fneg double {x}")
        return v

    def param(name: str, i: int) -> str:
        layout.append((name, int(i)))
        if literal:  # the double's bits in hex: exact, and LLVM's own notation
            return "0x%016X" % int(flat[name][i:i + 1].view(np.uint64)[0])
        return load("par", len(layout) - 1)

    force = {}
    for e in range(ne):
        if e in spline_part:  # zero stiffness and damping here: the spline's law, below
            continue
        # an element without error: its E and E' are 0, and -0 + x == x for every x, so
        # the sums start at their first product (same result as rhs_slot, fewer loads)
        errs = bool(has_error[e])
        d = neg(load("E", e)) if errs else None
        r = neg(load("ED", e)) if errs else None
        for j in range(vr_ptr[e], vr_ptr[e + 1]):
            c = param("v_coef", j)
            pd = op("fmul", c, load("y", vq_idx[j]))
            pr = op("fmul", c, load("y", n + vq_idx[j]))
            d = pd if d is None else op("fadd", d, pd)
            r = pr if r is None else op("fadd", r, pr)
        if d is None:  # an element without projection entries
            d, r = "0.0", "0.0"
        k = load("K", e)
        c = param("damping", e)
        # the law (laws.spring_force) on this element: its own compiled code, inlined
        gapped = bool(np.any(gap_values[gap_ptr[e]:gap_ptr[e + 1]] > 0.0))
        g = load("G", e) if gapped else "0.0"
        st, fe = new(), new()
        body.append(f"  {st} = call i32 @{law}(ptr %ret, ptr %exc, double {k}, double {c}, "
                    f"double {d}, double {r}, double {g}) #0")
        body.append(f"  {fe} = load double, ptr %ret, align 8")
        # without an additive force table P is 0: f + 0 == f (but for the sign of a zero)
        f = op("fadd", fe, load("P", e)) if has_force[e] else fe
        store("force", e, f)
        store("defl", e, d)
        force[e] = f
    acc_out = {}
    for i in range(n):
        v = load("y", n + i)
        acc = op("fsub", param("external_force", i), op("fmul", param("ground_damping", i), v))
        for j in range(vt_ptr[i], vt_ptr[i + 1]):
            if int(vt_el[j]) in spline_part:  # (its force is added below)
                continue
            acc = op("fsub", acc, op("fmul", param("vt_coef", j), force[int(vt_el[j])]))
        for j in range(gy_ptr[i], gy_ptr[i + 1]):
            acc = op("fsub", acc, op("fmul", param("gy_coef", j), load("y", gy_idx[j])))
        for j in range(fs_ptr[i], fs_ptr[i + 1]):
            acc = op("fsub", acc, op("fmul", param("fs_coef", j), load("y", fs_idx[j])))
        store("dy", i, v)
        acc_out[i] = op("fmul", param("inv_mass", i), acc)
    # splines, as rhs_extra does them after rhs_slot (same sums in the same order): the
    # radial law (laws.spline_force, its own compiled code) on the relative displacement
    # of the two component elements, their forces scattered through V
    for j in range(sp_el.shape[0]):
        comp = []
        for e in sp_el[j]:
            # less the component's error where it has one (a radial bearing's), as
            # rhs_extra: -0 + x == x, so a component without error starts at 0
            errs = bool(has_error[e])
            dd = neg(load("E", e)) if errs else "0.0"
            rr = neg(load("ED", e)) if errs else "0.0"
            for i in range(vr_ptr[e], vr_ptr[e + 1]):
                c = param("v_coef", i)
                dd = op("fadd", dd, op("fmul", c, load("y", vq_idx[i])))
                rr = op("fadd", rr, op("fmul", c, load("y", n + vq_idx[i])))
            comp.append((dd, rr))
        (dx, rx), (dyy, ry) = comp
        pars = ", ".join(f"double {param('sp_par', 6 * j + q)}" for q in range(6))
        st = new()
        body.append(f"  {st} = call i32 @{spline_law}(ptr %ret, ptr %exc, double {dx}, "
                    f"double {dyy}, double {rx}, double {ry}, {pars}, ptr %pair) #0")
        fx, fy = new(), new()
        body.append(f"  {fx} = load double, ptr %pair, align 8")
        p1 = new()
        body.append(f"  {p1} = getelementptr inbounds double, ptr %pair, i64 1")
        body.append(f"  {fy} = load double, ptr {p1}, align 8")
        for e, dd, fe in ((sp_el[j, 0], dx, fx), (sp_el[j, 1], dyy, fy)):
            store("defl", e, dd)
            store("force", e, fe)
        for e, fe in ((sp_el[j, 0], fx), (sp_el[j, 1], fy)):
            for i in range(vr_ptr[e], vr_ptr[e + 1]):
                q = int(vq_idx[i])
                scaled = op("fmul", param("inv_mass", q), op("fmul", param("v_coef", i), fe))
                acc_out[q] = op("fsub", acc_out[q], scaled)
    # tooth friction, as rhs_extra does it after the splines: -M^-1 W_e(s) max(f_e, 0)
    # on the working flank only (laws.positive_part; here max(f_e, 0) by a select, and
    # the product with 0 subtracted where the flank is unloaded: the same value)
    if fr_el.shape[0]:
        sl, off_fr = new(), "%off_fr"
        body.append(f"  {sl} = udiv i64 %off, {max(ne, 1)}")
        body.append(f"  {off_fr} = mul i64 {sl}, {n_fr_rows}")
    for j in range(fr_el.shape[0]):
        f = force[int(fr_el[j])]
        pos, fp = new(), new()
        body.append(f"  {pos} = fcmp ogt double {f}, 0.0")
        body.append(f"  {fp} = select i1 {pos}, double {f}, double 0.0")
        for i in range(fr_ptr[j], fr_ptr[j + 1]):
            q = int(fr_dof[i])
            w_i = op("fmul", op("fmul", param("fr_coef", i), load_friction(int(fr_row[i]))), fp)
            acc_out[q] = op("fsub", acc_out[q], op("fmul", param("inv_mass", q), w_i))
    for i in range(n):
        store("dy", n + i, acc_out[i])
    args = ", ".join(f"ptr noalias nocapture %{x}" for x in ARG_NAMES) + ", i64 %off"
    ir = (f"define internal void @rhs_body({args}) nounwind alwaysinline {{\nentry:\n"
          "  %ret = alloca double, align 8\n  %exc = alloca ptr, align 8\n"
          "  %pair = alloca [2 x double], align 8\n"
          + "\n".join(body) + "\n  ret void\n}\n\n"
          + f"declare i32 @{law}(ptr, ptr, double, double, double, double, double)\n\n"
          + (f"declare i32 @{spline_law}(ptr, ptr, {', '.join(['double'] * 10)}, ptr)\n\n"
             if spline_law else "")
          + _entry_point() + "\nattributes #0 = { alwaysinline }\n")
    return ir, layout


def _entry_point() -> str:
    """``rhs`` taking addresses (i64, see the calling convention above): the kernels pass
    addresses computed once per run (``Work.addr``), not ``array.ctypes`` per call
    (which costs a reference-count increment and decrement, atomic, per array and call:
    more than the arithmetic).  It loads the addresses of the excitation arrays, ``par``
    and FR from the table at ``addr``, casts them all and calls the body, whose noalias
    arguments LLVM keeps when it inlines it."""
    loads = "".join(f"  %a{x} = getelementptr i64, ptr %table, i64 {ADDR_INDEX[x]}\n"
                    f"  %{x} = load i64, ptr %a{x}, align 8\n" for x in ARG_NAMES[len(PASSED):])
    casts = "\n".join(f"  %p{i} = inttoptr i64 %{x} to ptr"
                      for i, x in enumerate(ARG_NAMES))
    args = ", ".join(f"i64 %{x}" for x in ("addr",) + PASSED) + ", i64 %off"
    call = ", ".join(f"ptr %p{i}" for i in range(len(ARG_NAMES))) + ", i64 %off"
    return (f"define void @rhs({args}) nounwind {{\nentry:\n"
            f"  %table = inttoptr i64 %addr to ptr\n{loads}{casts}\n"
            f"  call void @rhs_body({call})\n  ret void\n}}\n")


def _error_and_force_flags(a: dict):
    """Per element: does it own an error (constant or sinusoid), an additive force table."""
    ne = a["vr_ptr"].shape[0] - 1
    has_error = np.zeros(ne, dtype=bool)
    has_error[np.asarray(a["err_el"], dtype=np.int64)] = True
    has_error |= a["error_constant"] != 0.0
    has_force = np.any(a["force_table"] != 0.0, axis=1) if ne else np.zeros(0, dtype=bool)
    return has_error, has_force


_LAST_KEYS = threading.local()
"""Per thread, the keys of the last kernel model asked about (``keys``: weak references
to its arrays, and {"pattern", "value"}): a run asks for them up to six times (cached?
worth it? available?), each digest 0.2-0.5 ms of a Dong et al. 2021 case.  The same
arrays (not only the same tuple: ``_replace`` makes a new tuple of them) give the same
keys, as a kernel model's arrays are not changed in place
(:func:`.kernel_data.kernel_model`); held weakly, so that nothing of a finished run (its
phase tables: 7 MB for Ji & Li's drive) is kept alive."""


def _same_arrays(refs, model) -> bool:
    return len(refs) == len(model) and all(r() is x for r, x in zip(refs, model))


def _last_key(model, kind: str, compute) -> str:
    last = getattr(_LAST_KEYS, "keys", None)
    if last is None or not _same_arrays(last[0], model):
        try:
            refs = tuple(weakref.ref(x) for x in model)
        except TypeError:  # (a field that is not an array: not kept)
            _LAST_KEYS.keys = None
            return compute(model)
        last = _LAST_KEYS.keys = (refs, {})
    if kind not in last[1]:
        last[1][kind] = compute(model)
    return last[1][kind]


def _pattern_key(model) -> str:
    """What the generated code depends on: sparsity of V, V^T and G, which elements have
    a dead zone, an error, an additive force, which are spline components, which meshes
    have tooth friction on which DOFs."""
    return _last_key(model, "pattern", _pattern_digest)


def _pattern_digest(model) -> str:
    a = _arrays(model)
    gp, gv = a["gap_ptr"], a["gap_values"]
    gapped = np.array([np.any(gv[gp[e]:gp[e + 1]] > 0.0) for e in range(gp.shape[0] - 1)])
    has_error, has_force = _error_and_force_flags(a)
    return hash_arrays(hashlib.sha256(), (
        np.int64(a["inv_mass"].shape[0]), a["vr_ptr"], a["vq_idx"], a["vt_ptr"], a["vt_el"],
        a["gy_ptr"], a["gy_idx"], a["fs_ptr"], a["fs_idx"], gapped, has_error, has_force,
        np.asarray(a["sp_el"], dtype=np.int64), a["fr_el"], a["fr_ptr"], a["fr_dof"],
        a["fr_row"], np.int64(a["friction_table"].shape[0]))).hexdigest()


def _value_key(model) -> str:
    """The pattern key and the values of every parameter array (a literal code's key)."""
    return _last_key(model, "value", _value_digest)


def _value_digest(model) -> str:
    a = _arrays(model)
    h = hashlib.sha256(_pattern_key(model).encode())
    for name in PARAMETER_ARRAYS:
        arr = np.ascontiguousarray(a[name], dtype=np.float64)
        h.update(str(arr.shape).encode())
        h.update(arr.tobytes())
    return h.hexdigest()


class _Compiler:
    """One llvmlite MCJIT engine for every generated function, as numba keeps one for its
    own code, and the cache of compiled patterns (thread-safe).

    Every pattern is a module added to the same engine under its own function name; the
    code is never freed (a process compiles few distinct patterns).  An engine per
    pattern sharing one target machine crashed when threads compiled at once.
    """

    def __init__(self):
        self._lock = threading.Lock()
        self._cache: dict[str, tuple] = {}
        self._literal: dict[str, tuple] = {}
        self._demand: dict[str, float] = {}
        """Literal code's key -> the evaluations runs of those values asked for so far
        in this process (:func:`worth_literal`)."""
        self._engine = None
        self._tm = None

    def _setup(self):
        import llvmlite.binding as llvm

        if self._engine is None:
            llvm.initialize_native_target()
            llvm.initialize_native_asmprinter()
            target = llvm.Target.from_default_triple()

            def machine():
                return target.create_target_machine(
                    cpu=llvm.get_host_cpu_name(),
                    features=llvm.get_host_cpu_features().flatten(), opt=2)

            self._tm = machine()  # optimisation passes
            empty = llvm.parse_assembly("")
            empty.triple = target.triple
            self._engine = llvm.create_mcjit_compiler(empty, machine())
        return llvm

    def compile(self, name: str, ir: str) -> int:
        """Add the IR (whose entry point is ``@rhs``) as function ``name``; its address."""
        # LLVM's global context is not thread-safe: hold numba's own compiler lock, so
        # that threads (e.g. Dask workers) never compile at the same time as each other
        # or as numba
        from numba.core.compiler_lock import global_compiler_lock

        ir = ir.replace("@rhs(", f"@{name}(").replace("@rhs_body(", f"@{name}_body(")
        kinds = ("spring", "spline") if "spline_force_scalar" in ir else ("spring",)
        law_irs = [_law_ir(kind)[0] for kind in kinds]  # (the spline law where declared)
        with global_compiler_lock:
            llvm = self._setup()
            mod = llvm.parse_assembly(ir)
            own = {f.name for f in mod.functions if not f.is_declaration}
            for law_ir in law_irs:
                mod.link_in(llvm.parse_assembly(law_ir))
            for sym in list(mod.functions) + list(mod.global_variables):
                # the law's symbols are private to this module (each pattern links its
                # own copy into the one engine): only the entry point is exported
                if not sym.is_declaration and sym.name not in own | {name}:
                    sym.linkage = "internal"
            mod.verify()
            _optimise(llvm, mod, self._tm)
            self._engine.add_module(mod)
            self._engine.finalize_object()
            return self._engine.get_function_address(name)

    def cached(self, model, literal: bool = False) -> bool:
        with self._lock:
            if literal:
                return _value_key(model) in self._literal
            return _pattern_key(model) in self._cache

    def demand(self, model) -> float:
        """The evaluations earlier runs of this model's values made with the pattern's
        code in this process (:func:`note_pattern_run`)."""
        with self._lock:
            return self._demand.get(_value_key(model), 0.0)

    def add_demand(self, model, n_rhs: float) -> None:
        """Count ``n_rhs`` evaluations of this model's values (at most
        :data:`DEMAND_KEYS` sets of values kept, the oldest dropped: a study that varies
        a stiffness has a new set in every case)."""
        key = _value_key(model)
        with self._lock:
            total = self._demand.pop(key, 0.0) + n_rhs
            while len(self._demand) >= DEMAND_KEYS:
                self._demand.pop(next(iter(self._demand)))
            self._demand[key] = total

    def literal_available(self, model) -> bool:
        """Whether this model's literal code is compiled or may still be (at most
        :data:`LITERAL_MAX` a process)."""
        with self._lock:
            return len(self._literal) < LITERAL_MAX or _value_key(model) in self._literal

    def get(self, model, literal: bool = False):
        import time

        key = _value_key(model) if literal else _pattern_key(model)
        cache = self._literal if literal else self._cache
        with self._lock:
            hit = cache.get(key)
        if hit is not None:
            return hit, 0.0
        t0 = time.perf_counter()
        ir, layout = rhs_ir(model, literal)
        with self._lock:  # another thread may have compiled it meanwhile
            hit = cache.get(key)
        if hit is not None:
            return hit, 0.0
        address = self.compile(f"rhs_{'v' if literal else ''}{key[:24]}", ir)
        entry = (address, layout, ir.count("\n"))
        with self._lock:
            cache.setdefault(key, entry)
        return entry, time.perf_counter() - t0


def _optimise(llvm, mod, tm) -> None:
    """O2 with the new pass manager (llvmlite >= 0.44) or the legacy one (older)."""
    if hasattr(llvm, "create_pass_builder"):
        pto = llvm.create_pipeline_tuning_options(speed_level=2)
        pb = llvm.create_pass_builder(tm, pto)
        pb.getModulePassManager().run(mod, pb)
        return
    pmb = llvm.create_pass_manager_builder()
    pmb.opt_level = 2
    pmb.inlining_threshold = 275
    pm = llvm.create_module_pass_manager()
    tm.add_analysis_passes(pm)
    pmb.populate(pm)
    pm.run(mod)


_COMPILER = _Compiler()
_SIGNATURE = None


_FUNCTION_CLASS = None


def _function(address: int):
    """A numba first-class function of the rhs signature at ``address`` (the code lives
    in the compiler's engine for the whole process).  One class serves every address:
    numba types an argument through a dispatch on its class, and a class made per call
    missed that dispatch's cache (4.5 ms of every run)."""
    global _FUNCTION_CLASS, _SIGNATURE
    if _FUNCTION_CLASS is None:
        import numba.experimental.function_type  # noqa: F401 - registers its typeof
        from numba.core.types import WrapperAddressProtocol

        _SIGNATURE = _signature()

        class _Rhs(WrapperAddressProtocol):
            def __init__(self, at: int):
                self._at = at

            def __wrapper_address__(self):
                return self._at

            def signature(self):
                return _SIGNATURE

        _FUNCTION_CLASS = _Rhs
    return _FUNCTION_CLASS(address)


_GENERAL = None


def general_rhs() -> GeneratedRhs:
    """The placeholder that makes the kernels use the general ``rhs_slot``: empty
    parameters and a no-op of the rhs signature that is never called, compiled by numba
    itself (so the general path needs nothing of llvmlite beyond what numba uses)."""
    global _GENERAL
    if _GENERAL is None:
        from numba import cfunc

        _GENERAL = GeneratedRhs(cfunc(_signature(), cache=True)(_noop), np.zeros(0), 0.0, 0)
    return _GENERAL


def _noop(addr, y, dy, force, defl, off):
    """Body of the general placeholder (never called: the kernels test ``gen`` first)."""
    return


def _signature():
    """The numba signature of the calling convention: ``void(uintp addr, y, dy, force,
    defl, int64 off)``."""
    from numba import types

    return types.void(*([types.uintp] * (1 + len(PASSED))), types.int64)


# Cost model of "auto" (measured on the 2-core development machine, benchmarks/RESULTS.md):
# compiling L lines of IR takes about 4e-5 L + 5e-9 L^2 s (0.05 s for Ji & Li's 974 lines,
# 7 s for a 392-DOF model's 35 000), about 30 lines per non-zero of V; each right-hand-side
# call saves about 5 ns per non-zero against the general kernel.
_COMPILE_S_PER_LINE = 4e-5
_COMPILE_S_PER_LINE2 = 5e-9
_LINES_PER_NONZERO = 30.0
_SAVING_S_PER_NONZERO = 5e-9
# ... and of "auto"'s choice of literal code: it compiles in about 0.6 times the pattern's
# time (Dong et al. 2021: 0.09 against 0.15 s) and saves, per call against the pattern's
# code, 0.2-1 ns per non-zero (Ji & Li, Liu et al. 2021: 0.2; Dong et al. 2021: 1, most
# of it in its splines' laws): counted as 0.2 ns per non-zero and 15 ns per spline.
_LITERAL_COMPILE = 0.7
_LITERAL_SAVING_S_PER_NONZERO = 0.2e-9
_LITERAL_SAVING_S_PER_SPLINE = 15e-9


def _literal_max(default: int = 16) -> int:
    """:data:`LITERAL_MAX`: the environment's ``TORQUESPLIT_LITERAL_MAX`` (a count >= 0)
    or ``default``."""
    text = os.environ.get("TORQUESPLIT_LITERAL_MAX", "").strip()
    if not text:
        return default
    try:
        value = int(text)
        if value < 0:
            raise ValueError
    except ValueError:
        import warnings

        warnings.warn(f"TORQUESPLIT_LITERAL_MAX={text!r} is not a count (0, 1, 2, ...): "
                      f"using {default}", RuntimeWarning, stacklevel=2)
        return default
    return value


LITERAL_MAX = _literal_max()
"""Literal codes compiled at most per process (16, or the environment's
``TORQUESPLIT_LITERAL_MAX``; 0: never): MCJIT never frees code (0.9 MiB for Dong et al.
2021's model even after its module is removed), and a study would compile one per case;
beyond it the runs use the pattern's code (same results)."""


def worth_generating(model, n_rhs: float) -> bool:
    """Whether generating the right-hand side of the kernel model arrays ``model`` repays
    its compilation over ``n_rhs`` evaluations (always, when the pattern is cached)."""
    if _COMPILER.cached(model):
        return True
    nnz = float(_arrays(model)["v_coef"].shape[0]) + 1.0
    lines = _LINES_PER_NONZERO * nnz
    compile_s = _COMPILE_S_PER_LINE * lines + _COMPILE_S_PER_LINE2 * lines**2
    return n_rhs * _SAVING_S_PER_NONZERO * nnz > compile_s


DEMAND_KEYS = 1024
"""Sets of model values whose literal-code demand a process remembers
(:meth:`_Compiler.demand`)."""


def worth_literal(model, n_rhs: float) -> bool:
    """Whether code with this model's values as constants (``generated_rhs(model,
    literal=True)``) repays its compilation over ``n_rhs`` evaluations against the
    pattern's code: always when it was compiled before; never once :data:`LITERAL_MAX`
    of them were compiled in this process.  The evaluations earlier runs of the same
    values made with the pattern's code in this process count too
    (:func:`note_pattern_run`): a study's cases that vary only what the code reads at
    every call (errors, their phases) share one literal code, which one case alone may
    not repay (a Monte Carlo of eccentricities on Dong et al. 2021's model with a
    spline friction scale of 2 mm/s, each case just below the break-even, ran every
    case with the pattern's code, 0.7x as fast)."""
    if _COMPILER.cached(model, literal=True):
        return True
    if not _COMPILER.literal_available(model):
        return False
    return n_rhs + _COMPILER.demand(model) > literal_break_even(model)


def literal_break_even(model) -> float:
    """The evaluations over which the literal code of the kernel model arrays ``model``
    saves its compilation time against the pattern's code (an estimate)."""
    a = _arrays(model)
    nnz = float(a["v_coef"].shape[0]) + 1.0
    lines = _LINES_PER_NONZERO * nnz
    compile_s = _LITERAL_COMPILE * (_COMPILE_S_PER_LINE * lines + _COMPILE_S_PER_LINE2 * lines**2)
    saving = _LITERAL_SAVING_S_PER_NONZERO * nnz + _LITERAL_SAVING_S_PER_SPLINE * (
        np.asarray(a["sp_el"]).size // 2)
    return compile_s / saving


def note_pattern_run(model, n_rhs: float) -> None:
    """A run of these model values took the pattern's code where literal code was
    possible: its ``n_rhs`` evaluations count towards the next run's choice
    (:func:`worth_literal`)."""
    _COMPILER.add_demand(model, n_rhs)


def generated_rhs(model, literal: bool = False) -> GeneratedRhs:
    """The compiled right-hand side of the kernel model arrays ``model`` (the tuple
    ``integrate`` passes to the kernels), from the cache when its pattern (with
    ``literal``: its pattern and values) was compiled before in this process.

    ``literal``: the model's values are constants of the code, which LLVM folds where
    that is exact (a coefficient 1 or -1, a constant operand instead of a load): 4-8 %
    of a whole RK4 step of Ji & Li's and Liu et al. 2021's models, 20-25 % of Dong et
    al. 2021's (benchmarks/RESULTS.md), results bit for bit the same.  The code then serves only
    models with these values, and is never freed: at most :data:`LITERAL_MAX` per
    process (about 1 MiB each for a 50-DOF model)."""
    if literal and not _COMPILER.literal_available(model):
        from torquesplit.errors import SolverError

        raise SolverError(f"{LITERAL_MAX} literal right-hand sides were compiled in this "
                           f"process already (codegen.LITERAL_MAX); use literal=False")
    (address, layout, lines), seconds = _COMPILER.get(model, literal)
    a = _arrays(model)
    par = np.array([np.ravel(a[name])[i] for name, i in layout], dtype=np.float64)
    return GeneratedRhs(_function(address), par, seconds, lines, literal)
