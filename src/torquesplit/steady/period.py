"""The fundamental period of a model's excitations, and excitations kept for a period.

A periodic steady state exists only over a period common to every excitation: mesh
stiffness, impact-force and friction tables (one per mesh cycle), error sinusoids
(shaft rotations for eccentricities), per-engagement backlash sequences (n engagements
per repeat).  Their frequencies are rational multiples of each other (tooth counts), so
the least common period is 1 / gcd(f_1, ..., f_m), computed here in exact rational
arithmetic.  It is often long: a pair of gears repeats only after the hunting-tooth
period, and an eccentricity error on a slow shaft makes the period one revolution of
that shaft.  :func:`fundamental_period` says so (:class:`LongPeriodError`) instead of
assuming a period, and :func:`keep_excitations` keeps only the excitations that are
periodic with a chosen base (one stage's mesh frequency, one shaft's rotation): the
others are replaced by their means, and the list of what was dropped is returned.

Units: Hz and s.  Tables and sequences whose values do not change are not excitations.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from torquesplit.assembly.structure import Structure
from torquesplit.errors import LongPeriodError, PeriodError, SolverError  # noqa: F401 - re-exported
from torquesplit.errors import OptionError

__all__ = ["ExcitationSource", "Period", "PeriodError", "LongPeriodError",
           "default_max_cycles", "excitation_sources", "fundamental_period",
           "keep_excitations", "scale_speed", "base_frequency"]

MAX_DENOMINATOR = 10**6
"""Largest denominator of a frequency ratio accepted as rational (tooth-count products
of real trains are far below)."""
RTOL = 1e-9
"""Relative mismatch below which a frequency ratio equals its rational approximation."""
TYPED_RTOL = 1e-5
"""Relative mismatch of a base frequency given as a number (``keep=2675.335``) from a
whole fraction of an excitation's frequency, below which it is that fraction."""
MAX_CYCLES = 1000
"""Default largest number of cycles of the fastest excitation in one period (harmonic
balance: its harmonics grow with the cycles)."""
MAX_CYCLES_SHOOTING = 10_000
"""The same for shooting (its cost grows with the RK4 steps of one period: Liu et al.
2021's full period holds 3638 cycles, Jin et al. 2019's 7252; their times are in
benchmarks/STEADY_RESULTS.md)."""


def default_max_cycles(method: str) -> int:
    """The longest period accepted by default for ``method`` ('hb', 'shooting' or 'auto',
    which shoots on long periods)."""
    return MAX_CYCLES if method == "hb" else MAX_CYCLES_SHOOTING


@dataclass(frozen=True)
class ExcitationSource:
    """One periodic excitation of the structure."""

    element: str
    kind: str
    """'stiffness', 'impact force', 'torque fluctuation', 'friction', 'error' (or
    'harmonic k of the error', a harmonic of the mesh's error series) or 'backlash
    sequence'."""
    frequency: float
    """[Hz]"""
    index: int
    """Element index (error sinusoids: the index of the sinusoid)."""

    def describe(self, speed: float = 1.0) -> str:
        """In words, at ``speed`` times the model's speeds."""
        return f"{self.kind} of {self.element} at {self.frequency * speed:.6g} Hz"


@dataclass(frozen=True)
class Period:
    """The least common period of a set of excitations."""

    frequency: float
    """Fundamental frequency f0 [Hz] (0 if nothing excites the structure)."""
    sources: tuple[ExcitationSource, ...]
    orders: tuple[int, ...]
    """Cycles of each source in one period (its frequency / f0, an integer)."""

    @property
    def period(self) -> float:
        """[s]; inf without excitation."""
        return 1.0 / self.frequency if self.frequency > 0 else math.inf

    @property
    def max_order(self) -> int:
        return max(self.orders, default=0)

    def describe(self, speed: float = 1.0) -> str:
        """In words, at ``speed`` times the model's speeds (every frequency scales)."""
        if not self.sources:
            return "no time-varying excitation (any period; the steady state is static)"
        top = max(range(len(self.sources)), key=lambda i: self.orders[i])
        slow = min(range(len(self.sources)), key=lambda i: self.orders[i])
        head = (f"least common period {self.period / speed:.6g} s (f0 = "
                f"{self.frequency * speed:.6g} Hz): ")
        cycles = lambda k: f"{k} cycle{'s' if k != 1 else ''}"  # noqa: E731
        if self.orders[top] == self.orders[slow]:  # one frequency: name one source
            more = len(self.sources) - 1
            return (head + f"{cycles(self.orders[top])} of the "
                    f"{self.sources[top].describe(speed)}"
                    + (f" and of {more} more excitation{'s' if more != 1 else ''} at that "
                       f"frequency" if more else ""))
        return (head + f"{cycles(self.orders[top])} of the "
                f"{self.sources[top].describe(speed)}, {self.orders[slow]} of the "
                f"{self.sources[slow].describe(speed)}")


