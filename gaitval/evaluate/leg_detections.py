"""Leg *detections* (no identity, no side) scored against the mocap legs (issue 37).

leg_tracker's ``/detected_leg_clusters`` (``leg_tracker/LegArray``) lists, per scan, the
positions of the clusters its classifier took for legs.  They are not tracks: nothing says
which detection is the left leg, or that a detection is the same leg as one in the
previous scan.  gaitval does not pair them into left and right tracks — that pairing would
be a tracker (gaitval's, not the external system's), and its errors would be charged to
the detector — so they enter none of the protocol tables (which score tracks: success,
identity swaps, RMSE of a leg's track).  They are scored as what they are, a detector's
output, scan by scan (docs/formats_external.md, *Leg detections*):

* each scan with a detection message and both mocap legs known (``valid``) is matched
  one-to-one, detections to the two legs, minimising the summed distance
  (:func:`scipy.optimize.linear_sum_assignment`), a pair farther than ``gate_m`` not
  matched (default 0.30 m, the TUG evaluation's ``lost_m``);
* per leg: the fraction of such scans in which it was detected (its *detection rate*;
  1 − it is the detector's miss rate, which includes the leg being hidden — the laser
  does not see it — and the classifier missing a visible leg: without the scan's own
  cluster the two cannot be told apart);
* the matched detections' RMSE in x and y (sensor frame) — a detection's position error
  against the leg's centre at the laser's height;
* unmatched detections per scan (false detections: another object, the other leg's
  second cluster, or a leg farther than the gate).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

#: gate of a detection to a leg (m): the TUG evaluation's lost_m (gaitval/evaluate/tug.py)
GATE_M = 0.30
#: a message stamp within this of a truth scan time is that scan (s; a bag's integer
#: seconds and nanoseconds)
MATCH_S = 1e-6
SIDES = ("L", "R")


def detection_statistics(detections: pd.DataFrame, t_messages, truth: pd.DataFrame,
                         gate_m: float = GATE_M) -> tuple[pd.DataFrame, dict]:
    """Score leg detections against the mocap legs, scan by scan.

    Parameters
    ----------
    detections : DataFrame
        ``t_s, msg, x_m, y_m`` (sensor clock, laser frame, metres;
        :func:`gaitval.io.tracks.bag.read_bag_leg_detections`).
    t_messages : sequence of float
        Every detection message's stamp (sensor clock), with legs or without.
    truth : DataFrame
        The registration step's ground truth ``t_sensor_s, side, xs_m, ys_m, valid``.
    gate_m : float
        A detection farther than this from a leg is not that leg's.

    Returns
    -------
    (DataFrame, dict)
        Per scored scan and leg: ``t_sensor_s, side, detected, dx_m, dy_m`` (detection −
        leg; NaN when not detected), and ``n_false`` per scan repeated on both legs' rows;
        and a summary: ``n_messages``, ``n_scans`` (scored: a message at a truth scan time
        with both legs valid), ``detection_rate_L``, ``detection_rate_R``,
        ``rmse_x_m``, ``rmse_y_m`` (matched detections), ``false_per_scan``, ``gate_m``.
    """
    t_msg = np.unique(np.asarray(t_messages, float))
    tr = truth[truth["valid"].to_numpy(bool)]
    tr = tr[np.isfinite(tr["xs_m"].to_numpy(float)) & np.isfinite(tr["ys_m"].to_numpy(float))]
    per_t = {t: g.set_index("side") for t, g in tr.groupby("t_sensor_s")}
    times = np.array(sorted(t for t, g in per_t.items() if set(SIDES) <= set(g.index)))
    det_by_t = {t: g for t, g in detections.groupby("t_s")}
    det_t = np.array(sorted(det_by_t))
    rows = []
    for tm in t_msg:
        if not len(times):
            break
        j = int(np.clip(np.searchsorted(times, tm), 0, len(times) - 1))
        cand = [k for k in (j - 1, j) if 0 <= k < len(times)]
        k = min(cand, key=lambda k: abs(times[k] - tm))
        if abs(times[k] - tm) > MATCH_S:
            continue                  # no truth scan at this message's time: not scored
        legs = per_t[times[k]].loc[list(SIDES), ["xs_m", "ys_m"]].to_numpy(float)
        d = np.empty((0, 2))
        if len(det_t):
            i = int(np.clip(np.searchsorted(det_t, tm), 0, len(det_t) - 1))
            near = [q for q in (i - 1, i) if 0 <= q < len(det_t)]
            q = min(near, key=lambda q: abs(det_t[q] - tm))
            if abs(det_t[q] - tm) <= MATCH_S:
                d = det_by_t[det_t[q]][["x_m", "y_m"]].to_numpy(float)
        matched = {}
        if len(d):
            cost = np.hypot(legs[:, None, 0] - d[None, :, 0], legs[:, None, 1] - d[None, :, 1])
            big = gate_m * 1e3 + 1.0
            r, c = linear_sum_assignment(np.where(cost <= gate_m, cost, big))
            matched = {int(a): int(b) for a, b in zip(r, c) if cost[a, b] <= gate_m}
        n_false = len(d) - len(matched)
        for a, side in enumerate(SIDES):
            b = matched.get(a)
            dx = d[b, 0] - legs[a, 0] if b is not None else np.nan
            dy = d[b, 1] - legs[a, 1] if b is not None else np.nan
            rows.append((float(times[k]), side, b is not None, dx, dy, n_false))
    per_scan = pd.DataFrame(rows, columns=["t_sensor_s", "side", "detected", "dx_m", "dy_m",
                                           "n_false"])
    n = len(per_scan) // 2
    hit = per_scan[per_scan["detected"]]
    summary = {
        "n_messages": int(len(t_msg)), "n_scans": int(n), "gate_m": float(gate_m),
        **{f"detection_rate_{s}": (float(per_scan.loc[per_scan["side"] == s, "detected"]
                                         .mean()) if n else None) for s in SIDES},
        "rmse_x_m": float(np.sqrt(np.mean(hit["dx_m"] ** 2))) if len(hit) else None,
        "rmse_y_m": float(np.sqrt(np.mean(hit["dy_m"] ** 2))) if len(hit) else None,
        "false_per_scan": (float(per_scan["n_false"].iloc[::2].mean()) if n else None),
    }
    return per_scan, summary
