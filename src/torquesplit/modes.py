"""Model-level modal analysis: every mode, its multiplicity, type and shape.

:func:`model_modes` linearises a model about its static equilibrium
(:func:`torquesplit.solve.modal.modal_analysis`) and groups and labels the modes the way
an epicyclic analyst reads them (Lin & Parker 1999; Cooley & Parker 2012 with a turning
carrier):

* **multiplicity** -- modes whose frequencies agree to ``rtol`` form one group (the
  degenerate pairs of the translational modes, the N - 3 planet modes);
* **type** (models with planets) -- from the share of the mass-weighted motion
  ``m_i |phi_i|^2`` (summed over the group, so it does not depend on the basis the
  eigensolver picked) on the DOFs of the stage's members that are not planets
  ("central": carriers and the gears that mesh with a planet), within the stage's own
  motion: ``rotational`` when the central members do not translate, ``translational``
  when they do not rotate, ``planet`` when they do not move at all, ``mixed`` otherwise
  (each below ``tol``); ``other`` when no member of a stage moves (a mode of the rest of
  the model: a split path's pinion on its bearing).  The labels follow this rule, not
  Lin & Parker's counts: when no central member translates (sun, ring and carrier
  ``dofs = ["theta"]``), the degenerate pair of each translational type loses its central
  motion and is labelled ``planet``; with equally spaced planets it falls at the planet
  modes' frequency, so the planet groups have multiplicity N - 1 (2 for three planets,
  which have no Lin & Parker planet modes; docs/theory/planetary.md);
* **whirl** (turning carrier) -- each translational mode's whirl in the carrier's frame,
  forward or backward against its rotation (:func:`whirl_senses`), which selects the mesh
  harmonics that excite it (:meth:`PhasedStage.excites`);
* **strain energy per element of a group** -- the sum over the group's mass-normalised
  modes of each element's strain energy over the group's total: the trace of the
  element's stiffness over the group's subspace, the same in any basis of a degenerate
  pair (the per-mode shares of :class:`~torquesplit.solve.modal.ModalSolution` depend on
  the basis the solver happened to return).

Rigid-body modes are counted and left out, as in ``modal_analysis``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import OptionError
from .solve.modal import DEGENERATE_RTOL

__all__ = ["ModeRow", "ModalReport", "classify", "model_modes", "MODE_TYPES",
           "PhasedStage", "phased_stages", "phasing_suppresses", "whirl_senses"]

MODE_TYPES = ("rotational", "translational", "planet", "mixed", "other")

#: shape units of a mass-normalised mode: phi^H M phi = 1 with M in kg on translations
#: and kg m^2 on rotations, so the modal coordinate is in m kg^(1/2) (sqrt(kg m^2))
SHAPE_UNITS = "kg-1/2 (translations), rad m-1 kg-1/2 (rotations)"
NORMALISATION = ("phi^H M phi = 1, M in kg (translations) and kg m^2 (rotations): a shape "
                 "times a modal coordinate in m kg^(1/2) gives m or rad")
#: strain-energy shares listed per group in --json and the table's summaries
STRAIN_ENERGY_LISTED = 6


def shape_unit(dof: str) -> str:
    """Unit of a mass-normalised shape on ``dof`` (:data:`SHAPE_UNITS`)."""
    return "rad m-1 kg-1/2" if dof.endswith(".theta") else "kg-1/2"


DAMPING_RATIO_DEFINITION = (
    "modal (proportional-damping) approximation zeta = phi^H C phi / (2 omega) of the "
    "mass-normalised undamped mode, 2 omega + Im(phi^H G phi) in a turning carrier's frame "
    "(G: Coriolis terms), the coupling of modes through C ignored; mean over the "
    "degenerate group; C: the damping of the elements in contact at the static "
    "equilibrium and of speed-dependent loads")


SUPPORT_AXES = ("x", "y", "z", "loa")
"""Component suffixes of a support's elements (``BODY.support.x``, ...)."""


