"""Annotated recordings without mocap (issue 18): track, score with CLEAR-MOT, tabulate.

File-level steps behind the verbs ``gaitval legbench-track``, ``legbench-evaluate`` and
``legbench-tables`` (rules in ``workflow/rules/legbench.smk``; docs/legbench.md).  They
take file paths and topics, not a trial sheet, so the same two commands score a tracker
on anybody's annotated bag (README):

    gaitval legbench-track --sensor my.bag --scan-topic /scan --annotations my.bag \\
        --annotation-topic /ground_truth_people_tracks --method tug_m1 --init annotation \\
        --out track.parquet
    gaitval legbench-evaluate --track track.parquet --annotations my.bag \\
        --annotation-topic /ground_truth_people_tracks --scan-topic /scan --out eval/

Initialisation (``--init``)
    ``own``: the method's own initialiser (TUG ``closest_pair``, MTST ``mtst_participant``
    without a lane, rollator ``facing_pair``).  ``annotation``: ``annotated_pair``
    (:mod:`gaitval.track.init_annotated`) at the trial's first annotated scan — issue 18
    scope 2, "initialisation from the annotation at the first annotated time".  For a
    raw-scan tracker (``rollator_pf``) the override goes to ``kind__init``.
Scan rate
    Every scan is tracked at the recording's own rate (the MTST steps' 0.05 s resampling
    of seed 001 is not applied: the leg_tracker bags run at 10 Hz, slower than 20 Hz).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, GaitvalError
from gaitval.io.atomic import write_parquet
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.steps.config import (load_json, method_definition, method_display_names,
                                           method_overrides, offline_methods)

INITS = ("own", "annotation")
#: How many of the person's later clicks the annotation initialiser is given: at least its
#: ``search_scans`` (10), so every scan it searches has the click nearest in time.
ANNOTATION_PATH_LEN = 20
SUMMARY_FILE, FRAMES_FILE = "summary.parquet", "frames.parquet"


def read_scans(path, scan_topic: str | None, trial: str | None):
    """A ROS bag's LaserScan topic or a gaitval scan log."""
    from gaitval.io.rosbag import is_rosbag, read_rosbag_scans
    from gaitval.io.scanlog import read_scanlog
    if is_rosbag(path):
        return read_rosbag_scans(path, scan_topic, trial=trial)
    return read_scanlog(path, trial=trial)


def read_positions(path, annotation_topic: str | None, scan_topic: str | None,
                   scan_t: np.ndarray | None, trial: str | None) -> tuple[pd.DataFrame, dict]:
    """Annotated positions with their scan index ``k`` (bag topic or position CSV)."""
    from gaitval.evaluate.clearmot import assign_scans
    from gaitval.io.annotations_bag import read_bag_annotations, read_position_csv
    from gaitval.io.rosbag import is_rosbag
    if is_rosbag(path):
        return read_bag_annotations(path, annotation_topic, scan_topic, trial=trial)
    pos = read_position_csv(path, trial=trial)
    if scan_t is None:
        raise GaitvalError("a position CSV needs the scan times to find each annotation's "
                           "scan", path=path, trial=trial)
    return assign_scans(pos, scan_t), {"topic": "", "frame_source": "position CSV",
                                       "frame": ",".join(sorted(set(pos["frame"])))}


def with_init(method_def, init: str, positions: pd.DataFrame) -> dict:
    """The method definition with its initialiser chosen by ``init`` (module notes)."""
    from gaitval.methods import get_method
    m = get_method(method_def)
    if init == "own":
        return m
    if init != "annotation":
        raise ConfigError(f"unknown legbench init {init!r}", hint=f"one of {', '.join(INITS)}")
    if positions.empty:
        raise GaitvalError("init 'annotation' needs at least one annotated position")
    ordered = positions.sort_values(["k", "id"], kind="stable")
    first = ordered.iloc[0]
    # the same person's next clicks, for the scans searched after the first (init_annotated)
    later = ordered[(ordered["id"] == first["id"]) & (ordered["k"] > first["k"])].head(
        ANNOTATION_PATH_LEN)
    spec = {"name": "annotated_pair", "k": int(first["k"]), "x_m": float(first["x_m"]),
            "y_m": float(first["y_m"]),
            "path": [[int(r.k), float(r.x_m), float(r.y_m)] for r in later.itertuples()]}
    kind = m.get("kind")
    raw_scan = isinstance(kind, dict) and kind.get("name", "detect_then_track") != \
        "detect_then_track"
    holder = m["kind"] if raw_scan else m           # a raw-scan tracker's init is its own
    base = holder.get("init") if isinstance(holder.get("init"), dict) else {}
    holder["init"] = {**{k: base[k] for k in ("max_pair_m", "min_leg_widths") if k in base},
                      **spec}
    return m


