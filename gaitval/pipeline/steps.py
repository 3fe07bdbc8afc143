"""Pipeline steps at file level: read the files of one rule, call the library, write files.

One function per rule family; :mod:`gaitval.cli` exposes each as a verb and the Snakemake
rules call those verbs.  The library functions they call take objects and return objects;
only this module and :mod:`gaitval.io` know where files live.

Per-study configuration (``results/<study>/config.json``) is the workflow config's
analysis sections merged with the study's own calibration file ``study.yaml`` beside
the trial sheet (pole diameter, the sensor mount on the rollator, ...): a calibration
belongs to the study, not to gaitval.
"""
from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval import consts as C
from gaitval.config import deep_merge
from gaitval.errors import ConfigError, FileFormatError, GaitvalError
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.pipeline.memo import FileMemo, file_identity
from gaitval.io.parquet import read_parquet
from gaitval.io.trialsheet import load_subjects, load_trial_row

#: Config sections that parameterise the analysis (copied into the per-study config).
ANALYSIS_SECTIONS = ("registration", "groundtruth", "rollator", "tracking", "tug",
                     "ultrasonic", "evaluation", "mtst")


STUDY_VIEW = "study"

#: the sections of one protocol family's own settings: a job of one family reads its own
#: and the shared sections (registration, groundtruth, tracking, evaluation), never another
#: family's (a view's scope, :func:`method_view`)
SCOPES = ("tug", "mtst", "rollator", "ultrasonic")
ALL_SCOPE = "all"
#: trial-sheet protocol -> scope of its jobs' views (another protocol: ALL_SCOPE)
PROTOCOL_SCOPE = {"tug": "tug", "mtst": "mtst", "rollator": "rollator",
                  "treadmill": "ultrasonic", "pendulum": "ultrasonic"}


def method_view(cfg: dict, view: str, scope: str = ALL_SCOPE) -> dict:
    """``cfg`` as the jobs of one method and protocol family read it: ``tracking.methods``
    and ``tracking.overrides`` reduced to method ``view``'s entries, or to none for
    ``view == STUDY_VIEW`` (the jobs without a method: registration, ultrasonic, ...), and,
    for a ``scope`` in :data:`SCOPES`, the other families' sections left out (``all``: none
    left out).  Every other key is kept.  A job looks up no other method's definition (it
    calls :func:`method_definition` with its own method) and no other family's section, so
    its results depend on this view only; the workflow reruns a method's jobs when its view
    changes, not on any change of another method or family (``workflow/rules/register.smk``,
    rule ``config_view``)."""
    if scope != ALL_SCOPE and scope not in SCOPES:
        raise ConfigError(f"unknown config view scope {scope!r} (one of {SCOPES + (ALL_SCOPE,)})")
    out = {k: v for k, v in cfg.items()
           if scope == ALL_SCOPE or k not in SCOPES or k == scope}
    tracking = dict(out.get("tracking") or {})
    for key in ("methods", "overrides", "external"):
        entries = tracking.get(key) or {}
        if key == "external" and view not in entries:
            tracking.pop(key, None)   # declaring an external method changes no other view
            continue
        tracking[key] = {view: entries[view]} if view in entries else {}
    out["tracking"] = tracking
    return out


def analysis_config(config: dict, sheet: str | Path, *, check: bool = False) -> dict:
    """A study's analysis config: the workflow config's :data:`ANALYSIS_SECTIONS`, with
    ``study.yaml`` beside the trial sheet, when present, merged over them (``check``:
    checked against the config schema first, :func:`gaitval.configcheck.check_study_file`)."""
    from gaitval.configcheck import check_study_file

    cfg = {k: config[k] for k in ANALYSIS_SECTIONS if k in config}
    cal = Path(sheet).parent / "study.yaml"
    if cal.is_file():
        with open(cal, encoding="utf-8") as fh:
            study = yaml.safe_load(fh) or {}
        if check:
            check_study_file(study, cal)
        cfg = deep_merge(cfg, {k: v for k, v in study.items() if k in ANALYSIS_SECTIONS})
        cfg["calibration_file"] = str(cal)
    own = study_external(sheet)     # the study's own external methods (issue 37): its
    if own:                         # study.yaml's and external.yaml's
        tracking = cfg.setdefault("tracking", {})
        tracking["external"] = {**(tracking.get("external") or {}), **own}
    return cfg


def study_config(config: dict, sheet: str | Path, out: str | Path,
                 view: str | None = None, scope: str = ALL_SCOPE) -> dict:
    """Write the effective analysis config of one study (JSON) and return it.

    The workflow config's :data:`ANALYSIS_SECTIONS` are the base; ``study.yaml`` beside the
    trial sheet, when present, overrides them (the study's calibration); it is checked
    against the config schema first, so a typo in it stops with the file and key named
    (:func:`gaitval.configcheck.check_study_file`).  With ``view`` (a method name or
    :data:`STUDY_VIEW`), only that view of it, in ``scope``, is written
    (:func:`method_view`).
    """
    cfg = analysis_config(config, sheet, check=True)
    if view is not None:
        cfg = method_view(cfg, view, scope)
    write_text(out, json.dumps(cfg, indent=1, sort_keys=True) + "\n")
    return cfg


def load_json(path: str | Path) -> dict:
    return json.loads(Path(path).read_text(encoding="utf-8"))


def _clean(v):
    if isinstance(v, (np.floating, float)):
        return None if not math.isfinite(float(v)) else float(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (np.bool_,)):
        return bool(v)
    return v


#: What a process read of a trial sheet and its subject table, by the files' identities:
#: the validated sheet (or None when it has a problem) and each subject's row.  A batch
#: worker's steps ask for trial after trial of the same sheet (~35 ms to validate the
#: default study's sheet once, against ~13 ms for one row alone every time).
_SHEETS = FileMemo(32 * 2 ** 20)
_SUBJECTS = FileMemo(8 * 2 ** 20)


