"""Where the tooth pairs are during one mesh cycle.

Mesh phase ``phi`` runs over [0, 1) per tooth-mesh period.  ``phi = 0`` is the instant
a new tooth pair enters contact at the start of active profile A (the wheel tip) -- for
helical gears at the reference end ``y = 0`` of the face.  Tooth pair ``k`` (k = 0 the
newest) then sits, at face position ``y``, at the transverse path position::

    s_k(phi, y) = s_A + (phi + k) p_bt - y tan(beta_b)

(the contact line of a helical pair is inclined at ``beta_b`` in the plane of action,
so a slice further along the face engages later, by ``y tan(beta_b) / p_bt`` of a
cycle).  A pair touches at ``(phi, y)`` while ``s_A <= s_k < s_E``.

All lengths in metres.
"""

from __future__ import annotations

import math

import numpy as np

from torquesplit.errors import ModelError
from torquesplit.gears.geometry import PairGeometry

__all__ = ["phase_grid", "pair_count", "pair_positions", "contact_line_length", "slice_offsets"]


def phase_grid(n: int) -> np.ndarray:
    """``n`` uniform mesh phases ``k / n``, k = 0..n-1 (periodic, endpoint excluded)."""
    if not isinstance(n, (int, np.integer)) or n < 2:
        raise ModelError([("n", f"the number of phase samples must be an integer >= 2, got {n!r}")])
    return np.arange(n, dtype=float) / n


def pair_count(pair: PairGeometry) -> int:
    """Number of tooth-pair indices ``k`` that can touch somewhere on the face in one cycle."""
    span = pair.transverse_contact_ratio + pair.overlap_contact_ratio
    return int(math.floor(span)) + 2


def require_contact(pair: PairGeometry) -> None:
    """Refuse pairs whose total contact ratio is below 1 (contact would be lost)."""
    if pair.total_contact_ratio < 1.0:
        raise ModelError(
            [("addendum", f"total contact ratio {pair.total_contact_ratio:.3f} < 1: the pair loses "
                          "contact during each mesh cycle; increase addenda or face width")],
            source="PairGeometry",
        )


def slice_offsets(pair: PairGeometry, slices: int) -> tuple[np.ndarray, float]:
    """Phase lag of each face slice and the slice width.

    The face width ``b`` (of one helix) is cut into ``slices`` equal slices; slice j
    (centre ``y_j = (j + 1/2) b / N``) lags by ``y_j tan(beta_b) / p_bt`` cycles.
    Returns ``(lag [cycles], slice width [m])``.
    """
    if not isinstance(slices, (int, np.integer)) or slices < 1:
        raise ModelError([("slices", f"must be a positive integer, got {slices!r}")])
    b = pair.face_width
    y = (np.arange(slices) + 0.5) * b / slices
    lag = y * math.tan(pair.base_helix_angle) / pair.base_pitch
    return lag, b / slices


def pair_positions(pair: PairGeometry, phase: np.ndarray, lag: np.ndarray | float = 0.0) -> np.ndarray:
    """Transverse path positions ``s`` of every tooth pair [m].

    Shape ``phase.shape + lag.shape + (K,)`` with ``K = pair_count(pair)``.
    Positions outside ``[s_A, s_E)`` are not in contact.
    """
    phase = np.asarray(phase, dtype=float)
    lag = np.asarray(lag, dtype=float)
    k = np.arange(pair_count(pair), dtype=float)
    cyc = phase[..., None] - lag[None, ...] if lag.ndim else phase - lag
    cyc = cyc[..., None] + k
    return pair.path_start + cyc * pair.base_pitch


def in_contact(pair: PairGeometry, s: np.ndarray) -> np.ndarray:
    """Boolean mask: position on the active path ``s_A <= s < s_E``."""
    return (s >= pair.path_start) & (s < pair.path_end)


def contact_line_length(pair: PairGeometry, phase: np.ndarray, offset: float = 0.0) -> np.ndarray:
    """Total length of the contact lines of one helix at each phase [m].

    A pair whose contact line crosses the face end ``y = 0`` at transverse position
    ``s0`` occupies ``s0 - y tan(beta_b)`` for ``0 <= y <= b``; the part inside
    ``[s_A, s_E]`` has axial extent ``Delta y`` and length ``Delta y / cos(beta_b)``
    (the field-of-action construction, e.g. ISO 6336-1 / Niemann & Winter).
    For spur gears each pair in contact contributes ``b``.
    ``offset`` shifts the phase (cycles) -- used for the second helix.
    """
    phase = np.mod(np.asarray(phase, dtype=float) + offset, 1.0)
    b = pair.face_width
    s0 = pair_positions(pair, phase)  # (n, K) at y = 0
    tb = math.tan(pair.base_helix_angle)
    if tb == 0.0:
        return in_contact(pair, s0).sum(axis=-1) * b
    y_lo = np.clip((s0 - pair.path_end) / tb, 0.0, b)
    y_hi = np.clip((s0 - pair.path_start) / tb, 0.0, b)
    return np.clip(y_hi - y_lo, 0.0, None).sum(axis=-1) / math.cos(pair.base_helix_angle)
