"""Stride segmentation, stride parameters and autocorrelation symmetry from a heel path.

Implements seed 003 §3.3: the unbiased autocorrelation (eq. 16), stride regularity and
horizontal / vertical stride symmetry (§3.3.2), and the per-stride parameters S, NS, T, V,
NV, C (eq. 17–22) from the horizontal (progression) displacement of the heel on a
treadmill, where the heel oscillates back and forth: it is most anterior near heel strike
and moves backward with the belt during stance.

A gait cycle ``j`` runs from one maximum of the horizontal displacement to the next
(``Index(max(x_j))`` of eq. 19), so its duration is the distance between consecutive maxima.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434

Moe-Nilssen, R.; Helbostad, J.L. Estimation of gait cycle characteristics by trunk
accelerometry. *J. Biomech.* 2004, 37, 121–126.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import correlate, find_peaks

#: Tidy column names of :func:`stride_table`.
STRIDE_COLUMNS = ["stride", "i_start", "i_end", "t_start_s", "t_end_s", "stride_length",
                  "stride_length_norm", "stride_duration", "stride_velocity",
                  "stride_velocity_norm", "cadence"]


def autocorr_unbiased(a: np.ndarray, max_lag: int | None = None,
                      normalise: bool = False) -> np.ndarray:
    """Unbiased autocorrelation ``A(m) = 1/(N-m) sum_{i=1}^{N-m} a_i a_{i+m}`` (eq. 16).

    Parameters
    ----------
    a : ndarray, shape (N,)
        The observations (remove the mean first if a DC level should not dominate; this
        function uses the values as given, as eq. 14–16 do).
    max_lag : int, optional
        Largest lag ``m`` returned (default ``N - 1``).
    normalise : bool
        Divide by ``A(0)`` so that the zero-lag value is 1.

    Returns
    -------
    ndarray, shape (max_lag + 1,)
        ``A(m)`` for ``m = 0 .. max_lag``.

    Notes
    -----
    The raw sum (eq. 14) is computed with an FFT correlation; dividing it by ``N`` would
    give the biased estimator of eq. (15), which attenuates with the lag.
    """
    a = np.asarray(a, dtype=float)
    n = a.size
    if n == 0:
        return np.zeros(0)
    max_lag = n - 1 if max_lag is None else int(min(max_lag, n - 1))
    raw = correlate(a, a, mode="full", method="auto")[n - 1:n + max_lag]   # seed003 eq. (14)
    A = raw / (n - np.arange(max_lag + 1))                          # seed003 eq. (16)
    if normalise and A[0] != 0:
        A = A / A[0]
    return A


def dominant_period(a: np.ndarray, fs: float, min_period_s: float = 0.6,
                    max_period_s: float = 2.5) -> float:
    """Stride period (s) from the unbiased autocorrelation (eq. 16).

    The first autocorrelation peak in ``[min_period_s, max_period_s]`` that reaches at
    least 90 % of the highest peak there.
    """
    a = np.asarray(a, dtype=float)
    a = a - np.nanmean(a)
    lo = max(1, int(np.floor(min_period_s * fs)))
    hi = int(np.ceil(max_period_s * fs))
    if a.size < 2 * hi:
        hi = a.size // 2
    if hi <= lo + 1:
        return float("nan")
    A = autocorr_unbiased(np.nan_to_num(a), hi, normalise=True)
    seg = A[lo:hi + 1]
    peaks, _ = find_peaks(seg)
    if peaks.size == 0:
        return float("nan")
    # the first peak that is nearly as high as the highest: a periodic signal correlates
    # as well at two periods as at one, and the stride is the shortest of those lags
    top = seg[peaks].max()
    best = peaks[np.flatnonzero(seg[peaks] >= top - 0.1 * abs(top))[0]]
    return float((lo + best) / fs)


def _parabolic(y: np.ndarray, i: int) -> float:
    """Sub-sample offset of a peak at ``i`` by a parabola through three samples."""
    if i <= 0 or i >= len(y) - 1:
        return 0.0
    a, b, c = y[i - 1], y[i], y[i + 1]
    den = a - 2 * b + c
    return 0.0 if den == 0 else float(0.5 * (a - c) / den)


def stride_maxima(x: np.ndarray, fs: float, *, min_period_s: float = 0.6,
                  max_period_s: float = 2.5, prominence_frac: float = 0.3) -> np.ndarray:
    """Indices of the per-cycle maxima of the horizontal displacement (eq. 19).

    The expected cycle is found from the unbiased autocorrelation; maxima closer than
    60 % of it, or less prominent than ``prominence_frac`` of the 5–95 % range, are not
    cycle boundaries.
    """
    x = np.asarray(x, dtype=float)
    T = dominant_period(x, fs, min_period_s, max_period_s)
    if not np.isfinite(T):
        return np.zeros(0, dtype=int)
    lo, hi = np.nanpercentile(x, [5, 95])
    peaks, _ = find_peaks(np.nan_to_num(x, nan=float(np.nanmin(x))),
                          distance=max(1, int(0.6 * T * fs)),
                          prominence=prominence_frac * (hi - lo))
    return peaks.astype(int)


def stride_table(x: np.ndarray, fs: float, *, t0: float = 0.0, maxima: np.ndarray | None = None,
                 n_norm: int | None = None, subsample: bool = False,
                 min_period_s: float = 0.6, max_period_s: float = 2.5) -> pd.DataFrame:
    """Per-stride S, NS, T, V, NV, C from a horizontal heel displacement (eq. 17–22).

    Parameters
    ----------
    x : ndarray, shape (N,)
        Horizontal (progression) displacement in metres, sampled at ``fs``.
    fs : float
        Sampling rate (Hz).
    t0 : float
        Time of sample 0 (s), for ``t_start_s`` / ``t_end_s``.
    maxima : ndarray of int, optional
        Cycle boundaries; default :func:`stride_maxima`.
    n_norm : int, optional
        The ``n`` of eq. (18) and (21) ("normalised by the number of strides n");
        default the number of strides in this table.
    subsample : bool
        Refine each maximum by a parabola (eq. 19 itself uses whole samples).

    Returns
    -------
    DataFrame
        Columns :data:`STRIDE_COLUMNS`: ``stride`` (0-based), ``i_start``, ``i_end``
        (indices of the bounding maxima), ``t_start_s``, ``t_end_s``, ``stride_length``
        (m), ``stride_length_norm`` (m), ``stride_duration`` (s), ``stride_velocity`` (m/s),
        ``stride_velocity_norm`` (m/s), ``cadence`` (strides/s).

    Notes
    -----
    ``St(j) = Max(x_j) - Min(x_j)``, ``S(j) = 2 St(j)`` (eq. 17), with ``x_j`` the samples
    from maximum ``j`` to maximum ``j+1`` inclusive; ``NS = S/n`` (eq. 18);
    ``T(j) = Index(max(x_{j+1})) - Index(max(x_j))`` over ``fs`` (eq. 19);
    ``V = S/T`` (eq. 20); ``NV = V/n`` (eq. 21); ``C = 1/T`` (eq. 22).
    """
    x = np.asarray(x, dtype=float)
    if maxima is None:
        maxima = stride_maxima(x, fs, min_period_s=min_period_s, max_period_s=max_period_s)
    maxima = np.asarray(maxima, dtype=int)
    if maxima.size < 2:
        return pd.DataFrame({c: pd.Series(dtype=float) for c in STRIDE_COLUMNS})
    pos = maxima.astype(float)
    if subsample:
        pos = pos + np.array([_parabolic(x, int(i)) for i in maxima])
    i0, i1 = maxima[:-1], maxima[1:]
    S = np.array([2.0 * (np.nanmax(x[a:b + 1]) - np.nanmin(x[a:b + 1]))   # seed003 eq. (17)
                  for a, b in zip(i0, i1)])
    T = np.diff(pos) / fs                                           # seed003 eq. (19)
    n = len(S) if n_norm is None else int(n_norm)
    V = S / T                                                       # seed003 eq. (20)
    return pd.DataFrame({
        "stride": np.arange(len(S)), "i_start": i0, "i_end": i1,
        "t_start_s": t0 + pos[:-1] / fs, "t_end_s": t0 + pos[1:] / fs,
        "stride_length": S, "stride_length_norm": S / n,            # seed003 eq. (18)
        "stride_duration": T, "stride_velocity": V,
        "stride_velocity_norm": V / n,                              # seed003 eq. (21)
        "cadence": 1.0 / T})                                        # seed003 eq. (22)


def match_strides(ref: pd.DataFrame, sys: pd.DataFrame,
                  tolerance: float = 0.25) -> list[tuple[int, int]]:
    """Pair the strides of two systems that segmented the same walk.

    Parameters
    ----------
    ref, sys : DataFrame
        Stride tables (:func:`stride_table`) of the reference and of the system, on one
        clock.
    tolerance : float
        A system stride matches a reference stride when it is the nearest by start time
        and starts within ``tolerance`` of that reference stride's duration; each system
        stride is used once (the first reference stride to claim it keeps it).

    Returns
    -------
    list of (int, int)
        Row positions ``(i_ref, i_sys)`` in reference order.
    """
    pairs, used = [], set()
    ts = sys["t_start_s"].to_numpy()
    for i, r in enumerate(ref.itertuples()):
        if ts.size == 0:
            break
        j = int(np.argmin(np.abs(ts - r.t_start_s)))
        if j in used or abs(ts[j] - r.t_start_s) > tolerance * r.stride_duration:
            continue
        used.add(j)
        pairs.append((i, j))
    return pairs


def autocorr_symmetry(a: np.ndarray, fs: float, period_s: float, *,
                      search_frac: float = 0.3) -> dict[str, float]:
    """Stride regularity ``R1``, ``R2`` and symmetry ``R2 / R1`` of one signal window.

    Parameters
    ----------
    a : ndarray
        Horizontal or vertical displacement over a window of several strides.  The mean is
        removed first (otherwise the DC level makes every lag look alike).
    fs : float
        Sampling rate (Hz).
    period_s : float
        Expected stride period; peak ``k`` is searched in ``k T (1 +- search_frac)``.

    Returns
    -------
    dict
        ``R1``, ``R2``: normalised unbiased autocorrelation (eq. 16) at the first and second
        stride peaks (stride regularity between neighbouring strides, hR_i / vR_i);
        ``symmetry``: ``R2 / R1`` (§3.3.2: "the closeness of hR_{i+1}/hR_i reflects the
        stride symmetry"); ``lag1_s``, ``lag2_s``: the peak lags.  NaN when the window is
        shorter than three periods.
    """
    a = np.asarray(a, dtype=float)
    a = a - np.nanmean(a)
    out = {"R1": np.nan, "R2": np.nan, "symmetry": np.nan, "lag1_s": np.nan,
           "lag2_s": np.nan}
    if not np.isfinite(period_s) or a.size < 3 * period_s * fs or not np.all(np.isfinite(a)):
        return out
    hi = int(np.ceil(2 * (1 + search_frac) * period_s * fs))
    A = autocorr_unbiased(a, hi, normalise=True)
    R = []
    for k in (1, 2):
        lo_k = int(np.floor(k * (1 - search_frac) * period_s * fs))
        hi_k = min(int(np.ceil(k * (1 + search_frac) * period_s * fs)), len(A) - 1)
        i = lo_k + int(np.argmax(A[lo_k:hi_k + 1]))
        R.append((float(A[i]), i / fs))
    out.update(R1=R[0][0], R2=R[1][0], lag1_s=R[0][1], lag2_s=R[1][1],
               symmetry=R[1][0] / R[0][0] if R[0][0] != 0 else np.nan)
    return out
