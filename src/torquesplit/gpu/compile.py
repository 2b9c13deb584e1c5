"""Compile a generated ensemble kernel for the CPU (numba) or for CUDA (numba.cuda).

The source of :mod:`torquesplit.gpu.source` is executed in a fresh namespace; each of
its functions is then replaced by its compiled form, ``numba.njit`` for the CPU or a
``numba.cuda.jit`` device function for CUDA, and they find each other (and the laws of
:mod:`torquesplit.solve.laws`) by global name when numba compiles them.  A short driver
is added per target: for the CPU a loop over the cases in one compiled function
(:func:`cpu_driver`), for CUDA a kernel with one case per thread whose scratch arrays are
thread-local (``cuda.local.array``, indexed by constants: registers).

For CUDA the laws are bound as CUDA device functions compiled from the laws' own Python
(numba-cuda's documented way for one device function to call another); where that
binding does not compile, the kernel is compiled again with the laws as plain numba
functions (numba compiles a ``@jit`` function called from a kernel for the CUDA target),
and the binding used is reported.  The CUDA kernel is compiled eagerly, for the one
signature the ensemble launches, so that compile time is never counted as kernel time.

Compiled kernels are kept per process by the hash of their source (a study that runs
batch after batch of one pattern compiles once).  Under ``NUMBA_ENABLE_CUDASIM=1`` the
CUDA path runs in numba's simulator (the tests without a GPU).
"""

from __future__ import annotations

import hashlib
import math
import threading
import types

import numpy as np

from torquesplit.solve import laws

from .source import KernelSource

__all__ = ["cpu_driver", "cuda_kernel", "cuda_available", "cuda_simulated", "ptx",
           "kernel_signature"]

_LOCK = threading.Lock()
_CACHE: dict[tuple, object] = {}

_CPU_DRIVER = """
def run_all(n_cases, P, PT, PI, Y0, TK, TF, TFR, GS, CN, OF, OI):
    W = np.empty({n_w}, DT)
    X = np.empty({n_x})
    WI = np.empty({n_wi}, np.int64)
    for c in range(n_cases):
        run_case(c, P, PT, PI, Y0, TK, TF, TFR, GS, CN, OF, OI, W, X, WI)
    return 0
"""

_CUDA_KERNEL = """
def kernel(n_cases, P, PT, PI, Y0, TK, TF, TFR, GS, CN, OF, OI):
    c = cuda.grid(1)
    if c < n_cases:
        W = cuda.local.array({n_w}, DT_NB)
        X = cuda.local.array({n_x}, float64)
        WI = cuda.local.array({n_wi}, int64)
        run_case(c, P, PT, PI, Y0, TK, TF, TFR, GS, CN, OF, OI, W, X, WI)
"""


#: the element laws the generated code calls (by these names)
LAWS = ("spring_force", "spline_force", "positive_part", "table_phase", "lerp", "stat_cycle",
        "contact_shares")
_LAW_DISPATCHERS: dict = {}


def law_functions() -> dict:
    """The laws of :mod:`torquesplit.solve.laws` as the generated code calls them: each
    law's own Python function compiled by numba as an ordinary (not IR-inlined)
    function, with the laws' flags.  ``inline="always"`` (how the engine's kernels take
    them) would re-type a law at each of its hundreds of call sites in straight-line
    code (minutes of compilation); as a callee it is typed once per signature, and LLVM
    (NVVM on a GPU) still inlines it.  The arithmetic is the same instructions."""
    from numba import njit

    with _LOCK:
        if not _LAW_DISPATCHERS:
            for name in LAWS:
                _LAW_DISPATCHERS[name] = njit(error_model="numpy")(
                    getattr(laws, name).py_func)
        return dict(_LAW_DISPATCHERS)


#: the scalar laws, among them those that the laws of :data:`LAWS` call
SCALAR_LAWS = ("dead_zone", "spring_force", "spline_radial", "spline_force",
               "spline_tangent", "positive_part", "table_phase", "lerp", "stat_cycle",
               "negative_share", "may_cross", "contact_shares")
_CUDA_LAWS: dict = {}


def cuda_law_functions() -> dict:
    """The laws as CUDA device functions: each law's own Python function, bound in a copy
    of the laws module's globals in which the laws it calls are device functions too (so
    the arithmetic is the laws' own, and no CPU dispatcher is called from a kernel)."""
    from numba import cuda

    with _LOCK:
        if not _CUDA_LAWS:
            scope = dict(vars(laws))
            for name in SCALAR_LAWS:
                f = getattr(laws, name).py_func
                scope[name] = cuda.jit(device=True)(types.FunctionType(
                    f.__code__, scope, name, f.__defaults__, f.__closure__))
            _CUDA_LAWS.update({name: scope[name] for name in LAWS})
        return dict(_CUDA_LAWS)


