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
        (``leg_width_m`` is not used: the travel is in metres).  Each pair is followed by
        the compiled :func:`gaitval.track.init_motion_kernel.follow`."""
        from gaitval.track.init_motion_kernel import follow

        every = getattr(source, "arrays", None)          # every scan's (J, 2) float array
        arrays = (every() if every is not None
                  else [source.array(k) for k in range(len(source))])
        still = self.still_scans(arrays)
        bg = Background(arrays)
        memo = np.full(bg.P.shape[:2], -1, dtype=np.int8)    # background test per obs.
        visited_k = np.empty((len(arrays), 3), dtype=np.int64)
        visited: set[tuple[int, int, int]] = set()          # (k, i, j) followed already
        for k in range(first_scan, len(arrays)):
            if len(arrays[k]) < 2:
                continue
            for i, j in self._pairs(arrays[k].tolist(), d_min, d_max):
                if (k, i, j) in visited:
                    continue                       # already followed from an earlier scan
                moved, nv = follow(bg.P, bg.sizes, still, memo, k, i, j, 1.5 * d_max,
                                   self.min_travel_m, self.max_step_m, self.max_gate_m,
                                   self.max_lost_scans, bg.r, bg.window, bg.fraction,
                                   visited_k)
                if moved:
                    return k, i, j
                visited.update(map(tuple, visited_k[:nv].tolist()))
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


class Background:
    """Places observed again and again: an observation lies within ``radius_m`` of a
    position in at least ``fraction`` of the scans ``k - window .. k + window`` (the test is
    :func:`gaitval.track.init_motion_kernel._occupied`).  The scans are held as one
    padded ``(n, J_max, 2)`` array ``P`` (padding far from everything) with ``sizes``, the
    layout the compiled follow (:mod:`gaitval.track.init_motion_kernel`) reads.
    """

    def __init__(self, arrays: list[np.ndarray], radius_m: float = 0.06, window: int = 15,
                 fraction: float = 0.5):
        self.r, self.window, self.fraction, self.n = radius_m, window, fraction, len(arrays)
        self.sizes = np.array([len(a) for a in arrays], dtype=np.int64)
        jmax = int(self.sizes.max()) if len(self.sizes) else 0
        self.P = np.full((self.n, max(jmax, 1), 2), 1e9)
        if jmax:
            self.P[np.arange(jmax)[None, :] < self.sizes[:, None]] = np.concatenate(arrays)
