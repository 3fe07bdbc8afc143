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
  tried, each with *its own* annotated position when the rater clicked that scan too
  (``path``: the person's annotations in scan order), else with the latest one before it
  — the person walks on while the legs are searched for, so the first click is not held
  fixed (issue 36); then None (no subject: the run has no track).

The left leg is the one at the larger bearing (the ``closest_pair`` convention; the
tracker may decide the sides from the walking direction afterwards).  The workflow sets
``k``, ``x_m`` and ``y_m`` from the trial's first annotation (``legbench.inits``
``annotation``; :mod:`gaitval.pipeline.legbench`).

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (a person-following robot is told whom to follow at the start).
"""
from __future__ import annotations

import math

from gaitval.errors import ConfigError
from gaitval.track.init import Initialiser, left_first, leg_pairs


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
    path : list of [k, x_m, y_m], optional
        The same person's later annotations (scan, position), used for the scans searched
        after ``k`` (module notes).
    max_pair_m, min_leg_widths : float
        What counts as a leg pair (as ``closest_pair``).
    """

    def __init__(self, k=None, x_m=None, y_m=None, max_offset_m: float = 0.75,
                 search_scans: int = 10, max_pair_m: float = 0.8,
                 min_leg_widths: float = 0.7, path=None):
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
        try:
            later = sorted((int(a), float(b), float(c)) for a, b, c in (path or ()))
        except (TypeError, ValueError):
            raise ConfigError("init annotated_pair: path must be a list of [k, x_m, y_m]; "
                              f"got {path!r}") from None
        self.path = [(self.k, self.x, self.y)] + [p for p in later if p[0] > self.k]

    def position_at(self, k: int) -> tuple[float, float]:
        """The annotated position for scan ``k``: its own click, else the latest before."""
        x, y = self.x, self.y
        for kk, xx, yy in self.path:
            if kk > k:
                break
            x, y = xx, yy
        return x, y

    def find(self, source, leg_width_m):
        d_min = self.min_leg_widths * leg_width_m
        for k in range(self.k, min(len(source), self.k + self.search_scans + 1)):
            obs = source.array(k)
            ax, ay = self.position_at(k)
            near = []
            for i, j, d in leg_pairs(obs, d_min, self.max_pair_m):
                off = math.hypot(0.5 * (obs[i][0] + obs[j][0]) - ax,
                                 0.5 * (obs[i][1] + obs[j][1]) - ay)
                if off <= self.max_offset_m:
                    near.append(((off, d), i, j))
            best = min(near, key=lambda c: c[0], default=None)   # nearest (first of equals)
            if best is not None:
                return left_first(k, obs, best[1], best[2])
        return None
