"""The shipped example gearboxes as model files (package data), most from one paper each.

=================================  =====================================================
name                               system (paper)
=================================  =====================================================
``ji_li_mill_drive``               heavy industrial helical split drive of a grinding
                                   mill, 2 branches, 14 DOF (Ji & Li) -- small and fast:
                                   start here
``mo2017_star_reducer``            two-stage external-mesh star reducer, 3 paths,
                                   floating suns (Mo, Ma, Jin et al. 2017)
``dong2021_face_gear``             face-gear dual-power split helicopter drive with
                                   backlash, support and spline clearances (Dong, Zhang,
                                   Zhao & Duan 2021)
``jin2019_friction_split``         double-input split-torque drive, herringbone stage,
                                   tooth friction (Jin, Yang, Lu & Zhu 2019)
``liu2021_split_torque_helicopter``  two-input two-path split-torque helicopter reducer,
                                   49 DOF (Liu, Fang, Jia et al. 2021)
``lin_parker1999_planetary``       planetary stage, ring fixed, 4 planets: the modal
                                   benchmark of Lin & Parker 1999
``lin_parker1999_star``            the same gears as a star stage (carrier held)
``split_path_planetary_``          two-path split drive recombining in a planetary
``differential``                   differential (sun and ring driven, carrier output)
=================================  =====================================================

``optimize/liu2021_dh_modification`` is an optimisation file (``torquesplit optimize``).

The earlier names (``seed000_split_torque`` ...) still work, with a note:
:func:`example_path` maps them to the current names with a :class:`FutureWarning`
(:data:`RENAMED`).
"""

from __future__ import annotations

import tomllib
import warnings
from importlib import resources
from pathlib import Path

from ..errors import warn_user

#: the earlier names -> the current names (still accepted, with a FutureWarning)
RENAMED = {
    "seed000_split_torque": "liu2021_split_torque_helicopter",
    "seed001_mill_drive": "ji_li_mill_drive",
    "seed002_face_gear": "dong2021_face_gear",
    "seed003_friction_split": "jin2019_friction_split",
    "seed004_star_reducer": "mo2017_star_reducer",
}
#: the same for the shipped optimisation files (``examples/optimize``)
RENAMED_OPTIMIZATIONS = {"seed000_dh_modification": "liu2021_dh_modification"}

#: the example to start with: small (14 DOF) and a run takes seconds
FIRST_EXAMPLE = "ji_li_mill_drive"


def example_names() -> list[str]:
    """Names of the shipped example models.

    Examples
    --------
    >>> "ji_li_mill_drive" in example_names()
    True
    """
    files = resources.files(__name__)
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def current_name(name: str, renamed: dict[str, str] | None = None) -> tuple[str, str | None]:
    """``(current name, note)`` of an example name: an earlier name (``seed001_mill_drive``)
    gives its current name and a note saying so (None for a current name).

    Examples
    --------
    >>> current_name("seed001_mill_drive")[0]
    'ji_li_mill_drive'
    >>> current_name("ji_li_mill_drive")
    ('ji_li_mill_drive', None)
    """
    renamed = RENAMED if renamed is None else renamed
    stem = name.removesuffix(".toml")
    if stem in renamed:
        new = renamed[stem]
        return new, (f"the example name {stem!r} is deprecated and will be removed; use "
                     f"{new!r}")
    return stem, None


def example_path(name: str) -> Path:
    """Path of a shipped example model file.

    An earlier name (:data:`RENAMED`: ``seed000_split_torque`` ...) still works: it gives
    the renamed file, with a :class:`FutureWarning`.

    Raises
    ------
    NoSuchExampleError
        No example of that name (the message lists them); a torquesplit error and a
        ``FileNotFoundError``.
    """
    from ..errors import NoSuchExampleError

    stem, note = current_name(name)
    if note:
        warn_user(note, FutureWarning)
    path = Path(str(resources.files(__name__) / f"{stem}.toml"))
    if not path.exists():
        raise NoSuchExampleError(
            f"no example named {name!r}; use one of {', '.join(example_names())}")
    return path


def optimization_names() -> list[str]:
    """Names of the shipped optimisation files (``torquesplit optimize NAME``)."""
    folder = resources.files(__name__) / "optimize"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def optimization_path(name: str) -> Path | None:
    """Path of a shipped optimisation file (``examples/optimize``), or None."""
    stem, note = current_name(name, RENAMED_OPTIMIZATIONS)
    path = Path(str(resources.files(__name__) / "optimize" / f"{stem}.toml"))
    if not path.exists():
        return None
    if note:
        warn_user(note, FutureWarning)
    return path


def example_info(name: str) -> dict:
    """The [model] section (name, description, reference) of an example."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        data = tomllib.loads(example_path(name).read_text(encoding="utf-8"))
    return data.get("model", {})
