"""Assemble a simulated study: subjects, trials, raw files, truth and realism figures.

Entry point :func:`generate_study`; presets live in ``config/studies/<name>.yaml``.  The
trial-sheet and subject-table columns, the sensor clock draw and the realism summary are
shared with the replay of real walks (:mod:`gaitval.simulate.replay`) from
:mod:`gaitval.simulate.sheet` and re-exported here.
"""
from __future__ import annotations

import concurrent.futures as cf
import copy
import logging
import multiprocessing as mp
import os
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
from gaitval.simulate.mtst import TARGETS_FILE, mtst_calibration
from gaitval.simulate.physics import write_physics
from gaitval.simulate.sheet import (SUBJECT_COLUMNS, TRIAL_COLUMNS, sensor_clock,
                                    summarise_realism)

__all__ = ["PRESET_DIR", "SUBJECT_COLUMNS", "TRIAL_COLUMNS", "generate_study", "load_preset",
           "summarise_realism"]

log = logging.getLogger(__name__)
PRESET_DIR = Path(__file__).resolve().parents[2] / "config" / "studies"


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
        # the layout as a study input (field frame), named by study.yaml's mtst.targets
        write_csv(sim.targets[["target", "x_m", "y_m", "color", "assigned"]],
                  out / TARGETS_FILE.format(trial=sim.trial), float_format="%.4f")
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
            out.append((proto, *_subject_choices(study_cfg, proto, subj, gp)))
            k += 1
    return out


def _subject_choices(study_cfg: dict, proto: str, subj: dict, gp: GaitParams
                     ) -> tuple[dict, GaitParams]:
    """A participant with the preset's free choices of the participants applied after
    their draws (so every other draw is unchanged): ``leg_width_scale`` (top level)
    scales the leg width at the scan height, ``shank_clearance_m`` (top level) replaces
    the air between passing shanks, ``tug.turn_step_factor`` replaces the turning
    step length factor, ``mtst.step_width_scale`` scales the step width.  Absent keys
    change nothing (docs/robustness.md, "Plausible ranges")."""
    from dataclasses import replace

    c = study_cfg.get(proto) or {}
    scale = float(study_cfg.get("leg_width_scale", 1.0))
    if scale != 1.0:
        subj = {**subj, "leg_width_m": round(subj["leg_width_m"] * scale, 4)}
    if proto == "tug" and "turn_step_factor" in c:
        gp = replace(gp, turn_step_factor=float(c["turn_step_factor"]))
    if proto == "mtst" and "step_width_scale" in c:
        gp = replace(gp, step_width_m=gp.step_width_m * float(c["step_width_scale"]))
    if "shank_clearance_m" in study_cfg:
        gp = replace(gp, shank_clearance_m=float(study_cfg["shank_clearance_m"]))
    return subj, gp


def _subject_trials(proto: str, c: dict, study: str, subj: dict, gp: GaitParams, rng_s,
                    attendant_gp: GaitParams) -> list:
    """One participant's trials as ``(build, args)``, in order: ``build(rng_t, *args)`` is
    the trial's ``TrialSim`` (module-level functions and plain arguments, so a trial can be
    rendered in a worker process).

    TUG and MTST draw the fixed sensor's pose for this participant from ``rng_s`` here.
    """
    sid = subj["subject"]
    if proto == "tug":
        pose = P._pose_jitter(rng_s, c["sensor_nominal_pose"])
        return [(P.build_tug, (study, subj, gp, f"tug_{sid}_t{r}", r, pose, c))
                for r in range(1, int(c["n_trials"]) + 1)]
    if proto == "mtst":
        pose = P._pose_jitter(rng_s, c["sensor_nominal_pose"])
        return [(P.build_mtst, (study, subj, gp, f"mtst_{sid}_t{r}", r, pose, c,
                                P.COLORS[(r - 1) % 3], bool(subj["stick"]), attendant_gp))
                for r in range(1, int(c["n_trials"]) + 1)]
    if proto == "rollator":
        return [(P.build_rollator, (study, subj, gp, f"rollator_{sid}_{scen}_r{r}", r, scen, c))
                for scen in c.get("scenarios", ["straight", "obstacle"])
                for r in range(1, int(c.get("n_repetitions", 2)) + 1)]
    return []


