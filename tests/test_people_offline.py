"""The offline people tracker: forward and backward passes joined (issue 36, v16-v19;
gaitval/track/passes.py, benchmarks/people_gate.py)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.methods import METHODS, reads_later_scans
from gaitval.track.lifecycle import leg_tracker_person_gate
from gaitval.track.passes import PASSES, join_passes, reverse_rows
from gaitval.track.people import PEOPLE_COLUMNS

from test_people import DT, _observations, _scans, _tracker, _walker

OFFLINE = METHODS["people_offline"]["kind"]["passes"]


def _rows(pid, ks, left, right):
    """Reported rows of one person: ``left``/``right`` give (x, y) per scan k."""
    out = []
    for k in ks:
        for side, f in (("L", left), ("R", right)):
            x, y = f(k)
            out.append((k, k * DT, pid, "confirmed", side, x, y, 0.0, 0.0, True, "SL", 0))
    return pd.DataFrame.from_records(out, columns=list(PEOPLE_COLUMNS)).astype(
        {"k": np.int64, "person_id": np.int64, "phase": np.int64, "observed": bool})


def _side_at(df, pid, k, side):
    r = df[(df["person_id"] == pid) & (df["k"] == k) & (df["side"] == side)]
    return float(r["y_m"].iloc[0])


def test_the_offline_method_is_the_people_method_read_both_ways():
    assert OFFLINE["name"] == "forward_backward" and OFFLINE["extend_only"]
    assert "passes" not in METHODS["people"]["kind"]           # people stays online
    assert reads_later_scans(METHODS["people_offline"])
    assert not reads_later_scans(METHODS["people"]) and not reads_later_scans(METHODS["tug_m1"])
    assert set(PASSES.names()) >= {"forward", "forward_backward"}
    # the link gate is leg_tracker's person gate with no unobserved scan (0.83 m at 10 Hz)
    gate = PASSES.build(OFFLINE).link_gate(0.1)
    assert gate == leg_tracker_person_gate(0.1)[0] and abs(gate - 0.83) < 0.005


def test_a_person_who_stands_before_walking_is_reported_from_the_first_scan_offline():
    """Online, a person is confirmed only once it walks; read backwards, the same person
    walks first and stands afterwards, and a confirmed person stays confirmed while it is
    observed.  Where the online method reports, the offline one reports the same legs."""
    n_stand, n_walk = 40, 60
    n = n_stand + n_walk
    t = np.arange(n_walk) * DT
    c0 = np.array([1.5, -1.0])
    _, left, right = _walker(c0, (0.0, 0.8), t)
    stand_l, stand_r = left[0], right[0]
    legs = ([np.vstack([stand_l, stand_r])] * n_stand
            + [np.vstack([left[k], right[k]]) for k in range(n_walk)])
    xy, pats = _observations(legs, np.random.default_rng(11))
    online = _tracker().run(_scans(n), xy, pats, 0.10)
    offline = _tracker(passes=OFFLINE).run(_scans(n), xy, pats, 0.10)
    assert online.k_init >= n_stand                     # confirmed only once it walks
    assert offline.k_init <= 2                          # ... and reported from the start
    assert offline.subject_id == online.subject_id
    k = np.flatnonzero(np.isfinite(online.x[0]))
    np.testing.assert_array_equal(offline.x[:, k], online.x[:, k])
    np.testing.assert_array_equal(offline.y[:, k], online.y[:, k])
    # while standing, the reported legs are the standing legs, each on its own side
    mid = n_stand // 2
    got = {tuple(np.round([offline.x[f, mid], offline.y[f, mid]], 1)) for f in (0, 1)}
    assert got == {tuple(np.round(stand_l, 1)), tuple(np.round(stand_r, 1))}
    # each label names the same leg on both sides of the splice: the trajectory (left or
    # right) the online method's leg f follows when it is first reported
    k0 = k[0]
    for f in (0, 1):
        p0 = np.array([online.x[f, k0], online.y[f, k0]])
        own = left if (np.linalg.norm(p0 - left[k0 - n_stand])
                       < np.linalg.norm(p0 - right[k0 - n_stand])) else right
        assert np.hypot(offline.x[f, mid] - own[0][0], offline.y[f, mid] - own[0][1]) < 0.05


def test_backward_rows_take_their_labels_from_the_splice_not_the_whole_overlap():
    """v18's failure (mtst_E07_t1): the backward pass swapped its legs at a crossing inside
    the overlap, and the majority of the overlap decided the extension's labels.  v19
    aligns each run of backward rows by the scans next to it."""
    fwd = _rows(1, range(10, 30), lambda k: (1.0, 0.1), lambda k: (1.0, -0.1))
    # backward: swapped on 0..14 (the extension and the first overlap scans), right after
    bl = lambda k: (1.0, -0.1) if k < 15 else (1.0, 0.1)          # noqa: E731
    br = lambda k: (1.0, 0.1) if k < 15 else (1.0, -0.1)          # noqa: E731
    bwd = _rows(1, range(0, 30), bl, br)
    at_splice, _ = join_passes(fwd, bwd, 0.84, extend_only=True, splice_scans=5)
    whole, _ = join_passes(fwd, bwd, 0.84, extend_only=True, splice_scans=None)
    for k in range(10):
        assert _side_at(at_splice, 1, k, "L") == 0.1            # continued across the splice
        assert _side_at(whole, 1, k, "L") == -0.1               # v16-v18: the majority
    # the forward rows are never changed
    pd.testing.assert_frame_equal(
        at_splice[at_splice["k"] >= 10].reset_index(drop=True),
        fwd.sort_values(["k", "person_id", "side"]).reset_index(drop=True))


def test_a_backward_person_joined_to_nobody_is_dropped_when_only_extending():
    fwd = _rows(3, range(10, 20), lambda k: (1.0, 0.1), lambda k: (1.0, -0.1))
    ghost = _rows(2, range(0, 20), lambda k: (4.0, 2.1), lambda k: (4.0, 1.9))
    bwd = pd.concat([_rows(1, range(0, 20), lambda k: (1.0, 0.1), lambda k: (1.0, -0.1)),
                     ghost])
    ext, ids = join_passes(fwd, bwd, 0.84, extend_only=True, splice_scans=5)
    assert set(ext["person_id"]) == {3} and ids == {3: 3}
    assert sorted(ext["k"].unique()) == list(range(20))
    kept, _ = join_passes(fwd, bwd, 0.84, extend_only=False, splice_scans=5)
    assert set(kept["person_id"]) == {3, 3 + 2}       # an id after every forward id


def test_two_people_at_once_are_never_joined_into_one():
    """Side by side 0.5 m apart (within the 0.84 m gate): each backward person joins its
    own forward person, and nobody joins the two forward persons into one."""
    a = lambda k: (1.0 + 0.1 * k, 0.35)                          # noqa: E731
    b = lambda k: (1.0 + 0.1 * k, -0.15)                         # noqa: E731
    off = lambda f, dy: (lambda k: (f(k)[0], f(k)[1] + dy))     # noqa: E731
    fwd = pd.concat([_rows(1, range(10, 30), off(a, 0.1), off(a, -0.1)),
                     _rows(2, range(10, 30), off(b, 0.1), off(b, -0.1))])
    bwd = pd.concat([_rows(1, range(0, 30), off(b, 0.1), off(b, -0.1)),
                     _rows(2, range(0, 30), off(a, 0.1), off(a, -0.1))])
    out, ids = join_passes(fwd, bwd, 0.84, extend_only=True, splice_scans=5)
    assert ids == {1: 1, 2: 2}
    early = out[out["k"] == 0].groupby("person_id")["y_m"].mean()
    assert abs(early[1] - 0.35) < 1e-9 and abs(early[2] + 0.15) < 1e-9


def test_a_backward_person_that_overlaps_another_backward_member_still_extends_alone():
    """The outdoor bag's first 10.7 s: the backward pass holds the person twice for a while
    (an early backward track that drifts off at times, and a later one that follows the
    forward track), and only the early one covers the scans before the forward person is
    confirmed.  The later one joins first (nearer); the early one, joined to no forward
    person, still joins that group and reports the scans before it, one backward member
    per scan."""
    walk = lambda k: (1.0 + 0.05 * k, 0.1)                        # noqa: E731
    other = lambda k: (1.0 + 0.05 * k, -0.1)                      # noqa: E731
    fwd = _rows(5, range(10, 40), walk, other)
    # the early one reaches before scan 10 and runs 0.3 m beside the person (the farther link)
    early = _rows(1, range(0, 25), lambda k: (walk(k)[0], 0.4), lambda k: (other(k)[0], 0.2))
    # the later backward track follows the forward one exactly (the nearer link)
    late = _rows(2, range(15, 40), walk, other)
    bwd = pd.concat([early, late])
    out, ids = join_passes(fwd, bwd, 0.84, extend_only=True, splice_scans=5)
    assert ids == {5: 5} and set(out["person_id"]) == {5}
    assert sorted(out["k"].unique()) == list(range(40))          # scans 0-9 from `early`
    assert out.groupby("k").size().max() == 2                     # one person, two legs


def test_reverse_rows_maps_scans_times_and_velocities_back():
    t = np.arange(5) * DT + 100.0
    r = _rows(1, [0, 1], lambda k: (1.0, 0.0), lambda k: (1.0, 0.2)).assign(vx_mps=0.5)
    back = reverse_rows(r, t)
    assert back["k"].tolist() == [4, 4, 3, 3]
    np.testing.assert_allclose(back["t_sensor_s"], t[[4, 4, 3, 3]])
    assert (back["vx_mps"] == -0.5).all()


def test_nothing_to_join_leaves_the_forward_pass_as_it_is():
    fwd = _rows(1, range(3), lambda k: (1.0, 0.1), lambda k: (1.0, -0.1))
    out, ids = join_passes(fwd, fwd.iloc[0:0], 0.84, extend_only=True)
    assert out is fwd and ids == {}


def test_the_benchmark_table_marks_offline_whatever_the_method_is_called(tmp_path):
    """The ``online`` column follows the definition the track ran with (its method view):
    a study's own method composing ``forward_backward``, or ``people`` switched to it by an
    override, is offline; ``people`` as built in is not."""
    import json

    from gaitval.pipeline.steps.config import offline_methods
    mine = {"label": "mine", "kind": dict(METHODS["people_offline"]["kind"])}
    views = {"mine": {"tracking": {"methods": {"mine": mine}}},
             "people": {"tracking": {"overrides": {"people": {"kind__passes": OFFLINE}}}},
             "tug_m1": {}}
    for m, cfg in views.items():
        (tmp_path / f"{m}.json").write_text(json.dumps(cfg))
    assert offline_methods(tmp_path, ["mine", "people", "tug_m1"]) == {"mine", "people"}
    assert offline_methods(None, ["people", "people_offline", "x"]) == {"people_offline"}
