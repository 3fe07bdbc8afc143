"""Evaluation of MTST walking parameters against rater annotations (seed 001 §3.3, Table 4).

The paper's reference is video analysis; gaitval's is the rater annotation file of the
trial (``*.annotations.csv``, :mod:`gaitval.io.annotations`): ``foot_contact``,
``target_step`` (``hit`` / ``miss``, target id) and ``cross_step`` events per leg.

Clocks
    System contacts carry sensor time.  Annotation times are on ``time_base``: ``sensor``
    (used as is) or ``video`` / ``mocap``, which ``time_offset_s`` maps to mocap time;
    mocap time maps to the sensor clock through the trial's clock,
    ``t_sensor = clock_offset_s + (1 + clock_drift_ppm·1e-6)·t_mocap`` — the registered
    clock when the trial has mocap, else the trial sheet's ``clock_offset_s`` (drift 0).
Matching steps
    The system's contact is the shank-vertical instant of a stance (§2.5.1), after the
    loading response; a rater marks the foot's first contact, which opens the stride.  A
    system contact and an annotated contact of the same leg are the same step when the
    system's lies from ``contact_tolerance_s`` (0.15 s: two SD of a video rater's event
    timing, ≈ 40 ms, plus one video frame at 30 fps and one scan at 20 Hz) before the
    annotated one to half a stride after it — stance is ≈ 60 % of the stride and the
    shank is vertical within its first half.  The stride time is the median interval of
    the leg's annotated contacts in the trial (twice the median step interval, else
    1.1 s).  Pairs are made one to one, nearest first.  A system contact of the *other*
    leg in that window marks a possible left/right swap (a correct one lies half a stride
    away from the other leg's contacts).
Per step (Table 4)
    N = the annotated contacts of the trial.  Target steps: the reference says *on
    target* when a ``target_step`` event with value ``hit`` marks the step; the system says
    so when the matched contact lies in an assigned target's judgement region
    (:func:`gaitval.gait.mtst.judge_target_steps`).  Reference on, system not (or no
    matched contact): a **non-judgement**; reference not on, system on — or on another
    target than the rater's, or a system contact without an annotated step that the
    system judges on target: a **misjudgement**.  Cross steps: a crossing episode is the
    step the rater marks ``cross_step`` (the foot placed across the other's line) and the
    next step of the other leg (its swing round the crossed foot, where eq. (11) fires,
    :mod:`gaitval.gait.mtst`).  A marked crossing whose episode the system did not flag is
    a **non-detection**; a system cross step outside every marked episode, or on a system
    contact without an annotated step, is a **false detection**.
Bad input (one :class:`~gaitval.errors.FileFormatError` naming the file and trial)
    Event types other than the three above; event times outside the trial's scans
    (± ``contact_tolerance_s``); a ``target_step`` without a ``hit``/``miss`` value.

References
----------
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (seed 001), §2.5, §3.3, Table 4.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError

EVENTS = ("foot_contact", "target_step", "cross_step")
DEFAULTS = {"contact_tolerance_s": 0.15}
STEP_COLUMNS = ("side", "t_ann_s", "ref_target", "ref_on", "ref_cross", "match",
                "match_other", "sys_target", "sys_cross", "non_judgement", "misjudgement",
                "non_detection", "false_detection")


def check_annotations(ann: pd.DataFrame, *, path, trial: str) -> None:
    """Event types and values a seed 001 evaluation can use (module notes)."""
    bad = sorted(set(ann["event"].astype(str)) - set(EVENTS))
    if bad:
        raise FileFormatError(f"unknown annotation event type(s) {bad}; an MTST annotation "
                              f"file holds only {', '.join(EVENTS)}", path=path, trial=trial,
                              hint="see docs/formats_recordings.md, rater annotations")
    ts = ann[ann["event"] == "target_step"]
    odd = ts[~ts["value"].isin(["hit", "miss"])]
    if len(odd):
        raise FileFormatError(f"target_step at t = {odd['t_s'].iloc[0]:.3f} s has value "
                              f"{odd['value'].iloc[0]!r}; expected hit or miss", path=path,
                              trial=trial)
    no_side = ann[~ann["side"].isin(["L", "R"])]
    if len(no_side):
        raise FileFormatError(f"{no_side['event'].iloc[0]} at t = {no_side['t_s'].iloc[0]:.3f}"
                              " s has no side (L or R)", path=path, trial=trial)


def to_sensor_clock(ann: pd.DataFrame, meta: dict, clock_offset_s: float | None,
                    clock_drift_ppm: float = 0.0, *, path=None, trial: str = "") -> np.ndarray:
    """Annotation times on the sensor clock (module notes, Clocks)."""
    base = str(meta.get("time_base", "video")).strip().lower()
    if base == "sensor":
        return ann["t_s"].to_numpy(float)
    if clock_offset_s is None or not np.isfinite(clock_offset_s):
        raise FileFormatError(
            f"annotations are on the {base} clock but the trial has no clock offset to the "
            "sensor", path=path, trial=trial,
            hint="register the trial against its mocap, give clock_offset_s in the trial "
                 "sheet, or write the annotations with time_base: sensor")
    t_mocap = ann["t_mocap_s"].to_numpy(float)
    return clock_offset_s + (1.0 + clock_drift_ppm * 1e-6) * t_mocap


def check_times(t: np.ndarray, ann: pd.DataFrame, t_first: float, t_last: float, tol: float,
                *, path, trial: str) -> None:
    """Every event inside the trial's scans (± ``tol``) on the sensor clock."""
    out = (t < t_first - tol) | (t > t_last + tol)
    if out.any():
        i = int(np.flatnonzero(out)[0])
        raise FileFormatError(
            f"{int(out.sum())} annotation event(s) lie outside the trial: "
            f"{ann['event'].iloc[i]} at t = {ann['t_s'].iloc[i]:.3f} s is "
            f"{t[i]:.3f} s on the sensor clock, the scans cover {t_first:.3f}-{t_last:.3f} s",
            path=path, trial=trial,
            hint="check the file belongs to this trial and its time_offset_s / the trial's "
                 "clock_offset_s")


