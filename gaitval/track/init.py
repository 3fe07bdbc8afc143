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
            best = min(leg_pairs(obs, d_min, self.max_pair_m), key=lambda p: p[2],
                       default=None)                       # the closest (first of equals)
            if best is not None:
                return left_first(k, obs, best[0], best[1])
        return None


def leg_pairs(obs, d_min: float, d_max: float):
    """``(i, j, d)`` of every pair i < j of one scan's observations ``d_min``..``d_max``
    apart (a pair of legs; nearer than ~0.7 w_l is one leg seen twice)."""
    for i in range(len(obs)):
        for j in range(i + 1, len(obs)):
            d = math.hypot(*(obs[i] - obs[j]))
            if d_min <= d <= d_max:
                yield i, j, d


def left_first(k: int, obs, i: int, j: int) -> tuple[int, int, int]:
    """``(k, left, right)`` for the pair (i, j): the observation at the larger bearing is
    the left leg (the tracker may decide the sides again from the walking direction)."""
    ai = math.atan2(obs[i][1], obs[i][0])
    aj = math.atan2(obs[j][1], obs[j][0])
    return (k, i, j) if ai >= aj else (k, j, i)


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
        return keep_if_moving(self, source, super().find(source, leg_width_m), leg_width_m)


def keep_if_moving(init, source, start, leg_width_m: float):
    """``start``, or None when no leg-like pair of ``source`` moves from its scan on
    (``init``'s ``check``, a :class:`MotionCheck`, with its ``require_motion``,
    ``min_scans``, ``min_leg_widths`` and ``max_pair_m``): the no-subject rule of
    ``closest_pair`` and ``mtst_participant``."""
    if start is None or not init.require_motion or len(source) < init.min_scans:
        return start
    d_min = init.min_leg_widths * leg_width_m
    moving = init.check.moving_pair(source, d_min, init.max_pair_m, first_scan=start[0],
                                    leg_width_m=leg_width_m)
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

    def moving_pair(self, source, d_min: float, d_max: float, first_scan: int = 0,
                    leg_width_m: float | None = None) -> tuple[int, int, int] | None:
        """The first moving pair ``(k, i, j)`` from ``first_scan`` on, or None
        (``leg_width_m`` is not used: the travel is in metres)."""
        arrays = [source.array(k) for k in range(len(source))]        # (J, 2) float each
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


