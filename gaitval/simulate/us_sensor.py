"""The simulated ultrasonic system and what it records (seed 003): board, ranging, clocks.

Shared by the treadmill (:mod:`gaitval.simulate.us_treadmill`) and pendulum
(:mod:`gaitval.simulate.us_pendulum`) trials of :mod:`gaitval.simulate.ultrasonic`, whose
notes describe the frames and the error model: the receiver board and its pose in the
field, the speed of sound of dry air (the simulator's physics, not the pipeline's linear
eq. (2)), true ranges to logged times of flight (noise, multipath, dropouts, 1 us tick),
the logged air temperature, the ultrasonic log's clock, and the camera's noise and gaps.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.io.ultrasonic import distance_to_tof
from gaitval.types import UltrasonicLog

#: The paper's receiver positions p1..p4 (m) in the ultrasonic frame (seed 003 §4.1).
PAPER_ANCHORS = np.array([[0.0, 0.0, 0.0], [0.324, 0.0, 0.0], [0.324, 0.230, 0.0],
                          [0.0, 0.230, 0.0]])
ANCHOR_IDS = ["ANC1", "ANC2", "ANC3", "ANC4"]
#: The paper's measurement noise V = diag(11, 9.3, 9, 9) mm^2 (seed 003 §4.3.2), in m^2.
PAPER_V_M2 = np.array([11.0, 9.3, 9.0, 9.0]) * 1e-6


def speed_of_sound_true(temp_c):
    """Speed of sound in dry air (m/s): ``331.3 sqrt(1 + T/273.15)`` (the simulator's physics)."""
    return C.SPEED_OF_SOUND_0C * np.sqrt(1.0 + np.asarray(temp_c) / C.KELVIN_0C)


def board_pose(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Draw the receiver board's pose: rotation ``R`` (ultrasonic -> field) and origin ``o``."""
    psi = np.deg2rad(rng.uniform(-2.0, 2.0))
    ex = np.array([np.cos(psi), np.sin(psi), 0.0])          # X_u: progression
    ey = np.array([0.0, 0.0, 1.0])                          # Y_u: vertical
    ez = np.cross(ex, ey)                                   # Z_u = X_u x Y_u (right)
    R = np.column_stack([ex, ey, ez])
    o = np.array([-0.162 + rng.uniform(-0.03, 0.03), -0.40 + rng.uniform(-0.03, 0.03),
                  rng.uniform(0.0, 0.01)])
    return R, o


def _ranges_to_tof(d_true: np.ndarray, temp_c: np.ndarray, rng: np.random.Generator,
                   V_m2: np.ndarray, multipath_prob: float, dropout_prob: float
                   ) -> tuple[np.ndarray, dict]:
    """True ranges -> logged times of flight (noise, multipath, dropouts, 1 us tick)."""
    n, m = d_true.shape
    d = d_true + rng.standard_normal((n, m)) * np.sqrt(V_m2)[None, :]
    mp = rng.random((n, m)) < multipath_prob
    d = d + mp * rng.uniform(0.05, 0.5, size=(n, m))
    tof = distance_to_tof(d, temp_c, speed=speed_of_sound_true)      # seed003 eq. (1)
    tof = np.round(tof * 1e6) * 1e-6                         # 16-bit counter, 1 us tick
    drop = rng.random((n, m)) < dropout_prob
    tof[drop] = np.nan
    return tof, {"n_multipath": int(mp.sum()), "n_dropout": int(drop.sum())}


def _temperature(rng: np.random.Generator, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    T0 = rng.uniform(22.0, 26.0)
    drift = rng.uniform(-0.5, 0.5) * (t - t[0]) / max(t[-1] - t[0], 1.0)
    true = T0 + drift
    logged = np.round((true + 0.05 * rng.standard_normal(len(t))) / 0.0625) * 0.0625
    return true, logged


def _mocap_noise_and_gaps(rng, xyz: np.ndarray, labels: list[str], rate: float,
                          sigma: float) -> np.ndarray:
    xyz = xyz + sigma * rng.standard_normal(xyz.shape)
    n = xyz.shape[0]
    dur = n / rate
    for lab in ("TX", "RHEE", "RTOE", "LHEE", "LTOE"):
        if lab not in labels:
            continue
        i = labels.index(lab)
        for _ in range(rng.poisson(dur / 20.0)):
            start = int(rng.integers(0, n))
            length = int(rng.integers(2, 21))
            xyz[start:start + length, i] = np.nan
    return xyz


def _clock(rng: np.random.Generator, duration_s: float, us_rate: float):
    # the operator starts and stops the two systems by hand: the log may start up to 1.5 s
    # before or 3 s after the capture, and stop up to 1 s after or 1.5 s before it
    start = rng.uniform(-1.5, 3.0)
    stop = duration_s - rng.uniform(-1.0, 1.5)
    drift_ppm = rng.uniform(-10.0, 10.0)
    offset = -(1.0 + drift_ppm * 1e-6) * start               # t_us = 0 at t_mocap = start
    n = int(np.floor((stop - start) * us_rate))
    t_us = np.arange(n) / us_rate
    t_mocap = (t_us - offset) / (1.0 + drift_ppm * 1e-6)
    return t_us, t_mocap, offset, drift_ppm


def _to_us_frame(p_field: np.ndarray, R: np.ndarray, o: np.ndarray) -> np.ndarray:
    return (p_field - o) @ R


def _to_field(p_us: np.ndarray, R: np.ndarray, o: np.ndarray) -> np.ndarray:
    return p_us @ R.T + o


def _anchor_log(t_us, tof, temp_logged, trial: str) -> UltrasonicLog:
    anchors = pd.DataFrame({"anchor": ANCHOR_IDS, "x_m": PAPER_ANCHORS[:, 0],
                            "y_m": PAPER_ANCHORS[:, 1], "z_m": PAPER_ANCHORS[:, 2]})
    return UltrasonicLog(t=t_us, temperature_c=temp_logged, anchors=anchors, tof_s=tof,
                         meta={"trial": trial, "frame": "seed003: X progression, Y up, "
                               "Z = X x Y (lateral)"})
