"""One MTST trial end to end after tracking: walking parameters, tracking verdicts, steps.

:func:`evaluate_mtst_trial` takes objects (the track, the sensor pose, the trial's
targets, annotations, clock and, where there is one, the mocap truth) and returns tidy
tables; :mod:`gaitval.pipeline.mtst` reads and writes the files.  :data:`DEFAULTS` is the
``mtst:`` section of the config with every default (``workflow/schemas``; the rules and
their reasons are in :mod:`gaitval.gait.mtst`, :mod:`gaitval.evaluate.mtst` and
:mod:`gaitval.evaluate.mtst_tracking`).

Parts of a trial that cannot be evaluated are said, not hidden: a trial without
annotations (allowed by ``require_annotations: false``) has no step judgements and no
rater verdict; one without targets (``require_targets: false``) has no target
judgements; one without mocap has no mocap verdict.  The summary row carries
``has_annotations``, ``has_targets`` and ``has_mocap``.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.config import deep_merge, section
from gaitval.evaluate.mtst import evaluate_steps
from gaitval.evaluate.mtst_tracking import (gate_usage, persistent_swap_verdict,
                                            tracking_vs_annotations, tracking_vs_truth)
from gaitval.evaluate.tug import align_truth
from gaitval.gait.mtst import (FootModel, cross_steps, foot_contacts, judge_target_steps,
                               judgement_region)
from gaitval.registration.rigid import sensor_to_field

#: The ``mtst:`` config section and its defaults (schema: workflow/schemas/config.schema.yaml)
DEFAULTS: dict = {
    "methods": ["mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed", "people",
                "people_offline"],
    "scan_period_s": 0.05,
    "targets": None,
    "target_size_m": [0.165, 0.160],
    "mat": {"start_m": [0.0, 0.0], "goal_m": [5.85, 0.0], "width_m": 1.15},
    "poles_m": None,
    "require_annotations": True,
    "require_targets": True,
    "foot": {"length_per_height": 0.152, "width_per_height": 0.055, "heel_per_length": 0.25,
             "default_height_m": 1.60},
    "contacts": {"min_stance_s": 0.10, "min_swing_s": 0.10},
    "cross": {"wc_leg_widths": 0.5, "y_towards": "support_side"},
    "evaluation": {"contact_tolerance_s": 0.15, "lost_m": 0.30, "swap_margin_m": 0.05,
                   "swap_min_m": 0.10, "min_bad_s": 0.20, "min_run": 2,
                   "persistent_swap_s": 0.5},
    "figure_trial": None,
}

SUMMARY_COLUMNS = ("trial", "method", "stick", "has_mocap", "has_annotations", "has_targets",
                   "category_mocap", "category_annotations", "n_contacts_sys", "n_steps",
                   "n_target_ref", "non_judgement", "misjudgement", "n_cross_ref",
                   "non_detection", "false_detection", "n_cross_sys", "n_cross_sys_all",
                   "category_mocap_persistent_swap")


def settings(cfg: dict | None) -> dict:
    """:data:`DEFAULTS` updated with a config's ``mtst:`` section (or the section itself)."""
    sec = section(cfg, "mtst")
    return deep_merge(DEFAULTS, {k: v for k, v in sec.items() if k in DEFAULTS})


def heading(mat: dict) -> np.ndarray:
    """Unit walking direction start → goal of the mat (field frame)."""
    d = np.asarray(mat["goal_m"], float) - np.asarray(mat["start_m"], float)
    return d / max(float(np.hypot(*d)), 1e-12)


def track_in_field(track: pd.DataFrame, pose) -> pd.DataFrame:
    """The track with positions and velocities rotated into the field frame."""
    out = track.copy()
    xy = sensor_to_field(track[["x_m", "y_m"]].to_numpy(float), *pose)
    v = sensor_to_field(track[["vx_mps", "vy_mps"]].to_numpy(float), 0.0, 0.0, pose[2])
    out["x_m"], out["y_m"] = xy[:, 0], xy[:, 1]
    out["vx_mps"], out["vy_mps"] = v[:, 0], v[:, 1]
    return out


