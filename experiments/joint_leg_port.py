"""leg_tracker's Joint Leg tracker, ported line by line, on the outdoor bag and the empty room
(issue 55: is the published outdoor row reachable with the released materials?).

Question (written and committed before the first run)
-----------------------------------------------------
Issue 55 asks the online ``people`` method for ≥ 6,073 matched scans on
``person_following_outdoor_1.bag`` (following mode): leg_tracker's published Joint Leg row.
gaitval's ports of leg_tracker's *rules* inside its own people loop stop near 5,550
(docs/history/people.md), and 952 of ``people``'s 998 misses are three runs in which the
followed person stands 1.0-1.3 m in front of the robot from their first annotated scan.
This script ports leg_tracker's whole tracker instead, as its benchmark launch file for
this bag runs it (``person_following_outdoor_1_joint_leg.launch`` of
angusleigh/leg_tracker_benchmarks): ``joint_leg_tracker.py`` (one constant-velocity
Kalman filter per leg *and per person*, a person matched to up to two clusters, the path a
leg "travels" summed over filter steps longer than 0.01 m, a person confirmed from two
legs that each travelled 0.5 m since they were paired with one of them in free space),
``detect_leg_clusters.cpp`` (every cluster of ≥ ``min_points_per_cluster`` = 5 returns
within 10 m, with its forest P(leg)) and ``local_occupancy_grid_mapping.cpp`` (a log-odds
grid, 0.05 m cells, 400 a side, in ``fixed_frame`` = ``base_laser_link``, so the grid and
the "travel" are in the laser's frame, as the launch file sets them).  What is not
leg_tracker's: the forest, which is gaitval's re-training with leg_tracker's recipe
(``leg_tracker_bags``; the trained YAML is absent from the repository snapshot reachable
here), and the clusters' features (gaitval's port, ``gaitval/track/legclusters.py``).

It answers two questions, and decides only what goes into the issue note:

1. Outdoors, following mode, scored by gaitval's CLEAR-MOT code (the benchmark's rules):
   does the port reach 6,073 matched?  If it does (≥ 6,073), the published row is
   reachable with the released materials and the people method's shortfall is a design
   gap.  If it stays under 6,073, the published row is not reproduced by leg_tracker's own
   algorithm with the forest retrained here, which is evidence that the target rests on
   what is not available (its trained forest) or on the recording as it was then.
2. The empty room (``negative_2.bag``, each laser with the forest that did not see it,
   read forwards, ``min_points_per_cluster`` at leg_tracker's default 3 and the grid in the
   laser's frame, since no launch file of leg_tracker's runs this bag): how many persons
   does the same port confirm?  Reported, not judged: it
   says whether the design that scores outdoors would keep issue 55's empty room at 0.

3. (Added after 1 and 2 had run, before this variant ran.) The same port with
   leg_tracker's default ``fixed_frame`` = ``odom``: the tracks, the travelled paths and the
   grid (shifted by ``shift_threshold`` 0.5 m, the launch file's value) in a world frame,
   with gaitval's scan matching (``ScanMatching()``, its defaults) standing in for the
   odometry the bags do not carry; an unknown step is taken as no motion.  Reported on both
   recordings, not judged.

4. (Added after 3 had run: world frame outdoors 5,344 matched, empty room 2 / 6 / 3.)
   A real multi-person scene from a moving robot: ``general_tracking_moving_1.bag`` of
   angusleigh/leg_tracker_benchmarks (``benchmark_rosbags/annotated/*.bag.zip``; given on
   the command line, ``--general BAG``; no file of gaitval's has used it), scored as the
   benchmark scores its general sets (bearings −80°…+12°, false positives counted): the
   port as its launch file runs it (``fixed_frame`` odom, here gaitval's scan matching in
   its place; ``scan_frequency`` 7.5; ``publish_occluded`` false; ``min_points_per_cluster``
   3), beside the published Joint Leg row of the two moving bags together (MOTA 10.2 %).
   Reported, not judged; gaitval's own methods are scored on it with ``gaitval
   legbench-track`` / ``legbench-evaluate --sector-deg -80 12`` (the note gives the
   commands).

Nothing in gaitval's methods is changed by this script.

Usage::

    .venv/bin/python experiments/joint_leg_port.py [--outdoor] [--empty] [--world]
    .venv/bin/python experiments/joint_leg_port.py --general general_tracking_moving_1.bag
"""
from __future__ import annotations

