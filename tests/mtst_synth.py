"""A constructed two-leg MTST walk for the tests (not the project's simulator)."""
from __future__ import annotations

import numpy as np
import pandas as pd

DT = 0.05


def walk(footholds: list[tuple[str, float, float]], step_s: float = 0.6, stand_s: float = 0.2,
         start: dict | None = None) -> pd.DataFrame:
    """Tidy track (``k, t_sensor_s, side, x_m, y_m, vx_mps, vy_mps, swing``) of legs stepping
    onto ``footholds`` (side, x, y) in turn, walking +x, Δt = 0.05 s.

    Each leg stands (creeping at 0.02 m/s) and swings to its next foothold in ``step_s``
    along a half-cosine profile (swing flag while moving); after each step both legs stand
    ``stand_s``.  The legs start side by side 0.4 m behind the first foothold (or at
    ``start``: side -> (x, y)).
    """
    start = start or {"L": (footholds[0][1] - 0.4, 0.1), "R": (footholds[0][1] - 0.4, -0.1)}
    pos = {s: [np.array(p, float)] for s, p in start.items()}
    swing = {"L": [False], "R": [False]}
    n_sw = int(round(step_s / DT))
    for side, x, y in footholds:
        other = "R" if side == "L" else "L"
        a, b = pos[side][-1], np.array([x, y], float)
        u = 0.5 - 0.5 * np.cos(np.pi * np.arange(1, n_sw + 1) / n_sw)
        for k, f in enumerate(u):
            pos[side].append(a + f * (b - a))
            swing[side].append(k < n_sw - 1)
            pos[other].append(pos[other][-1] + [0.001, 0.0])
            swing[other].append(False)
        for _ in range(int(round(stand_s / DT))):
            for s in ("L", "R"):
                pos[s].append(pos[s][-1] + [0.001, 0.0])
                swing[s].append(False)
    rows = []
    for s in ("L", "R"):
        p = np.array(pos[s])
        v = np.gradient(p, DT, axis=0)
        for k in range(len(p)):
            rows.append((k, k * DT, s, p[k, 0], p[k, 1], v[k, 0], v[k, 1], swing[s][k]))
    out = pd.DataFrame(rows, columns=["k", "t_sensor_s", "side", "x_m", "y_m", "vx_mps",
                                      "vy_mps", "swing"])
    return out.sort_values(["k", "side"]).reset_index(drop=True)
