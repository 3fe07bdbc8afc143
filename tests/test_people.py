"""The people tracker (issue 36): life-cycle roles, several persons, real recordings."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gaitval.methods import METHODS, build_method, track_trial
from gaitval.track import TRACK_COLUMNS
from gaitval.track.lifecycle import (AREAS, BIRTHS, CONFIRMERS, DELETERS, REFINDS,
                                     FieldOfView, UnexplainedPairs, leg_tracker_person_gate)
from gaitval.track.people import PEOPLE_COLUMNS, PeopleTracker, people_frame_for_scoring
from gaitval.types import ScanSeries

DT = 0.1                                     # 10 Hz, like the leg_tracker benchmark bags


def _scans(n, range_max=8.0):
    """A ScanSeries frame for synthetic observations: 181 beams over −90°…+90°."""
    return ScanSeries(t=np.arange(n) * DT, ranges=np.full((n, 181), np.nan),
                      angle_min=-math.pi / 2, angle_increment=math.pi / 180,
                      range_min=0.02, range_max=range_max)


def _walker(c0, v, t, stride_s=1.1, step_m=0.5, half_width_m=0.1, phase=0.0):
    """Two legs of a person whose body centre moves from c0 at velocity v: along the walking
    direction the legs swing past each other (r = ±step_m), 2·half_width_m apart sideways."""
    c0, v = np.asarray(c0, float), np.asarray(v, float)
    u = v / np.linalg.norm(v)
    nrm = np.array([-u[1], u[0]])
    c = c0 + t[:, None] * v
    s = 0.5 * step_m * np.sin(2 * np.pi * t / stride_s + phase)
    left = c + s[:, None] * u + half_width_m * nrm
    right = c - s[:, None] * u - half_width_m * nrm
    return c, left, right


def _observations(legs_per_scan, rng, sd=0.01):
    xy = [np.array(p, float).reshape(-1, 2) + rng.normal(0, sd, (len(p), 2))
          for p in legs_per_scan]
    return xy, [["SL"] * len(o) for o in xy]


def _tracker(**kw):
    kind = dict(METHODS["people"]["kind"])
    kind.pop("name")
    kind["detector"] = {"name": "leg_patterns"}
    kind.update(kw)
    return PeopleTracker(**kind)


def _owner(people, centres):
    """Per reported (scan, person): index of the true person nearest its legs' midpoint."""
    mid = people.groupby(["k", "person_id"])[["x_m", "y_m"]].mean().reset_index()
    k = mid["k"].to_numpy()
    d = np.stack([np.hypot(mid["x_m"] - c[k, 0], mid["y_m"] - c[k, 1]) for c in centres])
    mid["owner"] = d.argmin(axis=0)
    mid["d_m"] = d.min(axis=0)
    return mid


def test_role_registries_hold_the_life_cycle_parts():
    assert "unexplained_pairs" in BIRTHS and "m_of_n_moving" in CONFIRMERS
    assert "unsupported_time" in DELETERS and {"field_of_view", "rectangle"} <= set(AREAS.names())
    assert {"leg_tracker_gate", "none"} <= set(REFINDS.names())


def test_births_pair_the_closest_unexplained_observations():
    obs = [(1.0, 0.0), (1.0, 0.3), (3.0, 0.0), (1.2, 0.15), (5.0, 5.0)]
    free = [True, True, True, False, True]
    # 0–1 are 0.3 m apart; 2 and 4 have nobody within 0.8 m; 3 is explained
    assert UnexplainedPairs().propose(obs, free, 0.10) == [(0, 1)]
    # two legs cannot overlap: 0.05 m < 0.7 w_l
    assert UnexplainedPairs().propose([(1, 0), (1, 0.05)], [True, True], 0.10) == []


def test_field_of_view_area():
    a = FieldOfView(margin_m=0.25).bind(_scans(2, range_max=5.0))
    assert a.contains(2.0, 0.0)
    assert not a.contains(4.9, 0.0)                 # within the margin of the range limit
    assert not a.contains(-1.0, 0.0)                # behind the laser (−90°…+90°)


def test_two_people_crossing_keep_their_identities():
    """Two walkers cross on an X (B 0.9 m behind A where their paths cross): both are
    confirmed, each person id stays on one walker, and each walker keeps one id."""
    n = 90
    t = np.arange(n) * DT
    ca, la, ra = _walker((1.5, -2.0), (0.25, 1.0), t)
    cb, lb, rb = _walker((3.8, -2.9), (-0.25, 1.0), t, phase=1.3)
    rng = np.random.default_rng(0)
    xy, pats = _observations([np.vstack([la[k], ra[k], lb[k], rb[k]]) for k in range(n)],
                             rng)
    res = _tracker().run(_scans(n), xy, pats, 0.10)
    assert res.n_confirmed == 2
    own = _owner(res.people, [ca, cb])
    assert (own["d_m"] < 0.15).all()
    assert own.groupby("person_id")["owner"].nunique().max() == 1    # an id stays on one walker
    assert sorted(own.groupby("owner")["person_id"].nunique().tolist()) == [1, 1]
    # the walkers' closest approach is in the run and both are reported through it
    k_cross = int(np.argmin(np.hypot(*(ca - cb).T)))
    assert set(own.loc[own["k"] == k_cross, "owner"]) == {0, 1}
    assert list(res.people.columns) == list(PEOPLE_COLUMNS)


