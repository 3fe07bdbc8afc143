"""A people tracker: several persons, two legs each, with a life cycle (issue 36).

Tracker kind ``people`` (:class:`PeopleTracker`).  Per scan k (docs/people.md)::

    for every person alive:  prior = filter.predict(leg, Δt, motion.inputs(phase))   # each leg
    assign(confirmed and coasting persons' legs  ×  observations)     # λ² inside the gate,
    assign(tentative persons' legs  ×  the observations left)         # linear_sum_assignment
    correct each assigned leg (filter.correct); identify each person's gait phase
    confirmer.step(person)   → tentative becomes confirmed           (lifecycle.MOfNMoving)
    deleter.ended(person)    → ended: unsupported too long, or left the area
    birth.propose(unexplained observations) → new tentative persons  (lifecycle.UnexplainedPairs)
    refind.match(tentative persons seen now) → a recently ended person found again: confirmed,
                                               with the ended person's id (lifecycle.LegTrackerGate)

The leg model is the seed papers': one ``filter`` per leg (seed 000's KF, seed000 eq.
(7)–(8), (14)–(16)), a ``motion`` input (constant velocity, seed001 eq. (2); or seed 000's
gait-phase acceleration, eq. (18)–(20)), the ``phase`` identification (seed000 eq. (3)–(5))
and a ``gate`` (seed000 eq. (11)–(13) χ², or seed 001's regions).  The assignment is the
global nearest neighbour of seed 001 eq. (6)–(8) across all persons' legs at once: minimum
Σλ² over the gated pairs, solved by :func:`scipy.optimize.linear_sum_assignment` (the
Hungarian method; leg_tracker's ``match_detections_to_tracks_GNN`` does the same).
Confirmed persons are assigned before tentative ones, so a hypothesis that is not yet a
person cannot take a person's leg; an observation inside a confirmed person's leg gate
does not start a new person.

Output
    :class:`PeopleResult`: a :class:`~gaitval.track.leg.TrackResult` of the *subject* — the
    person confirmed and observed on most scans (what the studies evaluate against their
    reference) — plus ``people``, every confirmed person's legs per scan
    (:data:`PEOPLE_COLUMNS`; tentative hypotheses are not people and are not reported;
    coasting ones are, as leg_tracker publishes occluded people).

Initialisation (``init``)
    None: persons are born from the data only.  An initialiser spec (e.g. legbench's
    ``annotated_pair``): the pair it finds is a confirmed person from its scan on (the
    person the annotator or the clinician points at is known).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451 (seed 000: leg KF, gate,
gait phase).  Yorozu, A.; Takahashi, M. Sensors 2015, 15, 11151 (seed 001: GNN assignment).
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (life cycle defaults, see :mod:`gaitval.track.lifecycle`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from gaitval.detect import DETECTORS
from gaitval.detect.base import split_observations
from gaitval.track.appearance import APPEARANCES
from gaitval.track.gate import GATES, GateContext
from gaitval.track.init import INITIALISERS
from gaitval.track.kalman import FILTERS
from gaitval.track.kinds import TRACKER_KINDS, TrackerKind
from gaitval.track.leg import TrackResult, empty_result, handedness, swap_sides
from gaitval.track.lifecycle import (AREAS, BIRTHS, COASTING, CONFIRMED, CONFIRMERS,
                                     DELETERS, ENDED, REFINDS, TENTATIVE)
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.observations import DetectionSeries
from gaitval.track.passes import PASSES, reverse_rows
from gaitval.track.phase import PHASE_MODELS
from gaitval.track.staticmap import (ARRIVALS, EGO_MOTIONS, STATIC_MAPS, scan_points,
                                     to_world)
from gaitval.track.tracker import _SWING, step_durations

#: columns of :attr:`PeopleResult.people` (one row per scan, reported person and leg)
PEOPLE_COLUMNS = ("k", "t_sensor_s", "person_id", "status", "side", "x_m", "y_m", "vx_mps",
                  "vy_mps", "observed", "pattern", "phase")
_NO = 1.0e12            # cost of a pair outside the gate (never chosen)


@dataclass
class PeopleResult(TrackResult):
    """A :class:`TrackResult` of the subject plus every confirmed person (module notes).

    ``people``: DataFrame with :data:`PEOPLE_COLUMNS`; ``subject_id``: the person id the
    TrackResult arrays follow (−1: nobody); ``n_born``/``n_confirmed``: hypotheses started /
    confirmed over the run; ``n_refound``: hypotheses that were an ended person found again
    (confirmed by the ``refind`` role, not counted in ``n_confirmed``)."""

    people: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=PEOPLE_COLUMNS))
    subject_id: int = -1
    n_born: int = 0
    n_confirmed: int = 0
    n_refound: int = 0


class Person:
    """One person hypothesis: two legs' filter states and its life-cycle state."""

    __slots__ = ("pid", "status", "post", "prior", "seen", "pattern", "obs_j", "phase",
                 "windows", "t_last_seen", "confirm_memory", "n_unobs", "k_born", "n_obs",
                 "world_centre", "seen_centre", "z", "zp", "look", "n_both")

    def __init__(self, pid, filter, zl, zr, pl, pr, jl, jr, k, t, windows, memory,
                 status=TENTATIVE, scores=(1.0, 1.0), look=None):
        self.pid = pid
        self.status = status
        self.post = [filter.init(float(zl[0]), float(zl[1])),
                     filter.init(float(zr[0]), float(zr[1]))]
        self.prior = list(self.post)
        self.seen = [True, True]
        self.pattern = [pl, pr]
        self.obs_j = [jl, jr]
        self.phase = 0
        self.windows = windows
        self.t_last_seen = t
        self.confirm_memory = memory
        self.n_unobs = [0, 0]
        self.n_obs = [1, 1]
        self.k_born = k
        self.world_centre = (0, 0.0, 0.0)      # (ego-motion segment, x, y)
        self.seen_centre = self.centre()       # the centre on the last scan with a leg seen
        self.z = [(float(zl[0]), float(zl[1])), (float(zr[0]), float(zr[1]))]  # observations
        self.zp = [float(scores[0]), float(scores[1])]  # their appearance scores (None: unseen)
        self.look = look                       # the appearance role's memory
        self.n_both = 1                        # scans with both legs observed since birth

    def pos(self, f: int) -> tuple[float, float]:
        s = self.post[f]
        return s[0], s[1]

    def centre(self) -> tuple[float, float]:
        a, b = self.post
        return 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])

    @property
    def reported(self) -> bool:
        return self.status in (CONFIRMED, COASTING)


