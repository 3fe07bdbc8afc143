"""The leg tracker: wires one part per role and runs seed 000's loop.

Per scan k (seed 000 §5): **predict** both legs (eq. 7–8, input u from the gait phase at
k−1, eq. 18–20); **gate** every observation (eq. 11–13); **associate** (eq. 9–10, GNN or the
gait-phase rule of §5.2); **correct** (eq. 14–16; a leg without an observation keeps its
prediction and gets the UO pattern); identify the **gait phase** (eq. 3–5); **handle
occlusion** (nothing, or Catmull–Rom virtual observations and re-filtering, eq. 17).

Track initialisation (TUG: both legs at the chair at the start).  The tracker starts at
the first scan with two observations between 0.7 w_l (two shanks cannot be closer; two
observations nearer than that are one leg seen twice) and ``init_max_pair_m`` apart (the
closest such pair), both legs at rest (v = 0, Phase 0).  Scans before that have no track
(NaN).  Which of the two is the *left* leg is decided after the run from the walking
direction (``sides="walking_direction"``): the left leg is on the left of the motion of the
legs' midpoint, Σ_k (v_mid × (p_L − p_R)) > 0 over the first 0.5 s of steps in which the
midpoint moves faster than 0.3 m/s — the first swing away from the chair (a swing lasts
0.35–0.5 s), before a false association could have exchanged the tracks.  (Summing over the
whole trial would let a later swap decide the labels of the start, and every error would
then appear at the first step.)  If the sum is negative the two tracks' labels are
exchanged (and Phases 1↔3, 2↔4) — exact, because the tracker treats both legs
symmetrically.  ``sides="as_initialised"`` keeps the initial
guess (the observation with the larger bearing angle is the left leg).

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
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.gait.phases import SWINGING, gait_phase_xy
from gaitval.track.associate import ASSOCIATORS
from gaitval.track.gate import GATES, ChiSquareGate
from gaitval.track.kalman import FILTERS, AxisKalmanFilter
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.occlusion import OCCLUSION_HANDLERS

TRACK_COLUMNS = ("k", "t_sensor_s", "side", "x_m", "y_m", "vx_mps", "vy_mps", "observed",
                 "pattern", "phase", "swing", "interpolated")

_MIRROR_PHASE = np.array([0, 3, 4, 1, 2, 5], dtype=np.int8)


@dataclass
class TrackResult:
    """Arrays of one run; index [0] = left, [1] = right leg, shape (2, n_scans).

    ``phase`` is -1 before initialisation; ``pattern`` is ``""`` there, else the pattern
    of the associated observation or ``"UO"``; ``obs_index`` is the 0-based index of the
    associated observation in its scan (-1: none); ``refiltered`` lists Method 3's
    re-filtering passes as ``(leg, k_from, k_to)``: both legs were filtered again over
    steps k_from+1..k_to after leg ``leg`` (0 = left) reappeared (eq. 17).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    observed: np.ndarray
    interpolated: np.ndarray
    pattern: np.ndarray
    phase: np.ndarray
    k_init: int
    swapped_sides: bool = False
    obs_index: np.ndarray | None = None     # (2, n): associated observation j (0-based), -1
    refiltered: list = field(default_factory=list)   # Method 3: (leg, k_from, k_to) re-runs

    @property
    def swing(self) -> np.ndarray:
        ph = np.clip(self.phase, 0, 5)
        sw = np.array([SWINGING[i] for i in range(6)])        # (6, 2)
        out = sw[ph].T.copy()
        out[:, self.phase < 0] = False
        return out

    def to_frame(self) -> pd.DataFrame:
        """Tidy table, one row per scan and side (columns :data:`TRACK_COLUMNS`)."""
        n = len(self.t)
        sw = self.swing
        return pd.DataFrame({
            "k": np.repeat(np.arange(n, dtype=np.int64), 2),
            "t_sensor_s": np.repeat(np.asarray(self.t, dtype=float), 2),
            "side": pd.Series(np.tile(np.array(["L", "R"], dtype=object), n), dtype=object),
            "x_m": self.x.T.ravel(), "y_m": self.y.T.ravel(),
            "vx_mps": self.vx.T.ravel(), "vy_mps": self.vy.T.ravel(),
            "observed": self.observed.T.ravel(),
            "pattern": pd.Series(self.pattern.T.ravel(), dtype=object),
            "phase": np.repeat(self.phase.astype(np.int64), 2),
            "swing": sw.T.ravel(),
            "interpolated": self.interpolated.T.ravel(),
        })


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
    filter, motion, gate, associator, occlusion : str, dict or part
        Registry specs (see :mod:`gaitval.methods`) or ready objects.
    v_st_th, v_sw_th : float
        Stance/swing speed thresholds of eq. (3)–(4) (seed 000 Table 2: 0.47, 0.93 m/s).
    dt_s : float or None
        Scan period; None infers it from the timestamps.
    init_max_pair_m : float
        Largest distance between the two legs accepted for initialisation.
    sides : {"walking_direction", "as_initialised"}
        How the left/right labels are decided (module notes).
    """

    def __init__(self, filter="kf", motion="gait_phase_accel", gate="chi2",
                 associator="gnn", occlusion="predict_only", v_st_th: float = 0.47,
                 v_sw_th: float = 0.93, dt_s: float | None = None,
                 init_max_pair_m: float = 0.8, sides: str = "walking_direction"):
        self.filter = FILTERS.build(filter)
        self.motion = MOTION_MODELS.build(motion)
        self.gate = GATES.build(gate)
        self.associator = ASSOCIATORS.build(associator)
        self.occlusion = OCCLUSION_HANDLERS.build(occlusion)
        self.v_st_th = v_st_th
        self.v_sw_th = v_sw_th
        self.dt_s = dt_s
        self.init_max_pair_m = init_max_pair_m
        self.sides = sides

    # -- initialisation -----------------------------------------------------------------
    def _initial_pair(self, xy: list[np.ndarray], leg_width_m: float):
        d_min = 0.7 * leg_width_m
        for k, obs in enumerate(xy):
            if len(obs) < 2:
                continue
            best = None
            for i in range(len(obs)):
                for j in range(i + 1, len(obs)):
                    d = math.hypot(*(obs[i] - obs[j]))
                    if d_min <= d <= self.init_max_pair_m and (best is None or d < best[0]):
                        best = (d, i, j)
            if best is not None:
                _, i, j = best
                ai = math.atan2(obs[i][1], obs[i][0])
                aj = math.atan2(obs[j][1], obs[j][0])
                return (k, i, j) if ai >= aj else (k, j, i)   # left = larger bearing
        return None

    # -- the run ------------------------------------------------------------------------
    def run(self, t: np.ndarray, xy: list[np.ndarray], patterns: list[list[str]],
            leg_width_m: float) -> TrackResult:
        """Track both legs through a series of per-scan observations.

        Parameters
        ----------
        t : ndarray (n_scans,)
            Scan times (sensor clock, s).
        xy : list of ndarray (J_k, 2)
            Observed leg positions per scan (sensor frame, m).
        patterns : list of list of str
            Their patterns (SL, LT, FS_O, FS_U).
        leg_width_m : float
            w_l, passed to the gate's context.

        Returns
        -------
        TrackResult
        """
        n = len(t)
        _, dts = step_durations(t, self.dt_s) if n > 1 else (self.dt_s or 0.025,
                                                             np.array([self.dt_s or 0.025]))
        F = self.filter
        # plain Python floats in the loop (numpy scalars are several times slower)
        arrs = [np.asarray(o, dtype=float).reshape(-1, 2) for o in xy]
        flat = np.concatenate(arrs).tolist() if n else []      # one conversion, then slices
        xyl, i = [], 0
        for o in arrs:
            xyl.append(flat[i:i + len(o)])
            i += len(o)
        needs_ctx = getattr(self.gate, "needs_context", True)
        nan = np.full((2, n), np.nan)
        res = TrackResult(t=np.asarray(t, dtype=float), x=nan.copy(), y=nan.copy(),
                          vx=nan.copy(), vy=nan.copy(),
                          observed=np.zeros((2, n), bool), interpolated=np.zeros((2, n), bool),
                          pattern=np.full((2, n), "", dtype=object),
                          phase=np.full(n, -1, dtype=np.int8), k_init=-1,
                          obs_index=np.full((2, n), -1, dtype=np.int64))
        init = self._initial_pair(xy, leg_width_m)
        if init is None:
            return res
        k0, il, ir = init
        res.k_init = k0
        post: list[list] = [[None] * n, [None] * n]
        oidx = [[-1] * n, [-1] * n]          # associated observation (0-based), -1
        z: list[list] = [[None] * n, [None] * n]         # observation used (real or virtual)
        real = [[False] * n, [False] * n]
        acc = [[0.0] * n, [0.0] * n]
        phase = [0] * n
        pats = [[""] * n, [""] * n]
        obs0 = xyl[k0]
        for f, i in ((0, il), (1, ir)):
            post[f][k0] = F.init(float(obs0[i][0]), float(obs0[i][1]))
            z[f][k0] = (float(obs0[i][0]), float(obs0[i][1]))
            real[f][k0] = True
            pats[f][k0] = patterns[k0][i]
            oidx[f][k0] = i
        last_real = [k0, k0]
        n_unobs = [0, 0]
        n_ac = self.motion.n_ac
        gsum = [0.0, 0.0]
        gcnt = [0, 0]
        pending: list[tuple[int, int, int, int]] = []
        next_due = n                     # earliest due step of the pending re-filters
        v_st, v_sw = self.v_st_th, self.v_sw_th
        gate, assoc, occ, motion = self.gate, self.associator, self.occlusion, self.motion

        # Speed: everything the per-scan loop calls is bound to a local name once, the
        # swing table is a tuple indexed by phase, and the ``kf`` filter's Mahalanobis
        # distance (one S per leg and scan, eq. 12) and the χ² gate test (eq. 13) are
        # evaluated inline.  Same arithmetic in the same order as the part methods, so
        # the results are identical (tests/test_track.py regression snapshot).
        posvel = F.posvel
        vel = F.vel
        hypot, sqrt = math.hypot, math.sqrt
        predict = F.predict
        correct = F.correct
        mahal2 = F.mahalanobis2
        inputs = motion.inputs
        admits = gate.admits
        select = assoc.select
        sw_tab = tuple(SWINGING[i] for i in range(6))
        axis_kf = type(F) is AxisKalmanFilter
        r2 = F.r_sd_m ** 2 if axis_kf else 0.0
        chi2_g = gate.g if type(gate) is ChiSquareGate else None
        post_l, post_r = post
        acc_l, acc_r = acc
        if axis_kf:
            # the ``kf`` filter's predict / correct as plain closures (no method lookup,
            # constants per Δt cached here): the same expressions as
            # AxisKalmanFilter.predict (eq. 7–8) and .correct (eq. 12, 14–16)
            kcache: dict = {}
            consts = F._consts

            def predict(s, dt, ux, uy):
                cst = kcache.get(dt)
                if cst is None:
                    cst = kcache[dt] = consts(dt)
                h, qaa, qab, qbb = cst
                x, y, vx, vy, a, b, c = s
                return (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux,
                        vy + dt * uy, a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab,
                        c + qbb)

            def predict2(sl, sr, dt, ul, ur):
                """Both legs' predictions with one constants look-up (= predict twice)."""
                cst = kcache.get(dt)
                if cst is None:
                    cst = kcache[dt] = consts(dt)
                h, qaa, qab, qbb = cst
                x, y, vx, vy, a, b, c = sl
                ux, uy = ul
                pl = (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux,
                      vy + dt * uy, a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab,
                      c + qbb)
                x, y, vx, vy, a, b, c = sr
                ux, uy = ur
                return pl, (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux,
                            vy + dt * uy, a + dt * (2.0 * b + dt * c) + qaa,
                            b + dt * c + qab, c + qbb)

            def correct(s, zx, zy):
                x, y, vx, vy, a, b, c = s
                sv = a + r2
                k0_ = a / sv
                k1 = b / sv
                ex = zx - x
                ey = zy - y
                return (x + k0_ * ex, y + k0_ * ey, vx + k1 * ex, vy + k1 * ey,
                        a - k0_ * a, b - k0_ * b, c - k1 * b)

            def vel(s):
                return s[2], s[3]

            def phase_from(sl, sr):
                return gait_phase_xy(sl[0], sl[1], sl[2], sl[3], sr[0], sr[1], sr[2], sr[3],
                                     v_st, v_sw)
        else:
            def phase_from(sl, sr):
                return gait_phase_xy(*posvel(sl), *posvel(sr), v_st, v_sw)

            def predict2(sl, sr, dt, ul, ur):
                return predict(sl, dt, ul[0], ul[1]), predict(sr, dt, ur[0], ur[1])

        swings_of = (tuple(sw[0] for sw in sw_tab), tuple(sw[1] for sw in sw_tab))

        def resync_gain(k):
            """g from scratch over the window (after a re-filter rewrote its history)."""
            lo = max(k0 + 1, k - n_ac + 1)
            ph = phase[lo:k + 1]
            for f in (0, 1):
                swf = swings_of[f]
                sel = [a for a, p in zip(acc[f][lo:k + 1], ph) if swf[p]]
                gsum[f], gcnt[f] = float(sum(sel)), len(sel)

        def rerun_kf(ka, k_now):
            """The re-filtering loop of :func:`refilter` for the ``kf`` filter, unrolled
            over the two legs (same operations in the same order as the generic loop)."""
            z_l, z_r = z
            gl = gsum[0] / gcnt[0] if gcnt[0] > 0 else 0.0
            gr = gsum[1] / gcnt[1] if gcnt[1] > 0 else 0.0
            sl = post_l[ka]
            sr = post_r[ka]
            for k in range(ka + 1, k_now + 1):
                dt = dts[k]
                ul, ur = inputs(phase[k - 1], (sl[2], sl[3]), (sr[2], sr[3]), gl, gr, dt)
                ol, orr = sl, sr
                sl, sr = predict2(sl, sr, dt, ul, ur)          # eq. (7)–(8)
                zk = z_l[k]
                if zk is not None:
                    sl = correct(sl, zk[0], zk[1])              # eq. (14)–(16)
                zk = z_r[k]
                if zk is not None:
                    sr = correct(sr, zk[0], zk[1])
                post_l[k] = sl
                post_r[k] = sr
                ph = phase[k] = gait_phase_xy(sl[0], sl[1], sl[2], sl[3],    # eq. (3)–(5)
                                              sr[0], sr[1], sr[2], sr[3], v_st, v_sw)
                # book_accel(k, dt), inline (§5.5)
                al = acc_l[k] = math.hypot(sl[2] - ol[2], sl[3] - ol[3]) / dt
                ar = acc_r[k] = math.hypot(sr[2] - orr[2], sr[3] - orr[3]) / dt
                if n_ac:
                    sw_now = sw_tab[ph]
                    old = k - n_ac
                    sw_old = sw_tab[phase[old]] if old > k0 else (False, False)
                    if sw_now[0]:
                        gsum[0] += al
                        gcnt[0] += 1
                    if sw_old[0]:
                        gsum[0] -= acc_l[old]
                        gcnt[0] -= 1
                    if sw_now[1]:
                        gsum[1] += ar
                        gcnt[1] += 1
                    if sw_old[1]:
                        gsum[1] -= acc_r[old]
                        gcnt[1] -= 1
                    gl = gsum[0] / gcnt[0] if gcnt[0] > 0 else 0.0
                    gr = gsum[1] / gcnt[1] if gcnt[1] > 0 else 0.0

        def refilter(f, ka, m, k_now):
            """Catmull–Rom virtual observations for leg f, then re-filter (eq. 17, §5.4)."""
            res.refiltered.append((f, ka, k_now))
            n_uo = m - ka - 1
            nbo, nao = occ.n_before(n_uo), occ.n_after(n_uo)
            p1, p2 = z[f][ka], z[f][m]
            i0 = ka - nbo
            p0 = None
            for i in range(max(i0, k0), k0 - 1, -1):
                if real[f][i]:
                    p0 = z[f][i]
                    break
            if p0 is None:
                p0 = F.pos(post[f][max(i0, k0)])
            p3 = p2
            for i in range(min(m + nao, k_now), m - 1, -1):
                if real[f][i]:
                    p3 = z[f][i]
                    break
            virt = occ.virtual_observations(p0, p1, p2, p3, n_uo).tolist()
            zf = z[f]
            for i in range(n_uo):
                zf[ka + 1 + i] = (virt[i][0], virt[i][1])
            res.interpolated[f, ka + 1:ka + 1 + n_uo] = True
            # re-run both legs from ka with the stored associations (§5.4: "all state
            # parameters are updated")
            resync_gain(ka)
            z_l, z_r = z
            if axis_kf:
                rerun_kf(ka, k_now)
                return
            for k in range(ka + 1, k_now + 1):
                dt = dts[k]
                sl, sr = post_l[k - 1], post_r[k - 1]
                ul, ur = inputs(phase[k - 1], (sl[2], sl[3]) if axis_kf else vel(sl),
                                (sr[2], sr[3]) if axis_kf else vel(sr),
                                gsum[0] / gcnt[0] if gcnt[0] > 0 else 0.0,
                                gsum[1] / gcnt[1] if gcnt[1] > 0 else 0.0, dt)
                sl, sr = predict2(sl, sr, dt, ul, ur)
                zk = z_l[k]
                if zk is not None:
                    sl = correct(sl, zk[0], zk[1])
                zk = z_r[k]
                if zk is not None:
                    sr = correct(sr, zk[0], zk[1])
                post_l[k] = sl
                post_r[k] = sr
                ph = phase[k] = phase_from(sl, sr)
                # book_accel(k, dt), inline (same operations)
                sw_now = sw_tab[ph]
                old = k - n_ac
                sw_old = sw_tab[phase[old]] if (n_ac and old > k0) else (False, False)
                for f_, s1, s0, af in ((0, sl, post_l[k - 1], acc_l),
                                       (1, sr, post_r[k - 1], acc_r)):
                    if axis_kf:
                        aa = math.hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt
                    else:
                        v1 = vel(s1)
                        v0 = vel(s0)
                        aa = math.hypot(v1[0] - v0[0], v1[1] - v0[1]) / dt
                    af[k] = aa
                    if n_ac:
                        if sw_now[f_]:
                            gsum[f_] += aa
                            gcnt[f_] += 1
                        if sw_old[f_]:
                            gsum[f_] -= af[old]
                            gcnt[f_] -= 1

        # per-scan association state, read by the two helpers below (closures see the
        # current binding of ``prior``, ``obs``, ``cache`` and ``pcache``)
        prior = obs = None
        cache: tuple[dict, dict] = ({}, {})
        pcache: dict = {}

        def corrected(f, j):
            s = cache[f].get(j)
            if s is None:
                s = correct(prior[f], obs[j - 1][0], obs[j - 1][1])   # eq. (14)–(16)
                cache[f][j] = s
            return s

        if axis_kf:
            def phase_of(a, b):
                ph = pcache.get((a, b))
                if ph is None:
                    sl = corrected(0, a)
                    sr = corrected(1, b)
                    ph = pcache[(a, b)] = gait_phase_xy(sl[0], sl[1], sl[2], sl[3], sr[0],
                                                        sr[1], sr[2], sr[3], v_st, v_sw)
                return ph
        else:
            def phase_of(a, b):
                ph = pcache.get((a, b))
                if ph is None:
                    ph = pcache[(a, b)] = phase_from(corrected(0, a), corrected(1, b))
                return ph

        for k in range(k0 + 1, n):
            dt = dts[k]
            sl_prev, sr_prev = post_l[k - 1], post_r[k - 1]
            if axis_kf:
                vl = (sl_prev[2], sl_prev[3])
                vr = (sr_prev[2], sr_prev[3])
            else:
                vl, vr = vel(sl_prev), vel(sr_prev)
            # predict, eq. (7)–(8) with u_{k-1} from eq. (18)–(20)
            gl = gsum[0] / gcnt[0] if gcnt[0] > 0 else 0.0
            gr = gsum[1] / gcnt[1] if gcnt[1] > 0 else 0.0
            ul, ur = inputs(phase[k - 1], vl, vr, gl, gr, dt)
            prior = predict2(sl_prev, sr_prev, dt, ul, ur)
            # gate, eq. (11)–(13)
            obs = xyl[k]
            cands = ([], [])
            if obs:
                for f in (0, 1):
                    pf = prior[f]
                    px, py = pf[0], pf[1]
                    cf = cands[f]
                    if axis_kf and chi2_g is not None:
                        sv = pf[4] + r2                       # eq. (12), per axis
                        for j, (zx, zy) in enumerate(obs):
                            ex = zx - px
                            ey = zy - py
                            lam2 = (ex * ex + ey * ey) / sv   # eq. (11)
                            if lam2 < chi2_g:                 # eq. (13)
                                cf.append((j + 1, sqrt(lam2)))
                        continue
                    px, py = F.pos(pf)
                    ctx = None
                    if needs_ctx:
                        v = vl if f == 0 else vr
                        ctx = {"leg_width_m": leg_width_m, "dt": dt, "speed": math.hypot(*v),
                               "swing": sw_tab[phase[k - 1]][f], "n_unobserved": n_unobs[f]}
                    for j, (zx, zy) in enumerate(obs):
                        lam2 = mahal2(pf, zx, zy)
                        if admits(lam2, math.hypot(zx - px, zy - py), ctx):
                            cf.append((j + 1, math.sqrt(lam2)))
            # associate, eq. (9)–(10) and §5.2
            cache = ({0: prior[0]}, {0: prior[1]})
            pcache = {}
            a, b = select(cands[0], cands[1], phase[k - 1], phase_of)
            # correct, eq. (14)–(16)
            for f, j in ((0, a), (1, b)):
                s = cache[f].get(j)
                post[f][k] = s if s is not None else corrected(f, j)
                if j:
                    o = obs[j - 1]
                    z[f][k] = (o[0], o[1])
                    real[f][k] = True
                    pats[f][k] = patterns[k][j - 1]
                    oidx[f][k] = j - 1
                    n_unobs[f] = 0
                else:
                    pats[f][k] = "UO"
                    n_unobs[f] += 1
            # gait phase, eq. (3)–(5)
            ph = pcache.get((a, b))
            if ph is None:
                ph = phase_of(a, b)
            phase[k] = ph
            # book_accel(k, dt), inline (the same operations as in rerun_kf)
            sl, sr = post_l[k], post_r[k]
            if axis_kf:
                al = acc_l[k] = hypot(sl[2] - sl_prev[2], sl[3] - sl_prev[3]) / dt
                ar = acc_r[k] = hypot(sr[2] - sr_prev[2], sr[3] - sr_prev[3]) / dt
            else:
                v1, v0 = vel(sl), vel(sl_prev)
                al = acc_l[k] = hypot(v1[0] - v0[0], v1[1] - v0[1]) / dt
                v1, v0 = vel(sr), vel(sr_prev)
                ar = acc_r[k] = hypot(v1[0] - v0[0], v1[1] - v0[1]) / dt
            if n_ac:
                sw_now = sw_tab[ph]
                old = k - n_ac
                sw_old = sw_tab[phase[old]] if old > k0 else (False, False)
                if sw_now[0]:
                    gsum[0] += al
                    gcnt[0] += 1
                if sw_old[0]:
                    gsum[0] -= acc_l[old]
                    gcnt[0] -= 1
                if sw_now[1]:
                    gsum[1] += ar
                    gcnt[1] += 1
                if sw_old[1]:
                    gsum[1] -= acc_r[old]
                    gcnt[1] -= 1
            # occlusion handling (eq. 17 for Method 3)
            for f in (0, 1):
                if real[f][k]:
                    if last_real[f] < k - 1:
                        d = occ.delay(k - last_real[f] - 1)
                        if d is not None:
                            pending.append((k + d, f, last_real[f], k))
                            next_due = min(next_due, k + d)
                    last_real[f] = k
            if pending and k >= next_due:
                due = [p for p in pending if p[0] <= k]
                if due:
                    pending = [p for p in pending if p[0] > k]
                    for _, f, ka, m in sorted(due, key=lambda p: (p[2], p[1])):
                        refilter(f, ka, m, k)
                    resync_gain(k)
                next_due = min((p[0] for p in pending), default=n)
        for _, f, ka, m in sorted(pending, key=lambda p: (p[2], p[1])):
            refilter(f, ka, m, n - 1)

        for f in (0, 1):
            pv = np.array([p[:4] for p in post[f][k0:]] if axis_kf else
                          [F.pos(p) + F.vel(p) for p in post[f][k0:]], dtype=float)
            res.x[f, k0:], res.y[f, k0:] = pv[:, 0], pv[:, 1]
            res.vx[f, k0:], res.vy[f, k0:] = pv[:, 2], pv[:, 3]
            res.observed[f, k0:] = real[f][k0:]
            res.obs_index[f, k0:] = oidx[f][k0:]
            res.pattern[f, k0:] = pats[f][k0:]
        res.phase[k0:] = np.asarray(phase[k0:], dtype=np.int8)
        if self.sides == "walking_direction" and _handedness(res) < 0:
            _swap_sides(res)
        return res


