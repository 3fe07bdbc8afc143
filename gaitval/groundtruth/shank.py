"""The leg point at sensor height: on the knee-ankle axis, or on a fitted tibia cylinder.

* Seed 000 §4: "the leg trajectory was calculated as the trajectory at the LRS height".
  gaitval takes the point of the ankle-to-knee joint-centre line where ``z = h``::

      s = (h - A_z) / (K_z - A_z),   P = A + s (K - A)

  valid when the shank is not near-horizontal (``K_z - A_z >= 0.1 m``) and ``s`` lies in
  ``[-0.1, 1.1]`` (the scan plane cuts the shank, allowing 10 % extrapolation).
* Seed 002 §IV: "cylinder fitting on the tibia markers for representing the user's tibia at
  each time frame".  gaitval fits, per frame, a circle to the tibia markers
  (``LTB1..LTB4``) projected on the plane perpendicular to the shank axis (direction from
  the ankle to the knee joint centre; the cluster's principal axis when no joint centres are
  available), by the algebraic (Kasa) least-squares fit; the circle centre on that plane
  and the axis direction define the cylinder axis, its radius minus the marker offset
  (marker centre 9 mm outside the skin) is the skin radius.  The cross-section at sensor
  height is the axis point with ``z = h``.  Four markers around the shank determine the
  circle; markers all on one side of the shank make it ill-conditioned (then the radius
  comes out implausible and the frame is invalid: skin radius outside 0.02..0.12 m).

References
----------
Kasa, I. (1976). A circle fitting procedure and its error analysis. IEEE Trans. Instrum.
Meas. 25(1), 8-14.
"""
from __future__ import annotations

import numpy as np


