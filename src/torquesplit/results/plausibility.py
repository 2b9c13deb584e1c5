"""Plausibility of computed results: numbers that are possible but need a word.

A run can finish cleanly and still print numbers an engineer cannot put in a report:
a mesh loaded on its back flank at rest, tensile tooth forces in a mesh modelled without
backlash, a dynamic factor of 5.  Each check here returns ``(location, message)`` pairs
naming the model field to look at; :meth:`torquesplit.results.Results.warnings` collects
them with the model's own warnings and the run's, and the command line prints them, puts
them in ``--json`` (``warnings``) and in the results file's attributes.

=========================  ===========================================================
check                      says
=========================  ===========================================================
:func:`static_force`       a mesh whose static force is negative (loaded on its back
                           flank at rest: an error or a sign against the power flow)
:func:`static_deflection`  a static translation beyond half the module of its gear (a
                           stiffness far too small: a unit slip)
:func:`contact_loss`       drive flank separated (the teeth move inside the backlash)
:func:`back_flank`         back-flank contact; without backlash: double-flank contact,
                           tensile tooth force no real pair with backlash carries
:func:`damping_pull`       a tensile force on the working flank: the mesh damping pulls
                           while the teeth move apart (no contact can)
:func:`resonance`          dynamic factor above :data:`RESONANCE_FACTOR`: the run is near
                           a resonance (``torquesplit modes``)
:func:`settling`           the transient did not die out: the last half was used; or
                           the run is too short to tell
:func:`peak_drift`         settled peaks that still change from the first settled
                           window to the last by more than :data:`PEAK_DRIFT` (a slowly
                           decaying mode, or a response that never repeats)
:func:`mean_drift`         mean-force coefficients that differ between the two halves
                           of the settled part by more than :data:`MEAN_DRIFT` (slow
                           excitations whose common period is longer than the run)
:func:`coarse_history`     a decimated history (files, figures, bearing forces) that
                           misses the settled peak force by more than
                           :data:`HISTORY_MISS`: its waveform and the bearing peaks are
                           not the response's (the mesh metrics are streamed, unaffected)
=========================  ===========================================================
"""

from __future__ import annotations

import math

import numpy as np

#: a history whose largest settled force is this much below the streamed peak is too
#: coarse for the waveform (:func:`coarse_history`)
HISTORY_MISS = 0.05
#: ... or this much of the dynamic part of the peak (settled peak - static force), where
#: that part is at least DYNAMIC_PART of the peak: Ji & Li's default history missed 3 %
#: of the peak but 43 % of its dynamic increment, and its figures said nothing
HISTORY_MISS_DYNAMIC = 0.25
DYNAMIC_PART = 0.01
#: a dynamic factor (settled peak / the mesh's own static force) above this is reported
#: as "near a resonance"; gear standards' K_v rarely exceeds 2
RESONANCE_FACTOR = 3.0
#: time fractions below this (of the run) are rounding: not reported
FRACTION_FLOOR = 1e-4
#: settled peaks whose first and last settle windows differ by more than this (relative)
#: leave the third digit of the dynamic factor open: said (the settle criterion itself
#: accepts 1 %, what a transient's end looks like, not what a printed digit needs)
PEAK_DRIFT = 1e-3
#: mean-force coefficients of the two halves of the settled part that differ by more than
#: this (absolute) leave their third decimal to the run length: said
MEAN_DRIFT = 1e-3
#: a settled tensile force on the working flank below this share of the static force is
#: rounding, not a pull worth a word (:func:`damping_pull`)
PULL_FLOOR = 0.01


def _kn(force: float) -> str:
    return f"{force / 1e3:.4g} kN" if abs(force) >= 1e3 else f"{force:.4g} N"


def _pct(fraction: float) -> str:
    return f"{100 * fraction:.3g} %"


