"""Evaluation of rollator leg tracking against the tibia-cylinder ground truth (seed 002 §IV).

The ground truth is the one registration builds (``groundtruth.parquet``: the tibia
cylinder's cross-section at laser height, carried into the moving laser frame by the
rollator markers, velocities by differentiation, seed 002 §IV.B).  This module judges a
tracker's per-scan output against it; the statistics (RMSE, MAD) and the tables are
computed downstream (:mod:`gaitval.tables.rollator`).

Per scan (``status``)
    ``outside_capture``
        the scan's mocap time is outside the capture (the laser log runs longer);
    ``pose_unknown``
        inside the capture, but a rollator marker is missing at a neighbouring mocap frame,
        so the laser's pose — and the truth in its frame — is unknown: excluded and
        counted, never interpolated across (seed 002's Euclidean transformation needs all
        four rollator markers; gaps are not filled for the pose);
    ``no_truth``
        the pose is known but a leg's truth is not (tibia markers missing);
    ``evaluated``
        both legs' truth known: the scan counts in Tables I and II.
Error frame (Table II; the paper gives no rule)
    An evaluated scan is an error when a tracker has no estimate of a leg (not yet
    initialised), either leg's estimate is farther than ``error_m`` = 0.10 m from its
    truth (about one shank diameter: the estimate is no longer on that leg), or the legs
    are swapped (each estimate nearer to the other leg's truth than to its own; two shank
    centres are at least a leg width apart, so this is unambiguous).
Tracking time
    Correct (evaluated, non-error) scans × the scan period (median timestamp difference):
    seed 002 Table II's "total tracking time" is the time of correct tracking (its KF and
    PF times differ by the error frames at ~37 frames/s).
Table I errors
    Of the mean of both legs (seed 002 §IV.C: "x, y refer to the mean position and v_x,
    v_y to the mean velocity of both legs"), over every evaluated scan with an estimate,
    error frames included (the paper blames the KF's large errors on its failures).

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017, §IV.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.registration.clock import to_mocap_time
from gaitval.registration.moving import ROLLATOR_MARKERS, interp_pose, rollator_pose

DEFAULTS = {"error_m": 0.10}
STATUSES = ("evaluated", "no_truth", "pose_unknown", "outside_capture")
#: per-leg columns of the frames table, each with suffix _L and _R
_LEG = ("x_true_m", "y_true_m", "vx_true_mps", "vy_true_mps", "x_m", "y_m", "vx_mps",
        "vy_mps", "err_m")
FRAME_COLUMNS = (("trial", "tracker", "scan", "t_sensor_s", "status", "has_estimate",
                  "swapped", "error", "restart")
                 + tuple(f"{c}_{s}" for s in "LR" for c in _LEG))
SUMMARY_COLUMNS = ("trial", "tracker", "n_scans", "n_outside_capture", "n_pose_unknown",
                   "n_no_truth", "n_evaluated", "n_error", "n_swapped", "n_far",
                   "n_no_estimate", "error_pct", "tracking_time_s", "evaluated_time_s",
                   "restarts", "scan_period_s")


def pose_known(mocap, t_sensor: np.ndarray, clock_offset_s: float, clock_drift_ppm: float,
               labels=ROLLATOR_MARKERS, *, trial: str | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Which scans have a known laser pose, from the raw rollator markers.

    Parameters
    ----------
    mocap : MocapTrial
    t_sensor : ndarray (n_scans,) scan times, sensor clock.
    clock_offset_s, clock_drift_ppm : float
        The registration's clock record.
    labels : the four rollator markers (front-left, front-right, rear-left, rear-right).

    Returns
    -------
    known : (n_scans,) bool; inside : (n_scans,) bool, the scan is within the capture.

    Raises
    ------
    RegistrationError
        The C3D lacks a rollator marker (naming the file and trial).
    """
    rp = rollator_pose(mocap, list(labels), trial=trial)                 # raw, no gap fill
    t_m = to_mocap_time(t_sensor, clock_offset_s, clock_drift_ppm)
    inside = (t_m >= mocap.t[0]) & (t_m <= mocap.t[-1])
    known = np.all(np.isfinite(interp_pose(mocap.t, rp, t_m)), axis=1) & inside
    return known, inside


def _per_leg(df: pd.DataFrame, n: int, cols: list[str], side_col: str = "side",
             index_col: str = "scan") -> dict[str, np.ndarray]:
    out = {}
    for s in "LR":
        d = df[df[side_col] == s].set_index(index_col).reindex(range(n))
        for c in cols:
            out[f"{c}_{s}"] = d[c].to_numpy(dtype=float)
    return out


