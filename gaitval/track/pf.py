"""Seed 002's particle-filter leg tracker: one filter of N particles per leg (§III A–E).

Tracker kind ``rollator_pf`` (:class:`ParticleFilterTracker`), a
:class:`~gaitval.track.kinds.RawScanTracker`: it reads the raw laser points and returns
the same :class:`~gaitval.track.leg.TrackResult` as the Kalman-filter trackers.

Per scan (seed 002 §III; parameters learned by :mod:`gaitval.track.pf_model`):

A. Initialisation, at the first scan where the §II detector (window, grouping, K-means,
   circle fit) finds a pair of legs (:class:`~gaitval.track.reinit.FacingPair` labels
   them): every particle of a leg sits on its detection, with a velocity drawn from the
   zero-mean mixture, weights 1/N; the estimate is the weighted mean.  The detector is
   never used again.
B. Propagation: N velocities per leg from the leg's 2-component Gaussian mixture;
   p_k^i = p̂_{k−1} + v_k^i Δt from the leg's *previous estimate* p̂_{k−1}, as §III.B
   prints it (the alternative, each particle from its own previous position, is not what
   the text says).  Δt is the scan period (a gap of n periods is one step of n·Δt).
C. Weights ω^i = p(y^i | x^i) (:func:`~gaitval.track.pf_likelihood.likelihood`),
   normalised per leg; when every weight of a leg is 0 (no laser point near any particle)
   the weights stay uniform: the filter predicts.
D. When N_eff = 1/Σω̂² < N/2 for a leg: systematic resampling (the SIR step §III.D names),
   then a random walk on each particle's velocity (the position follows,
   p = p̂_{k−1} + v Δt, so the move stays on the propagation's support), re-weighting, and a
   Metropolis–Hastings accept/reject per particle with probability min(1, ω*/ω): the
   resample-move scheme §III.D describes to undo SIR's impoverishment.  The kept pairs
   (x, ω) carry their own likelihoods into E.
E. Estimate: the weighted mean (position and velocity) of the particles with
   ω ≥ 0.8·max ω.

All random draws come from one ``numpy.random.Generator`` seeded with ``seed``: the same
seed, input and machine give the same track, bit for bit.  The steps are numpy, but for
the likelihood's loop over particle–point pairs, compiled with numba
(:mod:`gaitval.track.pf_kernels`, imported at the first likelihood, so that importing this
module — every tracking job does — does not import numba).

Output columns as every tracker's: ``observed`` (and pattern ``SL``) when some particle of
the leg had laser points in its window, else ``UO``; ``phase`` from seed 000's speed
thresholds on the estimates (for the table's completeness; the PF does not use it).

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017, §III.
Arulampalam MS, Maskell S, Gordon N, Clapp T. A tutorial on particle filters for online
nonlinear/non-Gaussian Bayesian tracking. IEEE Trans. Signal Process. 2002, 50(2), 174-188.
Gilks WR, Berzuini C. Following a moving target — Monte Carlo inference for dynamic Bayesian
models. J. R. Stat. Soc. B 2001, 63(1), 127-146.
"""
from __future__ import annotations

import numpy as np

from gaitval.detect import DETECTORS
from gaitval.errors import ConfigError
from gaitval.track.init import INITIALISERS
from gaitval.track.kinds import RawScanTracker
from gaitval.track.leg import TrackResult, empty_result
from gaitval.track.observations import WindowedDetections
from gaitval.track.pf_likelihood import PFArrays, likelihood, sample_velocities
from gaitval.track.pf_model import default_pf_model
from gaitval.track.phase import PHASE_MODELS
from gaitval.track.tracker import step_durations

#: the §II detector the PF is initialised with (same as ``rollator_kf``'s)
DEFAULT_DETECTOR = {"name": "rollator_window"}
DEFAULT_INIT = {"name": "facing_pair"}


class _Scan:
    """The scan's Cartesian points (polar → Cartesian once per trial)."""

    def __init__(self, scans):
        a = scans.angles
        with np.errstate(invalid="ignore"):
            self.X = scans.ranges * np.cos(a)
            self.Y = scans.ranges * np.sin(a)