def static_force(results, metrics) -> list[tuple[str, str]]:
    """Meshes whose force at the static equilibrium is negative (or zero)."""
    out = []
    for r in metrics.rows:
        if r.static_force < 0:
            out.append((f"meshes.{r.mesh}", (
                f"the static force is {_kn(r.static_force)} (nominal {_kn(r.nominal_force)}): "
                f"at rest the mesh is loaded on its back flank, against the power flow, so "
                f"its load sharing and dynamic factor are not meaningful; check the errors "
                f"and backlash of this mesh and of its gears and their units (a '20 mm' for "
                f"'20 um' does this)")))
    return out


#: a mesh whose static force differs from its LTCA tables' load by more than this
#: fraction is said (the tables are those of another load)
LTCA_LOAD_MISMATCH = 0.1


def ltca_load(results, metrics) -> list[tuple[str, str]]:
    """Meshes with LTCA tables built at a load their static equilibrium does not carry:
    a planetary stage's meshes share one table load, the nominal equal share, while a
    pin error puts 45 % more on one planet (a reviewer's K_gamma 1.45, silently).  One
    message per table field (a stage's sun or ring mesh: all its planets' meshes)."""
    model, kin = results.model, results.kinematics
    off: dict[str, list] = {}
    for r in metrics.rows:
        mesh = model.meshes.get(r.mesh)
        if mesh is None or mesh.stiffness.method != "ltca":
            continue
        given = mesh.stiffness.ltca.load
        load = float(given if given is not None else kin.meshes[r.mesh].force)
        if load > 0 and abs(r.static_force / load - 1.0) > LTCA_LOAD_MISMATCH:
            where = model.written_at(f"meshes.{r.mesh}.stiffness.ltca.load")
            off.setdefault(where, []).append((r.mesh, r.static_force, load, given))
    out = []
    for where, rows in off.items():
        load, given = rows[0][2], rows[0][3]
        forces = [f for _, f, _, _ in rows]
        carried = (_kn(forces[0]) if len(rows) == 1 else
                   f"{_kn(min(forces))} to {_kn(max(forces))} "
                   f"({', '.join(m for m, _, _, _ in rows)})")
        fix = (f"give {where} = '{forces[0] / 1e3:.4g} kN'" if len(rows) == 1 else
               f"one {where} serves every planet's mesh of the stage: give the load of "
               f"the planet whose peak matters (the most loaded: "
               f"'{max(forces) / 1e3:.4g} kN'); per-planet tables are not supported")
        loc = f"meshes.{rows[0][0]}" if len(rows) == 1 else where.rsplit(".stiffness", 1)[0]
        out.append((loc, (
            f"LTCA stiffness and transmission error are tables at {_kn(load)} "
            f"({'given' if given is not None else 'the nominal load'}), but the static "
            f"equilibrium puts {carried} on the mesh: the tables are those of another "
            f"load; {fix}")))
    return out


def static_deflection(results, metrics) -> list[tuple[str, str]]:
    """:func:`~torquesplit.model.checks.deflection_warnings` of a run's static
    equilibrium."""
    from ..model.checks import deflection_warnings

    return deflection_warnings(results.model, results.structure, results.static.q)


def contact_lost(row) -> bool:
    """Whether a mesh row loses contact in the settled response: separated more than
    FRACTION_FLOOR of the run, and a settled smallest force that is not positive (a
    separated mesh carries none; a loss in the start-up transient alone leaves it
    positive).  A study's case status ``contact_lost`` follows it."""
    return row.contact_loss > FRACTION_FLOOR and not row.min_force > 0.0


