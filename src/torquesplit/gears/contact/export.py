"""A loaded tooth contact analysis from Python (:func:`contact_analysis`, the twin of
``torquesplit contact``) and as an xarray Dataset, for the NetCDF, MATLAB and spreadsheet
files of ``torquesplit contact --out`` (:mod:`torquesplit.results.export`).

Four tables, one per row dimension: ``load_case`` (the scalars of each analysed load, as
the printed table), ``position`` (the curves over the mesh cycle and the load per tooth
pair: a column per load, named by it in kN), ``slice`` (the load per unit face width
across the face, a column per load) and ``harris_load`` (the Harris map).  SI units on
every variable; the transmission error also in arc seconds of the driven gear (Liu et al.
2021 eq. 3).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def contact_dataset(results, *, operating_load=None, harris=None, impact=None, given=None,
                    mesh: str = "", gears=("", "")):
    """The Dataset of ``results`` (one :class:`~torquesplit.gears.contact.ltca.
    LtcaResult` per load, in the order given), the tooth-pair loads of the largest, the
    :class:`~torquesplit.gears.contact.ltca.HarrisMap` ``harris`` and the meshing-in
    ``impact`` (at the largest load: attributes) if given; ``operating_load``: the
    model's [N]; ``given``: each load as the command line gave it."""
    import xarray as xr

    op = max(results, key=lambda r: r.load)  # (where the figures and the impact are)
    rows = [r.summary() for r in results]
    loads = np.array([r.load for r in results], dtype=float)
    per_load = {  # name -> (summary key, unit, description)
        "te_mean": ("te_mean_m", "m", "mean loaded transmission error along the normal"),
        "te_peak_to_peak": ("te_peak_to_peak_m", "m",
                            "peak-to-peak loaded transmission error (Liu et al. 2021 eq. 4)"),
        "te_peak_to_peak_arcsec": ("te_peak_to_peak_arcsec", "arcsec",
                                   f"the same as an angle of {gears[1]} (eq. 3)"),
        "stiffness_secant_mean": ("stiffness_secant_mean_N_per_m", "N/m",
                                  "mean secant mesh stiffness load / TE (eq. 5)"),
        "stiffness_tangent_mean": ("stiffness_tangent_mean_N_per_m", "N/m",
                                   "mean tangent mesh stiffness dload / dTE"),
        "max_hertz_pressure": ("max_hertz_pressure_Pa", "Pa", "largest Hertz pressure"),
        "contact_ratio": ("actual_contact_ratio", "1",
                          "mean number of loaded tooth pairs over the cycle"),
        "face_load_factor": ("face_load_factor", "1",
                             "K_Hbeta: largest load per unit face width over its mean "
                             "(ISO 6336-1), the load averaged over the mesh positions"),
    }
    data = {name: ("load_case", np.array([row[key] for row in rows], dtype=float),
                   {"units": unit, "long_name": text})
            for name, (key, unit, text) in per_load.items()}
    if given is not None:
        data["given_as"] = ("load_case", np.array(list(given), dtype=object),
                            {"long_name": "the load as given (a torque on a gear, or a force)"})
    curves = {  # name -> (values (position, load), unit, description)
        "transmission_error": ([r.transmission_error for r in results], "m",
                               "loaded transmission error along the normal"),
        "transmission_error_arcsec": ([r.te_arcsec for r in results], "arcsec",
                                      f"loaded transmission error as an angle of {gears[1]}"),
        "stiffness_secant": ([r.stiffness_secant for r in results], "N/m",
                             "secant mesh stiffness load / TE"),
        "stiffness_tangent": ([r.stiffness_tangent for r in results], "N/m",
                              "tangent mesh stiffness"),
        "max_pressure": ([r.max_pressure for r in results], "Pa",
                         "largest Hertz pressure at the position"),
        "loaded_pairs": ([r.loaded_pairs for r in results], "1",
                         "tooth pairs carrying load at the position"),
    }
    for name, (values, unit, text) in curves.items():
        data[name] = (("position", "load_case"), np.stack(values, axis=1),
                      {"units": unit, "long_name": text})
    # the load across the face (a reviewer had to compute K_Hbeta and the line loads
    # from the Python result): per slice, averaged over the positions, every load
    data["face_load"] = (("slice", "load_case"),
                         np.stack([r.face_load.max(axis=0) for r in results], axis=1),
                         {"units": "N/m", "long_name": "load per unit face width across the "
                          "face, averaged over the mesh positions (the larger helix's)"})
    data["unloaded_te"] = ("position", np.asarray(op.unloaded_te, dtype=float),
                           {"units": "m", "long_name": "transmission error at vanishing "
                            "load (geometric: modifications and misalignment)"})
    # at every load, labelled as the other curves: at the largest only, its columns did
    # not say which load they were of (an LTCA reviewer)
    data["pair_load"] = (("position", "load_case", "pair"),
                         np.stack([r.pair_load.sum(axis=1) for r in results], axis=1),
                         {"units": "N", "long_name": "load of each tooth pair, over the "
                          "helices"})
    # the loads label the columns of the position table ('transmission_error_10kN_m')
    labels = [f"{x / 1e3:.6g}kN" for x in loads]
    if len(set(labels)) < len(labels):
        labels = [f"load{k + 1}" for k in range(len(labels))]
    # (the dimension is not 'load': ds.load is xarray's Dataset.load(), which hid it)
    coords = {"load_case": ("load_case", np.array(labels, dtype=object),
                            {"long_name": "the load analysed (its value: load_N)"}),
              "load_N": ("load_case", loads, {"units": "N", "long_name": "normal tooth load"}),
              "phase": ("position", np.asarray(op.phase, dtype=float),
                        {"units": "1", "long_name": "mesh position in cycles"}),
              "position": np.arange(1, op.phase.size + 1),
              "pair": np.arange(1, op.pair_load.shape[2] + 1),
              "face_position": ("slice", np.asarray(op.model.y, dtype=float),
                                {"units": "m", "long_name": "position of the slice's middle "
                                 "across the face, from its start"})}
    if harris is not None:
        coords["harris_load"] = ("harris_load", np.asarray(harris.loads, dtype=float),
                                 {"units": "N", "long_name": "normal tooth load"})
        for name, values, unit in (
                ("harris_te_peak_to_peak", harris.te_peak_to_peak, "m"),
                ("harris_te_peak_to_peak_arcsec", harris.te_peak_to_peak_arcsec, "arcsec"),
                ("harris_mean_stiffness", harris.mean_stiffness, "N/m"),
                ("harris_contact_ratio", harris.contact_ratio, "1")):
            data[name] = ("harris_load", np.asarray(values, dtype=float), {"units": unit})
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(mesh=mesh, driver=gears[0], driven=gears[1], positions=int(op.phase.size),
                    largest_load_N=float(op.load))
    if operating_load is not None:
        ds.attrs["operating_load_N"] = float(operating_load)
    if impact is not None:  # (at the largest load)
        ds.attrs.update(impact_peak_force_N=float(impact.peak_force),
                        impact_advance_m=float(impact.advance),
                        impact_corner_separation_m=float(impact.corner_separation))
    return ds


