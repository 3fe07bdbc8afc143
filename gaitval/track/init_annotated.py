"""Initialisation from a hand annotation: the subject's legs at the first annotated scan.

Role ``init`` (:mod:`gaitval.track.init`): ``find(source, leg_width_m) -> (k0, i_left,
i_right) | None``.

A recording without poles or mocap (docs/legbench.md) has nothing that says where the
subject stands except the rater's annotation.  ``annotated_pair``
(:class:`AnnotatedPair`) starts both legs on the leg-like pair of observations whose
midpoint is nearest the annotated person position ``(x_m, y_m)`` at scan ``k``:

* a pair is two observations ``min_leg_widths`` · w_l .. ``max_pair_m`` apart (as
  ``closest_pair``);
* its midpoint must lie within ``max_offset_m`` of the annotation (default 0.75 m, the
  CLEAR-MOT match distance of the leg_tracker benchmark: a start farther away would
  already count as a miss);
* when scan ``k`` has no such pair (a leg hidden), the next ``search_scans`` scans are
  tried with the same annotated position; then None (no subject: the run has no track).

The left leg is the one at the larger bearing (the ``closest_pair`` convention; the
tracker may decide the sides from the walking direction afterwards).  The workflow sets
``k``, ``x_m`` and ``y_m`` from the trial's first annotation (``legbench.inits``
``annotation``; :mod:`gaitval.steps_legbench`).

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (a person-following robot is told whom to follow at the start).
"""
from __future__ import annotations

import math

from gaitval.errors import ConfigError
from gaitval.track.init import INITIALISERS, Initialiser, left_first, leg_pairs


@INITIALISERS.register("annotated_pair")
class AnnotatedPair(Initialiser):
    """The leg pair nearest an annotated person position (rule in the module notes).

    Parameters
    ----------
    k : int
        Scan index of the annotation.
    x_m, y_m : float
        Annotated person position at scan ``k`` (sensor frame, m).
    max_offset_m : float
        Largest distance of the pair's midpoint from the annotation (m).
    search_scans : int
        Further scans tried when scan ``k`` has no pair near the annotation.
    max_pair_m, min_leg_widths : float
        What counts as a leg pair (as ``closest_pair``).
    """

    def __init__(self, k=None, x_m=None, y_m=None, max_offset_m: float = 0.75,
                 search_scans: int = 10, max_pair_m: float = 0.8,
                 min_leg_widths: float = 0.7):
        try:
            self.k, self.x, self.y = int(k), float(x_m), float(y_m)
        except (TypeError, ValueError):
            raise ConfigError("init annotated_pair needs the annotated scan k and position "
                              f"x_m, y_m; got k={k!r}, x_m={x_m!r}, y_m={y_m!r}") from None
        if self.k < 0 or not (math.isfinite(self.x) and math.isfinite(self.y)):
            raise ConfigError(f"init annotated_pair: k must be >= 0 and x_m, y_m finite; got "
                              f"k={k!r}, x_m={x_m!r}, y_m={y_m!r}")
        self.max_offset_m = float(max_offset_m)
        self.search_scans = int(search_scans)
        self.max_pair_m = float(max_pair_m)
        self.min_leg_widths = float(min_leg_widths)

    def find(self, source, leg_width_m):
        d_min = self.min_leg_widths * leg_width_m
        for k in range(self.k, min(len(source), self.k + self.search_scans + 1)):
            obs = source.array(k)
            near = []
            for i, j, d in leg_pairs(obs, d_min, self.max_pair_m):
                off = math.hypot(0.5 * (obs[i][0] + obs[j][0]) - self.x,
                                 0.5 * (obs[i][1] + obs[j][1]) - self.y)
                if off <= self.max_offset_m:
                    near.append(((off, d), i, j))
            best = min(near, key=lambda c: c[0], default=None)   # nearest (first of equals)
            if best is not None:
                return left_first(k, obs, best[1], best[2])
        return None