@TRACKER_KINDS.register("people")
class PeopleTracker(TrackerKind):
    """Several people, two legs each, with tentative/confirmed/coasting/ended hypotheses.

    Parameters
    ----------
    detector, filter, motion, phase, gate : spec
        The leg roles (registries of :mod:`gaitval.detect` and :mod:`gaitval.track`).
    tentative_gate : spec or None
        The gate of tentative persons' legs (None: ``gate``).
    tentative_motion : spec or None
        The motion input of tentative persons' legs (None: ``motion``): a hypothesis that
        is not yet a person has no gait to model (experiments/people_gate.py).
    birth, confirmer, deleter, area, refind : spec
        The life-cycle roles (:mod:`gaitval.track.lifecycle`); ``refind`` (default
        ``leg_tracker_gate``; ``none``: an ended person stays ended) gives a recently ended
        person back when a tentative hypothesis appears where it was last seen.
    appearance : spec
        Does an observation look like a leg (:mod:`gaitval.track.appearance`; ``none``:
        everything does; ``leg_forest``: leg_tracker's classifier and confidence rule — a
        pair scoring below its threshold is not born, a tentative pair or a confirmed person
        whose running confidence falls below it ends).
    ego_motion, static_map : spec
        The sensor's motion and the map of what never moves (:mod:`gaitval.track.staticmap`):
        an observation on a static cell starts no person, and a tentative person with
        both legs on static cells is not confirmed (leg_tracker's "in free space").
    passes : spec
        ``forward`` (online, the default) or ``forward_backward`` (offline: the scans are
        also read in reverse order and the passes joined; :mod:`gaitval.track.passes`).
    init : spec or None
        An initialiser whose pair starts a confirmed person (module notes; forward pass
        only).
    max_leg_separation_m : float
        An observation further than this from a person's other leg (predicted) is not that
        person's leg (leg_tracker's ``max_leg_pairing_dist``, 0.8 m).
    person_points_m : float
        Scan returns within this distance of an observation assigned to a reported person
        are that person's leg and are not learned by the static map (leg_tracker's cluster
        distance ``cluster_dist_euclid``, 0.13 m).
    dt_s : float or None
        Scan period (None: the median timestamp difference).
    sides : {"walking_direction", "as_initialised"}
        Left/right of the subject's legs, as :class:`~gaitval.track.tracker.Tracker`.
    """

    def __init__(self, detector="leg_patterns", filter="kf", motion="constant_velocity",
                 phase="speed_thresholds", gate="chi2", birth="unexplained_pairs",
                 confirmer="m_of_n_moving", deleter="unsupported_time",
                 area="field_of_view", ego_motion="none", static_map="none",
                 init=None, tentative_gate=None, tentative_motion=None,
                 refind="leg_tracker_gate",
                 appearance="none", arrival="none", passes="forward",
                 max_leg_separation_m: float = 0.8, person_points_m: float = 0.13,
                 dt_s: float | None = None, sides: str = "walking_direction"):
        self.detector = DETECTORS.build(detector)
        self.filter = FILTERS.build(filter)
        self.motion = MOTION_MODELS.build(motion)
        self.phase = PHASE_MODELS.build(phase)
        self.gate = GATES.build(gate)
        self.tentative_gate = GATES.build(tentative_gate) if tentative_gate else None
        self.tentative_motion = (MOTION_MODELS.build(tentative_motion) if tentative_motion
                                 else None)
        self.birth = BIRTHS.build(birth)
        self.confirmer = CONFIRMERS.build(confirmer)
        self.deleter = DELETERS.build(deleter)
        self.area = AREAS.build(area)
        self.refind = REFINDS.build(refind)
        self.appearance = APPEARANCES.build(appearance)
        self.ego_motion = EGO_MOTIONS.build(ego_motion)
        self.static_map = STATIC_MAPS.build(static_map)
        self.arrival = ARRIVALS.build(arrival)
        self.passes = PASSES.build(passes)
        self.init = INITIALISERS.build(init) if init else None
        self.max_leg_separation_m = max_leg_separation_m
        self.person_points_m = person_points_m
        self.dt_s = dt_s
        self.sides = sides

    # -- the loop ----------------------------------------------------------------------------
    accepts_observations = True

    def track(self, scans, leg_width_m: float, observations=None) -> PeopleResult:
        """``observations``: the detector's table of these scans made earlier (None:
        detect now; :class:`~gaitval.track.kinds.TrackerKind`)."""
        obs_df = (self.detector.detect(scans, leg_width_m) if observations is None
                  else observations)
        xy, pats = split_observations(obs_df, scans.n_scans)
        return self.run(scans, xy, pats, leg_width_m)

    def run(self, scans, xy, pats, leg_width_m: float, profile: bool = False
            ) -> PeopleResult:
        """Track every person through precomputed per-scan observations (``xy[k]``: (J, 2)
        array, ``pats[k]``: their patterns).  ``profile``: also return ``scan_seconds`` and
        ``scan_hypotheses`` (per scan: time spent, person hypotheses alive; both passes
        summed) as attributes of the result (benchmarks/people_tracker.py), and
        ``scan_static`` (per scan: for each observation, whether it lay on a static cell of
        the forward pass's map; experiments/people_misses.py).

        With ``passes: forward_backward`` the same loop also reads the scans in reverse
        order and the two passes are joined (:mod:`gaitval.track.passes`)."""
        t = np.asarray(scans.t, dtype=float)
        n = len(t)
        if n == 0:
            return _empty(t)
        rows, n_born, n_conf, n_refound, prof = self._pass(scans, xy, pats, leg_width_m,
                                                           profile, self.init)
        people = _people_frame(rows)
        subject = None
        if self.passes.backward:
            rscans = replace(scans, t=(t[0] + t[-1]) - t[::-1],
                             ranges=np.ascontiguousarray(scans.ranges[::-1]))
            brows, b_born, b_conf, b_refound, bprof = self._pass(
                rscans, list(xy)[::-1], list(pats)[::-1], leg_width_m, profile, None)
            back = reverse_rows(_people_frame(brows), t)
            dt0 = float(step_durations(t, self.dt_s)[0]) if n > 1 else float(self.dt_s or 0.1)
            # the subject and its labels are the forward (online) pass's
            ahead = self._result(t, people, n_born, n_conf)
            people, ids = self.passes.join(people, back, dt0)
            if ahead.subject_id >= 0:
                subject = (ids.get(ahead.subject_id, ahead.subject_id), ahead.swapped_sides)
            n_born, n_conf, n_refound = n_born + b_born, n_conf + b_conf, n_refound + b_refound
            if profile:
                prof = (prof[0] + bprof[0][::-1], prof[1] + bprof[1][::-1], prof[2])
        res = self._result(t, people, n_born, n_conf, subject)
        res.n_refound = n_refound
        if profile:
            res.scan_seconds, res.scan_hypotheses, res.scan_static = prof
        return res

    def _pass(self, scans, xy, pats, leg_width_m: float, profile: bool, init):
        """One pass of the loop over the scans in their order (module notes): the reported
        rows, hypotheses born / confirmed / re-found, and the profile (or None)."""
        # scipy here, not at the top: the Snakefile imports this module (the kind registry)
        from scipy.optimize import linear_sum_assignment

        from time import perf_counter
        t = np.asarray(scans.t, dtype=float)
        n = len(t)
        dts = (step_durations(t, self.dt_s)[1] if n > 1 else np.array([self.dt_s or 0.1]))
        dt0 = float(step_durations(t, self.dt_s)[0]) if n > 1 else float(dts[0])
        F = self.filter.for_leg_width(leg_width_m)
        gates = (self.gate.for_leg_width(leg_width_m),
                 (self.tentative_gate or self.gate).for_leg_width(leg_width_m))
        confirmer = self.confirmer.bind(dt0, leg_width_m)
        refind = self.refind.bind(dt0)
        area = self.area.bind(scans)
        poses, segment = self.ego_motion.poses(scans)
        look = self.appearance
        score = look.scores(scans, xy)          # per scan, P(leg) of each observation
        smap, arrived, seg = None, None, None
        seeded = None
        if init is not None:
            seeded = init.find(DetectionSeries(xy, pats), leg_width_m)
        persons: list[Person] = []
        rows: list[tuple] = []
        next_id = 1
        n_born = n_conf = n_refound = 0
        predict, correct, identify = F.predict, F.correct, self.phase.identify
        inputs = self.motion.inputs
        tentative_inputs = (self.tentative_motion or self.motion).inputs
        sep2 = self.max_leg_separation_m ** 2
        dts = dts.tolist()
        cost, alive, on_static = ([], [], []) if profile else (None, None, None)
        for k in range(n):
            if profile:
                t_start = perf_counter()
            dt, tk = dts[k], float(t[k])
            obs = [(float(p[0]), float(p[1])) for p in xy[k]]
            J = len(obs)
            pose = poses[k]
            if segment[k] != seg:          # the sensor's motion was lost: a new map
                seg = int(segment[k])
                smap = self.static_map.start(scans, poses)
                arrived = self.arrival.start(scans, poses)
                confirmer.scan(k, None)
            else:
                confirmer.scan(k, _relative(poses[k - 1], pose))
            # the map as learned up to the previous scan (leg_tracker's local map is the one
            # published after the previous scan)
            static = [smap.is_static(*w) for w in
                      to_world(pose, np.asarray(obs).reshape(-1, 2)).tolist()]
            # predict (seed000 eq. (7)-(8); input u of the motion role, eq. (18)-(20))
            for p in persons:
                a, b = p.post
                w = p.windows
                ul, ur = (tentative_inputs if p.status == TENTATIVE else inputs)(
                    p.phase, (a[2], a[3]), (b[2], b[3]),
                    w[0].mean if w[0] is not None else 0.0,
                    w[1].mean if w[1] is not None else 0.0, dt)
                p.prior = [predict(a, dt, ul[0], ul[1]), predict(b, dt, ur[0], ur[1])]
            taken = [False] * J
            explained = [False] * J
            assigned: dict[tuple[int, int], int] = {}
            for gate, group in ((gates[0], [p for p in persons if p.reported]),
                                (gates[1], [p for p in persons if p.status == TENTATIVE])):
                if not group or not J:
                    continue
                ctx_needed = gate.needs_context
                legs = [(i, f) for i in range(len(group)) for f in (0, 1)]
                C = np.full((len(legs), J), _NO)
                any_in = False
                for r, (i, f) in enumerate(legs):
                    p = group[i]
                    ctx = None
                    if ctx_needed:
                        s = p.post[f]
                        if p.n_obs[f] < 2:
                            # a leg seen once has no measured speed: seed 001 Table 1's
                            # "unobservable swing" cell (assumed swing speed v_sw)
                            ctx = GateContext(leg_width_m, dt, math.hypot(s[2], s[3]), True,
                                              max(1, p.n_unobs[f]))
                        else:
                            ctx = GateContext(leg_width_m, dt, math.hypot(s[2], s[3]),
                                              _SWING[p.phase][f], p.n_unobs[f])
                    ox, oy = p.prior[1 - f][0], p.prior[1 - f][1]
                    for j, lam2 in gate.candidates(F, p.prior[f], obs, ctx):  # eq. (11)-(13)
                        zx, zy = obs[j - 1]
                        if (zx - ox) ** 2 + (zy - oy) ** 2 > sep2:   # not this person's leg
                            continue
                        if p.reported:
                            explained[j - 1] = True
                        if not taken[j - 1]:
                            C[r, j - 1] = lam2
                            any_in = True
                if not any_in:
                    continue
                rr, cc = linear_sum_assignment(C)          # min Σλ² (seed001 eq. (6)-(8))
                for r, c in zip(rr.tolist(), cc.tolist()):
                    if C[r, c] < _NO:
                        i, f = legs[r]
                        assigned[(id(group[i]), f)] = c
                        taken[c] = True
            # correct (seed000 eq. (14)-(16)) and the gait phase (eq. (3)-(5))
            for p in persons:
                before = tuple(p.post)
                for f in (0, 1):
                    j = assigned.get((id(p), f))
                    if j is None:
                        p.post[f] = p.prior[f]
                        p.seen[f] = False
                        p.z[f] = None
                        p.zp[f] = None
                        p.pattern[f] = "UO"
                        p.obs_j[f] = -1
                        p.n_unobs[f] += 1
                    else:
                        p.post[f] = correct(p.prior[f], obs[j][0], obs[j][1])
                        p.seen[f] = True
                        p.z[f] = obs[j]
                        p.zp[f] = float(score[k][j])
                        p.pattern[f] = pats[k][j]
                        p.obs_j[f] = j
                        p.n_unobs[f] = 0
                        p.n_obs[f] += 1
                p.n_both += p.seen[0] and p.seen[1]
                look.update(p)
                if p.seen[0] or p.seen[1]:
                    p.t_last_seen = tk
                    p.seen_centre = p.centre()
                p.phase = identify(p.post[0], p.post[1])
                for f in (0, 1):                          # ‖a_k‖ (seed 000 §5.5)
                    w = p.windows[f]
                    if w is not None:
                        s1, s0 = p.post[f], before[f]
                        w.push(math.hypot(s1[2] - s0[2], s1[3] - s0[3]) / dt,
                               _SWING[p.phase][f])
            # the static map learns this scan, except the returns on reported persons' legs
            # (leg_tracker maps only clusters not matched to a person: a person who stands
            # is not learned as background)
            pts = scan_points(scans, k)
            on_people = [obs[j] for p in persons if p.reported for j in p.obs_j if j >= 0]
            if on_people and len(pts):
                lx = np.array(on_people)
                d2 = ((pts[:, None, :] - lx[None, :, :]) ** 2).sum(axis=2).min(axis=1)
                pts = pts[d2 > self.person_points_m ** 2]
            smap.update(k, to_world(pose, pts))
            arrived.update(k, pose)
            # life cycle
            for p in persons:
                if p.status == TENTATIVE:
                    if not look.keeps(p):               # no longer looks like two legs
                        p.status = ENDED
                        continue
                    p.world_centre = (seg, *to_world(pose, np.array([_evidence_centre(
                        p, confirmer.evidence)]))[0].tolist())
                    if (confirmer.step(p, k) or arrived.confirms(p, pose, tk)) \
                            and not _on_static(p, pose, smap):
                        p.status = CONFIRMED
                        look.confirmed(p)
                        n_conf += 1
                    elif confirmer.failed(p):
                        p.status = ENDED
                        continue
                if p.status == ENDED:
                    continue
                if not look.keeps(p):                   # a confirmed person that looks
                    p.status = ENDED                    # like no legs: not re-found
                    continue
                why = self.deleter.ended(p, k, tk, area)
                if why:
                    if p.reported:
                        refind.remember(p.pid, p.t_last_seen, p.seen_centre)
                    p.status = ENDED
                elif p.reported:
                    p.status = CONFIRMED if (p.seen[0] or p.seen[1]) else COASTING
            persons = [p for p in persons if p.status != ENDED]
            # birth from the observations nobody explains
            free = [not (taken[j] or explained[j] or static[j]) for j in range(J)]
            pairs = self.birth.propose(obs, free, leg_width_m)
            if seeded is not None and k == seeded[0]:
                il, ir = seeded[1], seeded[2]
                pairs = [(il, ir)] + [(a, b) for a, b in pairs
                                      if a not in (il, ir) and b not in (il, ir)]
            for a, b in pairs:
                start = CONFIRMED if (seeded is not None and k == seeded[0]
                                      and (a, b) == (seeded[1], seeded[2])) else TENTATIVE
                if start == TENTATIVE and not look.admits(score[k][a], score[k][b]):
                    continue
                if not area.contains(0.5 * (obs[a][0] + obs[b][0]),
                                     0.5 * (obs[a][1] + obs[b][1])):
                    continue
                p = Person(next_id, F, obs[a], obs[b], pats[k][a], pats[k][b], a, b, k, tk,
                           [self.motion.new_window(), self.motion.new_window()],
                           confirmer.new_memory(), status=start,
                           scores=(score[k][a], score[k][b]),
                           look=look.start(score[k][a], score[k][b]))
                if start == CONFIRMED:
                    look.confirmed(p)
                next_id += 1
                n_born += 1
                n_conf += start == CONFIRMED
                if start == TENTATIVE:
                    p.world_centre = (seg, *to_world(pose, np.array([p.centre()]))[0].tolist())
                    confirmer.step(p, k)
                persons.append(p)
            # a recently ended person found again keeps its confirmation and its id
            # ... and a coasting person found where it was last seen, its prediction elsewhere
            tentative = [p for p in persons if p.status == TENTATIVE]
            found = refind.match(tentative, tk)
            refound = {id(p) for p, _ in found}
            taken_over = refind.take_over([p for p in tentative if id(p) not in refound],
                                          [p for p in persons if p.status == COASTING], tk)
            for p, q in taken_over:
                q.status = ENDED
                found.append((p, q.pid))
            for p, pid in found:
                p.status = CONFIRMED
                look.confirmed(p)
                p.pid = pid
                n_refound += 1
            if taken_over:
                persons = [p for p in persons if p.status != ENDED]
            # record the reported persons
            for p in persons:
                if p.reported:
                    for f in (0, 1):
                        s = p.post[f]
                        rows.append((k, tk, p.pid, p.status, "LR"[f], s[0], s[1], s[2], s[3],
                                     p.seen[f], p.pattern[f], p.phase))
            if profile:
                cost.append(perf_counter() - t_start)
                alive.append(len(persons))
                on_static.append(static)
        prof = ((np.asarray(cost), np.asarray(alive, dtype=np.int64), on_static) if profile
                else None)
        return rows, n_born, n_conf, n_refound, prof

    # -- output ------------------------------------------------------------------------------
    def _result(self, t, people: pd.DataFrame, n_born: int, n_conf: int,
                subject: tuple[int, bool] | None = None) -> PeopleResult:
        """``subject``: (person id, swap its labels) decided elsewhere (the forward pass's,
        with ``passes: forward_backward``); None: the person observed on most scans,
        labelled by its walking direction (``sides``)."""
        res = _empty(t)
        res.people, res.n_born, res.n_confirmed = people, n_born, n_conf
        if people.empty:
            return res
        if subject is not None:
            sid = int(subject[0])
        else:
            seen = people[people["observed"]].groupby("person_id")["k"].nunique()
            if seen.empty:
                seen = people.groupby("person_id")["k"].nunique()
            best = seen.max()
            sid = int(seen[seen == best].index.min())    # ties: the earliest person
        res.subject_id = sid
        sub = people[people["person_id"] == sid]
        for f, side in enumerate("LR"):
            leg = sub[sub["side"] == side]
            k = leg["k"].to_numpy()
            res.x[f, k] = leg["x_m"].to_numpy(float)
            res.y[f, k] = leg["y_m"].to_numpy(float)
            res.vx[f, k] = leg["vx_mps"].to_numpy(float)
            res.vy[f, k] = leg["vy_mps"].to_numpy(float)
            res.observed[f, k] = leg["observed"].to_numpy(bool)
            res.pattern[f, k] = leg["pattern"].to_numpy(object)
            if f == 0:
                res.phase[k] = leg["phase"].to_numpy(np.int8)
        res.k_init = int(sub["k"].min())
        if subject is not None:
            if subject[1]:
                swap_sides(res)
        elif self.sides == "walking_direction" and handedness(res) < 0:
            swap_sides(res)
        return res