def contact_loss(results, metrics) -> list[tuple[str, str]]:
    """Meshes whose drive flanks separate (inside the backlash) during the run: in the
    settled response (:func:`contact_lost`), or in the start-up transient only."""
    out = []
    for r in metrics.rows:
        if r.contact_loss <= FRACTION_FLOOR:
            continue
        periodic = getattr(results, "periodic", False)  # a steady state: no start-up
        span = "of the periodic state" if periodic else "of the whole run, start-up included"
        if contact_lost(r) or periodic:
            out.append((f"meshes.{r.mesh}", (
                f"contact loss {_pct(r.contact_loss)} {span}: the teeth separate "
                f"(backlash larger than the dynamic deflection), so peak forces are impacts "
                f"and its load-sharing coefficient is not meaningful; check "
                f"meshes.{r.mesh}.backlash and the excitation")))
        else:
            out.append((f"meshes.{r.mesh}", (
                f"contact loss {_pct(r.contact_loss)} of the whole run, in the start-up "
                f"transient only: the settled response's smallest force is positive "
                f"({_kn(r.min_force)}), so the start from the static equilibrium is what "
                f"separates the teeth")))
    return out


def back_flank(results, metrics) -> list[tuple[str, str]]:
    """Back-flank contact: with backlash the teeth rattle through it; without backlash the
    mesh is in double-flank contact and carries tensile force."""
    from . import back_flank_force

    out = []
    c_min = None
    for r in metrics.rows:
        if r.back_contact <= FRACTION_FLOOR:
            continue
        if c_min is None:  # the fraction counts the whole run: so does the force named here
            c_min = results.complete_cycle_statistics()[1]
        largest = back_flank_force(c_min[:, results.mesh_names.index(r.mesh)])
        if getattr(results, "periodic", False):  # a steady state: no start-up
            span = "of the periodic state"
            when = ""
        else:
            span = "over the whole run, start-up included"
            # (a force that stays compressive says nothing of when the deflection
            # reversed: the settled part's smallest force is then always >= 0)
            when = (" (in the start-up transient only: the settled part has none)"
                    if r.min_force >= 0 and largest > 0 else "")
        if largest <= 0:  # deflection reversed, force still compressive (damping)
            out.append((f"meshes.{r.mesh}", (
                f"the mesh deflection is reversed {_pct(r.back_contact)} of the time "
                f"{span}, "
                f"the force staying compressive only through the damping: a real pair "
                f"{'with backlash ' if r.double_flank else ''}would be about to lose contact "
                f"there; check meshes.{r.mesh}.backlash and the excitation")))
            continue
        if r.double_flank:
            out.append((f"meshes.{r.mesh}", (
                f"double-flank contact {_pct(r.back_contact)} of the time and back-flank "
                f"force up to {_kn(largest)} {span}{when}: "
                f"the mesh has no backlash, so the model lets it carry "
                f"tension, which a real pair with backlash cannot; give "
                f"meshes.{r.mesh}.backlash its real value (e.g. '100 um') or read its peak "
                f"and load sharing as those of a double-flank (anti-backlash) mesh")))
        else:
            out.append((f"meshes.{r.mesh}", (
                f"back-flank contact {_pct(r.back_contact)} of the time and back-flank force "
                f"up to {_kn(largest)} {span}{when}: the "
                f"teeth rattle through the backlash; peak forces are "
                f"impacts and the load sharing is not meaningful; check the excitation "
                f"and meshes.{r.mesh}.backlash")))
    return out


def damping_pull(results, metrics) -> list[tuple[str, str]]:
    """Meshes whose settled force turns tensile on the working flank (no back-flank
    contact): the viscous mesh damping outweighs the elastic force while the teeth move
    apart, a pull that a contact cannot exert (the Kelvin-Voigt mesh law of the papers
    allows it)."""
    out = []
    for r in metrics.rows:
        if r.back_contact > FRACTION_FLOOR or not r.min_force < 0:
            continue  # (back-flank contact: said by back_flank)
        nominal = abs(r.static_force) or abs(r.nominal_force) or 1.0
        if -r.min_force <= PULL_FLOOR * nominal:
            continue
        out.append((f"meshes.{r.mesh}", (
            f"the settled tooth force goes down to {_kn(r.min_force)} on the working flank "
            f"(no back-flank contact): the mesh damping outweighs the elastic force while "
            f"the teeth move apart, a pull a real contact cannot exert; its smallest force "
            f"and the history there are those of the viscous mesh model (a real pair would "
            f"just lose contact); check meshes.{r.mesh}.damping_ratio and the excitation")))
    return out


