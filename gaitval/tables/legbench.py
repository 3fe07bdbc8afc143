"""The CLEAR-MOT table of annotated recordings (docs/legbench.md).

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

from gaitval.tables._published_leigh2015 import BENCHMARK_SETS, SOURCE, TABLE3
from gaitval.tables.render import write_table

__all__ = ["BENCHMARK_SETS", "benchmark_table", "legbench_table", "write_legbench_table"]

COLUMNS = ["trial", "method", "init", "mota", "motp_m", "idsw", "idsw_ref", "idf1", "gt",
           "fn", "fp", "mota_following", "sector_deg",
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


BENCH_COLUMNS = ["benchmark_set", "tracker", "source", "online", "annotations", "matched",
                 "matched_pct", "misses", "idsw", "idsw_ref", "fp", "mota_pct",
                 "mota_pct_motmetrics", "motp_m"]


def benchmark_table(summary: pd.DataFrame, methods=None, inits=None, offline=()
                    ) -> pd.DataFrame:
    """The published rows of each benchmark set beside gaitval's, counted the way the
    set's authors count (spec ``leg-tracker-benchmark.md``).

    Per set: the paper's trackers (matched, ID switches, misses, FP, MOTA, MOTP), then
    every gaitval (method, init) summed over the set's recordings.  Following sets ignore
    false positives (``fp`` empty; MOTA = 1 − (misses + IDSW)/annotations); general sets
    count them.  ``annotations`` of a published row is its own matched + IDSW + misses
    (the paper's counts do not add up to the released bags' annotations), so
    ``matched_pct`` compares rates.  ``matched`` is the benchmark's "valid": matched pairs
    less the reference script's ID switches (matched + ``idsw_ref`` + misses =
    annotations).  ``idsw`` is py-motmetrics' count (a person matched to another
    hypothesis), ``idsw_ref`` the reference script's (also a hypothesis matched to another
    person); published rows have only the reference count.  ``offline``: the methods that
    read scans recorded after the one they report (column ``online`` "no").
    """
    rows = []
    sets = [b for b in BENCHMARK_SETS if "benchmark_set" in summary.columns
            and (summary["benchmark_set"] == b).any()]
    for b in sets:
        following = BENCHMARK_SETS[b]["mode"] == "following"
        for name, matched, idsw, misses, fp, mota, motp in TABLE3[b]:
            n = matched + idsw + misses
            rows.append({"benchmark_set": b, "tracker": name, "source": SOURCE,
                         "online": "yes", "annotations": n, "matched": matched,
                         "matched_pct": 100.0 * matched / n, "misses": misses,
                         "idsw": np.nan, "idsw_ref": idsw,
                         "fp": np.nan if fp is None else fp,
                         "mota_pct": np.nan if mota is None else mota,
                         "mota_pct_motmetrics": np.nan, "motp_m": motp})
        t = legbench_table(summary[summary["benchmark_set"] == b], methods, inits)
        t = t.assign(benchmark_set=b)
        extra = summary[summary["benchmark_set"] == b].set_index(["trial", "method", "init"])
        for (m, i), g in t.groupby(["method", "init"], sort=False):
            ex = extra.loc[[(tr, m, i) for tr in g["trial"]]]
            gt = int(g["gt"].sum())
            pairs = ex["matches"] + ex["idsw"]          # MOTP averages over every pair
            matched = int(ex["matched_ref"].sum())      # the benchmark's "valid"
            fn, sw, fp = int(g["fn"].sum()), int(g["idsw"].sum()), int(g["fp"].sum())
            sw_ref = int(g["idsw_ref"].sum())
            d = (ex["motp_m"].fillna(0.0) * pairs).sum()
            rows.append({"benchmark_set": b, "tracker": f"gaitval {m} ({i} init)",
                         "source": "reproduced",
                         "online": "no (reads later scans)" if m in offline else "yes",
                         "annotations": gt, "matched": matched,
                         "matched_pct": 100.0 * matched / gt if gt else np.nan,
                         "misses": fn, "idsw": sw, "idsw_ref": sw_ref,
                         "fp": np.nan if following else fp,
                         # MOTA from the reference script's ID switches, as the
                         # published rows count them; py-motmetrics' count beside it
                         "mota_pct": (100.0 * (1 - (fn + sw_ref + (0 if following else fp))
                                               / gt) if gt else np.nan),
                         "mota_pct_motmetrics": (100.0 * (1 - (fn + sw + (0 if following
                                                                          else fp)) / gt)
                                                 if gt else np.nan),
                         "motp_m": float(d / pairs.sum()) if pairs.sum() else np.nan})
    out = pd.DataFrame(rows, columns=BENCH_COLUMNS)
    for c in ("idsw", "fp"):            # counts, empty where a row has none (not 0.000)
        out[c] = ["" if pd.isna(v) else int(v) for v in out[c]]
        out[c] = out[c].astype(object)
    return out


def _bench_notes(b: pd.DataFrame) -> list[str]:
    notes = ["Counted as the benchmark's authors count (Leigh et al. ICRA 2015 §V-C and "
             "their clear_mot.py): per person, a match needs < 0.75 m; on the following "
             "sets only the followed person is annotated, so false positives are ignored "
             "and MOTA = 1 − (misses + IDSW) / annotations; the general sets count false "
             "positives and score bearings −80°…+12° only.",
             "annotations of a published row = its matched + ID switches + misses (on the "
             "outdoor set 7,728 / 6,288 / 6,198 against the released bag's 6,179 "
             "annotations): compare matched_pct as well as counts.",
             "idsw: py-motmetrics (a person matched to a new hypothesis); idsw_ref: the "
             "reference script's count (also a hypothesis matched to a new person) — the "
             "count the published rows use. mota_pct uses the reference count, as the "
             "published rows do; mota_pct_motmetrics the py-motmetrics count."]
    if (b["online"] != "yes").any():
        notes.append("online: does the tracker report a scan from that scan and the ones "
                     "before it (as a robot must, and as the published trackers do)? An "
                     "offline gaitval method (such as people_offline) also reads the "
                     "recording backwards: its rows are not comparable with the published "
                     "ones.")
    for bset, g in b.groupby("benchmark_set", sort=False):
        pub = g[g["source"] != "reproduced"]
        if pub.empty:
            continue
        best = pub.loc[pub["matched_pct"].idxmax()]
        for online, what in (("yes", "online"), ("no", "offline")):
            ours = g[(g["source"] == "reproduced") & g["online"].str.startswith(online)]
            if ours.empty:
                continue
            r = ours.loc[ours["matched_pct"].idxmax()]
            motp = f"{r['motp_m']:.3f} m" if np.isfinite(r["motp_m"]) else "no match"
            line = (f"{bset}: gaitval's best {what}, {r['tracker']}, matched {r['matched']} "
                    f"of {r['annotations']} ({r['matched_pct']:.1f} %), {r['idsw_ref']} ID "
                    f"switches (reference count), MOTP {motp}")
            if online == "yes":
                line += (f"; {best['tracker']}: {best['matched_pct']:.1f} %, "
                         f"{int(best['idsw_ref'])}, {best['motp_m']:.2f} m.")
            else:
                line += " (offline: not comparable with the published online trackers)."
            notes.append(line)
    return notes


def write_legbench_table(summary: pd.DataFrame, stem, methods=None, inits=None,
                         offline=()) -> list[Path]:
    """Write ``<stem>.csv/.md/.tex`` and, when a recording belongs to a published
    benchmark set, ``legbench_benchmark.*`` beside it."""
    t = legbench_table(summary, methods, inits)
    b = benchmark_table(summary, methods, inits, offline)
    extra = []
    if not len(b):                      # no published set any more: no stale table left
        for suffix in (".csv", ".md", ".tex"):
            Path(stem).with_name("legbench_benchmark" + suffix).unlink(missing_ok=True)
    else:
        extra = write_table(
            b, Path(stem).with_name("legbench_benchmark"),
            caption="The leg_tracker benchmark (Leigh et al. ICRA 2015, Table III): its "
                    "published trackers beside gaitval's, counted by the authors' rules per "
                    "set (following sets: false positives ignored).",
            notes=_bench_notes(b))
    return extra + write_table(
        t, stem,
        caption="CLEAR-MOT of gaitval's leg trackers on hand-annotated laser recordings "
                "without motion capture (py-motmetrics, 0.75 m), with false leg tracks per "
                "minute; own = the method's initialiser, annotation = started from the "
                "first annotated position.",
        notes=_notes(t, summary))
