"""Is anyone there?  The motion check of the initialisers for a sensor that stands still.

:class:`MotionCheck` follows leg-like pairs and asks both legs to travel over still scans
and off the background (:class:`Background`: places observed again and again); the
``closest_pair`` and ``mtst_participant`` initialisers (:mod:`gaitval.track.init`,
:mod:`gaitval.track.init_mtst`) answer "no subject" without such a pair.

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. ICRA 2015 (the leg_tracker recordings of empty scenes, ``negative_*.bag``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitval.track.params import NO_SOURCE, coerce, declared, param


@declared
@dataclass(eq=False)
class MotionCheck:
    """Is there a leg-like pair that moves?  (Used by :class:`ClosestMovingPair`.)

    Leg-like pairs (two observations ``d_min``..``d_max`` apart; the ``per_scan`` closest
    of each scan) are followed scan by scan, each leg by its nearest observation within
    ``max_step_m`` (the nearer leg keeps an observation both would take; the pair may not
    grow beyond ``1.5 d_max``), until a leg is lost for ``max_lost_scans``.  A leg's step
    counts towards its travel only when

    * the scene is still at that scan (:meth:`still_scans`): a sensor that moves makes the
      whole background move, and nothing can be told from it; and
    * the step lands off the background (:class:`Background`): a place observed in at
      least half the scans around it is a chair or table leg, even if a follow hops onto it.

    The pair moves when the net travel of *both* legs reaches ``min_travel_m`` — a walking
    subject's legs leave where they stood; one leg seen twice or a flickering background
    object does not.  On a leg_tracker recording of an empty room (``negative_2.bag``,
    three lasers on a moving robot) the largest travel found is 0.28 m; walking subjects
    (``positive_1.bag``, every simulated TUG and MTST trial) reach 0.5 m.
    """

    min_travel_m: float = param(0.5, "m", NO_SOURCE + " (empty room 0.28 m, walkers ≥ 0.5 m)",
                                "net travel of each leg of a moving pair (over still scans, "
                                "off the background)")
    max_step_m: float = param(0.7, "m", NO_SOURCE + " (a 5 m/s swing at 7.5 scans/s)",
                              "largest move of one leg between two scans")
    max_lost_scans: int = param(8, "scans", NO_SOURCE,
                                "a leg unseen for longer ends the pair's follow")
    per_scan: int = param(3, "pairs", NO_SOURCE, "closest leg-like pairs followed per scan")
    still_min_obs: int = param(8, "observations", NO_SOURCE,
                               "a scan with fewer is still (the background was subtracted)")
    still_lag: int = param(3, "scans", NO_SOURCE,
                           "how many scans back a crowded scan is compared")
    still_radius_m: float = param(0.05, "m", NO_SOURCE,
                                  "an observation this near one of the earlier scan stayed")

    def __post_init__(self):
        coerce(self)
        self.max_gate_m = 1.0        # a leg unseen for a while: still no further than this

    def moving_pair(self, source, d_min: float, d_max: float, first_scan: int = 0,
                    leg_width_m: float | None = None) -> tuple[int, int, int] | None:
        """The first moving pair ``(k, i, j)`` from ``first_scan`` on, or None
        (``leg_width_m`` is not used: the travel is in metres)."""
        every = getattr(source, "arrays", None)          # every scan's (J, 2) float array
        arrays = (every() if every is not None
                  else [source.array(k) for k in range(len(source))])
        still = self.still_scans(arrays).tolist()
        # plain Python floats from here on: the follow visits a few observations per scan,
        # where numpy's per-call overhead would cost more than the arithmetic
        lists = getattr(source, "lists", None)
        pts = lists() if lists is not None else [a.tolist() for a in arrays]
        background = Background(arrays)
        visited: set[tuple[int, int, int]] = set()          # (k, i, j) followed already
        for k in range(first_scan, len(pts)):
            for i, j in self._pairs(pts[k], d_min, d_max):
                if (k, i, j) in visited:
                    continue                       # already followed from an earlier scan
                if self._follow(pts, still, background, k, i, j, 1.5 * d_max, visited):
                    return k, i, j
        return None

    def _pairs(self, obs: list, d_min: float, d_max: float) -> list[tuple[int, int]]:
        """The ``per_scan`` closest leg-like pairs (i < j) of one scan (ties: lower i, j)."""
        if len(obs) > 12:                        # a cluttered scan: all pairs at once
            a = np.asarray(obs, dtype=float)
            iu, ju = np.triu_indices(len(a), 1)
            d = np.hypot(a[iu, 0] - a[ju, 0], a[iu, 1] - a[ju, 1])
            ok = np.flatnonzero((d >= d_min) & (d <= d_max))
            ok = ok[np.argsort(d[ok], kind="stable")][:self.per_scan]
            return [(int(iu[q]), int(ju[q])) for q in ok]
        hypot = math.hypot
        cand = []
        for i in range(len(obs)):
            xi, yi = obs[i]
            for j in range(i + 1, len(obs)):
                d = hypot(xi - obs[j][0], yi - obs[j][1])
                if d_min <= d <= d_max:
                    cand.append((d, i, j))
        cand.sort()
        return [(i, j) for _, i, j in cand[:self.per_scan]]

    def still_scans(self, arrays: list[np.ndarray]) -> np.ndarray:
        """Per scan: True unless the scene moved (a crowded scan most of whose observations
        are not within ``still_radius_m`` of one ``still_lag`` scans earlier)."""
        still = np.ones(len(arrays), dtype=bool)
        lag = self.still_lag
        sizes = np.fromiter(map(len, arrays), dtype=np.int64, count=len(arrays))
        # a sparse scan (fewer than still_min_obs: the background was subtracted) is still
        for k in (np.flatnonzero(sizes[lag:] >= self.still_min_obs) + lag).tolist():
            a, b = arrays[k], arrays[k - lag]
            if len(b) == 0:
                still[k] = False
                continue
            d = np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])
            still[k] = np.mean(d.min(axis=1) < self.still_radius_m) >= 0.5
        return still

    def _follow(self, pts, still, background, k0, i, j, span, visited) -> bool:
        """Follow the pair (i, j) of scan k0; True once both legs travelled far enough.

        A leg's net travel is the sum of its steps taken at still scans off the background.
        The background test is the costly part, so a step's test is put off while the leg
        could not have travelled ``min_travel_m`` even if every pending step counted (its
        net so far plus the lengths of its pending steps); pending steps are then tested and
        added in scan order, so the sums — and the answer — are those of testing each step
        as it comes.
        """
        pos = [pts[k0][i], pts[k0][j]]
        net = [[0.0, 0.0], [0.0, 0.0]]
        net_len = [0.0, 0.0]                  # per leg: |net|
        pending: list[list] = [[], []]        # per leg: (k, g, z, dx, dy) not yet tested
        reach = [0.0, 0.0]                    # per leg: Σ |pending step|
        lost = [0, 0]
        hypot, thr, max_lost = math.hypot, self.min_travel_m, self.max_lost_scans
        associate, travelled = self._associate, self._travelled
        for k in range(k0 + 1, len(pts)):
            obs = pts[k]
            got = associate(obs, pos, lost, span)
            for f in (0, 1):
                g = got[f]
                if g is None:
                    lost[f] += 1
                    continue
                z, p = obs[g], pos[f]
                if still[k] and still[k - 1]:          # a step within a still scene
                    dx, dy = z[0] - p[0], z[1] - p[1]
                    pending[f].append((k, g, z, dx, dy))
                    reach[f] += hypot(dx, dy)
                pos[f], lost[f] = z, 0
            g0, g1 = got
            if g0 is not None and g1 is not None:
                visited.add((k, g0, g1) if g0 < g1 else (k, g1, g0))
            # the bound |net| + Σ|pending| of both legs (with a margin for rounding) must
            # reach min_travel_m before the pending steps are worth testing
            if (not (net_len[0] + reach[0]) * (1 + 1e-9) + 1e-12 < thr
                    and not (net_len[1] + reach[1]) * (1 + 1e-9) + 1e-12 < thr
                    and travelled(net, net_len, pending, reach, background)):
                return True
            if lost[0] > max_lost or lost[1] > max_lost:
                return False
        return False

    def _travelled(self, net, net_len, pending, reach, background) -> bool:
        """|net travel| ≥ min_travel_m for both legs, testing the pending steps of each leg
        in scan order (the caller has checked the bounds)."""
        thr = self.min_travel_m
        for f in (0, 1):
            n, steps = net[f], pending[f]
            for (_, _, _, dx, dy), occupied in zip(steps, background.resolve(
                    [(k, g, z) for k, g, z, _, _ in steps])):
                if not occupied:
                    n[0] += dx
                    n[1] += dy
            steps.clear()
            reach[f] = 0.0
            net_len[f] = math.hypot(n[0], n[1])
            if net_len[f] < thr:
                return False
        return True

    def _associate(self, obs, pos, lost, span) -> list[int | None]:
        """Each leg's nearest observation within its gate (the first of equals); a shared one
        goes to the nearer leg, and a pair may not grow beyond ``span``."""
        got: list[int | None] = [None, None]
        dist = [0.0, 0.0]
        if not obs:
            return got
        hypot, step, gate_max = math.hypot, self.max_step_m, self.max_gate_m
        for f in (0, 1):
            px, py = pos[f]
            m, dm = 0, math.inf
            for q, (x, y) in enumerate(obs):
                d = hypot(x - px, y - py)
                if d < dm:
                    m, dm = q, d
            gate = step * (1 + lost[f])
            if dm <= (gate if gate < gate_max else gate_max):
                got[f], dist[f] = m, dm
        if got[0] is not None and got[0] == got[1]:
            got[1 if dist[0] <= dist[1] else 0] = None
        if got[0] is not None and got[1] is not None:
            a, b = obs[got[0]], obs[got[1]]
            if hypot(a[0] - b[0], a[1] - b[1]) > span:
                got[0 if dist[0] > dist[1] else 1] = None
        return got


class Background:
    """Places observed again and again.

    ``occupied(k, z)``: an observation lies within ``radius_m`` of ``z`` in at least
    ``fraction`` of the scans ``k - window .. k + window``.  The scans are held as one
    padded ``(n, J_max, 2)`` array, so a batch of questions is one numpy expression.
    """

    def __init__(self, arrays: list[np.ndarray], radius_m: float = 0.06, window: int = 15,
                 fraction: float = 0.5):
        self.r, self.window, self.fraction, self.n = radius_m, window, fraction, len(arrays)
        self._memo: dict[tuple[int, int], bool] = {}
        sizes = np.array([len(a) for a in arrays], dtype=int)
        jmax = int(sizes.max()) if len(sizes) else 0
        self.P = np.full((self.n, max(jmax, 1), 2), 1e9)      # padding: far from everything
        if jmax:
            self.P[np.arange(jmax)[None, :] < sizes[:, None]] = np.concatenate(arrays)
        self.offsets = np.arange(-window, window + 1)

    def occupied_obs(self, k: int, j: int, z) -> bool:
        """:meth:`occupied` for observation j of scan k, remembered (several candidate pairs
        are followed through the same scans)."""
        return self.resolve([(k, j, z)])[0]

    def resolve(self, queries) -> list[bool]:
        """:meth:`occupied` for a batch of ``(k, j, z)`` (z observation j of scan k),
        remembered by ``(k, j)``."""
        memo = self._memo
        todo = [(k, j, z) for k, j, z in queries if (k, j) not in memo]
        if todo:
            ks = np.array([q[0] for q in todo])
            hits = self.occupied_many(ks, np.array([q[2] for q in todo], dtype=float))
            for (k, j, _), h in zip(todo, hits.tolist()):
                memo[(k, j)] = h
        return [memo[(k, j)] for k, j, _ in queries]

    def occupied_many(self, ks: np.ndarray, zs: np.ndarray) -> np.ndarray:
        """:meth:`occupied` of positions ``zs`` (m, 2) at scans ``ks`` (m,)."""
        nb = ks[:, None] + self.offsets[None, :]                   # (m, 2w+1): scan k + o
        valid = (nb >= 0) & (nb < self.n)
        # np.minimum(np.maximum(…)) rather than np.clip: the same integers, without
        # np.clip's ~20 µs of dtype checks per call (several hundred calls a trial)
        Q = self.P.take(np.minimum(np.maximum(nb, 0), self.n - 1), axis=0)  # (m, 2w+1, J, 2)
        near = hypot_below(Q[..., 0] - zs[:, None, None, 0], Q[..., 1] - zs[:, None, None, 1],
                           self.r)
        count = (near.any(axis=2) & valid).sum(axis=1)
        return count >= self.fraction * valid.sum(axis=1)

    def occupied(self, k: int, z) -> bool:
        return bool(self.occupied_many(np.array([k]), np.asarray(z, dtype=float)[None, :])[0])


def hypot_below(dx: np.ndarray, dy: np.ndarray, r: float) -> np.ndarray:
    """``np.hypot(dx, dy) < r``, elementwise, with the same result but cheaper: dx² + dy² is
    compared with r², and ``np.hypot`` (a libm call per element) is evaluated only where
    dx² + dy² lies within a relative 1e-9 of r² (rounding cannot decide there)."""
    d2 = dx * dx
    d2 += dy * dy
    r2 = r * r
    lo, hi = r2 * (1.0 - 1e-9), r2 * (1.0 + 1e-9)
    near = d2 < lo
    edge = (d2 >= lo) & (d2 <= hi)
    if edge.any():
        near[edge] = np.hypot(dx[edge], dy[edge]) < r
    return near
