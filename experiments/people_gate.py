"""Judge a change of the people tracker (issue 36, v9-v19): twelve changes to its gate,
motion model, confirmer evidence, take-over of a coasting person and two passes, each with
its criteria written before its first run.  The record of each change (why, the change,
the criteria, the result) is docs/history/people_gate.md; what was adopted is described
in docs/people.md.

The criteria every change was judged on:

(a) the people method confirms nobody and re-finds nobody on the three lasers of
    ``negative_2.bag`` (this script, default mode);
(b) the default (simulated) study's people rows, where truth is known, are not worse
    (TUG Table 3 successes, MTST Table 3 successes against mocap, rollator error frames and
    RMSE), compared by ``--compare CURRENT_TABLES NEW_TABLES`` on two
    ``reports/default/tables`` directories;
(c) every row of the papers' methods in those tables is unchanged;
(d) the people tracker stays at least 20x real time per laser outdoors
    (``benchmarks/people_tracker.py``, median of 3).

The outdoor benchmark score (``--outdoor``) was measured once per change, after (a)-(d),
for the record; it decided nothing.

    .venv/bin/python experiments/people_gate.py                    # (a)
    .venv/bin/python experiments/people_gate.py --compare OLD NEW  # (b), (c)
    .venv/bin/python experiments/people_gate.py --outdoor          # the record

It needs the code of its commits (``git log --follow -- experiments/people_gate.py``):
several variants it names were removed after they were rejected.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from outdoor_score import score_outdoor

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "realdata" / "lrs"
NEGATIVE_TOPICS = ("/left_scan", "/rear_scan", "/right_scan")
GATE = {"name": "variable_region", "v_sw": 1.1, "v_st": 0.55}     # seed 001 Table 1
CHI2 = {"name": "chi2", "g": 13.82}                                # seed 000 Table 2
REFIND = {"name": "leg_tracker_gate", "max_std_m": 0.9, "percentile": 0.90,
          "std_obs_m": 0.1, "assoc_extra_m": 0.4}                  # METHODS["people"]
OBS_CONFIRMER = {"name": "m_of_n_moving", "window_s": 1.4, "m_fraction": 0.5,
                 "min_relative_travel_m": 0.5, "pass_leg_widths": 1.0, "min_travel_m": 0.5,
                 "evidence": "observations"}                       # METHODS["people"] + v12
VARIANTS = {"gate": ("χ² gate", {"kind__gate": CHI2}, "variable region", {"kind__gate": GATE}),
            "motion": ("constant velocity", {"kind__motion": {"name": "constant_velocity"}},
                       "gait-phase input",
                       {"kind__motion": {"name": "gait_phase_accel", "n_ac": 40,
                                         "limit_braking": True}}),
            "evidence": ("estimates", {}, "observations", {"kind__confirmer": OBS_CONFIRMER}),
            "evidence_motion": ("estimates, CV", {}, "observations, gait-phase input",
                                {"kind__confirmer": OBS_CONFIRMER,
                                 "kind__motion": {"name": "gait_phase_accel", "n_ac": 40,
                                                  "limit_braking": True}}),
            "tentative_motion": ("constant velocity", {}, "gait-phase input once confirmed",
                                 {"kind__motion": {"name": "gait_phase_accel", "n_ac": 40,
                                                   "limit_braking": True},
                                  "kind__tentative_motion": {"name": "constant_velocity"}}),
            "walk": ("gait tests asked", {}, "the walk suffices",
                     {"kind__confirmer": {**OBS_CONFIRMER, "walk_suffices": True}}),
            "coasting": ("re-find ended", {"kind__refind": REFIND}, "re-find coasting too",
                         {"kind__refind": {**REFIND, "coasting": True}}),
            "offline": ("forward (people)", {}, "forward and backward (people_offline)",
                        {"kind__passes": {"name": "forward_backward", "max_std_m": 0.9,
                                          "percentile": 0.90, "std_obs_m": 0.1,
                                          "assoc_extra_m": 0.4}}),
            "extend": ("forward (people)", {}, "backward extends forward (people_offline)",
                       {"kind__passes": {"name": "forward_backward", "max_std_m": 0.9,
                                         "percentile": 0.90, "std_obs_m": 0.1,
                                         "assoc_extra_m": 0.4, "extend_only": True}}),
            "splice": ("forward (people)", {}, "extends, aligned at splices (people_offline)",
                       {"kind__passes": {"name": "forward_backward", "max_std_m": 0.9,
                                         "percentile": 0.90, "std_obs_m": 0.1,
                                         "assoc_extra_m": 0.4, "extend_only": True,
                                         "splice_window_s": 1.4}})}


def negative(variant: str) -> None:
    from gaitval.io.rosbag import read_rosbag_scans
    from gaitval.methods import build_method

    bag = SHARED / "negative_2.bag"
    if not bag.exists():
        sys.exit(f"{bag} is absent")
    name0, over0, name1, over1 = VARIANTS[variant]
    print(f"(a) negative_2, persons confirmed + re-found ({name0} | {name1}):")
    for topic in NEGATIVE_TOPICS:
        scans = read_rosbag_scans(bag, topic)
        row = []
        for over in (over0, over1):
            t0 = time.perf_counter()
            r = build_method("people", over).track(scans, 0.10)
            row.append(f"{r.n_confirmed}+{r.n_refound}, reported {r.people['person_id'].nunique()}"
                       f" ({time.perf_counter() - t0:.1f} s)")
        print(f"  {topic:12s} {scans.n_scans} scans   " + "  |  ".join(row))


def compare(old: Path, new: Path, method: str = "people") -> None:
    """(b): ``method``'s rows in NEW against the ``people`` rows in OLD; (c): every other
    row of NEW (the papers' methods, and ``people`` when ``method`` is another) against
    OLD."""
    import pandas as pd

    def people(d, name, col="method"):
        t = pd.read_csv(d / f"{name}.csv")
        m = "people" if d == old else method
        return t[t[col] == m], t[t[col] != m]

    ok = True
    po, _ = people(old, "tug_table3")
    pn, _ = people(new, "tug_table3")
    b1 = int(pn["n_success"].iloc[0]) >= int(po["n_success"].iloc[0])
    print(f"(b1) TUG successes {int(po['n_success'].iloc[0])} -> {int(pn['n_success'].iloc[0])}"
          f" of {int(pn['n_trials'].iloc[0])}: {'met' if b1 else 'NOT met'}")
    po, _ = people(old, "mtst_table3")
    pn, _ = people(new, "mtst_table3")
    so = po[po["reference"] == "mocap"]["success"].iloc[0]
    sn = pn[pn["reference"] == "mocap"]["success"].iloc[0]
    count = lambda s: int(s.split("(")[1].split("/")[0])                   # noqa: E731
    b2 = count(sn) >= count(so)
    print(f"(b2) MTST successes (mocap) {so} -> {sn}: {'met' if b2 else 'NOT met'}")
    po, _ = people(old, "rollator_table2", "tracker")
    pn, _ = people(new, "rollator_table2", "tracker")
    eo, en = int(po["error_frames"].sum()), int(pn["error_frames"].sum())
    t1o = pd.read_csv(old / "rollator_table1.csv")
    t1n = pd.read_csv(new / "rollator_table1.csv")
    ratio = float((t1n[f"rmse_{method}"] / t1o["rmse_people"]).median())
    b3 = en <= eo and ratio <= 1.05
    print(f"(b3) rollator people error frames {eo} -> {en}; median RMSE ratio {ratio:.3f}: "
          f"{'met' if b3 else 'NOT met'}")
    ok = b1 and b2 and b3
    # (c) the papers' methods' rows
    changed = []
    for f in sorted(old.glob("*.csv")):
        g = new / f.name
        if not g.exists():
            changed.append(f"{f.name} (missing)")
            continue
        a, b = pd.read_csv(f), pd.read_csv(g)
        col = next((c for c in ("method", "tracker") if c in a.columns), None)
        if col is not None:
            a, b = a[a[col] != method], b[b[col] != method]
        drop = [c for c in b.columns if c.endswith(f"_{method}")]
        a, b = a.drop(columns=drop, errors="ignore"), b.drop(columns=drop)
        if not a.reset_index(drop=True).equals(b.reset_index(drop=True)):
            changed.append(f.name)
    print(f"(c) tables whose papers' rows changed: {changed or 'none'}")
    ok = ok and not changed
    print("criteria (b), (c):", "met" if ok else "NOT met")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compare", nargs=2, type=Path, metavar=("CURRENT", "NEW"))
    ap.add_argument("--method", default="people",
                    help="with --compare: the method whose NEW rows are held against OLD's "
                         "people rows (v16, v17: people_offline)")
    ap.add_argument("--variant", choices=sorted(VARIANTS), default="gate",
                    help="gate: v9 (variable region); coasting: v9b (re-find coasting persons); "
                         "motion: v11 (seed 000's gait-phase input); evidence, evidence_motion: v12; "
                         "tentative_motion: v13; walk: v14; offline: v16; extend: v17, v18; splice: v19")
    ap.add_argument("--outdoor", action="store_true",
                    help="score person_following_outdoor_1 once (decides nothing)")
    a = ap.parse_args()
    if a.compare:
        compare(*a.compare, a.method)
    elif a.outdoor:
        print("person_following_outdoor_1, following mode (for the record; decides nothing):")
        name0, over0, name1, over1 = VARIANTS[a.variant]
        for name, over in ((name0, over0), (name1, over1)):
            print(f"  {name:22s}", score_outdoor(over))
    else:
        negative(a.variant)


if __name__ == "__main__":
    main()
