"""One pass of the people tracker over a recording's scans, as a composition of roles.

:class:`PeoplePass` holds a pass's state (the persons alive, the rows reported, the bound
roles); :meth:`PeoplePass.scan` is the loop body of docs/people.md, one call per role::

    begin(k)      the sensor's pose, the static map of the ego-motion segment, static flags
    predict()     every person's legs (seed000 eq. (7)-(8); motion input eq. (18)-(20))
    associate()   reported persons first, then tentative ones (seed001 eq. (6)-(8))
    correct()     the assigned legs (seed000 eq. (14)-(16)), gait phase (eq. (3)-(5))
    support()     the deleter's evidence and the static map's update
    life_cycle()  confirmation, appearance, deletion
    births()      new tentative persons from the observations nobody explains
    refind()      recently ended or coasting persons found again
    record()      the reported persons' rows

An optional ``observer`` (:class:`gaitval.track.observe.ScanProfile`) is told before and
after each scan.
"""
from __future__ import annotations

import math

import numpy as np

from gaitval.track.gate import GateContext
from gaitval.track.lifecycle import COASTING, CONFIRMED, ENDED, TENTATIVE
from gaitval.track.observations import DetectionSeries
from gaitval.track.staticmap import scan_points, to_world
from gaitval.track.tracker import _SWING, step_durations

_NO = 1.0e12            # cost of a pair outside the gate (never chosen)
# a standing leg's reach in one scan: seed 001 Table 1's stance cell with its assumed
# stance speed (¾ w_l + Δt·v_st, v_st = 0.55 m/s): the leg beside which the other swings
STAND_LEG_WIDTHS = 0.75
STAND_MPS = 0.55


class Person:
    """One person hypothesis: two legs' filter states and its life-cycle state."""

    __slots__ = ("pid", "status", "post", "prior", "seen", "pattern", "obs_j", "phase",
                 "windows", "t_last_seen", "confirm_memory", "n_unobs", "k_born", "n_obs",
                 "world_centre", "seen_centre", "z", "zp", "look", "n_both", "t_last_return",
                 "apart")

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
        self.t_last_return = t                 # the last scan with support in its gate
        self.apart = True                      # no surface joins the two observations

    def pos(self, f: int) -> tuple[float, float]:
        s = self.post[f]
        return s[0], s[1]

    def centre(self) -> tuple[float, float]:
        a, b = self.post
        return 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])

    @property
    def reported(self) -> bool:
        return self.status in (CONFIRMED, COASTING)

    def evidence_centre(self, evidence: str) -> tuple[float, float]:
        """The body centre the confirmer's tests look at: the mean of the two observations
        on a scan that saw both legs (``evidence`` = "observations"), else of the
        estimates."""
        if evidence == "observations" and self.seen[0] and self.seen[1]:
            return 0.5 * (self.z[0][0] + self.z[1][0]), 0.5 * (self.z[0][1] + self.z[1][1])
        return self.centre()


