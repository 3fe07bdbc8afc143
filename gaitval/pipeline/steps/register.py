"""Registration steps: register one trial and build its ground truth; gather the records into
the registration table.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import GaitvalError
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.pipeline.steps.config import load_json
from gaitval.pipeline.steps.trials import load_ingested, trial_and_subject


def _clean(v):
    if isinstance(v, (np.floating, float)):
        return None if not math.isfinite(float(v)) else float(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (np.bool_,)):
        return bool(v)
    return v


def register_step(ingest_dir, sheet, subjects, trial: str, config_json, out_dir) -> dict:
    """Register one trial and build its ground truth.

    The trial's leg points at sensor height are computed once
    (:func:`~gaitval.groundtruth.sensor_leg_points`) and handed to the registration (pole
    motion evidence, clock) and then to the ground truth.

    Writes ``registration.json`` (the record, plus ``status`` ``ok`` or ``refused`` and the
    ``reason``) and ``groundtruth.parquet`` (empty when refused).  A refusal
    (:class:`~gaitval.errors.GaitvalError` from registration or ground truth: a pole not
    found, a residual too large, a weak clock peak, missing markers) is recorded, not
    hidden: the registration table shows it and later steps skip the trial.  Set
    ``registration.on_error: raise`` to stop the run instead.
    """
    from gaitval.groundtruth import GT_COLUMNS, ground_truth, sensor_leg_points
    from gaitval.registration import RECORD_FIELDS, register_trial

    cfg = load_json(config_json)
    row, subj = trial_and_subject(sheet, subjects, trial)
    mocap, sensor = load_ingested(ingest_dir, row)
    out = Path(out_dir)
    rec: dict = {C.TRIAL: trial, "protocol": row["protocol"], C.SUBJECT: row[C.SUBJECT]}
    try:
        legs = sensor_leg_points(mocap, sensor, row, subj, cfg)       # once per trial
        reg = register_trial(mocap, sensor, row, subj, cfg, legs=legs,
                             other_poses=sheet_poses(sheet))
        gt = ground_truth(mocap, sensor, reg, row, subj, cfg, legs=legs)
        rec.update({k: _clean(v) for k, v in reg.as_row().items()})
        rec.update(status="ok", reason="")
    except GaitvalError as exc:
        if cfg.get("registration", {}).get("on_error", "record") == "raise":
            raise exc.with_context(trial=trial) from None
        rec.update({k: None for k in RECORD_FIELDS if k != C.TRIAL})
        rec.update(status="refused", reason=str(exc.with_context(trial=trial)))
        gt = pd.DataFrame(columns=GT_COLUMNS)
    write_parquet(gt.reset_index(drop=True), out / "groundtruth.parquet")
    write_text(out / "registration.json", json.dumps(rec, indent=1, sort_keys=True) + "\n")
    return rec


def sheet_poses(sheet) -> dict:
    """trial -> ``(x_m, y_m, yaw_rad)`` of every row of the sheet with a pose measured by
    hand (rows with a partial pose are left to their own trial's error)."""
    from gaitval.errors import RegistrationError
    from gaitval.registration.trial import manual_pose

    df = pd.read_csv(sheet, dtype=str, keep_default_na=False)
    out = {}
    for row in df.to_dict("records"):
        try:
            p = manual_pose(row)
        except RegistrationError:
            continue
        if p is not None:
            out[str(row[C.TRIAL])] = p
    return out


def registration_summary(inputs: list[str | Path], study: str, out_csv, out_stem,
                         reports_dir, config_hash: str = "") -> pd.DataFrame:
    """Gather ``registration.json`` records into ``registration.csv`` and a report table."""
    from gaitval.registration import RECORD_FIELDS
    from gaitval.report.provenance import stamp
    from gaitval.tables import write_table

    rows = [load_json(p) for p in inputs]
    cols = list(RECORD_FIELDS) + ["protocol", C.SUBJECT, "status", "reason"]
    df = pd.DataFrame(rows).reindex(columns=cols).sort_values(C.TRIAL).reset_index(drop=True)
    write_csv(df, out_csv, float_format="%.6g")
    show = df.copy()
    show["yaw_deg"] = np.degrees(show["yaw_rad"].astype(float))
    by_hand = (["manual_pose_diff_m", "manual_pose_diff_deg"]
               if show["manual_pose_diff_m"].notna().any() else [])
    show = show[[C.TRIAL, "protocol", C.X, C.Y, "yaw_deg", "pose_source", *by_hand,
                 C.CLOCK_OFFSET, "clock_drift_ppm", "pole_residual_m", "sync_peak",
                 "joint_centre_source", "gt_frames_excluded", "legs_in_view", "legs_seen",
                 "status", "reason"]]
    n_ref = int((df["status"] != "ok").sum())
    notes = [f"{n_ref} trial(s) refused; their reason is given and later tables leave them "
             "out."] if n_ref else []
    paths = write_table(show, out_stem, notes=notes, caption=(
        f"Registration of each trial of study '{study}': estimated sensor pose in the mocap "
        "field (pose_source: from the calibration poles, or measured by hand where the C3D "
        "has no poles — where both exist, the poles' pose minus the hand-measured one; "
        "rollator trials have a per-frame pose, shown "
        "empty; ultrasonic trials show the receiver frame), clock offset and drift (sensor "
        "minus mocap), worst pole residual, correlation peak of the clock synchronisation, "
        "which joint-centre source built the ground truth, mocap frames excluded for "
        "gaps longer than groundtruth.max_gap_s, and the registration's plausibility: "
        "the share of the walk with a mocap leg in the laser's view and, of those frames, "
        "with a laser return near a leg (at least 0.5 each, else the trial is refused). "
        "Reviewers read this table first."))
    stamp(Path(out_stem).name, paths, reports_dir, config_hash_=config_hash)
    return df
