"""What never moves: the sensor's own motion from its scans, and a static map learned online.

A sensor on a robot (a following robot, a rollator) sees furniture and walls move; a
people tracker must not start a person on them.  leg_tracker solves this with odometry and
a local occupancy grid ("in free space"); gaitval's recordings carry no odometry, so two
roles stand in for it:

``ego_motion`` (:data:`EGO_MOTIONS`)
    ``poses(scans) -> (poses (n, 3), segment (n,))``: the sensor's pose (x, y, θ) per scan
    in a world frame, and the *segment* of scans whose poses share that frame: where the
    motion from one scan to the next cannot be measured, a new segment starts (its poses
    are not comparable with the previous segment's — the motion is unknown, not zero).
    ``none``: a sensor that stands still (identity).  ``scan_matching``: each scan's points
    aligned to the previous scan's by iterative closest point (Besl & McKay 1992) with the
    closed-form 2-D rigid fit of each iteration (Arun et al. 1987, Kabsch):
    pairs from :class:`scipy.spatial.cKDTree`, the closest ``trim`` fraction of pairs kept
    (people and new returns do not pull the fit), starting from the previous step's motion;
    fewer than ``min_pairs`` usable pairs: the step is unknown (a new segment).
``static_map`` (:data:`STATIC_MAPS`)
    ``start(scans, poses)`` then per scan ``update(k, points)`` and ``is_static(x, y)``
    (world frame).  ``recent_hits``: a grid of ``cell_m`` cells, each with a hit score that
    decays with time; a cell is *static* once the score is what ``min_static_s`` of
    continuous returns give — a walking leg stays in a cell for a few tenths of a second, a
    chair leg stays.  ``none``: nothing is static.

References
----------
Besl, P. J.; McKay, N. D. A method for registration of 3-D shapes. IEEE TPAMI 1992, 14,
239–256.  Arun, K. S.; Huang, T. S.; Blostein, S. D. Least-squares fitting of two 3-D point
sets. IEEE TPAMI 1987, 9, 698–700.  Leigh, A. et al. ICRA 2015 (leg_tracker's local
occupancy grid, ``in_free_space``).
"""
from __future__ import annotations

import math

import numpy as np

from gaitval.registry import Registry

#: a grid cell (i, j) is kept as the one integer i * _SHIFT + j (|j| < 2**31 cells, i.e.
#: 2e8 m at 0.1 m cells), which orders cells as the pairs would
_SHIFT = 1 << 32

EGO_MOTIONS = Registry("ego motion")
STATIC_MAPS = Registry("static map")


def scan_points(scans, k: int, step: int = 1) -> np.ndarray:
    """(m, 2) sensor-frame points of scan k (finite ranges only), every ``step``-th beam."""
    r = scans.ranges[k, ::step]
    a = scans.angle_min + scans.angle_increment * np.arange(0, scans.ranges.shape[1], step)
    ok = np.isfinite(r)
    return np.column_stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])])


def to_world(pose, pts: np.ndarray) -> np.ndarray:
    """Points of a scan taken at ``pose`` = (x, y, θ) in the world (first scan's) frame."""
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return np.column_stack([x + c * pts[:, 0] - s * pts[:, 1],
                            y + s * pts[:, 0] + c * pts[:, 1]])


class EgoMotion:
    """Role base."""

    def poses(self, scans) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


@EGO_MOTIONS.register("none")
class StandingSensor(EgoMotion):
    def poses(self, scans):
        return np.zeros((scans.n_scans, 3)), np.zeros(scans.n_scans, dtype=np.int64)


@EGO_MOTIONS.register("odometry")
class Odometry(EgoMotion):
    """The sensor's poses as recorded beside the scans (``scans.meta["odometry"]``: (n, 3)
    x, y, θ in one world frame; a robot's wheel odometry, leg_tracker's ``fixed_frame``).
    Without them the sensor is taken to stand."""

    def poses(self, scans):
        odo = scans.meta.get("odometry") if isinstance(scans.meta, dict) else None
        if odo is None:
            return StandingSensor().poses(scans)
        odo = np.asarray(odo, dtype=float).reshape(scans.n_scans, 3)
        return odo.copy(), np.zeros(scans.n_scans, dtype=np.int64)


