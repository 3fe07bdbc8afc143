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

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval.detect import DETECTORS
from gaitval.detect.base import split_observations
from gaitval.track.appearance import APPEARANCES
from gaitval.track.gate import GATES
from gaitval.track.init import INITIALISERS
from gaitval.track.kalman import FILTERS
from gaitval.track.kinds import TRACKER_KINDS, TrackerKind
from gaitval.track.leg import TrackResult, empty_result, handedness, swap_sides
from gaitval.track.lifecycle import AREAS, BIRTHS, CONFIRMERS, DELETERS, REFINDS
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.passes import PASSES, reverse_rows, reversed_scans
from gaitval.track.observe import ScanProfile
from gaitval.track.peoplepass import PeoplePass
from gaitval.track.phase import PHASE_MODELS
from gaitval.track.staticmap import ARRIVALS, EGO_MOTIONS, STATIC_MAPS
from gaitval.track.tracker import step_durations

#: columns of :attr:`PeopleResult.people` (one row per scan, reported person and leg)
PEOPLE_COLUMNS = ("k", "t_sensor_s", "person_id", "status", "side", "x_m", "y_m", "vx_mps",
                  "vy_mps", "observed", "pattern", "phase")


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
    pair_swing_mps : float or None
        A tentative person's legs associated as a pair (:meth:`~gaitval.track.peoplepass.
        PeoplePass._pair_swing`): beside a leg assigned on the scan, the other leg takes a
        free observation within the pairing distance of it and within w_l + (H + 1)·Δt·
        ``pair_swing_mps`` of its prediction — a swinging leg moves ahead while the other
        stands.  None (default): leg by leg only.
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
                 pair_swing_mps: float | None = None, dt_s: float | None = None,
                 sides: str = "walking_direction"):
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
        self.pair_swing_mps = None if pair_swing_mps is None else float(pair_swing_mps)
        self.birth_min_leg_widths = float(getattr(self.birth, "min_leg_widths", 0.7))
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
        if len(t) == 0:
            return _empty(t)
        watch = [ScanProfile(), ScanProfile()] if profile else [None, None]
        rows, n_born, n_conf, n_refound = self._pass(scans, xy, pats, leg_width_m, watch[0],
                                                     self.init)
        people = _people_frame(rows)
        subject = None
        if self.passes.backward:
            people, subject, more = self._backward(scans, xy, pats, leg_width_m, people,
                                                   n_born, n_conf, watch[1])
            n_born, n_conf, n_refound = n_born + more[0], n_conf + more[1], n_refound + more[2]
        res = self._result(t, people, n_born, n_conf, subject)
        res.n_refound = n_refound
        if profile:
            sec, alive, static = watch[0].arrays()
            if self.passes.backward:                  # both passes summed, per scan
                bsec, balive, _ = watch[1].arrays()
                sec, alive = sec + bsec[::-1], alive + balive[::-1]
            res.scan_seconds, res.scan_hypotheses, res.scan_static = sec, alive, static
        return res

    def _backward(self, scans, xy, pats, leg_width_m, people, n_born, n_conf, observer):
        """The same loop on the scans in reverse order (no initialiser), joined to the
        forward pass's persons: the joined rows, the subject (the forward pass's, with its
        labels) and the backward pass's (born, confirmed, re-found)."""
        t = np.asarray(scans.t, dtype=float)
        rscans = reversed_scans(scans)
        brows, b_born, b_conf, b_refound = self._pass(
            rscans, list(xy)[::-1], list(pats)[::-1], leg_width_m, observer, None)
        back = reverse_rows(_people_frame(brows), t)
        dt0 = (float(step_durations(t, self.dt_s)[0]) if len(t) > 1
               else float(self.dt_s or 0.1))
        ahead = self._result(t, people, n_born, n_conf)
        joined, ids = self.passes.join(people, back, dt0)
        subject = None
        if ahead.subject_id >= 0:
            subject = (ids.get(ahead.subject_id, ahead.subject_id), ahead.swapped_sides)
        return joined, subject, (b_born, b_conf, b_refound)

    def _pass(self, scans, xy, pats, leg_width_m: float, observer, init):
        """One pass of the loop over the scans in their order (:class:`~gaitval.track.
        peoplepass.PeoplePass`): the reported rows and the hypotheses born / confirmed /
        re-found.  ``observer``: told before and after each scan (or None)."""
        run = PeoplePass(self, scans, xy, pats, leg_width_m, init)
        for k in range(run.n):
            if observer is not None:
                observer.before(k)
            run.scan(k)
            if observer is not None:
                observer.after(k, run)
        return run.rows, run.n_born, run.n_conf, run.n_refound

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
