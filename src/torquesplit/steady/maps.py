"""Model-level speed sweep (:func:`sweep_speed`) and resonance map (:func:`campbell`).

Both return :class:`xarray.Dataset` objects with units and long names; speeds are the
first drive's speed [rpm in the coordinates, rad/s in ``speed``], frequencies in Hz.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from torquesplit._args import whole
from torquesplit.errors import (
    ModelWarning,
    OptionError,
    SolverError,
    from_interrupt,
    held_interrupt,
    interrupt_name,
    warn_user,
)
from torquesplit.solve.modal import DEGENERATE_RTOL
from torquesplit.steady.solution import warn_undamped
from torquesplit.steady.api import reference_speed
from torquesplit.steady.solution import check_method
from torquesplit.steady.period import (
    MAX_CYCLES,
    base_frequency,
    fundamental_period,
    keep_excitations,
)
from torquesplit.steady.problem import periodic_problem
from torquesplit.steady.sweep import (
    continue_in_speed,
    continue_in_speed_shooting,
    point_metrics,
    shooting_point_metrics,
    stepped_sweep,
)

RPM = 60.0 / (2 * math.pi)

__all__ = ["sweep_speed", "campbell", "near_critical_speeds"]


def _rad_per_s(value, name: str) -> float:
    """A speed in rad/s: a number (rad/s) or a text with its unit ('2400 rpm')."""
    if isinstance(value, str):
        from torquesplit.model.units import parse_quantity

        try:
            return float(parse_quantity(value, "speed"))
        except ValueError as exc:
            raise OptionError(f"{name}: {exc}") from None
    return float(value)


def _prepare(model, keep, max_cycles):
    from torquesplit.assembly.assemble import assemble
    from torquesplit.model.io import load_model
    from torquesplit.model.kinematics import solve_kinematics
    from torquesplit.solve.static import static_equilibrium

    if not hasattr(model, "meshes"):
        model = load_model(model)
    kin = solve_kinematics(model)
    full = assemble(model, kin)
    structure, dropped = full, []
    if keep is not None:
        base = base_frequency(full, keep, kin)
        structure, dropped = keep_excitations(full, base)
    per = fundamental_period(structure, max_cycles=max_cycles)
    if keep is not None:
        from torquesplit.steady.api import _at_base

        per = _at_base(per, base)
    static = static_equilibrium(structure)
    from torquesplit.model.checks import refuse_out_of_mesh

    refuse_out_of_mesh(model, structure, static.q, warn=True)
    return model, kin, structure, dropped, per, static


def _message_in_rpm(msg: str, w_ref: float, pts, s1: float, complete: bool) -> str:
    """The continuation's message with its speed factors in rpm; a sweep stopped by its
    point limit says where it stopped against the end asked for, and why it crawls (a
    reviewer's 20 points became 2000, the last 1100 within 4 rpm of an undamped
    resonance, told only 'stopped after 2000 points; curve kept')."""
    import re

    msg = re.sub(r"speed factor ([-+0-9.eE]+)",
                 lambda m: f"{float(m.group(1)) * w_ref * RPM:.6g} rpm", msg)
    if not complete and msg.startswith("stopped after") and pts:
        mu = pts[-1].max_multiplier
        near = (f" and the largest Floquet multiplier approaches 1 (|mu| = {mu:.6g} at the "
                f"last point): the edge of a parametric instability, or the resonance of a "
                f"mode without damping (see the warnings), where the periodic state grows "
                f"without bound; past it 'torquesplit run' at those speeds gives the "
                f"response" if math.isfinite(mu) and mu > 0.99 else
                ": the periodic state changes fast with speed there")
        msg = (msg.rstrip(".").replace("; curve kept", "") + f" at "
               f"{pts[-1].speed * w_ref * RPM:.6g} rpm, short of the {s1 * w_ref * RPM:.6g} "
               f"rpm asked (the curve up to there is kept): the continuation's steps shrank "
               f"as the response grew{near}")
    return msg




def _model_json(model) -> str:
    """The model as a run's file holds it (``model_json``: a saved map can be re-run)."""
    from torquesplit.model.io import model_to_json

    return model_to_json(model)


