"""The TUG occlusion two ways, per phase: seed 000's (the tracker's unobservable leg-steps,
Table 4) and the twin's (the truth: fewer than 3 beams on the leg, ``physics.csv``), on a
method's success trials of a built report; and, for the leg-steps the tracker calls
unobservable while the leg still returns 3 or more beams, how many beams and what the
other leg's observed pattern was (docs/simulator.md, "Calibrated settings").

Usage::

    .venv/bin/python experiments/tug_unobservable_vs_truth.py [--study default] [--method tug_m2]

Reads ``results/<study>/evaluate/<method>/<trial>/{summary,frames}.parquet`` and
``data/<study>/truth/<trial>/scans_legs.parquet``; prints one line per phase.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--study", default="default")
    ap.add_argument("--method", default="tug_m2")
    a = ap.parse_args(argv)
    ev = ROOT / "results" / a.study / "evaluate" / a.method
    truth = ROOT / "data" / a.study / "truth"
    rows = []
    for d in sorted(ev.glob("tug_*")):
        if not bool(pd.read_parquet(d / "summary.parquet")["success"].iloc[0]):
            continue
        f = pd.read_parquet(d / "frames.parquet")
        s = pd.read_parquet(truth / d.name / "scans_legs.parquet")
        rows.append(f.merge(s[["scan", "side", "n_beams", "occluded"]]
                            .rename(columns={"scan": "k"}), on=["k", "side"], how="left"))
    if not rows:
        raise SystemExit(f"no successful {a.method} trial under {ev}")
    m = pd.concat(rows, ignore_index=True)
    m = m[m["valid"]]
    other = m[["trial", "k", "side", "pattern"]].assign(
        side=lambda x: x["side"].map({"L": "R", "R": "L"})).rename(columns={"pattern": "other"})
    m = m.merge(other, on=["trial", "k", "side"], how="left")
    print(f"{a.method}: {m['trial'].nunique()} success trials of study {a.study}")
    for ph in ("forward", "turning", "return"):
        e = m[m["tug_phase"] == ph]
        uo = ~e["observed"].astype(bool)
        occ = e["occluded"].astype(bool)
        v = e[uo & ~occ]
        print(f"{ph:8s} leg-steps {len(e):5d}  tracker unobservable {uo.mean():.2%}  "
              f"truth occluded {occ.mean():.2%}  unobservable with >= 3 beams {len(v)} of "
              f"{int(uo.sum())} (median {v['n_beams'].median():.0f} beams; other leg "
              f"{v['other'].value_counts().to_dict()})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
