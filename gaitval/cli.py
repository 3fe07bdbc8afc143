"""``gaitval <verb>``: the pipeline's steps by hand, one verb per rule family.

Run ``gaitval --help`` or ``gaitval <verb> --help``.  Every verb reads files and writes
files; a data error prints one line ``gaitval: error: ...`` naming the file, the trial and
the problem, and exits with status 1; a usage error exits with 2
(:mod:`gaitval.cli_exit`).  ``-v``/``-q`` before or after the verb: more or less progress.
"""
from __future__ import annotations

import argparse
import functools
import json
import logging
import re
import sys
from pathlib import Path


# -- verbs --------------------------------------------------------------------------------
def cmd_inspect(a) -> int:
    from gaitval.io.inspect import describe, format_description
    d = describe(a.file, topic=a.topic)
    print(json.dumps(d, indent=1, sort_keys=True, default=str) if a.json
          else format_description(d))
    return 0


def cmd_validate(a) -> int:
    from gaitval.io.trialsheet import sheet_problems
    df, problems = sheet_problems(a.sheet, a.subjects, check_files=not a.no_file_check,
                                  allow_outside_paths=a.allow_outside_paths or None)
    if a.deep and not a.no_file_check:
        from gaitval.io.deepcheck import deep_problems
        said = {(p.trial, m.group(1)) for p in problems
                if (m := re.search(r"column '(\w+)': file .* not found", str(p)))}
        problems += [p for p in deep_problems(df, a.sheet, jobs=a.jobs)
                     if not any(p.trial == t and f"column {c!r}" in str(p) for t, c in said)]
    if not a.no_file_check:        # the study's external methods and study.yaml's keys
        from gaitval.pipeline.steps import external_problems, study_yaml_problems
        problems += study_yaml_problems(a.sheet)
        problems += external_problems(a.sheet, deep=a.deep)
    from gaitval.io.trialsheet import sheet_warnings
    for w in sheet_warnings(df):
        print(f"gaitval: warning: [file {a.sheet}] {w}", file=sys.stderr)
    if problems:
        for p in problems:
            print(f"gaitval: error: {p}", file=sys.stderr)
        print(f"{a.sheet}: {len(problems)} problem{'s' * (len(problems) > 1)}",
              file=sys.stderr)
        return 1
    counts = df.groupby("protocol").size().to_dict()
    opened = ", every file opened with its loader" if a.deep else ""
    print(f"{a.sheet}: {len(df)} trials OK ({', '.join(f'{k}: {v}' for k, v in counts.items())})"
          f"{opened}")
    return 0


def cmd_init_study(a) -> int:
    from gaitval.io.initstudy import init_study
    from gaitval.pipeline.steps import external_problems
    res = init_study(a.folder, study=a.study, force=a.force, max_time_gap_s=a.max_time_gap_s)
    # the study.yaml's external_methods: as `gaitval validate` checks them (issue 37)
    res.problems += external_problems(Path(a.folder) / "trials.csv")
    print(res.text())
    return 1 if res.problems else 0


def cmd_simulate(a) -> int:
    from gaitval.simulate import generate_study
    preset = a.preset
    if Path(preset).suffix in (".yaml", ".yml") and Path(preset).is_file():
        import yaml
        preset = yaml.safe_load(Path(preset).read_text())
    logging.getLogger("gaitval").info("simulating study %s into %s (the default preset "
                                      "takes about 10 s on two cores) ...", a.preset, a.out)
    sheet = generate_study(Path(a.out), preset, seed=a.seed)
    print(f"wrote {sheet}")
    return 0


def cmd_ingest(a) -> int:
    from gaitval.io.ingest import ingest_trial
    from gaitval.pipeline.steps import trial_row
    s = ingest_trial(trial_row(a.sheet, a.subjects, a.trial), a.out)
    print(json.dumps(s, sort_keys=True, default=str))
    return 0


def cmd_ingest_summary(a) -> int:
    import pandas as pd
    from gaitval.report.provenance import stamp
    from gaitval.tables import write_table
    rows = [json.loads(Path(p).read_text()) for p in sorted(a.inputs)]
    df = pd.DataFrame(rows)
    first = ["study", "trial", "protocol", "subject", "sensor_kind", "mocap_rate_hz",
             "mocap_frames", "markers", "marker_missing_pct", "events", "sensor_samples",
             "sensor_rate_hz", "beams", "anchors", "no_return_pct", "timestamp_issues",
             "annotations"]
    df = df[[c for c in first if c in df.columns]].sort_values("trial")
    for c in ("mocap_frames", "markers", "events", "sensor_samples", "beams", "anchors",
              "timestamp_issues", "annotations"):
        if c in df:
            df[c] = df[c].astype("Int64")
    stem = Path(a.out_stem)
    paths = write_table(df, stem, caption=(
        f"What gaitval read from each raw trial of study '{a.study}': mocap rate, frames and "
        "missing marker samples; sensor samples, rate, beams/anchors and no-return beams; "
        "timestamp problems (reported, never reordered); rater annotations."))
    stamp(stem.name, paths, a.reports_dir, config_hash_=a.config_hash)
    return 0


def cmd_peer(a) -> int:
    from gaitval.errors import ConfigError
    from gaitval.report.provenance import stamp
    from gaitval.tables.peer import write_peer_table
    units = {}
    for item in a.units or []:
        k, sep, v = item.partition("=")
        if not sep or not k.strip():
            raise ConfigError(f"--units {item!r}: give NAME=UNIT, e.g. stride_length=m")
        units[k.strip()] = v.strip()
    paths = write_peer_table(a.parquet, a.out_stem, name=a.name, system=a.system_prefix,
                             reference=a.reference_prefix, subject=a.subject,
                             units=units if a.units else None)
    stamp(Path(a.out_stem).name, paths, a.reports_dir, config_hash_=a.config_hash)
    return 0


def cmd_register(a) -> int:
    from gaitval.pipeline.steps import register_step
    rec = register_step(a.ingest, a.sheet, a.subjects, a.trial, a.config, a.out)
    print(json.dumps(rec, sort_keys=True, default=str))
    return 0


def cmd_registration_summary(a) -> int:
    from gaitval.pipeline.steps import registration_summary
    registration_summary(a.inputs, a.study, a.out_csv, a.out_stem, a.reports_dir,
                         a.config_hash)
    return 0