def _people_frame(rows: list[tuple]) -> pd.DataFrame:
    people = pd.DataFrame.from_records(rows, columns=list(PEOPLE_COLUMNS))
    return people.astype({"k": np.int64, "person_id": np.int64, "phase": np.int64,
                          "observed": bool})


def _evidence_centre(p: Person, evidence: str) -> tuple[float, float]:
    """The body centre the confirmer's tests look at: the mean of the two observations on
    a scan that saw both legs (``evidence`` = "observations"), else of the estimates."""
    if evidence == "observations" and p.seen[0] and p.seen[1]:
        return 0.5 * (p.z[0][0] + p.z[1][0]), 0.5 * (p.z[0][1] + p.z[1][1])
    return p.centre()


def _relative(a, b) -> tuple[float, float, float]:
    """Pose ``b`` = (x, y, θ) in the frame of pose ``a`` (both in one world frame)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = float(b[0] - a[0]), float(b[1] - a[1])
    return c * dx + s * dy, -s * dx + c * dy, float(b[2] - a[2])


def _on_static(p: Person, pose, smap) -> bool:
    """Either leg of ``p`` lies on a static cell of the map (not in free space; stricter
    than leg_tracker, which asks one leg in free space — docs/people.md)."""
    w = to_world(pose, np.array([p.pos(0), p.pos(1)]))
    return smap.is_static(*w[0]) or smap.is_static(*w[1])


def _empty(t) -> PeopleResult:
    base = empty_result(t)
    return PeopleResult(**{f: getattr(base, f) for f in base.__dataclass_fields__})


def people_frame_for_scoring(res: PeopleResult) -> pd.DataFrame:
    """The legbench track of a people result: :data:`~gaitval.track.leg.TRACK_COLUMNS` plus
    ``person_id``, one row per scan, reported person and side; a scan with nobody reported
    has two rows with ``person_id`` −1 and no position, so that every scan's time is kept.
    ``swing`` and ``interpolated`` are False (not kept per person)."""
    n = len(res.t)
    p = res.people
    cols = ["k", "t_sensor_s", "side", "x_m", "y_m", "vx_mps", "vy_mps", "observed",
            "pattern", "phase", "person_id"]
    out = p[cols].copy() if len(p) else pd.DataFrame(columns=cols)
    out["swing"] = False
    out["interpolated"] = False
    have = np.zeros(n, dtype=bool)
    if len(p):
        have[p["k"].to_numpy()] = True
    ks = np.flatnonzero(~have)
    if len(ks):
        nan = np.full(2 * len(ks), np.nan)
        pad = pd.DataFrame({
            "k": np.repeat(ks, 2).astype(np.int64),
            "t_sensor_s": np.repeat(np.asarray(res.t, float)[ks], 2),
            "side": np.tile(np.array(["L", "R"], dtype=object), len(ks)),
            "x_m": nan, "y_m": nan, "vx_mps": nan, "vy_mps": nan,
            "observed": False, "pattern": "", "phase": -1, "person_id": -1,
            "swing": False, "interpolated": False})
        out = pd.concat([out, pad], ignore_index=True)
    out = out.sort_values(["k", "person_id", "side"], kind="stable").reset_index(drop=True)
    return out.astype({"k": np.int64, "person_id": np.int64, "phase": np.int64,
                       "observed": bool, "swing": bool, "interpolated": bool})


def person_hypotheses(track: pd.DataFrame) -> pd.DataFrame:
    """Every reported person's hypothesis in a :func:`people_frame_for_scoring` track: the
    midpoint of its two legs, ``hyp_id`` = its person id (the columns of
    :data:`gaitval.evaluate.clearmot.HYP_COLUMNS`: ``k, hyp_id, x_m, y_m``)."""
    tr = track[track["person_id"] >= 0]
    mid = tr.groupby(["k", "person_id"], sort=True)[["x_m", "y_m"]].agg(["mean", "count"])
    mid = mid[(mid[("x_m", "count")] == 2) & (mid[("y_m", "count")] == 2)]
    return pd.DataFrame({"k": mid.index.get_level_values(0).astype(np.int64),
                         "hyp_id": mid.index.get_level_values(1).astype(np.int64),
                         "x_m": mid[("x_m", "mean")].to_numpy(float),
                         "y_m": mid[("y_m", "mean")].to_numpy(float)})