def sweep_speed(model, start: float, stop: float, *, points: int = 50,
                harmonics: int | None = None, samples: int | None = None, keep=None,
                max_cycles: int | None = MAX_CYCLES, stability: bool = True,
                max_step: float | None = None, cross_check: bool = False,
                settle_periods: int = 200, progress=None, method: str = "auto",
                steps_per_cycle: int | None = None):
    """Frequency (speed) response of the periodic state by pseudo-arclength continuation.

    Parameters
    ----------
    model : Model, str or Path
    start, stop : float or str
        Speeds of the first drive [rad/s], or texts with their unit ('2400 rpm'); the
        sweep runs from ``start`` to ``stop``.
    points : int
        Initial number of steps over the range (the step adapts; folds add points).
    method : {"auto", "shooting", "hb"}
        Continuation of the shooting equations (:class:`~torquesplit.steady.sweep.
        ShootingContinuation`: one monodromy per point, the tables' corners stepped
        through) or of the harmonic-balance equations; "auto" (default): shooting unless
        ``harmonics`` are given.
    steps_per_cycle : int, optional
        Shooting: RK4 steps per cycle of the fastest excitation (default 100, refined as
        :func:`~torquesplit.steady.steady_state` refines them, at the lowest speed).
    harmonics, samples, keep, max_cycles
        As :func:`torquesplit.steady.steady_state`.
    stability : bool
        Floquet multipliers at every point (Hill's method for small systems, else the
        monodromy); unstable points are dashed in the plot.
    cross_check : bool
        Also run-up and run-down time integrations at ``points`` speeds (each from the
        previous end state, ``settle_periods`` periods per speed) for the same plot.

    Returns
    -------
    xarray.Dataset
        dims ``point`` and ``mesh``: speed, mesh frequency, dynamic factor (peak / the
        mesh's static force), peak-to-nominal, load-sharing coefficients
        (``load_sharing_mean_force``:
        the ratio of mean forces, Dong et al. 2021 eq. 12, whatever the model's
        ``[analysis] load_sharing``;
        ``load_sharing_instantaneous``: the largest instantaneous ratio in its group
        over the period), RMS transmission error, peak and mean force, stability and
        largest Floquet multiplier; attributes: turning points (jump speeds), natural frequencies and their mesh-order crossings, status
        message.  A continuation that fails keeps the points computed so far
        (``attrs['complete'] == 0`` and the reason in ``attrs['message']``); so does a
        Ctrl-C, whose message starts "interrupted" (one after the continuation waits for
        the curve's metrics; one in the cross-check leaves the cross-check out).  The
        points are along ``point``, not indexed by speed: past a fold the curve passes a
        speed more than once.  Save it with :func:`torquesplit.save` (``.nc``, ``.mat``,
        ``.csv`` as ``sweep-speed --out`` writes them; the model in ``model_json``).
    """
    import xarray as xr

    from torquesplit.metrics.load_sharing import group_meshes

    if not (isinstance(points, (int, np.integer)) and points >= 1):
        raise OptionError(f"points must be a whole number >= 1, got {points!r}")
    if not (isinstance(settle_periods, (int, np.integer)) and not isinstance(
            settle_periods, bool) and settle_periods >= 1):  # (0: a ZeroDivisionError deep
        # inside; -1: cross-check numbers that looked plausible)
        raise OptionError(f"settle_periods must be a whole number >= 1 (periods run at "
                          f"each speed of the cross-check), got {settle_periods!r}; give "
                          f"e.g. 200")
    if max_step is not None and not (isinstance(max_step, (int, float))
                                     and not isinstance(max_step, bool) and max_step > 0):
        raise OptionError(f"max_step must be a positive speed in rad/s (the largest "
                          f"continuation step), got {max_step!r}; leave it out for the "
                          f"default")
    t_start = time.perf_counter()
    from torquesplit.steady.api import _check_options

    _check_options(steps_per_cycle=steps_per_cycle, tol=None, stability=stability,
                   energy_tol=None, method=method, harmonics=harmonics,
                   max_cycles=max_cycles)  # (as steady_state refuses them)
    model, kin, s, dropped, per, static = _prepare(model, keep, max_cycles)
    warn_undamped(s, static.q)
    sub = math.gcd(*[int(k) for k in per.orders]) if per.orders else 1
    w_ref = reference_speed(model)
    s0, s1 = _rad_per_s(start, "start") / w_ref, _rad_per_s(stop, "stop") / w_ref
    if not (s0 > 0 and s1 > 0 and math.isfinite(s0) and math.isfinite(s1)) or s0 == s1:
        raise OptionError(f"the speed range {s0 * w_ref * RPM:.6g}..{s1 * w_ref * RPM:.6g} rpm "
                          f"must be two different positive speeds; e.g. from '1000 rpm' to "
                          f"'3000 rpm' (--from, --to; in Python start=, stop=)")
    if per.frequency <= 0:
        raise SolverError("the model has no time-varying excitation: its response does not "
                          "change with speed; nothing to sweep.")
    check_method(method)
    if method == "auto":
        method = "hb" if harmonics is not None else "shooting"
    problem = periodic_problem(model, kin, s, per.frequency)
    step_max = None if max_step is None else max_step / w_ref
    if method == "shooting":
        cont, pts, folds, msg, complete, _ = continue_in_speed_shooting(
            problem, per, static.q, s0, s1, points=points, stability=stability,
            max_step=step_max, progress=progress, steps_per_cycle=steps_per_cycle)
    else:
        hb, pts, folds, msg, complete, _ = continue_in_speed(
            problem, per, static.q, s0, s1, points=points, harmonics=harmonics,
            samples=samples, stability=stability, max_step=step_max, progress=progress)
    msg = _message_in_rpm(msg, w_ref, pts, s1, complete)
    # (a Ctrl-C from here on lost the curve computed, "nothing written": it now waits
    # for the curve's metrics, then ends the sweep with them)
    with held_interrupt() as ctrl_c:
        mesh_names = list(model.meshes)
        names = list(s.element_names)
        track = [names.index(m) for m in mesh_names]
        meta = s.metadata["meshes"]
        groups = group_meshes({m: meta[m] for m in mesh_names})
        gcols = [[mesh_names.index(m) for m in g] for g in groups.values()]
        nominal = np.array([kin.meshes[m].force for m in mesh_names])

        def static_f(speed):  # the static forces at a point's speed (the dynamic factors)
            if s.metadata.get("rotating_frame"):  # (a turning carrier's centrifugal loads)
                from torquesplit.solve.static import static_equilibrium

                at = static_equilibrium(problem.structure_at(speed, frequencies=False))
                return np.array([at.element_forces[e] for e in track])
            return np.array([static.element_forces[e] for e in track])

        if method == "shooting":
            rows = [shooting_point_metrics(cont, p.x, p.speed, track, gcols, static_f(p.speed),
                                           nominal) for p in pts]
        else:
            rows = [point_metrics(hb, p.x, p.speed, track, gcols, static_f(p.speed), nominal,
                                  order=per.max_order) for p in pts]
        sp = np.array([p.speed for p in pts])

        def stack(key):
            return np.array([r[key] for r in rows]) if rows else np.zeros((0, len(track)))

        f_mesh = np.array([[meta[m]["frequency"] for m in mesh_names]]) * sp[:, None]
        ds = xr.Dataset(
            {
                "speed": ("point", sp * w_ref, {"units": "rad/s", "long_name": "input speed"}),
                "mesh_frequency": (("point", "mesh"), f_mesh,
                                   {"units": "Hz", "long_name": "mesh frequency"}),
                "dynamic_factor": (("point", "mesh"), stack("dynamic_factor"),
                                   {"units": "1", "long_name": "peak / the mesh's static force"}),
                "peak_to_nominal": (("point", "mesh"), stack("peak_to_nominal"),
                                    {"units": "1",
                                     "long_name": "peak / equal-split nominal force"}),
                "load_sharing_mean_force": (("point", "mesh"), stack("load_sharing"), {
                    "units": "1", "definition": "mean_force",
                    "long_name": "load-sharing coefficient N mean F_i / sum of the group's "
                                 "mean forces (mean_force, Dong et al. 2021 eq. 12)"}),
                "load_sharing_instantaneous": (("point", "mesh"),
                                               stack("load_sharing_instantaneous"), {
                    "units": "1", "definition": "instantaneous",
                    "long_name": "largest instantaneous N F_i / sum F_j over the period "
                                 "(Ji & Li eq. 18)"}),
                "rms_transmission_error": (("point", "mesh"), stack("rms_transmission_error"),
                                           {"units": "m", "long_name": "RMS dynamic "
                                            "transmission error about its mean (the flanks' "
                                            "relative displacement, errors included)"}),
                "peak_force": (("point", "mesh"), stack("peak_force"),
                               {"units": "N", "long_name": "peak mesh force"}),
                "mean_force": (("point", "mesh"), stack("mean_force"),
                               {"units": "N", "long_name": "mean mesh force"}),
                "contact_loss": (("point", "mesh"), stack("contact_loss"),
                                 {"units": "1", "long_name": "fraction of the period in which "
                                  "the mesh carries no force (teeth apart)"}),
                "stable": ("point", np.array([bool(p.stable) if p.stable is not None else True
                                              for p in pts], dtype=bool), {
                    "long_name": "1 if the periodic state is stable (Floquet multipliers "
                                 "inside the unit circle)"}),
                "max_multiplier": ("point", np.array([p.max_multiplier for p in pts]),
                                   {"units": "1", "long_name": "largest |Floquet multiplier|"}),
                # (over a period of several excitation cycles, a keep= fraction, a period-1
                # orbit's multipliers are powers of its own: they do not say how it loses
                # stability, so none is named)
                "instability": ("point", np.array([p.instability if sub == 1 else ""
                                                   for p in pts], dtype=str), {
                    "long_name": "how an unstable orbit loses stability: 'period doubling' (a "
                                 "multiplier below -1: the response is not this orbit), 'fold' "
                                 "(above 1), 'torus' (a complex pair); empty where stable"}),
            },
            coords={"speed_rpm": ("point", sp * w_ref * RPM,
                                  {"units": "rpm", "long_name": "input speed"}),
                    "mesh": mesh_names},
        )
        if not stability:  # (nothing judged: no variable that reads 'stable', a reviewer)
            ds = ds.drop_vars(["stable", "max_multiplier", "instability"])
            ds.attrs["stability"] = ("not computed (stability=False, --no-stability): every "
                                     "point is counted, an unstable one too")
        w_lo, w_hi = min(s0, s1) * w_ref, max(s0, s1) * w_ref
        crit = critical_speeds(s, static.q, kin, model, w_lo, w_hi)
        if s.n_gyroscopic:  # frequencies that move with speed: the Campbell map's crossings
            crit["crossings"] = campbell(model, w_lo, w_hi)[1]
        critical, suppressed = split_suppressed(crit["crossings"])
        ds.attrs.update(
            model=model.model.name, model_json=_model_json(model),
            method=("shooting" if method == "shooting" else "harmonic balance")
            + ", pseudo-arclength continuation",
            harmonics=0 if method == "shooting" else hb.H,
            samples=cont.steps if method == "shooting" else hb.N,
            # (samples: the RK4 steps per period, this many excitation cycles long: per
            # cycle, the resolution a check of the curve's numbers doubles)
            excitation_cycles_per_period=max(per.max_order, 1),
            fundamental_frequency_at_model_speed_Hz=per.frequency,
            complete=int(complete), message=msg,
            requested_speeds_rpm=[s0 * w_ref * RPM, s1 * w_ref * RPM],
            fold_speeds_rpm=[f * w_ref * RPM for f, _ in folds],
            fold_kinds=[k for _, k in folds],
            kept_excitations="all" if keep is None else str(keep),
            dropped_excitations=[x.describe() for x in dropped],
            natural_frequencies_Hz=list(crit["natural_frequencies"]),
            natural_frequencies_at_speed_rpm=w_ref * RPM,
            critical_speeds_rpm=[c["speed_rpm"] for c in critical],
            critical_speed_labels=[_undriven(c, f"mode {c['mode']} x {c['order']} {c['source']}")
                                   for c in critical],
            **({"suppressed_speeds_rpm": [c["speed_rpm"] for c in suppressed],
                "suppressed_speed_labels": [
                    f"mode {c['mode']} x {c['order']} {c['source']} ({mode_kind(c)} mode: "
                    f"suppressed by mesh phasing, Parker & Lin 2004)" for c in suppressed]}
               if suppressed else {}),
            loads="torques held at the model's values",
            wall_time_s=time.perf_counter() - t_start,
        )
        if method != "shooting" and rows and float(np.max(stack("contact_loss"))) > 0:
            warn_user(
                "harmonic balance over contact loss: a truncated series rings where the teeth "
                "separate, so the jump speeds and the peaks there can be off by per cents (on a "
                "single spur pair a fold 6 % off); shooting (--method shooting, the default "
                "without --harmonics) steps through the separations", ModelWarning)
        gaps = unresolved_critical_speeds(sp * w_ref * RPM, [c["speed_rpm"] for c in critical])
        ds.attrs["unresolved_critical_speeds_rpm"] = gaps
        if gaps:
            ds.attrs["message"] = ds.attrs["message"].rstrip(".") + (
                f"; the points lie too far apart to resolve the critical speed(s) at "
                f"{', '.join(f'{c:.5g}' for c in gaps[:5])} rpm (no point within "
                f"{100 * RESOLVE:g} % of them): give more --points or a narrower range")
    if ctrl_c.hit or str(msg).startswith("interrupted"):  # (an interrupted sweep ran its
        # whole cross-check, minutes, after the Ctrl-C: a reviewer)
        if not str(msg).startswith("interrupted"):
            rest = str(ds.attrs["message"])
            rest = rest[len("complete"):].lstrip("; ") if rest.startswith("complete") else rest
            ds.attrs["message"] = (
                f"interrupted ({interrupt_name()}) once the curve's {len(pts)} points were "
                f"computed; the curve is kept{' (the cross-check not run)' if cross_check else ''}"
                + (f"; {rest}" if rest else ""))
        return ds
    if cross_check:
        grid = np.linspace(min(s0, s1), max(s0, s1), points)
        try:  # (the run-up and run-down: minutes; a Ctrl-C keeps the curve without them)
            up, up_rms = stepped_sweep(problem, per, static.q, grid,
                                       settle_periods=settle_periods, track=track)
            down, dn_rms = stepped_sweep(problem, per, static.q, grid[::-1],
                                         settle_periods=settle_periods, track=track)
        except (KeyboardInterrupt, SystemError) as exc:
            if not from_interrupt(exc):
                raise
            ds.attrs["message"] = (f"interrupted ({interrupt_name()}) in the run-up and "
                                   "run-down cross-check, which is left out; the curve is "
                                   "kept: " + ds.attrs["message"])
            return ds
        ds = ds.assign_coords(check_speed_rpm=("check", grid * w_ref * RPM))
        at_grid = np.array([static_f(g) for g in grid])
        ds["run_up_dynamic_factor"] = (("check", "mesh"), up / at_grid)
        ds["run_down_dynamic_factor"] = (("check", "mesh"), down[::-1] / at_grid)
        ds["run_up_rms_transmission_error"] = (("check", "mesh"), up_rms)
        ds["run_down_rms_transmission_error"] = (("check", "mesh"), dn_rms[::-1])
    return ds


