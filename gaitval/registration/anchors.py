"""The ultrasonic system's frame in the field: a rigid fit of the receiver markers.

The receivers (anchors) of an ultrasonic system carry camera markers (``ANC1..ANC4``).
Their positions in the ultrasonic frame are in the log (``UltrasonicLog.anchors``); their
positions in the mocap field are the markers.  :func:`fit_anchor_frame` finds the rigid
transform ``p_field = R p_us + t`` between the two (Kabsch / SVD, no scaling) — the one
anchor registration of gaitval, used by the registration step
(:func:`gaitval.registration.trial.register_anchors`, for the pose and clock of an
ultrasonic trial) and by the camera reference of seed 003
(:func:`gaitval.groundtruth.reference.reference_trajectory`).

Anchors are matched to markers by name when every anchor id of the log is a marker label
of the C3D, else in order (anchor ``k`` <-> ``markers[k]``).  A marker's position is one
point per anchor taken over the whole capture (the receivers do not move):

* ``centre="median"`` (default): the median of the frames where the marker is seen;
* ``centre="mean"``: the mean of each coordinate over the frames where it is seen
  (``numpy.nanmean``), which is what seed 003's reference (Tables 1–8) uses.

References
----------
Kabsch, W. (1976). A solution for the best rotation to relate two sets of vectors.
Acta Cryst. A32, 922-923.
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gaitval.errors import RegistrationError
from gaitval.io.ultrasonic import anchor_positions
from gaitval.registration.rigid import fit_rigid_3d
from gaitval.types import MocapTrial

#: Receiver marker labels when the configuration names none.
DEFAULT_MARKERS = ("ANC1", "ANC2", "ANC3", "ANC4")


@dataclass
class AnchorFit:
    """What :func:`fit_anchor_frame` returns.

    Attributes
    ----------
    R : ndarray (3, 3)
        Rotation ultrasonic frame -> field (a proper rotation).
    t : ndarray (3,)
        Origin of the ultrasonic frame in the field (metres): ``p_field = R p_us + t``.
    residuals_m : ndarray (k,)
        Distance of each fitted anchor from its marker after the fit (metres).
    markers : list of str
        The marker fitted to each residual, in order.
    """

    R: np.ndarray
    t: np.ndarray
    residuals_m: np.ndarray
    markers: list[str]

    @property
    def rms_m(self) -> float:
        """RMS residual of the fit (metres)."""
        return float(np.sqrt(np.mean(self.residuals_m ** 2)))

    def to_ultrasonic(self, p_field: np.ndarray) -> np.ndarray:
        """Field points ``(..., 3)`` in the ultrasonic frame: ``p_us = R^T (p_field - t)``."""
        return (p_field - self.t) @ self.R


def anchor_marker_labels(mocap: MocapTrial, anchor_ids: list[str], markers) -> list[str]:
    """The marker label of each anchor: its own id when every id is a marker of the C3D,
    else ``markers`` in order."""
    ids = [str(a) for a in anchor_ids]
    return ids if all(mocap.has(a) for a in ids) else list(markers)[:len(ids)]


def _marker_centre(p: np.ndarray, centre: str) -> np.ndarray | None:
    """One position of a static marker ``(n, 3)``, or None when it is never seen."""
    if centre == "mean":
        with np.errstate(invalid="ignore"):
            c = np.nanmean(p, axis=0)
        return c if np.all(np.isfinite(c)) else None
    ok = np.isfinite(p).all(axis=1)
    return np.median(p[ok], axis=0) if ok.any() else None


def fit_anchor_frame(mocap: MocapTrial, anchors: pd.DataFrame, markers=DEFAULT_MARKERS, *,
                     centre: str = "median", max_residual_m: float = 0.02,
                     trial: str | None = None) -> AnchorFit:
    """Rigid transform ultrasonic frame -> mocap field from the receiver markers.

    Parameters
    ----------
    mocap : MocapTrial
        The trial's C3D (metres, field frame) with the receiver markers.
    anchors : DataFrame
        ``anchor, x_m, y_m, z_m``: the log's anchor table (ultrasonic frame, metres).
    markers : sequence of str
        Receiver marker labels in anchor order (used unless the anchor ids are marker
        labels themselves; module notes).
    centre : {"median", "mean"}
        How a marker's frames are reduced to one point (module notes).
    max_residual_m : float
        Largest anchor residual accepted (metres).
    trial : str, optional
        For error messages.

    Returns
    -------
    AnchorFit

    Raises
    ------
    RegistrationError
        Fewer than three anchors with a usable marker, or a residual above
        ``max_residual_m`` (the file and trial named).
    """
    if centre not in ("median", "mean"):
        raise ValueError(f"centre must be 'median' or 'mean', not {centre!r}")
    A = anchor_positions(anchors)
    labels = anchor_marker_labels(mocap, list(anchors["anchor"]), markers)
    src, dst, used = [], [], []
    for k, lb in enumerate(labels):
        if k < len(A) and mocap.has(lb):
            p = _marker_centre(mocap.marker(lb), centre)
            if p is not None:
                src.append(A[k])
                dst.append(p)
                used.append(lb)
    if len(src) < 3:
        raise RegistrationError(
            f"the C3D has {len(src)} usable anchor marker(s) (looked for {labels}); three "
            "are needed to register the ultrasonic frame", path=mocap.path, trial=trial,
            hint="label the receiver markers ANC1..ANC4 (or set anchor_markers)")
    R, t, res = fit_rigid_3d(np.array(src), np.array(dst))         # Kabsch, no scaling
    if res.max() > float(max_residual_m):
        raise RegistrationError(
            f"anchor residual {res.max() * 1000:.1f} mm at {used[int(np.argmax(res))]} "
            f"exceeds {max_residual_m * 1000:.0f} mm: the receiver markers do not match the "
            "log's anchor geometry", path=mocap.path, trial=trial,
            hint="check the anchor coordinates in the log metadata and the marker order")
    return AnchorFit(R=R, t=t, residuals_m=res, markers=used)
