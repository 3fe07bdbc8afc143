"""Plug-in-Gait lower-body markers (and extras) from the simulated skeleton.

Markers are placed at anatomically plausible offsets from the joint centres in the
segment frames (pelvis heading, foot heading), then get sub-millimetre noise and gaps
as Vicon exports have them: many short gaps and a few long ones.

References
----------
Vicon Motion Systems. Plug-in Gait Reference Guide (marker placement: ASIS/PSIS, lateral
thigh and shank wands, lateral femoral epicondyle, lateral malleolus, calcaneus, second
metatarsal head).
"""
from __future__ import annotations

import numpy as np

PIG16 = ["LASI", "RASI", "LPSI", "RPSI", "LTHI", "RTHI", "LKNE", "RKNE", "LTIB", "RTIB",
         "LANK", "RANK", "LHEE", "RHEE", "LTOE", "RTOE"]
MEDIAL = ["LKNEin", "RKNEin", "LANKin", "RANKin"]
BONES = ["LFEO", "RFEO", "LTIO", "RTIO"]
JOINT_CENTRES = ["LKJC", "RKJC", "LAJC", "RAJC"]
CLUSTER = [f"{s}TB{i}" for s in "LR" for i in range(1, 5)]
MARKER_RADIUS_M = 0.007        # 14 mm markers
SKIN_OFFSET_M = 0.009          # cluster marker centre outside the skin (common brief)


def _frame(heading: np.ndarray):
    fwd = np.stack([np.cos(heading), np.sin(heading), np.zeros_like(heading)], axis=-1)
    left = np.stack([-np.sin(heading), np.cos(heading), np.zeros_like(heading)], axis=-1)
    return fwd, left


