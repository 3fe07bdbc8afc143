"""Which axis of a C3D file points up, read from the markers themselves.

Part of :mod:`gaitval.io.c3d`.  gaitval's field frame has z up and the floor at z = 0
(``docs/formats_recordings.md``), but some labs export y up (OpenSim, some Motion Analysis set-ups);
read as z-up, such a walk leaves every leg point below the sensor's plane and ground truth
finds no valid frame, silently.  C3D has no reliable field for it (``POINT:X_SCREEN`` /
``Y_SCREEN`` describe the display, and are often left at their defaults), so
:func:`detect_vertical` looks at the data:

* a walking body is tall and thin: at any instant its markers spread over ~1 m along the
  vertical (toes to pelvis) and a few decimetres across it (median over frames of the
  spread across markers, ``A``);
* gravity keeps every marker near its own height: along the vertical a marker moves a few
  centimetres (toe clearance, pelvis bob), along the walking direction metres
  (median over markers of each marker's range over time, ``B``) — the floor-level
  markers, in stance, do not move along it at all.

The vertical is the axis with the largest ``A / (B + 5 cm)`` (``A`` between the 10th and
90th percentile of the markers, robust to a few stray ones), when it beats the runner-up
by half again and spans at least 0.5 m; up is where the markers are (the floor is at 0).
Only markers that move are used (poles and receivers standing in the field would look
like a wide body), and at least six of them: a static trial, or a file with a handful of
markers, is left as stored and reported as undetermined.
"""
from __future__ import annotations

import numpy as np

AXES = "xyz"


def detect_vertical(xyz: np.ndarray) -> tuple[str | None, float]:
    """The up axis (``"+z"``, ``"-y"`` ...) of marker data, or None; and the score ratio.

    Parameters
    ----------
    xyz : ndarray, shape (n_frames, n_markers, 3)
        Metres, NaN for gaps.
    """
    n_f, n_m, _ = xyz.shape
    if n_f < 10 or n_m < 6:
        return None, 0.0
    step = max(1, n_f // 400)
    x = xyz[::step]
    seen = np.isfinite(x[:, :, 0])
    ok = seen.mean(axis=0) >= 0.2
    with _quiet():
        lo, hi = nanpercentile(x, 5, axis=0), nanpercentile(x, 95, axis=0)
        travel = hi - lo                                      # (n_markers, 3)
        reach = np.where(ok, np.nanmax(np.nan_to_num(travel, nan=0.0), axis=1), 0.0)
    moving = reach > 0.05
    if moving.sum() < 6:
        return None, 0.0
    # markers that travel with the body; model outputs stored as points (joint angles in
    # degrees read as millimetres, moments) stay near the origin and are left out
    moving &= reach >= 0.5 * np.median(reach[moving])
    body = x[:, moving]
    frames = np.isfinite(body[:, :, 0]).sum(axis=1) >= 6
    if moving.sum() < 6 or frames.sum() < 5:
        return None, 0.0
    with _quiet():
        b = body[frames]
        spread = np.nanmedian(nanpercentile(b, 90, axis=1) - nanpercentile(b, 10, axis=1),
                              axis=0)                         # A, per axis
        move = np.nanmedian(travel[moving], axis=0)           # B, per axis
    score = spread / (move + 0.05)
    order = np.argsort(score)[::-1]
    a, runner_up = int(order[0]), float(score[order[1]])
    ratio = float(score[a] / runner_up) if runner_up > 0 else float("inf")
    if ratio < 1.5 or spread[a] < 0.5:
        return None, ratio
    with _quiet():
        level = float(np.nanmedian(np.nanmedian(body[:, :, a], axis=0)))
    if abs(level) < 0.1:
        return None, ratio
    return ("+" if level > 0 else "-") + AXES[a], ratio


def nanpercentile(a: np.ndarray, q: float, axis: int) -> np.ndarray:
    """``np.nanpercentile(a, q, axis=axis)`` (linear method): the same values (a zero may
    come out as -0.0 where numpy gives 0.0) without numpy's 1-D call per slice when there
    are NaNs (2,800 slices of a C3D file: 0.5 s).  The slices are sorted once (NaN last) and
    those with the same number of finite values go through one vectorised ``np.percentile``
    — the same order statistics and interpolation per slice.  All-NaN slices give NaN."""
    moved = np.moveaxis(np.asarray(a, float), axis, 0)
    flat = np.sort(moved.reshape(moved.shape[0], -1), axis=0)
    count = np.isfinite(flat).sum(axis=0)
    out = np.full(flat.shape[1], np.nan)
    for n in np.unique(count[count > 0]):
        cols = np.flatnonzero(count == n)
        out[cols] = np.percentile(flat[:n, cols], q, axis=0)
    return out.reshape(moved.shape[1:])


def to_z_up(xyz: np.ndarray, up: str) -> np.ndarray:
    """Rotate marker data whose up axis is ``up`` so that up becomes +z (a proper rotation:
    +y up -> (x, -z, y); +x up -> (-z, y, x); a minus sign turns about the first axis)."""
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    rot = {"+z": (x, y, z), "-z": (x, -y, -z), "+y": (x, -z, y), "-y": (x, z, -y),
           "+x": (-z, y, x), "-x": (z, y, -x)}[up]
    return np.stack(rot, axis=-1)


class _quiet(np.errstate):
    """Silence all-NaN slice warnings of nan-aware reductions."""

    def __init__(self):
        super().__init__(invalid="ignore", divide="ignore")

    def __enter__(self):
        import warnings
        self._w = warnings.catch_warnings()
        self._w.__enter__()
        warnings.simplefilter("ignore", RuntimeWarning)
        return super().__enter__()

    def __exit__(self, *exc):
        self._w.__exit__(*exc)
        return super().__exit__(*exc)
