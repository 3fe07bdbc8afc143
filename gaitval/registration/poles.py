"""Calibration poles: find them in the laser scans, match them to the C3D pole markers and
fit the sensor pose (seed 000 §2.2 / §4: "the field coordinate of the proposed system was
fixed to that of VICON by using two poles"; seed 001 §2: "aligns the mat and LRS using two
poles").

Method (all in the sensor frame, metres / radians)
--------------------------------------------------
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

import itertools
import re
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval.errors import RegistrationError
from gaitval.registration.rigid import field_to_sensor, fit_rigid_2d, wrap_angle
from gaitval.types import MocapTrial, ScanSeries

#: Defaults of the ``registration:`` config keys used here.
DEFAULTS = {
    "pole_labels": None,            # None: every C3D label matching POLE<n>
    "pole_diameter_m": 0.05,
    "max_pole_residual_m": 0.02,
    "pole_match_tol_m": 0.10,
    "pole_min_static_fraction": 0.5,
    "pole_static_tol_m": 0.03,
    "pole_segment_jump_m": 0.05,
    "pole_edge_step_m": 0.10,
    "pole_window_s": None,          # None: whole trial; else the first N seconds
    "pole_max_scans": 800,
    "pole_ambiguity": "motion",     # or "bearing"
}


def _cfg(cfg: dict | None) -> dict:
    out = dict(DEFAULTS)
    out.update({k: v for k, v in (cfg or {}).items() if k in DEFAULTS})
    return out


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
    return pd.DataFrame(rows, columns=["pole", "x_m", "y_m"])


def static_background(sensor: ScanSeries, cfg: dict | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per-beam median range and static fraction over the calibration window.

    Returns
    -------
    median_m : ndarray (n_beams,)
        NaN where a beam returns nothing in more than half of the window.
    static_fraction : ndarray (n_beams,)
        Fraction of scans within ``pole_static_tol_m`` of the median.
    """
    c = _cfg(cfg)
    r = sensor.ranges
    idx = np.arange(sensor.n_scans)
    if c["pole_window_s"] is not None:
        idx = idx[sensor.t - sensor.t[0] <= float(c["pole_window_s"])]
    if len(idx) > c["pole_max_scans"]:
        idx = idx[np.linspace(0, len(idx) - 1, int(c["pole_max_scans"])).astype(int)]
    sub = r[idx]
    valid_frac = np.mean(np.isfinite(sub), axis=0)
    with np.errstate(all="ignore"):
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            med = np.nanmedian(sub, axis=0)
        static = np.mean(np.abs(sub - med) <= c["pole_static_tol_m"], axis=0)
    med[valid_frac < 0.5] = np.nan
    return med, static


def _fit_fixed_radius(p: np.ndarray, R: float) -> np.ndarray:
    """Circle centre with known radius R through points p (k, 2) seen from the origin."""
    m = p.mean(axis=0)
    c = m + R * m / np.linalg.norm(m)
    if len(p) < 2:
        return c
    for _ in range(20):
        d = p - c
        n = np.linalg.norm(d, axis=1)
        res = n - R
        J = -d / n[:, None]
        step, *_ = np.linalg.lstsq(J, -res, rcond=None)
        c = c + step
        if np.linalg.norm(step) < 1e-7:
            break
    return c


def find_pole_candidates(sensor: ScanSeries, cfg: dict | None = None) -> pd.DataFrame:
    """Thin static objects of the pole diameter in the scans (sensor frame).

    Returns
    -------
    DataFrame ``xs_m, ys_m, range_m, bearing_rad, n_beams, width_m`` (centres, metres),
    one row per candidate, ordered by bearing.  See the module docstring for the method.
    """
    c = _cfg(cfg)
    d = float(c["pole_diameter_m"])
    R = d / 2.0
    med, static = static_background(sensor, c)
    r = med.copy()
    r[static < c["pole_min_static_fraction"]] = np.nan
    a = sensor.angles
    dth = abs(sensor.angle_increment)
    nb = len(r)
    ok = np.isfinite(r)
    # segments: split at missing beams and range jumps
    brk = np.ones(nb + 1, dtype=bool)
    with np.errstate(invalid="ignore"):
        brk[1:nb] = ~(ok[1:] & ok[:-1] & (np.abs(np.diff(r)) <= c["pole_segment_jump_m"]))
    starts = np.flatnonzero(brk[:-1] & ok)
    rows = []
    for s in starts:
        e = s
        while e + 1 < nb and not brk[e + 1]:
            e += 1
        n = e - s + 1
        rmin = np.nanmin(r[s:e + 1])
        if n * dth * rmin > 3 * d:          # far too wide to be a pole
            continue
        pts = np.column_stack([r[s:e + 1] * np.cos(a[s:e + 1]), r[s:e + 1] * np.sin(a[s:e + 1])])
        width = np.linalg.norm(pts[-1] - pts[0]) + rmin * dth
        if abs(width - d) > max(0.5 * d, 1.5 * rmin * dth):
            continue

        def step_ok(i0, direction):
            # depth step beside the segment, allowing one mixed pixel in between
            for k in (1, 2):
                j = i0 + direction * k
                if j < 0 or j >= nb:
                    return True  # edge of the field of view counts as open space
                if not np.isfinite(med[j]):
                    return True
                if med[j] >= rmin + c["pole_edge_step_m"]:
                    return True
                if med[j] < rmin + 0.5 * R:   # a nearer or equal surface: not a free pole
                    return False
            return False

        if not (step_ok(s, -1) and step_ok(e, +1)):
            continue
        keep = r[s:e + 1] <= rmin + 1.2 * R     # drop mixed pixels at the edges
        cen = _fit_fixed_radius(pts[keep], R)
        rows.append((cen[0], cen[1], float(np.hypot(*cen)), float(np.arctan2(cen[1], cen[0])),
                     int(n), float(width)))
    return pd.DataFrame(rows, columns=["xs_m", "ys_m", "range_m", "bearing_rad", "n_beams",
                                       "width_m"])


