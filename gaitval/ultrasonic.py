"""The ultrasonic gait system of seed 003, step by step for the pipeline.

* :func:`tof_to_distance` — time of flight to range with the temperature-corrected speed
  of sound (eq. 1–2).
* :func:`track_ultrasonic_trial` — UKF track of the heel transmitter (eq. 3–13).
* :func:`register_anchors`, :func:`reference_trajectory` — the camera reference: the
  transmitter marker ``TX`` in the ultrasonic frame, via a rigid fit of the receiver
  markers ``ANC1..`` to the anchor positions of the log.
* :func:`gait_parameters` — §4.1–4.2 and eq. 16–22: resample, low-pass, align by
  cross-correlation, segment strides in both systems, S, NS, T, V, NV, C per stride and the
  autocorrelation symmetry hS, vS per window: the **gait parameter table**.
* :func:`identify_noise`, :func:`pendulum_errors` — §4.3, eq. 23: V per anchor and W by
  the RMSE search from the pendulum trials; the errors behind Table 1.

Frames: every trajectory here is in the **ultrasonic frame** of the log's anchor geometry
(seed 003: X progression, Y vertical, Z lateral), not the mocap field frame; the mocap is
brought into it by :func:`register_anchors`.

Configuration (``cfg`` is the ``ultrasonic`` section of the workflow config, or a config
holding one under the key ``ultrasonic``; every key has the default in
:data:`DEFAULT_CFG`).

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations


import numpy as np
import pandas as pd
from scipy.signal import correlate, correlation_lags

from gaitval.config import deep_merge
from gaitval.errors import (ConfigError, GaitvalError, MarkerError, RegistrationError,
                            TimestampError)
from gaitval.gait.strides import autocorr_symmetry, stride_table
from gaitval.groundtruth.filters import lowpass  # zero-phase Butterworth, seed 003 §4.1
from gaitval.track.ukf import run_toa_ukf
from gaitval.types import MocapTrial, UltrasonicLog

DEFAULT_CFG: dict = {
    "transmitter_marker": "TX",
    "anchor_markers": ["ANC1", "ANC2", "ANC3", "ANC4"],
    "ukf": {
        "alpha": 1e-3, "beta": 2.0, "kappa": 0.0,
        # seed 003 §4.3.1 gives 30, 25, 10 "mm/s"; with G of eq. (5) w is an acceleration,
        # and a heel needs tens of m/s^2, so the numbers are read as m/s^2 (see report).
        "W_sigma_mps2": [30.0, 25.0, 10.0],
        "V_m2": [11e-6, 9.3e-6, 9e-6, 9e-6],          # seed 003 §4.3.2, diag(11, 9.3, 9, 9) mm^2
        "gate_sigma": 4.0, "max_reject": 2, "min_anchors": 3, "reinit_after": 10,
        "init_guess_m": [0.16, 0.10, -0.30], "init_sigma_pos_m": 0.05,
        "init_sigma_vel_mps": 1.0,
    },
    "resample_hz": 50.0,
    "lowpass": {"order": 2, "cutoff_hz": 10.0},
    "reference": {"max_gap_s": 0.2},
    "align": {"min_overlap": 0.8, "max_lag_s": None, "subsample": True},
    "strides": {"min_period_s": 0.6, "max_period_s": 2.5, "subsample_peaks": False,
                "match_tolerance": 0.25},
    "symmetry": {"window_strides": 5},
    "noise_id": {"W_grid_mps2": [1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 50.0, 100.0, 200.0],
                 "outlier_mad": 5.0, "skip_start_s": 0.5},
}

#: The parameters of the gait parameter table and their units.
PARAMETERS = {"stride_length": "m", "stride_length_norm": "m", "stride_duration": "s",
              "stride_velocity": "m/s", "stride_velocity_norm": "m/s", "cadence": "1/s",
              "h_symmetry": "1", "v_symmetry": "1"}
GAIT_COLUMNS = ["study", "trial", "subject", "speed", "stride", "parameter", "unit",
                "reference", "system"]
TRACK_COLUMNS = ["t_s", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps",
                 "used_anchors", "rejected_anchors"]


def resolve_cfg(cfg: dict | None) -> dict:
    """The ultrasonic configuration with every default filled in."""
    cfg = dict(cfg or {})
    if isinstance(cfg.get("ultrasonic"), dict):
        cfg = cfg["ultrasonic"]
    return deep_merge(DEFAULT_CFG, cfg)


# --------------------------------------------------------------------------- ranging
def speed_of_sound(temp_c):
    """Speed of ultrasound in air, ``v_s = 331.5 + 0.6 T_c`` (m/s), eq. (2)."""
    return 331.5 + 0.6 * np.asarray(temp_c, dtype=float)


def tof_to_distance(tof_s, temp_c):
    """Range from time of flight, ``d = t v_s(T_c)`` (eq. 1–2).

    Parameters
    ----------
    tof_s : array_like, shape (n,) or (n, m)
        Times of flight (s); NaN stays NaN.
    temp_c : array_like, shape (n,) or scalar
        Air temperature (degrees Celsius) at each sample.

    Returns
    -------
    ndarray
        Distances in metres, shape of ``tof_s``.
    """
    tof = np.asarray(tof_s, dtype=float)
    v = speed_of_sound(temp_c)
    if tof.ndim == 2 and np.ndim(v) == 1:
        v = v[:, None]
    return tof * v                                                       # eq. (1)


def log_distances(log: UltrasonicLog) -> np.ndarray:
    """(n, m) ranges in metres of a log that stores either TOF or distances."""
    if log.distance_m is not None:
        return np.asarray(log.distance_m, dtype=float)
    if log.tof_s is None:
        raise TimestampError("ultrasonic log holds neither times of flight nor distances",
                             path=log.source or None)
    return tof_to_distance(log.tof_s, log.temperature_c)


def _anchor_xyz(anchors: pd.DataFrame) -> np.ndarray:
    return anchors[["x_m", "y_m", "z_m"]].to_numpy(dtype=float)


# --------------------------------------------------------------------------- tracking
def track_ultrasonic_trial(log: UltrasonicLog, cfg: dict | None = None, *,
                           trial: str | None = None) -> pd.DataFrame:
    """Track the transmitter of one ultrasonic log with the UKF (seed 003 §3.2).

    Parameters
    ----------
    log : UltrasonicLog
    cfg : dict
        ``ukf.*`` keys of :data:`DEFAULT_CFG` (``W_sigma_mps2``, ``V_m2``, ``alpha``,
        ``beta``, ``kappa``, ``gate_sigma``, ``max_reject``, ``min_anchors``,
        ``reinit_after``, ``init_guess_m``, ``init_sigma_pos_m``, ``init_sigma_vel_mps``).
    trial : str, optional
        For error messages.

    Returns
    -------
    DataFrame
        One row per log sample: ``t_s`` (ultrasonic clock), ``x_m, y_m, z_m`` (position in
        the ultrasonic frame), ``vx_mps, vy_mps, vz_mps``, ``used_anchors`` (how many
        ranges entered the update), ``rejected_anchors`` (how many finite ranges the
        multipath gate dropped).  ``attrs["anchors"]`` holds the anchor table (records).
    """
    c = resolve_cfg(cfg)["ukf"]
    t = np.asarray(log.t, dtype=float)
    if t.size < 2 or np.any(np.diff(t) <= 0):
        raise TimestampError("ultrasonic sample times must increase strictly",
                             path=log.source or None, trial=trial,
                             hint="see the log's timestamp issues (gaitval inspect)")
    d = log_distances(log)
    anchors = _anchor_xyz(log.anchors)
    V = np.asarray(c["V_m2"], dtype=float)
    if V.shape[0] != anchors.shape[0]:
        raise ConfigError(f"ultrasonic.ukf.V_m2 has {V.shape[0]} entries but the log has "
                          f"{anchors.shape[0]} anchors", path=log.source or None, trial=trial)
    res = run_toa_ukf(t, d, anchors, W_sigma=np.asarray(c["W_sigma_mps2"], float), V=V,
                      alpha=c["alpha"], beta=c["beta"], kappa=c["kappa"],
                      init_guess=np.asarray(c["init_guess_m"], float),
                      init_sigma_pos=c["init_sigma_pos_m"],
                      init_sigma_vel=c["init_sigma_vel_mps"], gate_sigma=c["gate_sigma"],
                      max_reject=int(c["max_reject"]), min_anchors=int(c["min_anchors"]),
                      reinit_after=int(c["reinit_after"]))
    df = pd.DataFrame({"t_s": t, "x_m": res.x[:, 0], "y_m": res.x[:, 1], "z_m": res.x[:, 2],
                       "vx_mps": res.x[:, 3], "vy_mps": res.x[:, 4], "vz_mps": res.x[:, 5],
                       "used_anchors": res.used.sum(axis=1).astype(np.int64),
                       "rejected_anchors": res.rejected.sum(axis=1).astype(np.int64)})
    df.attrs["anchors"] = log.anchors.to_dict("records")
    df.attrs["n_reinit"] = int(res.reinit.sum())
    df.attrs["n_reflected"] = int(res.reflected.sum())
    return df


# --------------------------------------------------------------------------- reference
def register_anchors(mocap: MocapTrial, anchors: pd.DataFrame, cfg: dict | None = None, *,
                     trial: str | None = None) -> tuple[np.ndarray, np.ndarray, float]:
    """Rigid transform ultrasonic frame -> mocap field from the receiver markers.

    Fits ``p_field = R p_us + o`` (Kabsch / SVD, no scaling) between the time-averaged
    markers ``ANC1..`` and the anchor positions of the log.

    Returns
    -------
    R : ndarray (3, 3), o : ndarray (3,), rms_m : float
        Rotation, translation and the RMS residual of the fit (metres).
    """
    c = resolve_cfg(cfg)
    labels = list(c["anchor_markers"])
    ids = [str(a) for a in anchors["anchor"]]
    if len(labels) != len(ids):
        raise ConfigError(f"{len(labels)} anchor markers configured for {len(ids)} anchors",
                          path=mocap.path, trial=trial)
    missing = [m for m in labels if not mocap.has(m)]
    if missing:
        raise MarkerError(f"receiver markers {missing} are not in the C3D",
                          path=mocap.path, trial=trial,
                          hint="set ultrasonic.anchor_markers to the receiver marker labels")
    with np.errstate(invalid="ignore"):
        P = np.array([np.nanmean(mocap.marker(m), axis=0) for m in labels])
    if not np.all(np.isfinite(P)):
        raise MarkerError("a receiver marker has no valid sample", path=mocap.path,
                          trial=trial)
    from gaitval.registration.rigid import fit_rigid_3d
    R, o, res = fit_rigid_3d(_anchor_xyz(anchors), P)          # Kabsch, no scaling
    rms = float(np.sqrt(np.mean(res ** 2)))
    if rms > 0.02:
        raise RegistrationError(f"receiver markers do not match the log's anchor geometry "
                                f"(rigid-fit RMS {rms * 1000:.1f} mm)", path=mocap.path,
                                trial=trial, hint="check the marker-to-anchor order")
    return R, o, rms


def _fill_gaps(t: np.ndarray, xyz: np.ndarray, max_gap_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Linear gap filling; returns the filled array and a mask of samples in long gaps."""
    ok = np.all(np.isfinite(xyz), axis=1)
    if ok.sum() < 2:
        return xyz, np.ones(len(t), dtype=bool)
    out = xyz.copy()
    for k in range(xyz.shape[1]):
        out[~ok, k] = np.interp(t[~ok], t[ok], xyz[ok, k])
    bad = np.zeros(len(t), dtype=bool)
    if (~ok).any():
        idx = np.flatnonzero(~ok)
        breaks = np.flatnonzero(np.diff(idx) > 1)
        starts = np.concatenate([[idx[0]], idx[breaks + 1]])
        ends = np.concatenate([idx[breaks], [idx[-1]]])
        for a, b in zip(starts, ends):
            if (b - a + 1) / max(1.0 / np.median(np.diff(t)), 1e-9) > max_gap_s or a == 0 \
                    or b == len(t) - 1:
                bad[a:b + 1] = True
    return out, bad


