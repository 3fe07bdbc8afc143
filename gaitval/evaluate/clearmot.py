"""CLEAR-MOT of a person track against hand-annotated positions, and false leg tracks.

The leg_tracker benchmark's convention (Leigh et al., ICRA 2015; its ``clear_mot.py``):

* every scan is a frame; a frame's objects are the people annotated on that scan (none on
  an unannotated scan, so any hypothesis there is a false positive);
* a hypothesis matches an object within **0.75 m** (``match_m``; strictly closer, as the
  benchmark's ``dist < 0.75``);
* CLEAR-MOT (Bernardin & Stiefelhagen 2008): MOTA = 1 − (FN + FP + IDSW) / GT, MOTP = the
  mean distance of the matched pairs (metres here, since the distances given are
  Euclidean), plus IDF1 (Ristani et al. 2016).

The counting is py-motmetrics' (``MOTAccumulator`` per frame, ``metrics.create()``), not
gaitval's own; :func:`clear_mot` only builds the per-frame distance matrices.

A gaitval tracker follows one subject's two legs; its person hypothesis is the midpoint of
the two leg estimates (issue 18 scope 2) on every scan where both exist, with one
hypothesis id per run segment: a re-initialisation (``TrackResult.restarts``, e.g. seed
002's ``reinit_after_lost``) starts a new id, since the tracker may now follow someone or
something else.

False leg tracks (issue 18 scope 4): a leg estimate is *false* on a scan when it exists
and no annotated person is within ``match_m`` of it (a wall, a parked object, another
person, or a scan with nobody annotated).  A false leg track is a run of consecutive false
scans of one leg lasting at least ``min_false_s``; the rate is their number per minute of
recording (scan span + one period).  Leg-level CLEAR-MOT needs leg annotations, which the
leg_tracker bags do not have.

Benchmark scoring (Leigh et al. 2015, the leg_tracker benchmark's own scripts): besides full
CLEAR-MOT, :func:`following_counts` gives the *following* reading the benchmark's authors
use when only the followed person is annotated — false positives ignored, MOTA' = 1 −
(FN + IDSW) / GT — and :func:`reference_id_switches` counts ID switches as their
``clear_mot.py`` does: a matched pair counts when the hypothesis was last matched to
another person **or** the person was last matched to another hypothesis (py-motmetrics'
``num_switches`` counts only the second).  :func:`in_sector` keeps what lies in a bearing
sector (the general-tracking sets score −80°…+12° only).

References
----------
Bernardin, K.; Stiefelhagen, R. Evaluating multiple object tracking performance: the
CLEAR MOT metrics. EURASIP J. Image Video Process. 2008, 246309.
Ristani, E. et al. Performance measures and a data set for multi-target, multi-camera
tracking. ECCV Workshops 2016 (IDF1).
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (CLEAR-MOT at 0.75 m on annotated ROS bags).
Heindl, C. py-motmetrics. https://github.com/cheind/py-motmetrics
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError

MATCH_M = 0.75          # Leigh et al. ICRA 2015, clear_mot.py max_match_threshold
MIN_FALSE_S = 0.5       # a false leg estimate this long counts as a false leg track

#: motmetrics metric -> summary column
METRICS = {"num_frames": "n_frames", "num_objects": "gt", "num_predictions": "hyp",
           "num_matches": "matches", "num_misses": "fn", "num_false_positives": "fp",
           "num_switches": "idsw", "mota": "mota", "motp": "motp_m", "idf1": "idf1",
           "idp": "idp", "idr": "idr", "mostly_tracked": "mostly_tracked",
           "mostly_lost": "mostly_lost"}
HYP_COLUMNS = ["k", "hyp_id", "x_m", "y_m"]


def person_hypotheses(x: np.ndarray, y: np.ndarray, restarts=()) -> pd.DataFrame:
    """The person hypothesis of a two-leg track: the legs' midpoint (module notes).

    Parameters
    ----------
    x, y : ndarray (2, n_scans)
        Leg positions (row 0 left, row 1 right; NaN where there is no estimate).
    restarts : iterable of int
        Scans at which the tracker re-initialised (each starts a new hypothesis id).

    Returns
    -------
    DataFrame
        ``k, hyp_id, x_m, y_m``, one row per scan with both legs.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x).all(axis=0) & np.isfinite(y).all(axis=0)
    k = np.flatnonzero(ok)
    rs = np.sort(np.asarray(list(restarts), dtype=np.int64))
    hyp_id = 1 + np.searchsorted(rs, k, side="right")
    return pd.DataFrame({"k": k.astype(np.int64), "hyp_id": hyp_id.astype(np.int64),
                         "x_m": x[:, ok].mean(axis=0), "y_m": y[:, ok].mean(axis=0)})


