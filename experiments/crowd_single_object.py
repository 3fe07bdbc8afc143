"""How often a walker is one object in the scan: the crowd twin beside a real crowd (issue 55).

Asked after ``people`` matched none of ``general_tracking_moving_1``'s annotated
person-scans (docs/crowd.md, *The twin beside a real crowd*), and decides nothing: per
person-scan, the number of leg_tracker's clusters (≥ 3 returns joined at 0.13 m) within
0.5 m of the person, over the person-scans with at least one there, on

* the real bag (all its annotations; ``BAG``, from angusleigh/leg_tracker_benchmarks,
  ``benchmark_rosbags/annotated/general_tracking_moving_1.bag.zip``, unzipped), and
* the crowd twin's development scenes (seed 11) of the moving and crossing kinds, their
  ground truth inside the benchmark's sector.

Usage::

    .venv/bin/python experiments/crowd_single_object.py BAG
"""
from __future__ import annotations

import collections
import sys

import numpy as np


def clusters_near(scans, k, x, y, radius=0.5):
    from gaitval.track.legclusters import scan_clusters
    cen, _ = scan_clusters(np.ascontiguousarray(scans.ranges[k]), float(scans.angle_min),
                           float(scans.angle_increment), float(scans.range_min),
                           float(scans.range_max), 0.13, 3)
    return int((np.hypot(cen[:, 0] - x, cen[:, 1] - y) < radius).sum()) if len(cen) else 0


def shares(counts):
    seen = sum(v for k, v in counts.items() if k >= 1)
    one = counts.get(1, 0)
    return f"{seen} person-scans with a cluster: one {100 * one / seen:.0f} %, " \
           f"two or more {100 * (seen - one) / seen:.0f} %"


def main(bag):
    from gaitval.crowd import bench
    from gaitval.crowd.scenes import DEV_SEEDS, make_scene
    from gaitval.evaluate.clearmot import in_sector
    from gaitval.pipeline.legbench import read_positions, read_scans
    scans = read_scans(bag, "/scan", "general_tracking_moving_1")
    pos, _ = read_positions(bag, "/ground_truth_people_tracks", "/scan", scans.t, "g")
    c = collections.Counter(clusters_near(scans, r.k, r.x_m, r.y_m) for r in pos.itertuples())
    print(f"real general_tracking_moving_1, all {len(pos)} annotations: {shares(c)}")
    for kind in ("crossing_moving", "crowd_moving", "crossing_static"):
        c = collections.Counter()
        for seed in DEV_SEEDS:
            sc = make_scene(kind, seed)
            tr = sc.truth[in_sector(sc.truth["x_m"], sc.truth["y_m"], bench.SECTOR_DEG)]
            c.update(clusters_near(sc.scans, r.k, r.x_m, r.y_m) for r in tr.itertuples())
        print(f"twin dev {kind}: {shares(c)}")


if __name__ == "__main__":
    main(sys.argv[1])
