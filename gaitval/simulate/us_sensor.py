"""The simulated ultrasonic system and what it records (seed 003): board, ranging, clocks.

Shared by the treadmill (:mod:`gaitval.simulate.us_treadmill`) and pendulum
(:mod:`gaitval.simulate.us_pendulum`) trials of :mod:`gaitval.simulate.ultrasonic`, whose
notes describe the frames and the error model: the receiver board and its pose in the
field, the speed of sound of dry air (the simulator's physics, not the pipeline's linear
eq. (2)), true ranges to logged times of flight (noise, multipath, dropouts, 1 us tick),
the logged air temperature, the ultrasonic log's clock, and the camera's noise and gaps.

Threshold detection of the burst (issue 10; :func:`received_amplitude`,
:func:`detection_delay_m`): each anchor stops its counter when the received 40 kHz burst
(8 pulses, seed 003 §3.1) first crosses a fixed threshold.  The burst's amplitude falls
with the transmitter's and the receiver's directivity (circular pistons, −6 dB at ±40°),
spherical spreading and air absorption (1.3 dB/m) and fluctuates from ping to ping (5 %);
its envelope rises over the first cycles (a resonant transducer pair, τ = Q/π cycles,
Q = 20).  A weaker burst crosses the threshold later in its first cycle, or only in a later
cycle (a cycle slip of one wavelength, 8.6 mm), or not at all (a missed echo).  The
threshold is where an on-axis burst at the paper's maximum range of 20 m (seed 003 §5)
still crosses at its last cycle; the firmware's fixed delay is that of an on-axis burst
at 0.5 m (a one-time calibration).

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
from gaitval.errors import ConfigError
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


#: The receiver board's plane from the right heel transmitter's path (m, lateral): seed 003
#: gives the board, not its distance (docs/robustness.md: plausible 0.2-0.5 m); the
#: ultrasonic preset's ``board_distance_m`` replaces it.
BOARD_DISTANCE_M = 0.285


def board_pose(rng: np.random.Generator, distance_m: float = BOARD_DISTANCE_M
               ) -> tuple[np.ndarray, np.ndarray]:
    """Draw the receiver board's pose: rotation ``R`` (ultrasonic -> field) and origin ``o``,
    the board ``distance_m`` (± 3 cm) to the left of the heel transmitter's path."""
    psi = np.deg2rad(rng.uniform(-2.0, 2.0))
    ex = np.array([np.cos(psi), np.sin(psi), 0.0])          # X_u: progression
    ey = np.array([0.0, 0.0, 1.0])                          # Y_u: vertical
    ez = np.cross(ex, ey)                                   # Z_u = X_u x Y_u (right)
    R = np.column_stack([ex, ey, ez])
    y0 = -0.40 - (float(distance_m) - BOARD_DISTANCE_M)     # the path at y = -0.115 m
    o = np.array([-0.162 + rng.uniform(-0.03, 0.03), y0 + rng.uniform(-0.03, 0.03),
                  rng.uniform(0.0, 0.01)])
    return R, o


#: The burst (seed 003 §3.1): 8 pulses at 40 kHz.
BURST_HZ = 40_000.0
BURST_CYCLES = 8
#: ``k a`` of a circular-piston transducer whose beam is −6 dB at ±40° (the 80° beam of
#: common open-type 40 kHz transducers): ``2 J1(x)/x = 1/2`` at ``x = 2.215 = k a sin 40°``.
PISTON_KA = 2.215 / np.sin(np.deg2rad(40.0))
#: Envelope rise of a resonant transducer pair, in cycles: ``τ = Q/π`` with ``Q = 20``.
ENVELOPE_TAU_CYCLES = 20.0 / np.pi
#: Air absorption at 40 kHz, about 20 °C and 50 % relative humidity (ISO 9613-1), dB/m.
ABSORPTION_DB_PER_M = 1.3
#: Ping-to-ping fluctuation of the received amplitude (relative sd: air turbulence, supply).
AMPLITUDE_SD = 0.05
#: The paper's maximum propagation distance (seed 003 §5), which sets the threshold.
MAX_RANGE_M = 20.0
#: The firmware's fixed delay is that of an on-axis burst at this range (calibration).
CALIBRATION_RANGE_M = 0.5


def piston_directivity(cos_theta) -> np.ndarray:
    """Far-field directivity ``2 J1(ka sin θ) / (ka sin θ)`` of a circular piston (≥ 0)."""
    from scipy.special import j1

    c = np.clip(np.asarray(cos_theta, dtype=float), -1.0, 1.0)
    x = PISTON_KA * np.sqrt(1.0 - c * c)
    d = np.where(x < 1e-9, 1.0, 2.0 * j1(np.maximum(x, 1e-9)) / np.maximum(x, 1e-9))
    return np.where(c > 0, np.abs(d), 0.0)             # nothing radiates backwards


def received_amplitude(d_m, cos_tx, cos_rx) -> np.ndarray:
    """Burst amplitude at a receiver relative to an on-axis burst at 1 m: both pistons'
    directivity, spherical spreading ``1/d`` and air absorption."""
    d = np.asarray(d_m, dtype=float)
    return (piston_directivity(cos_tx) * piston_directivity(cos_rx) / d
            * 10.0 ** (-ABSORPTION_DB_PER_M * d / 20.0))