def test_a_person_leaving_the_field_of_view_ends():
    """A walker leaves through the range limit: the track ends when the body centre leaves
    the measurement area; nothing is reported after that."""
    n = 80
    t = np.arange(n) * DT
    c, left, right = _walker((1.0, 0.0), (1.0, 0.0), t)
    rng = np.random.default_rng(1)
    rmax = 5.0
    legs = [np.array([p for p in (left[k], right[k]) if np.hypot(*p) < rmax])
            for k in range(n)]
    xy, pats = _observations(legs, rng)
    res = _tracker().run(_scans(n, range_max=rmax), xy, pats, 0.10)
    assert res.n_confirmed == 1
    last = int(res.people["k"].max())
    k_out = int(np.argmax(np.hypot(*c.T) > rmax - 0.25))
    assert last < k_out                                  # ended on leaving, not coasted on
    assert res.people["person_id"].nunique() == 1


def test_a_person_who_is_no_longer_seen_ends_after_the_stated_time():
    n = 100
    t = np.arange(n) * DT
    c, left, right = _walker((1.5, -1.5), (0.0, 1.0), t)
    k_gone = 40
    legs = [np.vstack([left[k], right[k]]) if k < k_gone else np.zeros((0, 2))
            for k in range(n)]
    xy, pats = _observations(legs, np.random.default_rng(2))
    # the scans hold no return: ended 0.5 s after the last observation (the deleter's
    # max_no_return_s: nothing in its gate) ...
    for limit, deleter in ((0.5, "unsupported_time"),
                           # ... and 3.0 s after it without that rule (max_unsupported_s)
                           (3.0, {"name": "unsupported_time", "max_no_return_s": None})):
        res = _tracker(deleter=deleter).run(_scans(n), xy, pats, 0.10)
        assert res.n_confirmed == 1
        p = res.people
        assert set(p.loc[p["k"] >= k_gone, "status"]) == {"coasting"}
        t_last = p["t_sensor_s"].max()
        assert t_last - t[k_gone - 1] == pytest.approx(limit, abs=DT + 1e-9)


def test_a_slow_walker_is_confirmed():
    """0.5 m/s: a newborn leg's gate assumes seed 001's swing speed until it is seen twice."""
    n = 100
    t = np.arange(n) * DT
    _, left, right = _walker((1.5, -1.0), (0.0, 0.5), t)
    xy, pats = _observations([np.vstack([left[k], right[k]]) for k in range(n)],
                             np.random.default_rng(2))
    assert _tracker().run(_scans(n), xy, pats, 0.10).n_confirmed == 1


def test_static_leg_pairs_are_never_confirmed():
    """Chair legs (static pairs, flickering detections) stay tentative: no person."""
    rng = np.random.default_rng(3)
    pairs = np.array([[1.5, 0.3], [1.5, -0.1], [2.2, 0.8], [2.6, 0.8], [3.0, -1.0],
                      [3.4, -1.0]])
    legs = [pairs[rng.random(len(pairs)) > 0.2] for _ in range(200)]
    xy, pats = _observations(legs, rng)
    res = _tracker().run(_scans(200), xy, pats, 0.10)
    assert res.n_confirmed == 0 and res.people.empty and res.k_init == -1


def test_people_method_keeps_the_study_track_contract():
    """Every study reads the subject's two legs in the usual table (TRACK_COLUMNS)."""
    from gaitval.track.kinds import TRACKER_KINDS
    assert "people" in TRACKER_KINDS
    n = 60
    t = np.arange(n) * DT
    _, left, right = _walker((1.5, -1.5), (0.0, 1.0), t)
    xy, pats = _observations([np.vstack([left[k], right[k]]) for k in range(n)],
                             np.random.default_rng(4))
    res = _tracker().run(_scans(n), xy, pats, 0.10)
    df = res.to_frame()
    assert list(df.columns) == list(TRACK_COLUMNS) and len(df) == 2 * n
    assert res.subject_id == int(res.people["person_id"].iloc[0])
    scored = people_frame_for_scoring(res)
    assert sorted(scored["k"].unique()) == list(range(n))      # every scan keeps its time
    assert (scored.loc[scored["person_id"] < 0, "x_m"].isna()).all()


def test_people_tracker_is_deterministic():
    n = 60
    t = np.arange(n) * DT
    _, left, right = _walker((1.5, -1.5), (0.0, 1.0), t)
    xy, pats = _observations([np.vstack([left[k], right[k]]) for k in range(n)],
                             np.random.default_rng(5))
    a = _tracker().run(_scans(n), xy, pats, 0.10).people
    b = _tracker().run(_scans(n), xy, pats, 0.10).people
    assert a.equals(b)


# -- real recordings ------------------------------------------------------------------------
@pytest.mark.realdata
def test_a_walker_in_positive_1_is_found(realdata):
    from gaitval.io.rosbag import read_rosbag_scans
    scans = read_rosbag_scans(realdata / "lrs" / "positive_1.bag")
    res = build_method("people").track(scans, 0.10)
    p = res.people
    assert res.n_confirmed >= 1
    # the subject is reported for more than 10 s of the 53 s recording
    sub = p[p["person_id"] == res.subject_id]
    assert sub["k"].nunique() * float(np.median(np.diff(scans.t))) > 10.0
    assert len(track_trial(scans, "people", 0.10)) == 2 * scans.n_scans