import argparse
import copy
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment
from scipy.stats import norm

ROOT = Path(__file__).resolve().parents[1]
LRS = ROOT.parent / "shared" / "realdata" / "lrs"
OUTDOOR = LRS / "person_following_outdoor_1.bag"
NEGATIVE = LRS / "negative_2.bag"

# joint_leg_tracker.py defaults (KalmanMultiTracker.__init__)
MAX_LEG_PAIRING_DIST = 0.8
CONF_MAINTAIN = 0.1
DIST_TRAVELLED_TOGETHER = 0.5
IN_FREE_SPACE_THRESHOLD = 0.06
CONFIDENCE_PERCENTILE = 0.90
MAX_STD = 0.9
GATE = norm.ppf(1.0 - (1.0 - CONFIDENCE_PERCENTILE) / 2.0)
MAX_COV = MAX_STD ** 2
MAX_COST = 9999999.0
# local_occupancy_grid_mapping.cpp
ALPHA, BETA = 0.2, 0.1
OBSTACLE, FREE_SPACE, UNKNOWN, MIN_PROB = 0.7, 0.4, 0.5, 0.001
RES, WIDTH, RELIABLE_INF_RANGE = 0.05, 400, 10.0


def logit(p):
    return math.log(p / (1.0 - p))


class Track:
    """``ObjectTracked``: pykalman's ``filter_update`` is predict, then correct unless the
    observation is masked."""
    next_id = 1

    def __init__(self, x, y, confidence, is_person, in_free_space, dt, q_std):
        self.id_num = Track.next_id
        Track.next_id += 1
        self.seen_in_current_scan = True
        self.confidence = confidence
        self.dist_travelled = 0.0
        self.is_person = is_person
        self.deleted = False
        self.in_free_space = in_free_space
        self.var_obs = (0.1 + 0.4) ** 2
        self.F = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        self.Q = np.eye(4) * q_std ** 2
        self.R = np.eye(2) * 0.1 ** 2
        self.m = np.array([x, y, 0.0, 0.0])
        self.P = 0.5 * np.eye(4)
        self.pos = (x, y)

    def update(self, obs):
        m = self.F @ self.m
        P = self.F @ self.P @ self.F.T + self.Q
        if obs is not None:
            S = P[:2, :2] + self.R
            K = P[:, :2] @ np.linalg.inv(S)
            m = m + K @ (np.asarray(obs) - m[:2])
            P = P - K @ P[:2, :]
        self.m, self.P = m, P
        d = math.hypot(self.pos[0] - m[0], self.pos[1] - m[1])
        if d > 0.01:
            self.dist_travelled += d
        self.pos = (m[0], m[1])

    def cov(self):
        return self.P[0, 0] + self.var_obs


class Detect:
    __slots__ = ("x", "y", "confidence", "in_free_space", "in_free_space_bool")

    def __init__(self, x, y, confidence, in_free_space):
        self.x, self.y, self.confidence, self.in_free_space = x, y, confidence, in_free_space
        self.in_free_space_bool = in_free_space < IN_FREE_SPACE_THRESHOLD


