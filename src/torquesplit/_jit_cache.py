"""numba's on-disk cache of the package's kernels, stamped with every source they read.

numba stamps a cached function with a hash of its own file only.  A kernel in
``solve/_kernels.py`` inlines the element laws of ``solve/laws.py`` and freezes the
constants of ``solve/kernel_data.py``: after either changes (an editable install being
worked on, a package upgraded in place) numba would load the old machine code, and the
run would silently use the old law.  :func:`track_imports` puts in front of numba's
source-file locators a copy of each whose stamp also covers the package modules that
the cached function's file imports, transitively (read from its import statements).
Functions outside the package keep numba's own locators.

It uses numba's locator list (``numba.core.caching.CacheImpl._locator_classes``; in
older numba ``_CacheImpl``, ``_InTreeCacheLocator``...), a private name; where a numba
version lacks it, the package's kernels keep numba's own stamp and
``tests/solve/test_jit_cache.py`` fails, so that such a version is noticed.
"""

from __future__ import annotations

import functools
import hashlib
import re
from pathlib import Path

__all__ = ["dependencies", "track_imports"]

_PACKAGE = Path(__file__).resolve().parent
_ROOT = _PACKAGE.parent


def _module_file(name: str) -> Path | None:
    """The package file of module ``name`` (``torquesplit.solve.laws``), or None."""
    parts = name.split(".")
    if parts[0] != _PACKAGE.name:
        return None
    base = _ROOT.joinpath(*parts)
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _module_name(path: Path) -> str:
    parts = path.relative_to(_ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


#: top-level import statements (indented ones, inside functions or conditions, are
#: not read by compiled code); group 1 the module of a ``from`` import, 2 its names,
#: 3 the modules of a plain ``import``
_IMPORT = re.compile(r"^(?:from[ \t]+([.\w]+)[ \t]+import[ \t]+(\([^)]*\)|.*)|import[ \t]+(.*))",
                     re.MULTILINE)
_COMMENT = re.compile(r"#[^\n]*")


def _names(text: str) -> list[str]:
    """``(a as b, c)`` -> ["a", "c"]"""
    return [part.split()[0] for part in text.strip("()").split(",") if part.strip()]


@functools.lru_cache(maxsize=None)
def _imports(path: Path) -> frozenset[Path]:
    """Package files imported at the top level of ``path`` (``from a.b import c`` is the
    file of ``a.b.c`` where that is a module, else of ``a.b``)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[Path | None] = set()
    for module, names, plain in _IMPORT.findall(_COMMENT.sub("", path.read_text(encoding="utf-8"))):
        if plain:
            found.update(_module_file(m) for m in _names(plain))
            continue
        dots = len(module) - len(module.lstrip("."))
        if dots:
            parts = package.split(".")
            module = ".".join(parts[: len(parts) - dots + 1] + [module[dots:]]).rstrip(".")
        for alias in _names(names):
            found.add(_module_file(f"{module}.{alias}") or _module_file(module))
    found.discard(None)
    return frozenset(found)


@functools.lru_cache(maxsize=None)
def dependencies(py_file: str) -> tuple[Path, ...]:
    """Every package file that ``py_file`` imports, directly or through another, sorted
    (``py_file`` itself excluded)."""
    start = Path(py_file).resolve()
    seen, todo = {start}, [start]
    while todo:
        for path in _imports(todo.pop()) - seen:
            seen.add(path)
            todo.append(path)
    return tuple(sorted(seen - {start}))


@functools.lru_cache(maxsize=None)
def _digest(py_file: str) -> str:
    """Hash of the names and contents of ``py_file``'s dependencies (once per process:
    numba asks for every function of a file)."""
    digest = hashlib.sha256()
    for path in dependencies(py_file):
        digest.update(str(path.relative_to(_ROOT)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _in_package(py_file: str) -> bool:
    try:
        Path(py_file).resolve().relative_to(_PACKAGE)
    except (OSError, ValueError):
        return False
    return True


@functools.lru_cache(maxsize=1)
def track_imports() -> bool:
    """Stamp the package's cached kernels with their imports too (once per process;
    call before the first ``@njit(cache=True)`` of a module).  False where numba's
    locator list is not where this expects it."""
    from numba.core import caching

    def numba_class(name):  # public in recent numba, with a leading _ in older
        return getattr(caching, name, None) or getattr(caching, f"_{name}", None)

    standard = getattr(numba_class("CacheImpl"), "_locator_classes", None)
    bases = [numba_class(f"{kind}CacheLocator") for kind in ("UserProvided", "InTree", "UserWide")]
    if not isinstance(standard, list) or None in bases:
        return False

    def tracking(locator: type) -> type:
        class Tracking(locator):
            @classmethod
            def from_function(cls, py_func, py_file):
                return super().from_function(py_func, py_file) if _in_package(py_file) \
                    else None

            def get_source_stamp(self):
                return super().get_source_stamp(), _digest(self._py_file)

        Tracking.__name__ = Tracking.__qualname__ = f"ImportTracking{locator.__name__}"
        return Tracking

    mine = [tracking(cls) for cls in bases]
    standard[:0] = mine
    return True