def _crossing_cycles(amp: np.ndarray, threshold: float) -> np.ndarray:
    """Time (in cycles) at which ``amp · env(t) · sin(2π t)`` first reaches ``threshold``
    (positive half-cycles, envelope taken at each half-cycle's peak); NaN: never."""
    amp = np.asarray(amp, dtype=float)
    ratio = threshold / np.maximum(amp, 1e-12)
    # first cycle k whose peak (t = k + 1/4) reaches the threshold: env(k + 1/4) >= ratio
    need = -ENVELOPE_TAU_CYCLES * np.log(np.clip(1.0 - ratio, 1e-300, None)) - 0.25
    k = np.where(ratio < 1.0, np.maximum(np.ceil(need), 0.0), np.inf)
    env = 1.0 - np.exp(-(k + 0.25) / ENVELOPE_TAU_CYCLES)
    within = np.asarray(np.arcsin(np.clip(ratio / np.where(np.isfinite(env), env, 1.0),
                                          0.0, 1.0)) / (2.0 * np.pi))
    return np.where(k < BURST_CYCLES, k + within, np.nan)


def _threshold() -> float:
    """Detection threshold: an on-axis burst at :data:`MAX_RANGE_M` reaches it at the peak
    of its last cycle."""
    a_max = received_amplitude(MAX_RANGE_M, 1.0, 1.0)
    return float(a_max * (1.0 - np.exp(-(BURST_CYCLES - 0.75) / ENVELOPE_TAU_CYCLES)))


def detection_delay_m(amplitude: np.ndarray, wavelength_m) -> np.ndarray:
    """Extra range (m) the threshold detector adds to a burst of relative ``amplitude``,
    beyond the calibrated delay of an on-axis burst at :data:`CALIBRATION_RANGE_M`; NaN
    where the burst never reaches the threshold (a missed echo)."""
    h = _threshold()
    t_cal = _crossing_cycles(received_amplitude(CALIBRATION_RANGE_M, 1.0, 1.0), h)
    return (_crossing_cycles(amplitude, h) - t_cal) * np.asarray(wavelength_m, dtype=float)


def range_noise(rng: np.random.Generator, n: int, V_m2: np.ndarray,
                common_fraction: float = 0.0) -> np.ndarray:
    """Gaussian range errors (n, m) whose variance per anchor is ``V_m2`` (seed 003's V).

    A share ``common_fraction`` of the smallest anchor variance is one draw per ping shared
    by every anchor (the transmitter's trigger-to-RF latency starts all counters late or
    early together); the rest is independent per anchor (each anchor's own detection and
    counter start).  Per anchor the total variance is ``V_m2`` either way, which is all
    eq. (23) measures.  With ``common_fraction`` 0 no common draw is made.
    """
    V = np.asarray(V_m2, dtype=float)
    m = V.size
    if not 0.0 <= common_fraction <= 1.0:
        raise ConfigError(f"ultrasonic.noise_common_fraction is {common_fraction!r}; it "
                          "must be in [0, 1]")
    common = common_fraction * float(V.min())
    e = rng.standard_normal((n, m)) * np.sqrt(V - common)[None, :]
    if common > 0.0:
        e = e + rng.standard_normal((n, 1)) * np.sqrt(common)
    return e


def _ranges_to_tof(d_true: np.ndarray, temp_c: np.ndarray, rng: np.random.Generator,
                   V_m2: np.ndarray, multipath_prob: float, dropout_prob: float,
                   amplitude: np.ndarray | None = None, common_fraction: float = 0.0
                   ) -> tuple[np.ndarray, dict]:
    """True ranges -> logged times of flight (noise, multipath, dropouts, 1 us tick).

    The range noise is :func:`range_noise` (``common_fraction`` of it shared by the
    anchors).  ``amplitude`` (n, m): the bursts' relative amplitudes
    (:func:`received_amplitude`); when given, each range also carries the threshold
    detector's delay (:func:`detection_delay_m`, amplitude fluctuating by
    :data:`AMPLITUDE_SD` per ping) and a burst below the threshold is a missed echo.
    """
    n, m = d_true.shape
    d = d_true + range_noise(rng, n, V_m2, common_fraction)
    mp = rng.random((n, m)) < multipath_prob
    d = d + mp * rng.uniform(0.05, 0.5, size=(n, m))
    counts = {}
    if amplitude is not None:
        lam = speed_of_sound_true(temp_c)[:, None] / BURST_HZ
        amp = amplitude * (1.0 + AMPLITUDE_SD * rng.standard_normal((n, m)))
        delay = detection_delay_m(amp, lam)
        base = detection_delay_m(amplitude, lam)        # without the ping's fluctuation
        d = d + delay
        counts = {"n_missed_echo": int(np.isnan(delay).sum()),
                  "n_cycle_slip": int(np.sum(np.abs(delay - base) > 0.5 * lam)),
                  "detection_delay_mm_p5_p95": [float(v) for v in 1e3 * np.nanpercentile(
                      delay, [5, 95])] if np.isfinite(delay).any() else [np.nan, np.nan]}
    tof = distance_to_tof(d, temp_c, speed=speed_of_sound_true)      # seed003 eq. (1)
    tof = np.round(tof * 1e6) * 1e-6                         # 16-bit counter, 1 us tick
    drop = rng.random((n, m)) < dropout_prob
    tof[drop] = np.nan
    return tof, {"n_multipath": int(mp.sum()), "n_dropout": int(drop.sum()), **counts}


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
