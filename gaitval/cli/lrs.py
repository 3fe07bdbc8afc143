"""Verbs of the laser range sensor studies (seed 000's TUG and the shared steps): register,
track, detect, evaluate, the external trackers' and detectors' files, the TUG tables, and
the annotated recordings without mocap (legbench)."""
from __future__ import annotations

import json
import sys

from gaitval.cli.table import (FIGURES_ARG, HASH_ARG, LABEL_METHOD_ARG, REPORTS_ARG,
                               SCAN_LOG_ARG, SHEET_ARG, SUBJECTS_ARG, TABLES_ARG, TRIAL_ARG,
                               A, Verb)


def cmd_register(a) -> int:
    from gaitval.pipeline.steps.register import register_step
    rec = register_step(a.ingest, a.sheet, a.subjects, a.trial, a.config, a.out)
    print(json.dumps(rec, sort_keys=True, default=str))
    return 0


def cmd_registration_summary(a) -> int:
    from gaitval.pipeline.steps.register import registration_summary
    registration_summary(a.inputs, a.study, a.out_csv, a.out_stem, a.reports_dir,
                         a.config_hash)
    return 0


def cmd_track(a) -> int:
    from gaitval.pipeline.steps.tracking import track_step
    track_step(a.sensor, a.sheet, a.subjects, a.trial, a.method, a.config, a.out,
               detections=a.detections)
    return 0


def cmd_detect(a) -> int:
    from gaitval.pipeline.steps.tracking import detect_step
    detect_step(a.sensor, a.sheet, a.subjects, a.trial, a.detector, a.config, a.out)
    return 0


def cmd_evaluate_tug(a) -> int:
    from gaitval.pipeline.steps.tug import evaluate_tug_step
    s = evaluate_tug_step(a.track, a.groundtruth, a.registration, a.trial, a.method,
                          a.config, a.out)
    print(s.to_string(index=False))
    return 0


def cmd_export_tracks(a) -> int:
    from gaitval.pipeline.steps.external import export_tracks_step
    legs = None
    if a.legs:
        legs = dict(kv.split("=", 1) for kv in a.legs.split(",") if "=" in kv)
    print(f"wrote {export_tracks_step(a.track, a.out, a.units, a.topic, legs)}")
    return 0


def cmd_leg_detections(a) -> int:
    from gaitval.pipeline.steps.external import leg_detections_step
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
    from gaitval.pipeline.steps.external import import_tracks_step
    import_tracks_step(a.tracks, a.sensor, a.registration, a.trial, a.method, a.out,
                       config_json=a.config, moving_sensor=a.moving_sensor)
    return 0


def cmd_tug_tables(a) -> int:
    from gaitval.pipeline.steps.tug import tug_tables_step
    tug_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir, a.config_hash,
                    methods=a.methods, configs=a.configs)
    return 0


def cmd_legbench_track(a) -> int:
    from gaitval.pipeline.legbench import legbench_track_step
    legbench_track_step(a.sensor, a.method, a.out, init=a.init, scan_topic=a.scan_topic,
                        annotations=a.annotations, annotation_topic=a.annotation_topic,
                        leg_width_m=a.leg_width_m, config_json=a.config, trial=a.trial)
    return 0


def cmd_legbench_evaluate(a) -> int:
    from gaitval.pipeline.legbench import legbench_evaluate_step
    s = legbench_evaluate_step(a.track, a.annotations, a.out,
                               annotation_topic=a.annotation_topic, scan_topic=a.scan_topic,
                               match_m=a.match_m, min_false_s=a.min_false_s, trial=a.trial,
                               sector_deg=a.sector_deg, benchmark_set=a.benchmark_set or "")
    if s.iloc[0]["gt"] == 0:
        print(f"gaitval: warning: no annotated person in {a.annotations}"
              f"{' inside the sector' if a.sector_deg else ''}: nothing to score",
              file=sys.stderr)
    cols = ["method", "init", "mota", "motp_m", "idsw", "idsw_ref", "idf1", "matches", "fn",
            "fp", "gt", "mota_following", "false_leg_tracks_per_min"]
    print(s[cols].to_string(index=False))
    return 0