class LocalGrid:
    """local_occupancy_grid_mapping.cpp with fixed_frame = the laser's frame: the laser at
    the grid centre, never shifted."""

    def __init__(self, n_beams, angle_min, inc, range_min, range_max):
        self.n_beams, self.angle_min, self.inc = n_beams, angle_min, inc
        self.cx = self.cy = None                         # grid centre (world frame)
        self._geometry(0.0, 0.0, 0.0)
        self.range_min, self.range_max = range_min, range_max
        self.l0, self.lmin, self.lmax = logit(UNKNOWN), logit(MIN_PROB), logit(1 - MIN_PROB)
        self.l = np.full((WIDTH, WIDTH), self.lmin)      # unseen_is_freespace
        self.data = None                                 # no map published yet

    def _geometry(self, lx, ly, yaw):
        if self.cx is None:
            self.cx, self.cy = lx, ly
        c = np.arange(WIDTH) * RES - (WIDTH / 2.0) * RES
        X, Y = np.meshgrid(c + self.cx - lx, c + self.cy - ly, indexing="ij")
        self.dist = np.hypot(X, Y)
        ang = np.mod(np.arctan2(Y, X) - yaw, 2 * np.pi)  # betweenPIandNegPI
        ang = np.where(ang < np.pi, ang, ang - 2 * np.pi)
        n, a0, inc = self.n_beams, self.angle_min, self.inc
        self.in_fov = (ang > a0 - inc / 2) & (ang < a0 + (n - 1) * inc + inc / 2)
        raw = np.round(ang / inc).astype(int) + n // 2
        self.beam = np.clip(raw, 0, n - 1)
        self.ang_rel = ang - np.round(ang / inc) * inc

    def move(self, lx, ly, yaw):
        """The laser's pose in the grid's frame for the next update (world frame); the
        grid is shifted by whole cells when the laser is more than 0.5 m from its centre."""
        if math.hypot(self.cx - lx, self.cy - ly) > 0.5:
            tx = -int(round((self.cx - lx) / RES))
            ty = -int(round((self.cy - ly) / RES))
            new = np.full((WIDTH, WIDTH), self.lmin)
            src_i = np.arange(WIDTH) + tx
            src_j = np.arange(WIDTH) + ty
            oi, oj = (src_i >= 0) & (src_i < WIDTH), (src_j >= 0) & (src_j < WIDTH)
            new[np.ix_(oi, oj)] = self.l[np.ix_(src_i[oi], src_j[oj])]
            self.l = new
            self.cx, self.cy = lx, ly
        self._geometry(lx, ly, yaw)

    def update(self, ranges_raw, is_human):
        r = ranges_raw[self.beam]
        finite = np.isfinite(r)
        valid = (finite & (r >= self.range_min) & (r <= self.range_max)) | (np.isposinf(r))
        unknown = (~self.in_fov) | (~valid) | (self.dist > self.range_max) | \
            (finite & (self.dist > r + ALPHA / 2)) | (np.abs(self.ang_rel) > BETA / 2) | \
            ((~finite) & (self.dist > RELIABLE_INF_RANGE))
        obstacle = finite & (r < self.range_max) & (np.abs(self.dist - np.where(finite, r, 0)) < ALPHA / 2) \
            & (~is_human[self.beam])
        upd = np.where(unknown, logit(UNKNOWN), np.where(obstacle, logit(OBSTACLE),
                                                          logit(FREE_SPACE)))
        self.l = np.clip(self.l + upd - self.l0, self.lmin, self.lmax)
        self.data = (np.exp(self.l) / (1 + np.exp(self.l)) * 100).astype(int)

    def how_much_in_free_space(self, x, y):
        if self.data is None:
            return IN_FREE_SPACE_THRESHOLD * 2
        mx = int(round((x - (self.cx - (WIDTH / 2.0) * RES)) / RES))
        my = int(round((y - (self.cy - (WIDTH / 2.0) * RES)) / RES))
        s = 0
        for i in range(mx - 2, mx + 2):
            for j in range(my - 2, my + 2):
                if not (0 <= i < WIDTH and 0 <= j < WIDTH):
                    return IN_FREE_SPACE_THRESHOLD * 2
                s += self.data[i, j]
        return s / (25.0 * 100.0)


def q_std_for(freq):
    for f, q in ((7.5, 0.06666), (10.0, 0.05), (15.0, 0.03333)):
        if abs(freq - f) < 0.01:
            return q
    raise ValueError(f"scan frequency {freq}: leg_tracker has no process noise for it")


