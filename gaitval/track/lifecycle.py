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
``refind`` (:data:`REFINDS`)
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

import math
from collections import deque

import numpy as np

from gaitval.registry import Registry
from gaitval.track.init import leg_pairs

BIRTHS = Registry("birth")
CONFIRMERS = Registry("confirmer")
DELETERS = Registry("deleter")
REFINDS = Registry("refind")
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
    """

    def __init__(self, window_s: float = 1.4, m_fraction: float = 0.5,
                 min_relative_travel_m: float = 0.5, pass_leg_widths: float = 1.0,
                 min_travel_m: float = 0.0, evidence: str = "estimates",
                 walk_suffices: bool = False):
        self.walk_suffices = bool(walk_suffices)
        if evidence not in ("estimates", "observations"):
            raise ValueError(f"m_of_n_moving: evidence must be 'estimates' or "
                             f"'observations', not {evidence!r}")
        self.evidence = evidence
        self.window_s = window_s
        self.m_fraction = m_fraction
        self.min_relative_travel_m = min_relative_travel_m
        self.pass_leg_widths = pass_leg_widths
        self.min_travel_m = min_travel_m
        self.n = 1
        self.m = 1
        self.leg_width_m = 0.10

    def bind(self, dt, leg_width_m: float = 0.10):
        out = MOfNMoving(self.window_s, self.m_fraction, self.min_relative_travel_m,
                         self.pass_leg_widths, self.min_travel_m, self.evidence,
                         self.walk_suffices)
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
        both = person.seen[0] and person.seen[1]
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


# -- re-finding ----------------------------------------------------------------------------
class Refind:
    """Role base: ``bind(dt)`` → one for a recording; ``remember`` an ended person;
    ``match`` tentative persons against the remembered ones."""

    def bind(self, dt: float) -> "Refind":
        return self

    def remember(self, pid: int, t_last_seen: float, centre) -> None:
        pass

    def match(self, persons, t: float) -> list:
        return []

    def take_over(self, tentative, coasting, t: float) -> list:
        """Pairs (tentative person, coasting person): the tentative hypothesis is the
        coasting person, found where it was last seen while its prediction went elsewhere
        (``[]``: a coasting person only coasts)."""
        return []


@REFINDS.register("none")
class NoRefind(Refind):
    """An ended person stays ended: every new hypothesis is confirmed anew."""


def leg_tracker_person_gate(dt: float, max_std_m: float = 0.9, percentile: float = 0.90,
                            std_obs_m: float = 0.1, assoc_extra_m: float = 0.4,
                            p0: float = 0.5, process_std_per_s: float = 0.5) -> np.ndarray:
    """leg_tracker's person gate (m) after n = 0, 1, … scans without an observation, up to
    the scan on which it would delete the person (the array's length − 1).

    leg_tracker's person filter (``joint_leg_tracker.py``, ``ObjectTracked``): constant
    velocity, process noise std ``0.5·Δt`` on position and velocity per step (its 0.0667,
    0.05, 0.0333 at 7.5, 10, 15 Hz), observation std 0.1 m, P₀ = 0.5·I.  It gates a
    detection at Mahalanobis distance ``z = Φ⁻¹(1 − (1 − 0.90)/2)`` = 1.645 with
    cov = P_xx + (σ_obs + 0.4)², i.e. within ``z·√(P_xx + 0.25)`` m, and deletes the person
    once ``P_xx + 0.25 > max_std²`` = 0.81.  P_xx is the filter's steady state under
    observation, then predicted n scans on."""
    from scipy.stats import norm
    z = float(norm.ppf(1.0 - (1.0 - percentile) / 2.0))
    # The filter's x and y axes are independent and alike (F, Q, H, R block-diagonal), so
    # each axis's 2 × 2 covariance [[a, b], [b, c]] of (position, velocity) carries P:
    # F = [[1, Δt], [0, 1]], Q = (σ_p·Δt)² I, H = [1, 0], R = σ_obs².  (Written out as
    # scalars: the 4 × 4 matrix products cost ~23 ms per call, this ~0.3 ms; the gates
    # agree with them to 5e-16 m.)
    q = (process_std_per_s * dt) ** 2
    r = std_obs_m ** 2
    var_assoc = (std_obs_m + assoc_extra_m) ** 2
    a, b, c = p0, 0.0, p0

    def predict(a, b, c):
        return a + 2.0 * dt * b + dt * dt * c + q, b + dt * c, c + q

    for _ in range(1000):                     # the observed filter's steady state
        a, b, c = predict(a, b, c)
        ka, kb = a / (a + r), b / (a + r)     # Kalman gain of the position observation
        na, nb, nc = (1.0 - ka) * a, (1.0 - ka) * b, c - kb * b
        done = abs(na - a) <= 1e-12 and abs(nb - b) <= 1e-12 and abs(nc - c) <= 1e-12
        a, b, c = na, nb, nc
        if done:
            break
    out = [z * math.sqrt(a + var_assoc)]
    while True:
        a, b, c = predict(a, b, c)
        if a + var_assoc > max_std_m ** 2:
            return np.asarray(out)
        out.append(z * math.sqrt(a + var_assoc))


@REFINDS.register("leg_tracker_gate")
class LegTrackerGate(Refind):
    """A tentative hypothesis near where a confirmed person was last seen is that person.

    A confirmed person ends here sooner than leg_tracker would delete it (the measurement
    area test, docs/people.md), and a person whose track ended must otherwise be confirmed
    anew, which a standing person never is.  leg_tracker keeps an unobserved person until
    its filter's covariance passes ``max_std`` and matches it, meanwhile, to any detection
    inside its person gate; this role gives the same person back: for n scans between the
    ended person's last observation and now, a tentative hypothesis with both legs
    observed on this scan, whose centre lies within :func:`leg_tracker_person_gate` [n] of
    the ended person's last observed centre, is that person — confirmed, with its id.
    After leg_tracker's deletion time (3.0 s at 10 Hz) nobody is re-found.  Each ended
    person is re-found once, by the nearest such hypothesis.

    With ``coasting`` the same gate also applies to a person that is *coasting* (confirmed,
    neither leg observed on this scan): a tentative hypothesis with both legs observed
    within g(n) of the coasting person's last observed centre (n scans since it was last
    observed) is that person, and the coasting hypothesis ends (:meth:`take_over`).  The
    people tracker predicts an unseen leg with its own velocity (constant velocity, seed 001
    eq. (2)); one wrong association can give a standing leg metres per second, and the
    prediction then leaves the person, whose observations start a new hypothesis.
    leg_tracker matches detections to an unobserved person around its person filter's
    prediction, which moves at the person's walking speed; the last observed centre stands
    in for it here, as for an ended person (docs/people.md, *Re-finding*).

    Parameters are leg_tracker's defaults (``max_std`` 0.9 m, ``confidence_percentile``
    0.90, observation std 0.1 m, +0.4 m for association, P₀ = 0.5 I, process std 0.5·Δt);
    ``coasting`` (default False) switches the take-over on.
    """

    def __init__(self, max_std_m: float = 0.9, percentile: float = 0.90,
                 std_obs_m: float = 0.1, assoc_extra_m: float = 0.4,
                 coasting: bool = False):
        self.max_std_m = max_std_m
        self.percentile = percentile
        self.std_obs_m = std_obs_m
        self.assoc_extra_m = assoc_extra_m
        self.coasting = bool(coasting)
        self.gate_m = np.zeros(1)
        self.dt = 0.1
        self.ended: list[tuple[int, float, float, float]] = []

    def bind(self, dt):
        out = LegTrackerGate(self.max_std_m, self.percentile, self.std_obs_m,
                             self.assoc_extra_m, self.coasting)
        out.dt = float(dt)
        out.gate_m = leg_tracker_person_gate(out.dt, self.max_std_m, self.percentile,
                                             self.std_obs_m, self.assoc_extra_m)
        return out

    def _gate(self, gap_s: float) -> float:
        n = int(round(gap_s / self.dt))
        return float(self.gate_m[n]) if 0 <= n < len(self.gate_m) else -1.0

    def remember(self, pid, t_last_seen, centre):
        self.ended.append((int(pid), float(t_last_seen), float(centre[0]), float(centre[1])))

    def match(self, persons, t):
        self.ended = [e for e in self.ended if self._gate(t - e[1]) >= 0.0]
        if not self.ended:
            return []
        got = _nearest_pairs(
            [(e, p) for e in self.ended for p in persons if p.seen[0] and p.seen[1]],
            lambda e, p: math.hypot(p.centre()[0] - e[2], p.centre()[1] - e[3]),
            lambda e, p: self._gate(t - e[1]))
        used = {id(e) for e, _ in got}
        self.ended = [e for e in self.ended if id(e) not in used]
        return [(p, e[0]) for e, p in got]

    def take_over(self, tentative, coasting, t):
        if not self.coasting or not tentative or not coasting:
            return []
        return _nearest_pairs(
            [(p, q) for p in tentative if p.seen[0] and p.seen[1] for q in coasting],
            lambda p, q: math.hypot(p.centre()[0] - q.seen_centre[0],
                                    p.centre()[1] - q.seen_centre[1]),
            lambda p, q: self._gate(t - q.t_last_seen))


def _nearest_pairs(pairs, dist, gate) -> list:
    """One-to-one pairs (a, b) of ``pairs`` with dist(a, b) ≤ gate(a, b) (gate < 0: none),
    nearest first."""
    cand = []
    for i, (a, b) in enumerate(pairs):
        d = dist(a, b)
        if d <= gate(a, b):
            cand.append((d, i))
    cand.sort(key=lambda c: c[0])
    out, used_a, used_b = [], set(), set()
    for _, i in cand:
        a, b = pairs[i]
        if id(a) in used_a or id(b) in used_b:
            continue
        used_a.add(id(a))
        used_b.add(id(b))
        out.append((a, b))
    return out


# -- deletion ------------------------------------------------------------------------------
class Deleter:
    """Role base."""

    def ended(self, person, k: int, t: float, area: Area) -> str:
        raise NotImplementedError


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
    """

    def __init__(self, max_unsupported_s: float = 3.0, tentative_unsupported_s: float = 0.2):
        self.max_unsupported_s = max_unsupported_s
        self.tentative_unsupported_s = tentative_unsupported_s

    def ended(self, person, k, t, area):
        gap = t - person.t_last_seen
        if person.status == TENTATIVE:
            return "unsupported" if gap > self.tentative_unsupported_s + 1e-9 else ""
        if gap > self.max_unsupported_s + 1e-9:
            return "unsupported"
        x, y = person.centre()
        if not area.contains(x, y):
            return "left the area"
        return ""
