"""Per-step evidence for the TUG tables: what each failing trial's tracker saw when it failed.

Yorozu et al. 2015a Table 3 counts failures; a reviewer who finds the reproduced ranking different
from the paper's needs to see *where* and *why* each method failed.  For every trial a
method did not track successfully, :func:`failure_evidence` finds the first failure in the
evaluation frames and describes it: the trial, time, TUG phase and leg; for false tracking
whether the track jumped to the other leg (swap) or ran away (lost); the observed leg
patterns of both legs and the tracker's gait phase in the 0.5 s before; for a stance
failure the truth stance interval the tracker never called stance.

Also here: which reading of seed000 eq. (3)–(4) a method ran (:func:`method_reading`),
from its definition (``phase.reading``) or from its name (``<method>_<reading>``, the
variants the workflow adds for ``tug.phase_readings``).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472 (Table 3; §3.2 eq. (3)–(5); §5.2).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.evaluate.tug import stance_failures
from gaitval.evaluate.tug_truth import truth_stance_intervals
from gaitval.gait.phases import READINGS

DEFAULT_READING = READINGS[0]
LOOK_BACK_S = 0.5
EVIDENCE_COLUMNS = ["trial", "method", "base_method", "phase_reading", "category", "side",
                    "t_s", "tug_phase", "kind", "error_m", "other_leg_m", "legs_apart_m",
                    "patterns_before", "gait_phases_before", "uo_scans_before", "evidence"]


def method_reading(name: str, definitions: Mapping | None = None) -> tuple[str, str]:
    """``(base method, reading)`` of a method name.

    The reading is the definition's ``phase.reading`` when ``definitions`` holds the
    method, else read from a ``_<reading>`` suffix; the base is the name without that
    suffix.
    """
    reading = None
    d = (definitions or {}).get(name)
    if isinstance(d, Mapping) and isinstance(d.get("phase"), Mapping):
        reading = d["phase"].get("reading", DEFAULT_READING)
    if reading is None:
        reading = next((r for r in READINGS if name.endswith("_" + r)), DEFAULT_READING)
    suffix = "_" + reading
    base = name[:-len(suffix)] if name.endswith(suffix) else name
    return base, reading


def _runs_text(values) -> str:
    """``a×3 → b×2`` for a sequence (consecutive repeats compressed)."""
    out, prev, n = [], None, 0
    for v in values:
        if v == prev:
            n += 1
            continue
        if prev is not None:
            out.append(f"{prev}×{n}")
        prev, n = v, 1
    if prev is not None:
        out.append(f"{prev}×{n}")
    return " → ".join(out)


def _window(f: pd.DataFrame, t0: float) -> pd.DataFrame:
    t = f[C.T_SENSOR].to_numpy(float)
    return f[(t >= t0 - LOOK_BACK_S) & (t <= t0)]


def _seen_before(f: pd.DataFrame, t0: float, side: str) -> dict:
    """Patterns of both legs, gait phases and UO scans of ``side`` in the look-back window."""
    w = _window(f, t0)
    by = {s: w[w[C.SIDE].astype(str) == s] for s in C.SIDES}
    pats = "; ".join(f"{s} {_runs_text(by[s]['pattern'].astype(str))}" for s in C.SIDES)
    phases = _runs_text(int(p) for p in by["L"]["phase"])
    return {"patterns_before": pats, "gait_phases_before": phases,
            "uo_scans_before": int((by[side]["pattern"].astype(str) == "UO").sum())}


def _false_tracking(f: pd.DataFrame) -> dict | None:
    """The first bad scan of a trial's frames: side, time, errors and what was seen."""
    bad = f[f["bad"].astype(bool)]
    if not len(bad):
        return None
    b = bad.sort_values(C.T_SENSOR, kind="stable").iloc[0]
    side, t0 = str(b[C.SIDE]), float(b[C.T_SENSOR])
    at = f[f[C.T_SENSOR].to_numpy(float) == t0].set_index(C.SIDE)
    other = "R" if side == "L" else "L"
    own = float(np.hypot(b[C.X] - b[C.XS], b[C.Y] - b[C.YS]))
    oth = float(np.hypot(b[C.X] - at.loc[other, C.XS], b[C.Y] - at.loc[other, C.YS]))
    apart = float(np.hypot(at.loc["L", C.XS] - at.loc["R", C.XS],
                           at.loc["L", C.YS] - at.loc["R", C.YS]))
    return {"side": side, "t_s": t0, "tug_phase": str(b["tug_phase"]),
            "kind": "swap" if oth < own else "lost", "error_m": own, "other_leg_m": oth,
            "legs_apart_m": apart, **_seen_before(f, t0, side)}


