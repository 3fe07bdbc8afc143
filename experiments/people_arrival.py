"""A person who walks in and stands: confirmation by arrival in free space (issue 36)

Written, with its criteria, before it was first run.

Why.  The people method confirms a pair only when it *walks* (``m_of_n_moving``), so a
person who steps into view and stands is never reported: on the outdoor benchmark bag the
longest run of misses (scans 2702–3191, docs/people.md *Results*) is the followed person
stepping in from the edge of the field of view and standing 1.1–1.3 m in front of the
robot.  Motion cannot tell a standing person from furniture, and gaitval's leg classifier
is too weak to (docs/people.md, *Appearance*).  One thing does tell them apart without a
classifier: **history**.  The place where a person now stands was free space a moment
ago — the scan saw through it — whereas a chair leg's cell is hit on every scan on which
the chair is in view and is never seen through.  This is change detection on an occupancy
grid (Wang, Thorpe & Thrun's DATMO: a return in a cell that was observed free belongs to
a moving object; leg_tracker's local map uses the same evidence the other way round, a
leg "in free space").

The rule (role ``arrival``, ``free_space``; ``gaitval/track/staticmap.py``).  A grid of
last-free times in the ego-motion role's world frame (a new grid where that frame
restarts): on every scan, each cell that a beam traverses up to ``margin_m`` before its
return, and that holds no return of that scan, gets the scan's time.  A tentative person
is confirmed by arrival when, on the current scan,

* both legs are observed, and both legs were observed on at least ``min_support_s`` worth
  of scans since the hypothesis was born (half the confirmation window: the window's M);
* for each leg, every cell of the (2n+1)² block around the observation was seen free
  within the last ``memory_s``;
* and neither leg is on a static cell (the existing rule for every confirmation).

The walking confirmer stays as it is; a person is confirmed when either rule says so.

Values, fixed before the first run (none from the outdoor bag):

* ``cell_m`` 0.1 m, ``neighbourhood`` 1 (3 × 3 cells): the static map's cell and
  neighbourhood (a leg's width; the scan-matching error);
* ``memory_s`` 5 s: the static map's memory τ (what the map still remembers);
* ``margin_m`` 0.2 m: the return's own cell and the one before it (range noise and the
  cell's discretisation) are not marked free;
* ``min_support_s`` 0.7 s: M = ⌈N/2⌉ of the 1.4 s window.

Criteria, stated before the first run.  ``arrival: free_space`` becomes part of
``METHODS["people"]`` only if

(a) with it, the people method confirms nobody and re-finds nobody on each of the three
    lasers of ``negative_2.bag`` (a robot driving through a furnished, empty room);
(b) the people tracker stays at least 20× real time on the outdoor bag
    (``benchmarks/people_tracker.py``, median of 3, the issue's speed target);
(c) the test suite passes unchanged apart from tests that name the people row's numbers.

The outdoor benchmark (``--outdoor``) is scored once, afterwards, for the record: it
decides nothing, and no value above is changed because of it.

    .venv/bin/python experiments/people_arrival.py [--outdoor]

References: Wang, C.-C.; Thorpe, C.; Thrun, S.; Hebert, M.; Durrant-Whyte, H.
Simultaneous localization, mapping and moving object tracking. IJRR 2007, 26, 889–916.
Leigh, A. et al. ICRA 2015 (leg_tracker's ``in_free_space``).
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
ARRIVAL = {"name": "free_space", "cell_m": 0.1, "neighbourhood": 1, "memory_s": 5.0,
           "margin_m": 0.2, "min_support_s": 0.7}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outdoor", action="store_true",
                    help="also score person_following_outdoor_1 once (decides nothing)")
    a = ap.parse_args()
    from gaitval.io.rosbag import read_rosbag_scans
    from gaitval.methods import build_method

    bag = SHARED / "negative_2.bag"
    if not bag.exists():
        sys.exit(f"{bag} is absent")
    print("(a) negative_2, persons confirmed + re-found (people | people + arrival):")
    for topic in NEGATIVE_TOPICS:
        scans = read_rosbag_scans(bag, topic)
        row = []
        for over in ({}, {"kind__arrival": ARRIVAL}):
            t0 = time.perf_counter()
            r = build_method("people", over).track(scans, 0.10)
            row.append(f"{r.n_confirmed}+{r.n_refound} ({time.perf_counter() - t0:.1f} s)")
        print(f"  {topic:12s} {scans.n_scans} scans   " + "  |  ".join(row))

    if a.outdoor:
        print("\nperson_following_outdoor_1, following mode (for the record; decides nothing):")
        for name, over in (("people", {}), ("people + arrival", {"kind__arrival": ARRIVAL})):
            print(f"  {name:18s}", score_outdoor(over))


if __name__ == "__main__":
    main()
