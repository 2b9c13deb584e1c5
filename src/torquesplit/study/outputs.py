"""Study outputs: every metric of a run as a flat ``{name: float}`` dict.

:func:`output_values` is the ONE place where the study layer reads metrics: it takes a
dynamic :class:`~torquesplit.results.Results` through ``Results.metric_values()`` (the
core's flat names, :meth:`torquesplit.results.Metrics.values`) or a
:class:`~torquesplit.quasistatic.QuasiStaticResults` through its ``metrics()`` and
``mesh_forces()``.  Figures, tables and the store consume these numbers; none
recomputes a metric.

Names (``<group>`` is a load-sharing group key of
:func:`torquesplit.metrics.load_sharing.group_meshes`, ``<mesh>`` a mesh name):

==========================================  ==============================================
name                                        value
==========================================  ==============================================
``load_sharing.<definition>``               system load-sharing coefficient
``load_sharing.<definition>.<group|mesh>``  per group / per mesh; definitions
                                            ``cycle_peak``, ``instantaneous``,
                                            ``engineering``, ``mean_force`` (dynamic),
                                            ``static_torque`` (quasi-static)
``dynamic_factor[.<group|mesh>]``           settled peak force / the mesh's own static
                                            force (system: largest group)
``dynamic_factor_engineering.<mesh>``       mean settled cycle peak / own static force
``peak_to_nominal[.<group|mesh>]``          settled peak / equal-split nominal force
``peak_to_nominal_engineering.<group>``     Ji & Li eq. 19 G_it: mean over settled cycles
                                            of the group's largest peak / nominal force
``peak_force.<mesh>``, ``min_force.<mesh>``,
``mean_force.<mesh>``                       settled peak, trough, mean force [N]
``static_force.<mesh>``                     static-equilibrium force [N]
``nominal_force.<mesh>``                    equal-split nominal force [N]
``contact_loss.<mesh>``                     fraction of the run with the teeth apart
``back_contact.<mesh>``                     fraction of the run in back-flank contact
``back_flank_force.<mesh>``                 largest back-flank (tensile) force [N]
``settle_time``                             start of the settled part of the run [s]
``bearing_mean_force.<body>``               magnitude of the settled mean bearing force
                                            of a supported body [N] (the run's bearing
                                            table, :meth:`Results.bearing_forces`)
``bearing_peak_force.<body>``               largest settled bearing force magnitude [N]
                                            (streamed at every step, as the run's
                                            bearing table's)
==========================================  ==============================================

Quasi-static results give ``load_sharing.static_torque[.<group|mesh>]`` and
``peak_force``/``min_force``/``mean_force.<mesh>`` over the mesh positions.
``dynamic_factor_engineering.<group>`` is not defined by the core (a group's engineering
factor is ``peak_to_nominal_engineering.<group>``, Ji & Li's G_it).
"""

from __future__ import annotations

import fnmatch
import math

from ..errors import OptionError

#: load-sharing definitions of dynamic runs, in the order they are reported
DYNAMIC_DEFINITIONS = ("cycle_peak", "instantaneous", "engineering", "mean_force")
STATIC_DEFINITION = "static_torque"

#: output families (name head) -> (unit, long name)
FAMILIES: dict[str, tuple[str, str]] = {
    "load_sharing": ("1", "load-sharing coefficient"),
    "planet_load_sharing": ("1", "planet load-sharing factor (largest planet over the mean)"),
    "planet_peak_instantaneous_ratio": ("1", "largest instantaneous planet load ratio over "
                                            "the mesh positions (Mo et al. 2017), not "
                                            "K_gamma"),
    "dynamic_factor": ("1", "dynamic load factor (peak / own static force)"),
    "dynamic_factor_engineering": ("1", "engineering dynamic factor (mean cycle peak / own "
                                        "static force)"),
    "peak_to_nominal": ("1", "peak force / equal-split nominal force"),
    "peak_to_nominal_engineering": ("1", "engineering dynamic load coefficient (mean cycle "
                                         "peak / nominal force)"),
    "peak_force": ("N", "peak mesh force"),
    "min_force": ("N", "smallest mesh force"),
    "mean_force": ("N", "mean mesh force"),
    "static_force": ("N", "static mesh force"),
    "nominal_force": ("N", "nominal (equal-split) mesh force"),
    "contact_loss": ("1", "fraction of time with contact lost"),
    "back_contact": ("1", "fraction of time in back-flank contact"),
    "back_flank_force": ("N", "largest back-flank (tensile) force"),
    "settle_time": ("s", "start of the settled part of the run"),
    "bearing_mean_force": ("N", "settled mean bearing force (magnitude)"),
    "bearing_peak_force": ("N", "largest settled bearing force (magnitude, streamed at "
                                "every step)"),
}