def _stance_failure(f: pd.DataFrame, cfg: dict | None) -> dict | None:
    """The first truth stance interval the tracker never identified."""
    truth = f[[C.T_SENSOR, C.SIDE, C.XS, C.YS, C.VALID]]
    st = stance_failures(f, truth_stance_intervals(truth, cfg), cfg)
    failed = st[~st["identified"].astype(bool)] if len(st) else st
    if not len(failed):
        return None
    r = failed.sort_values("t_start_s", kind="stable").iloc[0]
    side, t0 = str(r[C.SIDE]), float(r["t_end_s"])
    return {"side": side, "t_s": float(r["t_start_s"]), "tug_phase": str(r["tug_phase"]),
            "kind": f"stance {r['t_start_s']:.2f}–{r['t_end_s']:.2f} s not identified",
            "error_m": np.nan, "other_leg_m": np.nan, "legs_apart_m": np.nan,
            **_seen_before(f, t0, side)}


def _sentence(r: dict) -> str:
    if r["category"].startswith("false_tracking"):
        what = (f"{r['side']} track {'jumped to the other leg' if r['kind'] == 'swap' else 'lost'}"
                f" ({r['error_m']:.2f} m from its leg, {r['other_leg_m']:.2f} m from the other;"
                f" legs {r['legs_apart_m']:.2f} m apart)")
    else:
        what = f"{r['side']} {r['kind']}"
    return (f"{r['trial']} {r['method']}: at {r['t_s']:.2f} s ({r['tug_phase']}) {what}; "
            f"0.5 s before: {r['patterns_before']}; {r['side']} unobservable in "
            f"{r['uo_scans_before']} scans; gait phases {r['gait_phases_before']}")


def failure_evidence(frames: pd.DataFrame, summaries: pd.DataFrame,
                     definitions: Mapping | None = None, cfg: dict | None = None
                     ) -> pd.DataFrame:
    """One row per (trial, method) that failed: its first failure and what the tracker saw.

    Parameters
    ----------
    frames, summaries : DataFrame
        Concatenated outputs of :func:`gaitval.evaluate.tug.evaluate_tug_trial`.
    definitions : mapping, optional
        Method name -> definition run (for the reading, :func:`method_reading`).
    cfg : dict, optional
        The evaluation rules (``evaluation.tug``) the trials were evaluated with.

    Returns
    -------
    DataFrame
        Columns :data:`EVIDENCE_COLUMNS`; ``evidence`` is one sentence.
    """
    rows = []
    need = {C.TRIAL, C.METHOD, C.T_SENSOR, C.SIDE, C.X, C.Y, C.XS, C.YS, C.VALID, "bad",
            "pattern", "phase", "swing", "tug_phase"}
    if not len(summaries) or not need <= set(frames.columns):
        return pd.DataFrame(columns=EVIDENCE_COLUMNS)      # frames without the evaluation's
    failed = summaries[~summaries["success"].astype(bool)]
    for s in failed.sort_values([C.METHOD, C.TRIAL]).itertuples(index=False):
        trial, method, cat = str(s.trial), str(s.method), str(s.category)
        f = frames[(frames[C.TRIAL].astype(str) == trial)
                   & (frames[C.METHOD].astype(str) == method)]
        f = f.sort_values([C.T_SENSOR, C.SIDE], kind="stable")
        first = (_false_tracking(f) if cat.startswith("false_tracking")
                 else _stance_failure(f, cfg)) if len(f) else None
        if first is None:
            continue
        base, reading = method_reading(method, definitions)
        r = {"trial": trial, "method": method, "base_method": base, "phase_reading": reading,
             "category": cat, **first}
        r["evidence"] = _sentence(r)
        rows.append(r)
    return pd.DataFrame(rows, columns=EVIDENCE_COLUMNS)
