"""Ultrasonic steps (seed 003): noise identification, UKF tracks, gait parameters per stride (of
gaitval's track or of another system's heel trajectory), the tables and the agreement of
several systems.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, GaitvalError
from gaitval.io.atomic import write_parquet, write_text
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.steps.config import load_json
from gaitval.pipeline.steps.trials import trial_and_subject


def ultrasonic_noise_step(ingest_dirs: list[str | Path], trials: list[str], config_json,
                          out_json, table_stem, reports_dir, config_hash: str = "") -> dict:
    """Identify V (per anchor) and W from the pendulum trials (seed 003 §4.3, eq. 23) and
    render Table 1.  Writes ``noise.json`` (V, W, bias, RMSE) for the treadmill tracks."""
    from gaitval.io.ingest import read_mocap_parquet
    from gaitval.io.ultrasonic import read_ultrasonic
    from gaitval.report.provenance import stamp
    from gaitval.tables.ultrasonic_table1 import build_ultrasonic_table1

    cfg = load_json(config_json).get("ultrasonic") or {}
    pairs = []
    for d, tid in zip(ingest_dirs, trials):
        d = Path(d)
        pairs.append((read_ultrasonic(d / "sensor.parquet", trial=tid),
                      read_mocap_parquet(d / "mocap.parquet", trial=tid)))
    if not pairs:
        raise GaitvalError("no pendulum trials: the noise identification of seed 003 §4.3 "
                           "needs at least one (protocol 'pendulum' in the trial sheet)")
    paths, noise = build_ultrasonic_table1(pairs, table_stem, cfg, names=list(trials))
    stamp(Path(table_stem).name, paths, reports_dir, config_hash_=config_hash)
    write_text(out_json, json.dumps(noise, indent=1, sort_keys=True) + "\n")
    return noise


def ultrasonic_track_step(ingest_dir, trial: str, config_json, noise_json, out_parquet
                          ) -> pd.DataFrame:
    """UKF track of one treadmill trial (seed 003 eq. 3-13).

    The tracker is the role :data:`gaitval.evaluate.ultrasonic_config.TRACKER` built from
    ``ultrasonic.ukf`` (:func:`~gaitval.evaluate.ultrasonic_config.build_tracker`).  V comes
    from the pendulum identification (``noise.json``); W stays the configured walking value
    (``ultrasonic.ukf.W_sigma_mps2``) unless ``ultrasonic.use_identified_W`` is true: the
    pendulum's slow arc gives a W far too small for a heel (see
    :func:`gaitval.stats.noise.identify_noise`).
    """
    from gaitval.evaluate.ultrasonic_config import build_tracker
    from gaitval.io.ultrasonic import read_ultrasonic

    cfg = dict(load_json(config_json).get("ultrasonic") or {})
    noise = load_json(noise_json)
    ukf = dict(cfg.get("ukf") or {})
    ukf["V_m2"] = noise["ukf"]["V_m2"]
    if cfg.get("use_identified_W", False):
        ukf["W_sigma_mps2"] = noise["ukf"]["W_sigma_mps2"]
    cfg["ukf"] = ukf
    log = read_ultrasonic(Path(ingest_dir) / "sensor.parquet", trial=trial)
    track = build_tracker(cfg).track(log, trial=trial)
    track.attrs = {}
    write_parquet(track, out_parquet)
    return track


def _treadmill_trial(ingest_dir, sheet, subjects, trial: str, config_json) -> tuple:
    """What a treadmill trial's stride extraction reads: the ``ultrasonic`` config section,
    the trial's sheet row and subject, its ultrasonic log (the anchors) and its mocap."""
    from gaitval.io.ingest import read_mocap_parquet
    from gaitval.io.ultrasonic import read_ultrasonic

    cfg = load_json(config_json).get("ultrasonic") or {}
    row, subj = trial_and_subject(sheet, subjects, trial)
    d = Path(ingest_dir)
    log = read_ultrasonic(d / "sensor.parquet", trial=trial)
    mocap = read_mocap_parquet(d / "mocap.parquet", source=row.get("mocap_path") or None,
                               trial=trial)
    return cfg, row, subj, log, mocap


def gait_parameters_step(track_parquet, ingest_dir, sheet, subjects, trial: str,
                         config_json, out_parquet) -> pd.DataFrame:
    """Gait parameters per stride for reference and system (seed 003 eq. 16-22)."""
    from gaitval.evaluate.ultrasonic import gait_parameters

    cfg, row, subj, log, mocap = _treadmill_trial(ingest_dir, sheet, subjects, trial,
                                                  config_json)
    track = read_parquet(track_parquet)
    gp = gait_parameters(track, mocap, row, subj, cfg, anchors=log.anchors)
    write_parquet(gp.reset_index(drop=True), out_parquet)
    return gp