RESOLVE = 0.05
"""A sweep resolves a critical speed when one of its points lies within this fraction
of it (a resonance of a few per cent damping is about that wide)."""


def unresolved_critical_speeds(speeds, critical) -> list[float]:
    """The critical speeds inside the swept range with no sweep point within
    :data:`RESOLVE` of them: a resonance there can lie between two points unseen (a
    reviewer's sweep to 1e9 rpm in 31 points reported 'complete' and missed one)."""
    speeds = np.asarray(speeds, dtype=float)
    if speeds.size < 2:
        return []
    lo, hi = float(speeds.min()), float(speeds.max())
    return [float(c) for c in critical if lo <= c <= hi
            and np.min(np.abs(speeds - c)) > RESOLVE * c]


def critical_speeds(structure, q, kin, model, w_lo, w_hi, orders=None):
    """Natural frequencies about ``q`` and their crossings with the mesh-frequency
    harmonics (orders 1..``orders``; None: :func:`mesh_orders` of each mesh's stiffness
    table) of every mesh and the rotation of every gear,
    between input speeds ``w_lo`` and ``w_hi`` [rad/s].  The natural frequencies of
    the model do not depend on speed unless it has speed-dependent (gyroscopic) terms;
    then they are recomputed per speed by :func:`campbell`."""
    from torquesplit.solve.modal import modal_analysis

    sol = modal_analysis(structure, q)
    w_ref = reference_speed(model)
    lines = _order_lines(kin, model, orders, structure)
    cycles: dict = {}  # mesh element -> its MeshCycle about q (each computed once)
    strength = _line_strength(kin, structure, lines, w_ref, q, cycles)
    phasing = _Phasing(model, kin)
    types = phasing.types(structure, sol)
    out = []
    for i, fn in enumerate(sol.frequencies):
        if fn <= 0:
            continue
        for label, order, per_rad in lines:  # f = order * per_rad * w_input
            w = fn / (order * per_rad)
            if w_lo <= w <= w_hi:
                out.append(_cancellation(structure, q, sol, phasing.groups, phasing.mark(dict(
                    mode=i + 1, frequency_Hz=float(fn), order=order, source=label,
                    speed_rpm=float(w * RPM),
                    energy=sol.dominant_elements(i, 4, group_rtol=DEGENERATE_RTOL),
                    **_strength_of(strength, label, order)), types), cycles))
    out.sort(key=lambda c: c["speed_rpm"])
    return dict(natural_frequencies=sol.frequencies, crossings=out, modal=sol,
                lines=lines, reference_speed=w_ref, strength=strength)


