"""UKF steps per second on the treadmill trials, and the ratio to filterpy's UKF.

Usage::

    .venv/bin/python benchmarks/ultrasonic_ukf.py [STUDY_DIR] [--max-steps N]

STUDY_DIR defaults to ``data/default`` (the generated default study); when it has no
trial sheet the tiny ultrasonic preset is generated into a temporary folder.  Both filters
run the same model on the same ranges: constant velocity, TOA measurement, alpha = 1e-3,
beta = 2, kappa = 0, W = diag(30, 25, 10)^2, V = the paper's diag(11, 9.3, 9, 9) mm^2,
with the multipath gate and the planar-array mirror guard off and samples with a missing
echo treated as predict-only (filterpy's update cannot drop one anchor).  filterpy runs on the first ``--max-steps``
samples of each trial (it is slow); gaitval's filter runs on the whole trials and on that
same subset, and the figures printed are medians of repeated runs.  The last line is
``speedup vs filterpy: <x>`` (per-step time of filterpy / gaitval on the same samples).

filterpy is a benchmark-only dependency.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitval.io.ultrasonic import anchor_positions, log_distances  # noqa: E402
from gaitval.track.ukf import cv_matrices, run_toa_ukf, toa_ranges  # noqa: E402

W = np.array([30.0, 25.0, 10.0])
V = np.array([11.0, 9.3, 9.0, 9.0]) * 1e-6
GUESS = np.array([0.16, 0.10, -0.30])


def _load(study: Path, sheet: pd.DataFrame | None = None):
    from gaitval.io.ultrasonic import read_ultrasonic

    if sheet is None:
        sheet = pd.read_csv(study / "trials.csv", keep_default_na=False)
    rows = sheet[sheet["protocol"] == "treadmill"]
    logs = []
    for r in rows.itertuples():
        logs.append(read_ultrasonic(study / r.sensor_file, trial=r.trial))
    return logs


def _tiny(tmp: Path):
    from gaitval.simulate.ultrasonic import generate_ultrasonic

    sheet, _ = generate_ultrasonic(tmp, {"n_subjects": 2, "duration_s": 60.0,
                                         "n_pendulum_trials": 0}, seed=1)
    return _load(tmp, sheet)


def _prepare(log):
    d = log_distances(log)
    d[~np.all(np.isfinite(d), axis=1)] = np.nan          # predict-only rows for both filters
    A = anchor_positions(log.anchors)
    return np.asarray(log.t, float), d, A


def _ours(t, d, A):
    return run_toa_ukf(t, d, A, W_sigma=W, V=V, init_guess=GUESS, gate_sigma=np.inf,
                       mirror_guard=False).x


def _filterpy(t, d, A, x0):
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    pts = MerweScaledSigmaPoints(6, alpha=1e-3, beta=2.0, kappa=0.0)
    f = UnscentedKalmanFilter(6, 4, 0.02, lambda x: toa_ranges(x[:3], A),
                              lambda x, dt: cv_matrices(dt)[0] @ x, pts)
    f.x = x0.copy()
    f.P = np.diag([0.05 ** 2] * 3 + [1.0] * 3)
    f.R = np.diag(V)
    out = np.empty((len(t), 6))
    out[0] = x0
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        _, G = cv_matrices(dt)
        f.Q = G @ np.diag(W ** 2) @ G.T
        f.predict(dt=dt)
        if np.all(np.isfinite(d[k])):
            f.update(d[k])
        out[k] = f.x
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", default=str(ROOT / "data" / "default"))
    ap.add_argument("--max-steps", type=int, default=1500)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    study = Path(args.study)
    with tempfile.TemporaryDirectory() as tmp:
        if (study / "trials.csv").is_file():
            logs = _load(study)
            source = str(study)
        else:
            logs = _tiny(Path(tmp))
            source = "tiny ultrasonic preset (generated)"
    if not logs:
        raise SystemExit(f"no treadmill trials in {source}")
    data = [_prepare(lg) for lg in logs]
    n_all = sum(len(t) for t, _, _ in data)
    print(f"trials: {len(data)} treadmill trials from {source}, {n_all} samples")

    full = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        for t, d, A in data:
            _ours(t, d, A)
        full.append(time.perf_counter() - t0)
    med = statistics.median(full)
    print(f"gaitval UKF, all samples: median {med:.3f} s, {n_all / med:,.0f} steps/s")

    sub = [(t[:args.max_steps], d[:args.max_steps], A) for t, d, A in data]
    n_sub = sum(len(t) for t, _, _ in sub)
    ours_t, fp_t, diff = [], [], 0.0
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        xs = [_ours(t, d, A) for t, d, A in sub]
        ours_t.append(time.perf_counter() - t0)
    first = [np.flatnonzero(np.isfinite(x[:, 0]))[0] for x in xs]
    for _ in range(max(1, args.repeat - 1)):
        t0 = time.perf_counter()
        fps = [_filterpy(t[k:], d[k:], A, x[k]) for (t, d, A), x, k in zip(sub, xs, first)]
        fp_t.append(time.perf_counter() - t0)
    for x, f, k in zip(xs, fps, first):
        diff = max(diff, float(np.nanmax(np.abs(x[k:, :3] - f[:, :3]))))
    o, f = statistics.median(ours_t), statistics.median(fp_t)
    print(f"same {n_sub} samples: gaitval {n_sub / o:,.0f} steps/s "
          f"({o / n_sub * 1e6:.1f} us/step), filterpy {n_sub / f:,.0f} steps/s "
          f"({f / n_sub * 1e6:.1f} us/step)")
    print(f"largest position difference gaitval vs filterpy: {diff:.2e} m")
    print(f"speedup vs filterpy: {f / o:.1f}")


if __name__ == "__main__":
    main()
