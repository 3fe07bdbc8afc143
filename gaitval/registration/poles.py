"""Calibration poles: find them in the laser scans, match them to the C3D pole markers and
fit the sensor pose (seed 000 §2.2 / §4: "the field coordinate of the proposed system was
fixed to that of VICON by using two poles"; seed 001 §2: "aligns the mat and LRS using two
poles").

Method (all in the sensor frame, metres / radians)
--------------------------------------------------
Steps 1-3 find the poles in the scans (:mod:`gaitval.registration.poledetect`); steps 4-5,
here, match them to the markers and fit the pose.

1. **Static background.**  The per-beam median range over the calibration window (by
   default every scan of the trial, evenly subsampled to at most ``pole_max_scans``) and the
   per-beam *static fraction* (share of scans whose range lies within ``pole_static_tol_m``
   of that median).  A leg passing in front of a pole changes the range of a few beams in a
   minority of scans, so the median is unaffected as long as the pole is visible in more
   than half of the window; beams with a static fraction below
   ``pole_min_static_fraction`` (default 0.5) are not used.
2. **Candidates.**  The median scan is cut into segments at range jumps larger than
   ``pole_segment_jump_m`` (0.05 m) and at missing beams.  A segment is a pole candidate
   when (a) its chord width (first-to-last point plus one beam spacing) is within
   ``max(0.5 d, 1.5 r dtheta)`` of the pole diameter ``d`` (``pole_diameter_m``, default
   0.05 m); and (b) it has a depth step on both sides: the next beam outside it (skipping
   one mixed pixel) is at least ``pole_edge_step_m`` (0.10 m) farther away, or returns
   nothing.
3. **Centre.**  Fixed-radius least-squares circle fit (Gauss-Newton on
   ``|p_i - c| - d/2``), starting from the mean return pushed back by ``d/2`` along its
   bearing; one-beam candidates get ``c = p + d/2 * u``.
4. **Correspondence.**  Every injective assignment candidate -> pole marker whose pairwise
   distances agree with the markers' within ``pole_match_tol_m`` (0.10 m) is fitted
   (:func:`~gaitval.registration.rigid.fit_rigid_2d`).  Assignments that give the same pose
   (within 0.05 m and 2 deg) are one hypothesis.  With two poles there are always two
   hypotheses (the pose and its 180 deg turn about the pole midpoint); with three or more
   poles in a symmetric pattern there can be several.  They are resolved by **motion
   evidence** (default ``pole_ambiguity: motion``): the mocap leg points of the trial,
   mapped into the sensor frame by each hypothesis, must land on the foreground returns of
   the scans (fraction of leg points with a foreground return within 0.2 m, pooled over
   the trial, time-agnostic).  The winner must beat the runner-up by 0.2; otherwise, or when
   the trial has no motion, a :class:`~gaitval.errors.RegistrationError` is raised, unless
   ``pole_ambiguity: bearing`` is configured, in which case the pole labels sorted
   naturally (POLE1, POLE2, ...) are taken at increasing beam angle (POLE1 is the pole at
   the smaller, i.e. more clockwise, bearing).
5. **Refusal.**  Fewer than two pole markers in the C3D, fewer matched poles than markers,
   or a worst residual above ``max_pole_residual_m`` (0.02 m) raise
   :class:`~gaitval.errors.RegistrationError` naming the trial, file and pole.

References
----------
Yorozu, A., Moriguchi, T., Takahashi, M. (2015). Improved leg tracking considering gait
phase and spline-based interpolation during turning motion in walk tests. Sensors 15(9),
22451-22472.
Yorozu, A., et al. (2015). Gait measurement system for the multi-target stepping task
using a laser range sensor. Sensors 15(5), 11151-11168.
"""
from __future__ import annotations
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import RegistrationError
from gaitval.registration.poledetect import (DEFAULTS, find_pole_candidates, foreground_points,
                                             pole_cfg, static_background)
from gaitval.registration.rigid import field_to_sensor, fit_rigid_2d, wrap_angle
from gaitval.types import MocapTrial, ScanSeries

__all__ = ["DEFAULTS", "PoleFit", "find_pole_candidates", "foreground_points",
           "mocap_pole_positions", "motion_score", "register_poles", "static_background"]

#: At most this many candidate -> marker assignments are fitted.
MAX_ASSIGNMENTS = 5000


@dataclass
class PoleFit:
    """Result of the pole registration of one fixed sensor.

    Attributes
    ----------
    x_m, y_m, yaw_rad : float
        Sensor pose in the field (common-brief convention).
    residual_m : dict[str, float]
        Distance between the mapped laser pole centre and the marker, per pole label.
    poles : DataFrame
        ``pole, xs_m, ys_m, x_m, y_m, residual_m``: matched pole centres in the sensor
        frame and marker positions in the field.
    motion_score : dict
        Motion-evidence score of each pose hypothesis (empty when unambiguous).
    """

    x_m: float
    y_m: float
    yaw_rad: float
    residual_m: dict[str, float]
    poles: pd.DataFrame
    motion_score: dict = field(default_factory=dict)

    @property
    def worst_residual_m(self) -> float:
        return float(max(self.residual_m.values()))