def _sheet_files(sheet, subjects) -> tuple:
    sheet_p = Path(sheet)
    return (sheet_p, Path(subjects) if subjects is not None else
            sheet_p.parent / "subjects.csv", sheet_p.parent / "study.yaml")


def trial_row(sheet, subjects, trial: str, *, check_files: bool = True) -> dict:
    """One trial's validated row, as :func:`gaitval.io.trialsheet.load_trial_row` gives
    it, from the validated sheet this process keeps (a sheet with a problem: the row
    checked alone, its problem named)."""
    from gaitval.io.trialsheet import clean_sheet, row_of

    idents = tuple(file_identity(p) for p in _sheet_files(sheet, subjects))
    key = idents if idents[0] and idents[1] else None
    clean = _SHEETS.fetch(key, lambda: clean_sheet(sheet, subjects),
                          lambda df: 0 if df is None else int(df.memory_usage(deep=True).sum()))
    row = row_of(clean, sheet, trial, check_files)
    return row if row is not None else load_trial_row(sheet, subjects, trial,
                                                     check_files=check_files)


def trial_and_subject(sheet, subjects, trial: str) -> tuple[dict, dict]:
    """One trial's validated row and its subject's, as dicts (the caller's own copies)."""
    row = trial_row(sheet, subjects, trial, check_files=False)
    path = _sheet_files(sheet, subjects)[1]
    ident = file_identity(path)
    subj = _SUBJECTS.fetch(
        None if ident is None else (ident, row["subject"]),
        lambda: load_subjects(subjects, only=row["subject"]).loc[row["subject"]].to_dict(),
        lambda _: 4096)
    return row, copy.deepcopy(subj)


def load_ingested(ingest_dir: str | Path, row: dict):
    """The ingested mocap and sensor of a trial (see :mod:`gaitval.io.ingest`)."""
    from gaitval.io.ingest import read_mocap_parquet
    d = Path(ingest_dir)
    mocap = read_mocap_parquet(d / "mocap.parquet", d / "events.csv",
                               source=row.get("mocap_path") or None, trial=row["trial"])
    if row["sensor_kind"] == "ultrasonic":
        from gaitval.io.ultrasonic import read_ultrasonic
        sensor = read_ultrasonic(d / "sensor.parquet", trial=row["trial"])
    else:
        from gaitval.io.scanlog import read_scanlog
        sensor = read_scanlog(d / "sensor.parquet", trial=row["trial"])
    return mocap, sensor


# -- register + ground truth ------------------------------------------------------------
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


# -- tracking (LRS) ------------------------------------------------------------------------
def method_display_names(view_dir: str | Path, methods) -> dict[str, str]:
    """method -> its name in the tables (``tug_m3 (occlusion.max_n = 10)`` when run with
    overrides), from the method views ``<view_dir>/<method>.json`` beside a tables step's
    study view (the views its tracks ran with); a method without a view keeps its name."""
    from gaitval.methods import display_name

    out = {}
    for m in methods:
        d = _resolved_method(view_dir, m)
        if d is not None:
            out[m] = display_name(m, d)
    return out


def offline_methods(view_dir: str | Path | None, methods) -> set[str]:
    """The methods that report a scan using scans recorded after it (issue 36:
    ``people_offline``), judged on the definitions the tracks ran with (the method views in
    ``view_dir``; a method without a view: its built-in definition, if there is one)."""
    from gaitval.methods import METHODS, get_method, reads_later_scans

    out = set()
    for m in methods:
        d = _resolved_method(view_dir, m) if view_dir else None
        if d is None and m in METHODS:
            d = get_method(m)
        if d is not None and reads_later_scans(d):
            out.add(m)
    return out


def _resolved_method(view_dir: str | Path, m: str) -> dict | None:
    """Method ``m``'s definition as its view ``<view_dir>/<m>.json`` resolves it
    (``tracking.methods`` and ``tracking.overrides``); None without a view, or for an
    external method (issue 37)."""
    from gaitval.methods import get_method, set_params

    p = Path(view_dir) / f"{m}.json"
    if not p.is_file():
        return None
    cfg = load_json(p)
    if m in ((cfg.get("tracking") or {}).get("external") or {}):
        return None
    return set_params(get_method(method_definition(cfg, m)), method_overrides(cfg, m))


def method_definition(cfg: dict, method: str):
    """A method's definition: ``tracking.methods.<name>`` from config, else the built-in."""
    custom = (cfg.get("tracking") or {}).get("methods") or {}
    return custom.get(method, method)


def method_overrides(cfg: dict, method: str) -> dict:
    """The user's ``tracking.overrides.<name>`` (``role__param: value``), a new dict, empty
    when there are none."""
    return dict(((cfg.get("tracking") or {}).get("overrides") or {}).get(method) or {})


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


#: A trial's TUG phase bounds and true stance intervals, by its ground truth's identity and
#: the evaluation settings: the same for all six tracks of a trial.
_TRUTH_PHASES = FileMemo(16 * 2 ** 20)