def gnn(tracks, detects):
    matched = {}
    rows, elig = [], []
    for d in detects:
        row, any_in = [], False
        for t in tracks:
            if t.is_person and not d.in_free_space_bool:
                cost = MAX_COST
            else:
                cov = t.P[0, 0] + t.var_obs
                md = math.sqrt(((d.x - t.pos[0]) ** 2 + (d.y - t.pos[1]) ** 2) / cov)
                if md < GATE:
                    cost, any_in = md, True
                else:
                    cost = MAX_COST
            row.append(cost)
        if any_in:
            rows.append(row)
            elig.append(d)
    if rows:
        ri, ci = linear_sum_assignment(np.array(rows))
        for a, b in zip(ri, ci):
            if rows[a][b] < GATE:
                matched[id(tracks[b])] = (tracks[b], elig[a])
    return matched


def raw_ranges(bag, topic):
    """The scans' ranges as recorded (gaitval's reader maps every "no return" to NaN; the
    grid tells +inf, valid, from NaN and out-of-range values, not valid)."""
    from rosbags.highlevel import AnyReader
    with AnyReader([Path(bag)]) as r:
        conns = [c for c in r.connections if c.topic == topic]
        return np.array([np.asarray(r.deserialize(raw, c.msgtype).ranges, dtype=float)
                         for c, _, raw in r.messages(connections=conns)])


def chained_poses(scans):
    """The laser's pose per scan in one world frame: gaitval's scan matching, an unknown
    step taken as no motion."""
    from gaitval.track.staticmap import ScanMatching
    out, seg = ScanMatching().poses(scans)
    g = np.zeros_like(out)
    for k in range(1, len(out)):
        if seg[k] != seg[k - 1]:
            g[k] = g[k - 1]
            continue
        x0, y0, t0 = out[k - 1]
        c, s = math.cos(t0), math.sin(t0)
        dx, dy = out[k, 0] - x0, out[k, 1] - y0
        rx, ry, rt = c * dx + s * dy, -s * dx + c * dy, out[k, 2] - t0
        X, Y, T = g[k - 1]
        c, s = math.cos(T), math.sin(T)
        g[k] = (X + c * rx - s * ry, Y + s * rx + c * ry, T + rt)
    return g


def _to(pose, x, y):
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[0] + c * x - s * y, pose[1] + s * x + c * y


def _from(pose, x, y):
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = x - pose[0], y - pose[1]
    return c * dx + s * dy, -s * dx + c * dy


