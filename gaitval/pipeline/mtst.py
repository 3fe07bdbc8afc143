"""MTST (seed 001) pipeline steps at file level: track, evaluate, tables.

Sits with :mod:`gaitval.pipeline.steps` (same layer: reads the files of one rule, calls the library,
writes files) and borrows its helpers.  Three steps, one Snakemake rule each
(``workflow/rules/mtst.smk``):

``mtst_track_step`` (one trial, one method)
    Keeps every n-th scan of the log so the scan period is ``mtst.scan_period_s`` (0.05 s,
    seed 001 §3.1: "The sampling time of the system Δt was set to 0.05 s"; a UTM-30LX
    scans every 25 ms, so n = 2 for a raw log and 1 for a log already written at 20 Hz,
    as the simulated one is), and tracks with the mat's lane as the initialiser's
    ``init__lane`` (:mod:`gaitval.track.init_mtst`), so the track starts on the
    participant, not on the attendant.
``mtst_evaluate_step`` (one trial, one method)
    Contacts, target steps and cross steps in the field frame, and the evaluations
    (:func:`gaitval.evaluate.mtst_trial.evaluate_mtst_trial`).
``mtst_tables_step`` (all trials)
    Tables 1, 3, 4 and the figure.

Sensor pose and clock.  From the trial's ``registration.json`` when its status is ``ok``
(mocap poles and clock).  A study without mocap gives the pole centres in the field (mat)
frame in ``mtst.poles_m`` (the paper aligns mat and sensor with two poles, §2.2); the
poles are then found in the scans and fitted (``pole_ambiguity: bearing``: the first pole
is the one at the smaller beam angle), and the clock offset comes from the trial sheet's
``clock_offset_s``.  The target layout is a study input: ``mtst.targets`` is a CSV path
relative to the trial sheet's folder, ``{trial}`` replaced by the trial id, with columns
``target, x_m, y_m, color, assigned`` in the field frame (optional ``trial`` column to
hold several trials in one file); docs/formats.md.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, FileFormatError, GaitvalError
from gaitval.io.atomic import write_parquet
from gaitval.pipeline.memo import FileMemo
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.steps.config import (load_json, method_definition, method_display_names,
                                           method_overrides)
from gaitval.pipeline.steps.tracking import fixed_sensor_overrides, track_and_write
from gaitval.pipeline.steps.trials import trial_and_subject

TARGET_COLUMNS = ("target", "x_m", "y_m", "color", "assigned")
EVAL_TABLES = ("contacts", "steps", "events", "gates", "track_field", "summary", "targets")


def mtst_config(config_json) -> tuple[dict, dict]:
    """(whole study config, its ``mtst`` settings with defaults)."""
    from gaitval.evaluate.mtst_trial import settings
    cfg = load_json(config_json)
    return cfg, settings(cfg)


def keep_every(scans, period_s: float, *, trial: str):
    """The scans at ``period_s`` (every n-th, n = round(period_s / log period), n ≥ 1)."""
    from dataclasses import replace
    d = np.diff(np.asarray(scans.t, float))
    d = d[d > 0]
    if len(d) == 0:
        raise GaitvalError("the scan log has fewer than two increasing timestamps",
                           path=scans.source or None, trial=trial)
    period = float(np.median(d))
    if period > 1.5 * period_s:
        raise GaitvalError(f"the scan log's period {period * 1000:.0f} ms is longer than "
                           f"mtst.scan_period_s = {period_s * 1000:.0f} ms", trial=trial,
                           path=scans.source or None,
                           hint="seed 001 runs at 0.05 s; set mtst.scan_period_s to the log's")
    n = max(1, int(round(period_s / period)))
    if n == 1:
        return scans
    return replace(scans, t=np.asarray(scans.t)[::n], ranges=np.asarray(scans.ranges)[::n],
                   meta={**scans.meta, "kept_every": n})


def _pose_from_poles(scans, s: dict, cfg: dict, trial: str):
    from gaitval.registration.poles import register_poles
    from gaitval.types import MocapTrial
    poles = np.asarray(s["poles_m"], float)
    if poles.shape != (2, 2):
        raise ConfigError(f"mtst.poles_m must be two [x, y] pole centres, got {s['poles_m']!r}")
    xyz = np.concatenate([poles, np.zeros((2, 1))], axis=1)[None]
    mocap = MocapTrial(path="mtst.poles_m", rate_hz=1.0, first_frame=1,
                       labels=["POLE1", "POLE2"], xyz=xyz, units="m")
    reg = {**(cfg.get("registration") or {}), "pole_ambiguity": "bearing",
           "pole_labels": ["POLE1", "POLE2"]}
    fit = register_poles(scans, mocap, reg, trial=trial)
    return (fit.x_m, fit.y_m, fit.yaw_rad)


def pose_and_clock(rec: dict | None, row: dict, scans, s: dict, cfg: dict, trial: str):
    """``(pose, (clock_offset_s or None, drift_ppm))`` of a trial (module notes)."""
    if rec and rec.get("status") == "ok" and all(
            rec.get(k) is not None and np.isfinite(rec[k]) for k in ("x_m", "y_m", "yaw_rad")):
        return ((float(rec["x_m"]), float(rec["y_m"]), float(rec["yaw_rad"])),
                (float(rec["clock_offset_s"]), float(rec.get("clock_drift_ppm") or 0.0)))
    manual = row.get("clock_offset_s")
    clock = (float(manual) if manual is not None and np.isfinite(manual) else None, 0.0)
    if s["poles_m"] is not None:
        return _pose_from_poles(scans, s, cfg, trial), clock
    why = f" (registration: {rec.get('reason')})" if rec and rec.get("reason") else ""
    raise GaitvalError(f"no sensor pose for the MTST trial{why}", trial=trial,
                       hint="register it against mocap, or give the pole centres in the mat "
                            "frame as mtst.poles_m in study.yaml")


def mat_lane(pose, mat: dict) -> list[list[float]]:
    """The mat's centreline start → goal in the sensor frame (the initialiser's lane)."""
    from gaitval.registration.rigid import field_to_sensor
    p = np.array([mat["start_m"], mat["goal_m"]], dtype=float)
    return field_to_sensor(p, *pose).tolist()


def _registration(path) -> dict | None:
    return load_json(path) if path and Path(path).is_file() else None


def refused_without_fallback(rec: dict | None, row: dict, s: dict) -> str | None:
    """The reason a trial cannot be evaluated because its registration was refused, or
    None.  A refused trial is left out (as in the TUG tables) when nothing else places
    it: no pole centres in ``mtst.poles_m`` for the pose, or no trial-sheet
    ``clock_offset_s`` to put its rater annotations on the sensor clock (its mocap truth
    is gone with the registration).  A study without mocap (no registration record) is
    not a refusal: a missing pose or clock there stays an error."""
    if not rec or rec.get("status") == "ok":
        return None
    manual = row.get("clock_offset_s")
    has_clock = manual is not None and np.isfinite(manual)
    if s["poles_m"] is not None and has_clock:
        return None
    return str(rec.get("reason") or "registration refused")


#: Scan logs and annotation files this process read, by file identity: a trial's
#: tracking reads them, then its evaluation, one after the other in the same batch worker
#: (gaitval.jobs.batch).  A caller gets its own copy.
_SCANS = FileMemo(256 * 2 ** 20)
_ANNOTATIONS = FileMemo(32 * 2 ** 20)


def read_scans(path, row: dict):
    """A scan log: gaitval's own Parquet (raw or ingested) or any format the trial sheet's
    reader knows (ROS bags)."""
    import copy

    from gaitval.io.ingest import read_sensor
    from gaitval.io.scanlog import read_scanlog

    def read():
        if str(path).endswith(".parquet"):
            return read_scanlog(path, trial=row["trial"])
        return read_sensor({**row, "sensor_path": str(path)})

    scans = _SCANS.fetch(_SCANS.key(path, str(path), row["trial"]), read,
                         lambda got: got.ranges.nbytes + got.t.nbytes)
    return copy.deepcopy(scans)


def mtst_track_step(sensor, sheet, subjects, trial: str, method: str, config_json,
                    registration_json, out_parquet, detections=None) -> pd.DataFrame:
    """Track one MTST trial with one method (module notes); sensor frame, sensor clock.
    ``detections``: the trial's observations made by :func:`mtst_detect_step` with this
    method's detector (:mod:`gaitval.pipeline.detections`), instead of detecting again."""
    from gaitval.methods import get_method

    from gaitval.io.tracks.exchange import TRACK_COLUMNS

    cfg, s = mtst_config(config_json)
    row, subj = trial_and_subject(sheet, subjects, trial)
    rec = _registration(registration_json)
    if refused_without_fallback(rec, row, s):      # left out (its evaluation says why)
        track = pd.DataFrame(columns=list(TRACK_COLUMNS))
        track.insert(0, "method", method)
        track.insert(0, "trial", trial)
        write_parquet(track, out_parquet)
        return track
    scans = keep_every(read_scans(sensor, row), float(s["scan_period_s"]), trial=trial)
    pose, _ = pose_and_clock(rec, row, scans, s, cfg, trial)
    mdef = method_definition(cfg, method)
    overrides = {**fixed_sensor_overrides(mdef),                 # the LRS stands still
                 **method_overrides(cfg, method)}
    if "init" in get_method(mdef):      # the papers' methods start on the mat's lane; the
        overrides.setdefault("init__lane", mat_lane(pose, s["mat"]))   # people tracker: own
    return track_and_write(scans, mdef, float(subj["leg_width_m"]), overrides, trial=trial,
                           method=method, source=sensor, out_parquet=out_parquet,
                           detections=detections)


