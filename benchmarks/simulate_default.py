"""Generate the default simulated study and print its cost (the budget check of issue 3).

Usage::

    .venv/bin/python benchmarks/simulate_default.py            # into a temp dir
    .venv/bin/python benchmarks/simulate_default.py --out data/default

Prints per-protocol file counts and sizes; the last line is exactly
``default study: <seconds> s, <megabytes> MB`` (budget: ≤ 60 s on 2 cores, ≤ 600 MB).
"""
from __future__ import annotations

import argparse
import logging
import resource
import tempfile
import time
from pathlib import Path

import pandas as pd

from gaitval.simulate import generate_study


def _size_mb(paths) -> float:
    return sum(p.stat().st_size for p in paths if p.is_file()) / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="study folder (default: temp dir)")
    ap.add_argument("--preset", default="default")
    ap.add_argument("--seed", type=int, default=None)
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    logging.getLogger("gaitval.simulate.study").setLevel(logging.INFO)
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or Path(tmp) / "default"
        t0 = time.perf_counter()
        sheet = generate_study(out, args.preset, args.seed)
        dt = time.perf_counter() - t0
        trials = pd.read_csv(sheet, keep_default_na=False)
        for proto, g in trials.groupby("protocol", sort=True):
            files = [out / f for c in ("mocap_file", "sensor_file", "annotation_file")
                     for f in g[c] if f]
            print(f"{proto:10s} trials {len(g):4d}  raw files {_size_mb(files):8.1f} MB")
        truth = _size_mb((out / "truth").rglob("*"))
        total = _size_mb(out.rglob("*"))
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"truth/     {truth:8.1f} MB;  peak RSS {rss:.0f} MB")
        real = pd.read_csv(out / "realism.csv")
        with pd.option_context("display.width", 200, "display.max_columns", 30):
            print(real.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        print(f"default study: {dt:.1f} s, {total:.1f} MB")


if __name__ == "__main__":
    main()
