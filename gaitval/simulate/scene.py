"""Walkers and scene objects in the field frame, and their view from a sensor.

A :class:`Walker` turns a step plan into legs (shank ellipses at any height), a pelvis
(for the Plug-in-Gait markers) and an optional walking stick.  :func:`scene_in_sensor`
puts every object of a trial into the sensor frame for a block of scans.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from gaitval.simulate.contact import CHECK_HEIGHTS_REL_M, separate_footholds, swing_detours
from gaitval.simulate.kinematics import GaitParams, LegState, StepPlan, leg_kinematics

# object ids used in ray-casting truth
ID_LEFT, ID_RIGHT, ID_ATTENDANT, ID_STICK, ID_CHAIR, ID_MARKER, ID_POLE, ID_WALL, \
    ID_ROLLATOR, ID_OBSTACLE = range(10)
ID_NAMES = {ID_LEFT: "left_leg", ID_RIGHT: "right_leg", ID_ATTENDANT: "attendant_leg",
            ID_STICK: "stick", ID_CHAIR: "chair_leg", ID_MARKER: "turn_marker",
            ID_POLE: "pole", ID_WALL: "wall", ID_ROLLATOR: "rollator_frame",
            ID_OBSTACLE: "obstacle"}


@dataclass
class Walker:
    """A person walking a step plan.

    Parameters
    ----------
    plan : StepPlan
    gp : GaitParams
    leg_width_m : float
        Shank width (medio-lateral) at sensor height; the cross-section is an ellipse of
        semi-axes ``w/2`` (medio-lateral) and ``0.95 w/2 / cos(tilt)`` (antero-posterior:
        a tilted cylinder cut by a horizontal plane is stretched along its tilt).
    sit : callable t -> [0, 1], optional
        Sitting level (1 seated) for TUG: lowers and moves back the pelvis.
    posture_tilt : callable t -> rad, optional
        Extra shank tilt of sit-to-stand (knees move forward as the trunk leans).
    stick_side : int or None
        Hand holding a stick (0 = L, 1 = R); the stick moves with the opposite leg.
    stick_offset_m : float
        The stick's distance from the pelvis line (m).
    sensor_height_m : float
        Height of the scan plane: the two shanks are kept apart there and 3 cm above and
        below (contact physics, :mod:`gaitval.simulate.contact`).
    """

    plan: StepPlan
    gp: GaitParams
    leg_width_m: float
    sit: Callable | None = None
    posture_tilt: Callable | None = None
    stick_side: int | None = None
    stick_offset_m: float = 0.28
    sensor_height_m: float = 0.27
    _pelvis_cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        # contact physics: each swing that would pass through the standing leg bends
        # around it (gaitval.simulate.contact); part of the plan, drawn before any frame
        if self.plan.detour is None:
            gp = self.gp
            fn = lambda p, s, t: leg_kinematics(p, s, t, gp)      # noqa: E731
            hs = tuple(self.sensor_height_m + dh for dh in CHECK_HEIGHTS_REL_M)
            cl = gp.shank_clearance_m
            plan = separate_footholds(self.plan, fn, self.leg_width_m, hs, clearance_m=cl)
            self.plan = plan.with_detours(swing_detours(plan, fn, self.leg_width_m, hs,
                                                        clearance_m=cl))

    def legs(self, t: np.ndarray) -> tuple[LegState, LegState]:
        pt = None if self.posture_tilt is None else self.posture_tilt(t)
        return (leg_kinematics(self.plan, 0, t, self.gp, pt),
                leg_kinematics(self.plan, 1, t, self.gp, pt))

    def shank_ellipses(self, t: np.ndarray, height: float, legs=None) -> np.ndarray:
        """(n, 2, 5) ``cx, cy, a, b, psi`` of the left and right shank at ``height``."""
        legs = self.legs(t) if legs is None else legs
        out = np.empty((len(t), 2, 5))
        for k, lg in enumerate(legs):
            c = lg.point_at_height(height)
            out[:, k, 0:2] = c
            out[:, k, 2] = 0.95 * self.leg_width_m / 2 / np.cos(lg.tilt)
            out[:, k, 3] = self.leg_width_m / 2
            out[:, k, 4] = lg.heading
        return out

    def _pelvis_grid(self):
        if "grid" not in self._pelvis_cache:
            t0 = min(self.plan.t_start, 0.0) - 3.0
            t1 = self.plan.t_end + 6.0
            tg = np.arange(t0, t1, 0.01)
            L, R = self.legs(tg)
            mid = 0.5 * (L.ankle[:, :2] + R.ankle[:, :2])
            hd = np.unwrap(np.angle(np.exp(1j * L.heading) + np.exp(1j * R.heading)))
            w = max(3, int(round(2 * self.gp.step_time_s / 0.01)) | 1)
            ker = np.ones(w) / w
            pad = lambda a: np.concatenate([np.full(w, a[0]), a, np.full(w, a[-1])])
            sm = lambda a: np.convolve(pad(a), ker, mode="same")[w:-w]
            self._pelvis_cache["grid"] = (tg, sm(mid[:, 0]), sm(mid[:, 1]), sm(hd))
        return self._pelvis_cache["grid"]

    def pelvis(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Hip-joint-centre midpoint (n, 3) and pelvis heading (n,).

        Standing: above the smoothed ankle midpoint (moving average over one stride) at
        hip height with a 0.02 m vertical oscillation; seated: back by the thigh length
        and down to seat height.
        """
        tg, x, y, h = self._pelvis_grid()
        px = np.interp(t, tg, x)
        py = np.interp(t, tg, y)
        hd = np.interp(t, tg, h)
        z = np.full(len(t), self.gp.hip_height_m)
        if self.sit is not None:
            s = self.sit(t)
            back = 0.42 * s
            px = px - back * np.cos(hd)
            py = py - back * np.sin(hd)
            z = z - (self.gp.hip_height_m - 0.50) * s
        return np.column_stack([px, py, z]), hd

    def stick(self, t: np.ndarray, legs=None) -> np.ndarray:
        """(n, 2) stick position at sensor height, or empty when no stick.

        The stick is held in hand ``stick_side`` ``stick_offset_m`` lateral of the pelvis line and
        advances with the opposite leg (longitudinal position of that leg's ankle).
        """
        if self.stick_side is None:
            return np.empty((len(t), 0))
        legs = self.legs(t) if legs is None else legs
        opp = legs[1 - self.stick_side]
        p, hd = self.pelvis(t)
        fwd = np.column_stack([np.cos(hd), np.sin(hd)])
        left = np.column_stack([-np.sin(hd), np.cos(hd)])
        along = np.sum((opp.ankle[:, :2] - p[:, :2]) * fwd, axis=1) + 0.05
        sgn = 1.0 if self.stick_side == 0 else -1.0
        return p[:, :2] + along[:, None] * fwd + sgn * self.stick_offset_m * left


def to_sensor(xy: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Field → sensor frame: ``p_s = R(-yaw) (p_f - [x, y])``; ``pose`` (n, 3) or (3,)."""
    pose = np.atleast_2d(pose)
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    if xy.ndim == 3:
        c, s = c[:, None], s[:, None]
        dx = xy[..., 0] - pose[:, None, 0]
        dy = xy[..., 1] - pose[:, None, 1]
    else:
        dx = xy[:, 0] - pose[:, 0]
        dy = xy[:, 1] - pose[:, 1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)


def to_field(xy_s: np.ndarray, pose) -> np.ndarray:
    """Sensor → field frame: ``p_f = R(yaw) p_s + [x, y]`` (the project convention)."""
    x, y, yaw = pose
    c, s = np.cos(yaw), np.sin(yaw)
    return np.stack([c * xy_s[..., 0] - s * xy_s[..., 1] + x,
                     s * xy_s[..., 0] + c * xy_s[..., 1] + y], axis=-1)