def evaluate_tug_step(track_parquet, gt_parquet, registration_json, trial: str, method: str,
                      config_json, out_dir) -> pd.DataFrame:
    """Evaluate one tracked TUG trial against its registered ground truth.

    Writes ``frames.parquet``, ``events.parquet``, ``stance.parquet`` and
    ``summary.parquet`` (see :func:`gaitval.evaluate.tug.evaluate_tug_trial`).  A trial whose
    registration was refused gets an empty evaluation and ``category = not_registered``.
    """
    from gaitval.evaluate.tug import FRAME_COLUMNS, evaluate_tug_trial, truth_phases_of

    cfg = load_json(config_json)
    rec = load_json(registration_json)
    out = Path(out_dir)
    if rec.get("status") != "ok":
        res = {"frames": pd.DataFrame(columns=list(FRAME_COLUMNS)),
               "events": pd.DataFrame(columns=["trial", "method", "side", "kind"]),
               "stance": pd.DataFrame(columns=["trial", "method", "side", "identified"]),
               "summary": pd.DataFrame([{"trial": trial, "method": method, "success": False,
                                         "category": "not_registered"}])}
    else:
        track = read_parquet(track_parquet).drop(columns=["trial", "method"])
        gt = read_parquet(gt_parquet)
        ecfg = (cfg.get("evaluation") or {}).get("tug")
        phases = _TRUTH_PHASES.fetch(
            _TRUTH_PHASES.key(gt_parquet, json.dumps(ecfg, sort_keys=True, default=str)),
            lambda: truth_phases_of(gt, ecfg), lambda _: 4096)
        res = evaluate_tug_trial(track, gt, trial=trial, method=method, cfg=ecfg,
                                 truth_phases=(dict(phases[0]), phases[1].copy()))
    for name, df in res.items():
        write_parquet(df.reset_index(drop=True), out / f"{name}.parquet")
    return res["summary"]


def tug_tables_step(eval_dirs: list[str | Path], tables_dir, figures_dir, reports_dir,
                    config_hash: str = "", methods=("tug_m1", "tug_m2", "tug_m3"),
                    configs: list[str | Path] | None = None) -> list[Path]:
    """Gather per-trial TUG evaluations into seed 000 Tables 2-5 and the figures.

    Table 2 shows the method definitions actually run: ``tracking.methods`` and
    ``tracking.overrides`` of each study's ``config.json`` or of its method views
    ``results/<study>/config_views/tug/<method>.json`` (``configs``, which the workflow
    gives: the views, so that another section's change does not rerun these tables; default
    ``results/<study>/config.json`` above the ``evaluate/<method>/<trial>`` folders).  A
    method run with different parameters in different studies gets one set of rows per
    study, labelled ``<method> (<study>)``.
    """
    from gaitval.evaluate.tug import FRAME_COLUMNS
    from gaitval.methods import get_method, set_params
    from gaitval.report.provenance import stamp
    from gaitval.report.tug_figures import write_tug_figures
    from gaitval.tables.tug import write_tug_tables

    parts: dict[str, list[pd.DataFrame]] = {"frames": [], "summary": [], "events": []}
    for d in eval_dirs:
        for name in parts:
            df = read_parquet(Path(d) / f"{name}.parquet")
            if len(df):
                parts[name].append(df)
    empty = {"frames": pd.DataFrame(columns=list(FRAME_COLUMNS)),
             "summary": pd.DataFrame(columns=["trial", "method", "success", "category"]),
             "events": pd.DataFrame(columns=["trial", "method", "side", "kind", "t_start_s",
                                             "t_end_s", "tug_phase"])}
    frames, summaries, events = (pd.concat(parts[n], ignore_index=True) if parts[n]
                                 else empty[n] for n in ("frames", "summary", "events"))
    summaries = summaries[summaries.get("category", "") != "not_registered"] \
        if len(summaries) else summaries
    # Table 2: the definitions each study ran (config-defined methods, overrides applied)
    if configs is None:
        configs = [Path(d).parents[2] / "config.json" for d in eval_dirs
                   if len(Path(d).parents) > 2]
    found = sorted({Path(c) for c in configs if Path(c).is_file()})
    cfgs: dict[str, dict] = {}
    for c in found:                      # a study's config.json, or its views merged
        views = [p for p in c.parents if p.name == "config_views"]   # <study>/config_views/
        study = views[0].parent.name if views else c.parent.name
        cfg = load_json(c)
        if study not in cfgs:
            cfgs[study] = cfg
            continue
        tracking = cfgs[study].setdefault("tracking", {})
        for key in ("methods", "overrides", "external"):
            tracking[key] = {**(tracking.get(key) or {}),
                             **((cfg.get("tracking") or {}).get(key) or {})}
    cfgs = cfgs or {"": {}}
    used: dict[str, dict] = {}
    for m in methods:
        if any(m in ((cfg.get("tracking") or {}).get("external") or {})
               for cfg in cfgs.values()):
            continue                    # an external tracker: no parameters of gaitval's
        runs = {study: set_params(get_method(method_definition(cfg, m)),
                                  method_overrides(cfg, m))
                for study, cfg in cfgs.items()}
        distinct = {json.dumps(d, sort_keys=True, default=str) for d in runs.values()}
        if len(distinct) == 1:
            used[m] = next(iter(runs.values()))
        else:
            used.update({f"{m} ({study})": d for study, d in runs.items()})
    paths = write_tug_tables(frames, summaries, tables_dir, methods=used)
    stamp("tug_tables", paths, reports_dir, config_hash_=config_hash)
    figs = write_tug_figures(frames, summaries, events, figures_dir)
    stamp("tug_figures", figs, reports_dir, config_hash_=config_hash)
    return paths + figs


# -- ultrasonic (seed 003) ------------------------------------------------------------------
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