def reference_trajectory(mocap: MocapTrial, anchors: pd.DataFrame, cfg: dict | None = None,
                         *, trial: str | None = None) -> pd.DataFrame:
    """The camera reference: marker ``TX`` in the ultrasonic frame on the mocap clock.

    Returns
    -------
    DataFrame
        ``t_s`` (mocap time), ``x_m, y_m, z_m`` (ultrasonic frame; gaps filled linearly),
        ``gap`` (True inside gaps longer than ``reference.max_gap_s`` or at the ends).
        ``attrs``: ``registration_rms_m``.
    """
    c = resolve_cfg(cfg)
    tx = c["transmitter_marker"]
    if not mocap.has(tx):
        raise MarkerError(f"transmitter marker {tx!r} is not in the C3D", path=mocap.path,
                          trial=trial, hint="set ultrasonic.transmitter_marker")
    R, o, rms = register_anchors(mocap, anchors, c, trial=trial)
    p = (mocap.marker(tx) - o) @ R                                 # p_us = R^T (p_f - o)
    t = mocap.t
    filled, bad = _fill_gaps(t, p, float(c["reference"]["max_gap_s"]))
    if bad.all():
        raise MarkerError(f"transmitter marker {tx!r} has fewer than two samples",
                          path=mocap.path, trial=trial)
    df = pd.DataFrame({"t_s": t, "x_m": filled[:, 0], "y_m": filled[:, 1],
                       "z_m": filled[:, 2], "gap": bad})
    df.attrs["registration_rms_m"] = rms
    return df


