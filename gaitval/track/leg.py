"""Per-leg track state and the result of a tracking run.

:class:`LegTrack` is one leg's history during a run (a posteriori state, the observation
used, flags); :class:`TrackResult` is what a run returns, as arrays over the scans, and
:meth:`TrackResult.to_frame` the tidy table the pipeline writes.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval.gait.phases import SWINGING

TRACK_COLUMNS = ("k", "t_sensor_s", "side", "x_m", "y_m", "vx_mps", "vy_mps", "observed",
                 "pattern", "phase", "swing", "interpolated")

_MIRROR_PHASE = np.array([0, 3, 4, 1, 2, 5], dtype=np.int8)


class LegTrack:
    """One leg's history over the n scans of a run (lists indexed by scan k).

    Attributes
    ----------
    post : list
        A posteriori filter state per scan (None before the track starts).
    z : list
        Observation used per scan, ``(x, y)``: a real one, a virtual one written by an
        occlusion handler, or None (UO, prediction kept).
    real, interpolated : list of bool
        A real observation was associated / a virtual one was used.
    pattern : list of str
        The associated observation's leg pattern, ``"UO"`` when none.
    obs_index : list of int
        The associated observation's index in its scan (0-based), −1 when none.
    acc : list of float
        ‖a_k‖, the finite-difference acceleration of the filtered velocity.
    window : SwingAccelerationWindow or None
        The motion model's running acceleration gain for this leg.
    n_unobserved : int
        H, consecutive UO scans up to the last one committed.
    """

    __slots__ = ("post", "z", "real", "interpolated", "pattern", "obs_index", "acc",
                 "window", "n_unobserved")

    def __init__(self, n: int, window=None):
        self.post: list = [None] * n
        self.z: list = [None] * n
        self.real = [False] * n
        self.interpolated = [False] * n
        self.pattern = [""] * n
        self.obs_index = [-1] * n
        self.acc = [0.0] * n
        self.window = window
        self.n_unobserved = 0

    @classmethod
    def start(cls, n: int, k0: int, filter, z, pattern: str, j: int, window=None):
        """A track initialised at scan k0 on observation ``z`` (at rest)."""
        leg = cls(n, window)
        leg.post[k0] = filter.init(float(z[0]), float(z[1]))
        leg.observed(k0, z, pattern, j)
        return leg

    def observed(self, k: int, z, pattern: str, j: int) -> None:
        self.z[k] = (z[0], z[1])
        self.real[k] = True
        self.pattern[k] = pattern
        self.obs_index[k] = j
        self.n_unobserved = 0

    def unobserved(self, k: int) -> None:
        self.pattern[k] = "UO"
        self.n_unobserved += 1

    def gain(self) -> float:
        """g_k of the motion model (0 without a window)."""
        return self.window.value() if self.window is not None else 0.0

    def fill(self, res: "TrackResult", f: int, k0: int) -> None:
        """Write scans k0.. of this leg into row f of ``res``."""
        post = self.post[k0:]
        # a state begins with x, y, vx, vy as Python floats: lists of floats convert several
        # times faster than numpy's shape discovery over the list of state tuples
        res.x[f, k0:] = [s[0] for s in post]
        res.y[f, k0:] = [s[1] for s in post]
        res.vx[f, k0:] = [s[2] for s in post]
        res.vy[f, k0:] = [s[3] for s in post]
        res.observed[f, k0:] = self.real[k0:]
        res.interpolated[f, k0:] = self.interpolated[k0:]
        res.obs_index[f, k0:] = self.obs_index[k0:]
        res.pattern[f, k0:] = self.pattern[k0:]


@dataclass
class TrackResult:
    """Arrays of one run; index [0] = left, [1] = right leg, shape (2, n_scans).

    ``phase`` is -1 before initialisation; ``pattern`` is ``""`` there, else the pattern
    of the associated observation or ``"UO"``; ``obs_index`` is the 0-based index of the
    associated observation in its scan (-1: none); ``refiltered`` lists Method 3's
    re-filtering passes as ``(leg, k_from, k_to)``: both legs were filtered again over
    steps k_from+1..k_to after leg ``leg`` (0 = left) reappeared (seed000 eq. (17)).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    observed: np.ndarray
    interpolated: np.ndarray
    pattern: np.ndarray
    phase: np.ndarray
    k_init: int
    swapped_sides: bool = False
    obs_index: np.ndarray | None = None     # (2, n): associated observation j (0-based), -1
    refiltered: list = field(default_factory=list)   # Method 3: (leg, k_from, k_to) re-runs
    restarts: list = field(default_factory=list)     # scans where both legs were re-initialised

    @property
    def swing(self) -> np.ndarray:
        ph = np.clip(self.phase, 0, 5)
        sw = np.array([SWINGING[i] for i in range(6)])        # (6, 2)
        out = sw[ph].T.copy()
        out[:, self.phase < 0] = False
        return out

    def to_frame(self) -> pd.DataFrame:
        """Tidy table, one row per scan and side (columns :data:`TRACK_COLUMNS`)."""
        n = len(self.t)
        sw = self.swing
        return pd.DataFrame({
            "k": np.repeat(np.arange(n, dtype=np.int64), 2),
            "t_sensor_s": np.repeat(np.asarray(self.t, dtype=float), 2),
            "side": pd.Series(np.tile(np.array(["L", "R"], dtype=object), n), dtype=object),
            "x_m": self.x.T.ravel(), "y_m": self.y.T.ravel(),
            "vx_mps": self.vx.T.ravel(), "vy_mps": self.vy.T.ravel(),
            "observed": self.observed.T.ravel(),
            "pattern": pd.Series(self.pattern.T.ravel(), dtype=object),
            "phase": np.repeat(self.phase.astype(np.int64), 2),
            "swing": sw.T.ravel(),
            "interpolated": self.interpolated.T.ravel(),
        })