def run(scans, forest_name, raw, min_points=5, scan_frequency=10.0, max_detect=10.0,
        world=False, publish_occluded=True, poses=None):
    """Per scan, the published persons in the laser's frame: list of (id, x, y).
    ``world``: fixed_frame = a world frame from scan matching (question 3)."""
    if poses is None:
        poses = chained_poses(scans) if world else np.zeros((scans.n_scans, 3))
    world = world or poses.any()
    from gaitval.track.legclusters import scan_clusters
    from gaitval.track.legforest import load_forest
    forest = load_forest(forest_name)
    dt, q = 1.0 / scan_frequency, q_std_for(scan_frequency)
    a0, inc = float(scans.angle_min), float(scans.angle_increment)
    rmin, rmax = float(getattr(scans, "range_min", 0.0) or 0.0), float(scans.range_max)
    R = np.ascontiguousarray(scans.ranges, dtype=float)
    nb = R.shape[1]
    grid = LocalGrid(nb, a0, inc, rmin, rmax)
    Track.next_id = 1
    objects, pairs, pair_init = [], set(), {}
    out = []
    for k in range(R.shape[0]):
        ranges = R[k]
        cen, feats = scan_clusters(ranges, a0, inc, rmin, rmax, 0.13, min_points)
        p = forest.votes(feats) if len(feats) else np.zeros(0)
        dist = np.hypot(cen[:, 0], cen[:, 1]) if len(cen) else np.zeros(0)
        keep = dist < max_detect
        order = np.argsort(dist[keep], kind="stable")    # published closest first
        cen_k, p_k = cen[keep][order], p[keep][order]
        pose = poses[k]
        wxy = [_to(pose, float(x), float(y)) for x, y in cen_k]
        detects = [Detect(x, y, float(c), grid.how_much_in_free_space(x, y))
                   for (x, y), c in zip(wxy, p_k)]
        # propagate
        prop = copy.deepcopy(objects)
        for t in prop:
            t.update(None)
        dup = {}
        for i, t in enumerate(list(prop)):
            if t.is_person:
                c = copy.deepcopy(t)
                prop.append(c)
                dup[id(t)] = c
        matched = gnn(prop, detects)
        # non-leg clusters for the grid: detections not matched to a person
        leg_clusters = {id(d) for (t, d) in matched.values() if t.is_person}
        non_legs = [(d.x, d.y) for d in detects if id(d) not in leg_clusters]
        # update tracks
        to_delete = set()
        for idx, track in enumerate(objects):
            pt = prop[idx]
            md = None
            if pt.is_person:
                a, b = matched.get(id(pt)), matched.get(id(dup[id(pt)]))
                if a and b:
                    d1, d2 = a[1], b[1]
                    md = Detect((d1.x + d2.x) / 2, (d1.y + d2.y) / 2,
                                (d1.confidence + d2.confidence) / 2,
                                (d1.in_free_space + d2.in_free_space) / 2)
                elif a:
                    d1, o = a[1], dup[id(pt)]
                    md = Detect((d1.x + o.pos[0]) / 2, (d1.y + o.pos[1]) / 2,
                                d1.confidence, d1.in_free_space)
                elif b:
                    d1, o = b[1], pt
                    md = Detect((d1.x + o.pos[0]) / 2, (d1.y + o.pos[1]) / 2,
                                d1.confidence, d1.in_free_space)
            else:
                a = matched.get(id(pt))
                md = a[1] if a else None
            if md is not None:
                track.in_free_space = 0.8 * track.in_free_space + 0.2 * md.in_free_space
                track.confidence = 0.95 * track.confidence + 0.05 * md.confidence
                track.seen_in_current_scan = True
                track.update((md.x, md.y))
            else:
                track.seen_in_current_scan = False
                track.update(None)
            if track.is_person and track.confidence < CONF_MAINTAIN:
                to_delete.add(id(track))
            elif track.cov() > MAX_COV:
                to_delete.add(id(track))
        for track in objects:
            if id(track) in to_delete:
                track.deleted = True
        objects = [t for t in objects if not t.deleted]
        used = {id(d) for (_, d) in matched.values()}
        for d in detects:
            if id(d) not in used:
                objects.append(Track(d.x, d.y, d.confidence, False, d.in_free_space, dt, q))
        for t1 in objects:
            for t2 in objects:
                if (t1 is not t2 and t1.id_num > t2.id_num
                        and (not t1.is_person or not t2.is_person)
                        and (t1, t2) not in pairs):
                    pairs.add((t1, t2))
                    pair_init[(t1, t2)] = (t1.dist_travelled, t2.dist_travelled)
        to_del_pairs = set()
        for t1, t2 in sorted(pairs, key=lambda tp: (tp[0].id_num, tp[1].id_num)):
            d = math.hypot(t1.pos[0] - t2.pos[0], t1.pos[1] - t2.pos[1])
            if (d > MAX_LEG_PAIRING_DIST or t1.deleted or t2.deleted
                    or (t1.is_person and t2.is_person)
                    or t1.confidence < CONF_MAINTAIN or t2.confidence < CONF_MAINTAIN):
                to_del_pairs.add((t1, t2))
                continue
            if t1.seen_in_current_scan and t2.seen_in_current_scan:
                i1, i2 = pair_init[(t1, t2)]
                trav = min(t1.dist_travelled - i1, t2.dist_travelled - i2)
                if trav > DIST_TRAVELLED_TOGETHER and (
                        t1.in_free_space < IN_FREE_SPACE_THRESHOLD
                        or t2.in_free_space < IN_FREE_SPACE_THRESHOLD):
                    if not t1.is_person and not t2.is_person:
                        objects.append(Track((t1.pos[0] + t2.pos[0]) / 2,
                                             (t1.pos[1] + t2.pos[1]) / 2,
                                             (t1.confidence + t2.confidence) / 2, True,
                                             0.0, dt, q))
                        for t in (t1, t2):
                            t.deleted = True
                            objects.remove(t)
                    elif t1.is_person:
                        t2.deleted = True
                        objects.remove(t2)
                    else:
                        t1.deleted = True
                        objects.remove(t1)
                    to_del_pairs.add((t1, t2))
        pairs -= to_del_pairs
        for key in to_del_pairs:
            pair_init.pop(key, None)
        out.append([(t.id_num, *_from(pose, t.pos[0], t.pos[1]))
                    for t in objects if t.is_person
                    and (publish_occluded or t.seen_in_current_scan)])
        # the grid for the next scan: this scan and its non-leg clusters
        non_legs = [_from(pose, x, y) for x, y in non_legs]
        is_human = _human_beams(ranges, a0, inc, rmin, rmax, min_points, non_legs)
        if world:
            grid.move(*pose)
        grid.update(raw[k], is_human)
    return out