def mtst_detect_step(sensor, sheet, subjects, trial: str, detector: str, config_json,
                     out_parquet) -> pd.DataFrame:
    """One MTST trial's observations by ``detector`` (a spec, as JSON text) on the scans
    and with the leg width its track step uses (every n-th scan, mtst.scan_period_s), for
    every method with that detector (:mod:`gaitval.pipeline.detections`)."""
    import json

    from gaitval.pipeline.detections import detect_and_write

    _, s = mtst_config(config_json)
    row, subj = trial_and_subject(sheet, subjects, trial)
    scans = keep_every(read_scans(sensor, row), float(s["scan_period_s"]), trial=trial)
    return detect_and_write(scans, json.loads(detector), float(subj["leg_width_m"]),
                            out_parquet, trial=trial, source=sensor)


def load_targets(s: dict, sheet, trial: str, *, required: bool) -> pd.DataFrame | None:
    """The trial's target layout (``mtst.targets``, module notes); None when the study
    allows a trial without one (``require_targets: false``)."""
    where = dict(trial=trial)
    if not s["targets"]:
        if not required:
            return None
        raise ConfigError("no target layout: mtst.targets is not set", **where,
                          hint="point mtst.targets in the study's study.yaml at the targets "
                               "CSV (field frame), e.g. targets/{trial}.targets.csv")
    path = Path(sheet).resolve().parent / str(s["targets"]).replace("{trial}", trial)
    if not path.is_file():
        if not required:
            return None
        raise FileFormatError("target layout file not found", path=path, **where,
                              hint="mtst.targets names a CSV relative to the trial sheet")

    def read():
        out = _read_targets(path, trial, required=required)
        return _NONE if out is None else out

    got = _TARGETS.fetch(_TARGETS.key(path, trial, required), read, lambda _: 4096)
    return None if got is _NONE else got.copy(deep=True)


