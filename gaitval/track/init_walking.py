"""Does a pair of legs walk *with* the sensor?  The check of the ``facing_pair`` initialiser
for a laser that travels with its user (the rollator's, seed 002).

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017, §II.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitval.track.init_motion import MotionCheck
from gaitval.track.params import NO_SOURCE, coerce, declared, param


@declared
@dataclass(eq=False)
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

    window_s: float = param(1.4, "s", NO_SOURCE + " (one stride at 85 steps/min)",
                            "the window N is counted over")
    m_fraction: float = param(0.5, "-", NO_SOURCE + " (the people tracker's M of N)",
                              "M = ⌈m_fraction · N⌉ scans with both legs")
    pass_leg_widths: float = param(1.0, "leg widths", NO_SOURCE, "c_p, the legs' passing")
    stay_leg_widths: float = param(1.0, "leg widths", NO_SOURCE,
                                   "largest RMS of the legs' midpoint about its mean")
    max_speed_mps: float = param(5.0, "m/s", NO_SOURCE + " (a fast swing)",
                                 "what a leg can move per scan period")
    max_gate_m: float = param(1.0, "m", NO_SOURCE, "largest gate of a leg unseen for a while")
    per_scan: int = param(3, "pairs", NO_SOURCE, "closest leg-like pairs followed per scan")

    def __post_init__(self):
        coerce(self)

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
