"""Training clusters for a leg classifier from the twin (gaitval/crowd/legdata.py), the
dev-only following scene, and the ``legs_confirm`` appearance role (issue 55)."""
import numpy as np
import pytest

from gaitval.crowd import bench, legdata, scenes
from gaitval.crowd.scenes import PERSON_ID0, Walk, make_scene, render
from gaitval.simulate.scene import ID_CHAIR

SMALL = {"cluster_dist_euclid": 0.13, "min_points_per_cluster": 3,
         "undersample_negative_factor": 1, "n_trees": 15, "max_depth": 20,
         "min_sample_count": 2, "active_var_count": 2, "seed": 0}


def _standing(x, y, radius=0.06, width=0.17, t_end=3.0):
    """A walker who stands at (x, y) facing +y, across the sensor's view (its feet half a
    stride apart along its path, as the scenes' gait leaves them)."""
    return Walk(np.array([[x, y], [x, y + 1.0]]), np.array([0.0, t_end]),
                np.array([0.0, 0.0]), 1.0, width, radius)


def _room_scene(walks, furn, n=30, speed_mps=0.0):
    """Scans of ``walks`` and furniture circles in a room, the sensor driving along +x at
    ``speed_mps`` from the origin (its poses the scans' odometry)."""
    t = np.arange(n) * scenes.DT_S
    pose = np.column_stack([speed_mps * t, np.zeros(n), np.zeros(n)])
    hits: dict = {}
    scans, truth = render(walks, furn, ((-1.5, 8.0), (-3.5, 3.5)), pose, t,
                          np.random.default_rng(0), hits)
    return scans, truth, hits


def _chairs(x, y):
    return np.array([[x + dx, y + dy, 0.012, ID_CHAIR] for dx in (-0.21, 0.21)
                     for dy in (-0.21, 0.21)])


def test_a_rendered_leg_is_labelled_leg_and_a_chair_leg_is_not():
    scans, _, hits = _room_scene([_standing(2.5, 1.0)], _chairs(1.2, -0.8), n=3)
    R = np.ascontiguousarray(scans.ranges, dtype=float)
    feats, lab = legdata.scan_labelled_clusters(R[0], hits["id"][0], scans)
    from gaitval.track.legclusters import cluster_scan
    label, nc = cluster_scan(R[0], scans.angle_min, scans.angle_increment, scans.range_min,
                             scans.range_max, 0.13, 3)
    assert nc == len(lab) == len(feats)
    kinds = {}
    for c in range(nc):
        ids = set(hits["id"][0][label == c].tolist())
        kinds[c] = ("leg" if ids <= {PERSON_ID0, PERSON_ID0 + 1} else
                    "chair" if ids == {ID_CHAIR} else "other")
    assert sum(v == "leg" for v in kinds.values()) == 2
    assert any(v == "chair" for v in kinds.values())
    for c, v in kinds.items():
        if v == "leg":
            assert lab[c] == 1
        elif v == "chair":
            assert lab[c] == -1


def test_training_scenes_are_seeded_and_never_the_benchmarks():
    a, ha = legdata.training_scene("assisted", 1001)
    b, hb = legdata.training_scene("assisted", 1001)
    np.testing.assert_array_equal(a.ranges, b.ranges)
    np.testing.assert_array_equal(ha, hb)
    assert not set(legdata.TRAIN_SEEDS) & (set(scenes.DEV_SEEDS) | set(scenes.TEST_SEEDS))
    with pytest.raises(ValueError):
        legdata.training_scene("assisted", scenes.TEST_SEEDS[0])


def test_the_following_scene_is_development_only_and_seeded():
    a, b = make_scene(scenes.FOLLOWING, 11), make_scene(scenes.FOLLOWING, 11)
    np.testing.assert_array_equal(a.scans.ranges, b.scans.ranges)
    assert scenes.FOLLOWING not in scenes.KINDS
    assert all(k != scenes.FOLLOWING for _, k, _ in bench.scenes("all"))
    # the followed person is seen on nearly every scan, standing at the start
    seen = a.truth[a.truth["id"] == "p0"]
    assert len(seen) > 0.9 * a.scans.n_scans
    first = seen.head(10)[["x_m", "y_m"]].to_numpy()
    assert np.ptp(first[:, 0]) < 0.05


@pytest.fixture(scope="module")
def twin_forest(tmp_path_factory):
    """A small forest (15 trees) on the twin's clusters of two training scenes."""
    from gaitval.track.legforest import train
    pos, neg = legdata.twin_clusters(seeds=(1001,), kinds=("meet_stand_turn", "assisted"))
    path = tmp_path_factory.mktemp("forest") / "twin.npz"
    train(pos, neg, SMALL, "twin").save(path)
    return path


def test_a_standing_person_is_confirmed_by_its_legs_within_k_scans(twin_forest):
    """A rendered person who stands 2.5 m ahead of a robot that drives slowly towards
    them (a standing sensor's detector takes a standing person for background): the
    walking confirmer never confirms them; with ``legs_confirm`` (K = 5) they are
    reported from scan K − 1 on (the birth scan counts); four chair legs beside them never
    are."""
    from gaitval.methods import build_method
    scans, truth, _ = _room_scene([_standing(2.5, 0.3)], _chairs(2.5, -1.2), n=30,
                                  speed_mps=0.3)
    base = {"kind__ego_motion": {"name": "odometry"}}
    plain = build_method("people", base).track(scans, 0.11)
    assert plain.n_confirmed == 0
    look = {**base, "kind__appearance": {"name": "legs_confirm", "forest": str(twin_forest),
                                         "min_score": 0.7, "n_scans": 5}}
    res = build_method("people", look).track(scans, 0.11)
    assert res.n_confirmed == 1
    p = res.people
    assert p["k"].min() == 4
    got = p.groupby("k")[["x_m", "y_m"]].mean()
    want = truth.set_index("k").loc[got.index, ["x_m", "y_m"]]
    assert np.hypot(*(got.to_numpy() - want.to_numpy()).T).max() < 0.1   # on the person


def test_chair_legs_alone_are_never_confirmed_by_their_looks(twin_forest):
    from gaitval.methods import build_method
    behind = _standing(-1.0, 0.0)           # bearing 180°: outside the 270° scan
    scans, truth, _ = _room_scene([behind], np.vstack([_chairs(2.0, 0.0), _chairs(3.5, 1.0)]),
                                  n=30, speed_mps=0.3)
    assert truth.empty
    look = {"kind__ego_motion": {"name": "odometry"},
            "kind__appearance": {"name": "legs_confirm", "forest": str(twin_forest),
                                 "min_score": 0.7, "n_scans": 5}}
    res = build_method("people", look).track(scans, 0.11)
    assert res.n_born > 0                       # chair-leg pairs were hypotheses
    assert res.n_confirmed == 0 and res.n_refound == 0
