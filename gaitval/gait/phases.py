"""Gait phase identification from both legs' estimated states (seed 000 §3, §3.2, §5.2).

Six phases (seed 000 §3, Figure 6):

====  ============================================================
0     both legs in stance
1     left leg swinging and accelerating, right leg in stance
2     left leg swinging and decelerating, right leg in stance
3     left leg in stance, right leg swinging and accelerating
4     left leg in stance, right leg swinging and decelerating
5     both legs swinging (unlikely in walking)
====  ============================================================

Notes
-----
Stance condition of the right leg, seed000 eq. (3): ‖v^R‖ < ‖v^L‖ ∨ ‖v^R‖ < v_st_th.
Swing condition, seed000 eq. (4): ‖v^R‖ > ‖v^L‖ ∨ ‖v^R‖ > v_sw_th.  (The left leg likewise.)

The two conditions overlap (a leg slower than the other but above v_sw_th satisfies
both) and can both fail (equal speeds between the thresholds).  The paper does not say
which wins, so both readings are available (``reading``):

* ``swing_first`` (the default, gaitval's reading since the start): ‖v‖ < v_st_th →
  stance and ‖v‖ > v_sw_th → swing (the absolute thresholds win: both legs slow is
  Phase 0, both fast is Phase 5); between the thresholds the relative test decides: the
  strictly faster leg swings, the other is in stance (equal speeds: stance).
* ``stance_first``: eq. (3) is tested first, so a leg slower than the other, or slower
  than v_st_th, is in stance; otherwise it swings when eq. (4) holds, and is in stance
  when it does not (equal speeds between the thresholds).  The slower leg is then always in
  stance: Phase 5 needs equal speeds above v_sw_th, and v_sw_th decides nothing else.

Why the default stays ``swing_first`` (docs/tracking.md): the paper lists v_sw_th in
Table 2 (0.93 m/s), and only the swing-first reading gives it a role; it calls Phase 5
"the unlikely state", not an impossible one, and lists transitions into it as unlikely
(§5.2), which presumes the identification can produce it.  The stance-first reading fits
the order in which eq. (3) and (4) are written and makes Phase 5 as rare as the words
suggest; neither is ruled out by the text, so TUG Tables 3–4 report both.

Acceleration vs deceleration, seed000 eq. (5): with the left leg swinging and the right in
stance,
(p^R − p^L)·v^L > 0 (the swing leg is still behind the stance leg: accelerating) is
Phase 1, otherwise Phase 2 (it has passed the stance leg: decelerating); mirrored for the right leg (Phases 3/4).

Unlikely transitions (§5.2): 0→5; 1→0,3,4,5; 2→1,4,5; 3→0,1,2,5; 4→2,3,5.  Nothing is
listed for Phase 5, so every transition out of 5 is allowed.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import math

import numpy as np

from gaitval.errors import ConfigError

#: seed 000 §5.2: phase at k-1 → phases at k that are unlikely in human walking.
UNLIKELY_TRANSITIONS: dict[int, frozenset[int]] = {
    0: frozenset({5}),
    1: frozenset({0, 3, 4, 5}),
    2: frozenset({1, 4, 5}),
    3: frozenset({0, 1, 2, 5}),
    4: frozenset({2, 3, 5}),
    5: frozenset(),
}

#: legs swinging in each phase: (left swings, right swings)
SWINGING = {0: (False, False), 1: (True, False), 2: (True, False),
            3: (False, True), 4: (False, True), 5: (True, True)}


def is_unlikely(prev_phase: int, phase: int) -> bool:
    """True when ``prev_phase → phase`` is in the list of seed 000 §5.2."""
    return phase in UNLIKELY_TRANSITIONS.get(prev_phase, frozenset())


#: The two readings of seed000 eq. (3)–(4) (module notes); the first is the default.
READINGS = ("swing_first", "stance_first")


def leg_swings(speed: float, other_speed: float, v_st_th: float, v_sw_th: float,
               reading: str = "swing_first") -> bool:
    """Swing (True) or stance (False) of one leg, seed000 eq. (3)–(4) under ``reading``
    (module notes)."""
    if reading == "stance_first":
        if speed < other_speed or speed < v_st_th:                   # seed000 eq. (3)
            return False
        return speed > other_speed or speed > v_sw_th                # seed000 eq. (4)
    if speed < v_st_th:
        return False
    if speed > v_sw_th:
        return True
    return speed > other_speed


def check_reading(reading: str) -> str:
    """``reading`` if it is one of :data:`READINGS`, else a ``ConfigError`` naming them."""
    if reading not in READINGS:
        raise ConfigError(f"unknown reading {reading!r} of seed000 eq. (3)-(4) "
                          "(phase__reading)", hint=f"choose one of {', '.join(READINGS)}")
    return reading


def gait_phase(pl: tuple[float, float], vl: tuple[float, float],
               pr: tuple[float, float], vr: tuple[float, float],
               v_st_th: float, v_sw_th: float, reading: str = "swing_first") -> int:
    """Gait phase 0–5 from both legs' positions and velocities (seed 000 §3.2).

    Parameters
    ----------
    pl, vl, pr, vr : (x, y) tuples
        Left/right position (m) and velocity (m/s).
    v_st_th, v_sw_th : float
        Stance and swing speed thresholds (m/s); seed 000 Table 2: 0.47, 0.93.
    reading : {"swing_first", "stance_first"}
        Which of eq. (3)–(4) wins where both hold (module notes).

    Returns
    -------
    int
        The phase (see the module table).
    """
    return gait_phase_xy(pl[0], pl[1], vl[0], vl[1], pr[0], pr[1], vr[0], vr[1],
                         v_st_th, v_sw_th, reading)


def gait_phase_xy(xl, yl, vxl, vyl, xr, yr, vxr, vyr, v_st_th, v_sw_th,
                  reading: str = "swing_first") -> int:
    """:func:`gait_phase` on plain floats."""
    if reading == "stance_first":
        return gait_phase_of_states_stance_first((xl, yl, vxl, vyl), (xr, yr, vxr, vyr),
                                                 v_st_th, v_sw_th)
    return gait_phase_of_states((xl, yl, vxl, vyl), (xr, yr, vxr, vyr), v_st_th, v_sw_th)


def _phase_of(lsw: bool, rsw: bool, l, r) -> int:
    """Phase code from the two legs' swing flags, seed000 eq. (5) for one swinging leg."""
    if lsw and rsw:
        return 5
    if not lsw and not rsw:
        return 0
    if lsw:
        # seed000 eq. (5): (p^R - p^L) · v^L
        return 1 if (r[0] - l[0]) * l[2] + (r[1] - l[1]) * l[3] > 0.0 else 2
    return 3 if (l[0] - r[0]) * r[2] + (l[1] - r[1]) * r[3] > 0.0 else 4