# -- external tracks (issue 37; gaitval/io/tracks.py, docs/formats.md "Leg tracks") ------
def export_tracks_step(track_parquet, out, units: str = "m", topic: str | None = None,
                       legs: dict | None = None) -> Path:
    """One of gaitval's own track files (``results/<study>/track/<method>/<trial>.parquet``)
    in the exchange format (sensor frame and clock), CSV or Parquet by ``out``'s suffix; or
    a tracker's people topic of a ROS bag (``*.bag`` or a ROS 2 bag folder; ``topic``:
    leg_tracker/PersonArray or people_msgs/People, :func:`gaitval.io.tracks.read_bag_tracks`);
    with ``out`` a ``*.foot.csv``/``.parquet``, gaitval's ultrasonic UKF track as a heel
    trajectory (:mod:`gaitval.io.foot`)."""
    from gaitval.io.tracks import read_bag_tracks, track_to_exchange, write_tracks

    src_path = Path(track_parquet)
    if not src_path.exists():
        raise FileFormatError("file not found", path=src_path,
                              hint="a track of gaitval's is results/<study>/track/<method>/"
                                   "<trial>.parquet, made by the report run")
    if src_path.suffix == ".bag" or src_path.is_dir():
        rows, meta = read_bag_tracks(src_path, topic)
        if legs:                  # each leg a person: leg rows (docs/formats.md, Leg tracks)
            from gaitval.io.tracks import people_to_legs
            rows = people_to_legs(rows, legs, path=src_path, topic=meta["source"]).rename(
                columns={"x_m": "x", "y_m": "y"})
        if units == "mm":
            rows[["x", "y"]] = rows[["x", "y"]] * 1000.0
        return write_tracks(rows, out, units=units, source=meta["source"])
    track = read_parquet(track_parquet)
    if Path(out).name.endswith((".foot.csv", ".foot.parquet")):
        # gaitval's ultrasonic UKF track (results/<study>/ultrasonic/track/<trial>.parquet)
        # as a heel trajectory (gaitval.io.foot; ultrasonic frame and clock)
        from gaitval.io.foot import ukf_track_to_foot, write_foot
        if not {"t_s", "x_m", "y_m", "z_m"} <= set(track.columns):
            raise FileFormatError("a *.foot.csv/parquet is a heel trajectory: the input "
                                  "is no ultrasonic track (columns t_s, x_m, y_m, z_m)",
                                  path=track_parquet, hint="export a leg track as "
                                  "*.tracks.csv, an ultrasonic track as *.foot.csv")
        rows = ukf_track_to_foot(track)
        if units == "mm":
            rows[["x", "y", "z"]] = rows[["x", "y", "z"]] * 1000.0
        return write_foot(rows, out, units=units, source="gaitval ultrasonic UKF")
    rows = track_to_exchange(track)
    if units == "mm":
        for c in ("x", "y", "vx", "vy"):
            if c in rows:
                rows[c] = rows[c] * 1000.0
    src = {}
    if len(track) and "method" in track and "trial" in track:
        src = {"source": f"gaitval {track['method'].iloc[0]}",
               "trial": str(track["trial"].iloc[0])}
    return write_tracks(rows, out, units=units, **src)


def external_track_path(sheet, entry: dict, trial: str, method: str = "",
                        field: str | None = None) -> Path:
    """The external track file of one trial: ``entry["path"]`` relative to the trial
    sheet's folder, ``{trial}`` replaced by the trial id.  Like the sheet's own paths it
    must stay inside that folder unless the study.yaml beside the sheet sets
    ``allow_outside_paths: true``.  ``field`` names the entry in the error (default
    ``tracking.external.<method>.path``)."""
    from gaitval.io.trialsheet import _allows_outside

    base = Path(sheet).parent
    path = base / str(entry["path"]).replace("{trial}", trial)
    if not path.resolve().is_relative_to(base.resolve()) and not _allows_outside(Path(sheet)):
        raise ConfigError(f"{field or f'tracking.external.{method}.path'}: {str(path)!r} "
                          f"(trial {trial}) leads outside the trial sheet's folder {base}",
                          hint="put the files beside the sheet, or set "
                               "allow_outside_paths: true in the study.yaml beside it")
    return path


EXTERNAL_PROTOCOLS = ("tug", "mtst")
#: the protocols an external detector's entry covers by default (a fixed laser; the
#: ground truth of these families is in the laser's frame on its clock)
DETECTION_PROTOCOLS = ("tug", "mtst")
#: a study's own declarations beside its trial sheet: study.yaml (written by the
#: simulator for a simulated study) and this side file, which gaitval never writes
#: (a simulated study's external methods and detectors, declared before its first run)
STUDY_SIDE_FILE = "external.yaml"
#: the keys a study declares external trackers and detectors under
DECLARATION_KEYS = ("external_methods", "external_detections")


#: the protocol whose external files are heel trajectories (*.foot.csv, gaitval.io.foot),
#: not leg tracks: an entry covering it covers no other protocol
FOOT_PROTOCOL = "treadmill"


def foot_entry_problem(method: str, entry: dict, where: str = "external_methods") -> None:
    """An external method whose ``protocols`` name the treadmill and another protocol:
    one file template cannot be heel trajectories there and leg tracks elsewhere
    (ConfigError naming the key)."""
    prots = list((entry or {}).get("protocols") or EXTERNAL_PROTOCOLS)
    if FOOT_PROTOCOL in prots and len(prots) > 1:
        raise ConfigError(f"{where}.{method}.protocols: {prots}: a treadmill method's files "
                          "are heel trajectories (*.foot.csv), the other protocols' are leg "
                          "tracks; declare two methods",
                          hint="e.g. my_feet: {path: ..., protocols: [treadmill]} beside "
                               "my_legs: {path: ..., protocols: [tug, mtst]}")


def is_foot_entry(entry: dict) -> bool:
    """The entry covers the treadmill trials (heel trajectories, :mod:`gaitval.io.foot`)."""
    return FOOT_PROTOCOL in ((entry or {}).get("protocols") or ())


