"""Clock synchronisation between a sensor and the mocap system.

Clock model (common brief)::

    t_sensor = clock_offset_s + (1 + clock_drift_ppm * 1e-6) * t_mocap      (+ jitter)

The offset is found, as in seed 003 §4.2 ("temporally delayed ... by finding the maximum
values of cross-correlation between these two trajectories"), by maximising the normalised
cross-correlation (NCC) of a motion signal seen by both systems, refined to sub-sample
precision by a parabola through the peak and its two neighbours.

* :func:`to_mocap_time` inverts the model for a registered trial (the ground truth maps
  every sensor sample to the mocap clock with it).
* :func:`estimate_clock_offset` is generic (any 1-D or multi-channel signals).
* :func:`lrs_occupancy_signals` builds the LRS signal: for every beam (grouped into bins of
  about 0.5 deg), the observed "foreground" indicator of each scan (range nearer than the
  static background, the person) versus the indicator predicted from the mocap leg points
  at sensor height (two circles of the subject's leg width, ray-cast in the sensor frame).
  Each beam's sample time is the scan stamp plus ``i * time_increment`` when the log states
  it (``meta['time_increment_s']``), else the stamp (``sync_beam_timing: false`` always
  uses the stamp).
* :func:`estimate_clock` adds drift: offsets estimated in ``sync_windows`` windows of the
  trial are fitted by a line ``offset(t_mocap) = clock_offset_s + drift * t_mocap`` when
  the trial lasts at least ``drift_min_duration_s``; shorter trials report drift 0 and the
  offset of the whole trial.

References
----------
Qi, Y., Soh, C. B., Gunawan, E., Low, K.-S., Thomas, R. (2014). Estimation of spatial-
temporal gait parameters using a low-cost ultrasonic motion analysis system. Sensors
14(8), 15434-15457.
Padfield, D. (2012). Masked object registration in the Fourier domain. IEEE Trans. Image
Process. 21(5), 2706-2718 (the masked NCC used here).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft

from gaitval.registration.occupancy import predicted_occupancy

#: Defaults of the ``registration:`` config keys used here.
DEFAULTS = {
    "sync_max_lag_s": 5.0,
    "sync_min_peak": 0.2,
    "sync_bin_deg": 0.5,
    "sync_foreground_margin_m": 0.10,
    "sync_moving_max_range_m": 1.5,
    "drift_min_duration_s": 60.0,
    "sync_windows": 4,
    "sync_beam_timing": True,
}


@dataclass
class ClockEstimate:
    """Result of a clock synchronisation.

    Attributes
    ----------
    clock_offset_s : float
        ``t_sensor - t_mocap`` at ``t_mocap = 0`` (seconds).
    clock_drift_ppm : float
        Relative rate error of the sensor clock (parts per million); 0 when not estimated.
    sync_peak : float
        Normalised cross-correlation at the peak, clipped to 0..1 (NaN for a manual offset).
    method : str
        ``ncc``, ``ncc+drift`` or ``manual``.
    """

    clock_offset_s: float
    clock_drift_ppm: float
    sync_peak: float
    method: str = "ncc"


def to_mocap_time(t_sensor, clock_offset_s: float, clock_drift_ppm: float) -> np.ndarray:
    """Sensor-clock times on the mocap clock, the clock model inverted:
    ``t_mocap = (t_sensor - clock_offset_s) / (1 + clock_drift_ppm * 1e-6)``."""
    return (np.asarray(t_sensor, dtype=float) - clock_offset_s) / (1.0 + clock_drift_ppm * 1e-6)


def _gap_mask(tj, g, gap):
    """Grid points ``g`` that fall inside a gap (``gap[i]``: from ``tj[i]`` to ``tj[i+1]``)."""
    k = np.searchsorted(tj, g) - 1
    inside = (k >= 0) & (k < len(gap))
    bad = np.zeros(len(g), dtype=bool)
    bad[inside] = gap[k[inside]]
    return bad


def _uniform_1(tj, xj, g):
    """One channel's present samples ``(tj, xj)`` linearly on the grid ``g``; NaN outside
    and in gaps longer than 3 median sample spacings."""
    v = np.interp(g, tj, xj, left=np.nan, right=np.nan)
    # do not bridge gaps longer than 3 median sample spacings
    gap = np.diff(tj) > 3 * np.median(np.diff(tj))
    if gap.any():
        v[_gap_mask(tj, g, gap)] = np.nan
    return v


def _uniform(t, x, t0, dt, n):
    """Linear resampling of (n_samples, ch) onto t0 + k dt; NaN outside / in gaps.

    ``t`` is (n_samples,) shared by the channels or (n_samples, ch) per channel.  The same
    arithmetic per channel as a loop of :func:`_uniform_1`, with the sample-spacing
    statistics computed once for channels that share their samples (shared times and the
    same missing samples) or for all channels at once (per-channel times, none missing).
    """
    g = t0 + dt * np.arange(n)
    out = np.full((n, x.shape[1]), np.nan)
    ok = np.isfinite(x) & np.isfinite(t if t.ndim == 2 else t[:, None])
    if t.ndim == 1 and x.shape[1] > 1 and (ok == ok[:, :1]).all():
        mask = ok[:, 0]
        if mask.sum() < 2:
            return out
        tj = t[mask]
        gap = np.diff(tj) > 3 * np.median(np.diff(tj))
        bad = _gap_mask(tj, g, gap) if gap.any() else None
        xs = x[mask]
        nz = (xs != 0).any(axis=0)
        # a channel of zeros (an LRS beam bin no leg ever crosses: most of them) is 0 on
        # [tj[0], tj[-1]] and NaN outside, as np.interp gives it
        out[(g >= tj[0]) & (g <= tj[-1])] = 0.0
        for j in np.flatnonzero(nz):
            out[:, j] = np.interp(g, tj, xs[:, j], left=np.nan, right=np.nan)
        if bad is not None:
            out[bad] = np.nan
        return out
    done = np.zeros(x.shape[1], dtype=bool)
    if t.ndim == 2 and len(t) >= 2:
        cols = np.flatnonzero(ok.all(axis=0))
        if cols.size:
            T = t[:, cols]
            d = np.diff(T, axis=0)
            gaps = d > 3 * np.median(d, axis=0)
            # a channel of zeros is 0 on [T[0], T[-1]] and NaN outside, as np.interp
            # gives it: all of them at once
            zero = ~(x[:, cols] != 0).any(axis=0)
            if zero.any():
                inside = (g[:, None] >= T[0, zero]) & (g[:, None] <= T[-1, zero])
                out[:, cols[zero]] = np.where(inside, 0.0, np.nan)
            for i in np.flatnonzero(~zero):
                out[:, cols[i]] = np.interp(g, T[:, i], x[:, cols[i]], left=np.nan,
                                            right=np.nan)
            for i in np.flatnonzero(gaps.any(axis=0)):
                out[_gap_mask(T[:, i], g, gaps[:, i]), cols[i]] = np.nan
            done[cols] = True
    for j in np.flatnonzero(~done):
        okj = ok[:, j]
        if okj.sum() < 2:
            continue
        tj = (t[:, j] if t.ndim == 2 else t)[okj]
        out[:, j] = _uniform_1(tj, x[okj, j], g)
    return out


def _xcorr(a, b, nfft, cols=None):
    """c[k] = sum_i a[i] b[i+k] summed over channels, for k = -(na-1) .. nb-1.

    ``cols``: the only channels where ``a * b`` can be non-zero (the FFTs skip the
    others; their zero products keep their places in the sum over channels).
    """
    if cols is None or len(cols) == a.shape[1]:
        prod = np.conj(sfft.rfft(a, nfft, axis=0)) * sfft.rfft(b, nfft, axis=0)
    else:
        prod = np.zeros((nfft // 2 + 1, a.shape[1]), dtype=complex)
        if len(cols):
            prod[:, cols] = np.conj(sfft.rfft(a[:, cols], nfft, axis=0)) \
                * sfft.rfft(b[:, cols], nfft, axis=0)
    full = sfft.irfft(np.sum(prod, axis=1), nfft)
    na, nb = a.shape[0], b.shape[0]
    return np.concatenate([full[nfft - (na - 1):], full[:nb]])


def estimate_clock_offset(t_a, sig_a, t_b, sig_b, max_lag_s: float, *,
                          dt: float | None = None, centre_s: float | None = None,
                          min_overlap: float = 0.3, _grids: dict | None = None
                          ) -> tuple[float, float]:
    """Offset between two clocks from one motion signal seen on both.

    Finds ``tau`` such that ``sig_b(t + tau) ~= sig_a(t)``, i.e. clock b reads
    ``t_b = t_a + tau`` (with ``a`` = mocap and ``b`` = sensor, ``tau`` is
    ``clock_offset_s`` of the common brief when there is no drift).

    Parameters
    ----------
    t_a, t_b : ndarray (n_a,), (n_b,)
        Sample times on each clock (seconds; need not be uniform).  ``t_b`` may also be
        (n_b, ch) to give every channel its own sample times (beam timing in a scan).
    sig_a, sig_b : ndarray (n,) or (n, ch)
        The signals (same channels); NaN marks missing samples.
    max_lag_s : float
        Search ``tau`` in ``[centre_s - max_lag_s, centre_s + max_lag_s]``.
    dt : float, optional
        Resampling step; default the smaller median sample spacing of the two.
    centre_s : float, optional
        Centre of the search; default 0 when the two time ranges overlap, else the
        difference of the start times (e.g. a sensor stamping in Unix time).
    min_overlap : float
        Lags where fewer than this fraction of the shorter signal's samples overlap are
        ignored.
    _grids : dict, optional
        :func:`estimate_clock`'s memo of signal ``a`` on its grid, by ``dt``: its windows
        correlate the same mocap signal with parts of the sensor's (same arrays, same
        grid, so the same numbers as computing it again).

    Returns
    -------
    tau_s : float
        The offset (seconds), refined by parabolic peak interpolation.
    peak : float
        Masked normalised cross-correlation at the peak (Pearson-like, -1..1).

    Notes
    -----
    Both signals are linearly resampled onto grids of step ``dt`` starting at their first
    samples, centred per channel, and correlated over all channels at once::

        NCC(k) = sum a'_i b'_{i+k} / sqrt(sum_overlap a'^2 * sum_overlap b'^2)

    (masked NCC: gaps do not count).  With ``k*`` the best lag,
    ``delta = (c[k*-1] - c[k*+1]) / (2 (c[k*-1] - 2 c[k*] + c[k*+1]))`` (parabola vertex)
    and ``tau = t_b0 - t_a0 + (k* + delta) dt``.
    """
    t_a = np.asarray(t_a, dtype=float)
    t_b = np.asarray(t_b, dtype=float)
    A = np.asarray(sig_a, dtype=float)
    B = np.asarray(sig_b, dtype=float)
    A = A[:, None] if A.ndim == 1 else A
    B = B[:, None] if B.ndim == 1 else B
    if A.shape[1] != B.shape[1]:
        raise ValueError("the two signals must have the same number of channels")
    tb_ch = t_b if t_b.ndim == 2 else np.repeat(t_b[:, None], B.shape[1], axis=1)
    if dt is None:
        dt = float(min(np.median(np.diff(t_a)), np.median(np.diff(tb_ch[:, 0]))))
    ta0, tb0 = float(np.nanmin(t_a)), float(np.nanmin(tb_ch))
    if _grids is None:
        Ag, wa = _centred_grid(t_a, A, ta0, dt)
    else:
        if dt not in _grids:
            _grids[dt] = _centred_grid(t_a, A, ta0, dt)
        Ag, wa = _grids[dt]
    Bg, wb = _centred_grid(tb_ch, B, tb0, dt)
    na, nb = len(Ag), len(Bg)
    if centre_s is None:
        overlap = (np.nanmax(t_a) >= tb0) and (np.nanmax(tb_ch) >= ta0)
        centre_s = 0.0 if overlap else tb0 - ta0
    nmin = min(wa.any(axis=1).sum(), wb.any(axis=1).sum()) * A.shape[1]
    # Only lags L with |tau - centre_s| <= max_lag_s count, and c[L] = sum_i a_i b_{i+L}
    # pairs b with the rows i of a in [-L, nb - 1 - L]: the (already centred) rows of a
    # outside that band for every such L (+-2 lags) are left out of the FFTs (an
    # ultrasonic trial's drift window: 3,800 of its mocap's 60,000 rows).  The lags keep
    # their numbers, so tau is computed as before.
    lo = int(np.ceil((centre_s - max_lag_s - (tb0 - ta0)) / dt)) - 2
    hi = int(np.floor((centre_s + max_lag_s - (tb0 - ta0)) / dt)) + 2
    i0, i1 = max(0, -hi), min(na - 1, nb - 1 - lo)
    if 0 <= i0 <= i1 < na and (i1 - i0 + 1) < 0.9 * na:
        Ag, wa, na_used = Ag[i0:i1 + 1], wa[i0:i1 + 1], i1 - i0 + 1
    else:
        i0, na_used = 0, na
    ncc, ea, eb, ov = _masked_ncc(Ag, Bg, wa, wb)
    tau = tb0 - ta0 + np.arange(-(na_used - 1) - i0, nb - i0) * dt
    usable = (np.abs(tau - centre_s) <= max_lag_s) & (ov >= min_overlap * nmin * 0.999) \
        & np.isfinite(ncc) & (ea > 1e-12) & (eb > 1e-12)
    if not usable.any():
        return float("nan"), float("nan")
    k = int(np.flatnonzero(usable)[np.argmax(ncc[usable])])
    return float(tau[k] + _parabolic_vertex(ncc, usable, k) * dt), float(ncc[k])


def _centred_grid(t: np.ndarray, x: np.ndarray, t0: float, dt: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Channels ``x`` (n, ch) sampled at ``t`` ((n,) shared, or (n, ch) per channel) on the
    grid ``t0 + k dt`` up to the last sample, each channel minus its mean on the grid.

    Returns
    -------
    grid : ndarray (n_grid, ch)
        Centred values, 0 where a channel has no sample (masked NCC: gaps do not count).
    weight : ndarray (n_grid, ch)
        1 where a channel has a sample, else 0.
    """
    n = int(np.floor((np.nanmax(t) - t0) / dt)) + 1
    g = _uniform(t, x, t0, dt, n)          # finite where a channel has a sample, else NaN
    fin = np.isfinite(g)
    # centred where a channel has samples, 0 elsewhere; a channel of zeros stays 0, so
    # only the others are centred
    act = np.flatnonzero(np.where(fin, g, 0.0).any(axis=0))
    out = np.zeros_like(g)
    if act.size:
        ga = g[:, act]
        out[:, act] = np.where(fin[:, act], ga - np.nanmean(ga, axis=0), 0.0)
    return out, fin.astype(float)