def cmd_track(a) -> int:
    from gaitval.pipeline.steps import track_step
    track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config, a.out,
               detections=a.detections)
    return 0


def cmd_detect(a) -> int:
    from gaitval.pipeline.steps import detect_step
    detect_step(a.sensor, a.sheet, a.subjects, a.trial, a.detector, a.config, a.out)
    return 0


def cmd_evaluate_tug(a) -> int:
    from gaitval.pipeline.steps import evaluate_tug_step
    s = evaluate_tug_step(a.track, a.groundtruth, a.registration, a.trial, a.method,
                          a.config, a.out)
    print(s.to_string(index=False))
    return 0


def cmd_export_tracks(a) -> int:
    from gaitval.pipeline.steps import export_tracks_step
    legs = None
    if a.legs:
        legs = dict(kv.split("=", 1) for kv in a.legs.split(",") if "=" in kv)
    print(f"wrote {export_tracks_step(a.track, a.out, a.units, a.topic, legs)}")
    return 0


def cmd_leg_detections(a) -> int:
    from gaitval.pipeline.steps import leg_detections_step
    print(json.dumps(leg_detections_step(a.detections, a.groundtruth, a.out, topic=a.topic,
                                         trial=a.trial, gate_m=a.gate_m,
                                         registration_json=a.registration,
                                         sensor_parquet=a.sensor, method=a.method,
                                         protocol=a.protocol,
                                         moving_sensor=a.moving_sensor),
                     sort_keys=True))
    return 0


def cmd_leg_detections_table(a) -> int:
    from gaitval.report.provenance import stamp
    from gaitval.tables.detections import write_detections_table
    paths = write_detections_table(a.dirs, a.out_stem)
    stamp("detections_table", paths, a.reports_dir, config_hash_=a.config_hash)
    return 0


def cmd_import_tracks(a) -> int:
    from gaitval.pipeline.steps import import_tracks_step
    import_tracks_step(a.tracks, a.sensor, a.registration, a.trial, a.method, a.out,
                       config_json=a.config, moving_sensor=a.moving_sensor)
    return 0


def cmd_tug_tables(a) -> int:
    from gaitval.pipeline.steps import tug_tables_step
    tug_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir, a.config_hash,
                    methods=a.methods, configs=a.configs)
    return 0


def cmd_ultrasonic_noise(a) -> int:
    from gaitval.pipeline.steps import ultrasonic_noise_step
    n = ultrasonic_noise_step(a.ingest, a.trials, a.config, a.out, a.table_stem,
                              a.reports_dir, a.config_hash)
    print(json.dumps(n, sort_keys=True))
    return 0


def cmd_ultrasonic_track(a) -> int:
    from gaitval.pipeline.steps import ultrasonic_track_step
    ultrasonic_track_step(a.ingest, a.trial, a.config, a.noise, a.out)
    return 0


def cmd_gait_parameters(a) -> int:
    from gaitval.pipeline.steps import gait_parameters_step
    gait_parameters_step(a.track, a.ingest, a.sheet, a.subjects, a.trial, a.config, a.out)
    return 0


def cmd_ultrasonic_tables(a) -> int:
    from gaitval.pipeline.steps import ultrasonic_tables_step
    ultrasonic_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir,
                           a.config_hash, config_json=a.config)
    return 0


def cmd_compare_tables(a) -> int:
    from gaitval.report.compare import run
    return run(a)


def cmd_report(a) -> int:
    from gaitval.report.index import build_index
    if a.complete is not None:     # the workflow's report job: no index over a partial report
        from gaitval.jobs.resume import refuse_unfinished
        refuse_unfinished(a.reports_dir, own_outputs=a.complete)
    md, html = build_index(a.reports_dir, study_names=a.studies)
    print(f"wrote {md} and {html}")
    return 0


# -- parser -------------------------------------------------------------------------------
# Help texts several verbs share; the paths are those the workflow passes (workflow/rules/).
_SHEET = ("the study's trial sheet, trials.csv (data/<study>/trials.csv for a simulated "
          "study; docs/formats.md, Trial sheet)")
_SUBJECTS = "the study's subject table, subjects.csv (leg width, height; docs/formats.md)"
_TRIAL = "trial id: a row of the trial sheet (named in errors and outputs)"
_REPORTS = ("the report folder (reports/<run> in the workflow): the step's provenance record "
            "goes to its provenance/ (default: reports)")
_HASH = "the run's config hash, written into the provenance record (default: empty)"
_TABLES = "folder the tables go to, each as .csv, .md, .tex (reports/<run>/tables)"
_FIGURES = "folder the figures go to, PNG (reports/<run>/figures)"