@pytest.mark.realdata
@pytest.mark.slow
def test_empty_room_gives_no_track_for_any_method(realdata):
    """negative_2: a robot driving through a furnished room with nobody in it, three lasers
    with ~36 leg-like detections a scan.  Every method — the papers' (TUG, MTST, rollator KF
    and PF) and the people tracker, online and offline — reports no track on any scan of
    any of them; the people tracker confirms no person, and the offline one reports none
    (its backward pass alone confirms furniture on two lasers, joined to nobody:
    benchmarks/people_gate.py, v16)."""
    from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
    bag = realdata / "lrs" / "negative_2.bag"
    if not bag.exists():
        pytest.skip(f"{bag} is absent")
    topics = list(describe_rosbag(bag)["scans"])
    assert len(topics) == 3, topics
    tracked = {}
    for topic in topics:
        scans = read_rosbag_scans(bag, topic)
        for method in METHODS:
            res = build_method(method).track(scans, 0.10)
            scans_with_track = int(np.isfinite(res.x).any(axis=0).sum())
            tracked[(topic, method)] = scans_with_track
            if method == "people":
                tracked[(topic, "people confirmed")] = res.n_confirmed
                tracked[(topic, "people re-found")] = res.n_refound
            if method == "people_offline":        # persons it reports (both passes joined)
                tracked[(topic, "people_offline persons")] = res.people["person_id"].nunique()
    assert len(tracked) == len(topics) * (len(METHODS) + 3)
    assert not any(tracked.values()), {k: v for k, v in tracked.items() if v}


def test_leg_tracker_person_gate_follows_its_filter():
    """The re-finding gate is leg_tracker's person gate: 1.645·√(P_xx + 0.5²) with its
    constant-velocity filter; it grows while the person is unobserved and ends on the scan
    leg_tracker deletes the person (P_xx + 0.25 > 0.9²: 30 scans at 10 Hz, the deleter's
    3.0 s; 20 at 7.5 Hz)."""
    g10 = leg_tracker_person_gate(0.1)
    assert len(g10) == 30 and len(leg_tracker_person_gate(1 / 7.5)) == 20
    assert np.all(np.diff(g10) > 0)
    assert 1.645 * 0.5 < g10[0] < 0.85                  # observed: P_xx small against 0.25
    assert g10[-1] <= 1.645 * 0.9 + 1e-9                 # never beyond the deletion bound


#: the re-finding scenarios need a prediction that runs on at the last velocity (the
#: constant-velocity model); the people method's gait input (v13) decelerates it
CV = {"name": "constant_velocity"}


def _stop_at_the_edge(k_stop=22, k_back=25, n=80, moved_m=(0.0, 0.0)):
    """A walker (1 m/s along x) stops at x = 2.6 m, 0.25 m inside the area's edge, unseen
    for k_back − k_stop scans; its coasting prediction carries it out of the area (the
    track ends), then its legs are seen again, standing (shifted by ``moved_m``)."""
    t = np.arange(n) * DT
    c, left, right = _walker((0.5, 0.0), (1.0, 0.0), t)
    stand = np.vstack([left[k_stop - 1], right[k_stop - 1]]) + np.asarray(moved_m)
    legs = [np.vstack([left[k], right[k]]) if k < k_stop else
            (np.zeros((0, 2)) if k < k_back else stand) for k in range(n)]
    xy, pats = _observations(legs, np.random.default_rng(7))
    area = {"name": "rectangle", "x_m": [0.0, float(c[k_stop - 1][0]) + 0.25],
            "y_m": [-2.0, 2.0]}
    return xy, pats, area, n


def test_a_person_whose_track_ended_is_found_again_and_kept_while_standing():
    """Re-finding (lifecycle.LegTrackerGate): the walker's track ends while it is unseen
    (its prediction leaves the area); when its legs are seen again where it stopped, the
    new hypothesis is that person — confirmed at once, with the same id — and it stays
    confirmed while it stands (support = observations).  Without re-finding the standing
    person is never confirmed again."""
    xy, pats, area, n = _stop_at_the_edge()
    res = _tracker(area=area, motion=CV).run(_scans(n), xy, pats, 0.10)
    p = res.people
    assert res.n_confirmed == 1 and res.n_refound == 1
    assert p["person_id"].nunique() == 1                     # the same id throughout
    assert p["k"].max() == n - 1 and p.loc[p["k"] >= 25, "k"].nunique() == n - 25
    assert set(p.loc[p["k"] >= 25, "status"]) == {"confirmed"}
    alone = _tracker(area=area, refind="none", motion=CV).run(_scans(n), xy, pats, 0.10)
    assert alone.n_confirmed == 1 and alone.n_refound == 0
    assert alone.people["k"].max() < 25                      # ended, and never again
    # the people method's own motion (seed 000's gait input once confirmed, v13) stops the
    # legs of the walker that stopped: its track never leaves the area, so the person
    # coasts and keeps its id, with nothing to re-find (the walker confirmed at k 20, its
    # legs associated leg by leg)
    own = _tracker(area=area, pair_swing_mps=None).run(_scans(n), xy, pats, 0.10)
    assert own.n_confirmed == 1 and own.n_refound == 0
    assert own.people["person_id"].nunique() == 1 and own.people["k"].max() == n - 1
    assert set(own.people.loc[own.people["k"] >= 25, "status"]) == {"confirmed"}
    # with the pair rule (the method's) it is confirmed 7 scans earlier, with a gait state
    # that carries its prediction out of the area while unseen: it ends and is re-found,
    # with its id, where it stands
    pair = _tracker(area=area).run(_scans(n), xy, pats, 0.10)
    assert pair.people["k"].min() < own.people["k"].min()
    assert pair.n_confirmed == 1 and pair.n_refound == 1
    assert pair.people["person_id"].nunique() == 1 and pair.people["k"].max() == n - 1
    assert set(pair.people.loc[pair.people["k"] >= 25, "status"]) == {"confirmed"}


