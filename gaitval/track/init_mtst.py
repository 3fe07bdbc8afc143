"""Initialisation that picks the MTST participant's legs, not the attendant's or the stick.

Role ``init`` (:mod:`gaitval.track.init`): ``find(source, leg_width_m) -> (k0, i_left,
i_right) | None``.

Seed 001 §3.1: "a nursing attendant walked alongside the participant", and two of the
sixteen participants use a stick.  Four or five leg-like objects are then in the scans,
and the closest pair of observations (the TUG initialiser) is as often the attendant's
legs as the participant's.  The paper does not say how its tracker starts (GAP); gaitval
uses what the set-up fixes before anybody walks: the mat.  The participant stands at the
start of the mat and walks along it; the attendant walks *beside* it (seed 001 Figure 1a),
and a stick is held about 0.3 m to the side of the body.

Rule (:class:`MatLaneParticipant`): the first scan with a pair of observations

* between ``min_leg_widths`` · w_l and ``max_pair_m`` apart (one person's two shanks),
* both within ``half_width_m`` of the lane — the mat's centreline, extended
  ``margin_before_m`` behind its start (where the participant stands) — measured
  perpendicular to it;

of all such pairs of that scan, the one whose midpoint lies closest to the centreline (the
participant walks on the mat, the attendant beside it; a leg and the stick make a pair
whose midpoint is ≈ 0.15 m off the body's centre).  The observation to the left of the
walking direction (start → goal) is the left leg; without a lane, the one at the larger
bearing (the convention of ``closest_pair``; the tracker decides the sides from the
walking direction afterwards).

**No phantom participant** (issue 36): the pair found this way is kept only when some
leg-like pair of the trial *moves* (:class:`gaitval.track.init.MotionCheck`, the check of
TUG's ``closest_pair``: both legs travel ≥ 0.5 m over still scans, off the learned
background).  A participant who walks the mat always does; chair and table legs in an
empty room never do, and the run then reports no track instead of following furniture
from the first scan to the last.  ``require_motion: false`` gives the rule above alone.

``lane`` is the centreline ``[[x_start, y_start], [x_goal, y_goal]]`` *in the sensor
frame*: a trial's value comes from the registered sensor pose and the mat geometry
(``mtst.mat`` in the config; :mod:`gaitval.pipeline.mtst` sets it as the override
``init__lane``).  Without it the sensor's own x axis is the lane (any direction, no
limits along it), the sensor standing on the mat's axis (seed 001 Figure 1a) — reliable
only when the sensor's yaw is known to within a degree or two, since 3° at 7 m is 0.37 m
sideways.

References
----------
Yorozu, A.; Nishiguchi, S.; Yamada, M.; Aoyama, T.; Moriguchi, T.; Takahashi, M. Gait
Measurement System for the Multi-Target Stepping Task Using a Laser Range Sensor. Sensors
2015, 15, 11151–11168 (seed 001), §2.1, §3.1, Figure 1a.
"""
from __future__ import annotations

import math

from gaitval.errors import ConfigError
from gaitval.track.init import Initialiser, MotionCheck, keep_if_moving


class MatLaneParticipant(Initialiser):
    """The participant's two legs on the mat's lane (rule in the module notes).

    Parameters
    ----------
    lane : [[x, y], [x, y]] or None
        The mat's centreline, start then goal, in the sensor frame (m); None: the sensor's
        x axis, walker approaching the sensor.
    half_width_m : float
        Largest distance of a leg from the centreline: half the 1.15 m mat plus 0.1 m
        (a foot placed on the mat's edge has its shank up to ≈ 0.1 m further out).
    margin_before_m : float
        How far behind the mat's start the lane reaches (the start position, seed 001 §3.1).
    max_pair_m : float
        Largest distance between the two legs (a standing or walking person, ≤ one step).
    min_leg_widths : float
        Smallest distance between the two legs, in leg widths (two shanks cannot overlap).
    require_motion, min_travel_m, max_step_m, max_lost_scans, min_scans
        The motion check (module notes), as
        :class:`gaitval.track.init.ClosestMovingPair`'s; its defaults too.
    """

    def __init__(self, lane=None, half_width_m: float = 0.675, margin_before_m: float = 1.5,
                 max_pair_m: float = 0.8, min_leg_widths: float = 0.7,
                 require_motion: bool = True, min_travel_m: float = 0.5,
                 max_step_m: float = 0.7, max_lost_scans: int = 8, min_scans: int = 10):
        self.require_motion = bool(require_motion)
        self.min_scans = int(min_scans)
        self.check = MotionCheck(min_travel_m=min_travel_m, max_step_m=max_step_m,
                                 max_lost_scans=max_lost_scans)
        if lane is not None:
            try:
                (x0, y0), (x1, y1) = lane
                lane = ((float(x0), float(y0)), (float(x1), float(y1)))
            except (TypeError, ValueError):
                raise ConfigError(f"init lane must be [[x, y], [x, y]] (sensor frame, m), got "
                                  f"{lane!r}") from None
        self.lane = lane
        self.half_width_m = half_width_m
        self.margin_before_m = margin_before_m
        self.max_pair_m = max_pair_m
        self.min_leg_widths = min_leg_widths

    def _frame(self):
        """(origin, unit direction start → goal, length) of the lane; None without one."""
        if self.lane is None:
            return None
        (x0, y0), (x1, y1) = self.lane
        d = math.hypot(x1 - x0, y1 - y0)
        if d <= 0:
            raise ConfigError("init lane has zero length (start and goal coincide)")
        return (x0, y0), ((x1 - x0) / d, (y1 - y0) / d), d

    def _lane_coords(self, obs):
        """Per observation (along, lateral, left-ness) and the along-lane limits."""
        frame = self._frame()
        if frame is None:           # the sensor's x axis; left = larger bearing (no direction)
            return ([(x, y, math.atan2(y, x)) for x, y in obs], -math.inf, math.inf)
        (ox, oy), (ux, uy), length = frame
        out = []
        for x, y in obs:
            c = -(x - ox) * uy + (y - oy) * ux              # left of start → goal positive
            out.append(((x - ox) * ux + (y - oy) * uy, c, c))
        return out, -self.margin_before_m, length

    def find(self, source, leg_width_m):
        return keep_if_moving(self, source, self._lane_pair(source, leg_width_m),
                              leg_width_m)

    def _lane_pair(self, source, leg_width_m):
        """The first scan's pair on the lane (rule in the module notes), or None."""
        d_min = self.min_leg_widths * leg_width_m
        for k in range(len(source)):
            obs = source.array(k)
            if len(obs) < 2:
                continue
            s, lo, hi = self._lane_coords(obs)
            ok = [i for i, (a, c, _) in enumerate(s)
                  if lo <= a <= hi and abs(c) <= self.half_width_m]
            best = None
            for m, i in enumerate(ok):
                for j in ok[m + 1:]:
                    d = math.hypot(*(obs[i] - obs[j]))
                    if not d_min <= d <= self.max_pair_m:
                        continue
                    off = abs(0.5 * (s[i][1] + s[j][1]))
                    if best is None or (off, d) < best[0]:
                        best = ((off, d), i, j)
            if best is not None:
                _, i, j = best
                return (k, i, j) if s[i][2] >= s[j][2] else (k, j, i)
        return None
