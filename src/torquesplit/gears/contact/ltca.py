"""Loaded tooth contact analysis (LTCA) of a cylindrical gear pair.

:class:`ContactModel` is built once per pair, modification, misalignment and options
(geometry, slice compliance tables, initial separations: everything that does not
depend on the load); :meth:`ContactModel.solve` then gives an :class:`LtcaResult` at
any load and :meth:`ContactModel.harris_map` the transmission error over a range of
loads.  The model and the solution method are described in the package docstring of
:mod:`torquesplit.gears.contact`.

Examples
--------
>>> import math
>>> from torquesplit.gears.geometry import GearGeometry, PairGeometry
>>> a = math.radians(20)
>>> pair = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
...                     GearGeometry(40, 2e-3, a, face_width=0.02))
>>> cm = ContactModel(pair, options=LtcaOptions(positions=16, slices=4))
>>> res = cm.solve(2000.0)
>>> bool(abs(res.slice_load.sum(axis=(1, 2, 3)) - 2000.0).max() < 1e-6)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from torquesplit.errors import ModelError, SolverError
from torquesplit.gears.contact import _kernels
from torquesplit.gears.contact.compliance import (
    SliceTables,
    interpolate,
    pasternak_parameter,
    slice_tables,
)
from torquesplit.gears.contact.modifications import (
    Misalignment,
    flank_coordinates,
    lead_separation,
    profile_separation,
)
from torquesplit.gears.geometry import PairGeometry
from torquesplit.gears.stiffness.phasing import pair_positions, require_contact
from torquesplit.gears.stiffness.potential_energy import _two, hertz_compliance

__all__ = ["LtcaOptions", "ContactModel", "LtcaResult", "HarrisMap", "ARCSEC_PER_RAD", "ltca_stiffness"]

#: seconds of arc per radian (Liu et al. 2021 eq. 3: 3600 * 180 / pi)
ARCSEC_PER_RAD = 3600.0 * 180.0 / math.pi


@dataclass(frozen=True)
class LtcaOptions:
    """Options of the loaded tooth contact analysis.

    Attributes
    ----------
    positions : int
        Mesh positions over one mesh cycle (uniform phases ``m / positions``).
    slices : int
        Slices across the face of one helix.
    contact_model : {"weber", "linear"}
        Hertzian contact of a slice: load dependent (Weber 1949 / Johnson 1985 §5.6) or
        the linear stiffness of the potential-energy method (Yang & Lin 1987).
    coupling : bool
        Couple neighbouring slices of a tooth (Pasternak strip, see compliance.py);
        False gives independent slices (the potential-energy slice method).
    stagger : float
        Phase offset of the second helix of a double-helical pair [mesh cycles].
    axial_float : bool
        Double-helical pair: one member floats axially (its bearings take no thrust), so
        the axial forces of the helices balance and each helix carries half the load
        with an approach of its own (the float shifts one helix's flanks towards, the
        other's away from the mating gear); the transmission error is the mean of the two
        approaches (the floating member's rotation).  False: both members held axially,
        one approach for both helices (a misalignment then loads one helix more).
    fillet_foundation : bool
        Include the fillet-foundation flexibility (Sainsot et al. 2004).
    grid : int
        Samples of the compliance tables along the path of contact.
    tolerance : float
        Relative tolerance of the Hertz fixed point (approach and loads).
    max_iterations : int
        Iteration limit of the active-set method and of the Hertz loop.
    """

    positions: int = 64
    slices: int = 40
    contact_model: str = "weber"
    coupling: bool = True
    stagger: float = 0.0
    axial_float: bool = False
    fillet_foundation: bool = True
    grid: int = 256
    tolerance: float = 1e-10
    max_iterations: int = 500

    def check(self, where: str = "ltca") -> None:
        issues = []
        if not (isinstance(self.positions, (int, np.integer)) and self.positions >= 2):
            issues.append((f"{where}.positions", f"must be an integer >= 2, got {self.positions!r}; "
                                                 "give e.g. 64"))
        if not (isinstance(self.slices, (int, np.integer)) and 1 <= self.slices <= 400):
            issues.append((f"{where}.slices", f"must be an integer in 1..400, got {self.slices!r}; "
                                              "give e.g. 40"))
        if self.contact_model not in ("weber", "linear"):
            issues.append((f"{where}.contact_model", f"unknown contact model {self.contact_model!r}; "
                                                     "use 'weber' or 'linear'"))
        if not (0 < self.tolerance < 1e-2):
            issues.append((f"{where}.tolerance", f"must lie in (0, 0.01), got {self.tolerance!r}; "
                                                 "give e.g. 1e-10"))
        if not (isinstance(self.max_iterations, (int, np.integer)) and self.max_iterations >= 10):
            issues.append((f"{where}.max_iterations", "must be an integer >= 10; give e.g. 500"))
        if issues:
            raise ModelError(issues)


class ContactModel:
    """Everything of an LTCA that does not depend on the load.

    Parameters
    ----------
    pair : PairGeometry
        Spur, helical, double-helical or internal pair; gear 1 (the pinion) drives.
    modifications : (ToothModification or None, ToothModification or None)
        Modification of gear 1 and gear 2.
    misalignment : Misalignment, optional
        Separations the pair opens.
    options : LtcaOptions, optional
    young_modulus, poisson_ratio : float or (float, float)
        Materials of gear 1 and gear 2 [Pa], [-].
    bore_radius : float or (float, float), optional
        Bore / rim inner radius of each gear for the fillet-foundation term [m].
    where : (str, str, str)
        Locations used in error messages for the two modifications and the misalignment
        (e.g. ``gears.L6.modifications``).

    Attributes
    ----------
    phase : (M,) mesh phases [cycles]; y : (N,) slice centres across one helix [m];
    s : (M, H, K, N) transverse path position of each potential contact point [m];
    zone : (M, H, K, N) bool, on the active path; separation : (M, H, K, N) initial
    separation [m] (its minimum over the active points of all positions is 0);
    unloaded_te : (M,) transmission error at vanishing load [m].
    """

    def __init__(self, pair: PairGeometry, modifications=(None, None),
                 misalignment: Misalignment | None = None, options: LtcaOptions | None = None, *,
                 young_modulus=206e9, poisson_ratio=0.3, bore_radius=None,
                 where: Sequence[str] = ("gear1.modifications", "gear2.modifications",
                                         "misalignment")):
        require_contact(pair)
        opts = options or LtcaOptions()
        opts.check()
        self.pair = pair
        self.options = opts
        self.modifications = tuple(modifications)
        self.misalignment = misalignment or Misalignment()
        (e1, e2), (n1, n2) = _two(young_modulus, "young_modulus"), _two(poisson_ratio, "poisson_ratio")
        self.young_modulus, self.poisson_ratio = (e1, e2), (n1, n2)
        H = 2 if pair.double_helical else 1
        M, N = int(opts.positions), int(opts.slices)
        b = pair.face_width
        cb = math.cos(pair.base_helix_angle)
        self.helices = H
        self.normal_factor = cb
        self.phase = np.arange(M) / M
        self.slice_width = b / N
        self.line_length = self.slice_width / cb
        self.y = (np.arange(N) + 0.5) * self.slice_width
        lag = self.y * math.tan(pair.base_helix_angle) / pair.base_pitch
        s = np.stack([np.transpose(pair_positions(pair, np.mod(self.phase + h * opts.stagger, 1.0), lag),
                                   (0, 2, 1)) for h in range(H)], axis=1)   # (M, H, K, N)
        self.s = s
        # part of each slice's contact line on the active path: the line over slice j
        # spans s_j -/+ db tan(beta_b) / 2
        ds = self.slice_width * math.tan(pair.base_helix_angle)
        if ds > 0:
            lo = np.maximum(s - 0.5 * ds, pair.path_start)
            hi = np.minimum(s + 0.5 * ds, pair.path_end)
            frac = np.clip((hi - lo) / ds, 0.0, 1.0)
        else:
            frac = ((s >= pair.path_start) & (s < pair.path_end)).astype(float)
        frac[frac < 1e-9] = 0.0
        self.fraction = frac
        self.zone = frac > 0.0
        self.tables: SliceTables = slice_tables(
            pair, young_modulus=(e1, e2), poisson_ratio=(n1, n2),
            fillet_foundation=opts.fillet_foundation, bore_radius=bore_radius, grid=opts.grid)
        t = interpolate(self.tables, s)
        kb1 = 1.0 / (cb * cb * t["bending1"])        # normal plate stiffness per unit width
        kb2 = 1.0 / (cb * cb * t["bending2"])
        self._arrays = dict(
            kb1=kb1, kb2=kb2,
            g1=pasternak_parameter(t["lever1"], kb1, n1),
            g2=pasternak_parameter(t["lever2"], kb2, n2),
            loc=cb * cb * (t["local1"] + t["local2"]),
            radius=t["radius"], depth1=t["depth1"], depth2=t["depth2"],
        )
        self.separation = self._separations(where)
        self.unloaded_te = np.where(self.zone, self.separation, np.inf).min(axis=(1, 2, 3))
        self.hertz_linear = hertz_compliance((e1, e2), (n1, n2))

    # ------------------------------------------------------------------ separations
    def raw_separation(self, s, y, helix: int, where=None) -> np.ndarray:
        """Initial separation at path positions ``s`` and face positions ``y`` of helix
        ``helix`` [m], before the shift :attr:`separation_shift` (broadcasting ``s``, ``y``)."""
        pair = self.pair
        where = where or self._where
        b = pair.face_width
        s = np.asarray(s, dtype=float)
        y = np.asarray(y, dtype=float)
        w = np.zeros(np.broadcast_shapes(s.shape, y.shape))
        rho1, rho2 = pair.roll_distances(s)
        for gear, mod, rho in ((1, self.modifications[0], rho1), (2, self.modifications[1], rho2)):
            if mod is None:
                continue
            fc = flank_coordinates(pair, gear)
            flank = mod.helix(helix)
            loc = where[gear - 1] if not (helix == 1 and mod.second_helix is not None) \
                else f"{where[gear - 1]}.second_helix"
            w = w + profile_separation(flank, fc, rho, loc)
            w = w + lead_separation(flank, y, b, loc)
        mis = self.misalignment
        if mis.lead_mismatch:
            w = w + mis.lead_mismatch * (y / b - 0.5)
        if mis.shaft_misalignment:
            # axial position from the middle of the gear; the entry ends of the two helices
            # of a double-helical gear are its outer ends
            z = y - 0.5 * b if self.helices == 1 else (y - b if helix == 0 else b - y)
            w = w + mis.shaft_misalignment * z * self.normal_factor
        if mis.base_pitch_deviation:
            s_mid = 0.5 * (pair.path_start + pair.path_end)
            w = w + mis.base_pitch_deviation * (s - s_mid) / pair.base_pitch
        if not np.all(np.isfinite(w)):
            raise ModelError([(where[2], "the separations are not finite; check the "
                                         "modification and misalignment values")])
        return w

    def _separations(self, where) -> np.ndarray:
        self._where = tuple(where)
        w = np.stack([self.raw_separation(self.s[:, h], self.y, h) for h in range(self.helices)],
                     axis=1)
        self.separation_shift = float(w[self.zone].min())
        return w - self.separation_shift

    # ----------------------------------------------------------------------- solve
    def solve(self, load: float, *, twin: bool = False) -> "LtcaResult":
        """Loaded contact at every mesh position under the normal load ``load`` [N].

        ``twin=True`` runs the readable numpy twin of the compiled kernel (slow; tests).
        """
        if not (load > 0 and math.isfinite(load)):
            raise ModelError([("load", f"must be a positive normal force in N, got {load!r}; "
                                       "give the operating load")])
        if self.helices == 2 and self.options.axial_float:
            # each helix on its own with half the load (axial forces balance); the float
            # takes up the difference of their approaches
            parts = [self._solve(0.5 * load, twin, helix=h) for h in range(2)]
            p = np.concatenate([q[0] for q in parts], axis=1)
            Zh = np.stack([q[1] for q in parts], axis=1)
            k0, k1 = parts[0][2], parts[1][2]
            # dZ/dP = (dZ0/dP0 + dZ1/dP1) / 4 with P_h = P/2 and Z = (Z0 + Z1)/2: the two
            # helices in parallel (2 k for equal ones), the float free
            kt = 4.0 * k0 * k1 / (k0 + k1)
            it = np.maximum(parts[0][3], parts[1][3])
            st = np.maximum(parts[0][4], parts[1][4])
            return LtcaResult(model=self, load=float(load), slice_load=p,
                              transmission_error=Zh.mean(axis=1), stiffness_tangent=kt,
                              iterations=it, status=st, helix_approach=Zh)
        p, Z, kt, it, st = self._solve(load, twin)
        return LtcaResult(model=self, load=float(load), slice_load=p, transmission_error=Z,
                          stiffness_tangent=kt, iterations=it, status=st)

    def _solve(self, load: float, twin: bool, helix: int | None = None) -> tuple:
        """The kernel (or its twin) on every helix, or on ``helix`` alone."""
        args = self._kernel_args(load, helix)
        if twin:
            p, Z, kt = _kernels.ltca_solve_twin(*args)
            return (p, Z, kt, np.zeros(Z.size, dtype=np.int64), np.zeros(Z.size, dtype=np.int64))
        return _kernels.ltca_solve(*args)

    def _kernel_args(self, load: float, helix: int | None = None) -> tuple:
        o = self.options
        a = self._arrays
        (e1, e2), (n1, n2) = self.young_modulus, self.poisson_ratio
        if helix is not None:  # the (M, H, K, N) arrays of that helix alone
            cut = slice(helix, helix + 1)  # (contiguous: the kernel's compiled layout)
            a = {k: np.ascontiguousarray(v[:, cut]) for k, v in a.items()}
            zone, fraction, sep = (np.ascontiguousarray(x[:, cut]) for x in
                                   (self.zone, self.fraction, self.separation))
        else:
            zone, fraction, sep = self.zone, self.fraction, self.separation
        return (zone, fraction, a["kb1"], a["kb2"], a["g1"], a["g2"], a["loc"],
                sep, a["radius"], a["depth1"], a["depth2"], self.slice_width,
                self.line_length, (1 - n1 * n1) / e1, (1 - n2 * n2) / e2, n1, n2,
                1 if o.contact_model == "weber" else 0, self.hertz_linear, bool(o.coupling),
                float(load), float(o.tolerance), int(o.max_iterations))

    def harris_map(self, loads) -> "HarrisMap":
        """Transmission error peak-to-peak and mean stiffness at each load [N]."""
        loads = np.asarray(loads, dtype=float).ravel()
        if loads.size == 0 or np.any(~(loads > 0)):
            raise ModelError([("loads", "need one or more positive normal loads in N; give "
                                        "e.g. 0.2 to 1.5 times the operating load")])
        res = [self.solve(float(f)) for f in loads]
        return HarrisMap(loads=loads, results=tuple(res))

    @property
    def shape(self) -> tuple[int, int, int, int]:
        """(M positions, H helices, K tooth pairs, N slices)."""
        return self.s.shape

    def te_angle(self, te_normal):
        """Angular transmission error of gear 2 for a normal one [rad] (Liu et al. 2021
        eq. 3: ``Z / (r_b2 cos(beta_b))``)."""
        # Liu et al. 2021 eq. 3 (without the 3600 * 180 / pi of arc seconds)
        return np.asarray(te_normal) / (self.pair.gear2.base_radius * self.normal_factor)


@dataclass(frozen=True)
class LtcaResult:
    """LTCA at one load: per position and per slice (SI).

    Attributes
    ----------
    model : ContactModel
    load : float
        Normal load [N] (both helices of a double-helical pair together).
    slice_load : (M, H, K, N)
        Normal load of each slice [N] (0 where not in contact).
    transmission_error : (M,)
        Loaded static transmission error: approach of the gear bodies along the flank
        normal [m] (Liu et al. 2021: "normal deformation Z"), measured from the
        conjugate position of the most prominent point: the separations of the
        modifications and misalignment are shifted so that their minimum over the contact
        zone at all positions is zero (``model.separation_shift``; docs/theory/ltca.md).
    stiffness_tangent : (M,)
        ``dP/dZ`` with the contact set held [N/m].
    iterations, status : (M,)
        Active-set iterations and status code (see ``_kernels.STATUS``) per position.
    helix_approach : (M, H) or None
        Approach of each helix [m] where they differ (a floating double-helical member,
        ``LtcaOptions.axial_float``); None: every helix at ``transmission_error``.
    """

    model: ContactModel = field(repr=False)
    load: float
    slice_load: np.ndarray = field(repr=False)
    transmission_error: np.ndarray = field(repr=False)
    stiffness_tangent: np.ndarray = field(repr=False)
    iterations: np.ndarray = field(repr=False)
    status: np.ndarray = field(repr=False)
    helix_approach: np.ndarray | None = field(default=None, repr=False)

    def approach(self, helix: int) -> np.ndarray:
        """(M,) approach of the gear bodies at ``helix`` [m] (module docstring)."""
        if self.helix_approach is None:
            return self.transmission_error
        return self.helix_approach[:, helix]

    @property
    def converged(self) -> bool:
        return bool(np.all(self.status == 0))

    @property
    def message(self) -> str:
        bad = np.flatnonzero(self.status != 0)
        if bad.size == 0:
            return "converged at every position"
        return (f"not converged at {bad.size} of {self.status.size} positions (first: position "
                f"{bad[0]}, {_kernels.STATUS[int(self.status[bad[0]])]})")

    def require_converged(self, where: str = "ltca") -> "LtcaResult":
        if not self.converged:
            raise SolverError(f"{where}: LTCA {self.message}; raise max_iterations or check the "
                              "modifications")
        return self

    # -------------------------------------------------------------- per position
    @property
    def phase(self) -> np.ndarray:
        return self.model.phase

    @property
    def stiffness_secant(self) -> np.ndarray:
        """``P / Z`` [N/m] (Liu et al. 2021 eq. 5)."""
        return self.load / self.transmission_error   # Liu et al. 2021 eq. 5

    @property
    def te_angle(self) -> np.ndarray:
        """Angular transmission error of gear 2 [rad] (Liu et al. 2021 eq. 3)."""
        return self.model.te_angle(self.transmission_error)

    @property
    def te_arcsec(self) -> np.ndarray:
        """Angular transmission error of gear 2 [arc seconds] (Liu et al. 2021 eq. 3)."""
        return self.te_angle * ARCSEC_PER_RAD

    @property
    def te_peak_to_peak(self) -> float:
        """Peak-to-peak loaded transmission error along the normal [m] (Liu et al. 2021 eq. 4)."""
        z = self.transmission_error
        return float(z.max() - z.min())   # Liu et al. 2021 eq. 4

    @property
    def te_peak_to_peak_arcsec(self) -> float:
        """Amplitude of the static loaded transmission error [arc seconds] (eqs. 3-4)."""
        return float(self.te_arcsec.max() - self.te_arcsec.min())

    @property
    def line_load(self) -> np.ndarray:
        """Load per unit contact-line length of each slice [N/m] (over its part on the
        active path)."""
        length = self.model.fraction * self.model.line_length
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(length > 0, self.slice_load / length, 0.0)

    @property
    def hertz_pressure(self) -> np.ndarray:
        """Maximum Hertz pressure of each slice's line contact [Pa] (0 where unloaded):
        ``p0 = sqrt(q E* / (pi R))`` (Johnson 1985 eq. 4.45)."""
        (e1, e2), (n1, n2) = self.model.young_modulus, self.model.poisson_ratio
        e_star = 1.0 / ((1 - n1 * n1) / e1 + (1 - n2 * n2) / e2)
        # Johnson 1985 eq. 4.45
        return np.sqrt(np.maximum(self.line_load, 0.0) * e_star / (math.pi * self.model._arrays["radius"]))

    @property
    def max_pressure(self) -> np.ndarray:
        """Largest Hertz pressure at each position [Pa]."""
        return self.hertz_pressure.max(axis=(1, 2, 3))

    @property
    def pair_load(self) -> np.ndarray:
        """(M, H, K) load of each tooth pair [N]."""
        return self.slice_load.sum(axis=3)

    @property
    def face_load(self) -> np.ndarray:
        """(H, N) load per unit face width of each slice [N/m], over the tooth pairs and
        averaged over the mesh positions: the distribution of the load across the face
        (the oblique contact lines of a helical pair average out over the cycle)."""
        return self.slice_load.sum(axis=2).mean(axis=0) / self.model.slice_width

    @property
    def face_load_factor(self) -> float:
        """Face load factor K_Hbeta: the largest load per unit face width over its mean
        (ISO 6336-1 w_max / w_m), from :attr:`face_load`, the larger of the helices'.
        The largest is a slice's, half a slice in from where it peaks: a load rising to a
        face end comes out low by about 1 / slices of K - 1."""
        w = self.face_load
        mean = w.mean(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.where(mean > 0, w.max(axis=1) / mean, np.nan)
        return float(np.nanmax(k)) if np.isfinite(k).any() else math.nan

    @property
    def helix_load(self) -> np.ndarray:
        """(M, H) load of each helix [N]."""
        return self.slice_load.sum(axis=(2, 3))

    @property
    def loaded_pairs(self) -> np.ndarray:
        """Number of tooth pairs carrying load at each position, averaged over the helices."""
        loaded = self.pair_load > 1e-9 * self.load
        return loaded.sum(axis=2).mean(axis=1)

    @property
    def actual_contact_ratio(self) -> float:
        """Mean number of loaded tooth pairs over the cycle (per helix) [-]."""
        return float(self.loaded_pairs.mean())

    @property
    def unloaded_te(self) -> np.ndarray:
        """Transmission error at vanishing load (geometric, from the separations) [m]."""
        return self.model.unloaded_te

    def gaps(self) -> np.ndarray:
        """(M, H, K, N) separation left under load at every potential contact point [m]
        (0 where loaded, >= 0 elsewhere; NaN off the active path): the contact condition,
        evaluated independently of the solver from the compliance and the loads."""
        cm = self.model
        args = cm._kernel_args(self.load)
        (zone, frac, kb1, kb2, g1, g2, loc, w, radius, d1, d2, db, length, c1, c2, nu1, nu2,
         model, lin, coupling) = args[:20]
        out = np.full(zone.shape, np.nan)
        for m in range(zone.shape[0]):
            C, where, wv, R, D1, D2, Ln = _kernels.position_system(
                zone, frac, kb1, kb2, g1, g2, loc, w, radius, d1, d2, db, length, coupling, m)
            p = np.array([self.slice_load[m][t] for t in where])
            if model == 1:
                delta = _kernels.contact_deflection_twin(p / Ln, R, D1, D2, c1, c2, nu1, nu2)
            else:
                delta = lin * p / Ln
            gap = C @ p + delta + wv - self.transmission_error[m]
            for i, t in enumerate(where):
                out[m][t] = gap[i]
        return out

    def summary(self) -> dict:
        """Scalars of the result (SI and arc seconds) for tables and JSON."""
        return {
            "load_N": self.load,
            "te_mean_m": float(self.transmission_error.mean()),
            "te_peak_to_peak_m": self.te_peak_to_peak,
            "te_peak_to_peak_arcsec": self.te_peak_to_peak_arcsec,
            "stiffness_secant_mean_N_per_m": float(self.stiffness_secant.mean()),
            "stiffness_secant_peak_to_peak_N_per_m": float(np.ptp(self.stiffness_secant)),
            "stiffness_tangent_mean_N_per_m": float(self.stiffness_tangent.mean()),
            "max_hertz_pressure_Pa": float(self.max_pressure.max()),
            "actual_contact_ratio": self.actual_contact_ratio,
            "face_load_factor": self.face_load_factor,
            "converged": self.converged,
        }


@dataclass(frozen=True)
class HarrisMap:
    """Transmission error against load (Harris 1958 map)."""

    loads: np.ndarray
    results: tuple[LtcaResult, ...] = field(repr=False)

    @property
    def te_peak_to_peak(self) -> np.ndarray:
        """Peak-to-peak TE along the normal at each load [m]."""
        return np.array([r.te_peak_to_peak for r in self.results])

    @property
    def te_peak_to_peak_arcsec(self) -> np.ndarray:
        return np.array([r.te_peak_to_peak_arcsec for r in self.results])

    @property
    def mean_stiffness(self) -> np.ndarray:
        """Mean secant stiffness at each load [N/m]."""
        return np.array([r.stiffness_secant.mean() for r in self.results])

    @property
    def contact_ratio(self) -> np.ndarray:
        return np.array([r.actual_contact_ratio for r in self.results])


def ltca_stiffness(pair: PairGeometry, n: int = 256, *, load: float, modifications=(None, None),
                   misalignment: Misalignment | None = None, positions: int = 64, slices: int = 40,
                   contact_model: str = "weber", coupling: bool = True, stagger: float = 0.0,
                   kind: str = "secant", young_modulus=206e9, poisson_ratio=0.3,
                   fillet_foundation: bool = True):
    """Mesh stiffness over one mesh cycle by loaded tooth contact analysis [N/m].

    ``kind`` = ``"secant"`` (``P / Z``, Liu et al. 2021 eq. 5) or ``"tangent"``
    (``dP/dZ``) at the normal load ``load`` [N]; resampled periodically onto ``n``
    phases.  The :class:`~torquesplit.gears.stiffness.MeshStiffness` ``info`` holds the
    LTCA summary (transmission error, contact ratio, pressure).

    Examples
    --------
    >>> import math
    >>> from torquesplit.gears.geometry import GearGeometry, PairGeometry
    >>> a = math.radians(20)
    >>> pair = PairGeometry(GearGeometry(20, 2e-3, a, face_width=0.02),
    ...                     GearGeometry(40, 2e-3, a, face_width=0.02))
    >>> k = ltca_stiffness(pair, 64, load=1000.0, positions=32, slices=2)
    >>> 1e8 < k.mean < 1e9
    True
    """
    from torquesplit.gears.stiffness.result import MeshStiffness, periodic_resample

    if kind not in ("secant", "tangent"):
        raise ModelError([("kind", f"unknown stiffness kind {kind!r}; use 'secant' or 'tangent'")])
    cm = ContactModel(pair, modifications, misalignment,
                      LtcaOptions(positions=positions, slices=slices, contact_model=contact_model,
                                  coupling=coupling, stagger=stagger,
                                  fillet_foundation=fillet_foundation),
                      young_modulus=young_modulus, poisson_ratio=poisson_ratio)
    res = cm.solve(load).require_converged()
    k = res.stiffness_secant if kind == "secant" else res.stiffness_tangent
    info = dict(res.summary(), kind=kind)
    return MeshStiffness.from_samples(periodic_resample(cm.phase, k, n), "ltca", info)
