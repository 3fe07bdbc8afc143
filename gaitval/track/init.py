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
from dataclasses import dataclass

from gaitval.registry import Registry
from gaitval.track.init_motion import MotionCheck
from gaitval.track.params import NO_SOURCE, declared, param, param_of

INITIALISERS = Registry("initialiser", table="gaitval.track.roles")


class Initialiser:
    """Role base."""

    def find(self, source, leg_width_m: float) -> tuple[int, int, int] | None:
        raise NotImplementedError


@declared
@dataclass(eq=False)
class ClosestPair(Initialiser):
    """The first scan with two observations between ``min_leg_widths`` · w_l and
    ``max_pair_m`` apart (the closest such pair), both legs at rest.

    Two shanks cannot be closer than about 0.7 w_l (two observations nearer than that are
    one leg seen twice).  The observation with the larger bearing is taken as the left leg;
    the tracker may decide the sides again from the walking direction afterwards.
    """

    max_pair_m: float = param(0.8, "m", NO_SOURCE, "largest distance between the two legs")
    min_leg_widths: float = param(0.7, "leg widths", NO_SOURCE + " (two shanks' width)",
                                  "smallest distance between the two legs")

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


@declared
@dataclass(eq=False)
class ClosestMovingPair(ClosestPair):
    """:class:`ClosestPair`'s start, or None when no leg-like pair of the trial moves
    (:class:`~gaitval.track.init_motion.MotionCheck`; ``max_pair_m`` and
    ``min_leg_widths`` also say what counts as a leg-like pair for it).

    Notes
    -----
    The check assumes a sensor that stands still (TUG, MTST).  A sensor that moves with the
    walker (the rollator's) sees the whole scene move; its initialiser (``facing_pair``)
    derives from :class:`ClosestPair` and has no motion check.
    """

    require_motion: bool = param(True, "-", NO_SOURCE, "False gives ClosestPair exactly")
    min_travel_m: float = param_of(MotionCheck, "min_travel_m")
    max_step_m: float = param_of(MotionCheck, "max_step_m")
    max_lost_scans: int = param_of(MotionCheck, "max_lost_scans")
    min_scans: int = param(10, "scans", NO_SOURCE,
                           "a source with fewer scans cannot show motion; its pair is kept")

    def __post_init__(self):
        self.require_motion = bool(self.require_motion)
        self.min_scans = int(self.min_scans)
        self.check = MotionCheck(min_travel_m=self.min_travel_m, max_step_m=self.max_step_m,
                                 max_lost_scans=self.max_lost_scans)

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