def test_a_hypothesis_beyond_the_gate_or_too_late_is_not_the_ended_person():
    """2 m from where the person was last seen (beyond leg_tracker's largest person gate,
    1.645 · 0.9 = 1.48 m, reached just before it would delete the person), or after
    leg_tracker's deletion time (3.0 s at 10 Hz), a standing pair is not re-found.  (A
    pair 1.5 m away is, once the gate has grown to 1.5 m, as leg_tracker's coasting
    person would take it.)"""
    xy, pats, area, n = _stop_at_the_edge(moved_m=(-2.0, 0.0))
    far = _tracker(area=area, motion=CV).run(_scans(n), xy, pats, 0.10)
    assert far.n_refound == 0 and far.people["k"].max() < 25
    xy, pats, area, n = _stop_at_the_edge(k_back=22 + 32)
    late = _tracker(area=area, motion=CV).run(_scans(n), xy, pats, 0.10)
    assert late.n_refound == 0 and late.people["k"].max() < 22 + 32


def test_an_initialiser_seeds_a_confirmed_person():
    """legbench's ``--init annotation``: the pair the initialiser finds is a person from its
    scan on, even one who stands (which the confirmer alone would never confirm)."""
    n = 30
    legs = [np.array([[2.0, 0.15], [2.0, -0.15]]) for _ in range(n)]
    xy, pats = _observations(legs, np.random.default_rng(6))
    alone = _tracker().run(_scans(n), xy, pats, 0.10)
    assert alone.n_confirmed == 0
    seeded = _tracker(init={"name": "annotated_pair", "k": 5, "x_m": 2.0, "y_m": 0.0}).run(
        _scans(n), xy, pats, 0.10)
    assert seeded.n_confirmed == 1 and seeded.k_init == 5
    assert seeded.people["k"].min() == 5 and seeded.people["k"].max() == n - 1


# -- issue 36 (standing people): the static map, leg_tracker's leg-travel rule, the entry --
def test_the_people_method_names_its_refind_role():
    """METHODS["people"] states the re-finding role and its values (leg_tracker's), instead
    of leaving them to the constructor's default."""
    kind = METHODS["people"]["kind"]
    assert kind["refind"] == {"name": "leg_tracker_gate", "max_std_m": 0.9, "percentile": 0.90,
                              "std_obs_m": 0.1, "assoc_extra_m": 0.4, "coasting": True}
    assert type(build_method("people").refind).__name__ == "LegTrackerGate"


def _ranges_with(points, n_beams=181, wall_m=4.0):
    """One scan's ranges (181 beams over −90°…+90°): a wall at ``wall_m`` on every beam, and
    each point in ``points`` (sensor frame) on the beam nearest its bearing."""
    r = np.full(n_beams, wall_m)
    for x, y in points:
        i = int(round(math.degrees(math.atan2(y, x)))) + 90
        r[i] = min(r[i], math.hypot(x, y))
    return r


class _RecordingMap:
    """A static map that learns nothing and records every point it is given."""

    def __init__(self):
        self.points = []

    def start(self, scans, poses):
        return self

    def update(self, k, pts):
        self.points.append((k, np.asarray(pts, float)))

    def is_static(self, x, y):
        return False


def test_a_reported_persons_legs_are_not_learned_by_the_static_map():
    """leg_tracker's local map learns only the clusters no person was matched to: a walker
    who stops and stands must not become background.  Once the walker is confirmed, the
    returns on its legs (within 0.13 m of its assigned observations) are not given to the
    static map; the wall's returns are."""
    n = 80
    t = np.arange(n) * DT
    _, left, right = _walker((1.0, -1.5), (0.0, 1.0), t)
    k_stop = 40
    for k in range(k_stop, n):                        # stops, and stands
        left[k], right[k] = left[k_stop], right[k_stop]
    legs = [np.vstack([left[k], right[k]]) for k in range(n)]
    xy, pats = _observations(legs, np.random.default_rng(8), sd=0.005)
    scans = _scans(n)
    scans = ScanSeries(t=scans.t, ranges=np.stack([_ranges_with(p) for p in legs]),
                       angle_min=scans.angle_min, angle_increment=scans.angle_increment,
                       range_min=scans.range_min, range_max=scans.range_max)
    rec = _RecordingMap()
    res = _tracker(static_map=rec).run(scans, xy, pats, 0.10)
    assert res.n_confirmed == 1
    p = res.people
    k_conf = int(p["k"].min())
    assert k_conf < k_stop
    on_legs = []
    for k, pts in rec.points:
        d = np.hypot(pts[:, None, 0] - legs[k][None, :, 0],
                     pts[:, None, 1] - legs[k][None, :, 1]).min(axis=1)
        on_legs.append(int((d < 0.05).sum()))
        assert (np.hypot(*pts.T) > 3.9).sum() >= 170           # the wall is learned
    assert all(c > 0 for c in on_legs[:k_conf])                 # before: legs learned too
    assert not any(on_legs[k_conf + 1:])                        # confirmed: never again


def test_leg_tracker_person_gate_equals_the_four_state_filter():
    """The gate's per-axis scalar recursion is leg_tracker's 4-state constant-velocity
    filter (F, Q = (0.5·Δt)² I, H = [I 0], R = 0.1² I, P₀ = 0.5 I) written out: the same
    gates as the 4 × 4 matrix form, iterated the same way, to 1e-12 m."""
    for dt in (0.025, 0.1, 1 / 7.5):
        F = np.array([[1.0, 0, dt, 0], [0, 1.0, 0, dt], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])
        Q, H, R = (0.5 * dt) ** 2 * np.eye(4), np.eye(2, 4), 0.01 * np.eye(2)
        P = 0.5 * np.eye(4)
        for _ in range(1000):
            P = F @ P @ F.T + Q
            K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
            P = (np.eye(4) - K @ H) @ P
        want = [1.6448536269514722 * np.sqrt(P[0, 0] + 0.25)]
        while True:
            P = F @ P @ F.T + Q
            if P[0, 0] + 0.25 > 0.81:
                break
            want.append(1.6448536269514722 * np.sqrt(P[0, 0] + 0.25))
        got = leg_tracker_person_gate(dt)
        assert len(got) == len(want)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


