"""The motion check's follow of one leg-like pair, compiled with numba.

:meth:`gaitval.track.init_motion.MotionCheck.moving_pair` asks, pair by pair, whether both
legs of a leg-like pair travel ``min_travel_m`` (the rules are in
:class:`~gaitval.track.init_motion.MotionCheck`); :func:`follow` is that follow over the
trial's scans held as one padded array, with the background test
(:class:`~gaitval.track.init_motion.Background`) done step by step and remembered per
observation.  numba is imported only when a motion check runs (a tracking job loads the
compiled kernel once before its pool forks, :func:`gaitval.jobs.stages.preload`).

Every comparison is the one of the rules: the nearest observation is the first of equals,
a distance below a radius is ``hypot(dx, dy) < r`` (decided on dx² + dy² against r² except
within a relative 1e-9 of it, where the hypotenuse decides), and the net travel is summed
in scan order.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _below(dx: float, dy: float, r: float) -> bool:
    """``hypot(dx, dy) < r`` (see module notes)."""
    d2 = dx * dx + dy * dy
    r2 = r * r
    if d2 < r2 * (1.0 - 1e-9):
        return True
    if d2 > r2 * (1.0 + 1e-9):
        return False
    return math.hypot(dx, dy) < r


@njit(cache=True)
def _occupied(P, sizes, k, zx, zy, r, window, fraction) -> bool:
    """An observation lies within ``r`` of z in at least ``fraction`` of the scans
    k − window .. k + window (those inside the trial)."""
    n = P.shape[0]
    count = 0
    valid = 0
    for nb in range(k - window, k + window + 1):
        if nb < 0 or nb >= n:
            continue
        valid += 1
        for q in range(sizes[nb]):
            if _below(P[nb, q, 0] - zx, P[nb, q, 1] - zy, r):
                count += 1
                break
    return count >= fraction * valid


@njit(cache=True)
def _associate(P, sizes, k, pos, lost, got, dist, max_step, max_gate, span):
    """Each leg's nearest observation of scan k within its gate (-1: none); a shared one
    goes to the nearer leg, and a pair may not grow beyond ``span``."""
    got[0] = -1
    got[1] = -1
    J = sizes[k]
    if J == 0:
        return
    for f in range(2):
        m, dm = 0, math.inf
        for q in range(J):
            d = math.hypot(P[k, q, 0] - pos[f, 0], P[k, q, 1] - pos[f, 1])
            if d < dm:
                m, dm = q, d
        gate = max_step * (1 + lost[f])
        if dm <= min(gate, max_gate):
            got[f], dist[f] = m, dm
    if got[0] >= 0 and got[0] == got[1]:
        got[1 if dist[0] <= dist[1] else 0] = -1
    if got[0] >= 0 and got[1] >= 0:
        a, b = got[0], got[1]
        if math.hypot(P[k, a, 0] - P[k, b, 0], P[k, a, 1] - P[k, b, 1]) > span:
            got[0 if dist[0] > dist[1] else 1] = -1


@njit(cache=True)
def follow(P, sizes, still, memo, k0, i, j, span, min_travel, max_step, max_gate, max_lost,
           bg_r, bg_window, bg_fraction, visited):
    """Follow the pair (i, j) of scan k0 (rules in ``MotionCheck``).

    ``P`` (n, J_max, 2) the scans' observations (padding far away), ``sizes`` (n,) how many
    each scan has, ``still`` (n,) the still scans, ``memo`` (n, J_max) int8 the background
    test per observation (-1 not asked yet; shared by the follows of a trial),
    ``visited`` (n, 3) int64 filled with the ``(k, g0, g1)`` (g0 < g1) of the scans where
    both legs were followed.  Returns ``(moved, n_visited)``.
    """
    n = P.shape[0]
    pos = np.empty((2, 2))
    pos[0, 0], pos[0, 1] = P[k0, i, 0], P[k0, i, 1]
    pos[1, 0], pos[1, 1] = P[k0, j, 0], P[k0, j, 1]
    net = np.zeros((2, 2))
    lost = np.zeros(2, dtype=np.int64)
    got = np.empty(2, dtype=np.int64)
    dist = np.zeros(2)
    nv = 0
    for k in range(k0 + 1, n):
        _associate(P, sizes, k, pos, lost, got, dist, max_step, max_gate, span)
        for f in range(2):
            g = got[f]
            if g < 0:
                lost[f] += 1
                continue
            zx, zy = P[k, g, 0], P[k, g, 1]
            if still[k] and still[k - 1]:                 # a step within a still scene
                if memo[k, g] < 0:
                    memo[k, g] = 1 if _occupied(P, sizes, k, zx, zy, bg_r, bg_window,
                                                bg_fraction) else 0
                if memo[k, g] == 0:                       # off the background: it counts
                    net[f, 0] += zx - pos[f, 0]
                    net[f, 1] += zy - pos[f, 1]
            pos[f, 0], pos[f, 1] = zx, zy
            lost[f] = 0
        if got[0] >= 0 and got[1] >= 0:
            visited[nv, 0] = k
            visited[nv, 1] = min(got[0], got[1])
            visited[nv, 2] = max(got[0], got[1])
            nv += 1
        if (math.hypot(net[0, 0], net[0, 1]) >= min_travel
                and math.hypot(net[1, 0], net[1, 1]) >= min_travel):
            return True, nv
        if lost[0] > max_lost or lost[1] > max_lost:
            return False, nv
    return False, nv


def warm_up() -> None:
    """Compile :func:`follow` (or load it from numba's cache) on a tiny problem with the
    argument types :meth:`~gaitval.track.init_motion.MotionCheck.moving_pair` passes:
    two legs walking away over twelve still scans.  Called where
    :func:`gaitval.track.pf.warm_up` is (a stage verb before its pool forks its workers;
    ``run.py`` after installing); tests/test_track.py checks that a motion check
    afterwards adds no specialisation."""
    n = 12
    P = np.full((n, 2, 2), 1e9)
    P[:, 0, 0] = P[:, 1, 0] = 1.0 + 0.1 * np.arange(n)
    P[:, 0, 1], P[:, 1, 1] = 0.1, -0.1
    follow(P, np.full(n, 2, dtype=np.int64), np.ones(n, dtype=bool),
           np.full((n, 2), -1, dtype=np.int8), 0, 0, 1, 1.2, 0.5, 0.7, 1.0, 8, 0.06, 15,
           0.5, np.empty((n, 3), dtype=np.int64))
