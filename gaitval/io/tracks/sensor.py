"""Exchange rows into gaitval's per-scan track (and detections onto the scans): the clock and
frame conversion with the trial's registration, time stamps snapped to the scans, the
columns a file lacks filled as docs/formats_external.md says.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import SIDES, TRACK_COLUMNS, _err
from gaitval.io.tracks.units import _check_detection_distances, _check_distances, _where


#: seed 000 Table 2 speed thresholds: a track without ``swing`` is in swing from the scan
#: its speed exceeds v_sw_th until it falls below v_st_th (the tracker's hysteresis)
V_ST_TH, V_SW_TH = 0.47, 0.93


def _check_registration(path, trial, frame: str, clock: str, reg: dict) -> None:
    """A file in the mocap frame or on the mocap clock needs the trial's registration's
    pose or clock offset: an error naming the file, the header field and what is unknown."""
    need = [f for f, v in (("frame", frame), ("clock", clock)) if v == "mocap"]
    if need:
        keys = (["x_m", "y_m", "yaw_rad"] if "frame" in need else []) + \
            (["clock_offset_s"] if "clock" in need else [])
        bad = [k for k in keys if reg.get(k) is None or not math.isfinite(float(reg[k]))]
        if bad:
            raise _err(path, f"header {' and '.join(need)} 'mocap' needs the trial's "
                       f"registration ({', '.join(bad)} unknown)", trial)


def _swing_from_speed(speed: np.ndarray) -> np.ndarray:
    """Swing by hysteresis on the leg speed (seed 000 Table 2 thresholds)."""
    out = np.zeros(len(speed), bool)
    state = False
    for i, v in enumerate(speed):
        if np.isfinite(v):
            if not state and v > V_SW_TH:
                state = True
            elif state and v < V_ST_TH:
                state = False
        out[i] = state
    return out


#: a converted time stamp this close to a scan's is that scan's (clock conversion rounding)
SNAP_S = 1e-6


def snap_to_scans(t: np.ndarray, scan_t: np.ndarray, tol_s: float = SNAP_S) -> np.ndarray:
    """``t`` with each time within ``tol_s`` of a scan time replaced by that scan time: a
    tracker's time stamp names the scan it tracked, and the mocap-to-sensor clock
    conversion (a subtraction and a division and back) moves it by a few 1e-16 s, enough to
    put a scan that lies on a TUG phase bound into the other phase."""
    t = np.asarray(t, float).copy()
    s = np.sort(np.asarray(scan_t, float))
    if not len(s) or not len(t):
        return t
    i = np.clip(np.searchsorted(s, t), 1, len(s) - 1) if len(s) > 1 else np.zeros(len(t), int)
    left, right = s[np.maximum(i - 1, 0)], s[i]
    near = np.where(np.abs(t - left) <= np.abs(right - t), left, right)
    hit = np.abs(near - t) <= tol_s
    t[hit] = near[hit]
    return t


def tracks_to_sensor(rows: pd.DataFrame, meta: dict, registration: dict | None = None, *,
                     path=None, trial: str | None = None,
                     t_range: tuple[float, float] | None = None,
                     tolerance_s: float = 0.0, scan_t: np.ndarray | None = None,
                     max_range_m: float | None = None) -> pd.DataFrame:
    """Exchange rows (from :func:`.read_tracks`) as gaitval's per-scan leg track.

    Parameters
    ----------
    rows, meta
        :func:`.read_tracks` output.
    registration : dict, optional
        The trial's registration record (``registration.json``: ``x_m``, ``y_m``,
        ``yaw_rad``, ``clock_offset_s``, ``clock_drift_ppm``); needed when the file's
        frame or clock is ``mocap``.
    t_range : (float, float), optional
        The recording's first and last scan time on the sensor clock; a track time stamp
        (after the clock conversion) outside it by more than ``tolerance_s`` is an error
        naming the row.
    scan_t : ndarray, optional
        The recording's scan times (sensor clock): a converted time stamp within
        :data:`SNAP_S` of one becomes that scan's time (:func:`snap_to_scans`).
    max_range_m : float, optional
        The laser's range: most positions (their median; in the sensor frame, after the
        conversion) farther than this + :data:`~gaitval.io.tracks.units.RANGE_MARGIN_M` (a
        track that diverged far in a few scans is a tracker's result, kept), or every
        position within :data:`~gaitval.io.tracks.units.MIN_DISTANCE_M` of the laser, is an
        error naming the row and the header's ``units`` (and ``frame``): positions in
        millimetres declared as metres, or the reverse, or in another frame.

    Returns
    -------
    DataFrame
        :data:`.TRACK_COLUMNS`, sorted by time and side, on the sensor clock in the sensor
        frame.  Columns the file lacks are filled as docs/formats_external.md says: ``k`` = the
        index of the time stamp, velocities by central differences, ``observed`` = a
        position is given, ``interpolated`` false, ``pattern`` ``UO`` where not observed
        (else empty), ``phase`` −1, ``swing`` from the speed (hysteresis between
        v_st_th = 0.47 and v_sw_th = 0.93 m/s, seed 000 Table 2).
    """
    if "side" not in rows:
        raise _err(path, "the file gives people (column 'person'), not legs; the leg "
                   "evaluation needs one row per leg (column 'side')", trial,
                   hint="a bag whose people are legs: set the method's legs: {L: id, R: id}")
    reg = registration or {}
    _check_registration(path, trial, meta["frame"], meta["clock"], reg)
    t = _sensor_times(rows, meta, reg, path=path, trial=trial, t_range=t_range,
                      tolerance_s=tolerance_s, scan_t=scan_t)
    x, y, vx, vy = _sensor_positions(rows, meta, reg)
    if max_range_m is not None:
        _check_distances(rows, meta, x, y, float(max_range_m), path, trial)
    df = pd.DataFrame({"t_sensor_s": t, "side": rows["side"].to_numpy(object),
                       "x_m": x, "y_m": y})
    if vx is not None:
        df["vx_mps"], df["vy_mps"] = vx, vy
    for c in ("k", "observed", "pattern", "phase", "swing", "interpolated"):
        if c in rows:
            df[c] = rows[c].to_numpy()
    df = df.sort_values(["t_sensor_s", "side"], kind="stable").reset_index(drop=True)
    return _fill_track_columns(df, scan_t, has_v=vx is not None)


def _sensor_times(rows: pd.DataFrame, meta: dict, reg: dict, *, path, trial, t_range,
                  tolerance_s: float, scan_t) -> np.ndarray:
    """The rows' time stamps on the sensor clock (:func:`tracks_to_sensor`): converted from
    the mocap clock with the registration, snapped to ``scan_t``, checked against
    ``t_range``."""
    t = rows["t_s"].to_numpy(float)
    if meta["clock"] == "mocap":
        # docs/formats.md, Clock: t_sensor = offset + (1 + drift ppm 1e-6) t_mocap
        drift = float(reg.get("clock_drift_ppm") or 0.0)
        t = float(reg["clock_offset_s"]) + (1.0 + drift * 1e-6) * t
    if scan_t is not None:      # also a bag's integer sec + nanosec stamps (1e-9 s steps)
        t = snap_to_scans(t, scan_t)
    if t_range is not None:
        lo, hi = t_range[0] - tolerance_s, t_range[1] + tolerance_s
        out_of = (t < lo) | (t > hi)
        if out_of.any():
            i = int(np.flatnonzero(out_of)[0])
            line = _where(rows, meta, i, "t_s")
            c0 = float(meta.get("clock_offset_s") or 0.0)
            off = f" after the header's clock_offset_s {c0!r} s" if c0 else ""
            raise _err(path, f"{line}: time stamp {float(rows['t_s'].iloc[i]) - c0!r} s "
                       f"({meta['clock']} clock{off}; {t[i]:.4f} s on the sensor clock) is "
                       f"outside the recording ({t_range[0]:.4f} to {t_range[1]:.4f} s on "
                       "the sensor clock)", trial,
                       hint="check the header's clock and the trial's clock offset")
    return t


def _sensor_positions(rows: pd.DataFrame, meta: dict, reg: dict) -> tuple:
    """The rows' positions and velocities (None when the file has none) in the sensor
    frame (:func:`tracks_to_sensor`), from the mocap frame with the registration's pose."""
    x, y = rows["x_m"].to_numpy(float), rows["y_m"].to_numpy(float)
    has_v = "vx_mps" in rows and "vy_mps" in rows
    vx = rows["vx_mps"].to_numpy(float) if has_v else None
    vy = rows["vy_mps"].to_numpy(float) if has_v else None
    if meta["frame"] == "mocap":
        # inverse of p_f = R(yaw) p_s + [x, y] (docs/formats.md, Sensor pose)
        c, s = math.cos(float(reg["yaw_rad"])), math.sin(float(reg["yaw_rad"]))
        dx, dy = x - float(reg["x_m"]), y - float(reg["y_m"])
        x, y = c * dx + s * dy, -s * dx + c * dy
        if has_v:
            vx, vy = c * vx + s * vy, -s * vx + c * vy
    return x, y, vx, vy


def _fill_track_columns(df: pd.DataFrame, scan_t, *, has_v: bool) -> pd.DataFrame:
    """The per-scan track's columns a file lacks, filled as docs/formats_external.md says
    (:func:`tracks_to_sensor`), in :data:`~gaitval.io.tracks.exchange.TRACK_COLUMNS` order
    and types."""
    if "k" not in df:
        tt = df["t_sensor_s"].to_numpy(float)
        idx = (np.clip(np.searchsorted(scan_t, tt), 0, len(scan_t) - 1)
               if scan_t is not None and len(scan_t) else None)
        if idx is not None and np.array_equal(np.asarray(scan_t)[idx], tt):
            df["k"] = idx.astype(np.int64)      # the scan each time stamp names
        else:
            df["k"] = pd.factorize(df["t_sensor_s"])[0].astype(np.int64)
    finite = np.isfinite(df["x_m"].to_numpy(float)) & np.isfinite(df["y_m"].to_numpy(float))
    if not has_v:
        df["vx_mps"], df["vy_mps"] = np.nan, np.nan
        for side in SIDES:
            m = (df["side"] == side).to_numpy() & finite
            if m.sum() >= 2:
                tt = df.loc[m, "t_sensor_s"].to_numpy(float)
                df.loc[m, "vx_mps"] = np.gradient(df.loc[m, "x_m"].to_numpy(float), tt)
                df.loc[m, "vy_mps"] = np.gradient(df.loc[m, "y_m"].to_numpy(float), tt)
    if "observed" not in df:
        df["observed"] = finite
    if "interpolated" not in df:
        df["interpolated"] = False
    if "pattern" not in df:
        df["pattern"] = np.where(df["observed"].to_numpy(bool), "", "UO").astype(object)
        df.loc[~finite, "pattern"] = ""
    if "phase" not in df:
        df["phase"] = np.int64(-1)
    if "swing" not in df:
        df["swing"] = False
        for side in SIDES:
            m = (df["side"] == side).to_numpy()
            sp = np.hypot(df.loc[m, "vx_mps"].to_numpy(float),
                          df.loc[m, "vy_mps"].to_numpy(float))
            df.loc[m, "swing"] = _swing_from_speed(sp)
    df = df[list(TRACK_COLUMNS)]
    df = df.astype({"k": np.int64, "phase": np.int64, "observed": bool, "swing": bool,
                    "interpolated": bool})
    df["pattern"] = df["pattern"].astype(object)
    df["side"] = df["side"].astype(object)
    return df


def detections_to_sensor(det: pd.DataFrame, meta: dict, registration: dict | None = None,
                         *, path=None, trial: str | None = None,
                         scan_t: np.ndarray | None = None, tolerance_s: float = 0.0,
                         max_range_m: float | None = None) -> tuple[pd.DataFrame, list]:
    """Detections (:func:`~gaitval.io.tracks.detections.read_detections` or
    :func:`~gaitval.io.tracks.bag.read_bag_leg_detections`) on the sensor clock in the
    laser frame, as :func:`tracks_to_sensor` converts tracks: with ``clock: mocap``
    ``t_sensor = clock_offset_s + (1 + clock_drift_ppm 1e-6) t``, with ``frame: mocap``
    ``p_s = R(-yaw) (p - [x, y])`` (the trial's ``registration``); a time within 1 µs of a
    scan's (``scan_t``) becomes that scan's.  With ``scan_t`` a time stamp outside the
    recording (± ``tolerance_s``) is an error naming its row; with ``max_range_m`` so are
    positions beyond the laser's range or all at its origin (wrong units or frame).
    Returns the rows (``t_s`` now on the sensor clock) and every message's time on the
    sensor clock."""
    frame, clock = meta.get("frame", "sensor"), meta.get("clock", "sensor")
    reg = registration or {}
    _check_registration(path, trial, frame, clock, reg)
    det = det.copy()
    t, tm = det["t_s"].to_numpy(float), np.asarray(meta["t_messages"], float)
    if clock == "mocap":
        drift = 1.0 + float(reg.get("clock_drift_ppm") or 0.0) * 1e-6
        t, tm = float(reg["clock_offset_s"]) + drift * t, float(reg["clock_offset_s"]) + drift * tm
    if scan_t is not None and len(scan_t):
        t, tm = snap_to_scans(t, scan_t), snap_to_scans(tm, scan_t)
        lo, hi = float(np.min(scan_t)) - tolerance_s, float(np.max(scan_t)) + tolerance_s
        out_of = (tm < lo) | (tm > hi)
        if out_of.any():
            i = int(np.flatnonzero(out_of)[0])
            c0 = float(meta.get("clock_offset_s") or 0.0)
            off = f" after the header's clock_offset_s {c0!r} s" if c0 else ""
            raise _err(path, f"time stamp {float(meta['t_messages'][i]) - c0!r} s ({clock} "
                       f"clock{off}; {tm[i]:.4f} s on the sensor clock) is outside the "
                       "recording "
                       f"({lo + tolerance_s:.4f} to {hi - tolerance_s:.4f} s on the sensor "
                       f"clock), as are {int(out_of.sum())} of {len(tm)} time stamps", trial,
                       hint="check the header's clock and the trial's clock offset")
    x, y = det["x_m"].to_numpy(float), det["y_m"].to_numpy(float)
    if frame == "mocap":
        c, s = math.cos(float(reg["yaw_rad"])), math.sin(float(reg["yaw_rad"]))
        dx, dy = x - float(reg["x_m"]), y - float(reg["y_m"])
        x, y = c * dx + s * dy, -s * dx + c * dy
    det["t_s"], det["x_m"], det["y_m"] = t, x, y
    if max_range_m is not None and len(det):
        _check_detection_distances(det, meta, x, y, float(max_range_m), path, trial)
    return det.drop(columns=["_row"], errors="ignore"), [float(v) for v in tm]