def _add_input_verbs(sub) -> None:
    """Getting data in: inspect a file, validate a sheet, simulate, ingest, a peer's results."""
    s = sub.add_parser("inspect", help="show what gaitval's loaders see in a file")
    s.add_argument("file", help="a *.c3d, a ROS 1 *.bag or ROS 2 bag folder, a *.scan.parquet, "
                   "a *.us.parquet or a *.annotations.csv (docs/formats.md)")
    s.add_argument("--json", action="store_true",
                   help="print the description as JSON instead of text")
    s.add_argument("--topic", help="LaserScan topic (ROS bags with several)")
    s.set_defaults(func=cmd_inspect)

    s = sub.add_parser("validate", help="validate a trial sheet and its subject table")
    s.add_argument("sheet", help=_SHEET)
    s.add_argument("--subjects", help="subject table (default: subjects.csv beside the sheet)")
    s.add_argument("--no-file-check", action="store_true",
                   help="check the sheet's columns and values only, not the files it names "
                   "(skips --deep and the study's external methods' files)")
    s.add_argument("--allow-outside-paths", action="store_true",
                   help="accept paths outside the sheet's folder (default: as study.yaml says)")
    s.add_argument("--deep", action="store_true",
                   help="also open every file with the loader the pipeline uses (C3D, scan "
                   "log or bag topic, ultrasonic log, annotations) and report each that does "
                   "not load or holds no data")
    s.add_argument("--jobs", type=int, default=None,
                   help="processes for --deep (default: one per core)")
    s.set_defaults(func=cmd_validate)

    s = sub.add_parser("init-study", help="trial sheet, subject table, study.yaml and a "
                       "config snippet from a folder of recordings; then validate")
    s.add_argument("folder", help="the study's folder: C3D files, scan logs or bags, "
                   "ultrasonic logs, annotations, target layouts, external trackers' "
                   "<trial>.tracks.csv (declared in the study.yaml; sub-folders too)")
    s.add_argument("--study", help="study id (default: the folder's name)")
    s.add_argument("--force", action="store_true",
                   help="replace an existing trials.csv and subjects.csv")
    s.add_argument("--max-time-gap-s", type=float, default=300.0,
                   help="pair a sensor file with a C3D of another name when the two were "
                   "written at most this far apart (s; default 300)")
    s.set_defaults(func=cmd_init_study)

    s = sub.add_parser("simulate", help="generate a simulated study (raw files + truth/)")
    s.add_argument("--preset", default="default",
                   help="preset name in config/studies/ (default, tiny, replay, ...) or a "
                   "YAML file (the workflow passes config/studies/<preset>.yaml; "
                   "default: default)")
    s.add_argument("--seed", type=int, default=None,
                   help="random seed, overrides the preset's seed (default: the preset's)")
    s.add_argument("--out", required=True, metavar="DIR",
                   help="the study folder to write (data/<study>): trials.csv, subjects.csv, "
                   "study.yaml, mocap/, lrs/, annotations/, ..., truth/")
    s.set_defaults(func=cmd_simulate)

    s = sub.add_parser("ingest", help="raw files of one trial -> tidy per-trial files")
    s.add_argument("--sheet", required=True, help=_SHEET)
    s.add_argument("--subjects", help="subject table (default: subjects.csv beside the sheet)")
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--out", required=True, metavar="DIR",
                   help="the trial's ingest folder (results/<study>/ingest/<trial>): "
                   "mocap.parquet (metres, mocap clock), events.csv, sensor.parquet, "
                   "annotations.csv, ingest.json")
    s.set_defaults(func=cmd_ingest)

    s = sub.add_parser("ingest-summary", help="table of what was ingested")
    s.add_argument("inputs", nargs="+", metavar="INGEST_JSON",
                   help="ingest.json files (results/<study>/ingest/<trial>/ingest.json)")
    s.add_argument("--study", required=True, help="study id (named in the caption)")
    s.add_argument("--out-stem", required=True, help="the table's path without suffix "
                   "(reports/<run>/tables/study_ingest_<study>; writes .csv, .md, .tex)")
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    s.set_defaults(func=cmd_ingest_summary)

    s = sub.add_parser("peer", help="agreement statistics (Bland-Altman, ICC, RMSE, "
                       "t-test) of any system's paired results against a reference: one "
                       "row per walk or stride, us_<name> / gt_<name> column pairs (e.g. "
                       "an external system's stride parameters against the mocap's)")
    s.add_argument("parquet", help="Parquet or CSV file with us_<name> / gt_<name> column "
                   "pairs (other prefixes: --system-prefix, --reference-prefix), one row "
                   "per walk or stride")
    s.add_argument("--system-prefix", default="us_", help="the system's column prefix "
                   "(default us_)")
    s.add_argument("--reference-prefix", default="gt_", help="the reference's column "
                   "prefix (default gt_)")
    s.add_argument("--subject", help="the column naming each row's participant (default: "
                   "the first of subject, participant, subject_id, participant_id); "
                   "without one, no repeated-measures statistics")
    s.add_argument("--units", nargs="+", metavar="NAME=UNIT", help="each parameter's unit "
                   "for the unit column, e.g. stride_length=m stride_time=s (default: the "
                   "peer data's: cm, s, cm/s, steps/min)")
    s.add_argument("--name", help="the system's name: a study's own paired results "
                   "(agreement_files.<name>) instead of the peer's worked example")
    s.add_argument("--out-stem", required=True, help="e.g. reports/<run>/tables/"
                   "peer_agreement (writes .csv, .md, .tex)")
    s.add_argument("--reports-dir", default="reports", help="the report folder "
                   "(provenance/)")
    s.add_argument("--config-hash", default="", help="provenance stamp")
    s.set_defaults(func=cmd_peer)