#: Target layouts read in this process, by file identity, trial and ``required`` (the four
#: methods of a trial read the same one); _NONE: the file has no targets for the trial.
_TARGETS = FileMemo(16 * 2 ** 20)
_NONE = object()


def _read_targets(path: Path, trial: str, *, required: bool) -> pd.DataFrame | None:
    where = dict(trial=trial)
    try:
        df = pd.read_csv(path, dtype={"target": str, "color": str})
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"cannot parse the target layout: {exc}", path=path,
                              **where) from None
    missing = [c for c in TARGET_COLUMNS if c not in df.columns]
    if missing:
        raise FileFormatError(f"target layout lacks column(s) {missing}", path=path, **where)
    if "trial" in df.columns:
        df = df[df["trial"].astype(str) == trial]
    if df.empty:
        if not required:
            return None
        raise FileFormatError("the target layout has no targets for this trial", path=path,
                              **where)
    xy = df[["x_m", "y_m"]].apply(pd.to_numeric, errors="coerce")
    if xy.isna().any().any():
        raise FileFormatError("target x_m / y_m must be numbers", path=path, **where)
    assigned = df["assigned"].astype(str).str.strip().str.lower()
    if not assigned.isin(["true", "false", "1", "0"]).all():
        raise FileFormatError("target 'assigned' must be true or false", path=path, **where)
    out = pd.DataFrame({"target": df["target"].astype(str), "x_m": xy["x_m"],
                        "y_m": xy["y_m"], "color": df["color"].astype(str),
                        "assigned": assigned.isin(["true", "1"])})
    return out.reset_index(drop=True)


