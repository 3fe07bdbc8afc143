"""Frames per second of gaitval's seed 002 particle filter vs the laser and vs Stone Soup.

gaitval's ``rollator_pf`` (two filters of N = 500 particles, seed 002 §III) runs over one
rollator trial's scans; the time per frame covers both legs' full step
(:meth:`~gaitval.track.pf.ParticleFilterTracker.step`, numpy but for the compiled
likelihood loop of :mod:`gaitval.track.pf_kernels`): the GMM propagation from the previous
estimate (§III.B), the laser-point likelihood (§III.C), the resample-move when N_eff < N/2
(§III.D) and the best-80 % estimate (§III.E).  The figures:

* the one-off cost per process, paid once by a ``rollator_track`` job before its first
  scan and not part of the frames/s: importing numba with the kernel module, and the first
  step, which loads the compiled likelihood from numba's cache (``__pycache__`` beside
  ``pf_kernels.py``; compiles it instead when there is no usable cache — the line says
  which);
* frames/s against the UBG-04LX-F01's scan rate (the trial's median period, ≈ 37 Hz):
  "× real time per leg pair" (the bar of issue 12 is ≥ 50×);
* frames/s of Stone Soup's ``ParticlePredictor`` + ``ParticleUpdater`` (with
  ``ESSResampler(SystematicResampler)`` at N/2) doing the same prediction and update: a
  transition model drawing the velocities from the same mixtures from the previous
  estimate, and a measurement model whose log-likelihood is the same (compiled) gaitval
  function, with the scan's points as the detection.  Stone Soup does no MH move here, so
  the comparison favours it.

Both run on the same scans with the same model.  Times are CPU seconds (``process_time``)
of the median of ``--repeat`` runs over ``--frames`` frames; wall time is printed too (on a
shared machine it is inflated by other processes, and CPU time somewhat too: two processes
on the cores of one machine slow each other's caches).

Usage::

    .venv/bin/python benchmarks/rollator_pf.py [study_dir] [--model model.json]
        [--frames 300] [--repeat 3]

``study_dir`` defaults to ``data/default`` (else the tiny study, generated into a temporary
folder).  ``--model`` defaults to ``results/<study>/rollator/model/<subject>.json`` when the
workflow has trained it, else the geometric placeholders.  The last line is
``speedup vs Stone Soup: <x>``.  Stone Soup is a benchmark-only dependency
(``pip install gaitval[bench]``).
"""
from __future__ import annotations

import argparse
import datetime
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitval.io.scanlog import read_scanlog  # noqa: E402
from gaitval.track.pf import ParticleFilterTracker, _Scan  # noqa: E402
from gaitval.track.pf_likelihood import PFArrays, likelihood, sample_velocities  # noqa: E402
from gaitval.track.pf_model import default_pf_model  # noqa: E402


def first_rollator_trial(study: Path):
    trials = pd.read_csv(study / "trials.csv", dtype=str, keep_default_na=False)
    subs = pd.read_csv(study / "subjects.csv", dtype=str, keep_default_na=False)
    row = trials[trials["protocol"] == "rollator"].iloc[0]
    width = float(subs.set_index("subject").loc[row["subject"], "leg_width_m"])
    return row, read_scanlog(study / row["sensor_file"]), width


def find_model(study: Path, subject: str, given: str | None, width: float):
    path = Path(given) if given else ROOT / "results" / study.name / "rollator" / "model" / \
        f"{subject}.json"
    if path.is_file():
        return json.loads(path.read_text()), str(path)
    return default_pf_model(width), "geometric placeholders (no trained model found)"


def run_gaitval(tracker: ParticleFilterTracker, P, scans, k0, p0, frames: int, dt: float):
    rng = np.random.default_rng(0)
    pts = _Scan(scans)
    prev = np.concatenate([p0, np.zeros((2, 2))], axis=1)
    for k in range(k0 + 1, k0 + 1 + frames):
        prev, _ = tracker.step(P, rng, pts, k, prev, dt)


