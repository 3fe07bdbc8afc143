"""Ground truth per trial: leg points at sensor height (or the heel transmitter) at the
sensor timestamps, in the field and sensor frames, with velocities.

Pipeline (LRS trials)
---------------------
1. Every marker is gap-filled (:func:`~gaitval.groundtruth.gaps.fill_short_gaps`, gaps up
   to ``max_gap_s``).
2. Knee and ankle centres (:mod:`~gaitval.groundtruth.joints`), then the leg point at the
   scan height ``h`` (:func:`~gaitval.groundtruth.shank.point_at_height`), or, for the
   rollator (or ``leg_point: cylinder``), the tibia-cylinder cross-section
   (:func:`~gaitval.groundtruth.shank.fit_cylinder_cluster`: one cylinder in the tibia
   cluster's frame, axis direction from knee - ankle, carried per frame by the cluster's
   rigid motion).
3. Mocap frames where either leg point is missing are counted
   (``gt_frames_excluded``).
4. Sensor timestamps are mapped to mocap time with the clock record,
   ``t_mocap = (t_sensor - clock_offset_s) / (1 + clock_drift_ppm * 1e-6)``, and positions
   are linearly interpolated there (error < 0.2 mm for a shin at 200 Hz).  A row is valid
   when both bracketing mocap frames are valid.
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

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import MarkerError, RegistrationError
from gaitval.groundtruth.filters import differentiate, lowpass
from gaitval.groundtruth.gaps import MAX_GAP_S, fill_short_gaps
from gaitval.groundtruth.joints import joint_centre, source_label
from gaitval.groundtruth.shank import cylinder_at_height, fit_cylinder_cluster, point_at_height
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

SIDES = ("L", "R")

#: Defaults of the ``groundtruth:`` config keys.
DEFAULTS = {
    "max_gap_s": MAX_GAP_S,
    "lowpass_hz": 10.0,
    "lowpass_order": 2,
    "filter_positions": False,
    "leg_point": "auto",            # auto | axis | cylinder
    "cylinder_marker_offset_m": 0.009,
    "tibia_markers": ["TB1", "TB2", "TB3", "TB4"],   # prefixed with L/R
    "tx_marker": "TX",
    "anchor_markers": ["ANC1", "ANC2", "ANC3", "ANC4"],
}

GT_COLUMNS = ["scan", "t_sensor_s", "t_mocap_s", "side", "x_m", "y_m", "xs_m", "ys_m",
              "vx_mps", "vy_mps", "vxs_mps", "vys_mps", "valid"]


def section(cfg: dict | None, name: str) -> dict:
    """The ``name:`` section of a config dict, or the dict itself when it has no such key."""
    cfg = cfg or {}
    sub = cfg.get(name)
    return dict(sub) if isinstance(sub, dict) else dict(cfg)


def gt_cfg(cfg: dict | None) -> dict:
    c = dict(DEFAULTS)
    c.update({k: v for k, v in section(cfg, "groundtruth").items() if k in DEFAULTS})
    return c


def as_float(v) -> float | None:
    """A trial-sheet / subject-table cell as float, or None when empty/NaN/unparseable."""
    if v is None:
        return None
    if isinstance(v, str) and not v.strip():
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if np.isfinite(f) else None


def sensor_height(sensor, trial: dict) -> float:
    """Scan-plane height: the trial sheet's ``sensor_height_m``, else the log metadata."""
    h = as_float((trial or {}).get("sensor_height_m"))
    if h is None:
        h = as_float(getattr(sensor, "mounting_height_m", None))
    if h is None:
        raise RegistrationError(
            "the sensor height is unknown (empty sensor_height_m in the trial sheet and "
            "no mounting_height_m in the log)", path=getattr(sensor, "source", None),
            trial=(trial or {}).get("trial"), hint="fill sensor_height_m in trials.csv")
    return h