def _resample(t: np.ndarray, y: np.ndarray, grid: np.ndarray) -> np.ndarray:
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
    ref50 = lowpass(_resample(t_ref, ref[["x_m", "y_m", "z_m"]].to_numpy(float), gr), fs,
                    lp["cutoff_hz"], lp["order"])
    gap50 = np.interp(gr, t_ref, ref["gap"].to_numpy(float)) > 0
    sys50 = lowpass(_resample(t_sys, xyz_sys, gs), fs, lp["cutoff_hz"], lp["order"])
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
    sys_on_ref = _resample(gs, sys50, tq[inside])
    return {"t": gr[inside], "ref": ref50[inside], "sys": sys_on_ref, "gap": gap50[inside],
            "clock_offset_s": clock_offset_s, "fs": fs}


# --------------------------------------------------------------------------- gait
def _match(ref_st: pd.DataFrame, sys_st: pd.DataFrame, tol: float) -> list[tuple[int, int]]:
    pairs, used = [], set()
    ts = sys_st["t_start_s"].to_numpy()
    for i, r in enumerate(ref_st.itertuples()):
        if ts.size == 0:
            break
        j = int(np.argmin(np.abs(ts - r.t_start_s)))
        if j in used or abs(ts[j] - r.t_start_s) > tol * r.stride_duration:
            continue
        used.add(j)
        pairs.append((i, j))
    return pairs


