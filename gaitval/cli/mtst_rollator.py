"""Verbs of the multi-target stepping task (seed 001) and the robotic rollator (seed 002)."""
from __future__ import annotations

from gaitval.cli.table import (SCAN_LOG_ARG, SHEET_ARG, SUBJECTS_ARG, TABLE_OUTPUT_ARGS,
                               TRIAL_ARG, A, Verb, eval_dirs_arg, labelled_eval_args,
                               view_arg)


def cmd_mtst_track(a) -> int:
    from gaitval.pipeline.mtst import mtst_track_step
    mtst_track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config,
                    a.registration, a.out, detections=a.detections)
    return 0


def cmd_mtst_detect(a) -> int:
    from gaitval.pipeline.mtst import mtst_detect_step
    mtst_detect_step(a.sensor, a.sheet, a.subjects, a.trial, a.detector, a.config, a.out)
    return 0


def cmd_mtst_evaluate(a) -> int:
    from gaitval.pipeline.mtst import mtst_evaluate_step
    s = mtst_evaluate_step(a.track, a.sheet, a.subjects, a.trial, a.method, a.config,
                           a.registration, a.groundtruth, a.out)
    print(s.to_string(index=False))
    return 0


def cmd_mtst_tables(a) -> int:
    from gaitval.pipeline.mtst import mtst_tables_step
    mtst_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir, a.config_hash,
                     methods=a.methods, config_json=a.config)
    return 0


def cmd_rollator_train(a) -> int:
    from gaitval.pipeline.rollator import rollator_train_step
    rollator_train_step(a.results, a.sheet, a.subjects, a.subject, a.config, a.out)
    return 0


def cmd_rollator_track(a) -> int:
    from gaitval.pipeline.rollator import rollator_track_step
    rollator_track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config, a.out,
                        a.model)
    return 0


def cmd_rollator_evaluate(a) -> int:
    from gaitval.pipeline.rollator import rollator_evaluate_step
    s = rollator_evaluate_step(a.track, a.groundtruth, a.registration, a.ingest, a.sheet,
                               a.subjects, a.trial, a.method, a.config, a.out)
    print(s.to_string(index=False))
    return 0


def cmd_rollator_tables(a) -> int:
    from gaitval.pipeline.rollator import rollator_tables_step
    rollator_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir,
                         a.config_hash, kf_method=a.kf, pf_method=a.pf, models=a.models,
                         config_json=a.config)
    return 0


#: an MTST step's scan log (ingested, or raw without mocap) and the trial it belongs to
MTST_TRIAL_ARGS = (
    A("--sensor", required=True,
      help="the trial's scan log: results/<study>/ingest/<trial>/sensor.parquet, or for a "
           "trial without mocap the raw scan log or bag the trial sheet names"),
    SHEET_ARG, SUBJECTS_ARG, TRIAL_ARG)