@dataclass(frozen=True)
class ModeRow:
    """One natural mode, with the properties of its degenerate group."""

    mode: int
    """1-based index in ascending frequency."""
    frequency: float
    """Natural frequency [Hz] (negative: statically unstable)."""
    group: int
    """1-based index of its group of equal frequencies."""
    multiplicity: int
    """Number of modes in the group."""
    type: str | None
    """rotational, translational, planet, mixed or other (None for a model without
    planets)."""
    strain_energy: dict[str, float]
    """Element -> share of the group's strain energy (basis-independent), largest first."""
    motion: dict[str, float] = field(default_factory=dict)
    """Share of the group's mass-weighted motion: central rotation, central translation,
    planets."""
    damping_ratio: float = float("nan")
    """Modal damping ratio: :data:`DAMPING_RATIO_DEFINITION`."""
    whirl: str | None = None
    """``forward`` or ``backward``: the sense of the central members' whirl in the
    turning carrier's frame against the carrier's rotation (a translational mode of a
    turning carrier; None otherwise, and for a degenerate pair: :func:`whirl_senses`)."""

    def largest_shares(self, n: int = 3) -> list[tuple[str, float]]:
        """The ``n`` largest strain-energy shares with a support's components taken
        together (``BODY.support`` for ``BODY.support.x`` + ``.y`` + ...): a planet's
        bearing on its pin showed as ``support.x`` in one planet and ``support.y`` in the
        next for one rotational mode (the carrier frame's axes, not the planet's), and a
        degenerate pair's split between x and y depends on the solver's basis; their sum
        does not.  Every component stays in :attr:`strain_energy`."""
        merged: dict[str, float] = {}
        for name, v in self.strain_energy.items():
            base, dot, comp = name.rpartition(".")
            key = base if dot and base.endswith(".support") and comp in SUPPORT_AXES else name
            merged[key] = merged.get(key, 0.0) + v
        return sorted(merged.items(), key=lambda kv: -kv[1])[:n]

    @property
    def damped_frequency(self) -> float:
        """f sqrt(1 - zeta^2) [Hz] (0 when zeta >= 1, nan for an unstable mode)."""
        if not self.frequency > 0:
            return float("nan")
        return self.frequency * float(np.sqrt(max(0.0, 1.0 - self.damping_ratio**2)))