def _handedness(res: TrackResult, min_speed: float = 0.3, window_s: float = 0.5) -> float:
    """Σ v_mid × (p_L − p_R) over the first ``window_s`` of steps in which the legs'
    midpoint moves faster than ``min_speed`` (module notes)."""
    vmx = 0.5 * (res.vx[0] + res.vx[1])
    vmy = 0.5 * (res.vy[0] + res.vy[1])
    dx = res.x[0] - res.x[1]
    dy = res.y[0] - res.y[1]
    with np.errstate(invalid="ignore"):
        moving = np.flatnonzero(np.hypot(vmx, vmy) > min_speed)
    if moving.size == 0:
        return 0.0
    t = np.asarray(res.t, dtype=float)
    moving = moving[t[moving] <= t[moving[0]] + window_s]
    return float(np.nansum((vmx * dy - vmy * dx)[moving]))


def _swap_sides(res: TrackResult) -> None:
    for name in ("x", "y", "vx", "vy", "observed", "interpolated", "pattern", "obs_index"):
        arr = getattr(res, name)
        setattr(res, name, arr[::-1].copy())
    ok = res.phase >= 0
    res.phase[ok] = _MIRROR_PHASE[res.phase[ok]]
    res.refiltered = [(1 - f, a, b) for f, a, b in res.refiltered]
    res.swapped_sides = True
