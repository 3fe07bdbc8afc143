"""Verbs of a study's inputs and of the report: inspect, validate, init-study, simulate,
ingest, ingest-summary, peer, sensitivity, report, compare-tables."""
from __future__ import annotations

import json
import logging
import re
import sys
from pathlib import Path


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