def _add_lrs_verbs(sub) -> None:
    """Laser range sensor studies: registration and ground truth, tracking, TUG evaluation."""
    s = sub.add_parser("register", help="register one trial and build its ground truth")
    s.add_argument("--ingest", required=True, metavar="DIR", help="the trial's ingest "
                   "folder (results/<study>/ingest/<trial>: mocap.parquet, sensor.parquet)")
    s.add_argument("--sheet", required=True, help=_SHEET)
    s.add_argument("--subjects", required=True, help=_SUBJECTS)
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--config", required=True, metavar="JSON", help="the study view of the "
                   "trial's protocol family (results/<study>/config_views/<family>/"
                   "study.json) or results/<study>/config.json: registration: and "
                   "groundtruth: sections")
    s.add_argument("--out", required=True, metavar="DIR", help="the trial's register folder "
                   "(results/<study>/register/<family>/<trial>): registration.json (pose, "
                   "clock offset, status ok/refused and reason), groundtruth.parquet (leg "
                   "points at the sensor's height, metres, sensor clock)")
    s.set_defaults(func=cmd_register)

    s = sub.add_parser("registration-summary", help="registration.csv + report table")
    s.add_argument("inputs", nargs="+", metavar="REGISTRATION_JSON",
                   help="registration.json files (results/<study>/register/<family>/"
                   "<trial>/registration.json)")
    s.add_argument("--study", required=True, help="study id (named in the caption)")
    s.add_argument("--out-csv", required=True, help="one row per trial "
                   "(results/<study>/registration.csv)")
    s.add_argument("--out-stem", required=True, help="the report table's path without "
                   "suffix (reports/<run>/tables/study_registration_<study>; writes .csv, "
                   ".md, .tex)")
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    s.set_defaults(func=cmd_registration_summary)

    s = sub.add_parser("track", help="run one tracker method on one LRS trial")
    s.add_argument("--sensor", required=True, help="the trial's ingested scan log "
                   "(results/<study>/ingest/<trial>/sensor.parquet)")
    s.add_argument("--sheet", required=True, help=_SHEET)
    s.add_argument("--subjects", required=True, help=_SUBJECTS)
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--method", required=True, help="the method's name: a built-in (e.g. "
                   "tug_m1, tug_m2, tug_m3, people) or one of tracking.methods")
    s.add_argument("--config", required=True, metavar="JSON", help="the method's config "
                   "view (results/<study>/config_views/tug/<method>.json) or "
                   "results/<study>/config.json: tracking.methods and tracking.overrides; "
                   "registration.default_leg_width_m for a subject without leg_width_m")
    s.add_argument("--detections", default=None,
                   help="the trial's observations by this method's detector (gaitval "
                        "detect: results/<study>/detect/tug/<detector>/<trial>.parquet), "
                        "used instead of detecting again (default: none, the step detects)")
    s.add_argument("--out", required=True, help="the per-scan track, Parquet, sensor frame "
                   "and clock, metres (results/<study>/track/<method>/<trial>.parquet)")
    s.set_defaults(func=cmd_track)

    s = sub.add_parser("detect", help="one TUG trial's leg observations by one detector, "
                                      "for every method with that detector")
    s.add_argument("--sensor", required=True, help="the trial's ingested scan log "
                   "(results/<study>/ingest/<trial>/sensor.parquet)")
    s.add_argument("--sheet", required=True, help=_SHEET)
    s.add_argument("--subjects", required=True, help=_SUBJECTS)
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--detector", required=True, help="the detector spec as JSON, e.g. "
                   "'{\"name\": \"leg_patterns\", \"use_fs_u\": true}'")
    s.add_argument("--config", required=True, metavar="JSON",
                   help="a config (view) JSON (results/<study>/config_views/tug/study.json): "
                   "registration.default_leg_width_m for a subject without leg_width_m")
    s.add_argument("--out", required=True, help="the observation table, Parquet "
                   "(results/<study>/detect/tug/<detector>/<trial>.parquet)")
    s.set_defaults(func=cmd_detect)

    s = sub.add_parser("evaluate-tug", help="evaluate one tracked TUG trial against its "
                       "mocap legs: per-frame errors, false tracking (swaps, lost legs), "
                       "stance identification (Yorozu et al. 2015a Tables 3-5)")
    s.add_argument("--track", required=True, help="the trial's per-scan track "
                   "(results/<study>/track/<method>/<trial>.parquet: gaitval's own, or an "
                   "external method's from 'gaitval import-tracks'; sensor frame and clock)")
    s.add_argument("--groundtruth", required=True, help="the trial's groundtruth.parquet "
                   "(results/<study>/register/tug/<trial>/): mocap legs at the laser's "
                   "height, on the sensor clock")
    s.add_argument("--registration", required=True, help="the trial's registration.json "
                   "(results/<study>/register/tug/<trial>/; a refused registration: the "
                   "trial is counted as not registered)")
    s.add_argument("--trial", required=True, help="trial id (named in errors and outputs)")
    s.add_argument("--method", required=True, help="the method's name (its label in the "
                   "tables)")
    s.add_argument("--config", required=True, help="the method's config view "
                   "(results/<study>/config_views/tug/<method>.json): its evaluation.tug "
                   "thresholds and tug: section")
    s.add_argument("--out", required=True, help="folder (results/<study>/evaluate/<method>/"
                   "<trial>): frames.parquet, events.parquet, stance.parquet, "
                   "summary.parquet")
    s.set_defaults(func=cmd_evaluate_tug)

    # external tracks (issue 37): docs/formats.md, "Leg tracks"
    s = sub.add_parser("export-tracks", help="one of gaitval's track files (or a bag's people "
                       "topic) in the leg-track exchange format (*.tracks.csv / .parquet); "
                       "an ultrasonic UKF track as a heel trajectory (*.foot.csv / .parquet)")
    s.add_argument("track", help="results/<study>/track/<method>/<trial>.parquet, a ROS "
                   "bag with a tracker's people topic, or an ultrasonic track "
                   "results/<study>/ultrasonic/track/<trial>.parquet")
    s.add_argument("out", help="*.tracks.csv or *.tracks.parquet (leg tracks); *.foot.csv "
                   "or *.foot.parquet (a heel trajectory, from an ultrasonic track)")
    s.add_argument("--units", choices=("m", "mm"), default="m", help="the file's position "
                   "unit (header units:; default m)")
    s.add_argument("--topic", help="bags: the leg_tracker/PersonArray or people_msgs/People "
                   "topic (default: the only one)")
    s.add_argument("--legs", help="bags whose people are legs: the person ids of the "
                   "left and right leg, e.g. L=1,R=2 (a PoseArray: the poses' indices)")
    s.set_defaults(func=cmd_export_tracks)

    s = sub.add_parser("leg-detections", help="a detector's leg detections (leg_tracker/"
                       "LegArray or a *.detections.csv; no identity or side) of one trial "
                       "scored against its mocap legs: detection rate per leg, RMSE, false "
                       "detections per scan (docs/formats.md, Leg detections)")
    s.add_argument("--detections", required=True, help="a ROS 1 bag or ROS 2 bag folder with "
                   "the detections and the laser's scans (the same frame), or a "
                   "*.detections.csv / *.detections.parquet")
    s.add_argument("--topic", help="a bag's LegArray topic (default: the only one, e.g. "
                   "/detected_leg_clusters)")
    s.add_argument("--groundtruth", required=True, help="the trial's groundtruth.parquet "
                   "(results/<study>/register/<family>/<trial>/), on the sensor clock")
    s.add_argument("--registration", help="the trial's registration.json: converts a file "
                   "on the mocap clock or in the mocap frame")
    s.add_argument("--sensor", help="the trial's ingested sensor.parquet: time stamps "
                   "outside the recording and positions in the wrong units are refused")
    s.add_argument("--trial", help="trial id (named in errors)")
    s.add_argument("--method", help="the detector's name (written into summary.json)")
    s.add_argument("--protocol", help="the trial's protocol (written into summary.json)")
    s.add_argument("--gate-m", type=float, default=0.30, help="a detection farther than "
                   "this from a leg is not that leg's (default 0.30 m)")
    s.add_argument("--out", required=True, help="folder (results/<study>/leg_detections/"
                   "<detector>/<trial>): per_scan.parquet, summary.json")
    s.add_argument("--moving-sensor", action="store_true",
                   help="the laser moves (rollator trials): refuse detections in the "
                   "mocap frame (the laser's pose changes every frame)")
    s.set_defaults(func=cmd_leg_detections)

    s = sub.add_parser("leg-detections-table", help="the detection table of external leg "
                       "detectors: per method and protocol, detection rate, RMSE, false "
                       "detections per scan, pooled over the trials' leg-detections folders")
    s.add_argument("dirs", nargs="+", help="leg-detections output folders (one per trial: "
                   "summary.json, per_scan.parquet)")
    s.add_argument("--out-stem", required=True, help="e.g. reports/<run>/tables/"
                   "detections_table (writes .csv, .md, .tex)")
    s.add_argument("--reports-dir", required=True, help="the report folder (provenance/)")
    s.add_argument("--config-hash", default="", help="provenance stamp")
    s.set_defaults(func=cmd_leg_detections_table)

    s = sub.add_parser("import-tracks", help="an external tracker's *.tracks.csv/parquet of "
                       "one trial as gaitval's track (sensor clock and frame)")
    s.add_argument("--tracks", required=True, help="*.tracks.csv or *.tracks.parquet, or a "
                   "ROS bag with a tracker's topic (--config names topic and legs)")
    s.add_argument("--sensor", required=True, help="the trial's ingested sensor.parquet "
                   "(results/<study>/ingest/<trial>/; its time span)")
    s.add_argument("--registration", help="the trial's registration.json (pose and clock "
                   "offset, for a file in the mocap frame or clock; none: a trial without "
                   "mocap, the file must be on the sensor clock in the sensor frame)")
    s.add_argument("--trial", required=True, help="trial id (named in errors)")
    s.add_argument("--method", required=True, help="the external method's name")
    s.add_argument("--config", help="the method's config view (results/<study>/"
                   "config_views/<family>/<method>.json): tracking.external.<method> gives "
                   "a bag's topic and legs")
    s.add_argument("--moving-sensor", action="store_true",
                   help="the laser moves (rollator): refuse tracks in the mocap frame")
    s.add_argument("--out", required=True, help="the per-scan track (Parquet; in the "
                   "workflow results/<study>/track/<method>/<trial>.parquet, for MTST "
                   "mtst_track/<method>/<trial>.parquet, for the rollator "
                   "rollator/<method>/<trial>.track.parquet)")
    s.set_defaults(func=cmd_import_tracks)

    s = sub.add_parser("tug-tables", help="Yorozu et al. 2015a Tables 2-5 and figures")
    s.add_argument("inputs", nargs="+", metavar="EVAL_DIR",
                   help="per-(trial, method) evaluation folders of evaluate-tug "
                   "(results/<study>/evaluate/<method>/<trial>)")
    s.add_argument("--methods", nargs="+", default=["tug_m1", "tug_m2", "tug_m3"],
                   help="the methods, in table order (default: tug_m1 tug_m2 tug_m3)")
    s.add_argument("--tables-dir", required=True, help=_TABLES)
    s.add_argument("--figures-dir", required=True, help=_FIGURES)
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    s.add_argument("--configs", nargs="+", default=None,
                   help="each study's config.json or its method views (config_views/tug/"
                        "<method>.json) for Table 2; default: the config.json above each "
                        "evaluation folder")
    s.set_defaults(func=cmd_tug_tables)


