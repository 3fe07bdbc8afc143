"""TUG occlusion per phase with both definitions beside the paper's (Yorozu et al. 2015a
Table 4, Method 2; :mod:`gaitval.report.verdicts`).

The paper counts a leg-scan occluded when its tracker found the leg unobservable; the
twin's ``physics.csv`` counts the truth (fewer than 3 beams on the leg, every trial).  The
verdict compares the like-defined one: Method 2's tracker-counted rate on its successful
trials (Table 4's ``occlusion_rate``) against the paper's by the Wilson interval; the
truth rate is shown beside it and not compared.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.report.verdicts_common import _pct, _proportion_verdict, _row

#: The phases of Table 4 with a published occlusion count.
PHASES = ("forward", "turning", "return")


def truth_occlusion(physics: list[Path] | None) -> dict[str, tuple[float, str]]:
    """Phase -> (the twin's truth occlusion, its source note) from ``physics.csv`` files
    (the first that has ``tug_occlusion`` rows); empty for real data."""
    for p in physics or []:
        try:
            df = pd.read_csv(p, usecols=["check", "phase", "value"])
        except (OSError, ValueError):
            continue
        occ = df[df["check"] == "tug_occlusion"]
        if len(occ):
            return {str(r.phase): (float(r.value), Path(p).parent.name)
                    for r in occ.itertuples()}
    return {}


def tug_occlusion_verdicts(t4: pd.DataFrame, reading: str,
                           physics: list[Path] | None = None) -> list[dict]:
    """One verdict per phase: Method 2's tracker-counted unobservable rate vs the paper's
    (published inside the reproduced 95 % Wilson interval), the truth rate beside it."""
    d = t4[(t4["method"].astype(str) == "tug_m2")
           & (t4.get("phase_reading", reading) == reading)].set_index("tug_phase")
    truth = truth_occlusion(physics)
    rows = []
    for ph in PHASES:
        if ph not in d.index or "n_uo" not in d:
            continue
        r = d.loc[ph]
        k, n = float(r["n_uo"]), float(r["n_steps"])
        pub = float(r["occlusion_rate_published"])
        text, ok, small = _proportion_verdict(k, n, pub)
        if ph in truth:
            text += (f"; truth (< 3 beams, every trial of {truth[ph][1]}) "
                     f"{_pct(truth[ph][0])}, not compared")
        rows.append(_row("tug", f"Occluded leg-scans, {ph} phase, M2 (tracker-counted, as the "
                         f"paper counts; reading {reading})", "Table 4",
                         f"{_pct(pub)} ({int(r['n_uo_published'])}/"
                         f"{int(r['n_steps_published'])})", text,
                         "paper inside our 95% CI (the tracker's unobservable leg-scans on "
                         "its successful trials; the truth rate is shown, not compared)", ok,
                         "the like-defined rates compared: the paper's is its tracker's "
                         "unobservable count, so the tracker's count is compared, not the "
                         "truth's.", "tug_table4", not_comparable=small))
    return rows
