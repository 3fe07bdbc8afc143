"""Seed 003's pendulum experiment (§4.3): measured against camera ranges, and track errors.

The transmitter swings on a pendulum with a camera marker on it.  :func:`pendulum_alignment`
brings the camera reference (:func:`gaitval.groundtruth.reference.reference_trajectory`) onto
the ultrasonic clock and turns it into the ranges the receivers should have measured;
:func:`pendulum_errors` runs the tracker and gives its per-sample errors against the camera
(Table 1's data).  The noise identification of §4.3 (eq. 23 and the W search) summarises
these in :mod:`gaitval.stats.noise`.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.evaluate.alignment import align_ssd, resample
from gaitval.evaluate.ultrasonic_config import build_tracker, reference_kwargs, resolve_cfg
from gaitval.groundtruth.filters import lowpass
from gaitval.groundtruth.reference import reference_trajectory
from gaitval.io.ultrasonic import anchor_positions, log_distances
from gaitval.types import MocapTrial, UltrasonicLog


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
    ref = reference_trajectory(mocap, log.anchors, **reference_kwargs(c), trial=trial)
    t_ref = ref["t_s"].to_numpy()
    p = ref[["x_m", "y_m", "z_m"]].to_numpy()
    A = anchor_positions(log.anchors)
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
    lag = align_ssd(resample(t_ref, r, gr), d_fill, min_overlap=c["align"]["min_overlap"])
    coarse = float(gs[0] - gr[0] - lag / fs)
    off = _fine_clock(t_us, d, t_ref, r, coarse)
    tm = t_us - off
    inside = (tm >= t_ref[0]) & (tm <= t_ref[-1])
    r_al = resample(t_ref, r, tm)
    ref_al = resample(t_ref, p, tm)
    r_al[~inside] = np.nan
    ref_al[~inside] = np.nan
    return {"t": t_us, "d": d, "r": r_al, "ref": ref_al, "clock_offset_s": off,
            "t_mocap": tm}


def pendulum_track_errors(tracker, log: UltrasonicLog, aligned: dict, skip_start_s: float,
                          *, lowpass_cfg: dict | None = None, trial: str | None = None
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Track one pendulum log and compare with the camera.

    Both trajectories pass through the zero-phase Butterworth low-pass of ``lowpass_cfg``
    (``order``, ``cutoff_hz``; the ``ultrasonic.lowpass`` of the treadmill trials) at the
    log's median rate before they are compared: seed 003 §4.1, "All data were low-pass
    filtered by second order low-pass Butterworth filter at 10 Hz".  ``None`` compares the
    raw samples.

    Parameters
    ----------
    tracker : ToaUkf
        The tracker role (:func:`gaitval.evaluate.ultrasonic_config.build_tracker`).
    log : UltrasonicLog
    aligned : dict
        :func:`pendulum_alignment` of the trial.
    skip_start_s : float
        Filter start-up left out (s).

    Returns
    -------
    e : ndarray (n, 3)
        Estimate − camera per log sample (ultrasonic frame; NaN outside the capture).
    keep : ndarray (n,) bool
        Samples after the first ``skip_start_s``.
    """
    tr = tracker.track(log, trial=trial)
    est, ref = tr[["x_m", "y_m", "z_m"]].to_numpy(float), np.asarray(aligned["ref"], float)
    if lowpass_cfg is not None:
        fs = 1.0 / float(np.median(np.diff(aligned["t"])))
        est, ref = (lowpass(x, fs, lowpass_cfg["cutoff_hz"], lowpass_cfg["order"])  # seed003 §4.1
                    for x in (est, ref))
    e = est - ref
    return e, (aligned["t"] - aligned["t"][0]) >= skip_start_s


def pendulum_errors(trials: list[tuple[UltrasonicLog, MocapTrial]], cfg: dict | None = None,
                    *, names: list[str] | None = None, aligned: list[dict] | None = None
                    ) -> pd.DataFrame:
    """Per-sample UKF errors against the camera on pendulum trials (Table 1's data).

    Returns
    -------
    DataFrame
        ``trial, t_s`` (ultrasonic clock), ``ex_m, ey_m, ez_m`` (estimate − camera in the
        ultrasonic frame: X progression, Y vertical, Z lateral), both low-passed as the
        treadmill's (``lowpass``, seed 003 §4.1).  The first
        ``noise_id.skip_start_s`` of each trial (filter initialisation) is left out.
    """
    c = resolve_cfg(cfg)
    names = names or [f"pendulum {i + 1}" for i in range(len(trials))]
    if aligned is None:
        aligned = [pendulum_alignment(lg, mo, c, trial=nm) for (lg, mo), nm in
                   zip(trials, names)]
    skip = float(c["noise_id"]["skip_start_s"])
    tracker = build_tracker(c)
    parts = []
    for (log, _), a, nm in zip(trials, aligned, names):
        e, keep = pendulum_track_errors(tracker, log, a, skip, lowpass_cfg=c["lowpass"],
                                        trial=nm)
        keep = keep & np.all(np.isfinite(e), axis=1)
        parts.append(pd.DataFrame({"trial": nm, "t_s": a["t"][keep], "ex_m": e[keep, 0],
                                   "ey_m": e[keep, 1], "ez_m": e[keep, 2]}))
    return pd.concat(parts, ignore_index=True)
