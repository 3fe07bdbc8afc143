"""A confirmation window of one step instead of one stride (issue 55).

Question (written and committed before the first run)
-----------------------------------------------------
The online ``people`` method's confirmer (``m_of_n_moving``) looks at the last N scans,
N = 1.4 s: "one stride of a slow walker (cadence 85 steps/min), so that the legs have
swung past each other at least once inside the window".  In one *step* (half a stride,
60/85 = 0.71 s) the swinging leg passes the standing one once, which is what the window's
tests ask (r on both sides of zero by a leg width; r spans d_c = 0.5 m, a slow walker's
step moves r from about −0.25 to +0.25 m; the body travels d_w = 0.5 m at ≥ 0.7 m/s).
The change measured: ``window_s`` 0.7 instead of 1.4, every other value unchanged (the pair
rule's age bound, the static map's 1.4 s, the splice window, the deletion times).

Why it is asked now: on ``general_tracking_moving_1`` of the leg_tracker benchmarks (a
real moving-robot crowd, ``experiments/people_general_moving.py``) 41 of the 133
annotated person-scans had a hypothesis near that was still younger than the window, and
people there are in view for 0.3–3.3 s.  That recording's classes were seen before this
question was written, so its score below is reported and decides nothing.

Data
----
* Development (values may be chosen on it): the crowd benchmark's dev scenes (seed 11,
  five kinds) and the dev-only ``following`` scenes (seeds 11-15).
* Test (measured once, only if the development criterion holds): negative_2.bag on its
  three lasers read forwards and backwards; the crowd test split (seed 23); the outdoor
  following bag.

Criteria
--------
Development: the summed dev MOTA of ``people`` over the six dev kinds is higher with 0.7 s,
and no dev kind's MOTA is lower by more than 1 point.
Test (adopt into ``people`` only if all hold):
1. negative_2.bag, each laser, forwards and backwards: ``people`` confirms and re-finds
   nobody, ``people_offline`` reports nobody.
2. Crowd test split: ``people``'s MOTA above both leg_tracker-rule rows on every kind.
3. Outdoor following: matched ≥ 5,179 (today's), ID switches ≤ 21, MOTP ≤ 0.09 m.
Reported only: ``general_tracking_moving_1`` (``--general BAG``).

Usage::

    .venv/bin/python experiments/people_window.py dev
    .venv/bin/python experiments/people_window.py test [--general BAG]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

WINDOW_S = 0.7


def over(window_s: float) -> dict:
    from gaitval.methods import get_method
    conf = dict(get_method("people")["kind"]["confirmer"])
    conf["window_s"] = window_s
    return {"kind__confirmer": conf}


def dev():
    from people_legs_confirm import dev_scores
    res = {}
    for w in (1.4, WINDOW_S):
        t = dev_scores(over(w))
        res[w] = dict(zip(t["kind"], t["mota_pct"]))
        print(f"window {w} s: sum {t['mota_pct'].sum():.1f}  " + "  ".join(
            f"{r.kind} {r.mota_pct:.1f} (matched {r.matched}, fp {r.fp})"
            for r in t.itertuples()))
    a, b = res[1.4], res[WINDOW_S]
    ok = sum(b.values()) > sum(a.values()) and all(b[k] >= a[k] - 1.0 for k in a)
    print("development criterion holds:", ok)


def test(general: Path | None):
    from gaitval.crowd import bench
    from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
    from gaitval.methods import build_method
    from gaitval.track.passes import reversed_scans
    from outdoor_score import score_outdoor
    o = over(WINDOW_S)
    bag = ROOT.parent / "shared" / "realdata" / "lrs" / "negative_2.bag"
    for topic in describe_rosbag(bag)["scans"]:
        scans = read_rosbag_scans(bag, topic)
        for way, s in (("forwards", scans), ("backwards", reversed_scans(scans))):
            on = build_method("people", o).track(s, 0.10)
            off = build_method("people_offline", o).track(s, 0.10)
            print(f"1. negative_2 {topic} {way}: people confirmed {on.n_confirmed} "
                  f"re-found {on.n_refound}; people_offline persons "
                  f"{off.people['person_id'].nunique()}")
    rows = bench.run("test", overrides={"people": o, "people_offline": o})
    t = bench.by_kind(rows)
    print("2. crowd test:\n" + t.pivot(index="kind", columns="method",
                                      values="mota_pct").round(1).to_string())
    print("3. outdoor:", score_outdoor(o))
    if general:
        import subprocess
        import tempfile
        import json
        with tempfile.TemporaryDirectory() as d:
            d = Path(d)
            cfg = d / "cfg.json"
            cfg.write_text(json.dumps({"tracking": {"overrides": {"people": o,
                                                                  "people_offline": o}}}))
            for m in ("people", "people_offline"):
                gv = [sys.executable, "-m", "gaitval"]
                subprocess.run(gv + ["legbench-track", "--sensor", str(general),
                                     "--scan-topic", "/scan", "--method", m, "--config",
                                     str(cfg), "--out", str(d / "t.parquet"), "-q"],
                               check=True)
                r = subprocess.run(gv + ["legbench-evaluate", "--track", str(d / "t.parquet"),
                                         "--annotations", str(general), "--annotation-topic",
                                         "/ground_truth_people_tracks", "--scan-topic", "/scan",
                                         "--sector-deg", "-80", "12", "--out", str(d / "e")],
                                   check=True, capture_output=True, text=True)
                print(f"general_tracking_moving_1 {m}:", r.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("stage", choices=["dev", "test"])
    ap.add_argument("--general", type=Path)
    a = ap.parse_args()
    dev() if a.stage == "dev" else test(a.general)