def legbench_track_step(sensor, method: str, out_parquet, *, init: str = "own",
                        scan_topic: str | None = None, annotations=None,
                        annotation_topic: str | None = None, leg_width_m: float = 0.10,
                        config_json=None, trial: str | None = None) -> pd.DataFrame:
    """Track one annotated recording with one method and initialisation; write the
    per-scan two-leg track (:data:`gaitval.track.TRACK_COLUMNS`, sensor frame, sensor
    clock) with ``method``, ``init``, ``k_init`` and ``restarts`` in the Parquet metadata."""
    from gaitval.methods import build_method

    cfg = load_json(config_json) if config_json else {}
    trial = trial or Path(sensor).name
    scans = read_scans(sensor, scan_topic, trial)
    mdef = method_definition(cfg, method)
    overrides = method_overrides(cfg, method)
    if init == "annotation":
        if annotations is None:
            raise GaitvalError("init 'annotation' needs --annotations", trial=trial)
        positions, _ = read_positions(annotations, annotation_topic, scan_topic, scans.t,
                                      trial)
    else:
        positions = pd.DataFrame()
    try:
        res = build_method(with_init(mdef, init, positions), overrides).track(
            scans, float(leg_width_m))
    except GaitvalError as exc:
        raise exc.with_context(path=sensor, trial=trial) from None
    if getattr(res, "people", None) is not None:     # a people tracker: every person (issue 36)
        from gaitval.track.people import people_frame_for_scoring
        track = people_frame_for_scoring(res)
    else:
        track = res.to_frame()
    k_init = getattr(res, "k_init", None)
    if k_init is None or k_init < 0:
        print(f"gaitval: warning: trial {trial}, method {method} ({init} init): the "
              f"initialiser found nobody in {sensor}{f' ({scan_topic})' if scan_topic else ''}"
              "; the track is empty and every annotation will count as a miss",
              file=sys.stderr)
    meta = {"gaitval_legbench": json.dumps({
        "method": method, "init": init, "trial": trial,
        "k_init": None if k_init is None or k_init < 0 else int(k_init),
        "restarts": [int(k) for k in (getattr(res, "restarts", None) or [])],
        "source": str(scans.source), "leg_width_m": float(leg_width_m)}, sort_keys=True)}
    write_parquet(track, out_parquet, metadata=meta)
    return track


def read_track(path) -> tuple[pd.DataFrame, dict]:
    """A legbench track and its metadata."""
    import pyarrow.parquet as pq
    from gaitval.errors import FileFormatError
    try:
        table = pq.read_table(path)
        raw = (table.schema.metadata or {}).get(b"gaitval_legbench")
        if raw is None:
            raise FileFormatError("not a legbench track (no gaitval_legbench metadata)",
                                  path=path, hint="make it with `gaitval legbench-track`")
        return table.to_pandas(), json.loads(raw)
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"cannot read the track: {exc}", path=path) from None


