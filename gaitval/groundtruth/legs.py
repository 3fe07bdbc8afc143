"""Leg points at sensor height from markers: the one place they are computed.

Steps 1-3 of the ground truth (:mod:`gaitval.groundtruth.build` has the whole pipeline):

1. Every marker used is gap-filled (:func:`~gaitval.groundtruth.gaps.fill_short_gaps`,
   gaps up to ``max_gap_s``).
2. Knee and ankle centres (:mod:`~gaitval.groundtruth.joints`), then the leg point at the
   scan height ``h`` (:func:`~gaitval.groundtruth.shank.point_at_height`), or, for the
   rollator (or ``leg_point: cylinder``), the tibia-cylinder cross-section
   (:func:`~gaitval.groundtruth.shank.fit_cylinder_cluster`: one cylinder in the tibia
   cluster's frame, axis direction from knee - ankle, carried per frame by the cluster's
   rigid motion).
3. Mocap frames where either leg point is missing are counted (``gt_frames_excluded``).

:func:`sensor_leg_points` does this once per LRS trial at the sensor's height; the result
(:class:`LegPoints`) is handed to the registration (motion evidence for the poles, leg
occupancy for the clock; :class:`gaitval.registration.legmotion.LegMotion`) and then to
:func:`gaitval.groundtruth.build.ground_truth`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gaitval import consts as C
from gaitval.config import as_float
from gaitval.errors import MarkerError, RegistrationError
from gaitval.groundtruth.gaps import fill_short_gaps
from gaitval.groundtruth.joints import MARKER_DIAMETER_M, joint_centre, source_label
from gaitval.groundtruth.settings import gt_cfg
from gaitval.groundtruth.shank import cylinder_at_height, fit_cylinder_cluster, point_at_height
from gaitval.registration.moving import is_moving, rollator_labels
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

#: Marker names (after the side letter) the leg points may use, besides the tibia cluster.
LEG_MARKERS = ("FEO", "TIO", "KJC", "AJC", "KNE", "KNEin", "ANK", "ANKin", "ASI", "HEE",
               "TOE")


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
    markers : dict  the gap-filled marker arrays (label -> (n, 3)); from
        :func:`sensor_leg_points` of a moving sensor also the rollator markers
    """

    t: np.ndarray
    xyz: np.ndarray
    valid: np.ndarray
    source: str
    n_excluded: int
    n_filled: int
    markers: dict


def sensor_height(sensor, trial: dict) -> float:
    """Scan-plane height: the trial sheet's ``sensor_height_m``, else the log metadata.

    Raises
    ------
    RegistrationError
        When neither gives a number (the log and trial named).
    """
    h = as_float((trial or {}).get(C.SENSOR_HEIGHT))
    if h is None:
        h = as_float(getattr(sensor, "mounting_height_m", None))
    if h is None:
        raise RegistrationError(
            "the sensor height is unknown (empty sensor_height_m in the trial sheet and "
            "no mounting_height_m in the log)", path=getattr(sensor, "source", None),
            trial=(trial or {}).get(C.TRIAL), hint="fill sensor_height_m in trials.csv")
    return h


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


def _use_cylinder(mocap: MocapTrial, c: dict) -> bool:
    """``leg_point``: ``cylinder``, ``axis``, or ``auto`` (cylinder when every tibia marker
    of both legs is in the C3D)."""
    if c["leg_point"] == "cylinder":
        return True
    if c["leg_point"] == "axis":
        return False
    return all(mocap.has(lb) for s in C.SIDES for lb in _tibia_labels(s, c))


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
        ``groundtruth:`` config (see :data:`gaitval.groundtruth.settings.DEFAULTS`).
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
    for s in C.SIDES:
        want |= {s + x for x in LEG_MARKERS}
        want |= set(_tibia_labels(s, c))
    markers, _ = filled_markers(mocap, c["max_gap_s"], [lb for lb in mocap.labels if lb in want])
    if cylinder is None:
        cylinder = _use_cylinder(mocap, c)
    n = mocap.n_frames
    xyz = np.full((n, 2, 3), np.nan)
    valid = np.zeros((n, 2), dtype=bool)
    sources = {}
    for j, s in enumerate(C.SIDES):
        r = 0.5 * MARKER_DIAMETER_M
        knee, sources[(s, "knee")] = joint_centre(mocap, s, "knee", subject, markers=markers,
                                                  trial=trial, marker_radius_m=r)
        ankle, sources[(s, "ankle")] = joint_centre(mocap, s, "ankle", subject,
                                                    markers=markers, trial=trial,
                                                    marker_radius_m=r)
        if cylinder:
            xyz[:, j], valid[:, j] = _cylinder_point(mocap, markers, s, knee, ankle, h, c,
                                                     trial)
        else:
            xyz[:, j], valid[:, j] = point_at_height(knee, ankle, h)
    src = "tibia_cylinder" if cylinder else source_label(sources)
    filled_any = np.zeros(n, dtype=bool)
    for lb, arr in markers.items():
        filled_any |= np.isfinite(arr).all(axis=1) & ~np.isfinite(mocap.marker(lb)).all(axis=1)
    n_excl = int((~valid.all(axis=1)).sum())
    return LegPoints(mocap.t, xyz, valid, src, n_excl, int(filled_any.sum()), markers)