class WalkingPairCheck:
    """Is there a pair of legs that walks *with* the sensor?  (For a laser that travels with
    its user: the rollator's, seed 002.)

    :class:`MotionCheck` asks the legs to travel in a still scene; on a rollator the scene
    is never still (the sensor moves with the user) and the user's legs do not travel away
    from the sensor: they stay in its observation window ("a rectangle area in the LRF's
    scanning plane, where the user is expected to be w.r.t. the rollator", seed 002 §II)
    and swing past each other.  A leg-like pair (``d_min``..``d_max`` apart, the
    ``per_scan`` closest of a scan) is followed scan by scan, each leg by its nearest
    observation within what a leg can move, ``max_speed_mps`` · Δt · (1 + scans unseen)
    (at most ``max_gate_m``; a shared observation goes to the nearer leg; the pair may not
    grow beyond ``1.5 d_max``), until a leg is unseen for more than a third of the window.
    The pair walks when, in some window of N = round(``window_s`` / Δt) consecutive scans
    of its follow, with r = p_L − p_R and c = (p_L + p_R) / 2 on the scans that saw both
    legs::

        |{scans with both legs}| ≥ M = ⌈m_fraction · N⌉                        (M of N)
        min r·û ≤ −c_p  ∧  max r·û ≥ c_p       (the legs pass each other; û: longest r)
        RMS(c − c̄) ≤ stay_leg_widths · w_l                 (the body stays with the sensor)

    with c_p = ``pass_leg_widths`` · w_l and û the direction along which r varies most
    (the principal axis of the window's r: the walking direction).  The first two are the
    people tracker's confirmation tests (:class:`gaitval.track.lifecycle.MOfNMoving`,
    docs/people.md); the third is its "the body walks steadily" for a user who walks
    *with* the sensor: in the sensor frame the body stays where it is (within one leg
    width, RMS).  Objects seen from a robot that drives or turns sweep through the window
    (their centre travels), and a follow that hops from one object to the next jumps.
    Defaults: the people tracker's window (1.4 s, one stride at 85 steps/min), M of N and
    pass threshold (one leg width); ``max_speed_mps`` = 5 m/s, a fast swing (the value
    :class:`MotionCheck`'s 0.7 m step per 7.5 Hz scan stands for).
    """

    def __init__(self, window_s: float = 1.4, m_fraction: float = 0.5,
                 pass_leg_widths: float = 1.0, stay_leg_widths: float = 1.0,
                 max_speed_mps: float = 5.0, max_gate_m: float = 1.0, per_scan: int = 3):
        self.window_s = float(window_s)
        self.m_fraction = float(m_fraction)
        self.pass_leg_widths = float(pass_leg_widths)
        self.stay_leg_widths = float(stay_leg_widths)
        self.max_speed_mps = float(max_speed_mps)
        self.max_gate_m = float(max_gate_m)
        self.per_scan = int(per_scan)

    def window_scans(self, source) -> int:
        """N: the scans of one window at the source's scan period."""
        return max(2, int(round(self.window_s / scan_period(source))))

    def moving_pair(self, source, d_min: float, d_max: float, first_scan: int = 0,
                    leg_width_m: float = 0.10) -> tuple[int, int, int] | None:
        """The first walking pair ``(k, i, j)`` from ``first_scan`` on, or None."""
        dt = scan_period(source)
        n = max(2, int(round(self.window_s / dt)))
        m = max(1, math.ceil(self.m_fraction * n))
        max_lost = max(1, n // 3)
        step = self.max_speed_mps * dt
        pts = _LazyLists(source)
        visited: set[tuple[int, int, int]] = set()
        pick = MotionCheck(per_scan=self.per_scan)._pairs
        for k in range(first_scan, len(pts)):
            for i, j in pick(pts[k], d_min, d_max):
                if (k, i, j) in visited:
                    continue
                if self._follow(pts, k, i, j, n, m, max_lost, step, 1.5 * d_max,
                                leg_width_m, visited):
                    return k, i, j
        return None

    def _follow(self, pts, k0, i, j, n, m, max_lost, step, span, leg_width_m,
                visited) -> bool:
        pos = [pts[k0][i], pts[k0][j]]
        lost = [0, 0]
        hist: list = [(pos[0][0] - pos[1][0], pos[0][1] - pos[1][1],
                       0.5 * (pos[0][0] + pos[1][0]), 0.5 * (pos[0][1] + pos[1][1]))]
        for k in range(k0 + 1, len(pts)):
            obs = pts[k]
            got = self._associate(obs, pos, lost, step, span)
            for f in (0, 1):
                if got[f] is None:
                    lost[f] += 1
                else:
                    pos[f], lost[f] = obs[got[f]], 0
            if got[0] is not None and got[1] is not None:
                visited.add((k, min(got), max(got)))
                (xl, yl), (xr, yr) = pos
                hist.append((xl - xr, yl - yr, 0.5 * (xl + xr), 0.5 * (yl + yr)))
            else:
                hist.append(None)
            if len(hist) >= n and self._walks(hist[-n:], m, leg_width_m):
                return True
            if lost[0] > max_lost or lost[1] > max_lost:
                return False
        return False

    def _walks(self, win, m, leg_width_m) -> bool:
        """The window's tests (class notes) on ``win``: per scan (rx, ry, cx, cy) or None."""
        idx = [q for q, h in enumerate(win) if h is not None]
        if len(idx) < m:
            return False
        ux, uy = principal_axis([win[q][:2] for q in idx])    # û: where r varies most
        proj = [win[q][0] * ux + win[q][1] * uy for q in idx]
        cp = self.pass_leg_widths * leg_width_m
        if min(proj) > -cp or max(proj) < cp:
            return False
        c = np.array([win[q][2:] for q in idx])
        rms = math.sqrt(float(((c - c.mean(axis=0)) ** 2).sum(axis=1).mean()))
        return rms <= self.stay_leg_widths * leg_width_m

    def _associate(self, obs, pos, lost, step, span) -> list[int | None]:
        """Each leg's nearest observation within its gate (class notes)."""
        got: list[int | None] = [None, None]
        dist = [0.0, 0.0]
        for f in (0, 1):
            px, py = pos[f]
            best, dm = None, math.inf
            for q, (x, y) in enumerate(obs):
                d = math.hypot(x - px, y - py)
                if d < dm:
                    best, dm = q, d
            if best is not None and dm <= min(step * (1 + lost[f]), self.max_gate_m):
                got[f], dist[f] = best, dm
        if got[0] is not None and got[0] == got[1]:
            got[1 if dist[0] <= dist[1] else 0] = None
        if got[0] is not None and got[1] is not None:
            a, b = obs[got[0]], obs[got[1]]
            if math.hypot(a[0] - b[0], a[1] - b[1]) > span:
                got[0 if dist[0] > dist[1] else 1] = None
        return got


class _LazyLists:
    """``source.array(k).tolist()`` computed when first asked for (a windowed detector
    costs milliseconds a scan; a walking pair is usually found in the first seconds)."""

    def __init__(self, source):
        self.source, self.cache = source, {}

    def __len__(self) -> int:
        return len(self.source)

    def __getitem__(self, k: int) -> list:
        got = self.cache.get(k)
        if got is None:
            got = self.cache[k] = self.source.array(k).tolist()
        return got


def principal_axis(rs) -> tuple[float, float]:
    """The unit direction along which the 2-D vectors ``rs`` vary most: the principal axis
    of their covariance, θ = ½·atan2(2 s_xy, s_xx − s_yy) (a 2 × 2 symmetric matrix's
    eigenvector of the larger eigenvalue; (1, 0) when they do not vary).

    For a walker's r = p_L − p_R this is the walking direction: r swings along it (± half
    the step length) while its component across it stays at the step width.  The direction
    of the *longest* r is not: it leans towards the step width, and when the step width is
    close to the swing the other leg's r never reaches the far side along it (a = 0.25 m,
    step width 0.2 m: −(a² − s²)/√(a² + s²) = −0.07 m, less than one leg width)."""
    n = len(rs)
    if n < 2:
        return 1.0, 0.0
    mx = sum(r[0] for r in rs) / n
    my = sum(r[1] for r in rs) / n
    sxx = sum((r[0] - mx) ** 2 for r in rs)
    syy = sum((r[1] - my) ** 2 for r in rs)
    sxy = sum((r[0] - mx) * (r[1] - my) for r in rs)
    if sxx == 0.0 and syy == 0.0 and sxy == 0.0:
        return 1.0, 0.0
    th = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    return math.cos(th), math.sin(th)


def scan_period(source) -> float:
    """The median scan period of an observation source (s): from its scans' times when it
    has them (:class:`~gaitval.track.observations.WindowedDetections`), else 0.1 s."""
    scans = getattr(source, "scans", None)
    if scans is not None and len(scans.t) > 1:
        d = np.diff(np.asarray(scans.t, dtype=float))
        d = d[d > 0]
        if len(d):
            return float(np.median(d))
    return 0.1


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
        Q = self.P.take(np.clip(nb, 0, self.n - 1), axis=0)        # (m, 2w+1, J, 2)
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