def _annotations(row: dict, s: dict, trial: str, sheet):
    """(table, meta, path) of the trial's rater annotations (the file the trial sheet
    names), or None when it names none and the study allows that."""
    from gaitval.io.annotations import read_annotations
    path = row.get("annotation_path") or ""
    if not path:
        if s["require_annotations"]:
            raise FileFormatError("the MTST trial has no rater annotations (its "
                                  "annotation_file is empty)", path=sheet, trial=trial,
                                  hint="add its *.annotations.csv, or set "
                                       "mtst.require_annotations: false")
        return None
    import copy

    ann, meta = _ANNOTATIONS.fetch(_ANNOTATIONS.key(path, trial),
                                   lambda: read_annotations(path, trial=trial),
                                   lambda got: int(got[0].memory_usage(deep=True).sum()))
    return ann.copy(deep=True), copy.deepcopy(meta), path


def _gate(cfg: dict, method: str):
    """The method's gate when it is seed 001's variable region (Table 1), else None."""
    from gaitval.methods import get_method, set_params
    from gaitval.track import GATES
    if method in ((cfg.get("tracking") or {}).get("external") or {}):
        return None                    # an external tracker (issue 37): gate unknown
    m = set_params(get_method(method_definition(cfg, method)),
                   method_overrides(cfg, method))
    spec = m.get("gate")
    name = spec if isinstance(spec, str) else (spec or {}).get("name")
    return GATES.build(spec) if name == "variable_region" else None


