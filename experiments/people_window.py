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

Candidate 2 (written after the 0.7 s window failed the development criterion)
----------------------------------------------------------------------------
The 0.7 s window gained on the walkers who cross quickly (dev crossing_moving 58.0 → 68.2,
crowd_moving 42.1 → 58.2, following 44.5 → 53.7) and lost the slow ones (assisted, the
participant with a cane, 64.4 → 28.3; meet_stand_turn 75.6 → 55.5): in one step of a slow
walker r does not span 0.5 m.  Candidate 2 asks both time scales: a hypothesis is
confirmed when the window's tests pass on the last 1.4 s (today's) **or** on the last
0.7 s (the same tests, N and M of the shorter window); a hypothesis still ends by the
1.4 s window's M of N.  The same criteria decide.

Usage::

    .venv/bin/python experiments/people_window.py dev [--both]
    .venv/bin/python experiments/people_window.py test [--both] [--general BAG]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

WINDOW_S = 0.7
BOTH = False        # candidate 2: the 1.4 s window or the 0.7 s one


def both_windows():
    """Candidate 2, patched into ``MOfNMoving``: the short window's tests after the long
    one's fail."""
    import math
    from collections import deque

    from gaitval.track.lifecycle import MOfNMoving
    bind0, step0 = MOfNMoving.bind, MOfNMoving.step

    def bind(self, dt, leg_width_m=0.10):
        out = bind0(self, dt, leg_width_m)
        out.n_short = max(1, int(round(WINDOW_S / dt)))
        out.m_short = max(1, math.ceil(self.m_fraction * out.n_short))
        return out

    def step(self, person, k):
        if step0(self, person, k):
            return True
        mem = person.confirm_memory
        ns = self.n_short
        if mem["age"] < ns:
            return False
        win = list(mem["win"])[-ns:]
        rs = [r for r in win if r is not None]
        if len(rs) < self.m_short:
            return False
        sub = {"win": deque(win), "world": deque(list(mem["world"])[-ns:]), "age": ns}
        world_known = len({c[0] for c in sub["world"] if c is not None}) == 1
        walk_asked = self.min_travel_m > 0 and world_known
        return self._legs_walk(rs) and (not walk_asked or self._walks(sub))

    MOfNMoving.bind, MOfNMoving.step = bind, step


def over(window_s: float) -> dict:
    if BOTH:                 # candidate 2: the shipped window, the short one patched in
        window_s = 1.4
    from gaitval.methods import get_method
    conf = dict(get_method("people")["kind"]["confirmer"])
    conf["window_s"] = window_s
    return {"kind__confirmer": conf}


def dev():
    from people_legs_confirm import dev_scores
    res = {}
    for w in (1.4, WINDOW_S):
        if BOTH and w == WINDOW_S:
            both_windows()
        t = dev_scores(over(w))
        res[w] = dict(zip(t["kind"], t["mota_pct"]))
        print(f"window {w} s: sum {t['mota_pct'].sum():.1f}  " + "  ".join(
            f"{r.kind} {r.mota_pct:.1f} (matched {r.matched}, fp {r.fp})"
            for r in t.itertuples()))
    a, b = res[1.4], res[WINDOW_S]
    ok = sum(b.values()) > sum(a.values()) and all(b[k] >= a[k] - 1.0 for k in a)
    print("development criterion holds:", ok)


def test(general: Path | None):
    from people_legs_confirm import empty_room_and_crowd_test
    if BOTH:
        both_windows()
    o = over(WINDOW_S)
    empty_room_and_crowd_test(o)
    outdoor = ROOT.parent / "shared" / "realdata" / "lrs" / "person_following_outdoor_1.bag"
    r = score_bag(outdoor, "/scan_base2", "people", o, None, "following_outdoor")
    print(f"3. outdoor people: matched {r['matched_ref']}, misses {r['fn']}, ID switches "
          f"{r['idsw_ref']}, MOTP {r['motp_m']:.3f} m")
    if general:
        for m in ("people", "people_offline"):
            r = score_bag(general, "/scan", m, o, (-80.0, 12.0), "general_moving")
            print(f"general_tracking_moving_1 {m}: matched {r['matched_ref']} of {r['gt']}, "
                  f"FP {r['fp']}, ID switches {r['idsw_ref']}, MOTA {100 * r['mota']:.1f} %")


def score_bag(bag, topic, method, o, sector, benchmark_set) -> dict:
    """legbench-track and legbench-evaluate in this process (so that candidate 2's patch
    applies), as the CLI runs them."""
    import json
    import tempfile

    from gaitval.pipeline.legbench import legbench_evaluate_step, legbench_track_step
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        cfg = d / "cfg.json"
        cfg.write_text(json.dumps({"tracking": {"overrides": {method: o}}}))
        legbench_track_step(bag, method, d / "t.parquet", scan_topic=topic, config_json=cfg)
        s = legbench_evaluate_step(d / "t.parquet", bag, d / "e",
                                   annotation_topic="/ground_truth_people_tracks",
                                   scan_topic=topic, sector_deg=sector,
                                   benchmark_set=benchmark_set)
    return s.iloc[0].to_dict()


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("stage", choices=["dev", "test"])
    ap.add_argument("--general", type=Path)
    ap.add_argument("--both", action="store_true", help="candidate 2")
    a = ap.parse_args()
    BOTH = a.both
    dev() if a.stage == "dev" else test(a.general)
