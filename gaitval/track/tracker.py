"""The leg tracker: one part per role, wired in seed 000's per-scan order.

Per scan k (seed 000 §5): **predict** both legs (seed000 eq. (7)–(8), input u from the
gait phase at k−1, eq. (18)–(20)); take the scan's **observations** (precomputed
detections, or a detector that places its window from the prediction); **gate** them per
leg (seed000 eq. (11)–(13) or seed001 Table 1); **associate** (seed000 eq. (9)–(10), GNN or
the gait-phase rule of §5.2); **correct** (seed000 eq. (14)–(16); a leg without an
observation keeps its prediction and gets the UO pattern) and identify the **gait phase**
(seed000 eq. (3)–(5)); **handle occlusion** (nothing, or Catmull–Rom virtual observations
and re-filtering, seed000 eq. (17)).  The loop in
:meth:`Tracker.run` holds no role's arithmetic; :class:`TrackingRun` keeps the per-leg
histories (:class:`~gaitval.track.leg.LegTrack`) the roles read and write.

Initialisation is a role too (``init``; TUG: the closest plausible pair of observations,
both legs at rest, :mod:`gaitval.track.init`).  Which of the two tracks is the *left* leg
is decided after the run from the walking direction (``sides="walking_direction"``,
:func:`gaitval.track.leg.handedness`), or kept as initialised (``"as_initialised"``).

Time step.  Δt is the sensor's scan period: ``dt_s`` if configured, else the median
timestamp difference; a gap of n periods in the timestamps (dropped scans) is predicted
as one step of n·Δt, so timestamp jitter does not enter the model.

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
from gaitval.track.associate import ASSOCIATORS
from gaitval.track.gate import GATES, GateContext
from gaitval.track.init import INITIALISERS
from gaitval.track.kalman import FILTERS
from gaitval.track.leg import (TRACK_COLUMNS, LegTrack, TrackResult,  # noqa: F401
                               empty_result, handedness, swap_sides)
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.observations import DetectionSeries, WindowedDetections
from gaitval.track.occlusion import OCCLUSION_HANDLERS, OcclusionHandler
from gaitval.track.phase import PHASE_MODELS

_SWING = tuple(SWINGING[i] for i in range(6))
_SWING_OF = tuple(tuple(sw[f] for sw in _SWING) for f in (0, 1))   # [leg][phase]


def step_durations(t: np.ndarray, dt_s: float | None) -> tuple[float, np.ndarray]:
    """Nominal Δt and per-step durations (whole multiples of Δt; see module notes)."""
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


class Tracker:
    """Two-leg tracker composed of one part per role.

    Parameters
    ----------
    filter, motion, phase, gate, associator, occlusion, init : str, dict or part
        Registry specs (see :mod:`gaitval.methods`) or ready objects.
    dt_s : float or None
        Scan period; None infers it from the timestamps.
    sides : {"walking_direction", "as_initialised"}
        How the left/right labels are decided (module notes).
    """

    def __init__(self, filter="kf", motion="gait_phase_accel", phase="speed_thresholds",
                 gate="chi2", associator="gnn", occlusion="predict_only",
                 init="closest_pair", dt_s: float | None = None,
                 sides: str = "walking_direction"):
        self.filter = FILTERS.build(filter)
        self.motion = MOTION_MODELS.build(motion)
        self.phase = PHASE_MODELS.build(phase)
        self.gate = GATES.build(gate)
        self.associator = ASSOCIATORS.build(associator)
        self.occlusion = OCCLUSION_HANDLERS.build(occlusion)
        self.init = INITIALISERS.build(init)
        self.dt_s = dt_s
        self.sides = sides

    def run(self, t, xy, patterns, leg_width_m: float) -> TrackResult:
        """Track both legs through precomputed per-scan observations.

        Parameters
        ----------
        t : ndarray (n_scans,)
            Scan times (sensor clock, s).
        xy : list of ndarray (J_k, 2)
            Observed leg positions per scan (sensor frame, m).
        patterns : list of list of str
            Their patterns (SL, LT, FS_O, FS_U).
        leg_width_m : float
            w_l, for the initialiser and context-dependent gates.
        """
        return self.track(t, DetectionSeries(xy, patterns), leg_width_m)

    def run_windowed(self, scans, detector, leg_width_m: float) -> TrackResult:
        """Track with a detector that places its observation window from the prediction
        (``detector.observe(scans, k, predicted)``, seed 002 §II)."""
        return self.track(scans.t, WindowedDetections(detector, scans, leg_width_m,
                                                      self.filter), leg_width_m)

    def track(self, t, source, leg_width_m: float) -> TrackResult:
        """The per-scan loop over an observation source (see module notes).

        The loop is :meth:`TrackingRun.predict`, the roles, :meth:`TrackingRun.commit` and
        :meth:`TrackingRun.book` written out with every name bound to a local (one scan
        costs a few microseconds, so Python's calls and attribute look-ups would be a large
        share of it); the operations and their order are those methods' exactly.
        """
        t = np.asarray(t, dtype=float)
        start = self.init.find(source, leg_width_m)
        if start is None:                                       # no subject found
            return empty_result(t)
        run = TrackingRun(self, t, source, leg_width_m, start)
        gate, assoc, occ = self.gate.for_leg_width(leg_width_m), self.associator, self.occlusion
        context = gate.needs_context
        state = occ.begin(run)
        hyp = Hypotheses(run)
        candidates, select, reset, phase_of = (gate.candidates, assoc.select, hyp.reset,
                                               hyp.phase_of)
        candidates_at = gate.candidates_at
        uses_phase = assoc.uses_phase
        after_scan = (occ.after_scan if type(occ).after_scan is not OcclusionHandler.after_scan
                      else None)                                  # predict only: nothing to do
        F = run.filter
        fpredict, correct, identify = F.predict, F.correct, run.phase_model.identify
        inputs = None if self.motion.zero_input else self.motion.inputs
        L, R = run.legs
        Lpost, Rpost, Lwin, Rwin = L.post, R.post, L.window, R.window
        Lz, Rz, Lreal, Rreal = L.z, R.z, L.real, R.real
        Lpat, Rpat, Lidx, Ridx = L.pattern, R.pattern, L.obs_index, R.obs_index
        Lacc, Racc = L.acc, R.acc
        phase, dts, hypot, swing_of = run.phase, run.dts, math.hypot, _SWING
        w_l = run.leg_width_m
        c0, c1 = hyp.cache
        pcache = hyp.pcache
        pre = source.precomputed() if isinstance(source, DetectionSeries) else None
        at = source.at
        for k in range(run.k0 + 1, run.n):
            # seed000 eq. (7)–(8), u from eq. (18)–(20) (TrackingRun.predict written out)
            dt, ph = dts[k], phase[k - 1]
            sl, sr = Lpost[k - 1], Rpost[k - 1]
            if inputs is None:
                pl, pr = fpredict(sl, dt, 0.0, 0.0), fpredict(sr, dt, 0.0, 0.0)
            else:
                ul, ur = inputs(ph, (sl[2], sl[3]), (sr[2], sr[3]),
                                Lwin.mean if Lwin is not None else 0.0,
                                Rwin.mean if Rwin is not None else 0.0, dt)
                pl, pr = fpredict(sl, dt, ul[0], ul[1]), fpredict(sr, dt, ur[0], ur[1])
            prior = (pl, pr)
            if pre is not None:                                   # take detections
                obs, pats = pre[0][k], pre[1][k]
            else:                                                 # detect
                obs, pats = at(k, prior)
            if context:                                           # seed000 eq. (11)–(13)
                # TrackingRun.gate_context written out, its fields as arguments
                sw = swing_of[ph]
                cl = candidates_at(F, pl, obs, w_l, dt, hypot(sl[2], sl[3]), sw[0],
                                   L.n_unobserved)
                cr = candidates_at(F, pr, obs, w_l, dt, hypot(sr[2], sr[3]), sw[1],
                                   R.n_unobserved)
            else:
                cl, cr = candidates(F, pl, obs, None), candidates(F, pr, obs, None)
            # TrackingRun.commit written out: seed000 eq. (14)–(16) (corrected states) and
            # eq. (3)–(5) (the phase they are in)
            if uses_phase:                   # the associator compares candidates' phases
                reset(prior, obs)
                a, b = select(cl, cr, ph, phase_of)               # seed000 eq. (9)–(10)
                php = pcache.get((a, b))                 # select has mostly computed it
                php = phase[k] = php if php is not None else phase_of(a, b)
                s1l, s1r = Lpost[k], Rpost[k] = c0[a], c1[b]
            else:
                a, b = select(cl, cr, ph, None)                   # seed000 eq. (9)–(10)
                if a:
                    z = obs[a - 1]
                    s1l = Lpost[k] = correct(pl, z[0], z[1])      # seed000 eq. (14)–(16)
                else:
                    s1l = Lpost[k] = pl
                if b:
                    z = obs[b - 1]
                    s1r = Rpost[k] = correct(pr, z[0], z[1])
                else:
                    s1r = Rpost[k] = pr
                php = phase[k] = identify(s1l, s1r)               # seed000 eq. (3)–(5)
            if a:
                z = obs[a - 1]
                Lz[k] = (z[0], z[1])
                Lreal[k] = True
                Lpat[k] = pats[a - 1]
                Lidx[k] = a - 1
                L.n_unobserved = 0
            else:
                Lpat[k] = "UO"
                L.n_unobserved += 1
            if b:
                z = obs[b - 1]
                Rz[k] = (z[0], z[1])
                Rreal[k] = True
                Rpat[k] = pats[b - 1]
                Ridx[k] = b - 1
                R.n_unobserved = 0
            else:
                Rpat[k] = "UO"
                R.n_unobserved += 1
            # TrackingRun.book written out: ‖a_k‖ per leg into its window (seed 000 §5.5)
            al = Lacc[k] = hypot(s1l[2] - sl[2], s1l[3] - sl[3]) / dt
            ar = Racc[k] = hypot(s1r[2] - sr[2], s1r[3] - sr[3]) / dt
            if Lwin is not None:
                sw = swing_of[php]
                Lwin.push(al, sw[0])
                Rwin.push(ar, sw[1])
            if after_scan is not None:
                after_scan(state, run, k)                         # seed000 eq. (17)
        occ.finish(state, run)
        res = run.result()
        if self.sides == "walking_direction" and handedness(res) < 0:
            swap_sides(res)
        return res


class Hypotheses:
    """Corrected states and gait phases of one scan's candidate associations, computed
    on demand and cached (the gait-phase associator asks for several, seed 000 §5.2).

    ``corrected(f, j)``: leg f corrected with observation j (0: the prediction);
    ``phase_of(a, b)``: the phase after left ← a, right ← b (seed000 eq. (3)–(5)).
    One object serves a whole run: :meth:`reset` starts each scan.
    """

    __slots__ = ("correct", "identify", "prior", "obs", "cache", "pcache")

    def __init__(self, run: TrackingRun, prior=None, obs=()):
        self.correct = run.filter.correct
        self.identify = run.phase_model.identify
        self.cache: tuple[dict, dict] = ({}, {})
        self.pcache: dict = {}
        if prior is not None:
            self.reset(prior, obs)

    def reset(self, prior, obs) -> None:
        """Start a scan: the pair of predicted states and the scan's observations."""
        self.prior, self.obs = prior, obs
        c0, c1 = self.cache
        c0.clear()
        c1.clear()
        c0[0], c1[0] = prior
        self.pcache.clear()

    def corrected(self, f: int, j: int):
        c = self.cache[f]
        s = c.get(j)
        if s is None:
            o = self.obs[j - 1]
            s = c[j] = self.correct(self.prior[f], o[0], o[1])   # seed000 eq. (14)–(16)
        return s

    def phase_of(self, a: int, b: int) -> int:
        ph = self.pcache.get((a, b))
        if ph is None:
            # corrected(0, a), corrected(1, b) written out: this runs several times a scan
            c0, c1 = self.cache
            sl = c0.get(a)
            if sl is None:
                o = self.obs[a - 1]
                sl = c0[a] = self.correct(self.prior[0], o[0], o[1])  # seed000 eq. (14)–(16)
            sr = c1.get(b)
            if sr is None:
                o = self.obs[b - 1]
                sr = c1[b] = self.correct(self.prior[1], o[0], o[1])
            ph = self.pcache[(a, b)] = self.identify(sl, sr)       # seed000 eq. (3)–(5)
        return ph

    def outcome(self, a: int, b: int):
        """``(left state, right state, phase)`` after left ← a, right ← b."""
        ph = self.phase_of(a, b)
        return self.cache[0][a], self.cache[1][b], ph


