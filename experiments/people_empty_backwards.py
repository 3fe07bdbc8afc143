"""Which hypotheses the people tracker confirms in the empty room read backwards, and what
its confirmer saw.

Question: ``negative_2.bag`` (a robot driving through a furnished room with nobody in it)
gives no confirmed person on any of its three lasers read forwards, but read backwards the
online ``people`` method confirms persons on ``/rear_scan`` and ``/right_scan``.  For each
confirmation on each laser and direction this script prints the scan, the person's body
centre in the sensor frame, and, on every scan of the confirmation window, the two
observations assigned to its legs in the ego-motion world frame (scan-matched poses), the
step of each leg since the previous scan, and the slower leg's speed on steps between
consecutive scans (a walker's stance leg stands while the other swings).

Criteria a candidate rule had to meet before adoption (written before the measurements):
it rejects every backward confirmation on every laser; it keeps ``positive_1.bag``'s
walker confirmed; it does not lower the online method's MOTA on any development scene
kind of the crowd benchmark (``gaitval legbench-crowd --split dev``).

Usage: ``.venv/bin/python experiments/people_empty_backwards.py [BAG]``
(default ``../shared/realdata/lrs/negative_2.bag``).
"""
from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
from gaitval.methods import build_method
from gaitval.track import peoplepass as pp
from gaitval.track.lifecycle import CONFIRMED

EVENTS: list[dict] = []
LEGS: dict[int, list] = {}
_confirm = pp.PeoplePass._confirm


def _spy(run, p):
    """The pass's confirmation step, recording both legs' world positions per scan."""
    before = p.status
    x0, y0, th = run.pose
    c, s = math.cos(th), math.sin(th)
    hist = LEGS.setdefault(id(p), [])
    if p.k_born == run.k:
        hist.clear()
    if p.seen[0] and p.seen[1]:
        hist.append((run.k, run.tk, [(x0 + c * z[0] - s * z[1], y0 + s * z[0] + c * z[1])
                                     for z in p.z]))
    _confirm(run, p)
    if p.status == CONFIRMED and before != CONFIRMED:
        win = [h for h in hist if h[0] > run.k - run.confirmer.n]
        EVENTS.append({"k": run.k, "born": p.k_born, "centre": p.centre(), "win": win,
                       "both_on_k": bool(p.seen[0] and p.seen[1])})


def report(tag: str, scans) -> None:
    EVENTS.clear()
    LEGS.clear()
    res = build_method("people").track(scans, 0.10)
    print(f"{tag}: confirmed {res.n_confirmed}, re-found {res.n_refound}")
    for e in EVENTS:
        cx, cy = e["centre"]
        print(f"  scan {e['k']} (born {e['born']}), centre ({cx:.2f}, {cy:.2f}) m, "
              f"both legs seen on the confirming scan: {e['both_on_k']}")
        prev = None
        for k, t, (lw, rw) in e["win"]:
            step = ""
            if prev is not None:
                dl, dr = math.dist(lw, prev[2][0]), math.dist(rw, prev[2][1])
                step = f"  step L {dl:.2f} R {dr:.2f} m"
                if k - prev[0] == 1:
                    step += f", slower leg {min(dl, dr) / (t - prev[1]):.2f} m/s"
            print(f"    k {k}: L ({lw[0]:.2f}, {lw[1]:.2f}) R ({rw[0]:.2f}, {rw[1]:.2f}){step}")
            prev = (k, t, (lw, rw))


def main(bag: Path) -> None:
    pp.PeoplePass._confirm = _spy
    for topic in describe_rosbag(bag)["scans"]:
        scans = read_rosbag_scans(bag, topic)
        t = np.asarray(scans.t, dtype=float)
        back = replace(scans, t=(t[0] + t[-1]) - t[::-1],
                       ranges=np.ascontiguousarray(scans.ranges[::-1]))
        report(f"{topic} forwards", scans)
        report(f"{topic} backwards (scan k is forward scan {len(t) - 1} - k)", back)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1
         else Path(__file__).resolve().parents[1] / ".." / "shared" / "realdata" / "lrs"
         / "negative_2.bag")
