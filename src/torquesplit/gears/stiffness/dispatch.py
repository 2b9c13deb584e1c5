"""One entry point for every mesh-stiffness method, and a side-by-side comparison."""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Callable, Mapping

from torquesplit.errors import ModelError, OptionTypeError
from torquesplit.gears.geometry import PairGeometry
from torquesplit.gears.stiffness.iso6336 import Iso6336Values, iso6336_stiffness, iso6336_values
from torquesplit.gears.stiffness.potential_energy import potential_energy_stiffness
from torquesplit.gears.stiffness.result import MeshStiffness
from torquesplit.gears.stiffness.tables import (
    constant_stiffness,
    fourier_stiffness,
    load_table_stiffness,
    table_stiffness,
)

__all__ = ["METHODS", "mesh_stiffness", "MethodComparison", "compare_methods"]


def _no_pair(func: Callable[..., MeshStiffness]) -> Callable[..., MeshStiffness]:
    def call(pair, n, **options):
        return func(n=n, **options)
    call.__wrapped__ = func
    return call


def _ltca(pair, n=256, **options):
    # imported on use: the contact package builds on this one
    from torquesplit.gears.contact.ltca import ltca_stiffness

    return ltca_stiffness(pair, n, **options)


def _ltca_options():
    from torquesplit.gears.contact.ltca import ltca_stiffness

    return ltca_stiffness


_ltca.__wrapped_lazy__ = _ltca_options

#: method name -> callable(pair, n, **options).  Methods that need no geometry ignore the pair.
METHODS: dict[str, Callable[..., MeshStiffness]] = {
    "constant": _no_pair(constant_stiffness),
    "iso6336": iso6336_stiffness,
    "potential_energy": potential_energy_stiffness,
    "table": _no_pair(table_stiffness),
    "fourier": _no_pair(fourier_stiffness),
    "load_table": _no_pair(load_table_stiffness),
    "ltca": _ltca,
}


def _option_names(func) -> list[str]:
    lazy = getattr(func, "__wrapped_lazy__", None)
    target = lazy() if lazy is not None else getattr(func, "__wrapped__", func)
    return [p for p in inspect.signature(target).parameters if p not in ("pair", "n")]


def mesh_stiffness(pair: PairGeometry | None, method: str, n: int = 256, **options) -> MeshStiffness:
    """Mesh stiffness over one mesh cycle by the named method [N/m].

    Parameters
    ----------
    pair : PairGeometry or None
        The gear pair (``None`` is accepted for ``constant``, ``table``, ``fourier``
        and ``load_table``, which need no geometry).
    method : str
        ``"constant"`` (``mean=``), ``"iso6336"``, ``"potential_energy"``,
        ``"table"`` (``phase=, stiffness=``), ``"fourier"`` (``mean=, cos=, sin=``),
        ``"load_table"`` (``loads=, phase=, stiffness=, load=``), ``"ltca"``
        (``load=`` and the options of
        :func:`~torquesplit.gears.contact.ltca.ltca_stiffness`).
    n : int
        Number of uniform mesh-phase samples.
    **options
        Passed to the method's function; an unknown option is an error.

    Examples
    --------
    >>> mesh_stiffness(None, "constant", n=4, mean=1e9).mean
    1000000000.0
    """
    try:
        func = METHODS[method]
    except KeyError:
        raise ModelError([("method", f"unknown mesh-stiffness method {method!r}; choose one of "
                                     f"{', '.join(METHODS)}")]) from None
    allowed = _option_names(func)
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise OptionTypeError(f"mesh_stiffness(method={method!r}) got unknown option(s) {unknown}; "
                        f"it accepts {allowed}")
    if pair is None and method in ("iso6336", "potential_energy", "ltca"):
        raise ModelError([("pair", f"method {method!r} needs the pair geometry")])
    return func(pair, n, **options)


@dataclass(frozen=True)
class MethodComparison:
    """Several mesh-stiffness results of one pair, with the ISO 6336-1 reference values."""

    pair: PairGeometry
    labels: tuple[str, ...]
    results: tuple[MeshStiffness, ...]
    iso: Iso6336Values

    @property
    def iso_mesh_stiffness(self) -> float:
        """ISO ``c_gamma b`` along the flank normal [N/m] -- the reference mean."""
        return self.iso.mesh_stiffness_normal

    def rows(self) -> list[dict]:
        """One dict per method: label, mean, minimum, maximum, peak_to_peak [N/m] and
        mean / ISO mesh stiffness [-]."""
        ref = self.iso_mesh_stiffness
        return [{"method": lab, "mean": r.mean, "minimum": r.minimum, "maximum": r.maximum,
                 "peak_to_peak": r.peak_to_peak, "mean_over_iso": r.mean / ref}
                for lab, r in zip(self.labels, self.results)]

    def table(self) -> str:
        """Plain-text table of :meth:`rows` (stiffness in N/m)."""
        head = f"{'method':<42}{'mean':>12}{'min':>12}{'max':>12}{'peak-peak':>12}{'mean/ISO':>10}"
        lines = [head, "-" * len(head)]
        for r in self.rows():
            lines.append(f"{r['method']:<42}{r['mean']:12.4e}{r['minimum']:12.4e}{r['maximum']:12.4e}"
                         f"{r['peak_to_peak']:12.4e}{r['mean_over_iso']:10.3f}")
        lines.append(f"ISO 6336-1: c' = {self.iso.c_prime_iso:.3f} N/(mm um), c_gamma = "
                     f"{self.iso.c_gamma_iso:.3f} N/(mm um) (transverse), c_gamma b / "
                     f"cos^2 beta_b = {self.iso_mesh_stiffness:.4e} N/m (normal), eps_alpha = {self.pair.transverse_contact_ratio:.4f}, "
                     f"eps_beta = {self.pair.overlap_contact_ratio:.4f}")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


def compare_methods(pair: PairGeometry, n: int = 256, *, young_modulus=206e9, poisson_ratio=0.3,
                    bore_radius=None, slices: int | None = None, blank_factor: float = 1.0,
                    extra: Mapping[str, MeshStiffness] | None = None) -> MethodComparison:
    """All applicable mesh-stiffness methods of ``pair`` side by side.

    Computes ISO 6336-1 with its default scale first and then the other scale
    (``single_pair`` / ``c_gamma``), and -- for external pairs -- the potential-energy
    method with and without the fillet-foundation term; ``extra`` adds user results
    (tables, LTCA) by label.
    """
    e = young_modulus
    labels, results = [], []
    default = iso6336_stiffness(pair, n, blank_factor=blank_factor, young_modulus=e)
    other = "c_gamma" if default.info["scale"] == "single_pair" else "single_pair"
    labels.append(f"iso6336 ({default.info['scale']})")
    results.append(default)
    labels.append(f"iso6336 ({other})")
    results.append(iso6336_stiffness(pair, n, scale=other, blank_factor=blank_factor, young_modulus=e))
    if not pair.is_internal:
        opts = dict(young_modulus=e, poisson_ratio=poisson_ratio, bore_radius=bore_radius,
                    slices=None if pair.gear1.beta == 0 else slices)
        labels.append("potential_energy")
        results.append(potential_energy_stiffness(pair, n, **opts))
        labels.append("potential_energy (no fillet foundation)")
        results.append(potential_energy_stiffness(pair, n, fillet_foundation=False, **opts))
    for lab, res in (extra or {}).items():
        labels.append(str(lab))
        results.append(res)
    iso = iso6336_values(pair, blank_factor=blank_factor, young_modulus=e)
    return MethodComparison(pair=pair, labels=tuple(labels), results=tuple(results), iso=iso)
