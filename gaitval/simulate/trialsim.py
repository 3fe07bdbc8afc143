"""What one simulated LRS trial is made of, and the scene pieces every protocol shares.

:class:`TrialSim` holds everything the renderer (:mod:`gaitval.simulate.render`) needs for
one trial; the protocol builders (:mod:`gaitval.simulate.tug`, :mod:`gaitval.simulate.mtst`,
:mod:`gaitval.simulate.rollator`) and the replay of real walks
(:mod:`gaitval.simulate.replay`) fill it in.  Also here: the calibration poles, the room's
walls and the hand placement of a fixed sensor.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from gaitval.simulate.scene import Walker

POLE_RADIUS_M = 0.025          # registration.pole_diameter_m default 0.05 m
POLE_TOP_M = 1.20


@dataclass
class TrialSim:
    """Everything needed to render one trial (field frame, mocap time)."""

    study: str
    protocol: str
    subject: str
    trial: str
    walker: Walker
    sensor: str
    sensor_height_m: float
    mocap_rate_hz: float
    t_end_s: float                              # mocap covers [0, t_end]
    circles: np.ndarray                         # (k, 4) cx, cy, r, id  (static, field)
    walls: np.ndarray                           # (m, 4) x0, y0, x1, y1 (field)
    poles: np.ndarray                           # (2, 2)
    fixed_pose: tuple | None                    # (x, y, yaw) of a fixed sensor
    rollator: Callable | None = None            # t -> (n, 3) rollator pose (field)
    sensor_mount: tuple | None = None           # sensor pose in the rollator frame
    attendant: Walker | None = None
    phase_fn: Callable | None = None            # t -> array of phase names
    targets: pd.DataFrame | None = None         # MTST targets (x_m, y_m, color, assigned)
    target_steps: dict = field(default_factory=dict)   # contact index -> target id
    log_every: int = 1                          # keep every n-th scan (MTST Δt = 0.05 s)
    scenario: str = ""
    repetition: int = 1
    speed: str = ""
    stick: bool = False
    variant: dict = field(default_factory=dict)


def preset_number(value, key: str, lo: float, hi: float, *, whole: bool = False):
    """A preset's number ``value`` at ``key`` (e.g. ``"mtst.targets.lane_m"``), checked to
    lie in ``[lo, hi]`` (a whole number when ``whole``), else a ConfigError naming the key,
    the range and the value."""
    from gaitval.errors import ConfigError

    kinds = (int,) if whole else (int, float)
    if isinstance(value, bool) or not isinstance(value, kinds) or not lo <= value <= hi:
        what = "a whole number" if whole else "a number"
        section = key.split(".")[0]
        raise ConfigError(f"{key} must be {what} from {lo:g} to {hi:g}, got {value!r}",
                          hint=f"the simulation preset's {section} section")
    return value


def _walls(x0, x1, y0, y1) -> np.ndarray:
    return np.array([[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]])


def _pose_jitter(rng, nominal, sd_xy=0.05, sd_yaw_deg=3.0) -> tuple:
    return (float(nominal[0] + sd_xy * rng.standard_normal()),
            float(nominal[1] + sd_xy * rng.standard_normal()),
            float(nominal[2] + np.deg2rad(sd_yaw_deg) * rng.standard_normal()))