def evaluate_rollator_trial(track: pd.DataFrame, truth: pd.DataFrame, known: np.ndarray,
                            inside: np.ndarray, *, trial: str = "", tracker: str = "",
                            cfg: dict | None = None) -> dict[str, pd.DataFrame]:
    """Per-scan judgement and trial summary of one tracker on one rollator trial.

    Parameters
    ----------
    track : DataFrame
        Tracker output (:data:`gaitval.track.TRACK_COLUMNS`; an optional bool column
        ``restart`` marks the KF's re-initialisations), sensor frame.
    truth : DataFrame
        ``groundtruth.parquet``: ``scan, side, xs_m, ys_m, vxs_mps, vys_mps, valid``.
    known, inside : ndarray (n_scans,) bool
        From :func:`pose_known`.
    trial, tracker : str
        Labels written into the tables.
    cfg : dict, optional
        ``{"error_m": ...}`` (module notes).

    Returns
    -------
    dict with ``frames`` (:data:`FRAME_COLUMNS`, one row per scan) and ``summary`` (one
    row, :data:`SUMMARY_COLUMNS`).
    """
    c = {**DEFAULTS, **(cfg or {})}
    n = len(known)
    if len(truth) and int(truth["scan"].max()) >= n:
        raise GaitvalError(f"ground truth has scans up to {int(truth['scan'].max())} but "
                           f"the track has {n}", trial=trial)
    tr = _per_leg(truth.rename(columns={"xs_m": "x_true_m", "ys_m": "y_true_m",
                                        "vxs_mps": "vx_true_mps", "vys_mps": "vy_true_mps"})
                  .assign(valid=lambda d: d["valid"].astype(float)), n,
                  ["x_true_m", "y_true_m", "vx_true_mps", "vy_true_mps", "valid"])
    est = _per_leg(track.rename(columns={"k": "scan"}), n, ["x_m", "y_m", "vx_mps", "vy_mps"])
    truth_ok = (tr.pop("valid_L") == 1.0) & (tr.pop("valid_R") == 1.0)
    status = np.where(~inside, "outside_capture",
                      np.where(~known, "pose_unknown",
                               np.where(~truth_ok, "no_truth", "evaluated")))
    P = {s: np.column_stack([est[f"x_m_{s}"], est[f"y_m_{s}"]]) for s in "LR"}
    T = {s: np.column_stack([tr[f"x_true_m_{s}"], tr[f"y_true_m_{s}"]]) for s in "LR"}
    err = {s: np.linalg.norm(P[s] - T[s], axis=1) for s in "LR"}
    cross = {s: np.linalg.norm(P[s] - T["R" if s == "L" else "L"], axis=1) for s in "LR"}
    has = np.isfinite(P["L"]).all(axis=1) & np.isfinite(P["R"]).all(axis=1)
    ev = status == "evaluated"
    with np.errstate(invalid="ignore"):
        swapped = has & ev & (cross["L"] < err["L"]) & (cross["R"] < err["R"])
        far = has & ev & ((err["L"] > c["error_m"]) | (err["R"] > c["error_m"]))
    error = ev & (~has | swapped | far)
    cols = {"trial": trial, "tracker": tracker, "scan": np.arange(n, dtype=np.int64),
            "t_sensor_s": _scan_times(track, n), "status": status, "has_estimate": has,
            "swapped": swapped, "error": error, "restart": _restarts(track, n)}
    for s in "LR":
        cols.update({f"{k}_{s}": tr[f"{k}_{s}"] for k in _LEG[:4]})
        cols.update({f"{k}_{s}": est[f"{k}_{s}"] for k in _LEG[4:8]})
        cols[f"err_m_{s}"] = np.where(ev, err[s], np.nan)
    frames = pd.DataFrame(cols)
    return {"frames": frames[list(FRAME_COLUMNS)],
            "summary": _summary(frames, trial, tracker, far & ~swapped)}


def _restarts(track: pd.DataFrame, n: int) -> np.ndarray:
    """Scans where the tracker re-initialised both legs (column ``restart``, if any)."""
    out = np.zeros(n, bool)
    if "restart" in track.columns:
        r = track.groupby("k")["restart"].any().reindex(range(n), fill_value=False)
        out[:] = r.to_numpy(bool)
    return out


def _scan_times(track: pd.DataFrame, n: int) -> np.ndarray:
    t = track.groupby("k")["t_sensor_s"].first().reindex(range(n))
    return t.to_numpy(dtype=float)


def _summary(frames: pd.DataFrame, trial: str, tracker: str, far: np.ndarray) -> pd.DataFrame:
    st = frames["status"]
    t = frames["t_sensor_s"].to_numpy(float)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else float("nan")
    ev = (st == "evaluated").to_numpy()
    n_ev, n_err = int(ev.sum()), int(frames["error"].sum())
    row = {"trial": trial, "tracker": tracker, "n_scans": len(frames),
           "n_outside_capture": int((st == "outside_capture").sum()),
           "n_pose_unknown": int((st == "pose_unknown").sum()),
           "n_no_truth": int((st == "no_truth").sum()), "n_evaluated": n_ev,
           "n_error": n_err, "n_swapped": int(frames["swapped"].sum()),
           "n_far": int(far.sum()),
           "n_no_estimate": int((ev & ~frames["has_estimate"].to_numpy()).sum()),
           "error_pct": 100.0 * n_err / n_ev if n_ev else float("nan"),
           "tracking_time_s": (n_ev - n_err) * dt, "evaluated_time_s": n_ev * dt,
           "restarts": int(frames["restart"].sum()), "scan_period_s": dt}
    return pd.DataFrame([row], columns=list(SUMMARY_COLUMNS))