def assign_scans(positions: pd.DataFrame, scan_t: np.ndarray,
                 tol_s: float | None = None) -> pd.DataFrame:
    """``k`` of annotations that lack one (a position CSV): the scan with the nearest stamp,
    within ``tol_s`` (default half the median scan period); others are dropped."""
    pos = positions.copy()
    need = pos["k"].to_numpy() < 0
    if not need.any():
        return pos
    t = np.asarray(scan_t, dtype=float)
    if tol_s is None:
        d = np.diff(t)
        tol_s = 0.5 * float(np.median(d[d > 0])) if np.any(d > 0) else 0.0
    q = pos.loc[need, "t_s"].to_numpy(dtype=float)
    j = np.clip(np.searchsorted(t, q), 1, len(t) - 1) if len(t) > 1 else np.zeros(len(q), int)
    if len(t) > 1:
        j = np.where(np.abs(t[j - 1] - q) <= np.abs(t[j] - q), j - 1, j)
    close = np.abs(t[j] - q) <= tol_s
    k = pos["k"].to_numpy().copy()
    k[np.flatnonzero(need)] = np.where(close, j, -1)
    pos["k"] = k
    return pos[pos["k"] >= 0].reset_index(drop=True)


def _distances(gt: np.ndarray, hy: np.ndarray, match_m: float) -> np.ndarray:
    d = np.hypot(gt[:, None, 0] - hy[None, :, 0], gt[:, None, 1] - hy[None, :, 1])
    d[~(d < match_m)] = np.nan                      # no match at or beyond match_m
    return d


def clear_mot(gt: pd.DataFrame, hyp: pd.DataFrame, n_frames: int,
              match_m: float = MATCH_M) -> tuple[dict, pd.DataFrame]:
    """CLEAR-MOT and IDF1 of hypotheses against annotations over frames 0..n_frames-1.

    Parameters
    ----------
    gt : DataFrame
        Annotations: ``k`` (frame), ``id``, ``x_m``, ``y_m``.
    hyp : DataFrame
        Hypotheses: ``k``, ``hyp_id``, ``x_m``, ``y_m`` (:func:`person_hypotheses`).
    n_frames : int
        Number of scans (every scan is a frame, module notes).
    match_m : float
        Match distance (m).

    Returns
    -------
    summary : dict
        :data:`METRICS` values (``mota``, ``motp_m``, ``idsw``, ``idf1``, counts).
    events : DataFrame
        motmetrics' events: ``k, type`` (MATCH, SWITCH, MISS, FP, ...), ``gt_id``,
        ``hyp_id``, ``d_m``.
    """
    import motmetrics as mm

    if n_frames < 1:
        raise GaitvalError("CLEAR-MOT needs at least one frame (scan)")
    for name, df in (("annotation", gt), ("hypothesis", hyp)):
        k = df["k"].to_numpy()
        if len(k) and (k.min() < 0 or k.max() >= n_frames):
            raise GaitvalError(f"{name} frame index outside 0..{n_frames - 1}")
    acc = mm.MOTAccumulator(auto_id=False)
    # motmetrics stores object ids as floats: number the annotation ids 0.. (sorted)
    names = sorted({str(v) for v in gt["id"]})
    code = {n: i for i, n in enumerate(names)}
    g_by = {k: g for k, g in gt.groupby("k", sort=True)}
    h_by = {k: h for k, h in hyp.groupby("k", sort=True)}
    empty_g = gt.iloc[:0]
    empty_h = hyp.iloc[:0]
    for k in range(n_frames):
        g = g_by.get(k, empty_g)
        h = h_by.get(k, empty_h)
        d = _distances(g[["x_m", "y_m"]].to_numpy(float).reshape(-1, 2),
                       h[["x_m", "y_m"]].to_numpy(float).reshape(-1, 2), match_m)
        acc.update([code[str(v)] for v in g["id"]], [int(v) for v in h["hyp_id"]], d,
                   frameid=k)
    mh = mm.metrics.create()
    res = mh.compute(acc, metrics=list(METRICS), name="run")
    summary = {METRICS[m]: _py(res[m].iloc[0]) for m in METRICS}
    ev = acc.mot_events.reset_index()
    events = pd.DataFrame({"k": ev["FrameId"].astype(np.int64),
                           "type": ev["Type"].astype(str),
                           "gt_id": ev["OId"].map(lambda v: "" if pd.isna(v) else names[int(v)]),
                           "hyp_id": ev["HId"].map(lambda v: -1 if pd.isna(v) else int(v)),
                           "d_m": ev["D"].astype(float)})
    return summary, events[events["type"] != "RAW"].reset_index(drop=True)