def _human_beams(ranges, a0, inc, rmin, rmax, min_points, non_legs):
    from gaitval.track.legclusters import cluster_scan
    label, nc = cluster_scan(ranges, a0, inc, rmin, rmax, 0.13, min_points)
    human = np.zeros(len(ranges), dtype=bool)
    nl = list(non_legs)
    for c in range(nc):
        idx = np.flatnonzero(label == c)
        a = a0 + idx * inc
        cx, cy = float(np.mean(np.cos(a) * ranges[idx])), float(np.mean(np.sin(a) * ranges[idx]))
        is_h = True
        for j, (x, y) in enumerate(nl):
            if math.hypot(cx - x, cy - y) < 0.1:
                nl.pop(j)
                is_h = False
                break
        human[idx] = is_h
    return human


def hyp_frame(out):
    rows = [(k, pid, x, y) for k, ps in enumerate(out) for pid, x, y in ps]
    return pd.DataFrame(rows, columns=["k", "hyp_id", "x_m", "y_m"])


def outdoor(world=False):
    from gaitval.evaluate.clearmot import clear_mot, following_counts
    from gaitval.pipeline.legbench import read_positions, read_scans
    scans = read_scans(OUTDOOR, "/scan_base2", "outdoor")
    freq = 1.0 / float(np.median(np.diff(scans.t)))
    print(f"outdoor: {len(scans.t)} scans, {freq:.2f} Hz (launch: scan_frequency 10)")
    raw = raw_ranges(OUTDOOR, "/scan_base2")
    assert raw.shape == scans.ranges.shape, (raw.shape, scans.ranges.shape)
    out = run(scans, "leg_tracker_bags", raw, min_points=5, scan_frequency=10.0,
              world=world)
    hyp = hyp_frame(out)
    pos, _ = read_positions(OUTDOOR, "/ground_truth_people_tracks", "/scan_base2",
                            scans.t, "outdoor")
    summary, events = clear_mot(pos, hyp, len(scans.t))
    f = following_counts(summary, events)
    print(f"Joint Leg port ({'world' if world else 'laser'} frame), outdoor following:",
          {k: f[k] for k in f})
    print("persons ever published:", hyp["hyp_id"].nunique())
    return f


