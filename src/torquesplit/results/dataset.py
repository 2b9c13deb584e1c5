"""Conversion of :class:`~torquesplit.results.Results` to an :class:`xarray.Dataset`."""

from __future__ import annotations

import json
import math

import numpy as np
import xarray as xr

from .. import _json
from ..assembly.structure import element_units
from ..errors import OptionError


def _var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, np.asarray(data), attrs={"units": units, "long_name": long_name,
                                                      **attrs})


#: a 0/1 variable's CF flag attributes: a MATLAB file makes it a logical
#: (:func:`torquesplit.results.export.mat_fields`)
FLAG = {"flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "false true"}


def is_flag(attrs) -> bool:
    """Whether a variable's attributes mark it a 0/1 flag (:data:`FLAG`)."""
    return np.ravel(attrs.get("flag_values", [])).tolist() == [0, 1]


def add_planet_load_sharing(ds: xr.Dataset, load_sharing, kinematics) -> xr.Dataset:
    """``ds`` with the planet load-sharing factor of a planetary model (nothing for other
    models): ``planet_load_sharing`` over ``planet_entity`` (each carrier's K_gamma, then
    each planet's factor), a quasi-static sweep's ``planet_peak_instantaneous_ratio``
    beside it, and the ``--json`` entry as the attribute ``planet_load_sharing_json``."""
    from ..cli_support import planet_sharing, planet_sharing_dict

    k = planet_sharing(load_sharing, kinematics)
    if k is None:
        return ds
    names = [*k.per_stage, *k.per_planet]
    what = "K_gamma of each stage (carrier: largest planet load over the mean, AGMA 6123 / " \
           "ISO 6336-1) and each planet's factor"
    ds = ds.assign_coords(planet_entity=("planet_entity", names))
    basis = " (loads averaged over the mesh positions)" if k.peak_per_stage else ""
    ds["planet_load_sharing"] = _var(
        ("planet_entity",), [{**k.per_stage, **k.per_planet}[n] for n in names], "1",
        f"{what}, {k.definition}{basis}")
    if k.peak_per_stage:
        peak = {**k.peak_per_stage, **k.peak_per_planet}
        ds["planet_peak_instantaneous_ratio"] = _var(
            ("planet_entity",), [peak[n] for n in names], "1",
            "largest instantaneous ratio over the mesh positions (Mo et al. 2017), not "
            "K_gamma")
    ds.attrs["planet_load_sharing_json"] = _json.dumps(planet_sharing_dict(k), default=float)
    return ds


def element_frames(res, names: list[str]) -> list[str]:
    """Frame of each recorded element force (see the ``element_frame`` coordinate)."""
    from ..model.kinematics import frame_label, support_frame

    out = []
    for name in names:
        body, sep, _ = name.partition(".support.")
        if not sep:
            out.append("")
            continue
        carrier, _, f_frame = support_frame(res.kinematics, body)
        out.append(frame_label(carrier if f_frame else None))
    return out


CUT = " (NaN: a cycle cut by the start or the end of the run)"
#: the variable of the bearings' largest force magnitude per history interval (files
#: before 2026-11-30 called it bearing_force_peak)
INTERVAL_PEAK = "bearing_interval_peak_force"


def results_to_dataset(res, definition: str | None = None) -> xr.Dataset:
    """Histories, per-cycle statistics, static and nominal forces, metrics (of
    ``definition``, default the model's), warnings, run info.

    The file holds everything :func:`results_from_dataset` needs to give back a
    :class:`~torquesplit.results.Results` with the same metrics (``torquesplit report
    RESULTS.nc``)."""
    s = res.solution
    st = res.structure
    meshes = res.mesh_names
    el = st.element_names
    hist_names = [el[i] for i in s.history_elements]
    all_units = element_units(st)
    hist_units = [all_units[i] for i in s.history_elements]
    mesh_cols = [list(s.tracked_elements).index(el.index(m)) for m in meshes]
    # a cycle cut by the start or the end of the run holds part of a cycle: emptied
    c_max, c_min, c_mean, _, c_ratio = (a.copy() for a in res.complete_cycle_statistics())
    ratio_min = np.where(res.complete_cycles, s.cycle_ratio_min[:, mesh_cols], np.nan)
    ds = xr.Dataset(
        data_vars={
            # (copies: the run's own arrays are read-only, and a Dataset is the user's to
            # change in place, ds["element_force"] /= 1e3)
            "element_force": _var(("time", "element"), s.history_forces.copy(),
                                  "N" if set(hist_units) <= {"N"} else "N or N m",
                                  "element force"),
            "cycle_start": _var(("cycle", "mesh"), s.cycle_start[:, mesh_cols], "s",
                                "start time of each mesh cycle"),
            "cycle_max_force": _var(("cycle", "mesh"), c_max, "N",
                                    "largest mesh force in each mesh cycle" + CUT),
            "cycle_min_force": _var(("cycle", "mesh"), c_min, "N",
                                    "smallest mesh force in each mesh cycle" + CUT),
            "cycle_mean_force": _var(("cycle", "mesh"), c_mean, "N",
                                     "mean mesh force in each mesh cycle" + CUT),
            "cycle_count": _var(("cycle", "mesh"), s.cycle_count[:, mesh_cols], "1",
                                "integration states in each mesh cycle"),
            "cycle_ratio_max": _var(("cycle", "mesh"), c_ratio, "1",
                                    "largest instantaneous load-sharing ratio in each mesh "
                                    "cycle" + CUT),
            "cycle_ratio_min": _var(("cycle", "mesh"), ratio_min, "1",
                                    "smallest instantaneous load-sharing ratio in each mesh "
                                    "cycle" + CUT),
            "nominal_force": _var(("mesh",), [res.kinematics.meshes[m].force for m in meshes],
                                  "N", "equal-split nominal tooth force"),
            "static_force": _var(("mesh",), list(res.static_forces().values()), "N",
                                 "mesh force at static equilibrium"),
            "mesh_frequency": _var(("mesh",), [res.kinematics.meshes[m].frequency
                                               for m in meshes], "Hz", "mesh frequency"),
            "static_displacement": _var(("dof",), np.array(res.static.q), "m or rad",
                                        "static equilibrium displacement"),
            "contact_loss_fraction": _var(("element",),
                                          s.separation_fraction[list(s.history_elements)], "1",
                                          "fraction of the whole run (start-up included) with "
                                          "the element inside its dead zone (drive flank "
                                          "separated)"),
            "back_contact_fraction": _var(("element",),
                                          s.back_contact_fraction[list(s.history_elements)],
                                          "1", "fraction of the whole run (start-up included) "
                                          "in back-flank contact (mesh without backlash: "
                                          "tensile force)"),
        },
        coords={
            "time": _var(("time",), s.history_t, "s", "time"),
            "element": ("element", hist_names),
            "mesh": ("mesh", meshes),
            "cycle": ("cycle", np.arange(s.cycle_max.shape[0])),
            "dof": ("dof", list(st.dof_names)),
        },
    )
    # (what the force is in a comment: the long_name is a plot label)
    ds["element_force"].attrs["comment"] = (
        "mesh: normal tooth force, negative in back-flank contact; support: the force on "
        "the bearing; shaft, spline torsion, torsional support: torque [N m], "
        "k (theta_a - theta_b) + damping, a the first body it connects, both angles about "
        "a's axis; each element's unit in 'element_unit'")
    ds = ds.assign_coords(element_unit=("element", hist_units, {
        "long_name": "unit of each element's force: N, or N m for a torque"}))
    ds = ds.assign_coords(element_frame=("element", element_frames(res, hist_names), {
        "long_name": "frame of the element force: a support force of a body measured in "
                     "a turning carrier's frame is in that frame (its shaft orders are "
                     "speeds relative to the carrier); 'housing' the fixed frame; '' a "
                     "mesh's normal force"}))
    if len(s.history_dofs):
        names = [st.dof_names[i] for i in s.history_dofs]
        ds = ds.assign_coords(history_dof=("history_dof", names))
        ds["displacement"] = _var(("time", "history_dof"), s.history_q, "m or rad",
                                  "displacement from the nominal rigid motion")
        ds["velocity"] = _var(("time", "history_dof"), s.history_v, "m/s or rad/s",
                              "vibratory velocity")
    if s.history_peaks is not None:  # (the bearing table's peaks: a file read back gives
        # the run's, not its samples')
        ds = ds.assign_coords(streamed_bearing=("streamed_bearing",
                                                list(s.history_peak_names)))
        # (named apart from bearing_peak_force, the settled peak of each bearing: a
        # MATLAB user took one for the other, a reviewer; files before read back too)
        ds[INTERVAL_PEAK] = _var(
            ("time", "streamed_bearing"), s.history_peaks.copy(), "N",
            "largest bearing force magnitude since the history sample before (this one "
            "included), streamed at every integration step (the settled peak of each "
            "bearing: bearing_peak_force)")
    _note_sampling(ds, s.history_t, res.statistics().get("step_s"),
                   res.history_keeps_every_step())
    if definition is not None and hasattr(res, "check_definition"):
        res.check_definition(definition)  # a misspelt one raises; a diverged run's do not
    try:
        if not res.success:  # a stopped run: its coefficients are not results (as its CSV)
            if getattr(res, "steady", None) is not None:
                raise OptionError("the periodic state did not converge: no metrics of the "
                                 "last iterate")
            raise OptionError("the run stopped before its end: no metrics of a part of it")
        met = res.metrics(definition)
        ds["load_sharing"] = _var(("mesh",), [met.load_sharing.per_mesh[m] for m in meshes],
                                  "1", f"load-sharing coefficient ({met.definition})")
        d = met.dynamic_factors
        ds["dynamic_factor"] = _var(("mesh",), [d.dynamic_factor[m] for m in meshes], "1",
                                    "dynamic factor: settled peak / the mesh's own static "
                                    "force (K_v sense)")
        ds["peak_to_nominal"] = _var(("mesh",), [d.peak_to_nominal[m] for m in meshes], "1",
                                     "settled peak / equal-split nominal force (Ji & Li "
                                     "eq. 19)")
        # the mesh table's forces, as the CSV has them (a .nc or .mat held them only
        # inside metrics_json)
        for name, field, text in (
                ("mean_force", "mean_force", "mean force over the settled cycles"),
                ("peak_force", "peak_force", "largest force over the settled cycles"),
                ("min_force", "min_force", "smallest force over the settled cycles")):
            ds[name] = _var(("mesh",), [getattr(r, field) for r in met.rows], "N", text)
        ds["dynamic_factor_engineering"] = _var(
            ("mesh",), [r.dynamic_factor_engineering for r in met.rows], "1",
            "mean over settled cycles of the per-cycle peak / the mesh's own static force")
        ds["back_flank_force"] = _var(("mesh",), [r.back_flank_force for r in met.rows], "N",
                                      "largest back-flank (tensile) force over the settled "
                                      "cycles")
        ds["double_flank"] = _var(("mesh",), [int(r.double_flank) for r in met.rows], "1",
                                  "1: the mesh has no backlash (double-flank contact)", **FLAG)
        # the settled span, so that the cycle variables give the peaks back (it was only
        # inside metrics_json)
        ds["first_settled_cycle"] = _var(("mesh",), np.array(
            [met.settling.first_cycle[m] for m in meshes], dtype=np.int64), "1",
            "first cycle of the settled span, a value of the cycle coordinate (counted "
            "from 0): peak_force, min_force and the coefficients are over the cycles from "
            "this one on")
        # whether the settle rule found the response settled (in metrics_json only: a
        # study's file has it as a variable, an exports reviewer)
        ds["settled"] = _var((), np.int8(met.settling.settled), "1",
                             "1: every mesh settled by the settle rule; 0: some mesh never "
                             "did, and its metrics are over the last half of the run", **FLAG)
        # each load-sharing group's and the system's numbers as variables too (for
        # xarray, MATLAB and spreadsheet users: not only inside metrics_json)
        groups = list(met.load_sharing.per_group)
        ds = ds.assign_coords(group=("group", groups))
        ds["settle_time"] = _var(("group",), [met.settling.group_time.get(g, np.nan)
                                              for g in groups], "s",
                                 "time from which the group's response is settled")
        ds["load_sharing_group"] = _var(("group",), [met.load_sharing.per_group[g]
                                                     for g in groups], "1",
                                        f"load-sharing coefficient of each group "
                                        f"({met.definition})")
        ds["dynamic_factor_group"] = _var(("group",), [d.per_group_dynamic_factor[g]
                                                       for g in groups], "1",
                                          "largest dynamic factor of the group's meshes")
        ds["peak_to_nominal_group"] = _var(("group",), [d.per_group_peak_to_nominal[g]
                                                        for g in groups], "1",
                                           "largest peak/nominal of the group's meshes")
        ds["peak_to_nominal_engineering_group"] = _var(
            ("group",), [d.per_group_peak_to_nominal_engineering.get(g, np.nan)
                         for g in groups], "1",
            "mean over settled cycles of the group's largest per-cycle peak / nominal force "
            "(Ji & Li eq. 19, engineering coefficient G_it)")
        of_mesh = {m: g for g, ms in met.load_sharing.groups.items() for m in ms}
        ds = ds.assign_coords(mesh_group=("mesh", [of_mesh.get(str(m), "")
                                                   for m in ds["mesh"].values]))
        ds["load_sharing_system"] = _var((), met.load_sharing.system, "1",
                                         f"system load-sharing coefficient "
                                         f"({met.definition})")
        ds.attrs["load_sharing_definition"] = met.definition
        ds.attrs["metrics_json"] = _json.dumps(met.to_dict(), default=float)
        ds = add_planet_load_sharing(ds, met.load_sharing, res.kinematics)
        bearings = res.bearing_forces(met.settling.start_time, metrics=met)
        if bearings:
            ds = ds.assign_coords(bearing=("bearing", [b["body"] for b in bearings]))
            ds["bearing_mean_force"] = _var(("bearing",), [b["mean_magnitude"] for b in bearings],
                                            "N", "magnitude of the settled mean bearing force "
                                            "(from the history)")
            ds["bearing_peak_force"] = _var(
                ("bearing",), [b["peak_magnitude"] for b in bearings], "N",
                "largest settled bearing force magnitude " + (
                    "(streamed at every step)" if all(b.get("peak_streamed") for b in bearings)
                    else "(from the history: a peak between its samples is missed)"))
            directions = sorted({d for b in bearings for d in b["directions"]})
            ds = ds.assign_coords(bearing_direction=("bearing_direction", directions))
            ds["bearing_mean_force_component"] = _var(
                ("bearing", "bearing_direction"),
                [[dict(zip(b["directions"], b["mean"])).get(d, np.nan) for d in directions]
                 for b in bearings], "N",
                "settled mean bearing force along each direction of the support's frame "
                "(NaN: no support in that direction)")
            ds.attrs["bearing_forces_json"] = _json.dumps(bearings)
    except Exception as exc:  # metrics of a diverged run may be undefined; keep the data
        ds.attrs["metrics_error"] = str(exc)
    steady = getattr(res, "steady", None)
    if steady is not None:  # a periodic steady state: one period repeated, not a run
        _steady_attributes(ds, res, steady)
        ds = _one_period(ds, float(ds.attrs["steady_period_s"]))
    elif getattr(res, "saved_steady", None):  # one read back: what its file said
        saved = res.saved_steady
        ds.attrs.update(saved["attrs"])
        if saved.get("rms_transmission_error") is not None:
            ds["rms_transmission_error"] = _var(
                ("mesh",), saved["rms_transmission_error"], "m", saved["rms_long_name"])
    notes = res.warnings(definition) if hasattr(res, "warnings") else []
    ds.attrs.update({
        "warnings": "\n".join(notes),
        "warnings_json": json.dumps(notes),
        "t_start": float(s.t_span[0]),
        "t_end": float(s.t_span[1]),
        "t_final": float(s.t_final),
        "title": f"torquesplit results: {res.model.model.name}",
        "model_name": res.model.model.name,
        "model_json": res.model_json(),
        "statistics_json": _json.dumps(res.statistics(), default=float),
        "status": int(s.status),
        "message": s.message,
        "software": "torquesplit",
    })
    return ds


def _steady_attributes(ds: xr.Dataset, res, steady) -> None:
    """What a saved steady state needs beside its repeated record: the solver's summary
    (period, residuals, stability, excitations replaced by their means), the RMS
    transmission error per mesh, and words that do not describe a run it never made."""
    info = steady.summary(results=res)  # (the record at hand, not a second one)
    ds["rms_transmission_error"] = _var(
        ("mesh",), [info["meshes"][m]["rms_transmission_error"] for m in res.mesh_names],
        "m", "RMS dynamic transmission error about its mean (the flanks' relative "
        "displacement, errors included)")
    ds.attrs.update(steady_attrs(res, info))
    _steady_words(ds, info)


def steady_attrs(res, info: dict) -> dict:
    """The attributes that say what a saved steady state is (``info``: its
    :meth:`~torquesplit.steady.SteadyState.summary`)."""
    periods = (float(res.solution.t_final - res.solution.t_span[0]) / info["period_s"]
               if info["period_s"] else math.nan)
    # (stable: 1 or 0, for a program; left out where the stability was not computed,
    # which steady_stability says; it was the text 'True', which a program reads as true
    # whatever it says)
    stable = {} if info["stable"] is None else {"steady_stable": np.int8(info["stable"])}
    return dict(
        analysis="periodic steady state",
        steady_json=_json.dumps(info, default=float),
        steady_method=info["method"], steady_period_s=info["period_s"],
        steady_residual=info["residual"], **stable,
        steady_stability=("not computed" if info["stable"] is None
                          else "stable" if info["stable"] else "unstable"),
        steady_largest_multiplier=(math.nan if info["largest_multiplier"] is None
                                   else info["largest_multiplier"]),
        dropped_excitations="; ".join(info["dropped_excitations"]) or "none",
        record=f"one period of the steady state repeated {periods:.0f} times (no start-up: "
               f"t_start..t_end is that record, not a simulated run)")


def _steady_words(ds: xr.Dataset, info: dict) -> None:
    """Words of a saved steady state's variables that do not describe a run it never
    made."""
    for name in ("contact_loss_fraction", "back_contact_fraction"):
        text = ds[name].attrs.get("long_name", "")
        ds[name].attrs["long_name"] = text.replace("of the whole run (start-up included)",
                                                   "of the period")
    for name in ("element_force", "displacement", "velocity"):
        if name in ds:
            ds[name].attrs["sampling"] = (
                f"the steady state's samples over one period ({info['method']}); the "
                f"metrics come from every step of it")


def _one_period(ds: xr.Dataset, period: float) -> xr.Dataset:
    """A steady state's history cut to its first period: the record repeats that period
    (its metrics need whole settle windows), and the files held every repetition (Ji & Li's
    steady state: 62 MB of CSV, one period 870 times).  The cycle statistics keep the
    whole record: the metrics of a file read back are computed from them."""
    if "time" not in ds.dims:
        return ds
    n = period_samples(ds["time"].values, period)
    if n is None:
        return ds
    out = ds.isel(time=slice(0, n))
    out.attrs["record"] = (
        f"{ds.attrs['record']}; the history (time dimension) holds its first period "
        f"({n} samples), the cycle statistics the whole record")
    out.attrs["history_periods"] = 1
    return out


def period_samples(t, period: float) -> int | None:
    """How many of the history times ``t`` fall in its first ``period`` (None where that
    is not a proper part of it): what a steady state's files keep (:func:`_one_period`)."""
    t = np.asarray(t, dtype=float)
    if not (t.size and period > 0):
        return None
    n = int(np.count_nonzero(t < t[0] + period * (1.0 - 1e-9)))
    return n if 2 <= n < t.size else None


def _note_sampling(ds: xr.Dataset, t, step, every_step: bool) -> None:
    """Say on each history variable that it is decimated (or holds ``every_step``), and
    its sample interval [s]."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return
    dt = float(np.median(np.diff(t)))
    steps = (f"the integration step is {step:.4g} s" if step else "adaptive integration "
             "steps")
    note = (f"decimated history for plots, sampled every {dt:.4g} s ({steps}); the metrics "
            "come from statistics of every step")
    if every_step:
        note = f"history of every integration step ({dt:.4g} s)"
    for name in ("element_force", "displacement", "velocity"):
        if name in ds:
            ds[name].attrs.update(sampling=note, sample_interval=dt,
                                  sample_interval_units="s")


def results_from_dataset(ds: xr.Dataset):
    """A :class:`~torquesplit.results.Results` rebuilt from a results Dataset written by
    :func:`results_to_dataset` (a ``.nc`` file of ``torquesplit run --out``).

    The model is the one embedded in the file; its kinematics, assembly and static
    equilibrium are recomputed (deterministic), the integration's per-cycle statistics
    and histories are the file's, so every metric equals the run's.  Files written before
    the per-cycle ratios were stored give NaN instantaneous coefficients.

    Raises
    ------
    ValueError
        The Dataset is not a torquesplit dynamic-run file.
    """

    from ..assembly.assemble import assemble
    from ..metrics.load_sharing import group_meshes
    from ..model.io import load_model
    from ..model.kinematics import solve_kinematics
    from ..solve.integrate import Solution
    from ..solve.static import static_equilibrium
    from . import Results

    if "model_json" not in ds.attrs or "cycle_max_force" not in ds:
        raise OptionError("not a torquesplit results file of a dynamic run (no embedded model "
                         "or cycle statistics); give a file written by 'torquesplit run "
                         "--out F.nc', or open this one as a Dataset with "
                         "torquesplit.open_results (a quasi-static sweep's, modes', a "
                         "sweep's or a study's file)")
    model = load_model(json.loads(ds.attrs["model_json"]))
    kin = solve_kinematics(model)
    structure = assemble(model, kin)
    static = static_equilibrium(structure)
    names = list(structure.element_names)
    meshes = [str(m) for m in ds["mesh"].values]
    track = tuple(names.index(m) for m in meshes)
    hist_el = tuple(names.index(str(e)) for e in ds["element"].values)
    dofs = list(structure.dof_names)
    hist_dof = (tuple(dofs.index(str(d)) for d in ds["history_dof"].values)
                if "history_dof" in ds.coords else ())
    stats = json.loads(ds.attrs.get("statistics_json", "{}"))
    span_s = float(stats.get("simulated_time_s", math.nan))
    t0 = float(ds.attrs.get("t_start", 0.0))
    t_end = float(ds.attrs.get("t_end", t0 + span_s))
    t_final = float(ds.attrs.get("t_final", t0 + span_s))
    span = max(t_final - t0, 1e-300)

    def cyc(name, fill=math.nan):
        if name in ds:
            return np.asarray(ds[name].values, dtype=float)
        return np.full(ds["cycle_max_force"].shape, fill)

    c_max = cyc("cycle_max_force")
    count = (np.asarray(ds["cycle_count"].values, dtype=np.int64) if "cycle_count" in ds
             else np.isfinite(c_max).astype(np.int64))
    sep_t = np.zeros(len(names))
    back_t = np.zeros(len(names))
    sep_t[list(hist_el)] = np.asarray(ds["contact_loss_fraction"].values) * span
    back_t[list(hist_el)] = np.asarray(ds["back_contact_fraction"].values) * span
    groups = tuple(tuple(names.index(m) for m in ms)
                   for ms in group_meshes(structure.metadata["meshes"]).values())
    n_hist = ds.sizes.get("time", 0)
    empty = np.zeros((n_hist, 0))

    def stat(key, default=math.nan):
        v = stats.get(key, default)
        return default if v is None else v

    solution = Solution(
        status=int(ds.attrs.get("status", 0)), message=str(ds.attrs.get("message", "")),
        success=int(ds.attrs.get("status", 0)) == 0, method=str(stat("method", "rk4")),
        t_span=(t0, t_end), t_final=t_final,
        y_final=np.full(2 * len(dofs), math.nan), n_steps=int(stat("steps", 0)),
        n_rejected=int(stat("rejected_steps", 0)), n_rhs=int(stat("rhs_evaluations", 0)),
        step=stats.get("step_s"),
        step_limited_by=str(stat("step_limited_by", "")), step_min=float(stat("step_min_s")),
        step_max=float(stat("step_max_s")), compile_time=float(stat("compile_time_s", 0.0)),
        wall_time=float(stat("wall_time_s", 0.0)), rhs=str(stat("rhs", "general")),
        rhs_compile_time=float(stat("rhs_compile_time_s", 0.0)),
        dof_names=tuple(dofs), element_names=tuple(names), tracked_elements=track,
        cycle_start=cyc("cycle_start"), cycle_max=c_max, cycle_min=cyc("cycle_min_force"),
        cycle_mean=cyc("cycle_mean_force"), cycle_count=count, load_sharing_groups=groups,
        cycle_ratio_max=cyc("cycle_ratio_max"), cycle_ratio_min=cyc("cycle_ratio_min"),
        history_elements=hist_el, history_dofs=hist_dof,
        history_t=np.asarray(ds["time"].values, dtype=float),
        history_forces=np.asarray(ds["element_force"].values, dtype=float),
        history_q=(np.asarray(ds["displacement"].values, dtype=float) if hist_dof else empty),
        history_v=(np.asarray(ds["velocity"].values, dtype=float) if hist_dof else empty),
        full_t=None, full_y=None, n_samples=int(count.sum()),
        separation_steps=np.zeros(len(names), np.int64),
        back_contact_steps=np.zeros(len(names), np.int64),
        separation_time=sep_t, back_contact_time=back_t,
        **({"history_peak_names": tuple(str(b) for b in ds["streamed_bearing"].values),
            "history_peaks": np.asarray(ds[peaks].values, dtype=float)}
           if (peaks := next((v for v in (INTERVAL_PEAK, "bearing_force_peak") if v in ds),
                             None)) else {}))
    notes = json.loads(ds.attrs.get("warnings_json", "[]"))
    # a steady state's record repeats one period: every complete cycle counts, as when
    # it was saved (its history holds the first period, :func:`_one_period`)
    res = Results(model=model, kinematics=kin, structure=structure, static=static,
                  solution=solution, model_warnings=notes,
                  periodic=ds.attrs.get("analysis") == "periodic steady state",
                  period=(float(ds.attrs["steady_period_s"]) if "steady_period_s" in ds.attrs
                          else None))
    res.saved_definition = ds.attrs.get("load_sharing_definition")
    if res.periodic:  # (a save of it writes them again: they were lost)
        rms = ds.get("rms_transmission_error")
        res.saved_steady = {
            "attrs": {k: v for k, v in ds.attrs.items() if k.startswith("steady_")
                      or k in ("analysis", "record", "dropped_excitations",
                               "history_periods")},
            "rms_transmission_error": (None if rms is None else
                                       np.asarray(rms.values, dtype=float)),
            "rms_long_name": "" if rms is None else rms.attrs.get("long_name", "")}
    return res