def _add_ultrasonic_verbs(sub) -> None:
    """The ultrasonic study (seed 003): noise identification, UKF tracking, gait parameters."""
    s = sub.add_parser("ultrasonic-noise", help="V and W from pendulum trials; Table 1")
    s.add_argument("--ingest", nargs="+", required=True, metavar="DIR",
                   help="pendulum ingest folders (results/<study>/ingest/<trial>: the "
                   "ultrasonic log sensor.parquet and mocap.parquet)")
    s.add_argument("--trials", nargs="+", required=True, metavar="TRIAL",
                   help="their trial ids, same order")
    s.add_argument("--config", required=True, metavar="JSON", help="a config (view) JSON "
                   "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic: "
                   "section")
    s.add_argument("--out", required=True, help="noise.json: V per anchor, W, bias, RMSE "
                   "(results/runs/<run>/ultrasonic_noise.json)")
    s.add_argument("--table-stem", required=True, help="Table 1's path without suffix "
                   "(reports/<run>/tables/ultrasonic_table1; writes .csv, .md, .tex)")
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    s.set_defaults(func=cmd_ultrasonic_noise)

    s = sub.add_parser("ultrasonic-track", help="UKF track of one ultrasonic trial")
    s.add_argument("--ingest", required=True, metavar="DIR", help="the treadmill trial's "
                   "ingest folder (results/<study>/ingest/<trial>: the ultrasonic log "
                   "sensor.parquet)")
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--config", required=True, metavar="JSON", help="a config (view) JSON "
                   "(results/<study>/config_views/ultrasonic/study.json): ultrasonic.ukf, "
                   "ultrasonic.use_identified_W")
    s.add_argument("--noise", required=True, help="noise.json of ultrasonic-noise "
                   "(results/runs/<run>/ultrasonic_noise.json): the identified V")
    s.add_argument("--out", required=True, help="the UKF track, Parquet "
                   "(results/<study>/ultrasonic/track/<trial>.parquet)")
    s.set_defaults(func=cmd_ultrasonic_track)

    s = sub.add_parser("gait-parameters", help="per-stride parameters, reference vs system")
    s.add_argument("--track", required=True, help="the trial's UKF track of ultrasonic-track "
                   "(results/<study>/ultrasonic/track/<trial>.parquet)")
    s.add_argument("--ingest", required=True, metavar="DIR", help="the trial's ingest folder "
                   "(results/<study>/ingest/<trial>: sensor.parquet for the anchors, "
                   "mocap.parquet for the reference)")
    s.add_argument("--sheet", required=True, help=_SHEET)
    s.add_argument("--subjects", required=True, help=_SUBJECTS)
    s.add_argument("--trial", required=True, help=_TRIAL)
    s.add_argument("--config", required=True, metavar="JSON", help="a config (view) JSON "
                   "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic: "
                   "section")
    s.add_argument("--out", required=True, help="one row per stride, reference and system "
                   "(Qi et al. 2014 eq. 16-22), Parquet (results/<study>/ultrasonic/gait/"
                   "<trial>.parquet)")
    s.set_defaults(func=cmd_gait_parameters)

    s = sub.add_parser("ultrasonic-tables", help="Qi et al. 2014 Tables 2-8, C1 and figures")
    s.add_argument("inputs", nargs="+", metavar="GAIT_PARQUET",
                   help="per-trial gait parameter files of gait-parameters "
                   "(results/<study>/ultrasonic/gait/<trial>.parquet)")
    s.add_argument("--tables-dir", required=True, help=_TABLES)
    s.add_argument("--figures-dir", required=True, help=_FIGURES)
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    s.add_argument("--config", default=None,
                   help="config (view) JSON: ultrasonic.tables, the strides the tables use "
                   "(default: the paper's 10 per subject)")
    s.set_defaults(func=cmd_ultrasonic_tables)


