"""Tracking steps of a fixed laser (LRS): one tracker method, or one detector, on one trial.
"""
from __future__ import annotations

import json

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.io.atomic import write_parquet
from gaitval.pipeline.steps.config import load_json, method_definition, method_overrides
from gaitval.pipeline.steps.trials import trial_and_subject


def tug_leg_width(subj: dict, cfg: dict) -> float:
    """The subject's shank width w_l (subjects.csv), else ``registration.default_leg_width_m``."""
    w = subj.get("leg_width_m")
    if w is None or not np.isfinite(w):
        w = float((cfg.get("registration") or {}).get("default_leg_width_m", 0.10))
    return float(w)


def fixed_sensor_overrides(definition) -> dict:
    """The people tracker's setup on a laser that stands still (TUG, MTST; issue 38):
    ``kind__ego_motion: none``.  Seed 000 and seed 001 put the LRS on a stand in the
    room, and gaitval's registration (calibration poles, one fixed pose per trial) rests
    on that; estimating the laser's motion from its own scans (``scan_matching``, for
    robots that move without odometry, e.g. the leg-tracker benchmark's bags) can only
    find a motion that is not there, at about half the people tracker's cost per scan.
    The rollator's carried laser keeps it (:func:`gaitval.pipeline.rollator.
    rollator_people_overrides`).  Empty for a method that is not of kind ``people``; the
    method's own ``tracking.overrides`` apply on top."""
    from gaitval.methods import get_method, kind_name

    if kind_name(get_method(definition)) != "people":
        return {}
    return {"kind__ego_motion": "none"}


def track_step(sensor_parquet, sheet, subjects, trial: str, method: str, config_json,
               out_parquet, detections=None) -> pd.DataFrame:
    """Run one tracker method on one LRS trial; write the per-scan track (sensor frame).
    ``detections``: the trial's observations made by :func:`detect_step` with this
    method's detector (:mod:`gaitval.pipeline.detections`), instead of detecting again."""
    from gaitval.io.scanlog import read_scanlog

    cfg = load_json(config_json)
    row, subj = trial_and_subject(sheet, subjects, trial)
    scans = read_scanlog(sensor_parquet, trial=trial)
    w = tug_leg_width(subj, cfg)
    mdef = method_definition(cfg, method)
    overrides = {**fixed_sensor_overrides(mdef),
                 **method_overrides(cfg, method)}
    return track_and_write(scans, mdef, w, overrides,
                           trial=trial, method=method, source=sensor_parquet,
                           out_parquet=out_parquet, detections=detections)


def detect_step(sensor_parquet, sheet, subjects, trial: str, detector: str, config_json,
                out_parquet) -> pd.DataFrame:
    """One TUG trial's observations by ``detector`` (a spec, as JSON text) with the leg
    width its track step uses, for every method with that detector
    (:mod:`gaitval.pipeline.detections`)."""
    from gaitval.io.scanlog import read_scanlog
    from gaitval.pipeline.detections import detect_and_write

    cfg = load_json(config_json)
    _, subj = trial_and_subject(sheet, subjects, trial)
    scans = read_scanlog(sensor_parquet, trial=trial)
    return detect_and_write(scans, json.loads(detector), tug_leg_width(subj, cfg),
                            out_parquet, trial=trial, source=sensor_parquet)


def track_and_write(scans, mdef, leg_width_m: float, overrides, *, trial: str, method: str,
                    source, out_parquet, detections=None) -> pd.DataFrame:
    """One method's per-scan track of one trial, tagged with trial and method and written
    atomically; a tracker's error names the scan file and the trial.  ``detections``: a
    file of the method's detector's observations of these scans, checked and used instead
    of detecting (:mod:`gaitval.pipeline.detections`)."""
    from gaitval.methods import track_trial, trial_detector
    from gaitval.pipeline.detections import detections_or_none

    obs = None
    if detections:
        obs = detections_or_none(detections, trial_detector(mdef, overrides), leg_width_m,
                                 scans, trial=trial, method=method)
    try:
        track = track_trial(scans, mdef, leg_width_m, {"overrides": overrides},
                            observations=obs)
    except GaitvalError as exc:
        raise exc.with_context(path=source, trial=trial) from None
    track.insert(0, "method", method)
    track.insert(0, "trial", trial)
    write_parquet(track, out_parquet)
    return track
