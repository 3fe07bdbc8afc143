"""Assemble a simulated study: subjects, trials, raw files, truth and realism figures.

Entry point :func:`generate_study`; presets live in ``config/studies/<name>.yaml``.
"""
from __future__ import annotations

import copy
import logging
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval.errors import ConfigError
from gaitval.io.annotations import write_annotations
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.io.c3d import write_c3d
from gaitval.io.scanlog import write_scanlog
from gaitval.simulate import protocols as P
from gaitval.simulate import render as RD
from gaitval.simulate.kinematics import GaitParams

log = logging.getLogger(__name__)
PRESET_DIR = Path(__file__).resolve().parents[2] / "config" / "studies"
TRIAL_COLUMNS = ["study", "protocol", "subject", "trial", "sensor_kind", "mocap_file",
                 "sensor_file", "sensor_topic", "annotation_file", "sensor_height_m",
                 "clock_offset_s", "speed", "speed_mps", "stick", "scenario", "repetition"]
SUBJECT_COLUMNS = ["subject", "group", "age_y", "sex", "height_m", "mass_kg", "leg_width_m",
                   "knee_width_m", "ankle_width_m", "leg_length_m", "shank_length_m", "stick"]


def load_preset(preset: str | dict) -> dict:
    """A preset by name (``config/studies/<name>.yaml``) or as a dict of the same shape."""
    if isinstance(preset, dict):
        return copy.deepcopy(preset)
    path = PRESET_DIR / f"{preset}.yaml"
    if not path.is_file():
        known = sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))
        raise ConfigError(f"unknown simulation preset {preset!r}", path=path,
                          hint=f"known presets: {', '.join(known)}")
    with open(path, encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def _rng(seed: int, *keys: int) -> np.random.Generator:
    """Independent stream per (seed, purpose, index...): results do not depend on order."""
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, *[int(k) for k in keys]])


def _clock(rng, cfg) -> dict:
    lo, hi = cfg.get("offset_s", [0.2, 2.0])
    return {"clock_offset_s": round(float(rng.uniform(lo, hi)), 6),
            "clock_drift_ppm": round(float(rng.normal(0.0, cfg.get("drift_ppm_sd", 30.0))), 3),
            "jitter_s": float(cfg.get("jitter_s", 0.0005))}


def _trial_row(study, sim: P.TrialSim, mocap, sensor, annot="", speed_mps=np.nan) -> dict:
    return {"study": study, "protocol": sim.protocol, "subject": sim.subject,
            "trial": sim.trial, "sensor_kind": "lrs", "mocap_file": mocap,
            "sensor_file": sensor, "sensor_topic": "", "annotation_file": annot,
            "sensor_height_m": sim.sensor_height_m, "clock_offset_s": np.nan,
            "speed": sim.speed, "speed_mps": speed_mps, "stick": bool(sim.stick),
            "scenario": sim.scenario, "repetition": int(sim.repetition)}


def _mtst_annotations(sim: P.TrialSim, ev: pd.DataFrame, rng) -> tuple[pd.DataFrame, float]:
    """The rater's video scoring: contacts, target steps (hit/miss), cross steps.

    Video at 30 fps on its own time base: ``t_video = t_mocap - time_offset_s``; the rater
    marks each contact with a timing error N(0, 40 ms) quantised to the video frame.
    Hit: the foot (0.25 × 0.09 m) overlaps the 0.160 × 0.165 m target.
    """
    offset = round(float(rng.uniform(-3.0, -0.5)), 4)
    fps = 30.0
    p = sim.walker.plan
    rows = []
    tg = sim.targets.set_index("target")
    for i in range(2, len(p.side)):
        if p.t_contact[i] > sim.t_end_s:
            continue
        side = "LR"[p.side[i]]
        tv = p.t_contact[i] - offset + 0.040 * rng.standard_normal()
        tv = np.round(tv * fps) / fps
        rows.append({"t_s": tv, "event": "foot_contact", "side": side})
        if i in sim.target_steps:
            t_id = sim.target_steps[i]
            dx = abs(p.xy[i, 0] + 0.05 - tg.loc[t_id, "x_m"])     # foot centre ahead of ankle
            dy = abs(p.xy[i, 1] - tg.loc[t_id, "y_m"])
            hit = dx < (P.TARGET_L + 0.25) / 2 and dy < (P.TARGET_W + 0.09) / 2
            rows.append({"t_s": tv, "event": "target_step", "side": side, "target": t_id,
                         "value": "hit" if hit else "miss"})
        if p.cross[i]:
            rows.append({"t_s": tv, "event": "cross_step", "side": side, "value": "yes"})
    df = pd.DataFrame(rows)
    for c in ("target", "value"):
        if c not in df:
            df[c] = ""
    df[["target", "value"]] = df[["target", "value"]].fillna("")
    return df, offset