def _stiffness_harmonics(kin, structure, lines) -> dict:
    """(line label, order) -> amplitude of that harmonic of the mesh stiffness over its
    mean (the largest over the group's meshes): how strongly the stiffness variation
    drives a crossing (a helical pair with a large overlap ratio has almost none at high
    orders).  Rotation lines and errors are not rated (their amplitude is elsewhere)."""
    if structure is None:
        return {}
    return _largest_harmonics(kin, structure, lines, lambda e: np.asarray(
        structure.stiffness_table[e], dtype=float))


def _largest_harmonics(kin, structure, lines, curve) -> dict:
    """(line label, order) -> the largest over the line's meshes of that harmonic's
    amplitude of ``curve(e)`` (mesh element e's array over one mesh cycle, or None) over
    the curve's mean."""
    names = list(structure.element_names)
    groups = mesh_groups(kin)
    spectra: dict[str, tuple | None] = {}  # mesh -> (its rfft, size, mean)
    out = {}
    for label, order, _ in lines:
        amps = []
        for n in groups.get(label, ()):
            if n not in names:
                continue
            if n not in spectra:
                f = curve(names.index(n))
                spectra[n] = None if f is None else (np.fft.rfft(f), f.size, float(f.mean()))
            got = spectra[n]
            if got is None or order >= got[1] // 2 or not got[2] > 0:
                continue
            amps.append(2 * abs(got[0][order]) / got[1] / got[2])
        if amps:
            out[(label, order)] = float(max(amps))
    return out


def _error_shares(kin, structure, lines, w_ref: float) -> dict:
    """(line label, order) -> (share, mesh): the error sinusoids of the meshes (a
    transmission error's harmonics, a gear's eccentricity or runout turning with it) on
    that line, rated as the force amplitude ``k_mean A`` over the mesh's nominal force
    (the largest over the meshes; an error at no line's frequency is not rated)."""
    if structure is None or not len(structure.error_amplitude) or not w_ref > 0:
        return {}
    names = list(structure.element_names)
    groups = mesh_groups(kin)
    k_mean = structure.mean_stiffness()
    out: dict = {}
    for name, mk in kin.meshes.items():
        if name not in names or not mk.force > 0:
            continue
        e = names.index(name)
        k = float(k_mean[e])
        # a mesh's error is on its own stage's lines (another stage's harmonic may share
        # the frequency) or on a shaft order (an eccentricity)
        own = {(label, order): 2.0 * math.pi * order * per_rad * w_ref
               for label, order, per_rad in lines
               if name in groups.get(label, ()) or label not in groups}
        for i in range(structure.error_ptr[e], structure.error_ptr[e + 1]):
            share = k * abs(float(structure.error_amplitude[i])) / mk.force
            om = abs(float(structure.error_omega[i]))
            for key, w in own.items():
                if abs(om - w) <= 1e-6 * w and share > out.get(key, (0.0, ""))[0]:
                    out[key] = (share, name)
    return out


@dataclass(frozen=True)
class MeshCycle:
    """One mesh's excitation over a mesh cycle, on its stiffness table's phase grid, at
    a static deflection (:func:`mesh_cycle`)."""

    phase: np.ndarray
    """Mesh phase s in [0, 1) (s = f t + phase, as the tables)."""
    stiffness: np.ndarray
    """k(s) [N/m]."""
    error: np.ndarray
    """e(s) [m] along the line of action: the constant and the sinusoids at mesh
    harmonics (a transmission error, the LTCA's loaded one; not a shaft order's)."""
    deflection: float
    """V q [m], the mesh's static deformation (errors not taken off; a mesh with
    backlash: its half-gap included, which the teeth do not carry)."""
    half_gap: float
    """The dead zone's half-width g [m] (half the backlash; 0 without)."""
    force: np.ndarray
    """k(s) h(V q - e(s)) [N] (h the dead zone): the static mesh force over the cycle."""


def mesh_cycle(structure, q, e: int) -> MeshCycle | None:
    """Mesh element ``e``'s excitation over one mesh cycle at the static displacement
    ``q``: its stiffness table, the errors that repeat every mesh cycle and the force
    ``k(s) h(V q - e(s))``.  The force's harmonics are what drives a mesh-frequency line
    (the stiffness variation and the transmission error together: tip relief makes them
    cancel).  None without a table."""
    table = np.asarray(structure.stiffness_table[e], dtype=float)
    f_mesh = float(structure.frequency[e])
    if table.size < 2 or not f_mesh > 0:
        return None
    sl = slice(structure.v_ptr[e], structure.v_ptr[e + 1])
    d = float(np.dot(structure.v_coef[sl], q[structure.v_dof[sl]]))
    s = np.arange(table.size) / table.size  # mesh phase s = f t + phase (tables' grid)
    t = (s - float(structure.phase[e])) / f_mesh
    err = np.full(table.size, float(structure.error_constant[e]))
    for i in range(structure.error_ptr[e], structure.error_ptr[e + 1]):
        om = float(structure.error_omega[i])
        n = om / (2.0 * math.pi * f_mesh)
        if n > 0.5 and abs(n - round(n)) <= 1e-6 * n:  # periodic in the mesh cycle
            err += float(structure.error_amplitude[i]) * np.sin(
                om * t + float(structure.error_phase[i]))
    g = (float(structure.gap_values[structure.gap_ptr[e]])
         if structure.gap_ptr[e + 1] > structure.gap_ptr[e] else 0.0)
    x = d - err
    h = np.where(x > g, x - g, np.where(x < -g, x + g, 0.0)) if g > 0 else x
    return MeshCycle(phase=s, stiffness=table, error=err, deflection=d, half_gap=g,
                     force=table * h)


def _cycle_of(cycles: dict | None, structure, q, e: int) -> MeshCycle | None:
    """:func:`mesh_cycle` of element ``e``, kept in ``cycles`` (one structure and q)."""
    if cycles is None:
        return mesh_cycle(structure, q, e)
    if e not in cycles:
        cycles[e] = mesh_cycle(structure, q, e)
    return cycles[e]


def _mesh_force_harmonics(kin, structure, lines, q, cycles=None) -> dict:
    """(line label, order) -> amplitude of that harmonic of the static mesh force
    (:func:`mesh_cycle`) over its mean, the largest over the group's meshes:
    the stiffness harmonic and the transmission error's force taken together, with
    their phases (each alone overstates a modified pair's excitation)."""
    if structure is None or q is None:
        return {}

    def force(e):
        cyc = _cycle_of(cycles, structure, q, e)
        return None if cyc is None else cyc.force

    return _largest_harmonics(kin, structure, lines, force)


