"""Pipeline steps of the rollator study (seed 002): train, track, evaluate, tables.

File-level wrappers like :mod:`gaitval.pipeline.steps` (whose helpers they use): each reads the
files of one Snakemake rule, calls the library and writes files.  Per study, under
``results/<study>/rollator/``:

``model/<subject>.json``
    The particle filter's parameters learned leave-one-subject-out: from every rollator
    trial of the *other* subjects of the study whose registration succeeded
    (:func:`gaitval.track.pf_model.train_pf_model`); the geometric placeholders of
    :func:`~gaitval.track.pf_model.default_pf_model` when the study has no other subject.
``<method>/<trial>.track.parquet``
    The method's per-scan track (:data:`gaitval.track.TRACK_COLUMNS` + ``restart``).
``<method>/<trial>/{frames,summary}.parquet``
    :func:`gaitval.evaluate.rollator.evaluate_rollator_trial`, with the trial's subject,
    scenario and repetition.

The ``rollator:`` config section (documented in ``config/config.yaml``) names the two
methods (``kf_method``, ``pf_method``), the PF's seed (``pf_seed``), the mixtures' seed
(``train_seed``), the error-frame threshold (``error_m``) and the figure's trial.
"""
from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.io.atomic import write_parquet, write_text
from gaitval.pipeline.memo import FileMemo, file_identity
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.steps.config import (PROTOCOL_SCOPE, load_json, method_definition,
                                           method_display_names, method_overrides)
from gaitval.pipeline.steps.trials import trial_and_subject

#: defaults of the ``rollator:`` keys read here
DEFAULTS = {"kf_method": "rollator_kf", "pf_method": "rollator_pf",
            "methods": ["people", "people_offline"],
            "pf_seed": 2017,
            "train_seed": 0, "error_m": 0.10, "figure_trial": None}


def rollator_cfg(cfg: dict) -> dict:
    """The ``rollator:`` section of a study config with defaults filled in."""
    return {**DEFAULTS, **{k: v for k, v in (cfg.get("rollator") or {}).items()
                           if k in DEFAULTS}}


def rollator_people_overrides() -> dict:
    """The people tracker's setup on the rollator (docs/people.md, "No phantom user on
    the rollator"): the sensor is carried by the walker, so the user's place is known
    by construction — seed 002 §II's user window (x 0.10–1.00 m, y ±0.40 m behind the
    laser) — and the papers' KF starts on the leg pair it finds there at once.  The people
    tracker gets the same three things, all the built-in ``rollator_kf``'s (seed 002 §II):
    its detector (the window's K-means grouping, run on every scan without a prediction),
    its initialiser (``facing_pair``: the pair found there is the user, confirmed from its
    scan on, the people tracker's ``init`` role) and births limited to the window
    (``area``).  Its motion-based confirmation (``m_of_n_moving``) is left to hypotheses
    born later: it was written for a sensor that stands in the room and never confirms a
    rollator user (the legs stay side by side in the laser's frame, docs/people.md).
    Applied by :func:`rollator_track_step` to every method of kind ``people``, under the
    method's own ``tracking.overrides``; the TUG, MTST and legbench steps do not use it."""
    from gaitval.methods import METHODS

    kf = METHODS["rollator_kf"]
    det = kf["detector"]
    return {"kind__detector": copy.deepcopy(det), "kind__init": copy.deepcopy(kf["init"]),
            "kind__area": {"name": "rectangle", "x_m": list(det["window_x_m"]),
                           "y_m": list(det["window_y_m"])}}


def _leg_width(subj: dict, cfg: dict) -> float:
    w = subj.get("leg_width_m")
    if w is None or not np.isfinite(w):
        w = float((cfg.get("registration") or {}).get("default_leg_width_m", 0.10))
    return float(w)


# -- train ----------------------------------------------------------------------------------
#: A trial's training samples, by its scan log's and ground truth's identities and the leg
#: width: the leave-one-subject-out models each train on every other subject's trials, so
#: a worker that trains two models would compute most trials' samples twice.
_SAMPLES = FileMemo(128 * 2 ** 20)