def stonesoup_filters(P: PFArrays, p0, N: int, rng, t0):
    """Per leg: (predictor, updater, prior) doing seed 002's prediction and update."""
    from stonesoup.base import Property
    from stonesoup.models.measurement.base import MeasurementModel
    from stonesoup.models.transition.base import TransitionModel
    from stonesoup.predictor.particle import ParticlePredictor
    from stonesoup.resampler.particle import ESSResampler, SystematicResampler
    from stonesoup.types.array import StateVectors
    from stonesoup.types.state import ParticleState
    from stonesoup.updater.particle import ParticleUpdater

    class GMMFromEstimate(TransitionModel):
        """p = p̂_{k−1} + v Δt, v from the leg's mixture, p̂ the best-80% mean (§III.B/E)."""
        leg: int = Property()

        @property
        def ndim_state(self):
            return 4

        def function(self, state, noise=False, time_interval=None, **kwargs):
            w = np.exp(state.log_weight)
            best = w >= 0.8 * w.max()
            est = (state.state_vector[:2, best] @ w[best]) / w[best].sum()
            v = sample_velocities(P, rng, N)[self.leg]
            dt = time_interval.total_seconds()
            return StateVectors(np.vstack([est[0] + v[:, 0] * dt, est[1] + v[:, 1] * dt,
                                           v[:, 0], v[:, 1]]))

        def rvs(self, num_samples=1, **kwargs):
            raise NotImplementedError

        def pdf(self, state1, state2, **kwargs):
            raise NotImplementedError

    class LaserPoints(MeasurementModel):
        """log p(scan points | particle): gaitval's §III.C likelihood."""
        other: list = Property(doc="the other leg's estimate, updated by the caller")

        @property
        def ndim_meas(self):
            return 2

        def function(self, state, noise=False, **kwargs):
            return state.state_vector[:2]

        def rvs(self, num_samples=1, **kwargs):
            raise NotImplementedError

        def pdf(self, state1, state2, **kwargs):
            return np.exp(self.logpdf(state1, state2))

        def logpdf(self, state1, state2, **kwargs):
            X, Y = state1.metadata["points"]
            px = np.asarray(state2.state_vector[0], float).ravel()
            py = np.asarray(state2.state_vector[1], float).ravel()
            lik, _ = likelihood(P, px, py, X, Y, self.other[0], self.other[1])
            with np.errstate(divide="ignore"):
                return np.log(lik)

    out = []
    for f in (0, 1):
        mm = LaserPoints(ndim_state=4, mapping=(0, 1), other=list(p0[1 - f]))
        pred = ParticlePredictor(GMMFromEstimate(leg=f))
        upd = ParticleUpdater(mm, resampler=ESSResampler(threshold=N / 2,
                                                         resampler=SystematicResampler()))
        v = sample_velocities(P, rng, N, zero_mean=True)[f]
        sv = StateVectors(np.vstack([np.full(N, p0[f, 0]), np.full(N, p0[f, 1]), v.T]))
        prior = ParticleState(sv, log_weight=np.full(N, -np.log(N)), timestamp=t0)
        out.append([pred, upd, prior, mm])
    return out


def run_stonesoup(P, scans, k0, p0, frames: int, dt: float, N: int):
    from stonesoup.types.detection import Detection
    from stonesoup.types.hypothesis import SingleHypothesis

    rng = np.random.default_rng(0)
    t0 = datetime.datetime(2017, 5, 29)
    legs = stonesoup_filters(P, p0, N, rng, t0)
    pts = _Scan(scans)
    for i, k in enumerate(range(k0 + 1, k0 + 1 + frames)):
        ts = t0 + datetime.timedelta(seconds=(i + 1) * dt)
        posts = []
        for pred, upd, prior, mm in legs:
            det = Detection(np.zeros((2, 1)), timestamp=ts, measurement_model=mm,
                            metadata={"points": (pts.X[k], pts.Y[k])})
            posts.append(upd.update(SingleHypothesis(pred.predict(prior, timestamp=ts), det)))
        est = [np.asarray(p.mean[:2], float).ravel() for p in posts]
        for f, leg in enumerate(legs):
            leg[2] = posts[f]
            leg[3].other = list(est[1 - f])


