"""Simulated pendulum trials of the ultrasonic study (seed 003 §4.3).

The transmitter (with a marker on it) at the end of a wooden pendulum swinging in a plane
parallel to the receiver board, as described in the notes of
:mod:`gaitval.simulate.ultrasonic`: the pendulum with its marker, built once per study
(:func:`pendulum_apparatus`), the nonlinear damped swing (:func:`_pendulum_theta`) and one
release as a whole trial in memory (:func:`simulate_pendulum_trial`).

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.simulate.us_sensor import (ANCHOR_IDS, PAPER_ANCHORS, _anchor_log, _clock,
                                        _ranges_to_tof, _temperature, _to_field,
                                        received_amplitude)

def _pendulum_theta(t: np.ndarray, L: float, theta0: float, zeta: float, t_release: float
                    ) -> np.ndarray:
    from scipy.integrate import solve_ivp

    g = 9.81
    w = np.sqrt(g / L)

    def f(_, s):
        return [s[1], -w * w * np.sin(s[0]) - 2 * zeta * w * s[1]]

    t_end = max(float(t.max()) - t_release, 0.0) + 0.1
    sol = solve_ivp(f, (0.0, t_end), [theta0, 0.0], method="DOP853", rtol=1e-9,
                    atol=1e-11, dense_output=True)
    tau = np.clip(t - t_release, 0.0, None)
    return sol.sol(tau)[0]


def pendulum_apparatus(rng: np.random.Generator, cfg: dict) -> dict:
    """The pendulum and its camera marker, built once (seed 003 §4.3: "A wooden pendulum was
    constructed ... a reflective marker was also located approximately in alignment with the
    ultrasonic transmitter head ... This action was repeated M times").

    Returns ``length_m``, ``pivot_u`` (pivot in the ultrasonic frame, m), ``tilt_rad`` (swing
    plane against the board) and ``marker_offset_m`` (radial, tangential, lateral offset of
    the marker from the transducer head, within ``pendulum_marker_offset_m`` per axis).
    """
    L = rng.uniform(0.50, 0.60)
    dist = float(cfg.get("pendulum_board_distance_m", 0.30))
    pivot_u = np.array([0.162 + rng.uniform(-0.02, 0.02), L + rng.uniform(0.10, 0.14),
                        -dist + rng.uniform(-0.02, 0.02)])
    tilt = np.deg2rad(rng.uniform(-3, 3))                   # swing plane vs the board
    mo = rng.uniform(-1.0, 1.0, 3) * float(cfg["pendulum_marker_offset_m"])
    return {"length_m": float(L), "pivot_u": pivot_u, "tilt_rad": float(tilt),
            "marker_offset_m": mo}


def simulate_pendulum_trial(rng: np.random.Generator, cfg: dict, R: np.ndarray,
                            o: np.ndarray, apparatus: dict | None = None):
    """One release of the pendulum (seed 003 §4.3) in memory.

    ``apparatus`` (:func:`pendulum_apparatus`) is the study's pendulum, shared by its
    trials; without it the trial builds its own from ``rng``.
    """
    dur, rate, us_rate = cfg["pendulum_duration_s"], cfg["mocap_rate_hz"], cfg["us_rate_hz"]
    app = pendulum_apparatus(rng, cfg) if apparatus is None else apparatus
    L, pivot_u, tilt = app["length_m"], np.asarray(app["pivot_u"]), app["tilt_rad"]
    mo = np.asarray(app["marker_offset_m"], dtype=float)
    lo, hi = cfg.get("pendulum_release_deg", (25.0, 35.0))
    theta0 = np.deg2rad(rng.uniform(lo, hi)) * (1 if rng.random() < 0.5 else -1)
    zeta = float(cfg.get("pendulum_damping_ratio", 0.03))
    t_rel = 1.0

    def tx_at(th):
        s = L * np.sin(th)
        p = np.column_stack([pivot_u[0] + s * np.cos(tilt), pivot_u[1] - L * np.cos(th),
                             pivot_u[2] + s * np.sin(tilt)])
        return p

    t_m = np.arange(int(round(dur * rate))) / rate
    t_us, t_true, offset, drift = _clock(rng, dur, us_rate)
    # one integration of the swing for both clocks' sample instants
    th_all = _pendulum_theta(np.concatenate([t_m, t_true]), L, theta0, zeta, t_rel)
    th_m = th_all[:len(t_m)]
    tx_u = tx_at(th_m)
    # the marker sits fixed on the arm near the transducer head (radial, tangential, z)
    radial = np.column_stack([np.sin(th_m) * np.cos(tilt), -np.cos(th_m),
                              np.sin(th_m) * np.sin(tilt)])
    tangential = np.column_stack([np.cos(th_m) * np.cos(tilt), np.sin(th_m),
                                  np.cos(th_m) * np.sin(tilt)])
    marker_u = tx_u + mo[0] * radial + mo[1] * tangential + mo[2] * np.array([0, 0, 1.0])
    tx_f = _to_field(tx_u, R, o)
    marker_f = _to_field(marker_u, R, o)
    anchors_f = _to_field(PAPER_ANCHORS, R, o)
    labels = ["TX"] + ANCHOR_IDS
    xyz = np.empty((len(t_m), 5, 3))
    xyz[:, 0] = marker_f
    xyz[:, 1:] = anchors_f[None]
    xyz = xyz + cfg["mocap_noise_m"] * rng.standard_normal(xyz.shape)
    p_true = tx_at(th_all[len(t_m):])
    to_rx = PAPER_ANCHORS[None] - p_true[:, None, :]
    d_true = np.linalg.norm(to_rx, axis=2)
    # the transducer faces the board (its axis, the board's normal, is also the swing's
    # rotation axis, so it keeps facing it); the receivers face back (threshold detection)
    cos_tx = to_rx[..., 2] / d_true
    amp = received_amplitude(d_true, cos_tx, cos_tx)
    temp_true, temp_log = _temperature(rng, t_us)
    tof, counts = _ranges_to_tof(d_true, temp_true, rng, np.asarray(cfg["noise_V_m2"]),
                                 cfg["multipath_prob"], cfg["dropout_prob"], amplitude=amp,
                                 common_fraction=float(cfg.get("noise_common_fraction", 0.0)))
    truth_tx = pd.DataFrame({"t_s": t_m, "x_m": tx_f[:, 0], "y_m": tx_f[:, 1],
                             "z_m": tx_f[:, 2], "xu_m": tx_u[:, 0], "yu_m": tx_u[:, 1],
                             "zu_m": tx_u[:, 2]})
    meta = {"clock_offset_s": offset, "clock_drift_ppm": drift, **counts,
            "pendulum_length_m": L, "theta0_rad": theta0, "release_s": t_rel,
            "marker_offset_m": mo.tolist(),
            "board_R": R.tolist(), "board_origin_m": o.tolist(),
            "noise_V_m2": list(map(float, cfg["noise_V_m2"]))}
    return labels, xyz, _anchor_log(t_us, tof, temp_log, ""), truth_tx, meta
