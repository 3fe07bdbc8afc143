"""A leg classifier trained the way leg_tracker trains its random forest (issue 36).

leg_tracker (Leigh et al., ICRA 2015; angusleigh/leg_tracker, BSD-3) decides whether a scan
cluster "looks like a leg" with an OpenCV random forest over 17 cluster features
(:mod:`gaitval.track.legclusters`), trained by ``src/train_leg_detector.cpp`` on its
training bags (``launch/training/train_leg_detector_res=0.33.launch``: positives from
``positive_{1,2,3,4,6,7}_extracted.bag``, negatives from ``negative_{1,2,3,4,9}.bag``, all
three lasers).  Its trained forest (``config/trained_leg_detector_res=0.33.yaml``, 14 MB)
is not in the repository snapshot available here, nor are ``negative_1/3/4/9.bag``; the
positive bags and ``negative_2.bag`` are.  So the forest is trained again, with
leg_tracker's recipe, on what is available (:func:`train`):

* positives: every cluster of ``/training_scan`` whose centroid lies within 1e-4 m of a
  pose of the latest ``/leg_cluster_positions`` (``loadPosData``), 6 bags;
* negatives: every cluster of ``negative_2.bag``'s lasers (``loadNegData``).  leg_tracker
  keeps one negative cluster in ``undersample_negative_factor`` = 50 (``rand() % 50 ==
  0``) because it has five negative bags; with the one available that leaves 788
  negatives against 1,851 positives, and a forest trained so (the first version) called
  25–30 % of the empty room's clusters legs (P ≥ 0.5, each laser scored by the forest
  that did not see it) and let the people tracker with ``leg_travel`` confirm 6–14 persons
  per laser there (docs/people.md).  So every negative cluster is used (factor 1: ≈ 40,000);
* the forest: 100 trees, depth ≤ 20, a node of fewer than 2 samples is a leaf, 2 features
  tried per split (``setActiveVarCount(2)``), bootstrap samples, equal class priors —
  :class:`sklearn.ensemble.RandomForestClassifier` with those values (OpenCV's Gini
  splits, as scikit-learn's default);
* the score of a cluster is leg_tracker's: the fraction of the trees that vote "leg"
  (``detect_leg_clusters.cpp``, ``getVotes``), evaluated here by :func:`votes` from the
  trees' arrays (no scikit-learn at tracking time; the same bits on every machine).

**negative_2.bag is the empty-room test's bag** (``tests/test_people.py``).  Four forests
are shipped (``gaitval/track/data/``): ``leg_tracker_bags`` (all three lasers of
negative_2 as negatives, like leg_tracker's own forest, which was also trained on
negative_2) and ``without_left_scan`` / ``without_rear_scan`` / ``without_right_scan``
(that laser left out): the empty-room test of each laser is made with the forest that did
not see it (leave-one-topic-out).  ``data/leg_tracker-LICENSE`` is leg_tracker's licence
(the training bags and the recipe are its authors').

Rebuild (the bags from a checkout of angusleigh/leg_tracker)::

    python -m gaitval.track.legforest LEG_TRACKER_CHECKOUT gaitval/track/data
"""
from __future__ import annotations

import sys
from functools import lru_cache
from pathlib import Path

import numpy as np
from numba import njit

from gaitval.errors import FileFormatError
from gaitval.track.legclusters import N_FEATURES, scan_clusters

DATA = Path(__file__).with_name("data")
#: the shipped forests (module notes)
FORESTS = ("leg_tracker_bags", "without_left_scan", "without_rear_scan",
           "without_right_scan")
#: leg_tracker's training recipe (train_leg_detector.cpp, lines 71-73 and 193-204)
RECIPE = {"cluster_dist_euclid": 0.13, "min_points_per_cluster": 3,
          "undersample_negative_factor": 1, "n_trees": 100, "max_depth": 20,
          "min_sample_count": 2, "active_var_count": 2, "seed": 0}
POSITIVE_BAGS = tuple(f"positive_{i}_extracted.bag" for i in (1, 2, 3, 4, 6, 7))
NEGATIVE_TOPICS = ("/left_scan", "/rear_scan", "/right_scan")