def one_off_cost(tracker, P, scans, k0, p0, dt):
    """What a process pays once before its first PF step: importing numba and
    :mod:`gaitval.track.pf_kernels` (which imports numba), and the first step, which loads
    the compiled likelihood from numba's cache (or compiles it when there is no cache).

    Returns ``(import_cpu, import_wall, first_cpu, first_wall, how)`` in seconds; ``how``:
    "loaded from the cache" or "compiled (no usable cache)".
    """
    if "numba" in sys.modules:
        raise RuntimeError("numba was imported before the one-off cost was measured")
    c, w = time.process_time(), time.perf_counter()
    from gaitval.track import pf_kernels
    imp = (time.process_time() - c, time.perf_counter() - w)
    pts = _Scan(scans)
    prev = np.concatenate([p0, np.zeros((2, 2))], axis=1)
    c, w = time.process_time(), time.perf_counter()
    tracker.step(P, np.random.default_rng(0), pts, k0 + 1, prev, dt)
    first = (time.process_time() - c, time.perf_counter() - w)
    hits = sum(pf_kernels.region_likelihood.stats.cache_hits.values()) > 0
    return (*imp, *first, "loaded from the cache" if hits else "compiled (no usable cache)")


def timed(fn, repeat: int):
    cpu, wall = [], []
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return float(np.median(cpu)), float(np.median(wall))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", default=str(ROOT / "data" / "default"))
    ap.add_argument("--model", help="a trained PF model (JSON)")
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args(argv)
    study, tmp = Path(a.study), None
    if not (study / "trials.csv").is_file():
        from gaitval.simulate import generate_study
        tmp = tempfile.TemporaryDirectory()
        study = Path(tmp.name) / "tiny"
        print(f"{a.study} has no trials.csv: generating the tiny study into {study}")
        generate_study(study, "tiny")
    row, scans, width = first_rollator_trial(study)
    model, source = find_model(study, row["subject"], a.model, width)
    tracker = ParticleFilterTracker(model=model, seed=0)
    P = PFArrays(model)
    k0, p0 = tracker.start(scans, width)
    frames = min(a.frames, scans.n_scans - k0 - 1)
    dt = float(np.median(np.diff(scans.t)))
    N = tracker.n_particles
    print(f"trial {row['trial']} ({study}): {frames} frames from scan {k0}, N = {N} "
          f"particles per leg; model: {source}")
    print(f"laser: {1 / dt:.1f} scans/s (median period {dt * 1000:.1f} ms)")
    ic, iw, fc, fw, how = one_off_cost(tracker, P, scans, k0, p0, dt)
    print(f"one-off per process: import numba + gaitval.track.pf_kernels {ic:.2f} s CPU "
          f"({iw:.2f} s wall); first step, kernels {how}: {fc:.2f} s CPU ({fw:.2f} s wall)")
    g_cpu, g_wall = timed(lambda: run_gaitval(tracker, P, scans, k0, p0, frames, dt),
                          a.repeat)
    rows = [("gaitval rollator_pf (B-E, both legs)", g_cpu, g_wall)]
    try:
        import stonesoup  # noqa: F401
    except ImportError:            # an optional reference: the bar is against the laser
        s_cpu = None
        print("Stone Soup not installed (pip install stonesoup): its comparison skipped")
    else:
        s_cpu, s_wall = timed(lambda: run_stonesoup(P, scans, k0, p0, frames, dt, N),
                              max(1, a.repeat // 2))
        rows.append(("Stone Soup predict + update + ESS resampling", s_cpu, s_wall))
    for name, c, w in rows:
        print(f"{name}: {frames / c:8.1f} frames/s CPU = {frames / c * dt:6.1f}x real time "
              f"per leg pair ({frames / w:.1f} frames/s wall)")
    print(f"bar of issue 12: >= 50x real time per leg pair = {50 / dt:.0f} frames/s")
    if s_cpu is not None:
        print(f"speedup vs Stone Soup: {s_cpu / g_cpu:.2f}")
    if tmp is not None:
        tmp.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())
