"""Study-level tables shared by the simulated and the replayed studies.

The trial-sheet and subject-table columns (the common brief's), the sensor clock every
LRS trial is drawn with, and the realism summary written to ``realism.csv``.  Both
:mod:`gaitval.simulate.study` and :mod:`gaitval.simulate.replay` import from here, so
neither imports the other's internals.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

TRIAL_COLUMNS = ["study", "protocol", "subject", "trial", "sensor_kind", "mocap_file",
                 "sensor_file", "sensor_topic", "annotation_file", "sensor_height_m",
                 "clock_offset_s", "speed", "speed_mps", "stick", "scenario", "repetition"]
SUBJECT_COLUMNS = ["subject", "group", "age_y", "sex", "height_m", "mass_kg", "leg_width_m",
                   "knee_width_m", "ankle_width_m", "leg_length_m", "shank_length_m", "stick"]


def sensor_clock(rng: np.random.Generator, cfg: dict) -> dict:
    """Draw a sensor clock (common brief): offset, drift and timestamp jitter.

    ``t_sensor = clock_offset_s + (1 + clock_drift_ppm·1e-6)·t_mocap`` plus jitter; the
    offset is uniform in ``cfg["offset_s"]`` ([0.2, 2.0] s), the drift normal with sd
    ``cfg["drift_ppm_sd"]`` (30 ppm), both drawn in that order from ``rng``.
    """
    lo, hi = cfg.get("offset_s", [0.2, 2.0])
    return {"clock_offset_s": round(float(rng.uniform(lo, hi)), 6),
            "clock_drift_ppm": round(float(rng.normal(0.0, cfg.get("drift_ppm_sd", 30.0))), 3),
            "jitter_s": float(cfg.get("jitter_s", 0.0005))}


def summarise_realism(rows: list[dict]) -> pd.DataFrame:
    """Per protocol (and TUG phase): occlusion, mixed-pixel and dropout fractions, speeds,
    steps per trial and cross steps per 100 steps (the published figures beside them)."""
    df = pd.DataFrame(rows)
    published = {("tug", "forward"): 0.035, ("tug", "turning"): 0.113,
                 ("tug", "return"): 0.051, ("tug", "all"): 0.054}
    out = []
    for (proto, ph), g in df.groupby(["protocol", "phase"], sort=True):
        r = {"protocol": proto, "phase": ph, "n_trials": g["trial"].nunique(),
             "leg_scans": int(g["leg_scans"].sum()),
             "occlusion_rate": g["occluded_leg_scans"].sum() / max(g["leg_scans"].sum(), 1),
             "occlusion_rate_L": 2 * g["occluded_L"].sum() / max(g["leg_scans"].sum(), 1),
             "occlusion_rate_R": 2 * g["occluded_R"].sum() / max(g["leg_scans"].sum(), 1),
             "occlusion_rate_published": published.get((proto, ph), np.nan)}
        if ph == "all":
            r.update({
                "mixed_pixel_frac": g["mixed"].sum() / max(g["returns"].sum(), 1),
                "dropout_frac": g["dropouts"].sum() / max(g["beams"].sum(), 1),
                "stance_speed_mps": g["stance_speed_mps"].mean(),
                "swing_speed_mps": g["swing_speed_mps"].mean(),
                "swing_peak_mps": g["swing_peak_mps"].mean(),
                "walking_speed_mps": g["walking_speed_mps"].mean(),
                "steps_per_trial": g["steps"].mean(),
                "cross_steps_per_100": 100 * g["cross_steps"].sum() / max(g["steps"].sum(), 1),
                "cross_steps_per_100_published": 100 * 19 / 414 if proto == "mtst" else np.nan,
            })
        out.append(r)
    return pd.DataFrame(out)