def legbench_evaluate_step(track_parquet, annotations, out_dir, *,
                           annotation_topic: str | None = None, scan_topic: str | None = None,
                           match_m: float = 0.75, min_false_s: float = 0.5,
                           trial: str | None = None, sector_deg=None,
                           benchmark_set: str = "") -> pd.DataFrame:
    """CLEAR-MOT and false leg tracks of one track against the annotations.

    Writes ``summary.parquet`` (one row: the CLEAR-MOT counts and rates, the benchmark's
    following reading and reference ID switches, false leg tracks, the initial offset)
    and ``frames.parquet`` (per scan: annotated and tracked person, the event).

    ``sector_deg``: ``(lo, hi)`` bearings in degrees; annotations and person hypotheses
    outside are left out of the scoring (the general-tracking sets' −80°…+12°); None: the
    whole scan.  ``benchmark_set``: the published set of the recording
    (:data:`gaitval.tables.legbench.BENCHMARK_SETS`), or "".
    """
    from gaitval.evaluate.clearmot import (clear_mot, false_leg_tracks, following_counts,
                                           in_sector, person_hypotheses)

    track, meta = read_track(track_parquet)
    trial = trial or meta.get("trial")
    people = "person_id" in track.columns        # a people tracker's track (issue 36)
    persons = _person_legs(track) if people else None
    t, x, y = _scan_times_and_legs(track, people)
    n = len(t)
    positions, ameta = read_positions(annotations, annotation_topic, scan_topic, t, trial)
    if len(positions) and positions["k"].max() >= n:
        raise GaitvalError(f"annotations refer to scan {int(positions['k'].max())} but the "
                           f"track has {n} scans: not the same recording or scan topic",
                           path=annotations, trial=trial)
    if people:
        from gaitval.track.people import person_hypotheses as people_hypotheses
        hyp = people_hypotheses(track)
    else:
        hyp = person_hypotheses(x, y, meta.get("restarts") or [])
    if sector_deg is not None:
        positions, hyp = (d[in_sector(d["x_m"], d["y_m"], sector_deg)].reset_index(drop=True)
                          for d in (positions, hyp))
    summary, events = clear_mot(positions, hyp, n, match_m=match_m)
    follow = following_counts(summary, events)
    legs = (_people_false_legs(persons, t, positions, match_m, min_false_s) if people
            # every person's legs, summed (recording_min is the same for all)
            else false_leg_tracks(x, y, t, positions, match_m=match_m, min_false_s=min_false_s))
    row = {"trial": trial, "method": meta["method"], "init": meta["init"],
           **_init_offset(meta.get("k_init"), t, positions, hyp), **summary, **legs,
           "idsw_ref": follow["idsw_ref"], "matched_ref": follow["matched"],
           "mota_following": follow["mota_following"],
           "sector_deg": ("" if sector_deg is None
                          else f"{float(sector_deg[0]):g}..{float(sector_deg[1]):g}"),
           "benchmark_set": str(benchmark_set or ""),
           "tracked_fraction": float(len(hyp) / n) if n else float("nan"),
           "annotated_scans": int(positions["k"].nunique()), "n_scans": int(n),
           "annotations_in_window": _window_fraction(meta["method"], positions),
           "match_m": float(match_m), "annotation_frame": str(ameta.get("frame", "")),
           "annotation_frame_source": str(ameta.get("frame_source", ""))}
    out = Path(out_dir)
    summary_df = pd.DataFrame([row])
    write_parquet(summary_df, out / SUMMARY_FILE)
    write_parquet(_frames(t, positions, hyp, events), out / FRAMES_FILE)
    return summary_df


def _scan_times_and_legs(track: pd.DataFrame, people: bool):
    """Per scan its time and, for a two-leg track, the legs' x and y (2, n) (None for a
    people tracker's track, whose persons are read by :func:`_person_legs`)."""
    if people:
        return track.groupby("k", sort=True)["t_sensor_s"].first().to_numpy(float), None, None
    t = track.loc[track["side"] == "L", "t_sensor_s"].to_numpy(float)
    x = np.vstack([track.loc[track["side"] == s, "x_m"].to_numpy(float) for s in "LR"])
    y = np.vstack([track.loc[track["side"] == s, "y_m"].to_numpy(float) for s in "LR"])
    return t, x, y


def _init_offset(k0, t, positions, hyp) -> dict:
    """The scan the track started on, its time, and the started person's distance from
    the nearest annotation on that scan."""
    offset = float("nan")
    if k0 is not None:
        g = positions[positions["k"] == k0]
        h = hyp[hyp["k"] == k0]
        if len(g) and len(h):
            offset = float(np.min(np.hypot(g["x_m"].to_numpy() - h["x_m"].iloc[0],
                                           g["y_m"].to_numpy() - h["y_m"].iloc[0])))
    return {"k_init": -1 if k0 is None else int(k0),
            "t_init_s": float(t[k0] - t[0]) if k0 is not None else float("nan"),
            "init_offset_m": offset}


def _person_legs(track: pd.DataFrame) -> list:
    """``[(person_id, x (2, n), y (2, n))]`` of a people tracker's track (``person_id`` ≥ 0;
    NaN where the person is not reported)."""
    n = int(track["k"].max()) + 1 if len(track) else 0
    out = []
    for pid, g in track[track["person_id"] >= 0].groupby("person_id", sort=True):
        x, y = np.full((2, n), np.nan), np.full((2, n), np.nan)
        for f, side in enumerate("LR"):
            leg = g[g["side"] == side]
            x[f, leg["k"].to_numpy()] = leg["x_m"].to_numpy(float)
            y[f, leg["k"].to_numpy()] = leg["y_m"].to_numpy(float)
        out.append((int(pid), x, y))
    return out