def _natural_key(s: str):
    return [int(p) if p.isdigit() else p for p in re.split(r"(\d+)", s)]


def mocap_pole_positions(mocap: MocapTrial, labels=None, *, trial=None) -> pd.DataFrame:
    """Median x-y position of each pole marker over the trial (field frame, metres).

    Parameters
    ----------
    mocap : MocapTrial
    labels : list of str, optional
        Pole marker labels; default every label matching ``POLE<n>``.

    Returns
    -------
    DataFrame ``pole, x_m, y_m`` sorted naturally by label (the marker centre is on the
    pole axis, so its x-y is the pole centre).

    Raises
    ------
    RegistrationError
        When fewer than two of the pole markers are present (with at least one frame).
    """
    want = list(labels) if labels else sorted(
        [lb for lb in mocap.labels if re.fullmatch(r"POLE\d+", lb)], key=_natural_key)
    looked = ", ".join(want) if want else "POLE1, POLE2"
    rows = []
    for lb in want:
        if not mocap.has(lb):
            continue
        xy = mocap.marker(lb)[:, :2]
        ok = np.all(np.isfinite(xy), axis=1)
        if ok.any():
            rows.append((lb, *np.median(xy[ok], axis=0)))
    if len(rows) < 2:
        found = [r[0] for r in rows]
        raise RegistrationError(
            f"the C3D has {len(rows)} usable calibration-pole marker(s) {found} "
            f"(looked for {looked}); at least two are needed to register the sensor",
            path=mocap.path, trial=trial,
            hint="label the pole markers POLE1, POLE2 (or set registration.pole_labels), "
                 "or register this trial by hand")
    return pd.DataFrame(rows, columns=["pole", C.X, C.Y])


def motion_score(pose, leg_xy_field: np.ndarray, fg_points: np.ndarray,
                 radius_m: float = 0.2) -> float:
    """Fraction of mocap leg points (field) that land within ``radius_m`` of a foreground
    return once mapped into the sensor frame by ``pose = (x, y, yaw)``."""
    from scipy.spatial import cKDTree

    if len(fg_points) == 0 or len(leg_xy_field) == 0:
        return float("nan")
    ps = field_to_sensor(leg_xy_field, *pose)
    dist, _ = cKDTree(fg_points).query(ps, k=1)
    return float(np.mean(dist <= radius_m))


def register_poles(sensor: ScanSeries, mocap: MocapTrial, cfg: dict | None = None, *,
                   leg_xy_field: np.ndarray | None = None, trial: str | None = None
                   ) -> PoleFit:
    """Sensor pose from the calibration poles (see the module docstring for the method).

    Parameters
    ----------
    sensor : ScanSeries
        Laser scans of a fixed sensor (metres, NaN = no return).
    mocap : MocapTrial
        The C3D with the pole markers.
    cfg : dict, optional
        ``registration:`` config (keys in :data:`DEFAULTS`).
    leg_xy_field : ndarray (m, 2), optional
        Mocap leg points at sensor height (field frame) used as motion evidence to resolve
        the pole-correspondence ambiguity.
    trial : str, optional
        Trial id for error messages.

    Returns
    -------
    PoleFit

    Raises
    ------
    RegistrationError
        No/one pole marker, a pole not found in the scans, an ambiguous correspondence, or
        a residual above ``max_pole_residual_m``.
    """
    c = pole_cfg(cfg)
    markers = mocap_pole_positions(mocap, c["pole_labels"], trial=trial)
    cand = find_pole_candidates(sensor, c)
    labels = list(markers["pole"])
    M = markers[[C.X, C.Y]].to_numpy()
    where = dict(path=sensor.source or None, trial=trial)
    if len(cand) < len(M):
        raise RegistrationError(
            f"found {len(cand)} thin static object(s) in the scans but the C3D has {len(M)} "
            f"calibration poles ({', '.join(labels)}); a pole is not visible to the sensor "
            "or hidden for more than half of the calibration window",
            hint="check that every pole stands in the scan plane, or set "
                 "registration.pole_window_s to a participant-free part of the trial", **where)
    S = cand[[C.XS, C.YS]].to_numpy()
    assignments = _consistent_assignments(S, M, float(c["pole_match_tol_m"]), labels, where)
    hyps = _pose_hypotheses(S, M, assignments)
    best, scores = hyps[0], {}
    if len(hyps) > 1:
        if c["pole_ambiguity"] == "bearing":
            best = _by_bearing(hyps, cand["bearing_rad"].to_numpy(), where)
        else:
            best, scores = _by_motion(hyps, sensor, c, leg_xy_field, where)
    worst, x, y, yaw, res, asg = best
    per_pole = {lb: float(v) for lb, v in zip(labels, res)}
    if worst > float(c["max_pole_residual_m"]):
        lb = labels[int(np.argmax(res))]
        raise RegistrationError(
            f"pole residual {worst * 1000:.1f} mm at {lb} exceeds "
            f"registration.max_pole_residual_m = {c['max_pole_residual_m'] * 1000:.0f} mm "
            f"(per pole: " + ", ".join(f"{k} {v * 1000:.1f} mm" for k, v in per_pole.items())
            + ")", hint="a pole may have moved between calibration and recording, or the "
                        "pole diameter in the config is wrong", **where)
    poles = pd.DataFrame({"pole": labels, C.XS: S[list(asg), 0], C.YS: S[list(asg), 1],
                          C.X: M[:, 0], C.Y: M[:, 1], "residual_m": res})
    return PoleFit(x, y, float(wrap_angle(yaw)), per_pole, poles, scores)