def stride_times(ann: pd.DataFrame) -> dict[str, float]:
    """Per leg, the median interval of its annotated contacts (``side, t_ann_s``)."""
    out = {}
    steps = np.diff(np.sort(ann["t_ann_s"].to_numpy(float)))
    fallback = 2.0 * float(np.median(steps)) if len(steps) else 1.1
    for side in ("L", "R"):
        d = np.diff(np.sort(ann.loc[ann["side"] == side, "t_ann_s"].to_numpy(float)))
        out[side] = float(np.median(d)) if len(d) else fallback
    return out


def match_contacts(contacts: pd.DataFrame, ann: pd.DataFrame, tol: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """One-to-one pairs of annotated and system contacts (module notes, Matching steps).

    Parameters
    ----------
    contacts : DataFrame
        System contacts ``side, t_sensor_s``.
    ann : DataFrame
        Annotated contacts ``side, t_ann_s`` (sensor clock).
    tol : float
        How far a system contact may precede the annotated one (s).

    Returns
    -------
    match, match_other : ndarray of int, one per annotated contact
        Index of the paired system contact of the same leg (−1: none), and of a system
        contact of the other leg in the same window (−1: none).
    """
    stride = stride_times(ann)

    def candidates(same: bool):
        pairs = []
        for i, (s, t) in enumerate(zip(ann["side"], ann["t_ann_s"])):
            for j, (s2, tc) in enumerate(zip(contacts["side"], contacts["t_sensor_s"])):
                if (s2 == s) == same and t - tol <= tc < t + 0.5 * stride[s]:
                    pairs.append((abs(tc - t), i, j))
        return sorted(pairs)

    def assign(pairs):
        out = np.full(len(ann), -1)
        used: set[int] = set()
        for _, i, j in pairs:
            if out[i] < 0 and j not in used:
                out[i] = j
                used.add(j)
        return out

    return assign(candidates(True)), assign(candidates(False))


def judge_steps(ann: pd.DataFrame, t_ann: np.ndarray, contacts: pd.DataFrame, tol: float
                ) -> tuple[pd.DataFrame, np.ndarray]:
    """Per annotated step: reference, matched system contact and the Table 4 outcomes.

    Parameters
    ----------
    ann : DataFrame
        The checked annotations (``event, side, target, value``), rows aligned with
        ``t_ann`` (their sensor-clock times).
    contacts : DataFrame
        System contacts with ``side, t_sensor_s``, ``target`` ("" none) and ``cross``.

    Returns
    -------
    steps : DataFrame
        :data:`STEP_COLUMNS`, one row per annotated contact.
    matched : ndarray of bool
        Per system contact: paired with an annotated contact.
    """
    a = ann.assign(t_ann_s=t_ann)
    fc = a[a["event"] == "foot_contact"].sort_values("t_ann_s", kind="stable")
    fc = fc.reset_index(drop=True)
    match, other = match_contacts(contacts, fc, tol)
    side_a, t_a = a["side"].to_numpy(object), a["t_ann_s"].to_numpy(float)
    is_step = (a["event"] == "target_step").to_numpy(bool)
    is_cross = (a["event"] == "cross_step").to_numpy(bool)
    hit, target = (a["value"] == "hit").to_numpy(bool), a["target"].to_numpy(object)
    c_target, c_cross = contacts["target"].to_numpy(object), contacts["cross"].to_numpy()
    rows = []
    for i, (side, t) in enumerate(zip(fc["side"].to_numpy(object), fc["t_ann_s"].to_numpy(float))):
        same = (side_a == side) & (np.abs(t_a - t) < 1e-6)     # this contact's annotations
        steps = same & is_step
        ref_on = bool(hit[steps].any())
        ref_target = str(target[steps][0]) if steps.any() else ""
        j = int(match[i])
        sys_target = str(c_target[j]) if j >= 0 else ""
        sys_on = sys_target != ""
        rows.append([side, float(t), ref_target, ref_on, bool(is_cross[same].any()), j,
                     int(other[i]), sys_target, bool(c_cross[j]) if j >= 0 else False,
                     ref_on and not sys_on, sys_on and (not ref_on or sys_target != ref_target),
                     False, False])
    _cross_episodes(rows)
    steps = pd.DataFrame(rows, columns=list(STEP_COLUMNS))
    matched = np.zeros(len(contacts), bool)
    matched[match[match >= 0]] = True
    return steps, matched


def _cross_episodes(rows: list[list]) -> None:
    """Fill non_detection / false_detection of the step rows (in time order): a crossing
    marked at step i is detected when the system flags step i or the next step of the
    other leg (eq. (11) fires on the swing round the crossed foot, see
    :mod:`gaitval.gait.mtst`); a system cross step is false unless its step, or the
    previous step of the other leg, is a marked crossing."""
    side = [r[0] for r in rows]
    ref = [r[4] for r in rows]
    sys_ = [r[8] for r in rows]

    def next_other(i: int) -> int | None:
        return next((j for j in range(i + 1, len(rows)) if side[j] != side[i]), None)

    def prev_other(i: int) -> int | None:
        return next((j for j in range(i - 1, -1, -1) if side[j] != side[i]), None)

    for i, r in enumerate(rows):
        n, p = next_other(i), prev_other(i)
        r[11] = ref[i] and not (sys_[i] or (n is not None and sys_[n]))
        r[12] = sys_[i] and not (ref[i] or (p is not None and ref[p]))


def extra_judgements(contacts: pd.DataFrame, matched: np.ndarray, t_lo: float, t_hi: float
                     ) -> tuple[int, int]:
    """(misjudgements, false detections) of system contacts with no annotated step inside
    the annotated span [t_lo, t_hi]: judgements the video does not support."""
    c = contacts[~matched]
    c = c[(c["t_sensor_s"] >= t_lo) & (c["t_sensor_s"] <= t_hi)]
    return int((c["target"] != "").sum()), int(c["cross"].sum())


def evaluate_steps(ann: pd.DataFrame, meta: dict, contacts: pd.DataFrame, *,
                   clock: tuple[float | None, float], t_scans: tuple[float, float],
                   cfg: dict | None = None, path=None, trial: str = ""
                   ) -> tuple[pd.DataFrame, np.ndarray, dict]:
    """Check one trial's annotations and judge its steps (module notes).

    Parameters
    ----------
    ann, meta : the annotation table and header (:func:`gaitval.io.annotations.read_annotations`).
    contacts : DataFrame
        System contacts with ``side, t_sensor_s, target, cross``.
    clock : (clock_offset_s or None, clock_drift_ppm)
    t_scans : (first, last) scan time of the trial (sensor clock).

    Returns
    -------
    steps : DataFrame (:data:`STEP_COLUMNS`)
    matched : ndarray of bool per system contact
    counts : dict
        ``n_steps, n_target_ref, non_judgement, misjudgement, n_cross_ref,
        non_detection, false_detection, n_cross_sys`` (misjudgements and false detections
        include those of unmatched system contacts).
    """
    tol = float({**DEFAULTS, **(cfg or {})}["contact_tolerance_s"])
    check_annotations(ann, path=path, trial=trial)
    t = to_sensor_clock(ann, meta, clock[0], clock[1], path=path, trial=trial)
    check_times(t, ann, t_scans[0], t_scans[1], tol, path=path, trial=trial)
    steps, matched = judge_steps(ann, t, contacts, tol)
    half = 0.5 * max(stride_times(steps).values()) if len(steps) else 0.0
    lo = float(steps["t_ann_s"].min()) - tol if len(steps) else np.inf
    hi = float(steps["t_ann_s"].max()) + half if len(steps) else -np.inf
    extra_mis, extra_false = extra_judgements(contacts, matched, lo, hi)
    counts = {"n_steps": int(len(steps)), "n_target_ref": int(steps["ref_on"].sum()),
              "non_judgement": int(steps["non_judgement"].sum()),
              "misjudgement": int(steps["misjudgement"].sum()) + extra_mis,
              "n_cross_ref": int(steps["ref_cross"].sum()),
              "non_detection": int(steps["non_detection"].sum()),
              "false_detection": int(steps["false_detection"].sum()) + extra_false,
              "n_cross_sys": int(steps["sys_cross"].sum()) + extra_false}
    return steps, matched, counts
