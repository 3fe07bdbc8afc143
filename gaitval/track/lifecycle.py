"""A person hypothesis's life: birth, confirmation, coasting and end, each a role.

A people tracker (:mod:`gaitval.track.people`) calls these roles once per scan; its loop
holds none of their rules (Stone Soup's initiator/deleter split):

``birth`` (:data:`BIRTHS`)
    ``propose(obs, free, leg_width_m) -> [(i, j)]``: pairs of observations that no person
    explains and that could be one person's two legs.  ``unexplained_pairs``: the closest
    pairs first, each at most ``max_pair_m`` apart (leg_tracker's
    ``max_leg_pairing_dist`` = 0.8 m, also seed 000's initialiser) and at least
    ``min_leg_widths`` · w_l (two legs do not overlap), each observation in one pair.
``confirmer`` (:data:`CONFIRMERS`)
    ``step(person, k)`` after the person's correction; returns True when a tentative person
    becomes a confirmed one, and ``failed(person)`` when a tentative one can no longer be
    confirmed.  ``m_of_n_moving``: M of the last N scans with both legs observed, **and**
    the leg pair moved: the path of the vector between the two legs over those N scans,
    counting only steps longer than ``min_step_m``, is at least ``min_relative_travel_m``::

        confirmed  ⇔  |{k'∈W : both legs observed}| ≥ M                         (M of N)
                      ∧  min_W r·û ≤ −c  ∧  max_W r·û ≥ c     (the legs pass each other)
                      ∧  max_{i,j∈W} |r_i − r_j| ≥ d_c                 (r spans d_c)
                      ∧  |v̂| (t_last − t_first) ≥ d_w ∧ RMS(c − ĉ) ≤ w_l   (the body walked)
                         with no gap in the scans with both legs longer than N/3

    with r = p_L − p_R over the scans of the window W (the last N) that saw both legs, û
    the direction of the longest r in W, c one leg width, and ĉ(t) = ĉ₀ + v̂ t the
    least-squares line through the body centres c of those scans in the world frame (the
    ego-motion role of :mod:`gaitval.track.staticmap`).  The *relative* vector is used because a
    walker's legs swing past each other (one stands while the other swings) whatever the
    sensor does, whereas a pair of static objects seen from a moving robot moves as one
    rigid pair (r constant up to the robot's turn), and a pair whose observations flicker
    between neighbouring clutter jumps about without ever reversing.  leg_tracker asks each
    leg to travel ``dist_travelled_together_to_initiate_leg_pair`` = 0.5 m in the odometry
    frame; gaitval has no odometry, so the same 0.5 m is asked of the vector between the
    legs.
``refind`` (:data:`REFINDS`, :mod:`gaitval.track.refind`)
    ``remember(pid, t_last_seen, centre)`` when a reported person ends; ``match(tentative
    persons, t_k)`` → [(person, pid)]: tentative hypotheses that are a recently ended person
    found again, and inherit its confirmation and its id.  ``leg_tracker_gate``: a
    hypothesis whose legs are both observed on the scan and whose centre lies within
    leg_tracker's person gate of where the ended person was last observed, the gate as
    leg_tracker's person filter would have grown it over the time since (module notes of
    :class:`LegTrackerGate`).
``deleter`` (:data:`DELETERS`)
    ``ended(person, k, t_k, area) -> str``: "" to keep the person, else why it ends.
    ``unsupported_time``: a confirmed person ends after ``max_unsupported_s`` without a leg
    observation, or when its body centre leaves the measurement area (``area.contains``);
    a tentative person ends as soon as neither leg is observed for ``tentative_unsupported_s``.

Statuses (:data:`TENTATIVE`, :data:`CONFIRMED`, :data:`COASTING`, :data:`ENDED`): a confirmed
person without a leg observation on the current scan is *coasting* (its legs predicted on);
an ended person found again by the ``refind`` role is confirmed again, with its id.

Measurement areas (:data:`AREAS`): ``field_of_view`` (the scan's bearings and range limits,
less a margin) and ``rectangle`` (x, y bounds in the sensor frame: the rollator's user
window, a mat, a walkway).

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (leg_tracker, ``joint_leg_tracker.py``: pairing, confirmation,
deletion defaults).
"""
from __future__ import annotations