def tug_scene_table(tug_cfg: dict) -> pd.DataFrame:
    """The TUG scene's static objects at shin height as the study's truth
    (``truth/tug_scene.csv``): ``x_m, y_m, radius_m`` in the field frame, ``object_id`` and
    ``object`` (:data:`gaitval.simulate.scene.ID_NAMES`).  The turn marker is there only
    when the preset's ``tug.marker_scan_radius_m`` puts it in the scan plane."""
    from gaitval.simulate.scene import ID_NAMES
    from gaitval.simulate.tug import marker_scan_radius, scene_circles

    c = scene_circles(marker_scan_radius(tug_cfg))
    return pd.DataFrame({"x_m": c[:, 0], "y_m": c[:, 1], "radius_m": c[:, 2],
                         "object_id": c[:, 3].astype(int),
                         "object": [ID_NAMES[int(k)] for k in c[:, 3]]})


def _lrs_tasks(cfg: dict, study: str, seed: int, subjects: list) -> list[tuple]:
    """Every LRS trial (TUG, MTST, rollator) of the preset as the arguments of
    :func:`_simulate_trial`, in trial order; appends the participants to ``subjects``.

    Streams: participant ``si`` draws from ``_rng(seed, 2, si)`` (sensor pose, clock
    drift), trial ``idx`` (1-based over the study) from ``_rng(seed, 3, idx)`` (scene,
    mocap variant, clock offset), so a trial's bytes do not depend on where it runs.
    """
    clock_cfg = cfg.get("clock", {})
    attendant_gp = GaitParams(step_length_m=0.55, step_width_m=0.12, step_time_s=0.6,
                              stance_frac=0.62, step_cv=0.03, place_sd_m=0.02,
                              shank_length_m=0.40, hip_height_m=0.85)
    tasks = []
    for si, (proto, subj, gp) in enumerate(_subject_rows(cfg, seed)):
        subjects.append(subj)
        rng_s = _rng(seed, 2, si)
        builders = _subject_trials(proto, cfg[proto], study, subj, gp, rng_s, attendant_gp)
        drift = sensor_clock(rng_s, clock_cfg)["clock_drift_ppm"]
        for build, bargs in builders:
            tasks.append((len(tasks) + 1, proto, build, bargs, subj, drift))
    return tasks


def _simulate_trial(out: Path, cfg: dict, study: str, seed: int, idx: int, build, bargs,
                    subj: dict, drift: float) -> tuple[list, list, list]:
    """Simulate and write trial ``idx``; its (realism, sheet, pose) rows."""
    rng_t = _rng(seed, 3, idx)
    sim = build(rng_t, *bargs)
    sim.variant.update(_variant(rng_t, cfg))
    clock = {**sensor_clock(rng_t, cfg.get("clock", {})), "clock_drift_ppm": drift}
    realism, sheet, poses = [], [], []
    _render_trial(out, study, sim, subj, clock, seed, idx, realism, sheet, poses)
    return realism, sheet, poses


def _ultrasonic_plan(cfg: dict, study: str, seed: int):
    """The ultrasonic protocols' plan (:func:`gaitval.simulate.ultrasonic.plan_ultrasonic`)
    and its module, or the reason they are skipped (a str)."""
    try:
        from gaitval.simulate import ultrasonic as U
    except ImportError as exc:
        return str(exc), None
    return U.plan_ultrasonic({**cfg["ultrasonic"], "study": study}, seed), U


def _workers(n_tasks: int, workers: int | None) -> int:
    if workers is None:
        try:
            workers = len(os.sched_getaffinity(0))
        except AttributeError:                                   # not Linux
            workers = os.cpu_count() or 1
    return max(1, min(int(workers), n_tasks))


class _Serial:
    """The ``concurrent.futures`` executor interface, run in this process (1 worker)."""

    def submit(self, fn, *args):
        f = cf.Future()
        f.set_result(fn(*args))
        return f

    def map(self, fn, *iterables):
        return map(fn, *iterables)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def _executor(n: int):
    if n <= 1:
        return _Serial()
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else None
    return cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx)


