"""The crowd benchmark: every scene tracked by each people method, scored as the
leg_tracker benchmark scores its general-tracking bags (docs/crowd.md).

Scoring (:mod:`gaitval.evaluate.clearmot`, the code that scores the real bags): each
reported person's legs' midpoint is a hypothesis; annotations and hypotheses outside the
bearing sector :data:`SECTOR_DEG` are left out; CLEAR-MOT at 0.75 m by py-motmetrics;
ID switches counted as the benchmark's ``clear_mot.py`` counts them (``idsw_ref``) and
false positives counted, so

    MOTA = 1 − (misses + FP + IDSW_ref) / GT,   matched = pairs − IDSW_ref

with py-motmetrics' own ID-switch count and MOTA beside (``idsw``,
``mota_pct_motmetrics``), as in the real bags' benchmark table.
"""
from __future__ import annotations

import time
from pathlib import Path

import pandas as pd

from gaitval.crowd.scenes import CHOICES, DEV_SEEDS, KINDS, TEST_SEEDS, make_scene

#: the rows of the table: leg_tracker's rules (with and without its leg classifier, whose
#: forest was trained on leg_tracker's real bags), then gaitval's online and offline trackers
METHODS = ("leg_tracker_rules", "leg_tracker_rules_no_classifier", "people", "people_offline")
#: the scored bearings: the sensor's front half-plane, where the scenes put people
SECTOR_DEG = (-90.0, 90.0)
MATCH_M = 0.75                  # leg_tracker benchmark, clear_mot.py
LEG_WIDTH_M = 0.11              # the mean shank width of the scenes (2 × 0.055 m)
SPLITS = {"dev": DEV_SEEDS, "test": TEST_SEEDS}


#: every method reads the sensor's motion from the scenes' odometry (the benchmark's moving
#: robot had its wheel odometry; scan matching along a corridor has nothing to hold on to)
ODOMETRY = {"kind__ego_motion": {"name": "odometry"}}


def tracker(method: str, overrides: dict | None = None):
    """A method's tracker on the scenes' odometry; ``leg_tracker_rules`` is
    :mod:`gaitval.crowd.baseline`'s."""
    from gaitval.methods import build_method, get_method, set_params
    over = {**ODOMETRY, **(overrides or {})}
    if method.startswith("leg_tracker_rules"):
        from gaitval.crowd.baseline import baseline_kind
        from gaitval.track.kinds import TRACKER_KINDS
        if method.endswith("_no_classifier"):
            over = {"kind__appearance": "none", **over}
        return TRACKER_KINDS.build(set_params({"kind": baseline_kind()}, over)["kind"])
    return build_method(get_method(method), over)


def hypotheses(res) -> pd.DataFrame:
    """A people result's person hypotheses (``k, hyp_id, x_m, y_m``), as legbench's."""
    from gaitval.track.people import people_frame_for_scoring, person_hypotheses
    return person_hypotheses(people_frame_for_scoring(res))


def score(truth: pd.DataFrame, hyp: pd.DataFrame, n_scans: int) -> dict:
    """The benchmark counts of person hypotheses against a scene's ground truth."""
    from gaitval.evaluate.clearmot import clear_mot, in_sector, reference_id_switches
    gt = truth[in_sector(truth["x_m"], truth["y_m"], SECTOR_DEG)].reset_index(drop=True)
    hyp = hyp[in_sector(hyp["x_m"], hyp["y_m"], SECTOR_DEG)].reset_index(drop=True)
    s, events = clear_mot(gt, hyp, n_scans, match_m=MATCH_M)
    ref = reference_id_switches(events)
    pairs = int(s["matches"]) + int(s["idsw"])
    n = int(s["gt"])
    bad = int(s["fn"]) + int(s["fp"]) + ref
    return {"gt": n, "matched": pairs - ref, "misses": int(s["fn"]), "fp": int(s["fp"]),
            "idsw_ref": ref, "idsw": int(s["idsw"]),
            "mota_pct": 100.0 * (1.0 - bad / n) if n else float("nan"),
            "mota_pct_motmetrics": 100.0 * s["mota"], "motp_m": s["motp_m"],
            "tracks": int(hyp["hyp_id"].nunique())}


