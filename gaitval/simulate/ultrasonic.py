"""Simulated treadmill and pendulum trials of the ultrasonic gait system (seed 003).

What is simulated, and where things sit
---------------------------------------
*Ultrasonic frame* (the paper's Fig. 1a): X = direction of progression, Y = vertical (up),
Z = X x Y (lateral, pointing to the subject's right).  The four receivers (anchors) sit at
the paper's positions ``p1 = 0``, ``p2 = (0.324, 0, 0)``, ``p3 = (0.324, 0.230, 0)``,
``p4 = (0, 0.230, 0)`` m: a vertical 0.324 x 0.230 m board standing on the floor beside the
treadmill, to the right of the subject, facing the transmitter strapped to the lateral side of
the right heel (the paper: "the transmitter ... pointing towards the four anchors").  The
transmitter therefore moves at Z < 0 (about -0.3 m); a planar array has a mirror solution at
Z > 0, which the tracker excludes by its initial guess.

*Field (mocap) frame*: x along the treadmill (walking direction), y left, z up, z = 0 on the
belt surface (a flush-mounted treadmill; a raised belt only shifts z).  The board's pose in
the field is drawn per study: origin near ``(-0.16, -0.40, 0.0)`` m and a yaw
misalignment of up to 2 degrees, so the ultrasonic frame is *not* the mocap frame.  The
receivers carry markers ``ANC1..ANC4`` (marker centre on the acoustic centre), so the
pipeline recovers the board pose by a rigid fit; the pose is never given to it.

*Heel on a treadmill* (right foot; the left foot is the same model half a cycle later):
a footstep plan of strides with subject-specific duration at each belt speed
(population curve through the paper's Table 8 means, scaled by leg length) and
stride-to-stride variability (CV ~2 %), plus a slow random wander of the foot-strike
position along the belt.  Within stride j (heel strike at ``u = 0``):

* loading and mid-stance, ``0 <= u < u_ho``: the heel rides on the belt backwards at the
  belt speed; the foot pitch goes from dorsiflexed (-0.3 rad) to flat in the first 10 %;
* heel rise, ``u_ho <= u < u_to``: the foot rotates about the metatarsal heads, which still
  move with the belt; pitch ``theta = theta_to s^2`` (heel accelerating upward);
* swing, ``u_to <= u < 1``: cubic Hermite arcs in x and z from the toe-off state (position,
  velocity) to the next foot strike, arriving slightly retracting (vx = -0.2 v) and
  descending (vz = -0.2 m/s): forward arc with heel lift (peak ~0.2 m).

The transmitter is rigidly attached to the heel (acoustic centre 2 cm forward, 4 cm lateral,
1 cm up of the posterior heel point ``RHEE``); its camera marker ``TX`` sits on the housing
within 4 mm (per axis, drawn per trial) of the acoustic centre and turns with the foot,
so the camera reference and the ultrasonic ranges do not see exactly the same point; toe markers
follow from the foot pitch.  (Pendulum trials: the marker is aligned with the transducer
head to within 2 mm, as the paper built that experiment to do.)

*Ranging*: time of flight with the speed of sound of dry air ``331.3 sqrt(1 + T/273.15)``
(the physics; the pipeline uses the paper's linear eq. (2), ``331.5 + 0.6 T``, whose
0.1 % error at room temperature is part of what it must live with), Gaussian noise with the
paper's ``V = diag(11, 9.3, 9, 9) mm^2`` converted to seconds, a 1 us counter tick,
occasional multipath (a late echo: path longer by 0.05-0.5 m, probability
``multipath_prob`` per anchor and sample) and missing echoes (``dropout_prob``).  Air
temperature drifts slowly around 22-26 degC and is logged with 0.0625 degC resolution.

*Clocks*: the ultrasonic log starts between 1.5 s before and 3 s after the mocap capture
(and may outlast it by up to 1 s), on its own clock:
``t_us = clock_offset_s + (1 + clock_drift_ppm 1e-6) t_mocap`` with drift up to 10 ppm
(the common brief's convention).  The pipeline must find the offset by cross-correlation.

*Mocap*: 200 Hz, 0.4 mm noise per coordinate (the paper's reference accuracy
0.43 +- 0.18 mm), occasional short TX gaps (one per ~20 s, 10-100 ms).

*Pendulum trials* (seed 003 §4.3): the transmitter (with a marker on it) at the end of a
0.50-0.60 m wooden pendulum pivoting about a horizontal axis, swinging in a plane parallel
to the board about 0.3 m in front of it; held at 25-35 degrees, released after 1 s and left
to swing (nonlinear pendulum, damping ratio 0.03) for ``pendulum_duration_s``.

Truth (for tests only, never read by the pipeline) goes to ``out_dir/truth/<trial>/``:
``tx.parquet`` (true transmitter path in field and ultrasonic frames on the mocap clock,
100 Hz, float32 coordinates),
``strides.csv`` (true right-heel strikes, durations, belt-relative stride lengths) and
``meta.json`` (clock offset and drift, board pose, noise settings); and one row per trial
in ``out_dir/truth/ultrasonic_truth.csv``.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.io.c3d import write_c3d
from gaitval.io.ultrasonic import write_ultrasonic
from gaitval.types import UltrasonicLog

#: The paper's receiver positions p1..p4 (m) in the ultrasonic frame (seed 003 §4.1).
PAPER_ANCHORS = np.array([[0.0, 0.0, 0.0], [0.324, 0.0, 0.0], [0.324, 0.230, 0.0],
                          [0.0, 0.230, 0.0]])
ANCHOR_IDS = ["ANC1", "ANC2", "ANC3", "ANC4"]
#: The paper's measurement noise V = diag(11, 9.3, 9, 9) mm^2 (seed 003 §4.3.2), in m^2.
PAPER_V_M2 = np.array([11.0, 9.3, 9.0, 9.0]) * 1e-6
#: Population stride duration (s) at the belt speeds of the paper's Table 8.
_T_OF_SPEED = (np.array([0.54, 0.99, 1.40]), np.array([1.645, 1.180, 1.006]))

DEFAULTS: dict = {
    "study": "default",
    "n_subjects": 10,
    "speeds": {"slow": 0.54, "normal": 0.99, "fast": 1.40},
    "duration_s": 300.0,
    "n_pendulum_trials": 5,
    "pendulum_duration_s": 20.0,
    "mocap_rate_hz": 200.0,
    "us_rate_hz": 50.0,
    "noise_V_m2": PAPER_V_M2.tolist(),
    "multipath_prob": 0.005,
    "dropout_prob": 0.002,
    "mocap_noise_m": 0.0004,
    "stride_cv": 0.02,
    "pendulum_marker_offset_m": 0.002,
    "folder": "ultrasonic",
}

_FOOT_MARKERS = ["RHEE", "RTOE", "LHEE", "LTOE"]


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


def _hermite(s, p0, v0, p1, v1, D):
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * D * v0
            + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * D * v1)


def _smooth(u):
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def stride_plan(rng: np.random.Generator, duration_s: float, T_mean: float, v: float,
                cv: float, t0: float) -> dict:
    """Foot-strike times and places of one foot on the treadmill (field x, metres)."""
    n = int(np.ceil((duration_s + 2.0 - t0) / (T_mean * (1 - 3 * cv)))) + 5
    T = T_mean * (1.0 + cv * rng.standard_normal(n))
    # the plan starts three strides before t0 so that the whole ultrasonic log (which may
    # start before the capture) lies inside it
    t_hs = t0 - T[0] - T[1] - T[2] + np.concatenate([[0.0], np.cumsum(T)])
    # slow wander of the strike position along the belt (AR(1), sd 3 cm)
    wander = np.zeros(n + 1)
    for j in range(1, n + 1):
        wander[j] = 0.9 * wander[j - 1] + np.sqrt(1 - 0.81) * 0.03 * rng.standard_normal()
    x_hs = 0.15 + wander
    return {"t_hs": t_hs, "x_hs": x_hs, "v": v,
            "u_ho": np.clip(0.34 + 0.02 * rng.standard_normal(n), 0.25, 0.45),
            "u_to": np.clip(0.61 + 0.01 * rng.standard_normal(n), 0.56, 0.66),
            "theta_to": np.clip(0.85 + 0.05 * rng.standard_normal(n), 0.6, 1.1),
            "z_h": 0.045, "L_h": 0.18, "L_f": 0.20, "theta_hs": -0.30}


def heel_path(t: np.ndarray, plan: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Posterior-heel position (x, z in the field) and foot pitch at times ``t``."""
    t_hs, x_hs, v = plan["t_hs"], plan["x_hs"], plan["v"]
    z_h, L_h = plan["z_h"], plan["L_h"]
    j = np.clip(np.searchsorted(t_hs, t, side="right") - 1, 0, len(t_hs) - 2)
    T = t_hs[j + 1] - t_hs[j]
    tau = t - t_hs[j]
    u = tau / T
    u_ho, u_to, th_to = plan["u_ho"][j], plan["u_to"][j], plan["theta_to"][j]
    th_hs = plan["theta_hs"]
    x = np.empty_like(t)
    z = np.empty_like(t)
    th = np.empty_like(t)
    # stance on the belt
    a = u < u_ho
    x[a] = x_hs[j[a]] - v * tau[a]
    z[a] = z_h
    th[a] = th_hs * (1.0 - _smooth(u[a] / 0.1))
    # heel rise about the metatarsal heads (which move with the belt)
    b = (u >= u_ho) & (u < u_to)
    s = (u[b] - u_ho[b]) / (u_to[b] - u_ho[b])
    thb = th_to[b] * s * s
    x[b] = x_hs[j[b]] - v * tau[b] + L_h - L_h * np.cos(thb)
    z[b] = z_h + L_h * np.sin(thb)
    th[b] = thb
    # swing: Hermite arcs from the toe-off state to the next strike
    c = u >= u_to
    jc = j[c]
    Tc = T[c]
    tau0 = u_to[c] * Tc
    dth = 2.0 * th_to[c] / ((u_to[c] - u_ho[c]) * Tc)
    x0 = x_hs[jc] - v * tau0 + L_h - L_h * np.cos(th_to[c])
    vx0 = -v + L_h * np.sin(th_to[c]) * dth
    z0 = z_h + L_h * np.sin(th_to[c])
    vz0 = L_h * np.cos(th_to[c]) * dth
    D = Tc - tau0
    sc = (tau[c] - tau0) / D
    x[c] = _hermite(sc, x0, vx0, x_hs[jc + 1], -0.2 * v, D)
    z[c] = _hermite(sc, z0, vz0, z_h, -0.2, D)
    th[c] = th_to[c] + (th_hs - th_to[c]) * _smooth(sc)
    return x, z, th