def cmd_legbench_tables(a) -> int:
    from gaitval.pipeline.legbench import legbench_tables_step
    legbench_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir, a.config_hash,
                         methods=a.methods, inits=a.inits, views_dir=a.views_dir)
    return 0


def cmd_legbench_crowd(a) -> int:
    from gaitval.crowd.bench import crowd_step
    crowd_step(a.tables_dir, a.split)
    return 0


VERBS = (
    Verb("register", cmd_register,
         "register one trial and build its ground truth",
         A("--ingest", required=True, metavar="DIR",
           help="the trial's ingest folder (results/<study>/ingest/<trial>: "
                "mocap.parquet, sensor.parquet)"),
         SHEET_ARG,
         SUBJECTS_ARG,
         TRIAL_ARG,
         A("--config", required=True, metavar="JSON",
           help="the study view of the trial's protocol family "
                "(results/<study>/config_views/<family>/study.json) or "
                "results/<study>/config.json: registration: and groundtruth: sections"),
         A("--out", required=True, metavar="DIR",
           help="the trial's register folder "
                "(results/<study>/register/<family>/<trial>): registration.json (pose, "
                "clock offset, status ok/refused and reason), groundtruth.parquet (leg "
                "points at the sensor's height, metres, sensor clock)")),
    Verb("registration-summary", cmd_registration_summary,
         "registration.csv + report table",
         A("inputs", nargs="+", metavar="REGISTRATION_JSON",
           help="registration.json files "
                "(results/<study>/register/<family>/<trial>/registration.json)"),
         A("--study", required=True, help="study id (named in the caption)"),
         A("--out-csv", required=True,
           help="one row per trial (results/<study>/registration.csv)"),
         A("--out-stem", required=True,
           help="the report table's path without suffix "
                "(reports/<run>/tables/study_registration_<study>; writes .csv, .md, "
                ".tex)"),
         REPORTS_ARG,
         HASH_ARG),
    Verb("track", cmd_track,
         "run one tracker method on one LRS trial",
         SCAN_LOG_ARG,
         SHEET_ARG,
         SUBJECTS_ARG,
         TRIAL_ARG,
         A("--method", required=True,
           help="the method's name: a built-in (e.g. tug_m1, tug_m2, tug_m3, people) "
                "or one of tracking.methods"),
         A("--config", required=True, metavar="JSON",
           help="the method's config view "
                "(results/<study>/config_views/tug/<method>.json) or "
                "results/<study>/config.json: tracking.methods and tracking.overrides; "
                "registration.default_leg_width_m for a subject without leg_width_m"),
         A("--detections",
           help="the trial's observations by this method's detector (gaitval detect: "
                "results/<study>/detect/tug/<detector>/<trial>.parquet), used instead "
                "of detecting again (default: none, the step detects)"),
         A("--out", required=True,
           help="the per-scan track, Parquet, sensor frame and clock, metres "
                "(results/<study>/track/<method>/<trial>.parquet)")),
    Verb("detect", cmd_detect,
         "one TUG trial's leg observations by one detector, for every method with that "
         "detector",
         SCAN_LOG_ARG,
         SHEET_ARG,
         SUBJECTS_ARG,
         TRIAL_ARG,
         A("--detector", required=True,
           help='the detector spec as JSON, e.g. \'{"name": "leg_patterns", '
                '"use_fs_u": true}\''),
         A("--config", required=True, metavar="JSON",
           help="a config (view) JSON (results/<study>/config_views/tug/study.json): "
                "registration.default_leg_width_m for a subject without leg_width_m"),
         A("--out", required=True,
           help="the observation table, Parquet "
                "(results/<study>/detect/tug/<detector>/<trial>.parquet)")),
    Verb("evaluate-tug", cmd_evaluate_tug,
         "evaluate one tracked TUG trial against its mocap legs: per-frame errors, "
         "false tracking (swaps, lost legs), stance identification (Yorozu et al. "
         "2015a Tables 3-5)",
         A("--track", required=True,
           help="the trial's per-scan track "
                "(results/<study>/track/<method>/<trial>.parquet: gaitval's own, or an "
                "external method's from 'gaitval import-tracks'; sensor frame and "
                "clock)"),
         A("--groundtruth", required=True,
           help="the trial's groundtruth.parquet "
                "(results/<study>/register/tug/<trial>/): mocap legs at the laser's "
                "height, on the sensor clock"),
         A("--registration", required=True,
           help="the trial's registration.json (results/<study>/register/tug/<trial>/; "
                "a refused registration: the trial is counted as not registered)"),
         A("--trial", required=True, help="trial id (named in errors and outputs)"),
         LABEL_METHOD_ARG,
         A("--config", required=True,
           help="the method's config view "
                "(results/<study>/config_views/tug/<method>.json): its evaluation.tug "
                "thresholds and tug: section"),
         A("--out", required=True,
           help="folder (results/<study>/evaluate/<method>/<trial>): frames.parquet, "
                "events.parquet, stance.parquet, summary.parquet")),
    Verb("export-tracks", cmd_export_tracks,
         "one of gaitval's track files (or a bag's people topic) in the leg-track "
         "exchange format (*.tracks.csv / .parquet); an ultrasonic UKF track as a heel "
         "trajectory (*.foot.csv / .parquet)",
         A("track",
           help="results/<study>/track/<method>/<trial>.parquet, a ROS bag with a "
                "tracker's people topic, or an ultrasonic track "
                "results/<study>/ultrasonic/track/<trial>.parquet"),
         A("out",
           help="*.tracks.csv or *.tracks.parquet (leg tracks); *.foot.csv or "
                "*.foot.parquet (a heel trajectory, from an ultrasonic track)"),
         A("--units", choices=["m", "mm"], default="m",
           help="the file's position unit (header units:; default m)"),
         A("--topic",
           help="bags: the leg_tracker/PersonArray or people_msgs/People topic "
                "(default: the only one)"),
         A("--legs",
           help="bags whose people are legs: the person ids of the left and right leg, "
                "e.g. L=1,R=2 (a PoseArray: the poses' indices)")),
    Verb("leg-detections", cmd_leg_detections,
         "a detector's leg detections (leg_tracker/LegArray or a *.detections.csv; no "
         "identity or side) of one trial scored against its mocap legs: detection rate "
         "per leg, RMSE, false detections per scan (docs/formats.md, Leg detections)",
         A("--detections", required=True,
           help="a ROS 1 bag or ROS 2 bag folder with the detections and the laser's "
                "scans (the same frame), or a *.detections.csv / *.detections.parquet"),
         A("--topic",
           help="a bag's LegArray topic (default: the only one, e.g. "
                "/detected_leg_clusters)"),
         A("--groundtruth", required=True,
           help="the trial's groundtruth.parquet "
                "(results/<study>/register/<family>/<trial>/), on the sensor clock"),
         A("--registration",
           help="the trial's registration.json: converts a file on the mocap clock or "
                "in the mocap frame"),
         A("--sensor",
           help="the trial's ingested sensor.parquet: time stamps outside the "
                "recording and positions in the wrong units are refused"),
         A("--trial", help="trial id (named in errors)"),
         A("--method", help="the detector's name (written into summary.json)"),
         A("--protocol", help="the trial's protocol (written into summary.json)"),
         A("--gate-m", type=float, default=0.3,
           help="a detection farther than this from a leg is not that leg's (default "
                "0.30 m)"),
         A("--out", required=True,
           help="folder (results/<study>/leg_detections/<detector>/<trial>): "
                "per_scan.parquet, summary.json"),
         A("--moving-sensor", action="store_true",
           help="the laser moves (rollator trials): refuse detections in the mocap "
                "frame (the laser's pose changes every frame)")),
    Verb("leg-detections-table", cmd_leg_detections_table,
         "the detection table of external leg detectors: per method and protocol, "
         "detection rate, RMSE, false detections per scan, pooled over the trials' "
         "leg-detections folders",
         A("dirs", nargs="+",
           help="leg-detections output folders (one per trial: summary.json, "
                "per_scan.parquet)"),
         A("--out-stem", required=True,
           help="e.g. reports/<run>/tables/detections_table (writes .csv, .md, .tex)"),
         A("--reports-dir", required=True, help="the report folder (provenance/)"),
         A("--config-hash", default="", help="provenance stamp")),
    Verb("import-tracks", cmd_import_tracks,
         "an external tracker's *.tracks.csv/parquet of one trial as gaitval's track "
         "(sensor clock and frame)",
         A("--tracks", required=True,
           help="*.tracks.csv or *.tracks.parquet, or a ROS bag with a tracker's topic "
                "(--config names topic and legs)"),
         A("--sensor", required=True,
           help="the trial's ingested sensor.parquet (results/<study>/ingest/<trial>/; "
                "its time span)"),
         A("--registration",
           help="the trial's registration.json (pose and clock offset, for a file in "
                "the mocap frame or clock; none: a trial without mocap, the file must "
                "be on the sensor clock in the sensor frame)"),
         A("--trial", required=True, help="trial id (named in errors)"),
         A("--method", required=True, help="the external method's name"),
         A("--config",
           help="the method's config view "
                "(results/<study>/config_views/<family>/<method>.json): "
                "tracking.external.<method> gives a bag's topic and legs"),
         A("--moving-sensor", action="store_true",
           help="the laser moves (rollator): refuse tracks in the mocap frame"),
         A("--out", required=True,
           help="the per-scan track (Parquet; in the workflow "
                "results/<study>/track/<method>/<trial>.parquet, for MTST "
                "mtst_track/<method>/<trial>.parquet, for the rollator "
                "rollator/<method>/<trial>.track.parquet)")),
    Verb("tug-tables", cmd_tug_tables,
         "Yorozu et al. 2015a Tables 2-5 and figures",
         A("inputs", nargs="+", metavar="EVAL_DIR",
           help="per-(trial, method) evaluation folders of evaluate-tug "
                "(results/<study>/evaluate/<method>/<trial>)"),
         A("--methods", nargs="+", default=["tug_m1", "tug_m2", "tug_m3"],
           help="the methods, in table order (default: tug_m1 tug_m2 tug_m3)"),
         TABLES_ARG,
         FIGURES_ARG,
         REPORTS_ARG,
         HASH_ARG,
         A("--configs", nargs="+",
           help="each study's config.json or its method views "
                "(config_views/tug/<method>.json) for Table 2; default: the "
                "config.json above each evaluation folder")),
)