def _masked_ncc(Ag, Bg, wa, wb):
    """Masked normalised cross-correlation of two centred grids at every lag.

    Returns ``ncc, ea, eb, ov`` at lags ``-(na - 1) .. nb - 1``: NCC(k) = sum a'_i b'_{i+k}
    / sqrt(ea(k) eb(k)), with ``ea``, ``eb`` the energies of each signal where the other
    has samples and ``ov`` the number of overlapping samples (Padfield 2012).
    """
    nfft = sfft.next_fast_len(len(Ag) + len(Bg))
    # Only channels with a non-zero value (foreground, or a predicted leg) add to the
    # correlation and the energies; the others' products are exact zeros, kept in their
    # places so the sum over channels adds the same numbers in the same order.
    nz_a, nz_b = (Ag != 0).any(axis=0), (Bg != 0).any(axis=0)
    act = np.flatnonzero(nz_a | nz_b)
    # the products a_c b_c: only channels non-zero on both sides (an LRS trial's sensor
    # side may show foreground in every bin, its mocap side legs in a third of them)
    num = _xcorr(Ag, Bg, nfft, np.flatnonzero(nz_a & nz_b))
    # When every channel of one side shares its mask (an LRS scan has all its beams, the
    # mocap all its frames: every LRS and most ultrasonic trials), the other side's energy
    # correlates with that one mask: sum_c xcorr(a_c^2, w) = xcorr(sum_c a_c^2, w), one
    # FFT pair instead of one per active channel (the same sums in another order)
    same_a = Ag.shape[1] > 1 and bool((wa == wa[:, :1]).all())
    same_b = Bg.shape[1] > 1 and bool((wb == wb[:, :1]).all())
    ea = _xcorr((Ag * Ag).sum(axis=1, keepdims=True), wb[:, :1], nfft) if same_b \
        else _xcorr(Ag * Ag, wb, nfft, act)
    eb = _xcorr(wa[:, :1], (Bg * Bg).sum(axis=1, keepdims=True), nfft) if same_a \
        else _xcorr(wa, Bg * Bg, nfft, act)
    # the overlap (a count, compared with a 0.1 % margin): one FFT when every channel
    # shares the masks of one side
    if same_a:
        ov = _xcorr(wa[:, :1], wb.sum(axis=1, keepdims=True), nfft)
    elif same_b:
        ov = _xcorr(wa.sum(axis=1, keepdims=True), wb[:, :1], nfft)
    else:
        ov = _xcorr(wa, wb, nfft)
    with np.errstate(invalid="ignore", divide="ignore"):
        ncc = num / np.sqrt(np.maximum(ea, 0) * np.maximum(eb, 0))
    return ncc, ea, eb, ov


