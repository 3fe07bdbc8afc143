"""Track initialisation: where and when the two leg tracks start.

Role ``init``: ``find(source, leg_width_m) -> (k0, i_left, i_right) | None`` where
``source`` is an observation source (:mod:`gaitval.track.observations`: ``len(source)``
scans, ``source.array(k)`` the ``(J, 2)`` observed positions of scan k, sensor frame); None
means no subject was found (the run reports no track).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), §6.1
(TUG: the subject starts seated, both legs at the chair).
"""
from __future__ import annotations

import math

from gaitval.registry import Registry

INITIALISERS = Registry("initialiser")


class Initialiser:
    """Role base."""

    def find(self, source, leg_width_m: float) -> tuple[int, int, int] | None:
        raise NotImplementedError


@INITIALISERS.register("closest_pair")
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
            best = None
            for i in range(len(obs)):
                for j in range(i + 1, len(obs)):
                    d = math.hypot(*(obs[i] - obs[j]))
                    if d_min <= d <= self.max_pair_m and (best is None or d < best[0]):
                        best = (d, i, j)
            if best is not None:
                _, i, j = best
                ai = math.atan2(obs[i][1], obs[i][0])
                aj = math.atan2(obs[j][1], obs[j][0])
                return (k, i, j) if ai >= aj else (k, j, i)   # left = larger bearing
        return None