@pytest.mark.realdata
@pytest.mark.slow
def test_leg_classifier_in_the_empty_room_each_laser_held_out(realdata):
    """leg_tracker's classifier (``kind__appearance: leg_forest``), each laser of
    negative_2 scored by the forest that did not see it (leave-one-topic-out,
    gaitval/track/legforest.py): with the people method's own confirmer nobody is
    confirmed and births fall to under a tenth."""
    from gaitval.io.rosbag import read_rosbag_scans
    bag = realdata / "lrs" / "negative_2.bag"
    if not bag.exists():
        pytest.skip(f"{bag} is absent")
    for topic in ("/left_scan", "/rear_scan", "/right_scan"):
        scans = read_rosbag_scans(bag, topic)
        look = {"kind__appearance": {"name": "leg_forest", "forest": "without_" + topic[1:]}}
        plain = build_method("people").track(scans, 0.10)
        res = build_method("people", look).track(scans, 0.10)
        assert res.n_confirmed == 0 and res.n_refound == 0, topic
        assert not np.isfinite(res.x).any(), topic
        assert res.n_born < plain.n_born / 10, (topic, res.n_born, plain.n_born)


# -- the protocol tables: a laser that stands still -----------------------------------------
def test_the_papers_standing_laser_gives_the_people_tracker_no_scan_matching():
    """TUG and MTST (seed 000, seed 001) put the LRS on a stand: their track steps give the
    ``people`` kind ``ego_motion: none`` (issue 38), every other method nothing, and a
    config-defined method of kind ``people`` the same as the built-in one."""
    from gaitval.pipeline.steps.tracking import fixed_sensor_overrides

    assert fixed_sensor_overrides("people") == {"kind__ego_motion": "none"}
    own = {**METHODS["people"], "label": "my people tracker"}
    assert fixed_sensor_overrides(own) == {"kind__ego_motion": "none"}
    for paper_method in ("tug_m1", "mtst_proposed", "rollator_kf", "rollator_pf"):
        assert fixed_sensor_overrides(paper_method) == {}


def test_scan_matching_on_a_standing_laser_finds_motion_that_is_not_there(tiny_simulated):
    """Why the standing laser gets no scan matching: on a TUG trial, whose laser stands
    still, scan-to-scan ICP against a scene with a walking person in it drifts by
    centimetres (the default study's tug_Y01_t1: 7 cm, 0.9°), while the standing-sensor
    role reports the truth, no motion at all."""
    from gaitval.io.scanlog import read_scanlog
    from gaitval.track.staticmap import EGO_MOTIONS

    scans = read_scanlog(tiny_simulated / "lrs" / "tug_Y01_t1.scan.parquet",
                         trial="tug_Y01_t1")
    icp = EGO_MOTIONS.build(METHODS["people"]["kind"]["ego_motion"])
    poses, _ = icp.poses(scans)
    drift = np.hypot(poses[:, 0], poses[:, 1]).max()
    assert drift > 0.01                                       # metres of a laser that stood
    still, segment = EGO_MOTIONS.build("none").poses(scans)
    assert not still.any() and not segment.any()


def _pole_scans(n, step_m, rad=0.07):
    """A sensor moving ``step_m`` per 0.1 s scan along x past sixteen poles (sparse: 30–33
    returns of 181 beams, as outdoors where most beams return nothing)."""
    poles = [(2.0 + 0.3 * i, (-1) ** i * (0.3 + 0.2 * i)) for i in range(16)]
    ang = -math.pi / 2 + math.pi / 180 * np.arange(181)
    ranges = np.full((n, 181), np.nan)
    for k in range(n):
        for i, a in enumerate(ang):
            ux, uy = math.cos(a), math.sin(a)
            for px, py in poles:                  # ray-circle intersection, nearest pole
                cx, cy = px - k * step_m, py
                b = ux * cx + uy * cy
                disc = b * b - (cx * cx + cy * cy - rad * rad)
                if disc >= 0 and b > 0:
                    r = b - math.sqrt(disc)
                    if not ranges[k, i] <= r:
                        ranges[k, i] = r
    return ScanSeries(t=np.arange(n) * DT, ranges=ranges, angle_min=-math.pi / 2,
                      angle_increment=math.pi / 180, range_min=0.02, range_max=8.0)


def test_scan_matching_uses_every_beam_before_it_calls_the_motion_unknown():
    """A sparse scan (outdoors most beams return nothing): sixteen poles, 30–33 returns of
    181 beams.  On every 2nd beam ICP has fewer than its 20 pairs, and the old role called
    every step's motion unknown (a new world frame each scan).  It now retries the step
    with every beam and follows the sensor's 3 cm per scan in one frame
    (benchmarks/scan_matching_fallback.py: on the outdoor bag 4,227 frames become 598, and
    1,865 once implausible steps are unknown too)."""
    from gaitval.track.staticmap import EGO_MOTIONS

    n, step_m = 20, 0.03
    scans = _pole_scans(n, step_m)
    ranges = scans.ranges
    every = np.isfinite(ranges).sum(axis=1)
    assert (every >= 30).all() and (np.isfinite(ranges[:, ::2]).sum(axis=1) < 20).all()
    spec = METHODS["people"]["kind"]["ego_motion"]
    assert spec["beam_step"] == 2 and spec["min_pairs"] == 20
    _, seg_old = EGO_MOTIONS.build({**spec, "fallback_every_beam": False}).poses(scans)
    assert seg_old.max() + 1 == n                             # every step unknown
    poses, seg = EGO_MOTIONS.build(spec).poses(scans)
    assert seg.max() == 0
    # each 3 cm step within 5 mm (point-to-point ICP on poles sampled at other places of
    # their surface each scan), no sideways motion or turn to speak of
    assert np.allclose(np.diff(poses[:, 0]), step_m, atol=0.005)
    assert np.allclose(poses[:, 1], 0.0, atol=0.02)
    assert np.allclose(poses[:, 2], 0.0, atol=0.01)


