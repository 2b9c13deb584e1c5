"""LTCA of a mesh of a model: what the assembly needs (stiffness method ``"ltca"``).

At model assembly a mesh with ``stiffness.method = "ltca"`` gets, at its operating
load (the nominal normal force of the power flow, or ``stiffness.ltca.load``):

* the mesh stiffness over one mesh cycle, and
* the transmission-error excitation ``e(phase)`` of the mesh element
  ``f = k(phase) h(V q - e) + ...`` (structure.py), such that at the operating load the
  static mesh force equals the load at every position:

  - ``excitation = "tangent"`` (default): ``k = dP/dZ`` (the LTCA tangent stiffness)
    and ``e = Z - P / k``.  Small vibrations about the loaded state see the right
    stiffness, and the loaded transmission error drives the mesh;
  - ``excitation = "secant"``: ``k = P / Z`` (Liu et al. 2021 eq. 5, the paper's form)
    and ``e = 0``;
* with ``impact = true``, the meshing-in impact from the loaded geometry
  (:mod:`torquesplit.gears.contact.impact`).

The stiffness and impact force are tables over ``n`` uniform phases; the error is
passed as its Fourier series in the mesh phase (sinusoids at multiples of the mesh
frequency, with the mesh's phase), so that the kernel also gets its rate ``e'``; the
series keeps the fewest harmonics, up to mesh order 16, that reproduce the LTCA samples
to 5 % of their peak-to-peak or 10 nm (each harmonic costs a sine per step); what the
cut leaves out is ``summary["error_series_residual_m"]``.  The tangent stiffness changes
in steps where a slice joins or leaves the contact, so ``e`` of a modified pair has
content beyond order 16.

Not done here (the kernel's): a stiffness table over load interpolated by the
instantaneous mesh force.

The gear that drives is gear 1 of the pair analysed (phase 0: a new pair enters at
the driver's start of active profile).  For an internal pair driven by its ring gear
the positions are run backwards (the contact travels from the pinion's tip).

Results are cached in memory and on disk (:mod:`~torquesplit.gears.contact.cache`) by a
hash of every input.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.contact import cache as _cache
from torquesplit.gears.contact.impact import loaded_meshing_in
from torquesplit.gears.contact.ltca import ContactModel, LtcaOptions
from torquesplit.gears.contact.modifications import misalignment_from_spec, modification_from_spec
from torquesplit.gears.geometry import PairGeometry
from torquesplit.gears.stiffness.result import periodic_resample

__all__ = ["MeshLtca", "pair_for_mesh", "contact_model_for_mesh", "mesh_ltca",
           "error_harmonics", "MAX_ERROR_HARMONICS"]

#: Fourier harmonics of the transmission-error excitation passed to the mesh element at
#: most: mesh orders 1..16 (each costs one sine per mesh per right-hand-side evaluation)
MAX_ERROR_HARMONICS = 16
#: the series is cut at the fewest harmonics that reproduce the LTCA samples to this
#: fraction of their peak-to-peak, or to SERIES_FLOOR, whichever is larger
SERIES_TOLERANCE = 0.05
SERIES_FLOOR = 1e-8  # m

_MEMO: dict[str, "MeshLtca"] = {}


@dataclass(frozen=True)
class MeshLtca:
    """LTCA excitation of one mesh at its operating load (SI).

    Attributes
    ----------
    stiffness : (n,) mesh stiffness at phases k/n [N/m].
    impact_force : (n,) meshing-in impact force [N], or None.
    te : (M,) loaded transmission error at the LTCA positions [m] (normal).
    error : (M,) transmission-error excitation e at the LTCA positions [m].
    summary : dict of scalars (load, TE peak-to-peak, stiffness, impact, ...).
    """

    stiffness: np.ndarray
    impact_force: np.ndarray | None
    te: np.ndarray
    error: np.ndarray
    summary: dict


def pair_for_mesh(model, kin, mesh_name: str) -> tuple[PairGeometry, tuple[str, str], bool]:
    """The PairGeometry of a mesh with its driver first where possible.

    Returns ``(pair, (gear 1 name, gear 2 name), reverse)``; ``reverse`` is True for an
    internal pair driven by its ring gear (the ring must be gear 2).
    """
    from torquesplit.gears.line_of_action import gear_geometry, is_conical

    mesh = model.meshes[mesh_name]
    mk = kin.meshes[mesh_name]
    a, b = mesh.gears
    ga, gb = model.gears[a], model.gears[b]
    if is_conical(ga, gb) or mk.geometry is None:
        raise ModelError([(f"meshes.{mesh_name}.stiffness.method", (
            "the LTCA is implemented for cylindrical pairs (spur, helical, double-helical, "
            "internal); use a table or a constant for this bevel/face mesh"))])
    driver, driven = mk.driver, mk.driven
    reverse = False
    if model.gears[driver].gear_type == "internal":
        g1, g2, reverse = driven, driver, True
    else:
        g1, g2 = driver, driven
    pair = PairGeometry(gear_geometry(model.gears[g1]), gear_geometry(model.gears[g2]))
    return pair, (g1, g2), reverse


def _options(spec) -> LtcaOptions:
    lt = spec.ltca
    return LtcaOptions(positions=int(lt.positions), slices=int(spec.slices),
                       contact_model=lt.contact_model, coupling=bool(lt.coupling),
                       stagger=float(lt.stagger), axial_float=bool(lt.axial_float),
                       fillet_foundation=bool(spec.fillet_foundation))


def contact_model_for_mesh(model, kin, mesh_name: str, *, options: LtcaOptions | None = None):
    """The :class:`ContactModel` of a mesh and its operating normal load [N].

    Returns ``(contact_model, load, (gear 1 name, gear 2 name), reverse)``.
    """
    spec = model.meshes[mesh_name].stiffness
    pair, names, reverse = pair_for_mesh(model, kin, mesh_name)
    mods = tuple(modification_from_spec(model.gears[g].modifications, pair.face_width,
                                        f"gears.{g}.modifications") for g in names)
    mis = misalignment_from_spec(model.meshes[mesh_name].misalignment)
    opts = options or _options(spec)
    gears = [model.gears[g] for g in names]
    cm = ContactModel(pair, mods, mis, opts,
                      young_modulus=tuple(g.youngs_modulus for g in gears),
                      poisson_ratio=tuple(g.poisson_ratio for g in gears),
                      where=(f"gears.{names[0]}.modifications", f"gears.{names[1]}.modifications",
                             f"meshes.{mesh_name}.misalignment"))
    load = spec.ltca.load if spec.ltca.load is not None else kin.meshes[mesh_name].force
    return cm, float(load), names, reverse


def _key_inputs(model, kin, mesh_name, n, pair, names, reverse, load) -> dict:
    mesh = model.meshes[mesh_name]
    spec = mesh.stiffness
    gears = {}
    for role, g in zip(("gear1", "gear2"), names):
        gg = model.gears[g]
        geo = pair.gear1 if role == "gear1" else pair.gear2
        gears[role] = dict(
            teeth=geo.teeth, module=geo.normal_module, alpha=geo.normal_pressure_angle,
            beta=geo.helix_angle, b=geo.face_width, x=geo.profile_shift, ha=geo.addendum,
            hf=geo.dedendum, internal=geo.internal, double=geo.double_helical,
            rho=geo.tool_tip_radius, E=gg.youngs_modulus, nu=gg.poisson_ratio,
            mods=None if gg.modifications is None else gg.modifications.model_dump(mode="json"))
    inputs = dict(gears=gears, reverse=reverse, load=load, n=n,
                  ltca={k: v for k, v in spec.ltca.model_dump(mode="json").items() if k != "cache"},
                  slices=spec.slices, fillet=spec.fillet_foundation,
                  misalignment=mesh.misalignment.model_dump(mode="json"), impact=bool(mesh.impact))
    if mesh.impact:
        mk = kin.meshes[mesh_name]
        inputs["impact_inputs"] = dict(
            omega=abs(mk.driver_speed), j_driver=kin.bodies[mk.driver].polar_inertia,
            j_driven=kin.bodies[mk.driven].polar_inertia)
    return inputs


def mesh_ltca(model, kin, mesh_name: str, n: int) -> MeshLtca:
    """LTCA stiffness table, error excitation and impact of a mesh (cached).

    Raises ModelError (naming the field) for unsupported meshes or bad modifications and
    SolverError if the contact problem does not converge.
    """
    mesh = model.meshes[mesh_name]
    spec = mesh.stiffness
    pair, names, reverse = pair_for_mesh(model, kin, mesh_name)
    mk = kin.meshes[mesh_name]
    load = float(spec.ltca.load if spec.ltca.load is not None else mk.force)
    if not (load > 0):
        raise ModelError([(f"meshes.{mesh_name}.stiffness.ltca.load", (
            "the mesh carries no load in the power flow; give the operating load, e.g. "
            "load = '10 kN'"))])
    key = _cache.cache_key(_key_inputs(model, kin, mesh_name, n, pair, names, reverse, load))
    if key in _MEMO:
        return _MEMO[key]
    use_disk = bool(spec.ltca.cache)
    hit = _cache.load(key) if use_disk else None
    if hit is not None:
        arrays, summary = hit
        out = MeshLtca(stiffness=arrays["stiffness"], te=arrays["te"], error=arrays["error"],
                       impact_force=arrays.get("impact_force"), summary=summary)
        _MEMO[key] = out
        return out
    cm, load, names, reverse = contact_model_for_mesh(model, kin, mesh_name)
    res = cm.solve(load).require_converged(f"meshes.{mesh_name}.stiffness")
    phase = cm.phase if not reverse else np.mod(-cm.phase, 1.0)
    if spec.ltca.excitation == "tangent":
        k = res.stiffness_tangent
        err = res.transmission_error - load / k
    else:
        k = res.stiffness_secant
        err = np.zeros_like(k)
    table = periodic_resample(phase, k, n)
    summary = {k_: v for k_, v in res.summary().items()}
    n_harm = harmonics_needed(err)
    summary.update(excitation=spec.ltca.excitation, gears=list(names), reverse=reverse,
                   error_peak_to_peak_m=float(np.ptp(err)), error_harmonics=n_harm,
                   error_series_residual_m=series_residual(err, n_harm))
    impact = None
    if mesh.impact:
        if reverse:
            raise ModelError([(f"meshes.{mesh_name}.impact", (
                "meshing-in impact from the LTCA needs the pinion to drive an internal pair; "
                "set impact = false"))])
        drv, dvn = kin.bodies[mk.driver], kin.bodies[mk.driven]
        mi = loaded_meshing_in(res, omega_driving=abs(mk.driver_speed),
                               inertia_driving=drv.polar_inertia,
                               inertia_driven=dvn.polar_inertia)
        impact = mi.force(np.arange(n) / n)
        summary.update(impact_peak_force_N=mi.peak_force, impact_advance_m=mi.advance,
                       impact_corner_separation_m=mi.corner_separation)
    # sort the samples by phase (the reversed order of an internal pair driven by its ring)
    order = np.argsort(phase, kind="stable")
    out = MeshLtca(stiffness=table, impact_force=impact, te=res.transmission_error[order],
                   error=err[order], summary=summary)
    if use_disk:
        arrays = dict(stiffness=out.stiffness, te=out.te, error=out.error)
        if impact is not None:
            arrays["impact_force"] = impact
        _cache.store(key, arrays, summary)
    _MEMO[key] = out
    return out


def harmonics_needed(error, rel_tol: float = SERIES_TOLERANCE,
                     harmonics: int = MAX_ERROR_HARMONICS, floor: float = SERIES_FLOOR) -> int:
    """Fewest harmonics (at most ``harmonics``) whose series of :func:`error_harmonics`
    reproduces the samples to ``rel_tol`` times their peak-to-peak or to ``floor`` [m]."""
    e = np.asarray(error, dtype=float)
    top = min(harmonics, e.size // 2)
    limit = max(rel_tol * float(np.ptp(e)), floor)
    for h in range(0, top + 1):
        if series_residual(e, h) <= limit:
            return h
    return top


def error_harmonics(error, frequency: float, phase0: float,
                    harmonics: int = MAX_ERROR_HARMONICS) -> tuple[float, list[tuple[float, float, float]]]:
    """Constant and sinusoids ``(amplitude, omega, phase)`` of an error given at ``M``
    uniform mesh phases, for a mesh of ``frequency`` [Hz] whose phase at t = 0 is
    ``phase0``: ``e(t) = c + sum A_h sin(omega_h t + psi_h)``, ``omega_h = 2 pi h f``,
    the mesh phase being ``f t + phase0`` (the convention of the assembled structure).

    Harmonics 1 .. min(harmonics, M/2) (the Nyquist one of an even M included, with its
    single weight): with ``M / 2 <= harmonics`` the series passes exactly through the
    samples.  :func:`harmonics_needed` gives the fewest that reproduce them to a tolerance.
    """
    e = np.asarray(error, dtype=float)
    m = e.size
    c = np.fft.rfft(e) / m
    const = float(c[0].real)
    out = []
    for h in range(1, min(harmonics, m // 2) + 1):
        weight = 1.0 if 2 * h == m else 2.0       # the Nyquist term is not doubled
        a, b = weight * c[h].real, -weight * c[h].imag   # e ~ a cos(2 pi h x) + b sin(2 pi h x)
        amp = math.hypot(a, b)
        if amp <= 1e-15:
            continue
        theta = math.atan2(a, b)                   # a cos u + b sin u = amp sin(u + theta)
        out.append((amp, 2.0 * math.pi * h * frequency, 2.0 * math.pi * h * phase0 + theta))
    return const, out


def series_residual(error, harmonics: int = MAX_ERROR_HARMONICS) -> float:
    """Largest difference at the samples between an error and its series of
    :func:`error_harmonics` [m] (0 when no harmonic is cut off)."""
    e = np.asarray(error, dtype=float)
    m = e.size
    c0, terms = error_harmonics(e, 1.0, 0.0, harmonics)
    x = np.arange(m) / m
    rebuilt = c0 + sum(a * np.sin(om * x + ph) for a, om, ph in terms)
    return float(np.abs(rebuilt - e).max())


def clear_memory_cache() -> None:
    """Forget the in-memory results (the disk cache stays)."""
    _MEMO.clear()