def _add_external_foot_verbs(sub) -> None:
    """Another system's heel trajectory on the treadmill trials (issue 37): its gait
    parameters and the agreement table of every system."""
    def run(a) -> int:
        from gaitval.pipeline import steps as S
        if a.verb == "external-gait-parameters":
            gp = S.external_gait_parameters_step(a.foot, a.ingest, a.sheet, a.subjects,
                                                 a.trial, a.method, a.config, a.out)
            print(f"{a.trial}: {gp['stride'].nunique()} strides matched")
        else:
            S.method_agreement_step(a.gait, a.out_stem, a.reports_dir, a.config_hash,
                                    a.config)
        return 0

    s = sub.add_parser("external-gait-parameters", help="per-stride gait parameters of "
                       "another system's heel trajectory (*.foot.csv/parquet) on one "
                       "treadmill trial, against the camera reference (docs/formats.md, "
                       "Foot trajectories)")
    s.add_argument("--foot", required=True, help="the system's *.foot.csv or "
                   "*.foot.parquet of this trial (t_s, x, y, z; header units, frame, clock)")
    s.add_argument("--ingest", required=True, help="the trial's ingest folder "
                   "(results/<study>/ingest/<trial>/: sensor.parquet with the anchors, "
                   "mocap.parquet)")
    s.add_argument("--sheet", required=True, help="the study's trials.csv")
    s.add_argument("--subjects", required=True, help="the study's subjects.csv")
    s.add_argument("--trial", required=True, help="trial id (a treadmill trial)")
    s.add_argument("--method", required=True, help="the system's name (the rows' method)")
    s.add_argument("--config", required=True, help="the study's config view "
                   "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic "
                   "section (markers, resampling, low-pass, strides)")
    s.add_argument("--out", required=True, help="the gait parameter table (Parquet; "
                   "results/<study>/ultrasonic_external/<method>/<trial>.parquet)")
    s.set_defaults(func=run)

    s = sub.add_parser("method-agreement", help="agreement (Bland-Altman, ICC, repeated "
                       "measures) of each foot-tracking system with the camera reference on "
                       "the treadmill trials, one block of rows per system")
    s.add_argument("--gait", nargs="+", action="append", required=True,
                   metavar="METHOD_OR_FILE", help="a system's name followed by its gait "
                   "parameter files (gait-parameters / external-gait-parameters output); "
                   "once per system")
    s.add_argument("--out-stem", required=True, help="e.g. reports/<run>/tables/"
                   "ultrasonic_agreement_methods (writes .csv, .md, .tex)")
    s.add_argument("--config", help="a config view JSON: ultrasonic.tables chooses the "
                   "strides (default: 10 per subject and speed, seed 2014)")
    s.add_argument("--reports-dir", default="reports", help="the report folder "
                   "(provenance/)")
    s.add_argument("--config-hash", default="", help="provenance stamp")
    s.set_defaults(func=run)


def _add_mtst_verbs(sub) -> None:
    """The MTST study (seed 001): tracking, walking parameters and evaluation, Tables 1/3/4."""
    def run(a) -> int:
        from gaitval.pipeline import mtst as S
        if a.verb == "mtst-track":
            S.mtst_track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config,
                              a.registration, a.out, detections=a.detections)
        elif a.verb == "mtst-detect":
            S.mtst_detect_step(a.sensor, a.sheet, a.subjects, a.trial, a.detector,
                               a.config, a.out)
        elif a.verb == "mtst-evaluate":
            s = S.mtst_evaluate_step(a.track, a.sheet, a.subjects, a.trial, a.method,
                                     a.config, a.registration, a.groundtruth, a.out)
            print(s.to_string(index=False))
        else:
            S.mtst_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir,
                               a.config_hash, methods=a.methods, config_json=a.config)
        return 0

    def common(s, **helps):
        """Required options ``--<name>`` (``_`` -> ``-``), each with its help text."""
        for n, text in helps.items():
            s.add_argument(f"--{n.replace('_', '-')}", required=True, help=text)
        s.set_defaults(func=run)

    sensor = ("the trial's scan log: results/<study>/ingest/<trial>/sensor.parquet, or for "
              "a trial without mocap the raw scan log or bag the trial sheet names")
    registration = ("the trial's registration.json (results/<study>/register/mtst/<trial>/); "
                    "none: the pose from mtst.poles_m, the clock offset from the trial "
                    "sheet's clock_offset_s")
    s = sub.add_parser("mtst-track", help="track one MTST trial (every scan at Δt = 0.05 s)")
    s.add_argument("--registration", help=registration)
    s.add_argument("--detections", default=None,
                   help="the trial's observations by this method's detector (gaitval "
                        "mtst-detect: results/<study>/detect/mtst/<detector>/<trial>.parquet), "
                        "used instead of detecting again (default: none, the step detects)")
    common(s, sensor=sensor, sheet=_SHEET, subjects=_SUBJECTS, trial=_TRIAL,
           method="the method's name: a built-in (mtst_m1, mtst_m2, mtst_m3, mtst_proposed, "
           "people) or one of tracking.methods",
           config="the method's config view (results/<study>/config_views/mtst/"
           "<method>.json): the mtst: section (scan_period_s, mat), tracking.methods and "
           "tracking.overrides",
           out="the per-scan track, Parquet, sensor frame and clock, metres, every scan at "
           "mtst.scan_period_s (results/<study>/mtst_track/<method>/<trial>.parquet)")
    s = sub.add_parser("mtst-detect", help="one MTST trial's leg observations by one "
                                           "detector, for every method with that detector")
    s.add_argument("--detector", required=True, help="the detector spec as JSON")
    common(s, sensor=sensor, sheet=_SHEET, subjects=_SUBJECTS, trial=_TRIAL,
           config="a config (view) JSON (results/<study>/config_views/mtst/study.json): "
           "mtst.scan_period_s",
           out="the observation table, Parquet "
           "(results/<study>/detect/mtst/<detector>/<trial>.parquet)")
    s = sub.add_parser("mtst-evaluate", help="contacts, target and cross steps of one trial, "
                                             "against annotations (and mocap)")
    s.add_argument("--registration", help=registration)
    s.add_argument("--groundtruth", help="the trial's groundtruth.parquet "
                   "(results/<study>/register/mtst/<trial>/; studies with mocap; none: "
                   "against the annotations only)")
    common(s, track="the trial's track of mtst-track or import-tracks "
           "(results/<study>/mtst_track/<method>/<trial>.parquet)",
           sheet=_SHEET + "; names the trial's annotation file",
           subjects=_SUBJECTS, trial=_TRIAL,
           method="the method's name (its label in the tables)",
           config="the method's config view (results/<study>/config_views/mtst/"
           "<method>.json): the mtst: section (targets, mat, gates)",
           out="folder (results/<study>/mtst_eval/<method>/<trial>): contacts, steps, "
           "events, gates, track_field, summary, targets (.parquet)")
    s = sub.add_parser("mtst-tables", help="Yorozu et al. 2015b Tables 1, 3, 4 and the trial figure")
    s.add_argument("inputs", nargs="+", metavar="EVAL_DIR",
                   help="per-(trial, method) evaluation folders of mtst-evaluate "
                   "(results/<study>/mtst_eval/<method>/<trial>)")
    s.add_argument("--methods", nargs="+", default=None,
                   help="the methods, in table order; one not in mtst.methods is shown as "
                   "an external tracker (default: mtst.methods of --config, else mtst_m1 "
                   "mtst_m2 mtst_m3 mtst_proposed)")
    s.add_argument("--config", help="a study's config (view) JSON (results/<study>/"
                   "config_views/mtst/study.json): the mtst: section; the method views "
                   "beside it name a method run with tracking.overrides")
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    common(s, tables_dir=_TABLES, figures_dir=_FIGURES)