def resonance(results, metrics) -> list[tuple[str, str]]:
    """Meshes whose dynamic factor exceeds :data:`RESONANCE_FACTOR`."""
    out = []
    kin = results.kinematics  # (a steady state's: at the speed it was solved at)
    for r in metrics.rows:
        if math.isfinite(r.dynamic_factor) and r.dynamic_factor > RESONANCE_FACTOR:
            f = kin.meshes[r.mesh].frequency
            out.append((f"meshes.{r.mesh}", (
                f"dynamic factor {r.dynamic_factor:.3g} (settled peak {_kn(r.peak_force)} / "
                f"static {_kn(r.static_force)}): the run is near a resonance (mesh "
                f"frequency {f:.5g} Hz); see `torquesplit modes` for the natural "
                f"frequencies and the elements that carry them, and check the stiffnesses "
                f"and inertias of those elements")))
    return out


def _longest_need(results, meshes: dict, windows: int):
    """The mesh of ``meshes`` (mesh -> (its cycles, its window W)) that needs the longest
    run for ``windows`` windows of whole cycles and one more (the run's start cuts a
    cycle of a mesh that does not start at phase 0: --cycles 40 completed 39, and the
    advice asked for the 40 it had): (mesh, its cycles, W, cycles needed, seconds)."""
    kin = results.kinematics
    need = {m: (windows * w + 1) / kin.meshes[m].frequency for m, (_, w) in meshes.items()}
    m = max(need, key=need.get)
    n, w = meshes[m]
    return m, n, w, windows * w + 1, need[m]


def settling(results, metrics) -> list[tuple[str, str]]:
    """A transient that did not settle by the end of the run."""
    if metrics.settling.settled:
        return []
    if metrics.settling.short:  # too short to tell: name the mesh that needs the longest run
        m, n, w, cycles, seconds = _longest_need(results, metrics.settling.short, 2)
        return [("analysis", (
            f"the run is too short to tell whether the response has settled: mesh {m} "
            f"completes {n} cycle{'' if n == 1 else 's'}, fewer than two settle windows of "
            f"{w} cycles (a window spans at least 20 cycles and the longest excitation "
            f"period, e.g. a gear revolution when errors turn with the gears; a cycle the "
            f"start or the end cuts does not count), so the metrics may not average over "
            f"whole excitation periods; simulate at least {seconds:.3g} s ({cycles} "
            f"cycles of {m}) plus the transient"))]
    if metrics.settling.shrunk:  # windows shorter than the excitation period
        m, n, w, cycles, seconds = _longest_need(results, metrics.settling.shrunk, 4)
        return [("analysis", (
            f"the run is too short to tell whether the response has settled: mesh {m} "
            f"completes {n} cycles, fewer than four settle windows of {w} cycles, so its "
            f"windows shrank below the longest excitation period (e.g. a gear revolution "
            f"when errors turn with the gears) and the response's own variation over that "
            f"period cannot be told from a transient; the last half of the run was used "
            f"for the metrics; simulate at least {seconds:.3g} s ({cycles} cycles of "
            f"{m}) plus the transient"))]
    return [("analysis", (
        "the transient did not die out within the run (the peaks still drift), so the last "
        "half of the run was used for the metrics; simulate longer (--cycles or --duration; "
        "cycles= or duration= in Python) "
        "or add damping"))]


