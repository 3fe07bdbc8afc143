"""Gates (validation regions): which observations may be associated with a leg.

Role ``gate``: ``candidates(filter, prior, obs, ctx) -> [(j, λ²), …]`` lists the
observations of one scan inside one leg's gate, j = 1..J (1-based, as in the papers), with
λ² the squared Mahalanobis distance of seed000 eq. (11) (the associator turns it into its
cost).  The base class implements it from ``admits(lam2, dist, ctx)``, the test for one
observation, where ``dist`` is the Euclidean distance to the predicted position.

``ctx`` (:class:`GateContext`) is only built for gates with ``needs_context = True``: the
leg width w_l, Δt, the leg's speed ‖v_{k−1}‖, whether it was swinging at k−1 and H, the
number of consecutive scans it has been unobserved (UO) up to k−1.  The tracker loop calls
``candidates_at`` with those five values as arguments; the base class builds the
GateContext from them, a gate may compute from them directly.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), eq. (13).
Yorozu, A.; Moriguchi, T.; Takahashi, M. Gait Measurement System for the Multi-Target
Stepping Task Using a Laser Range Sensor. Sensors 2015, 15, 11151–11168 (seed 001), eq. (5),
Table 1 and §3 (fixed radii).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from gaitval.gait.phases import SWINGING
from gaitval.registry import Registry
from gaitval.track.params import declared, param

GATES = Registry("gate", table="gaitval.track.roles")


class GateContext(NamedTuple):
    """What a context-dependent gate knows about one leg at scan k (see module notes)."""

    leg_width_m: float
    dt: float
    speed: float          # ‖v_{k−1}‖ of the leg (a posteriori at k−1), m/s
    swing: bool           # the leg's gait phase at k−1 is swing
    n_unobserved: int     # H: consecutive UO scans up to k−1


class Gate:
    """Role base.  ``needs_context = False`` lets the tracker pass ``ctx=None`` (faster)."""

    needs_context = True

    def for_leg_width(self, leg_width_m: float) -> "Gate":
        """The gate for one run (one subject's w_l); a gate that needs only w_l from the
        context returns a bound copy with ``needs_context = False`` (faster)."""
        return self

    def admits(self, lam2: float, dist: float, ctx: GateContext | None) -> bool:
        raise NotImplementedError

    def kernel(self, run):
        """The gate of one run (:class:`~gaitval.track.trackingrun.TrackingRun`, its
        subject's w_l already bound, :meth:`for_leg_width`): ``gate(k, prior, obs) ->
        (cand_l, cand_r)`` for the pair of predicted states ``prior`` at scan k."""
        F = run.filter
        if not self.needs_context:
            candidates = self.candidates

            def gate(k, prior, obs):
                return candidates(F, prior[0], obs, None), candidates(F, prior[1], obs, None)
            return gate
        at, w, dts, phase, hypot = self.candidates_at, run.leg_width_m, run.dts, run.phase, \
            math.hypot
        L, R = run.legs
        Lpost, Rpost = L.post, R.post

        def gate(k, prior, obs):                   # the GateContext fields as arguments
            dt, sw = dts[k], SWINGING[phase[k - 1]]
            sl, sr = Lpost[k - 1], Rpost[k - 1]
            return (at(F, prior[0], obs, w, dt, hypot(sl[2], sl[3]), sw[0], L.n_unobserved),
                    at(F, prior[1], obs, w, dt, hypot(sr[2], sr[3]), sw[1], R.n_unobserved))
        return gate

    def candidates_at(self, filter, prior, obs, leg_width_m: float, dt: float, speed: float,
                      swing: bool, n_unobserved: int) -> list[tuple[int, float]]:
        """:meth:`candidates` with the :class:`GateContext` fields as arguments: the
        tracker loop's call for a gate that needs the context (a gate that overrides it
        spares the loop a GateContext per leg and scan)."""
        return self.candidates(filter, prior, obs,
                               GateContext(leg_width_m, dt, speed, swing, n_unobserved))

    def candidates(self, filter, prior, obs, ctx: GateContext | None
                   ) -> list[tuple[int, float]]:
        """``(j, λ²)`` of the gated observations (j = 1..J) of one leg."""
        px, py = filter.pos(prior)
        admits = self.admits
        return [(j, lam2) for j, (lam2, (zx, zy)) in
                enumerate(zip(filter.lam2_all(prior, obs), obs), 1)
                if admits(lam2, math.hypot(zx - px, zy - py), ctx)]

    @staticmethod
    def within_radius(filter, prior, obs, r: float) -> list[tuple[int, float]]:
        """``(j, λ²)`` of the observations closer than ``r`` to the prediction (seed001
        eq. (5)); λ² only for those (the radius gates' fast path, same result as
        :meth:`candidates` with ``admits = dist < r``).  A state begins ``(x, y, ...)``."""
        px, py = prior[0], prior[1]
        r2 = r * r
        inside = []
        j = 0
        for zx, zy in obs:
            j += 1
            dx = zx - px
            dy = zy - py
            if dx * dx + dy * dy < r2:
                inside.append(j)
        if not inside:
            return inside
        if len(inside) == 1:
            j = inside[0]
            return [(j, filter.mahalanobis2(prior, *obs[j - 1]))]
        return list(zip(inside, filter.lam2_all(prior, [obs[j - 1] for j in inside])))


@declared
@dataclass(eq=False)
class ChiSquareGate(Gate):
    """Mahalanobis gate λ² < G, seed000 eq. (13)."""

    needs_context = False
    g: float = param(13.82, "λ² (χ², 2 dof)", "seed000 Table 2",
                     "G, the gate (P_G = 0.999)")

    def admits(self, lam2, dist, ctx):
        return lam2 < self.g                        # seed000 eq. (13)

    def candidates(self, filter, prior, obs, ctx):
        return filter.gated(prior, obs, self.g)     # seed000 eq. (13)

    def kernel(self, run):
        gated_pair, g = run.filter.gated_pair, self.g

        def gate(k, prior, obs):
            return gated_pair(prior[0], prior[1], obs, g)   # seed000 eq. (13), both legs
        return gate


@declared
@dataclass(eq=False)
class FixedRadiusGate(Gate):
    """Circular gate ‖y − ŷ‖ < r_val, r_val = ``radius_leg_widths`` · w_l (seed001 eq. (5)).
    """

    radius_leg_widths: float = param(1.5, "leg widths",
                                     "seed001 §3 (1.5 in Methods 1–2, 1.0 in Method 3)",
                                     "r_val in leg widths")

    def radius(self, ctx: GateContext) -> float:
        return self.radius_leg_widths * ctx.leg_width_m

    def admits(self, lam2, dist, ctx):
        return dist < self.radius(ctx)              # seed001 eq. (5)

    def candidates(self, filter, prior, obs, ctx):
        return self.within_radius(filter, prior, obs,                      # seed001 eq. (5)
                                  self.radius_leg_widths * ctx.leg_width_m)

    def for_leg_width(self, leg_width_m):
        return _BoundRadius(self.radius_leg_widths * leg_width_m)


class _BoundRadius(Gate):
    """:class:`FixedRadiusGate` for one subject: r_val computed once, no context."""

    needs_context = False

    def __init__(self, r: float):
        self.r = r

    def admits(self, lam2, dist, ctx):
        return dist < self.r                        # seed001 eq. (5)

    def candidates(self, filter, prior, obs, ctx):
        return self.within_radius(filter, prior, obs, self.r)             # seed001 eq. (5)


@declared
@dataclass(eq=False)
class VariableValidationRegion(Gate):
    """Seed 001's variable validation region, r_val by gait phase and observability.

    Seed001 Table 1, with the leg's phase at k−1, H consecutive unobserved scans up to
    k−1, and Δt the scan period:

    ==========  ====================  ====================================
    phase       observable (H = 0)    unobservable (H ≥ 1)
    ==========  ====================  ====================================
    stance      ¾ w_l + Δt ‖v_{k−1}‖   ¾ w_l + Δt H v_st
    swing       w_l + Δt ‖v_{k−1}‖     w_l + Δt ‖v_{k−1}‖ + Δt H v_sw
    ==========  ====================  ====================================

    The gate admits ‖y − ŷ‖ < r_val (seed001 eq. (5)).
    """

    v_sw: float = param(1.1, "m/s", "seed001, text introducing Table 1",
                        "assumed speed of a hidden leg in swing")
    v_st: float = param(0.55, "m/s", "seed001, text introducing Table 1",
                        "assumed speed of a hidden leg in stance")
    stance_leg_widths: float = param(0.75, "leg widths", "seed001 Table 1",
                                     "constant term of r_val in stance")
    swing_leg_widths: float = param(1.0, "leg widths", "seed001 Table 1",
                                    "constant term of r_val in swing")

    def cell(self, ctx: GateContext) -> str:
        """The Table 1 cell in use: ``stance|swing`` + ``_observable|_unobservable``."""
        return (("swing" if ctx.swing else "stance")
                + ("_unobservable" if ctx.n_unobserved > 0 else "_observable"))

    def radius(self, ctx: GateContext) -> float:
        return self.radius_of(ctx.leg_width_m, ctx.dt, ctx.speed, ctx.swing, ctx.n_unobserved)

    def radius_of(self, w: float, dt: float, speed: float, swing: bool, h: int) -> float:
        """r_val of seed001 Table 1 for leg width ``w``, scan period ``dt``, ‖v_{k−1}‖
        ``speed``, phase ``swing`` at k−1 and ``h`` consecutive unobserved scans."""
        if swing:
            r = self.swing_leg_widths * w + dt * speed         # seed001 Table 1, swing
            return r + dt * h * self.v_sw if h > 0 else r
        if h > 0:
            return self.stance_leg_widths * w + dt * h * self.v_st  # seed001 Table 1, stance
        return self.stance_leg_widths * w + dt * speed

    def admits(self, lam2, dist, ctx):
        return dist < self.radius(ctx)              # seed001 eq. (5)

    def candidates(self, filter, prior, obs, ctx):
        return self.within_radius(filter, prior, obs, self.radius(ctx))   # seed001 eq. (5)

    def candidates_at(self, filter, prior, obs, leg_width_m, dt, speed, swing, n_unobserved):
        return self.within_radius(filter, prior, obs, self.radius_of(   # seed001 eq. (5)
            leg_width_m, dt, speed, swing, n_unobserved))