def declared_entries(sheet, key: str) -> dict:
    """``key`` (:data:`DECLARATION_KEYS`) of the ``study.yaml`` and the
    :data:`STUDY_SIDE_FILE` beside a trial sheet: name -> (entry, the file declaring it).
    A name declared in both files is an error naming both."""
    from gaitval.configcheck import display_path

    out: dict = {}
    for f in (Path(sheet).parent / "study.yaml", Path(sheet).parent / STUDY_SIDE_FILE):
        if not f.is_file():
            continue
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh) or {}
        entries = (doc.get(key) or {}) if isinstance(doc, dict) else {}
        for m, e in (entries.items() if isinstance(entries, dict) else ()):
            if m in out:
                raise ConfigError(f"[file {display_path(f)}] {key}.{m}: {m!r} is also "
                                  f"declared in {display_path(out[m][1])}; declare it in "
                                  "one place")
            out[m] = (e, f)
    return out


def study_external(sheet, key: str = "external_methods") -> dict:
    """``external_methods:`` (or another of :data:`DECLARATION_KEYS`) of the study's
    ``study.yaml`` and its :data:`STUDY_SIDE_FILE` beside a trial sheet: the study's own
    entries, name -> entry as in ``tracking.external`` ({} without)."""
    return {m: e for m, (e, _) in declared_entries(sheet, key).items()}


def study_side_problems(sheet, schema: dict | None = None) -> None:
    """The :data:`STUDY_SIDE_FILE` beside a trial sheet, when there, against the config
    schema's ``$defs/external_file`` (only :data:`DECLARATION_KEYS`), raising one
    ConfigError naming the file and key."""
    from gaitval.configcheck import check_study_file

    f = Path(sheet).parent / STUDY_SIDE_FILE
    if f.is_file():
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh)
        check_study_file({} if doc is None else doc, f, schema=schema,
                         definition="external_file")


def external_declarations(config_external: dict | None, sheets: dict, taken,
                          key: str = "external_methods",
                          protocols: tuple = EXTERNAL_PROTOCOLS) -> dict:
    """Each study's external methods: ``tracking.external`` of the workflow config (every
    study of ``run``) and ``external_methods:`` of the study's own ``study.yaml`` or
    :data:`STUDY_SIDE_FILE`; with ``key="external_detections"`` (and no config entries)
    its external leg detectors alike.

    ``sheets``: study -> its trial sheet's path (the study.yaml beside it need not exist
    yet: a simulated study before its simulation); ``taken``: the names of gaitval's own
    methods (and, for detectors, of the external methods).  Returns
    ``{study: {method: entry}}``.

    Raises
    ------
    ConfigError
        Naming the file and key: a name that is already a method or also declared in
        the workflow config; a name declared by some studies of ``run`` and not by
        another, or with other ``protocols`` there (the tables pool the studies of
        ``run``, one row per method, so every study needs the method's files).
    """
    from gaitval.configcheck import display_path

    config_external = dict(config_external or {})
    decl = {s: declared_entries(sheet, key) for s, sheet in sheets.items()}
    own = {s: {m: e for m, (e, _) in d.items()} for s, d in decl.items()}
    cal = {s: display_path(Path(sheets[s]).parent / "study.yaml") for s in sheets}

    def where(s, m):
        return display_path(decl[s][m][1]) if m in decl[s] else cal[s]

    if key == "external_methods":
        for m, e in config_external.items():
            foot_entry_problem(m, e, "tracking.external")
        for s, entries in own.items():
            for m, e in entries.items():
                foot_entry_problem(m, e, f"[file {where(s, m)}] {key}")
    for s, entries in own.items():
        for m in entries:
            if m in taken:
                what = ("a tracking method; give the external tracker" if
                        key == "external_methods" else
                        "a method name; give the external detector")
                raise ConfigError(f"[file {where(s, m)}] {key}.{m}: {m!r} is already "
                                  f"{what} another name")
            if m in config_external:
                raise ConfigError(f"[file {where(s, m)}] {key}.{m}: {m!r} is also "
                                  "declared in the workflow config (tracking.external); "
                                  "declare it in one place")
    names = sorted({m for entries in own.values() for m in entries})
    for m in names:
        have = [s for s in sheets if m in own[s]]
        lack = [s for s in sheets if m not in own[s]]
        if lack:
            raise ConfigError(
                f"[file {where(have[0], m)}] {key}.{m}: study {lack[0]!r} of run "
                f"{list(sheets)} does not declare it (its study.yaml: {cal[lack[0]]})",
                hint="the tables pool the studies of run, one row per method: declare it "
                     f"in every study's study.yaml or {STUDY_SIDE_FILE}, or run the study "
                     "alone")
        prot = {s: sorted(own[s][m].get("protocols") or protocols) for s in have}
        if len({tuple(v) for v in prot.values()}) > 1:
            raise ConfigError(f"[file {where(have[1], m)}] {key}.{m}.protocols: "
                              f"{prot[have[1]]} here, {prot[have[0]]} in "
                              f"{where(have[0], m)}; one method covers the same protocols "
                              "in every study of run")
    return {s: {**config_external, **own[s]} for s in sheets}


def _entry_trials(df: pd.DataFrame, prots, mocap_only: bool) -> list[str]:
    """The trials of a sheet (``trial, protocol[, mocap_path]`` as text) of ``prots``;
    with ``mocap_only`` those with a mocap file (a detector is scored against it)."""
    keep = df["protocol"].str.strip().isin(prots)
    if mocap_only and "mocap_path" in df:
        keep &= df["mocap_path"].str.strip() != ""
    return sorted(df.loc[keep, "trial"].str.strip())


def _sheet_trials(sheet) -> pd.DataFrame | None:
    try:
        return pd.read_csv(sheet, usecols=lambda c: c in ("trial", "protocol", "mocap_path"),
                           dtype=str, keep_default_na=False)
    except (OSError, ValueError):
        return None