def _consistent_assignments(S: np.ndarray, M: np.ndarray, tol: float, labels, where
                            ) -> list[tuple[int, ...]]:
    """Injective assignments marker j -> candidate k whose pairwise distances agree with the
    markers' within ``tol`` (backtracking; at most :data:`MAX_ASSIGNMENTS`).

    Raises
    ------
    RegistrationError
        When no assignment fits the markers' distance pattern (a pole is not found).
    """
    n_p = len(M)
    DM = np.linalg.norm(M[:, None] - M[None], axis=2)
    DS = np.linalg.norm(S[:, None] - S[None], axis=2)
    assignments = []

    def extend(partial):
        j = len(partial)
        if j == n_p:
            assignments.append(tuple(partial))
            return
        for k in range(len(S)):
            if k in partial:
                continue
            if all(abs(DS[k, partial[i]] - DM[j, i]) <= tol for i in range(j)):
                extend(partial + [k])
        return

    extend([])
    if not assignments:
        raise RegistrationError(
            f"no set of {n_p} pole candidates in the scans matches the distances between "
            f"the pole markers {', '.join(labels)} (e.g. {labels[0]}-{labels[1]} = "
            f"{DM[0, 1]:.3f} m) within {tol} m; a pole is not found",
            hint="check the pole diameter (registration.pole_diameter_m) and that both "
                 "poles are visible", **where)
    return assignments[:MAX_ASSIGNMENTS]


def _pose_hypotheses(S: np.ndarray, M: np.ndarray, assignments) -> list[tuple]:
    """Rigid fit of every assignment (:func:`~gaitval.registration.rigid.fit_rigid_2d`),
    best worst-residual first, grouped into distinct poses (within 0.05 m and 2 deg).

    Returns a list of ``(worst_residual_m, x_m, y_m, yaw_rad, residuals, assignment)``.
    """
    fits = []
    for asg in assignments:
        x, y, yaw, res = fit_rigid_2d(S[list(asg)], M)
        fits.append((float(res.max()), x, y, yaw, res, asg))
    fits.sort(key=lambda f: f[0])
    hyps = []
    for f in fits:
        if any(np.hypot(f[1] - h[1], f[2] - h[2]) < 0.05
               and abs(wrap_angle(f[3] - h[3])) < np.deg2rad(2) for h in hyps):
            continue
        hyps.append(f)
    return hyps


def _by_bearing(hyps: list[tuple], bearing: np.ndarray, where) -> tuple:
    """``pole_ambiguity: bearing``: the best hypothesis with the pole labels at increasing
    beam angle."""
    ordered = [h for h in hyps if np.all(np.diff(bearing[list(h[5])]) > 0)]
    if not ordered:
        raise RegistrationError(
            "no pole assignment has the pole labels at increasing bearing "
            "(pole_ambiguity: bearing)", **where)
    return ordered[0]


def _by_motion(hyps: list[tuple], sensor: ScanSeries, c: dict, leg_xy_field, where
               ) -> tuple[tuple, dict]:
    """``pole_ambiguity: motion``: the hypothesis whose mapped leg points land on the
    foreground returns (:func:`motion_score`), ahead of the runner-up by 0.2.

    Returns the winning hypothesis and the score of each (``pose0``, ``pose1``, ...).
    """
    fg = None
    if leg_xy_field is not None and len(leg_xy_field):
        med, _ = static_background(sensor, c)
        fg = foreground_points(sensor, med)
    if fg is None or len(fg) == 0:
        raise RegistrationError(
            f"{len(hyps)} sensor poses fit the poles equally well (with two poles "
            "the pose and its 180-degree turn about the pole midpoint) and the "
            "trial shows no walking to tell them apart",
            hint="set registration.pole_ambiguity: bearing (POLE1 at the smaller "
                 "beam angle) or use three poles in an asymmetric pattern", **where)
    sc = [motion_score((h[1], h[2], h[3]), leg_xy_field, fg) for h in hyps]
    order = np.argsort(sc)[::-1]
    scores = {f"pose{i}": float(s) for i, s in enumerate(sc)}
    if not (sc[order[0]] - sc[order[1]] >= 0.2):
        raise RegistrationError(
            f"the pole correspondence is ambiguous: motion evidence "
            f"{sc[order[0]]:.2f} vs {sc[order[1]]:.2f} (fraction of mocap leg "
            "points on laser returns)",
            hint="set registration.pole_ambiguity: bearing, or check the clock "
                 "and the sensor height", **where)
    return hyps[int(order[0])], scores