def gait_parameters(track_df: pd.DataFrame, mocap: MocapTrial, trial: dict, subject: dict,
                    cfg: dict | None = None, *, anchors: pd.DataFrame | None = None
                    ) -> pd.DataFrame:
    """Spatial-temporal gait parameters of one treadmill trial, reference vs system.

    Parameters
    ----------
    track_df : DataFrame
        Output of :func:`track_ultrasonic_trial` (ultrasonic clock and frame).
    mocap : MocapTrial
        The trial's C3D with the transmitter marker and the receiver markers.
    trial : dict
        Trial-sheet row: ``study``, ``trial``, ``subject``, ``speed``, ``clock_offset_s``
        (NaN/empty = estimate by cross-correlation, a number = manual override).
    subject : dict
        Subject-table row (only ``subject`` is used).
    cfg : dict
        ``resample_hz``, ``lowpass``, ``align``, ``strides``, ``symmetry``, ``reference``
        and the marker keys of :data:`DEFAULT_CFG`.
    anchors : DataFrame, optional
        ``anchor, x_m, y_m, z_m`` of the log; default ``track_df.attrs["anchors"]``.

    Returns
    -------
    DataFrame
        The **gait parameter table**: one row per (trial, stride, parameter), columns
        ``study, trial, subject, speed, stride, parameter, unit, reference, system``.
        ``parameter`` is one of :data:`PARAMETERS`.  For the per-stride parameters
        ``stride`` is the reference stride index (0-based, strides matched between the
        systems by start time); for ``h_symmetry`` / ``v_symmetry`` it is the index of a
        window of ``symmetry.window_strides`` consecutive reference strides
        (non-overlapping).  ``n`` of NS and NV (eq. 18, 21) is the number of matched strides.
        ``attrs``: ``clock_offset_s``, ``n_strides_reference``, ``n_strides_system``,
        ``n_matched``, ``registration_rms_m``.

    Notes
    -----
    Reference: marker ``TX`` brought into the ultrasonic frame, linearly resampled to
    50 Hz; both trajectories low-passed (2nd-order Butterworth, 10 Hz, zero phase); the
    system trajectory delayed to the maximum of the cross-correlation of the horizontal and
    vertical displacements (§4.1–4.2).  Strides are segmented on each system's own
    horizontal displacement (eq. 17–22, :func:`gaitval.gait.strides.stride_table`).
    Strides that touch a reference gap longer than ``reference.max_gap_s`` are dropped.
    """
    c = resolve_cfg(cfg)
    tname = str(trial.get("trial", ""))
    if anchors is None:
        recs = track_df.attrs.get("anchors")
        if not recs:
            raise ConfigError("gait_parameters needs the anchor geometry: pass anchors= "
                              "(the log's anchor table)", trial=tname)
        anchors = pd.DataFrame(recs)
    ref = reference_trajectory(mocap, anchors, c, trial=tname)
    off = trial.get("clock_offset_s")
    try:
        off = float(off) if off not in (None, "") else None
    except (TypeError, ValueError):
        off = None
    al = align_track_to_reference(track_df, ref, c, clock_offset_s=off)
    fs, t = al["fs"], al["t"]
    sc = c["strides"]
    kw = {"min_period_s": sc["min_period_s"], "max_period_s": sc["max_period_s"]}
    st_r = stride_table(al["ref"][:, 0], fs, t0=t[0], subsample=sc["subsample_peaks"], **kw)
    st_s = stride_table(al["sys"][:, 0], fs, t0=t[0], subsample=sc["subsample_peaks"], **kw)
    gap = al["gap"]
    if len(st_r):
        bad = [gap[a:b + 1].any() for a, b in zip(st_r["i_start"], st_r["i_end"])]
        st_r = st_r[~np.asarray(bad, dtype=bool)].reset_index(drop=True)
    pairs = _match(st_r, st_s, float(sc["match_tolerance"]))
    n = len(pairs)
    if n == 0:
        raise GaitvalError(f"no stride found in both systems (reference {len(st_r)}, "
                           f"ultrasonic {len(st_s)} strides)", path=mocap.path, trial=tname,
                           hint="check the track (a process noise ultrasonic.ukf.W_sigma_mps2 "
                                "far below the heel's accelerations makes the filter lag) and "
                                "the clock offset")
    rows = []
    base = {"study": trial.get("study", ""), "trial": tname,
            "subject": trial.get("subject", subject.get("subject", "")),
            "speed": trial.get("speed", "")}
    for i, j in pairs:
        r, s = st_r.iloc[i], st_s.iloc[j]
        for p in ("stride_length", "stride_length_norm", "stride_duration",
                  "stride_velocity", "stride_velocity_norm", "cadence"):
            rv, sv = float(r[p]), float(s[p])
            if p.endswith("_norm"):                      # eq. (18), (21): n = matched strides
                rv, sv = float(r[p.replace("_norm", "")]) / n, \
                    float(s[p.replace("_norm", "")]) / n
            rows.append({**base, "stride": int(r["stride"]), "parameter": p,
                         "unit": PARAMETERS[p], "reference": rv, "system": sv})
    K = int(c["symmetry"]["window_strides"])
    for w in range(len(st_r) // K if K > 0 else 0):
        a = int(st_r["i_start"].iloc[w * K])
        b = int(st_r["i_end"].iloc[w * K + K - 1])
        if gap[a:b + 1].any():
            continue
        T = float(st_r["stride_duration"].iloc[w * K:w * K + K].mean())
        for axis, p in ((0, "h_symmetry"), (1, "v_symmetry")):
            rs = autocorr_symmetry(al["ref"][a:b + 1, axis], fs, T)["symmetry"]
            ss = autocorr_symmetry(al["sys"][a:b + 1, axis], fs, T)["symmetry"]
            rows.append({**base, "stride": w, "parameter": p, "unit": PARAMETERS[p],
                         "reference": rs, "system": ss})
    out = pd.DataFrame(rows, columns=GAIT_COLUMNS)
    out["stride"] = out["stride"].astype(np.int64)
    out.attrs.update(clock_offset_s=al["clock_offset_s"], n_strides_reference=len(st_r),
                     n_strides_system=len(st_s), n_matched=n,
                     registration_rms_m=ref.attrs["registration_rms_m"])
    return out


# --------------------------------------------------------------------------- pendulum
def _fine_clock(t_us, d, t_ref, r, coarse_offset) -> float:
    """Clock offset ``t_us - t_mocap`` by robust least squares on the ranges.

    Drift is not fitted: a crystal clock drifts by ~10 ppm, 0.2 ms over a 20 s pendulum
    trial, below what the ranges can resolve (a free drift term only absorbs model error).
    """
    from scipy.optimize import least_squares

    ok = np.isfinite(d)

    def resid(p):
        tm = t_us - p[0]
        pred = np.column_stack([np.interp(tm, t_ref, r[:, k]) for k in range(r.shape[1])])
        return (d - pred)[ok]

    sol = least_squares(resid, x0=[coarse_offset], loss="soft_l1", f_scale=0.01,
                        x_scale=[0.001], diff_step=[1e-5])
    return float(sol.x[0])


def pendulum_alignment(log: UltrasonicLog, mocap: MocapTrial, cfg: dict | None = None, *,
                       trial: str | None = None) -> dict:
    """Measured and camera-derived ranges of one pendulum trial on the ultrasonic clock.

    Returns
    -------
    dict
        ``t`` (ultrasonic clock), ``d`` (measured ranges, (n, m)), ``r`` (camera ranges at
        the same instants), ``ref`` (TX marker in the ultrasonic frame at those instants,
        (n, 3)), ``clock_offset_s`` (``t_us - t_mocap``), ``t_mocap``.
    """
    c = resolve_cfg(cfg)
    ref = reference_trajectory(mocap, log.anchors, c, trial=trial)
    t_ref = ref["t_s"].to_numpy()
    p = ref[["x_m", "y_m", "z_m"]].to_numpy()
    A = _anchor_xyz(log.anchors)
    r = np.linalg.norm(p[:, None, :] - A[None], axis=2)
    d = log_distances(log)
    t_us = np.asarray(log.t, dtype=float)
    fs = float(c["resample_hz"])
    gr = np.arange(t_ref[0], t_ref[-1], 1.0 / fs)
    gs = np.arange(t_us[0], t_us[-1], 1.0 / fs)
    d_fill = np.column_stack([np.interp(gs, t_us[np.isfinite(d[:, k])],
                                        d[np.isfinite(d[:, k]), k]) for k in range(d.shape[1])])
    from scipy.ndimage import median_filter

    d_fill = median_filter(d_fill, size=(5, 1), mode="nearest")   # isolated late echoes
    lag = align_ssd(_resample(t_ref, r, gr), d_fill, min_overlap=c["align"]["min_overlap"])
    coarse = float(gs[0] - gr[0] - lag / fs)
    off = _fine_clock(t_us, d, t_ref, r, coarse)
    tm = t_us - off
    inside = (tm >= t_ref[0]) & (tm <= t_ref[-1])
    r_al = _resample(t_ref, r, tm)
    ref_al = _resample(t_ref, p, tm)
    r_al[~inside] = np.nan
    ref_al[~inside] = np.nan
    return {"t": t_us, "d": d, "r": r_al, "ref": ref_al, "clock_offset_s": off,
            "t_mocap": tm}


def measurement_noise(aligned: list[dict], outlier_mad: float = 5.0) -> pd.DataFrame:
    """Mean and variance of the range errors per anchor (seed 003 eq. 23).

    ``u = 1/(MN) sum_i sum_j (m_i^j - r_i^j)``,
    ``e^2 = 1/(M(N-1)) sum_i sum_j (m_i^j - r_i^j - u)^2``, pooled over the M trials.
    The paper writes ``(m_i^j - u)^2`` and one actual distance ``r_i`` per test; a swinging
    pendulum has a camera distance per sample, so the error is taken per sample and the
    variance is of the error about its mean.  Multipath outliers (``|err - median| >
    outlier_mad * 1.4826 MAD``) are excluded and counted: the paper's line-of-sight
    experiment had none, and one late echo would dominate the variance.

    Returns
    -------
    DataFrame
        ``anchor`` (index 0..m-1), ``mean_m``, ``var_m2``, ``std_m``, ``n``, ``n_outliers``.
    """
    m = aligned[0]["d"].shape[1]
    rows = []
    for k in range(m):
        errs = [a["d"][:, k] - a["r"][:, k] for a in aligned]
        allv = np.concatenate(errs)
        allv = allv[np.isfinite(allv)]
        med = np.median(allv)
        mad = 1.4826 * np.median(np.abs(allv - med))
        keep_sets = [e[np.isfinite(e) & (np.abs(e - med) <= outlier_mad * mad)] for e in errs]
        M = sum(1 for e in keep_sets if e.size > 1)
        N_tot = sum(e.size for e in keep_sets)
        u = sum(e.sum() for e in keep_sets) / N_tot                         # eq. (23)
        e2 = sum(((e - u) ** 2).sum() for e in keep_sets) / (N_tot - M)     # eq. (23)
        rows.append({"anchor": k, "mean_m": u, "var_m2": e2, "std_m": np.sqrt(e2),
                     "n": int(N_tot), "n_outliers": int(allv.size - N_tot)})
    return pd.DataFrame(rows)


def _track_errors(aligned: list[dict], logs: list[UltrasonicLog], cfg: dict,
                  skip_start_s: float) -> np.ndarray:
    errs = []
    for a, log in zip(aligned, logs):
        tr = track_ultrasonic_trial(log, cfg)
        e = tr[["x_m", "y_m", "z_m"]].to_numpy() - a["ref"]
        keep = (a["t"] - a["t"][0]) >= skip_start_s
        errs.append(e[keep])
    e = np.concatenate(errs)
    return e[np.all(np.isfinite(e), axis=1)]


def _rmse3(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(e ** 2, axis=1))))


