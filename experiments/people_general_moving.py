"""Why the online ``people`` method reports nobody in the benchmark's sector of a real
multi-person recording from a moving robot (issue 55).

Question (written before the first run)
---------------------------------------
``general_tracking_moving_1.bag`` (angusleigh/leg_tracker_benchmarks,
``benchmark_rosbags/annotated/``; no file of gaitval's had used it) is the kind of scene
issue 55 says the people tracker fails on: a wheelchair robot driving through a hall while
people cross its view for two or three seconds each.  Scored as the benchmark scores it
(bearings −80°…+12°, false positives counted), ``people`` and ``people_offline`` match 0 of
its 133 annotated person-scans and report nobody there (``gaitval legbench-track`` /
``legbench-evaluate --sector-deg -80 12``).  For every annotated person-scan in the sector
this script puts it in the first class that applies:

``no observation``   the detector gave no leg observation within 0.5 m of the annotation;
``no hypothesis``    observations, but no tentative or confirmed person within 0.75 m
                     (after the first run: with the birth flags of the observations within
                     0.5 m: ``taken`` / ``explained`` by a person, ``static``, ``free``;
                     and whether one or several observations lie within 0.8 m of it);
``tentative: T``     a tentative person within 0.75 m; T is the first confirmation test it
                     failed on that scan (of the hypotheses near, the one that got
                     furthest): ``young`` (fewer than N scans old), ``M of N`` (fewer than M
                     scans of the window saw both legs apart), ``legs do not pass``,
                     ``r span``, ``body walk`` (the world-frame steady walk), ``static``
                     (every test passed, a leg on a static cell);
``reported``         a confirmed or coasting person within 0.75 m.

It prints the classes and, per annotated person, its annotated scans, how long it was in
view and the classes of its scans.  It decides nothing by itself: the evidence goes into
the issue note, and any change it suggests needs development data other than this bag's
scores.

Usage::

    .venv/bin/python experiments/people_general_moving.py BAG [--odometry]

``--odometry``: the people method with the bag's wheel odometry (``/odom`` and the laser's
mount from ``/tf``) as its ``ego_motion`` instead of scan matching.
"""
from __future__ import annotations

import argparse
import collections
import math
import sys
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parent))

ORDER = ["young", "M of N", "legs do not pass", "r span", "body walk", "static", "pass"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bag", type=Path)
    ap.add_argument("--odometry", action="store_true")
    a = ap.parse_args()

    from gaitval.evaluate.clearmot import in_sector
    from gaitval.methods import build_method
    from gaitval.pipeline.legbench import read_positions, read_scans
    from gaitval.pipeline.steps.config import method_definition
    from gaitval.track import lifecycle as lc
    from gaitval.track import peoplepass as pp

    scans = read_scans(a.bag, "/scan", "general_tracking_moving_1")
    pos, _ = read_positions(a.bag, "/ground_truth_people_tracks", "/scan", scans.t, "g")
    pos = pos[in_sector(pos["x_m"], pos["y_m"], (-80.0, 12.0))].reset_index(drop=True)
    if a.odometry:
        from joint_leg_port import odom_laser_poses
        scans.meta["odometry"] = odom_laser_poses(a.bag, scans.t)

    # -- observe the confirmer: the first failed test of each tentative person per scan
    seen = collections.defaultdict(list)          # k -> [(centre, status/why)]
    WHY = {}
    step0 = lc.MOfNMoving.step

    def step(self, person, k):
        ok = step0(self, person, k)
        mem = person.confirm_memory
        win = mem["win"]
        if ok:
            why = "pass"
        elif len(win) < self.n:
            why = "young"
        else:
            rs = [r for r in win if r is not None]
            if len(rs) < self.m:
                why = "M of N"
            else:
                ux, uy = max(rs, key=lambda r: r[0] * r[0] + r[1] * r[1])
                nrm = math.hypot(ux, uy) or 1.0
                proj = [(r[0] * ux + r[1] * uy) / nrm for r in rs]
                w = self.pass_leg_widths * self.leg_width_m
                if min(proj) > -w or max(proj) < w:
                    why = "legs do not pass"
                elif not self._legs_walk(rs):
                    why = "r span"
                else:
                    why = "body walk"
        WHY[id(person)] = why
        return ok

    confirm0 = pp.PeoplePass._confirm

    def confirm(self, p):
        WHY.pop(id(p), None)
        confirm0(self, p)
        why = WHY.get(id(p)) or "young"
        if why == "pass" and p.status != lc.CONFIRMED:
            why = "static"
        seen[self.k].append((p.centre(), why if p.status == lc.TENTATIVE or
                             p.status == lc.ENDED else "reported"))

    record0 = pp.PeoplePass.record

    def record(self):
        for p in self.persons:
            if p.status in (lc.CONFIRMED, lc.COASTING):
                seen[self.k].append((p.centre(), "reported"))
        obs_k[self.k] = [tuple(o) for o in self.obs]
        record0(self)

    obs_k = {}
    flags_k = {}
    births0 = pp.PeoplePass.births

    def births(self):
        flags_k[self.k] = [("taken" if self.taken[j] else "explained" if self.explained[j]
                            else "static" if self.static[j] else "free")
                           for j in range(len(self.obs))]
        births0(self)

    pp.PeoplePass.births = births
    lc.MOfNMoving.step = step
    pp.PeoplePass._confirm = confirm
    pp.PeoplePass.record = record

    mdef = method_definition({}, "people")
    overrides = {"kind__ego_motion": "odometry"} if a.odometry else {}
    build_method(mdef, overrides).track(scans, 0.10)

    classes = collections.Counter()
    per = collections.defaultdict(list)
    for r in pos.itertuples():
        gx, gy = r.x_m, r.y_m
        near = [(c, w) for c, w in seen.get(r.k, [])
                if math.hypot(c[0] - gx, c[1] - gy) < 0.75]
        if any(w == "reported" for _, w in near):
            cl = "reported"
        elif near:
            best = max((w for _, w in near), key=lambda w: ORDER.index(w) if w in ORDER else -1)
            cl = f"tentative: {best}"
        elif any(math.hypot(o[0] - gx, o[1] - gy) < 0.5 for o in obs_k.get(r.k, [])):
            fl = [f for o, f in zip(obs_k[r.k], flags_k.get(r.k, []))
                  if math.hypot(o[0] - gx, o[1] - gy) < 0.5]
            n08 = sum(math.hypot(o[0] - gx, o[1] - gy) < 0.8 for o in obs_k[r.k])
            cl = "no hypothesis: " + "+".join(sorted(set(fl))) + \
                (", one observation" if n08 == 1 else ", several observations")
        else:
            cl = "no observation"
        classes[cl] += 1
        per[r.id].append((r.k, cl))
    print(f"annotated person-scans in the sector: {len(pos)}")
    for cl, n in classes.most_common():
        print(f"  {cl:28s} {n:4d}")
    print("per annotated person: scans annotated, first-last scan, seconds, classes")
    for pid, rows in sorted(per.items(), key=lambda kv: kv[1][0][0]):
        ks = [k for k, _ in rows]
        dur = float(scans.t[max(ks)] - scans.t[min(ks)])
        print(f"  {pid:>5s} {len(ks):3d}  {min(ks)}-{max(ks)}  {dur:4.1f} s  "
              + ", ".join(f"{c}×{n}" for c, n in collections.Counter(c for _, c in rows).most_common()))


if __name__ == "__main__":
    main()