def _mesh_beat(results) -> float | None:
    """Frequency [Hz] of the common period of the meshes' stiffness cycles (the beat of
    two stages: Ji & Li's stage-1 peaks repeat every 168 of its cycles), None where the
    meshes have no common period within 10^5 cycles of the fastest."""
    from fractions import Fraction

    meta = getattr(results, "_mesh_meta", None)
    if meta is None:
        return None
    f = [float(meta[m]["frequency"]) for m in results.mesh_names]
    f = [x for x in f if x > 0]
    if not f:
        return None
    top = max(f)
    num, den = 0, 1
    for x in f:
        r = Fraction(x / top).limit_denominator(10**6)
        if abs(float(r) - x / top) > 1e-9 * x / top:
            return None
        num = math.gcd(num * r.denominator, r.numerator * den)
        den *= r.denominator
        g = math.gcd(num, den)
        num, den = num // g, den // g
    return top * num / den if den / num <= 1e5 else None


def peak_drift(results, metrics) -> list[tuple[str, str]]:
    """Settled per-cycle peaks that still differ between the first and the last window
    of the settled part (each mesh's settle window, the longest excitation period at
    least, widened to the meshes' common period: the peaks of one stage's cycles beat
    with the other stage's; a mesh whose settled part holds fewer than two windows is
    not judged): a lightly damped mode
    still decaying, or a response that does not repeat.  The dynamic factor and the
    peak-based coefficients take the largest settled peak, so they carry that
    difference; one message, for the mesh where it is largest.  None for a periodic
    steady state (its record repeats one period: nothing decays)."""
    if not metrics.settling.settled or getattr(results, "periodic", False):
        return []  # (not settled: said by `settling`)
    c_max = results.complete_cycle_statistics()[0]
    beat = _mesh_beat(results)
    worst = None
    for j, (m, w) in enumerate(zip(results.mesh_names, results.settle_windows())):
        p = c_max[metrics.settling.first_cycle[m]:, j]
        p = p[np.isfinite(p)]
        if beat:
            w = max(w, math.ceil(float(results._mesh_meta[m]["frequency"]) / beat - 1e-9))
        if p.size < 2 * w:
            continue
        first, last = float(p[:w].max()), float(p[-w:].max())
        if last <= 0:
            continue
        change = (last - first) / last
        if abs(change) > PEAK_DRIFT and (worst is None or abs(change) > abs(worst[1])):
            worst = (m, change, first, last)
    if worst is None:
        return []
    m, change, first, last = worst
    row = next(r for r in metrics.rows if r.mesh == m)
    alone = (f"; the last window alone gives {last / row.static_force:.4g}"
             if row.static_force > 0 else "")
    return [(f"meshes.{m}", (
        f"the settled peaks are not steady: the largest force of the first settled window "
        f"is {_kn(first)}, of the last {_kn(last)} ({100 * change:+.2g} %): a lightly "
        f"damped mode still decaying, or a response that does not repeat (impacts); the "
        f"dynamic factor ({row.dynamic_factor:.4g}) and the peak-based coefficients take "
        f"the largest settled peak{alone}; for the steady-state values solve the periodic "
        f"state (`torquesplit steady`)"))]


def mean_force_halves(results, metrics) -> dict[str, tuple[float, float]]:
    """Group -> its mean-force coefficient (Dong et al. 2021 eq. 12: the largest member's
    N F_i / sum F_j of the mean forces) over the first and over the second half of each
    member's settled cycles; groups of one mesh, or too few settled cycles, left out."""
    _, _, c_mean, c_cnt, _ = results.complete_cycle_statistics()
    col = {m: j for j, m in enumerate(results.mesh_names)}
    out = {}
    for g, members in metrics.load_sharing.groups.items():
        halves = []
        for m in members:
            k0, j = metrics.settling.mean_first[m], col[m]  # (the coefficients' span)
            done = np.flatnonzero(c_cnt[:, j] > 0)
            end = int(done[-1]) + 1 if done.size else k0
            mid = k0 + (end - k0) // 2
            if mid - k0 < 2:
                break
            halves.append([float(np.sum(np.nan_to_num(c_mean[a:b, j]) * c_cnt[a:b, j])
                                 / max(np.sum(c_cnt[a:b, j]), 1)) for a, b in
                           ((k0, mid), (mid, end))])
        if len(halves) != len(members) or len(members) < 2:
            continue
        h = np.asarray(halves)  # (members, 2)
        out[g] = tuple(float(np.max(len(members) * h[:, i] / h[:, i].sum())) for i in (0, 1))
    return out