def rollator_train_step(results_dir, sheet, subjects, subject: str, config_json,
                        out_json) -> dict:
    """Learn the PF model for held-out ``subject`` from the other subjects' trials.

    Reads ``<results_dir>/ingest/<trial>/sensor.parquet``,
    ``<results_dir>/register/rollator/<trial>/{registration.json,groundtruth.parquet}``
    (the rollator family's registration folder) of every rollator trial of another
    subject; refused registrations are left out (and listed in the model under
    ``skipped``).
    """
    from gaitval.io.scanlog import read_scanlog
    from gaitval.io.trialsheet import load_subjects, load_trial_sheet
    from gaitval.track.pf_model import default_pf_model, train_pf_model, training_samples

    cfg = load_json(config_json)
    rc = rollator_cfg(cfg)
    df = load_trial_sheet(sheet, subjects, check_files=False)
    subj = load_subjects(subjects)
    if subject not in set(df["subject"]):
        raise GaitvalError(f"subject {subject!r} has no trial in the trial sheet", path=sheet)
    train = df[(df["protocol"] == "rollator") & (df["subject"] != subject)].sort_index()
    rd = Path(results_dir)
    registered = rd / "register" / PROTOCOL_SCOPE["rollator"]   # register.smk: per family
    samples, used, skipped = [], [], []
    for trial, row in train.iterrows():
        reg = load_json(registered / trial / "registration.json")
        if reg.get("status") != "ok":
            skipped.append(trial)
            continue
        sensor = rd / "ingest" / trial / "sensor.parquet"
        gt_path = registered / trial / "groundtruth.parquet"
        w = _leg_width(subj.loc[row["subject"]].to_dict(), cfg)
        got = _SAMPLES.fetch(
            _SAMPLES.key(sensor, file_identity(gt_path), w),
            lambda: training_samples(read_scanlog(sensor, trial=trial), read_parquet(gt_path),
                                     w),
            lambda got: sum(getattr(v, "nbytes", 8) for v in got.values()))
        samples.append({k: v.copy() if isinstance(v, np.ndarray) else v
                        for k, v in got.items()})
        used.append(trial)
    if samples:
        try:
            model = train_pf_model(samples, seed=int(rc["train_seed"]), trained_on=used,
                                   held_out=subject)
        except GaitvalError as exc:
            raise exc.with_context(path=sheet, trial=f"training for {subject}") from None
    else:
        model = default_pf_model(_leg_width(subj.loc[subject].to_dict(), cfg))
        model["held_out_subject"] = subject
    model["skipped"] = skipped
    write_text(out_json, json.dumps(model, indent=1, sort_keys=True) + "\n")
    return model


# -- track ----------------------------------------------------------------------------------
def rollator_track_step(sensor_parquet, sheet, subjects, trial: str, method: str,
                        config_json, out_parquet, model_json=None) -> pd.DataFrame:
    """Track one rollator trial with one method (KF, PF, or an extra method of
    ``rollator.methods``); write the per-scan track.  A ``people`` method runs with the
    rollator's setup (:func:`rollator_people_overrides`).

    A raw-scan (particle-filter) method gets the held-out subject's model
    (``model_json``) and ``rollator.pf_seed`` as ``kind__model`` / ``kind__seed``;
    ``tracking.overrides`` of the method apply on top.  scikit-learn's thread pool is
    limited to one thread (per-scan K-means calls, see :mod:`gaitval.detect.window`).
    """
    from threadpoolctl import threadpool_limits

    from gaitval.io.scanlog import read_scanlog
    from gaitval.methods import build_method, get_method, kind_name

    cfg = load_json(config_json)
    rc = rollator_cfg(cfg)
    row, subj = trial_and_subject(sheet, subjects, trial)
    scans = read_scanlog(sensor_parquet, trial=trial)
    overrides = method_overrides(cfg, method)
    if model_json is not None:
        overrides = {"kind__model": load_json(model_json),
                     "kind__seed": int(rc["pf_seed"]), **overrides}
    try:
        definition = method_definition(cfg, method)
        if kind_name(get_method(definition)) == "people":        # the user's window (issue 36)
            overrides = {**rollator_people_overrides(), **overrides}
        kind = build_method(definition, overrides)
        with threadpool_limits(1):
            res = kind.track(scans, _leg_width(subj, cfg))
    except GaitvalError as exc:
        raise exc.with_context(path=sensor_parquet, trial=trial) from None
    track = res.to_frame()
    restarted = np.zeros(scans.n_scans, bool)
    restarted[np.asarray(res.restarts, dtype=int)] = True
    track["restart"] = np.repeat(restarted, 2)
    track.insert(0, "method", method)
    track.insert(0, "trial", trial)
    write_parquet(track, out_parquet)
    return track