def _line_strength(kin, structure, lines, w_ref: float, q=None, cycles=None) -> dict:
    """(line label, order) -> how the model drives that line: ``stiffness_harmonic``
    (:func:`_stiffness_harmonics`), ``error_share`` / ``error_mesh``
    (:func:`_error_shares`) and, with the static deflection ``q``, ``force_harmonic``
    (:func:`_mesh_force_harmonics`: both together), the keys that apply."""
    out: dict = {}
    for key, v in _stiffness_harmonics(kin, structure, lines).items():
        out.setdefault(key, {})["stiffness_harmonic"] = v
    for key, (share, mesh) in _error_shares(kin, structure, lines, w_ref).items():
        out.setdefault(key, {}).update(error_share=share, error_mesh=mesh)
    for key, v in _mesh_force_harmonics(kin, structure, lines, q, cycles).items():
        out.setdefault(key, {})["force_harmonic"] = v
    return out


def _strength_of(strength: dict, label: str, order: int) -> dict:
    """How the model drives a crossing's line (:func:`_line_strength`), or nothing."""
    return dict(strength.get((label, order), {}))


#: a mesh line's force harmonic whose modal force is below this fraction of the sum
#: of its meshes' contributions drives the mode not at all (the meshes' forces cancel)
CANCELLED = 1e-6


def _modal_force_share(structure, q, shape, meshes, order: int,
                       cycles=None) -> float | None:
    """How much of the ``order``-th harmonic of the meshes' static forces reaches a mode
    (``shape``: its displacement part): |sum_m a_m| / sum_m |a_m| with
    a_m = F_m e^(2 pi i order phase_m) (V_m . conj(shape)), F_m that harmonic of mesh m's
    static force over its cycle (:func:`mesh_cycle`: its stiffness harmonic times
    its static deflection, plus its transmission error's force), phase_m its mesh phase.
    0 where the meshes' forces cancel on the mode (branches in phase on a mode where they
    move against each other, half a cycle apart on one where they move together); the
    planets' mesh phasing of Parker & Lin 2004 is a case of it.  None if no mesh of the
    line acts on the mode."""
    names = list(structure.element_names)
    n = structure.n_dof
    a = []
    for m in meshes:
        if m not in names:
            continue
        e = names.index(m)
        cyc = _cycle_of(cycles, structure, q, e)
        if cyc is None or order >= cyc.force.size // 2:
            continue
        f = cyc.force
        c = np.fft.rfft(f)[order] / f.size
        sl = slice(structure.v_ptr[e], structure.v_ptr[e + 1])
        # the projection on the mode is phi^H F: the complex whirl modes of a turning
        # carrier's frame (gyroscopic) take the conjugate (phi^T F measured the other
        # whirl: Lin & Parker N = 5, order 2 drives the backward whirl, which it called
        # cancelled, a planetary reviewer); a real mode is unchanged
        v = complex(np.dot(structure.v_coef[sl], np.conj(shape[:n][structure.v_dof[sl]])))
        a.append(c * np.exp(2j * np.pi * order * structure.phase[e]) * v)
    total = sum(abs(x) for x in a)
    if not total > 0:
        return None
    return float(abs(sum(a)) / total)


def _cancellation(structure, q, sol, groups: dict, crossing: dict, cycles=None) -> dict:
    """``stiffness_cancelled`` (and the share, :func:`_modal_force_share`) of a crossing
    of a mesh line whose force harmonic (stiffness and transmission error) would drive
    it, True where the meshes' forces cancel on the mode: a reviewer's Campbell
    diagram called six crossings of Ji & Li's drive driven that the two branches' mesh
    forces cannot excite, and 'run' warned of one at the drive's own speed."""
    meshes = groups.get(crossing["source"])  # (:func:`mesh_groups`)
    if not meshes or not ("stiffness_harmonic" in crossing or "force_harmonic" in crossing):
        return crossing
    # a degenerate mode's shape is any of its group's: judged on the whole group (the
    # largest share of its members), so that the solver's basis cannot hide a force
    f = np.asarray(sol.frequencies, dtype=float)
    i = crossing["mode"] - 1
    group = np.flatnonzero(np.abs(f - f[i]) <= 1e-6 * abs(f[i]))
    cycles = {} if cycles is None else cycles  # (the group's modes share the meshes')
    shares = [_modal_force_share(structure, q, sol.mode_shapes[:, j], meshes,
                                 crossing["order"], cycles) for j in group]
    known = [x for x in shares if x is not None]
    share = max(known) if known else None
    crossing["modal_force_share"] = share
    # cancelled also where the meshes' forces nearly cancel: what reaches the mode (the
    # harmonic times the share) is below a driving harmonic, although the harmonic alone
    # is not (the tutorial's three branches, one with a 15 um error: 35.5 % x 0.77 %,
    # a critical speed and a 'resonant' warning at 3425 rpm where the steady response
    # rises smoothly)
    harmonic = crossing.get("force_harmonic", crossing.get("stiffness_harmonic", 0.0))
    crossing["stiffness_cancelled"] = (share is None or share < CANCELLED
                                       or harmonic * share < DRIVING_HARMONIC <= harmonic)
    return crossing


class _Phasing:
    """Marks the crossings that the planets' mesh phasing leaves unexcited (Parker & Lin
    2004, :func:`torquesplit.modes.phased_stages`): ``suppressed`` True for a mode whose
    type the stage's mesh harmonic does not excite, with the mode's ``mode_type``; a model
    without such a stage gets neither key (its crossings are as before)."""

    def __init__(self, model, kin):
        from torquesplit.modes import phased_stages

        self.kin = kin
        self.stages = phased_stages(model, kin)
        self.groups = mesh_groups(kin)

    def types(self, structure, sol) -> dict[int, tuple[str | None, str | None]]:
        """1-based mode -> (type, whirl) (only for a model with a phased stage)."""
        if not self.stages:
            return {}
        from torquesplit.modes import classify

        return {r.mode: (r.type, r.whirl) for r in classify(structure, sol, kin=self.kin)}

    def mark(self, crossing: dict, types: dict[int, tuple[str | None, str | None]]) -> dict:
        meshes = self.groups.get(crossing["source"])
        if meshes:
            crossing["meshes"] = list(meshes)
        if not self.stages:
            return crossing
        from torquesplit.modes import phasing_suppresses

        kind, whirl = types.get(crossing["mode"], (None, None))
        crossing["mode_type"] = kind
        if whirl:
            crossing["whirl"] = whirl
        # suppressed when no mesh of the line's group excites the mode
        crossing["suppressed"] = bool(meshes) and all(phasing_suppresses(
            self.stages, m, crossing["order"], kind, whirl) for m in meshes)
        return crossing


def mode_kind(crossing: dict) -> str:
    """The crossing's mode type, with its whirl (``translational, forward whirl``)."""
    kind = str(crossing.get("mode_type"))
    return kind + (f", {crossing['whirl']} whirl" if crossing.get("whirl") else "")


def split_suppressed(crossings: list[dict]) -> tuple[list[dict], list[dict]]:
    """(critical, suppressed by mesh phasing) crossings."""
    return ([c for c in crossings if not c.get("suppressed")],
            [c for c in crossings if c.get("suppressed")])


