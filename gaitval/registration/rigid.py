"""Rigid transforms between the sensor frame and the field (mocap) frame.

Conventions (common to all of gaitval)
--------------------------------------
* Field frame: the mocap frame, z up, floor z = 0; 2-D work happens in the x-y plane.
* Sensor pose ``(x_m, y_m, yaw_rad)``: the position of the sensor origin in the field and
  the heading of its beam-angle-0 axis, counter-clockwise from field +x.  A point ``p_s``
  in the sensor frame maps to the field as ``p_f = R(yaw) @ p_s + [x_m, y_m]``.

All functions take and return metres and radians.
"""
from __future__ import annotations

import numpy as np


def rot2(yaw: float | np.ndarray) -> np.ndarray:
    """2-D rotation matrix ``R(yaw)`` (shape (2, 2), or (n, 2, 2) for an array of angles)."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def wrap_angle(a):
    """Wrap angles (radians) to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def sensor_to_field(p_s: np.ndarray, x_m, y_m, yaw_rad) -> np.ndarray:
    """Map sensor-frame points to the field: ``p_f = R(yaw) p_s + t``.

    Parameters
    ----------
    p_s : ndarray, shape (..., 2)
        Points in the sensor frame (metres).
    x_m, y_m, yaw_rad : float or ndarray broadcastable to ``p_s[..., 0]``
        Sensor pose in the field (per point/frame for a moving sensor).

    Returns
    -------
    ndarray, shape (..., 2)
        Points in the field frame (metres).
    """
    p_s = np.asarray(p_s, dtype=float)
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    x = c * p_s[..., 0] - s * p_s[..., 1] + x_m
    y = s * p_s[..., 0] + c * p_s[..., 1] + y_m
    return np.stack([x, y], axis=-1)


def field_to_sensor(p_f: np.ndarray, x_m, y_m, yaw_rad) -> np.ndarray:
    """Map field points into the sensor frame: ``p_s = R(yaw)^T (p_f - t)``.

    Same shapes and units as :func:`sensor_to_field` (its exact inverse).
    """
    p_f = np.asarray(p_f, dtype=float)
    dx = p_f[..., 0] - x_m
    dy = p_f[..., 1] - y_m
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)


def fit_rigid_2d(src: np.ndarray, dst: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    """Least-squares 2-D rigid transform (rotation + translation, no scale) ``src -> dst``.

    Finds ``R(yaw), t`` minimising ``sum_i |R src_i + t - dst_i|^2`` (Kabsch / Umeyama
    without scale, in 2-D), i.e. the sensor pose when ``src`` are pole centres in the
    sensor frame and ``dst`` the same poles in the field.

    Parameters
    ----------
    src, dst : ndarray, shape (n, 2), n >= 2
        Corresponding points (metres).

    Returns
    -------
    x_m, y_m, yaw_rad : float
        The pose: ``dst ~= R(yaw) @ src + [x_m, y_m]``.
    residuals : ndarray, shape (n,)
        ``|R src_i + t - dst_i|`` per point (metres).

    Notes
    -----
    With centred points ``a_i = src_i - mean(src)``, ``b_i = dst_i - mean(dst)``, the
    optimal angle is ``yaw = atan2(sum(a x b), sum(a . b))`` (the 2-D closed form of
    Kabsch's SVD solution; a reflection can never be returned), and
    ``t = mean(dst) - R mean(src)``.

    References
    ----------
    Umeyama, S. (1991). Least-squares estimation of transformation parameters between two
    point patterns. IEEE Trans. Pattern Anal. Mach. Intell. 13(4), 376-380.
    """
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] != 2 or src.shape[0] < 2:
        raise ValueError("fit_rigid_2d needs two (n>=2, 2) arrays of corresponding points")
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    cross = np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    dot = np.sum(a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1])
    yaw = float(np.arctan2(cross, dot))
    t = md - rot2(yaw) @ ms
    res = np.linalg.norm(sensor_to_field(src, t[0], t[1], yaw) - dst, axis=1)
    return float(t[0]), float(t[1]), yaw, res


def fit_rigid_3d(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares 3-D rigid transform ``dst ~= R @ src + t`` (Kabsch, no scale).

    Parameters
    ----------
    src, dst : ndarray, shape (n, 3), n >= 3, not collinear

    Returns
    -------
    R : ndarray (3, 3), a proper rotation (det +1)
    t : ndarray (3,)
    residuals : ndarray (n,), metres

    References
    ----------
    Kabsch, W. (1976). A solution for the best rotation to relate two sets of vectors.
    Acta Cryst. A32, 922-923.
    """
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    H = (src - ms).T @ (dst - md)
    U, _, Vt = np.linalg.svd(H)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    t = md - R @ ms
    res = np.linalg.norm(src @ R.T + t - dst, axis=1)
    return R, t, res


def batch_kabsch_3d(ref: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame rigid transforms mapping a reference cluster onto observed clusters.

    Parameters
    ----------
    ref : ndarray (k, 3)
        Reference marker cluster (e.g. the mean shape in a local frame).
    pts : ndarray (n, k, 3)
        Observed clusters per frame (no NaN; mask frames beforehand).

    Returns
    -------
    R : ndarray (n, 3, 3) and t : ndarray (n, 3) with ``pts[i] ~= ref @ R[i].T + t[i]``.
    """
    mr = ref.mean(axis=0)
    mp = pts.mean(axis=1)
    H = np.einsum("kd,nke->nde", ref - mr, pts - mp[:, None, :])
    U, _, Vt = np.linalg.svd(H)
    V = np.swapaxes(Vt, 1, 2)
    det = np.linalg.det(V @ np.swapaxes(U, 1, 2))
    D = np.zeros((len(pts), 3, 3))
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = 1.0
    D[:, 2, 2] = np.sign(det)
    R = V @ D @ np.swapaxes(U, 1, 2)
    t = mp - np.einsum("nij,j->ni", R, mr)
    return R, t
