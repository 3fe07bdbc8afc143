"""Marker gaps: fill short ones with a cubic, leave long ones missing.

A gap is a run of missing samples (NaN) strictly inside a trajectory.  Gaps of at most
``max_gap_s`` (config ``groundtruth.max_gap_s``, default 0.10 s, i.e. 20 frames at 200 Hz
or 10 at 100 Hz, the order of Vicon Nexus' default spline-fill limit) are filled by a cubic
spline through up to four valid samples on each side of the gap (a local spline, so a
distant gap or outlier cannot influence the fill).  Longer gaps, and missing samples at the
start or end of a trajectory, stay NaN and are counted by the caller as frames excluded
from every later metric.

``method="linear"`` is the rule of seed 003's camera reference
(:mod:`gaitval.groundtruth.reference`, which resamples the marker linearly, §4.1): every
missing frame is interpolated linearly in time between the valid frames on either side,
long gaps included and the ends held at the first / last valid value, so the trajectory can
be resampled and filtered; ``was_filled`` still marks only the short interior gaps, so a
caller can flag the rest (``missing & ~was_filled``) as not to be trusted.
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
                    n_side: int = 4, *, method: str = "spline",
                    t: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Fill interior gaps of at most ``max_gap_s`` (module notes).

    Parameters
    ----------
    x : ndarray (n_frames, ...)
        Trajectory (e.g. (n, 3) marker positions in metres); a frame is missing when any
        of its values is NaN.
    rate_hz : float
        Sampling rate (Hz).
    max_gap_s : float
        Longest gap that counts as short (seconds).  ``"spline"``: at most
        ``floor(max_gap_s * rate_hz + 1e-9)`` frames; ``"linear"``: ``n / rate_hz`` not
        above ``max_gap_s``.
    n_side : int
        ``"spline"``: valid samples taken on each side of a gap (fewer at the edges or
        between gaps; with two samples in all the fill is linear).
    method : {"spline", "linear"}
        ``"spline"``: short interior gaps filled by a local cubic spline, the rest left NaN.
        ``"linear"``: every missing frame interpolated linearly in time (module notes).
    t : ndarray (n_frames,), optional
        ``"linear"``: the frame times (s); default ``arange(n_frames) / rate_hz``.

    Returns
    -------
    filled : ndarray, same shape as ``x``
    was_filled : ndarray (n_frames,) bool
        Frames of the short interior gaps that were filled.
    """
    if method not in ("spline", "linear"):
        raise ValueError(f"method must be 'spline' or 'linear', not {method!r}")
    x = np.asarray(x, dtype=float)
    out = x.copy()
    flat = out.reshape(len(x), -1)
    missing = ~np.all(np.isfinite(flat), axis=1)
    flat[missing] = np.nan
    if method == "linear":
        tt = np.arange(len(x)) / rate_hz if t is None else np.asarray(t, dtype=float)
        return out, _fill_linear(flat, missing, tt, rate_hz, max_gap_s)
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


def _fill_linear(flat: np.ndarray, missing: np.ndarray, t: np.ndarray, rate_hz: float,
                 max_gap_s: float) -> np.ndarray:
    """``method="linear"`` in place on ``flat`` (n, k); returns ``was_filled``."""
    filled = np.zeros(len(flat), dtype=bool)
    ok = ~missing
    if ok.sum() < 2:
        return filled
    for k in range(flat.shape[1]):
        flat[missing, k] = np.interp(t[missing], t[ok], flat[ok, k])
    for s, e in nan_runs(missing):
        long_gap = (e - s) / max(rate_hz, 1e-9) > max_gap_s
        if not (long_gap or s == 0 or e == len(flat)):
            filled[s:e] = True
    return filled
