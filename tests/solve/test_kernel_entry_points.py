"""Kernels compiled without a Python entry point are called from compiled code only.

The kernels that only other kernels call (``_inner`` and ``_callee`` in
``solve/_kernels.py``, ``_var_stage`` in ``steady/_kernels.py``) are compiled with
``no_cpython_wrapper=True``: the Python entry point unboxes the kernels' bundles and
cost more compile time than most of these functions' bodies (the first RK4 run's
compilation went from about 20 s to about 13 s).  Called from Python, such a function
crashes the interpreter (a segmentation fault, not an exception), so this reads every
Python file of the project and fails on a call of one of them outside a compiled
function.
"""

from __future__ import annotations

import ast
import inspect
import textwrap
from pathlib import Path

from torquesplit.solve import _kernels
from torquesplit.steady import _kernels as steady_kernels

ROOT = Path(__file__).resolve().parents[2]
KERNEL_MODULES = (_kernels, steady_kernels)


def _njit_options(node: ast.expr) -> dict | None:
    """The keyword options of ``njit(...)`` (``{}`` for a bare ``njit``), else None."""
    if isinstance(node, ast.Call) and ast.unparse(node.func) in ("njit", "numba.njit"):
        return {k.arg: ast.unparse(k.value) for k in node.keywords}
    if ast.unparse(node) in ("njit", "numba.njit"):
        return {}
    return None


def _decorators(tree: ast.Module) -> dict:
    """Module-level aliases of njit (``_kernel = njit(...)``): name -> its options."""
    out = {}
    for node in tree.body:
        if isinstance(node, ast.Assign):
            opts = _njit_options(node.value)
            if opts is not None:
                out.update({t.id: opts for t in node.targets if isinstance(t, ast.Name)})
    return out


def _options(fn: ast.FunctionDef, aliases: dict) -> dict | None:
    """numba options of a function's decorator, None for a Python function."""
    for dec in fn.decorator_list:
        opts = _njit_options(dec)
        if opts is None:
            opts = aliases.get(ast.unparse(dec))
        if opts is not None:
            return opts
    return None


def entry_less() -> set[str]:
    """Names of the kernel modules' functions compiled without a Python entry point."""
    names = set()
    for module in KERNEL_MODULES:
        tree = ast.parse(textwrap.dedent(inspect.getsource(module)))
        aliases = _decorators(tree)
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                opts = _options(node, aliases)
                if opts is not None and opts.get("no_cpython_wrapper") == "True":
                    names.add(node.name)
    return names


def python_calls(source: str, names: set[str]) -> list[str]:
    """Calls of ``names`` made by Python code in ``source`` (not inside a compiled
    function): a bare name imported from a ``_kernels`` module, or an attribute
    (``kern.excite(...)``) in a file that imports one."""
    tree = ast.parse(source)
    aliases = _decorators(tree)
    imported, uses_kernels = set(), False
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if (node.module or "").endswith("_kernels"):
                uses_kernels = True
                imported.update(a.asname or a.name for a in node.names)
            if any(a.name == "_kernels" for a in node.names):
                uses_kernels = True
        elif isinstance(node, ast.Import) and any(a.name.endswith("_kernels")
                                                  for a in node.names):
            uses_kernels = True
    found = []

    def visit(node, compiled: bool) -> None:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            compiled = compiled or _options(node, aliases) is not None
        if isinstance(node, ast.Call) and not compiled:
            f = node.func
            if isinstance(f, ast.Name) and f.id in names and f.id in imported:
                found.append(f"line {node.lineno}: {ast.unparse(node)[:60]}")
            elif isinstance(f, ast.Attribute) and f.attr in names and uses_kernels:
                found.append(f"line {node.lineno}: {ast.unparse(node)[:60]}")
        for child in ast.iter_child_nodes(node):
            visit(child, compiled)

    visit(tree, False)
    return found


def test_the_entry_less_kernels_are_found_and_compiled_so():
    names = entry_less()
    # what the compile-time change made entry-less (the scan below depends on finding them)
    assert {"excite", "enter_instant", "copy_slot", "rk4_through_corners", "hermite",
            "_var_stage"} <= names
    for module in KERNEL_MODULES:
        for name in names & set(vars(module)):
            assert getattr(module, name).targetoptions.get("no_cpython_wrapper") is True, name
    # and the kernels Python calls keep their entry point
    for name in ("rk4_run", "dopri_run", "evaluate"):
        assert not getattr(_kernels, name).targetoptions.get("no_cpython_wrapper"), name
    assert not steady_kernels.rk4_variational.targetoptions.get("no_cpython_wrapper")


def test_no_python_code_calls_an_entry_less_kernel():
    names = entry_less()
    bad = {}
    for folder in ("src", "tests", "benchmarks", "scripts"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            calls = python_calls(path.read_text(encoding="utf-8"), names)
            if calls:
                bad[str(path.relative_to(ROOT))] = calls
    assert not bad, ("called from Python, a kernel without a Python entry point crashes "
                     f"the interpreter; call it from a compiled kernel: {bad}")


def test_the_scan_catches_a_python_call_and_allows_a_compiled_one():
    names = {"excite"}
    direct = ("from torquesplit.solve._kernels import excite\n"
              "def f(m, w):\n    excite(0.0, 0, -1, m, w)\n")
    assert python_calls(direct, names)
    through_module = ("from torquesplit.solve import _kernels as kern\n"
                      "kern.excite(0.0, 0, -1, None, None)\n")
    assert python_calls(through_module, names)
    compiled = ("from numba import njit\n"
                "from torquesplit.solve._kernels import excite\n"
                "_kernel = njit(cache=True)\n"
                "@_kernel\ndef f(m, w):\n    excite(0.0, 0, -1, m, w)\n"
                "@njit(cache=True)\ndef g(m, w):\n    excite(0.0, 0, -1, m, w)\n")
    assert python_calls(compiled, names) == []
    # a function of the same name that is not the kernel (a transcription's own)
    own = "def excite(t):\n    return t\nexcite(1.0)\n"
    assert python_calls(own, names) == []
