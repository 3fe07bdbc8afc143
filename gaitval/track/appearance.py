"""Appearance: does an observation look like a leg?  A role of the people tracker (issue 36).

:class:`~gaitval.track.people.PeopleTracker` calls it; its loop holds none of its rules.

``appearance`` (:data:`APPEARANCES`)
    ``scores(scans, xy) -> [p_k]``: per scan, P(leg) of each observation; ``admits(p_L,
    p_R)``: may a pair of observations with these scores start a person;
    ``start(p_L, p_R)`` → the memory of a new hypothesis; ``update(person)`` once per scan
    after the correction (``person.zp``: the scores of the legs' observations, None when a
    leg is unobserved); ``confirmed(person)`` when a tentative person becomes a confirmed
    one; ``keeps(person)``: False when the person (tentative or confirmed) no longer looks
    like legs and ends.

``confirms(person, leg_width_m)`` once per scan for a tentative person, after
``update``: True when its looks alone confirm it (a standing person; the confirmer's
motion tests are the other way).

``none``
    Everything looks like a leg (p = 1; no hypothesis ends for its looks, none is
    confirmed by them).
``leg_forest``
    leg_tracker's classifier and its confidence rule (Leigh et al., ICRA 2015;
    angusleigh/leg_tracker).  Each scan is clustered and each cluster scored as leg_tracker's
    ``detect_leg_clusters`` does (:mod:`gaitval.track.legclusters`,
    :mod:`gaitval.track.legforest`: clusters of ≥ 3 returns joined at < 0.13 m, P(leg) =
    the fraction of the forest's trees voting "leg", clusters farther than
    ``max_detect_distance`` = 10 m not detected).  An observation's score is the highest
    score of a cluster whose centroid is within ``match_m`` of it (0 if none: no cluster
    of 3 returns there).  Then ``joint_leg_tracker.py``'s rule, per leg while tentative and
    per person once confirmed::

        c_f ← c_f,0 = p(z_f) at birth;     c_f ← 0.95 c_f + 0.05 p(z_f)   on a scan seeing leg f
        pair kept   ⇔  min(c_L, c_R) ≥ 0.1          (confidence_threshold_to_maintain_track)
        confirmed:  c ← (c_L + c_R)/2,  then  c ← 0.95 c + 0.05 p̄,  p̄ the mean score of the
                    legs seen on the scan (none seen: c unchanged);  person kept ⇔ c ≥ 0.1

    (joint_leg_tracker.py: leg confidence update line 387, pair deletion lines 446–452,
    person confidence at creation line 472, person's matched detection lines 358–372,
    person deletion line 401).  A pair whose two observations score below 0.1 is not
    born: leg_tracker would delete that pair on the scan it forms.
``legs_confirm``
    Appearance as evidence of a person, not as a veto (issue 55): the same clusters and
    scores as ``leg_forest`` (its own forest), no pair is refused or ended for its looks,
    and a tentative pair is confirmed when on each of the last K = ``n_scans`` scans both
    legs were observed, as two separate objects (``person.apart``, the confirmer's surface
    test) at least one leg width apart, and each leg's P(leg), averaged over those K scans,
    is at least θ = ``min_score``::

        confirmed  ⇔  ∀ k' ∈ last K scans: both legs seen ∧ apart ∧ |z_L − z_R| ≥ w_l
                      ∧  mean_K p_L ≥ θ  ∧  mean_K p_R ≥ θ

    (the mean, not every scan: a rendered or real leg's score varies from scan to scan
    with the beams that fall on it; leg_tracker's running confidence averages too).

    A person who stands is then confirmed by how its legs look, where the motion tests
    wait for a walk.  The tracker still refuses a pair with a leg on a static cell.
"""
from __future__ import annotations

from collections import deque

import numpy as np

from gaitval.registry import Registry

APPEARANCES = Registry("appearance")


class Appearance:
    """Role base: everything looks like a leg (``none``)."""

    def scores(self, scans, xy) -> list[np.ndarray]:
        return [np.ones(len(z)) for z in xy]

    def admits(self, p_l: float, p_r: float) -> bool:
        return True

    def start(self, p_l: float, p_r: float):
        return None

    def update(self, person) -> None:
        pass

    def confirmed(self, person) -> None:
        pass

    def keeps(self, person) -> bool:
        return True

    def confirms(self, person, leg_width_m: float) -> bool:
        return False


APPEARANCES.register("none")(Appearance)