@dataclass(frozen=True)
class ContactAnalysis:
    """A loaded tooth contact analysis of one mesh at one or more loads (what
    ``torquesplit contact`` computes), from :func:`contact_analysis`."""

    mesh: str
    gears: tuple[str, str]
    """(gear 1, gear 2) as the LTCA takes them (the driver first, but where a ring
    drives): gear 2's angle is the angular transmission error."""
    operating_load: float
    """The mesh's operating normal load [N] (the model's)."""
    results: tuple = field(repr=False)
    """One :class:`~torquesplit.gears.contact.ltca.LtcaResult` per load, in order."""
    harris: object = field(default=None, repr=False)
    """The :class:`~torquesplit.gears.contact.ltca.HarrisMap`, or None."""
    model: object = field(default=None, repr=False)
    """The :class:`~torquesplit.model.schema.Model` (a saved file names and holds it)."""

    @property
    def loads(self) -> list[float]:
        """The normal loads analysed [N]."""
        return [float(r.load) for r in self.results]

    def summary(self) -> list[dict]:
        """The scalars of each load (SI, TE also in arc seconds), as the command's table."""
        return [r.summary() for r in self.results]

    def to_dataset(self):
        """The results as ``torquesplit contact --out`` writes them (:func:`contact_dataset`)."""
        return contact_dataset(self.results, operating_load=self.operating_load,
                               harris=self.harris, mesh=self.mesh, gears=self.gears)

    def save(self, path, *, overwrite: bool = False):
        """Save :meth:`to_dataset` by suffix (``.nc``, ``.mat``, ``.csv``) with its model;
        atomically, an existing file kept unless ``overwrite``.  Returns the path written.
        (``torquesplit contact --out`` also writes the meshing-in impact and each load as
        the command line gave it.)"""
        from ...results.export import save_dataset, with_model

        ds = self.to_dataset()
        if self.model is not None:
            ds = with_model(ds, self.model)
        return save_dataset(ds, path, overwrite=overwrite)


