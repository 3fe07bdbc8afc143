"""Ground truth per trial: leg points at sensor height (or the heel transmitter) at the
sensor timestamps, in the field and sensor frames, with velocities.

Pipeline (LRS trials)
---------------------
1.-3. Leg points at the scan height for every mocap frame, gap-filled, from the joint
   centres or the tibia cylinder, with the frames where either is missing counted
   (:mod:`gaitval.groundtruth.legs`).  They are computed once per trial
   (:func:`~gaitval.groundtruth.legs.sensor_leg_points`), used first by the registration
   and then handed to :func:`ground_truth` (``legs``).
4. Sensor timestamps are mapped to mocap time with the clock record,
   ``t_mocap = (t_sensor - clock_offset_s) / (1 + clock_drift_ppm * 1e-6)``
   (:func:`~gaitval.registration.clock.to_mocap_time`), and positions are linearly
   interpolated there (error < 0.2 mm for a shin at 200 Hz).  A row is valid when both
   bracketing mocap frames are valid.
5. Velocities: positions low-passed (2nd-order Butterworth, 10 Hz, zero phase), then
   central differences (seed 002: "velocities resulted from simple differentiation"),
   then interpolated like the positions.  Positions themselves are not filtered unless
   ``filter_positions: true``.
6. Sensor frame: ``p_s = R(yaw)^T (p_f - t)`` with the fixed pose, or, for the rollator, the
   per-frame pose from the rollator markers (interpolated at each scan's mocap time).

Ultrasonic trials (seed 003 §4.1)
---------------------------------
The reference is the ``TX`` marker (the transmitter on the right heel); it is linearly
resampled to the ultrasonic timestamps (50 Hz) and low-pass filtered (2nd-order
Butterworth at 10 Hz, zero phase) -- "the difference between the sampling rate of these two
systems was compensated by linear interpolation.  All data were low-pass filtered by
second order low-pass Butterworth filter at 10 Hz."  The sensor frame is the ultrasonic
system's frame (anchor coordinates), found by a 3-D rigid fit of the anchor positions of
the log to the ``ANC1..ANC4`` markers; NaN when those markers are absent.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import MarkerError, RegistrationError
from gaitval.groundtruth.filters import differentiate, lowpass
from gaitval.groundtruth.gaps import fill_short_gaps
from gaitval.groundtruth.legs import LegPoints, sensor_leg_points
from gaitval.groundtruth.settings import DEFAULTS, gt_cfg
from gaitval.registration.clock import to_mocap_time
from gaitval.registration.moving import (is_moving, mount_from_cfg, rollator_labels,
                                         rollator_pose, sensor_pose_from_rollator)
from gaitval.registration.rigid import field_to_sensor
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

__all__ = ["DEFAULTS", "GT_COLUMNS", "ground_truth", "resample", "ultrasonic_ground_truth"]

#: Columns of an LRS trial's ground truth, in order (:func:`ground_truth`).
GT_COLUMNS = [C.SCAN, C.T_SENSOR, C.T_MOCAP, C.SIDE, C.X, C.Y, C.XS, C.YS,
              C.VX, C.VY, "vxs_mps", "vys_mps", C.VALID]


def resample(t_src: np.ndarray, x: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear interpolation of x (n, ...) at times t; valid only between two valid frames.

    Returns (values (len(t), ...), valid (len(t),) bool).
    """
    flat = np.asarray(x, dtype=float).reshape(len(t_src), -1)
    ok = np.all(np.isfinite(flat), axis=1)
    t = np.asarray(t, dtype=float)
    idx = np.searchsorted(t_src, t, side="right")
    lo = np.clip(idx - 1, 0, len(t_src) - 1)
    hi = np.clip(idx, 0, len(t_src) - 1)
    exact = np.isclose(t_src[lo], t, rtol=0, atol=1e-9)
    inside = (t >= t_src[0]) & (t <= t_src[-1])
    valid = inside & ok[lo] & (ok[hi] | exact)
    out = np.full((len(t), flat.shape[1]), np.nan)
    if ok.sum() >= 1:
        for j in range(flat.shape[1]):
            out[:, j] = np.interp(t, t_src[ok], flat[ok, j]) if ok.sum() >= 2 else np.nan
    out[~valid] = np.nan
    return out.reshape((len(t),) + np.asarray(x).shape[1:]), valid


