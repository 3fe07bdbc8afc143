"""Automatic evaluation of TUG leg tracking against mocap ground truth (seed 000 §6).

Everything is computed from the tracker output (:func:`gaitval.methods.track_trial`) and
the ground truth at sensor height in the sensor frame (a DataFrame with ``t_sensor_s,
side, xs_m, ys_m, valid``, from the registration/ground-truth step); no manual inspection.
This module judges the tracker (false tracking, stance matching, the trial summary); what
the truth alone gives — thresholds, alignment, TUG phases, truth stance intervals — is in
:mod:`gaitval.evaluate.tug_truth`, whose public names are re-exported here.

Rules (all thresholds in :data:`DEFAULTS`, overridable by the ``cfg`` argument)
--------------------------------------------------------------------------------
Alignment
    The truth of each side is linearly interpolated to the scan times; a scan is *valid*
    when both neighbouring truth samples are valid and it is inside the truth's time span.
TUG phases (forward / turning / return)
    From the truth midpoint m(t) of both legs (positions smoothed over
    ``smooth_s`` = 0.5 s, about one step, so the left–right sway averages out): the
    farthest point from the start position splits out from back; the straight heading
    h = unit(m_far − m_start).  *Turning* is the interval around the farthest point where
    the walking heading (direction of the smoothed midpoint velocity, only where the
    midpoint moves faster than ``heading_min_speed_mps`` = 0.2 m/s) differs by more than
    ``turn_angle_deg`` = 30° from h (before) and from −h (after): it starts at the last
    such in-line sample before the farthest point and ends at the first one after it.
    Before: *forward* (including rising from the chair); after: *return* (including
    sitting down), as in seed 000 Figure 3a.
False tracking
    A scan is *bad* for leg f if its track is farther than ``lost_m`` = 0.30 m from the
    leg's truth, or closer to the other leg's truth by more than ``swap_margin_m`` = 0.05 m
    while ``swap_min_m`` = 0.10 m from its own.  A run of ≥ ``min_bad_s`` = 0.20 s (8 scans
    at 40 Hz) of bad scans is an event, of kind

    * ``swap`` — most of its scans are closer to the other leg's truth (seed 000 Fig. 11a,b:
      "false tracking via switching of the left and right legs");
    * ``lost`` — far from its own leg while taking observations in at least half of its
      scans: the track follows something that is not its leg;
    * ``drift`` — far from its own leg while mostly unobservable (UO), never more than
      ``drift_max_m`` = 1.0 m (about a stride) away: the prediction ran off during an
      occlusion (seed 000 Fig. 13a).  This is a measurement-accuracy error (it enters
      Table 5's unobservable RMSE and may cause a stance failure), not false tracking, and
      is not counted as such.  A prediction that runs off farther has lost its leg
      (``lost``) even if it later finds it again.

    Its TUG phase is the phase at its first scan; its duration is its number of scans
    over the scan rate.  Brief crossings (the legs pass each other every step) stay below
    these limits.
Two judging rules, reported side by side (issue 34; neither is picked by its outcome)
    * **paper** (primary): every ``swap`` and ``lost`` event above is false tracking — the
      paper's "tracking both legs without false tracking" with gaitval's event rule.
    * **persistent swap**: a ``swap`` counts only when it lasts longer than
      ``persistent_swap_s`` = 0.5 s; shorter swaps that recover are forgiven (what a
      rater who watches the tracked legs, not every scan, would likely not call a switch).
      ``lost`` events count as under the paper rule; stance failures are unchanged.
    The summary carries each rule's verdict: the paper rule's columns without suffix,
    the persistent-swap rule's with ``_persistent_swap``.
Stance-phase identification
    Ground-truth stance: the truth leg speed (central differences of the 0.05 s-smoothed
    track) is below ``stance_speed_mps`` = 0.70 m/s (between the tracker's thresholds
    v_st_th = 0.47 and v_sw_th = 0.93) for ≥ ``min_stance_s`` = 0.10 s.  A truth stance
    interval within the tracked, valid time is *identified* if the tracker reports that
    leg in stance (not swinging) for ≥ ``min_stance_scans`` = 2 consecutive scans inside
    it — enough for a foot-contact position, which is what the stance phase is needed for.
    Otherwise it is a stance-phase identification failure, placed in the TUG phase of its
    midpoint.
Tracking success (seed 000 §6.2)
    "tracking both legs without false tracking and identifying the stance phase
    correctly": no false-tracking event and no stance failure.  Each failed trial gets
    one category, the false tracking if there is one (else the stance failure), in the TUG
    phase of the first such event — the paper's Table 3 counts add up this way
    (e.g. Method 1: 12 + 2 failures = 28 − 14 successes).
RMSE, occlusion rate
    Over the valid scans of both legs (leg-steps, as the paper's time steps: Table 4's
    counts are about twice the scans of a 7-s TUG); occlusion = the UO pattern (no
    observation associated; Catmull–Rom steps are UO too).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import GaitvalError
from gaitval.evaluate.tug_truth import (DEFAULTS, TRUTH_COLUMNS, TUG_PHASES, _cfg, _rate,
                                        _runs, align_truth, truth_stance_intervals,
                                        tug_phase_bounds, tug_phase_of)

__all__ = ["DEFAULTS", "FRAME_COLUMNS", "JUDGING_RULES", "SUMMARY_COLUMNS", "TRUTH_COLUMNS", "TUG_PHASES",
           "align_truth", "evaluate_tug_trial", "false_tracking", "judged_false",
           "stance_failures",
           "truth_phases_of", "truth_stance_intervals", "tug_phase_bounds", "tug_phase_of"]

FRAME_COLUMNS = (C.TRIAL, C.METHOD, "k", C.T_SENSOR, C.SIDE, C.X, C.Y, C.XS, C.YS,
                 C.VALID, "err_x_m", "err_y_m", "observed", "interpolated", "pattern",
                 "phase", "swing", "tug_phase", "bad")
#: Columns of the summary row of :func:`evaluate_tug_trial`.
SUMMARY_COLUMNS = (C.TRIAL, C.METHOD, "n_scans", "n_leg_steps", "n_uo", "false_tracking",
                   "ft_phase", "n_ft_events", "n_drift_events", "stance_failure",
                   "sf_phase", "n_stance_true", "n_stance_failures", "success", "category",
                   "t_turn_start_s", "t_turn_end_s", "false_tracking_persistent_swap",
                   "ft_phase_persistent_swap", "n_ft_events_persistent_swap",
                   "success_persistent_swap", "category_persistent_swap")
#: The judging rules of false tracking (module notes), primary first, and the suffix of
#: each one's summary columns.
JUDGING_RULES = {"paper": "", "persistent_swap": "_persistent_swap"}


def judged_false(events: pd.DataFrame, rule: str = "paper", cfg: dict | None = None
                 ) -> pd.DataFrame:
    """The events of :func:`false_tracking` that are false tracking under ``rule``.

    ``"paper"``: every ``swap`` and ``lost`` event.  ``"persistent_swap"``: ``lost``
    events and the ``swap`` events longer than ``persistent_swap_s`` (module notes).
    """
    if rule not in JUDGING_RULES:
        raise GaitvalError(f"unknown judging rule {rule!r}; known: {', '.join(JUDGING_RULES)}")
    ft = events[events["kind"].isin(["swap", "lost"])]
    if rule == "persistent_swap":
        keep = (ft["kind"] != "swap") | (ft["duration_s"] > _cfg(cfg)["persistent_swap_s"])
        ft = ft[keep]
    return ft


def false_tracking(frames: pd.DataFrame, cfg: dict | None = None
                   ) -> tuple[np.ndarray, pd.DataFrame]:
    """Per-row bad flags and the false-tracking events (rule in the module notes).

    Parameters
    ----------
    frames : DataFrame
        :func:`align_truth` output with ``tug_phase`` (rows per scan and side).

    Returns
    -------
    bad : ndarray of bool, aligned with ``frames`` rows
    events : DataFrame
        ``side, kind (swap|lost|drift), k_start, k_end, t_start_s, t_end_s, duration_s,
        tug_phase, max_error_m``.
    """
    c = _cfg(cfg)
    bad = np.zeros(len(frames), bool)
    rows = []
    f = frames.reset_index(drop=True)
    side = f[C.SIDE].astype(str).to_numpy()
    t_all = f[C.T_SENSOR].to_numpy(float)
    rate = _rate(np.unique(t_all)) if len(t_all) > 1 else 40.0
    min_n = max(1, int(math.ceil(c["min_bad_s"] * rate - 1e-9)))
    idx = {s: np.flatnonzero(side == s) for s in C.SIDES}
    if len(idx["L"]) != len(idx["R"]):
        raise GaitvalError("track has a different number of rows for L and R")
    for s, o in (("L", "R"), ("R", "L")):
        a, b = idx[s], idx[o]
        x, y = f[C.X].to_numpy(float)[a], f[C.Y].to_numpy(float)[a]
        e_own = np.hypot(x - f[C.XS].to_numpy(float)[a], y - f[C.YS].to_numpy(float)[a])
        e_oth = np.hypot(x - f[C.XS].to_numpy(float)[b], y - f[C.YS].to_numpy(float)[b])
        ok = f[C.VALID].to_numpy(bool)[a] & f[C.VALID].to_numpy(bool)[b]
        observed = (f["observed"].to_numpy(bool)[a] if "observed" in f
                    else np.ones(len(a), bool))
        closer_other = (e_oth + c["swap_margin_m"] < e_own) & (e_own > c["swap_min_m"])
        b_s = ok & ((e_own > c["lost_m"]) | closer_other)
        for i0, i1 in _runs(b_s):
            if i1 - i0 < min_n:
                continue
            bad[a[i0:i1]] = True
            if closer_other[i0:i1].mean() > 0.5:
                kind = "swap"
            elif observed[i0:i1].mean() >= 0.5 or np.nanmax(e_own[i0:i1]) > c["drift_max_m"]:
                kind = "lost"
            else:
                kind = "drift"
            rows.append({C.SIDE: s, "kind": kind,
                         "k_start": int(f["k"].iloc[a[i0]]), "k_end": int(f["k"].iloc[a[i1 - 1]]),
                         "t_start_s": float(t_all[a[i0]]), "t_end_s": float(t_all[a[i1 - 1]]),
                         "duration_s": (i1 - i0) / rate,
                         "tug_phase": str(f["tug_phase"].iloc[a[i0]]),
                         "max_error_m": float(np.nanmax(e_own[i0:i1]))})
    ev = pd.DataFrame(rows, columns=[C.SIDE, "kind", "k_start", "k_end", "t_start_s",
                                     "t_end_s", "duration_s", "tug_phase", "max_error_m"])
    return bad, ev.sort_values(["t_start_s", C.SIDE], kind="stable").reset_index(drop=True)


def stance_failures(frames: pd.DataFrame, stance: pd.DataFrame, cfg: dict | None = None
                    ) -> pd.DataFrame:
    """Match truth stance intervals to the tracker's stance (module notes).

    Returns
    -------
    DataFrame
        One row per truth stance interval inside the tracked, valid time:
        ``side, t_start_s, t_end_s, tug_phase, identified (bool), n_stance_scans``.
    """
    c = _cfg(cfg)
    rows = []
    for s in C.SIDES:
        d = frames[frames[C.SIDE].astype(str) == s]
        tt = d[C.T_SENSOR].to_numpy(float)
        tracked = d[C.VALID].to_numpy(bool)
        st = ~d["swing"].to_numpy(bool) & tracked
        ph = d["tug_phase"].to_numpy(object)
        if not tracked.any():
            continue
        t_lo, t_hi = tt[tracked].min(), tt[tracked].max()
        for r in stance[stance[C.SIDE] == s].itertuples(index=False):
            if r.t_start_s < t_lo or r.t_end_s > t_hi:
                continue
            sel = (tt >= r.t_start_s) & (tt <= r.t_end_s)
            if not sel.any():
                continue
            longest = max((b - a for a, b in _runs(st[sel])), default=0)
            mid = 0.5 * (r.t_start_s + r.t_end_s)
            rows.append({C.SIDE: s, "t_start_s": r.t_start_s, "t_end_s": r.t_end_s,
                         "tug_phase": str(ph[np.argmin(np.abs(tt - mid))]),
                         "identified": bool(longest >= c["min_stance_scans"]),
                         "n_stance_scans": int(st[sel].sum())})
    return pd.DataFrame(rows, columns=[C.SIDE, "t_start_s", "t_end_s", "tug_phase",
                                       "identified", "n_stance_scans"])


def truth_phases_of(truth: pd.DataFrame, cfg: dict | None = None) -> tuple:
    """What the evaluation takes from the ground truth alone: the TUG phase bounds
    (:func:`tug_phase_bounds`) and the true stance intervals
    (:func:`truth_stance_intervals`)."""
    return tug_phase_bounds(truth, cfg), truth_stance_intervals(truth, cfg)


def evaluate_tug_trial(track: pd.DataFrame, truth: pd.DataFrame, *, trial: str = "",
                       method: str = "", cfg: dict | None = None,
                       truth_phases: tuple | None = None) -> dict[str, pd.DataFrame]:
    """Evaluate one tracked TUG trial.

    Parameters
    ----------
    track : DataFrame
        :func:`gaitval.methods.track_trial` output (sensor frame).
    truth : DataFrame
        Ground truth ``t_sensor_s, side, xs_m, ys_m, valid`` (sensor frame, sensor clock).
    trial, method : str
        Identifiers copied into every output.
    cfg : dict, optional
        Overrides of :data:`DEFAULTS`.
    truth_phases : tuple, optional
        :func:`truth_phases_of` the same ``truth`` and ``cfg`` when the caller has them
        (they do not depend on the track: a trial's methods share them).

    Returns
    -------
    dict of DataFrame
        ``frames`` (columns :data:`FRAME_COLUMNS`, one row per scan and side),
        ``events`` (false tracking, see :func:`false_tracking`, plus trial/method),
        ``stance`` (see :func:`stance_failures`, plus trial/method) and ``summary`` (one
        row: ``trial, method, n_scans, n_leg_steps, n_uo, false_tracking, ft_phase,
        n_ft_events (swap + lost), n_drift_events, stance_failure, sf_phase, n_stance_true,
        n_stance_failures, success, category, t_turn_start_s, t_turn_end_s``, then the
        persistent-swap rule's ``false_tracking, ft_phase, n_ft_events, success,
        category`` with the suffix ``_persistent_swap``: :data:`SUMMARY_COLUMNS`).
    """
    bounds, truth_stance = truth_phases if truth_phases is not None else \
        truth_phases_of(truth, cfg)
    fr = align_truth(track, truth)
    fr["tug_phase"] = tug_phase_of(fr[C.T_SENSOR].to_numpy(float), bounds)
    bad, events = false_tracking(fr, cfg)
    fr["bad"] = bad
    fr.insert(0, C.METHOD, method)
    fr.insert(0, C.TRIAL, trial)
    for col in ("observed", "interpolated", "swing"):
        if col not in fr:
            fr[col] = False
    fr = fr[list(FRAME_COLUMNS)]
    stance = stance_failures(fr, truth_stance.copy(), cfg)
    for d in (events, stance):
        d.insert(0, C.METHOD, method)
        d.insert(0, C.TRIAL, trial)
    failed = stance[~stance["identified"]] if len(stance) else stance
    sf = len(failed) > 0
    sf_phase = str(failed.sort_values("t_start_s")["tug_phase"].iloc[0]) if sf else ""
    v = fr[fr[C.VALID]]
    row = {C.TRIAL: trial, C.METHOD: method, "n_scans": int(fr["k"].nunique()),
           "n_leg_steps": int(len(v)), "n_uo": int((v["pattern"] == "UO").sum())}
    for rule, sfx in JUDGING_RULES.items():
        ftev = judged_false(events, rule, cfg)
        ft = len(ftev) > 0
        ft_phase = str(ftev["tug_phase"].iloc[0]) if ft else ""
        row.update({f"false_tracking{sfx}": ft, f"ft_phase{sfx}": ft_phase,
                    f"n_ft_events{sfx}": int(len(ftev))})
        if not sfx:
            row.update({"n_drift_events": int((events["kind"] == "drift").sum()),
                        "stance_failure": sf, "sf_phase": sf_phase,
                        "n_stance_true": int(len(stance)),
                        "n_stance_failures": int(len(failed))})
        row.update({f"success{sfx}": not ft and not sf, f"category{sfx}": (
            f"false_tracking_{ft_phase}" if ft else
            f"stance_failure_{sf_phase}" if sf else "success")})
    row.update({"t_turn_start_s": bounds["t_turn_start_s"],
                "t_turn_end_s": bounds["t_turn_end_s"]})
    summary = pd.DataFrame([row], columns=list(SUMMARY_COLUMNS))
    return {"frames": fr.reset_index(drop=True), "events": events, "stance": stance,
            "summary": summary}
