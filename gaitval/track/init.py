"""Track initialisation: where and when the two leg tracks start, and whether anyone is there.

Role ``init``: ``find(source, leg_width_m) -> (k0, i_left, i_right) | None`` where
``source`` is an observation source (:mod:`gaitval.track.observations`: ``len(source)``
scans, ``source.array(k)`` the ``(J, 2)`` observed positions of scan k, sensor frame); None
means no subject was found (the run reports no track).

``closest_pair`` (:class:`ClosestMovingPair`, the TUG methods' initialiser)
    Starts where :class:`ClosestPair` does, but answers "no subject" when no leg-like pair
    in the trial moves (:class:`MotionCheck`): an empty scene — a real leg_tracker
    recording of a room with nobody in it — has plenty of leg-like pairs (chair and table
    legs, door frames), and without this check every TUG method reported two leg tracks on
    every scan of it.  The start itself is unchanged, so a trial with a walking subject
    gets exactly the track it got before.
:class:`ClosestPair` (not registered; the base of ``facing_pair``)
    The plain rule: the first scan with a plausible pair.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), §6.1
(TUG: the subject starts seated, both legs at the chair).
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. ICRA 2015 (the leg_tracker recordings of empty scenes, ``negative_*.bag``).
"""
from __future__ import annotations

import bisect
import math

import numpy as np

from gaitval.registry import Registry

INITIALISERS = Registry("initialiser")


class Initialiser:
    """Role base."""

    def find(self, source, leg_width_m: float) -> tuple[int, int, int] | None:
        raise NotImplementedError


class ClosestPair(Initialiser):
    """The first scan with two observations between ``min_leg_widths`` · w_l and
    ``max_pair_m`` apart (the closest such pair), both legs at rest.

    Two shanks cannot be closer than about 0.7 w_l (two observations nearer than that are
    one leg seen twice).  The observation with the larger bearing is taken as the left leg;
    the tracker may decide the sides again from the walking direction afterwards.

    Parameters
    ----------
    max_pair_m : float
        Largest distance between the two legs accepted (m).
    min_leg_widths : float
        Smallest distance, in leg widths.
    """

    def __init__(self, max_pair_m: float = 0.8, min_leg_widths: float = 0.7):
        self.max_pair_m = max_pair_m
        self.min_leg_widths = min_leg_widths

    def find(self, source, leg_width_m):
        d_min = self.min_leg_widths * leg_width_m
        for k in range(len(source)):
            obs = source.array(k)
            if len(obs) < 2:
                continue
            best = None
            for i in range(len(obs)):
                for j in range(i + 1, len(obs)):
                    d = math.hypot(*(obs[i] - obs[j]))
                    if d_min <= d <= self.max_pair_m and (best is None or d < best[0]):
                        best = (d, i, j)
            if best is not None:
                _, i, j = best
                ai = math.atan2(obs[i][1], obs[i][0])
                aj = math.atan2(obs[j][1], obs[j][0])
                return (k, i, j) if ai >= aj else (k, j, i)   # left = larger bearing
        return None