@EGO_MOTIONS.register("scan_matching")
class ScanMatching(EgoMotion):
    """Scan-to-previous-scan ICP (module notes).

    Parameters
    ----------
    max_pair_m : float
        Pairs further apart are not used (0.5 m: more than a robot at 2 m/s moves, or
        turns a point 2.5 m away at 1.5 rad/s, in one scan period of 0.1–0.13 s).
    trim : float
        Fraction of the closest pairs kept per iteration.
    iterations : int
        ICP iterations per scan (stops earlier when the update is below 1 mm and 0.1 mrad).
    beam_step : int
        Every n-th beam is used (speed).
    min_pairs : int
        Fewer usable pairs: the step is unknown (module notes).
    fallback_every_beam : bool
        A step that fails on every ``beam_step``-th beam is tried once more with every beam
        before the motion is called unknown (sparse scans, e.g. outdoors with most beams
        returning nothing: experiments/scan_matching_fallback.py).  A step that succeeds on
        the subsampled beams is unchanged.
    max_speed_mps, max_turn_rps : float or None
        A step that moves the sensor faster than this (translation / Δt, |turn| / Δt) is an
        unknown step: ICP aligned something that is not the static scene (outdoors, the
        followed person gives half the returns; experiments/scan_matching_fallback.py).
        2 m/s and 1.5 rad/s: the motion ``max_pair_m`` already assumes.  None: no bound.
    """

    def __init__(self, max_pair_m: float = 0.5, trim: float = 0.8, iterations: int = 20,
                 beam_step: int = 2, min_pairs: int = 20, fallback_every_beam: bool = True,
                 max_speed_mps: float | None = 2.0, max_turn_rps: float | None = 1.5):
        self.max_pair_m = max_pair_m
        self.trim = trim
        self.iterations = iterations
        self.beam_step = beam_step
        self.min_pairs = min_pairs
        self.fallback_every_beam = fallback_every_beam
        self.max_speed_mps = max_speed_mps
        self.max_turn_rps = max_turn_rps

    def plausible(self, step, dt: float) -> bool:
        """The step is within the sensor's stated speed and turn rate (``max_*``)."""
        if step is None:
            return False
        if dt <= 0:
            return True
        x, y, th = step
        return ((self.max_speed_mps is None or math.hypot(x, y) <= self.max_speed_mps * dt)
                and (self.max_turn_rps is None or abs(th) <= self.max_turn_rps * dt))

    def step(self, prev: np.ndarray, cur: np.ndarray, guess):
        """(x, y, θ) of the current scan in the previous scan's frame; None: unknown."""
        if len(prev) < self.min_pairs or len(cur) < self.min_pairs:
            return None
        # scipy here, not at the top: the Snakefile imports this module (the role registries)
        from scipy.spatial import cKDTree

        tree = cKDTree(prev)
        x, y, th = guess
        for _ in range(self.iterations):
            moved = to_world((x, y, th), cur)
            d, i = tree.query(moved, distance_upper_bound=self.max_pair_m)
            ok = np.isfinite(d)
            if ok.sum() < self.min_pairs:
                return None
            d, src, dst = d[ok], moved[ok], prev[i[ok]]
            keep = np.argsort(d, kind="stable")[:max(self.min_pairs, int(self.trim * len(d)))]
            src, dst = src[keep], dst[keep]
            ps, pd_ = src.mean(axis=0), dst.mean(axis=0)
            a, b = src - ps, dst - pd_
            h00, h01 = float(a[:, 0] @ b[:, 0]), float(a[:, 0] @ b[:, 1])
            h10, h11 = float(a[:, 1] @ b[:, 0]), float(a[:, 1] @ b[:, 1])
            dth = math.atan2(h01 - h10, h00 + h11)        # Arun et al. 1987, in 2-D
            c, s = math.cos(dth), math.sin(dth)
            dx = pd_[0] - (c * ps[0] - s * ps[1])
            dy = pd_[1] - (s * ps[0] + c * ps[1])
            # compose the increment with the current estimate
            x, y = c * x - s * y + dx, s * x + c * y + dy
            th += dth
            if abs(dx) < 1e-3 and abs(dy) < 1e-3 and abs(dth) < 1e-4:
                break
        return x, y, th

    def poses(self, scans):
        n = scans.n_scans
        out = np.zeros((n, 3))
        seg = np.zeros(n, dtype=np.int64)
        prev = scan_points(scans, 0, self.beam_step) if n else None
        again = self.fallback_every_beam and self.beam_step > 1
        rel = (0.0, 0.0, 0.0)
        for k in range(1, n):
            cur = scan_points(scans, k, self.beam_step)
            dt = float(scans.t[k] - scans.t[k - 1])
            step = self.step(prev, cur, rel)
            if step is None and again:           # too few points: every beam, once more
                step = self.step(scan_points(scans, k - 1), scan_points(scans, k), rel)
            if not self.plausible(step, dt):     # faster than the sensor moves: unknown
                step = None
            prev = cur
            if step is None:                 # unknown motion: a new frame from here on
                seg[k] = seg[k - 1] + 1
                rel = (0.0, 0.0, 0.0)
                continue
            seg[k] = seg[k - 1]
            rel = step
            x0, y0, t0 = out[k - 1]
            c, s = math.cos(t0), math.sin(t0)
            out[k] = (x0 + c * rel[0] - s * rel[1], y0 + s * rel[0] + c * rel[1], t0 + rel[2])
        return out, seg