def scenes(split: str = "all") -> list[tuple[str, str, int]]:
    """``(split, kind, seed)`` of the benchmark's scenes: ``dev``, ``test`` or ``all``."""
    names = list(SPLITS) if split == "all" else [split]
    return [(s, kind, seed) for s in names for seed in SPLITS[s] for kind in KINDS]


def run(split: str = "all", methods=METHODS, overrides: dict | None = None) -> pd.DataFrame:
    """One row per (scene, method): the counts of :func:`score` and the CPU seconds."""
    rows = []
    for sp, kind, seed in scenes(split):
        sc = make_scene(kind, seed)
        for m in methods:
            t0 = time.process_time()
            res = tracker(m, (overrides or {}).get(m)).track(sc.scans, LEG_WIDTH_M)
            row = {"split": sp, "kind": kind, "seed": seed, "method": m,
                   **score(sc.truth, hypotheses(res), sc.scans.n_scans),
                   "cpu_s": time.process_time() - t0}
            rows.append(row)
    return pd.DataFrame(rows)


def by_kind(rows: pd.DataFrame) -> pd.DataFrame:
    """Counts summed per (split, kind, method), MOTA and MOTP from the sums (the benchmark
    sums a set's bags before the metrics)."""
    cnt = ["gt", "matched", "misses", "fp", "idsw_ref", "idsw", "tracks"]
    pairs = rows["matched"] + rows["idsw_ref"]             # MOTP averages over every pair
    r = rows.assign(d=rows["motp_m"].fillna(0) * pairs, pairs=pairs)
    g = r.groupby(["split", "kind", "method"], sort=False)
    out = g[cnt + ["d", "pairs"]].sum().reset_index()
    miss_fp = out["misses"] + out["fp"]
    out["mota_pct"] = 100.0 * (1.0 - (miss_fp + out["idsw_ref"]) / out["gt"])
    out["mota_pct_motmetrics"] = 100.0 * (1.0 - (miss_fp + out["idsw"]) / out["gt"])
    out["motp_m"] = out["d"] / out["pairs"].where(out["pairs"] > 0)
    return out[["split", "kind", "method", *cnt, "mota_pct", "mota_pct_motmetrics",
                "motp_m"]]


def write_crowd_table(rows: pd.DataFrame, stem) -> list[Path]:
    from gaitval.tables.render import write_table
    t = by_kind(rows)
    free = "; ".join(f"{c.name} {c.lo:g}–{c.hi:g} {c.unit}" for c in CHOICES.values())
    return write_table(
        t, stem,
        caption="Multi-person laser scenes rendered by the twin (stationary and moving "
                "sensor, 2–8 walkers, furniture and clutter, a participant with a cane and "
                "an attendant), scored as the leg_tracker benchmark scores its general "
                f"sets: CLEAR-MOT at {MATCH_M} m inside bearings {SECTOR_DEG[0]:g}…"
                f"{SECTOR_DEG[1]:g}°, false positives counted, MOTA from the benchmark "
                "script's ID-switch count (py-motmetrics' count and MOTA "
                "beside). leg_tracker_rules: leg_tracker's confirmation, classifier and "
                "deletion on gaitval's sensing (_no_classifier: without its classifier); "
                "every method reads the scenes' odometry; people_offline reads later "
                "scans.",
        notes=[f"dev seeds {', '.join(map(str, DEV_SEEDS))} (looked at while developing); "
               f"test seeds {', '.join(map(str, TEST_SEEDS))} (scored only).",
               f"free choices, drawn per scene: {free}."])


def crowd_step(tables_dir, split: str = "all") -> pd.DataFrame:
    """Run the benchmark and write ``legbench_crowd.*`` (by kind) and
    ``legbench_crowd_scenes.csv`` (per scene) to ``tables_dir``."""
    from gaitval.io.atomic import write_csv
    rows = run(split)
    # CPU seconds vary from run to run: the tables hold what the same seed reproduces
    rows = rows.drop(columns="cpu_s")
    write_csv(rows, Path(tables_dir) / "legbench_crowd_scenes.csv", float_format="%.6g")
    write_crowd_table(rows, Path(tables_dir) / "legbench_crowd")
    return rows
