"""Planet load sharing: the mesh-load factor K_gamma of each planetary stage.

The planetary gear standards rate the unequal sharing of a stage's planets by the
mesh-load factor K_gamma = the load of the most heavily loaded planet over the mean
planet load (AGMA 6123-B06 §5; ISO 6336-1 K_gamma).  It is the load-sharing coefficient
of :mod:`torquesplit.metrics.load_sharing` restricted to the planet meshes: a planet's
sun meshes form one load-sharing group, its ring meshes another (the stage labels of
``[[planetary]]``, ``<name>-sun`` and ``<name>-ring``, or the tooth-count labels of
general elements), and each group's coefficient is max_i N X_i / sum_j X_j = largest
over mean.  Every definition gives a planet coefficient; the standards' K_gamma, a
ratio of mean loads, is the ``mean_force`` one (dynamic) or the position-averaged one
(quasi-static):

* quasi-static (``static_torque``, with pin position errors, carrier eccentricity and
  floating members): K_gamma from each planet's load averaged over the mesh positions of
  the sweep -- the mean load per planet over the mean of all, as the standards define it
  (AGMA 6123-B06 §5, ISO 6336-1) -- and, apart, the peak of the instantaneous ratio over
  the positions (Mo et al. 2017 eqs. 14-15 generalised to planets), which is not
  K_gamma: with sequentially phased planets it exceeds 1 (1.0915 for a 25/29/83 spur
  stage) although every planet carries the same mean load (studies:
  ``planet_peak_instantaneous_ratio[.<carrier>|.<planet>]``);
* dynamic: ``mean_force`` gives K_gamma from the mean forces of the settled run; the
  peak-based ``cycle_peak``, ``instantaneous`` and ``engineering`` give the same ratio of
  peak forces, a planet load-sharing coefficient that contains the dynamics (not
  K_gamma: do not multiply it by a dynamic factor).

The coefficient of a stage is the largest over its sun and ring groups; per planet the
largest coefficient of its meshes.  Names for studies: ``planet_load_sharing.<def>``
(the largest stage), ``.<carrier>`` and ``.<planet>``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

__all__ = ["PlanetLoadSharing", "planet_load_sharing"]


@dataclass(frozen=True)
class PlanetLoadSharing:
    """K_gamma per planetary stage (carrier) and per planet, for one definition."""

    definition: str
    per_stage: dict[str, float]
    """Carrier -> K_gamma (largest planet load over the mean)."""
    per_planet: dict[str, float]
    """Planet -> the largest load-sharing coefficient of its meshes."""
    groups: dict[str, list[str]]
    """Carrier -> the load-sharing groups of its planet meshes."""
    peak_per_stage: dict[str, float] = field(default_factory=dict)
    """Quasi-static only: carrier -> the peak of the instantaneous ratio over the mesh
    positions (Mo et al. 2017), not K_gamma."""
    peak_per_planet: dict[str, float] = field(default_factory=dict)
    """Quasi-static only: planet -> the peak instantaneous ratio of its meshes."""

    def values(self) -> dict[str, float]:
        key = f"planet_load_sharing.{self.definition}"
        out = {key: max(self.per_stage.values())} if self.per_stage else {}
        out.update({f"{key}.{c}": v for c, v in self.per_stage.items()})
        out.update({f"{key}.{p}": v for p, v in self.per_planet.items()})
        if self.peak_per_stage:  # quasi-static: the peak ratio beside K_gamma
            out["planet_peak_instantaneous_ratio"] = max(self.peak_per_stage.values())
            for who, v in (*self.peak_per_stage.items(), *self.peak_per_planet.items()):
                out[f"planet_peak_instantaneous_ratio.{who}"] = v
        return out


def planet_load_sharing(load_sharing, kinematics) -> PlanetLoadSharing:
    """K_gamma of every planetary stage from a :class:`~torquesplit.metrics.load_sharing.
    LoadSharing` (any definition) and the model's kinematics.

    Examples
    --------
    >>> import torquesplit
    >>> from torquesplit.quasistatic import quasi_static_load_sharing
    >>> qs = quasi_static_load_sharing(torquesplit.example_path("lin_parker1999_planetary"),
    ...                                revolutions=0.05)
    >>> k = planet_load_sharing(qs.metrics(), qs.kinematics)
    >>> round(k.per_stage["stage_carrier"], 9)
    1.0
    """
    ls = load_sharing
    position_mean = getattr(ls, "position_mean", None)
    if position_mean:
        # quasi-static: K_gamma from the loads averaged over the positions, the peak of
        # the instantaneous ratio apart
        mean = replace(ls, per_mesh=dict(position_mean), per_group={
            g: max(position_mean[m] for m in ms) for g, ms in ls.groups.items()},
            position_mean={})
        k = planet_load_sharing(mean, kinematics)
        peak = planet_load_sharing(replace(ls, position_mean={}), kinematics)
        return replace(k, peak_per_stage=peak.per_stage, peak_per_planet=peak.per_planet)
    per_stage: dict[str, float] = {}
    per_planet: dict[str, float] = {}
    groups: dict[str, list[str]] = {}
    group_of = {m: g for g, ms in ls.groups.items() for m in ms}
    for carrier in kinematics.carriers:
        planet_meshes = {n: mk for n, mk in kinematics.meshes.items()
                         if mk.carrier == carrier and n in group_of}
        gs = sorted({group_of[n] for n in planet_meshes})
        if not gs:
            continue
        groups[carrier] = gs
        per_stage[carrier] = max(ls.per_group[g] for g in gs)
        # one factor per planet shaft, named after its body on the pin: a compound
        # planet's gears (one rigid group) count together
        pins = kinematics.carriers.get(carrier, ())
        for planet, c in kinematics.planet_bodies.items():
            if c != carrier:
                continue
            name = next((q for q in pins if kinematics.groups[q] == kinematics.groups[planet]),
                        planet)
            mine = [ls.per_mesh[n] for n, mk in planet_meshes.items()
                    if planet in (mk.driver, mk.driven)]
            if mine:
                per_planet[name] = max(mine + ([per_planet[name]] if name in per_planet
                                               else []))
    return PlanetLoadSharing(ls.definition, per_stage, per_planet, groups)