def generate_study(out_dir: Path, preset: str | dict = "default", seed: int | None = None,
                   *, workers: int | None = None) -> Path:
    """Write a complete simulated study into ``out_dir``.

    Parameters
    ----------
    out_dir : Path
        Study folder (created).  Receives ``trials.csv``, ``subjects.csv``,
        ``study.yaml`` (study calibrations: rollator sensor mount, pole diameter),
        ``mocap/*.c3d``, ``lrs/*.scan.parquet``, ``annotations/*.annotations.csv`` and
        ``targets/*.targets.csv`` (MTST; study.yaml's ``mtst`` names them),
        the ultrasonic protocols' files (when :mod:`gaitval.simulate.ultrasonic` is
        present), ``realism.csv``, ``physics.csv`` (the physical checks of
        :mod:`gaitval.simulate.physics`) and ``truth/`` (for tests only).
    preset : str or dict
        ``default``, ``tiny``, ``replay`` (``config/studies/<name>.yaml``) or a dict of
        the same shape.
    seed : int, optional
        Overrides the preset's ``seed``.
    workers : int, optional
        Processes rendering trials at once (default: the CPUs this process may use; 1
        renders in this process).  Every trial draws from its own seeded streams, so the
        files are byte-identical whatever the number.

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
    t0 = time.perf_counter()
    tasks = _lrs_tasks(cfg, study, seed, subjects)
    us_plan, U = _ultrasonic_plan(cfg, study, seed) if cfg.get("ultrasonic") else (None, None)
    us_tasks = us_plan.tasks if U is not None else []
    with _executor(_workers(len(tasks) + len(us_tasks), workers)) as ex:
        # the ultrasonic trials first (5-min treadmill walks, the longest tasks), each its
        # own task beside the LRS trials; every trial has its own seed
        us_futures = [ex.submit(U.simulate_ultrasonic_trial, out, us_plan, task)
                      for task in us_tasks]
        futures = [ex.submit(_simulate_trial, out, cfg, study, seed, idx, build, bargs,
                             subj, drift)
                   for idx, proto, build, bargs, subj, drift in tasks]
        for f in futures:                                        # in trial order
            r, sh, po = f.result()
            realism += r
            sheet += sh
            poses += po
        us = U.finish_ultrasonic(out, us_plan, [f.result() for f in us_futures]) \
            if U is not None else us_plan
    log.info("simulated %d LRS trials%s in %.2f s", len(tasks),
             f" and {len(us_tasks)} ultrasonic trials" if us_tasks else "",
             time.perf_counter() - t0)
    trials = pd.DataFrame(sheet, columns=TRIAL_COLUMNS)
    subj_df = pd.DataFrame(subjects, columns=SUBJECT_COLUMNS)
    if isinstance(us, str):
        warnings.warn(f"ultrasonic protocols skipped: {us}", stacklevel=2)
    elif us is not None:
        ut, usj = us
        trials = pd.concat([trials, ut.reindex(columns=TRIAL_COLUMNS)], ignore_index=True)
        subj_df = pd.concat([subj_df, usj.reindex(columns=SUBJECT_COLUMNS)],
                            ignore_index=True)
    write_csv(trials, out / "trials.csv")
    write_csv(subj_df, out / "subjects.csv")
    write_csv(pd.DataFrame(poses, columns=["trial", "x_m", "y_m", "yaw_rad", "clock_offset_s",
                                           "clock_drift_ppm"]),
              out / "truth" / "sensor_pose.csv", float_format="%.9g")
    if (cfg.get("tug") or {}).get("n_subjects"):
        write_csv(tug_scene_table(cfg["tug"]), out / "truth" / "tug_scene.csv",
                  float_format="%.9g")
    if realism:
        write_csv(summarise_realism(realism), out / "realism.csv", float_format="%.6g")
    # the physical checks of the twin (gaitval.simulate.physics): data/<study>/physics.csv;
    # the per-trial swing statistics read back across the same workers (same rows)
    walkers = [(p, s["group"], gp) for p, s, gp in _subject_rows(cfg, seed)]
    with _executor(_workers(len(tasks), workers)) as ex:
        write_physics(out, walkers=walkers, map_fn=ex.map)
    mount = cfg.get("rollator", {}).get("sensor_mount",
                                        {"x_m": -0.22, "y_m": 0.0, "yaw_rad": float(np.pi)})
    calibration = {
        "study": study, "seed": seed,
        "registration": {"pole_diameter_m": 2 * P.POLE_RADIUS_M},
        "rollator": {"sensor_mount": {k: float(v) for k, v in mount.items()}},
    }
    if (cfg.get("mtst") or {}).get("n_subjects"):
        calibration["mtst"] = mtst_calibration()
    write_text(out / "study.yaml", yaml.safe_dump(calibration, sort_keys=True))
    return out / "trials.csv"