# -- evaluation ----------------------------------------------------------------------------
@njit(cache=True)
def _votes(X, feature, threshold, left, right, leaf_leg, roots):
    out = np.zeros(X.shape[0])
    n_trees = roots.shape[0]
    for i in range(X.shape[0]):
        v = 0
        for t in range(n_trees):
            node = roots[t]
            while left[node] >= 0:
                if X[i, feature[node]] <= threshold[node]:
                    node = left[node]
                else:
                    node = right[node]
            v += leaf_leg[node]
        out[i] = v / n_trees
    return out


class LegForest:
    """A forest as arrays: per node its feature, threshold, children (−1: a leaf) and, for a
    leaf, whether its majority is "leg"; ``roots`` the first node of each tree."""

    def __init__(self, feature, threshold, left, right, leaf_leg, roots, name=""):
        self.feature = np.ascontiguousarray(feature, dtype=np.int64)
        self.threshold = np.ascontiguousarray(threshold, dtype=np.float64)
        self.left = np.ascontiguousarray(left, dtype=np.int64)
        self.right = np.ascontiguousarray(right, dtype=np.int64)
        self.leaf_leg = np.ascontiguousarray(leaf_leg, dtype=np.int64)
        self.roots = np.ascontiguousarray(roots, dtype=np.int64)
        self.name = name

    @property
    def n_trees(self) -> int:
        return len(self.roots)

    def votes(self, X) -> np.ndarray:
        """P(leg) of each row of ``X`` (n, 17): the fraction of trees voting "leg"."""
        X = np.ascontiguousarray(np.asarray(X, dtype=np.float64).reshape(-1, N_FEATURES))
        return _votes(X, self.feature, self.threshold, self.left, self.right,
                      self.leaf_leg, self.roots)

    @classmethod
    def from_sklearn(cls, model, name=""):
        feats, thr, lef, rig, leg, roots = [], [], [], [], [], []
        off = 0
        leg_col = list(model.classes_).index(1)
        for est in model.estimators_:
            t = est.tree_
            n = t.node_count
            roots.append(off)
            leafs = t.children_left < 0
            feats.append(np.where(leafs, 0, t.feature))
            thr.append(np.where(leafs, 0.0, t.threshold))
            lef.append(np.where(leafs, -1, t.children_left + off))
            rig.append(np.where(leafs, -1, t.children_right + off))
            v = t.value[:, 0, :]
            leg.append((np.argmax(v, axis=1) == leg_col).astype(np.int64))
            off += n
        return cls(np.concatenate(feats), np.concatenate(thr), np.concatenate(lef),
                   np.concatenate(rig), np.concatenate(leg), np.asarray(roots), name)

    def save(self, path) -> None:
        import io

        from gaitval.io.atomic import write_bytes
        buf = io.BytesIO()
        np.savez_compressed(buf, feature=self.feature.astype(np.int8),
                            threshold=self.threshold, left=self.left.astype(np.int32),
                            right=self.right.astype(np.int32),
                            leaf_leg=self.leaf_leg.astype(np.int8),
                            roots=self.roots.astype(np.int32))
        write_bytes(Path(path), buf.getvalue())


@lru_cache(maxsize=None)
def load_forest(name: str = "leg_tracker_bags") -> LegForest:
    """One of the shipped forests (:data:`FORESTS`) or a path to a ``.npz``."""
    path = DATA / f"{name}.npz" if name in FORESTS else Path(name)
    if not path.exists():
        raise FileFormatError(f"leg classifier {name!r} not found (shipped: "
                              f"{', '.join(FORESTS)})", path=path)
    with np.load(path) as z:
        return LegForest(z["feature"], z["threshold"], z["left"], z["right"],
                         z["leaf_leg"], z["roots"], name=str(name))


# -- training ------------------------------------------------------------------------------
def _bag_messages(path: Path, topics):
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    reader.open()
    try:
        conns = [c for c in reader.connections if c.topic in topics]
        for con, _, raw in reader.messages(connections=conns):
            yield con.topic, reader.deserialize(raw, con.msgtype)
    finally:
        reader.close()