def ground_truth(mocap: MocapTrial, sensor, reg, trial: dict, subject: dict | None,
                 cfg: dict | None, *, legs: LegPoints | None = None) -> pd.DataFrame:
    """Ground-truth trajectories of one trial at the sensor timestamps.

    Parameters
    ----------
    mocap : MocapTrial
    sensor : ScanSeries or UltrasonicLog
    reg : RegistrationRecord
        From :func:`gaitval.registration.register_trial` (pose and clock).
    trial : dict
        Trial-sheet row (``trial``, ``protocol``, ``sensor_height_m``).
    subject : dict
        Subject-table row.
    cfg : dict
        Whole config or its ``groundtruth:`` section (``rollator.sensor_mount`` is read
        from the whole config for the rollator).
    legs : LegPoints, optional
        LRS: the trial's leg points, :func:`~gaitval.groundtruth.legs.sensor_leg_points`,
        as handed to the registration; computed here when not given.

    Returns
    -------
    DataFrame
        LRS: one row per (scan, side) with columns :data:`GT_COLUMNS`:
        ``scan`` (index in the log), ``t_sensor_s``, ``t_mocap_s``, ``side`` (L/R),
        ``x_m, y_m`` (field), ``xs_m, ys_m`` (sensor frame), ``vx_mps, vy_mps`` (field
        velocity), ``vxs_mps, vys_mps`` (velocity in the sensor frame; for a moving sensor
        the velocity relative to the sensor), ``valid`` (bool).
        Ultrasonic: one row per sample, side ``R`` (``""`` for pendulum trials), plus
        ``z_m``, ``zs_m``, ``vz_mps``; see :func:`ultrasonic_ground_truth`.
    """
    if isinstance(sensor, UltrasonicLog):
        return ultrasonic_ground_truth(mocap, sensor, reg, trial, cfg)
    if not isinstance(sensor, ScanSeries):
        raise TypeError(f"ground_truth: unsupported sensor type {type(sensor).__name__}")
    c = gt_cfg(cfg)
    lp = legs if legs is not None else sensor_leg_points(mocap, sensor, trial, subject, cfg)
    P = lp.xyz[..., :2]                                         # (n, 2, 2)
    tm = lp.t
    t_m = to_mocap_time(sensor.t, reg.clock_offset_s, reg.clock_drift_ppm)
    Pf = lowpass(P, mocap.rate_hz, c["lowpass_hz"], c["lowpass_order"])
    V = differentiate(Pf, tm)
    Ppos = Pf if c["filter_positions"] else P
    moving = is_moving(trial)
    if moving:
        Ps, Vs = _relative_to_moving_sensor(mocap, P, Ppos, tm, trial, cfg, c)
    rows = []
    for j, side in enumerate(C.SIDES):
        rel = (Ps[:, j], Vs[:, j]) if moving else None
        rows.append(_side_rows(sensor, reg, side, tm, t_m, Ppos[:, j], V[:, j], rel))
    df = pd.concat(rows, ignore_index=True)
    df = df.sort_values([C.SCAN, C.SIDE], kind="stable").reset_index(drop=True)
    return df[GT_COLUMNS]


def _relative_to_moving_sensor(mocap, P, Ppos, tm, trial, cfg, c):
    """Leg positions and velocities (n, 2, 2) in the frame of the moving sensor at the
    mocap frames: the per-frame sensor pose from the rollator markers and the mount.

    The rollator pose here comes from the raw rollator markers (a rollator-marker gap
    leaves those frames without a sensor frame), while the registration's clock signal
    uses the gap-filled ones (``legs.markers``); both are kept as they are so the ground
    truth of a trial with rollator-marker gaps does not change.
    """
    tid = (trial or {}).get(C.TRIAL)
    rp = rollator_pose(mocap, rollator_labels(cfg), trial=tid)
    pose_m = sensor_pose_from_rollator(rp, mount_from_cfg(cfg, tid))
    x, y, yaw = pose_m[:, None, 0], pose_m[:, None, 1], pose_m[:, None, 2]
    Ps = field_to_sensor(Ppos, x, y, yaw)
    Vs = differentiate(lowpass(field_to_sensor(P, x, y, yaw), mocap.rate_hz, c["lowpass_hz"],
                               c["lowpass_order"]), tm)
    return Ps, Vs


