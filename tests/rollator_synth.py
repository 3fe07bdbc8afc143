"""A small rollator scene for the seed 002 tests (not the project simulator).

The laser sits on the rollator facing the user (sensor frame: x towards the user, y to the
laser's left, so the user's left leg is at negative y).  Two shanks (circles of diameter
w_l) walk with the rollator: each swings forward and back along x around 0.35 m, half a
cycle apart, with a small lateral sway; the two rear frame tubes stand at (0.08, ±0.28).
Used only by tests; the project's simulator (gaitval.simulate) is the real thing.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.types import ScanSeries

#: Hokuyo UBG-04LX-F01: 683 beams of 360°/1024 over 240°, 28 ms
ANGLE_MIN = -np.deg2rad(120.0)
INC = 2 * np.pi / 1024
N_BEAMS = 683
DT = 0.028
TUBES = ((0.08, 0.28), (0.08, -0.28))


def legs(t, *, period=1.1, amp=0.11, x0=0.36, half_gap=0.075, phase=0.0):
    """Left and right centres (n, 2) and velocities (n, 2) at times t."""
    w = 2 * np.pi / period
    out = []
    for f, sgn in ((0, -1.0), (1, 1.0)):                     # left at negative y
        ph = phase + f * np.pi
        x = x0 + amp * np.sin(w * t + ph)
        y = sgn * half_gap + 0.01 * np.sin(0.5 * w * t + ph)
        vx = amp * w * np.cos(w * t + ph)
        vy = 0.01 * 0.5 * w * np.cos(0.5 * w * t + ph)
        out.append((np.column_stack([x, y]), np.column_stack([vx, vy])))
    return out


def cast(circles, n, *, noise_m=0.005, seed=0):
    """Ranges (n, N_BEAMS) of circles ``[(centres (n, 2) or (2,), radius), ...]``."""
    rng = np.random.default_rng(seed)
    a = ANGLE_MIN + INC * np.arange(N_BEAMS)
    ux, uy = np.cos(a), np.sin(a)
    r = np.full((n, N_BEAMS), np.inf)
    for c, rad in circles:
        c = np.broadcast_to(np.asarray(c, float), (n, 2))
        proj = c[:, :1] * ux + c[:, 1:] * uy
        disc = rad ** 2 - (c[:, :1] ** 2 + c[:, 1:] ** 2 - proj ** 2)
        with np.errstate(invalid="ignore"):
            hit = proj - np.sqrt(disc)
        r = np.minimum(r, np.where((disc >= 0) & (hit > 0), hit, np.inf))
    r = r + rng.normal(0.0, noise_m, r.shape)
    r[~np.isfinite(r) | (r > 5.6)] = np.nan
    return r


def walk(n=300, *, seed=0, leg_width=0.10, hide_right=None, tubes=True, **kw):
    """(ScanSeries, truth DataFrame as groundtruth.parquet) of one synthetic trial.

    ``hide_right=(k0, k1)`` removes the right leg from scans k0..k1−1 (an occlusion).
    """
    t = np.arange(n) * DT
    (pl, vl), (pr, vr) = legs(t, **kw)
    circles = [(pl, leg_width / 2)]
    r = cast(circles + [(pr, leg_width / 2)] + ([(c, 0.0125) for c in TUBES] if tubes else []),
             n, seed=seed)
    if hide_right is not None:
        k0, k1 = hide_right
        r[k0:k1] = cast(circles + ([(c, 0.0125) for c in TUBES] if tubes else []), n,
                        seed=seed + 1)[k0:k1]
    scans = ScanSeries(t=t, ranges=r, angle_min=ANGLE_MIN, angle_increment=INC,
                       range_min=0.02, range_max=5.6, sensor_model="synthetic UBG-04LX",
                       mounting_height_m=0.40)
    rows = []
    for side, p, v in (("L", pl, vl), ("R", pr, vr)):
        rows.append(pd.DataFrame({"scan": np.arange(n), "t_sensor_s": t, "side": side,
                                  "xs_m": p[:, 0], "ys_m": p[:, 1], "vxs_mps": v[:, 0],
                                  "vys_mps": v[:, 1], "valid": True}))
    truth = pd.concat(rows).sort_values(["scan", "side"]).reset_index(drop=True)
    return scans, truth