HARMONIC_SHARE = 0.05
"""A mesh-frequency harmonic whose amplitude in the stiffness table is at least this share
of the fundamental's is an excitation line of the resonance map."""
MIN_ORDERS, MAX_ORDERS = 3, 10


def mesh_orders(table) -> int:
    """Highest mesh-frequency order worth a line: the last harmonic of the stiffness table
    (one mesh cycle) with HARMONIC_SHARE of the fundamental's amplitude, within
    [MIN_ORDERS, MAX_ORDERS] (a rectangular single/double contact wave of contact ratio
    1.6 has 9 % at the 7th; a constant stiffness gets the minimum)."""
    amp = np.abs(np.fft.rfft(np.asarray(table, dtype=float)))[1:MAX_ORDERS + 1]
    if amp.size == 0 or amp[0] <= 0:
        return MIN_ORDERS
    strong = np.flatnonzero(amp >= HARMONIC_SHARE * amp[0])
    return int(min(MAX_ORDERS, max(MIN_ORDERS, strong[-1] + 1)))


def strong_orders_beyond(table, top: int = MAX_ORDERS) -> tuple[int, float] | None:
    """(highest order, largest share) of the stiffness table's harmonics above ``top``
    with HARMONIC_SHARE of the fundamental's amplitude, or None: what :func:`mesh_orders`
    leaves off the map (a steep stiffness step keeps 5 % up to the 15th order and
    beyond)."""
    amp = np.abs(np.fft.rfft(np.asarray(table, dtype=float)))[1:]
    if amp.size <= top or amp[0] <= 0:
        return None
    share = amp[top:] / amp[0]
    strong = np.flatnonzero(share >= HARMONIC_SHARE)
    if strong.size == 0:
        return None
    return int(top + strong[-1] + 1), float(share.max())


def orders_left_out(kin, structure) -> list[str]:
    """A line per mesh-frequency group whose stiffness harmonics above MAX_ORDERS (the
    map's default cap) still carry HARMONIC_SHARE of the fundamental: the map leaves them
    out unless asked for more orders."""
    names = list(structure.element_names)
    out = []
    for label, group in mesh_groups(kin).items():
        found = [strong_orders_beyond(structure.stiffness_table[names.index(n)])
                 for n in group if n in names]
        found = [f for f in found if f is not None]
        if found:
            top = max(f[0] for f in found)
            share = max(f[1] for f in found)
            out.append(f"{label}: stiffness harmonics up to order {top} carry at least "
                       f"{100 * HARMONIC_SHARE:g} % of the fundamental (up to "
                       f"{100 * share:.3g} % above order {MAX_ORDERS}); the map draws orders "
                       f"1..{MAX_ORDERS}: ask for orders={top} (modes --campbell --orders "
                       f"{top}) to draw them")
    return out


def counted_points(ds) -> np.ndarray:
    """The points of a speed sweep its summaries count: the stable ones, or every point
    where stability was not computed (no ``stable`` variable)."""
    if "stable" in ds:
        return np.asarray(ds["stable"].values, bool)
    return np.ones(ds.sizes["point"], dtype=bool)


def mesh_groups(kin) -> dict[str, list[str]]:
    """Excitation-line label -> the meshes of one mesh frequency (one line stands for
    them all): ``mesh NAME`` for one, ``meshes a1..4, b1..4`` (:func:`names_label`) for
    several."""
    by_f: dict[float, list[str]] = {}
    for name, mk in kin.meshes.items():
        by_f.setdefault(round(mk.frequency, 9), []).append(name)
    return {(f"mesh {g[0]}" if len(g) == 1 else f"meshes {names_label(g)}"): g
            for g in by_f.values()}


def names_label(names) -> str:
    """Names with a common stem and numbered ends in short: ``a_planet1..4, b_planet1..4``
    (a run of consecutive numbers as first..last)."""
    import re

    stems: dict[str, list[int]] = {}
    plain: list[str] = []
    order: list[str] = []
    for n in names:
        m = re.fullmatch(r"(.*?)(\d+)", n)
        if m is None:
            plain.append(n)
            order.append(n)
            continue
        if m.group(1) not in stems:
            order.append(m.group(1))
        stems.setdefault(m.group(1), []).append(int(m.group(2)))
    out = []
    for key in order:
        if key in plain:
            out.append(key)
            continue
        nums = sorted(stems[key])
        run = nums == list(range(nums[0], nums[0] + len(nums)))
        out.append(f"{key}{nums[0]}..{nums[-1]}" if run and len(nums) > 2 else
                   ", ".join(f"{key}{k}" for k in nums))
    return ", ".join(out)


def _order_lines(kin, model, orders, structure=None):
    """(label, order, Hz per rad/s of input speed) of every excitation line: orders
    1..``orders`` of each mesh frequency (None: :func:`mesh_orders` of the mesh's table),
    and the rotation of every gear in the frame its translations are measured in (its
    speed relative to a turning carrier, as its eccentricity is applied and as the
    carrier-frame natural frequencies are: :func:`~torquesplit.model.kinematics.
    support_frame`)."""
    from torquesplit.model.kinematics import support_frame

    w_ref = reference_speed(model)
    lines = []
    names = list(structure.element_names) if structure is not None else []
    for label, group in mesh_groups(kin).items():
        top = orders
        if top is None:
            top = max(mesh_orders(structure.stiffness_table[names.index(n)])
                      if n in names else MIN_ORDERS for n in group)
        for h in range(1, top + 1):
            lines.append((label, h, kin.meshes[group[0]].frequency / w_ref))
    shafts = set()
    for b in kin.bodies:
        frame, f_rot, f_frame = support_frame(kin, b)
        key = round(f_rot or 0.0, 9)
        if key in shafts or not f_rot:
            continue
        shafts.add(key)
        where = f" relative to {frame}" if f_frame else ""
        lines.append((f"rotation of {b}{where}", 1, f_rot / w_ref))
    return lines