def ultrasonic_tables_step(inputs: list[str | Path], tables_dir, figures_dir, reports_dir,
                           config_hash: str = "", config_json=None) -> list[Path]:
    """Seed 003 Tables 2-8, C1 and the figures from the per-trial gait parameters; the
    tables on the strides ``ultrasonic.tables`` of ``config_json`` selects (default: the
    paper's 10 per subject), the figures on every stride."""
    from gaitval.report.provenance import stamp
    from gaitval.report.stats_figures import write_ultrasonic_figures
    from gaitval.tables.ultrasonic import write_ultrasonic_tables

    gp = pd.concat([read_parquet(p) for p in inputs], ignore_index=True)
    cfg = (load_json(config_json).get("ultrasonic") or {}) if config_json else {}
    paths = write_ultrasonic_tables(gp, tables_dir, cfg)
    stamp("ultrasonic_tables", paths, reports_dir, config_hash_=config_hash)
    figs = write_ultrasonic_figures(gp, figures_dir)
    stamp("ultrasonic_figures", figs, reports_dir, config_hash_=config_hash)
    return paths + figs


def external_gait_parameters_step(foot_file, ingest_dir, sheet, subjects, trial: str,
                                  method: str, config_json, out_parquet) -> pd.DataFrame:
    """Gait parameters per stride of another system's heel trajectory on one treadmill
    trial (a ``*.foot.csv``/``.parquet``, :mod:`gaitval.io.foot`), reference vs that
    system, exactly as :func:`gait_parameters_step` does for gaitval's UKF track (seed 003
    eq. 16-22; issue 37).

    Frame: ``sensor`` is the ultrasonic receivers' frame (the trial's anchor table);
    ``mocap`` positions are brought into it by the receiver markers' rigid fit, as the
    reference is (:func:`gaitval.registration.anchors.fit_anchor_frame`).  Clock: a file
    on the mocap clock is aligned with offset 0; on the sensor clock, with the trial
    sheet's ``clock_offset_s`` when given, else by the cross-correlation that aligns
    gaitval's own track (§4.2).  The rows get a ``method`` column."""
    from gaitval.evaluate.ultrasonic import gait_parameters
    from gaitval.evaluate.ultrasonic_config import reference_kwargs, resolve_cfg
    from gaitval.groundtruth.reference import MAX_ANCHOR_RESIDUAL_M
    from gaitval.io.foot import check_foot, read_foot
    from gaitval.io.ultrasonic import anchor_positions
    from gaitval.registration.anchors import fit_anchor_frame

    cfg, row, subj, log, mocap = _treadmill_trial(ingest_dir, sheet, subjects, trial,
                                                  config_json)
    foot, meta = read_foot(foot_file, trial=trial)
    if meta["frame"] == "mocap":
        fit = fit_anchor_frame(mocap, log.anchors, reference_kwargs(resolve_cfg(cfg))
                               ["anchor_markers"], centre="mean",
                               max_residual_m=MAX_ANCHOR_RESIDUAL_M, trial=trial)
        foot[["x_m", "y_m", "z_m"]] = fit.to_ultrasonic(
            foot[["x_m", "y_m", "z_m"]].to_numpy(float))        # p_us = R^T (p_f - t)
    t_rec = np.asarray(log.t if meta["clock"] == "sensor" else mocap.t, float)
    check_foot(foot, meta, t_range=(float(t_rec[0]), float(t_rec[-1])),
               tolerance_s=float(np.median(np.diff(t_rec))) if len(t_rec) > 1 else 0.0,
               centre=anchor_positions(log.anchors).mean(axis=0), path=foot_file,
               trial=trial)
    if meta["clock"] == "mocap":
        row = {**row, "clock_offset_s": 0.0}      # t_system = t_mocap: no offset to find
    try:
        gp = gait_parameters(foot, mocap, row, subj, cfg, anchors=log.anchors)
    except GaitvalError as exc:           # the reference's file, or no stride in both
        raise GaitvalError(f"external method {method}, {foot_file}: {exc.problem}",
                           path=exc.path, trial=trial, hint=exc.hint) from None
    gp = gp.reset_index(drop=True)
    gp.insert(0, "method", method)
    write_parquet(gp, out_parquet)
    return gp


def method_agreement_step(groups: list[list[str]], out_stem, reports_dir,
                          config_hash: str = "", config_json=None) -> list[Path]:
    """The agreement table of several systems on the treadmill trials (issue 37): for
    each ``[method, gait file, ...]`` group, the pooled and repeated-measures agreement
    (:func:`gaitval.tables.ultrasonic_agreement.agreement_table`) of every parameter at
    every speed, on the strides ``ultrasonic.tables`` of ``config_json`` selects (the
    strides of seed 003's Tables 2-6)."""
    from gaitval.report.provenance import stamp
    from gaitval.tables.method_agreement import write_method_agreement

    gps = {}
    for g in groups:
        if len(g) < 2:
            raise ConfigError(f"--gait {' '.join(g)}: give a method name and its gait "
                              "parameter files")
        gps[g[0]] = pd.concat([read_parquet(f) for f in g[1:]], ignore_index=True)
    cfg = (load_json(config_json).get("ultrasonic") or {}) if config_json else {}
    paths = write_method_agreement(gps, out_stem, cfg)
    stamp(Path(out_stem).name, paths, reports_dir, config_hash_=config_hash)
    return paths
