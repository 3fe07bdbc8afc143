"""Verbs of a study's inputs and of the report: inspect, validate, init-study, simulate,
ingest, ingest-summary, peer, sensitivity, report, compare-tables."""
from __future__ import annotations

import argparse

import json
import logging
import re
import sys
from pathlib import Path

from gaitval.cli.table import (SHEET, HASH_ARG, REPORTS_ARG, SHEET_ARG, TRIAL_ARG, A, Verb)


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
        from gaitval.pipeline.steps.checks import external_problems, study_yaml_problems
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
    from gaitval.pipeline.steps.checks import external_problems
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
    from gaitval.pipeline.steps.trials import trial_row
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


def cmd_report(a) -> int:
    from gaitval.report.index import build_index
    if a.complete is not None:     # the workflow's report job: no index over a partial report
        from gaitval.jobs.resume import refuse_unfinished
        refuse_unfinished(a.reports_dir, own_outputs=a.complete)
    md, html = build_index(a.reports_dir, study_names=a.studies)
    print(f"wrote {md} and {html}")
    return 0


def cmd_sensitivity(a) -> int:
    from gaitval.tables.sensitivity import write_sensitivity
    for p in write_sensitivity(a.reports, a.out,
                               protocols=tuple(a.protocol) if a.protocol else None):
        print(p)
    return 0


def cmd_robustness(a) -> int:
    from gaitval.robustness.runner import robustness_step
    return robustness_step(a.step, a.config, a.out, a.reports_dir, a.workdir, a.snakemake)


def cmd_compare_tables(a) -> int:
    from gaitval.report.compare import run
    return run(a)


VERBS = (
    Verb("inspect", cmd_inspect,
         "show what gaitval's loaders see in a file",
         A("file",
           help="a *.c3d, a ROS 1 *.bag or ROS 2 bag folder, a *.scan.parquet, a "
                "*.us.parquet or a *.annotations.csv (docs/formats.md)"),
         A("--json", action="store_true",
           help="print the description as JSON instead of text"),
         A("--topic", help="LaserScan topic (ROS bags with several)")),
    Verb("validate", cmd_validate,
         "validate a trial sheet and its subject table",
         A("sheet", help=SHEET),
         A("--subjects", help="subject table (default: subjects.csv beside the sheet)"),
         A("--no-file-check", action="store_true",
           help="check the sheet's columns and values only, not the files it names "
                "(skips --deep and the study's external methods' files)"),
         A("--allow-outside-paths", action="store_true",
           help="accept paths outside the sheet's folder (default: as study.yaml says)"),
         A("--deep", action="store_true",
           help="also open every file with the loader the pipeline uses (C3D, scan log "
                "or bag topic, ultrasonic log, annotations) and report each that does "
                "not load or holds no data"),
         A("--jobs", type=int, help="processes for --deep (default: one per core)")),
    Verb("init-study", cmd_init_study,
         "trial sheet, subject table, study.yaml and a config snippet from a folder of "
         "recordings; then validate",
         A("folder",
           help="the study's folder: C3D files, scan logs or bags, ultrasonic logs, "
                "annotations, target layouts, external trackers' <trial>.tracks.csv "
                "(declared in the study.yaml; sub-folders too)"),
         A("--study", help="study id (default: the folder's name)"),
         A("--force", action="store_true",
           help="replace an existing trials.csv and subjects.csv"),
         A("--max-time-gap-s", type=float, default=300.0,
           help="pair a sensor file with a C3D of another name when the two were "
                "written at most this far apart (s; default 300)")),
    Verb("simulate", cmd_simulate,
         "generate a simulated study (raw files + truth/)",
         A("--preset", default="default",
           help="preset name in config/studies/ (default, tiny, replay, ...) or a YAML "
                "file (the workflow passes config/studies/<preset>.yaml; default: "
                "default)"),
         A("--seed", type=int,
           help="random seed, overrides the preset's seed (default: the preset's)"),
         A("--out", required=True, metavar="DIR",
           help="the study folder to write (data/<study>): trials.csv, subjects.csv, "
                "study.yaml, mocap/, lrs/, annotations/, ..., truth/")),
    Verb("ingest", cmd_ingest,
         "raw files of one trial -> tidy per-trial files",
         SHEET_ARG,
         A("--subjects", help="subject table (default: subjects.csv beside the sheet)"),
         TRIAL_ARG,
         A("--out", required=True, metavar="DIR",
           help="the trial's ingest folder (results/<study>/ingest/<trial>): "
                "mocap.parquet (metres, mocap clock), events.csv, sensor.parquet, "
                "annotations.csv, ingest.json")),
    Verb("ingest-summary", cmd_ingest_summary,
         "table of what was ingested",
         A("inputs", nargs="+", metavar="INGEST_JSON",
           help="ingest.json files (results/<study>/ingest/<trial>/ingest.json)"),
         A("--study", required=True, help="study id (named in the caption)"),
         A("--out-stem", required=True,
           help="the table's path without suffix "
                "(reports/<run>/tables/study_ingest_<study>; writes .csv, .md, .tex)"),
         REPORTS_ARG,
         HASH_ARG),
    Verb("peer", cmd_peer,
         "agreement statistics (Bland-Altman, ICC, RMSE, t-test) of any system's "
         "paired results against a reference: one row per walk or stride, us_<name> / "
         "gt_<name> column pairs (e.g. an external system's stride parameters against "
         "the mocap's)",
         A("parquet",
           help="Parquet or CSV file with us_<name> / gt_<name> column pairs (other "
                "prefixes: --system-prefix, --reference-prefix), one row per walk or "
                "stride"),
         A("--system-prefix", default="us_",
           help="the system's column prefix (default us_)"),
         A("--reference-prefix", default="gt_",
           help="the reference's column prefix (default gt_)"),
         A("--subject",
           help="the column naming each row's participant (default: the first of "
                "subject, participant, subject_id, participant_id); without one, no "
                "repeated-measures statistics"),
         A("--units", nargs="+", metavar="NAME=UNIT",
           help="each parameter's unit for the unit column, e.g. stride_length=m "
                "stride_time=s (default: the peer data's: cm, s, cm/s, steps/min)"),
         A("--name",
           help="the system's name: a study's own paired results "
                "(agreement_files.<name>) instead of the peer's worked example"),
         A("--out-stem", required=True,
           help="e.g. reports/<run>/tables/peer_agreement (writes .csv, .md, .tex)"),
         A("--reports-dir", default="reports", help="the report folder (provenance/)"),
         A("--config-hash", default="", help="provenance stamp")),
)

