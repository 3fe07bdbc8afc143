"""One tracking run: both legs' histories and the per-run steps the tracker loop composes.

:class:`TrackingRun` holds the per-leg histories (:class:`~gaitval.track.leg.LegTrack`)
and the gait phase per scan, and offers the steps :meth:`Tracker.track
<gaitval.track.tracker.Tracker.track>` composes: ``predict(k)`` (motion model and filter),
``commit(k, a, b, post_l, post_r, phase, obs, pats)`` (book-keeping of the association, the
acceleration windows) and, for occlusion handlers, ``replay``, ``resync`` and ``restart``.

Each step is a *per-run kernel*: a closure built once at the start of the run from the
roles' parts, with every name it needs bound (a scan costs a few microseconds, so
attribute look-ups would be a large share of it).  The roles themselves build their
kernels the same way: ``filter.predict_pair``, the gate's
:meth:`~gaitval.track.gate.Gate.kernel`, the associator's :meth:`~gaitval.track.associate.Associator.kernel` (association, then
correction and gait phase from the same cache of hypotheses).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import math

import numpy as np

from gaitval.errors import GaitvalError
from gaitval.gait.phases import SWINGING
from gaitval.track.leg import LegTrack, TrackResult, empty_result

#: per gait phase, (left swings, right swings)
SWING = tuple(SWINGING[i] for i in range(6))
_SWING_OF = tuple(tuple(sw[f] for sw in SWING) for f in (0, 1))   # [leg][phase]
_ZERO = (0.0, 0.0)


def step_durations(t: np.ndarray, dt_s: float | None) -> tuple[float, np.ndarray]:
    """Nominal Δt and per-step durations (whole multiples of Δt; see
    :mod:`gaitval.track.tracker`)."""
    t = np.asarray(t, dtype=float)
    d = np.diff(t)
    if dt_s is None:
        pos = d[d > 0]
        if len(pos) == 0:
            raise GaitvalError("scan timestamps do not increase; cannot infer the scan period",
                               hint="set dt_s in the tracker configuration")
        dt_s = float(np.median(pos))
    mult = np.maximum(1, np.rint(d / dt_s))
    return float(dt_s), np.concatenate([[dt_s], mult * dt_s])


class TrackingRun:
    """The state of one run: both legs' histories and the gait phase per scan.

    Roles act on it through ``predict``, ``commit``, ``replay``, ``resync`` and
    ``restart``; the occlusion handler reads ``legs``, ``k0``, ``n``, ``filter`` and
    ``source`` (the observations, e.g. to re-initialise from them).  Filter states are
    tuples beginning ``(x, y, vx, vy)`` (:mod:`gaitval.track.kalman`), so the steps read
    velocities by index.
    """

    def __init__(self, tracker, t: np.ndarray, source, leg_width_m: float,
                 start: tuple[int, int, int]):
        self.filter = tracker.filter.for_leg_width(leg_width_m)
        self.motion = tracker.motion
        self.phase_model = tracker.phase
        self.t, self.n, self.leg_width_m = t, len(t), leg_width_m
        dts = (step_durations(t, tracker.dt_s)[1] if self.n > 1 else
               np.array([tracker.dt_s or 0.025]))
        self.dts = dts.tolist()
        self.k0, il, ir = start
        self.source = source
        self.phase = [0] * self.n
        self.refiltered: list[tuple[int, int, int]] = []
        self.restarts: list[int] = []
        obs, pats = source.at(self.k0, None)
        self.legs = tuple(LegTrack.start(self.n, self.k0, self.filter, obs[i], pats[i], i,
                                         self.motion.new_window()) for i in (il, ir))
        self.predict = _predictor(self)
        self.book = _bookkeeper(self)
        self.commit = _committer(self, self.book)

    def replay(self, ka: int, k_now: int) -> None:
        """Filter both legs again over ka+1..k_now with the stored observations (real or
        virtual) and associations (seed 000 §5.4)."""
        correct, identify = self.filter.correct, self.phase_model.identify
        predict, book, phase = self.predict, self.book, self.phase
        L, R = self.legs
        for k in range(ka + 1, k_now + 1):
            sl, sr = predict(k)                                   # seed000 eq. (7)–(8)
            z = L.z[k]
            sl = L.post[k] = correct(sl, z[0], z[1]) if z is not None else sl
            z = R.z[k]
            sr = R.post[k] = correct(sr, z[0], z[1]) if z is not None else sr
            phase[k] = identify(sl, sr)                           # seed000 eq. (3)–(5)
            book(k)

    def resync(self, k: int) -> None:
        """Rebuild the acceleration windows from the (rewritten) history up to k."""
        for leg, swing in zip(self.legs, _SWING_OF):
            if leg.window is not None:
                lo = max(self.k0 + 1, k - leg.window.n_ac + 1)
                leg.window.reset(leg.acc[lo:k + 1], [swing[p] for p in self.phase[lo:k + 1]])

    def restart(self, k: int, obs, pats, il: int, ir: int) -> None:
        """Re-initialise both legs at scan k on observations ``il`` (left) and ``ir``
        (right), at rest, as at the start (e.g. seed 002's KF after N lost frames); the
        scan is recorded in ``TrackResult.restarts``."""
        F = self.filter
        self.restarts.append(k)
        for leg, i in ((self.legs[0], il), (self.legs[1], ir)):
            leg.post[k] = F.init(float(obs[i][0]), float(obs[i][1]))
            leg.observed(k, obs[i], pats[i], i)
        self.phase[k] = 0

    def result(self) -> TrackResult:
        res = empty_result(self.t)
        res.k_init, k0 = self.k0, self.k0
        for f, leg in enumerate(self.legs):
            leg.fill(res, f, k0)
        res.phase[k0:] = np.asarray(self.phase[k0:], dtype=np.int8)
        res.refiltered = self.refiltered
        res.restarts = self.restarts
        return res


def _predictor(run: TrackingRun):
    """``predict(k) -> (left, right)``: both legs' a priori states at k (seed000 eq.
    (7)–(8)), the input u from the gait phase at k−1 (seed000 eq. (18)–(20))."""
    predict_pair = run.filter.predict_pair
    inputs = None if run.motion.zero_input else run.motion.inputs
    phase, dts = run.phase, run.dts
    L, R = run.legs
    Lpost, Rpost, Lwin, Rwin = L.post, R.post, L.window, R.window

    def predict(k):
        dt = dts[k]
        sl, sr = Lpost[k - 1], Rpost[k - 1]
        if inputs is None:
            return predict_pair(sl, sr, dt, _ZERO, _ZERO)
        ul, ur = inputs(phase[k - 1], (sl[2], sl[3]), (sr[2], sr[3]),
                        Lwin.mean if Lwin is not None else 0.0,
                        Rwin.mean if Rwin is not None else 0.0, dt)
        return predict_pair(sl, sr, dt, ul, ur)
    return predict


def _bookkeeper(run: TrackingRun):
    """``book(k)``: ‖a_k‖ per leg into its acceleration window (seed 000 §5.5)."""
    phase, dts, hypot, swing_of = run.phase, run.dts, math.hypot, SWING
    L, R = run.legs
    Lpost, Rpost, Lacc, Racc, Lwin, Rwin = L.post, R.post, L.acc, R.acc, L.window, R.window

    def book(k):
        dt = dts[k]
        s1, s0 = Lpost[k], Lpost[k - 1]
        al = Lacc[k] = hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt
        s1, s0 = Rpost[k], Rpost[k - 1]
        ar = Racc[k] = hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt
        if Lwin is not None:
            sw = swing_of[phase[k]]
            Lwin.push(al, sw[0])
            Rwin.push(ar, sw[1])
    return book


def _committer(run: TrackingRun, book):
    """``commit(k, a, b, post_l, post_r, phase, obs, pats)``: the association (a, b) at
    scan k (0: none), the corrected states and their gait phase into the histories, then
    :func:`book <_bookkeeper>`."""
    phase = run.phase
    L, R = run.legs
    Lpost, Rpost, Lz, Rz = L.post, R.post, L.z, R.z
    Lreal, Rreal, Lpat, Rpat, Lidx, Ridx = L.real, R.real, L.pattern, R.pattern, \
        L.obs_index, R.obs_index

    def commit(k, a, b, post_l, post_r, ph, obs, pats):
        Lpost[k], Rpost[k], phase[k] = post_l, post_r, ph
        if a:                                   # observation a − 1 taken; H back to 0
            z = obs[a - 1]
            Lz[k], Lreal[k], Lpat[k], Lidx[k] = (z[0], z[1]), True, pats[a - 1], a - 1
        Lpat[k], L.n_unobserved = (Lpat[k], 0) if a else ("UO", L.n_unobserved + 1)
        if b:
            z = obs[b - 1]
            Rz[k], Rreal[k], Rpat[k], Ridx[k] = (z[0], z[1]), True, pats[b - 1], b - 1
        Rpat[k], R.n_unobserved = (Rpat[k], 0) if b else ("UO", R.n_unobserved + 1)
        book(k)
    return commit