def missing_external_files(sheet, entries: dict, source: str = "", *,
                           protocols: tuple = EXTERNAL_PROTOCOLS,
                           what: str = "track files", key: str | None = None,
                           mocap_only: bool = False) -> None:
    """Check, before any job runs, that every trial of each external method's protocols
    has its file, inside the sheet's folder (:func:`external_track_path`).  A sheet that
    cannot be read yet (a simulated study before its simulation; a broken sheet, which its
    own check reports) is skipped.  ``protocols``: an entry's default; ``what``: the files'
    name in the message; ``key``: the declaration key, named when a path leads outside;
    ``mocap_only``: only the trials with a mocap file (an external detector's).

    Raises
    ------
    ConfigError
        One message per method naming where it is declared, how many files are missing
        and the first few of them."""
    df = _sheet_trials(sheet)
    if df is None or not {"trial", "protocol"} <= set(df.columns):
        return
    for m, entry in entries.items():
        prots = (entry or {}).get("protocols") or protocols
        trials = _entry_trials(df, prots, mocap_only)
        paths = [external_track_path(sheet, entry, t, m,
                                     field=f"{key}.{m}.path" if key else None)
                 for t in trials]
        missing = [p for p in paths if not p.exists()]
        if missing:
            shown = ", ".join(str(p) for p in missing[:3])
            raise ConfigError(
                f"{source or 'external method'} {m}: {len(missing)} of {len(paths)} "
                f"trials' {what} are missing ({shown}"
                f"{', ...' if len(missing) > 3 else ''})",
                hint=f"path {entry['path']!r} is relative to the trial sheet's folder "
                     f"{Path(sheet).parent}; every trial of {', '.join(prots)} needs its "
                     "file")


def detection_topic_problems(sheet, entries: dict, source: str = "") -> None:
    """Each external detector's bags (the trials with mocap of its protocols) opened
    before any job
    runs: its ``topic`` (or, without one, exactly one ``leg_tracker/LegArray`` topic) must
    be in every bag and be a ``LegArray``.  Files that are no bag are read by the job
    (their header and rows; ``gaitval validate --deep`` reads them first).  Skipped, like
    :func:`missing_external_files`, while the sheet cannot be read.

    Raises
    ------
    ConfigError
        Naming where the detector is declared, the bag, and the topics it has."""
    from gaitval.io.rosbag import _norm, is_rosbag
    from gaitval.io.tracks import BAG_LEG_DETECTIONS

    df = _sheet_trials(sheet)
    if df is None or not {"trial", "protocol"} <= set(df.columns):
        return
    for m, entry in entries.items():
        prots = (entry or {}).get("protocols") or DETECTION_PROTOCOLS
        topic = (entry or {}).get("topic")
        for t in _entry_trials(df, prots, mocap_only=True):
            path = external_track_path(sheet, entry, t, m,
                                       field=f"external_detections.{m}.path")
            if not is_rosbag(path):
                continue
            from rosbags.highlevel import AnyReader
            try:
                with AnyReader([path]) as r:
                    have = {c.topic: c.msgtype for c in r.connections}
            except Exception as exc:          # noqa: BLE001 - any unreadable bag
                raise ConfigError(f"{source} {m}: trial {t}: {path} is not a readable ROS "
                                  f"bag ({type(exc).__name__}: {exc})") from None
            if topic:
                got = {k: v for k, v in have.items() if _norm(k) == _norm(str(topic))}
                if not got:
                    raise ConfigError(f"{source} {m}.topic: {topic!r} is not in {path} "
                                      f"(trial {t}); its topics: {sorted(have)}")
                bad = [v for v in got.values() if v != BAG_LEG_DETECTIONS]
                if bad:
                    raise ConfigError(f"{source} {m}.topic: {topic!r} in {path} (trial "
                                      f"{t}) holds {bad[0]}, not {BAG_LEG_DETECTIONS}")
            elif sum(v == BAG_LEG_DETECTIONS for v in have.values()) != 1:
                raise ConfigError(f"{source} {m}: {path} (trial {t}) has "
                                  f"{sum(v == BAG_LEG_DETECTIONS for v in have.values())} "
                                  f"topics of type {BAG_LEG_DETECTIONS}; its topics: "
                                  f"{sorted(have)}", hint="name the topic (topic: ...)")


def study_yaml_problems(sheet) -> list:
    """The ``study.yaml`` beside a trial sheet against the config schema, as the run checks
    it at start (``_check_study_files`` in workflow/rules/common.smk): a typo is one problem
    naming the file, the key and the nearest valid one."""
    from gaitval.configcheck import check_study_file

    f = Path(sheet).parent / "study.yaml"
    if not f.is_file():
        return []
    try:
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh)
        check_study_file({} if doc is None else doc, f)
    except GaitvalError as exc:
        return [exc]
    except (OSError, yaml.YAMLError) as exc:
        return [f"[file {f}] cannot be read: {exc}"]
    return []


#: Leg positions whose median lies farther than this from the origin of their frame (the
#: laser or the mocap origin, metres) are no gait laboratory's: millimetres declared as metres.
MAX_TRACK_DISTANCE_M = 100.0


def _units_problem(rows: pd.DataFrame, meta: dict, path, trial: str) -> None:
    """A track file whose positions cannot be in the units its header declares (checked
    without the trial's registration, so against any room's size; the run checks them
    against the laser's range once registered)."""
    x = rows["x_m" if "x_m" in rows else "x"].to_numpy(float)
    y = rows["y_m" if "y_m" in rows else "y"].to_numpy(float)
    d = np.hypot(x, y)
    d = d[np.isfinite(d)]
    if d.size and np.median(d) > MAX_TRACK_DISTANCE_M:
        raise FileFormatError(
            f"the leg positions lie a median {np.median(d):,.0f} m from the origin of their "
            f"frame ({meta.get('frame', 'sensor')!r}), beyond any room (header units "
            f"{meta.get('units', 'm')!r})", path=path, trial=trial,
            hint="positions in millimetres need 'units: mm' in the header")