def _namespace(src: KernelSource, literal_calls: bool = False) -> dict:
    import numba

    fp32 = src.precision == "fp32"
    const = (lambda k: k) if literal_calls else np.int64
    ns = {"math": math, "np": np, **law_functions(),
          "DT": np.float32 if fp32 else np.float64,
          "DT_NB": numba.float32 if fp32 else numba.float64,
          "float64": numba.float64, "int64": numba.int64, "IM1": const(-1),
          **{f"I{k}": const(k) for k in src.call_constants}}
    exec(compile(src.text, f"<torquesplit.gpu kernel {_digest(src)[:12]}>", "exec"), ns)
    return ns


def _digest(src: KernelSource) -> str:
    return hashlib.sha256((src.precision + src.text).encode()).hexdigest()


def _functions(ns: dict) -> list[str]:
    """Names of the generated functions (every ``def`` of the source)."""
    import types as _t

    return [k for k, v in ns.items() if isinstance(v, _t.FunctionType)
            and v.__code__.co_filename.startswith("<torquesplit.gpu kernel")]


def _cuda_namespace(src: KernelSource, binding: str = "device") -> dict:
    """The kernel's namespace for CUDA; ``binding``: the laws as CUDA device functions
    (``"device"``) or as plain numba functions (``"njit"``)."""
    from numba import cuda

    ns = _namespace(src, literal_calls=True)
    if binding == "device":
        ns.update(cuda_law_functions())
    ns["cuda"] = cuda
    for name in _functions(ns):
        ns[name] = cuda.jit(device=True)(ns[name])
    exec(_CUDA_KERNEL.format(n_w=src.n_w, n_x=src.n_x, n_wi=src.n_wi), ns)
    return ns


def cpu_driver(src: KernelSource, contract: bool = False):
    """The generated code compiled with numba for the CPU: ``run_all(n_cases, P, PT, PI,
    Y0, TK, TF, TFR, GS, CN, OF, OI)`` runs every case in turn (the reference the CUDA
    kernel is tested against; not a fast path).  ``contract``: multiply-adds fused, as a
    GPU compiles them (the laws too): how far rounding of the GPU's kind moves a run."""
    from numba import njit

    key = ("cpu", _digest(src), contract)
    with _LOCK:
        hit = _CACHE.get(key)
    if hit is not None:
        return hit
    ns = _namespace(src)
    flags = {"error_model": "numpy"} | ({"fastmath": {"contract"}} if contract else {})
    if contract:
        for name in LAWS:
            ns[name] = njit(**flags)(getattr(laws, name).py_func)
    # the generated functions are called from run_all only: without numba's Python and
    # C entry points, which cost compile time (as the engine's inner kernels)
    inner = njit(**flags, no_cpython_wrapper=True, no_cfunc_wrapper=True)
    for name in _functions(ns):
        ns[name] = inner(ns[name])
    exec(_CPU_DRIVER.format(n_w=src.n_w, n_x=src.n_x, n_wi=src.n_wi), ns)
    fn = njit(**flags)(ns["run_all"])
    with _LOCK:
        _CACHE.setdefault(key, fn)
    return fn


#: how the laws were bound in the last CUDA kernel compiled, and why not the first way
LAST_BINDING: dict = {}


def kernel_signature(precision: str) -> tuple:
    """The numba types of the kernel's arguments (``P`` in the working precision)."""
    from numba import float32, float64, int64

    dt = float64 if precision == "fp64" else float32
    return (int64, dt[:, ::1], float64[:, ::1], int64[:, ::1], float64[:, ::1],
            float64[:, :, ::1], float64[:, :, ::1], float64[:, :, ::1], float64[:, ::1],
            int64[::1], float64[:, ::1], int64[:, ::1])


def cuda_kernel(src: KernelSource, bindings: tuple[str, ...] = ("device", "njit")):
    """The generated code as a CUDA kernel ``kernel[blocks, threads](n_cases, P, PT, PI,
    Y0, TK, TF, TFR, GS, CN, OF, OI)``: one case per thread, compiled here for its one
    signature (numba's simulator under ``NUMBA_ENABLE_CUDASIM=1``).  The law bindings
    are tried in turn (see the module's docstring); where none compiles eagerly, the
    first is left to compile at the first launch (which then raises numba's error)."""
    from numba import cuda

    key = ("cuda", _digest(src), cuda_simulated(), tuple(bindings))
    with _LOCK:
        hit = _CACHE.get(key)
    if hit is not None:
        LAST_BINDING.update(hit[1])
        return hit[0]
    sig = kernel_signature(src.precision)
    failed = []
    for binding in bindings:
        ns = _cuda_namespace(src, binding)
        try:
            kern = cuda.jit(sig)(ns["kernel"])
        except Exception as exc:  # noqa: BLE001 - a binding this numba-cuda cannot type
            failed.append(f"{binding}: {type(exc).__name__}: {str(exc)[:300]}")
            continue
        break
    else:  # no eager compile worked: numba compiles at the first launch (or says why)
        binding = f"{bindings[0]} (compiled at launch)"
        kern = cuda.jit(_cuda_namespace(src, bindings[0])["kernel"])
    info = {"binding": binding, "failed": failed}
    LAST_BINDING.update(info)
    with _LOCK:
        _CACHE.setdefault(key, (kern, info))
    return kern