@dataclass(frozen=True)
class ModalReport:
    """Modes of a model, grouped (degenerate groups) and, for a model with a planetary
    stage, classified (rotational, translational, planet: Lin & Parker 1999)."""

    solution: object
    """The :class:`~torquesplit.solve.modal.ModalSolution`."""
    rows: list[ModeRow]
    rigid_modes: int
    dof_names: tuple[str, ...]
    rotating_frame: bool
    """True if the modes include the carrier-frame Coriolis and centripetal terms."""
    model: object = field(default=None, repr=False)
    """The :class:`~torquesplit.model.schema.Model` (a saved file names and holds it)."""

    def __repr__(self) -> str:
        f = [r.frequency for r in self.rows]
        span = f", {f[0]:.5g}..{f[-1]:.5g} Hz" if f else ""
        return (f"ModalReport({len(self.rows)} modes{span}, {self.rigid_modes} rigid-body, "
                f"{len(self.dof_names)} DOFs{', turning frame' if self.rotating_frame else ''})")

    def shape(self, mode: int) -> dict[str, complex]:
        """Mass-normalised shape of ``mode`` (1-based) by DOF name."""
        n = self.solution.mode_shapes.shape[1]
        if not (isinstance(mode, (int, np.integer)) and 1 <= mode <= n):
            raise OptionError(f"mode must be a whole number 1..{n} (1-based, ascending "
                              f"frequency), got {mode!r}")
        phi = self.solution.mode_shapes[:, mode - 1]
        return {n: complex(v) for n, v in zip(self.dof_names, phi)}

    def to_dict(self, shapes: bool = True) -> dict:
        """JSON-serialisable summary (shapes as real numbers, or [re, im] pairs for the
        complex modes of a rotating frame), with a ``units`` entry; ``motion`` and ``whirl``
        only for a model with planets (they describe a planetary stage)."""
        out = []
        truncated = False
        for r in self.rows:
            truncated |= len(r.strain_energy) > STRAIN_ENERGY_LISTED
            d = dict(mode=r.mode, frequency_Hz=r.frequency,
                     damping_ratio=_finite(r.damping_ratio),
                     damped_frequency_Hz=_finite(r.damped_frequency), group=r.group,
                     multiplicity=r.multiplicity, type=r.type,
                     strain_energy=dict(list(r.strain_energy.items())[:STRAIN_ENERGY_LISTED]))
            if r.type is not None:
                d.update(motion=r.motion, whirl=r.whirl)
            if shapes:
                sh = self.solution.mode_shapes[:, r.mode - 1]
                if np.iscomplexobj(sh):
                    d["shape"] = {n: [float(v.real), float(v.imag)]
                                  for n, v in zip(self.dof_names, sh)}
                else:
                    d["shape"] = {n: float(v) for n, v in zip(self.dof_names, sh)}
            out.append(d)
        units = dict(frequency_Hz="Hz", damped_frequency_Hz="Hz", damping_ratio="1",
                     strain_energy="1 (share of the group's strain energy)",
                     shape=SHAPE_UNITS, normalisation=NORMALISATION)
        if truncated:
            units["strain_energy"] += (f"; the {STRAIN_ENERGY_LISTED} largest shares of each "
                                       f"group (--out keeps every element's)")
        return dict(rigid_body_modes=self.rigid_modes, rotating_frame=self.rotating_frame,
                    damping_ratio=DAMPING_RATIO_DEFINITION, units=units, modes=out)

    def save(self, path, *, overwrite: bool = False):
        """Save :meth:`to_dataset` by suffix (``.nc``, ``.mat``, ``.csv``: a table per mode
        and per DOF), as ``torquesplit modes --out`` does; atomically, an existing file
        kept unless ``overwrite``.  Returns the path written."""
        from .results.export import save_dataset, with_model

        ds = self.to_dataset()
        if self.model is not None:  # (an API save named no model: an exports reviewer)
            ds = with_model(ds, self.model)
        return save_dataset(ds, path, overwrite=overwrite)

    def to_dataset(self):
        """The modes as an xarray Dataset (frequencies, multiplicity, type, group
        strain-energy shares, shapes: real and imaginary parts)."""
        import xarray as xr

        sol = self.solution
        mode = [r.mode for r in self.rows]
        phi = np.asarray(sol.mode_shapes)[:, [m - 1 for m in mode]]  # the kept modes
        elements = list(sol.element_names)
        energy = np.array([[r.strain_energy.get(e, 0.0) for e in elements]
                           for r in self.rows]).reshape(len(self.rows), len(elements))
        return xr.Dataset(
            {"frequency": (("mode",), [r.frequency for r in self.rows],
                           {"units": "Hz", "long_name": "natural frequency"}),
             "damping_ratio": (("mode",), [r.damping_ratio for r in self.rows],
                               {"units": "1", "long_name": "modal damping ratio",
                                "comment": DAMPING_RATIO_DEFINITION}),
             "damped_frequency": (("mode",), [r.damped_frequency for r in self.rows],
                                  {"units": "Hz", "long_name": "damped natural frequency "
                                   "f sqrt(1 - zeta^2) of the damping-ratio estimate"}),
             "multiplicity": (("mode",), [r.multiplicity for r in self.rows],
                              {"units": "1", "long_name": "modes of equal frequency"}),
             "group": (("mode",), [r.group for r in self.rows],
                       {"units": "1", "long_name": "group of equal frequencies"}),
             "type": (("mode",), [r.type or "" for r in self.rows],
                      {"long_name": "mode type of a planetary stage (rotational, translational, "
                                   "planet, mixed, other); empty for a model without one"}),
             "whirl": (("mode",), [r.whirl or "" for r in self.rows],
                       {"long_name": "whirl of a translational mode of a turning carrier "
                        "in its frame against its rotation (forward, backward); empty "
                        "otherwise"}),
             "strain_energy": (("mode", "element"), energy,
                               {"units": "1", "long_name": "share of the group's strain "
                                "energy (basis-independent)"}),
             "shape_real": (("dof", "mode"), np.real(phi),
                            {"units": SHAPE_UNITS, "normalisation": NORMALISATION,
                             "long_name": "mass-normalised mode shape, real part"}),
             "shape_imag": (("dof", "mode"), np.imag(phi) if np.iscomplexobj(phi)
                            else np.zeros_like(phi),
                            {"units": SHAPE_UNITS, "normalisation": NORMALISATION,
                             "long_name": "mass-normalised mode shape, imaginary part"})},
            coords={"mode": mode, "dof": list(self.dof_names), "element": elements,
                    "shape_unit": ("dof", [shape_unit(n) for n in self.dof_names],
                                   {"long_name": "unit of the shape on this DOF"})},
            attrs={"rigid_body_modes": self.rigid_modes,
                   "rotating_frame": int(self.rotating_frame)})


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _groups(freqs: np.ndarray, rtol: float) -> list[list[int]]:
    groups: list[list[int]] = []
    for i, f in enumerate(freqs):
        if groups and abs(f - freqs[groups[-1][0]]) <= rtol * max(abs(f), 1e-300):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


