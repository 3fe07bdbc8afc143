"""Scans per second of gaitval's MTST trackers (seed 001) vs a plain filterpy Kalman loop.

The same comparison as ``benchmarks/tug_trackers.py`` (whose ``filterpy_loop`` this reuses)
for ``mtst_m1``..``mtst_proposed``: every MTST trial of a study, the detector run once per
detector setting (timed separately), the tracker per method started on the mat's lane from
the simulator's sensor pose (``truth/sensor_pose.csv``, the registered pose in the
pipeline).  The reference does, per scan and leg, a filterpy ``KalmanFilter`` predict and,
when the method associated an observation, an update — no gating, association, phases or
UO pseudo-updates, so the ratio is conservative (it is the one on the last line).  A
second line per method times the reference doing the method's UO pseudo-updates too
(seed 001 §2.4.3: an update with the prediction as the observation wherever the leg is
UO), the like-for-like figure.  A third line times the method's initialiser alone
(``tracker.init.find`` on the same observations: the lane initialiser follows candidate
pairs over the first scans, work the reference does not do, since it starts from the
method's ``k_init``) and gives the like-for-like ratio without it.  Times are medians of
``--repeat`` runs.

Usage::

    .venv/bin/python benchmarks/mtst_trackers.py [study_dir] [--repeat 5]

The last line is ``min speedup vs filterpy: <x>`` (the bar: ≥ 3).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from tug_trackers import filterpy_loop  # noqa: E402

from gaitval.detect import split_observations  # noqa: E402
from gaitval.io.scanlog import read_scanlog  # noqa: E402
from gaitval.methods import build_tracker, get_method  # noqa: E402
from gaitval.track.observations import DetectionSeries  # noqa: E402
from gaitval.pipeline.mtst import mat_lane  # noqa: E402
from gaitval.evaluate.mtst_trial import DEFAULTS  # noqa: E402

METHODS = ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")


def filterpy_uo_loop(t, xy, res, q_sd, r_sd, p0_pos, p0_vel):
    """:func:`filterpy_loop` plus the pseudo-update of every UO step (same filtering work
    as ``uo_pseudo_update``)."""
    from filterpy.kalman import KalmanFilter

    dt = float(np.median(np.diff(t)))
    B = np.array([[dt * dt / 2, 0], [0, dt * dt / 2], [dt, 0], [0, dt]])
    kfs = []
    k0 = max(res.k_init, 0)
    for f in (0, 1):
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.F = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        kf.Q = B @ (np.eye(2) * q_sd ** 2) @ B.T
        kf.H = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])
        kf.R = np.eye(2) * r_sd ** 2
        kf.P = np.diag([p0_pos ** 2] * 2 + [p0_vel ** 2] * 2)
        kf.x = np.array([res.x[f, k0], res.y[f, k0], 0.0, 0.0])
        kfs.append(kf)
    idx = res.obs_index
    for k in range(k0 + 1, len(t)):
        for f in (0, 1):
            kfs[f].predict()
            j = idx[f, k]
            kfs[f].update(xy[k][j] if j >= 0 else kfs[f].x[:2].copy())
    return kfs


def load_trials(study: Path):
    trials = pd.read_csv(study / "trials.csv", dtype=str, keep_default_na=False)
    subs = pd.read_csv(study / "subjects.csv", dtype=str, keep_default_na=False)
    width = dict(zip(subs["subject"], subs["leg_width_m"].astype(float)))
    poses = pd.read_csv(study / "truth" / "sensor_pose.csv").set_index("trial")
    out = []
    for row in trials[trials["protocol"] == "mtst"].itertuples(index=False):
        p = poses.loc[row.trial]
        lane = mat_lane((p.x_m, p.y_m, p.yaw_rad), DEFAULTS["mat"])
        out.append((row.trial, read_scanlog(study / row.sensor_file), width[row.subject], lane))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", default=str(ROOT / "data" / "default"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)
    study = Path(a.study)
    tmp = None
    if not (study / "trials.csv").is_file():
        from gaitval.simulate import generate_study
        tmp = tempfile.TemporaryDirectory()
        study = Path(tmp.name) / "tiny"
        print(f"{a.study} has no trials.csv: generating the tiny study into {study}")
        generate_study(study, "tiny")
    trials = load_trials(study)
    n_scans = sum(s.n_scans for _, s, _, _ in trials)
    print(f"study {study}: {len(trials)} MTST trials, {n_scans} scans")
    obs = {}
    for fsu in (False, True):
        det, _ = build_tracker("mtst_m1" if not fsu else "mtst_m2")
        t0 = time.perf_counter()
        obs[fsu] = [split_observations(det.detect(s, w), s.n_scans) for _, s, w, _ in trials]
        print(f"detection (use_fs_u={fsu}): {n_scans / (time.perf_counter() - t0):,.0f} scans/s")
    ratios = {}
    for m in METHODS:
        spec = get_method(m)
        fsu = spec["detector"]["use_fs_u"]
        cfg = spec["filter"]
        ours, ref, ref2, init = [], [], [], []
        for _ in range(a.repeat):
            t_o = t_r = t_r2 = t_i = 0.0
            for (_, s, w, lane), (xy, pats) in zip(trials, obs[fsu]):
                _, tracker = build_tracker(m, {"init__lane": lane})
                t0 = time.perf_counter()
                res = tracker.run(s.t, xy, pats, w)
                t1 = time.perf_counter()
                args = (s.t, xy, res, cfg["q_accel_sd_mps2"], cfg["r_sd_leg_widths"] * w,
                        cfg["p0_pos_sd_m"], cfg["p0_vel_sd_mps"])
                filterpy_loop(*args)
                t2 = time.perf_counter()
                if spec["occlusion"]["name"] == "uo_pseudo_update":
                    filterpy_uo_loop(*args)
                t_o += t1 - t0
                t_r += t2 - t1
                t_r2 += time.perf_counter() - t2
                src = DetectionSeries(xy, pats)
                t3 = time.perf_counter()
                tracker.init.find(src, w)
                t_i += time.perf_counter() - t3
            ours.append(t_o)
            ref.append(t_r)
            ref2.append(t_r2)
            init.append(t_i)
        to, tr = float(np.median(ours)), float(np.median(ref))
        ratios[m] = tr / to
        print(f"{m}: gaitval {n_scans / to:,.0f} scans/s, filterpy loop {n_scans / tr:,.0f} "
              f"scans/s, speedup {ratios[m]:.2f}x  (median of {a.repeat})")
        tr2 = float(np.median(ref2))
        if tr2 > 0:
            print(f"{m}: filterpy loop doing the UO pseudo-updates too: {n_scans / tr2:,.0f} "
                  f"scans/s, speedup {tr2 / to:.2f}x (like for like; not in the minimum)")
            ti = float(np.median(init))
            print(f"{m}: of which the initialiser {ti * 1e3:.1f} ms ({ti / to:.0%}); like for "
                  f"like without it: speedup {tr2 / (to - ti):.2f}x (not in the minimum)")
    if tmp is not None:
        tmp.cleanup()
    print(f"min speedup vs filterpy: {min(ratios.values()):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
