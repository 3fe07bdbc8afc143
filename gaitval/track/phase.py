"""Gait-phase identification: the role that names the phase of both legs at a scan.

Role ``phase``: ``identify(l, r) -> int`` with ``l``, ``r`` the legs' filter states, read
as ``(x, y, vx, vy, …)`` (a posteriori, sensor frame) and the phase code of :mod:`gaitval.gait.phases` (0 both in
stance, 1/2 left swings accelerating/decelerating, 3/4 the same for the right leg, 5 both
swing).  The tracker feeds it to the motion model (seed000 eq. (18)–(20)), the gait-phase
associator (seed 000 §5.2) and context-dependent gates (seed001 Table 1).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), §3.2.
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (seed 001), eq. (9)–(10).
"""
from __future__ import annotations

from gaitval.gait.phases import gait_phase_of_states
from gaitval.registry import Registry

PHASE_MODELS = Registry("gait phase model")


class PhaseModel:
    """Role base."""

    def identify(self, l, r) -> int:
        raise NotImplementedError


@PHASE_MODELS.register("speed_thresholds")
class SpeedThresholdPhases(PhaseModel):
    """Swing/stance per leg from its speed against two thresholds and the other leg's
    speed (seed000 eq. (3)–(4), the same form as seed001 eq. (9)–(10)), and
    accelerating/decelerating from the swing leg's velocity towards the stance leg
    (seed000 eq. (5)).

    Parameters
    ----------
    v_st_th, v_sw_th : float
        Stance and swing speed thresholds (m/s): seed 000 Table 2 0.47 and 0.93; seed 001
        0.18 and 0.37.
    """

    def __init__(self, v_st_th: float = 0.47, v_sw_th: float = 0.93):
        self.v_st_th = v_st_th
        self.v_sw_th = v_sw_th

    def identify(self, l, r):
        return gait_phase_of_states(l, r, self.v_st_th, self.v_sw_th)   # seed000 eq. (3)–(5)