def external_problems(sheet, deep: bool = False) -> list[str]:
    """What ``gaitval validate`` reports of the study's own external methods and leg
    detectors (``external_methods:``, ``external_detections:`` of the study.yaml or
    :data:`STUDY_SIDE_FILE` beside ``sheet``): the entries against the schema, each
    trial's file present and inside the folder (a detector's bags: its topic), and with
    ``deep`` every file read (:func:`read_external`, :func:`read_external_detections`:
    header, columns, rows, a bag's topic and legs; the clock and frame conversion needs the
    registration and is checked when the run imports it).  One text per problem."""
    from gaitval.configcheck import check_study_file

    out = []
    for key, check, default in (("external_methods", "external_method", EXTERNAL_PROTOCOLS),
                                ("external_detections", "external_detection",
                                 DETECTION_PROTOCOLS)):
        try:
            decl = declared_entries(sheet, key)
            if not decl:
                continue
            study_side_problems(sheet)
            for m, (entry, f) in decl.items():
                check_study_file({key: {m: entry}}, f)
                if key == "external_methods":
                    foot_entry_problem(m, entry, f"[file {f}] {key}")
        except GaitvalError as exc:
            out.append(str(exc))
            continue
        except (OSError, yaml.YAMLError) as exc:
            out.append(f"[file {Path(sheet).parent}] {key} cannot be read: {exc}")
            continue
        for m, (entry, f) in decl.items():
            try:
                missing_external_files(sheet, {m: entry}, f"[file {f}] {key}",
                                       protocols=default, key=key,
                                       what=("detection files" if key != "external_methods"
                                             else "heel trajectories" if is_foot_entry(entry)
                                             else "track files"),
                                       mocap_only=key == "external_detections")
                if key == "external_detections":
                    detection_topic_problems(sheet, {m: entry}, f"[file {f}] {key}")
            except GaitvalError as exc:
                out.append(str(exc))
                continue
            if not deep:
                continue
            df = _sheet_trials(sheet)
            prots = entry.get("protocols") or default
            for t in _entry_trials(df, prots, key == "external_detections"):
                try:
                    path = external_track_path(sheet, entry, t, m)
                    if key == "external_methods" and is_foot_entry(entry):
                        from gaitval.io.foot import read_foot
                        read_foot(path, trial=t)
                    elif key == "external_methods":
                        rows, meta = read_external(path, entry, t)
                        _units_problem(rows, meta, path, t)
                    else:
                        read_external_detections(path, entry.get("topic"), t)
                except GaitvalError as exc:
                    out.append(f"{key}.{m}: {exc}")
    return out


def external_entry(config_json, method: str) -> dict:
    """``tracking.external.<method>`` of a config view (empty without one)."""
    if not config_json:
        return {}
    ext = ((load_json(config_json).get("tracking") or {}).get("external") or {})
    return dict(ext.get(method) or {})


def read_external(tracks_file, entry: dict, trial: str) -> tuple[pd.DataFrame, dict]:
    """An external method's file of one trial as :func:`gaitval.io.tracks.read_tracks`
    rows: a ``*.tracks.csv``/``.parquet``, or a ROS bag's tracker topic (``entry``'s
    ``topic``) whose people are the legs named by ``entry``'s ``legs``."""
    from gaitval.io.rosbag import is_rosbag
    from gaitval.io.tracks import people_to_legs, read_bag_tracks, read_tracks

    if not is_rosbag(tracks_file):
        return read_tracks(tracks_file, trial=trial)
    rows, meta = read_bag_tracks(tracks_file, entry.get("topic"), trial=trial)
    legs = entry.get("legs")
    if not legs:
        return rows.rename(columns={"x": "x_m", "y": "y_m"}), meta
    return people_to_legs(rows, legs, path=tracks_file, trial=trial,
                          topic=meta["source"]), meta


def read_external_detections(path, topic: str | None = None, trial: str | None = None
                             ) -> tuple[pd.DataFrame, dict]:
    """A detector's leg detections of one trial: a ROS bag's ``leg_tracker/LegArray``
    topic (:func:`gaitval.io.tracks.read_bag_leg_detections`) or a
    ``*.detections.csv``/``.parquet`` (:func:`gaitval.io.tracks.read_detections`)."""
    from gaitval.io.rosbag import is_rosbag
    from gaitval.io.tracks import read_bag_leg_detections, read_detections

    if is_rosbag(path):
        return read_bag_leg_detections(path, topic, trial=trial)
    return read_detections(path, trial=trial)


def _refuse_mocap_frame(meta: dict, path, trial, what: str) -> None:
    """A file in the mocap frame on a trial whose laser moves (the rollator): refused with
    one error naming the file and the header field (only a fixed laser's pose converts
    the field frame into the laser's)."""
    if meta.get("frame", "sensor") == "mocap":
        raise FileFormatError(
            "header field 'frame' is 'mocap', but this trial's laser moves (rollator): "
            f"gaitval converts only a fixed laser's {what} from the mocap frame",
            path=path, trial=trial, hint=f"write the {what} in the laser's frame "
            "(frame: sensor)")


