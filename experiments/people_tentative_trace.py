"""Why leg_tracker's rules confirm crowd walkers that the online ``people`` method misses.

Question (issue 55, task 1): on the crowd benchmark's development scenes, per walker,
does ``leg_tracker_rules_no_classifier`` (gaitval/crowd/baseline.py) report it on more
scans than ``people``; and for one such walker, scan by scan, what do the two trackers'
tentative hypotheses on it do: which legs are assigned, how their confirmation evidence
grows, and why each hypothesis ends (``failed``: fewer than M of the last N scans saw
both legs; ``unsupported``: neither leg seen for the tentative time).  Both trackers
share the sensing, gates and association (baseline.py); they differ in the confirmer,
so the trace prints each one's state.

Nothing is decided by this script alone: it prints evidence.

Usage: ``.venv/bin/python experiments/people_tentative_trace.py KIND [WALKER]``
(KIND a crowd scene kind, dev seed; WALKER e.g. p2: the first walker whose reported
scans differ most when omitted).
"""
from __future__ import annotations

import math
import sys

import numpy as np

from gaitval.crowd import bench
from gaitval.crowd.scenes import DEV_SEEDS, make_scene
from gaitval.track import peoplepass as pp
from gaitval.track.lifecycle import ENDED, TENTATIVE

METHODS = ("leg_tracker_rules_no_classifier", "people")
#: ``people`` as it was when the question was asked: its tentative legs associated leg by
#: leg (``pair_swing_mps`` None; the pair rule was adopted after this trace)
OVERRIDES = {"people": {"kind__pair_swing_mps": None}}
NEAR_M = 0.5            # a hypothesis "on" the walker: centre this close to its midpoint
TRACE = {}              # method -> list of per-scan lines
_life = pp.PeoplePass.life_cycle


def _traced_life_cycle(run):
    """The pass's life cycle, noting why each tentative hypothesis near the walker ends."""
    before = [p for p in run.persons if p.status == TENTATIVE]
    state = {id(p): (p.seen[0], p.seen[1]) for p in before}
    _life(run)
    alive = {id(p) for p in run.persons}
    w = run._walker.get(run.k)
    if w is None:
        return
    out = []
    for p in before + [p for p in run.persons if p.status != TENTATIVE]:
        c = p.centre()
        if math.hypot(c[0] - w[0], c[1] - w[1]) > NEAR_M:
            continue
        mem = p.confirm_memory
        if isinstance(mem, dict) and "win" in mem:
            ev = f"both {sum(r is not None for r in mem['win'])}/{len(mem['win'])}"
        elif isinstance(mem, dict) and "path" in mem:
            ev = f"path {mem['path'][0]:.2f}/{mem['path'][1]:.2f}"
        else:
            ev = ""
        if id(p) not in alive or p.status == ENDED:
            why = "failed" if run.confirmer.failed(p) else "ended"
        else:
            why = p.status
        seen = state.get(id(p), (p.seen[0], p.seen[1]))
        d = [math.hypot(p.pos(f)[0] - w[2 + 2 * f], p.pos(f)[1] - w[3 + 2 * f])
             for f in (0, 1)]
        out.append(f"#{p.pid}:{'L' if seen[0] else '-'}{'R' if seen[1] else '-'} {ev} "
                   f"{why} legerr {min(d):.2f}/{max(d):.2f}")
    near = [j for j, (ox, oy) in enumerate(run.obs) if math.hypot(ox - w[0], oy - w[1]) <= NEAR_M]
    obs = " ".join(f"{'s' if run.static[j] else ''}{'t' if run.taken[j] else ''}"
                   f"{'e' if run.explained[j] else ''}o" for j in near)
    TRACE[run._method].append(f"k={run.k:3d} [{obs:8s}] "
                              + ("; ".join(out) if out else "(none)"))


def reported_scans(truth, hyp):
    """Per walker: scans with a reported hypothesis within 0.75 m of its midpoint."""
    out = {}
    for pid, g in truth.groupby("id"):
        n = 0
        for k, x, y in g[["k", "x_m", "y_m"]].itertuples(index=False):
            h = hyp[hyp["k"] == k]
            n += bool(len(h)) and bool(np.any(np.hypot(h["x_m"] - x, h["y_m"] - y)
                                              <= bench.MATCH_M))
        out[pid] = (len(g), n)
    return out


def walker_legs(sc, pid):
    """k -> (mid x, mid y, leg0 x, y, leg1 x, y) in the sensor frame (truth scans only)."""
    # the scene keeps the midpoint only: both "legs" are the midpoint
    g = sc.truth[sc.truth["id"] == pid]
    return {int(k): (x, y, x, y, x, y) for k, x, y in g[["k", "x_m", "y_m"]]
            .itertuples(index=False)}


def main(kind: str, walker: str | None = None) -> None:
    sc = make_scene(kind, DEV_SEEDS[0])
    res = {m: bench.tracker(m, OVERRIDES.get(m)).track(sc.scans, bench.LEG_WIDTH_M)
           for m in METHODS}
    per = {m: reported_scans(sc.truth, bench.hypotheses(r)) for m, r in res.items()}
    print(f"{sc.name}: per walker, visible scans / reported within 0.75 m")
    print("walker  visible  " + "  ".join(METHODS))
    for pid in sorted(per[METHODS[0]]):
        print(f"{pid:6s}  {per[METHODS[0]][pid][0]:7d}  "
              + "  ".join(f"{per[m][pid][1]:{len(m)}d}" for m in METHODS))
    if walker is None:
        walker = max(per[METHODS[0]], key=lambda p: per[METHODS[0]][p][1]
                     - per["people"][p][1])
    print(f"\ntrace of the hypotheses within {NEAR_M} m of {walker} "
          "[observations within "
          f"{NEAR_M} m: o, t taken by a leg, s on the static map, e in a reported "
          "person's gate] (L/R: legs assigned on the scan; legerr: leg estimates to the "
          "walker's midpoint, m)")
    wl = walker_legs(sc, walker)
    pp.PeoplePass.life_cycle = _traced_life_cycle
    for m in METHODS:
        TRACE[m] = []
        init = pp.PeoplePass.__init__

        def _init(self, *a, _m=m, _init=init, **kw):
            _init(self, *a, **kw)
            self._method, self._walker = _m, wl
        pp.PeoplePass.__init__ = _init
        bench.tracker(m, OVERRIDES.get(m)).track(sc.scans, bench.LEG_WIDTH_M)
        pp.PeoplePass.__init__ = init
    pp.PeoplePass.life_cycle = _life
    for m in METHODS:
        print(f"\n== {m} (first 40 visible scans)")
        for line in TRACE[m][:40]:
            print(line)


if __name__ == "__main__":
    main(*sys.argv[1:3])
