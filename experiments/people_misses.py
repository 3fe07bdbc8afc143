"""Where the people tracker's misses on an annotated bag come from (issue 36).

Usage::

    .venv/bin/python experiments/people_misses.py BAG TOPIC FRAMES [--refind none]

``FRAMES``: the ``frames.parquet`` that ``gaitval legbench-evaluate`` wrote for a ``people``
track of the same bag and topic (one row per scan: the annotated position ``gt_x_m,
gt_y_m`` and the event, MATCH / SWITCH / MISS).  The tracker is run again with its
life-cycle roles observed (nothing in it changes), and every annotated scan the score
counts as a miss is put in one class, the first that applies:

``reported near``
    a confirmed or coasting person lies within 0.75 m (the scorer paired another one).
``no observation``
    the detector gave no leg observation within 0.75 m of the annotation.
``tentative: <test>``
    a tentative hypothesis lies within 0.75 m; <test> is the first confirmation test of
    :class:`gaitval.track.lifecycle.MOfNMoving` it failed at that scan (of the hypotheses
    near, the one that got furthest): ``young`` (alive for fewer than N scans), ``M of N``,
    ``legs do not pass``, ``gap``, ``body travel`` / ``body RMS`` (world frame), ``r span``,
    or ``static`` (all passed but a leg lies on a static cell).
``no hypothesis``
    observations, but no hypothesis near (they were explained, static, or unpaired).

For the misses whose first failed test is "legs do not pass", whether the hypothesis near
also fails the world-frame walk, has no known world frame over its window, or walks (the
test that v14 of experiments/people_gate.py let confirm alone): the first failed test is
not the only one.

Then every confirmed person that ended: the scan, why (``left the area`` / ``unsupported``),
how long it had been unseen, how far its last observed centre was from the annotation
(the latest click of the last 5 scans), and on how many of the annotated scans of the next 3 s a leg observation lay
within 0.75 m of the annotation (the person was still there to be seen); and the re-finds
(``refind`` role): on the annotated person (< 0.75 m) or elsewhere.

Then the runs of consecutive misses, longest first, with the annotation's mean range and
its path speed in the sensor frame (clicks included), on how many of its scans the
hypothesis nearest the annotation has *still* legs: r = p_L − p_R, over the confirmation
window's scans with both legs, spreads less than one leg width along its principal axis
(a walker's r swings through ± half a step; a person who stands keeps r), and on how many
every leg observation within 0.5 m of the annotation lay on a static cell of the tracker's
map (the map absorbed the person; ``PeopleResult.scan_static``).
"""
from __future__ import annotations

import argparse
import collections
import math

import numpy as np
import pandas as pd

ORDER = ["static", "r span", "body RMS", "body travel", "gap", "legs do not pass", "M of N",
         "young"]