def _people_false_legs(persons, t, positions, match_m, min_false_s) -> dict:
    """:func:`~gaitval.evaluate.clearmot.false_leg_tracks` summed over every person."""
    from gaitval.evaluate.clearmot import false_leg_tracks
    nan = np.full((2, len(t)), np.nan)
    total = false_leg_tracks(nan, nan, t, positions, match_m=match_m, min_false_s=min_false_s)
    for _, x, y in persons:
        r = false_leg_tracks(x, y, t, positions, match_m=match_m, min_false_s=min_false_s)
        for key in ("false_leg_tracks", "false_leg_time_s", "leg_time_s"):
            total[key] += r[key]
    m = total["recording_min"]
    total["false_leg_tracks_per_min"] = total["false_leg_tracks"] / m if m > 0 else float("nan")
    return total


def _window_fraction(method: str, positions: pd.DataFrame) -> float:
    """Fraction of the annotated positions inside the method's fixed detection window
    (seed 002's ``rollator_window``: the only detector that looks at part of the scan);
    NaN for a detector that sees the whole scan or a method gaitval does not know."""
    from gaitval.methods import METHODS
    m = METHODS.get(method) or {}
    det = m.get("detector")
    if det is None and isinstance(m.get("kind"), dict):
        det = m["kind"].get("detector")               # a raw-scan tracker's own detector
    if not isinstance(det, dict) or "window_x_m" not in det or positions.empty:
        return float("nan")
    (x0, x1), (y0, y1) = det["window_x_m"], det["window_y_m"]
    x, y = positions["x_m"].to_numpy(float), positions["y_m"].to_numpy(float)
    return float(np.mean((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)))


def _frames(t, positions, hyp, events) -> pd.DataFrame:
    """Per scan: the (first) annotated person, the person hypothesis, the event."""
    n = len(t)
    f = pd.DataFrame({"k": np.arange(n, dtype=np.int64), "t_s": t - t[0]})
    g = positions.drop_duplicates("k").set_index("k")
    f["gt_x_m"] = g["x_m"].reindex(f["k"]).to_numpy(float)
    f["gt_y_m"] = g["y_m"].reindex(f["k"]).to_numpy(float)
    h = hyp.drop_duplicates("k").set_index("k")
    f["hyp_x_m"] = h["x_m"].reindex(f["k"]).to_numpy(float)
    f["hyp_y_m"] = h["y_m"].reindex(f["k"]).to_numpy(float)
    f["hyp_id"] = h["hyp_id"].reindex(f["k"]).fillna(-1).astype(np.int64).to_numpy()
    order = {"SWITCH": 0, "MISS": 1, "FP": 2, "MATCH": 3}
    ev = events[events["type"].isin(list(order))].copy()
    ev["rank"] = ev["type"].map(order)
    first = ev.sort_values(["k", "rank"], kind="stable").drop_duplicates("k").set_index("k")
    f["event"] = first["type"].reindex(f["k"]).fillna("").astype(str).to_numpy()
    return f


def legbench_tables_step(inputs, tables_dir, figures_dir, reports_dir, config_hash: str = "",
                         *, methods=None, inits=None, views_dir=None) -> pd.DataFrame:
    """The CLEAR-MOT table and the figure of every evaluated (trial, method, init).

    ``views_dir``: the folder of the method config views the tracks ran with; a method run
    with ``tracking.overrides`` is then named with its changes in the tables
    (:func:`gaitval.pipeline.steps.config.method_display_names`)."""
    from gaitval.report.legbench_figures import write_legbench_figure
    from gaitval.report.provenance import stamp
    from gaitval.tables.legbench import write_legbench_table

    summaries, frames = [], {}
    for d in map(Path, inputs):
        s = read_parquet(d / SUMMARY_FILE)
        summaries.append(s)
        r = s.iloc[0]
        frames[(r["trial"], r["method"], r["init"])] = read_parquet(d / FRAMES_FILE)
    summary = pd.concat(summaries, ignore_index=True)
    offline = offline_methods(views_dir, list(dict.fromkeys(summary["method"])))
    if views_dir:
        shown = method_display_names(views_dir, list(dict.fromkeys(summary["method"])))
        if any(shown.get(m, m) != m for m in shown):
            summary["method"] = summary["method"].map(lambda m: shown.get(m, m))
            frames = {(t, shown.get(m, m), i): f for (t, m, i), f in frames.items()}
            methods = [shown.get(m, m) for m in methods] if methods else methods
            offline = {shown.get(m, m) for m in offline}
    paths = write_legbench_table(summary, Path(tables_dir) / "legbench_clearmot",
                                 methods=methods, inits=inits, offline=offline)
    fig = write_legbench_figure(frames, summary, Path(figures_dir) / "legbench_tracks.png",
                                methods=methods, inits=inits)
    stamp("legbench_tables", [*paths, fig], reports_dir, config_hash_=config_hash)
    return summary