def _clusters(m, recipe):
    r = np.asarray(m.ranges, dtype=np.float64)
    return scan_clusters(r, float(m.angle_min), float(m.angle_increment),
                         float(m.range_min), float(m.range_max),
                         float(recipe["cluster_dist_euclid"]),
                         int(recipe["min_points_per_cluster"]))


def labelled_clusters(path: Path, recipe=RECIPE) -> tuple[np.ndarray, np.ndarray]:
    """(leg clusters, other clusters) of a positive bag's ``/training_scan``, from the
    first ``/leg_cluster_positions`` on: a leg is a cluster at a pose of the latest
    ``/leg_cluster_positions`` (within 1e-4 m)."""
    pos, neg, poses = [], [], np.zeros((0, 2))
    for topic, m in _bag_messages(path, ("/training_scan", "/leg_cluster_positions")):
        if topic == "/leg_cluster_positions":
            poses = np.array([[p.position.x, p.position.y] for p in m.poses]).reshape(-1, 2)
            continue
        if not len(poses):
            continue
        cen, f = _clusters(m, recipe)
        for c in range(len(cen)):
            leg = (np.hypot(*(poses - cen[c]).T) < 1e-4).any()
            (pos if leg else neg).append(f[c])
    return (np.asarray(pos).reshape(-1, N_FEATURES), np.asarray(neg).reshape(-1, N_FEATURES))


def positive_features(path: Path, recipe=RECIPE) -> np.ndarray:
    """leg_tracker's ``loadPosData``: the leg clusters of :func:`labelled_clusters`."""
    return labelled_clusters(path, recipe)[0]


def negative_features(path: Path, topic: str, rng, recipe=RECIPE) -> np.ndarray:
    """leg_tracker's ``loadNegData``: every cluster, one in ``undersample_negative_factor``
    kept at random."""
    rows = []
    for _, m in _bag_messages(path, (topic,)):
        _, f = _clusters(m, recipe)
        for c in range(len(f)):
            if rng.integers(recipe["undersample_negative_factor"]) == 0:
                rows.append(f[c])
    return np.asarray(rows).reshape(-1, N_FEATURES)


def train(pos: np.ndarray, neg: np.ndarray, recipe=RECIPE, name="") -> LegForest:
    """leg_tracker's forest (module notes) fitted with scikit-learn."""
    from sklearn.ensemble import RandomForestClassifier
    X = np.vstack([pos, neg])
    y = np.r_[np.ones(len(pos), dtype=int), -np.ones(len(neg), dtype=int)]
    model = RandomForestClassifier(
        n_estimators=recipe["n_trees"], max_depth=recipe["max_depth"],
        min_samples_split=recipe["min_sample_count"],
        max_features=recipe["active_var_count"], bootstrap=True,
        random_state=recipe["seed"], n_jobs=1)
    model.fit(X, y)
    return LegForest.from_sklearn(model, name)


def build_all(leg_tracker_dir, out_dir, recipe=RECIPE) -> dict:
    """Train and save the shipped forests (module notes); returns the sample counts."""
    root = Path(leg_tracker_dir) / "rosbags" / "training_scans_res=0.33"
    pos = np.vstack([positive_features(root / b, recipe) for b in POSITIVE_BAGS])
    neg = {}
    for i, topic in enumerate(NEGATIVE_TOPICS):
        rng = np.random.default_rng(recipe["seed"] + i)
        neg[topic] = negative_features(root / "negative_2.bag", topic, rng, recipe)
    counts = {"positive": len(pos), **{f"negative{t}": len(v) for t, v in neg.items()}}
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name in FORESTS:
        held = "/" + name[len("without_"):] if name.startswith("without_") else None
        n = np.vstack([v for t, v in neg.items() if t != held])
        train(pos, n, recipe, name).save(out / f"{name}.npz")
    return counts


if __name__ == "__main__":            # python -m gaitval.track.legforest CHECKOUT OUT_DIR
    print(build_all(sys.argv[1], sys.argv[2]))