def _variant(rng, cfg) -> dict:
    m = cfg.get("mocap", {})
    u = rng.random()
    pb = m.get("p_bones", 0.5)
    bones = "pig" if u < pb else ("jc" if u < pb + m.get("p_jc", 0.15) else None)
    return {"bones": bones, "medial": bool(rng.random() < m.get("p_medial", 0.5))}


def _render_trial(out: Path, study: str, sim: P.TrialSim, subj: dict, clock: dict,
                  seed: int, idx: int, realism_rows: list, sheet_rows: list,
                  pose_rows: list) -> None:
    rng_l = _rng(seed, 11, idx)
    rng_m = _rng(seed, 12, idx)
    series, scans, stats, poses = RD.render_laser(sim, clock, rng_l)
    labels, xyz, legs, rpose = RD.render_mocap(sim, subj, rng_m)
    ev = RD.gait_events(sim)
    mocap_rel = f"mocap/{sim.trial}.c3d"
    lrs_rel = f"lrs/{sim.trial}.scan.parquet"
    write_c3d(out / mocap_rel, labels, xyz, sim.mocap_rate_hz, events=RD.c3d_events(ev))
    spec_period = 0.025 if sim.sensor == "utm30lx" else 0.028
    write_scanlog(out / lrs_rel, series, scan_time_s=spec_period)
    tdir = out / "truth" / sim.trial
    write_parquet(legs, tdir / "legs.parquet")
    write_parquet(scans, tdir / "scans_legs.parquet")
    write_csv(ev, tdir / "events.csv", float_format="%.5f")
    if rpose is not None:
        write_parquet(rpose, tdir / "sensor_pose.parquet")
    annot_rel = ""
    if sim.protocol == "mtst":
        ann, off = _mtst_annotations(sim, ev, _rng(seed, 13, idx))
        annot_rel = f"annotations/{sim.trial}.annotations.csv"
        write_annotations(out / annot_rel, ann, time_base="video", time_offset_s=off,
                          rater="R1", fps=30.0)
        write_csv(sim.targets, tdir / "targets.csv", float_format="%.4f")
    p = sim.walker.plan
    # walking speed: distance each foot travelled (mean of both) over the walking time
    dist = np.mean([np.sum(np.hypot(*np.diff(p.xy[p.side == k], axis=0).T)) for k in (0, 1)])
    speed = float(dist) / max(p.t_end - p.t_start, 1e-6)
    sheet_rows.append(_trial_row(study, sim, mocap_rel, lrs_rel, annot_rel,
                                 round(speed, 3)))
    if sim.fixed_pose is not None:
        pose_rows.append({"trial": sim.trial, "x_m": sim.fixed_pose[0],
                          "y_m": sim.fixed_pose[1], "yaw_rad": sim.fixed_pose[2],
                          "clock_offset_s": clock["clock_offset_s"],
                          "clock_drift_ppm": clock["clock_drift_ppm"]})
    else:
        pose_rows.append({"trial": sim.trial, "x_m": np.nan, "y_m": np.nan,
                          "yaw_rad": np.nan, "clock_offset_s": clock["clock_offset_s"],
                          "clock_drift_ppm": clock["clock_drift_ppm"]})
    # realism per trial (aggregated later)
    in_mocap = (scans["t_mocap_s"] >= 0) & (scans["t_mocap_s"] <= sim.t_end_s)
    sp = RD.leg_speeds(legs)
    n_steps = int(np.sum(np.isfinite(p.t_contact) & (p.t_contact <= sim.t_end_s)))
    n_cross = int(np.sum(p.cross & (p.t_contact <= sim.t_end_s)))
    phases = ["all"] + (["forward", "turning", "return"] if sim.protocol == "tug" else [])
    for ph in phases:
        s = scans[in_mocap] if ph == "all" else scans[in_mocap & (scans["phase"] == ph)]
        realism_rows.append({
            "protocol": sim.protocol, "phase": ph, "trial": sim.trial,
            "leg_scans": len(s), "occluded_leg_scans": int(s["occluded"].sum()),
            "occluded_L": int(s.loc[s["side"] == "L", "occluded"].sum()),
            "occluded_R": int(s.loc[s["side"] == "R", "occluded"].sum()),
            "beams": stats["n_beams_total"] if ph == "all" else np.nan,
            "returns": stats["n_returns"] if ph == "all" else np.nan,
            "mixed": stats["n_mixed"] if ph == "all" else np.nan,
            "dropouts": stats["n_dropout"] if ph == "all" else np.nan,
            "stance_speed_mps": sp["stance_speed_mps"] if ph == "all" else np.nan,
            "swing_speed_mps": sp["swing_speed_mps"] if ph == "all" else np.nan,
            "swing_peak_mps": sp["swing_peak_mps"] if ph == "all" else np.nan,
            "walking_speed_mps": speed if ph == "all" else np.nan,
            "steps": n_steps if ph == "all" else np.nan,
            "cross_steps": n_cross if ph == "all" else np.nan,
        })


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


