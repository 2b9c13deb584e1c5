"""numba's on-disk cache of the kernels follows the element laws they inline.

numba stamps a cached function with its own file only; :mod:`torquesplit._jit_cache`
adds the package files it imports.  Without it, a kernel cached before ``laws.py``
changed keeps running the old law.
"""

from __future__ import annotations

import importlib
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import pytest

import torquesplit
from torquesplit import _jit_cache

PACKAGE = Path(torquesplit.__file__).parent


def _cached_modules():
    """Every package module that declares a cached numba function (outside docstrings)."""
    for path in sorted(PACKAGE.rglob("*.py")):
        if "cache=True)" in path.read_text() and path.name != "__init__.py":
            yield ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)


def test_every_cached_kernel_of_the_package_is_stamped_with_its_imports():
    checked = 0
    for name in _cached_modules():
        module = importlib.import_module(name)
        for obj in vars(module).values():
            cache = getattr(obj, "_cache", None)
            locator = getattr(getattr(cache, "_impl", None), "locator", None)
            if locator is None or getattr(obj, "__module__", name) != name:
                continue
            assert type(locator).__name__.startswith("ImportTracking"), (name, obj)
            checked += 1
    assert checked >= 20


def _dependencies(module):
    return {p.relative_to(PACKAGE).as_posix() for p in _jit_cache.dependencies(module.__file__)}


def test_the_kernels_dependencies_are_read_from_their_imports():
    from torquesplit.solve import _kernels, codegen
    from torquesplit.steady import _kernels as steady_kernels

    kernels = _dependencies(_kernels)
    assert {"solve/laws.py", "solve/kernel_data.py", "assembly/structure.py"} <= kernels
    assert "solve/_kernels.py" not in kernels and "cli.py" not in kernels
    # relative imports (from . import laws, from .._memo import ...)
    assert {"solve/laws.py", "solve/kernel_data.py", "_memo.py"} <= _dependencies(codegen)
    # through another module: steady kernels -> solve/_kernels -> laws
    assert {"solve/_kernels.py", "solve/laws.py"} <= _dependencies(steady_kernels)


def test_functions_outside_the_package_keep_numbas_locators(tmp_path):
    assert _jit_cache.track_imports()
    source = tmp_path / "outside.py"
    source.write_text("def f():\n    return 1\n")
    spec = importlib.util.spec_from_file_location("outside", source)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    locator = numba.njit(cache=True)(module.f)._cache._impl.locator
    assert not type(locator).__name__.startswith("ImportTracking")


_LAW = "from numba import njit\n\n\n@njit(inline='always')\ndef law(x):\n    return {} * x\n"
_KERNEL = textwrap.dedent("""
    from numba import njit

    from torquesplit._jit_cache import track_imports
    from torquesplit.laws import law

    track_imports()


    @njit(cache=True)
    def kernel(x):
        return law(x)
""")
_RUN = ("from torquesplit.kernel import kernel; print(kernel(1.0), "
        "kernel.stats.cache_hits.get(kernel.signatures[0], 0))")


@pytest.mark.skipif(sys.platform == "win32", reason="in-tree numba cache folder semantics")
def test_a_changed_law_recompiles_the_kernel_that_inlines_it(tmp_path):
    """A copy of the mechanism in a throwaway package: cache, change the law, rerun."""
    package = tmp_path / "torquesplit"
    package.mkdir()
    (package / "__init__.py").write_text("")
    shutil.copy(_jit_cache.__file__, package / "_jit_cache.py")
    (package / "kernel.py").write_text(_KERNEL)
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env["PYTHONPATH"] = str(tmp_path)

    def run(factor):
        (package / "laws.py").write_text(_LAW.format(factor))
        out = subprocess.run([sys.executable, "-c", _RUN], cwd=tmp_path, env=env,
                             capture_output=True, text=True, check=True).stdout.split()
        return float(out[0]), int(out[1])

    assert run(1.0) == (1.0, 0)    # compiled and cached
    assert run(1.0) == (1.0, 1)    # loaded from the cache
    assert run(2.0) == (2.0, 0)    # the law changed: compiled again, not the stale code


def test_older_numba_names_are_found_and_a_missing_list_is_reported(monkeypatch):
    """numba before its public names: _CacheImpl, _InTreeCacheLocator, ..."""
    import types

    from numba import core
    from numba.core import caching

    class OldImpl:
        _locator_classes = ["numba's own"]

    old = types.SimpleNamespace(_CacheImpl=OldImpl, **{
        f"_{kind}CacheLocator": getattr(caching, f"{kind}CacheLocator")
        for kind in ("UserProvided", "InTree", "UserWide")})
    monkeypatch.setattr(core, "caching", old)
    assert _jit_cache.track_imports.__wrapped__()
    assert [c.__name__ for c in OldImpl._locator_classes[:3]] == [
        "ImportTrackingUserProvidedCacheLocator", "ImportTrackingInTreeCacheLocator",
        "ImportTrackingUserWideCacheLocator"]
    assert OldImpl._locator_classes[3:] == ["numba's own"]
    monkeypatch.setattr(core, "caching", types.SimpleNamespace(_CacheImpl=OldImpl))
    assert not _jit_cache.track_imports.__wrapped__()
