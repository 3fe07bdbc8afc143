"""Verbs of the ultrasonic foot tracking study (seed 003) and of other systems' heel
trajectories on its treadmill trials."""
from __future__ import annotations

import json

from gaitval.cli.table import (TRIAL, FIGURES_ARG, HASH_ARG, REPORTS_ARG, SHEET_ARG,
                               SUBJECTS_ARG, TABLES_ARG, TRIAL_ARG, A, Verb)


def cmd_ultrasonic_noise(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import ultrasonic_noise_step
    n = ultrasonic_noise_step(a.ingest, a.trials, a.config, a.out, a.table_stem,
                              a.reports_dir, a.config_hash)
    print(json.dumps(n, sort_keys=True))
    return 0


def cmd_ultrasonic_track(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import ultrasonic_track_step
    ultrasonic_track_step(a.ingest, a.trial, a.config, a.noise, a.out)
    return 0


def cmd_gait_parameters(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import gait_parameters_step
    gait_parameters_step(a.track, a.ingest, a.sheet, a.subjects, a.trial, a.config, a.out)
    return 0


def cmd_ultrasonic_tables(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import ultrasonic_tables_step
    ultrasonic_tables_step(a.inputs, a.tables_dir, a.figures_dir, a.reports_dir,
                           a.config_hash, config_json=a.config)
    return 0


def cmd_external_gait_parameters(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import external_gait_parameters_step
    gp = external_gait_parameters_step(a.foot, a.ingest, a.sheet, a.subjects, a.trial,
                                       a.method, a.config, a.out)
    print(f"{a.trial}: {gp['stride'].nunique()} strides matched")
    return 0


def cmd_method_agreement(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import method_agreement_step
    method_agreement_step(a.gait, a.out_stem, a.reports_dir, a.config_hash, a.config)
    return 0


VERBS = (
    Verb("ultrasonic-noise", cmd_ultrasonic_noise,
         "V and W from pendulum trials; Table 1",
         A("--ingest", nargs="+", required=True, metavar="DIR",
           help="pendulum ingest folders (results/<study>/ingest/<trial>: the "
                "ultrasonic log sensor.parquet and mocap.parquet)"),
         A("--trials", nargs="+", required=True, metavar="TRIAL",
           help="their trial ids, same order"),
         A("--config", required=True, metavar="JSON",
           help="a config (view) JSON "
                "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic: "
                "section"),
         A("--out", required=True,
           help="noise.json: V per anchor, W, bias, RMSE "
                "(results/runs/<run>/ultrasonic_noise.json)"),
         A("--table-stem", required=True,
           help="Table 1's path without suffix "
                "(reports/<run>/tables/ultrasonic_table1; writes .csv, .md, .tex)"),
         REPORTS_ARG,
         HASH_ARG),
    Verb("ultrasonic-track", cmd_ultrasonic_track,
         "UKF track of one ultrasonic trial",
         A("--ingest", required=True, metavar="DIR",
           help="the treadmill trial's ingest folder (results/<study>/ingest/<trial>: "
                "the ultrasonic log sensor.parquet)"),
         TRIAL_ARG,
         A("--config", required=True, metavar="JSON",
           help="a config (view) JSON "
                "(results/<study>/config_views/ultrasonic/study.json): ultrasonic.ukf, "
                "ultrasonic.use_identified_W"),
         A("--noise", required=True,
           help="noise.json of ultrasonic-noise "
                "(results/runs/<run>/ultrasonic_noise.json): the identified V"),
         A("--out", required=True,
           help="the UKF track, Parquet "
                "(results/<study>/ultrasonic/track/<trial>.parquet)")),
    Verb("gait-parameters", cmd_gait_parameters,
         "per-stride parameters, reference vs system",
         A("--track", required=True,
           help="the trial's UKF track of ultrasonic-track "
                "(results/<study>/ultrasonic/track/<trial>.parquet)"),
         A("--ingest", required=True, metavar="DIR",
           help="the trial's ingest folder (results/<study>/ingest/<trial>: "
                "sensor.parquet for the anchors, mocap.parquet for the reference)"),
         SHEET_ARG,
         SUBJECTS_ARG,
         TRIAL_ARG,
         A("--config", required=True, metavar="JSON",
           help="a config (view) JSON "
                "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic: "
                "section"),
         A("--out", required=True,
           help="one row per stride, reference and system (Qi et al. 2014 eq. 16-22), "
                "Parquet (results/<study>/ultrasonic/gait/<trial>.parquet)")),
    Verb("ultrasonic-tables", cmd_ultrasonic_tables,
         "Qi et al. 2014 Tables 2-8, C1 and figures",
         A("inputs", nargs="+", metavar="GAIT_PARQUET",
           help="per-trial gait parameter files of gait-parameters "
                "(results/<study>/ultrasonic/gait/<trial>.parquet)"),
         TABLES_ARG,
         FIGURES_ARG,
         REPORTS_ARG,
         HASH_ARG,
         A("--config",
           help="config (view) JSON: ultrasonic.tables, the strides the tables use "
                "(default: the paper's 10 per subject)")),
    Verb("external-gait-parameters", cmd_external_gait_parameters,
         "per-stride gait parameters of another system's heel trajectory "
         "(*.foot.csv/parquet) on one treadmill trial, against the camera reference "
         "(docs/formats.md, Foot trajectories)",
         A("--foot", required=True,
           help="the system's *.foot.csv or *.foot.parquet of this trial (t_s, x, y, "
                "z; header units, frame, clock)"),
         A("--ingest", required=True,
           help="the trial's ingest folder (results/<study>/ingest/<trial>/: "
                "sensor.parquet with the anchors, mocap.parquet)"),
         A("--sheet", required=True, help="the study's trials.csv"),
         A("--subjects", required=True, help="the study's subjects.csv"),
         A("--trial", required=True, help="trial id (a treadmill trial)"),
         A("--method", required=True, help="the system's name (the rows' method)"),
         A("--config", required=True,
           help="the study's config view "
                "(results/<study>/config_views/ultrasonic/study.json): its ultrasonic "
                "section (markers, resampling, low-pass, strides)"),
         A("--out", required=True,
           help="the gait parameter table (Parquet; "
                "results/<study>/ultrasonic_external/<method>/<trial>.parquet)")),
    Verb("method-agreement", cmd_method_agreement,
         "agreement (Bland-Altman, ICC, repeated measures) of each foot-tracking "
         "system with the camera reference on the treadmill trials, one block of rows "
         "per system",
         A("--gait", action="append", nargs="+", required=True, metavar="METHOD_OR_FILE",
           help="a system's name followed by its gait parameter files (gait-parameters "
                "/ external-gait-parameters output); once per system"),
         A("--out-stem", required=True,
           help="e.g. reports/<run>/tables/ultrasonic_agreement_methods (writes .csv, "
                ".md, .tex)"),
         A("--config",
           help="a config view JSON: ultrasonic.tables chooses the strides (default: "
                "10 per subject and speed, seed 2014)"),
         A("--reports-dir", default="reports", help="the report folder (provenance/)"),
         A("--config-hash", default="", help="provenance stamp")),
)