def mean_drift(results, metrics) -> list[tuple[str, str]]:
    """Mean-force coefficients (Dong et al. 2021 eq. 12) that differ between the first and
    the second half of the settled part (:func:`mean_force_halves`): the mean forces still
    change over the run (errors turning with different shafts beat over a common period
    longer than the run), so the coefficient depends on where the run ends.  One message,
    for the group where the halves differ most.  None for a periodic steady state."""
    if metrics.definition != "mean_force" or getattr(results, "periodic", False):
        return []
    worst = None
    for g, coef in mean_force_halves(results, metrics).items():
        change = abs(coef[1] - coef[0])
        if change > MEAN_DRIFT and (worst is None or change > worst[1]):
            worst = (g, change, coef)
    if worst is None:
        return []
    g, change, (a, b) = worst
    return [("analysis", (
        f"the mean-force coefficient of {g} is {metrics.load_sharing.per_group[g]:.4g} over "
        f"the settled part, {a:.4g} over its first half and {b:.4g} over its second: the "
        f"mean forces still change over the run (slow excitations, e.g. errors turning "
        f"with different shafts, whose common period is longer than the run), so its "
        f"digits beyond the change ({change:.2g}) depend on the run length; simulate much "
        f"longer and compare"))]


def coarse_history(results, metrics) -> list[tuple[str, str]]:
    """The history (saved to files, drawn in the figures) against the settled peak and
    smallest force the integrator streams at every step and at the tables' corners:
    where its largest settled sample falls short of the peak, or its smallest stays above
    the smallest force, by more than :data:`HISTORY_MISS` of the peak (or
    :data:`HISTORY_MISS_DYNAMIC` of the swing from the static force), its waveform is not
    the response's (the force range matters for fatigue: Ji & Li's default history stayed
    6 kN above the smallest force, silently).  One message, for the mesh and extreme it
    misses most, with the advice that fits: more samples of a decimated history; a finer
    step where it keeps every step already (the extreme then falls at a table corner
    inside a step, where RK4 splits the step, or between two steps); more steps per cycle
    of a periodic steady state."""
    if results.solution is None or not results.solution.history_t.size:
        return []
    t, forces = results.mesh_force_history()
    if t.size < 2:
        return []
    worst = None
    for j, row in enumerate(metrics.rows):
        group = row.group if row.group in metrics.settling.group_time else None
        start = results.history_start(metrics, group)
        seen = forces[t >= start, j]
        seen = seen[np.isfinite(seen)]
        if not (seen.size and row.peak_force > 0 and math.isfinite(row.peak_force)):
            continue
        # (kind, how far the history falls short of what the run streamed, the history's
        # extreme, the streamed one, the swing from static); one-sided: the history can
        # pass the streamed extremes, which are over complete cycles only (its end may hold
        # part of one: Dong et al. 2021's m58 at 40 cycles, 170 kN against 153 kN)
        for kind, short, shown, streamed, swing in (
                ("peak", row.peak_force - float(seen.max()), float(seen.max()), row.peak_force,
                 row.peak_force - row.static_force),
                ("smallest", float(seen.min()) - row.min_force, float(seen.min()),
                 row.min_force, row.static_force - row.min_force)):
            if not (math.isfinite(streamed) and short > 0.0):
                continue
            miss = short / row.peak_force
            of_swing = short / swing if swing > DYNAMIC_PART * row.peak_force else 0.0
            if ((miss > HISTORY_MISS or of_swing > HISTORY_MISS_DYNAMIC)
                    and (worst is None or miss > worst[1])):
                worst = (row.mesh, miss, shown, streamed, of_swing, kind)
    if worst is None:
        return []
    m, miss, seen, streamed, of_swing, kind = worst
    per = results.history_samples_per_period() or math.nan
    swing = (f", {100 * of_swing:.2g} % of its "
             f"{'rise above' if kind == 'peak' else 'dip below'} the static force"
             if of_swing > HISTORY_MISS_DYNAMIC else "")
    missed = (f"misses the settled peak force of mesh {m} by {100 * miss:.2g} % "
              f"({_kn(seen)} against {_kn(streamed)}{swing})" if kind == "peak" else
              f"misses the settled smallest force of mesh {m} by {100 * miss:.2g} % of its "
              f"peak ({_kn(seen)} against {_kn(streamed)}{swing})")
    exact = ("The mesh table's forces, load sharing and dynamic factors (and peak_force in "
             "the files) include every step and the instants between them")
    if getattr(results, "steady", None) is not None:
        return [("analysis", (
            f"the saved waveform of the periodic state ({per:.3g} samples per shortest "
            f"mesh period), which the results files and the figures hold, {missed}: the "
            f"extreme falls between its samples, at a corner of a stiffness table or between "
            f"kept steps.  {exact}; the waveform and the bearing forces do not.  More "
            f"--steps-per-cycle (Python: steps_per_cycle=) brings the waveform closer"))]
    if results.history_keeps_every_step():
        from ..simulation import AUTO_HISTORY_RECORDS
        from ..solve.integrate import finer_step_advice

        s = results.solution
        return [("analysis", (
            f"the history keeps every RK4 step, yet {missed}: that extreme falls inside a "
            f"step, at a corner of a stiffness table, which the mesh table's numbers (and "
            f"peak_force, min_force in the files) include and the history (files, "
            f"figures{'' if streamed_peaks(results) else BEARING_PEAK}) does not; "
            f"a finer step brings it closer "
            f"({finer_step_advice(results.structure, s.step_limited_by, s.step or 0.0)}), "
            f"kept whole in the history with as many --samples-per-period "
            f"(samples_per_period=; a long run's history keeps every step only up to "
            f"{AUTO_HISTORY_RECORDS:,} of them)"))]
    more = max(100, 5 * round(per)) if math.isfinite(per) else 100
    streamed = streamed_peaks(results)
    return [("analysis", (
        f"the history ({per:.3g} samples per shortest mesh period), which the results "
        f"files and the figures hold, {missed}: the response is faster "
        f"than its sampling and the saved waveform is not the response's.  The mesh "
        f"table's forces, load sharing and dynamic factors"
        f"{STREAMED_TOO if streamed else ''} are streamed at every "
        f"step and unaffected; "
        f"{'for waveforms' if streamed else BEARING_HISTORY}, run again with "
        f"--samples-per-period {more} (Python: samples_per_period={more})"))]