def why_not(c, person) -> str:
    """The first confirmation test of ``c`` (a bound MOfNMoving) that ``person`` fails
    (the tests of ``MOfNMoving.step``, in its order)."""
    mem = person.confirm_memory
    win = mem["win"]
    if len(win) < c.n:
        return "young"
    rs = [r for r in win if r is not None]
    if len(rs) < c.m:
        return "M of N"
    ux, uy = max(rs, key=lambda r: r[0] * r[0] + r[1] * r[1])
    nrm = math.hypot(ux, uy)
    proj = [(r[0] * ux + r[1] * uy) / nrm for r in rs] if nrm > 0 else [0.0]
    w = c.pass_leg_widths * c.leg_width_m
    if min(proj) > -w or max(proj) < w:
        return "legs do not pass"
    world = mem["world"]
    if c.min_travel_m > 0 and len({x[0] for x in world if x is not None}) == 1:
        idx = [i for i, x in enumerate(world) if x is not None]
        if max(b - a - 1 for a, b in zip(idx[:-1], idx[1:])) > len(world) // 3:
            return "gap"
        cs = np.array([world[i][1:] for i in idx])
        ti = np.array(idx, float)
        A = np.column_stack([np.ones_like(ti), ti - ti.mean()])
        coef, *_ = np.linalg.lstsq(A, cs, rcond=None)
        if math.hypot(*(coef[1] * (ti[-1] - ti[0]))) < c.min_travel_m:
            return "body travel"
        if ((cs - A @ coef) ** 2).sum(axis=1).mean() > c.leg_width_m ** 2:
            return "body RMS"
    d2 = c.min_relative_travel_m ** 2
    if not any((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 >= d2
               for i, a in enumerate(rs) for b in rs[i + 1:]):
        return "r span"
    return "static"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bag")
    ap.add_argument("topic")
    ap.add_argument("frames")
    ap.add_argument("--refind", default=None,
                    help="the refind role (e.g. none: v4, without re-finding; default: the "
                         "method's)")
    args = ap.parse_args()
    from gaitval.detect.base import split_observations
    from gaitval.io.rosbag import read_rosbag_scans
    from gaitval.methods import build_method
    from gaitval.track import lifecycle as lc
    from gaitval.track.init_walking import principal_axis

    scans = read_rosbag_scans(args.bag, args.topic)
    kind = build_method("people", {"kind__refind": args.refind} if args.refind else None)
    xy, pats = split_observations(kind.detector.detect(scans, 0.10), scans.n_scans)
    seen = collections.defaultdict(list)            # k -> [(status, cx, cy, why)]
    why: dict[int, str] = {}                        # person id -> last failed test
    spread: dict[int, float] = {}                   # person id -> r spread in the window
    walk: dict[int, str] = {}                       # person id -> walk_state
    ended = kind.deleter.ended
    ends = []                                       # (k, pid, why, unseen s, last centre)
    refound = []                                    # (t, pid, centre)

    def observed_ended(p, k, tk, area):
        out = ended(p, k, tk, area)
        seen[k].append((p.status, *p.centre(), why.get(p.pid, "young"),
                        spread.get(p.pid), walk.get(p.pid)))
        if out and p.reported:
            ends.append((k, p.pid, out, tk - p.t_last_seen, p.seen_centre))
        return out

    rbind = lc.LegTrackerGate.bind

    def observed_rbind(self, dt):
        r = rbind(self, dt)
        match = r.match

        def observed_match(persons, t):
            out = match(persons, t)
            refound.extend((t, pid, p.centre()) for p, pid in out)
            return out
        r.match = observed_match
        return r

    bind = lc.MOfNMoving.bind

    def observed_bind(self, dt, leg_width_m=0.10):
        c = bind(self, dt, leg_width_m)
        step = c.step

        def observed_step(p, k):
            ok = step(p, k)
            why[p.pid] = "static" if ok else why_not(c, p)
            walk[p.pid] = walk_state(c, p)
            rs = [r for r in p.confirm_memory["win"] if r is not None]
            if len(rs) >= 2:
                ux, uy = principal_axis(rs)
                pr = [r[0] * ux + r[1] * uy for r in rs]
                spread[p.pid] = max(pr) - min(pr)
            return ok
        c.step = observed_step
        return c

    kind.deleter.ended = observed_ended
    lc.MOfNMoving.bind = observed_bind
    lc.LegTrackerGate.bind = observed_rbind
    try:
        res = kind.run(scans, xy, pats, 0.10, profile=True)
    finally:
        lc.MOfNMoving.bind = bind
        lc.LegTrackerGate.bind = rbind
    f = pd.read_parquet(args.frames)
    gt_all = f.set_index("k")[["gt_x_m", "gt_y_m"]]
    f = f[np.isfinite(f["gt_x_m"])]
    classes = collections.Counter()
    class_of = {}
    near_of = {}
    n_known = n_still = 0
    for r in f[f["event"] == "MISS"].itertuples():
        g = (r.gt_x_m, r.gt_y_m)
        near = [h for h in seen.get(int(r.k), []) if math.dist(h[1:3], g) < 0.75]
        o = xy[int(r.k)]
        if any(h[0] in (lc.CONFIRMED, lc.COASTING) for h in near):
            c = "reported near"
        elif not len(o) or np.hypot(o[:, 0] - g[0], o[:, 1] - g[1]).min() >= 0.75:
            c = "no observation"
        elif any(h[0] == lc.TENTATIVE for h in near):
            c = "tentative: " + min((getattr_why(h) for h in near if h[0] == lc.TENTATIVE),
                                    key=ORDER.index)
        else:
            c = "no hypothesis"
        classes[c] += 1
        class_of[int(r.k)] = c
        near_of[int(r.k)] = near
        hs = [h for h in near if h[4] is not None]
        if hs:
            n_known += 1
            n_still += min(hs, key=lambda h: math.dist(h[1:3], g))[4] < 0.10
    n = sum(classes.values())
    print(f"{n} misses of {len(f)} annotated scans")
    for c, k in classes.most_common():
        print(f"  {k:5d} ({100 * k / n:4.1f} %)  {c}")
    # the first failed test is not the only one: would the walk alone have passed?
    gait = [near_of[k] for k, c in class_of.items() if c == "tentative: legs do not pass"]
    states = collections.Counter(
        max((h[5] for h in hs if h[0] == lc.TENTATIVE and getattr_why(h) == "legs do not pass"),
            key=lambda w: WALK_RANK.get(w, -1), default=None) for hs in gait)
    print(f"  of the {len(gait)} 'legs do not pass' misses, the hypothesis near also fails "
          f"the walk on {states['no walk']}, has no known world frame over its window on "
          f"{states['world unknown']}, and walks (d_w steadily) on {states['walks']}")
    print(f"  on {n_still} of the {n_known} misses with a hypothesis near, its legs are still "
          "(r spread < w_l over 1.4 s)")
    # the confirmed persons that ended, and the re-finds
    dt0 = float(np.median(np.diff(scans.t)))
    print(f"{len(ends)} confirmed persons ended:")
    for k, pid, reason, unseen, c in ends:
        prev = gt_all.loc[max(0, k - 5):k].dropna()        # the latest click of the last 0.5 s
        d = (math.dist(c, (prev.iloc[-1].gt_x_m, prev.iloc[-1].gt_y_m)) if len(prev)
             else math.nan)
        nxt = gt_all.loc[k + 1:k + int(round(3.0 / dt0))].dropna()
        near = sum(len(xy[int(j)]) and np.hypot(xy[int(j)][:, 0] - r.gt_x_m,
                                                 xy[int(j)][:, 1] - r.gt_y_m).min() < 0.75
                   for j, r in nxt.iterrows())
        print(f"  scan {k} person {pid}: {reason} after {unseen:.1f} s unseen; last observed "
              f"centre ({c[0]:.2f}, {c[1]:.2f}) m, {d:.2f} m from the annotation; next 3 s: "
              f"{len(nxt)} annotated scans, {near} with a leg observation within 0.75 m")
    ts = np.asarray(scans.t, float)
    on = off = na = 0
    for t, pid, c in refound:
        g = gt_all.loc[int(np.argmin(np.abs(ts - t)))]
        if not np.isfinite(g.gt_x_m):
            na += 1
        elif math.dist(c, (g.gt_x_m, g.gt_y_m)) < 0.75:
            on += 1
        else:
            off += 1
    print(f"{len(refound)} re-finds: {on} on the annotated person, {off} further than 0.75 m "
          f"from it, {na} on scans without an annotation")
    # runs of consecutive misses
    miss = f[f["event"] == "MISS"]["k"].to_numpy()
    runs = np.split(miss, np.flatnonzero(np.diff(miss) != 1) + 1) if len(miss) else []
    by_k = f.set_index("k")
    dt = float(np.median(np.diff(scans.t)))
    nwin = max(2, int(round(1.4 / dt)))
    print(f"{len(runs)} runs of misses; the longest:")
    for run in sorted(runs, key=len, reverse=True)[:8]:
        g = by_k.loc[run[0]:run[-1]]
        gx, gy = g["gt_x_m"].to_numpy(), g["gt_y_m"].to_numpy()
        speed = np.hypot(np.diff(gx), np.diff(gy)).sum() / max(dt * (len(run) - 1), dt)
        # the hypothesis nearest the annotation: do its legs move against each other?
        still = known = 0
        for k, x, y in zip(g.index, gx, gy):
            hs = [h for h in seen.get(int(k), []) if math.dist(h[1:3], (x, y)) < 0.75
                  and h[4] is not None]
            if hs:
                known += 1
                still += min(hs, key=lambda h: math.dist(h[1:3], (x, y)))[4] < 0.10
        # the static map (hypothesis: it absorbs a person who stands): on how many scans do
        # all observations within 0.5 m of the annotation lie on static cells
        absorbed = 0
        for k, x, y in zip(g.index, gx, gy):
            o = xy[int(k)]
            near = np.flatnonzero(np.hypot(o[:, 0] - x, o[:, 1] - y) < 0.5) if len(o) else []
            absorbed += bool(len(near)) and all(res.scan_static[int(k)][j] for j in near)
        print(f"  scans {run[0]}-{run[-1]} ({len(run)}): range {np.hypot(gx, gy).mean():.2f} m,"
              f" annotation path speed {speed:.2f} m/s; nearest hypothesis's legs still "
              f"(r spread < w_l over 1.4 s) on {still} of {known} scans with one; every "
              f"observation within 0.5 m on a static cell on {absorbed}")
        print("    " + "; ".join(f"{c}: {n}" for c, n in collections.Counter(
            class_of[int(k)] for k in run).most_common()))


WALK_RANK = {"world unknown": 0, "no walk": 1, "walks": 2}


def walk_state(c, person) -> str | None:
    """Whether the body's steady walk in the world frame (``MOfNMoving._walks``, the test
    that v14 let confirm alone) holds over ``person``'s window: ``walks`` / ``no walk``, or
    ``world unknown`` (the window spans more than one ego-motion segment); None before the
    window is full or fails M of N."""
    mem = person.confirm_memory
    if len(mem["win"]) < c.n or sum(r is not None for r in mem["win"]) < c.m:
        return None
    segs = {x[0] for x in mem["world"] if x is not None}
    if len(segs) != 1:
        return "world unknown" if segs else "no walk"
    return "walks" if c._walks(mem) else "no walk"


def getattr_why(h) -> str:
    return h[3] if h[3] in ORDER else "young"


if __name__ == "__main__":
    main()