#: |sum m Im(U x conj U) . axis| / sum m |U|^2 above which a mode whirls (1: circular
#: orbits; 0: straight lines, the real modes of a degenerate pair)
WHIRL_CIRCULARITY = 0.5


def whirl_senses(structure, sol, kin) -> dict[int, int]:
    """0-based mode -> +1 (-1) when the central members (not planets) whirl in (against)
    the sense of the turning carrier's rotation in its frame, from the complex shape:
    the whirl orbit's angular momentum ``sum m Im(U x conj U)`` along the carrier's axis
    (``q = Re(phi e^(i omega t))``), U the member's complex translation.  0 for a mode
    whose orbits are not circular enough (:data:`WHIRL_CIRCULARITY`: the real shapes of
    a degenerate pair of a carrier at rest, or a model without a rotating frame); {} for
    a model without exactly one turning carrier."""
    carriers = getattr(kin, "carriers", {})
    if len(carriers) != 1:
        return {}
    (carrier, planets), = carriers.items()
    w_c = kin.bodies[carrier].speed
    phi = np.asarray(sol.mode_shapes)
    if w_c == 0 or not np.iscomplexobj(phi) or not phi.size:
        return {}
    axis = np.asarray(kin.bodies[carrier].axis, float)
    names = list(structure.dof_names)
    mass = 1.0 / np.asarray(structure.inv_mass)
    L = np.zeros(phi.shape[1])
    total = np.zeros(phi.shape[1])
    for b in kin.bodies:
        if b in planets or kin.frames.get(b) != carrier:
            continue
        rows = [names.index(f"{b}.{c}") if f"{b}.{c}" in names else -1 for c in "xyz"]
        if sum(r >= 0 for r in rows) < 2:
            continue
        U = np.array([phi[r] if r >= 0 else np.zeros(phi.shape[1]) for r in rows])
        m = mass[next(r for r in rows if r >= 0)]
        L += m * np.imag(np.cross(U, U.conj(), axis=0).T @ axis)
        total += m * np.real(np.sum(U * U.conj(), axis=0))
    ratio = np.divide(L, total, out=np.zeros_like(L), where=total > 0)
    sense = np.where(ratio > WHIRL_CIRCULARITY, 1, np.where(ratio < -WHIRL_CIRCULARITY, -1, 0))
    return {k: int(v) * int(np.sign(w_c)) for k, v in enumerate(sense)}