BEARING_PEAK = ", the bearing table's peak |F|"
STREAMED_TOO = ", and the bearing table's peaks,"
BEARING_HISTORY = ("the bearing table is computed from this history, so its peak |F| can "
                   "be low too; for waveforms and bearing peaks")


def streamed_peaks(results) -> bool:
    """Whether the run streamed the bearing table's peaks at every step (``integrate``'s
    ``history_peaks``), or they come from the history's samples."""
    s = results.solution
    return s is not None and s.history_peaks is not None


def harmonic_truncation(results, metrics) -> list[tuple[str, str]]:
    """A harmonic-balance steady state whose series is cut short: its top quarter of
    harmonics holds more of the velocity energy than an adaptive solve accepts
    (:data:`torquesplit.steady.solution.ENERGY_TOL`).  With a fixed count (--harmonics
    --fixed) 16 harmonics of Ji & Li's stage 1 gave dynamic factors 1.6 % low and two
    symmetric meshes different factors, with nothing said."""
    steady = getattr(results, "steady", None)
    ps = getattr(steady, "solution", None)
    if ps is None or ps.method != "hb" or not ps.converged:
        return []
    from ..steady.solution import ENERGY_TOL

    # against the limit the solve was given (a looser energy_tol asked for is not
    # contradicted), the library's where none was
    limit = max(ENERGY_TOL, float(getattr(steady, "options", {}).get("energy_tol")
                                  or ENERGY_TOL))
    top = ps.top_harmonic_energy
    if not (math.isfinite(top) and top > limit):
        return []
    return [("analysis", (
        f"harmonic balance with {ps.harmonics} harmonics: the top quarter of them holds "
        f"{top:.2g} of the velocity energy (a converged series: below {limit:g}; the "
        f"time-domain residual is {ps.time_residual:.2g}), so the series is cut short and "
        f"the peaks and dynamic factors can be off by percent; let the harmonics double "
        f"(--adaptive, the default without --harmonics; adaptive=True in Python) or solve "
        f"by shooting (--method shooting; method='shooting')"))]