def _parabolic_vertex(c: np.ndarray, usable: np.ndarray, k: int) -> float:
    """Sub-sample shift of the peak ``k`` of ``c``: the vertex of the parabola through
    ``c[k-1], c[k], c[k+1]`` (0 at an edge, beside an unusable lag, or when not a maximum),
    ``delta = (c[k-1] - c[k+1]) / (2 (c[k-1] - 2 c[k] + c[k+1]))`` clipped to +-0.5."""
    if 0 < k < len(c) - 1 and usable[k - 1] and usable[k + 1]:
        y0, y1, y2 = c[k - 1], c[k], c[k + 1]
        den = y0 - 2 * y1 + y2
        if den < 0:
            return float(np.clip(0.5 * (y0 - y2) / den, -0.5, 0.5))
    return 0.0


def beam_times(sensor) -> np.ndarray:
    """Per-beam sample times (n_scans, n_beams) on the sensor clock.

    ``t[k] + i * time_increment`` when the log states the time between beams
    (``meta['time_increment_s']``, ROS ``LaserScan.time_increment``); otherwise every beam
    is taken at the stamp.  ``scan_time_s`` (the scan period) alone is not used: it does
    not say whether the logger swept the beams or stamped a snapshot (gaitval's simulator
    casts all beams at the stamp).
    """
    meta = sensor.meta or {}
    inc = float(meta.get("time_increment_s") or 0.0)
    return sensor.t[:, None] + inc * np.arange(sensor.n_beams)[None, :]


