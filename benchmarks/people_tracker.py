"""Speed of the people tracker (issue 36 scope 5): real-time factor per laser, and the
cost of a scan against the number of people in view.

Usage::

    .venv/bin/python benchmarks/people_tracker.py [BAG[:TOPIC] ...] [--repeats 3]

Default: ``../shared/realdata/lrs/person_following_outdoor_1.bag`` (``/scan_base2``, the
benchmark bag) and the three lasers of ``negative_2.bag``.  For each laser, ``--repeats``
runs of detection + tracking (``build_method("people")``: the detector on the whole
recording, then the per-scan loop) on CPU time of this process
(``time.process_time``, so that the other jobs on a shared machine do not count), and the
real-time factor = recording span (last − first scan time + one period) / CPU seconds, the
median of the runs.  Then, from one profiled run, the per-scan cost of the loop
(``perf_counter`` around each scan) grouped by the number of reported people (confirmed
or coasting) and by the number of hypotheses alive (tentative ones too).
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
LRS = (ROOT / ".." / "shared" / "realdata" / "lrs").resolve()
DEFAULT = [f"{LRS / 'person_following_outdoor_1.bag'}:/scan_base2",
           f"{LRS / 'negative_2.bag'}:/left_scan", f"{LRS / 'negative_2.bag'}:/rear_scan",
           f"{LRS / 'negative_2.bag'}:/right_scan"]


def _split(arg: str):
    path, _, topic = arg.partition(".bag:")
    return (path + ".bag", topic or None) if topic or arg.endswith(".bag") else (arg, None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lasers", nargs="*", default=DEFAULT)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--method", default="people",
                    help="people (online) or people_offline (both passes)")
    args = ap.parse_args()
    from gaitval.detect.base import split_observations
    from gaitval.io.rosbag import read_rosbag_scans
    from gaitval.methods import build_method

    for arg in args.lasers:
        path, topic = _split(arg)
        scans = read_rosbag_scans(path, topic)
        d = np.diff(scans.t)
        span = float(scans.t[-1] - scans.t[0] + np.median(d[d > 0]))
        cpu = []
        for _ in range(args.repeats):
            kind = build_method(args.method)
            c0 = time.process_time()
            kind.track(scans, 0.10)
            cpu.append(time.process_time() - c0)
        med = statistics.median(cpu)
        name = f"{Path(path).name}{' ' + topic if topic else ''}"
        print(f"{name}: {scans.n_scans} scans, {span:.1f} s recorded, CPU "
              f"{', '.join(f'{c:.2f}' for c in cpu)} s -> real-time factor "
              f"{span / med:.1f}x (median of {args.repeats})")
        kind = build_method(args.method)
        xy, pats = split_observations(kind.detector.detect(scans, 0.10), scans.n_scans)
        res = kind.run(scans, xy, pats, 0.10, profile=True)
        people = res.people.groupby("k")["person_id"].nunique().reindex(
            range(scans.n_scans), fill_value=0).to_numpy()
        df = pd.DataFrame({"people": people, "hypotheses": res.scan_hypotheses,
                           "us": res.scan_seconds * 1e6})
        for col, bins in (("people", None), ("hypotheses", [0, 1, 3, 6, 10, 20, 40, 1000])):
            key = df[col] if bins is None else pd.cut(df[col], bins, right=False)
            g = df.groupby(key, observed=True)["us"].agg(["count", "median", "mean"])
            print(f"  per-scan loop cost (µs) by {col} in view:")
            for idx, r in g.iterrows():
                print(f"    {str(idx):>10}: {int(r['count']):5d} scans, median "
                      f"{r['median']:7.1f}, mean {r['mean']:7.1f}")


if __name__ == "__main__":
    main()