@INITIALISERS.register("closest_pair")
class ClosestMovingPair(ClosestPair):
    """:class:`ClosestPair`'s start, or None when no leg-like pair of the trial moves.

    Parameters
    ----------
    max_pair_m, min_leg_widths : float
        As :class:`ClosestPair` (also what counts as a leg-like pair for the motion check).
    require_motion : bool
        False gives :class:`ClosestPair` exactly.
    min_travel_m : float
        How far each leg of a pair must travel (net, over still scans, off the background)
        for the pair to count as moving (:class:`MotionCheck`).
    max_step_m : float
        Largest move of one leg between two scans (a 5 m/s swing at 7.5 scans/s).
    max_lost_scans : int
        A leg unseen for more scans than this ends the pair's follow.
    min_scans : int
        A source with fewer scans cannot show motion; its pair is kept.

    Notes
    -----
    The check assumes a sensor that stands still (TUG, MTST).  A sensor that moves with the
    walker (the rollator's) sees the whole scene move; its initialiser (``facing_pair``)
    derives from :class:`ClosestPair` and has no motion check.
    """

    def __init__(self, max_pair_m: float = 0.8, min_leg_widths: float = 0.7,
                 require_motion: bool = True, min_travel_m: float = 0.5,
                 max_step_m: float = 0.7, max_lost_scans: int = 8, min_scans: int = 10):
        super().__init__(max_pair_m=max_pair_m, min_leg_widths=min_leg_widths)
        self.require_motion = bool(require_motion)
        self.min_scans = int(min_scans)
        self.check = MotionCheck(min_travel_m=min_travel_m, max_step_m=max_step_m,
                                 max_lost_scans=max_lost_scans)

    def find(self, source, leg_width_m):
        start = super().find(source, leg_width_m)
        if start is None or not self.require_motion or len(source) < self.min_scans:
            return start
        d_min = self.min_leg_widths * leg_width_m
        moving = self.check.moving_pair(source, d_min, self.max_pair_m, first_scan=start[0])
        return start if moving is not None else None


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

    def __init__(self, min_travel_m: float = 0.5, max_step_m: float = 0.7,
                 max_lost_scans: int = 8, per_scan: int = 3, still_min_obs: int = 8,
                 still_lag: int = 3, still_radius_m: float = 0.05):
        self.min_travel_m = float(min_travel_m)
        self.max_step_m = float(max_step_m)
        self.max_lost_scans = int(max_lost_scans)
        self.per_scan = int(per_scan)
        self.still_min_obs = int(still_min_obs)
        self.still_lag = int(still_lag)
        self.still_radius_m = float(still_radius_m)
        self.max_gate_m = 1.0        # a leg unseen for a while: still no further than this

    def moving_pair(self, source, d_min: float, d_max: float, first_scan: int = 0
                    ) -> tuple[int, int, int] | None:
        """The first moving pair ``(k, i, j)`` from ``first_scan`` on, or None."""
        arrays = [np.asarray(source.array(k), dtype=float).reshape(-1, 2)
                  for k in range(len(source))]
        still = self.still_scans(arrays)
        background = Background(arrays)
        visited: dict[int, set] = {}
        for k in range(first_scan, len(arrays)):
            for i, j in self._pairs(arrays[k], d_min, d_max):
                if (i, j) in visited.get(k, ()):
                    continue                       # already followed from an earlier scan
                if self._follow(arrays, still, background, k, i, j, 1.5 * d_max, visited):
                    return k, i, j
        return None

    def _pairs(self, obs: np.ndarray, d_min: float, d_max: float) -> list[tuple[int, int]]:
        """The ``per_scan`` closest leg-like pairs (i < j) of one scan."""
        if len(obs) < 2:
            return []
        iu, ju = np.triu_indices(len(obs), 1)
        d = np.hypot(obs[iu, 0] - obs[ju, 0], obs[iu, 1] - obs[ju, 1])
        ok = np.flatnonzero((d >= d_min) & (d <= d_max))
        ok = ok[np.argsort(d[ok], kind="stable")][:self.per_scan]
        return [(int(iu[q]), int(ju[q])) for q in ok]

    def still_scans(self, arrays: list[np.ndarray]) -> np.ndarray:
        """Per scan: True unless the scene moved (a crowded scan most of whose observations
        are not within ``still_radius_m`` of one ``still_lag`` scans earlier)."""
        still = np.ones(len(arrays), dtype=bool)
        for k in range(self.still_lag, len(arrays)):
            a, b = arrays[k], arrays[k - self.still_lag]
            if len(a) < self.still_min_obs:
                continue                   # a sparse scan: the background was subtracted
            if len(b) == 0:
                still[k] = False
                continue
            d = np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])
            still[k] = np.mean(d.min(axis=1) < self.still_radius_m) >= 0.5
        return still

    def _follow(self, arrays, still, background, k0, i, j, span, visited) -> bool:
        """Follow the pair (i, j) of scan k0; True once both legs travelled far enough."""
        pos = [arrays[k0][i].copy(), arrays[k0][j].copy()]
        net = [np.zeros(2), np.zeros(2)]
        lost = [0, 0]
        for k in range(k0 + 1, len(arrays)):
            obs = arrays[k]
            got = self._associate(obs, pos, lost, span)
            for f in (0, 1):
                if got[f] is None:
                    lost[f] += 1
                    continue
                z = obs[got[f]]
                if still[k] and not background.occupied_obs(k, got[f], z):
                    net[f] += z - pos[f]
                pos[f], lost[f] = z.copy(), 0
            if got[0] is not None and got[1] is not None:
                visited.setdefault(k, set()).add((min(got), max(got)))
            if min(math.hypot(*net[0]), math.hypot(*net[1])) >= self.min_travel_m:
                return True
            if max(lost) > self.max_lost_scans:
                return False
        return False

    def _associate(self, obs, pos, lost, span) -> list[int | None]:
        """Each leg's nearest observation within its gate; a shared one goes to the nearer
        leg, and a pair may not grow beyond ``span``."""
        got: list[int | None] = [None, None]
        dist = [0.0, 0.0]
        if not len(obs):
            return got
        for f in (0, 1):
            d = np.hypot(obs[:, 0] - pos[f][0], obs[:, 1] - pos[f][1])
            m = int(np.argmin(d))
            if d[m] <= min(self.max_step_m * (1 + lost[f]), self.max_gate_m):
                got[f], dist[f] = m, float(d[m])
        if got[0] is not None and got[0] == got[1]:
            got[1 if dist[0] <= dist[1] else 0] = None
        if got[0] is not None and got[1] is not None and \
                math.hypot(*(obs[got[0]] - obs[got[1]])) > span:
            got[0 if dist[0] > dist[1] else 1] = None
        return got


