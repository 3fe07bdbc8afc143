"""Is a registration plausible?  The mocap legs, carried into the laser's frame and onto its
clock by the registration, must lie where the laser can see them and where it sees something.

Every LRS registration (poles, a pose measured by hand, the rollator's mount) ends with
:func:`check`, on the trial's leg points at the scan height (both legs known):

``in_view``
    The share of those mocap frames in which at least one leg lies inside the laser's
    recording (its first to last scan, through the clock), inside its field of view
    (``angle_min .. angle_max``) and its range (``range_min .. range_max``).
``seen``
    Of the frames in view, the share in which the laser has a foreground return (nearer than
    the beam's static background by ``sync_foreground_margin_m``; for a moving laser, within
    ``sync_moving_max_range_m``) within the leg's radius plus ``plausible_tol_m`` of a leg
    that is in view, in the scan nearest in time.

A registration passes when both shares reach ``plausible_min_in_view`` and
``plausible_min_seen`` (0.5 each: "most of the walk").  Why these values: a correct
registration puts a leg under a return in every frame but those where *both* legs are hidden
or outside the field of view at once -- the papers' tracker-counted unobservable rates, per
leg, are 3.5--30 % (Yorozu et al. 2015, TUG Table 5 and MTST Table 3) -- so its ``seen`` lies
far above one half; a wrong pose or clock puts the legs where the laser sees the static room
or nothing, and only chance coincidences with the person count, far below one half.  The
tolerance (0.15 m) is the mocap leg point's own uncertainty at shin height (the tibia fit
against the laser's arc of the shank, a few centimetres) plus one stride-phase's worth of
clock error at 10 ms.  The values were stated before any study was checked; the shares of
every trial are in ``registration.csv`` (``legs_in_view``, ``legs_seen``).

When a trial fails (or its clock cannot be synchronised with the pose the sheet gives),
:func:`diagnose` tries the usual mistakes one at a time -- the position typed in
millimetres, the yaw in radians, x and y exchanged, the yaw off by 180 degrees, another
trial's pose, a wrong clock offset -- and names the one under which the check passes: the
probable cause.  It never corrects the sheet: the user does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Defaults of the ``registration:`` keys read here.
DEFAULTS = {
    "plausible_min_in_view": 0.5,
    "plausible_min_seen": 0.5,
    "plausible_tol_m": 0.15,
    "plausible_max_frames": 1500,
}


@dataclass(frozen=True)
class Plausibility:
    """The two shares of :func:`check` and the frames they were computed on."""

    n_frames: int
    in_view: float
    seen: float
    min_in_view: float = DEFAULTS["plausible_min_in_view"]
    min_seen: float = DEFAULTS["plausible_min_seen"]

    @property
    def ok(self) -> bool:
        return (self.n_frames > 0 and self.in_view >= self.min_in_view
                and self.seen >= self.min_seen)

    def describe(self) -> str:
        if self.n_frames == 0:
            return "no mocap frame has both legs at the laser's height"
        return (f"the mocap legs lie inside the laser's recording, field of view and range in "
                f"{self.in_view:.0%} of the walk, and the laser sees something within "
                f"reach of them in {self.seen:.0%} of those frames (at least "
                f"{self.min_in_view:.0%} and {self.min_seen:.0%} needed)")


def foreground(sensor, background: np.ndarray, cfg: dict, *, moving: bool) -> np.ndarray:
    """(n_scans, n_beams) bool: returns that are not the static room (as the clock's
    occupancy signal defines them, :func:`gaitval.registration.clock.lrs_occupancy_signals`)."""
    r = sensor.ranges
    with np.errstate(invalid="ignore"):
        if moving:
            return np.isfinite(r) & (r <= float(cfg["sync_moving_max_range_m"]))
        bg = np.where(np.isfinite(background), background, np.inf)
        return np.isfinite(r) & (r < bg - float(cfg["sync_foreground_margin_m"]))


def check(sensor, t_mocap: np.ndarray, legs_s: np.ndarray, valid: np.ndarray,
          clock_offset_s: float, clock_drift_ppm: float, radius_m: float, fg: np.ndarray,
          cfg: dict) -> Plausibility:
    """The plausibility of one registration (module docstring).

    Parameters
    ----------
    sensor : ScanSeries
    t_mocap : (n,) mocap frame times, s
    legs_s : (n, 2, 2) leg points in the sensor frame (through the registered pose), m
    valid : (n, 2) bool, the leg points known
    clock_offset_s, clock_drift_ppm : the registered clock (``t_sensor = offset + (1 + drift
        * 1e-6) * t_mocap``)
    radius_m : the leg's radius at the scan height
    fg : (n_scans, n_beams) bool, :func:`foreground`
    """
    c = {**DEFAULTS, **(cfg or {})}
    lims = dict(min_in_view=float(c["plausible_min_in_view"]),
                min_seen=float(c["plausible_min_seen"]))
    frames = np.flatnonzero(np.asarray(valid).all(axis=1))
    if frames.size == 0 or sensor.n_scans == 0 or not np.isfinite(clock_offset_s):
        return Plausibility(int(frames.size), 0.0, 0.0, **lims)
    k = int(c["plausible_max_frames"])
    if frames.size > k:
        frames = frames[np.linspace(0, frames.size - 1, k).astype(int)]
    ts = clock_offset_s + (1.0 + clock_drift_ppm * 1e-6) * np.asarray(t_mocap, float)[frames]
    st = np.asarray(sensor.t, float)
    inrec = (ts >= st[0]) & (ts <= st[-1])
    P = np.asarray(legs_s, float)[frames]                          # (k, 2, 2)
    rng = np.hypot(P[..., 0], P[..., 1])
    bearing = np.arctan2(P[..., 1], P[..., 0])
    lo, hi = sorted((sensor.angle_min, sensor.angle_max))
    view = ((rng >= sensor.range_min) & (rng <= sensor.range_max) & (bearing >= lo)
            & (bearing <= hi) & inrec[:, None])                       # (k, 2)
    in_view = view.any(axis=1)
    if not in_view.any():
        return Plausibility(int(frames.size), 0.0, 0.0, **lims)
    sel = np.flatnonzero(in_view)
    j = np.clip(np.searchsorted(st, ts[sel]), 1, len(st) - 1)
    j = np.where(np.abs(st[j - 1] - ts[sel]) <= np.abs(st[j] - ts[sel]), j - 1, j)
    ang = sensor.angles
    with np.errstate(invalid="ignore"):
        r = np.where(fg[j], sensor.ranges[j], np.nan)                  # (m, nb)
        rx, ry = r * np.cos(ang), r * np.sin(ang)
        reach = radius_m + float(c["plausible_tol_m"])
        near = np.zeros((sel.size, 2), dtype=bool)
        for leg in range(2):
            d = np.hypot(rx - P[sel, leg, 0:1], ry - P[sel, leg, 1:2])
            near[:, leg] = np.any(d <= reach, axis=1)
    seen = (near & view[sel]).any(axis=1)
    return Plausibility(int(frames.size), float(in_view.mean()), float(seen.mean()), **lims)


@dataclass(frozen=True)
class Candidate:
    """One mistake :func:`diagnose` tries: what it would mean, the pose (field frame, m,
    rad) and clock offset (None: estimate it) under which the trial is checked again."""

    cause: str
    fix: str
    pose: tuple[float, float, float] | None
    clock_offset_s: float | None = None


def pose_candidates(pose, yaw_deg_typed: float | None, others: dict) -> list[Candidate]:
    """The usual mistakes of a pose measured by hand, as candidate poses.

    ``pose``: the sheet's ``(x_m, y_m, yaw_rad)``; ``yaw_deg_typed``: the number in
    ``sensor_yaw_deg``; ``others``: other trials' hand-measured poses (trial -> pose)."""
    x, y, yaw = pose
    out = [Candidate("the position looks typed in millimetres "
                     f"(sensor_x_m = {x:g}, sensor_y_m = {y:g})",
                     "give sensor_x_m and sensor_y_m in metres in the trial sheet", (x / 1000, y / 1000, yaw))]
    if yaw_deg_typed is not None and abs(yaw_deg_typed) <= 2 * math.pi:
        out.append(Candidate(f"the yaw looks typed in radians (sensor_yaw_deg = "
                             f"{yaw_deg_typed:g})", "give sensor_yaw_deg in degrees "
                             f"({math.degrees(yaw_deg_typed):.1f} if {yaw_deg_typed:g} is "
                             "radians)", (x, y, yaw_deg_typed)))
    out.append(Candidate("x and y look exchanged", "swap sensor_x_m and sensor_y_m",
                         (y, x, yaw)))
    out.append(Candidate("the yaw looks off by 180 degrees (the laser's forward axis is "
                         "its x axis, towards its field of view's centre)",
                         "add or subtract 180 in sensor_yaw_deg", (x, y, yaw + math.pi)))
    for t, p in sorted(others.items()):
        if not np.allclose(p, pose, atol=1e-6):
            out.append(Candidate(f"the pose in trial {t}'s row fits this recording: the "
                                 "rows' poses look exchanged or copied",
                                 f"check the poses of this trial and of {t}", tuple(p)))
    return out


def same_pose_as(pose, others: dict) -> list[str]:
    """Other trials whose hand-measured pose is exactly this one (a copied row?)."""
    return sorted(t for t, p in others.items() if np.allclose(p, pose, atol=1e-6))
