"""Simulated treadmill trials of the ultrasonic study (seed 003): heel path and markers.

The right heel on a treadmill, as described in the notes of
:mod:`gaitval.simulate.ultrasonic`: a footstep plan of strides (:func:`stride_plan`), the
posterior-heel path and foot pitch through loading, heel rise and swing
(:func:`heel_path`), the heel, toe and transmitter points (:func:`foot_points`), and one
whole trial in memory (:func:`simulate_treadmill_trial`).

Error sources of the paper's set-up added in issue 10 (seed 003 §4.1, §5):

* **stride-to-stride variability of real gait**: stride times are not independent from
  stride to stride but persistently correlated (fractional Gaussian noise, Hurst exponent
  :data:`STRIDE_HURST` = 0.8: the DFA α ≈ 0.75–0.9 of healthy young adults' stride
  intervals, Hausdorff et al. 1995), with the same coefficient of variation as before;
* **strap motion**: the transmitter is held on the heel by an elastic strap (§4.1); each
  heel strike sets the housing oscillating on it, a damped oscillation of 2–4 mm at
  :data:`STRAP_HZ` (ζ = :data:`STRAP_DAMPING`) along the belt and downwards (the motion
  artefact of strap- and skin-mounted sensors after heel strike, Forner-Cordero et al.
  2008).  The camera marker ``TX`` sits on the shoe beside the housing (the paper's
  Fig. 1a: markers on the foot), so it does not share the wobble;
* **transmitter directivity**: the transducer points at the board's centre when the foot
  is flat (§4.1: "pointing towards the four anchors") and turns with the foot's pitch; the
  burst each receiver gets is weaker off both axes, which the threshold detector turns into
  a later detection, a cycle slip or a missed echo (:mod:`gaitval.simulate.us_sensor`).

References
----------
Hausdorff JM, Peng CK, Ladin Z, Wei JY, Goldberger AL. Is walking a random walk? Evidence
for long-range correlations in stride interval of human gait. J Appl Physiol
1995;78:349–358.

Forner-Cordero A, Mateu-Arce M, Forner-Cordero I, Alcántara E, Moreno JC, Pons JL. Study
of the motion artefacts of skin-mounted inertial sensors under different attachment
conditions. Physiol Meas 2008;29:N21–N31.

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
                                        _mocap_noise_and_gaps, _ranges_to_tof, _temperature,
                                        _to_field, _to_us_frame, received_amplitude)

#: Population stride duration (s) at the belt speeds of the paper's Table 8.
_T_OF_SPEED = (np.array([0.54, 0.99, 1.40]), np.array([1.645, 1.180, 1.006]))

_FOOT_MARKERS = ["RHEE", "RTOE", "LHEE", "LTOE"]
#: Hurst exponent of the stride-time fluctuations (persistent; Hausdorff et al. 1995).
STRIDE_HURST = 0.8
#: The strap-held housing after heel strike: amplitude range (m), frequency, damping ratio,
#: and the direction of the first excursion (along the belt, downwards; field x, z).
STRAP_AMPLITUDE_M = (0.002, 0.004)
STRAP_HZ = 15.0
STRAP_DAMPING = 0.25
STRAP_DIRECTION = np.array([0.8, 0.0, -0.6])


def fgn(n: int, hurst: float, rng: np.random.Generator) -> np.ndarray:
    """``n`` samples of unit-variance fractional Gaussian noise (Davies–Harte method).

    Autocovariance ``γ(k) = (|k+1|^{2H} - 2|k|^{2H} + |k-1|^{2H}) / 2``, embedded in a
    circulant of size ``2n`` whose eigenvalues come from one FFT.
    """
    k = np.arange(n + 1, dtype=float)
    g = 0.5 * ((k + 1) ** (2 * hurst) - 2 * k ** (2 * hurst) + np.abs(k - 1) ** (2 * hurst))
    row = np.concatenate([g, g[-2:0:-1]])                  # circulant first row, size 2n
    lam = np.clip(np.fft.fft(row).real, 0.0, None)
    m = len(row)
    z = rng.standard_normal(m) + 1j * rng.standard_normal(m)
    x = np.fft.fft(np.sqrt(lam / m) * z).real[:n]
    return x / max(float(np.std(x)), 1e-12)


def strap_motion(t: np.ndarray, t_hs: np.ndarray, amps: np.ndarray) -> np.ndarray:
    """(n, 3) displacement of the strap-held transmitter from its place on the heel (field).

    After the heel strike at ``t_hs[j]`` (the latest before ``t``):
    ``A_j exp(-ζωτ) sin(ω_d τ) · STRAP_DIRECTION``, ``τ = t - t_hs[j]``,
    ``ω = 2π STRAP_HZ``, ``ω_d = ω sqrt(1 - ζ²)``; earlier strikes have died out (ζω ≈ 24/s).
    """
    j = np.searchsorted(t_hs, t, side="right") - 1
    tau = np.where(j >= 0, t - t_hs[np.clip(j, 0, None)], np.inf)
    w = 2 * np.pi * STRAP_HZ
    wd = w * np.sqrt(1 - STRAP_DAMPING ** 2)
    a = np.where(np.isfinite(tau), amps[np.clip(j, 0, len(amps) - 1)], 0.0)
    tau = np.where(np.isfinite(tau), tau, 0.0)
    u = a * np.exp(-STRAP_DAMPING * w * tau) * np.sin(wd * tau)
    return u[:, None] * (STRAP_DIRECTION / np.linalg.norm(STRAP_DIRECTION))[None, :]


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
    T = T_mean * (1.0 + cv * fgn(n, STRIDE_HURST, rng))     # persistent fluctuations
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


def _burst_amplitudes(tx: np.ndarray, pitch: np.ndarray, anchors_f: np.ndarray,
                      R: np.ndarray, o: np.ndarray, y_tx: float, z_heel: float
                      ) -> np.ndarray:
    """(n, 4) relative burst amplitude at each receiver (``us_sensor.received_amplitude``).

    The transducer's axis points at the board's centre from the transmitter's place on a
    flat foot at the board's middle (x = board centre, heel on the belt) and pitches with
    the foot; the receivers' axes are the board's normal towards the subject.
    """
    centre = _to_field(PAPER_ANCHORS.mean(axis=0), R, o)
    rest = np.array([centre[0], y_tx - 0.04, z_heel + 0.01])
    a0 = (centre - rest) / np.linalg.norm(centre - rest)       # foot flat: pitch 0
    c, s = np.cos(pitch), np.sin(pitch)
    axis = np.column_stack([a0[0] * c + a0[2] * s, np.full_like(c, a0[1]),
                            -a0[0] * s + a0[2] * c])           # foot-fixed, pitched
    to_rx = anchors_f[None, :, :] - tx[:, None, :]
    dist = np.linalg.norm(to_rx, axis=2)
    unit = to_rx / dist[..., None]
    normal = -R[:, 2]                                          # board normal to the subject
    normal = normal if normal @ (rest - centre) > 0 else -normal
    cos_tx = np.einsum("nk,nmk->nm", axis, unit)
    cos_rx = -unit @ normal
    return received_amplitude(dist, cos_tx, cos_rx)


#: The heel model's mean stride shape (:func:`stride_plan`'s draws' centres), for
#: :func:`belt_speed`.
_MEAN_SHAPE = {"u_ho": 0.34, "u_to": 0.61, "theta_to": 0.85, "z_h": 0.045, "L_h": 0.18,
               "L_f": 0.20, "theta_hs": -0.30}


def eq17_ratio(v: float, T: float) -> float:
    """seed003 eq. (17) on the heel model's steady stride (mean shape) over its belt
    stride ``v T``: 2 (max x - min x) / (v T).  Above 1: the heel keeps riding backwards
    with the belt through heel rise (its forward swing about the metatarsal heads is
    slower than the belt) and is rearmost just after toe-off, so its excursion is more
    than half the stride."""
    n = 4
    t_hs = np.arange(n + 1) * T
    plan = {"t_hs": t_hs, "x_hs": np.zeros(n + 1), "v": v,
            **{k: (np.full(n, val) if k in ("u_ho", "u_to", "theta_to") else val)
               for k, val in _MEAN_SHAPE.items()}}
    t = np.linspace(t_hs[1], t_hs[2], 2001)
    x, _, _ = heel_path(t, plan)
    return float(2.0 * (x.max() - x.min()) / (v * T))


def belt_speed(stride_velocity: float, T: float) -> float:
    """The belt speed at which eq. (17)-(20) on the heel give ``stride_velocity`` (the
    paper's V = S/T, Table 8: what its reference system measured, not its belt's speed)
    for strides of duration ``T``: ``v = V / eq17_ratio(v, T)``, by fixed-point iteration
    (the ratio changes little with v)."""
    v = stride_velocity
    for _ in range(6):
        v = stride_velocity / eq17_ratio(v, T)
    return float(v)


def simulate_treadmill_trial(rng: np.random.Generator, cfg: dict, subject: dict,
                             speed_mps: float, R: np.ndarray, o: np.ndarray):
    """One treadmill trial in memory: mocap (labels, xyz), log, truth tables.

    ``speed_mps`` is the trial's stride velocity as the paper reports it (seed003 eq. (20),
    V = S/T with S by eq. (17)); the belt runs at :func:`belt_speed` of it, which the
    trial sheet records (``meta["speed_mps"]``)."""
    dur, rate, us_rate = cfg["duration_s"], cfg["mocap_rate_hz"], cfg["us_rate_hz"]
    T_pop = float(np.interp(speed_mps, *_T_OF_SPEED))
    T_mean = T_pop * np.sqrt(subject["leg_length_m"] / (0.53 * 1.714)) * subject["_t_factor"]
    cv = cfg["stride_cv"] * (1.3 if speed_mps < 0.7 else 1.0)
    speed_mps = round(belt_speed(speed_mps, T_mean), 3)            # the belt's
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
    # the housing wobbles on its strap after each strike; the marker on the shoe does not
    strap_amps = rng.uniform(*STRAP_AMPLITUDE_M, size=len(plan_r["t_hs"]))
    pts["TXA"] = pts["TXA"] + strap_motion(t_m, plan_r["t_hs"], strap_amps)
    anchors_f = _to_field(PAPER_ANCHORS, R, o)
    labels = ["TX"] + ANCHOR_IDS + _FOOT_MARKERS
    xyz = np.empty((len(t_m), len(labels), 3))
    xyz[:, 0] = pts["TX"]
    xyz[:, 1:5] = anchors_f[None, :, :]
    for k, lab in enumerate(_FOOT_MARKERS):
        xyz[:, 5 + k] = pts[lab]
    xyz = _mocap_noise_and_gaps(rng, xyz, labels, rate, cfg["mocap_noise_m"])

    t_us, t_true, offset, drift = _clock(rng, dur, us_rate)
    tx_us_t = (foot_points(t_true, plan_r, y_r, phase, "R")["TXA"]
               + strap_motion(t_true, plan_r["t_hs"], strap_amps))
    d_true = np.linalg.norm(tx_us_t[:, None, :] - anchors_f[None], axis=2)
    amp = _burst_amplitudes(tx_us_t, heel_path(t_true, plan_r)[2], anchors_f, R, o, y_r,
                            plan_r["z_h"])
    temp_true, temp_log = _temperature(rng, t_us)
    tof, counts = _ranges_to_tof(d_true, temp_true, rng, np.asarray(cfg["noise_V_m2"]),
                                 cfg["multipath_prob"], cfg["dropout_prob"], amplitude=amp,
                                 common_fraction=float(cfg.get("noise_common_fraction", 0.0)))

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