def pig_markers(legs, pelvis: np.ndarray, pelvis_heading: np.ndarray, subj: dict,
                *, medial: bool, bones: str | None, cluster: bool) -> dict[str, np.ndarray]:
    """Marker positions (n, 3) in metres by label.

    Parameters
    ----------
    legs : (LegState, LegState)
        Left and right leg.
    pelvis : ndarray (n, 3)
        Hip-joint-centre midpoint.
    pelvis_heading : ndarray (n,)
    subj : dict
        ``knee_width_m``, ``ankle_width_m``, ``leg_width_m`` (shank width for clusters).
    medial : bool
        Add ``LKNEin RKNEin LANKin RANKin``.
    bones : ``"pig"``, ``"jc"`` or None
        Add PiG bone outputs ``LFEO RFEO LTIO RTIO`` (knee / ankle joint centres) or
        explicit ``LKJC RKJC LAJC RAJC``.
    cluster : bool
        Add shank clusters ``LTB1..4 RTB1..4`` on the skin (rollator trials).
    """
    out: dict[str, np.ndarray] = {}
    fwd, left = _frame(pelvis_heading)
    up = np.array([0.0, 0.0, 1.0])
    for sgn, pre in ((1.0, "L"), (-1.0, "R")):
        out[pre + "ASI"] = pelvis + 0.06 * fwd + sgn * 0.12 * left + 0.05 * up
        out[pre + "PSI"] = pelvis - 0.13 * fwd + sgn * 0.045 * left + 0.08 * up
    for k, (sgn, pre) in enumerate(((1.0, "L"), (-1.0, "R"))):
        lg = legs[k]
        ffw, flf = _frame(lg.heading)
        lat = sgn * flf
        hip = pelvis + sgn * 0.085 * left
        knee, ankle = lg.knee, lg.ankle
        out[pre + "THI"] = hip + 0.6 * (knee - hip) + 0.075 * lat
        out[pre + "KNE"] = knee + (subj["knee_width_m"] / 2 + MARKER_RADIUS_M) * lat
        out[pre + "TIB"] = knee + 0.6 * (ankle - knee) + 0.06 * lat
        out[pre + "ANK"] = ankle + (subj["ankle_width_m"] / 2 + MARKER_RADIUS_M) * lat
        # foot: heel behind and below the ankle; toe on the second metatarsal head,
        # which stays on the floor while the heel rises
        rise = lg.heel_rise[:, None]
        out[pre + "HEE"] = ankle - 0.065 * ffw + np.array([0, 0, -0.045]) + 0.03 * rise * up
        # (the ankle rolls roll_dx forward and roll_dz up over the planted forefoot)
        roll = lg.roll_dx if lg.roll_dx is not None else np.zeros(len(ankle))
        rise_m = lg.roll_dz if lg.roll_dz is not None else 0.05 * lg.heel_rise
        toe = ankle + (0.15 - roll)[:, None] * ffw
        toe[:, 2] = np.maximum(0.025, ankle[:, 2] - 0.055 - rise_m)
        out[pre + "TOE"] = toe
        if medial:
            out[pre + "KNEin"] = knee - (subj["knee_width_m"] / 2 + MARKER_RADIUS_M) * lat
            out[pre + "ANKin"] = ankle - (subj["ankle_width_m"] / 2 + MARKER_RADIUS_M) * lat
        if bones == "pig":
            out[pre + "FEO"] = knee.copy()
            out[pre + "TIO"] = ankle.copy()
        elif bones == "jc":
            out[pre + "KJC"] = knee.copy()
            out[pre + "AJC"] = ankle.copy()
        if cluster:
            axis = knee - ankle
            axis /= np.linalg.norm(axis, axis=1, keepdims=True)
            # the shank's own frame (the cluster is rigid on the bone): lateral axis
            # perpendicular to the shank axis, forward = lateral x axis direction
            e_lat = lat - np.sum(lat * axis, axis=1, keepdims=True) * axis
            e_lat /= np.linalg.norm(e_lat, axis=1, keepdims=True)
            e_fwd = np.cross(e_lat, axis) * (1.0 if sgn > 0 else -1.0)
            # directions around the shank, perpendicular to its axis
            for i, (frac, ang) in enumerate(((0.35, 90.0), (0.45, 45.0), (0.55, 135.0),
                                             (0.65, 70.0)), start=1):
                a = np.deg2rad(ang)
                d = np.cos(a) * e_fwd + np.sin(a) * e_lat
                r = subj["leg_width_m"] / 2 + SKIN_OFFSET_M
                out[f"{pre}TB{i}"] = ankle + frac * (knee - ankle) + r * d
    return out


def add_noise_and_gaps(xy: dict[str, np.ndarray], rng: np.random.Generator, *,
                       noise_m: float = 0.0003, short_rate_per_s: float = 0.15,
                       long_prob: float = 0.12, rate_hz: float = 100.0,
                       no_gaps: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """Sub-millimetre white noise and Vicon-like gaps (NaN).

    Short gaps (1–8 frames) arrive as a Poisson process per marker; with probability
    ``long_prob`` a marker also loses a long stretch (0.2–0.6 s), as when a foot marker
    is hidden by the other leg or a hand during a turn.  Foot and pelvis markers are
    twice as gap-prone as the knee and shank markers.  Labels in ``no_gaps`` keep every
    sample (derived outputs such as joint centres).
    """
    out = {}
    for lab in sorted(xy):
        p = xy[lab] + noise_m * rng.standard_normal(xy[lab].shape)
        n = len(p)
        if lab not in no_gaps:
            f = 2.0 if lab[1:] in ("HEE", "TOE", "ASI", "PSI") else 1.0
            k = rng.poisson(short_rate_per_s * f * n / rate_hz)
            for _ in range(k):
                s = int(rng.integers(0, n))
                p[s:s + int(rng.integers(1, 9))] = np.nan
            if rng.random() < long_prob * f:
                ln = int(rng.uniform(0.2, 0.6) * rate_hz)
                s = int(rng.integers(0, max(1, n - ln)))
                p[s:s + ln] = np.nan
        out[lab] = p
    return out
