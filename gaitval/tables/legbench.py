"""The CLEAR-MOT table of annotated recordings (issue 18; docs/legbench.md).

One row per (trial, method, initialisation): MOTA, MOTP (m), ID switches, IDF1 and the
counts behind them (Bernardin & Stiefelhagen 2008, through py-motmetrics), at the
leg_tracker benchmark's 0.75 m match distance (Leigh et al., ICRA 2015), beside false leg
tracks per minute of recording (:mod:`gaitval.evaluate.clearmot`).  No published values
stand beside them: the benchmark paper scores multi-person trackers (every person in
view), gaitval's trackers follow one subject's two legs.  The notes quote every row's
MOTA/MOTP/IDF1 and the evidence for a poor start (where the tracker began relative to the
annotated person), all computed from the rows themselves.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.tables.render import write_table

COLUMNS = ["trial", "method", "init", "mota", "motp_m", "idsw", "idf1", "gt", "fn", "fp",
           "false_leg_tracks", "false_leg_tracks_per_min", "false_leg_time_s",
           "tracked_fraction", "k_init",
           "t_init_s", "init_offset_m", "annotations_in_window"]


def legbench_table(summary: pd.DataFrame, methods=None, inits=None) -> pd.DataFrame:
    """The table rows in method order (``methods``, else as given) then init order."""
    df = summary.copy()
    m_order = list(methods) if methods else list(dict.fromkeys(df["method"]))
    i_order = list(inits) if inits else list(dict.fromkeys(df["init"]))
    df["_m"] = df["method"].map({m: i for i, m in enumerate(m_order)}).fillna(len(m_order))
    df["_i"] = df["init"].map({m: i for i, m in enumerate(i_order)}).fillna(len(i_order))
    df = df.sort_values(["trial", "_m", "_i", "method", "init"], kind="stable")
    return df[COLUMNS].reset_index(drop=True)


def _notes(t: pd.DataFrame, summary: pd.DataFrame) -> list[str]:
    notes = []
    s0 = summary.iloc[0]
    notes.append(
        f"Every scan is a frame ({int(s0['n_scans'])} scans, {int(s0['annotated_scans'])} "
        f"annotated); a tracker's person is the midpoint of its two legs and matches the "
        f"annotated person within {s0['match_m']:g} m (Leigh et al. ICRA 2015). A person "
        "reported on a scan nobody is annotated on is a false positive (the benchmark's "
        "rule). MOTA = 1 - (FN + FP + IDSW) / GT; MOTP = mean matched distance (m).")
    notes.append(f"Annotation frame: {s0['annotation_frame']} "
                 f"(from the {s0['annotation_frame_source']}); no leg-level annotations, so "
                 "no leg-level CLEAR-MOT.")
    notes.append("False leg tracks: runs of at least 0.5 s in which a leg estimate has no "
                 "annotated person within the match distance, per minute of recording.")
    for r in t.itertuples(index=False):
        head = f"{r.method} ({r.init} init)"
        if r.k_init < 0:
            win = (f" (only {100 * r.annotations_in_window:.0f}% of the annotated positions "
                   "lie inside its fixed detection window, which is all its initialiser sees)"
                   if np.isfinite(r.annotations_in_window) else "")
            notes.append(f"{head}: no track: the initialiser found no subject{win}; MOTA "
                         f"{r.mota:.3f}, every annotation a miss.")
            continue
        motp = f"{r.motp_m:.3f} m" if np.isfinite(r.motp_m) else "- (no match)"
        line = (f"{head}: MOTA {r.mota:.3f}, MOTP {motp}, IDF1 {r.idf1:.3f}, "
                f"{r.idsw} ID switch(es), {r.false_leg_tracks_per_min:.2f} false leg "
                f"tracks/min; started at scan {r.k_init} ({r.t_init_s:.1f} s)")
        if np.isfinite(r.init_offset_m):
            line += f", {r.init_offset_m:.2f} m from the annotated person"
            if r.init_offset_m >= s0["match_m"]:
                line += " (not on the person: a background object or someone else)"
        else:
            line += " on a scan without an annotation"
        if np.isfinite(r.annotations_in_window):
            line += (f"; only {100 * r.annotations_in_window:.0f}% of the annotated "
                     "positions lie inside its fixed detection window")
        notes.append(line + ".")
    return notes


def write_legbench_table(summary: pd.DataFrame, stem, methods=None, inits=None
                         ) -> list[Path]:
    """Write ``<stem>.csv/.md/.tex``."""
    t = legbench_table(summary, methods, inits)
    return write_table(
        t, stem,
        caption="CLEAR-MOT of gaitval's leg trackers on hand-annotated laser recordings "
                "without motion capture (py-motmetrics, 0.75 m), with false leg tracks per "
                "minute; own = the method's initialiser, annotation = started from the "
                "first annotated position.",
        notes=_notes(t, summary), digits=3)