# -- evaluate -------------------------------------------------------------------------------
def rollator_evaluate_step(track_parquet, gt_parquet, registration_json, ingest_dir, sheet,
                           subjects, trial: str, method: str, config_json, out_dir
                           ) -> pd.DataFrame:
    """Evaluate one tracked rollator trial (:mod:`gaitval.evaluate.rollator`).

    Writes ``frames.parquet`` and ``summary.parquet`` (with ``subject``, ``scenario``,
    ``repetition``).  A trial whose registration was refused for another reason than its
    rollator markers gets an empty evaluation with ``status = not_registered``; a trial
    whose C3D lacks a rollator marker stops with one
    :class:`~gaitval.errors.RegistrationError` naming the file and the trial.
    """
    from gaitval.evaluate.rollator import (FRAME_COLUMNS, SUMMARY_COLUMNS,
                                           evaluate_rollator_trial, pose_known)
    from gaitval.io.ingest import read_mocap_parquet
    from gaitval.registration.moving import rollator_labels

    cfg = load_json(config_json)
    row, _ = trial_and_subject(sheet, subjects, trial)
    rec = load_json(registration_json)
    track = read_parquet(track_parquet).drop(columns=["trial", "method"])
    mocap = read_mocap_parquet(Path(ingest_dir) / "mocap.parquet",
                               source=row.get("mocap_path") or None, trial=row["trial"])
    labels = rollator_labels(cfg)
    if rec.get("status") == "ok":
        known, inside = pose_known(mocap, track.groupby("k")["t_sensor_s"].first().to_numpy(),
                                   rec["clock_offset_s"], rec["clock_drift_ppm"] or 0.0,
                                   labels, trial=trial)
        res = evaluate_rollator_trial(track, read_parquet(gt_parquet), known, inside,
                                      trial=trial, tracker=method,
                                      cfg={"error_m": rollator_cfg(cfg)["error_m"]})
        summary = res["summary"].assign(status="ok")
    else:
        missing = [lb for lb in labels if not mocap.has(lb)]
        if missing:
            from gaitval.registration.moving import rollator_pose
            rollator_pose(mocap, labels, trial=trial)          # raises, naming file + trial
        res = {"frames": pd.DataFrame(columns=list(FRAME_COLUMNS))}
        summary = pd.DataFrame([{"trial": trial, "tracker": method}],
                               columns=list(SUMMARY_COLUMNS)).assign(status="not_registered")
    summary = summary.assign(subject=row["subject"], scenario=row.get("scenario") or "",
                             repetition=row.get("repetition"))
    out = Path(out_dir)
    write_parquet(res["frames"].reset_index(drop=True), out / "frames.parquet")
    write_parquet(summary.reset_index(drop=True), out / "summary.parquet")
    return summary


# -- tables ---------------------------------------------------------------------------------
def rollator_tables_step(eval_dirs: list[str | Path], tables_dir, figures_dir, reports_dir,
                         config_hash: str = "", kf_method: str = "rollator_kf",
                         pf_method: str = "rollator_pf", models: list[str | Path] = (),
                         config_json=None) -> list[Path]:
    """Seed 002 Tables I and II and the figure (a successful and a failed trial,
    :mod:`gaitval.report.rollator_figures`) from the evaluations."""
    from gaitval.report.provenance import stamp
    from gaitval.report.rollator_figures import write_rollator_figure
    from gaitval.tables.rollator import write_rollator_tables

    frames, summaries = [], []
    for d in eval_dirs:
        s = read_parquet(Path(d) / "summary.parquet")
        summaries.append(s)
        f = read_parquet(Path(d) / "frames.parquet")
        if len(f):
            frames.append(f.merge(s[["trial", "tracker", "subject", "scenario",
                                     "repetition"]], on=["trial", "tracker"]))
    if not summaries:
        raise GaitvalError("no rollator evaluations to tabulate")
    summary = pd.concat(summaries, ignore_index=True)
    frames_df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    cfg = load_json(config_json) if config_json else {}
    rc = rollator_cfg(cfg)
    sources = sorted({load_json(m).get("source", "") for m in models})
    shown = (method_display_names(Path(config_json).parent, [kf_method, pf_method])
             if config_json else {})
    # the other trackers evaluated: gaitval's own extra methods (rollator.methods, issue
    # 36) in the config's order, then external methods (tracking.external, issue 37)
    present = set(summary["tracker"].astype(str)) - {kf_method, pf_method}
    own = [m for m in rc["methods"] if m in present]
    external = own + sorted(present - set(own))
    paths = write_rollator_tables(frames_df, summary, tables_dir, kf=kf_method,
                                  pf=pf_method, error_m=float(rc["error_m"]),
                                  model_sources=sources, shown=shown, external=external,
                                  own=own)
    stamp("rollator_tables", paths, reports_dir, config_hash_=config_hash)
    figs = write_rollator_figure(frames_df, figures_dir, kf=kf_method, pf=pf_method,
                                 trial=rc["figure_trial"],
                                 mount=(cfg.get("rollator") or {}).get("sensor_mount"))
    stamp("rollator_figures", figs, reports_dir, config_hash_=config_hash)
    return paths + figs
