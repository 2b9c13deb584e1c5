"""Linear stability of the fixed-step RK4 integrator for an assembled structure.

The check linearises the equations of motion with every element at the maximum of its
stiffness table and every dead zone closed (the stiffest state the run can reach)::

    A = [[0, I], [-M^-1 K_max, -M^-1 (C + G)]]

and requires ``|R(h lambda)| <= 1`` for every eigenvalue ``lambda`` of ``A``, with the
RK4 amplification factor ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``.  Zero (rigid-body)
eigenvalues give ``R = 1`` and never limit the step; eigenvalues with a clearly positive
real part (a physically unstable model, e.g. negative stiffness) are left out, since
no step makes them decay.
"""

from __future__ import annotations

import math

import numpy as np

from torquesplit._memo import remember_content, remember_last
from torquesplit.assembly.structure import Structure
from torquesplit.errors import StepTooLargeError

__all__ = [
    "rk4_amplification",
    "system_eigenvalues",
    "highest_natural_frequency",
    "stable_step",
    "check_step",
    "highest_mode",
    "stability_cause",
]

SAFETY = 0.8
"""Safe step = SAFETY x the largest stable step."""

_REAL_TOL = 1e-8  # real parts below this x max|lambda| count as zero (round-off)
_R_TOL = 1e-12  # |R| may exceed 1 by this much (round-off)


def rk4_amplification(z):
    """RK4 amplification factor R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24."""
    return 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)))