def campbell(model, start: float, stop: float, *, points: int = 41,
             orders: int | None = None, count: int | None = None):
    """Resonance (Campbell) map: natural frequencies against input speed [rad/s] with the
    mesh-frequency harmonics of every stage (orders 1..``orders``; None: those the
    stiffness table excites, :func:`mesh_orders`) and the shaft orders, and every crossing in
    the range as a critical speed with the mode's strain-energy shares.

    Natural frequencies are those of the model linearised about its static equilibrium
    (mean mesh stiffness); a model with speed-dependent terms (a gyroscopic matrix from
    a rotating frame) is re-assembled at each speed.  Returns ``(dataset, crossings)``:
    an :class:`xarray.Dataset` (dims ``speed``, ``mode``, ``line``; ``attrs``
    ``critical_speeds_rpm`` and ``critical_speed_labels``, and the crossings that the
    planets' mesh phasing suppresses apart) and the list of crossings as dicts (mode,
    frequency_Hz, order, source, speed_rpm, energy: the strain-energy shares), which
    :func:`torquesplit.save` writes by suffix as ``modes --campbell --out`` does.
    """
    import xarray as xr

    from torquesplit.solve.modal import modal_analysis

    points = whole(points, "points", "points=41", minimum=2)  # (0 failed inside xarray)
    if orders is not None:
        orders = whole(orders, "orders", "orders=3")
    if count is not None:  # (0 or less sliced the frequencies away, or from the end)
        count = whole(count, "count", "count=10")
    model, kin, s, _, _, static = _prepare(model, None, None)
    w_ref = reference_speed(model)
    lo, hi = sorted((_rad_per_s(start, "start"), _rad_per_s(stop, "stop")))  # (a map: the
    # range either way round, as sweep_speed takes it; from standstill as a map usually is)
    if not (lo >= 0 and hi > lo and math.isfinite(hi)):
        raise OptionError(f"the speed range {lo * RPM:.6g}..{hi * RPM:.6g} rpm must be two "
                          f"different speeds, the lower one 0 or more; e.g. from '0 rpm' to "
                          f"'3000 rpm' (--from, --to; in Python start=, stop=).")
    speeds = np.linspace(lo, hi, points)
    if s.n_gyroscopic:
        freqs = []
        for w in speeds:
            # (a model at standstill is refused: the frequencies at a millionth of the
            # model's speed stand for it)
            st = _structure_at(model, max(w / w_ref, 1e-6))
            freqs.append(modal_analysis(st, static.q).frequencies)
        nf = min(len(f) for f in freqs)
        F = np.array([f[:nf] for f in freqs])
    else:
        f = modal_analysis(s, static.q).frequencies
        F = np.tile(f, (points, 1))
    if count is not None:
        F = F[:, :count]
    crit = critical_speeds(s, static.q, kin, model, lo, hi, orders)
    lines = crit["lines"]
    L = np.array([[o * per * w for (_, o, per) in lines] for w in speeds])
    if s.n_gyroscopic:  # the frequencies move with speed: cross the curves themselves
        crit["crossings"] = _curve_crossings(model, static.q, speeds, F, lines, w_ref,
                                             crit["strength"])
    crossings = [c for c in crit["crossings"] if count is None or c["mode"] <= count]
    critical, suppressed = split_suppressed(crossings)
    ds = xr.Dataset(
        # (every variable with its long_name, as the sweep's: an exports reviewer)
        {"natural_frequency": (("speed", "mode"), F, {
            "units": "Hz", "long_name": "natural frequency (linearised about the static "
                                       "equilibrium, mean mesh stiffness)"}),
         "excitation_frequency": (("speed", "line"), L, {
             "units": "Hz", "long_name": "frequency of each excitation line (an order of a "
                                        "mesh or shaft frequency)"})},
        coords={"speed": ("speed", speeds, {"units": "rad/s", "long_name": "input speed"}),
                "speed_rpm": ("speed", speeds * RPM,
                              {"units": "rpm", "long_name": "input speed"}),
                "mode": np.arange(1, F.shape[1] + 1),
                "line": [f"{o} x {lab}" for lab, o, _ in lines]})
    ds.attrs["model"] = model.model.name
    ds.attrs["model_json"] = _model_json(model)  # (a saved map says what it is of)
    ds.attrs["model_speed_rpm"] = w_ref * RPM  # the drive's speed: the operating point
    label = lambda c: (f"mode {c['mode']} ({c['frequency_Hz']:.5g} Hz) x "  # noqa: E731
                       f"{c['order']} {c['source']}")
    _crossing_table(ds, crossings)
    ds.attrs["critical_speeds_rpm"] = [c["speed_rpm"] for c in critical]
    ds.attrs["critical_speed_labels"] = [_undriven(c, label(c)) for c in critical]
    left_out = orders_left_out(kin, s) if orders is None else []
    if left_out:
        ds.attrs["orders_left_out"] = left_out
    if suppressed:
        # crossings that the planets' mesh phasing leaves unexcited (Parker & Lin 2004)
        ds.attrs["suppressed_speeds_rpm"] = [c["speed_rpm"] for c in suppressed]
        ds.attrs["suppressed_speed_labels"] = [
            f"{label(c)} ({mode_kind(c)} mode: suppressed by mesh phasing)"
            for c in suppressed]
    return ds, crossings


def _crossing_table(ds, crossings: list[dict]) -> None:
    """The crossings as variables along a ``crossing`` dimension (a table of its own in
    a CSV export, arrays in MATLAB): a reviewer found the critical speeds only as text
    attributes, without their stiffness harmonic or whether the model drives them."""
    def col(key, default=math.nan):
        return np.array([c.get(key, default) if c.get(key) is not None else default
                         for c in crossings], dtype=float)

    ds.coords["crossing"] = np.arange(1, len(crossings) + 1)
    ds["crossing_speed_rpm"] = ("crossing", col("speed_rpm"),
                                {"units": "rpm", "long_name": "critical speed"})
    modes = col("mode")  # (whole numbers: 3, not 3.0, in a CSV; MATLAB gets doubles)
    ds["crossing_mode"] = ("crossing", modes.astype(np.int64) if np.isfinite(modes).all()
                           else modes, {"units": "1", "long_name": "mode number"})
    ds["crossing_frequency"] = ("crossing", col("frequency_Hz"),
                                {"units": "Hz", "long_name": "natural frequency"})
    ds["crossing_excitation"] = ("crossing", np.array(
        [f"{c['order']} x {c['source']}" for c in crossings], dtype=object),
        {"long_name": "excitation line: order x source"})
    ds["crossing_stiffness_harmonic"] = ("crossing", col("stiffness_harmonic"), {
        "units": "1", "long_name": "that harmonic of the mesh stiffness over its mean"})
    ds["crossing_error_share"] = ("crossing", col("error_share"), {
        "units": "1", "long_name": "error force k A on the line over the nominal force"})
    ds["crossing_force_harmonic"] = ("crossing", col("force_harmonic"), {
        "units": "1", "long_name": "that harmonic of the static mesh force k(s) (delta - "
        "e(s)) over its mean: stiffness variation and transmission error together"})
    ds["crossing_modal_force_share"] = ("crossing", col("modal_force_share"), {
        "units": "1", "long_name": "share of the meshes' harmonic forces that reaches the "
        "mode (0: they cancel on it)"})
    ds["crossing_driven"] = ("crossing", np.array(
        [int(driven(c) and not c.get("suppressed", False)) for c in crossings],
        dtype=np.int8), {
        "units": "1", "long_name": "1 if the model drives the crossing (a mesh force "
        "harmonic, or else a stiffness harmonic or error, of at least 1 % that reaches "
        "the mode)"})