def classify(structure, sol, *, rtol: float = DEGENERATE_RTOL, tol: float = 1e-6,
             kin=None) -> list[ModeRow]:
    """Group and label the modes of ``sol`` (a ModalSolution of ``structure``).

    ``planet``: the central members (not planets) carry less than ``tol`` of the group's
    mass-weighted motion.  With central members that cannot translate this includes Lin &
    Parker's translational-type pairs (net force, no net torque of the planets on a centre
    that cannot translate): with equally spaced planets they fall at the planet modes'
    frequency, so such a model lists planet groups of multiplicity N - 1, not N - 3 (2
    for N = 3, which has no planet modes of Lin & Parker's kind).  Not a relabelling: the
    central members do not move in these modes.  With ``kin`` (the model's kinematics),
    a translational mode of a turning carrier gets its whirl (:func:`whirl_senses`).
    """
    meta = structure.metadata
    planets = set(meta.get("planet_bodies", {}))
    # the stages' central members: carriers and the gears that mesh with a planet (the
    # other bodies of a model -- a split path's pinions -- are no member of a stage)
    central = set(meta.get("carriers", {}))
    for mk in meta.get("meshes", {}).values():
        pair = {mk.get("driver"), mk.get("driven")}
        if pair & planets:
            central |= pair - planets - {None}
    names = list(structure.dof_names)
    mass = 1.0 / np.asarray(structure.inv_mass)
    body = [n.rpartition(".")[0] for n in names]
    is_rot = np.array([n.endswith(".theta") for n in names])
    is_planet = np.array([b in planets for b in body])
    is_central = np.array([b in central for b in body])
    # a rigid shaft joins rotations into one DOF named after the group's representative
    groups_of = meta.get("dof_map").theta if meta.get("dof_map") is not None else {}
    for b, (idx, _) in groups_of.items():
        if idx >= 0 and b in planets:
            is_planet[idx] = True
        elif idx >= 0 and b in central:
            is_central[idx] = True
    is_central &= ~is_planet
    phi = np.asarray(sol.mode_shapes)
    freqs = np.asarray(sol.frequencies)
    zeta = np.asarray(sol.damping_ratios)
    senses = whirl_senses(structure, sol, kin) if kin is not None and planets else {}
    rows: list[ModeRow] = []
    for gi, members in enumerate(_groups(freqs, rtol), start=1):
        w = mass[:, None] * np.abs(phi[:, members]) ** 2
        motion = w.sum(axis=1)
        total = float(motion.sum()) or 1.0
        c_rot = float(motion[is_rot & is_central].sum()) / total
        c_tr = float(motion[~is_rot & is_central].sum()) / total
        p = float(motion[is_planet].sum()) / total
        other = max(1.0 - c_rot - c_tr - p, 0.0)
        kind = None
        if planets:
            # the type by the stage's own motion (its central members' and planets'): a
            # mode of the rest of the model is "other"
            stage = (c_rot + c_tr + p) or 1.0
            s_rot, s_tr = c_rot / stage, c_tr / stage
            if other > 1.0 - tol:
                kind = "other"
            elif s_rot + s_tr < tol:
                kind = "planet"
            elif s_tr < tol:
                kind = "rotational"
            elif s_rot < tol:
                kind = "translational"
            else:
                kind = "mixed"
        share = sol.group_shares(members)  # (basis-independent)
        order = np.argsort(-share)
        energy = {structure.element_names[k]: float(share[k]) for k in order
                  if share[k] > 1e-12}
        for k in members:
            sense = senses.get(k, 0) if kind == "translational" else 0
            rows.append(ModeRow(mode=k + 1, frequency=float(freqs[k]), group=gi,
                                multiplicity=len(members), type=kind,
                                strain_energy=energy,
                                motion={"central_rotation": c_rot,
                                        "central_translation": c_tr, "planets": p,
                                        "other": other},
                                damping_ratio=float(zeta[members].mean()),
                                whirl={1: "forward", -1: "backward"}.get(sense)))
    return rows