def _bin(x: np.ndarray, k: int) -> np.ndarray:
    """Means of ``k`` neighbouring columns (the last ``shape[1] % k`` dropped).

    Summed slice by slice, left to right, then divided by ``k``: for ``k < 8`` the same
    additions in the same order as ``reshape(..., k).mean(axis=2)`` (numpy's pairwise sum
    adds fewer than 8 values one by one), so the same bits, without a reduction over an
    axis of length ``k`` for every element.
    """
    if k <= 1:
        return x
    n = x.shape[1] // k * k
    if k >= 8:
        return x[:, :n].reshape(x.shape[0], -1, k).mean(axis=2)
    s = x[:, 0:n:k] + x[:, 1:n:k]
    for j in range(2, k):
        s += x[:, j:n:k]
    s /= k
    return s


def lrs_occupancy_signals(sensor, background: np.ndarray, legs_s: np.ndarray,
                          radius_m: float, cfg: dict | None = None, *, moving: bool = False):
    """Observed and predicted per-beam-bin leg occupancy (see the module docstring).

    Returns
    -------
    obs : ndarray (n_scans, n_bins)
    obs_t : ndarray (n_scans, n_bins) sample times on the sensor clock
    pred : ndarray (n_frames, n_bins) from ``legs_s`` (n_frames, 2, 2) at mocap frames
    """
    c = dict(DEFAULTS)
    c.update(cfg or {})
    r = sensor.ranges
    bg = np.where(np.isfinite(background), background, np.inf)
    with np.errstate(invalid="ignore"):
        fg = np.isfinite(r) & (r < bg - c["sync_foreground_margin_m"])
        if moving:
            fg &= r <= c["sync_moving_max_range_m"]
    k = max(1, int(round(np.deg2rad(c["sync_bin_deg"]) / abs(sensor.angle_increment))))
    obs = _bin(fg.astype(float), k)
    bt = beam_times(sensor) if c["sync_beam_timing"] else \
        np.repeat(sensor.t[:, None], sensor.n_beams, axis=1)
    obs_t = _bin(bt, k)
    pred = _bin(predicted_occupancy(legs_s, sensor.angles, radius_m), k)
    return obs, obs_t, pred