#: output families read from the history (the means from its samples, the peaks from the
#: streams written with it): a run without one (the GPU backend's) cannot give them
HISTORY_FAMILIES = ("bearing_mean_force", "bearing_peak_force")

#: outputs that change with the run length by nature (the settled part starts later in a
#: longer run): the settle rule does not wait for them to stop changing
NOT_CONVERGING = frozenset({"settle_time"})

# ============================================================================ values
def output_values(result, definitions=None, *, bearings: bool = True) -> dict[str, float]:
    """Every study output of one finished run, by name (see the module docstring).

    Parameters
    ----------
    result : Results or QuasiStaticResults
        A dynamic run (:func:`torquesplit.simulate`) or a quasi-static sweep
        (:func:`torquesplit.quasistatic.quasi_static_load_sharing`).
    definitions : iterable of str, optional
        Load-sharing definitions to evaluate for a dynamic run (default: all four).
        Other names do not depend on the definition.
    bearings : bool, optional
        Include the bearing forces of a dynamic run (``HISTORY_FAMILIES``, from its
        history).  A study that asks for none leaves them out (Dong et al. 2021's model
        at its validation settings: all outputs 16.6 ms, without the bearings 3.7 ms).

    Returns
    -------
    dict of str to float
        SI values (forces in N, times in s); NaN where a metric is undefined.

    Examples
    --------
    >>> import torquesplit
    >>> from torquesplit.study.outputs import output_values
    >>> res = torquesplit.simulate(torquesplit.example_path("ji_li_mill_drive"), cycles=20)
    >>> v = output_values(res, ["engineering"])
    >>> 1.0 <= v["load_sharing.engineering"] < 2.0
    True
    """
    if _is_quasi_static(result):
        return _quasi_static_values(result)
    defs = list(DYNAMIC_DEFINITIONS if definitions is None else definitions)
    unknown = [d for d in defs if d not in DYNAMIC_DEFINITIONS]
    if unknown:
        raise OptionError(f"unknown load-sharing definition(s) {unknown} for a dynamic run; "
                         f"use {', '.join(DYNAMIC_DEFINITIONS)}")
    # no load sharing asked for: one (cheap) definition still gives the other metrics
    out = {k: float(v) for k, v in result.metric_values(defs or ["cycle_peak"]).items()}
    if result.success and bearings:
        for b in result.bearing_forces():  # the run's bearing table
            out[f"bearing_mean_force.{b['body']}"] = float(b["mean_magnitude"])
            out[f"bearing_peak_force.{b['body']}"] = float(b["peak_magnitude"])
    return out


def _quasi_static_values(result) -> dict[str, float]:
    from ..metrics.planetary import planet_load_sharing

    out: dict[str, float] = {}
    lsc = result.metrics()
    _put_load_sharing(out, STATIC_DEFINITION, lsc)
    out.update(planet_load_sharing(lsc, result.kinematics).values())  # K_gamma (planets)
    forces = result.mesh_forces()
    for j, m in enumerate(result.mesh_names):
        f = forces[:, j]
        out[f"peak_force.{m}"] = float(f.max())
        out[f"min_force.{m}"] = float(f.min())
        out[f"mean_force.{m}"] = float(f.mean())
    return out


def _put_load_sharing(out: dict, definition: str, lsc) -> None:
    out[f"load_sharing.{definition}"] = _f(lsc.system)
    for g, v in lsc.per_group.items():
        out[f"load_sharing.{definition}.{g}"] = _f(v)
    for m, v in lsc.per_mesh.items():
        out[f"load_sharing.{definition}.{m}"] = _f(v)


def _is_quasi_static(result) -> bool:
    return hasattr(result, "orbits") and not hasattr(result, "statistics")


def _f(x) -> float:
    return float(x) if x is not None else math.nan