def empty(world=False):
    from gaitval.pipeline.legbench import read_scans
    held = {"/left_scan": "without_left_scan", "/rear_scan": "without_rear_scan",
            "/right_scan": "without_right_scan"}
    for topic, forest in held.items():
        scans = read_scans(NEGATIVE, topic, "negative_2")
        freq = 1.0 / float(np.median(np.diff(scans.t)))
        f = min((7.5, 10.0, 15.0), key=lambda v: abs(v - freq))
        raw = raw_ranges(NEGATIVE, topic)
        assert raw.shape == scans.ranges.shape, (raw.shape, scans.ranges.shape)
        out = run(scans, forest, raw, min_points=3, scan_frequency=f, world=world)
        n = len({pid for ps in out for pid, _, _ in ps})
        print(f"empty room ({'world' if world else 'laser'} frame) {topic}: {len(scans.t)} scans at {freq:.2f} Hz (process noise "
              f"of {f} Hz), forest {forest}: persons confirmed {n}")


def odom_laser_poses(bag, scan_t, laser="left_laser"):
    """The laser's pose in /odom at each scan stamp: /tf's /odom -> /base_link, linearly
    interpolated, composed with base_link -> ``laser``."""
    from rosbags.highlevel import AnyReader
    odo, mount = [], None
    with AnyReader([Path(bag)]) as r:
        conns = [c for c in r.connections if c.topic == "/tf"]
        for c, _, raw in r.messages(connections=conns):
            for tr in r.deserialize(raw, c.msgtype).transforms:
                par, ch = tr.header.frame_id.strip("/"), tr.child_frame_id.strip("/")
                q = tr.transform.rotation
                yaw = 2 * math.atan2(q.z, q.w)
                if (par, ch) == ("odom", "base_link"):
                    st = tr.header.stamp
                    odo.append((st.sec + st.nanosec * 1e-9, tr.transform.translation.x,
                                tr.transform.translation.y, yaw))
                elif (par, ch) == ("base_link", laser) and mount is None:
                    mount = (tr.transform.translation.x, tr.transform.translation.y, yaw)
    o = np.array(sorted(odo))
    yaw = np.unwrap(o[:, 3])
    bx, by, bt = (np.interp(scan_t, o[:, 0], v) for v in (o[:, 1], o[:, 2], yaw))
    lx, ly = bx + np.cos(bt) * mount[0] - np.sin(bt) * mount[1], by + np.sin(bt) * mount[0] + np.cos(bt) * mount[1]
    return np.column_stack([lx, ly, bt + mount[2]])


def general(bag, odometry=False):
    from gaitval.evaluate.clearmot import clear_mot, in_sector
    from gaitval.pipeline.legbench import read_positions, read_scans
    scans = read_scans(bag, "/scan", "general_tracking_moving_1")
    raw = raw_ranges(bag, "/scan")
    assert raw.shape == scans.ranges.shape, (raw.shape, scans.ranges.shape)
    poses = odom_laser_poses(bag, scans.t) if odometry else None
    out = run(scans, "leg_tracker_bags", raw, min_points=3, scan_frequency=7.5, world=True,
              publish_occluded=False, poses=poses)
    hyp = hyp_frame(out)
    pos, _ = read_positions(bag, "/ground_truth_people_tracks", "/scan", scans.t, "g")
    pos, hyp = (d[in_sector(d["x_m"], d["y_m"], (-80.0, 12.0))].reset_index(drop=True)
                for d in (pos, hyp))
    summary, _ = clear_mot(pos, hyp, len(scans.t))
    print(f"Joint Leg port ({'odometry' if odometry else 'scan matching'}), "
          "general_tracking_moving_1, -80..12 deg:",
          {k: summary[k] for k in ("mota", "motp_m", "idsw", "matches", "fn", "fp", "gt")})


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--outdoor", action="store_true")
    ap.add_argument("--empty", action="store_true")
    ap.add_argument("--world", action="store_true", help="question 3")
    ap.add_argument("--general", type=Path, help="question 4: general_tracking_moving_1.bag")
    ap.add_argument("--odometry", action="store_true",
                    help="question 4 with the bag's own /odom (and its tf mount) as fixed frame")
    a = ap.parse_args()
    if a.general:
        general(a.general, a.odometry)
        sys.exit(0)
    if a.outdoor or not a.empty:
        outdoor(a.world)
    if a.empty or not a.outdoor:
        empty(a.world)
    sys.exit(0)