def test_scan_matching_calls_a_step_faster_than_the_sensor_moves_unknown():
    """A step that moves the sensor faster than 2 m/s or turns it faster than 1.5 rad/s (the
    motion the role's 0.5 m pairing distance assumes) is not the sensor's motion — outdoors
    ICP aligns the followed person, half the returns — and starts a new world frame.  The
    same poles passed at 3 m/s (0.3 m a scan, which ICP itself can follow) give a frame per
    scan; without the bounds, one frame."""
    from gaitval.track.staticmap import EGO_MOTIONS

    n = 10
    scans = _pole_scans(n, 0.3)
    spec = METHODS["people"]["kind"]["ego_motion"]
    assert (spec["max_speed_mps"], spec["max_turn_rps"]) == (2.0, 1.5)
    free, seg_free = EGO_MOTIONS.build({**spec, "max_speed_mps": None,
                                        "max_turn_rps": None}).poses(scans)
    assert seg_free.max() == 0 and abs(free[-1, 0] - 0.3 * (n - 1)) < 0.3
    _, seg = EGO_MOTIONS.build(spec).poses(scans)
    assert seg.max() + 1 == n
    # at 1.5 m/s the bound lets the steps through
    _, seg_slow = EGO_MOTIONS.build(spec).poses(_pole_scans(n, 0.15))
    assert seg_slow.max() == 0


# -- issue 36, v9–v14 (benchmarks/people_gate.py) -------------------------------------------
def test_a_coasting_person_is_taken_over_where_it_was_last_seen():
    """``refind: leg_tracker_gate`` with ``coasting: true`` (the default since v15): a walker
    (1 m/s) stops and is unseen for 0.8 s; its constant-velocity prediction runs on, so
    when its legs are seen again, standing where it stopped, they are outside its gates.
    With the take-over the new hypothesis there is that person at once (same id, confirmed,
    kept while it stands); without it the prediction coasts on to the end and the
    standing person is never confirmed (nothing is re-found: the person ends 3 s later,
    at leg_tracker's deletion time)."""
    n, k_stop, gap = 80, 22, 8
    t = np.arange(n) * DT
    _, left, right = _walker((0.5, 0.0), (1.0, 0.0), t)
    stand = np.vstack([left[k_stop - 1], right[k_stop - 1]])
    legs = [np.vstack([left[k], right[k]]) if k < k_stop else
            (np.zeros((0, 2)) if k < k_stop + gap else stand) for k in range(n)]
    xy, pats = _observations(legs, np.random.default_rng(7))
    area = {"name": "rectangle", "x_m": [0.0, 8.0], "y_m": [-2.0, 2.0]}
    refind = {**METHODS["people"]["kind"]["refind"], "coasting": False}
    # (the prediction coasts on only without the deleter's no-return rule: these scans
    # hold no return, so with it the person ends 0.5 s into the gap and is re-found)
    keep = {"name": "unsupported_time", "max_no_return_s": None}
    # (legs associated leg by leg: with the pair rule the walker is confirmed at k 13, not
    # 20, and the coasting person's grown χ² gate takes the standing legs back itself at
    # k 30, 0.7 m behind its prediction: no take-over is needed to test)
    leg_by_leg = {"pair_swing_mps": None}
    off = _tracker(area=area, refind=refind, motion=CV, deleter=keep, **leg_by_leg).run(
        _scans(n), xy, pats, 0.10)
    assert off.n_refound == 0 and off.people["k"].max() < n - 1
    last = off.people[off.people["k"] == off.people["k"].max()]
    assert (last["x_m"] > stand[:, 0].max() + 2.0).all()       # coasted far past the person
    on = _tracker(area=area, refind={**refind, "coasting": True}, motion=CV,
                  **leg_by_leg).run(_scans(n), xy, pats, 0.10)
    p = on.people
    assert on.n_confirmed == 1 and on.n_refound == 1
    assert p["person_id"].nunique() == 1 and p["k"].max() == n - 1
    after = p[p["k"] >= k_stop + gap]
    assert set(after["status"]) == {"confirmed"}
    assert np.hypot(after["x_m"].to_numpy()[:, None] - stand[:, 0],
                    after["y_m"].to_numpy()[:, None] - stand[:, 1]).min(axis=1).max() < 0.05


def test_the_confirmer_reads_the_observations_not_the_filtered_legs():
    """``m_of_n_moving`` with ``evidence: observations`` (the people method's, v12) tests
    the observations assigned to the legs: filtered legs that swing past each other over
    observations of a still pair confirm nothing, and observations of swinging legs
    confirm whatever the estimates say.  ``estimates`` reads the filtered legs.  An
    unknown evidence is refused."""
    from types import SimpleNamespace

    assert METHODS["people"]["kind"]["confirmer"]["evidence"] == "observations"
    n = 20
    t = np.arange(n) * DT
    _, left, right = _walker((2.0, 0.0), (1e-6, 0.0), t, step_m=0.6)   # legs swing, body stays
    still = [(2.0, 0.1), (2.0, -0.1)]

    def confirmed(evidence, pos, z):
        c = CONFIRMERS.build({"name": "m_of_n_moving", "window_s": 1.4, "m_fraction": 0.5,
                              "min_relative_travel_m": 0.5, "pass_leg_widths": 1.0,
                              "min_travel_m": 0.0, "evidence": evidence}).bind(DT, 0.10)
        p = SimpleNamespace(seen=[True, True], confirm_memory=c.new_memory(),
                            world_centre=(0, 2.0, 0.0))
        out = []
        for k in range(n):
            p.z = [tuple(z[k][0]), tuple(z[k][1])]
            p.pos = lambda f, k=k: tuple(pos[k][f])
            out.append(c.step(p, k))
        return any(out)

    swing = [(left[k], right[k]) for k in range(n)]
    stay = [still] * n
    assert confirmed("estimates", swing, stay)
    assert not confirmed("observations", swing, stay)
    assert confirmed("observations", stay, swing)
    assert not confirmed("estimates", stay, swing)
    with pytest.raises(ValueError, match="evidence"):
        CONFIRMERS.build({"name": "m_of_n_moving", "evidence": "priors"})