def _add_rollator_verbs(sub) -> None:
    """The rollator study (seed 002): PF training, KF/PF tracking, evaluation, Tables I-II."""
    def run(a) -> int:
        from gaitval.pipeline import rollator as S
        if a.verb == "rollator-train":
            S.rollator_train_step(a.results, a.sheet, a.subjects, a.subject, a.config, a.out)
        elif a.verb == "rollator-track":
            S.rollator_track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config,
                                  a.out, a.model)
        elif a.verb == "rollator-evaluate":
            s = S.rollator_evaluate_step(a.track, a.groundtruth, a.registration, a.ingest,
                                         a.sheet, a.subjects, a.trial, a.method, a.config,
                                         a.out)
            print(s.to_string(index=False))
        else:
            S.rollator_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir,
                                   a.config_hash, kf_method=a.kf, pf_method=a.pf,
                                   models=a.models, config_json=a.config)
        return 0

    def common(s, **helps):
        """Required options ``--<name>`` (``_`` -> ``-``), each with its help text."""
        for n, text in helps.items():
            s.add_argument(f"--{n.replace('_', '-')}", required=True, help=text)
        s.set_defaults(func=run)

    view = ("the method's config view (results/<study>/config_views/rollator/<method>.json): "
            "the rollator: section, tracking.methods and tracking.overrides")
    s = sub.add_parser("rollator-train", help="learn the PF model for one held-out subject")
    s.add_argument("--results", required=True, metavar="DIR",
                   help="results/<study>: the other subjects' rollator trials' "
                   "ingest/<trial>/sensor.parquet and register/rollator/<trial>/")
    common(s, sheet=_SHEET, subjects=_SUBJECTS,
           subject="the held-out subject's id: the model learns from every other subject's "
           "rollator trials",
           config="a config (view) JSON (results/<study>/config_views/rollator/study.json): "
           "rollator.train_seed; registration.default_leg_width_m",
           out="the PF model, JSON (results/<study>/rollator/model/<subject>.json)")
    s = sub.add_parser("rollator-track", help="track one rollator trial with the KF or PF")
    s.add_argument("--model", help="the held-out subject's PF model of rollator-train "
                   "(results/<study>/rollator/model/<subject>.json; PF methods)")
    common(s, sensor="the trial's ingested scan log "
           "(results/<study>/ingest/<trial>/sensor.parquet)",
           sheet=_SHEET, subjects=_SUBJECTS, trial=_TRIAL,
           method="rollator_kf, rollator_pf or one of rollator.methods (e.g. people)",
           config=view,
           out="the per-scan track, Parquet, in the laser's (moving) frame, metres "
           "(results/<study>/rollator/<method>/<trial>.track.parquet)")
    s = sub.add_parser("rollator-evaluate", help="evaluate one tracked rollator trial")
    s.add_argument("--ingest", required=True, metavar="DIR", help="the trial's ingest folder "
                   "(results/<study>/ingest/<trial>: mocap.parquet with the rollator's "
                   "markers)")
    common(s, track="the trial's track of rollator-track or import-tracks "
           "(results/<study>/rollator/<method>/<trial>.track.parquet)",
           groundtruth="the trial's groundtruth.parquet "
           "(results/<study>/register/rollator/<trial>/)",
           registration="the trial's registration.json "
           "(results/<study>/register/rollator/<trial>/): clock offset and drift, status",
           sheet=_SHEET, subjects=_SUBJECTS, trial=_TRIAL,
           method="the method's name (its label in the tables)", config=view,
           out="folder (results/<study>/rollator/<method>/<trial>): frames.parquet, "
           "summary.parquet")
    s = sub.add_parser("rollator-tables", help="Chalvatzaki et al. 2017 Tables I, II and the figure")
    s.add_argument("inputs", nargs="+", metavar="EVAL_DIR",
                   help="per-(trial, method) evaluation folders of rollator-evaluate "
                   "(results/<study>/rollator/<method>/<trial>)")
    s.add_argument("--kf", default="rollator_kf",
                   help="the KF method's name (rollator.kf_method; default rollator_kf)")
    s.add_argument("--pf", default="rollator_pf",
                   help="the PF method's name (rollator.pf_method; default rollator_pf)")
    s.add_argument("--models", nargs="*", default=[],
                   help="the PF models used (results/<study>/rollator/model/<subject>.json); "
                   "the tables name their training source (default: none)")
    s.add_argument("--config", help="a study's config (view) JSON (results/<study>/"
                   "config_views/rollator/study.json): the rollator: section; the method "
                   "views beside it name a method run with tracking.overrides")
    s.add_argument("--reports-dir", default="reports", help=_REPORTS)
    s.add_argument("--config-hash", default="", help=_HASH)
    common(s, tables_dir=_TABLES, figures_dir=_FIGURES)