LEGBENCH = (
    Verb("legbench-track", cmd_legbench_track,
         "track an annotated recording (bag or scan log, no mocap) with one method",
         A("--sensor", required=True,
           help="ROS 1 *.bag, ROS 2 bag folder or *.scan.parquet (the trial sheet's "
                "sensor_file)"),
         A("--scan-topic", help="the bag's LaserScan topic (default: the only one)"),
         A("--method", required=True,
           help="the method's name: a built-in (e.g. tug_m1, tug_m2, tug_m3) or one of "
                "tracking.methods (legbench.methods)"),
         A("--init", choices=["own", "annotation"], default="own",
           help="own: the method's initialiser; annotation: the first annotation "
                "(default: own)"),
         A("--annotations",
           help="bag with the annotation topic, or *.positions.csv (read by --init "
                "annotation)"),
         A("--annotation-topic",
           help="the bag's annotation topic, e.g. /ground_truth_people_tracks "
                "(default: the only one; docs/formats.md, Annotated person positions)"),
         A("--leg-width-m", type=float, default=0.1,
           help="the subject's shank width (subjects.csv leg_width_m; m, default 0.10)"),
         A("--config",
           help="a config (view) JSON "
                "(results/<study>/config_views/all/<method>.json): tracking.methods "
                "and tracking.overrides (default: the built-in method as it is)"),
         A("--trial",
           help="trial id, named in errors and the track (default: the sensor file's "
                "name)"),
         A("--out", required=True,
           help="the per-scan track, Parquet, sensor frame and clock, metres "
                "(results/<study>/legbench/<method>/<init>/<trial>/track.parquet)")),
    Verb("legbench-evaluate", cmd_legbench_evaluate,
         "CLEAR-MOT (0.75 m) and false leg tracks of a legbench track",
         A("--track", required=True,
           help="the track of legbench-track "
                "(results/<study>/legbench/<method>/<init>/<trial>/track.parquet)"),
         A("--annotations", required=True,
           help="bag with the annotation topic, or *.positions.csv"),
         A("--annotation-topic",
           help="the bag's annotation topic, e.g. /ground_truth_people_tracks "
                "(default: the only one; docs/formats.md, Annotated person positions)"),
         A("--scan-topic",
           help="the bag's LaserScan topic (default: the only one): the scan times the "
                "annotations are matched to"),
         A("--match-m", type=float, default=0.75,
           help="a tracked person (midpoint of its two legs) matches an annotated one "
                "within this distance (m; default 0.75, the leg_tracker benchmark's)"),
         A("--min-false-s", type=float, default=0.5,
           help="a leg estimate with no annotated person within --match-m for at least "
                "this long is a false leg track (s; default 0.5)"),
         A("--sector-deg", nargs=2, type=float, metavar=["LO", "HI"],
           help="score only what lies at bearings LO..HI degrees (the general tracking "
                "sets: -80 12; default: the whole scan)"),
         A("--benchmark-set", default="",
           help="the published set the recording belongs to (e.g. following_outdoor): "
                "its published rows stand beside gaitval's (default: none)"),
         A("--trial", help="trial id (default: the one in the track)"),
         A("--out", required=True,
           help="folder (results/<study>/legbench_eval/<method>/<init>/<trial>): "
                "summary.parquet, frames.parquet")),
    Verb("legbench-tables", cmd_legbench_tables,
         "CLEAR-MOT table and figure of legbench runs",
         A("inputs", nargs="+", metavar="EVAL_DIR",
           help="legbench-evaluate output folders "
                "(results/<study>/legbench_eval/<method>/<init>/<trial>)"),
         A("--methods", nargs="+",
           help="the methods, in table order (default: the inputs' order)"),
         A("--inits", nargs="+",
           help="the initialisations, in table order (default: the inputs' order)"),
         A("--views-dir",
           help="folder of the method config views the tracks ran with (names a method "
                "run with tracking.overrides with its changes; "
                "results/<study>/config_views/all)"),
         A("--tables-dir", required=True,
           help="folder the table goes to (legbench_clearmot.csv, .md, ...; "
                "reports/<run>/tables)"),
         A("--figures-dir", required=True,
           help="folder the figure goes to (legbench_tracks.png; "
                "reports/<run>/figures)"),
         REPORTS_ARG,
         HASH_ARG),
    Verb("legbench-crowd", cmd_legbench_crowd,
         "the multi-person benchmark on rendered scenes (docs/crowd.md)",
         A("--tables-dir", required=True,
           help="folder the tables go to (legbench_crowd.csv, .md, .tex, "
                "legbench_crowd_scenes.csv)"),
         A("--split", choices=("dev", "test", "all"), default="all",
           help="the development scenes, the test scenes or both (default: all)")),
)