class ParticleFilterTracker(RawScanTracker):
    """Two particle filters, one per leg, on raw laser points (module notes).

    Parameters
    ----------
    model : dict or None
        The learned parameters (:func:`gaitval.track.pf_model.train_pf_model`); None:
        :func:`~gaitval.track.pf_model.default_pf_model` for the subject's leg width.
    n_particles : int
        N per leg (seed 002: 500).
    seed : int or sequence of int
        Seed of the ``numpy.random.Generator`` every draw comes from.
    best_fraction : float
        §III.E: particles with ω ≥ best_fraction · max ω form the estimate (0.8).
    resample_fraction : float
        §III.D: resample-move when N_eff < resample_fraction · N (0.5).
    detector, init : dict
        The §II detector and the pair rule of the initialisation (§III.A).
    dt_s : float or None
        Scan period; None: the median timestamp difference.
    """

    def __init__(self, model: dict | None = None, n_particles: int = 500, seed=0,
                 best_fraction: float = 0.8, resample_fraction: float = 0.5,
                 detector: dict | None = None, init: dict | None = None,
                 dt_s: float | None = None):
        if int(n_particles) < 2:
            raise ConfigError(f"rollator_pf: n_particles must be ≥ 2, got {n_particles!r}")
        if not 0.0 < float(best_fraction) <= 1.0:
            raise ConfigError(f"rollator_pf: best_fraction must be in (0, 1], got "
                              f"{best_fraction!r}")
        self.model = model
        self.n_particles = int(n_particles)
        self.seed = seed
        self.best_fraction = float(best_fraction)
        self.resample_fraction = float(resample_fraction)
        self.detector = detector or dict(DEFAULT_DETECTOR)
        self.init = init or dict(DEFAULT_INIT)
        self.dt_s = dt_s

    def start(self, scans, leg_width_m: float):
        """§III.A: ``(k0, (2, 2) leg positions)`` from the §II detector, or None."""
        source = WindowedDetections(DETECTORS.build(self.detector), scans, leg_width_m)
        found = INITIALISERS.build(self.init).find(source, leg_width_m)
        if found is None:
            return None
        k0, il, ir = found
        obs = source.array(k0)
        return k0, obs[[il, ir]]

    def track(self, scans, leg_width_m) -> TrackResult:
        P = PFArrays(self.model if self.model is not None else default_pf_model(leg_width_m))
        rng = np.random.default_rng(self.seed)
        res = empty_result(scans.t)
        begun = self.start(scans, leg_width_m)
        if begun is None:
            return res
        k0, p0 = begun
        n, N = scans.n_scans, self.n_particles
        dts = step_durations(scans.t, self.dt_s)[1] if n > 1 else np.array([0.0])
        est = np.full((n, 2, 4), np.nan)
        seen = np.zeros((n, 2), bool)
        v = sample_velocities(P, rng, N, zero_mean=True)             # §III.A
        est[k0, :, :2] = p0                                           # positions = detections
        est[k0, :, 2:] = v.mean(axis=1)                               # MMSE, ω = 1/N
        seen[k0] = True
        pts = _Scan(scans)
        for k in range(k0 + 1, n):
            est[k], seen[k] = self.step(P, rng, pts, k, est[k - 1], float(dts[k]))
        return self._result(res, est, seen, k0)

    def step(self, P: PFArrays, rng, pts: _Scan, k: int, prev: np.ndarray, dt: float):
        """One scan for both legs: B (propagate), C (weigh), D (resample-move), E.

        The draws come from ``rng`` in the order B (component uniforms, normals), D (one
        systematic-resampling uniform per leg, the walk's normals, the MH uniforms).
        Returns the (2, 4) estimate (x, y, vx, vy per leg) and whether each leg saw points.
        """
        N = self.n_particles
        X, Y = pts.X[k], pts.Y[k]
        v = sample_velocities(P, rng, N)                              # §III.B, (2, N, 2)
        lik, cnt = _weigh(P, prev, v, dt, X, Y, (0, 1))               # §III.C
        w = _normalise(lik)
        need = np.flatnonzero(1.0 / np.sum(w * w, axis=1)             # N_eff, §III.D
                              < self.resample_fraction * N)
        if need.size:                                                 # §III.D
            u_res = rng.random(need.size)
            z_walk = rng.standard_normal((need.size, N, 2))
            u_mh = rng.random((need.size, N))
            idx = np.stack([systematic_resample(w[f], u_res[r]) for r, f in enumerate(need)])
            v_old = np.take_along_axis(v[need], idx[..., None], axis=1)
            lik_old = np.take_along_axis(lik[need], idx, axis=1)
            v_new = v_old + z_walk * P.walk_sd                        # random walk on v
            lik_new, _ = _weigh(P, prev, v_new, dt, X, Y, need)
            accept = (lik_old <= 0.0) | (u_mh * lik_old < lik_new)    # u < ω*/ω (MH)
            v[need] = np.where(accept[..., None], v_new, v_old)
            lik[need] = np.where(accept, lik_new, lik_old)
            w[need] = _normalise(lik[need])
        pos = prev[:, None, :2] + v * dt                              # p = p̂_{k−1} + v Δt
        best = w >= self.best_fraction * w.max(axis=1, keepdims=True)  # seed002 §III.E
        ws = np.where(best, w, 0.0)
        ws /= ws.sum(axis=1, keepdims=True)
        est = np.concatenate([np.einsum("ln,lnj->lj", ws, pos),
                              np.einsum("ln,lnj->lj", ws, v)], axis=1)
        return est, cnt.max(axis=1) > 0

    def _result(self, res: TrackResult, est: np.ndarray, seen: np.ndarray, k0: int):
        res.k_init = k0
        res.x[:, k0:], res.y[:, k0:] = est[k0:, :, 0].T, est[k0:, :, 1].T
        res.vx[:, k0:], res.vy[:, k0:] = est[k0:, :, 2].T, est[k0:, :, 3].T
        res.observed[:, k0:] = seen[k0:].T
        res.pattern[:, k0:] = np.where(seen[k0:].T, "SL", "UO")   # points weighed / none
        phase = PHASE_MODELS.build("speed_thresholds")
        res.phase[k0:] = [phase.identify(tuple(e[0]), tuple(e[1])) for e in est[k0:]]
        return res