#: every check, in the order the messages are listed
CHECKS = (static_force, ltca_load, static_deflection, contact_loss, back_flank, damping_pull,
          resonance, settling, peak_drift, mean_drift, coarse_history, harmonic_truncation)


def result_warnings(results, metrics, *, history: bool = True) -> list[tuple[str, str]]:
    """Every plausibility warning of a finished run, as ``(location, message)``;
    ``history=False`` leaves out :func:`coarse_history` (a study's case: nothing it
    reports comes from the history)."""
    out: list[tuple[str, str]] = []
    for check in CHECKS:
        if history or check is not coarse_history:
            out += check(results, metrics)
    return out


def static_warnings(results) -> list[tuple[str, str]]:
    """Warnings of a quasi-static sweep: positions that did not converge, meshes loaded
    on their back flank."""
    import numpy as np

    from ..model.checks import deflection_warnings

    sol = results.solution
    conv = np.asarray(sol.converged, bool)
    q = np.asarray(sol.q, dtype=float)
    out = deflection_warnings(results.model, results.structure,
                              q[conv][np.argmax(np.abs(q[conv]).max(axis=1))] if conv.any()
                              else np.zeros(q.shape[1]))
    if getattr(sol, "interrupted", False):
        out.append(("analysis", (
            f"stopped by Ctrl-C after {conv.size} of {sol.planned} positions: the load "
            f"sharing and orbits cover only the positions done; run it again to the end "
            f"(or give fewer --revolutions, revolutions= in Python) for the whole "
            f"period")))
    if conv.size and not conv.all():
        out.append(("analysis", (
            f"{int((~conv).sum())} of {conv.size} positions did not converge and are left "
            f"out of the load sharing; check the clearances and supports (a member free "
            f"inside its clearance needs a support or a spring)")))
    forces = results.mesh_forces()
    for j, m in enumerate(results.mesh_names):
        fmin = float(np.nanmin(forces[conv, j])) if conv.any() else math.nan
        if fmin < 0:
            st = results.structure
            e = st.element_names.index(m)
            gap = float(np.max(st.gap_values[st.gap_ptr[e]:st.gap_ptr[e + 1]], initial=0.0))
            note = ("; without backlash its teeth pull (double-flank contact), and the "
                    "load-sharing coefficients count that pull (a planet's factor can then "
                    "exceed the number of planets): give the backlash" if gap <= 0 else "")
            out.append((f"meshes.{m}", (
                f"the quasi-static force reaches {_kn(fmin)}: the mesh is loaded on its back "
                f"flank at some positions, against the power flow; check the errors and "
                f"backlash of this mesh and their units{note}")))
    return out
