"""Re-finding: a person who ended (or coasts) found again where it was last seen.

A role of the people tracker (:mod:`gaitval.track.people`; the life cycle's other roles are
in :mod:`gaitval.track.lifecycle`).  ``remember(pid, t_last_seen, centre)`` when a reported
person ends; ``match(tentative persons, t_k)`` → [(person, pid)]: tentative hypotheses that
are a recently ended person found again, and inherit its confirmation and its id;
``take_over(tentative, coasting, t_k)`` → [(person, coasting person)]: the same for a
person that still coasts.  ``none``: nobody is re-found.  ``leg_tracker_gate``: leg_tracker's
person gate, grown over the time since the person was last observed
(:class:`LegTrackerGate`).

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (leg_tracker, ``joint_leg_tracker.py``: its person filter and
gate).
"""
from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np

from gaitval.registry import Registry

REFINDS = Registry("refind")


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
    # the standard library's normal quantile (Wichura's AS 241, ~1e-16): scipy.stats would
    # cost ~0.5 s of imports in every worker that binds this gate (docs/speed.md)
    z = NormalDist().inv_cdf(1.0 - (1.0 - percentile) / 2.0)
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