def _side_rows(sensor, reg, side, tm, t_m, pos_m, vel_m, rel=None) -> pd.DataFrame:
    """One side's rows at the scans: field position and velocity at mocap frames
    (``pos_m``, ``vel_m``, (n, 2)) resampled at the scans' mocap times ``t_m``; the sensor
    frame through the fixed pose of ``reg``, or resampled from ``rel`` = (positions,
    velocities) relative to a moving sensor."""
    pos, ok = resample(tm, pos_m, t_m)
    vel, _ = resample(tm, vel_m, t_m)
    if rel is not None:
        ps, oks = resample(tm, rel[0], t_m)
        vs, _ = resample(tm, rel[1], t_m)
        ok = ok & oks
    else:
        ps = field_to_sensor(pos, reg.x_m, reg.y_m, reg.yaw_rad)
        cy, sy = np.cos(reg.yaw_rad), np.sin(reg.yaw_rad)
        vs = np.column_stack([cy * vel[:, 0] + sy * vel[:, 1],       # R(yaw)^T v
                              -sy * vel[:, 0] + cy * vel[:, 1]])
    return pd.DataFrame({
        C.SCAN: np.arange(sensor.n_scans, dtype=np.int64),
        C.T_SENSOR: sensor.t, C.T_MOCAP: t_m, C.SIDE: side,
        C.X: pos[:, 0], C.Y: pos[:, 1], C.XS: ps[:, 0], C.YS: ps[:, 1],
        C.VX: vel[:, 0], C.VY: vel[:, 1], "vxs_mps": vs[:, 0], "vys_mps": vs[:, 1],
        C.VALID: ok & np.all(np.isfinite(ps), axis=1),
    })


def ultrasonic_ground_truth(mocap: MocapTrial, log: UltrasonicLog, reg, trial: dict,
                            cfg: dict | None) -> pd.DataFrame:
    """TX-marker reference at the ultrasonic timestamps (seed 003 §4.1; module docstring).

    Returns
    -------
    DataFrame ``sample, t_sensor_s, t_mocap_s, side, x_m, y_m, z_m, xs_m, ys_m, zs_m,
    vx_mps, vy_mps, vz_mps, valid``: field frame (``x_m..``), ultrasonic-system frame
    (``xs_m..``, NaN when the anchors are not registered), velocities in the field frame
    (metres per second), one row per ultrasonic sample.
    """
    from gaitval.registration.trial import register_anchors

    c = gt_cfg(cfg)
    tid = (trial or {}).get(C.TRIAL)
    tx = c["tx_marker"]
    if not mocap.has(tx):
        raise MarkerError(f"the C3D has no transmitter marker {tx!r}", path=mocap.path,
                          trial=tid, hint="set groundtruth.tx_marker")
    X, _ = fill_short_gaps(mocap.marker(tx), mocap.rate_hz, c["max_gap_s"])
    t_m = to_mocap_time(log.t, reg.clock_offset_s, reg.clock_drift_ppm)
    pos, ok = resample(mocap.t, X, t_m)                       # linear (seed 003 §4.1)
    rate = log.rate_hz
    pos = lowpass(pos, rate, c["lowpass_hz"], c["lowpass_order"])
    vel = differentiate(pos, t_m)
    try:
        R, t, _ = register_anchors(mocap, log, cfg, trial=tid)
        ps = (pos - t) @ R                                      # R^T (p - t)
    except RegistrationError:
        ps = np.full_like(pos, np.nan)
    side = "" if str((trial or {}).get("protocol", "")) == "pendulum" else "R"
    return pd.DataFrame({
        "sample": np.arange(len(log.t), dtype=np.int64), C.T_SENSOR: log.t,
        C.T_MOCAP: t_m, C.SIDE: side, C.X: pos[:, 0], C.Y: pos[:, 1], C.Z: pos[:, 2],
        C.XS: ps[:, 0], C.YS: ps[:, 1], "zs_m": ps[:, 2], C.VX: vel[:, 0],
        C.VY: vel[:, 1], "vz_mps": vel[:, 2], C.VALID: ok & np.all(np.isfinite(pos), axis=1),
    })