def identify_noise(trials: list[tuple[UltrasonicLog, MocapTrial]], cfg: dict | None = None,
                   *, names: list[str] | None = None) -> dict:
    """Measurement noise V per anchor and process noise W from pendulum trials (§4.3).

    Parameters
    ----------
    trials : list of (UltrasonicLog, MocapTrial)
        The pendulum trials: transmitter with a marker ``TX`` on the pendulum, receivers
        with markers ``ANC1..``.
    cfg : dict
        ``noise_id.W_grid_mps2`` (candidate sigmas, m/s^2), ``noise_id.outlier_mad``,
        ``noise_id.skip_start_s`` and the ``ukf`` keys used while searching.
    names : list of str, optional
        Trial ids for error messages.

    Returns
    -------
    dict
        ``V_m2`` (list, variance per anchor, eq. 23), ``bias_m`` (mean range error per
        anchor), ``W_sigma_mps2`` ([sx, sy, sz], minimum-RMSE search), ``rmse_m`` (3-D RMSE
        of the UKF track at that W), ``noise`` (DataFrame of :func:`measurement_noise`),
        ``search`` (DataFrame ``sx, sy, sz, rmse_m`` of every candidate tried),
        ``clock`` (DataFrame ``trial, clock_offset_s``), ``_aligned`` (the per-trial
        :func:`pendulum_alignment` dicts, to pass on to :func:`pendulum_errors`).

    Notes
    -----
    §4.3.1: "By varying the values of sigma_wx, sigma_wy and sigma_wz, we will get the
    corresponding trajectory ... to compute the RMSE value.  Typical values ... will be
    selected when their corresponding RMSE is minimal."  The search here first varies one
    common sigma over the grid, then each axis in turn (coordinate descent, one sweep per
    axis, twice), with the identified V in the filter.
    """
    c = resolve_cfg(cfg)
    names = names or [f"pendulum {i + 1}" for i in range(len(trials))]
    aligned = [pendulum_alignment(log, mo, c, trial=nm) for (log, mo), nm in zip(trials, names)]
    logs = [log for log, _ in trials]
    noise = measurement_noise(aligned, float(c["noise_id"]["outlier_mad"]))
    V = noise["var_m2"].to_list()
    grid = [float(g) for g in c["noise_id"]["W_grid_mps2"]]
    skip = float(c["noise_id"]["skip_start_s"])
    cache: dict[tuple, float] = {}

    def rmse(w):
        key = tuple(round(x, 9) for x in w)
        if key not in cache:
            cc = deep_merge(c, {"ukf": {"W_sigma_mps2": list(key), "V_m2": V}})
            cache[key] = _rmse3(_track_errors(aligned, logs, cc, skip))
        return cache[key]

    best = min(([g, g, g] for g in grid), key=rmse)
    for _ in range(2):
        for ax in range(3):
            cands = [best[:ax] + [g] + best[ax + 1:] for g in grid]
            best = min(cands, key=rmse)
    search = pd.DataFrame([{"sx": k[0], "sy": k[1], "sz": k[2], "rmse_m": v}
                           for k, v in cache.items()])
    clock = pd.DataFrame({"trial": names,
                          "clock_offset_s": [a["clock_offset_s"] for a in aligned]})
    return {"V_m2": V, "bias_m": noise["mean_m"].to_list(), "W_sigma_mps2": list(best),
            "rmse_m": rmse(best), "noise": noise, "search": search, "clock": clock,
            "_aligned": aligned}