def contact_analysis(model, mesh: str, loads=None, *, positions: int | None = None,
                     slices: int | None = None, harris: int = 0) -> ContactAnalysis:
    """Loaded tooth contact analysis of ``mesh`` of ``model`` (a Model, file or example
    name) with its gears' tooth modifications and misalignment: transmission error,
    mesh stiffness, load distribution and Hertz pressure over the mesh cycle (Liu et al.
    2021 eqs. 1-5), at each of ``loads`` (normal forces: numbers in N or texts such as
    '40 kN'; default the operating load), on ``positions`` x ``slices`` (default the
    model's ``stiffness.ltca`` settings), with a Harris map of ``harris`` loads from 0.1
    to 1.5 times the largest (0: none).  Python's twin of ``torquesplit contact``."""
    from dataclasses import replace

    from ...errors import OptionError
    from ...model.io import load_model
    from ...model.kinematics import solve_kinematics
    from ...model.units import parse_quantity
    from .coupling import _options, contact_model_for_mesh

    m = load_model(model) if not hasattr(model, "meshes") else model
    if mesh not in m.meshes:
        raise OptionError(f"no mesh named {mesh!r}; name one of {', '.join(m.meshes)}")
    from ...model.schema_modifications import MAX_POSITIONS, MIN_POSITIONS

    # (the bounds of the model file's stiffness.ltca fields and of the command's options)
    for value, name, low, high in ((positions, "positions", MIN_POSITIONS, MAX_POSITIONS),
                                   (slices, "slices", 1, 400)):
        if value is not None and not (isinstance(value, (int, np.integer))
                                      and not isinstance(value, bool) and low <= value <= high):
            raise OptionError(f"{name} must be a whole number from {low} to {high}, got "
                              f"{value!r}")
    if not (isinstance(harris, (int, np.integer)) and not isinstance(harris, bool)
            and harris >= 0):
        raise OptionError(f"harris must be a whole number >= 0 (0: no map), got {harris!r}")
    kin = solve_kinematics(m)
    opts = _options(m.meshes[mesh].stiffness)
    opts = replace(opts, positions=positions or opts.positions, slices=slices or opts.slices)
    cm, op_load, names, _ = contact_model_for_mesh(m, kin, mesh, options=opts)
    given = [op_load] if loads is None else (
        [loads] if isinstance(loads, (str, int, float)) else list(loads))
    forces = []
    for value in given:
        try:
            forces.append(parse_quantity(value, "force"))
        except ValueError as exc:
            raise OptionError(f"loads: {exc}") from None
        if not forces[-1] > 0:
            raise OptionError(f"loads: a normal load must be positive, got {value!r}")
    results = tuple(cm.solve(f).require_converged(f"meshes.{mesh}") for f in forces)
    hm = cm.harris_map(np.linspace(0.1, 1.5, harris) * max(forces)) if harris else None
    return ContactAnalysis(mesh=mesh, gears=tuple(names), operating_load=float(op_load),
                           results=results, harris=hm, model=m)