def model_modes(model, *, rotating_frame: bool = True, below: float | str | None = None,
                count: int | None = None, rtol: float = DEGENERATE_RTOL) -> ModalReport:
    """Modes of a model about its static equilibrium, grouped, and classified where it has
    a planetary stage (``ModeRow.type`` None otherwise).

    Parameters
    ----------
    model : Model, str or Path
    rotating_frame : bool
        Include the Coriolis and centripetal terms of the bodies in a turning carrier's
        frame (False: the stationary-carrier modes of Lin & Parker 1999).
    below : float, optional
        Keep the modes below this frequency [Hz, or a text with its unit: "1 kHz"] (whole
        degenerate groups).
    count : int, optional
        Keep at most this many modes (a degenerate group is not cut: the last group is
        kept whole).
    rtol : float
        Relative difference of frequencies that are one group.

    Examples
    --------
    >>> import torquesplit
    >>> rep = torquesplit.model_modes(torquesplit.example_path("lin_parker1999_planetary"),
    ...                               rotating_frame=False)
    >>> [(r.type, r.multiplicity) for r in rep.rows[:3]]
    [('translational', 2), ('translational', 2), ('translational', 2)]
    """
    from .assembly.assemble import assemble
    from .model.checks import refuse_out_of_mesh
    from .model.io import load_model
    from .model.kinematics import solve_kinematics
    from .solve.modal import modal_analysis
    from .solve.static import static_equilibrium

    if count is not None and not (isinstance(count, (int, np.integer)) and count >= 1):
        raise OptionError(f"count must be a whole number of modes, 1 or more, got {count!r}")
    if isinstance(below, str):  # '1 kHz', as simulate(duration='5 ms') reads a text
        from .model.units import parse_quantity

        try:
            below = parse_quantity(below, "frequency")
        except ValueError as exc:
            raise OptionError(f"below {exc}") from None
    if below is not None and not (isinstance(below, (int, float)) and not isinstance(
            below, bool) and below > 0):
        raise OptionError(f"below must be a positive frequency (in Hz, or a text with its "
                          f"unit such as '1 kHz'), got {below!r}")
    if not (isinstance(rtol, (int, float)) and not isinstance(rtol, bool) and 0 <= rtol < 1):
        raise OptionError(f"rtol must be a relative difference of frequencies, 0 <= rtol < 1, "
                          f"got {rtol!r}; give e.g. rtol=1e-6")
    if not hasattr(model, "meshes"):
        model = load_model(model)
    kin = solve_kinematics(model)
    st = assemble(model, kin, options={"rotating_frame": rotating_frame})
    q = static_equilibrium(st).q
    refuse_out_of_mesh(model, st, q, warn=True)  # (modes about an equilibrium out of mesh)
    sol = modal_analysis(st, q)
    rows = classify(st, sol, rtol=rtol, kin=kin)
    if below is not None:
        rows = [r for r in rows if r.frequency < below]
    if count is not None and len(rows) > count:
        last = rows[count - 1].group
        rows = [r for r in rows if r.mode <= count or r.group == last]
    return ModalReport(solution=sol, rows=rows, rigid_modes=int(sol.rigid_modes.shape[1]),
                       dof_names=tuple(st.dof_names),
                       rotating_frame=bool(st.metadata.get("rotating_frame", False)),
                       model=model)


# --------------------------------------------------------------------------- mesh phasing
#: planets closer than this to equal spacing [rad] are equally spaced
SPACING_TOLERANCE = 1e-6


@dataclass(frozen=True)
class PhasedStage:
    """A stage whose mesh phasing selects the modes a mesh harmonic excites: one carrier,
    N >= 3 identical planets equally spaced on it, each meshing with one sun and one
    ring, no pin errors (equal planet loads), and a central member that translates (else
    the translational modes are labelled ``planet``, :func:`classify`)."""

    carrier: str
    planets: int
    sun_teeth: int
    meshes: frozenset[str]
    """The stage's sun-planet and ring-planet meshes."""
    sun_sense: int = 0
    """+1 (-1): the sun turns relative to the carrier in (against) the carrier's sense of
    rotation; 0: the carrier does not turn (the whirl of a mode is not used)."""

    def excites(self, order: int, mode_type: str | None, whirl: str | None = None) -> bool:
        """Whether mesh harmonic ``order`` excites a mode of ``mode_type``: Parker & Lin
        2004 ("Mesh phasing relationships in planetary and epicyclic gears", J. Mech.
        Des. 126), with equally spaced planets harmonic l excites the rotational modes
        only when l z_s / N is an integer, the translational modes only when
        (l z_s +- 1) / N is, the planet modes only when neither is.  A mode of no pure
        type (``mixed``, None) is always excited; a mode in which no member of the stage
        moves (``other``) never is by the stage's meshes (they do no work on it).

        With a turning carrier the translational pairs split into whirls (``whirl``
        forward or backward against the carrier's rotation): the planets' net mesh force
        of harmonic l turns in the carrier's frame in the sense of the sun's rotation
        relative to the carrier when (l z_s - 1) / N is an integer, against it when
        (l z_s + 1) / N is (sum_n cos(l omega t - l z_s psi_n) e^(i psi_n)), and excites
        only the whirl of its sense (a forced response of a 3-planet stage: ~900 times
        less on the other)."""
        n, lz = self.planets, order * self.sun_teeth
        rot = lz % n == 0
        trans = (lz + 1) % n == 0 or (lz - 1) % n == 0
        if mode_type == "rotational":
            return rot
        if mode_type == "translational":
            if whirl in ("forward", "backward") and self.sun_sense:
                with_sun = (whirl == "forward") == (self.sun_sense > 0)
                return (lz - 1) % n == 0 if with_sun else (lz + 1) % n == 0
            return trans
        if mode_type == "planet":
            return not (rot or trans)
        return mode_type != "other"