def _subject_rows(study_cfg: dict, seed: int):
    """Yield (protocol, subject dict, GaitParams) for every participant of the preset."""
    out = []
    k = 0
    for proto, group, prefix in (("tug", "young", "Y"), ("mtst", "elderly", "E"),
                                 ("rollator", "patient", "P")):
        c = study_cfg.get(proto)
        if not c or not c.get("n_subjects"):
            continue
        n = int(c["n_subjects"])
        n_stick = int(c.get("n_stick", 0))
        for i in range(n):
            stick = i >= n - n_stick
            subj, gp = P.sample_subject(_rng(seed, 1, k), group, f"{prefix}{i + 1:02d}",
                                        c["sensor_height_m"], stick=stick)
            out.append((proto, subj, gp))
            k += 1
    return out


def generate_study(out_dir: Path, preset: str | dict = "default", seed: int | None = None
                   ) -> Path:
    """Write a complete simulated study into ``out_dir``.

    Parameters
    ----------
    out_dir : Path
        Study folder (created).  Receives ``trials.csv``, ``subjects.csv``,
        ``study.yaml`` (study calibrations: rollator sensor mount, pole diameter),
        ``mocap/*.c3d``, ``lrs/*.scan.parquet``, ``annotations/*.annotations.csv`` (MTST),
        the ultrasonic protocols' files (when :mod:`gaitval.simulate.ultrasonic` is
        present), ``realism.csv`` and ``truth/`` (for tests only).
    preset : str or dict
        ``default``, ``tiny``, ``replay`` (``config/studies/<name>.yaml``) or a dict of
        the same shape.
    seed : int, optional
        Overrides the preset's ``seed``.

    Returns
    -------
    Path
        ``out_dir / "trials.csv"``.
    """
    cfg = load_preset(preset)
    if cfg.get("replay"):
        from gaitval.simulate.replay import generate_replay_study
        return generate_replay_study(Path(out_dir), cfg, seed)
    seed = int(cfg.get("seed", 0) if seed is None else seed)
    study = str(cfg.get("study", "default"))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sheet, realism, poses, subjects = [], [], [], []
    clock_cfg = cfg.get("clock", {})
    idx = 0
    attendant_gp = GaitParams(step_length_m=0.55, step_width_m=0.12, step_time_s=0.6,
                              stance_frac=0.62, step_cv=0.03, place_sd_m=0.02,
                              shank_length_m=0.40, hip_height_m=0.85)
    tick = {"t": time.perf_counter(), "proto": None}

    def lap(proto):
        now = time.perf_counter()
        if tick["proto"] is not None:
            log.info("simulated %s in %.2f s", tick["proto"], now - tick["t"])
        tick.update(t=now, proto=proto)

    for si, (proto, subj, gp) in enumerate(_subject_rows(cfg, seed)):
        if proto != tick["proto"]:
            lap(proto)
        c = cfg[proto]
        subjects.append(subj)
        rng_s = _rng(seed, 2, si)
        if proto == "tug":
            pose = P._pose_jitter(rng_s, c["sensor_nominal_pose"])
            drift = _clock(rng_s, clock_cfg)["clock_drift_ppm"]
            for r in range(1, int(c["n_trials"]) + 1):
                idx += 1
                rng_t = _rng(seed, 3, idx)
                sim = P.build_tug(rng_t, study, subj, gp, f"tug_{subj['subject']}_t{r}", r,
                                  pose, c)
                sim.variant.update(_variant(rng_t, cfg))
                clock = {**_clock(rng_t, clock_cfg), "clock_drift_ppm": drift}
                _render_trial(out, study, sim, subj, clock, seed, idx, realism, sheet, poses)
        elif proto == "mtst":
            pose = P._pose_jitter(rng_s, c["sensor_nominal_pose"])
            drift = _clock(rng_s, clock_cfg)["clock_drift_ppm"]
            for r in range(1, int(c["n_trials"]) + 1):
                idx += 1
                rng_t = _rng(seed, 3, idx)
                color = P.COLORS[(r - 1) % 3]
                sim = P.build_mtst(rng_t, study, subj, gp, f"mtst_{subj['subject']}_t{r}", r,
                                   pose, c, color, bool(subj["stick"]), attendant_gp)
                sim.variant.update(_variant(rng_t, cfg))
                clock = {**_clock(rng_t, clock_cfg), "clock_drift_ppm": drift}
                _render_trial(out, study, sim, subj, clock, seed, idx, realism, sheet, poses)
        elif proto == "rollator":
            drift = _clock(rng_s, clock_cfg)["clock_drift_ppm"]
            for scen in c.get("scenarios", ["straight", "obstacle"]):
                for r in range(1, int(c.get("n_repetitions", 2)) + 1):
                    idx += 1
                    rng_t = _rng(seed, 3, idx)
                    sim = P.build_rollator(rng_t, study, subj, gp,
                                           f"rollator_{subj['subject']}_{scen}_r{r}", r, scen, c)
                    sim.variant.update(_variant(rng_t, cfg))
                    clock = {**_clock(rng_t, clock_cfg), "clock_drift_ppm": drift}
                    _render_trial(out, study, sim, subj, clock, seed, idx, realism, sheet,
                                  poses)
    lap("ultrasonic" if cfg.get("ultrasonic") else None)
    trials = pd.DataFrame(sheet, columns=TRIAL_COLUMNS)
    subj_df = pd.DataFrame(subjects, columns=SUBJECT_COLUMNS)
    if cfg.get("ultrasonic"):
        try:
            from gaitval.simulate.ultrasonic import generate_ultrasonic
        except ImportError as exc:
            warnings.warn(f"ultrasonic protocols skipped: {exc}", stacklevel=2)
        else:
            ucfg = {**cfg["ultrasonic"], "study": study}
            ut, us = generate_ultrasonic(out, ucfg, seed)
            lap(None)
            trials = pd.concat([trials, ut.reindex(columns=TRIAL_COLUMNS)], ignore_index=True)
            subj_df = pd.concat([subj_df, us.reindex(columns=SUBJECT_COLUMNS)],
                                ignore_index=True)
    write_csv(trials, out / "trials.csv")
    write_csv(subj_df, out / "subjects.csv")
    write_csv(pd.DataFrame(poses, columns=["trial", "x_m", "y_m", "yaw_rad", "clock_offset_s",
                                           "clock_drift_ppm"]),
              out / "truth" / "sensor_pose.csv", float_format="%.9g")
    if realism:
        write_csv(summarise_realism(realism), out / "realism.csv", float_format="%.6g")
    mount = cfg.get("rollator", {}).get("sensor_mount",
                                        {"x_m": -0.22, "y_m": 0.0, "yaw_rad": float(np.pi)})
    write_text(out / "study.yaml", yaml.safe_dump({
        "study": study, "seed": seed,
        "registration": {"pole_diameter_m": 2 * P.POLE_RADIUS_M},
        "rollator": {"sensor_mount": {k: float(v) for k, v in mount.items()}},
    }, sort_keys=True))
    return out / "trials.csv"