def test_a_surface_running_through_both_legs_is_not_two_legs():
    """``joined_by_surface``: a wall seen at a grazing angle, broken into leg-sized pieces,
    has returns on the line through two of its pieces, between them and beyond; a
    walker's two legs have the background behind them and nothing on their line, whether
    they are apart or side by side."""
    from gaitval.track.peoplepass import joined_by_surface

    w = 0.10
    rng = np.random.default_rng(0)
    wall = np.column_stack([np.linspace(3.0, 4.0, 40), np.linspace(1.4, 0.8, 40)])
    wall = wall + rng.normal(0.0, 0.01, wall.shape)
    assert joined_by_surface(wall[12], wall[22], wall, w)        # 0.3 m apart on the wall
    assert joined_by_surface(wall[18], wall[22], wall, w)        # close: the wall goes on
    # two legs of 0.05 m radius 0.4 m apart, their returns, and a wall 2 m behind them
    a = np.linspace(-np.pi / 2, np.pi / 2, 15)
    back = np.column_stack([np.full(50, 4.0), np.linspace(-1.0, 1.0, 50)])

    def scan(legs):
        return np.concatenate([c + 0.05 * np.column_stack([-np.cos(a), np.sin(a)])
                               for c in legs] + [back])

    legs = np.array([[2.0, 0.2], [2.0, -0.2]])
    assert not joined_by_surface(legs[0], legs[1], scan(legs), w)
    side = np.array([[2.0, 0.06], [2.0, -0.06]])                 # side by side, touching
    assert not joined_by_surface(side[0], side[1], scan(side), w)
    assert not joined_by_surface(legs[0], legs[1], np.empty((0, 2)), w)


def test_scans_whose_legs_a_surface_joins_do_not_count_towards_confirmation():
    """``separate_legs`` (the people method's): a pair that walks like legs but whose two
    observations a surface joins on every scan (``person.apart`` False, set by the
    tracker) is never confirmed; the same pair apart is, and so it is without the test."""
    from types import SimpleNamespace

    assert METHODS["people"]["kind"]["confirmer"]["separate_legs"] is True
    n = 20
    t = np.arange(n) * DT
    c, left, right = _walker((2.0, -1.0), (0.0, 1.0), t)

    def confirmed(separate, apart):
        conf = CONFIRMERS.build({**METHODS["people"]["kind"]["confirmer"],
                                 "separate_legs": separate}).bind(DT, 0.10)
        p = SimpleNamespace(seen=[True, True], confirm_memory=conf.new_memory(), apart=apart)
        out = []
        for k in range(n):
            p.z = [tuple(left[k]), tuple(right[k])]
            p.world_centre = (0, float(c[k, 0]), float(c[k, 1]))
            out.append(conf.step(p, k))
        return any(out)

    assert confirmed(True, True)
    assert not confirmed(True, False)
    assert confirmed(False, False)


@pytest.mark.realdata
@pytest.mark.slow
def test_empty_room_read_backwards_gives_no_person(realdata):
    """negative_2 with its scans in reverse order (the robot driving backwards through the
    room): neither people method reports anyone on any laser.  Without the surface test
    the online method confirms two persons on /rear_scan and two on /right_scan, pieces
    of walls seen at grazing angles (experiments/people_empty_backwards.py)."""
    from gaitval.track.passes import reversed_scans

    from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
    bag = realdata / "lrs" / "negative_2.bag"
    if not bag.exists():
        pytest.skip(f"{bag} is absent")
    reported = {}
    for topic in describe_rosbag(bag)["scans"]:
        scans = read_rosbag_scans(bag, topic)
        back = reversed_scans(scans)
        for method in ("people", "people_offline"):
            res = build_method(method).track(back, 0.10)
            reported[(topic, method)] = (res.n_confirmed if method == "people"
                                         else res.people["person_id"].nunique())
    assert len(reported) == 6
    assert not any(reported.values()), {k: v for k, v in reported.items() if v}


def test_the_walk_alone_confirms_a_side_stepper_only_when_asked_and_the_world_is_known():
    """``walk_suffices`` (v14, not the default): a person who side-steps 0.6 m in 1.4 s
    with the legs never passing each other fails the gait tests; with ``walk_suffices``
    the steady world-frame walk confirms them, but only while the world frame is known
    (one ego-motion segment over the window)."""
    from types import SimpleNamespace

    assert not METHODS["people"]["kind"]["confirmer"].get("walk_suffices", False)
    n = 20
    cx = 2.0 + 0.05 * np.arange(n)                       # 0.5 m/s along x
    legs = [((x + 0.05, 0.1), (x - 0.05, -0.1)) for x in cx]   # the same leg leads

    def confirmed(walk_suffices, segments):
        c = CONFIRMERS.build({"name": "m_of_n_moving", "window_s": 1.4, "m_fraction": 0.5,
                              "min_relative_travel_m": 0.5, "pass_leg_widths": 1.0,
                              "min_travel_m": 0.5, "evidence": "observations",
                              "walk_suffices": walk_suffices}).bind(DT, 0.10)
        p = SimpleNamespace(seen=[True, True], confirm_memory=c.new_memory())
        out = []
        for k in range(n):
            p.z = [legs[k][0], legs[k][1]]
            p.world_centre = (segments(k), float(cx[k]), 0.0)
            out.append(c.step(p, k))
        return any(out)

    assert not confirmed(False, lambda k: 0)
    assert confirmed(True, lambda k: 0)
    assert not confirmed(True, lambda k: k % 2)          # the world frame keeps breaking


