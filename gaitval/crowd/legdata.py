"""Labelled scan clusters for a leg classifier: the twin's rendered scenes and leg_tracker's
positive bags, never a recording or a scene the benchmarks score (issue 55).

leg_tracker trains its forest on real clusters: legs from its positive bags, every cluster
of five negative bags (:mod:`gaitval.track.legforest`).  Four of those negative bags are
not available and the fifth, ``negative_2.bag``, is the empty-room test.  This module
collects training clusters elsewhere:

* **rendered** (:func:`twin_clusters`): scenes drawn as the crowd benchmark draws them
  (:func:`gaitval.crowd.scenes.draw_scene`, every scene kind: walls, tables, chairs, thin
  poles, a cane, walkers who cross, meet, stand and turn, a standing and a driving
  sensor), with the *training* seeds :data:`TRAIN_SEEDS` (the benchmark's scored scenes
  are seeds 11 and 23), each walker's shank half-width redrawn from
  :data:`TRAIN_LEG_RADIUS_M` (a slim bare shank to wide trousers).  Every scan is
  clustered as leg_tracker clusters (:func:`gaitval.track.legclusters.cluster_scan`);
  a cluster is a **leg** when at least :data:`MIN_ON_PERSON` of its returns hit one
  person's legs, **not a leg** when none hits a person, and left out otherwise (a leg
  merged with the background).  One scan in :data:`SCAN_STEP` is used (consecutive
  scans are nearly the same clusters);
* **real** (:func:`bag_clusters`): the six positive bags leg_tracker trains on
  (``positive_{1,2,3,4,6,7}_extracted.bag``): their annotated leg clusters
  (``loadPosData``) as legs, and every other cluster of the same scans as not legs (the
  room around the walker: walls, furniture, doors).

Everything is deterministic: the scenes are seeded, the bags are read in order.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from gaitval.crowd.scenes import KINDS, PERSON_ID0, draw_scene, render
from gaitval.track.legclusters import N_FEATURES, cluster_features, cluster_scan

#: the twin's training scenes: one scene of each kind per seed; never the benchmark's
#: development (11) or test (23) seeds
TRAIN_SEEDS = tuple(range(1001, 1009))
#: shank half-width at scan height, redrawn per training walker: a slim bare shank (0.04 m)
#: to wide trousers (0.08 m; the benchmark's scenes draw 0.045-0.065 m)
TRAIN_LEG_RADIUS_M = (0.04, 0.08)
#: a cluster is a leg when at least this share of its returns hit one person's legs
MIN_ON_PERSON = 0.8
#: one scan in this many is used (10 Hz scenes: 0.3 s apart)
SCAN_STEP = 3
#: leg_tracker's clustering (detect_leg_clusters.cpp: cluster_dist_euclid, min points)
CLUSTER_DIST_M, MIN_POINTS = 0.13, 3


def scan_labelled_clusters(ranges, hit_id, scans, thresh=CLUSTER_DIST_M,
                           min_points=MIN_POINTS):
    """Features (C, 17) and labels (+1 leg, −1 not a leg, 0 left out) of one rendered
    scan's clusters (module notes)."""
    a0, inc = float(scans.angle_min), float(scans.angle_increment)
    rmin, rmax = float(scans.range_min), float(scans.range_max)
    label, nc = cluster_scan(ranges, a0, inc, rmin, rmax, float(thresh), int(min_points))
    feats = np.zeros((nc, N_FEATURES))
    lab = np.zeros(nc, dtype=int)
    for c in range(nc):
        idx = np.flatnonzero(label == c)
        feats[c] = cluster_features(idx, ranges, a0, inc, rmin, rmax)
        ids = hit_id[idx].astype(int)
        person = np.where(ids >= PERSON_ID0, (ids - PERSON_ID0) // 2, -1)
        on = person >= 0
        if not on.any():
            lab[c] = -1
        else:
            top = np.bincount(person[on]).max()
            lab[c] = 1 if top >= MIN_ON_PERSON * len(idx) else 0
    return feats, lab


def training_scene(kind: str, seed: int):
    """A training scene of ``kind``: scans and the object hit by each beam."""
    if seed in (11, 23):
        raise ValueError("seeds 11 and 23 are the crowd benchmark's scored scenes")
    walks, furn, room, pose, t, rng, _ = draw_scene(kind, seed)
    wide = np.random.default_rng([seed, list(KINDS).index(kind), 55])
    for w in walks:
        w.radius_m = float(wide.uniform(*TRAIN_LEG_RADIUS_M))
    hits: dict = {}
    scans, _ = render(walks, furn, room, pose, t, rng, hits)
    return scans, hits["id"]


def twin_clusters(seeds=TRAIN_SEEDS, kinds=tuple(KINDS)) -> tuple[np.ndarray, np.ndarray]:
    """(leg features, non-leg features) of the rendered training scenes."""
    pos, neg = [], []
    for seed in seeds:
        for kind in kinds:
            scans, hit = training_scene(kind, seed)
            R = np.ascontiguousarray(scans.ranges, dtype=float)
            for k in range(0, R.shape[0], SCAN_STEP):
                f, lab = scan_labelled_clusters(R[k], hit[k], scans)
                pos.append(f[lab == 1])
                neg.append(f[lab == -1])
    return (np.vstack(pos).reshape(-1, N_FEATURES), np.vstack(neg).reshape(-1, N_FEATURES))


def bag_clusters(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(annotated leg clusters, the other clusters) of a leg_tracker positive bag's
    ``/training_scan`` (:func:`gaitval.track.legforest.labelled_clusters`)."""
    from gaitval.track.legforest import labelled_clusters
    return labelled_clusters(Path(path))


def training_set(leg_tracker_dir=None, seeds=TRAIN_SEEDS) -> dict[str, np.ndarray]:
    """Every training cluster: ``twin_pos``, ``twin_neg`` and, with a leg_tracker checkout
    (or a folder holding its positive bags), ``bag_pos``, ``bag_neg``."""
    from gaitval.track.legforest import POSITIVE_BAGS
    tp, tn = twin_clusters(seeds)
    out = {"twin_pos": tp, "twin_neg": tn}
    if leg_tracker_dir is not None:
        root = Path(leg_tracker_dir)
        sub = root / "rosbags" / "training_scans_res=0.33"
        root = sub if sub.is_dir() else root
        bp, bn = zip(*(bag_clusters(root / b) for b in POSITIVE_BAGS))
        out["bag_pos"], out["bag_neg"] = np.vstack(bp), np.vstack(bn)
    return out


def train_forest(data: dict[str, np.ndarray], name: str = "twin_and_bags"):
    """leg_tracker's forest (:func:`gaitval.track.legforest.train`, its recipe: 100 trees,
    depth ≤ 20, 2 features a split, seed 0) on every leg and every non-leg cluster of
    :func:`training_set`."""
    from gaitval.track.legforest import train
    pos = np.vstack([v for k, v in sorted(data.items()) if k.endswith("_pos")])
    neg = np.vstack([v for k, v in sorted(data.items()) if k.endswith("_neg")])
    return train(pos, neg, name=name)


if __name__ == "__main__":   # python -m gaitval.crowd.legdata LEG_TRACKER_CHECKOUT OUT.npz
    data = training_set(sys.argv[1])
    train_forest(data).save(sys.argv[2])
    print({k: len(v) for k, v in data.items()})
