"""Notes of the MTST tables: every difference from the published values, its direction and
the likely cause.

The direction statements are computed from the tables; the causes are the mechanisms
found on the simulated twin (docs/mtst.md, "Reproduced vs published"), stated once per
kind of difference so a reader sees why, not only that, a number differs.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.tables import _published_yorozu2015b as P

#: cause of a difference, by (quantity, direction)
CAUSES = {
    ("lost", "more"): (
        "more lost tracks: the twin's elderly leave stance with the shin point already "
        "moving at about 1.5 times the walking speed (docs/simulator.md), so the first swing "
        "scans fall outside a region sized for a leg at rest (3/4 w_l, or w_l for Method 3) "
        "while the constant-velocity prediction (Q = 5^2 m^2/s^4) still stands still"),
    ("lost", "fewer"): (
        "fewer lost tracks: on the twin an occluded leg reappears in the five-pattern "
        "detector within a few scans (1.7 % of leg-scans occluded), so a prediction rarely "
        "runs far"),
    ("false", "more"): (
        "more false tracks: the twin's attendant walks 0.75 m to the right and 0.25 m "
        "behind at the participant's speed and the stick stands 0.28 m to the side; a lost "
        "leg's growing region (or a fixed 1.5 w_l one) then takes the other leg or one of "
        "them, and the paper's video check cannot be replicated exactly (mocap rule "
        "0.30 m / 0.20 s, gaitval.evaluate.mtst_tracking)"),
    ("false", "fewer"): (
        "fewer false tracks: the initialiser starts on the mat's lane "
        "(gaitval.track.init_mtst), which the paper does not describe, and the twin's stick "
        "users are only 2 participants (6 trials), so a difference of one or two trials is "
        "within chance"),
    ("success", "lower"): (
        "lower success: the lost and false tracks above; each failed trial counts once"),
    ("success", "higher"): (
        "higher success: fewer failures than published, see the lost / false notes"),
    ("non", "more"): (
        "more non-judgements / non-detections: a contact the track misses (a stance the "
        "speed-threshold rule does not see, or a failed part of a trial that the mocap "
        "verdict still called successful) cannot be judged"),
    ("non", "fewer"): (
        "fewer non-judgements / non-detections: the twin's rater judges 'hit' from the "
        "true foot (docs/simulator.md) with the same foot size gaitval's region assumes, "
        "while the paper's video raters saw real feet"),
    ("mis", "more"): (
        "more misjudgements / false detections: contacts near a region's edge and steps "
        "the system finds that the rater did not mark"),
    ("mis", "fewer"): (
        "fewer misjudgements / false detections: see the non-judgement note; the twin's "
        "targets never touch each other"),
}


def _direction(rep: float, pub: float, words=("more", "fewer")) -> str | None:
    if rep is None or pub is None or not np.isfinite(rep) or not np.isfinite(pub):
        return None
    if np.isclose(rep, pub):
        return None
    return words[0] if rep > pub else words[1]


def table3_notes(t3: pd.DataFrame) -> list[str]:
    """One note per method whose primary reference differs from the paper, with causes."""
    notes = ["Published Method 3 success is printed '64.6% (31/44)'; 31/44 would be 70.5 %, "
             "and 48 - (14 + 0 + 1 + 2) = 31, so the denominator is 48 (as the checklist "
             "reads it): gaitval compares with 31/48."]
    if t3.empty:
        return notes + ["No MTST trials were evaluated."]
    used: set[tuple[str, str]] = set()
    for m, d in t3.groupby("method", sort=False):
        r = d.iloc[0]                                      # mocap first when present
        parts = []
        for q, label in (("lost", "lost"), ("false", "false")):
            for g in ("no_stick", "stick"):
                n, n_pub = int(r[f"n_trials_{g}"]), P.N_TRIALS[g]
                rep, pub = r[f"{q}_{g}"], r[f"{q}_{g}_published"]
                if n == 0 or pub is None or pd.isna(pub):
                    continue
                rate, rate_pub = rep / n, float(pub) / n_pub
                dirn = _direction(rate, rate_pub)
                if dirn:
                    parts.append(f"{label} {g.replace('_', ' ')} {rep}/{n} vs {int(pub)}/{n_pub}"
                                 f" ({dirn})")
                    used.add((q, dirn))
        dirn = _direction(r["success_pct"], r["success_pct_published"], ("higher", "lower"))
        if dirn:
            used.add(("success", dirn))
            parts.append(f"success {r['success_pct']:.1f} % vs "
                         f"{r['success_pct_published']:.1f} % ({dirn})")
        if parts:
            notes.append(f"{r['label']} ({r['reference']}): " + "; ".join(parts) + ".")
    notes += [f"Why {CAUSES[k]}." for k in sorted(used) if k in CAUSES]
    return notes


def table4_notes(t4: pd.DataFrame, trials: pd.DataFrame) -> list[str]:
    """Notes of Table 4: trials used, differences from the paper and their causes, and the
    cross steps per 100 steps of the study against the paper's 4.6."""
    notes = [f"{len(trials)} trials (the paper: 46 of 48) that the proposed method tracked "
             "successfully; steps = the rater's foot contacts (the paper: 414, 9.0 per "
             f"trial; here {trials['n_steps'].sum() / max(len(trials), 1):.1f} per trial: "
             "the twin counts every contact from the start position to the goal)."]
    if "has_targets" in trials and (~trials["has_targets"].astype(bool)).any():
        notes.append(f"{int((~trials['has_targets'].astype(bool)).sum())} trial(s) had no "
                     "target layout and are left out of the target-step row.")
    if t4.empty:
        return notes
    cross = t4[t4["row"] == "cross_step"].iloc[0]
    notes.append(f"Cross steps per 100 steps: {cross['cross_per_100_steps']:.1f} on these "
                 f"trials against the paper's {P.CROSS_PER_100:.1f} (19/414).")
    used = set()
    for _, r in t4.iterrows():
        for q, col in (("non", "non"), ("mis", "mis_or_false")):
            rep = int(r[f"{col}_no_stick"]) + int(r[f"{col}_stick"])
            pub = int(r[f"{col}_no_stick_published"]) + int(r[f"{col}_stick_published"])
            n = (int(r["n_steps_no_stick"]) + int(r["n_steps_stick"]) if r["row"] ==
                 "target_step" else int(r["n_cross_no_stick"]) + int(r["n_cross_stick"]))
            n_pub = P.STEPS["total"] if r["row"] == "target_step" else P.CROSS["total"]
            if n == 0:
                continue
            dirn = _direction(rep / n, pub / n_pub)
            if dirn:
                used.add((q, dirn))
                notes.append(f"{r['row']}: {col.replace('_', ' ')} {rep} of {n} vs {pub} of "
                             f"{n_pub} ({dirn}).")
    notes += [f"Why {CAUSES[k]}." for k in sorted(used) if k in CAUSES]
    return notes