def run_verbs(argvs: list[list[str]]) -> None:
    """A batch task (gaitval.jobs.batch): gaitval verbs one after the other, each as
    ``gaitval ARGV`` on the command line would run it (this parser and its exit codes);
    the first that fails stops the task.  Each verb's command line goes to the log first
    (``$ gaitval ...``, quoted as a shell would need it): the same step, by hand."""
    import copy
    import shlex

    from gaitval.cli_exit import run_verb
    from gaitval.jobs.batch import VerbFailed

    saved = sys.argv
    try:
        for argv in argvs:
            sys.argv = ["gaitval", *argv]        # what a table's provenance records
            print(f"$ {shlex.join(sys.argv)}", flush=True)   # the same step by hand
            args = copy.deepcopy(parser().parse_args(list(argv)))
            rc = run_verb(args.func, args)
            if rc:
                raise VerbFailed(f"gaitval {argv[0]} exited with status {rc}")
    finally:
        sys.argv = saved


def cmd_stage(a) -> int:
    """``gaitval <stage>-trials``: make the job's output folders, then run every trial's
    verbs (:data:`gaitval.jobs.stages.STAGES`) in a pool of ``--threads`` processes forked
    from this one, largest first by ``--sizes`` (the log: gaitval.jobs.batch.run_batch)."""
    from pathlib import Path

    from gaitval.jobs.batch import Task, by_size, run_batch
    from gaitval.jobs.stages import STAGES, aligned, preload

    for d in a.out:
        Path(d).mkdir(parents=True, exist_ok=True)   # a batch of no trial leaves its folder
    tasks = [Task(label, run_verbs, {"argvs": argvs}) for label, argvs in STAGES[a.verb][0](a)]
    if a.sizes:
        tasks = by_size(tasks, [float(s) for s in aligned(a, "sizes")])
    if tasks:
        preload(a.verb)
    run_batch(tasks, a.threads, a.log, fork=True)
    return 0


def _add_stage_verbs(sub) -> None:
    """The workflow's jobs: one stage's trials in a process pool (gaitval.jobs.stages)."""
    from gaitval.jobs.stages import OPTIONS, STAGES

    for name, (_, text) in STAGES.items():
        s = sub.add_parser(name, help=f"{text} (a workflow job; the per-trial verbs in a "
                           "pool of --threads processes)")
        for opt, kw in OPTIONS.items():
            s.add_argument(f"--{opt.replace('_', '-')}", **kw)
        s.set_defaults(func=cmd_stage)


def build_parser() -> argparse.ArgumentParser:
    """The ``gaitval`` argument parser: one sub-command per verb, in pipeline order."""
    p = argparse.ArgumentParser(
        prog="gaitval", description=__doc__.splitlines()[0].replace("``", ""),
        epilog="'gaitval VERB --help': what the verb reads and writes (the paths the "
               "workflow uses, formats, units, defaults). Exit codes: 0 done, 1 a data "
               "error, 2 a usage error (README, 'When something goes wrong').")
    from gaitval import __version__
    p.add_argument("--version", action="version", version=f"gaitval {__version__}")
    sub = p.add_subparsers(dest="verb", required=True, metavar="VERB",
                           title="verbs (in pipeline order)")
    _add_input_verbs(sub)
    _add_lrs_verbs(sub)
    _add_ultrasonic_verbs(sub)
    _add_external_foot_verbs(sub)
    _add_mtst_verbs(sub)
    _add_rollator_verbs(sub)
    _add_stage_verbs(sub)
    from gaitval.pipeline.legbench import add_legbench_verbs
    add_legbench_verbs(sub)              # annotated recordings without mocap (issue 18)
    from gaitval.pipeline.paper_figures import add_paper_figure_verbs
    add_paper_figure_verbs(sub)          # the papers' example figures

    s = sub.add_parser("report", help="write reports/<run>/index.md, index.html and the "
                       "verdict table from the report folder's tables and figures")
    s.add_argument("--reports-dir", default="reports", metavar="DIR",
                   help="the report folder (reports/<run>: tables/, figures/, provenance/); "
                   "writes index.md, index.html, verdicts.csv/.md/.tex there (default: "
                   "reports)")
    s.add_argument("--studies", nargs="*", default=[], metavar="STUDY",
                   help="the run's study ids (default: 'run' of <reports-dir>/provenance/"
                   "config.yaml)")
    s.add_argument("--complete", nargs="*", default=None, metavar="OUTPUT",
                   help="refuse (exit 1) while a table or figure a step's provenance lists "
                   "is missing or a file of the report is marked unfinished by an "
                   "interrupted Snakemake job; OUTPUT: the calling job's own outputs")
    s.set_defaults(func=cmd_report)
    s = sub.add_parser("compare-tables", help="two report folders' tables within a stated "
                       "tolerance (docs/numerics.md)")
    from gaitval.report.compare import add_arguments
    add_arguments(s)
    s.set_defaults(func=cmd_compare_tables)
    for choice in sub._choices_actions:  # `gaitval VERB --help` opens with what the verb does
        if sub.choices[choice.dest].description is None:
            sub.choices[choice.dest].description = choice.help
    from gaitval.cli_exit import add_verbosity
    add_verbosity(p, sub)
    return p

@functools.cache
def parser() -> argparse.ArgumentParser:
    """:func:`build_parser`, built once per process (~12 ms; a batch job's worker runs
    the verbs of many trials, gaitval.jobs.batch)."""
    return build_parser()


def main(argv: list[str] | None = None) -> int:
    """Run one verb; exit codes 0 ok, 1 data/analysis error, 2 usage (gaitval.cli_exit)."""
    import copy

    from gaitval.cli_exit import configure_logging, run_verb
    from gaitval.jobs.lifeline import verb_process
    verb_process()      # started by a workflow's job: end with its Snakemake (jobs/lifeline.py)
    # a copy: a verb that changes a default list (--methods ...) leaves the next job's alone
    args = copy.deepcopy(parser().parse_args(argv))
    configure_logging(args.verbose, args.quiet)
    return run_verb(args.func, args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
