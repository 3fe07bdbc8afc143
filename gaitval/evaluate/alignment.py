"""Resampling and time alignment of an ultrasonic track to its camera reference (seed 003).

Seed 003 §4.1–4.2: both trajectories are linearly resampled to 50 Hz and low-passed
(2nd-order Butterworth, 10 Hz, zero phase), and the system trajectory is delayed to the
maximum of the cross-correlation of the horizontal and vertical displacements
(:func:`align_xcorr`, :func:`align_track_to_reference`).  The pendulum ranges are aligned by
the least squared difference instead (:func:`align_ssd`), which keeps the decaying swing's
amplitude.  Lags follow ``ref[i] ~ sys[i - lag]``.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import RegistrationError, TimestampError
from gaitval.evaluate.ultrasonic_config import resolve_cfg
from gaitval.groundtruth.filters import lowpass  # zero-phase Butterworth, seed 003 §4.1


def resample(t: np.ndarray, y: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """``y`` (n,) or (n, k) sampled at ``t``, linearly interpolated at ``grid`` (§4.1)."""
    y = np.asarray(y, dtype=float)
    if y.ndim == 1:
        return np.interp(grid, t, y)
    return np.column_stack([np.interp(grid, t, y[:, k]) for k in range(y.shape[1])])


def _lag_grid(ref, sys, min_overlap: float):
    """Both signals as (n, channels) arrays and, for every lag of a full correlation,
    the overlap length ``n`` and whether it covers ``min_overlap`` of the shorter one."""
    ref = np.asarray(ref, float)
    sys = np.asarray(sys, float)
    if ref.ndim == 1:
        ref = ref[:, None]
    if sys.ndim == 1:
        sys = sys[:, None]
    from scipy.signal import correlation_lags

    N, M = len(ref), len(sys)
    lags = correlation_lags(N, M, mode="full")
    lo = np.maximum(0, lags)
    hi = np.minimum(N, M + lags)
    n = np.maximum(hi - lo, 1)
    valid = (hi - lo) >= max(min_overlap * min(N, M), 3)
    return ref, sys, N, M, lags, lo, hi, n, valid


def align_xcorr(ref: np.ndarray, sys: np.ndarray, fs: float, *, min_overlap: float = 0.8,
                max_lag: int | None = None, subsample: bool = True) -> float:
    """Lag (in samples) that best aligns ``sys`` to ``ref`` by maximum cross-correlation.

    ``ref[i]`` matches ``sys[i - lag]``.  Inputs are (N, k) arrays of channels.  For every
    lag the correlation coefficient of the overlapping parts is computed per channel (the
    cross-products come from one FFT correlation, the overlap means and variances from
    cumulative sums) and averaged over the channels; lags with less than ``min_overlap`` of
    the shorter signal overlapping are not considered.  A correlation *coefficient* rather
    than the raw cross-product keeps a periodic gait signal from preferring a lag one
    stride off where the overlapping part happens to have a larger amplitude.  With
    ``subsample`` the peak is refined by a parabola through its neighbours.
    """
    from scipy.signal import correlate

    ref, sys, N, M, lags, lo, hi, n, valid = _lag_grid(ref, sys, min_overlap)
    if max_lag is not None:
        valid &= np.abs(lags) <= max_lag
    if not valid.any():
        raise RegistrationError("the ultrasonic and mocap recordings do not overlap enough "
                                "to align them")
    score = np.zeros(len(lags))
    for k in range(ref.shape[1]):
        a = ref[:, k] - ref[:, k].mean()
        b = sys[:, k] - sys[:, k].mean()
        ca = np.concatenate([[0.0], np.cumsum(a)])
        ca2 = np.concatenate([[0.0], np.cumsum(a * a)])
        cb = np.concatenate([[0.0], np.cumsum(b)])
        cb2 = np.concatenate([[0.0], np.cumsum(b * b)])
        sab = correlate(a, b, mode="full", method="fft")
        sa, sa2 = ca[hi] - ca[lo], ca2[hi] - ca2[lo]
        sb, sb2 = cb[hi - lags] - cb[lo - lags], cb2[hi - lags] - cb2[lo - lags]
        cov = sab - sa * sb / n
        var = np.maximum(sa2 - sa * sa / n, 0.0) * np.maximum(sb2 - sb * sb / n, 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            score += np.where(var > 0, cov / np.sqrt(var), 0.0)
    score = np.where(valid, score / ref.shape[1], -np.inf)
    i = int(np.argmax(score))
    frac = 0.0
    if subsample and 0 < i < len(score) - 1 and np.isfinite(score[i - 1]) and \
            np.isfinite(score[i + 1]):
        a3, b3, c3 = score[i - 1], score[i], score[i + 1]
        den = a3 - 2 * b3 + c3
        frac = 0.0 if den == 0 else 0.5 * (a3 - c3) / den
    return float(lags[i] + frac)


def align_ssd(ref: np.ndarray, sys: np.ndarray, *, min_overlap: float = 0.8) -> int:
    """Lag (samples, ``ref[i]`` ~ ``sys[i - lag]``) of the least mean squared difference.

    Unlike a correlation coefficient this keeps absolute levels and amplitudes, which is
    what separates the true lag from one a period away in a decaying swing (a pendulum's
    envelope is exponential, so a correlation coefficient cannot tell them apart).
    """
    from scipy.signal import correlate

    ref, sys, N, M, lags, lo, hi, n, valid = _lag_grid(ref, sys, min_overlap)
    if not valid.any():
        raise RegistrationError("the ultrasonic and mocap recordings do not overlap enough "
                                "to align them")
    ssd = np.zeros(len(lags))
    for k in range(ref.shape[1]):
        a, b = ref[:, k], sys[:, k]
        ca2 = np.concatenate([[0.0], np.cumsum(a * a)])
        cb2 = np.concatenate([[0.0], np.cumsum(b * b)])
        sab = correlate(a, b, mode="full", method="fft")
        ssd += (ca2[hi] - ca2[lo]) + (cb2[hi - lags] - cb2[lo - lags]) - 2.0 * sab
    ssd = np.where(valid, ssd / n, np.inf)
    return int(lags[int(np.argmin(ssd))])


def _clean_track(track: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    t = track["t_s"].to_numpy(dtype=float)
    xyz = track[["x_m", "y_m", "z_m"]].to_numpy(dtype=float)
    ok = np.all(np.isfinite(xyz), axis=1)
    if ok.sum() < 10:
        raise TimestampError("the ultrasonic track has fewer than 10 valid samples")
    return t[ok], xyz[ok]


def align_track_to_reference(track: pd.DataFrame, ref: pd.DataFrame, cfg: dict | None = None,
                             *, clock_offset_s: float | None = None) -> dict:
    """Resample, low-pass and time-align the system track to the reference (§4.1–4.2).

    Returns
    -------
    dict
        ``t`` (common 50 Hz grid, mocap clock), ``ref`` and ``sys`` ((N, 3) low-passed
        positions on that grid, ultrasonic frame), ``gap`` (reference samples in long
        gaps), ``clock_offset_s`` (``t_us - t_mocap``, from the cross-correlation unless
        given), ``fs``.
    """
    c = resolve_cfg(cfg)
    fs = float(c["resample_hz"])
    lp = c["lowpass"]
    t_sys, xyz_sys = _clean_track(track)
    t_ref = ref["t_s"].to_numpy(dtype=float)
    gr = np.arange(t_ref[0], t_ref[-1] + 1e-9, 1.0 / fs)
    gs = np.arange(t_sys[0], t_sys[-1] + 1e-9, 1.0 / fs)
    ref50 = lowpass(resample(t_ref, ref[["x_m", "y_m", "z_m"]].to_numpy(float), gr), fs,
                    lp["cutoff_hz"], lp["order"])
    gap50 = np.interp(gr, t_ref, ref["gap"].to_numpy(float)) > 0
    sys50 = lowpass(resample(t_sys, xyz_sys, gs), fs, lp["cutoff_hz"], lp["order"])
    if clock_offset_s is None or not np.isfinite(clock_offset_s):
        ac = c["align"]
        max_lag = None if ac.get("max_lag_s") is None else int(ac["max_lag_s"] * fs)
        lag = align_xcorr(ref50[:, :2], sys50[:, :2], fs, min_overlap=ac["min_overlap"],
                          max_lag=max_lag, subsample=ac["subsample"])
        # ref[i] ~ sys[i - lag]:  t_ref = gr[0] + i/fs  <->  t_sys = gs[0] + (i - lag)/fs
        clock_offset_s = float(gs[0] - gr[0] - lag / fs)
    # system positions at the reference grid times (t_us = t_mocap + offset)
    tq = gr + clock_offset_s
    inside = (tq >= gs[0]) & (tq <= gs[-1])
    sys_on_ref = resample(gs, sys50, tq[inside])
    return {"t": gr[inside], "ref": ref50[inside], "sys": sys_on_ref, "gap": gap50[inside],
            "clock_offset_s": clock_offset_s, "fs": fs}