@APPEARANCES.register("leg_forest")
class LegForestAppearance(Appearance):
    """leg_tracker's leg classifier and confidence rule (module notes).

    Parameters
    ----------
    forest : str
        A shipped forest of :mod:`gaitval.track.legforest` (``leg_tracker_bags``; the
        ``without_*_scan`` ones for the empty-room test) or a path to one.
    threshold : float
        leg_tracker's ``confidence_threshold_to_maintain_track`` (0.1).
    rate : float
        The weight of a new score in the running confidence (leg_tracker's 0.05).
    match_m : float
        An observation takes the score of a cluster whose centroid is this close (0.13 m:
        leg_tracker's ``cluster_dist_euclid``, the distance at which returns join one
        cluster).
    cluster_dist_m, min_points, max_detect_distance_m : float, int, float
        leg_tracker's ``cluster_dist_euclid`` 0.13 m, ``min_points_per_cluster`` 3,
        ``max_detect_distance`` 10 m (``detect_leg_clusters.cpp`` lines 78–80).
    """

    def __init__(self, forest: str = "leg_tracker_bags", threshold: float = 0.1,
                 rate: float = 0.05, match_m: float = 0.13, cluster_dist_m: float = 0.13,
                 min_points: int = 3, max_detect_distance_m: float = 10.0):
        self.forest = forest
        self.threshold = threshold
        self.rate = rate
        self.match_m = match_m
        self.cluster_dist_m = cluster_dist_m
        self.min_points = min_points
        self.max_detect_distance_m = max_detect_distance_m

    def cluster_scores(self, scans):
        """Per scan: (cluster centroids (C, 2), P(leg) per cluster)."""
        from gaitval.track.legclusters import all_clusters
        from gaitval.track.legforest import load_forest
        forest = load_forest(self.forest)
        per = all_clusters(scans, self.cluster_dist_m, self.min_points)
        if not per:
            return []
        cen = np.vstack([c for c, _ in per])
        feats = np.vstack([f for _, f in per])
        p = forest.votes(feats) if len(feats) else np.zeros(0)
        p[np.hypot(cen[:, 0], cen[:, 1]) >= self.max_detect_distance_m] = 0.0
        out, i = [], 0
        for c, _ in per:
            out.append((c, p[i:i + len(c)]))
            i += len(c)
        return out

    def scores(self, scans, xy):
        out = []
        m2 = self.match_m ** 2
        for (cen, p), z in zip(self.cluster_scores(scans), xy):
            z = np.asarray(z, dtype=float).reshape(-1, 2)
            s = np.zeros(len(z))
            if len(z) and len(cen):
                d2 = ((z[:, None, :] - cen[None, :, :]) ** 2).sum(axis=2)
                s = np.where(d2 < m2, p[None, :], 0.0).max(axis=1)
            out.append(s)
        return out

    def admits(self, p_l, p_r):
        return min(p_l, p_r) >= self.threshold

    def start(self, p_l, p_r):
        return {"legs": [float(p_l), float(p_r)], "person": None}

    def update(self, person):
        mem, a = person.look, self.rate
        ps = [p for p in person.zp if p is not None]
        if mem["person"] is None:
            for f in (0, 1):
                if person.zp[f] is not None:
                    mem["legs"][f] = (1 - a) * mem["legs"][f] + a * person.zp[f]
        elif ps:
            mem["person"] = (1 - a) * mem["person"] + a * (sum(ps) / len(ps))

    def confirmed(self, person):
        mem = person.look
        if mem["person"] is None:
            mem["person"] = 0.5 * (mem["legs"][0] + mem["legs"][1])

    def keeps(self, person):
        mem = person.look
        c = min(mem["legs"]) if mem["person"] is None else mem["person"]
        return c >= self.threshold


@APPEARANCES.register("legs_confirm")
class LegsConfirm(LegForestAppearance):
    """Two legs that look like legs for K scans confirm a tentative pair (module notes).

    Parameters
    ----------
    forest : str
        A forest of :mod:`gaitval.track.legforest` or a path to one.
    min_score : float
        θ: each leg's cluster scores at least this P(leg) on a counted scan.
    n_scans : int
        K: the scans, consecutive, over which both legs are seen and their scores averaged.
    match_m, cluster_dist_m, min_points, max_detect_distance_m
        As ``leg_forest`` (leg_tracker's values).
    """

    def __init__(self, forest: str = "leg_tracker_bags", min_score: float = 0.9,
                 n_scans: int = 5, match_m: float = 0.13, cluster_dist_m: float = 0.13,
                 min_points: int = 3, max_detect_distance_m: float = 10.0):
        super().__init__(forest, 0.0, 0.0, match_m, cluster_dist_m, min_points,
                         max_detect_distance_m)
        self.min_score = float(min_score)
        self.n_scans = int(n_scans)

    def admits(self, p_l, p_r):
        return True

    def start(self, p_l, p_r):
        return deque(maxlen=self.n_scans)       # per scan: (p_L, p_R), or None

    def update(self, person):
        pass

    def confirmed(self, person):
        pass

    def keeps(self, person):
        return True

    def confirms(self, person, leg_width_m):
        win = person.look
        both = (person.seen[0] and person.seen[1] and person.apart
                and ((person.z[0][0] - person.z[1][0]) ** 2
                     + (person.z[0][1] - person.z[1][1]) ** 2) >= leg_width_m ** 2)
        win.append((person.zp[0], person.zp[1]) if both else None)
        if len(win) < self.n_scans or any(w is None for w in win):
            return False
        return all(sum(w[f] for w in win) >= self.min_score * self.n_scans for f in (0, 1))
