"""Which laser beams hit a leg, from the leg centres (the predicted occupancy of the clock
estimate, :mod:`gaitval.registration.clock`).

A beam with unit vector u hits a circle of centre c and radius r when ``c.u > 0`` and
``|c x u| < r``.  Evaluated for every (frame, leg, beam) that is 1081 beams per leg and
frame, most of them nowhere near the leg: a beam can only hit it within ``asin(r / |c|)``
of the leg's bearing.  :func:`predicted_occupancy` therefore evaluates the same predicate,
with the same arithmetic, only on the beams within that bearing plus a margin of two beam
steps, and leaves the others at 0 — the same 0/1 values as the full evaluation
(:func:`predicted_occupancy_full`, which it falls back to when the beams are not evenly
spaced, a leg is within 1.5 radii of the sensor, or a window reaches the ±180° seam).
"""
from __future__ import annotations

import numpy as np

__all__ = ["predicted_occupancy", "predicted_occupancy_full"]


def predicted_occupancy_full(legs_s: np.ndarray, angles: np.ndarray, radius_m: float
                             ) -> np.ndarray:
    """:func:`predicted_occupancy` over every (frame, leg, beam)."""
    u = np.stack([np.cos(angles), np.sin(angles)], axis=-1)           # (nb, 2)
    cx, cy = legs_s[..., 0], legs_s[..., 1]
    along = cx[..., None] * u[:, 0] + cy[..., None] * u[:, 1]          # (n, L, nb)
    perp = np.abs(cx[..., None] * u[:, 1] - cy[..., None] * u[:, 0])
    with np.errstate(invalid="ignore"):
        hit = ((along > 0) & (perp < radius_m)).any(axis=1).astype(float)
    unknown = ~np.all(np.isfinite(legs_s), axis=(1, 2))
    hit[unknown] = np.nan
    return hit


def _windows(legs_s, angles, radius_m):
    """First beam index (n, L) and width of the beam windows around each leg's bearing,
    or None when the windowed evaluation does not apply (see the module docstring)."""
    nb = len(angles)
    if nb < 3:
        return None
    inc = (angles[-1] - angles[0]) / (nb - 1)
    if not inc > 0 or np.max(np.abs(angles - (angles[0] + inc * np.arange(nb)))) > 0.01 * inc:
        return None
    cx, cy = legs_s[..., 0], legs_s[..., 1]
    known = np.isfinite(cx) & np.isfinite(cy)
    d = np.hypot(cx[known], cy[known])
    if d.size == 0 or d.min() <= 1.5 * radius_m:
        return None
    half = np.arcsin(radius_m / d) + 2 * inc
    bearing = np.arctan2(cy[known], cx[known])
    if np.any(np.abs(bearing) + half >= np.pi):
        return None
    lo = np.zeros(cx.shape, dtype=np.int64)
    hi = np.zeros(cx.shape, dtype=np.int64)
    lo[known] = np.floor((bearing - half - angles[0]) / inc).astype(np.int64)
    hi[known] = np.ceil((bearing + half - angles[0]) / inc).astype(np.int64)
    width = int((hi - lo).max()) + 1
    return lo, width, known


def predicted_occupancy(legs_s: np.ndarray, angles: np.ndarray, radius_m: float) -> np.ndarray:
    """Which beams hit a leg, from leg centres in the sensor frame.

    Parameters
    ----------
    legs_s : ndarray (n, n_legs, 2)
        Leg centres in the sensor frame (metres); NaN = unknown.
    angles : ndarray (n_beams,)
    radius_m : float
        Leg radius (half the subject's leg width).

    Returns
    -------
    ndarray (n, n_beams) of 0/1 floats; NaN for frames where any leg is unknown.
    """
    win = _windows(legs_s, angles, radius_m)
    if win is None:
        return predicted_occupancy_full(legs_s, angles, radius_m)
    lo, width, known = win
    nb = len(angles)
    idx = lo[..., None] + np.arange(width)                             # (n, L, W)
    inside = (idx >= 0) & (idx < nb) & known[..., None]
    idx = np.clip(idx, 0, nb - 1)
    ux, uy = np.cos(angles)[idx], np.sin(angles)[idx]                  # the full version's u
    cx, cy = legs_s[..., 0][..., None], legs_s[..., 1][..., None]
    along = cx * ux + cy * uy
    perp = np.abs(cx * uy - cy * ux)
    with np.errstate(invalid="ignore"):
        h = (along > 0) & (perp < radius_m) & inside
    hitb = np.zeros((legs_s.shape[0], nb), dtype=bool)
    frame = np.broadcast_to(np.arange(legs_s.shape[0])[:, None, None], idx.shape)
    hitb[frame[h], idx[h]] = True                                      # legs: any()
    hit = hitb.astype(float)
    hit[~np.all(np.isfinite(legs_s), axis=(1, 2))] = np.nan
    return hit