# ========================================================================= catalogue
def available_outputs(mesh_names, groups: dict[str, list[str]], analysis: str,
                      planets: dict[str, list[str]] | None = None,
                      bearings=()) -> list[str]:
    """Every output name a run of this model gives (``analysis``: "run" or "static").

    ``groups`` are the load-sharing groups (key -> meshes); ``planets`` the planetary
    stages (carrier -> planets), whose mesh-load factor K_gamma is
    ``planet_load_sharing.<definition>[.<carrier>|.<planet>]``
    (:mod:`torquesplit.metrics.planetary`); ``bearings`` the supported bodies
    (:func:`torquesplit.results.bearing_bodies`).  Used to check a study's requested
    names before any case runs.
    """
    names: list[str] = []
    defs = (STATIC_DEFINITION,) if analysis == "static" else DYNAMIC_DEFINITIONS
    for d in defs:
        names.append(f"load_sharing.{d}")
        names += [f"load_sharing.{d}.{g}" for g in groups]
        names += [f"load_sharing.{d}.{m}" for m in mesh_names]
        if planets:
            names.append(f"planet_load_sharing.{d}")
            for carrier, members in planets.items():
                names += [f"planet_load_sharing.{d}.{x}" for x in (carrier, *members)]
    if analysis == "static":
        if planets:
            names.append("planet_peak_instantaneous_ratio")
            for carrier, members in planets.items():
                names += [f"planet_peak_instantaneous_ratio.{x}" for x in (carrier, *members)]
        for fam in ("peak_force", "min_force", "mean_force"):
            names += [f"{fam}.{m}" for m in mesh_names]
        return names
    names += ["dynamic_factor", "peak_to_nominal"]
    names += [f"dynamic_factor.{x}" for x in (*groups, *mesh_names)]
    names += [f"dynamic_factor_engineering.{m}" for m in mesh_names]
    names += [f"peak_to_nominal.{x}" for x in (*groups, *mesh_names)]
    names += [f"peak_to_nominal_engineering.{g}" for g in groups]
    for fam in ("peak_force", "min_force", "mean_force", "static_force", "nominal_force",
                "contact_loss", "back_contact", "back_flank_force"):
        names += [f"{fam}.{m}" for m in mesh_names]
    names.append("settle_time")
    for fam in HISTORY_FAMILIES:
        names += [f"{fam}.{b}" for b in bearings]
    return names


def select_outputs(patterns, available: list[str]) -> tuple[list[str], list[str]]:
    """Names matching the patterns (``fnmatch``: ``*``, ``?``, ``[..]``), in the order of
    the patterns then of ``available``; and the patterns that match nothing."""
    chosen: list[str] = []
    unmatched: list[str] = []
    for p in patterns:
        hits = [n for n in available if fnmatch.fnmatchcase(n, p)]
        if not hits:
            unmatched.append(p)
        for n in hits:
            if n not in chosen:
                chosen.append(n)
    return chosen, unmatched


def definitions_needed(names) -> list[str]:
    """The dynamic load-sharing definitions that the output ``names`` need."""
    need = []
    for d in DYNAMIC_DEFINITIONS:
        heads = (f"load_sharing.{d}", f"planet_load_sharing.{d}")
        if any(n in heads or n.startswith(tuple(h + "." for h in heads)) for n in names):
            need.append(d)
    return need


def family(name: str) -> tuple[str, str]:
    """Split an output name into (family, member): ``("load_sharing.engineering",
    "stage1")``, ``("planet_load_sharing.mean_force", "planet2")``, ``("peak_force",
    "m11")``, ``("dynamic_factor", "system")``."""
    parts = name.split(".")
    if parts[0] in ("load_sharing", "planet_load_sharing"):
        head = ".".join(parts[:2])
        rest = ".".join(parts[2:])
    else:
        head = parts[0]
        rest = ".".join(parts[1:])
    return head, rest or "system"


def output_unit(name: str) -> str:
    """SI unit of an output ("1" for coefficients)."""
    return FAMILIES.get(name.split(".")[0], ("1", ""))[0]


def output_definitions(names) -> list[str]:
    """What each family of the outputs ``names`` measures, one line per family in the
    order met (a study's summary table names its columns only): the load-sharing
    definitions in their own words, the others as their long names say."""
    from ..metrics.load_sharing import DEFINITION_TEXT

    seen: dict[str, str] = {}
    for n in names:
        parts = n.split(".")
        sharing = parts[0] in ("load_sharing", "planet_load_sharing") and len(parts) > 1
        head = ".".join(parts[:2]) if sharing else parts[0]
        if head in seen:
            continue
        if sharing and parts[1] in DEFINITION_TEXT:
            seen[head] = DEFINITION_TEXT[parts[1]]
            if parts[0] == "planet_load_sharing":
                # (static: K_gamma from the loads averaged over the positions, not the peak
                # ratio the definition's own text describes: a planetary reviewer)
                seen[head] = (
                    "mesh load factor K_gamma of each planetary stage: the largest planet's "
                    "load over the mean, from the quasi-static loads averaged over the mesh "
                    "positions (ISO 6336-1, AGMA 6123)" if parts[1] == STATIC_DEFINITION
                    else f"mesh load factor of each planetary stage, the largest planet over "
                         f"the mean, by the {parts[1]} definition: {seen[head]}") + (
                    "; .<planet>: that planet's own load over the mean")
        elif head in FAMILIES:
            seen[head] = FAMILIES[head][1]
    return [f"{head}: {text}" for head, text in seen.items()]


def output_long_name(name: str) -> str:
    """A readable description of an output, e.g. "load-sharing coefficient (engineering),
    stage1"."""
    parts = name.split(".")
    unit_text = FAMILIES.get(parts[0], ("1", parts[0]))[1]
    _, member = family(name)
    if parts[0] in ("load_sharing", "planet_load_sharing") and len(parts) > 1:
        unit_text += f" ({parts[1]})"
    return unit_text + ("" if member == "system" else f", {member}")