def ptx(src: KernelSource, cc: tuple[int, int] = (9, 0), binding: str = "njit") -> str:
    """PTX of the CUDA kernel for compute capability ``cc``, compiled without a device
    (needs NVIDIA's libNVVM, e.g. a CUDA toolkit, which numba finds itself or through
    ``CUDA_HOME``): a check that the laws and the generated code compile for the GPU.

    ``binding="device"``: the kernel exactly as :func:`cuda_kernel` compiles it first
    (generated functions and laws as CUDA device functions); ``"njit"``: its fallback
    (plain numba functions, which numba compiles for the CUDA target when a kernel calls
    them).  numba asks the current device for its compute capability, so a stand-in
    answering ``cc`` is put in its place for the call."""
    from types import SimpleNamespace
    from unittest import mock

    from numba import cuda, njit

    if binding == "device":
        ns = _cuda_namespace(src, "device")
    else:
        ns = _namespace(src, literal_calls=True)
        ns["cuda"] = cuda
        for name in _functions(ns):
            ns[name] = njit(ns[name])
        exec(_CUDA_KERNEL.format(n_w=src.n_w, n_x=src.n_x, n_wi=src.n_wi), ns)
    sig = kernel_signature(src.precision)
    stand_in = SimpleNamespace(compute_capability=tuple(cc))
    with mock.patch("numba.cuda.dispatcher.get_current_device", lambda: stand_in):
        text, _ = cuda.compile_ptx(ns["kernel"], sig, cc=cc)
    return text


def cuda_simulated() -> bool:
    """Whether numba runs CUDA code in its simulator (``NUMBA_ENABLE_CUDASIM=1``)."""
    from numba import config

    return bool(config.ENABLE_CUDASIM)


_PROBE: dict = {}


def _probe_compile() -> str:
    """Compile and run a one-line kernel once per process: an empty string when it works,
    else why not.  A driver can see the device while numba-cuda cannot compile (seen on
    an H200 machine: numba-cuda 0.30.4 with numpy 2.5 fails in its typing registry on
    ``np.row_stack``), and a study should then fall back with that reason, not stop."""
    if "why" not in _PROBE:
        try:
            from numba import cuda

            @cuda.jit("void(float64[::1])")
            def _twice(a):  # pragma: no cover - runs on the device
                i = cuda.grid(1)
                if i < a.shape[0]:
                    a[i] = 2.0 * a[i]

            d = cuda.to_device(np.ones(4))
            _twice[1, 4](d)
            ok = bool(np.all(d.copy_to_host() == 2.0))
            _PROBE["why"] = "" if ok else "a test kernel gave wrong results"
        except Exception as exc:  # noqa: BLE001 - any failure of the CUDA tool chain
            _PROBE["why"] = (f"numba-cuda cannot compile a kernel here ({type(exc).__name__}: "
                             f"{str(exc)[:200]}; numpy {np.__version__}): install a "
                             "numba-cuda that supports this numpy, or an older numpy")
    return _PROBE["why"]


def cuda_available() -> tuple[bool, str]:
    """Whether a CUDA device (or numba's simulator) can run the kernels, and if not why
    (the device is opened and a one-line kernel compiled and run, once per process)."""
    try:
        from numba import cuda
    except Exception as exc:  # noqa: BLE001 - a broken CUDA installation
        return False, f"numba.cuda cannot be imported ({type(exc).__name__}: {exc})"
    if cuda_simulated():
        return True, "numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1)"
    try:
        ok = cuda.is_available()
    except Exception as exc:  # noqa: BLE001 - driver errors
        return False, f"the CUDA driver failed ({type(exc).__name__}: {exc})"
    if not ok:
        return False, "no CUDA device or driver found"
    try:
        dev = cuda.get_current_device()
        name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
    except Exception as exc:  # noqa: BLE001
        return False, f"the CUDA device cannot be opened ({type(exc).__name__}: {exc})"
    why = _probe_compile()
    if why:
        return False, f"{name}: {why}"
    return True, name