class TrackingRun:
    """The state of one run: both legs' histories and the gait phase per scan.

    Roles act on it through ``predict``, ``commit``, ``replay``, ``resync`` and
    ``restart``; the occlusion handler reads ``legs``, ``k0``, ``n``, ``filter`` and
    ``source`` (the observations, e.g. to re-initialise from them).  Filter states are
    tuples beginning ``(x, y, vx, vy)`` (:mod:`gaitval.track.kalman`), so the loop reads
    velocities by index.
    """

    def __init__(self, tracker: Tracker, t: np.ndarray, source, leg_width_m: float,
                 start: tuple[int, int, int]):
        self.filter = tracker.filter.for_leg_width(leg_width_m)
        self.motion = tracker.motion
        self.phase_model = tracker.phase
        self.t, self.n, self.leg_width_m = t, len(t), leg_width_m
        self.dts = (step_durations(t, tracker.dt_s)[1] if self.n > 1 else
                    np.array([tracker.dt_s or 0.025]))
        self.dts = self.dts.tolist()
        self.k0, il, ir = start
        self.source = source
        self.phase = [0] * self.n
        self.refiltered: list[tuple[int, int, int]] = []
        self.restarts: list[int] = []
        obs, pats = source.at(self.k0, None)
        self.legs = tuple(LegTrack.start(self.n, self.k0, self.filter, obs[i], pats[i], i,
                                         self.motion.new_window()) for i in (il, ir))

    def predict(self, k: int):
        """Both legs' a priori states at k (seed000 eq. (7)–(8), u from eq. (18)–(20))."""
        predict, dt = self.filter.predict, self.dts[k]
        L, R = self.legs
        sl, sr = L.post[k - 1], R.post[k - 1]
        ul, ur = self.motion.inputs(self.phase[k - 1], (sl[2], sl[3]), (sr[2], sr[3]),
                                    L.window.mean if L.window is not None else 0.0,
                                    R.window.mean if R.window is not None else 0.0, dt)
        return predict(sl, dt, ul[0], ul[1]), predict(sr, dt, ur[0], ur[1])

    def gate_context(self, f: int, k: int) -> GateContext:
        leg = self.legs[f]
        s = leg.post[k - 1]
        return GateContext(self.leg_width_m, self.dts[k], math.hypot(s[2], s[3]),
                           _SWING[self.phase[k - 1]][f], leg.n_unobserved)

    def commit(self, k: int, a: int, b: int, hyp: Hypotheses, obs, pats) -> None:
        """The association (a, b): corrected states, observations used, phase, book-keeping."""
        L, R = self.legs
        # seed000 eq. (14)–(16) (corrected states) and eq. (3)–(5) (the phase they are in)
        L.post[k], R.post[k], self.phase[k] = hyp.outcome(a, b)
        if a:
            L.observed(k, obs[a - 1], pats[a - 1], a - 1)
        else:
            L.unobserved(k)
        if b:
            R.observed(k, obs[b - 1], pats[b - 1], b - 1)
        else:
            R.unobserved(k)
        self.book(k)

    def book(self, k: int) -> None:
        """‖a_k‖ per leg into its acceleration window (seed 000 §5.5)."""
        dt, sw = self.dts[k], _SWING[self.phase[k]]
        hypot = math.hypot
        L, R = self.legs
        s1, s0 = L.post[k], L.post[k - 1]
        al = L.acc[k] = hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt
        s1, s0 = R.post[k], R.post[k - 1]
        ar = R.acc[k] = hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt
        if L.window is not None:
            L.window.push(al, sw[0])
        if R.window is not None:
            R.window.push(ar, sw[1])

    def replay(self, ka: int, k_now: int) -> None:
        """Filter both legs again over ka+1..k_now with the stored observations (real or
        virtual) and associations (seed 000 §5.4)."""
        F = self.filter
        fpredict, correct, identify = F.predict, F.correct, self.phase_model.identify
        inputs = self.motion.inputs
        phase, dts, hypot, swing_of = self.phase, self.dts, math.hypot, _SWING
        L, R = self.legs
        Lpost, Rpost, Lz, Rz, Lacc, Racc = L.post, R.post, L.z, R.z, L.acc, R.acc
        Lwin, Rwin = L.window, R.window
        for k in range(ka + 1, k_now + 1):
            # predict (as TrackingRun.predict, seed000 eq. (7)–(8), (18)–(20))
            dt = dts[k]
            s0l, s0r = Lpost[k - 1], Rpost[k - 1]
            ul, ur = inputs(phase[k - 1], (s0l[2], s0l[3]), (s0r[2], s0r[3]),
                            Lwin.mean if Lwin is not None else 0.0,
                            Rwin.mean if Rwin is not None else 0.0, dt)
            sl, sr = fpredict(s0l, dt, ul[0], ul[1]), fpredict(s0r, dt, ur[0], ur[1])
            z = Lz[k]
            sl = Lpost[k] = correct(sl, z[0], z[1]) if z is not None else sl
            z = Rz[k]
            sr = Rpost[k] = correct(sr, z[0], z[1]) if z is not None else sr
            ph = phase[k] = identify(sl, sr)                      # seed000 eq. (3)–(5)
            # book (as TrackingRun.book): ‖a_k‖ per leg into its window (seed 000 §5.5)
            al = Lacc[k] = hypot(sl[2] - s0l[2], sl[3] - s0l[3]) / dt
            ar = Racc[k] = hypot(sr[2] - s0r[2], sr[3] - s0r[3]) / dt
            if Lwin is not None:
                sw = swing_of[ph]
                Lwin.push(al, sw[0])
                Rwin.push(ar, sw[1])

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