def phased_stages(model, kin) -> list[PhasedStage]:
    """The stages of ``model`` to which Parker & Lin 2004's phasing rule applies
    (:class:`PhasedStage`); [] for a model with more than one carrier or none, unequal
    spacing, unlike planets, pin errors, or central members that do not translate."""
    from .model.kinematics import gear_geometry

    if len(kin.carriers) != 1:
        return []
    (carrier, planets), = kin.carriers.items()
    n = len(planets)
    if n < 3 or any(p not in model.gears for p in planets):
        return []
    gears = [model.gears[p] for p in planets]
    first = gears[0].model_dump(exclude={"position", "place", "support"})
    if any(g.model_dump(exclude={"position", "place", "support"}) != first for g in gears):
        return []  # unlike planets
    if any(g.support is None or not g.support.pin_error.is_zero
           or g.support.model_dump(exclude={"pin_error"})
           != gears[0].support.model_dump(exclude={"pin_error"}) for g in gears):
        return []  # pin errors or unlike bearings: unequal planet loads
    c = kin.bodies[carrier]
    axis = np.asarray(c.axis, float)
    ref = None
    angles = []
    for p in planets:
        r = np.asarray(kin.bodies[p].position, float) - np.asarray(c.position, float)
        r = r - axis * float(r @ axis)
        if ref is None:
            ref = r / np.linalg.norm(r)
        angles.append(float(np.arctan2(np.cross(ref, r) @ axis, ref @ r)) % (2 * np.pi))
    angles.sort()
    step = 2 * np.pi / n
    if any(abs(a - k * step) > SPACING_TOLERANCE for k, a in enumerate(angles)):
        return []
    # one sun and one ring, each meshing with every planet, the planets with nothing else
    mates: dict[str, set[str]] = {}
    meshes: set[str] = set()
    for name, m in model.meshes.items():
        a, b = m.gears
        for p, o in ((a, b), (b, a)):
            if p in planets:
                if o in planets:
                    return []
                mates.setdefault(o, set()).add(p)
                meshes.add(name)
    if len(mates) != 2 or any(len(v) != n for v in mates.values()):
        return []
    kinds = {o: model.gears[o].gear_type == "internal" for o in mates if o in model.gears}
    if sorted(kinds.values()) != [False, True] or len(meshes) != 2 * n:
        return []
    sun = next(o for o, internal in kinds.items() if not internal)
    ring = next(o for o, internal in kinds.items() if internal)
    if not any(any(d != "theta" for d in _dofs(model, b)) for b in (sun, ring, carrier)):
        return []
    gear_geometry(model.gears[sun])  # a sun of valid geometry
    # the sun's speed relative to the carrier, about the carrier's axis, against its speed
    w_rel = kin.relative_speed(sun, carrier) * float(np.asarray(kin.bodies[sun].axis) @ axis)
    sense = int(np.sign(w_rel * c.speed))
    return [PhasedStage(carrier=carrier, planets=n, sun_teeth=model.gears[sun].teeth,
                        meshes=frozenset(meshes), sun_sense=sense)]


def _dofs(model, body) -> list[str]:
    spec = model.gears.get(body) or model.bodies.get(body)
    return list(spec.dofs) if spec is not None else []


def phasing_suppresses(stages, mesh: str, order: int, mode_type: str | None,
                       whirl: str | None = None) -> bool:
    """Whether harmonic ``order`` of ``mesh`` leaves a mode of ``mode_type`` (and
    ``whirl``) unexcited by the planets' mesh phasing (Parker & Lin 2004;
    :meth:`PhasedStage.excites`)."""
    return any(mesh in st.meshes and not st.excites(order, mode_type, whirl)
               for st in stages)
