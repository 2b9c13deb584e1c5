"""No compiled callee of the kernels is called with a literal integer.

numba types an integer literal argument as ``Literal[int](k)`` and compiles a separate
copy of a callee that is not inlined in numba's IR for each literal value: ``record``
passing the row ``F_MAIN`` while ``record_extrema`` passed an int64 compiled the
statistics callee twice (about 3 s of the first run's cold compile), and the steady
state's ``_var_stage`` was compiled for ``Y_STATE`` and for ``Y_TRIAL`` (about 4 s).
Compiling the kernels in a fresh cache to count their specialisations would cost CI
tens of seconds, so this reads the kernels' source: a call of a compiled callee
(``_kernel``, ``_callee``, a plain ``njit``) must not get an integer constant, a
module-level integer (``Y_STATE``, ``F_MAIN``...) or a local assigned one, directly
or through a parameter that an inlined function forwards to such a callee.
Wrap the value in ``np.int64(...)``.
"""

from __future__ import annotations

import ast
import inspect
import textwrap

import pytest

from torquesplit.gears.contact import _kernels as contact_kernels
from torquesplit.solve import _kernels, laws, static
from torquesplit.steady import _kernels as steady_kernels

MODULES = (laws, _kernels, steady_kernels, static, contact_kernels)


def _njit_kind(call: ast.expr) -> str:
    """'inline' for njit(inline="always", ...), 'compiled' for any other njit(...)."""
    if isinstance(call, ast.Call) and ast.unparse(call.func) == "njit":
        inline = any(k.arg == "inline" and ast.unparse(k.value) == "'always'"
                     for k in call.keywords)
        return "inline" if inline else "compiled"
    return ""


def _kind(fn: ast.FunctionDef, decorators: dict) -> str:
    """'inline' (numba inlines it: literals are harmless), 'compiled' (its own
    specialisations) or '' (plain Python)."""
    for dec in fn.decorator_list:
        kind = _njit_kind(dec) or decorators.get(ast.unparse(dec), "")
        if kind:
            return kind
    return ""


def _functions():
    """{name: (FunctionDef, kind, module)} of every function of the kernel modules."""
    out = {}
    for module in MODULES:
        tree = ast.parse(textwrap.dedent(inspect.getsource(module)))
        decorators = {t.id: _njit_kind(node.value) for node in tree.body
                      if isinstance(node, ast.Assign) for t in node.targets
                      if isinstance(t, ast.Name)}
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                out[node.name] = (node, _kind(node, decorators), module)
    return out


def _is_literal(arg: ast.expr, module, local: frozenset = frozenset()) -> bool:
    """What numba types as ``Literal[int]``: an integer constant (``-1`` too: Python
    folds it), a module-level integer, or a local name assigned one of them
    (``local``: ``kf = Y_KFSAL`` keeps the literal type).  Arithmetic on them is typed
    int64 (checked with numba 0.68: ``k2 = kf + 1`` passed on gives an int64
    specialisation)."""
    if isinstance(arg, ast.Constant):
        return isinstance(arg.value, int) and not isinstance(arg.value, bool)
    if isinstance(arg, ast.UnaryOp) and isinstance(arg.operand, ast.Constant):
        return _is_literal(arg.operand, module, local)
    if isinstance(arg, ast.Name):
        if arg.id in local:
            return True
        value = getattr(module, arg.id, None)
        return isinstance(value, int) and not isinstance(value, bool) and arg.id.isupper()
    return False


def _literal_locals(fn: ast.FunctionDef, module) -> frozenset:
    """Names the function assigns only once, from a literal (``kf = Y_KFSAL``)."""
    assigned: dict[str, list[ast.expr]] = {}
    for node in ast.walk(fn):
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                for name in ast.walk(t):
                    if isinstance(name, ast.Name) and isinstance(name.ctx, ast.Store):
                        value = node.value if isinstance(node, ast.Assign) and t is name \
                            else None
                        assigned.setdefault(name.id, []).append(value)
        elif isinstance(node, (ast.For, ast.comprehension)):
            for name in ast.walk(node.target):
                if isinstance(name, ast.Name) and isinstance(name.ctx, ast.Store):
                    assigned.setdefault(name.id, []).append(None)
    literal: set[str] = set()
    changed = True
    while changed:  # (k = Y_K1 then j = k)
        changed = False
        for name, values in assigned.items():
            if name not in literal and len(values) == 1 and values[0] is not None \
                    and _is_literal(values[0], module, frozenset(literal)):
                literal.add(name)
                changed = True
    return frozenset(literal)