def gait_phase_of_states(l, r, v_st_th: float, v_sw_th: float) -> int:
    """:func:`gait_phase` of two states read as ``(x, y, vx, vy, …)`` (the tracker's loop),
    reading ``swing_first``."""
    vxl, vyl, vxr, vyr = l[2], l[3], r[2], r[3]
    sl = math.hypot(vxl, vyl)
    sr = math.hypot(vxr, vyr)
    # seed000 eq. (3)–(4) with the resolution of the module notes
    lsw = False if sl < v_st_th else (True if sl > v_sw_th else sl > sr)
    rsw = False if sr < v_st_th else (True if sr > v_sw_th else sr > sl)
    if lsw and rsw:
        return 5
    if not lsw and not rsw:
        return 0
    if lsw:
        # seed000 eq. (5): (p^R - p^L) · v^L
        return 1 if (r[0] - l[0]) * vxl + (r[1] - l[1]) * vyl > 0.0 else 2
    return 3 if (l[0] - r[0]) * vxr + (l[1] - r[1]) * vyr > 0.0 else 4


def gait_phase_of_states_stance_first(l, r, v_st_th: float, v_sw_th: float) -> int:
    """:func:`gait_phase_of_states` under the ``stance_first`` reading (module notes)."""
    sl = math.hypot(l[2], l[3])
    sr = math.hypot(r[2], r[3])
    # seed000 eq. (3) first: the slower leg, or a leg below v_st_th, is in stance; then
    # eq. (4)
    lsw = not (sl < sr or sl < v_st_th) and (sl > sr or sl > v_sw_th)
    rsw = not (sr < sl or sr < v_st_th) and (sr > sl or sr > v_sw_th)
    return _phase_of(lsw, rsw, l, r)


def gait_phases(pl: np.ndarray, vl: np.ndarray, pr: np.ndarray, vr: np.ndarray,
                v_st_th: float, v_sw_th: float, reading: str = "swing_first") -> np.ndarray:
    """Vectorised :func:`gait_phase` over (n, 2) arrays; returns int8 phases (n,)."""
    check_reading(reading)
    sl = np.hypot(vl[:, 0], vl[:, 1])
    sr = np.hypot(vr[:, 0], vr[:, 1])

    def swings(s, o):
        if reading == "stance_first":
            return ~((s < o) | (s < v_st_th)) & ((s > o) | (s > v_sw_th))
        return np.where(s < v_st_th, False, np.where(s > v_sw_th, True, s > o))

    lsw, rsw = swings(sl, sr), swings(sr, sl)
    ipl = np.einsum("ij,ij->i", pr - pl, vl)
    ipr = np.einsum("ij,ij->i", pl - pr, vr)
    out = np.zeros(len(sl), dtype=np.int8)
    out[lsw & ~rsw] = np.where(ipl[lsw & ~rsw] > 0, 1, 2)
    out[~lsw & rsw] = np.where(ipr[~lsw & rsw] > 0, 3, 4)
    out[lsw & rsw] = 5
    return out
