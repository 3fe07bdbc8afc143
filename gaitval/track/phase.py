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

import types
from dataclasses import dataclass

from gaitval.gait.phases import (check_reading, gait_phase_of_states,
                                 gait_phase_of_states_stance_first)
from gaitval.registry import Registry
from gaitval.track.params import declared, param

PHASE_MODELS = Registry("gait phase model", table="gaitval.track.roles")


class PhaseModel:
    """Role base."""

    def identify(self, l, r) -> int:
        raise NotImplementedError


@declared
@dataclass(eq=False)
class SpeedThresholdPhases(PhaseModel):
    """Swing/stance per leg from its speed against two thresholds and the other leg's
    speed (seed000 eq. (3)–(4), the same form as seed001 eq. (9)–(10)), and
    accelerating/decelerating from the swing leg's velocity towards the stance leg
    (seed000 eq. (5)).

    ``reading`` says which of eq. (3)–(4) decides where both hold (:mod:`gaitval.gait.phases`
    notes): ``swing_first`` lets the absolute thresholds win, so two fast legs are Phase 5;
    ``stance_first`` puts the slower leg in stance first, so Phase 5 is all but impossible.
    Set per method as ``phase__reading``; TUG Tables 3–4 report both (config
    ``tug.phase_readings``).  Seed 001 uses 0.18 and 0.37 m/s as its thresholds.
    """

    v_st_th: float = param(0.47, "m/s", "seed000 Table 2", "stance speed threshold")
    v_sw_th: float = param(0.93, "m/s", "seed000 Table 2", "swing speed threshold")
    reading: str = param("swing_first", "-", "gaitval's reading of seed000 eq. (3)–(4)",
                         "swing_first or stance_first")

    def __post_init__(self):
        reading = self.reading = check_reading(self.reading)
        self._of_states = (gait_phase_of_states_stance_first if reading == "stance_first"
                           else gait_phase_of_states)
        # identify(l, r): the same function with this model's thresholds as its defaults,
        # one Python frame per call (it runs several times a scan) -- the phase model's
        # per-run kernel
        f = self._of_states
        self.identify = types.FunctionType(f.__code__, f.__globals__, "identify",
                                           (self.v_st_th, self.v_sw_th))  # eq. (3)–(5)

    def __reduce__(self):       # the bound copy does not pickle: rebuild it from the parameters
        return type(self), (self.v_st_th, self.v_sw_th, self.reading)

    def identify(self, l, r):  # the role's method; each instance binds a copy of it (above)
        return self._of_states(l, r, self.v_st_th, self.v_sw_th)   # seed000 eq. (3)–(5)