def _callee_name(call: ast.Call) -> str | None:
    f = call.func
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "laws":
        return f.attr
    return None


def _calls(fn: ast.FunctionDef):
    for node in ast.walk(fn):
        if isinstance(node, ast.Call):
            name = _callee_name(node)
            if name is not None:
                yield name, node


def _sensitive(functions) -> dict[str, set[int]]:
    """Per function, the positions of the parameters whose literal value would make numba
    compile a callee twice: every parameter of a compiled function; a parameter of an
    inlined one that it passes on, as it is, to a sensitive position of a callee."""
    sens = {n: set(range(len(fn.args.args))) for n, (fn, kind, _) in functions.items()
            if kind == "compiled"}
    changed = True
    while changed:
        changed = False
        for name, (fn, kind, _) in functions.items():
            if kind != "inline":
                continue
            params = [a.arg for a in fn.args.args]
            mine = sens.setdefault(name, set())
            for callee, call in _calls(fn):
                for pos in sens.get(callee, ()):
                    if pos < len(call.args) and isinstance(call.args[pos], ast.Name) \
                            and call.args[pos].id in params:
                        i = params.index(call.args[pos].id)
                        if i not in mine:
                            mine.add(i)
                            changed = True
    return sens


def literal_arguments() -> list[str]:
    """'module.function: callee(argument)' for every literal at a sensitive position."""
    functions = _functions()
    sens = _sensitive(functions)
    found = []
    for name, (fn, kind, module) in functions.items():
        if not kind:
            continue
        local = _literal_locals(fn, module)
        for callee, call in _calls(fn):
            for pos in sorted(sens.get(callee, ())):
                if pos < len(call.args) and _is_literal(call.args[pos], module, local):
                    found.append(f"{module.__name__}.{name}: {callee}(... "
                                 f"{ast.unparse(call.args[pos])} ...)")
    return found


def test_the_kernel_modules_are_read():
    functions = _functions()
    kinds = {n: k for n, (_, k, _) in functions.items()}
    assert kinds["rk4_run"] == "compiled" and kinds["enter_instant"] == "compiled"
    assert kinds["record"] == "inline" and kinds["_var_stage"] == "compiled"
    assert kinds["spring_force"] == "inline"
    sens = _sensitive(functions)
    # record forwards its row i_f (position 2) to enter_instant through np.int64 only
    assert 2 not in sens["record"]
    assert 0 in sens["_stage"]  # _stage passes its slot on, as it is, to rhs_slot
    assert 1 not in sens["_stage"]  # ... and its rows through np.int64


def test_no_compiled_callee_gets_a_literal_integer():
    found = literal_arguments()
    assert not found, ("numba would compile these callees once per literal value; wrap "
                       "the argument in np.int64(...):\n" + "\n".join(found))


@pytest.mark.parametrize("source, expected", [
    ("def f(x):\n    g(Y_STATE, x)\n", True),
    ("def f(x):\n    g(np.int64(Y_STATE), x)\n", False),
    ("def f(x):\n    g(-1, x)\n", True),
    ("def f(x):\n    g(Y_K1 + 1, x)\n", False),
    ("def f(x):\n    g(x, 0.5)\n", False),
    ("def f(x):\n    k = Y_K1\n    g(k, x)\n", True),
    ("def f(x):\n    k = Y_K1\n    j = k\n    g(j, x)\n", True),
    ("def f(x):\n    k = Y_K1\n    g(k + 1, x)\n", False),
    ("def f(x):\n    k = Y_K1\n    k = x\n    g(k, x)\n", False),
    ("def f(x):\n    k = Y_K1\n    y[k] = x\n    g(k, x)\n", True),
])
def test_literal_detection(source, expected):
    fn = ast.parse(source).body[0]
    call = fn.body[-1].value
    assert _is_literal(call.args[0], _kernels, _literal_locals(fn, _kernels)) is expected
