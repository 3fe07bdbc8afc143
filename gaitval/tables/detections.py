"""The detection table: external leg *detectors* scored per scan against the mocap legs.

A detector's output (leg_tracker's ``/detected_leg_clusters``, ``leg_tracker/LegArray``, or
a ``*.detections.csv``; docs/formats_external.md, *Leg detections*) has no identity and no side, so
it is no track and gets no row in the protocol tables (TUG Tables 3–5, MTST Tables 3–4,
rollator Tables I–II score tracks: success, swaps, a leg's RMSE).  This table scores it as
what it is (:func:`gaitval.evaluate.leg_detections.detection_statistics`, run per trial by
``gaitval leg-detections``): per method and protocol, pooled over the trials of the studies
run, the fraction of scored scans in which each leg was detected, the matched detections'
RMSE and the unmatched detections per scan.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.parquet import read_parquet
from gaitval.tables.render import write_table

COLUMNS = ("method", "protocol", "n_trials", "n_not_registered", "n_scans",
           "left_detection_rate", "right_detection_rate", "detection_rate", "rmse_x_m",
           "rmse_y_m", "rmse_m", "false_per_scan", "gate_m")


def detections_table(dirs) -> pd.DataFrame:
    """One row per (method, protocol) from the trials' ``leg-detections`` folders
    (``summary.json`` with ``method`` and ``protocol``, ``per_scan.parquet``), pooled over
    trials scan by scan: ``left_detection_rate``, ``right_detection_rate`` the fraction
    of scored scans with the leg detected, ``detection_rate`` both legs' together;
    ``rmse_x_m``, ``rmse_y_m``, ``rmse_m`` (Euclidean) over every matched detection;
    ``false_per_scan`` unmatched detections per scored scan; ``gate_m`` the matching gate."""
    parts = []
    for d in map(Path, dirs):
        try:
            s = json.loads((d / "summary.json").read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise FileFormatError(f"cannot read the leg-detections summary ({exc})",
                                  path=d / "summary.json") from None
        ps = read_parquet(d / "per_scan.parquet")
        if not len(ps):          # a trial without a registration: counted, not scored
            ps = pd.DataFrame({"trial": [s.get("trial", d.name)], "side": [None],
                               "detected": [np.nan]})
        parts.append(ps.assign(method=s.get("method", d.parent.name),
                               protocol=s.get("protocol", ""), trial=s.get("trial", d.name),
                               gate_m=float(s["gate_m"])))
    if not parts:
        return pd.DataFrame(columns=list(COLUMNS))
    df = pd.concat(parts, ignore_index=True)
    rows = []
    for (m, p), g in df.groupby(["method", "protocol"], sort=True):
        scored = g[g["side"].notna()]
        hit = scored[scored["detected"].astype(bool)]
        scans = scored.drop_duplicates(["trial", "t_sensor_s"])
        rmse = (lambda v: float(np.sqrt(np.mean(v))) if len(hit) else np.nan)
        rows.append({
            "method": m, "protocol": p, "n_trials": int(g["trial"].nunique()),
            "n_not_registered": int(g["trial"].nunique() - scored["trial"].nunique()),
            "n_scans": int(len(scans)),
            **{f"{w}_detection_rate": float(scored.loc[scored["side"] == s_, "detected"]
                                            .astype(float).mean())
               for w, s_ in (("left", "L"), ("right", "R"))},
            "detection_rate": float(scored["detected"].astype(float).mean()),
            "rmse_x_m": rmse(hit["dx_m"] ** 2), "rmse_y_m": rmse(hit["dy_m"] ** 2),
            "rmse_m": rmse(hit["dx_m"] ** 2 + hit["dy_m"] ** 2),
            "false_per_scan": float(scans["n_false"].mean()),
            "gate_m": float(g["gate_m"].iloc[0])})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def write_detections_table(dirs, out_stem) -> list[Path]:
    """:func:`detections_table` as ``<out_stem>.csv/.md/.tex``."""
    table = detections_table(dirs)
    gate = table["gate_m"].iloc[0] if len(table) else 0.30
    caption = ("External leg detectors (external_detections: of the studies' study.yaml "
               "or external.yaml): per scan, the detections matched one-to-one to the "
               "two mocap legs at the laser's height; per method and protocol, pooled over "
               "the trials run.")
    notes = [
        "Detections have no identity and no side (leg_tracker/LegArray, "
        "/detected_leg_clusters, or a *.detections.csv): they are a tracker's input, not "
        "tracks, so a detector gets no row in the tracking tables (TUG Tables 3-5, MTST "
        "Tables 3-4, rollator Tables I-II); gaitval does not pair them into left/right "
        "tracks, which would charge a tracker's mistakes to the detector.",
        "A scan is scored when the detector reported at a ground-truth scan time (within "
        "1 µs, sensor clock) with both legs known; detections are matched to the legs by "
        f"minimum summed distance (scipy linear_sum_assignment), none farther than "
        f"{gate * 1000:.0f} mm (the TUG evaluation's lost_m).",
        "left_/right_detection: per cent of the scored scans in which the leg was detected "
        "(100 - it is the miss rate, hidden and missed legs alike); detection: both legs; "
        "n_not_registered: trials whose registration was refused (no mocap legs in the "
        "laser's frame to score against); rmse_*: matched detection - leg centre, laser "
        "frame; false_per_scan: unmatched detections per scored scan (other objects, a "
        "leg's second cluster, a leg beyond the gate).",
        "No published value: the seed papers report no detector of this kind; no row on "
        "the verdict page."]
    return write_table(table, out_stem, caption=caption, notes=notes)
