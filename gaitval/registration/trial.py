"""Register one trial: sensor pose in the field, clock offset/drift, ground-truth summary.

:func:`register_trial` is what the pipeline calls per trial; its result is one row of
``results/<study>/registration.csv`` (:data:`RECORD_FIELDS`).

* Fixed LRS (TUG, MTST, ...): pose from the calibration poles
  (:func:`~gaitval.registration.poles.register_poles`).  A pose measured by hand (trial
  sheet ``sensor_x_m``, ``sensor_y_m``, ``sensor_yaw_deg``, field frame) is checked against
  the poles where the C3D has them — the poles' pose is used and the difference recorded
  (``manual_pose_diff_m``, ``manual_pose_diff_deg``) — and used alone where it has none
  (``pose_source`` ``manual``, ``pole_residual_m`` NaN): a lab without calibration poles
  can still register its sensor.
* Moving LRS (protocol ``rollator``): per-frame pose from the rollator markers and the mount
  (:mod:`~gaitval.registration.moving`); the record's ``x_m, y_m, yaw_rad`` and
  ``pole_residual_m`` are NaN (the per-frame pose is recomputed by the ground truth).
* Ultrasonic: the ultrasonic system's frame from a 3-D rigid fit of the log's anchor
  coordinates to the ``ANC1..ANC4`` markers; the record holds its projection on the floor
  (``x_m, y_m`` of the frame origin, ``yaw_rad`` of its x axis) and ``pole_residual_m`` is
  the worst anchor residual.  NaN when the C3D has no anchor markers.
* Clock: a number in the trial sheet's ``clock_offset_s`` overrides the estimate (drift 0,
  ``sync_peak`` NaN).  Otherwise :mod:`~gaitval.registration.clock` estimates it from leg
  occupancy (LRS) or from the transmitter-anchor distances (ultrasonic); a peak below
  ``sync_min_peak`` (0.2) is refused with a :class:`~gaitval.errors.RegistrationError`.

An LRS trial is registered with the subject's leg points at sensor height handed in
(``legs``, :class:`~gaitval.registration.legmotion.LegMotion`): the ground truth computes
them once per trial and the same points serve registration and ground truth.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.config import as_float, section
from gaitval.errors import RegistrationError
from gaitval.io.ultrasonic import log_distances
from gaitval.registration import clock as CK
from gaitval.registration import plausibility as PL
from gaitval.registration import poles as PO
from gaitval.registration.anchors import fit_anchor_frame
from gaitval.registration.legmotion import LegMotion, legs_in_sensor_frame, pole_evidence
from gaitval.registration.moving import ROLLATOR_MARKERS, is_moving
from gaitval.registration.poledetect import static_background
from gaitval.registration.rigid import wrap_angle
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

#: Columns of ``registration.csv`` (issue 4), in order.
RECORD_FIELDS = (C.TRIAL, C.X, C.Y, "yaw_rad", C.CLOCK_OFFSET, "clock_drift_ppm",
                 "pole_residual_m", "sync_peak", "joint_centre_source", "gt_frames_excluded",
                 "pose_source", "manual_pose_diff_m", "manual_pose_diff_deg",
                 "legs_in_view", "legs_seen")
#: Trial-sheet columns of a pose measured by hand (field frame; metres, degrees).
MANUAL_POSE_COLUMNS = ("sensor_x_m", "sensor_y_m", "sensor_yaw_deg")

#: Defaults of the ``registration:`` keys read here (plus those of poles and clock).
DEFAULTS = {
    "default_leg_width_m": 0.10,
    "rollator_markers": list(ROLLATOR_MARKERS),
    "anchor_markers": ["ANC1", "ANC2", "ANC3", "ANC4"],
    "tx_marker": "TX",
    "max_anchor_residual_m": 0.02,
}


@dataclass
class RegistrationRecord:
    """One row of ``registration.csv``.

    Attributes
    ----------
    trial : str
    x_m, y_m, yaw_rad : float
        Sensor pose in the field (NaN for a moving sensor).
    clock_offset_s, clock_drift_ppm : float
        ``t_sensor = clock_offset_s + (1 + clock_drift_ppm * 1e-6) * t_mocap``.
    pole_residual_m : float
        Worst pole (ultrasonic: anchor) residual of the rigid fit, metres.
    sync_peak : float
        Normalised cross-correlation at the clock peak, 0..1 (NaN when manual).
    joint_centre_source : str
    gt_frames_excluded : int
        Mocap frames without a ground-truth point (either leg) after short-gap filling.
    pose_source : str
        ``poles``, ``manual`` (measured by hand, no poles), ``anchors`` (ultrasonic),
        ``rollator markers`` (moving sensor).
    manual_pose_diff_m, manual_pose_diff_deg : float
        Pole pose minus the pose measured by hand (position distance, yaw difference);
        NaN without one of the two.
    legs_in_view, legs_seen : float
        The registration's plausibility (:mod:`gaitval.registration.plausibility`): share
        of the walk with a mocap leg in the laser's view, and of those frames with a laser
        return near a leg; NaN for ultrasonic trials.
    """

    trial: str
    x_m: float
    y_m: float
    yaw_rad: float
    clock_offset_s: float
    clock_drift_ppm: float
    pole_residual_m: float
    sync_peak: float
    joint_centre_source: str
    gt_frames_excluded: int
    pose_source: str = "poles"
    manual_pose_diff_m: float = float("nan")
    manual_pose_diff_deg: float = float("nan")
    legs_in_view: float = float("nan")
    legs_seen: float = float("nan")

    def as_row(self) -> dict:
        return asdict(self)


def registration_table(records) -> pd.DataFrame:
    """Records -> the ``registration.csv`` DataFrame (columns :data:`RECORD_FIELDS`)."""
    return pd.DataFrame([r.as_row() for r in records], columns=list(RECORD_FIELDS))


def reg_cfg(cfg: dict | None) -> dict:
    """The ``registration:`` section with every default of this package filled in."""
    c = dict(DEFAULTS)
    c.update(PO.DEFAULTS)
    c.update(CK.DEFAULTS)
    c.update(PL.DEFAULTS)
    c.update(section(cfg, "registration"))
    return c


def _manual_offset(trial: dict | None) -> float | None:
    return as_float((trial or {}).get(C.CLOCK_OFFSET))


def manual_pose(trial: dict | None) -> tuple[float, float, float] | None:
    """``(x_m, y_m, yaw_rad)`` measured by hand (:data:`MANUAL_POSE_COLUMNS`), or None when
    the sheet gives none.  Part of a pose is refused: it cannot be checked or used."""
    vals = [as_float((trial or {}).get(k)) for k in MANUAL_POSE_COLUMNS]
    if all(v is None for v in vals):
        return None
    if any(v is None for v in vals):
        missing = [k for k, v in zip(MANUAL_POSE_COLUMNS, vals) if v is None]
        raise RegistrationError(f"a sensor pose measured by hand needs all of "
                                f"{', '.join(MANUAL_POSE_COLUMNS)}; {', '.join(missing)} "
                                "empty", hint="fill the three cells, or leave all empty")
    return vals[0], vals[1], math.radians(vals[2])


def _has_pole_markers(mocap: MocapTrial, c: dict) -> bool:
    try:
        PO.mocap_pole_positions(mocap, c.get("pole_labels"))
    except RegistrationError:
        return False
    return True


def _leg_width(subject, c) -> float:
    w = as_float((subject or {}).get("leg_width_m"))
    return w if w is not None else float(c["default_leg_width_m"])


def register_trial(mocap: MocapTrial, sensor, trial: dict, subject: dict | None,
                   cfg: dict | None, *, legs: LegMotion | None = None,
                   other_poses: dict | None = None) -> RegistrationRecord:
    """Register one trial (pose, clock) and summarise its ground truth.

    Parameters
    ----------
    mocap : MocapTrial
        The trial's C3D (metres, field frame).
    sensor : ScanSeries or UltrasonicLog
        The sensor log (sensor clock, metres).
    trial : dict
        Trial-sheet row: ``trial``, ``protocol``, ``sensor_height_m``, ``clock_offset_s``
        (empty = estimate).
    subject : dict or None
        Subject-table row (``leg_width_m``).
    cfg : dict
        The whole config (sections ``registration``, ``groundtruth``, ``rollator``) or
        the ``registration`` section alone.
    legs : LegMotion
        The mocap points the sensor sees, from the ground truth's ``sensor_leg_points``
        (the same object then goes to its ``ground_truth``): LRS trials the subject's leg
        points at sensor height for every mocap frame; an ultrasonic log the gap-filled
        heel transmitter.
    other_poses : dict, optional
        trial -> ``(x_m, y_m, yaw_rad)`` measured by hand in other rows of the sheet: the
        candidates "another trial's pose" of a failed plausibility check.

    Returns
    -------
    RegistrationRecord
        ``joint_centre_source`` and ``gt_frames_excluded`` are those of ``legs`` (LRS).

    Raises
    ------
    RegistrationError, MarkerError, ConfigError
        With the file and trial named (poles missing/ambiguous, residual too large,
        synchronisation peak too weak, markers missing, mount not configured).
    TypeError
        An LRS sensor without ``legs``, or a sensor of another type.
    """
    tid = str((trial or {}).get(C.TRIAL, ""))
    try:
        if isinstance(sensor, (UltrasonicLog, ScanSeries)) and legs is None:
            raise TypeError(
                "register_trial: a trial is registered with the mocap points its sensor "
                "sees; pass legs=sensor_leg_points(mocap, sensor, trial, subject, cfg) (from "
                "the groundtruth package)")
        if isinstance(sensor, UltrasonicLog):
            return _register_ultrasonic(mocap, sensor, trial, cfg, tid, legs)
        if isinstance(sensor, ScanSeries):
            return _register_lrs(mocap, sensor, trial, subject, cfg, tid, legs,
                                 other_poses or {})
    except RegistrationError as e:
        raise e.with_context(path=getattr(sensor, "source", None) or mocap.path, trial=tid)
    raise TypeError(f"register_trial: unsupported sensor type {type(sensor).__name__}")


def _register_lrs(mocap, sensor, trial, subject, cfg, tid, legs, other_poses):
    c = reg_cfg(cfg)
    moving = is_moving(trial)
    by_hand = manual_pose(trial)
    diff_m = diff_deg = float("nan")
    if moving:
        pose = None
        x = y = yaw = resid = float("nan")
        source = "rollator markers"
    elif by_hand is not None and not _has_pole_markers(mocap, c):
        x, y, yaw = by_hand                        # no poles: the measured pose alone
        resid, source = float("nan"), "manual"
        pose = by_hand
    else:
        pf = PO.register_poles(sensor, mocap, c, leg_xy_field=pole_evidence(legs), trial=tid)
        x, y, yaw, resid = pf.x_m, pf.y_m, pf.yaw_rad, pf.worst_residual_m
        pose, source = (x, y, yaw), "poles"
        if by_hand is not None:                    # checked against the poles
            diff_m = math.hypot(x - by_hand[0], y - by_hand[1])
            diff_deg = math.degrees(float(wrap_angle(yaw - by_hand[2])))
    attempt = _Attempt(mocap, sensor, legs, trial, subject, cfg, c, moving)
    manual = _manual_offset(trial)
    ce, pl = attempt(pose, manual)
    if not (attempt.clock_ok(ce) and pl.ok):
        raise _implausible(attempt, ce, pl, pose, source, manual, trial, other_poses, tid)
    return RegistrationRecord(tid, x, y, yaw, ce.clock_offset_s, ce.clock_drift_ppm, resid,
                              ce.sync_peak, legs.source, legs.n_excluded, source, diff_m,
                              diff_deg, pl.in_view, pl.seen)


class _Attempt:
    """A trial's registration checked under one pose and clock: the clock estimated (or
    taken from the sheet) and the plausibility of the result.  Callable, so that the
    diagnosis of a failed trial tries each candidate mistake the same way."""

    def __init__(self, mocap, sensor, legs, trial, subject, cfg, c, moving):
        self.mocap, self.sensor, self.legs, self.trial = mocap, sensor, legs, trial
        self.cfg, self.c, self.moving = cfg, c, moving
        self.radius = _leg_width(subject, c) / 2.0
        self.bg, _ = static_background(sensor, {**c, "pole_window_s": None})
        self.fg = PL.foreground(sensor, self.bg, c, moving=moving)

    def __call__(self, pose, manual_offset):
        legs_s = legs_in_sensor_frame(self.mocap, self.legs, self.trial, self.cfg, pose)
        legs_s[~self.legs.valid] = np.nan
        if manual_offset is not None:
            ce = CK.ClockEstimate(manual_offset, 0.0, float("nan"), "manual")
        else:
            obs, obs_t, pred = CK.lrs_occupancy_signals(self.sensor, self.bg, legs_s,
                                                        self.radius, self.c,
                                                        moving=self.moving)
            ce = CK.estimate_clock(self.legs.t, pred, obs_t, obs, self.c)
        pl = PL.check(self.sensor, self.legs.t, legs_s, self.legs.valid, ce.clock_offset_s,
                      ce.clock_drift_ppm, self.radius, self.fg, self.c)
        return ce, pl

    def clock_ok(self, ce) -> bool:
        return ce.method == "manual" or (np.isfinite(ce.clock_offset_s)
                                         and ce.sync_peak >= float(self.c["sync_min_peak"]))


def _implausible(attempt, ce, pl, pose, source, manual, trial, other_poses, tid):
    """The error of a registration that failed its clock or plausibility check, with the
    probable cause found by trying the usual mistakes (:mod:`.plausibility`)."""
    c = attempt.c
    src = (trial or {}).get("sensor_path") or attempt.sensor.source    # the raw file
    if not attempt.clock_ok(ce):
        what = (f"clock synchronisation failed with this pose: correlation peak "
                f"{ce.sync_peak:.2f} is below registration.sync_min_peak = "
                f"{c['sync_min_peak']}")
    else:
        what = "the registration is implausible: " + pl.describe()
    cands = []
    if source == "manual":
        yaw_typed = as_float((trial or {}).get("sensor_yaw_deg"))
        others = {t: p for t, p in other_poses.items() if t != tid}
        cands += PL.pose_candidates(pose, yaw_typed, others)
    if manual is not None:
        cands.insert(0, PL.Candidate(f"the clock offset in the sheet ({manual:g} s) looks "
                                     "wrong", "correct clock_offset_s, or leave it empty to "
                                     "estimate it from the subject's motion", pose, None))
    best = None
    for cand in cands:
        ce2, pl2 = attempt(cand.pose, manual if cand.clock_offset_s is None and
                           cand.pose is not pose else cand.clock_offset_s)
        if attempt.clock_ok(ce2) and pl2.ok and (best is None or pl2.seen > best[2].seen):
            best = (cand, ce2, pl2)
    if best is not None:
        cand, ce2, pl2 = best
        cause = cand.cause
        if cand.pose is pose and manual is not None:        # the clock candidate
            cause += (f": the subject's motion gives {ce2.clock_offset_s:.3f} s "
                      f"({ce2.clock_offset_s - manual:+.2f} s)")
        return RegistrationError(f"{what}; probable cause: {cause}; with that correction "
                                 f"the laser sees the legs in {pl2.seen:.0%} of the walk",
                                 path=src, trial=tid, hint=cand.fix)
    if source == "manual":
        same = PL.same_pose_as(pose, {t: p for t, p in other_poses.items() if t != tid})
        copied = (f"; its pose is the same as trial {', '.join(same)}'s (copied?)"
                  if same else "")
        hint = ("check the sensor pose in the trial sheet first (sensor_x_m, sensor_y_m in "
                "metres, sensor_yaw_deg in degrees, in the mocap frame); if it is right, "
                "check the clock (clock_offset_s, registration.sync_max_lag_s)")
        return RegistrationError(f"{what}{copied}; none of the usual mistakes (millimetres, "
                                 "radians, x/y exchanged, yaw off by 180 degrees, another "
                                 "trial's pose, the clock) explains it", path=src,
                                 trial=tid, hint=hint)
    hint = ("give the offset by hand in the trial sheet's clock_offset_s, or widen "
            "registration.sync_max_lag_s" if not attempt.clock_ok(ce) else
            "check the pose source (the calibration poles, or the rollator's mount in "
            "study.yaml) and the clock (clock_offset_s)")
    return RegistrationError(what, path=src, trial=tid, hint=hint)


def _check_peak(ce, c, path, tid):
    if not np.isfinite(ce.clock_offset_s) or ce.sync_peak < float(c["sync_min_peak"]):
        raise RegistrationError(
            f"clock synchronisation failed: correlation peak {ce.sync_peak:.2f} is below "
            f"registration.sync_min_peak = {c['sync_min_peak']} (offset "
            f"{ce.clock_offset_s:.3f} s would not be trustworthy)", path=path, trial=tid,
            hint="give the offset by hand in the trial sheet's clock_offset_s, or widen "
                 "registration.sync_max_lag_s")


def register_anchors(mocap: MocapTrial, log: UltrasonicLog, cfg: dict | None = None, *,
                     trial=None):
    """The ultrasonic frame of one trial, with the ``registration`` configuration.

    :func:`~gaitval.registration.anchors.fit_anchor_frame` (the one anchor registration)
    with ``registration.anchor_markers``, ``registration.max_anchor_residual_m`` and each
    marker's median position.

    Returns
    -------
    R : (3, 3), t : (3,), residuals : (n_anchors,) with ``p_field = R p_us + t`` (metres).

    Raises
    ------
    RegistrationError
        Fewer than three anchor markers, or a residual above ``max_anchor_residual_m``.
    """
    c = reg_cfg(cfg)
    fit = fit_anchor_frame(mocap, log.anchors, c["anchor_markers"], centre="median",
                           max_residual_m=float(c["max_anchor_residual_m"]), trial=trial)
    return fit.R, fit.t, fit.residuals_m


def anchor_distances(log: UltrasonicLog) -> np.ndarray:
    """Transmitter-anchor distances (n, n_anchors), metres, from ``distance_m`` or from
    ``tof_s`` with seed003 eq. (1)-(2) (:func:`gaitval.io.ultrasonic.log_distances`)."""
    return log_distances(log)


def _register_ultrasonic(mocap, log, trial, cfg, tid, tx):
    c = reg_cfg(cfg)
    X = tx.xyz[:, 0, :]                    # the gap-filled transmitter (ground truth's)
    n_excl = tx.n_excluded
    try:
        R, t, res = register_anchors(mocap, log, cfg, trial=tid)
        yaw = float(wrap_angle(math.atan2(R[1, 0], R[0, 0])))
        x, y, resid = float(t[0]), float(t[1]), float(res.max())
        anchors_f = log.anchors[["x_m", "y_m", "z_m"]].to_numpy(float) @ R.T + t
    except RegistrationError:
        x = y = yaw = resid = float("nan")
        anchors_f = None
    manual = _manual_offset(trial)
    if manual is not None:
        ce = CK.ClockEstimate(manual, 0.0, float("nan"), "manual")
    else:
        if anchors_f is None:
            raise RegistrationError(
                "cannot synchronise the ultrasonic clock: the anchors are not registered "
                "(no ANC markers) and no clock_offset_s is given", path=mocap.path, trial=tid,
                hint="fill clock_offset_s in the trial sheet or label ANC1..ANC4")
        pred = np.linalg.norm(X[:, None, :] - anchors_f[None], axis=2)   # (n, n_anchors)
        ce = CK.estimate_clock(mocap.t, pred, log.t, anchor_distances(log), c)
        _check_peak(ce, c, log.source, tid)
    return RegistrationRecord(tid, x, y, yaw, ce.clock_offset_s, ce.clock_drift_ppm, resid,
                              ce.sync_peak, "tx_marker", n_excl, "anchors")