#: after every other verb in ``gaitval --help``
LAST = (
    Verb("robustness", cmd_robustness,
         "the robustness ensemble of the simulated replica (python3 run.py robustness; "
         "docs/simulator.md): design the twins, write the table, or run both with every "
         "twin's report between them",
         A("step", choices=["design", "table", "run"],
           help="design: the twins' presets, design.csv, ensemble.yaml; table: "
                "robustness.* from the twins' verdicts; run: both, the twins' reports "
                "built by the workflow between them"),
         A("--config", type=Path,
           help="the ensemble's configuration (default config/robustness.yaml)"),
         A("--out", type=Path, help="output folder of design and table"),
         A("--reports-dir", type=Path,
           help="the twins' report folders (table; default OUT/twins)"),
         A("--workdir", type=Path, default=Path("."),
           help="the checkout the run step works in (default: here)"),
         A("--snakemake", nargs=argparse.REMAINDER, default=[], metavar="ARG",
           help="last: everything after it goes to each twin's Snakemake run (run)")),
    Verb("sensitivity", cmd_sensitivity,
         "the verdicts of a report beside the same verdicts under the simulated "
         "replica's alternative free choices, and which flip (docs/simulator.md)",
         A("reports", nargs="+", type=Path,
           help="report folders; the first is the reference"),
         A("--out", type=Path, required=True, help="output stem (.csv, .md, .tex)"),
         A("--protocol", action="append",
           help="keep only these verdict groups (e.g. mtst); repeatable")),
    Verb("report", cmd_report,
         "write reports/<run>/index.md, index.html and the verdict table from the "
         "report folder's tables and figures",
         A("--reports-dir", default="reports", metavar="DIR",
           help="the report folder (reports/<run>: tables/, figures/, provenance/); "
                "writes index.md, index.html, verdicts.csv/.md/.tex there (default: "
                "reports)"),
         A("--studies", nargs="*", default=[], metavar="STUDY",
           help="the run's study ids (default: 'run' of "
                "<reports-dir>/provenance/config.yaml)"),
         A("--complete", nargs="*", metavar="OUTPUT",
           help="refuse (exit 1) while a table or figure a step's provenance lists is "
                "missing or a file of the report is marked unfinished by an "
                "interrupted Snakemake job; OUTPUT: the calling job's own outputs")),
    Verb("compare-tables", cmd_compare_tables,
         "two report folders' tables within a stated tolerance (docs/numerics.md)",
         A("a", type=Path, metavar="A",
           help="a report folder, e.g. reports/default (its tables/*.csv and "
                "verdicts.csv), or its tables/ folder"),
         A("b", type=Path, metavar="B", help="the report folder to compare it with"),
         A("--rtol", type=float, default=1e-09,
           help="relative tolerance of numbers (default 1e-9)"),
         A("--atol", type=float, default=0.0,
           help="absolute tolerance of numbers, in the column's unit (default 0)"),
         A("--strict-digits", action="store_true",
           help="a difference of one unit in the last printed digit fails too"),
         A("--ignore", action="append", default=[], metavar="GLOB",
           help="relative paths to leave out, e.g. 'tables/sensitivity.csv' "
                "(repeatable)")),
)