def foreground_points(sensor: ScanSeries, background: np.ndarray, *, margin_m: float = 0.10,
                      max_scans: int = 300, max_range_m: float | None = None) -> np.ndarray:
    """Sensor-frame points of returns nearer than the static background (pooled scans).

    Returns an (m, 2) array of points (metres) from at most ``max_scans`` evenly spaced
    scans; used as time-agnostic motion evidence.
    """
    idx = np.linspace(0, sensor.n_scans - 1, min(max_scans, sensor.n_scans)).astype(int)
    r = sensor.ranges[idx]
    bg = np.where(np.isfinite(background), background, np.inf)
    with np.errstate(invalid="ignore"):
        fg = np.isfinite(r) & (r < bg - margin_m)
        if max_range_m is not None:
            fg &= r <= max_range_m
    k, i = np.nonzero(fg)
    a = sensor.angles[i]
    return np.column_stack([r[k, i] * np.cos(a), r[k, i] * np.sin(a)])


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
    c = _cfg(cfg)
    markers = mocap_pole_positions(mocap, c["pole_labels"], trial=trial)
    cand = find_pole_candidates(sensor, c)
    labels = list(markers["pole"])
    M = markers[["x_m", "y_m"]].to_numpy()
    n_p = len(M)
    where = dict(path=sensor.source or None, trial=trial)
    if len(cand) < n_p:
        raise RegistrationError(
            f"found {len(cand)} thin static object(s) in the scans but the C3D has {n_p} "
            f"calibration poles ({', '.join(labels)}); a pole is not visible to the sensor "
            "or hidden for more than half of the calibration window",
            hint="check that every pole stands in the scan plane, or set "
                 "registration.pole_window_s to a participant-free part of the trial", **where)
    S = cand[["xs_m", "ys_m"]].to_numpy()
    DM = np.linalg.norm(M[:, None] - M[None], axis=2)
    DS = np.linalg.norm(S[:, None] - S[None], axis=2)
    tol = float(c["pole_match_tol_m"])

    # backtracking over injective assignments consistent with the distance pattern
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
    if len(assignments) > 5000:
        assignments = assignments[:5000]
    if not assignments:
        raise RegistrationError(
            f"no set of {n_p} pole candidates in the scans matches the distances between "
            f"the pole markers {', '.join(labels)} (e.g. {labels[0]}-{labels[1]} = "
            f"{DM[0, 1]:.3f} m) within {tol} m; a pole is not found",
            hint="check the pole diameter (registration.pole_diameter_m) and that both "
                 "poles are visible", **where)
    fits = []
    for asg in assignments:
        x, y, yaw, res = fit_rigid_2d(S[list(asg)], M)
        fits.append((float(res.max()), x, y, yaw, res, asg))
    fits.sort(key=lambda f: f[0])
    # group into distinct pose hypotheses
    hyps = []
    for f in fits:
        if any(np.hypot(f[1] - h[1], f[2] - h[2]) < 0.05
               and abs(wrap_angle(f[3] - h[3])) < np.deg2rad(2) for h in hyps):
            continue
        hyps.append(f)
    best = hyps[0]
    scores = {}
    if len(hyps) > 1:
        if c["pole_ambiguity"] == "bearing":
            ordered = [h for h in hyps
                       if np.all(np.diff(cand["bearing_rad"].to_numpy()[list(h[5])]) > 0)]
            if not ordered:
                raise RegistrationError(
                    "no pole assignment has the pole labels at increasing bearing "
                    "(pole_ambiguity: bearing)", **where)
            best = ordered[0]
        else:
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
            best = hyps[int(order[0])]
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
    poles = pd.DataFrame({"pole": labels, "xs_m": S[list(asg), 0], "ys_m": S[list(asg), 1],
                          "x_m": M[:, 0], "y_m": M[:, 1], "residual_m": res})
    return PoleFit(x, y, float(wrap_angle(yaw)), per_pole, poles, scores)
