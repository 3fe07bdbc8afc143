"""Verbs of the laser range sensor studies (seed 000's TUG and the shared steps): register,
track, detect, evaluate, the external trackers' and detectors' files, the TUG tables, and
the annotated recordings without mocap (legbench)."""
from __future__ import annotations

import json
import sys


def cmd_register(a) -> int:
    from gaitval.pipeline.steps.register import register_step
    rec = register_step(a.ingest, a.sheet, a.subjects, a.trial, a.config, a.out)
    print(json.dumps(rec, sort_keys=True, default=str))
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
