"""Motion models: the acceleration input u of seed000 eq. (1) (seed 000 §3, §5.5).

Role ``motion``: ``inputs(phase, vl, vr, gl, gr, dt) -> ((ulx, uly), (urx, ury))`` and the
acceleration-gain window ``n_ac``.

Notes
-----
seed000 eq. (18): Phase 0 → u^L = u^R = 0.
seed000 eq. (19): Phase 1 → u^L = g^L v^L/‖v^L‖, u^R = 0.
seed000 eq. (20): Phase 2 → u^L = −g^L v^L/‖v^L‖, u^R = 0.
Phases 3 and 4 mirror 1 and 2 for the right leg.  Phase 5 (both legs swinging) has no
input in the paper; gaitval uses u = 0 there.

Braking limit (gaitval's addition, ``limit_braking=True``): in the decelerating phases the
input may stop the leg within one step but not reverse it, ‖u‖ ≤ ‖v‖/Δt.  Without it,
g·Δt (≈ 1 m/s per 25 ms step for a swing acceleration of 40 m/s²) overshoots the stance
band ‖v‖ < v_st_th at the end of every swing; the reversed velocity then points back
towards the stance leg, seed000 eq. (5) calls that "accelerating" (Phase 1/3), and eq. (19)
accelerates the leg backwards while it stands still — a runaway seen on simulated TUGs.
``limit_braking=False`` gives the paper's equations unchanged.

g_k^f, the acceleration function: "the average of the norm of the acceleration vector in
the swing phase of the previous N_ac steps".  The printed definition a = (ẋ/Δt, ẏ/Δt)
would be a velocity divided by Δt; gaitval reads it as the finite-difference acceleration
a_k = (v_k − v_{k−1})/Δt of the filtered velocity, averaged over those of the previous N_ac
steps in which leg f was in swing (0 when there were none).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from gaitval.registry import Registry
from gaitval.track.params import NO_SOURCE, declared, param

MOTION_MODELS = Registry("motion model", table="gaitval.track.roles")

_ZERO = (0.0, 0.0)


def _along(v: tuple[float, float], g: float, brake_dt: float = 0.0) -> tuple[float, float]:
    """g · v/‖v‖; with ``brake_dt`` > 0 a braking input (g < 0) is limited to ‖v‖/Δt."""
    n = math.hypot(v[0], v[1])
    if n <= 1e-9 or g == 0.0:
        return _ZERO
    if brake_dt > 0.0 and g < 0.0:
        g = max(g, -n / brake_dt)
    return (g * v[0] / n, g * v[1] / n)


class SwingAccelerationWindow:
    """g_k^f of seed000 eq. (19)–(20): the mean ‖a‖ of one leg over the steps among the
    last N_ac in which it was swinging (0 when there were none).

    Kept as a running sum over the entries pushed since the last :meth:`reset`: :meth:`push`
    adds step k and drops step k − N_ac; after a re-filter rewrote the history,
    :meth:`reset` starts again from the rewritten window.  ``steps`` holds one entry per
    step, ‖a‖ when the leg was swinging and None when not.
    """

    __slots__ = ("n_ac", "steps", "total", "count", "mean")

    def __init__(self, n_ac: int):
        self.n_ac = n_ac
        self.steps: list[float | None] = []
        self.total = 0.0
        self.count = 0
        self.mean = 0.0          # = value(), kept current so the per-scan read is a load

    def push(self, a: float, swinging: bool) -> None:
        steps = self.steps
        changed = swinging
        if swinging:
            steps.append(a)
            self.total += a
            self.count += 1
        else:
            steps.append(None)
        i = len(steps) - 1 - self.n_ac          # the step that leaves the window
        if i >= 0:
            old = steps[i]
            if old is not None:
                self.total -= old
                self.count -= 1
                changed = True
        if changed:                              # else the mean is what it was
            self.mean = self.total / self.count if self.count > 0 else 0.0

    def reset(self, acc: list[float], swing: list[bool]) -> None:
        """Start from the window's steps, oldest first: ``acc`` their ‖a‖, ``swing`` whether
        the leg was swinging."""
        self.steps = [a if sw else None for a, sw in zip(acc, swing)]
        sel = [a for a, sw in zip(acc, swing) if sw]
        self.total, self.count = float(sum(sel)), len(sel)
        self.mean = self.total / self.count if self.count > 0 else 0.0

    def value(self) -> float:
        return self.mean


class MotionModel:
    """Role base.  ``n_ac`` = 0 means the model needs no acceleration gain;
    ``zero_input = True`` says :meth:`inputs` is always zero (the tracker then skips it)."""

    n_ac = 0
    zero_input = False

    def inputs(self, phase: int, vl, vr, gl: float, gr: float, dt: float):
        raise NotImplementedError

    def new_window(self) -> SwingAccelerationWindow | None:
        """A per-leg acceleration window for one run (None: the model needs none)."""
        return SwingAccelerationWindow(self.n_ac) if self.n_ac else None


@declared
@dataclass(eq=False)
class GaitPhaseAcceleration(MotionModel):
    """Acceleration input per gait phase, seed000 eq. (18)–(20)."""

    n_ac: int = param(40, "scans", "seed000 Table 2",
                      "N_ac, steps averaged for the acceleration function g")
    limit_braking: bool = param(True, "-", NO_SOURCE + " (gaitval's addition, module notes)",
                                "a braking input may stop the leg within a step, not "
                                "reverse it")

    def __post_init__(self):
        self.n_ac = int(self.n_ac)

    def inputs(self, phase, vl, vr, gl, gr, dt):
        bdt = dt if self.limit_braking else 0.0
        if phase == 1:
            return _along(vl, gl), _ZERO          # seed000 eq. (19)
        if phase == 2:
            return _along(vl, -gl, bdt), _ZERO    # seed000 eq. (20)
        if phase == 3:
            return _ZERO, _along(vr, gr)
        if phase == 4:
            return _ZERO, _along(vr, -gr, bdt)
        return _ZERO, _ZERO                       # seed000 eq. (18); Phase 5: none


class ConstantVelocity(MotionModel):
    """u = 0: the constant-velocity model of seed001 eq. (2) and seed 002 §II."""

    zero_input = True

    def inputs(self, phase, vl, vr, gl, gr, dt):
        return _ZERO, _ZERO