def _curve_crossings(model, q, speeds, F, lines, w_ref, strength=None):
    """Crossings of the natural-frequency curves ``F`` (speeds x modes) with the
    excitation lines, located by linear interpolation between the speeds where their
    difference changes sign; the strain-energy shares from the modes at the crossing's
    speed (the frequencies of a turning frame depend on speed: the crossings of the
    model's-speed frequencies would be off by the frequencies' change)."""
    from torquesplit.solve.modal import modal_analysis

    from torquesplit.model.kinematics import solve_kinematics

    phasing = _Phasing(model, solve_kinematics(model))
    out = []
    for label, order, per_rad in lines:
        g = F - (order * per_rad * speeds)[:, None]
        for m in range(F.shape[1]):
            for i in np.flatnonzero(np.sign(g[:-1, m]) * np.sign(g[1:, m]) < 0):
                th = g[i, m] / (g[i, m] - g[i + 1, m])
                w = speeds[i] + th * (speeds[i + 1] - speeds[i])
                st = _structure_at(model, max(w / w_ref, 1e-6))
                sol = modal_analysis(st, q)
                out.append(_cancellation(st, q, sol, phasing.groups, phasing.mark(dict(
                    mode=m + 1, frequency_Hz=float(sol.frequencies[m]), order=order,
                    source=label, speed_rpm=float(w * RPM),
                    energy=sol.dominant_elements(m, 4, group_rtol=DEGENERATE_RTOL),
                    **_strength_of(strength or {}, label, order)), phasing.types(st, sol))))
    out.sort(key=lambda c: c["speed_rpm"])
    return out


def _structure_at(model, factor):  # the model at another speed (a turning carrier)
    from torquesplit.assembly.assemble import assemble
    from torquesplit.model.io import model_from_dict, model_to_json
    import json

    data = json.loads(model_to_json(model))
    for d in data.get("drives", {}).values():
        d["speed"] = float(d["speed"]) * factor if isinstance(d["speed"], (int, float)) \
            else d["speed"]
    return assemble(model_from_dict(data))


NEAR_CRITICAL = 0.01
"""A critical speed within this share of the model's speed is said
(:func:`near_critical_speeds`)."""
DRIVING_HARMONIC = 0.01
"""... when the harmonic of the mesh stiffness that drives it is at least this share of the
mean stiffness (a helical pair's high orders, 1e-4 and below, drive next to nothing)."""


def near_critical_notes(model, structure, q, kinematics, speed=None) -> list[str]:
    """:func:`near_critical_speeds` as ``"location: message"`` lines, a best effort (a
    model the Campbell map cannot take says nothing): what ``run`` (at the model's speed)
    and ``steady`` (at its own) print."""
    try:
        return [f"{loc}: {msg}" for loc, msg in near_critical_speeds(
            model, structure, q, kinematics, speed=speed)]
    except Exception:  # noqa: BLE001 - a note, never a reason to lose the results
        return []


def _undriven(crossing: dict, label: str) -> str:
    """A critical speed's label, marked where the model does not drive it (:func:`driven`:
    no harmonic of at least :data:`DRIVING_HARMONIC`, or the meshes' forces cancel on the
    mode): the speed sweep's figure numbered such crossings as any other (a reviewer)."""
    return label if driven(crossing) else f"{label} (not driven)"


def driven(crossing: dict, least: float = DRIVING_HARMONIC) -> bool:
    """Whether the model drives a crossing by at least ``least``: on a mesh line, the
    harmonic of its static mesh force (``force_harmonic``: the stiffness variation and
    the transmission error with their phases; a modification's relief can cancel the
    stiffness harmonic), where the meshes' forces do not cancel on the mode
    (``stiffness_cancelled``); without it (a shaft order) a stiffness harmonic or an
    error force (``stiffness_harmonic``, ``error_share``).  One it does not drive
    resonates only through what the model leaves out."""
    if "force_harmonic" in crossing:
        return (crossing["force_harmonic"] >= least
                and not crossing.get("stiffness_cancelled", False))
    return ((crossing.get("stiffness_harmonic", 0.0) >= least
             and not crossing.get("stiffness_cancelled", False))
            or crossing.get("error_share", 0.0) >= least)


def near_critical_speeds(model, structure, q, kinematics, within: float = NEAR_CRITICAL,
                         least_harmonic: float = DRIVING_HARMONIC,
                         speed: float | None = None) -> list[tuple[str, str]]:
    """The critical speeds (:func:`critical_speeds`: a mesh order or a shaft order
    meeting a natural frequency of the structure linearised about ``q``) within
    ``within`` of the model's own speed, driven by a stiffness harmonic of at least
    ``least_harmonic`` of the mean or by an error whose force amplitude ``k A`` is at least
    ``least_harmonic`` of the mesh's nominal force, as one ``(location, message)``
    warning naming the nearest: Ji & Li's drive runs at 745 rpm, 0.24 % above the
    critical speed where order 3 of its stage-2 mesh meets a support mode (71.45 Hz, the
    largest line of its support-force spectrum), and ``run`` said nothing of it.  The
    frequencies are those at the model's speed (a turning carrier's move by far less than
    ``within`` across the band).  ``speed`` [rad/s]: another input speed to judge (a
    steady state solved at one), default the model's.  Empty for a model without a
    speed."""
    w = reference_speed(model) if speed is None else float(speed)
    if not (w > 0 and math.isfinite(w)):
        return []
    crossings = critical_speeds(structure, q, kinematics, model, (1.0 - within) * w,
                                (1.0 + within) * w, None)["crossings"]
    # (a crossing the planets' mesh phasing leaves unexcited is none: Parker & Lin 2004)
    near = sorted((c for c in crossings if not c.get("suppressed")
                   and driven(c, least_harmonic)),
                  key=lambda c: abs(c["speed_rpm"] / (w * RPM) - 1.0))
    if not near:
        return []
    c = near[0]
    off = w * RPM / c["speed_rpm"] - 1.0
    top, share = c["energy"][0] if c["energy"] else ("-", math.nan)
    more = (f"; {len(near) - 1} more within {100 * within:.2g} % (torquesplit modes "
            f"--campbell lists them)" if len(near) > 1 else "")
    k_by = (f"a harmonic of {100 * c.get('stiffness_harmonic', 0.0):.2g} % of the mean mesh "
            f"stiffness" if c.get("stiffness_harmonic", 0.0) >= least_harmonic
            and not c.get("stiffness_cancelled", False) else "")
    e_by = (f"an error of mesh {c['error_mesh']} (k e = {100 * c['error_share']:.2g} % of "
            f"its nominal force)" if c.get("error_share", 0.0) >= least_harmonic else "")
    if "force_harmonic" in c and k_by and e_by:  # both: with their phases, not each alone
        by = [f"a harmonic of {100 * c['force_harmonic']:.2g} % of the static mesh force "
              f"k (delta - e), of its stiffness ({100 * c['stiffness_harmonic']:.2g} % "
              f"alone) and transmission error (k e {100 * c['error_share']:.2g} % alone) "
              f"together"]
    elif "force_harmonic" in c and not (k_by or e_by):
        by = [f"a harmonic of {100 * c['force_harmonic']:.2g} % of the static mesh force "
              f"k (delta - e)"]
    else:
        by = [x for x in (k_by, e_by) if x]
    return [("analysis", (
        f"the speed ({w * RPM:.5g} rpm) is {100 * abs(off):.2g} % "
        f"{'above' if off > 0 else 'below'} a critical speed ({c['speed_rpm']:.5g} rpm): "
        f"order {c['order']} of {c['source']} meets mode {c['mode']} "
        f"({c['frequency_Hz']:.5g} Hz, {100 * share:.0f} % of its strain energy in {top}), "
        f"driven by {' and '.join(by)}: the response there is resonant and sensitive to "
        f"small changes of speed or stiffness{more}"))]