import copy
import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from gaitval.registry import Registry
from gaitval.track.init import leg_pairs
# the re-finding role lives in its own module; its registry and leg_tracker's person gate
# are named here too, beside the other life-cycle roles
from gaitval.track.refind import REFINDS, leg_tracker_person_gate  # noqa: F401

BIRTHS = Registry("birth")
CONFIRMERS = Registry("confirmer")
DELETERS = Registry("deleter")
AREAS = Registry("measurement area")

TENTATIVE, CONFIRMED, COASTING, ENDED = "tentative", "confirmed", "coasting", "ended"


# -- measurement area ----------------------------------------------------------------------
class Area:
    """Role base: ``bind(scans)`` → an area for one recording; ``contains(x, y)``."""

    def bind(self, scans) -> "Area":
        return self

    def contains(self, x: float, y: float) -> bool:
        raise NotImplementedError


@AREAS.register("field_of_view")
class FieldOfView(Area):
    """What the laser sees: bearing within the scan's angles and range below its maximum,
    each less ``margin_m`` (a person whose centre is that close to the edge has a leg out
    of view).

    Parameters
    ----------
    margin_m : float
        How far inside the edge the body centre must be (0.25 m: about half the distance
        between the legs of a walker, so that both legs can still be in view).
    """

    def __init__(self, margin_m: float = 0.25):
        self.margin_m = margin_m
        self._lim = None

    def bind(self, scans) -> "FieldOfView":
        out = FieldOfView(self.margin_m)
        a0 = float(scans.angle_min)
        a1 = a0 + float(scans.angle_increment) * (scans.ranges.shape[1] - 1)
        out._lim = (min(a0, a1), max(a0, a1), float(scans.range_max))
        return out

    def contains(self, x, y):
        a0, a1, rmax = self._lim
        r = math.hypot(x, y)
        if r > rmax - self.margin_m:
            return False
        if a1 - a0 >= 2 * math.pi - 1e-6:
            return True
        b = math.atan2(y, x)
        m = self.margin_m / max(r, 1e-6)          # the margin as an angle at range r
        return a0 + m <= b <= a1 - m


@AREAS.register("rectangle")
class Rectangle(Area):
    """A registered area in the sensor frame (a mat, a walkway): ``x_m = [x0, x1]``,
    ``y_m = [y0, y1]``."""

    def __init__(self, x_m=(-math.inf, math.inf), y_m=(-math.inf, math.inf)):
        self.x_m = tuple(float(v) for v in x_m)
        self.y_m = tuple(float(v) for v in y_m)

    def contains(self, x, y):
        return self.x_m[0] <= x <= self.x_m[1] and self.y_m[0] <= y <= self.y_m[1]


# -- birth ---------------------------------------------------------------------------------
class Birth:
    """Role base."""

    def propose(self, obs, free, leg_width_m: float) -> list[tuple[int, int]]:
        raise NotImplementedError


@BIRTHS.register("unexplained_pairs")
class UnexplainedPairs(Birth):
    """Pairs of unexplained observations, closest first (module notes).

    Parameters
    ----------
    max_pair_m : float
        leg_tracker's ``max_leg_pairing_dist`` (0.8 m); seed 000's ``closest_pair`` 0.8 m.
    min_leg_widths : float
        Minimum distance between the two legs in leg widths (seed 000's initialiser: 0.7).
    """

    def __init__(self, max_pair_m: float = 0.8, min_leg_widths: float = 0.7):
        self.max_pair_m = max_pair_m
        self.min_leg_widths = min_leg_widths

    def propose(self, obs, free, leg_width_m):
        lo, hi = self.min_leg_widths * leg_width_m, self.max_pair_m
        idx = [j for j in range(len(obs)) if free[j]]
        sub = np.asarray([obs[j] for j in idx], dtype=float).reshape(-1, 2)
        cand = sorted((d, idx[a], idx[b]) for a, b, d in leg_pairs(sub, lo, hi))
        used, out = set(), []
        for _, i, j in cand:
            if i not in used and j not in used:
                used.update((i, j))
                out.append((i, j))
        return out


