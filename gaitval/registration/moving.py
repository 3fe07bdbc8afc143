"""Moving sensor (robotic rollator, seed 002): per-frame sensor pose from rollator markers.

Rollator frame (common brief): origin = centroid of ``RLT_FL RLT_FR RLT_RL RLT_RR`` in
x-y; +x from the midpoint of the rear pair to the midpoint of the front pair; +y left.
The sensor mount ``{x_m, y_m, yaw_rad}`` is the sensor pose in that frame (a study
calibration, config ``rollator.sensor_mount``).  The sensor pose in the field is the
composition::

    p_sensor_f = p_rollator_f + R(yaw_r) @ [mount.x_m, mount.y_m]
    yaw_sensor  = yaw_r + mount.yaw_rad

so field points map into the laser frame per frame ("Using the rollator markers' data, we
have applied a Euclidean transformation on the data to project them to the LRF's reference
frame", seed 002 §IV).

References
----------
Chalvatzaki, G., Papageorgiou, X. S., Tzafestas, C. S., Maragos, P. (2017). Comparative
experimental validation of human gait tracking algorithms for an intelligent robotic
rollator. IEEE ICRA 2017, 6026-6031.
"""
from __future__ import annotations

import numpy as np

from gaitval.config import section
from gaitval.errors import ConfigError, RegistrationError
from gaitval.registration.rigid import wrap_angle
from gaitval.types import MocapTrial

#: Default of ``registration.rollator_markers``: front-left, front-right, rear-left, rear-right.
ROLLATOR_MARKERS = ("RLT_FL", "RLT_FR", "RLT_RL", "RLT_RR")


def is_moving(trial: dict | None) -> bool:
    """True for trials whose sensor moves (protocol ``rollator``)."""
    return str((trial or {}).get("protocol", "")).strip().lower() == "rollator"


def rollator_labels(cfg: dict | None) -> list[str]:
    """``registration.rollator_markers`` (default :data:`ROLLATOR_MARKERS`) as a list."""
    return list(section(cfg, "registration").get("rollator_markers", list(ROLLATOR_MARKERS)))


def mount_from_cfg(cfg: dict | None, trial_id=None) -> tuple[float, float, float]:
    """``rollator.sensor_mount`` (or ``registration.sensor_mount``) as (x, y, yaw).

    Raises
    ------
    ConfigError
        When neither is set (the moving-sensor trial ``trial_id`` is named).
    """
    cfg = cfg or {}
    m = None
    if isinstance(cfg.get("rollator"), dict):
        m = cfg["rollator"].get("sensor_mount")
    if m is None:
        m = section(cfg, "registration").get("sensor_mount")
    if m is None:
        raise ConfigError("rollator.sensor_mount is not set: the sensor pose on the rollator "
                          "(x_m, y_m, yaw_rad in the rollator frame) is needed for the "
                          f"moving-sensor trial {trial_id}",
                          hint="set rollator.sensor_mount in config/config.yaml")
    return parse_mount(m)


def parse_mount(mount) -> tuple[float, float, float]:
    """``{x_m, y_m, yaw_rad}`` (dict) -> tuple; ConfigError when incomplete."""
    try:
        return float(mount["x_m"]), float(mount["y_m"]), float(mount["yaw_rad"])
    except (KeyError, TypeError, ValueError):
        raise ConfigError(
            f"rollator.sensor_mount must be a mapping with x_m, y_m, yaw_rad (got {mount!r})",
            hint="set rollator.sensor_mount in config/config.yaml (the sensor pose in the "
                 "rollator frame, a study calibration)") from None


def rollator_pose(mocap: MocapTrial, labels=ROLLATOR_MARKERS, *, trial=None,
                  xyz: dict | None = None) -> np.ndarray:
    """Per-frame rollator pose in the field.

    Parameters
    ----------
    mocap : MocapTrial
    labels : 4 labels in the order front-left, front-right, rear-left, rear-right.
    xyz : dict, optional
        Already gap-filled marker arrays (label -> (n, 3)); default the raw markers.

    Returns
    -------
    ndarray (n_frames, 3): ``x_m, y_m, yaw_rad`` (NaN where a marker is missing).
    """
    missing = [lb for lb in labels if not mocap.has(lb)]
    if missing:
        raise RegistrationError(
            f"the C3D lacks rollator marker(s) {missing}; the moving sensor's pose "
            "cannot be computed", path=mocap.path, trial=trial,
            hint="label the rollator markers RLT_FL RLT_FR RLT_RL RLT_RR")
    P = [(xyz[lb] if xyz is not None and lb in xyz else mocap.marker(lb))[:, :2]
         for lb in labels]
    fl, fr, rl, rr = P
    origin = (fl + fr + rl + rr) / 4.0
    fwd = (fl + fr) / 2.0 - (rl + rr) / 2.0
    yaw = np.arctan2(fwd[:, 1], fwd[:, 0])
    return np.column_stack([origin, yaw])


def sensor_pose_from_rollator(rollator: np.ndarray, mount) -> np.ndarray:
    """Compose per-frame rollator poses (n, 3) with the mount -> sensor poses (n, 3)."""
    mx, my, myaw = parse_mount(mount) if isinstance(mount, dict) else mount
    c, s = np.cos(rollator[:, 2]), np.sin(rollator[:, 2])
    x = rollator[:, 0] + c * mx - s * my
    y = rollator[:, 1] + s * mx + c * my
    return np.column_stack([x, y, wrap_angle(rollator[:, 2] + myaw)])


def interp_pose(t_src: np.ndarray, pose: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Linear interpolation of poses (x, y, unwrapped yaw); NaN outside or across gaps."""
    out = np.full((len(t), 3), np.nan)
    ok = np.all(np.isfinite(pose), axis=1)
    if ok.sum() < 2:
        return out
    ts = t_src[ok]
    P = pose[ok].copy()
    P[:, 2] = np.unwrap(P[:, 2])
    for j in range(3):
        out[:, j] = np.interp(t, ts, P[:, j], left=np.nan, right=np.nan)
    # invalidate samples whose neighbouring mocap frames are missing
    idx = np.searchsorted(t_src, t)
    lo = np.clip(idx - 1, 0, len(t_src) - 1)
    hi = np.clip(idx, 0, len(t_src) - 1)
    bad = ~(ok[lo] & ok[hi])
    out[bad] = np.nan
    out[:, 2] = wrap_angle(out[:, 2])
    return out
