"""Marker gaps: fill short ones with a cubic, leave long ones missing.

A gap is a run of missing samples (NaN) strictly inside a trajectory.  Gaps of at most
``max_gap_s`` (config ``groundtruth.max_gap_s``, default 0.10 s, i.e. 20 frames at 200 Hz
or 10 at 100 Hz, the order of Vicon Nexus' default spline-fill limit) are filled by a cubic
spline through up to four valid samples on each side of the gap (a local spline, so a
distant gap or outlier cannot influence the fill).  Longer gaps, and missing samples at the
start or end of a trajectory, stay NaN and are counted by the caller as frames excluded
from every later metric.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

#: default maximum length of a gap that is filled (seconds)
MAX_GAP_S = 0.10


def nan_runs(missing: np.ndarray) -> list[tuple[int, int]]:
    """Runs of True in a boolean vector as (start, stop) index pairs (stop exclusive)."""
    m = np.concatenate([[False], np.asarray(missing, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def fill_short_gaps(x: np.ndarray, rate_hz: float, max_gap_s: float = MAX_GAP_S,
                    n_side: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Fill interior gaps of at most ``max_gap_s`` with a local cubic spline.

    Parameters
    ----------
    x : ndarray (n_frames, ...) 
        Trajectory (e.g. (n, 3) marker positions in metres); a frame is missing when any
        of its values is NaN.
    rate_hz : float
        Sampling rate (Hz).
    max_gap_s : float
        Longest gap that is filled (seconds); ``floor(max_gap_s * rate_hz + 1e-9)`` frames.
    n_side : int
        Valid samples taken on each side of a gap for the spline (fewer at the edges or
        between gaps; with two samples in all the fill is linear).

    Returns
    -------
    filled : ndarray, same shape as ``x``
    was_filled : ndarray (n_frames,) bool
    """
    x = np.asarray(x, dtype=float)
    out = x.copy()
    flat = out.reshape(len(x), -1)
    missing = ~np.all(np.isfinite(flat), axis=1)
    flat[missing] = np.nan
    filled = np.zeros(len(x), dtype=bool)
    max_len = int(np.floor(max_gap_s * rate_hz + 1e-9))
    if max_len < 1 or not missing.any():
        return out, filled
    valid_idx = np.flatnonzero(~missing)
    for s, e in nan_runs(missing):
        if s == 0 or e == len(x) or e - s > max_len:
            continue
        left = valid_idx[valid_idx < s][-n_side:]
        right = valid_idx[valid_idx >= e][:n_side]
        # only samples contiguous with the gap (stop at the next gap)
        left = left[left >= s - n_side]
        right = right[right < e + n_side]
        knots = np.concatenate([left, right])
        if len(knots) < 2:
            continue
        idx = np.arange(s, e)
        if len(knots) >= 4:
            flat[idx] = CubicSpline(knots, flat[knots], axis=0)(idx)
        else:
            for j in range(flat.shape[1]):
                flat[idx, j] = np.interp(idx, knots, flat[knots, j])
        filled[idx] = True
    return out, filled