def foot_points(t: np.ndarray, plan: dict, y0: float, rng_phase: float, side: str,
                marker_offset: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Field positions (n, 3) of the heel, toe and (right foot) transmitter at ``t``.

    ``TXA`` is the transmitter's acoustic centre (what the ranges measure), ``TX`` the
    camera marker on it, ``marker_offset`` (forward, lateral-right, up; metres, foot frame)
    away from the acoustic centre.
    """
    x, z, th = heel_path(t, plan)
    period = float(np.median(np.diff(plan["t_hs"])))
    y = y0 + 0.008 * np.sin(2 * np.pi * t / period + rng_phase)
    heel = np.column_stack([x, y, z])
    c, s = np.cos(th), np.sin(th)
    L_f = plan["L_f"]
    toe = np.column_stack([x + L_f * c, y, z - L_f * s + 0.02])
    out = {f"{side}HEE": heel, f"{side}TOE": toe}
    if side == "R":
        # transmitter: 2 cm forward, 1 cm up (foot frame, pitch th), 4 cm to the right
        fx, fz = 0.02, 0.01
        out["TXA"] = np.column_stack([x + fx * c + fz * s, y - 0.04, z - fx * s + fz * c])
        mo = np.zeros(3) if marker_offset is None else np.asarray(marker_offset, float)
        out["TX"] = out["TXA"] + np.column_stack([mo[0] * c + mo[2] * s,
                                                  np.full_like(x, -mo[1]),
                                                  -mo[0] * s + mo[2] * c])
    return out


def _ranges_to_tof(d_true: np.ndarray, temp_c: np.ndarray, rng: np.random.Generator,
                   V_m2: np.ndarray, multipath_prob: float, dropout_prob: float
                   ) -> tuple[np.ndarray, dict]:
    """True ranges -> logged times of flight (noise, multipath, dropouts, 1 us tick)."""
    n, m = d_true.shape
    c = speed_of_sound_true(temp_c)[:, None]
    d = d_true + rng.standard_normal((n, m)) * np.sqrt(V_m2)[None, :]
    mp = rng.random((n, m)) < multipath_prob
    d = d + mp * rng.uniform(0.05, 0.5, size=(n, m))
    tof = np.round(d / c * 1e6) * 1e-6                       # 16-bit counter, 1 us tick
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


def _write_trial(out_dir: Path, folder: str, trial: str, labels, xyz, mocap_rate, log,
                 truth_tx: pd.DataFrame, truth_meta: dict, strides: pd.DataFrame | None
                 ) -> tuple[str, str]:
    c3d_rel = f"{folder}/{trial}.c3d"
    us_rel = f"{folder}/{trial}.us.parquet"
    write_c3d(out_dir / c3d_rel, labels, xyz, mocap_rate)
    write_ultrasonic(out_dir / us_rel, log, transmitter="right heel" if strides is not None
                     else "pendulum", sensor_model="simulated 40 kHz TOA system (seed 003)")
    tdir = out_dir / "truth" / trial
    step = max(1, int(round(mocap_rate / 100.0)))       # truth path at 100 Hz, float32
    small = truth_tx.iloc[::step].reset_index(drop=True)
    small = small.astype({c: np.float32 for c in small.columns if c != "t_s"})
    write_parquet(small, tdir / "tx.parquet")
    write_text(tdir / "meta.json", json.dumps(truth_meta, indent=1, sort_keys=True) + "\n")
    if strides is not None:
        write_csv(strides, tdir / "strides.csv", float_format="%.6f")
    return c3d_rel, us_rel


def _subjects(rng: np.random.Generator, n: int) -> pd.DataFrame:
    rows = []
    for i in range(n):
        h = float(np.clip(rng.normal(1.714, 0.065), 1.55, 1.90))
        sex = "M" if rng.random() < 0.6 else "F"
        leg = 0.53 * h * (1 + 0.02 * rng.standard_normal())
        rows.append({"subject": f"US{i + 1:02d}", "group": "adult",
                     "age_y": float(np.round(rng.normal(25.7, 1.4), 0)), "sex": sex,
                     "height_m": round(h, 3),
                     "mass_kg": round(float(np.clip(rng.normal(62.8, 5.6), 45, 90)), 1),
                     "leg_width_m": round(float(rng.uniform(0.095, 0.115)), 3),
                     "knee_width_m": round(float(rng.uniform(0.095, 0.11)), 3),
                     "ankle_width_m": round(float(rng.uniform(0.065, 0.075)), 3),
                     "leg_length_m": round(leg, 3), "shank_length_m": round(0.246 * h, 3),
                     "stick": False})
    return pd.DataFrame(rows)


def _trial_row(cfg, protocol, subject, trial, c3d_rel, us_rel, speed="", speed_mps=np.nan,
               repetition=1):
    return {"study": cfg["study"], "protocol": protocol, "subject": subject, "trial": trial,
            "sensor_kind": "ultrasonic", "mocap_file": c3d_rel, "sensor_file": us_rel,
            "sensor_topic": "", "annotation_file": "", "sensor_height_m": np.nan,
            "clock_offset_s": np.nan, "speed": speed, "speed_mps": speed_mps,
            "stick": False, "scenario": "", "repetition": repetition}


def simulate_treadmill_trial(rng: np.random.Generator, cfg: dict, subject: dict,
                             speed_mps: float, R: np.ndarray, o: np.ndarray):
    """One treadmill trial in memory: mocap (labels, xyz), log, truth tables."""
    dur, rate, us_rate = cfg["duration_s"], cfg["mocap_rate_hz"], cfg["us_rate_hz"]
    T_pop = float(np.interp(speed_mps, *_T_OF_SPEED))
    T_mean = T_pop * np.sqrt(subject["leg_length_m"] / (0.53 * 1.714)) * subject["_t_factor"]
    cv = cfg["stride_cv"] * (1.3 if speed_mps < 0.7 else 1.0)
    t0 = rng.uniform(0.0, T_mean)
    plan_r = stride_plan(rng, dur, T_mean, speed_mps, cv, t0=t0)
    plan_l = stride_plan(rng, dur, T_mean, speed_mps, cv, t0=t0 + 0.5 * T_mean)
    phase = rng.uniform(0, 2 * np.pi)
    y_r = -0.075 + 0.01 * rng.standard_normal()

    t_m = np.arange(int(round(dur * rate))) / rate
    # the camera marker is "approximately in alignment with the transmitter head"
    # (seed 003 §4.3): placed by hand on the housing, within 4 mm of the acoustic centre
    # per axis; it turns with the foot, so its offset from the acoustic centre in the
    # ultrasonic frame changes over the gait cycle
    marker_offset = rng.uniform(-0.004, 0.004, 3)
    pts = foot_points(t_m, plan_r, y_r, phase, "R", marker_offset)
    pts.update(foot_points(t_m, plan_l, y_r + 0.15, phase + np.pi, "L"))
    anchors_f = _to_field(PAPER_ANCHORS, R, o)
    labels = ["TX"] + ANCHOR_IDS + _FOOT_MARKERS
    xyz = np.empty((len(t_m), len(labels), 3))
    xyz[:, 0] = pts["TX"]
    xyz[:, 1:5] = anchors_f[None, :, :]
    for k, lab in enumerate(_FOOT_MARKERS):
        xyz[:, 5 + k] = pts[lab]
    xyz = _mocap_noise_and_gaps(rng, xyz, labels, rate, cfg["mocap_noise_m"])

    t_us, t_true, offset, drift = _clock(rng, dur, us_rate)
    tx_us_t = foot_points(t_true, plan_r, y_r, phase, "R")["TXA"]
    d_true = np.linalg.norm(tx_us_t[:, None, :] - anchors_f[None], axis=2)
    temp_true, temp_log = _temperature(rng, t_us)
    tof, counts = _ranges_to_tof(d_true, temp_true, rng, np.asarray(cfg["noise_V_m2"]),
                                 cfg["multipath_prob"], cfg["dropout_prob"])

    t_hs = plan_r["t_hs"]
    keep = (t_hs[:-1] >= 0) & (t_hs[1:] <= dur)
    T = np.diff(t_hs)
    strides = pd.DataFrame({
        "stride": np.arange(int(keep.sum())),
        "t_hs_s": t_hs[:-1][keep], "duration_s": T[keep],
        # belt-relative stride length: belt travel plus the change of strike position
        "length_m": (speed_mps * T + np.diff(plan_r["x_hs"]))[keep]})
    tx_f = pts["TXA"]                                    # truth: the acoustic centre
    tx_u = _to_us_frame(tx_f, R, o)
    truth_tx = pd.DataFrame({"t_s": t_m, "x_m": tx_f[:, 0], "y_m": tx_f[:, 1],
                             "z_m": tx_f[:, 2], "xu_m": tx_u[:, 0], "yu_m": tx_u[:, 1],
                             "zu_m": tx_u[:, 2]})
    meta = {"clock_offset_s": offset, "clock_drift_ppm": drift, **counts,
            "speed_mps": speed_mps, "marker_offset_m": marker_offset.tolist(), "stride_duration_mean_s": float(T_mean),
            "board_R": R.tolist(), "board_origin_m": o.tolist(),
            "noise_V_m2": list(map(float, cfg["noise_V_m2"]))}
    return labels, xyz, _anchor_log(t_us, tof, temp_log, ""), truth_tx, meta, strides


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


def simulate_pendulum_trial(rng: np.random.Generator, cfg: dict, R: np.ndarray,
                            o: np.ndarray):
    """One pendulum trial (seed 003 §4.3) in memory."""
    dur, rate, us_rate = cfg["pendulum_duration_s"], cfg["mocap_rate_hz"], cfg["us_rate_hz"]
    L = rng.uniform(0.50, 0.60)
    pivot_u = np.array([0.162 + rng.uniform(-0.02, 0.02), L + rng.uniform(0.10, 0.14),
                        -0.30 + rng.uniform(-0.02, 0.02)])
    tilt = np.deg2rad(rng.uniform(-3, 3))                   # swing plane vs the board
    theta0 = np.deg2rad(rng.uniform(25, 35)) * (1 if rng.random() < 0.5 else -1)
    t_rel = 1.0

    def tx_at(th):
        s = L * np.sin(th)
        p = np.column_stack([pivot_u[0] + s * np.cos(tilt), pivot_u[1] - L * np.cos(th),
                             pivot_u[2] + s * np.sin(tilt)])
        return p

    t_m = np.arange(int(round(dur * rate))) / rate
    t_us, t_true, offset, drift = _clock(rng, dur, us_rate)
    # one integration of the swing for both clocks' sample instants
    th_all = _pendulum_theta(np.concatenate([t_m, t_true]), L, theta0, 0.03, t_rel)
    th_m = th_all[:len(t_m)]
    tx_u = tx_at(th_m)
    # marker within 2 mm of the transducer head, fixed on the arm (radial, tangential, z)
    mo = rng.uniform(-1.0, 1.0, 3) * float(cfg["pendulum_marker_offset_m"])
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
    d_true = np.linalg.norm(p_true[:, None, :] - PAPER_ANCHORS[None], axis=2)
    temp_true, temp_log = _temperature(rng, t_us)
    tof, counts = _ranges_to_tof(d_true, temp_true, rng, np.asarray(cfg["noise_V_m2"]),
                                 cfg["multipath_prob"], cfg["dropout_prob"])
    truth_tx = pd.DataFrame({"t_s": t_m, "x_m": tx_f[:, 0], "y_m": tx_f[:, 1],
                             "z_m": tx_f[:, 2], "xu_m": tx_u[:, 0], "yu_m": tx_u[:, 1],
                             "zu_m": tx_u[:, 2]})
    meta = {"clock_offset_s": offset, "clock_drift_ppm": drift, **counts,
            "pendulum_length_m": L, "theta0_rad": theta0, "release_s": t_rel,
            "marker_offset_m": mo.tolist(),
            "board_R": R.tolist(), "board_origin_m": o.tolist(),
            "noise_V_m2": list(map(float, cfg["noise_V_m2"]))}
    return labels, xyz, _anchor_log(t_us, tof, temp_log, ""), truth_tx, meta


def generate_ultrasonic(out_dir: Path, cfg: dict | None = None, seed: int = 0
                        ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Write the treadmill and pendulum trials of the ultrasonic study (seed 003).

    Parameters
    ----------
    out_dir : Path
        Study folder; files go to ``out_dir/<folder>/`` and truth to ``out_dir/truth/``.
    cfg : dict, optional
        Keys (defaults in :data:`DEFAULTS`): ``study`` ("default"), ``n_subjects`` (10),
        ``speeds`` ({slow: 0.54, normal: 0.99, fast: 1.40} m/s), ``duration_s`` (300),
        ``n_pendulum_trials`` (5), ``pendulum_duration_s`` (20), ``mocap_rate_hz`` (200),
        ``us_rate_hz`` (50), ``noise_V_m2`` (the paper's V), ``multipath_prob`` (0.005),
        ``dropout_prob`` (0.002), ``mocap_noise_m`` (0.0004), ``stride_cv`` (0.02),
        ``pendulum_marker_offset_m`` (0.002: largest per-axis offset of the pendulum's
        camera marker from the transducer head), ``folder`` ("ultrasonic").
    seed : int
        Seed of ``np.random.default_rng``; each trial gets its own child stream, so the
        same seed gives byte-identical files.

    Returns
    -------
    trials : DataFrame
        Trial-sheet rows (columns of the common brief), paths relative to ``out_dir``;
        protocols ``treadmill`` and ``pendulum``, sensor_kind ``ultrasonic``.
    subjects : DataFrame
        Subject-table rows: ``US01..`` (adults like the paper's: 25.7 +- 1.4 y,
        1.714 +- 0.065 m, 62.8 +- 5.6 kg) and a ``pendulum`` row for the pendulum trials
        (``leg_width_m`` is the pendulum arm's width; the subject table requires it).
    """
    cfg = {**DEFAULTS, **(cfg or {})}
    out_dir = Path(out_dir)
    root = np.random.SeedSequence(seed)
    s_subj, s_board, s_trials, s_pend = root.spawn(4)
    subjects = _subjects(np.random.default_rng(s_subj), int(cfg["n_subjects"]))
    R, o = board_pose(np.random.default_rng(s_board))
    t_factor = np.exp(0.04 * np.random.default_rng(s_subj.spawn(1)[0]).standard_normal(
        len(subjects)))
    rows, truth_rows = [], []
    speeds = dict(cfg["speeds"])
    trial_seeds = s_trials.spawn(len(subjects) * len(speeds))
    k = 0
    for si, sub in subjects.iterrows():
        sub = {**sub.to_dict(), "_t_factor": float(t_factor[si])}
        for name, v_nom in speeds.items():
            rng = np.random.default_rng(trial_seeds[k])
            k += 1
            v = float(round(v_nom + 0.03 * rng.standard_normal(), 3))
            trial = f"us_{sub['subject']}_{name}"
            labels, xyz, log, truth_tx, meta, strides = simulate_treadmill_trial(
                rng, cfg, sub, v, R, o)
            log.meta["trial"] = trial
            c3d_rel, us_rel = _write_trial(out_dir, cfg["folder"], trial, labels, xyz,
                                           cfg["mocap_rate_hz"], log, truth_tx, meta, strides)
            rows.append(_trial_row(cfg, "treadmill", sub["subject"], trial, c3d_rel, us_rel,
                                   name, v))
            truth_rows.append({"trial": trial, "clock_offset_s": meta["clock_offset_s"],
                               "clock_drift_ppm": meta["clock_drift_ppm"],
                               "n_multipath": meta["n_multipath"],
                               "n_dropout": meta["n_dropout"]})
    pend_seeds = s_pend.spawn(int(cfg["n_pendulum_trials"]))
    for i, ps in enumerate(pend_seeds):
        rng = np.random.default_rng(ps)
        trial = f"us_pendulum_{i + 1:02d}"
        labels, xyz, log, truth_tx, meta = simulate_pendulum_trial(rng, cfg, R, o)
        log.meta["trial"] = trial
        c3d_rel, us_rel = _write_trial(out_dir, cfg["folder"], trial, labels, xyz,
                                       cfg["mocap_rate_hz"], log, truth_tx, meta, None)
        rows.append(_trial_row(cfg, "pendulum", "pendulum", trial, c3d_rel, us_rel,
                               repetition=i + 1))
        truth_rows.append({"trial": trial, "clock_offset_s": meta["clock_offset_s"],
                           "clock_drift_ppm": meta["clock_drift_ppm"],
                           "n_multipath": meta["n_multipath"], "n_dropout": meta["n_dropout"]})
    write_csv(pd.DataFrame(truth_rows), out_dir / "truth" / "ultrasonic_truth.csv",
              float_format="%.9g")
    if int(cfg["n_pendulum_trials"]) > 0:
        subjects = pd.concat([subjects, pd.DataFrame([{
            "subject": "pendulum", "group": "", "age_y": np.nan, "sex": "",
            "height_m": np.nan, "mass_kg": np.nan, "leg_width_m": 0.05,
            "knee_width_m": np.nan, "ankle_width_m": np.nan, "leg_length_m": np.nan,
            "shank_length_m": np.nan, "stick": False}])], ignore_index=True)
    return pd.DataFrame(rows), subjects