def truth_in_field(track: pd.DataFrame, truth: pd.DataFrame | None, pose
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The mocap leg point of each track row (its leg, its scan time) in the field frame;
    NaN where the truth is invalid or outside the recording, everywhere without mocap."""
    if truth is None:
        nan = np.full(len(track), np.nan)
        return nan, nan.copy()
    fr = align_truth(track, truth)
    xy = sensor_to_field(fr[["xs_m", "ys_m"]].to_numpy(float), *pose)
    return xy[:, 0], xy[:, 1]


def walking_parameters(track_f: pd.DataFrame, targets: pd.DataFrame | None, *,
                       leg_width_m: float, height_m: float, s: dict) -> pd.DataFrame:
    """Contacts (field frame) with their stance times, target and cross-step flag."""
    c = foot_contacts(track_f, **s["contacts"])
    t = track_f.drop_duplicates("k").set_index("k")["t_sensor_s"]
    c["t_start_s"] = t.reindex(c["k_stance_start"]).to_numpy(float)
    c["t_end_s"] = t.reindex(c["k_stance_end"]).to_numpy(float)
    h = heading(s["mat"])
    if targets is not None and len(c):
        f = s["foot"]
        foot = FootModel.for_height(height_m, f["length_per_height"], f["width_per_height"],
                                    f["heel_per_length"])
        region = judgement_region(foot, tuple(s["target_size_m"]))
        c["target"] = judge_target_steps(c[["x_m", "y_m"]].to_numpy(float), targets,
                                         region, h)
    else:
        c["target"] = ""
    c["cross"] = (cross_steps(c, track_f, h, s["cross"]["wc_leg_widths"] * leg_width_m,
                              s["cross"]["y_towards"]) if len(c) else np.zeros(0, bool))
    return c


def evaluate_mtst_trial(track: pd.DataFrame, *, trial: str, method: str, stick: bool,
                        pose, leg_width_m: float, height_m: float,
                        targets: pd.DataFrame | None, annotations=None, clock=(None, 0.0),
                        truth: pd.DataFrame | None = None, gate=None, cfg: dict | None = None,
                        annotation_path=None) -> dict[str, pd.DataFrame]:
    """Walking parameters and evaluations of one tracked MTST trial.

    Parameters
    ----------
    track : DataFrame
        :func:`gaitval.methods.track_trial` output (sensor frame, sensor clock).
    pose : (x_m, y_m, yaw_rad)
        The sensor in the field frame (targets and mat are in the field frame).
    targets : DataFrame or None
        ``target, x_m, y_m, color, assigned`` of this trial.
    annotations : (DataFrame, dict) or None
        :func:`gaitval.io.annotations.read_annotations` output.
    clock : (clock_offset_s or None, clock_drift_ppm)
    truth : DataFrame or None
        Mocap ground truth (``t_sensor_s, side, xs_m, ys_m, valid``).
    gate : VariableValidationRegion or None
        The method's gate when it is the variable region (Table 1 usage), else None.

    Returns
    -------
    dict of DataFrame
        ``contacts`` (field frame), ``steps`` (one row per annotated contact),
        ``events`` (tracking failures, both references), ``gates`` (Table 1 cells),
        ``track_field`` (the track in the field frame with the true leg point at each row,
        ``x_true_m, y_true_m``, NaN without mocap; for the figure) and ``summary`` (one
        row, :data:`SUMMARY_COLUMNS`).
    """
    s = settings(cfg)
    ev_cfg = s["evaluation"]
    track_f = track_in_field(track, pose)
    contacts = walking_parameters(track_f, targets, leg_width_m=leg_width_m,
                                  height_m=height_m, s=s)
    track_f["x_true_m"], track_f["y_true_m"] = truth_in_field(track, truth, pose)
    events = []
    row = {"trial": trial, "method": method, "stick": bool(stick), "has_mocap": truth is not None,
           "has_annotations": annotations is not None, "has_targets": targets is not None,
           "category_mocap": "", "category_annotations": "", "n_contacts_sys": len(contacts),
           "category_mocap_persistent_swap": "",
           "n_cross_sys_all": int(contacts["cross"].sum())}
    if truth is not None:
        row["category_mocap"], ev = tracking_vs_truth(track, truth, ev_cfg)
        # the second judging rule, beside the paper's (issue 34)
        row["category_mocap_persistent_swap"] = persistent_swap_verdict(ev, ev_cfg)
        events.append(ev)
    steps = pd.DataFrame()
    if annotations is not None:
        t = track["t_sensor_s"].to_numpy(float)
        steps, matched, counts = evaluate_steps(
            annotations[0], annotations[1], contacts, clock=clock,
            t_scans=(float(np.nanmin(t)), float(np.nanmax(t))), cfg=ev_cfg,
            path=annotation_path, trial=trial)
        contacts["matched"] = matched
        row["category_annotations"], ev = tracking_vs_annotations(steps, contacts, ev_cfg)
        events.append(ev)
        row.update(counts)
        if targets is None:
            row.update(n_target_ref=0, non_judgement=0, misjudgement=0)
    gates = (gate_usage(track, leg_width_m, gate) if gate is not None
             else pd.DataFrame(columns=["k", "side", "cell", "radius_m", "radius_leg_widths"]))
    for df in [contacts, steps, gates, track_f] + events:
        df.insert(0, "method", method)
        df.insert(0, "trial", trial)
    ev_all = (pd.concat(events, ignore_index=True) if events else
              pd.DataFrame(columns=["trial", "method", "side", "kind", "t_start_s",
                                    "t_end_s", "duration_s", "reference"]))
    summary = pd.DataFrame([row]).reindex(columns=list(SUMMARY_COLUMNS))
    return {"contacts": contacts, "steps": steps, "events": ev_all, "gates": gates,
            "track_field": track_f[["trial", "method", "k", "t_sensor_s", "side", "x_m",
                                    "y_m", "pattern", "swing", "x_true_m", "y_true_m"]],
            "summary": summary}