def _py(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating, float)):
        return float(v)
    return v


def false_leg_tracks(x: np.ndarray, y: np.ndarray, t: np.ndarray, gt: pd.DataFrame,
                     match_m: float = MATCH_M, min_false_s: float = MIN_FALSE_S) -> dict:
    """False leg tracks of a two-leg track (module notes).

    Parameters
    ----------
    x, y : ndarray (2, n_scans)
        Leg positions (NaN: no estimate).
    t : ndarray (n_scans,)
        Scan times (s).
    gt : DataFrame
        Annotations ``k, x_m, y_m``.

    Returns
    -------
    dict
        ``false_leg_tracks`` (count over both legs), ``false_leg_tracks_per_min``,
        ``false_leg_time_s`` (time of those tracks), ``leg_time_s`` (time with a leg
        estimate, both legs), ``recording_min``.
    """
    x, y, t = np.asarray(x, float), np.asarray(y, float), np.asarray(t, float)
    n = len(t)
    d = np.diff(t)
    period = float(np.median(d[d > 0])) if np.any(d > 0) else 0.0
    near = np.zeros((2, n), dtype=bool)
    for k, g in gt.groupby("k", sort=True):
        gx, gy = g["x_m"].to_numpy(float), g["y_m"].to_numpy(float)
        for f in (0, 1):
            if np.isfinite(x[f, k]) and np.isfinite(y[f, k]):
                near[f, k] = bool(np.any(np.hypot(gx - x[f, k], gy - y[f, k]) < match_m))
    count, false_s = 0, 0.0
    for f in (0, 1):
        false = np.isfinite(x[f]) & np.isfinite(y[f]) & ~near[f]
        edges = np.diff(np.concatenate([[0], false.astype(np.int8), [0]]))
        for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            dur = (b - a) * period
            if dur >= min_false_s - 1e-9:
                count += 1
                false_s += dur
    minutes = ((t[-1] - t[0]) + period) / 60.0 if n else 0.0
    leg_s = float((np.isfinite(x) & np.isfinite(y)).sum()) * period
    return {"false_leg_tracks": int(count),
            "false_leg_tracks_per_min": float(count / minutes) if minutes > 0 else float("nan"),
            "false_leg_time_s": float(false_s), "leg_time_s": leg_s,
            "recording_min": float(minutes)}


def in_sector(x, y, sector_deg) -> np.ndarray:
    """Per point: its bearing ``atan2(y, x)`` lies in ``[lo, hi]`` degrees (inclusive); all
    True when ``sector_deg`` is None."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if sector_deg is None:
        return np.ones(x.shape, dtype=bool)
    lo, hi = (float(v) for v in sector_deg)
    b = np.degrees(np.arctan2(y, x))
    return (b >= lo) & (b <= hi)


def reference_id_switches(events: pd.DataFrame) -> int:
    """ID switches as the benchmark's ``clear_mot.py`` counts them (module notes), over the
    matched pairs of :func:`clear_mot`'s events, in frame order."""
    pairs = events[events["type"].isin(["MATCH", "SWITCH"])].sort_values("k", kind="stable")
    last_hyp: dict = {}
    last_gt: dict = {}
    count = 0
    for g, h in zip(pairs["gt_id"], pairs["hyp_id"]):
        if (g in last_hyp and last_hyp[g] != h) or (h in last_gt and last_gt[h] != g):
            count += 1
        last_hyp[g], last_gt[h] = h, g
    return count


def following_counts(summary: dict, events: pd.DataFrame) -> dict:
    """The benchmark's *following* reading of a :func:`clear_mot` result (module notes).

    ``pairs``: matched (person, hypothesis) pairs, switches included; ``idsw``:
    py-motmetrics' switches; ``idsw_ref``: the reference script's; ``matched``: the
    benchmark's "valid" = pairs − ``idsw_ref`` (so matched + ``idsw_ref`` + misses = GT, as
    in its Table III); ``misses``; ``motp_m``; ``mota_following`` = 1 − (FN + IDSW) / GT
    with py-motmetrics' IDSW.  False positives are not counted."""
    gt = int(summary["gt"])
    idsw = int(summary["idsw"])
    fn = int(summary["fn"])
    pairs = int(summary["matches"]) + idsw
    ref = reference_id_switches(events)
    return {"pairs": pairs, "matched": pairs - ref, "misses": fn, "idsw": idsw,
            "idsw_ref": ref, "motp_m": summary["motp_m"],
            "mota_following": (1.0 - (fn + idsw) / gt) if gt else float("nan")}
