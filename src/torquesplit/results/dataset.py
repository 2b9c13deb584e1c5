"""Conversion of :class:`~torquesplit.results.Results` to an :class:`xarray.Dataset`."""

from __future__ import annotations

import json

import numpy as np
import xarray as xr


def _var(dims, data, units, long_name):
    return xr.Variable(dims, np.asarray(data), attrs={"units": units, "long_name": long_name})


def results_to_dataset(res) -> xr.Dataset:
    """Histories, per-cycle statistics, static and nominal forces, metrics, run info."""
    s = res.solution
    st = res.structure
    meshes = res.mesh_names
    el = st.element_names
    hist_names = [el[i] for i in s.history_elements]
    mesh_cols = [list(s.tracked_elements).index(el.index(m)) for m in meshes]
    ds = xr.Dataset(
        data_vars={
            "element_force": _var(("time", "element"), s.history_forces, "N",
                                  "element force (mesh: normal tooth force; support: bearing "
                                  "force)"),
            "cycle_start": _var(("cycle", "mesh"), s.cycle_start[:, mesh_cols], "s",
                                "start time of each mesh cycle"),
            "cycle_max_force": _var(("cycle", "mesh"), s.cycle_max[:, mesh_cols], "N",
                                    "largest mesh force in each mesh cycle"),
            "cycle_min_force": _var(("cycle", "mesh"), s.cycle_min[:, mesh_cols], "N",
                                    "smallest mesh force in each mesh cycle"),
            "cycle_mean_force": _var(("cycle", "mesh"), s.cycle_mean[:, mesh_cols], "N",
                                     "mean mesh force in each mesh cycle"),
            "nominal_force": _var(("mesh",), [res.kinematics.meshes[m].force for m in meshes],
                                  "N", "equal-split nominal tooth force"),
            "static_force": _var(("mesh",), list(res.static_forces().values()), "N",
                                 "mesh force at static equilibrium"),
            "mesh_frequency": _var(("mesh",), [res.kinematics.meshes[m].frequency
                                               for m in meshes], "Hz", "mesh frequency"),
            "static_displacement": _var(("dof",), res.static.q, "m or rad",
                                        "static equilibrium displacement"),
            "contact_loss_fraction": _var(("element",),
                                          s.separation_fraction[list(s.history_elements)], "1",
                                          "fraction of the run with the element inside its "
                                          "dead zone (drive flank separated)"),
            "back_contact_fraction": _var(("element",),
                                          s.back_contact_fraction[list(s.history_elements)],
                                          "1", "fraction of the run in back-flank contact "
                                          "(mesh without backlash: tensile force)"),
        },
        coords={
            "time": _var(("time",), s.history_t, "s", "time"),
            "element": ("element", hist_names),
            "mesh": ("mesh", meshes),
            "cycle": ("cycle", np.arange(s.cycle_max.shape[0])),
            "dof": ("dof", list(st.dof_names)),
        },
    )
    if len(s.history_dofs):
        names = [st.dof_names[i] for i in s.history_dofs]
        ds = ds.assign_coords(history_dof=("history_dof", names))
        ds["displacement"] = _var(("time", "history_dof"), s.history_q, "m or rad",
                                  "displacement from the nominal rigid motion")
        ds["velocity"] = _var(("time", "history_dof"), s.history_v, "m/s or rad/s",
                              "vibratory velocity")
    try:
        met = res.metrics()
        ds["load_sharing"] = _var(("mesh",), [met.load_sharing.per_mesh[m] for m in meshes],
                                  "1", f"load-sharing coefficient ({met.definition})")
        d = met.dynamic_factors
        ds["dynamic_factor"] = _var(("mesh",), [d.dynamic_factor[m] for m in meshes], "1",
                                    "dynamic factor: settled peak / the mesh's own static "
                                    "force (K_v sense)")
        ds["peak_to_nominal"] = _var(("mesh",), [d.peak_to_nominal[m] for m in meshes], "1",
                                     "settled peak / equal-split nominal force (Ji & Li "
                                     "eq. 19)")
        ds.attrs["metrics_json"] = json.dumps(met.to_dict(), default=float)
    except Exception as exc:  # metrics of a diverged run may be undefined; keep the data
        ds.attrs["metrics_error"] = str(exc)
    ds.attrs.update({
        "title": f"torquesplit results: {res.model.model.name}",
        "model_name": res.model.model.name,
        "model_json": res.model_json(),
        "statistics_json": json.dumps(res.statistics(), default=float),
        "status": int(s.status),
        "message": s.message,
        "software": "torquesplit",
    })
    return ds