def _system_matrix(structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """``A`` of the module docstring (maximum stiffness, gaps closed) and ``k_max``."""
    n = structure.n_dof
    k_max = structure.stiffness_table.max(axis=1) if structure.n_table else np.zeros(0)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -structure.inv_mass[:, None] * structure.stiffness_matrix(k_max)
    A[n:, n:] = -structure.inv_mass[:, None] * (structure.damping_matrix()
                                                + structure.gyroscopic_matrix())
    return A, k_max


@remember_last(replay=False)
def system_eigenvalues(structure: Structure) -> np.ndarray:
    """Eigenvalues of the first-order system at maximum stiffness, all gaps closed [1/s].

    Round-off positive real parts (below 1e-8 max|lambda|) are set to zero.  Kept per
    live structure (frozen), and per system matrix (:func:`_eigenvalues`), and returned
    read-only: a run with a given step checks it with two of these eigenvalue problems
    (6 ms of every run of Ji & Li's drive).
    """
    if structure.n_dof == 0:
        lam = np.zeros(0, dtype=complex)
        lam.setflags(write=False)
        return lam
    return _eigenvalues(_system_matrix(structure)[0])


@remember_content
def _eigenvalues(A: np.ndarray) -> np.ndarray:
    """:func:`system_eigenvalues` of the system matrix ``A``, kept by its content: the
    cases of a study that vary errors or phases have new structures but the same ``A``
    (with :func:`_top_mode` and :func:`_largest_stable_step`, 1.3 ms of a Dong et
    al. 2021 Monte Carlo case's 20 ms set-up)."""
    lam = np.linalg.eigvals(A)
    scale = np.max(np.abs(lam)) if lam.size else 0.0
    tiny = (lam.real > 0) & (lam.real <= _REAL_TOL * scale)
    lam = np.where(tiny, 1j * lam.imag, lam)
    lam.setflags(write=False)
    return lam


def highest_natural_frequency(structure: Structure) -> float:
    """Largest |lambda| / 2 pi of :func:`system_eigenvalues` [Hz] (0 without stiffness)."""
    lam = system_eigenvalues(structure)
    return float(np.max(np.abs(lam)) / (2 * math.pi)) if lam.size else 0.0


def highest_mode(structure: Structure) -> tuple[float, str]:
    """Highest natural frequency at maximum stiffness [Hz] and the element holding the
    largest share of that mode's strain energy (the one that sets the step)."""
    n = structure.n_dof
    if n == 0:
        return 0.0, ""
    k_max = structure.stiffness_table.max(axis=1)
    V = structure.projection_matrix()
    f, phi = _top_mode(k_max, V, structure.inv_mass)
    energy = k_max * (V @ phi) ** 2
    name = structure.element_names[int(np.argmax(energy))] if energy.size else ""
    return f, name


@remember_content
def _top_mode(k_max: np.ndarray, V: np.ndarray, inv_mass: np.ndarray):
    """Highest undamped natural frequency [Hz] of stiffnesses ``k_max`` on projections
    ``V`` and its mass-normalised mode shape (read-only), kept by content as
    :func:`_eigenvalues`."""
    K = V.T @ (k_max[:, None] * V)
    d = np.sqrt(inv_mass)
    lam, psi = np.linalg.eigh(0.5 * (d[:, None] * K * d[None, :] + (d[:, None] * K * d[None, :]).T))
    phi = d * psi[:, -1]
    phi.setflags(write=False)
    return float(np.sqrt(max(lam[-1], 0.0)) / (2 * math.pi)), phi


def stability_cause(structure: Structure) -> str:
    """What sets :func:`stable_step`, in words: the step-limiting eigenvalue of largest
    modulus (RK4's region reaches about as far along the real as along the imaginary
    axis, so it leaves the region first), whether it is an oscillation or a heavily damped
    motion, and the element with the largest share of its forces
    ``|k_e + lambda c_e| |V_e phi|^2`` (c_e from :meth:`Structure.element_damping`, a
    spline's regularised friction included)."""
    n = structure.n_dof
    if n == 0:
        return ""
    A, k_max = _system_matrix(structure)
    c = structure.element_damping()
    lam, vec = np.linalg.eig(A)
    limiting = _limiting_mask(lam)
    if not limiting.any() or not k_max.size:
        return ""
    size = np.abs(lam)
    i = int(np.argmax(np.where(limiting, size, -1.0)))
    phi = vec[:n, i]
    share = np.abs(k_max + lam[i] * c) * np.abs(structure.projection_matrix() @ phi) ** 2
    e = int(np.argmax(share))
    lam_i = lam[i]
    if abs(lam_i.imag) < abs(lam_i.real):
        what = f"a heavily damped motion (decay rate {-lam_i.real:.3g} 1/s)"
    else:
        what = f"a mode at {abs(lam_i) / (2 * math.pi):.6g} Hz"
    what += f", mostly element '{structure.element_names[e]}'"
    friction = c[e] - structure.damping[e]  # the spline friction's share of c_e
    if friction > 0 and abs(lam_i) * friction > k_max[e]:
        what += (" (its regularised spline friction F_m / v: a larger [analysis] "
                 "spline_velocity_scale v makes it softer)")
    return what


def _limiting_mask(lam: np.ndarray) -> np.ndarray:
    """Which eigenvalues can limit the step (physically decaying or oscillating)."""
    scale = np.max(np.abs(lam)) if lam.size else 0.0
    return (lam.real <= _REAL_TOL * scale) & (np.abs(lam) > 0.0)


def _limiting(lam: np.ndarray) -> np.ndarray:
    """The eigenvalues of :func:`_limiting_mask`."""
    return lam[_limiting_mask(lam)]


def _is_stable(h: float, lam: np.ndarray) -> bool:
    return bool(np.all(np.abs(rk4_amplification(h * lam)) <= 1.0 + _R_TOL))


@remember_last(replay=False)
def stable_step(structure: Structure) -> float:
    """Largest RK4 step [s] for which every mode stays bounded (``inf`` if none limits).

    Found by bisection on |R(h lambda)| <= 1 (RK4's region lies within |z| < 3); kept
    per live structure, as its eigenvalues are, and per set of eigenvalues.
    """
    return _largest_stable_step(_limiting(system_eigenvalues(structure)))


@remember_content
def _largest_stable_step(lam: np.ndarray) -> float:
    """:func:`stable_step` of the step-limiting eigenvalues ``lam``."""
    if lam.size == 0:
        return math.inf
    lo, hi = 0.0, 4.0 / float(np.max(np.abs(lam)))
    while _is_stable(hi, lam):  # not expected: the region lies inside |z| < 3
        lo, hi = hi, 2.0 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if _is_stable(mid, lam):
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-13 * hi:
            break
    return lo


def check_step(structure: Structure, h: float) -> float:
    """Raise :class:`StepTooLargeError` if RK4 with step ``h`` is unstable; else return
    the safe step (0.8 x the largest stable step).

    Examples
    --------
    >>> from torquesplit.assembly.structure import build_structure
    >>> s = build_structure(["a.x"], [1.0], [dict(name="k", dofs=[0], coefs=[1.0],
    ...                                           stiffness=1.0e6)])
    >>> round(check_step(s, 1e-4), 6)
    0.002263
    """
    h = float(h)
    if not (h > 0.0 and math.isfinite(h)):
        raise StepTooLargeError(f"RK4 step must be a positive finite number of seconds, "
                                f"got {h!r}; give e.g. step=1e-6.")
    lam = _limiting(system_eigenvalues(structure))
    h_stable = stable_step(structure)
    safe = SAFETY * h_stable
    if lam.size and not _is_stable(h, lam):
        f_max = float(np.max(np.abs(lam))) / (2 * math.pi)
        raise StepTooLargeError(
            f"RK4 step {h:.4g} s is unstable for this model: the highest natural "
            f"frequency is {f_max:.6g} Hz (period {1.0 / f_max:.4g} s), so the largest "
            f"stable step is {h_stable:.4g} s and a safe step is {safe:.4g} s. "
            f"Use step <= {safe:.4g} s (or a larger steps_per_period), or method='dopri'."
        )
    return safe