class StaticMap:
    """Role base."""

    def start(self, scans, poses) -> "StaticMap":
        return self

    def update(self, k: int, pts_world: np.ndarray) -> None:
        pass

    def is_static(self, x: float, y: float) -> bool:
        return False


@STATIC_MAPS.register("none")
class NoStaticMap(StaticMap):
    pass


@STATIC_MAPS.register("recent_hits")
class RecentHits(StaticMap):
    """Grid of return hits learned online, forgetting what it no longer sees (module notes).

    Per cell c, a hit score decayed with time constant τ::

        h_c ← h_c · exp(−(t_k − t_last,c) / τ) + 1      on every scan with a return in c

    A cell is static when its decayed score is at least what ``min_static_s`` of returns
    on every scan gives, Σ_{i<n} aⁱ with a = exp(−Δt/τ) and n = ``min_static_s``/Δt.

    Parameters
    ----------
    cell_m : float
        Cell size (0.1 m: a leg's width).
    min_static_s : float
        How long a return must stay in a cell (1.4 s: one slow stride, the confirmation
        window; a walker's stance leg stays in a cell for under 0.7 s, 60 % of a 1.1 s
        stride).
    tau_s : float
        Memory (5 s: a walker back on the same path after a TUG turn, some 5 s later, has
        left too little score to make the walkway static).
    neighbourhood : int
        Cells either side looked at by :meth:`is_static` (1: 3 × 3 cells, ±0.15 m: the
        scan-matching error and a leg's own width).
    """

    def __init__(self, cell_m: float = 0.1, min_static_s: float = 1.4, tau_s: float = 5.0,
                 neighbourhood: int = 1):
        self.cell_m = cell_m
        self.min_static_s = min_static_s
        self.tau_s = tau_s
        self.neighbourhood = neighbourhood

    def start(self, scans, poses):
        out = RecentHits(self.cell_m, self.min_static_s, self.tau_s, self.neighbourhood)
        d = np.diff(scans.t)
        dt = float(np.median(d[d > 0])) if np.any(d > 0) else 0.1
        a = math.exp(-dt / self.tau_s)
        n = max(1, int(round(self.min_static_s / dt)))
        out._threshold = (1.0 - a ** n) / (1.0 - a) - 1e-9
        out._t = np.asarray(scans.t, dtype=float)
        out._cells: dict = {}          # cell key (_SHIFT) -> [score, time of last hit]
        out._now = 0.0
        out._answers: dict = {}        # cell -> is_static, until the map next changes
        return out

    def update(self, k, pts_world):
        now = self._now = float(self._t[k])
        self._answers.clear()          # the map (and its clock) change: answers go stale
        if not len(pts_world):
            return
        ij = np.floor(pts_world / self.cell_m).astype(np.int64)
        # one int per cell (_key): a 1-D unique is ~10x faster than unique(axis=0) on pairs
        cells = np.unique(ij[:, 0] * _SHIFT + ij[:, 1])
        tab, tau, exp = self._cells, self.tau_s, math.exp
        for c in cells.tolist():
            e = tab.get(c)
            if e is None:
                tab[c] = [1.0, now]
            else:
                e[0] = e[0] * exp(-(now - e[1]) / tau) + 1.0
                e[1] = now

    def is_static(self, x, y):
        # a scan's points fall in few cells and the answer depends on the cell only, until
        # the next update: each cell is looked up once per scan
        cx, cy = int(math.floor(x / self.cell_m)), int(math.floor(y / self.cell_m))
        got = self._answers.get((cx, cy))
        if got is None:
            got = self._answers[(cx, cy)] = self._cell_static(cx, cy)
        return got

    def _cell_static(self, cx, cy):
        n = self.neighbourhood
        tab, now, thr = self._cells, self._now, self._threshold
        for i in range(cx - n, cx + n + 1):
            for j in range(cy - n, cy + n + 1):
                e = tab.get(i * _SHIFT + j)
                if e is not None and e[0] * math.exp(-(now - e[1]) / self.tau_s) >= thr:
                    return True
        return False


# -- arrival: what was free space a moment ago -----------------------------------------------
ARRIVALS = Registry("arrival")


class Arrival:
    """Role base: ``start(scans, poses)`` (a new world frame), per scan ``update(k, pose)``
    after the scan's observations were used, and ``confirms(person, pose, t)``: does
    a tentative person stand where the scan saw free space a moment ago.  ``none`` (the
    only one) confirms nobody: arrival in free space (``free_space``) confirmed furniture
    from a moving robot and was removed (docs/history/people.md)."""

    def start(self, scans, poses) -> "Arrival":
        return self

    def update(self, k: int, pose) -> None:
        pass

    def confirms(self, person, pose, t: float) -> bool:
        """``person.z``: its legs' observations of this scan (sensor frame; None: unseen),
        ``pose``: the sensor's pose in the world frame, ``person.n_both``: scans with both
        legs observed since birth."""
        return False


@ARRIVALS.register("none")
class NoArrival(Arrival):
    pass