def _relative(a, b) -> tuple[float, float, float]:
    """Pose ``b`` = (x, y, θ) in the frame of pose ``a`` (both in one world frame)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return c * dx + s * dy, -s * dx + c * dy, b[2] - a[2]


def joined_by_surface(zl, zr, pts: np.ndarray, leg_width_m: float) -> bool:
    """Is the pair of observations ``zl``, ``zr`` part of one surface: a scan return
    (``pts``, sensor frame) farther than one leg width from both, within half a leg width
    of the line through them, between them or up to two leg widths beyond either?
    Between a person's legs the beams pass through to the background, and along the line
    of the legs lies the space the person walks through; a return there is a surface that
    runs through both "legs" (a wall or a piece of furniture seen at a grazing angle,
    broken into leg-sized pieces by range steps and dropouts:
    experiments/people_empty_backwards.py)."""
    if not len(pts):
        return False
    a = np.array(zl, dtype=float)
    d = np.array(zr, dtype=float) - a
    n = float(np.hypot(*d))
    if n <= 0.0:
        return False
    u = d / n
    q = pts - a
    along = q @ u
    off = np.abs(q[:, 0] * u[1] - q[:, 1] * u[0])
    far = (np.hypot(*q.T) > leg_width_m) & (np.hypot(*(q - d).T) > leg_width_m)
    on_line = (off <= 0.5 * leg_width_m) & (along >= -2.0 * leg_width_m) \
        & (along <= n + 2.0 * leg_width_m)
    return bool(np.any(far & on_line))


def _on_static(p: Person, pose, smap) -> bool:
    """Is either of a tentative person's legs on a static cell (the map as learned so
    far)?  leg_tracker confirms a pair only when one of its legs is in free space."""
    pts = to_world(pose, np.array([p.pos(0), p.pos(1)]))
    return smap.is_static(*pts[0]) or smap.is_static(*pts[1])


class PeoplePass:
    """One pass of :class:`~gaitval.track.people.PeopleTracker` (module notes)."""

    def __init__(self, tracker, scans, xy, pats, leg_width_m: float, init):
        self.tk_ = tracker
        self.scans, self.xy, self.pats, self.w = scans, xy, pats, leg_width_m
        t = np.asarray(scans.t, dtype=float)
        self.t = t
        self.n = len(t)
        dts = (step_durations(t, tracker.dt_s)[1] if self.n > 1
               else np.array([tracker.dt_s or 0.1]))
        dt0 = float(step_durations(t, tracker.dt_s)[0]) if self.n > 1 else float(dts[0])
        self.dts = dts.tolist()
        self.F = tracker.filter.for_leg_width(leg_width_m)
        self.gates = (tracker.gate.for_leg_width(leg_width_m),
                      (tracker.tentative_gate or tracker.gate).for_leg_width(leg_width_m))
        self.confirmer = tracker.confirmer.bind(dt0, leg_width_m)
        self.refinder = tracker.refind.bind(dt0)
        self.area = tracker.area.bind(scans)
        self.poses, self.segment = tracker.ego_motion.poses(scans)
        self.look = tracker.appearance
        self.score = self.look.scores(scans, xy)       # per scan, P(leg) of each observation
        self.smap = self.arrived = self.seg = None
        self.seeded = (init.find(DetectionSeries(xy, pats), leg_width_m)
                       if init is not None else None)
        self.persons: list[Person] = []
        self.rows: list[tuple] = []
        self.next_id = 1
        self.n_born = self.n_conf = self.n_refound = 0
        self.sep2 = tracker.max_leg_separation_m ** 2

    # -- the loop body --------------------------------------------------------------------
    def scan(self, k: int) -> None:
        self.begin(k)
        self.predict()
        self.associate()
        self.correct()
        self.support()
        self.life_cycle()
        self.births()
        self.refind()
        self.record()

    def begin(self, k: int) -> None:
        """Scan k's observations, pose and static flags (the map as learned up to the
        previous scan: leg_tracker's local map is the one published after it)."""
        self.k, self.dt, self.tk = k, self.dts[k], float(self.t[k])
        self.pts = None                          # the scan's returns, when asked for
        self.obs = [(float(p[0]), float(p[1])) for p in self.xy[k]]
        self.pose = self.poses[k]
        if self.segment[k] != self.seg:          # the sensor's motion was lost: a new map
            self.seg = int(self.segment[k])
            self.smap = self.tk_.static_map.start(self.scans, self.poses)
            self.arrived = self.tk_.arrival.start(self.scans, self.poses)
            self.confirmer.scan(k, None)
        else:
            self.confirmer.scan(k, _relative(self.poses[k - 1], self.pose))
        self.static = [self.smap.is_static(*w) for w in
                       to_world(self.pose, np.asarray(self.obs).reshape(-1, 2)).tolist()]

    def predict(self) -> None:
        """seed000 eq. (7)-(8), input u of the motion role (eq. (18)-(20))."""
        tr, dt, predict = self.tk_, self.dt, self.F.predict
        inputs = tr.motion.inputs
        tentative_inputs = (tr.tentative_motion or tr.motion).inputs
        for p in self.persons:
            a, b = p.post
            w = p.windows
            ul, ur = (tentative_inputs if p.status == TENTATIVE else inputs)(
                p.phase, (a[2], a[3]), (b[2], b[3]),
                w[0].mean if w[0] is not None else 0.0,
                w[1].mean if w[1] is not None else 0.0, dt)
            p.prior = [predict(a, dt, ul[0], ul[1]), predict(b, dt, ur[0], ur[1])]

    def associate(self) -> None:
        """Reported persons' legs first, then tentative ones', each group by minimum Σλ²
        over its gated pairs (seed001 eq. (6)-(8))."""
        from scipy.optimize import linear_sum_assignment
        J = len(self.obs)
        self.taken = [False] * J
        self.explained = [False] * J
        self.assigned: dict[tuple[int, int], int] = {}
        for gate, group in ((self.gates[0], [p for p in self.persons if p.reported]),
                            (self.gates[1], [p for p in self.persons
                                             if p.status == TENTATIVE])):
            if not group or not J:
                continue
            legs = [(i, f) for i in range(len(group)) for f in (0, 1)]
            C = self._costs(gate, group, legs)
            if C is None:
                continue
            rr, cc = linear_sum_assignment(C)          # min Σλ² (seed001 eq. (6)-(8))
            for r, c in zip(rr.tolist(), cc.tolist()):
                if C[r, c] < _NO:
                    i, f = legs[r]
                    self.assigned[(id(group[i]), f)] = c
                    self.taken[c] = True
        if self.tk_.pair_swing_mps is not None:
            self._pair_swing()

    def half_seen(self):
        """(person, seen leg) of each tentative person with exactly one leg assigned an
        observation on this scan."""
        for p in self.persons:
            if p.status != TENTATIVE:
                continue
            a = [self.assigned.get((id(p), f)) is not None for f in (0, 1)]
            if a[0] != a[1]:
                yield p, 0 if a[0] else 1

    def _pair_swing(self) -> None:
        """The pair rule (docs/people.md): a tentative person with one leg assigned takes,
        for its other leg, a free observation that a swinging leg can have reached while
        the assigned leg stood — within the pairing distance of the assigned leg (0.7 w_l
        … ``max_leg_separation_m``, the birth's bounds) and within w_l + (H + 1)·Δt·v_pair
        of the other leg's prediction (H: its unobserved scans, v_pair the tracker's
        ``pair_swing_mps``), the nearest to that prediction.  Only when the assigned leg
        stood (observed on the previous scan too, within seed 001's stance reach of its
        prediction) and the person is younger than the confirmer's window (a pair that
        stood through a whole window is not mid-walk); a lone leg keeps its own gate."""
        lo, hi = self.tk_.birth_min_leg_widths * self.w, self.tk_.max_leg_separation_m
        v = self.tk_.pair_swing_mps
        stay = STAND_LEG_WIDTHS * self.w + self.dt * STAND_MPS
        young = getattr(self.confirmer, "n", None)
        for p, seen in self.half_seen():
            zx, zy = self.obs[self.assigned[(id(p), seen)]]
            sx, sy = p.prior[seen][0], p.prior[seen][1]
            if p.n_unobs[seen] > 0 or math.hypot(zx - sx, zy - sy) > stay:
                continue                # the seen leg was not seen standing there
            if young is not None and self.k - p.k_born >= young:
                continue                # stood through a whole window: not mid-walk
            px, py = p.prior[1 - seen][0], p.prior[1 - seen][1]
            reach = self.w + (p.n_unobs[1 - seen] + 1) * self.dt * v
            best, bd = None, reach
            for j, (ox, oy) in enumerate(self.obs):
                if self.taken[j] or self.explained[j] or self.static[j]:
                    continue
                if not lo <= math.hypot(ox - zx, oy - zy) <= hi:
                    continue
                d = math.hypot(ox - px, oy - py)
                if d <= bd:
                    best, bd = j, d
            if best is not None:
                self.assigned[(id(p), 1 - seen)] = best
                self.taken[best] = True

    def _gate_context(self, p: Person, f: int):
        s = p.post[f]
        if p.n_obs[f] < 2:
            # a leg seen once has no measured speed: seed 001 Table 1's "unobservable
            # swing" cell (assumed swing speed v_sw)
            return GateContext(self.w, self.dt, math.hypot(s[2], s[3]), True,
                               max(1, p.n_unobs[f]))
        return GateContext(self.w, self.dt, math.hypot(s[2], s[3]), _SWING[p.phase][f],
                           p.n_unobs[f])

    def _costs(self, gate, group, legs):
        """λ² of each (leg, observation) pair inside the gate and within the pairing
        distance of the person's other leg (None when no pair is)."""
        obs, F = self.obs, self.F
        C = np.full((len(legs), len(obs)), _NO)
        any_in = False
        for r, (i, f) in enumerate(legs):
            p = group[i]
            ctx = self._gate_context(p, f) if gate.needs_context else None
            ox, oy = p.prior[1 - f][0], p.prior[1 - f][1]
            for j, lam2 in gate.candidates(F, p.prior[f], obs, ctx):      # eq. (11)-(13)
                zx, zy = obs[j - 1]
                if (zx - ox) ** 2 + (zy - oy) ** 2 > self.sep2:   # not this person's leg
                    continue
                if p.reported:
                    self.explained[j - 1] = True
                if not self.taken[j - 1]:
                    C[r, j - 1] = lam2
                    any_in = True
        return C if any_in else None

    def correct(self) -> None:
        """seed000 eq. (14)-(16) on the assigned legs, the prior on the others; the gait
        phase (eq. (3)-(5)) and each leg's acceleration window (seed 000 §5.5)."""
        tk, identify = self.tk, self.tk_.phase.identify
        for p in self.persons:
            before = tuple(p.post)
            for f in (0, 1):
                self._correct_leg(p, f, self.assigned.get((id(p), f)))
            p.n_both += p.seen[0] and p.seen[1]
            self.look.update(p)
            if p.seen[0] or p.seen[1]:
                p.t_last_seen = tk
                p.seen_centre = p.centre()
            p.phase = identify(p.post[0], p.post[1])
            for f in (0, 1):                          # ‖a_k‖ (seed 000 §5.5)
                w = p.windows[f]
                if w is not None:
                    s1, s0 = p.post[f], before[f]
                    w.push(math.hypot(s1[2] - s0[2], s1[3] - s0[3]) / self.dt,
                           _SWING[p.phase][f])

    def _correct_leg(self, p: Person, f: int, j) -> None:
        if j is None:
            p.post[f] = p.prior[f]
            p.seen[f], p.z[f], p.zp[f], p.pattern[f], p.obs_j[f] = False, None, None, "UO", -1
            p.n_unobs[f] += 1
            return
        obs = self.obs[j]
        p.post[f] = self.F.correct(p.prior[f], obs[0], obs[1])
        p.seen[f], p.z[f], p.zp[f] = True, obs, float(self.score[self.k][j])
        p.pattern[f], p.obs_j[f] = self.pats[self.k][j], j
        p.n_unobs[f] = 0
        p.n_obs[f] += 1

    def support(self) -> None:
        """The deleter's evidence (returns and observations off the static map in each
        gate), then the static map learns this scan, except the returns on reported
        persons' legs (leg_tracker maps only clusters not matched to a person: a person
        who stands is not learned as background)."""
        pts = scan_points(self.scans, self.k)
        smap, pose = self.smap, self.pose
        self.tk_.deleter.support(self.persons, pts, self.tk, lambda q: np.array(
            [smap.is_static(*w) for w in to_world(pose, q).tolist()], dtype=bool),
            self.static)
        on_people = [self.obs[j] for p in self.persons if p.reported for j in p.obs_j
                     if j >= 0]
        if on_people and len(pts):
            lx = np.array(on_people)
            d2 = ((pts[:, None, :] - lx[None, :, :]) ** 2).sum(axis=2).min(axis=1)
            pts = pts[d2 > self.tk_.person_points_m ** 2]
        smap.update(self.k, to_world(pose, pts))
        self.arrived.update(self.k, pose)

    def life_cycle(self) -> None:
        """Tentative persons confirmed or failed, then every person's appearance and
        deletion (an ended reported person is remembered for re-finding)."""
        look = self.look
        for p in self.persons:
            if p.status == TENTATIVE:
                self._confirm(p)
            if p.status == ENDED:
                continue
            if not look.keeps(p):                   # a confirmed person that looks
                p.status = ENDED                    # like no legs: not re-found
                continue
            why = self.tk_.deleter.ended(p, self.k, self.tk, self.area)
            if why:
                if p.reported:
                    self.refinder.remember(p.pid, p.t_last_seen, p.seen_centre)
                p.status = ENDED
            elif p.reported:
                p.status = CONFIRMED if (p.seen[0] or p.seen[1]) else COASTING
        self.persons = [p for p in self.persons if p.status != ENDED]

    def _confirm(self, p: Person) -> None:
        confirmer = self.confirmer
        if not self.look.keeps(p):                  # no longer looks like two legs
            p.status = ENDED
            return
        self._apart(p)
        p.world_centre = (self.seg, *to_world(self.pose, np.array([p.evidence_centre(
            confirmer.evidence)]))[0].tolist())
        moved = confirmer.step(p, self.k)
        looks = self.look.confirms(p, self.w)         # counted on every scan
        if (moved or looks or self.arrived.confirms(p, self.pose, self.tk)) \
                and not _on_static(p, self.pose, self.smap):
            p.status = CONFIRMED
            self.look.confirmed(p)
            self.n_conf += 1
        elif confirmer.failed(p):
            p.status = ENDED

    def _apart(self, p: Person) -> None:
        """Whether a tentative person's two observations on this scan are two separate
        objects (:func:`joined_by_surface`), for a confirmer that asks it."""
        if not getattr(self.confirmer, "separate_legs", False):
            return
        if self.pts is None:
            self.pts = scan_points(self.scans, self.k)
        p.apart = not (p.seen[0] and p.seen[1]) or not joined_by_surface(
            p.z[0], p.z[1], self.pts, self.w)

    def births(self) -> None:
        """Tentative persons from the pairs of observations nobody explains (the
        initialiser's pair, on its scan, a confirmed one)."""
        k, obs, score = self.k, self.obs, self.score[self.k]
        free = [not (self.taken[j] or self.explained[j] or self.static[j])
                for j in range(len(obs))]
        pairs = self.tk_.birth.propose(obs, free, self.w)
        seeded = self.seeded
        if seeded is not None and k == seeded[0]:
            il, ir = seeded[1], seeded[2]
            pairs = [(il, ir)] + [(a, b) for a, b in pairs
                                  if a not in (il, ir) and b not in (il, ir)]
        for a, b in pairs:
            start = CONFIRMED if (seeded is not None and k == seeded[0]
                                  and (a, b) == (seeded[1], seeded[2])) else TENTATIVE
            if start == TENTATIVE and not self.look.admits(score[a], score[b]):
                continue
            if not self.area.contains(0.5 * (obs[a][0] + obs[b][0]),
                                      0.5 * (obs[a][1] + obs[b][1])):
                continue
            self._born(a, b, start)

    def _born(self, a: int, b: int, start: str) -> None:
        k, obs, score, tr = self.k, self.obs, self.score[self.k], self.tk_
        p = Person(self.next_id, self.F, obs[a], obs[b], self.pats[k][a], self.pats[k][b],
                   a, b, k, self.tk, [tr.motion.new_window(), tr.motion.new_window()],
                   self.confirmer.new_memory(), status=start, scores=(score[a], score[b]),
                   look=self.look.start(score[a], score[b]))
        if start == CONFIRMED:
            self.look.confirmed(p)
        self.next_id += 1
        self.n_born += 1
        self.n_conf += start == CONFIRMED
        if start == TENTATIVE:
            self._apart(p)
            p.world_centre = (self.seg, *to_world(self.pose,
                                                  np.array([p.centre()]))[0].tolist())
            self.confirmer.step(p, k)
            self.look.confirms(p, self.w)            # the birth scan counts
        self.persons.append(p)

    def refind(self) -> None:
        """A recently ended person found again keeps its confirmation and its id; so does
        a coasting person found where it was last seen, its prediction elsewhere."""
        tentative = [p for p in self.persons if p.status == TENTATIVE]
        found = self.refinder.match(tentative, self.tk)
        refound = {id(p) for p, _ in found}
        taken_over = self.refinder.take_over(
            [p for p in tentative if id(p) not in refound],
            [p for p in self.persons if p.status == COASTING], self.tk)
        for p, q in taken_over:
            q.status = ENDED
            found.append((p, q.pid))
        for p, pid in found:
            p.status = CONFIRMED
            self.look.confirmed(p)
            p.pid = pid
            self.n_refound += 1
        if taken_over:
            self.persons = [p for p in self.persons if p.status != ENDED]

    def record(self) -> None:
        k, tk = self.k, self.tk
        for p in self.persons:
            if p.reported:
                for f in (0, 1):
                    s = p.post[f]
                    self.rows.append((k, tk, p.pid, p.status, "LR"[f], s[0], s[1], s[2],
                                      s[3], p.seen[f], p.pattern[f], p.phase))