def mtst_evaluate_step(track_parquet, sheet, subjects, trial: str, method: str, config_json,
                       registration_json, groundtruth, out_dir) -> pd.DataFrame:
    """Walking parameters and evaluations of one tracked MTST trial (module notes).

    ``registration_json`` and ``groundtruth`` may be None (a study without mocap).  Writes
    ``<name>.parquet`` for every table of
    :func:`gaitval.evaluate.mtst_trial.evaluate_mtst_trial` plus the trial's targets.
    """
    from gaitval.evaluate.mtst_trial import evaluate_mtst_trial

    from gaitval.evaluate.mtst_trial import SUMMARY_COLUMNS

    cfg, s = mtst_config(config_json)
    row, subj = trial_and_subject(sheet, subjects, trial)
    rec = _registration(registration_json)
    out = Path(out_dir)
    if refused_without_fallback(rec, row, s):
        summary = pd.DataFrame([{
            "trial": trial, "method": method, "stick": bool(row.get("stick", False)),
            "has_mocap": False, "has_annotations": False, "has_targets": False,
            "category_mocap": "not_registered", "category_annotations": "not_registered",
            "category_mocap_persistent_swap": "not_registered"}]
        ).reindex(columns=list(SUMMARY_COLUMNS))
        for name in EVAL_TABLES:
            write_parquet(summary if name == "summary" else pd.DataFrame(columns=["trial"]),
                          out / f"{name}.parquet")
        return summary
    scans = None
    if not (rec and rec.get("status") == "ok") and s["poles_m"] is not None:
        scans = keep_every(read_scans(row["sensor_path"], row), float(s["scan_period_s"]),
                           trial=trial)
    pose, clock = pose_and_clock(rec, row, scans, s, cfg, trial)
    targets = load_targets(s, sheet, trial, required=bool(s["require_targets"]))
    ann = _annotations(row, s, trial, sheet)
    truth = None
    if groundtruth and Path(groundtruth).is_file() and rec and rec.get("status") == "ok":
        truth = read_parquet(groundtruth)
    height = subj.get("height_m")
    if height is None or not np.isfinite(height):
        height = float(s["foot"]["default_height_m"])
    track = read_parquet(track_parquet).drop(columns=["trial", "method"])
    res = evaluate_mtst_trial(
        track, trial=trial, method=method, stick=bool(row.get("stick", False)), pose=pose,
        leg_width_m=float(subj["leg_width_m"]), height_m=float(height), targets=targets,
        annotations=None if ann is None else ann[:2], clock=clock, truth=truth,
        gate=_gate(cfg, method), cfg=s, annotation_path=None if ann is None else ann[2])
    res["targets"] = (targets if targets is not None else
                      pd.DataFrame(columns=list(TARGET_COLUMNS))).assign(trial=trial)
    for name in EVAL_TABLES:
        write_parquet(res[name].reset_index(drop=True), out / f"{name}.parquet")
    return res["summary"]


def mtst_tables_step(eval_dirs: list[str | Path], tables_dir, figures_dir, reports_dir,
                     config_hash: str = "", methods=None, config_json=None) -> list[Path]:
    """Seed 001 Tables 1, 3, 4 and the figure (a successful and a failed trial, tracked vs
    mocap legs) from the per-(trial, method) folders."""
    from gaitval.report.mtst_figures import write_mtst_figure
    from gaitval.report.provenance import stamp
    from gaitval.tables.mtst import write_mtst_tables

    parts: dict[str, list[pd.DataFrame]] = {n: [] for n in EVAL_TABLES}
    for d in eval_dirs:
        for name in EVAL_TABLES:
            p = Path(d) / f"{name}.parquet"
            if p.is_file():
                df = read_parquet(p)
                if len(df):
                    parts[name].append(df)
    data = {n: (pd.concat(v, ignore_index=True) if v else pd.DataFrame())
            for n, v in parts.items()}
    left_out: dict[str, str] = {}              # trials whose registration was refused
    if not data["summary"].empty:
        gone = data["summary"]["category_mocap"].astype(str) == "not_registered"
        left_out = {str(t): "registration refused" for t in
                    sorted(data["summary"].loc[gone, "trial"].astype(str).unique())}
        data["summary"] = data["summary"][~gone].reset_index(drop=True)
    s = mtst_config(config_json)[1] if config_json else None
    methods = list(methods or (s or {}).get("methods") or
                   ["mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed"])
    shown = method_display_names(Path(config_json).parent, methods) if config_json else {}
    own = set((s or {}).get("methods") or ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed"))
    external = [m for m in methods if m not in own]    # tracking.external (issue 37)
    paths = write_mtst_tables(data, tables_dir, methods=methods, shown=shown,
                              external=external, left_out=left_out)
    stamp("mtst_tables", paths, reports_dir, config_hash_=config_hash)
    figs = write_mtst_figure(data, figures_dir, trial=(s or {}).get("figure_trial"),
                             methods=methods)
    stamp("mtst_figures", figs, reports_dir, config_hash_=config_hash)
    return paths + figs
