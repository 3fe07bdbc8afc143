"""Low-pass filtering and differentiation of ground-truth trajectories.

Seed 003 §4.1: "All data were low-pass filtered by second order low-pass Butterworth
filter at 10 Hz"; seed 002 §IV: "The legs' velocities resulted from simple
differentiation" (after interpolation and smoothing).  gaitval applies the Butterworth
filter forwards and backwards (zero phase, ``scipy.signal.filtfilt``; the paper does not
say, zero phase is what keeps the reference in time with the sensor) to each run of
valid samples separately; runs too short for the filter's padding (``3 * max(len(a),
len(b))`` samples) are left unfiltered.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import butter, filtfilt

from gaitval.groundtruth.gaps import nan_runs


def lowpass(x: np.ndarray, rate_hz: float, cutoff_hz: float = 10.0, order: int = 2
            ) -> np.ndarray:
    """Zero-phase Butterworth low-pass along axis 0, run by run of valid samples.

    Parameters
    ----------
    x : ndarray (n, ...) ; NaN rows are gaps and stay NaN.
    rate_hz, cutoff_hz : float (Hz); the cutoff must be below the Nyquist rate.
    order : int, the Butterworth order (2 in seed 003).
    """
    x = np.asarray(x, dtype=float)
    if cutoff_hz >= rate_hz / 2:
        return x.copy()
    b, a = butter(order, cutoff_hz / (rate_hz / 2.0))
    flat = x.reshape(len(x), -1)
    out = flat.copy()
    ok = np.all(np.isfinite(flat), axis=1)
    pad = 3 * max(len(a), len(b))
    for s, e in nan_runs(ok):
        if e - s > pad:
            out[s:e] = filtfilt(b, a, flat[s:e], axis=0)
    return out.reshape(x.shape)


def differentiate(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Central differences d x / d t along axis 0 (one-sided at run ends); NaN in gaps."""
    x = np.asarray(x, dtype=float)
    flat = x.reshape(len(x), -1)
    out = np.full_like(flat, np.nan)
    ok = np.all(np.isfinite(flat), axis=1)
    for s, e in nan_runs(ok):
        if e - s >= 2:
            out[s:e] = np.gradient(flat[s:e], t[s:e], axis=0)
    return out.reshape(x.shape)