def leg_detections_step(detections, groundtruth_parquet, out_dir, *, topic: str | None = None,
                        trial: str | None = None, gate_m: float = 0.30,
                        registration_json=None, sensor_parquet=None,
                        method: str | None = None, protocol: str | None = None,
                        moving_sensor: bool = False) -> dict:
    """A detector's leg detections of one trial (leg_tracker's ``leg_tracker/LegArray``
    in a bag, or a ``*.detections.csv``/``.parquet``; no identity, no side) scored against
    the trial's mocap legs (:func:`gaitval.evaluate.leg_detections.detection_statistics`);
    writes ``per_scan.parquet`` and ``summary.json`` into ``out_dir`` (atomically) and
    returns the summary.  A file on the mocap clock or in the mocap frame is converted with
    the trial's registration (``registration_json``); with the trial's scan log
    (``sensor_parquet``) time stamps outside the recording and positions in the wrong
    units are refused naming the row (:func:`gaitval.io.tracks.detections_to_sensor`).
    Stamps on the sensor clock must be the scans' (the ground truth's ``t_sensor_s``).
    ``moving_sensor`` (the rollator): a file in the mocap frame is refused, as
    :func:`import_tracks_step` refuses one (the ground truth is in the moving laser's
    frame, scan by scan)."""
    from gaitval.evaluate.leg_detections import detection_statistics
    from gaitval.io.tracks import detections_to_sensor

    det, meta = read_external_detections(detections, topic, trial)
    if moving_sensor:
        _refuse_mocap_frame(meta, detections, trial, "detections")
    rec = load_json(registration_json) if registration_json else None
    out = Path(out_dir)
    if rec is not None and rec.get("status") != "ok":
        # no mocap legs in the laser's frame: nothing to score (the tracking tables count
        # such a trial as not registered too)
        summary = {"trial": trial, "source": meta["source"], "status": "not_registered",
                   "n_messages": int(meta["n_messages"]), "n_scans": 0, "gate_m": gate_m}
        summary.update({k: v for k, v in (("method", method), ("protocol", protocol))
                        if v is not None})
        write_parquet(pd.DataFrame({"t_sensor_s": pd.Series(dtype=float),
                                    "side": pd.Series(dtype=object),
                                    "detected": pd.Series(dtype=bool),
                                    "dx_m": pd.Series(dtype=float),
                                    "dy_m": pd.Series(dtype=float),
                                    "n_false": pd.Series(dtype=np.int64)}),
                      out / "per_scan.parquet")
        write_text(out / "summary.json", json.dumps(summary, indent=1, sort_keys=True) + "\n")
        return summary
    scan_t, period, rng = None, 0.0, None
    if sensor_parquet:
        from gaitval.io.scanlog import read_scanlog
        scans = read_scanlog(sensor_parquet, trial=trial)
        scan_t = np.asarray(scans.t, float)
        period = float(np.median(np.diff(scan_t))) if len(scan_t) > 1 else 0.0
        rng = float(scans.range_max)
    det, t_messages = detections_to_sensor(det, meta, rec, path=detections, trial=trial,
                                           scan_t=scan_t, tolerance_s=period,
                                           max_range_m=rng)
    truth = read_parquet(groundtruth_parquet)
    per_scan, summary = detection_statistics(det, t_messages, truth, gate_m)
    if not summary["n_scans"]:
        raise FileFormatError(f"no time stamp of {meta['source']} is a scan time of the "
                              "ground truth with both legs known (no scan to score)",
                              path=detections, trial=trial, hint="the detections' time "
                              "stamps must be the scans' stamps, on the registered sensor "
                              "clock (or 'clock: mocap' in a detections file's header)")
    summary = {"trial": trial, "source": meta["source"], "status": "ok", **summary}
    summary.update({k: v for k, v in (("method", method), ("protocol", protocol))
                    if v is not None})
    write_parquet(per_scan, out / "per_scan.parquet")
    write_text(out / "summary.json", json.dumps(summary, indent=1, sort_keys=True) + "\n")
    return summary


def import_tracks_step(tracks_file, sensor_parquet, registration_json, trial: str,
                       method: str, out_parquet, config_json=None,
                       moving_sensor: bool = False) -> pd.DataFrame:
    """An external tracker's file of one trial as gaitval's per-scan track (the columns of
    :func:`gaitval.methods.track_trial`, plus ``trial`` and ``method``), so that the TUG
    evaluation and tables treat it as one more method.  The clock and frame conversion use
    the trial's registration (docs/formats.md); a file on the sensor clock in the sensor
    frame needs none.  A trial whose registration was refused gets an empty track when the
    file needs it (its evaluation is ``not_registered`` anyway).  ``config_json``: the
    method's config view, whose ``tracking.external.<method>`` gives a bag's ``topic``
    and ``legs`` (:func:`read_external`).  ``moving_sensor`` (the rollator): a file in
    the mocap frame is refused (the laser's pose changes every frame; give the tracks in
    the laser's frame)."""
    from gaitval.io.scanlog import read_scanlog
    from gaitval.io.tracks import TRACK_COLUMNS, tracks_to_sensor

    rows, meta = read_external(tracks_file, external_entry(config_json, method), trial)
    if moving_sensor:
        _refuse_mocap_frame(meta, tracks_file, trial, "tracks")
    rec = load_json(registration_json) if registration_json else None
    needs_reg = "mocap" in (meta["frame"], meta["clock"])
    if needs_reg and rec is not None and rec.get("status") != "ok":
        track = pd.DataFrame(columns=list(TRACK_COLUMNS))
    else:
        scans = read_scanlog(sensor_parquet, trial=trial)
        t = np.asarray(scans.t, float)
        period = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        track = tracks_to_sensor(rows, meta, rec, path=tracks_file, trial=trial,
                                 t_range=(float(t[0]), float(t[-1])), tolerance_s=period,
                                 scan_t=t, max_range_m=float(scans.range_max))
    track.insert(0, "method", method)
    track.insert(0, "trial", trial)
    write_parquet(track, out_parquet)
    return track