VERBS = (
    Verb("mtst-track", cmd_mtst_track,
         "track one MTST trial (every scan at Δt = 0.05 s)",
         A("--registration",
           help="the trial's registration.json "
                "(results/<study>/register/mtst/<trial>/); none: the pose from "
                "mtst.poles_m, the clock offset from the trial sheet's clock_offset_s"),
         A("--detections",
           help="the trial's observations by this method's detector (gaitval "
                "mtst-detect: results/<study>/detect/mtst/<detector>/<trial>.parquet), "
                "used instead of detecting again (default: none, the step detects)"),
         *MTST_TRIAL_ARGS,
         A("--method", required=True,
           help="the method's name: a built-in (mtst_m1, mtst_m2, mtst_m3, "
                "mtst_proposed, people) or one of tracking.methods"),
         view_arg("mtst", "the mtst: section (scan_period_s, mat), tracking.methods and "
                  "tracking.overrides"),
         A("--out", required=True,
           help="the per-scan track, Parquet, sensor frame and clock, metres, every "
                "scan at mtst.scan_period_s "
                "(results/<study>/mtst_track/<method>/<trial>.parquet)")),
    Verb("mtst-detect", cmd_mtst_detect,
         "one MTST trial's leg observations by one detector, for every method with "
         "that detector",
         A("--detector", required=True, help="the detector spec as JSON"),
         *MTST_TRIAL_ARGS,
         A("--config", required=True,
           help="a config (view) JSON (results/<study>/config_views/mtst/study.json): "
                "mtst.scan_period_s"),
         A("--out", required=True,
           help="the observation table, Parquet "
                "(results/<study>/detect/mtst/<detector>/<trial>.parquet)")),
    Verb("mtst-evaluate", cmd_mtst_evaluate,
         "contacts, target and cross steps of one trial, against annotations (and "
         "mocap)",
         A("--registration",
           help="the trial's registration.json "
                "(results/<study>/register/mtst/<trial>/); none: the pose from "
                "mtst.poles_m, the clock offset from the trial sheet's clock_offset_s"),
         A("--groundtruth",
           help="the trial's groundtruth.parquet "
                "(results/<study>/register/mtst/<trial>/; studies with mocap; none: "
                "against the annotations only)"),
         A("--track", required=True,
           help="the trial's track of mtst-track or import-tracks "
                "(results/<study>/mtst_track/<method>/<trial>.parquet)"),
         A("--sheet", required=True,
           help="the study's trial sheet, trials.csv (data/<study>/trials.csv for a "
                "simulated study; docs/formats.md, Trial sheet); names the trial's "
                "annotation file"),
         *labelled_eval_args(
             "mtst", "the mtst: section (targets, mat, gates)",
             "folder (results/<study>/mtst_eval/<method>/<trial>): contacts, steps, "
             "events, gates, track_field, summary, targets (.parquet)")),
    Verb("mtst-tables", cmd_mtst_tables,
         "Yorozu et al. 2015b Tables 1, 3, 4 and the trial figure",
         eval_dirs_arg("per-(trial, method) evaluation folders of mtst-evaluate "
                       "(results/<study>/mtst_eval/<method>/<trial>)"),
         A("--methods", nargs="+",
           help="the methods, in table order; one not in mtst.methods is shown as an "
                "external tracker (default: mtst.methods of --config, else mtst_m1 "
                "mtst_m2 mtst_m3 mtst_proposed)"),
         A("--config",
           help="a study's config (view) JSON "
                "(results/<study>/config_views/mtst/study.json): the mtst: section; "
                "the method views beside it name a method run with tracking.overrides"),
         *TABLE_OUTPUT_ARGS),
    Verb("rollator-train", cmd_rollator_train,
         "learn the PF model for one held-out subject",
         A("--results", required=True, metavar="DIR",
           help="results/<study>: the other subjects' rollator trials' "
                "ingest/<trial>/sensor.parquet and register/rollator/<trial>/"),
         SHEET_ARG,
         SUBJECTS_ARG,
         A("--subject", required=True,
           help="the held-out subject's id: the model learns from every other "
                "subject's rollator trials"),
         A("--config", required=True,
           help="a config (view) JSON "
                "(results/<study>/config_views/rollator/study.json): "
                "rollator.train_seed; registration.default_leg_width_m"),
         A("--out", required=True,
           help="the PF model, JSON (results/<study>/rollator/model/<subject>.json)")),
    Verb("rollator-track", cmd_rollator_track,
         "track one rollator trial with the KF or PF",
         A("--model",
           help="the held-out subject's PF model of rollator-train "
                "(results/<study>/rollator/model/<subject>.json; PF methods)"),
         SCAN_LOG_ARG,
         SHEET_ARG,
         SUBJECTS_ARG,
         TRIAL_ARG,
         A("--method", required=True,
           help="rollator_kf, rollator_pf or one of rollator.methods (e.g. people)"),
         view_arg("rollator", "the rollator: section, tracking.methods and "
                  "tracking.overrides"),
         A("--out", required=True,
           help="the per-scan track, Parquet, in the laser's (moving) frame, metres "
                "(results/<study>/rollator/<method>/<trial>.track.parquet)")),
    Verb("rollator-evaluate", cmd_rollator_evaluate,
         "evaluate one tracked rollator trial",
         A("--ingest", required=True, metavar="DIR",
           help="the trial's ingest folder (results/<study>/ingest/<trial>: "
                "mocap.parquet with the rollator's markers)"),
         A("--track", required=True,
           help="the trial's track of rollator-track or import-tracks "
                "(results/<study>/rollator/<method>/<trial>.track.parquet)"),
         A("--groundtruth", required=True,
           help="the trial's groundtruth.parquet "
                "(results/<study>/register/rollator/<trial>/)"),
         A("--registration", required=True,
           help="the trial's registration.json "
                "(results/<study>/register/rollator/<trial>/): clock offset and drift, "
                "status"),
         SHEET_ARG,
         *labelled_eval_args(
             "rollator", "the rollator: section, tracking.methods and tracking.overrides",
             "folder (results/<study>/rollator/<method>/<trial>): frames.parquet, "
             "summary.parquet")),
    Verb("rollator-tables", cmd_rollator_tables,
         "Chalvatzaki et al. 2017 Tables I, II and the figure",
         eval_dirs_arg("per-(trial, method) evaluation folders of rollator-evaluate "
                       "(results/<study>/rollator/<method>/<trial>)"),
         A("--kf", default="rollator_kf",
           help="the KF method's name (rollator.kf_method; default rollator_kf)"),
         A("--pf", default="rollator_pf",
           help="the PF method's name (rollator.pf_method; default rollator_pf)"),
         A("--models", nargs="*", default=[],
           help="the PF models used (results/<study>/rollator/model/<subject>.json); "
                "the tables name their training source (default: none)"),
         A("--config",
           help="a study's config (view) JSON "
                "(results/<study>/config_views/rollator/study.json): the rollator: "
                "section; the method views beside it name a method run with "
                "tracking.overrides"),
         *TABLE_OUTPUT_ARGS),
)