@dataclass
class LegPoints:
    """Mocap-side leg points at sensor height.

    Attributes
    ----------
    t : ndarray (n_frames,) mocap time, seconds
    xyz : ndarray (n_frames, 2, 3) field frame, metres; sides in order ``L, R``
    valid : ndarray (n_frames, 2) bool
    source : str  (``joint_centre_source``)
    n_excluded : int  mocap frames where either leg point is missing after gap filling
    n_filled : int  mocap frames where a used marker was gap-filled
    markers : dict  the gap-filled marker arrays (label -> (n, 3))
    """

    t: np.ndarray
    xyz: np.ndarray
    valid: np.ndarray
    source: str
    n_excluded: int
    n_filled: int
    markers: dict


def filled_markers(mocap: MocapTrial, max_gap_s: float, labels=None) -> tuple[dict, int]:
    """Gap-fill markers; returns ({label: (n, 3)}, frames with any fill)."""
    out, any_fill = {}, np.zeros(mocap.n_frames, dtype=bool)
    for lb in (labels if labels is not None else mocap.labels):
        if not mocap.has(lb):
            continue
        out[lb], f = fill_short_gaps(mocap.marker(lb), mocap.rate_hz, max_gap_s)
        any_fill |= f
    return out, int(any_fill.sum())


def _tibia_labels(side, c):
    return [side + m for m in c["tibia_markers"]]


def leg_points(mocap: MocapTrial, h: float, subject: dict | None = None,
               cfg: dict | None = None, *, cylinder: bool | None = None,
               trial: str | None = None) -> LegPoints:
    """Leg points at height ``h`` for both legs at every mocap frame (field frame).

    Parameters
    ----------
    mocap : MocapTrial
    h : float
        Scan-plane height (metres above the floor).
    subject : dict, optional
        Subject-table row (joint widths for the lateral-offset joint centres).
    cfg : dict, optional
        ``groundtruth:`` config (see :data:`DEFAULTS`).
    cylinder : bool, optional
        Use the tibia-cylinder cross-section (seed 002) instead of the knee-ankle axis;
        default from ``leg_point`` (``auto``: cylinder when every tibia marker of both legs
        is in the C3D).

    Returns
    -------
    LegPoints
    """
    c = gt_cfg(cfg)
    want = set()
    for s in SIDES:
        o = "R" if s == "L" else "L"
        want |= {s + x for x in ("FEO", "TIO", "KJC", "AJC", "KNE", "KNEin", "ANK", "ANKin",
                                 "ASI")}
        want |= set(_tibia_labels(s, c))
    markers, _ = filled_markers(mocap, c["max_gap_s"], [lb for lb in mocap.labels if lb in want])
    if cylinder is None:
        if c["leg_point"] == "cylinder":
            cylinder = True
        elif c["leg_point"] == "axis":
            cylinder = False
        else:
            cylinder = all(mocap.has(lb) for s in SIDES for lb in _tibia_labels(s, c))
    n = mocap.n_frames
    xyz = np.full((n, 2, 3), np.nan)
    valid = np.zeros((n, 2), dtype=bool)
    sources = {}
    filled_any = np.zeros(n, dtype=bool)
    for j, s in enumerate(SIDES):
        knee, sk = joint_centre(mocap, s, "knee", subject, markers=markers, trial=trial)
        ankle, sa = joint_centre(mocap, s, "ankle", subject, markers=markers, trial=trial)
        sources[(s, "knee")], sources[(s, "ankle")] = sk, sa
        if cylinder:
            tl = _tibia_labels(s, c)
            miss = [lb for lb in tl if lb not in markers]
            if miss:
                raise MarkerError(f"tibia-cylinder ground truth needs {tl}; missing {miss}",
                                  path=mocap.path, trial=trial,
                                  hint="set groundtruth.leg_point: axis to use the "
                                       "knee-ankle axis instead")
            M = np.stack([markers[lb] for lb in tl], axis=1)
            axis = knee - ankle
            cen, d, _ = fit_cylinder_cluster(M, axis, c["cylinder_marker_offset_m"])
            p, ok = cylinder_at_height(cen, d, h)
        else:
            p, ok = point_at_height(knee, ankle, h)
        xyz[:, j] = p
        valid[:, j] = ok
    src = source_label(sources)
    if cylinder:
        src = "tibia_cylinder"
    for lb, arr in markers.items():
        filled_any |= np.isfinite(arr).all(axis=1) & ~np.isfinite(mocap.marker(lb)).all(axis=1)
    n_excl = int((~valid.all(axis=1)).sum())
    return LegPoints(mocap.t, xyz, valid, src, n_excl, int(filled_any.sum()), markers)