# -- confirmation --------------------------------------------------------------------------
class Confirmer:
    """Role base.  ``evidence``: what the tests look at — ``"estimates"`` (the legs'
    filtered positions) or ``"observations"`` (the observations assigned to the legs on
    the scans with both legs observed); the tracker gives ``person.world_centre`` from the
    same."""

    evidence = "estimates"

    def bind(self, dt: float, leg_width_m: float = 0.10) -> "Confirmer":
        return self

    def new_memory(self):
        return None

    def step(self, person, k: int) -> bool:
        raise NotImplementedError

    def failed(self, person) -> bool:
        return False

    def scan(self, k: int, motion) -> None:
        """Called once per scan before the persons' steps: the sensor's motion from scan
        k−1 to k ((dx, dy, dθ) in the frame of k−1, or None: unknown)."""


@CONFIRMERS.register("m_of_n_moving")
@dataclass(eq=False)
class MOfNMoving(Confirmer):
    """M of N scans with both legs observed and a leg pair that walks (module notes).

    Parameters
    ----------
    window_s : float
        N as time: one stride of a slow walker (1.4 s: cadence 85 steps/min), so that the
        legs have swung past each other at least once inside the window.
    m_fraction : float
        M = ⌈m_fraction · N⌉ (0.5: both legs seen in half the window's scans).
    min_relative_travel_m : float
        d_c: the vector between the legs spans at least this much over the window (the
        diameter of the set of r); leg_tracker's ``dist_travelled_together_to_initiate_
        leg_pair`` = 0.5 m.
    pass_leg_widths : float
        The legs pass each other: along the direction of the longest r in the window, r
        reaches at least ``pass_leg_widths`` · w_l on both sides of zero (1.0: each leg gets
        a leg's width ahead of the other).
    min_travel_m : float
        d_w: the body centre moved steadily at least this far in the world frame over the
        window (a line fit, module notes; ``person.world_centre`` = (segment, x, y), set by
        the tracker from its ego-motion role; 0 = not asked).  Where the sensor's motion
        was lost inside the window (more than one segment) the world frame is unknown and
        this test is not made.  leg_tracker's 0.5 m of travel in the odometry
        frame; over 1.4 s it asks for at least 0.36 m/s, a slow walk.
    evidence : {"estimates", "observations"}
        r and the body centre from the legs' filtered positions (default) or from the
        observations assigned to them: with ``observations`` the tests see only what the
        scan saw, whatever the motion model predicts (experiments/people_gate.py).
    walk_suffices : bool
        Where the world frame is known over the window and ``min_travel_m`` > 0, the body's
        steady walk (with the gap test) alone confirms, without the two gait tests (the
        legs pass, r spans d_c); where it is not known, the gait tests alone decide, as
        before.  False (default): every test is asked; True confirms furniture in the
        empty room (experiments/people_gate.py).
    separate_legs : bool
        A scan counts as one with both legs observed only when no return lies on the line
        between the two observations, beyond one leg width of each
        (:func:`gaitval.track.peoplepass.joined_by_surface`): between a person's legs the
        beams pass through.  False (default): not asked.
    min_apart_leg_widths : float
        A scan counts as one with both legs observed only when the two observations are
        at least this many leg widths apart (1.0: two solid shanks' centres are a leg
        width apart when they touch; closer, it is one object seen as two).  0 (default):
        not asked.
    """

    window_s: float = 1.4
    m_fraction: float = 0.5
    min_relative_travel_m: float = 0.5
    pass_leg_widths: float = 1.0
    min_travel_m: float = 0.0
    evidence: str = "estimates"
    walk_suffices: bool = False
    separate_legs: bool = False
    min_apart_leg_widths: float = 0.0
    # bound to a run (bind): the window in scans, M of it, the leg width
    n: int = field(default=1, init=False)
    m: int = field(default=1, init=False)
    leg_width_m: float = field(default=0.10, init=False)

    def __post_init__(self):
        self.min_apart_leg_widths = float(self.min_apart_leg_widths)
        self.walk_suffices, self.separate_legs = bool(self.walk_suffices), bool(self.separate_legs)
        if self.evidence not in ("estimates", "observations"):
            raise ValueError(f"m_of_n_moving: evidence must be 'estimates' or "
                             f"'observations', not {self.evidence!r}")

    def bind(self, dt, leg_width_m: float = 0.10):
        out = copy.copy(self)          # the declared values; n, m, w_l for this run
        out.n = max(1, int(round(self.window_s / dt)))
        out.m = max(1, math.ceil(self.m_fraction * out.n))
        out.leg_width_m = leg_width_m
        return out

    def new_memory(self):
        # per scan of the window: r = p_L - p_R when both legs were observed, else None;
        # and the body centre in the world frame
        return {"win": deque(maxlen=self.n), "world": deque(maxlen=self.n), "age": 0}

    def step(self, person, k):
        mem = person.confirm_memory
        both = person.seen[0] and person.seen[1] and (not self.separate_legs or person.apart)
        if both and self.min_apart_leg_widths > 0:      # two solid shanks do not overlap
            both = math.dist(person.z[0], person.z[1]) >= \
                self.min_apart_leg_widths * self.leg_width_m
        if both:
            (xl, yl), (xr, yr) = ((person.z[0], person.z[1]) if self.evidence == "observations"
                                  else (person.pos(0), person.pos(1)))
            mem["win"].append((xl - xr, yl - yr))
            mem["world"].append(person.world_centre)
        else:
            mem["win"].append(None)
            mem["world"].append(None)
        mem["age"] += 1
        win = mem["win"]
        if len(win) < self.n:
            return False
        rs = [r for r in win if r is not None]
        if len(rs) < self.m:
            return False
        world_known = len({c[0] for c in mem["world"] if c is not None}) == 1
        walk_asked = self.min_travel_m > 0 and world_known
        if self.walk_suffices and walk_asked:
            return self._walks(mem)
        return self._legs_walk(rs) and (not walk_asked or self._walks(mem))

    def _legs_walk(self, rs) -> bool:
        """The gait tests: the legs pass each other along the longest r, and r spans d_c."""
        # the legs pass each other: r on both sides of zero along the longest r
        ux, uy = max(rs, key=lambda r: r[0] * r[0] + r[1] * r[1])
        norm = math.hypot(ux, uy)
        if norm <= 0.0:
            return False
        proj = [(r[0] * ux + r[1] * uy) / norm for r in rs]
        w = self.pass_leg_widths * self.leg_width_m
        if min(proj) > -w or max(proj) < w:
            return False
        # ... and r spans d_c (the diameter of the set of r)
        d2 = self.min_relative_travel_m ** 2
        return any((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 >= d2
                   for i, a in enumerate(rs) for b in rs[i + 1:])

    def _walks(self, mem) -> bool:
        """The body walked d_w in the world, steadily: a straight-line fit c(t) = c0 + v t
        to the world centres of the window's scans with both legs spans d_w, with an RMS
        residual below one leg width (a pair flickering between objects jumps instead)."""
        idx = [i for i, c in enumerate(mem["world"]) if c is not None]
        # the walk is seen throughout: no gap between scans with both legs longer than a
        # third of the window (across a gap, two clusters of a flickering pair would fit a
        # line)
        if max(b - a - 1 for a, b in zip(idx[:-1], idx[1:])) > len(mem["world"]) // 3:
            return False
        cs = [mem["world"][i][1:] for i in idx]
        ti = [float(i) for i in idx]
        tm = sum(ti) / len(ti)
        stt = sum((x - tm) ** 2 for x in ti)
        if stt <= 0:
            return False
        res2 = 0.0
        span2 = 0.0
        for ax in (0, 1):
            v = [c[ax] for c in cs]
            vm = sum(v) / len(v)
            slope = sum((x - tm) * (y - vm) for x, y in zip(ti, v)) / stt
            res2 += sum((y - vm - slope * (x - tm)) ** 2 for x, y in zip(ti, v))
            span2 += (slope * (ti[-1] - ti[0])) ** 2
        return span2 >= self.min_travel_m ** 2 and res2 / len(cs) <= self.leg_width_m ** 2

    def failed(self, person):
        mem = person.confirm_memory
        if mem["age"] < self.n:
            return False
        # fewer than M of the last N scans saw both legs: not a person (yet)
        return sum(1 for r in mem["win"] if r is not None) < self.m


# -- deletion ------------------------------------------------------------------------------
class Deleter:
    """Role base."""

    def ended(self, person, k: int, t: float, area: Area) -> str:
        raise NotImplementedError

    def support(self, persons, pts: np.ndarray, t: float, static=None,
                obs_static=()) -> None:
        """Once per scan, the scan's returns ``pts`` (P, 2) in the sensor frame,
        ``static(q) -> bool array``, which of points q lie on the static map, and
        ``obs_static[j]``, whether observation j does: a person with a return in its gate
        or an observation assigned (``person.obs_j``), either off the static map, gets
        ``t_last_return = t``."""


@DELETERS.register("unsupported_time")
class UnsupportedTime(Deleter):
    """End a person after a stated time without a leg observation, or outside the area.

    Parameters
    ----------
    max_unsupported_s : float
        A confirmed person's longest life without support (3.0 s: leg_tracker deletes a
        track when its position variance plus 0.5² m² exceeds ``max_std``² = 0.9² m²; with
        its constant-velocity filter at 10 Hz that is 30 unobserved scans, 3.0 s; at
        7.5 Hz 20 scans, 2.7 s).
    tentative_unsupported_s : float
        A tentative person's: one scan period at 7.5–10 Hz plus margin (0.2 s) — a
        hypothesis not yet confirmed is not worth predicting through an occlusion.
    max_no_return_s : float
        A reported person with no scan return off the static map within ``return_gate_m``
        of its (predicted) body centre for longer than this ends (0.5 s: the confirmer's largest
        gap, a third of its 1.4 s window, rounded up — a person's legs return light on
        every scan they are not hidden; a prediction that left its person, or clutter
        that stopped returning, is not coasted for seconds).  An occluded person ends too
        and is re-found by the ``refind`` role when seen again.  None: not asked.
    return_gate_m : float
        Half leg_tracker's ``max_leg_pairing_dist`` (0.8 m): both legs of a person lie
        within 0.4 m of its centre.
    """

    def __init__(self, max_unsupported_s: float = 3.0, tentative_unsupported_s: float = 0.2,
                 max_no_return_s: float | None = 0.5, return_gate_m: float = 0.4):
        self.max_unsupported_s = max_unsupported_s
        self.tentative_unsupported_s = tentative_unsupported_s
        self.max_no_return_s = max_no_return_s
        self.return_gate_m = return_gate_m

    def support(self, persons, pts, t, static=None, obs_static=()):
        for p in persons:                       # an observation is made of returns
            if any(j >= 0 and not obs_static[j] for j in p.obs_j):
                p.t_last_return = t
        if self.max_no_return_s is None or not persons or not len(pts):
            return
        c = np.array([p.centre() for p in persons])
        near = ((c[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2) <= self.return_gate_m ** 2
        use = near.any(axis=0)
        if static is not None and use.any():
            use[use] = ~static(pts[use])           # walls and furniture support nobody
        for p, ok in zip(persons, (near & use[None, :]).any(axis=1).tolist()):
            if ok:
                p.t_last_return = t

    def ended(self, person, k, t, area):
        gap = t - person.t_last_seen
        if person.status == TENTATIVE:
            return "unsupported" if gap > self.tentative_unsupported_s + 1e-9 else ""
        if gap > self.max_unsupported_s + 1e-9:
            return "unsupported"
        if self.max_no_return_s is not None and \
                t - person.t_last_return > self.max_no_return_s + 1e-9:
            return "no return"
        x, y = person.centre()
        if not area.contains(x, y):
            return "left the area"
        return ""