def _stance_swing_walker(c0, v, t, beta=0.6, step_width_m=0.16):
    """Two legs that walk as the crowd scenes' walkers do (docs/crowd.md): each foot stands
    for β of the stride and then swings to its next foothold, S = 2·(0.35 + 0.3·v) m, so
    the swinging leg moves at about 2.5 times the body speed while the other stands."""
    c0, v = np.asarray(c0, float), np.asarray(v, float)
    speed = float(np.hypot(*v))
    u, stride = v / speed, 2.0 * (0.35 + 0.3 * speed)
    nrm = np.array([-u[1], u[0]])
    s = speed * t
    legs = []
    for offset, side in ((0.0, 1.0), (0.5, -1.0)):
        ph = (s / stride + offset) % 1.0
        x = np.clip((ph - beta) / (1.0 - beta), 0.0, 1.0)
        rel = np.where(ph < beta, stride * beta * (0.5 - ph / beta),
                       stride * beta * (-0.5 + x * x * (3.0 - 2.0 * x)))
        legs.append(c0 + (s + rel)[:, None] * u + side * 0.5 * step_width_m * nrm)
    return legs


@pytest.mark.parametrize("speed", [1.0, 1.5])
def test_a_tentative_pair_keeps_its_swinging_leg(speed):
    """A walker whose swinging leg moves 0.25-0.4 m per scan while the other stands: leg by
    leg, the newborn hypothesis loses the swinging leg (seed 001's gate of a leg seen once
    is w_l + Δt·v_sw = 0.22 m) and is never confirmed; with the legs associated as a pair
    (``pair_swing_mps``, the people method's 3.0 m/s) the swinging leg is kept beside the
    standing one and the walker is confirmed."""
    assert METHODS["people"]["kind"]["pair_swing_mps"] == 3.0
    n = 60
    t = np.arange(n) * DT
    left, right = _stance_swing_walker((2.0, -1.5), (0.0, speed), t)
    xy, pats = _observations([np.vstack([left[k], right[k]]) for k in range(n)],
                             np.random.default_rng(5))
    assert _tracker(pair_swing_mps=None).run(_scans(n), xy, pats, 0.11).n_confirmed == 0
    res = _tracker().run(_scans(n), xy, pats, 0.11)
    assert res.n_confirmed == 1
    mid = res.people.groupby("k")[["x_m", "y_m"]].mean()
    k = mid.index.to_numpy()
    centre = 0.5 * (left + right)
    assert np.hypot(mid["x_m"] - centre[k, 0], mid["y_m"] - centre[k, 1]).max() < 0.3


def test_a_pair_that_stood_a_window_does_not_take_a_far_observation_as_a_swing():
    """Two still objects 0.25 m apart, then one of them is not seen for three scans and an
    observation appears 0.8 m from where it was, within the pairing distance of the other:
    a swinging leg could reach it (w_l + 4·Δt·3.0 m/s).  A pair born a few scans earlier
    takes it as its swinging leg; a pair that stood through a whole confirmation window
    (1.4 s) is not mid-walk and does not (outside the pair rule the leg-by-leg gate does
    not take it either)."""
    from gaitval.track.peoplepass import PeoplePass

    a, b, far = (2.28, 0.94), (2.03, 1.01), (1.57, 1.30)

    def takes_far(n_still, **kw):
        legs = [[a, b]] * n_still + [[b]] * 3 + [[far, b]]
        xy, pats = _observations(legs, np.random.default_rng(7), sd=0.005)
        run = PeoplePass(_tracker(ego_motion="none", static_map="none", **kw),
                         _scans(len(xy)), xy, pats, 0.11, None)
        for k in range(run.n):
            run.scan(k)
        (p,) = run.persons
        return p.k_born == 0 and p.seen == [True, True] and \
            math.dist(p.z[0], far) < 0.05
    assert takes_far(4)
    assert not takes_far(4, pair_swing_mps=None)
    assert not takes_far(30)


def test_observations_closer_than_a_leg_width_are_not_two_legs():
    """``min_apart_leg_widths`` (the people method's 1.0): two shanks are solid, so a scan
    whose two observations are closer than one leg width (one object split in two) does
    not count as both legs seen; a walker whose observations are split so on two scans in
    three is not confirmed with the test and is without it."""
    from types import SimpleNamespace

    assert METHODS["people"]["kind"]["confirmer"]["min_apart_leg_widths"] == 1.0
    n = 20
    t = np.arange(n) * DT
    c, left, right = _walker((2.0, -1.0), (0.0, 1.0), t, step_m=0.6)

    def confirmed(apart):
        conf = CONFIRMERS.build({**METHODS["people"]["kind"]["confirmer"],
                                 "min_apart_leg_widths": apart}).bind(DT, 0.10)
        p = SimpleNamespace(seen=[True, True], confirm_memory=conf.new_memory(), apart=True)
        out = []
        for k in range(n):
            split = k % 3 != 0
            p.z = [tuple(left[k]), tuple(left[k] + (0.06, 0.0) if split else right[k])]
            p.world_centre = (0, float(c[k, 0]), float(c[k, 1]))
            out.append(conf.step(p, k))
        return any(out)

    assert not confirmed(1.0)
    assert confirmed(0.0)