def _cylinder_point(mocap, markers, side, knee, ankle, h, c, trial):
    """Tibia-cylinder cross-section at height ``h`` of one side (seed 002)."""
    tl = _tibia_labels(side, c)
    miss = [lb for lb in tl if lb not in markers]
    if miss:
        raise MarkerError(f"tibia-cylinder ground truth needs {tl}; missing {miss}",
                          path=mocap.path, trial=trial,
                          hint="set groundtruth.leg_point: axis to use the "
                               "knee-ankle axis instead")
    M = np.stack([markers[lb] for lb in tl], axis=1)
    cen, d, _ = fit_cylinder_cluster(M, knee - ankle, c["cylinder_marker_offset_m"])
    return cylinder_at_height(cen, d, h)


def sensor_leg_points(mocap: MocapTrial, sensor, trial: dict, subject: dict | None,
                      cfg: dict | None) -> LegPoints | None:
    """The leg points of one LRS trial at the sensor's height, computed once for both the
    registration and the ground truth.

    Parameters
    ----------
    mocap : MocapTrial
    sensor : ScanSeries or UltrasonicLog
    trial : dict
        Trial-sheet row (``trial``, ``protocol``, ``sensor_height_m``).
    subject : dict or None
        Subject-table row.
    cfg : dict or None
        Whole config (``groundtruth``; ``registration.rollator_markers`` for the rollator).

    Returns
    -------
    LegPoints or None
        :func:`leg_points` at :func:`sensor_height`; for a moving sensor (protocol
        ``rollator``) ``markers`` also holds the gap-filled rollator markers, from which
        registration computes the sensor's per-frame pose.  For an ultrasonic log the
        points the sensor ranges instead: :func:`transmitter_points`.

    Raises
    ------
    RegistrationError
        Sensor height unknown (with the log, or else the C3D, named).
    MarkerError
        Markers missing for the joint centres or the tibia cylinder.
    """
    tid = str((trial or {}).get(C.TRIAL, ""))
    if isinstance(sensor, UltrasonicLog):
        return transmitter_points(mocap, cfg, trial=tid)
    if not isinstance(sensor, ScanSeries):
        return None
    try:
        h = sensor_height(sensor, trial)
    except RegistrationError as e:
        raise e.with_context(path=getattr(sensor, "source", None) or mocap.path, trial=tid)
    lp = leg_points(mocap, h, subject, cfg, trial=tid)
    if is_moving(trial):
        rollator, _ = filled_markers(mocap, gt_cfg(cfg)["max_gap_s"], rollator_labels(cfg))
        lp = replace(lp, markers={**lp.markers, **rollator})
    return lp


def transmitter_points(mocap: MocapTrial, cfg: dict | None, trial: str = "") -> LegPoints:
    """The heel transmitter marker (``groundtruth.tx_marker``) gap-filled like the leg
    points (``groundtruth.max_gap_s``), as the one "point" an ultrasonic system ranges:
    ``xyz`` has shape (n_frames, 1, 3), ``source`` is ``"tx_marker"``.

    Raises
    ------
    MarkerError
        The C3D has no transmitter marker.
    """
    g = gt_cfg(cfg)
    tx = g["tx_marker"]
    if not mocap.has(tx):
        raise MarkerError(f"the C3D has no transmitter marker {tx!r}", path=mocap.path,
                          trial=trial, hint="set groundtruth.tx_marker")
    X, _ = fill_short_gaps(mocap.marker(tx), mocap.rate_hz, g["max_gap_s"])
    ok = np.isfinite(X).all(axis=1)
    return LegPoints(t=np.asarray(mocap.t, dtype=float), xyz=X[:, None, :], valid=ok[:, None],
                     source="tx_marker", n_excluded=int((~ok).sum()), n_filled=0,
                     markers={tx: X})