class Background:
    """Places observed again and again: a grid index of every observation of a trial.

    ``occupied(k, z)``: an observation lies within ``radius_m`` of ``z`` in at least
    ``fraction`` of the scans ``k - window .. k + window``.
    """

    def __init__(self, arrays: list[np.ndarray], radius_m: float = 0.06, window: int = 15,
                 fraction: float = 0.5):
        self.r, self.window, self.fraction, self.n = radius_m, window, fraction, len(arrays)
        self._memo: dict[tuple[int, int], bool] = {}
        # per grid cell: the scans (ascending, as appended) and positions of its observations
        self.cells: dict[tuple[int, int], tuple[list[int], list[tuple[float, float]]]] = {}
        for k, obs in enumerate(arrays):
            for x, y in obs.tolist():
                ks, xy = self.cells.setdefault(self._cell(x, y), ([], []))
                ks.append(k)
                xy.append((x, y))

    def _cell(self, x: float, y: float) -> tuple[int, int]:
        return math.floor(x / self.r), math.floor(y / self.r)

    def occupied_obs(self, k: int, j: int, z: np.ndarray) -> bool:
        """:meth:`occupied` for observation j of scan k, remembered (several candidate pairs
        are followed through the same scans)."""
        key = (k, j)
        hit = self._memo.get(key)
        if hit is None:
            hit = self._memo[key] = self.occupied(k, z)
        return hit

    def occupied(self, k: int, z: np.ndarray) -> bool:
        lo, hi = max(0, k - self.window), min(self.n - 1, k + self.window)
        cx, cy = self._cell(float(z[0]), float(z[1]))
        zx, zy = float(z[0]), float(z[1])
        scans = set()
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                cell = self.cells.get((cx + dx, cy + dy))
                if cell is None:
                    continue
                ks, xy = cell
                # only the cell's observations of scans lo..hi (ks is ascending)
                for q in range(bisect.bisect_left(ks, lo), bisect.bisect_right(ks, hi)):
                    x, y = xy[q]
                    if math.hypot(x - zx, y - zy) < self.r:
                        scans.add(ks[q])
        return len(scans) >= self.fraction * (hi - lo + 1)
