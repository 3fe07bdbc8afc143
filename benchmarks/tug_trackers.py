"""Scans per second of gaitval's TUG trackers vs a straightforward filterpy Kalman loop.

For every method (tug_m1..3) the tracker runs on the detector output of every TUG trial of
a study (default ``data/default``; the tiny study is generated into a temporary folder when
that is absent).  The reference is the same filtering done the plain way: per scan and
leg, a ``filterpy.kalman.KalmanFilter`` predict (A, B u, B Q Bᵀ of seed 000 eq. 1/8) and,
when the method associated an observation, an update (eq. 14–16) — no gating, association,
gait phases or interpolation, so the ratio is conservative.  For Method 3 a second line
also times the reference repeating the method's re-filtering passes (eq. 17: both legs
again from the step before each occlusion, ~40 % more filter steps on the default
study) — the like-for-like figure; the minimum on the last line stays the conservative
one.  Detection is timed separately (it is shared by all methods).  Times are medians
of ``--repeat`` runs.

Usage::

    .venv/bin/python benchmarks/tug_trackers.py [study_dir] [--repeat 5]

The last line is ``min speedup vs filterpy: <x>`` (the smallest ratio over the methods).
filterpy is a benchmark-only dependency (``pip install gaitval[bench]``).
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

from gaitval.detect import split_observations  # noqa: E402
from gaitval.io.scanlog import read_scanlog  # noqa: E402
from gaitval.methods import build_tracker, get_method  # noqa: E402

METHODS = ("tug_m1", "tug_m2", "tug_m3")


def load_trials(study: Path):
    trials = pd.read_csv(study / "trials.csv", dtype=str, keep_default_na=False)
    subs = pd.read_csv(study / "subjects.csv", dtype=str, keep_default_na=False)
    width = dict(zip(subs["subject"], subs["leg_width_m"].astype(float)))
    out = []
    for row in trials[trials["protocol"] == "tug"].itertuples(index=False):
        out.append((row.trial, read_scanlog(study / row.sensor_file), width[row.subject]))
    return out


def filterpy_loop(t, xy, res, q_sd, r_sd, p0_pos, p0_vel, refilter=False):
    """Plain per-step filterpy filtering of both legs with the tracker's associations.

    ``refilter=True`` also repeats Method 3's re-filtering passes (``res.refiltered``:
    both legs again from the step before the occlusion, virtual observations where the
    track was interpolated), keeping the per-step state history that needs: the same
    filtering work as the method, not only one pass.
    """
    from filterpy.kalman import KalmanFilter

    dt = float(np.median(np.diff(t)))
    A = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    B = np.array([[dt * dt / 2, 0], [0, dt * dt / 2], [dt, 0], [0, dt]])
    kfs = []
    k0 = max(res.k_init, 0)
    for f in (0, 1):
        kf = KalmanFilter(dim_x=4, dim_z=2, dim_u=2)
        kf.F, kf.B = A, B
        kf.Q = B @ (np.eye(2) * q_sd ** 2) @ B.T
        kf.H = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])
        kf.R = np.eye(2) * r_sd ** 2
        kf.P = np.diag([p0_pos ** 2] * 2 + [p0_vel ** 2] * 2)
        kf.x = np.array([res.x[f, k0], res.y[f, k0], 0.0, 0.0])
        kfs.append(kf)
    u = np.zeros(2)
    idx = res.obs_index
    redo: dict[int, list] = {}
    if refilter:
        for f, ka, kb in res.refiltered:
            redo.setdefault(kb, []).append((f, ka))
        hist = {k0: [(kf.x.copy(), kf.P.copy()) for kf in kfs]}

    def step(k):
        for f in (0, 1):
            kfs[f].predict(u=u)
            j = idx[f, k]
            if j >= 0:
                kfs[f].update(xy[k][j])
            elif refilter and res.interpolated[f, k]:
                kfs[f].update(np.array([res.x[f, k], res.y[f, k]]))   # virtual observation
        if refilter:
            hist[k] = [(kf.x.copy(), kf.P.copy()) for kf in kfs]

    for k in range(k0 + 1, len(t)):
        step(k)
        for f, ka in redo.get(k, ()):
            # Method 3 re-filters both legs from ka with the virtual observations (§5.4)
            for g in (0, 1):
                kfs[g].x, kfs[g].P = (a.copy() for a in hist[ka][g])
            for kk in range(ka + 1, k + 1):
                step(kk)
    return kfs


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
    if not trials:
        print("no TUG trials found")
        return 1
    n_scans = sum(s.n_scans for _, s, _ in trials)
    print(f"study {study}: {len(trials)} TUG trials, {n_scans} scans")

    det, _ = build_tracker("tug_m1")
    t0 = time.perf_counter()
    obs = [split_observations(det.detect(s, w), s.n_scans) for _, s, w in trials]
    t_det = time.perf_counter() - t0
    print(f"detection (shared): {n_scans / t_det:,.0f} scans/s")

    ratios = {}
    for m in METHODS:
        _, tracker = build_tracker(m)
        cfg = get_method(m)["filter"]
        ours, ref, ref2 = [], [], []
        n_refilter_steps = 0
        for _ in range(a.repeat):
            # trial by trial, ours then the reference, so machine-load drifts hit both alike
            t_o = t_r = t_r2 = 0.0
            n_refilter_steps = 0
            for (_, s, w), (xy, pats) in zip(trials, obs):
                t0 = time.perf_counter()
                res = tracker.run(s.t, xy, pats, w)
                t1 = time.perf_counter()
                args = (s.t, xy, res, cfg["q_accel_sd_mps2"], cfg["r_sd_m"],
                        cfg["p0_pos_sd_m"], cfg["p0_vel_sd_mps"])
                filterpy_loop(*args)
                t2 = time.perf_counter()
                if res.refiltered:
                    filterpy_loop(*args, refilter=True)
                t_o += t1 - t0
                t_r += t2 - t1
                t_r2 += time.perf_counter() - t2
                n_refilter_steps += sum(kb - ka for _, ka, kb in res.refiltered)
            ours.append(t_o)
            ref.append(t_r)
            ref2.append(t_r2)
        to, tr = float(np.median(ours)), float(np.median(ref))
        ratios[m] = tr / to
        print(f"{m}: gaitval {n_scans / to:,.0f} scans/s, filterpy loop {n_scans / tr:,.0f} "
              f"scans/s, speedup {ratios[m]:.2f}x  (median of {a.repeat})")
        if n_refilter_steps:
            tr2 = float(np.median(ref2))
            print(f"{m}: re-filtering repeats {n_refilter_steps} of {n_scans} steps; filterpy "
                  f"loop doing the re-filtering too: {n_scans / tr2:,.0f} scans/s, "
                  f"speedup {tr2 / to:.2f}x (like for like; not in the minimum below)")
    if tmp is not None:
        tmp.cleanup()
    print(f"min speedup vs filterpy: {min(ratios.values()):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