def estimate_clock(t_mocap: np.ndarray, pred: np.ndarray, obs_t: np.ndarray, obs: np.ndarray,
                   cfg: dict | None = None) -> ClockEstimate:
    """Offset (and drift for long trials) from mocap-side and sensor-side signals.

    Parameters
    ----------
    t_mocap : ndarray (n_frames,)
        Mocap frame times (seconds).
    pred : ndarray (n_frames, ch)
        Mocap-derived signal.
    obs_t : ndarray (n, ch) or (n,)
        Sensor-clock sample times.
    obs : ndarray (n, ch)
        Sensor-derived signal of the same channels.
    cfg : dict
        ``sync_max_lag_s``, ``drift_min_duration_s``, ``sync_windows``.

    Returns
    -------
    ClockEstimate
        ``sync_peak`` is the NCC of the whole-trial peak clipped to 0..1.  With drift
        (trials of at least ``drift_min_duration_s``), window offsets ``tau_w`` at window
        mocap-time centres ``c_w`` are fitted by ``tau_w = clock_offset_s + d * c_w``
        (least squares; exact for the clock model, since ``t_sensor - t_mocap =
        clock_offset_s + drift * 1e-6 * t_mocap``) and ``clock_drift_ppm = d * 1e6``.
    """
    c = dict(DEFAULTS)
    c.update(cfg or {})
    grids: dict = {}            # the mocap signal on its grid, once per dt for all windows
    tau, peak = estimate_clock_offset(t_mocap, pred, obs_t, obs, float(c["sync_max_lag_s"]),
                                      _grids=grids)
    if not np.isfinite(tau):
        return ClockEstimate(float("nan"), 0.0, 0.0, "ncc")
    t_first = obs_t if np.ndim(obs_t) == 1 else obs_t[:, 0]
    duration = float(np.nanmax(t_first) - np.nanmin(t_first))
    if duration < float(c["drift_min_duration_s"]) or int(c["sync_windows"]) < 2:
        return ClockEstimate(tau, 0.0, float(np.clip(peak, 0, 1)), "ncc")
    nw = int(c["sync_windows"])
    edges = np.linspace(np.nanmin(t_first), np.nanmax(t_first), nw + 1)
    centres, taus = [], []
    for w in range(nw):
        sel = (t_first >= edges[w]) & (t_first <= edges[w + 1])
        if sel.sum() < 10:
            continue
        tw, pw = estimate_clock_offset(t_mocap, pred, obs_t[sel], obs[sel], 0.05,
                                       centre_s=tau, _grids=grids)
        if np.isfinite(tw):
            centres.append(0.5 * (edges[w] + edges[w + 1]) - tw)   # mocap time of centre
            taus.append(tw)
    if len(taus) < 2:
        return ClockEstimate(tau, 0.0, float(np.clip(peak, 0, 1)), "ncc")
    d, off = np.polyfit(np.asarray(centres), np.asarray(taus), 1)
    return ClockEstimate(float(off), float(d * 1e6), float(np.clip(peak, 0, 1)), "ncc+drift")