def _varies(row: np.ndarray) -> bool:
    scale = float(np.max(np.abs(row))) if row.size else 0.0
    return scale > 0 and float(np.ptp(row)) > 1e-12 * scale


def excitation_sources(structure: Structure) -> list[ExcitationSource]:
    """Every time-varying excitation of ``structure`` (constant tables are left out)."""
    s = structure
    out = []
    for e in range(s.n_elements):
        f = float(s.frequency[e])
        if f <= 0:
            continue
        name = s.element_names[e]
        if _varies(s.stiffness_table[e]):
            out.append(ExcitationSource(name, "stiffness", f, e))
        if _varies(s.force_table[e]):
            fluct = name in (s.metadata.get("torque_fluctuation_elements") or ())
            out.append(ExcitationSource(name, "torque fluctuation" if fluct else
                                        "impact force", f, e))
        gaps = s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]
        if gaps.size > 1 and _varies(gaps):
            out.append(ExcitationSource(name, "backlash sequence", f / gaps.size, e))
    for j, e in enumerate(s.fr_el):
        rows = s.friction_table[3 * j:3 * j + 3]
        if s.frequency[e] > 0 and any(_varies(r) for r in rows):
            out.append(ExcitationSource(s.element_names[e], "friction", float(s.frequency[e]),
                                        int(e)))
    owner = np.repeat(np.arange(s.n_elements), np.diff(s.error_ptr))
    for i in range(len(s.error_amplitude)):
        if s.error_amplitude[i] != 0 and s.error_omega[i] != 0:
            f = abs(float(s.error_omega[i])) / (2 * math.pi)
            f_mesh = float(s.frequency[owner[i]])
            k = round(f / f_mesh) if f_mesh > 0 else 0
            # a harmonic of the mesh's own error series (an LTCA's loaded TE) named so:
            # '14 cycles of the error of m at 7583 Hz' read as a slow error (a reviewer)
            kind = (f"harmonic {k} of the error" if k > 1 and abs(f - k * f_mesh) <= 1e-9 * f
                    else "error")
            out.append(ExcitationSource(s.element_names[owner[i]], kind, f, i))
    return out


def _rational(x: float) -> Fraction | None:
    """The rational of smallest denominator (bounds 10, 100, ..., MAX_DENOMINATOR)
    within RTOL of x, or None."""
    bound = 10
    while bound <= MAX_DENOMINATOR:
        fr = Fraction(x).limit_denominator(bound)
        if abs(float(fr) - x) <= RTOL * abs(x):
            return fr
        bound *= 10
    return None


def fundamental_period(structure: Structure, *, max_cycles: int | None = MAX_CYCLES
                       ) -> Period:
    """The least common period of every excitation of ``structure``.

    Raises :class:`PeriodError` when two frequencies have no rational ratio (within
    1e-9, denominators up to 1e6), and :class:`LongPeriodError` when the period holds
    more than ``max_cycles`` cycles of the fastest excitation (None: no limit); both
    messages say which excitations set the period and how to keep fewer.
    """
    src = excitation_sources(structure)
    if not src:
        return Period(0.0, (), ())
    f_ref = max(x.frequency for x in src)
    ratios = []
    for x in src:
        fr = _rational(x.frequency / f_ref)
        if fr is None:
            raise PeriodError(
                f"no common period: the {x.describe()} has no rational ratio to "
                f"{f_ref:.9g} Hz (denominator up to {MAX_DENOMINATOR}); keep only the "
                f"excitations of one stage or shaft (keep=...), or make the frequencies "
                f"commensurate (tooth counts and speeds of one gear train are).")
        ratios.append(fr)
    num, den = 0, 1
    for r in ratios:
        num = math.gcd(num * r.denominator, r.numerator * den)
        den = den * r.denominator
        g = math.gcd(num, den)
        num, den = num // g, den // g
    f0 = f_ref * num / den
    orders = tuple(int(round(float(r * den / num))) for r in ratios)
    per = Period(f0, tuple(src), orders)
    if max_cycles is not None and per.max_order > max_cycles:
        raise LongPeriodError(
            f"the {per.describe()}; that is longer than {max_cycles} cycles of the fastest "
            f"excitation. Keep only one stage's or one shaft's excitations "
            f"(keep='<stage, mesh or body>', the others by their means; stages: "
            f"{', '.join(_stages(structure)) or 'none'}), or accept the long period "
            f"(max_cycles={per.max_order}).")
    return per