def to_mocap_time(t_sensor, clock_offset_s: float, clock_drift_ppm: float) -> np.ndarray:
    """``t_mocap = (t_sensor - clock_offset_s) / (1 + clock_drift_ppm * 1e-6)``."""
    return (np.asarray(t_sensor, dtype=float) - clock_offset_s) / (1.0 + clock_drift_ppm * 1e-6)


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
                 cfg: dict | None) -> pd.DataFrame:
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
    from gaitval.registration.moving import (interp_pose, rollator_pose,
                                             sensor_pose_from_rollator)
    from gaitval.registration.rigid import field_to_sensor
    from gaitval.registration.trial import is_moving, mount_from_cfg, rollator_labels

    c = gt_cfg(cfg)
    tid = (trial or {}).get("trial")
    h = sensor_height(sensor, trial)
    lp = leg_points(mocap, h, subject, c, trial=tid)
    P = lp.xyz[..., :2]                                         # (n, 2, 2)
    tm = lp.t
    t_m = to_mocap_time(sensor.t, reg.clock_offset_s, reg.clock_drift_ppm)
    Pf = lowpass(P, mocap.rate_hz, c["lowpass_hz"], c["lowpass_order"])
    V = differentiate(Pf, tm)
    Ppos = Pf if c["filter_positions"] else P
    moving = is_moving(trial)
    if moving:
        rp = rollator_pose(mocap, rollator_labels(cfg), trial=tid, xyz=lp.markers
                           if all(lb in lp.markers for lb in rollator_labels(cfg)) else None)
        pose_m = sensor_pose_from_rollator(rp, mount_from_cfg(cfg, tid))
        Ps = field_to_sensor(Ppos, pose_m[:, None, 0], pose_m[:, None, 1], pose_m[:, None, 2])
        Vs = differentiate(lowpass(field_to_sensor(P, pose_m[:, None, 0], pose_m[:, None, 1],
                                                   pose_m[:, None, 2]),
                                   mocap.rate_hz, c["lowpass_hz"], c["lowpass_order"]), tm)
    rows = []
    for j, side in enumerate(SIDES):
        pos, ok = resample(tm, Ppos[:, j], t_m)
        vel, okv = resample(tm, V[:, j], t_m)
        if moving:
            ps, oks = resample(tm, Ps[:, j], t_m)
            vs, _ = resample(tm, Vs[:, j], t_m)
            ok = ok & oks
        else:
            ps = field_to_sensor(pos, reg.x_m, reg.y_m, reg.yaw_rad)
            cy, sy = np.cos(reg.yaw_rad), np.sin(reg.yaw_rad)
            vs = np.column_stack([cy * vel[:, 0] + sy * vel[:, 1],
                                  -sy * vel[:, 0] + cy * vel[:, 1]])
        rows.append(pd.DataFrame({
            "scan": np.arange(sensor.n_scans, dtype=np.int64),
            "t_sensor_s": sensor.t, "t_mocap_s": t_m, "side": side,
            C.X: pos[:, 0], C.Y: pos[:, 1], "xs_m": ps[:, 0], "ys_m": ps[:, 1],
            C.VX: vel[:, 0], C.VY: vel[:, 1], "vxs_mps": vs[:, 0], "vys_mps": vs[:, 1],
            "valid": ok & np.all(np.isfinite(ps), axis=1),
        }))
    df = pd.concat(rows, ignore_index=True)
    df = df.sort_values(["scan", "side"], kind="stable").reset_index(drop=True)
    return df[GT_COLUMNS]


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
    tid = (trial or {}).get("trial")
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
        "sample": np.arange(len(log.t), dtype=np.int64), "t_sensor_s": log.t,
        "t_mocap_s": t_m, "side": side, C.X: pos[:, 0], C.Y: pos[:, 1], C.Z: pos[:, 2],
        "xs_m": ps[:, 0], "ys_m": ps[:, 1], "zs_m": ps[:, 2], C.VX: vel[:, 0],
        C.VY: vel[:, 1], "vz_mps": vel[:, 2], "valid": ok & np.all(np.isfinite(pos), axis=1),
    })