def noise_to_config(noise: dict) -> dict:
    """The plain-number part of :func:`identify_noise`'s result, ready for YAML/JSON.

    Returns ``{"ukf": {"W_sigma_mps2": [...], "V_m2": [...]}, "bias_m": [...],
    "rmse_m": float}``; merge the ``ukf`` part into the ``ultrasonic`` config to track
    with the identified noise.
    """
    return {"ukf": {"W_sigma_mps2": [float(w) for w in noise["W_sigma_mps2"]],
                    "V_m2": [float(v) for v in noise["V_m2"]]},
            "bias_m": [float(b) for b in noise["bias_m"]], "rmse_m": float(noise["rmse_m"])}


def pendulum_errors(trials: list[tuple[UltrasonicLog, MocapTrial]], cfg: dict | None = None,
                    *, names: list[str] | None = None, aligned: list[dict] | None = None
                    ) -> pd.DataFrame:
    """Per-sample UKF errors against the camera on pendulum trials (Table 1's data).

    Returns
    -------
    DataFrame
        ``trial, t_s`` (ultrasonic clock), ``ex_m, ey_m, ez_m`` (estimate − camera in the
        ultrasonic frame: X progression, Y vertical, Z lateral).  The first
        ``noise_id.skip_start_s`` of each trial (filter initialisation) is left out.
    """
    c = resolve_cfg(cfg)
    names = names or [f"pendulum {i + 1}" for i in range(len(trials))]
    if aligned is None:
        aligned = [pendulum_alignment(lg, mo, c, trial=nm) for (lg, mo), nm in
                   zip(trials, names)]
    skip = float(c["noise_id"]["skip_start_s"])
    parts = []
    for (log, _), a, nm in zip(trials, aligned, names):
        tr = track_ultrasonic_trial(log, c, trial=nm)
        e = tr[["x_m", "y_m", "z_m"]].to_numpy() - a["ref"]
        keep = ((a["t"] - a["t"][0]) >= skip) & np.all(np.isfinite(e), axis=1)
        parts.append(pd.DataFrame({"trial": nm, "t_s": a["t"][keep], "ex_m": e[keep, 0],
                                   "ey_m": e[keep, 1], "ez_m": e[keep, 2]}))
    return pd.concat(parts, ignore_index=True)