def _stages(structure: Structure) -> list[str]:
    meshes = structure.metadata.get("meshes", {})
    return sorted({str(m.get("stage")) for m in meshes.values() if m.get("stage")})


def base_frequency(structure: Structure, keep, kinematics=None) -> float:
    """The frequency [Hz] named by ``keep``: a number (Hz), a mesh name, a stage label
    (its meshes' common frequency) or, with ``kinematics``, a body (one revolution)."""
    if isinstance(keep, (int, float)):
        if not keep > 0:
            raise OptionError(f"keep={keep!r}: a base frequency must be > 0 Hz.")
        # a frequency as typed (2675.335 Hz for half of 5350.67 Hz): the excitation's own
        # fraction where it lies within TYPED_RTOL of one, so that its multiples are kept
        # and the period is exact
        for x in excitation_sources(structure):
            k = round(x.frequency / keep)
            if k >= 1 and abs(x.frequency / keep - k) <= TYPED_RTOL * k:
                return x.frequency / k
        return float(keep)
    names = structure.element_names
    meshes = structure.metadata.get("meshes", {})
    if keep in meshes or keep in names:
        f = float(structure.frequency[names.index(keep)])
        if f > 0:
            return f
    stage = [float(structure.frequency[names.index(m)]) for m, meta in meshes.items()
             if str(meta.get("stage")) == str(keep)]
    if stage:
        if max(stage) - min(stage) > RTOL * max(stage):
            raise OptionError(f"the meshes of stage {keep!r} have different frequencies "
                              f"{sorted(set(stage))} Hz; keep one mesh by its name instead.")
        return stage[0]
    if kinematics is not None and keep in kinematics.bodies:
        return abs(kinematics.bodies[keep].speed) / (2 * math.pi)
    raise OptionError(f"keep={keep!r} is no mesh, stage or body of the model; use one of "
                      f"the stages {_stages(structure)}, a mesh {list(meshes)} or a "
                      f"frequency in Hz.")


def keep_excitations(structure: Structure, base: float):
    """Keep the excitations whose frequency is a whole multiple of ``base`` [Hz].

    The others are replaced by their means: a stiffness, impact-force or friction table
    by its mean value, an error sinusoid by zero, a backlash sequence by its mean
    half-gap.  Returns ``(structure, dropped)``: the new structure (period 1 / base)
    and the :class:`ExcitationSource` list of what was replaced.
    """
    s = structure
    ktab = s.stiffness_table.copy()
    ftab = s.force_table.copy()
    frtab = s.friction_table.copy()
    amp = s.error_amplitude.copy()
    gap_ptr = [0]
    gaps: list[float] = []
    dropped = []

    def multiple(f):
        r = f / base
        return r >= 1 - RTOL and abs(r - round(r)) <= RTOL * r

    for x in excitation_sources(s):
        if multiple(x.frequency):
            continue
        dropped.append(x)
        if x.kind == "stiffness":
            ktab[x.index] = ktab[x.index].mean()
        elif x.kind in ("impact force", "torque fluctuation"):
            ftab[x.index] = ftab[x.index].mean()
        elif x.kind == "friction":
            j = int(np.flatnonzero(s.fr_el == x.index)[0])
            frtab[3 * j:3 * j + 3] = frtab[3 * j:3 * j + 3].mean(axis=1, keepdims=True)
        elif x.kind.endswith("error"):  # (the error, or a harmonic of its series)
            amp[x.index] = 0.0
    drop_gaps = {x.index for x in dropped if x.kind == "backlash sequence"}
    for e in range(s.n_elements):
        seq = s.gap_values[s.gap_ptr[e]:s.gap_ptr[e + 1]]
        if e in drop_gaps:
            seq = np.array([seq.mean()])
        gaps.extend(seq.tolist())
        gap_ptr.append(len(gaps))
    out = dataclasses.replace(
        s, stiffness_table=ktab, force_table=ftab, friction_table=frtab,
        error_amplitude=amp, gap_ptr=np.asarray(gap_ptr, dtype=np.int64),
        gap_values=np.asarray(gaps, dtype=np.float64),
        metadata={**s.metadata, "kept_base_frequency": float(base),
                  "dropped_excitations": [x.describe() for x in dropped]})
    return out, dropped


def scale_speed(structure: Structure, factor: float) -> Structure:
    """The structure at ``factor`` times its speed: every excitation frequency and error
    angular frequency scaled (tables are functions of the mesh phase and stay)."""
    return dataclasses.replace(structure, frequency=structure.frequency * factor,
                               error_omega=structure.error_omega * factor)