def empty_result(t) -> TrackResult:
    """A result with no track (every position NaN, phase −1)."""
    t = np.asarray(t, dtype=float)
    n = len(t)
    nan = np.full((2, n), np.nan)
    return TrackResult(t=t, x=nan.copy(), y=nan.copy(), vx=nan.copy(), vy=nan.copy(),
                       observed=np.zeros((2, n), bool), interpolated=np.zeros((2, n), bool),
                       pattern=np.full((2, n), "", dtype=object),
                       phase=np.full(n, -1, dtype=np.int8), k_init=-1,
                       obs_index=np.full((2, n), -1, dtype=np.int64))


def handedness(res: TrackResult, min_speed: float = 0.3, window_s: float = 0.5) -> float:
    """Σ v_mid × (p_L − p_R) over the first ``window_s`` of steps in which the legs'
    midpoint moves faster than ``min_speed`` (module notes)."""
    vmx = 0.5 * (res.vx[0] + res.vx[1])
    vmy = 0.5 * (res.vy[0] + res.vy[1])
    dx = res.x[0] - res.x[1]
    dy = res.y[0] - res.y[1]
    with np.errstate(invalid="ignore"):
        moving = np.flatnonzero(np.hypot(vmx, vmy) > min_speed)
    if moving.size == 0:
        return 0.0
    t = np.asarray(res.t, dtype=float)
    moving = moving[t[moving] <= t[moving[0]] + window_s]
    return float(np.nansum((vmx * dy - vmy * dx)[moving]))


def swap_sides(res: TrackResult) -> None:
    for name in ("x", "y", "vx", "vy", "observed", "interpolated", "pattern", "obs_index"):
        arr = getattr(res, name)
        setattr(res, name, arr[::-1].copy())
    ok = res.phase >= 0
    res.phase[ok] = _MIRROR_PHASE[res.phase[ok]]
    res.refiltered = [(1 - f, a, b) for f, a, b in res.refiltered]
    res.swapped_sides = True