def _weigh(P: PFArrays, prev: np.ndarray, v: np.ndarray, dt: float, X, Y, legs):
    """Likelihoods and contour counts (len(legs), N) of the particles p = p̂_{k−1} + v Δt
    of ``legs`` (``v``: (len(legs), N, 2)), β against the other leg's p̂_{k−1}."""
    out = [likelihood(P, prev[f, 0] + v[r, :, 0] * dt, prev[f, 1] + v[r, :, 1] * dt, X, Y,
                      prev[1 - f, 0], prev[1 - f, 1]) for r, f in enumerate(legs)]
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def _normalise(lik: np.ndarray) -> np.ndarray:
    """Weights per row; a row of zeros (no laser point near any particle): uniform."""
    s = lik.sum(axis=-1, keepdims=True)
    return np.where(s > 0, lik / np.where(s > 0, s, 1.0), 1.0 / lik.shape[-1])


def systematic_resample(w: np.ndarray, u: float) -> np.ndarray:
    """Indices of systematic resampling of normalised weights ``w`` with one uniform ``u``
    (Arulampalam et al. 2002, Algorithm 2): for each (i + u)/N the first cumulative weight
    ≥ it, the last cumulative weight set to 1."""
    c = np.cumsum(w)
    c[-1] = 1.0
    return np.searchsorted(c, (np.arange(w.size) + u) / w.size)


def warm_up() -> None:
    """Compile the likelihood kernel a PF track (and the training) runs, or load it from
    numba's cache, on a tiny problem (two scans of an arc, eight particles per leg,
    resampling forced).

    A stage verb calls it once before its process pool forks its workers
    (:func:`gaitval.jobs.stages.preload`), so that a job loads it once instead of once per
    worker; ``run.py`` calls it after installing.  The arguments have the types and layouts of :meth:`ParticleFilterTracker.step`'s (tests/test_pf_kernel.py
    checks that a track afterwards adds no specialisation).
    """
    tracker = ParticleFilterTracker(n_particles=8, resample_fraction=1.0)
    P = PFArrays(default_pf_model(0.10))
    a = np.linspace(-1.0, 1.0, 41)
    r = np.full((2, a.size), 0.5)

    class _Arc:
        X, Y = r * np.cos(a), r * np.sin(a)

    prev = np.array([[0.55, 0.06, 0.0, 0.0], [0.55, -0.06, 0.0, 0.0]])
    tracker.step(P, np.random.default_rng(0), _Arc, 1, prev, 0.028)
    likelihood(P, np.full(8, 0.55), np.full(8, 0.06), _Arc.X[1], _Arc.Y[1], 0.55, -0.06)