def point_at_height(knee: np.ndarray, ankle: np.ndarray, h: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Point of the ankle->knee line at height ``h`` (see module docstring).

    Parameters
    ----------
    knee, ankle : ndarray (n, 3), metres, field frame (NaN in gaps)
    h : float, sensor (scan-plane) height above the floor, metres

    Returns
    -------
    p : ndarray (n, 3) with ``p[:, 2] == h`` where valid, NaN elsewhere
    valid : ndarray (n,) bool
    """
    dz = knee[:, 2] - ankle[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (h - ankle[:, 2]) / dz
        valid = np.isfinite(s) & (dz >= 0.1) & (s >= -0.1) & (s <= 1.1)
    p = ankle + s[:, None] * (knee - ankle)
    p[~valid] = np.nan
    return p, valid


def _basis(d):
    """Two unit vectors perpendicular to unit vectors d (n, 3)."""
    ref = np.where(np.abs(d[:, [0]]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    e1 = np.cross(d, ref)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(d, e1)
    return e1, e2


def fit_cylinder(markers: np.ndarray, axis_dir: np.ndarray | None = None,
                 marker_offset_m: float = 0.009) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-frame cylinder through tibia markers (see module docstring).

    Parameters
    ----------
    markers : ndarray (n, k, 3), k >= 3, metres (NaN rows: frame unusable)
    axis_dir : ndarray (n, 3), optional
        Axis direction per frame (e.g. knee - ankle); default the principal axis of the
        marker cluster, oriented upwards.
    marker_offset_m : float
        Marker centre distance outside the skin (9 mm).

    Returns
    -------
    centre : ndarray (n, 3), a point on the axis (metres)
    direction : ndarray (n, 3), unit axis direction (z >= 0)
    skin_radius : ndarray (n,), metres
    """
    M = np.asarray(markers, dtype=float)
    n, k, _ = M.shape
    ok = np.all(np.isfinite(M), axis=(1, 2))
    m0 = np.nanmean(M, axis=1)
    if axis_dir is None:
        X = M - m0[:, None]
        X = np.where(ok[:, None, None], X, 0.0)
        _, _, Vt = np.linalg.svd(X)
        d = Vt[:, 0]
    else:
        d = np.asarray(axis_dir, dtype=float).copy()
    d = np.where(np.isfinite(d), d, np.array([0.0, 0.0, 1.0]))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d[d[:, 2] < 0] *= -1
    e1, e2 = _basis(d)
    X = M - m0[:, None]
    u = np.einsum("nkd,nd->nk", X, e1)
    v = np.einsum("nkd,nd->nk", X, e2)
    # Kasa: u^2 + v^2 = 2 a u + 2 b v + c   (least squares per frame)
    A = np.stack([2 * u, 2 * v, np.ones_like(u)], axis=-1)            # (n, k, 3)
    y = u * u + v * v
    AtA = np.einsum("nki,nkj->nij", A, A)
    Aty = np.einsum("nki,nk->ni", A, y)
    AtA[~ok] = np.eye(3)
    Aty[~ok] = 0.0
    sol = np.linalg.solve(AtA, Aty[..., None])[..., 0]
    a, b, c = sol[:, 0], sol[:, 1], sol[:, 2]
    with np.errstate(invalid="ignore"):
        R = np.sqrt(c + a * a + b * b)
    centre = m0 + a[:, None] * e1 + b[:, None] * e2
    skin = R - marker_offset_m
    bad = ~ok | ~np.isfinite(skin) | (skin < 0.02) | (skin > 0.12)
    centre[bad] = np.nan
    skin[bad] = np.nan
    return centre, d, skin


def cylinder_at_height(centre: np.ndarray, direction: np.ndarray, h: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Axis point of the cylinder at height ``h``: ``C + ((h - C_z) / d_z) d``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (h - centre[:, 2]) / direction[:, 2]
        valid = np.isfinite(s) & (direction[:, 2] > 0.5)
    p = centre + s[:, None] * direction
    p[~valid] = np.nan
    return p, valid


def fit_cylinder_cluster(markers: np.ndarray, axis_dir: np.ndarray | None = None,
                         marker_offset_m: float = 0.009
                         ) -> tuple[np.ndarray, np.ndarray, float]:
    """Tibia cylinder fitted once in the marker cluster's own frame, moved per frame.

    The tibia markers form a (near) rigid cluster, so the cylinder is fixed in the
    cluster's frame: the mean cluster shape (after per-frame Kabsch alignment) gets one
    circle fit (:func:`fit_cylinder` on the mean shape) with the axis direction averaged
    over the frames where ``axis_dir`` (knee - ankle) is known, expressed in the cluster
    frame; every frame with all markers present then carries that axis by its rigid
    transform.  This averages marker noise over the whole trial and keeps the axis through
    gaps of the knee/ankle markers.

    Returns
    -------
    centre : ndarray (n, 3), point on the axis (NaN where a tibia marker is missing)
    direction : ndarray (n, 3), unit axis direction
    skin_radius : float, metres
    """
    from gaitval.registration.rigid import batch_kabsch_3d

    M = np.asarray(markers, dtype=float)
    n = len(M)
    ok = np.all(np.isfinite(M), axis=(1, 2))
    centre = np.full((n, 3), np.nan)
    direction = np.full((n, 3), np.nan)
    if ok.sum() < 1:
        return centre, direction, float("nan")
    V = M[ok]
    ref = V[0] - V[0].mean(axis=0)
    for _ in range(2):
        R, t = batch_kabsch_3d(ref, V)
        local = np.einsum("nji,nkj->nki", R, V - t[:, None, :])       # R^T (p - t)
        ref = local.mean(axis=0)
    R, t = batch_kabsch_3d(ref, V)
    d_loc = None
    if axis_dir is not None:
        A = np.asarray(axis_dir, dtype=float)[ok]
        good = np.all(np.isfinite(A), axis=1)
        if good.any():
            a = A[good] / np.linalg.norm(A[good], axis=1, keepdims=True)
            dl = np.einsum("nji,nj->ni", R[good], a).mean(axis=0)
            d_loc = dl / np.linalg.norm(dl)
    if d_loc is None:                      # principal axis of the cluster shape
        _, _, Vt = np.linalg.svd(ref - ref.mean(axis=0))
        d_loc = Vt[0]
    c_loc, d_fit, skin = fit_cylinder(ref[None], d_loc[None], marker_offset_m)
    centre[ok] = np.einsum("nij,j->ni", R, c_loc[0]) + t
    d_f = np.einsum("nij,j->ni", R, d_loc)
    d_f[d_f[:, 2] < 0] *= -1
    direction[ok] = d_f
    return centre, direction, float(skin[0])
